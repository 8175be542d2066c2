//! Expanding objects and grids into a flat list of placed instances, with a tiny
//! deterministic generator for grid jitter.

use glam::{EulerRot, Mat4, Quat, Vec3};

use crate::scene::desc::{GridDesc, Jitter, ObjectDesc, SceneDesc, Shape};

/// One placed copy of an object: everything needed to spawn it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectInstance<'a> {
    /// Index of the object in [`SceneDesc::objects`] it was made from.
    pub object: usize,
    /// Which copy of the object's grid it is (0 for an object without a grid), in the grid's
    /// order.
    pub copy: u64,
    /// The geometry, in local space.
    pub shape: &'a Shape,
    /// World position.
    pub translation: Vec3,
    /// World rotation.
    pub rotation: Quat,
    /// Per-axis scale.
    pub scale: Vec3,
    /// Index into [`SceneDesc::materials`].
    pub material: usize,
    /// Whether it is drawn into the shadow maps.
    pub cast_shadows: bool,
    /// Whether it samples the shadow maps.
    pub receive_shadows: bool,
}

impl ObjectInstance<'_> {
    /// The local-to-world matrix: scale, then rotation, then translation.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

impl SceneDesc {
    /// Every object instance, grids expanded, in file order (grid copies x fastest, then y,
    /// then z). Lazy: a 100k-copy grid costs nothing until iterated. Objects whose material is
    /// not defined are skipped; [`SceneDesc::load`] never returns such a scene.
    pub fn instances(&self) -> impl Iterator<Item = ObjectInstance<'_>> + '_ {
        let lookup = self.material_lookup();
        self.objects.iter().enumerate().flat_map(move |(index, object)| {
            let material = lookup.get(&object.material);
            let copies = match (material, &object.grid) {
                (None, _) => 0,
                (Some(_), None) => 1,
                (Some(_), Some(grid)) => grid.len(),
            };
            (0..copies).map(move |n| place(index, object, material.unwrap_or(0), n))
        })
    }

    /// How many instances [`instances`](Self::instances) yields (saturating).
    pub fn instance_count(&self) -> u64 {
        let lookup = self.material_lookup();
        self.objects
            .iter()
            .filter(|o| lookup.get(&o.material).is_some())
            .map(|o| o.grid.as_ref().map_or(1, GridDesc::len))
            .fold(0u64, u64::saturating_add)
    }
}

/// The `n`-th copy of `object` (the object itself when it has no grid).
fn place(index: usize, object: &ObjectDesc, material: usize, n: u64) -> ObjectInstance<'_> {
    let r = object.rotation;
    let mut rotation = Quat::from_euler(EulerRot::XYZ, r.x.to_radians(), r.y.to_radians(), r.z.to_radians());
    let mut translation = object.translation;
    let mut scale = object.scale;
    if let Some(grid) = &object.grid {
        let c = grid.count.max(glam::UVec3::ONE);
        let (nx, ny) = (c.x as u64, c.y as u64);
        let cell = Vec3::new((n % nx) as f32, ((n / nx) % ny) as f32, (n / (nx * ny)) as f32);
        translation += cell * grid.spacing;
        if let Some(jitter) = &grid.jitter {
            let (offset, yaw, factor) = jitter_for(jitter, n);
            translation += offset;
            rotation = Quat::from_rotation_y(yaw.to_radians()) * rotation;
            scale *= factor;
        }
    }
    ObjectInstance {
        object: index,
        copy: n,
        shape: &object.shape,
        translation,
        rotation,
        scale,
        material,
        cast_shadows: object.cast_shadows,
        receive_shadows: object.receive_shadows,
    }
}

/// The offset, yaw (degrees) and scale factor of copy `n`; depends only on the seed and `n`.
fn jitter_for(jitter: &Jitter, n: u64) -> (Vec3, f32, f32) {
    let mut rng = SplitMix64::new(jitter.seed ^ mix(n));
    let offset = Vec3::new(rng.signed(), rng.signed(), rng.signed()) * jitter.offset;
    let yaw = rng.signed() * jitter.yaw;
    let (lo, hi) = (jitter.scale.x, jitter.scale.y);
    let factor = lo + (hi - lo) * rng.unit();
    (offset, yaw, factor)
}

/// SplitMix64 (Steele, Lea and Flood 2014): tiny, fast, and good enough for placement.
struct SplitMix64(u64);

impl SplitMix64 {
    fn new(seed: u64) -> Self {
        SplitMix64(mix(seed))
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.0)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [-1, 1).
    fn signed(&mut self) -> f32 {
        self.unit() * 2.0 - 1.0
    }
}

