//! Checks on a parsed scene: every out-of-range value or dangling reference is collected
//! (not just the first), then located in the text and sorted into file order.

use std::path::Path;

use glam::{UVec3, Vec3};

use crate::asset_io::AssetIo;
use crate::ecs::view_list::{POINT_NEAR, SPOT_NEAR};
use crate::scene::desc::{
    AlphaMode, CameraDesc, GridDesc, LightDesc, MaterialDesc, MaterialLookup, ObjectDesc, SceneDesc, Shape, SunDesc,
};
use crate::scene::error::Problem;
use crate::scene::limits::SceneLimits;
use crate::scene::locate::{Node, Seg};
use crate::scene::suggest::{Suggester, quoted};
use crate::scene::values::{MIN_DIRECTION_LENGTH, Shown, is_colour, is_direction, is_rgba, is_size2, is_size3};
use crate::settings::ShadowSettings;

/// The widest spot-light cone accepted (half-angle, degrees): a perspective shadow view
/// cannot cover a hemisphere.
const MAX_SPOT_OUTER: f32 = 89.0;

/// The largest sun angular diameter accepted, degrees.
const MAX_SUN_DIAMETER: f32 = 30.0;

/// Every problem in `scene`, positioned in `text`, in file order. Texture and model files are
/// checked (they must exist inside the asset root of `limits`) only when `base_dir` is given
/// (the scene was loaded from a file). Linear in the size of the scene.
pub(crate) fn validate(scene: &SceneDesc, text: &str, base_dir: Option<&Path>, limits: &SceneLimits) -> Vec<Problem> {
    let lookup = scene.material_lookup();
    let assets = match (&limits.asset_root, base_dir) {
        (Some(root), _) => AssetIo::with_root(root),
        (None, Some(dir)) => AssetIo::for_dir(dir),
        (None, None) => AssetIo::for_dir(Path::new("")),
    };
    let mut c = Checks {
        found: Vec::new(),
        lookup: &lookup,
        suggest: Suggester::new(scene.materials.iter().map(|m| m.name.as_str())),
        limits,
        assets,
    };
    let root = FieldPath::default();
    check_camera(&mut c, &scene.camera, &root.field("camera"));
    if let Some(sun) = &scene.sun {
        check_sun(&mut c, sun, &root.field("sun"));
    }
    for (i, light) in scene.lights.iter().enumerate() {
        check_light(&mut c, light, &root.field("lights").item(i));
    }
    if !is_colour(scene.ambient) {
        let expected = "linear RGB with finite components ≥ 0";
        c.add(root.field("ambient"), expected, scene.ambient.shown());
    }
    for p in scene.shadows.problems() {
        c.add(root.field("shadows").fields(p.field), p.expected, p.found);
    }
    let materials = root.field("materials");
    for (i, m) in scene.materials.iter().enumerate() {
        check_material(&mut c, i, m, &materials, base_dir);
    }
    for (i, o) in scene.objects.iter().enumerate() {
        check_object(&mut c, o, &root.field("objects").item(i), base_dir);
    }
    check_instance_budget(&mut c, scene);
    if c.found.is_empty() {
        return Vec::new();
    }
    let tree = Node::parse(text);
    let mut problems: Vec<Problem> = (c.found.into_iter())
        .map(|(at, expected, found, suggestion)| {
            let pos = tree.find(&at.segs);
            let (line, column, field) = (pos.line, pos.column, at.text);
            Problem {
                line,
                column,
                field,
                expected,
                found,
                suggestion,
            }
        })
        .collect();
    problems.sort_by_key(|p| (p.line, p.column));
    problems
}

/// A field path, both as steps for the locator and as text for messages.
#[derive(Clone, Debug, Default)]
struct FieldPath {
    segs: Vec<Seg>,
    text: String,
}

impl FieldPath {
    fn then(&self, seg: Seg, text: &str) -> FieldPath {
        let mut next = self.clone();
        next.segs.push(seg);
        next.text.push_str(text);
        next
    }

