//! The scene description types, as read from a RON scene file.
//!
//! Every type here mirrors one construct of the file format (see `docs/scene-format.md`):
//! the field names are the names written in the file, and every optional field has a serde
//! default so that simple objects fit on one line.

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

use glam::{UVec3, Vec2, Vec3, Vec4};
use serde::de::{MapAccess, Visitor};
use serde::{Deserialize, Deserializer};

use crate::asset_io::{AssetError, AssetIo, AssetPath};
use crate::scene::animation::AnimationDesc;
use crate::scene::limits::SceneLimits;
use crate::settings::ShadowSettings;

/// A whole scene: what [`SceneDesc::load`] returns.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct SceneDesc {
    /// The viewpoint.
    pub camera: CameraDesc,
    /// The sun: the first directional light, with the scene's `shadows`. Optional; more
    /// lights go in `lights`.
    #[serde(default)]
    pub sun: Option<SunDesc>,
    /// More lights: directional, spot and point, in file order. Default none.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// Constant ambient light, linear RGB. Default black.
    #[serde(default)]
    pub ambient: Vec3,
    /// Shadow parameters; every field is optional and defaults to [`ShadowSettings::default`].
    #[serde(default)]
    pub shadows: ShadowSettings,
    /// Materials in file order; [`ObjectInstance::material`](crate::scene::ObjectInstance)
    /// indexes this list. Written in the file as a map from name to material.
    #[serde(default, deserialize_with = "materials_in_file_order")]
    pub materials: Vec<MaterialDesc>,
    /// Objects and object grids in file order.
    #[serde(default)]
    pub objects: Vec<ObjectDesc>,
    /// Directory that relative paths in the scene (textures, models) are relative to: the
    /// scene file's directory after [`SceneDesc::load`], empty after
    /// [`SceneDesc::from_str`](crate::scene::SceneDesc::from_str).
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// The budgets the scene was loaded with, and where its files may be read from; spawning
    /// holds to them too.
    #[serde(skip)]
    pub limits: SceneLimits,
}

/// A perspective camera looking from `position` at `target`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(rename = "Camera", deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position, world space, metres.
    pub position: Vec3,
    /// Point looked at; must differ from `position`.
    pub target: Vec3,
    /// Up hint; need not be normalised. Default `(0, 1, 0)`.
    #[serde(default = "unit_y")]
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov: f32,
    /// Near plane distance in metres, > 0.
    pub near: f32,
    /// Far plane distance in metres, > `near`.
    pub far: f32,
}

/// The sun: a directional light with an angular size (for soft shadows).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(rename = "Sun", deny_unknown_fields)]
pub struct SunDesc {
    /// Direction the light travels (from the sun towards the ground); finite and non-zero,
    /// need not be normalised.
    pub direction: Vec3,
    /// Linear RGB colour. Default white.
    #[serde(default = "one3")]
    pub color: Vec3,
    /// Linear intensity multiplier applied to `color`. Default 1.
    #[serde(default = "one")]
    pub illuminance: f32,
    /// Angular diameter of the sun disc in degrees, 0–30. Default 0.53 (the real sun).
    #[serde(default = "sun_diameter")]
    pub angular_diameter: f32,
}

