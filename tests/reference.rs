//! The ray-traced reference against geometry whose answer is known in closed form: open
//! skies, full occluders, a straight edge's penumbra, a sphere in front of the sun; plus
//! convergence, determinism, alpha masks, far-from-origin precision and bad input.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Quat, Vec2, Vec3};
use penumbra::mesh::{MeshData, cuboid, plane, sphere};
use penumbra::reference::{
    AlphaMask, Caster, ReferencePoint, ReferenceScene, ReferenceSettings, SunDisc, Visibility, sun_visibility,
};

fn no_progress(_: usize) {}

fn opaque(mesh: &MeshData, world_from_local: Mat4) -> Caster<'_> {
    Caster {
        mesh,
        world_from_local,
        mask: None,
    }
}

fn up(position: Vec3) -> ReferencePoint {
    ReferencePoint {
        position,
        normal: Vec3::Y,
    }
}

fn settings(max_samples: u32, seed: u64) -> ReferenceSettings {
    ReferenceSettings {
        max_samples,
        min_samples: 16,
        seed,
    }
}

fn run(scene: &ReferenceScene, sun: &SunDisc, points: &[ReferencePoint], s: &ReferenceSettings) -> Vec<Visibility> {
    sun_visibility(scene, sun, points, s, &no_progress)
}

/// Fraction of a unit disc's area on the far side of a chord at signed distance `d` from
/// the centre (1 at d = −1, 0 at d = 1).
fn beyond_chord(d: f64) -> f64 {
    let d = d.clamp(-1.0, 1.0);
    (d.acos() - d * (1.0 - d * d).sqrt()) / std::f64::consts::PI
}

/// Area of the intersection of two discs of radii `r1`, `r2` whose centres are `d` apart.
fn disc_overlap(r1: f64, r2: f64, d: f64) -> f64 {
    use std::f64::consts::PI;
    if d >= r1 + r2 {
        return 0.0;
    }
    if d <= (r1 - r2).abs() {
        return PI * r1.min(r2).powi(2);
    }
    let a1 = ((d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1)).clamp(-1.0, 1.0).acos();
    let a2 = ((d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2)).clamp(-1.0, 1.0).acos();
    let k = ((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2)).max(0.0);
    r1 * r1 * a1 + r2 * r2 * a2 - 0.5 * k.sqrt()
}

/// Asserts `got` is within three standard errors plus 0.01 of `want`. The standard error is the
/// larger of the reported one and the one `want` implies for the same sample count, so an
/// estimate that wrongly reports 0 or 1 with zero error cannot pass on a tiny tolerance alone.
fn assert_close(got: Visibility, want: f64, what: &str) {
    assert!(got.samples > 0, "{what}: no samples");
    let implied = (want * (1.0 - want) / f64::from(got.samples)).sqrt();
    let sigma = implied.max(f64::from(got.std_error));
    let err = (f64::from(got.value) - want).abs();
    assert!(
        err <= 3.0 * sigma + 0.01,
        "{what}: got {got:?}, want {want:.4} (error {err:.4}, sigma {sigma:.4})"
    );
}

#[test]
fn open_sky_is_fully_visible_after_the_minimum_samples() {
    let scene = ReferenceScene::build(Vec::<Caster>::new());
    assert_eq!(scene.triangle_count(), 0);
    let points: Vec<ReferencePoint> = (0..100)
        .map(|i| ReferencePoint {
            position: Vec3::new(i as f32 * 7.0 - 300.0, (i % 13) as f32, -(i as f32) * 3.0),
            normal: Vec3::new((i % 3) as f32 - 1.0, 1.0, 0.0).normalize(),
        })
        .collect();
    let sun = SunDisc {
        direction: Vec3::new(0.3, -1.0, 0.2),
        angular_diameter: 0.05,
    };
    for v in run(&scene, &sun, &points, &ReferenceSettings::default()) {
        assert_eq!(
            v,
            Visibility {
                value: 1.0,
                std_error: 0.0,
                samples: 16
            }
        );
    }
}