    fn field(&self, name: &'static str) -> FieldPath {
        let dot = if self.text.is_empty() { "" } else { "." };
        self.then(Seg::Field(name), &format!("{dot}{name}"))
    }

    /// The path of a dotted `path` of fields below this one (`layout.levels`).
    fn fields(&self, path: &'static str) -> FieldPath {
        path.split('.').fold(self.clone(), |at, name| at.field(name))
    }

    fn item(&self, i: usize) -> FieldPath {
        self.then(Seg::Item(i), &format!("[{i}]"))
    }
}

/// The problems found so far (where, what was expected, what was found, what was likely
/// meant), and what the checks consult.
struct Checks<'s> {
    found: Vec<(FieldPath, String, String, Option<String>)>,
    lookup: &'s MaterialLookup<'s>,
    suggest: Suggester<'s>,
    limits: &'s SceneLimits,
    /// Where texture and model paths must resolve.
    assets: AssetIo,
}

impl Checks<'_> {
    fn add(&mut self, at: FieldPath, expected: impl Into<String>, found: String) {
        self.found.push((at, expected.into(), found, None));
    }
}

fn check_camera(c: &mut Checks, cam: &CameraDesc, at: &FieldPath) {
    let (pos, target, up) = (cam.position, cam.target, cam.up);
    if !pos.is_finite() {
        c.add(at.field("position"), "a finite point", pos.shown());
    }
    let apart = (target - pos).length_squared() > 1e-12;
    if !target.is_finite() {
        c.add(at.field("target"), "a finite point", target.shown());
    } else if pos.is_finite() && !apart {
        let expected = "a point different from `camera.position`";
        c.add(at.field("target"), expected, target.shown());
    }
    if !is_direction(up) {
        add_direction(c, at.field("up"), "a finite, non-zero vector", up);
    } else if pos.is_finite() && target.is_finite() && apart {
        let forward = (target - pos).normalize();
        if forward.cross(up.normalize()).length() < 1e-4 {
            let expected = "an up vector not parallel to the view direction";
            c.add(at.field("up"), expected, up.shown());
        }
    }
    if !(cam.fov > 0.0 && cam.fov < 180.0) {
        let expected = "vertical degrees between 0 and 180 (exclusive)";
        c.add(at.field("fov"), expected, cam.fov.shown());
    }
    let near_ok = cam.near.is_finite() && cam.near > 0.0;
    if !near_ok {
        c.add(at.field("near"), "a distance greater than 0", cam.near.shown());
    }
    if !(cam.far.is_finite() && cam.far > 0.0 && (cam.far > cam.near || !near_ok)) {
        let expected = match near_ok {
            true => format!("a distance greater than `near` ({})", cam.near),
            false => "a distance greater than `near`".to_owned(),
        };
        c.add(at.field("far"), expected, cam.far.shown());
    }
}

fn check_sun(c: &mut Checks, sun: &SunDesc, at: &FieldPath) {
    if !is_direction(sun.direction) {
        let expected = "a finite, non-zero direction (the way the light travels)";
        add_direction(c, at.field("direction"), expected, sun.direction);
    }
    if !is_colour(sun.color) {
        let expected = "linear RGB with finite components ≥ 0";
        c.add(at.field("color"), expected, sun.color.shown());
    }
    if !(sun.illuminance.is_finite() && sun.illuminance >= 0.0) {
        let expected = "a finite multiplier ≥ 0";
        c.add(at.field("illuminance"), expected, sun.illuminance.shown());
    }
    if !(0.0..=MAX_SUN_DIAMETER).contains(&sun.angular_diameter) {
        let expected = "degrees from 0 to 30";
        c.add(at.field("angular_diameter"), expected, sun.angular_diameter.shown());
    }
}

