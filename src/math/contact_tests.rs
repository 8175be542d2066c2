//! Contact-shadow march against scenes ray-cast on the CPU: a ground plane and boxes, seen
//! by a camera whose depth and normals are traced per pixel, marched towards a sun and
//! compared with the boxes the light's ray really meets.

use glam::{IVec2, Mat4, UVec2, Vec2, Vec3};

use super::{March, SeenDepth, interleaved_gradient_noise};
use crate::math::{Aabb, CameraView};

const SIZE: UVec2 = UVec2::new(320, 180);

/// A ground plane at y = 0 and boxes over it, traced per pixel.
struct Scene {
    boxes: Vec<Aabb>,
    camera: CameraView,
}

/// Where a ray first enters a box: distance along it and the face's normal.
fn enter_box(origin: Vec3, dir: Vec3, b: &Aabb) -> Option<(f32, Vec3)> {
    let inv = dir.recip();
    let t0 = (b.min - origin) * inv;
    let t1 = (b.max - origin) * inv;
    let near = t0.min(t1);
    let far = t0.max(t1);
    let enter = near.max_element();
    if enter > far.min_element() || far.min_element() <= 0.0 || enter <= 0.0 {
        return None;
    }
    let axis = if enter == near.x {
        Vec3::X
    } else if enter == near.y {
        Vec3::Y
    } else {
        Vec3::Z
    };
    Some((enter, -axis * dir.dot(axis).signum()))
}

/// A camera's transform at `eye`, its −Z towards `target`, +Y up.
fn world_from_view_at(eye: Vec3, target: Vec3) -> Mat4 {
    let back = (eye - target).normalize();
    let right = Vec3::Y.cross(back).normalize();
    Mat4::from_cols(
        right.extend(0.0),
        back.cross(right).extend(0.0),
        back.extend(0.0),
        eye.extend(1.0),
    )
}

impl Scene {
    fn new(eye: Vec3, target: Vec3, boxes: Vec<Aabb>) -> Scene {
        let camera = CameraView {
            world_from_view: world_from_view_at(eye, target),
            fov_y: 50f32.to_radians(),
            aspect: SIZE.x as f32 / SIZE.y as f32,
            near: 0.05,
            far: 200.0,
        };
        Scene { boxes, camera }
    }