#[test]
fn huge_plane_above_blocks_everything() {
    let roof = plane(Vec2::splat(10_000.0));
    let ground = plane(Vec2::splat(10_000.0));
    let scene = ReferenceScene::build([
        opaque(&roof, Mat4::from_translation(Vec3::Y * 10.0)),
        opaque(&ground, Mat4::IDENTITY),
    ]);
    assert_eq!(scene.triangle_count(), 4);
    let points: Vec<ReferencePoint> = (0..400)
        .map(|i| {
            up(Vec3::new(
                (i % 20) as f32 * 13.7 - 130.0,
                0.0,
                (i / 20) as f32 * 11.3 - 110.0,
            ))
        })
        .collect();
    for direction in [Vec3::NEG_Y, Vec3::new(1.0, -1.0, 0.5), Vec3::new(-0.2, -0.3, -0.9)] {
        let sun = SunDisc {
            direction,
            angular_diameter: 0.2,
        };
        for (i, v) in run(&scene, &sun, &points, &settings(256, 3)).into_iter().enumerate() {
            assert_eq!(
                v,
                Visibility {
                    value: 0.0,
                    std_error: 0.0,
                    samples: 16
                },
                "point {i}, sun {direction}"
            );
        }
    }
}

/// The straight-edge setup: a large horizontal plane at height `h` covering x > `edge.x` (all z),
/// a ground plane at y = 0, the sun straight down. Returns the scene and the points at the
/// given angular offsets (in units of the sun's angular radius) from the edge, on the ground.
struct EdgeSetup {
    h: f32,
    half_angle: f32,
    origin: Vec3,
}

impl EdgeSetup {
    fn meshes() -> (MeshData, MeshData) {
        (plane(Vec2::splat(400.0)), plane(Vec2::splat(1000.0)))
    }

    fn scene(&self, slab: &MeshData, ground: &MeshData) -> ReferenceScene {
        ReferenceScene::build([
            opaque(
                slab,
                Mat4::from_translation(self.origin + Vec3::new(200.0, self.h, 0.0)),
            ),
            opaque(ground, Mat4::from_translation(self.origin)),
        ])
    }

    fn sun(&self) -> SunDisc {
        SunDisc {
            direction: Vec3::new(0.0, -5.0, 0.0),
            angular_diameter: 2.0 * self.half_angle,
        }
    }

    /// A ground point where the edge is seen `d` sun radii from the sun's centre, towards
    /// +x (d > 0: the disc's centre is visible).
    fn point(&self, d: f32, z: f32) -> ReferencePoint {
        let x = -self.h * (d * self.half_angle).tan();
        up(self.origin + Vec3::new(x, 0.0, z))
    }

    /// The analytic visible fraction at `p` (flat-disc approximation of the cap).
    fn expected(&self, p: &ReferencePoint) -> f64 {
        let x = f64::from(p.position.x) - f64::from(self.origin.x);
        // The edge is seen atan(−x/h) from the zenith, towards +x; directions beyond it hit the slab.
        let edge = (-x / f64::from(self.h)).atan();
        1.0 - beyond_chord(edge / f64::from(self.half_angle))
    }
}

const EDGE_OFFSETS: [f32; 9] = [-0.9, -0.65, -0.4, -0.15, 0.0, 0.2, 0.45, 0.7, 0.9];

#[test]
fn straight_edge_penumbra_matches_the_circular_segment() {
    let (slab, ground) = EdgeSetup::meshes();
    for (h, degrees) in [(20.0, 5.0f32), (3.0, 1.0), (50.0, 0.53)] {
        let setup = EdgeSetup {
            h,
            half_angle: degrees.to_radians() * 0.5,
            origin: Vec3::ZERO,
        };
        let scene = setup.scene(&slab, &ground);
        let points: Vec<ReferencePoint> = EDGE_OFFSETS
            .iter()
            .enumerate()
            .map(|(i, &d)| setup.point(d, i as f32 * 3.0 - 10.0))
            .collect();
        let got = run(&scene, &setup.sun(), &points, &settings(1024, 11));
        for (p, v) in points.iter().zip(got) {
            let want = setup.expected(p);
            assert_close(v, want, &format!("h {h}, θ {degrees}°, x {}", p.position.x));
        }
        // Well outside the penumbra: fully lit / fully shadowed.
        let outside = [setup.point(1.5, 0.0), setup.point(-1.5, 0.0)];
        let got = run(&scene, &setup.sun(), &outside, &settings(1024, 11));
        assert_eq!((got[0].value, got[1].value), (1.0, 0.0));
    }
}