/// The checks of one entry of `lights`.
fn check_light(c: &mut Checks, light: &LightDesc, at: &FieldPath) {
    let (color, intensity, name) = match light {
        LightDesc::Directional {
            direction,
            color,
            illuminance,
            angular_diameter,
            shadows,
            ..
        } => {
            check_sun(
                c,
                &SunDesc {
                    direction: *direction,
                    color: *color,
                    illuminance: *illuminance,
                    angular_diameter: *angular_diameter,
                },
                at,
            );
            for p in shadows.iter().flat_map(ShadowSettings::problems) {
                c.add(at.field("shadows").fields(p.field), p.expected, p.found);
            }
            return;
        }
        LightDesc::Spot {
            position,
            direction,
            color,
            intensity,
            range,
            inner_angle,
            outer_angle,
            radius,
            shadows,
            shadows_enabled,
        } => {
            check_positional(c, (*position, *range, *radius), *shadows_enabled, SPOT_NEAR, at);
            for p in shadows.iter().flat_map(ShadowSettings::problems) {
                c.add(at.field("shadows").fields(p.field), p.expected, p.found);
            }
            if !is_direction(*direction) {
                add_direction(c, at.field("direction"), "a finite, non-zero direction", *direction);
            }
            // NOTE: a positive angle too small for a 32-bit float in radians is 0 to the light.
            if !(outer_angle.to_radians() > 0.0 && *outer_angle <= MAX_SPOT_OUTER) {
                let expected = "a half-angle in degrees greater than 0 and at most 89";
                let found = match *outer_angle > 0.0 && outer_angle.to_radians() == 0.0 {
                    true => format!("{outer_angle:e}, which is 0 in radians"),
                    false => outer_angle.shown(),
                };
                c.add(at.field("outer_angle"), expected, found);
            } else if !(*inner_angle >= 0.0 && inner_angle <= outer_angle) {
                let expected = format!("a half-angle in degrees from 0 to `outer_angle` ({outer_angle})");
                c.add(at.field("inner_angle"), expected, inner_angle.shown());
            }
            (color, intensity, "intensity")
        }
        LightDesc::Point {
            position,
            color,
            intensity,
            range,
            radius,
            shadows,
            shadows_enabled,
        } => {
            check_positional(c, (*position, *range, *radius), *shadows_enabled, POINT_NEAR, at);
            for p in shadows.iter().flat_map(ShadowSettings::problems) {
                c.add(at.field("shadows").fields(p.field), p.expected, p.found);
            }
            (color, intensity, "intensity")
        }
    };
    if !is_colour(*color) {
        c.add(
            at.field("color"),
            "linear RGB with finite components ≥ 0",
            color.shown(),
        );
    }
    if !(intensity.is_finite() && *intensity >= 0.0) {
        c.add(at.field(name), "a finite multiplier ≥ 0", intensity.shown());
    }
}

/// The checks shared by spot and point lights: where they are and how far they reach. A light
/// that casts shadows must reach past its shadow views' `near` plane, or it could make none.
fn check_positional(
    c: &mut Checks,
    (position, range, radius): (Vec3, f32, f32),
    shadows_enabled: bool,
    near: f32,
    at: &FieldPath,
) {
    if !position.is_finite() {
        c.add(at.field("position"), "a finite position", position.shown());
    }
    if !(range.is_finite() && range > 0.0) {
        c.add(at.field("range"), "a distance greater than 0 (metres)", range.shown());
    } else if shadows_enabled && range <= near {
        let expected = format!(
            "a distance greater than {near} m (its shadow views' near plane) for a light that casts shadows, or `shadows_enabled: false`"
        );
        c.add(at.field("range"), expected, range.shown());
    }
    if !(radius.is_finite() && radius >= 0.0) {
        c.add(at.field("radius"), "an emitter radius ≥ 0 (metres)", radius.shown());
    }
}

