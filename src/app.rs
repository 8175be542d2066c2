//! Glue for applications and tools: spawning a scene file into an ECS world, and a headless
//! app that renders scenes to images.

use std::collections::HashMap;
use std::path::Path;

use bevy_app::App;
use bevy_ecs::world::World;
use image::RgbaImage;
use thiserror::Error;

use crate::ecs::assets::{AlphaMode, ImageData, ImageHandle, Images, Material, Materials, MeshHandle, Meshes};
use crate::ecs::components::{
    AmbientLight, Camera3d, CastShadows, DirectionalLight, Mesh3d, MeshMaterial3d, NotShadowReceiver, Transform,
    ViewportSize,
};
use crate::ecs::plugin::ShadowPlugin;
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::mesh::{MeshData, cuboid, plane, sphere};
use crate::render::target::AnalysisImage;
use crate::render::{FrameReport, GpuError, RenderPlugin, Renderer};
use crate::scene::{self, SceneDesc, Shape};
use crate::settings::ShadowSettings;

/// A scene that loaded but could not be spawned.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SpawnError {
    /// A texture file could not be read or decoded.
    #[error("{path}: cannot load texture: {message}")]
    Texture {
        /// Texture path.
        path: String,
        /// Why.
        message: String,
    },
    /// The object uses a shape this version cannot build.
    #[error("object {object}: glTF models are not supported yet (`{path}`); use Plane, Cuboid or Sphere")]
    UnsupportedShape {
        /// Index of the object in the file.
        object: usize,
        /// The model path.
        path: String,
    },
}

