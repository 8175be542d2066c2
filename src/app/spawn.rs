//! Spawning a scene file into an ECS world, in two steps: [`PreparedScene::new`] does every
//! fallible thing (reading textures and models, building meshes) without touching the world,
//! and [`PreparedScene::spawn`] cannot fail. A live reload prepares the new scene first and
//! only then replaces the old one, so a bad edit never leaves a half-spawned world.

use std::collections::HashMap;
use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;

use bevy_ecs::bundle::{Bundle, NoBundleEffect};
use bevy_ecs::entity::Entity;
use bevy_ecs::query::With;
use bevy_ecs::world::World;
use bevy_transform::components::Transform;
use glam::Mat4;
use thiserror::Error;

use crate::app::lights::{LightPlan, light_plans, spawn_lights};
pub use crate::app::scene_entity::SceneEntity;
use crate::app::spawn::skinned::{SkinPart, SkinnedPlans, first_player};
use crate::asset_io::{AssetError, AssetIo, AssetPath};
use crate::ecs::assets::{AlphaMode, ImageData, ImageHandle, Images, Material, MaterialHandle, Materials, Meshes};
use crate::ecs::components::{AmbientLight, Camera3d, Mesh3d, MeshMaterial3d, NotShadowCaster, NotShadowReceiver};
use crate::ecs::mobility::Static;
use crate::ecs::shadow_lods::{ShadowLod, ShadowLods};
use crate::ecs::skinning::{AnimationPlayer, SkinSource, SkinSources};
use crate::math::pose::Skeleton;
use crate::mesh::{MeshData, cuboid, plane, sphere};
use crate::scene::{self, SceneDesc, Shape};
use crate::text::echoed;
use bevy_ecs::name::Name;

mod model;
mod skinned;

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
    /// The scene would spawn more mesh entities (instances × the primitives of their shape)
    /// than its instance budget allows.
    #[error(
        "the scene would spawn {entities} mesh entities (each glTF object counts its primitives), more than the {max} its instance budget allows"
    )]
    Budget {
        /// Mesh entities the scene would spawn.
        entities: u64,
        /// [`SceneLimits::max_instances`](crate::scene::SceneLimits::max_instances).
        max: u64,
    },
    /// A glTF model could not be loaded (the message names the file and the problem).
    #[error("object {object}: {message}")]
    Model {
        /// Index of the object in the scene file.
        object: usize,
        /// The loader's message.
        message: String,
        /// The loader's error itself, whose text `message` is, when the model file was read:
        /// [`render_error`](crate::diagnostic::render_error) shows its offending JSON line.
        error: Option<Box<dyn std::error::Error + Send + Sync>>,
    },
}

impl SpawnError {
    /// The loader's error of a [`SpawnError::Model`], if kept.
    pub(crate) fn model_error(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SpawnError::Model { error: Some(e), .. } => Some(&**e),
            _ => None,
        }
    }
}

/// One mesh entity to spawn: indices into the prepared meshes and materials.
#[derive(Clone, Debug)]
struct EntityPlan {
    transform: Transform,
    mesh: usize,
    material: usize,
    cast: bool,
    receive: bool,
    skin: Option<SkinPart>,
    /// How a skinned entity's animation starts (None for the others).
    player: Option<AnimationPlayer>,
}

/// What an object's shape is built from: a model file, or a primitive (by its description).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum ShapeKey {
    Model(AssetPath),
    Primitive(String),
}

/// Resolves a path written in the scene inside the asset root.
fn resolve(desc: &SceneDesc, io: &AssetIo, rel: &Path) -> Result<AssetPath, AssetError> {
    io.resolve(&desc.base_dir, &rel.to_string_lossy())
}

/// The error for a model path that does not resolve.
fn model_error(object: usize, e: AssetError) -> SpawnError {
    SpawnError::Model {
        object,
        message: e.to_string(),
        error: None,
    }
}

/// A scene with every file read and every mesh built, ready to spawn.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    camera: (Camera3d, Transform),
    /// The sun first, then the scene's other lights, with their names.
    lights: Vec<(Name, LightPlan)>,
    ambient: AmbientLight,
    images: Vec<ImageData>,
    /// Materials; `base_color_texture` holds an index into `images`.
    materials: Vec<Material>,
    meshes: Vec<MeshData>,
    /// Shadow LODs: (mesh, [(coarser mesh, relative error)]), indices into `meshes`.
    shadow_lods: Vec<(usize, Vec<(usize, f32)>)>,
    entities: Vec<EntityPlan>,
    /// Bind poses of the skinned meshes, with their influences.
    skin_sources: Vec<SkinSource>,
    /// The skins' skeletons.
    skeletons: Vec<Arc<Skeleton>>,
    /// Bytes of the decoded images, RGBA8 with their mip chains.
    texture_bytes: u64,
    /// Images downscaled to fit the texture budget.
    warnings: Vec<String>,
}

