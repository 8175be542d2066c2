//! Glue for applications and tools: spawning a scene file into an ECS world, and a headless
//! app that renders scenes to images.

mod lights;
mod scene_entity;
mod spawn;

pub use spawn::{PreparedScene, SceneEntity, SpawnError, despawn_scene, spawn_scene};

use bevy_app::App;
use bevy_ecs::query::{QueryState, With};
use bevy_ecs::world::World;
use bevy_transform::components::Transform;
use glam::Vec3;
use image::RgbaImage;
use thiserror::Error;

use crate::ecs::components::{Camera3d, ViewportSize};
use crate::ecs::plugin::ShadowPlugin;
use crate::ecs::shadow_memory::{ShadowMemory, ShadowMemoryBudget};
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::ecs::view_lod::CameraLod;
use crate::render::gpu_types::InstanceGpu;
use crate::render::options::RenderOptions;
use crate::render::target::AnalysisImage;
use crate::render::{FrameReport, GpuError, LimitError, RenderPlugin, Renderer};
use crate::scene::{self, SceneDesc};
use crate::settings::ShadowSettings;

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
    /// The shadow-memory budget cannot hold a light's shadows
    /// ([`ShadowMemory::error`](crate::ecs::ShadowMemory::error)).
    #[error("{0}")]
    ShadowMemory(String),
    /// The PNG could not be written.
    #[error("cannot write `{path}`: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

/// An app with [`ShadowPlugin`] and [`RenderPlugin`] around a headless renderer.
pub fn headless_app(renderer: Renderer) -> App {
    let mut app = App::new();
    app.add_plugins((ShadowPlugin, RenderPlugin));
    // NOTE: the first frame's cascades already need the target's aspect ratio.
    let (width, height) = renderer.size();
    app.insert_resource(ViewportSize { width, height });
    app.insert_resource(renderer.gpu.shadow_memory_budget());
    app.insert_resource(renderer);
    app
}

/// The shadow memory of `prepared` in a `width`×`height` view under `budget`, as the shadow
/// systems fit it in the first frame — without a GPU (what `penumbra check` reports).
pub fn shadow_memory_of(
    prepared: PreparedScene,
    (width, height): (u32, u32),
    budget: ShadowMemoryBudget,
) -> ShadowMemory {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ViewportSize { width, height });
    app.insert_resource(budget);
    prepared.spawn(app.world_mut());
    app.update();
    app.world().resource::<ShadowMemory>().clone()
}

/// Overrides applied on top of a scene's shadow settings and each light's own.
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
    /// CPU time of the shadow systems of every frame ([`ShadowStats::frame_cpu`]).
    pub frames_cpu: Vec<std::time::Duration>,
    /// Warnings raised.
    pub warnings: Vec<String>,
    /// Adapter description.
    pub adapter: String,
    /// Mesh entities spawned.
    pub instances: usize,
    /// The last frame's shadow memory, as fitted to the budget before allocating.
    pub memory: ShadowMemory,
}

impl HeadlessFrame {
    /// The median of [`frames_cpu`](Self::frames_cpu) in milliseconds, the first frame left
    /// out when there are more (it builds everything); None without frames.
    pub fn median_frame_cpu_ms(&self) -> Option<f64> {
        let skip = usize::from(self.frames_cpu.len() > 1);
        let mut ms: Vec<f64> = self.frames_cpu[skip..].iter().map(|d| d.as_secs_f64() * 1e3).collect();
        ms.sort_by(f64::total_cmp);
        ms.get(ms.len() / 2).copied()
    }
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
            options: RenderOptions::default(),
            shadow_budget: None,
            count_fragments: false,
            camera_lod: None,
            camera_motion: CameraMotion::default(),
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
    /// Render-wide switches (depth prepass).
    pub options: RenderOptions,
    /// Most bytes of shadow storage (None: the device's default,
    /// [`GpuContext::shadow_memory_budget`](crate::render::GpuContext::shadow_memory_budget)).
    pub shadow_budget: Option<u64>,
    /// Count the lighting pass's fragment invocations (`FrameReport::forward_fragments`;
    /// each frame waits for the count). Ignored where the device cannot count them.
    pub count_fragments: bool,
    /// How the camera moves between frames (still by default).
    pub camera_motion: CameraMotion,
    /// The camera view's level of detail (None: the default [`CameraLod`]).
    pub camera_lod: Option<CameraLod>,
}