/// SplitMix64's output function: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"Scene(
        camera: Camera(position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
        sun: Sun(direction: (0, -1, 0)),
        materials: { "a": (), "b": Material(base_color: (1, 0, 0, 1)) },
        objects: [
            Object(shape: Sphere(radius: 1), material: "b", cast_shadows: false),
            (
                shape: Cuboid(size: (1, 1, 1)),
                material: "a",
                translation: (10, 0, 0),
                rotation: (0, 90, 0),
                scale: (2, 2, 2),
                receive_shadows: false,
                grid: Some(Grid(count: (2, 3, 1), spacing: (1, 2, -3))),
            ),
            (shape: Plane(size: (1, 1)), material: "a", grid: (count: (4, 1, 4), spacing: (1, 0, 1),
                jitter: (seed: 9, offset: (0.25, 0, 0.25), yaw: 45, scale: (0.5, 1.5)))),
        ],
    )"#;

    #[test]
    fn grids_expand_in_order_with_their_transforms() {
        let scene = SceneDesc::from_str(SCENE, "grid.ron").unwrap();
        let all: Vec<ObjectInstance<'_>> = scene.instances().collect();
        assert_eq!(all.len(), 1 + 6 + 16);
        assert_eq!(scene.instance_count(), 23);

        let sphere = &all[0];
        assert_eq!((sphere.object, sphere.material), (0, 1));
        assert!(!sphere.cast_shadows && sphere.receive_shadows);
        assert_eq!(sphere.matrix(), Mat4::IDENTITY);

        let cells: Vec<Vec3> = all[1..7].iter().map(|i| i.translation).collect();
        let expected =
            [(10, 0), (11, 0), (10, 2), (11, 2), (10, 4), (11, 4)].map(|(x, y)| Vec3::new(x as f32, y as f32, 0.0));
        assert_eq!(cells, expected);
        let boxed = &all[1];
        assert_eq!((boxed.object, boxed.material), (1, 0));
        assert!(boxed.cast_shadows && !boxed.receive_shadows);
        assert_eq!(boxed.scale, Vec3::splat(2.0));
        // 90° about Y turns +X into -Z.
        assert!((boxed.rotation * Vec3::X).abs_diff_eq(-Vec3::Z, 1e-6));
        // The documented Euler convention: q = Rx * Ry * Rz.
        let object = ObjectDesc {
            rotation: Vec3::new(30.0, 40.0, 50.0),
            grid: None,
            ..scene.objects[1].clone()
        };
        let [x, y, z] = [30f32, 40.0, 50.0].map(f32::to_radians);
        let expected = Quat::from_rotation_x(x) * Quat::from_rotation_y(y) * Quat::from_rotation_z(z);
        assert!(place(1, &object, 0, 0).rotation.abs_diff_eq(expected, 1e-6));

        let jittered: Vec<ObjectInstance<'_>> = all[7..].to_vec();
        for (n, i) in jittered.iter().enumerate() {
            let cell = Vec3::new((n % 4) as f32, 0.0, (n / 4) as f32);
            let offset = i.translation - cell;
            assert!(offset.x.abs() <= 0.25 && offset.y == 0.0 && offset.z.abs() <= 0.25);
            assert!((0.5..=1.5).contains(&i.scale.x) && i.scale.x == i.scale.z);
            let yaw = (i.rotation * Vec3::X).z.atan2((i.rotation * Vec3::X).x).to_degrees();
            assert!(yaw.abs() <= 45.001, "{yaw}");
        }
        // Deterministic: loading again gives the very same instances.
        let again = SceneDesc::from_str(SCENE, "grid.ron").unwrap();
        assert!(again.instances().eq(scene.instances()));
    }

    #[test]
    fn objects_with_an_undefined_material_are_skipped() {
        let mut scene = SceneDesc::from_str(SCENE, "grid.ron").unwrap();
        scene.objects[1].material = "missing".to_owned();
        assert_eq!(scene.instances().count(), 17);
        assert_eq!(scene.instance_count(), 17);
    }

    #[test]
    fn generator_is_deterministic_and_in_range() {
        let mut a = SplitMix64::new(7);
        let mut b = SplitMix64::new(7);
        for _ in 0..1000 {
            let (x, y) = (a.unit(), b.unit());
            assert_eq!(x, y);
            assert!((0.0..1.0).contains(&x));
        }
        // Known first output of SplitMix64 seeded with 0 (after our extra mix of the seed).
        assert_ne!(SplitMix64::new(0).next_u64(), SplitMix64::new(1).next_u64());
    }

    #[test]
    fn jitter_stays_within_bounds() {
        let j = Jitter {
            seed: 3,
            offset: Vec3::new(0.5, 0.0, 0.25),
            yaw: 30.0,
            scale: glam::Vec2::new(0.5, 2.0),
        };
        for n in 0..10_000 {
            let (o, yaw, s) = jitter_for(&j, n);
            assert!(o.x.abs() <= 0.5 && o.y == 0.0 && o.z.abs() <= 0.25, "{o}");
            assert!(yaw.abs() <= 30.0);
            assert!((0.5..=2.0).contains(&s));
        }
        assert_eq!(jitter_for(&j, 42), jitter_for(&j, 42));
        assert_ne!(jitter_for(&j, 42), jitter_for(&j, 43));
    }
}