/// One mesh an object's shape expands to.
#[derive(Clone, Copy, Debug)]
struct MeshPart {
    /// Index into the prepared meshes.
    mesh: usize,
    /// The model's own material, or None for the object's.
    material: Option<usize>,
    /// Where the mesh sits in the object.
    object_from_mesh: Mat4,
    /// The skin that deforms it.
    skin: Option<SkinPart>,
}

impl PreparedScene {
    /// Reads every texture and model the scene uses and builds its meshes; files are confined
    /// to the scene's asset root (see [`SceneDesc::asset_io`]).
    pub fn new(desc: &SceneDesc) -> Result<Self, SpawnError> {
        Self::with_assets(desc, &desc.asset_io())
    }

    /// Like [`new`](Self::new), with files confined to `io`'s asset root and read under its
    /// limits.
    pub fn with_assets(desc: &SceneDesc, io: &AssetIo) -> Result<Self, SpawnError> {
        let c = &desc.camera;
        let camera = (
            Camera3d {
                fov_y: c.fov.to_radians(),
                near: c.near,
                far: c.far,
                exposure: 1.0,
            },
            Transform::from_translation(c.position).looking_at(c.target, c.up),
        );
        let mut scene = PreparedScene {
            camera,
            lights: light_plans(desc),
            ambient: AmbientLight { color: desc.ambient },
            images: Vec::new(),
            materials: Vec::new(),
            meshes: Vec::new(),
            shadow_lods: Vec::new(),
            entities: Vec::new(),
            skin_sources: Vec::new(),
            skeletons: Vec::new(),
            texture_bytes: 0,
            warnings: Vec::new(),
        };
        let before = io.texture_bytes();
        scene.add_materials(desc, io)?;
        scene.add_objects(desc, io)?;
        scene.texture_bytes = io.texture_bytes() - before;
        scene.warnings = io.take_notes();
        Ok(scene)
    }

    /// Adds the scene's materials, loading each texture file once (however it is spelt).
    fn add_materials(&mut self, desc: &SceneDesc, io: &AssetIo) -> Result<(), SpawnError> {
        let mut textures: HashMap<AssetPath, usize> = HashMap::new();
        for m in &desc.materials {
            let texture = match &m.texture {
                Some(rel) => Some(self.texture(&mut textures, desc, io, rel)?),
                None => None,
            };
            self.materials.push(Material {
                base_color: m.base_color,
                base_color_texture: texture.map(|i| ImageHandle(i as u32)),
                alpha_mode: match m.alpha {
                    scene::AlphaMode::Opaque => AlphaMode::Opaque,
                    scene::AlphaMode::Mask(c) => AlphaMode::Mask(c),
                },
                double_sided: m.is_double_sided(),
                transmission: m.transmission,
            });
        }
        Ok(())
    }