fn check_material(c: &mut Checks, i: usize, m: &MaterialDesc, materials: &FieldPath, base_dir: Option<&Path>) {
    let name = quoted(&m.name);
    let at = materials.then(Seg::Entry(i), &format!("[{name}]"));
    if c.lookup.get(&m.name) != Some(i) {
        let key = materials.then(Seg::Key(i), &format!("[{name}]"));
        c.add(key, "a material name not used before", format!("{name} again"));
    }
    if !is_rgba(m.base_color) {
        let expected = "linear RGBA with finite components ≥ 0 and alpha from 0 to 1";
        c.add(at.field("base_color"), expected, m.base_color.shown());
    }
    if let Some(texture) = &m.texture {
        let shown = format!("{:?}", texture.display().to_string());
        if texture.as_os_str().is_empty() {
            c.add(at.field("texture"), "a non-empty path", shown);
        } else if let Some(Err(e)) = base_dir.map(|dir| c.assets.resolve(dir, &texture.to_string_lossy())) {
            let expected = "an image file inside the asset folder (the path is relative to the scene file)";
            c.add(at.field("texture"), expected, format!("{shown} ({e})"));
        }
    }
    if !(0.0..=1.0).contains(&m.transmission) {
        let expected = "a diffuse transmission from 0 to 1";
        c.add(at.field("transmission"), expected, m.transmission.shown());
    }
    if let AlphaMode::Mask(cutoff) = m.alpha
        && !(cutoff > 0.0 && cutoff <= 1.0)
    {
        let expected = "an alpha cutoff greater than 0 and at most 1";
        // Points at the number inside `Mask(...)`.
        let cutoff_at = at.field("alpha").then(Seg::Item(0), "");
        c.add(cutoff_at, expected, cutoff.shown());
    }
}

fn check_object<'s>(c: &mut Checks<'s>, o: &'s ObjectDesc, at: &FieldPath, base_dir: Option<&Path>) {
    let shape = at.field("shape");
    let sizes = "sizes greater than 0 (metres)";
    match &o.shape {
        Shape::Plane { size } if !is_size2(*size) => c.add(shape.field("size"), sizes, size.shown()),
        Shape::Cuboid { size } if !is_size3(*size) => {
            c.add(shape.field("size"), sizes, size.shown());
        }
        Shape::Sphere { radius } if !(radius.is_finite() && *radius > 0.0) => {
            let expected = "a radius greater than 0 (metres)";
            c.add(shape.field("radius"), expected, radius.shown());
        }
        Shape::Gltf { path } if path.as_os_str().is_empty() => {
            c.add(shape.field("path"), "a non-empty path", "\"\"".to_owned());
        }
        Shape::Gltf { path } => {
            if let Some(Err(e)) = base_dir.map(|dir| c.assets.resolve(dir, &path.to_string_lossy())) {
                let expected = "a .gltf or .glb file inside the asset folder (the path is relative to the scene file)";
                let shown = format!("{:?}", path.display().to_string());
                c.add(shape.field("path"), expected, format!("{shown} ({e})"));
            }
        }
        _ => {}
    }
    if c.lookup.get(&o.material).is_none() {
        let (expected, suggestion) = c.suggest.expected(&o.material);
        let found = quoted(&o.material);
        c.found.push((at.field("material"), expected, found, suggestion));
    }
    if !o.translation.is_finite() {
        c.add(at.field("translation"), "a finite position", o.translation.shown());
    }
    if !o.rotation.is_finite() {
        let expected = "finite Euler angles in degrees";
        c.add(at.field("rotation"), expected, o.rotation.shown());
    }
    if !is_size3(o.scale) {
        c.add(at.field("scale"), "scale factors greater than 0", o.scale.shown());
    }
    if let Some(grid) = &o.grid {
        let per_grid = c.limits.max_grid_instances();
        check_grid(c, grid, &at.field("grid"), per_grid);
    }
    if let Some(animation) = &o.animation {
        let at = at.field("animation");
        if !matches!(o.shape, Shape::Gltf { .. }) {
            let expected = "no animation: only a `Gltf` shape's skinned meshes animate";
            c.add(at.clone(), expected, "an animation".to_owned());
        }
        for (field, expected, found) in animation.problems() {
            c.add(at.field(field), expected, found.shown());
        }
    }
}

