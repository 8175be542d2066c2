//! Ground truth for spherical lights (spot and point lights with an emitter radius): the
//! fraction of the light's sphere visible from a point is the fraction of the spherical cap
//! it covers, seen from there, that reaches it without crossing a caster before the light.

use glam::Vec3;

use crate::reference::sampling::SunCap;
use crate::reference::{ReferencePoint, ReferenceScene, ReferenceSettings, Target, Visibility, trace};

/// A spherical light: a sphere of emitters (a radius of 0 is a point light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    /// Centre of the sphere, world space.
    pub center: Vec3,
    /// Radius in metres; 0 (or anything not positive or not finite) is a point.
    pub radius: f32,
}

impl SphereLight {
    /// The radius used: the given one when positive and finite, else 0.
    fn radius(&self) -> f32 {
        if self.radius.is_finite() && self.radius > 0.0 {
            self.radius
        } else {
            0.0
        }
    }

    /// The cap of directions from `from` that reach the sphere, or None when `from` is inside
    /// it (or on its centre) or anything is not finite.
    pub(crate) fn cap_from(&self, from: Vec3) -> Option<SunCap> {
        let to_light = self.center - from;
        let distance = to_light.length();
        let radius = self.radius();
        if !(distance.is_finite() && distance > radius && distance > 0.0) {
            return None;
        }
        // NOTE: the cap's half angle is asin(r / d): the directions tangent to the sphere.
        let half = (radius / distance).min(1.0).asin();
        SunCap::new(-to_light, 2.0 * half)
    }

    /// How far a ray from `origin` along the unit `dir` travels before it meets the sphere's
    /// near side (the centre's distance for a point light): casters beyond it do not shadow.
    pub(crate) fn distance_along(&self, origin: Vec3, dir: Vec3) -> f32 {
        let to_light = self.center - origin;
        let along = to_light.dot(dir);
        let radius = self.radius();
        // NOTE: directions come from the cap, so the ray meets the sphere; rounding at the
        // cap's rim can make the discriminant slightly negative, which reads as tangent.
        let off_axis = to_light.length_squared() - along * along;
        let half_chord = (radius * radius - off_axis).max(0.0).sqrt();
        (along - half_chord).max(0.0)
    }
}