#[test]
fn sphere_in_front_of_the_sun_matches_the_disc_overlap() {
    // An oblique sun; a sphere whose centre is seen `gamma` from the sun's centre covers a
    // disc of angular radius asin(r / distance).
    let ball = sphere(0.5, 96, 48);
    let light = Vec3::new(1.0, -2.0, 0.5).normalize();
    let half_angle = 1.5f32.to_radians();
    let distance = 12.0f32;
    let radius = (0.5f32 / distance).asin();
    let side = light.any_orthonormal_vector();
    let sun = SunDisc {
        direction: light * 3.0,
        angular_diameter: 2.0 * half_angle,
    };
    for (k, gamma_deg) in [0.0f32, 1.0, 2.0, 2.5, 3.5, 5.0].into_iter().enumerate() {
        let gamma = gamma_deg.to_radians();
        let towards = Quat::from_axis_angle(side, gamma) * -light;
        let p = Vec3::new(k as f32 * 40.0, 0.0, 5.0);
        let scene = ReferenceScene::build([opaque(&ball, Mat4::from_translation(p + towards * distance))]);
        let got = run(&scene, &sun, &[up(p)], &settings(1024, 5))[0];
        let sun_area = f64::from(PI * half_angle * half_angle);
        let blocked = disc_overlap(f64::from(half_angle), f64::from(radius), f64::from(gamma)) / sun_area;
        assert_close(got, 1.0 - blocked, &format!("sphere {gamma_deg}° off the sun"));
    }
}

#[test]
fn error_falls_as_samples_grow() {
    let (slab, ground) = EdgeSetup::meshes();
    let setup = EdgeSetup {
        h: 10.0,
        half_angle: 2.0f32.to_radians(),
        origin: Vec3::ZERO,
    };
    let scene = setup.scene(&slab, &ground);
    // 50 points spread over the penumbra, at different z, with a small tilt of the sun so the
    // edge is not aligned with any sampling axis.
    let points: Vec<ReferencePoint> = (0..50)
        .map(|i| setup.point(-0.95 + 1.9 * (i as f32 + 0.5) / 50.0, i as f32 * 1.7 - 40.0))
        .collect();
    let sun = SunDisc {
        direction: Vec3::new(0.01, -1.0, 0.02),
        ..setup.sun()
    };
    let exhaustive = ReferenceSettings {
        max_samples: 16_384,
        min_samples: 16_384,
        seed: 1_000,
    };
    let truth = run(&scene, &sun, &points, &exhaustive);
    assert!(truth.iter().all(|v| v.samples == 16_384));
    let mut errors = Vec::new();
    for n in [16, 64, 256, 1024] {
        let got = run(&scene, &sun, &points, &settings(n, 7));
        let mae = got
            .iter()
            .zip(&truth)
            .map(|(g, t)| (g.value - t.value).abs())
            .sum::<f32>()
            / 50.0;
        errors.push(mae);
    }
    eprintln!("mean absolute error at 16, 64, 256, 1024 samples: {errors:?}");
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "errors do not fall: {errors:?}");
    assert!(errors[3] < errors[0] * 0.5, "{errors:?}");
}

fn mixed_points(setup: &EdgeSetup) -> Vec<ReferencePoint> {
    (0..300)
        .map(|i| setup.point(-1.6 + 3.2 * i as f32 / 300.0, (i % 17) as f32))
        .collect()
}

#[test]
fn same_seed_same_bits_on_any_thread_count() {
    let (slab, ground) = EdgeSetup::meshes();
    let setup = EdgeSetup {
        h: 10.0,
        half_angle: 1.0f32.to_radians(),
        origin: Vec3::ZERO,
    };
    let scene = setup.scene(&slab, &ground);
    let points = mixed_points(&setup);
    let s = settings(256, 42);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let single = pool.install(|| run(&scene, &setup.sun(), &points, &s));
    let many = run(&scene, &setup.sun(), &points, &s);
    let wide = rayon::ThreadPoolBuilder::new().num_threads(5).build().unwrap();
    let five = wide.install(|| run(&scene, &setup.sun(), &points, &s));
    let bits = |v: &[Visibility]| -> Vec<(u32, u32, u32)> {
        v.iter()
            .map(|v| (v.value.to_bits(), v.std_error.to_bits(), v.samples))
            .collect()
    };
    assert_eq!(bits(&single), bits(&many));
    assert_eq!(bits(&single), bits(&five));
    assert!(single.iter().any(|v| v.value > 0.0 && v.value < 1.0));

    let other = run(&scene, &setup.sun(), &points, &settings(256, 43));
    let penumbra: Vec<usize> = (0..points.len()).filter(|&i| single[i].samples == 256).collect();
    assert!(penumbra.len() > 50);
    let differ = penumbra.iter().filter(|&&i| other[i].value != single[i].value).count();
    assert!(
        differ * 2 > penumbra.len(),
        "only {differ} of {} penumbra values changed",
        penumbra.len()
    );
}

/// A 40 m square card at height 2 with the given mask, and the ground.
fn masked_scene(card: &MeshData, ground: &MeshData, mask: AlphaMask) -> ReferenceScene {
    ReferenceScene::build([
        Caster {
            mesh: card,
            world_from_local: Mat4::from_translation(Vec3::Y * 2.0),
            mask: Some(Arc::new(mask)),
        },
        opaque(ground, Mat4::IDENTITY),
    ])
}