fn check_grid(c: &mut Checks, grid: &GridDesc, at: &FieldPath, per_grid: u64) {
    let n = grid.count;
    if n.min_element() == 0 {
        let expected = "counts of at least 1 along each axis";
        c.add(at.field("count"), expected, n.shown());
    } else if grid.len() > per_grid {
        let expected = format!("at most {per_grid} copies in one grid");
        let found = format!("{} = {} copies", n.shown(), grid.len());
        c.add(at.field("count"), expected, found);
    }
    // The farthest copy must be at a finite position too.
    let farthest = grid.spacing * (n.max(UVec3::ONE) - UVec3::ONE).as_vec3();
    if !(grid.spacing.is_finite() && farthest.is_finite()) {
        let expected = "finite offsets in metres";
        c.add(at.field("spacing"), expected, grid.spacing.shown());
    }
    if let Some(j) = &grid.jitter {
        let at = at.field("jitter");
        if !(j.offset.is_finite() && j.offset.min_element() >= 0.0) {
            let expected = "finite offsets ≥ 0 (metres)";
            c.add(at.field("offset"), expected, j.offset.shown());
        }
        if !(0.0..=180.0).contains(&j.yaw) {
            c.add(at.field("yaw"), "degrees from 0 to 180", j.yaw.shown());
        }
        if !(j.scale.is_finite() && j.scale.x > 0.0 && j.scale.x <= j.scale.y) {
            let expected = "a range (min, max) with 0 < min ≤ max";
            c.add(at.field("scale"), expected, j.scale.shown());
        }
    }
}

/// The instances of the whole scene within [`SceneLimits::max_instances`]; reported at the
/// object or grid where the running total passes it. Grids already reported as too big on
/// their own are left out of the total.
fn check_instance_budget(c: &mut Checks, scene: &SceneDesc) {
    let (max, per_grid) = (c.limits.max_instances, c.limits.max_grid_instances());
    let mut total = 0u64;
    let mut passed_at = None;
    for (i, o) in scene.objects.iter().enumerate() {
        let copies = o.grid.as_ref().map_or(1, GridDesc::len);
        if copies > per_grid {
            continue;
        }
        total = total.saturating_add(copies);
        if total > max && passed_at.is_none() {
            passed_at = Some(i);
        }
    }
    let Some(i) = passed_at else { return };
    let expected = format!("at most {max} instances in all objects and grids");
    let at = FieldPath::default().field("objects").item(i);
    match &scene.objects[i].grid {
        Some(grid) => {
            let found = format!(
                "{total} instances in all, the limit passed at this grid of {} = {} copies",
                grid.count.shown(),
                grid.len()
            );
            c.add(at.field("grid").field("count"), expected, found);
        }
        None => c.add(
            at,
            expected,
            format!("{total} instances in all, the limit passed at this object"),
        ),
    }
}

/// Reports the direction `v` (not [`is_direction`]): as `expected` asks, or, for a finite one
/// that is not zero, as too short to normalise, with its length.
fn add_direction(c: &mut Checks, at: FieldPath, expected: &str, v: Vec3) {
    if v.is_finite() && v != Vec3::ZERO && v.as_dvec3().length() < MIN_DIRECTION_LENGTH {
        let expected = format!("a direction long enough to normalise (length at least {MIN_DIRECTION_LENGTH:e})");
        let e = |x: f32| if x == 0.0 { "0".to_owned() } else { format!("{x:e}") };
        let length = v.as_dvec3().length() as f32;
        let found = format!("({}, {}, {}), length {length:e}", e(v.x), e(v.y), e(v.z));
        c.add(at, &expected, found);
        return;
    }
    c.add(at, expected, v.shown());
}