/// One entry of a scene's `lights` list. Angles are in degrees; positions and ranges in
/// metres.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// A directional light (another sun).
    Directional {
        /// Direction the light travels; finite and non-zero.
        direction: Vec3,
        /// Linear RGB colour. Default white.
        #[serde(default = "one3")]
        color: Vec3,
        /// Intensity multiplier. Default 1.
        #[serde(default = "one")]
        illuminance: f32,
        /// Angular diameter of the disc in degrees, 0–30. Default 0.53.
        #[serde(default = "sun_diameter")]
        angular_diameter: f32,
        /// Its own shadow settings; default the scene's `shadows`.
        #[serde(default)]
        shadows: Option<ShadowSettings>,
        /// Whether it casts shadows. Default true.
        #[serde(default = "yes")]
        shadows_enabled: bool,
    },
    /// A spot light: a cone from `position` along `direction`.
    Spot {
        /// Position, world space.
        position: Vec3,
        /// Direction the cone points; finite and non-zero.
        direction: Vec3,
        /// Linear RGB colour. Default white.
        #[serde(default = "one3")]
        color: Vec3,
        /// Intensity multiplier. Default 1.
        #[serde(default = "one")]
        intensity: f32,
        /// Distance past which it has no effect, > 0. Default 20.
        #[serde(default = "light_range")]
        range: f32,
        /// Half-angle of the fully lit inner cone, 0 ≤ inner ≤ outer. Default 0.
        #[serde(default)]
        inner_angle: f32,
        /// Half-angle of the outer cone, 0 < outer ≤ 89. Default 45.
        #[serde(default = "spot_outer")]
        outer_angle: f32,
        /// Radius of the emitter, ≥ 0 (soft-shadow size). Default 0.
        #[serde(default)]
        radius: f32,
        /// Its own shadow settings (filter, PCF radius, PCSS quality, biases, and
        /// `resolution`: the side of its map). Default: the default settings at the light
        /// budget's spot resolution (1024), not the scene's `shadows`.
        #[serde(default)]
        shadows: Option<ShadowSettings>,
        /// Whether it casts shadows. Default true.
        #[serde(default = "yes")]
        shadows_enabled: bool,
    },
    /// A point light at `position`.
    Point {
        /// Position, world space.
        position: Vec3,
        /// Linear RGB colour. Default white.
        #[serde(default = "one3")]
        color: Vec3,
        /// Intensity multiplier. Default 1.
        #[serde(default = "one")]
        intensity: f32,
        /// Distance past which it has no effect, > 0. Default 20.
        #[serde(default = "light_range")]
        range: f32,
        /// Radius of the emitter, ≥ 0 (soft-shadow size). Default 0.
        #[serde(default)]
        radius: f32,
        /// Its own shadow settings (filter, PCF radius, PCSS quality, biases, and
        /// `resolution`: the side of each cube face, shared by every shadowed point light —
        /// the largest asked for). Default: the default settings at the light budget's point
        /// resolution (512), not the scene's `shadows`.
        #[serde(default)]
        shadows: Option<ShadowSettings>,
        /// Whether it casts shadows. Default true.
        #[serde(default = "yes")]
        shadows_enabled: bool,
    },
}

/// A named surface description.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Material", deny_unknown_fields)]
pub struct MaterialDesc {
    /// The material's name: its key in the file's `materials` map.
    #[serde(skip)]
    pub name: String,
    /// Linear RGBA base colour, multiplied with the texture. Default opaque white.
    #[serde(default = "one4")]
    pub base_color: Vec4,
    /// Base-colour texture, relative to the scene file's directory; resolve it with
    /// [`SceneDesc::resolve_path`].
    #[serde(default)]
    pub texture: Option<PathBuf>,
    /// How alpha is treated. Default [`AlphaMode::Opaque`].
    #[serde(default)]
    pub alpha: AlphaMode,
    /// Whether back faces are drawn (lit with the flipped normal). Default: true for masked
    /// materials (foliage cards), false for opaque ones; see
    /// [`is_double_sided`](Self::is_double_sided).
    #[serde(default)]
    pub double_sided: Option<bool>,
    /// Diffuse transmission of a double-sided material, 0–1 (default 0): the share of the
    /// light on one side that the other side shows, as a leaf's underside in the sun.
    #[serde(default)]
    pub transmission: f32,
}

impl MaterialDesc {
    /// The `double_sided` value in effect, after its default.
    pub fn is_double_sided(&self) -> bool {
        self.double_sided.unwrap_or(matches!(self.alpha, AlphaMode::Mask(_)))
    }
}

/// How a material's alpha (base colour alpha × texture alpha) is used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
pub enum AlphaMode {
    /// Alpha is ignored.
    #[default]
    Opaque,
    /// Fragments with alpha below the cutoff, in (0, 1], are discarded (in the shadow pass
    /// too).
    Mask(f32),
}