fn uniform_mask(alpha: u8, factor: f32) -> AlphaMask {
    AlphaMask {
        width: 4,
        height: 4,
        alpha: vec![alpha; 16],
        factor,
        cutoff: 0.5,
    }
}

#[test]
fn alpha_masks_let_light_through_clear_texels() {
    let card = plane(Vec2::splat(40.0));
    let ground = plane(Vec2::splat(100.0));
    let points: Vec<ReferencePoint> = (0..20)
        .map(|i| up(Vec3::new(i as f32 - 10.0, 0.0, 7.0 - i as f32 * 0.5)))
        .collect();
    let sun = SunDisc {
        direction: Vec3::new(0.1, -1.0, 0.05),
        angular_diameter: 0.1,
    };
    let s = settings(256, 9);

    let clear = masked_scene(&card, &ground, uniform_mask(0, 1.0));
    assert!(run(&clear, &sun, &points, &s).iter().all(|v| v.value == 1.0));
    // Opaque texels, but the base colour alpha drops them below the cutoff.
    let faded = masked_scene(&card, &ground, uniform_mask(255, 0.3));
    assert!(run(&faded, &sun, &points, &s).iter().all(|v| v.value == 1.0));
    let solid = masked_scene(&card, &ground, uniform_mask(255, 1.0));
    assert!(run(&solid, &sun, &points, &s).iter().all(|v| v.value == 0.0));

    // A one-texel checker, far finer than the sun's footprint on the card: half the disc.
    let n = 512u32;
    let checker = AlphaMask {
        width: n,
        height: n,
        alpha: (0..n * n)
            .map(|i| if (i % n + i / n).is_multiple_of(2) { 255 } else { 0 })
            .collect(),
        factor: 1.0,
        cutoff: 0.5,
    };
    let checkered = masked_scene(&card, &ground, checker);
    let wide = SunDisc {
        direction: Vec3::NEG_Y,
        angular_diameter: 40.0f32.to_radians(),
    };
    let got = run(&checkered, &wide, &points, &settings(1024, 9));
    for v in &got {
        assert!((v.value - 0.5).abs() < 0.06, "{v:?}");
    }
    let mean = got.iter().map(|v| v.value).sum::<f32>() / got.len() as f32;
    assert!((mean - 0.5).abs() < 0.02, "{mean}");
}

#[test]
fn alpha_mask_orientation_follows_the_uvs() {
    // The plane's u runs along +x and v = 0 is its −z edge; mask rows go from v = 0 (top).
    let card = plane(Vec2::splat(40.0));
    let ground = plane(Vec2::splat(100.0));
    let sun = SunDisc {
        direction: Vec3::NEG_Y,
        angular_diameter: 0.02,
    };
    // Top-left texel opaque only (2×2 mask): covers x < 0, z < 0.
    let quarter = AlphaMask {
        width: 2,
        height: 2,
        alpha: vec![255, 0, 0, 0],
        factor: 1.0,
        cutoff: 0.5,
    };
    let scene = masked_scene(&card, &ground, quarter);
    let quadrants = [
        up(Vec3::new(-10.0, 0.0, -10.0)),
        up(Vec3::new(10.0, 0.0, -10.0)),
        up(Vec3::new(-10.0, 0.0, 10.0)),
        up(Vec3::new(10.0, 0.0, 10.0)),
    ];
    let got: Vec<f32> = run(&scene, &sun, &quadrants, &settings(64, 2))
        .iter()
        .map(|v| v.value)
        .collect();
    assert_eq!(got, [0.0, 1.0, 1.0, 1.0]);
}

#[test]
fn far_from_the_origin_matches_near_it() {
    let (slab, ground) = EdgeSetup::meshes();
    let near = EdgeSetup {
        h: 20.0,
        half_angle: 2.5f32.to_radians(),
        origin: Vec3::ZERO,
    };
    let far = EdgeSetup {
        origin: Vec3::new(1e5, 0.0, 1e5),
        ..near
    };
    let s = settings(1024, 17);
    let near_scene = near.scene(&slab, &ground);
    let far_scene = far.scene(&slab, &ground);
    let offsets = EDGE_OFFSETS.iter().chain(&[-1.4, 1.4]);
    let near_points: Vec<ReferencePoint> = offsets.clone().map(|&d| near.point(d, 3.0)).collect();
    let far_points: Vec<ReferencePoint> = offsets.map(|&d| far.point(d, 3.0)).collect();
    let a = run(&near_scene, &near.sun(), &near_points, &s);
    let b = run(&far_scene, &far.sun(), &far_points, &s);
    for ((p, va), vb) in far_points.iter().zip(&a).zip(&b) {
        assert!(
            (va.value - vb.value).abs() <= 0.02,
            "{va:?} vs {vb:?} at {}",
            p.position
        );
        assert_close(*vb, far.expected(p), &format!("far, x {}", p.position.x));
    }
    // Outside the penumbra: the ground the far points lie on must not shadow them.
    assert_eq!((b[b.len() - 2].value, b[b.len() - 1].value), (0.0, 1.0));
}