/// Anything that can stop a headless render.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The scene file is invalid.
    #[error(transparent)]
    Scene(#[from] scene::SceneError),
    /// The scene could not be spawned.
    #[error(transparent)]
    Spawn(#[from] SpawnError),
    /// No GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The shadow image could not be written.
    #[error(transparent)]
    Export(#[from] crate::export::ExportError),
    /// The PNG could not be written.
    #[error("cannot write `{path}`: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

fn load_texture(path: &Path) -> Result<ImageData, SpawnError> {
    let image = image::open(path)
        .map_err(|e| SpawnError::Texture {
            path: path.display().to_string(),
            message: e.to_string(),
        })?
        .to_rgba8();
    Ok(ImageData {
        width: image.width(),
        height: image.height(),
        rgba: image.into_raw(),
    })
}

fn shape_mesh(shape: &Shape, object: usize) -> Result<MeshData, SpawnError> {
    match shape {
        Shape::Plane { size } => Ok(plane(*size)),
        Shape::Cuboid { size } => Ok(cuboid(*size)),
        Shape::Sphere { radius } => Ok(sphere(*radius, 32, 16)),
        Shape::Gltf { path } => Err(SpawnError::UnsupportedShape {
            object,
            path: path.display().to_string(),
        }),
    }
}

/// Spawns a loaded scene: camera, sun (with its shadow settings), ambient light, materials,
/// meshes and one entity per object instance. Returns the number of mesh entities spawned.
pub fn spawn_scene(world: &mut World, desc: &SceneDesc) -> Result<usize, SpawnError> {
    let c = &desc.camera;
    world.spawn((
        Camera3d {
            fov_y: c.fov.to_radians(),
            near: c.near,
            far: c.far,
            exposure: 1.0,
        },
        Transform::from_translation(c.position).looking_at(c.target, c.up),
    ));
    let sun_transform = Transform::default().looking_at(desc.sun.direction, glam::Vec3::Y);
    world.spawn((
        DirectionalLight {
            color: desc.sun.color,
            illuminance: desc.sun.illuminance,
            angular_diameter: desc.sun.angular_diameter.to_radians(),
            shadows_enabled: true,
        },
        sun_transform,
        desc.shadows,
    ));
    world.insert_resource(AmbientLight { color: desc.ambient });

    let mut textures: HashMap<std::path::PathBuf, ImageHandle> = HashMap::new();
    let mut material_handles = Vec::with_capacity(desc.materials.len());
    for m in &desc.materials {
        let texture = match &m.texture {
            Some(rel) => {
                let path = desc.resolve_path(rel);
                let handle = match textures.get(&path) {
                    Some(h) => *h,
                    None => {
                        let h = world.resource_mut::<Images>().add(load_texture(&path)?);
                        textures.insert(path, h);
                        h
                    }
                };
                Some(handle)
            }
            None => None,
        };
        let alpha_mode = match m.alpha {
            scene::AlphaMode::Opaque => AlphaMode::Opaque,
            scene::AlphaMode::Mask(c) => AlphaMode::Mask(c),
        };
        let material = Material {
            base_color: m.base_color,
            base_color_texture: texture,
            alpha_mode,
            double_sided: m.is_double_sided(),
        };
        material_handles.push(world.resource_mut::<Materials>().add(material));
    }

    let mut mesh_handles: HashMap<String, MeshHandle> = HashMap::new();
    let mut object_meshes: Vec<MeshHandle> = Vec::with_capacity(desc.objects.len());
    for (i, object) in desc.objects.iter().enumerate() {
        let key = format!("{:?}", object.shape);
        let handle = match mesh_handles.get(&key) {
            Some(h) => *h,
            None => {
                let h = world.resource_mut::<Meshes>().add(shape_mesh(&object.shape, i)?);
                mesh_handles.insert(key, h);
                h
            }
        };
        object_meshes.push(handle);
    }

    let mut batch = Vec::new();
    let mut count = 0;
    for instance in desc.instances() {
        let transform = Transform {
            translation: instance.translation,
            rotation: instance.rotation,
            scale: instance.scale,
        };
        let mesh = Mesh3d(object_meshes[instance.object]);
        let material = MeshMaterial3d(material_handles[instance.material]);
        batch.push((
            transform,
            mesh,
            material,
            instance.cast_shadows,
            instance.receive_shadows,
        ));
        count += 1;
    }
    for (transform, mesh, material, cast, receive) in batch {
        let mut e = world.spawn((transform, mesh, material));
        if cast {
            e.insert(CastShadows);
        }
        if !receive {
            e.insert(NotShadowReceiver);
        }
    }
    Ok(count)
}

/// An app with [`ShadowPlugin`] and [`RenderPlugin`] around a headless renderer.
pub fn headless_app(renderer: Renderer) -> App {
    let mut app = App::new();
    app.add_plugins((ShadowPlugin, RenderPlugin));
    // NOTE: the first frame's cascades already need the target's aspect ratio.
    let (width, height) = renderer.size();
    app.insert_resource(ViewportSize { width, height });
    app.insert_resource(renderer);
    app
}

/// Overrides applied on top of a scene's own shadow settings.
pub type SettingsOverride<'a> = &'a dyn Fn(&mut ShadowSettings);

/// The result of rendering a scene headless.
pub struct HeadlessFrame {
    /// The final image.
    pub image: RgbaImage,
    /// The analysis targets of the final frame, when requested.
    pub analysis: Option<AnalysisImage>,
    /// GPU report of the last frame.
    pub report: FrameReport,
    /// Statistics of the last frame.
    pub stats: ShadowStats,
    /// GPU reports of every frame (for medians).
    pub frames: Vec<FrameReport>,
    /// Warnings raised.
    pub warnings: Vec<String>,
    /// Adapter description.
    pub adapter: String,
    /// Mesh entities spawned.
    pub instances: usize,
}

/// Renders `frames` frames of a scene on a new headless device and returns the last image.
pub fn render_scene(
    desc: &SceneDesc,
    width: u32,
    height: u32,
    frames: u32,
    tweak: Option<SettingsOverride<'_>>,
) -> Result<HeadlessFrame, RenderError> {
    render_scene_with(
        desc,
        &RenderRequest {
            width,
            height,
            frames,
            tweak,
            analysis: false,
        },
    )
}

/// What [`render_scene_with`] renders.
pub struct RenderRequest<'a> {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Frames to render (at least one).
    pub frames: u32,
    /// Changes to the scene's shadow settings.
    pub tweak: Option<SettingsOverride<'a>>,
    /// Also record the per-pixel shadow factor, position and normal.
    pub analysis: bool,
}

/// Renders a scene as requested and returns the last frame.
pub fn render_scene_with(desc: &SceneDesc, request: &RenderRequest<'_>) -> Result<HeadlessFrame, RenderError> {
    let (width, height, frames) = (request.width, request.height, request.frames);
    let mut desc = desc.clone();
    if let Some(tweak) = request.tweak {
        tweak(&mut desc.shadows);
    }
    let renderer = if request.analysis {
        Renderer::headless_with_analysis(width, height)?
    } else {
        Renderer::headless(width, height)?
    };
    let adapter = renderer.gpu.describe();
    let mut app = headless_app(renderer);
    let instances = spawn_scene(app.world_mut(), &desc)?;
    let mut reports = Vec::new();
    for _ in 0..frames.max(1) {
        app.update();
        reports.push(app.world().resource::<Renderer>().last_report.clone());
    }
    let world = app.world();
    let renderer = world.resource::<Renderer>();
    Ok(HeadlessFrame {
        image: renderer.read_image(),
        analysis: renderer.read_analysis(),
        report: renderer.last_report.clone(),
        stats: world.resource::<ShadowStats>().clone(),
        frames: reports,
        warnings: world.resource::<ShadowDiagnostics>().current.clone(),
        adapter,
        instances,
    })
}