    /// Builds each distinct shape once, then plans one entity per mesh part of every object
    /// instance.
    fn add_objects(&mut self, desc: &SceneDesc, io: &AssetIo) -> Result<(), SpawnError> {
        let mut shapes: HashMap<ShapeKey, usize> = HashMap::new();
        let mut built: Vec<Vec<MeshPart>> = Vec::new();
        let mut object_shapes = Vec::with_capacity(desc.objects.len());
        for (i, object) in desc.objects.iter().enumerate() {
            // NOTE: a model is keyed by its file, so two spellings of one path load it once.
            let key = match &object.shape {
                Shape::Gltf { path } => ShapeKey::Model(resolve(desc, io, path).map_err(|e| model_error(i, e))?),
                other => ShapeKey::Primitive(format!("{other:?}")),
            };
            let index = match shapes.get(&key) {
                Some(&index) => index,
                None => {
                    let parts = match &key {
                        ShapeKey::Model(file) => self.add_model(file, io, i)?,
                        ShapeKey::Primitive(_) => self.build_primitive(&object.shape),
                    };
                    built.push(parts);
                    shapes.insert(key, built.len() - 1);
                    built.len() - 1
                }
            };
            object_shapes.push(index);
        }
        // NOTE: counted before any entity is planned: a model with many primitives placed by
        // a large grid multiplies into more entities than the scene's instance budget.
        let entities = desc
            .objects
            .iter()
            .zip(&object_shapes)
            .fold(0u64, |sum, (object, &shape)| {
                let copies = object.grid.as_ref().map_or(1, |g| g.len());
                sum.saturating_add(copies.saturating_mul(built[shape].len() as u64))
            });
        let max = desc.limits.max_instances;
        if entities > max {
            return Err(SpawnError::Budget { entities, max });
        }
        self.entities.reserve(entities as usize);
        for instance in desc.instances() {
            let object = Transform {
                translation: instance.translation,
                rotation: instance.rotation,
                scale: instance.scale,
            };
            for part in &built[object_shapes[instance.object]] {
                // NOTE: a part at the object's origin takes the object's transform as it is;
                // composing and decomposing a matrix would round it.
                let transform = if part.object_from_mesh == Mat4::IDENTITY {
                    object
                } else {
                    let (scale, rotation, translation) =
                        (object.to_matrix() * part.object_from_mesh).to_scale_rotation_translation();
                    Transform {
                        translation,
                        rotation,
                        scale,
                    }
                };
                let animation = desc.objects[instance.object].animation.as_ref();
                let player = match part.skin {
                    Some(skin) => Some(
                        first_player(&self.skeletons[skin.skeleton], animation, instance.copy).map_err(|message| {
                            SpawnError::Model {
                                object: instance.object,
                                message,
                                error: None,
                            }
                        })?,
                    ),
                    None => None,
                };
                self.entities.push(EntityPlan {
                    transform,
                    mesh: part.mesh,
                    material: part.material.unwrap_or(instance.material),
                    cast: instance.cast_shadows,
                    receive: instance.receive_shadows,
                    skin: part.skin,
                    player,
                });
            }
        }
        Ok(())
    }

    /// Index of the texture `rel` in `images`, loading it on first use.
    fn texture(
        &mut self,
        loaded: &mut HashMap<AssetPath, usize>,
        desc: &SceneDesc,
        io: &AssetIo,
        rel: &Path,
    ) -> Result<usize, SpawnError> {
        let texture_error = |e: AssetError| SpawnError::Texture {
            path: rel.display().to_string(),
            message: e.to_string(),
        };
        let file = resolve(desc, io, rel).map_err(texture_error)?;
        if let Some(&i) = loaded.get(&file) {
            return Ok(i);
        }
        let reference = rel.to_string_lossy();
        let bytes = io.read(&file, &reference, None).map_err(texture_error)?;
        let what = format!("texture `{}`", echoed(&reference));
        self.images.push(io.decode_image(&bytes, &what).map_err(texture_error)?);
        loaded.insert(file, self.images.len() - 1);
        Ok(self.images.len() - 1)
    }

    /// A sphere (32 × 16 quads) with four coarser levels (24 × 12, 16 × 8, 12 × 6 and 8 × 4),
    /// for the shadow views and the camera.
    fn build_sphere(&mut self, radius: f32) -> Vec<MeshPart> {
        self.meshes.push(sphere(radius, 32, 16));
        let full = self.meshes.len() - 1;
        let mut levels = Vec::new();
        for (segments, rings) in [(24, 12), (16, 8), (12, 6), (8, 4)] {
            self.meshes.push(sphere(radius, segments, rings));
            // NOTE: a level's error is relative to an instance's bounding radius, the sphere
            // around its world box: at least √3 times the sphere's radius (times its scale).
            let relative = sphere_error(segments, rings) / 3f32.sqrt();
            levels.push((self.meshes.len() - 1, relative));
        }
        self.shadow_lods.push((full, levels));
        vec![MeshPart {
            mesh: full,
            material: None,
            object_from_mesh: Mat4::IDENTITY,
            skin: None,
        }]
    }

    /// Builds a primitive shape: one mesh with the object's material.
    fn build_primitive(&mut self, shape: &Shape) -> Vec<MeshPart> {
        let mesh = match shape {
            Shape::Plane { size } => plane(*size),
            Shape::Cuboid { size } => cuboid(*size),
            Shape::Sphere { radius } => return self.build_sphere(*radius),
            // NOTE: models are keyed and built by `add_model`; an empty part list is never drawn.
            Shape::Gltf { .. } => return Vec::new(),
        };
        self.meshes.push(mesh);
        vec![MeshPart {
            mesh: self.meshes.len() - 1,
            material: None,
            object_from_mesh: Mat4::IDENTITY,
            skin: None,
        }]
    }

    /// Bytes of the scene's decoded images, RGBA8 with their mip chains (what the texture
    /// budget, [`SceneLimits::max_texture_bytes`](crate::scene::SceneLimits::max_texture_bytes), bounds).
    pub fn texture_bytes(&self) -> u64 {
        self.texture_bytes
    }