/// The geometry of an object, in its local space.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Shape {
    /// A horizontal rectangle facing +Y, centred on the origin; `size` is its (x, z) extent.
    Plane {
        /// Extent along x and z, metres, both > 0.
        size: Vec2,
    },
    /// An axis-aligned box centred on the origin.
    Cuboid {
        /// Extent along x, y and z, metres, all > 0.
        size: Vec3,
    },
    /// A sphere centred on the origin.
    Sphere {
        /// Radius in metres, > 0.
        radius: f32,
    },
    /// A glTF 2.0 model (`.gltf` with its buffers and images, or `.glb`): every mesh
    /// primitive of its default scene, placed by the node hierarchy, with the model's own
    /// materials; primitives without a material use the object's.
    Gltf {
        /// Model file, relative to the scene file's directory; must exist.
        path: PathBuf,
    },
}

/// One object of the file, or a grid of copies of it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Object", deny_unknown_fields)]
pub struct ObjectDesc {
    /// The geometry.
    pub shape: Shape,
    /// Name of a material in [`SceneDesc::materials`].
    pub material: String,
    /// Position in metres (of the first copy, for a grid). Default origin.
    #[serde(default)]
    pub translation: Vec3,
    /// Rotation as Euler angles in degrees, glam's `EulerRot::XYZ` order
    /// (`q = qx * qy * qz`). Default none.
    #[serde(default)]
    pub rotation: Vec3,
    /// Per-axis scale, all > 0. Default `(1, 1, 1)`.
    #[serde(default = "one3")]
    pub scale: Vec3,
    /// Whether the object is drawn into the shadow maps. Default true.
    #[serde(default = "yes")]
    pub cast_shadows: bool,
    /// Whether the object samples the shadow maps when shaded. Default true.
    #[serde(default = "yes")]
    pub receive_shadows: bool,
    /// Repeat the object on a grid. Default: a single object.
    #[serde(default)]
    pub grid: Option<GridDesc>,
    /// How a [`Shape::Gltf`] object's skinned meshes animate. Default: the model's first
    /// clip from its start, looping.
    #[serde(default)]
    pub animation: Option<AnimationDesc>,
}

/// A regular 3D grid of copies of one object.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(rename = "Grid", deny_unknown_fields)]
pub struct GridDesc {
    /// Copies along x, y and z, each ≥ 1; at most
    /// [`SceneLimits::max_grid_instances`](crate::scene::SceneLimits::max_grid_instances) in
    /// all (one million by default).
    pub count: UVec3,
    /// Offset between neighbouring copies along each axis, metres (may be negative).
    pub spacing: Vec3,
    /// Deterministic per-copy variation. Default none.
    #[serde(default)]
    pub jitter: Option<Jitter>,
}

/// Deterministic random variation of grid copies.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jitter {
    /// Seed of the generator; the same seed gives the same scene. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// Largest offset along each axis, metres, ≥ 0: each copy moves by up to ± this.
    #[serde(default)]
    pub offset: Vec3,
    /// Largest extra rotation about world +Y, degrees, 0–180: each copy turns by up to ± this.
    #[serde(default)]
    pub yaw: f32,
    /// Range `(min, max)` of a uniform scale factor, 0 < min ≤ max. Default `(1, 1)`.
    #[serde(default = "one2")]
    pub scale: Vec2,
}

impl SceneDesc {
    /// Multiplies the speed of every glTF object's animation by `factor` (an object without
    /// an `animation` gets the default one, at `factor` times normal speed).
    pub fn scale_animation_speed(&mut self, factor: f32) {
        for object in &mut self.objects {
            if matches!(object.shape, Shape::Gltf { .. }) {
                object.animation.get_or_insert_default().speed *= factor;
            }
        }
    }

    /// Every shadow settings the scene holds: its `shadows`, then each light's own (for
    /// changing them all at once, as the command line's overrides do).
    pub fn settings_mut(&mut self) -> impl Iterator<Item = &mut ShadowSettings> {
        let own = self.lights.iter_mut().filter_map(|light| match light {
            LightDesc::Directional { shadows, .. }
            | LightDesc::Spot { shadows, .. }
            | LightDesc::Point { shadows, .. } => shadows.as_mut(),
        });
        std::iter::once(&mut self.shadows).chain(own)
    }

