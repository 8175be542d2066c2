//! Which surface points lie near a caster: the contact band, where a shadow map's texels and
//! bias lose the shadow at a caster's foot and contact shadows are meant to restore it.

use glam::Vec3;
use rayon::iter::{IntoParallelRefIterator, ParallelIterator};

use super::{ReferencePoint, ReferenceScene, offset_distance};

/// Directions probed around a point's normal: a Fibonacci spiral over the hemisphere.
const PROBE_DIRECTIONS: usize = 64;

/// The probe directions around +Z: elevations spread evenly in sine from 0.5° (grazing: a
/// caster standing on the point's own plane) to the zenith.
fn probe_directions() -> Vec<Vec3> {
    let golden_angle = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let lowest = 0.5f32.to_radians().sin();
    (0..PROBE_DIRECTIONS)
        .map(|i| {
            let z = lowest + (1.0 - lowest) * i as f32 / (PROBE_DIRECTIONS - 1) as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden_angle * i as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// For each point, whether an opaque caster lies within `radius` metres of it on the side its
/// normal faces: one of 64 rays spread over that hemisphere (down to 0.5° above the point's
/// plane) hits a caster before `radius`. A point whose position or normal is not finite is
/// not near anything. Rays start lifted off the surface as [`sun_visibility`](super::sun_visibility)'s do.
pub fn near_casters(scene: &ReferenceScene, points: &[ReferencePoint], radius: f32) -> Vec<bool> {
    let directions = probe_directions();
    points
        .par_iter()
        .map(|p| {
            let normal = p.normal.normalize_or_zero();
            if !p.position.is_finite() || normal == Vec3::ZERO || radius.is_nan() || radius <= 0.0 {
                return false;
            }
            let (tangent, bitangent) = normal.any_orthonormal_pair();
            let origin = p.position + normal * offset_distance(p.position);
            directions.iter().any(|d| {
                let dir = tangent * d.x + bitangent * d.y + normal * d.z;
                scene.occluded_within(origin, dir, radius)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::cuboid;
    use crate::reference::Caster;
    use glam::Mat4;

    fn point(x: f32, z: f32) -> ReferencePoint {
        ReferencePoint {
            position: Vec3::new(x, 0.0, z),
            normal: Vec3::Y,
        }
    }

    #[test]
    fn ground_points_near_a_standing_box_are_in_the_band_and_far_ones_are_not() {
        let mesh = cuboid(Vec3::splat(1.0));
        let scene = ReferenceScene::build([Caster {
            mesh: &mesh,
            world_from_local: Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0)),
            mask: None,
        }]);
        let points = [point(0.6, 0.0), point(0.75, 0.0), point(0.85, 0.0), point(3.0, 0.0)];
        let near = near_casters(&scene, &points, 0.3);
        assert_eq!(near, [true, true, false, false]);
        // Under a box hovering 0.2 m above, the ground is near it; 0.5 m above, it is not.
        for (height, expected) in [(0.2, true), (0.5, false)] {
            let scene = ReferenceScene::build([Caster {
                mesh: &mesh,
                world_from_local: Mat4::from_translation(Vec3::new(0.0, 0.5 + height, 0.0)),
                mask: None,
            }]);
            assert_eq!(near_casters(&scene, &[point(0.0, 0.0)], 0.3), [expected], "{height}");
        }
    }

    #[test]
    fn unusable_points_are_not_near_anything() {
        let mesh = cuboid(Vec3::splat(1.0));
        let scene = ReferenceScene::build([Caster {
            mesh: &mesh,
            world_from_local: Mat4::IDENTITY,
            mask: None,
        }]);
        let bad = [
            ReferencePoint {
                position: Vec3::NAN,
                normal: Vec3::Y,
            },
            ReferencePoint {
                position: Vec3::new(0.0, 0.6, 0.0),
                normal: Vec3::ZERO,
            },
        ];
        assert_eq!(near_casters(&scene, &bad, 0.3), [false, false]);
        assert_eq!(near_casters(&scene, &[point(0.6, 0.0)], f32::NAN), [false]);
    }
}