    /// Number of decoded images.
    pub fn image_count(&self) -> usize {
        self.images.len()
    }

    /// What loading changed to fit the limits (images downscaled to the texture budget).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of mesh entities [`spawn`](Self::spawn) creates.
    pub fn entity_count(&self) -> usize {
        self.entities.len()
    }

    /// Adds the scene's assets to the world's stores and spawns the camera, the sun and one
    /// entity per mesh instance, each marked [`SceneEntity`]. Sets the ambient light.
    pub fn spawn(self, world: &mut World) -> usize {
        world.spawn((self.camera.0, self.camera.1, SceneEntity));
        spawn_lights(world, self.lights);
        world.insert_resource(self.ambient);
        let images: Vec<ImageHandle> = {
            let mut store = world.resource_mut::<Images>();
            self.images.into_iter().map(|i| store.add(i)).collect()
        };
        let materials: Vec<MaterialHandle> = {
            let mut store = world.resource_mut::<Materials>();
            self.materials
                .into_iter()
                .map(|m| {
                    store.add(Material {
                        base_color_texture: m.base_color_texture.map(|t| images[t.0 as usize]),
                        ..m
                    })
                })
                .collect()
        };
        let meshes: Vec<_> = {
            let mut store = world.resource_mut::<Meshes>();
            self.meshes.into_iter().map(|m| store.add(m)).collect()
        };
        if let Some(mut lods) = world.get_resource_mut::<ShadowLods>() {
            for (mesh, levels) in &self.shadow_lods {
                let levels = levels.iter().map(|&(m, relative_error)| ShadowLod {
                    mesh: meshes[m],
                    relative_error,
                });
                lods.set(meshes[*mesh], levels.collect());
            }
        }
        // NOTE: one batch per combination of shadow flags, so every entity is spawned straight
        // into its final archetype.
        let mut spawned = 0;
        let parts = |e: &EntityPlan| {
            (
                e.transform,
                Mesh3d(meshes[e.mesh]),
                MeshMaterial3d(materials[e.material]),
                SceneEntity,
                Static,
            )
        };
        let plans = |cast: bool, receive: bool| {
            self.entities
                .iter()
                .filter(move |e| e.cast == cast && e.receive == receive && e.skin.is_none())
        };
        spawned += spawn_all(world, plans(true, true).map(parts));
        spawned += spawn_all(world, plans(true, false).map(|e| (parts(e), NotShadowReceiver)));
        spawned += spawn_all(world, plans(false, true).map(|e| (parts(e), NotShadowCaster)));
        spawned += spawn_all(
            world,
            plans(false, false).map(|e| (parts(e), NotShadowCaster, NotShadowReceiver)),
        );
        let skinned = SkinnedPlans {
            entities: &self.entities,
            sources: self.skin_sources,
            skeletons: &self.skeletons,
        };
        spawned + skinned.spawn(world, &meshes, &materials)
    }
}

/// How far a UV sphere of `segments` × `rings` quads lies inside the true sphere at most
/// (at a quad's centre), relative to the radius.
fn sphere_error(segments: u32, rings: u32) -> f32 {
    let (around, along) = (PI / segments as f32, PI / (2 * rings) as f32);
    1.0 - around.cos() * along.cos()
}

/// Spawns every bundle of `bundles` and returns how many there were.
fn spawn_all<B: Bundle<Effect: NoBundleEffect>>(world: &mut World, bundles: impl Iterator<Item = B>) -> usize {
    world.spawn_batch(bundles).count()
}

/// Spawns a loaded scene: camera, sun (with its shadow settings), ambient light, materials,
/// meshes and one entity per mesh instance. Returns the number of mesh entities spawned.
pub fn spawn_scene(world: &mut World, desc: &SceneDesc) -> Result<usize, SpawnError> {
    Ok(PreparedScene::new(desc)?.spawn(world))
}

/// Removes every entity [`spawn_scene`] created and empties the mesh, material and image
/// stores (scene files own all assets in a world they were spawned into).
pub fn despawn_scene(world: &mut World) {
    let entities: Vec<Entity> = world
        .query_filtered::<Entity, With<SceneEntity>>()
        .iter(world)
        .collect();
    for entity in entities {
        world.despawn(entity);
    }
    world.resource_mut::<Meshes>().clear();
    if let Some(mut sources) = world.get_resource_mut::<SkinSources>() {
        sources.clear();
    }
    if let Some(mut lods) = world.get_resource_mut::<ShadowLods>() {
        lods.clear();
    }
    world.resource_mut::<Materials>().clear();
    world.resource_mut::<Images>().clear();
}