#[test]
fn far_sloped_ground_does_not_shadow_itself() {
    // A tilted ground far from the origin: its points, rounded to f32, lie up to half an ulp
    // (4 mm at 1e5 m) on either side of its triangles, and must still see the open sky.
    let ground = plane(Vec2::splat(200.0));
    for offset in [Vec3::ZERO, Vec3::new(1e5, 2e3, -1e5), Vec3::new(-3e5, 1e5, 2e5)] {
        let rotation = Quat::from_rotation_z(0.2) * Quat::from_rotation_x(-0.1);
        let m = Mat4::from_rotation_translation(rotation, offset);
        let scene = ReferenceScene::build([opaque(&ground, m)]);
        let normal = rotation * Vec3::Y;
        let md = m.as_dmat4();
        let points: Vec<ReferencePoint> = (0..2000)
            .map(|i| {
                let local = glam::DVec3::new((i % 50) as f64 * 3.7 - 90.0, 0.0, (i / 50) as f64 * 4.3 - 85.0);
                ReferencePoint {
                    position: md.transform_point3(local).as_vec3(),
                    normal,
                }
            })
            .collect();
        for direction in [-normal, Vec3::new(0.3, -1.0, 0.1)] {
            let sun = SunDisc {
                direction,
                angular_diameter: 0.01,
            };
            let got = run(&scene, &sun, &points, &ReferenceSettings::default());
            let shadowed = got.iter().filter(|v| v.value < 1.0).count();
            assert_eq!(
                shadowed, 0,
                "{shadowed} points shadow themselves at {offset}, sun {direction}"
            );
        }
    }
}

#[test]
fn non_finite_input_never_panics() {
    let cube = cuboid(Vec3::ONE);
    let ball = sphere(1.0, 8, 4);
    let mut broken = cuboid(Vec3::ONE);
    broken.vertices[3].position = [f32::NAN, 0.0, f32::INFINITY];
    broken.indices.push(10_000);
    let scene = ReferenceScene::build([
        opaque(&cube, Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0))),
        opaque(&ball, Mat4::from_scale(Vec3::splat(f32::INFINITY))),
        opaque(&broken, Mat4::from_translation(Vec3::Y * 3.0)),
        opaque(&cube, Mat4::from_translation(Vec3::new(5.0, 3.0, 0.0))),
    ]);
    // Only `broken`'s triangles that do not use vertex 3 (11 of 12) and the last cube's 12.
    assert_eq!(scene.triangle_count(), 23);

    let points = [
        up(Vec3::new(f32::NAN, 0.0, 0.0)),
        ReferencePoint {
            position: Vec3::ZERO,
            normal: Vec3::NAN,
        },
        up(Vec3::new(f32::INFINITY, 0.0, 0.0)),
        up(Vec3::new(5.0, 0.0, 0.0)),
        up(Vec3::new(-5.0, 0.0, 0.0)),
    ];
    let sun = SunDisc {
        direction: Vec3::NEG_Y,
        angular_diameter: 0.01,
    };
    let got = run(&scene, &sun, &points, &ReferenceSettings::default());
    for v in &got[..3] {
        assert_eq!(
            *v,
            Visibility {
                value: 1.0,
                std_error: 0.0,
                samples: 0
            }
        );
    }
    assert_eq!(got[3].value, 0.0);
    assert_eq!(got[4].value, 1.0);
    for bad_sun in [
        SunDisc {
            direction: Vec3::NAN,
            angular_diameter: 0.01,
        },
        SunDisc {
            direction: Vec3::NEG_Y,
            angular_diameter: f32::NAN,
        },
        SunDisc {
            direction: Vec3::NEG_Y,
            angular_diameter: f32::INFINITY,
        },
    ] {
        let got = run(&scene, &bad_sun, &points, &ReferenceSettings::default());
        assert_eq!(got.len(), points.len());
        assert!(got.iter().all(|v| (0.0..=1.0).contains(&v.value)));
    }
}