    /// Where the scene's files are read from, and the read limits (with its texture budget): the
    /// [`asset_root`](SceneLimits::asset_root) of its [`limits`](Self::limits), or the default
    /// root for [`base_dir`](Self::base_dir).
    pub fn asset_io(&self) -> AssetIo {
        let mut io = match &self.limits.asset_root {
            Some(root) => AssetIo::with_root(root),
            None => AssetIo::for_dir(&self.base_dir),
        };
        io.max_texture_bytes = self.limits.max_texture_bytes;
        io
    }

    /// Resolves a path written in the scene (a texture or model) against
    /// [`base_dir`](Self::base_dir), inside the scene's asset root (see
    /// [`asset_io`](Self::asset_io)): what spawning the scene would read.
    pub fn resolve_path(&self, path: &Path) -> Result<AssetPath, AssetError> {
        self.asset_io().resolve(&self.base_dir, &path.to_string_lossy())
    }

    /// Index of the (first) material called `name` in [`materials`](Self::materials). A
    /// linear search: for many lookups, build a [`material_lookup`](Self::material_lookup).
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }

    /// An index from material name to position in [`materials`](Self::materials) (the first
    /// of duplicate names, like [`material_index`](Self::material_index)), built once in
    /// linear time for constant-time lookups. It borrows the scene, so it cannot go stale.
    pub fn material_lookup(&self) -> MaterialLookup<'_> {
        let mut index = HashMap::with_capacity(self.materials.len());
        for (i, m) in self.materials.iter().enumerate() {
            index.entry(m.name.as_str()).or_insert(i);
        }
        MaterialLookup { index }
    }
}

/// Material names of a [`SceneDesc`] mapped to their index; see
/// [`SceneDesc::material_lookup`].
#[derive(Clone, Debug)]
pub struct MaterialLookup<'a> {
    index: HashMap<&'a str, usize>,
}

impl MaterialLookup<'_> {
    /// Index of the material called `name`, like [`SceneDesc::material_index`].
    pub fn get(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }
}

impl GridDesc {
    /// Total number of copies (saturating; no overflow on absurd counts).
    pub fn len(&self) -> u64 {
        let c = self.count;
        (c.x as u64).saturating_mul(c.y as u64).saturating_mul(c.z as u64)
    }

    /// Whether a count is zero, so the grid has no copies.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

fn unit_y() -> Vec3 {
    Vec3::Y
}

fn one() -> f32 {
    1.0
}

fn one2() -> Vec2 {
    Vec2::ONE
}

fn one3() -> Vec3 {
    Vec3::ONE
}

fn one4() -> Vec4 {
    Vec4::ONE
}

fn light_range() -> f32 {
    20.0
}

fn spot_outer() -> f32 {
    45.0
}

fn sun_diameter() -> f32 {
    0.53
}

fn yes() -> bool {
    true
}

/// Reads the `materials` map into a list, keeping file order and duplicate keys (duplicates
/// are reported by validation, with their position).
fn materials_in_file_order<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<MaterialDesc>, D::Error> {
    struct InOrder;

    impl<'de> Visitor<'de> for InOrder {
        type Value = Vec<MaterialDesc>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a map from material name to material")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut list = Vec::new();
            while let Some((name, mut material)) = map.next_entry::<String, MaterialDesc>()? {
                material.name = name;
                list.push(material);
            }
            Ok(list)
        }
    }

    d.deserialize_map(InOrder)
}

#[cfg(test)]
mod tests {
    use crate::scene::SceneDesc;
    use crate::settings::ShadowMode;

    #[test]
    fn settings_mut_reaches_the_scene_settings_and_every_lights_own() {
        let mut desc = SceneDesc::from_str(
            r#"Scene(
                camera: (position: (0, 5, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
                lights: [
                    Spot(position: (0, 5, 0), direction: (0, -1, 0), shadows: (mode: Pcss)),
                    Point(position: (2, 3, 0), shadows: (resolution: 256)),
                    Point(position: (-2, 3, 0)),
                ],
            )"#,
            "test.ron",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        desc.settings_mut().for_each(|s| s.filter.mode = ShadowMode::Vsm);
        let modes: Vec<ShadowMode> = desc.settings_mut().map(|s| s.filter.mode).collect();
        // The scene's settings and the two lights that have their own; the third light
        // takes the scene's.
        assert_eq!(modes, [ShadowMode::Vsm; 3]);
    }
}