    /// The nearest surface along a ray: distance and normal.
    fn trace(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        let ground = (dir.y < 0.0 && origin.y > 0.0).then(|| (-origin.y / dir.y, Vec3::Y));
        self.boxes
            .iter()
            .filter_map(|b| enter_box(origin, dir, b))
            .chain(ground)
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Depth and normal seen at every pixel, row-major.
    fn depth_buffer(&self) -> Vec<(f32, Vec3)> {
        let clip_from_world = self.camera.clip_from_world();
        let view = self.view(&clip_from_world, &|_| (0.0, Vec3::Y));
        let eye = self.camera.position();
        (0..SIZE.y)
            .flat_map(|y| (0..SIZE.x).map(move |x| Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
            .map(|pixel| {
                let dir = (view.world_at(pixel, 0.5) - eye).normalize();
                match self.trace(eye, dir) {
                    Some((t, normal)) => {
                        let clip = clip_from_world * (eye + dir * t).extend(1.0);
                        (clip.z / clip.w, normal)
                    }
                    None => (0.0, Vec3::Y),
                }
            })
            .collect()
    }

    fn view<'a>(&self, clip_from_world: &Mat4, seen: &'a dyn Fn(IVec2) -> (f32, Vec3)) -> SeenDepth<'a> {
        SeenDepth {
            clip_from_world: *clip_from_world,
            world_from_clip: clip_from_world.inverse(),
            camera_position: self.camera.position(),
            size: SIZE,
            seen,
        }
    }

    /// Every ground pixel's march towards `to_light` and whether a box really blocks that
    /// light within `reach`: (pixel, contact visibility, distance to the nearest box along
    /// the light's ray, infinite where it meets none).
    fn march_ground(&self, to_light: Vec3, reach: f32, thickness: f32) -> Vec<(IVec2, f32, f32)> {
        let buffer = self.depth_buffer();
        let seen = |p: IVec2| buffer[(p.y as u32 * SIZE.x + p.x as u32) as usize];
        let view = self.view(&self.camera.clip_from_world(), &seen);
        let mut out = Vec::new();
        for y in 0..SIZE.y as i32 {
            for x in 0..SIZE.x as i32 {
                let (depth, normal) = seen(IVec2::new(x, y));
                if depth <= 0.0 || normal != Vec3::Y {
                    continue;
                }
                let pixel = Vec2::new(x as f32, y as f32) + 0.5;
                let position = view.world_at(pixel, depth);
                if position.y.abs() > 1e-3 {
                    continue; // the top face of a box
                }
                let march = March {
                    reach,
                    steps: 16,
                    thickness,
                    intensity: 1.0,
                    jitter: interleaved_gradient_noise(pixel.floor()),
                };
                let v = view.contact_visibility(&march, position, normal, to_light, pixel, depth);
                let hit = self
                    .boxes
                    .iter()
                    .filter_map(|b| enter_box(position + Vec3::Y * 1e-4, to_light, b))
                    .map(|(t, _)| t)
                    .fold(f32::INFINITY, f32::min);
                out.push((IVec2::new(x, y), v, hit));
            }
        }
        out
    }
}

fn sun(elevation_degrees: f32, azimuth_degrees: f32) -> Vec3 {
    let (e, a) = (elevation_degrees.to_radians(), azimuth_degrees.to_radians());
    Vec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

fn cube(center: Vec3, half: f32) -> Aabb {
    Aabb::new(center - half, center + half)
}

#[test]
fn flat_ground_never_shadows_itself_at_grazing_angles() {
    for eye_height in [0.05, 0.3, 2.0] {
        let scene = Scene::new(Vec3::new(0.0, eye_height, 4.0), Vec3::new(0.0, 0.0, -6.0), vec![]);
        for elevation in [1.0, 3.0, 10.0, 45.0, 89.0] {
            for azimuth in [0.0, 90.0, 200.0] {
                let ground = scene.march_ground(sun(elevation, azimuth), 0.3, 0.05);
                assert!(ground.len() > 10_000, "only {} ground pixels judged", ground.len());
                let shadowed = ground.iter().filter(|g| g.1 < 1.0).count();
                assert_eq!(
                    shadowed, 0,
                    "{shadowed} ground pixels shadowed themselves (eye {eye_height} m, sun {elevation}°/{azimuth}°)"
                );
            }
        }
    }
}

#[test]
fn ground_at_a_standing_box_base_is_occluded() {
    let scene = Scene::new(
        Vec3::new(0.3, 1.9, 4.6),
        Vec3::new(0.0, 0.25, 0.2),
        vec![cube(Vec3::new(0.0, 0.3, 0.0), 0.3)],
    );
    // The sun behind the box, low: its contact shadow falls towards the camera.
    let ground = scene.march_ground(sun(30.0, -80.0), 0.3, 0.05);
    // Blocked before the march's last two steps (the last sample lies up to a step short of
    // the reach).
    let blocked: Vec<_> = ground.iter().filter(|g| g.2 <= 0.3 * (1.0 - 2.0 / 16.0)).collect();
    assert!(
        blocked.len() > 80,
        "only {} blocked ground pixels judged",
        blocked.len()
    );
    let found = blocked.iter().filter(|g| g.1 == 0.0).count() as f32 / blocked.len() as f32;
    eprintln!("the march found {found} of {} blocked ground pixels", blocked.len());
    assert!(found > 0.9, "the march found {found} of the blocked ground pixels");
}

#[test]
fn no_contact_shadow_where_the_light_is_not_blocked() {
    let boxes = vec![
        cube(Vec3::new(-1.6, 0.3, -0.4), 0.3),
        // Hovering 3 cm and 15 cm above the ground.
        cube(Vec3::new(-0.6, 0.33, -0.4), 0.3),
        cube(Vec3::new(0.4, 0.45, -0.4), 0.3),
    ];
    let scene = Scene::new(Vec3::new(0.3, 1.9, 4.6), Vec3::new(0.0, 0.25, 0.2), boxes);
    for (elevation, azimuth) in [(30.0, -80.0), (15.0, -120.0), (50.0, 200.0)] {
        let ground = scene.march_ground(sun(elevation, azimuth), 0.3, 0.05);
        let lit: Vec<_> = ground.iter().filter(|g| g.2 > 0.3).collect();
        assert!(lit.len() > 10_000, "only {} lit ground pixels judged", lit.len());
        let false_shadows = lit.iter().filter(|g| g.1 < 1.0).count();
        eprintln!(
            "sun {elevation}°/{azimuth}°: {false_shadows} of {} lit pixels shadowed",
            lit.len()
        );
        // A pixel's centre and its march's samples are a pixel apart at the box's rim.
        assert!(
            false_shadows as f32 <= 0.0003 * lit.len() as f32,
            "{false_shadows} of {} truly lit ground pixels got a contact shadow (sun {elevation}°/{azimuth}°)",
            lit.len()
        );
    }
}

#[test]
fn hovering_box_leaves_its_gap_lit() {
    // 15 cm above the ground; the sun low enough that its rays pass under the box.
    let scene = Scene::new(
        Vec3::new(0.3, 1.9, 4.6),
        Vec3::new(0.0, 0.25, 0.2),
        vec![cube(Vec3::new(0.0, 0.45, 0.0), 0.3)],
    );
    let ground = scene.march_ground(sun(20.0, -90.0), 0.3, 0.05);
    // Under the box's near edge: the truth's rays pass through the gap.
    let gap: Vec<_> = ground.iter().filter(|g| g.2 > 0.3).collect();
    let wrong = gap.iter().filter(|g| g.1 < 1.0).count();
    assert!(gap.len() > 10_000, "only {} lit pixels judged", gap.len());
    assert!(wrong <= 5, "{wrong} pixels in the lit gap were shadowed");
}

#[test]
fn geometry_off_screen_never_casts() {
    // The box stands just left of the view, its shadow falling into it.
    let scene = Scene::new(
        Vec3::new(0.0, 1.0, 3.0),
        Vec3::new(0.0, 0.0, 0.0),
        vec![cube(Vec3::new(-3.2, 0.3, 0.0), 0.3)],
    );
    let ground = scene.march_ground(sun(20.0, 180.0), 2.0, 0.5);
    assert!(
        ground.iter().any(|g| g.2 <= 2.0),
        "the off-screen box blocks no visible ground pixel"
    );
    let shadowed = ground.iter().filter(|g| g.1 < 1.0).count();
    assert_eq!(shadowed, 0, "{shadowed} pixels shadowed by geometry off screen");
}

#[test]
fn no_reach_is_lit_and_a_reach_finds_the_box() {
    let scene = Scene::new(
        Vec3::new(0.0, 1.0, 3.0),
        Vec3::ZERO,
        vec![cube(Vec3::new(0.0, 0.3, 0.0), 0.3)],
    );
    for reach in [0.0, 0.3] {
        let ground = scene.march_ground(sun(30.0, 0.0), reach, 0.05);
        let any = ground.iter().any(|g| g.1 < 1.0);
        assert_eq!(any, reach > 0.0, "reach {reach}");
    }
}

#[test]
fn noise_is_in_the_unit_interval() {
    for y in 0..64 {
        for x in 0..64 {
            let n = interleaved_gradient_noise(Vec2::new(x as f32, y as f32));
            assert!((0.0..1.0).contains(&n), "{n} at {x},{y}");
        }
    }
}