/// Estimates the fraction of `light`'s sphere visible from each point (by solid angle),
/// casting rays at `scene` on the current rayon thread pool.
///
/// Per point, the directions are uniform over the cap the sphere covers from there, and only
/// casters between the point and the sphere's surface count. Budget, ray offsets, progress
/// reports and determinism are those of [`sun_visibility`](crate::reference::sun_visibility).
/// A point inside the sphere, or with a non-finite position or normal, gets value 1.0 with 0
/// samples; a point light (radius 0) casts one ray per point.
pub fn sphere_light_visibility(
    scene: &ReferenceScene,
    light: &SphereLight,
    points: &[ReferencePoint],
    settings: &ReferenceSettings,
    progress: &(dyn Fn(usize) + Sync),
) -> Vec<Visibility> {
    trace(scene, Target::Sphere(*light), points, settings, progress)
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec2};

    use super::*;
    use crate::mesh::plane;
    use crate::reference::Caster;

    fn settings() -> ReferenceSettings {
        ReferenceSettings {
            max_samples: 1024,
            min_samples: 16,
            seed: 3,
        }
    }

    fn at(position: Vec3) -> ReferencePoint {
        ReferencePoint {
            position,
            normal: Vec3::Y,
        }
    }

    /// A 2×2 m square caster at height `y`, centred on the y axis.
    fn square_at(y: f32) -> (crate::mesh::MeshData, Mat4) {
        (plane(Vec2::splat(2.0)), Mat4::from_translation(Vec3::new(0.0, y, 0.0)))
    }

    #[test]
    fn casters_behind_the_light_do_not_shadow() {
        let (mesh, world) = square_at(3.0);
        let scene = ReferenceScene::build([Caster {
            mesh: &mesh,
            world_from_local: world,
            mask: None,
        }]);
        let points = [at(Vec3::ZERO)];
        let below = SphereLight {
            center: Vec3::new(0.0, 2.0, 0.0),
            radius: 0.1,
        };
        let above = SphereLight {
            center: Vec3::new(0.0, 4.0, 0.0),
            radius: 0.1,
        };
        let v = sphere_light_visibility(&scene, &below, &points, &settings(), &|_| {});
        assert_eq!(v[0].value, 1.0, "the square is behind a light at 2 m");
        let v = sphere_light_visibility(&scene, &above, &points, &settings(), &|_| {});
        assert_eq!(v[0].value, 0.0, "the square hides a light at 4 m");
        // A point light casts one ray.
        let point = SphereLight { radius: 0.0, ..above };
        let v = sphere_light_visibility(&scene, &point, &points, &settings(), &|_| {});
        assert_eq!((v[0].value, v[0].samples), (0.0, 1));
    }

    #[test]
    fn a_half_covered_light_is_half_visible() {
        // An infinite-ish half plane at y = 1 covering x > 0, light centred above x = 0.
        let mesh = plane(Vec2::new(100.0, 100.0));
        let scene = ReferenceScene::build([Caster {
            mesh: &mesh,
            world_from_local: Mat4::from_translation(Vec3::new(50.0, 1.0, 0.0)),
            mask: None,
        }]);
        let light = SphereLight {
            center: Vec3::new(0.0, 2.0, 0.0),
            radius: 0.3,
        };
        let v = sphere_light_visibility(&scene, &light, &[at(Vec3::ZERO)], &settings(), &|_| {});
        assert!((v[0].value - 0.5).abs() < 0.03, "{:?}", v[0]);
        assert_eq!(v[0].samples, 1024);
    }

    #[test]
    fn penumbrae_widen_with_the_light_and_the_gap() {
        // A caster edge at x = 0, 1 m above the ground; the light 4 m up, offset in x.
        let mesh = plane(Vec2::new(100.0, 100.0));
        let scene = ReferenceScene::build([Caster {
            mesh: &mesh,
            world_from_local: Mat4::from_translation(Vec3::new(-50.0, 1.0, 0.0)),
            mask: None,
        }]);
        let penumbra_width = |radius: f32| {
            let light = SphereLight {
                center: Vec3::new(0.0, 4.0, 0.0),
                radius,
            };
            let xs: Vec<f32> = (0..200).map(|i| -1.0 + i as f32 * 0.01).collect();
            let points: Vec<ReferencePoint> = xs.iter().map(|&x| at(Vec3::new(x, 0.0, 0.0))).collect();
            let v = sphere_light_visibility(&scene, &light, &points, &settings(), &|_| {});
            v.iter().filter(|v| v.value > 0.02 && v.value < 0.98).count()
        };
        let (small, large) = (penumbra_width(0.1), penumbra_width(0.4));
        // Similar triangles: width = 2 r · gap / (light height − caster height) = 2r / 3.
        assert!((4..=10).contains(&small), "{small} cm for r = 0.1 (expected about 7)");
        assert!((22..=32).contains(&large), "{large} cm for r = 0.4 (expected about 27)");
    }

    #[test]
    fn points_inside_the_light_or_not_finite_are_not_estimated() {
        let scene = ReferenceScene::build([]);
        let light = SphereLight {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        let points = [
            at(Vec3::new(0.5, 0.0, 0.0)),
            at(Vec3::NAN),
            at(Vec3::new(3.0, 0.0, 0.0)),
        ];
        let v = sphere_light_visibility(&scene, &light, &points, &settings(), &|_| {});
        assert_eq!(v[0].samples, 0);
        assert_eq!(v[1].samples, 0);
        assert_eq!((v[2].value, v[2].samples), (1.0, 16), "an empty scene hides nothing");
        let nan = SphereLight {
            center: Vec3::NAN,
            radius: 1.0,
        };
        let v = sphere_light_visibility(&scene, &nan, &points[2..], &settings(), &|_| {});
        assert_eq!(v[0].samples, 0);
    }

    #[test]
    fn the_distance_to_the_sphere_is_to_its_near_side() {
        let light = SphereLight {
            center: Vec3::new(0.0, 5.0, 0.0),
            radius: 1.0,
        };
        assert!((light.distance_along(Vec3::ZERO, Vec3::Y) - 4.0).abs() < 1e-5);
        let point = SphereLight { radius: 0.0, ..light };
        assert!((point.distance_along(Vec3::ZERO, Vec3::Y) - 5.0).abs() < 1e-5);
        let cap = light.cap_from(Vec3::ZERO).unwrap();
        assert!(!cap.is_point());
        assert!(light.cap_from(Vec3::new(0.0, 4.5, 0.0)).is_none(), "inside");
    }
}