/// How a headless render moves its camera before each frame after the first: by `step`
/// (metres, world axes) and turning by `turn_degrees` about the vertical. A measurement of
/// moving frames: a translating camera moves cascades and clipmap windows, a turning one
/// moves cascades only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraMotion {
    /// Translation per frame, metres.
    pub step: Vec3,
    /// Turn per frame about +Y, degrees.
    pub turn_degrees: f32,
}

/// Moves every camera of `world` (found by `cameras`, made once per render) by `motion`.
fn move_cameras(world: &mut World, cameras: &mut QueryState<&mut Transform, With<Camera3d>>, motion: CameraMotion) {
    for mut t in cameras.iter_mut(world) {
        t.translation += motion.step;
        t.rotate_y(motion.turn_degrees.to_radians());
    }
}

/// Renders a scene as requested and returns the last frame.
pub fn render_scene_with(desc: &SceneDesc, request: &RenderRequest<'_>) -> Result<HeadlessFrame, RenderError> {
    let (width, height, frames) = (request.width, request.height, request.frames);
    let mut desc = desc.clone();
    if let Some(tweak) = request.tweak {
        desc.settings_mut().for_each(tweak);
    }
    let renderer = if request.analysis {
        Renderer::headless_with_analysis(width, height)?
    } else {
        Renderer::headless(width, height)?
    };
    let adapter = renderer.gpu.describe();
    // NOTE: checked before anything is spawned or uploaded, so an oversized scene costs no
    // GPU memory and names its cause.
    let most = renderer.gpu.limits.storage_elements(size_of::<InstanceGpu>() as u64);
    let wanted = desc.instance_count();
    if wanted > most {
        return Err(RenderError::Gpu(GpuError::Limit(LimitError {
            what: "the scene's instance count".to_owned(),
            found: wanted,
            min: 0,
            max: most,
        })));
    }
    let mut renderer = renderer;
    renderer.count_forward_fragments(request.count_fragments);
    let mut app = headless_app(renderer);
    app.insert_resource(request.options);
    if let Some(lod) = request.camera_lod {
        app.insert_resource(lod);
    }
    if let Some(bytes) = request.shadow_budget {
        app.world_mut().resource_mut::<ShadowMemoryBudget>().bytes = bytes;
    }
    let prepared = PreparedScene::new(&desc)?;
    let mut warnings = prepared.warnings().to_vec();
    let instances = prepared.spawn(app.world_mut());
    let mut reports = Vec::new();
    let mut frames_cpu = Vec::new();
    let mut cameras = app.world_mut().query_filtered::<&mut Transform, With<Camera3d>>();
    for frame in 0..frames.max(1) {
        if frame > 0 && request.camera_motion != CameraMotion::default() {
            move_cameras(app.world_mut(), &mut cameras, request.camera_motion);
        }
        app.update();
        frames_cpu.push(app.world().resource::<ShadowStats>().frame_cpu);
        // NOTE: the lights it names cast no shadow and nothing was allocated for them; a
        // headless render fails rather than write an image without them.
        if let Some(error) = &app.world().resource::<ShadowMemory>().error {
            return Err(RenderError::ShadowMemory(error.clone()));
        }
        let mut renderer = app.world_mut().resource_mut::<Renderer>();
        let errors = renderer.take_errors();
        if !errors.is_empty() {
            return Err(RenderError::Gpu(GpuError::Validation(errors.join("; "))));
        }
        warnings.extend(renderer.take_warnings());
        // NOTE: a headless measurement waits for each frame's timings, so every frame is
        // timed (an interactive frame loop does not wait; its timings arrive a frame or two
        // later).
        let frame = renderer.frames_rendered() - 1;
        let timings = renderer.wait_for_timings();
        let mut report = renderer.last_report.clone();
        report.timed_frame = frame;
        report.passes = timings
            .into_iter()
            .find(|t| t.frame == frame)
            .map(|t| t.passes)
            .unwrap_or_default();
        report.pages = renderer.read_page_stats();
        report.occlusion_drawn = renderer.read_occlusion_drawn();
        reports.push(report);
    }
    let world = app.world();
    let renderer = world.resource::<Renderer>();
    warnings.extend(world.resource::<ShadowDiagnostics>().current.iter().cloned());
    Ok(HeadlessFrame {
        image: renderer.read_image(),
        analysis: renderer.read_analysis(),
        report: reports.last().cloned().unwrap_or_default(),
        stats: world.resource::<ShadowStats>().clone(),
        frames: reports,
        frames_cpu,
        warnings,
        adapter,
        instances,
        memory: world.resource::<ShadowMemory>().clone(),
    })
}
