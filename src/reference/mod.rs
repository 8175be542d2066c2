//! Ray-traced ground truth for shadows: the fraction of the sun's disc — or of a spherical
//! light (a spot or point light with a radius) — visible from each of a list of surface
//! points, estimated by casting rays at the casters' triangles.
//!
//! Build a [`ReferenceScene`] from the shadow casters once, then call [`sun_visibility`] or
//! [`sphere_light_visibility`] with the points to score. Every shadow technique is measured against these values, so the
//! estimator favours being right over being fast:
//!
//! - directions are uniform over the solid angle of the sun's disc (a spherical cap, not a
//!   flat disc), drawn from a per-point Owen-scrambled Sobol sequence, so a penumbra's error
//!   falls about as N^-3/4 rather than N^-1/2;
//! - results depend only on the inputs and the seed, never on the number of threads;
//! - triangles are two-sided and alpha-tested casters let rays through their clear texels;
//! - ray origins are offset by an amount that grows with the distance from the world origin,
//!   so points far from it (1e5 m) do not shadow themselves.

mod proximity;
mod sampling;
mod scene;
mod sphere;
mod triangle;

pub use proximity::near_casters;
pub use scene::ReferenceScene;
pub use sphere::{SphereLight, sphere_light_visibility};

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use glam::{Mat4, Vec3};
use rayon::iter::{IndexedParallelIterator, ParallelIterator};
use rayon::slice::ParallelSliceMut;

use crate::mesh::MeshData;
use sampling::{PointSequence, SunCap};

/// Alpha mask of a caster (alpha-tested foliage): texels below the cutoff let rays through.
///
/// A ray that hits a masked triangle reads the texel nearest to the interpolated UV (repeat
/// wrapping, `v = 0` at the top row) and passes through when `alpha / 255 · factor < cutoff`,
/// as the alpha-tested shadow pass does.
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaMask {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width · height` alpha values, rows from top to bottom. A mask with no texels, or with
    /// fewer values than `width · height`, counts as a single texel of alpha 255.
    pub alpha: Vec<u8>,
    /// Base colour alpha, multiplied into every texel.
    pub factor: f32,
    /// Alpha cutoff: a texel stops rays when `alpha / 255 · factor >= cutoff`.
    pub cutoff: f32,
}

/// One shadow caster: a mesh placed in the world.
#[derive(Clone, Debug)]
pub struct Caster<'a> {
    /// The mesh, in local space.
    pub mesh: &'a MeshData,
    /// Local to world transform (affine). A caster with a non-finite element is skipped.
    pub world_from_local: Mat4,
    /// Alpha mask, for alpha-tested casters; `None` is opaque.
    pub mask: Option<Arc<AlphaMask>>,
}

/// The sun as seen from the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDisc {
    /// Direction the light travels (from the sun into the scene); need not be unit length.
    pub direction: Vec3,
    /// Full angular diameter of the disc in radians; 0 is a point sun (the real sun is about
    /// 0.0093).
    pub angular_diameter: f32,
}

/// A surface point to estimate the sun's visibility at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferencePoint {
    /// World-space position.
    pub position: Vec3,
    /// World-space unit surface normal, used only to lift ray origins off the surface.
    pub normal: Vec3,
}

/// How many rays to cast per point, and the seed of their directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReferenceSettings {
    /// Rays per point where the first `min_samples` disagree (penumbrae). At least 1.
    pub max_samples: u32,
    /// Rays cast at every point first; when all of them are blocked or all pass, the point
    /// stops there. Clamped to `1..=max_samples`.
    pub min_samples: u32,
    /// Seed of the sample directions; the same seed gives bit-identical results.
    pub seed: u64,
}

impl Default for ReferenceSettings {
    /// 256 rays in penumbrae, 16 elsewhere, seed 1.
    fn default() -> Self {
        Self {
            max_samples: 256,
            min_samples: 16,
            seed: 1,
        }
    }
}

/// The estimated visibility of the sun from one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Visibility {
    /// Fraction of the sun's disc (by solid angle) that is visible, in `0..=1`.
    pub value: f32,
    /// `sqrt(value · (1 − value) / samples)`: the standard error of independent samples.
    /// The directions are stratified, so the actual error is usually well below this (it is a
    /// conservative bound, not an estimate). 0 where every ray agreed.
    pub std_error: f32,
    /// Rays cast at this point; 0 when the point (or the sun) was not usable.
    pub samples: u32,
}

impl Visibility {
    /// The answer for a point that could not be estimated: fully lit, no samples.
    const NOT_ESTIMATED: Visibility = Visibility {
        value: 1.0,
        std_error: 0.0,
        samples: 0,
    };
}

/// Points handed to a worker at a time, and the granularity of progress reports.
const CHUNK: usize = 64;

/// Estimates the fraction of the sun's disc visible from each point, casting rays against
/// `scene` on the current rayon thread pool.
///
/// Per point, `settings.min_samples` rays are cast towards directions uniform over the disc's
/// solid angle; if they all agree (all blocked or all free) the point is done, otherwise rays
/// are cast up to `settings.max_samples`. A point sun (diameter 0) casts a single ray. Rays
/// start at `position + normal·ε + direction·ε`, with ε = 1e-4 m plus 4 to 8 float ulps of the
/// position's largest coordinate (5 cm at 1e5 m), and go to infinity.
///
/// The normal only sets that offset: rays are cast even when the sun is below the point's
/// horizon, and the result is whatever they hit (a closed caster then usually shadows its own
/// back faces; a lone plane does not).
///
/// A point with a non-finite position or normal (or one so close to `f32::MAX` that the lifted
/// origin could overflow) gets value 1.0 with 0 samples, and so does every point when
/// `sun.direction` is zero or not finite. A non-finite angular diameter is a point sun. The
/// result has one entry per point, in order, and depends only on the inputs and
/// `settings.seed`, not on the number of threads.
///
/// `progress(n)` is called now and then (about every 64 points), from worker threads, with the
/// number of points finished so far, never decreasing, and once more with `points.len()` on
/// the calling thread before returning. Calls never overlap; a worker that would report while
/// another one is reporting skips its report rather than waiting.
pub fn sun_visibility(
    scene: &ReferenceScene,
    sun: &SunDisc,
    points: &[ReferencePoint],
    settings: &ReferenceSettings,
    progress: &(dyn Fn(usize) + Sync),
) -> Vec<Visibility> {
    match SunCap::new(sun.direction, sun.angular_diameter) {
        Some(cap) => trace(scene, Target::Sun(cap), points, settings, progress),
        None => {
            progress(points.len());
            vec![Visibility::NOT_ESTIMATED; points.len()]
        }
    }
}

/// What the rays of one estimate aim at.
#[derive(Clone, Copy, Debug)]
enum Target {
    /// The sun: the same cap of directions from every point, casters at any distance.
    Sun(SunCap),
    /// A spherical light: the cap it covers seen from each point, casters only before it.
    Sphere(SphereLight),
}

/// Estimates the visibility of `target` from every point in parallel (see [`sun_visibility`]
/// for the budget, determinism and progress reports).
fn trace(
    scene: &ReferenceScene,
    target: Target,
    points: &[ReferencePoint],
    settings: &ReferenceSettings,
    progress: &(dyn Fn(usize) + Sync),
) -> Vec<Visibility> {
    let mut out = vec![Visibility::NOT_ESTIMATED; points.len()];
    let max = settings.max_samples.max(1);
    let budget = Budget {
        min: settings.min_samples.clamp(1, max),
        max,
    };
    let done = AtomicUsize::new(0);
    // The last count reported; held while reporting so that reports never go backwards.
    let reported = Mutex::new(0usize);
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, chunk)| {
        let first = c * CHUNK;
        for (k, slot) in chunk.iter_mut().enumerate() {
            let i = first + k;
            *slot = estimate(scene, &target, &points[i], i as u64, settings.seed, budget);
        }
        done.fetch_add(chunk.len(), Ordering::Relaxed);
        // A worker that finds another one reporting skips its report instead of waiting.
        if let Ok(mut last) = reported.try_lock() {
            let now = done.load(Ordering::Relaxed);
            if now > *last {
                *last = now;
                progress(now);
            }
        }
    });
    progress(points.len());
    out
}

/// Rays per point: `min` first, up to `max` in penumbrae (`1 <= min <= max`).
#[derive(Clone, Copy, Debug)]
struct Budget {
    min: u32,
    max: u32,
}

/// The visibility of the target from one point.
fn estimate(
    scene: &ReferenceScene,
    target: &Target,
    point: &ReferencePoint,
    index: u64,
    seed: u64,
    budget: Budget,
) -> Visibility {
    if !point.position.is_finite() || !point.normal.is_finite() {
        return Visibility::NOT_ESTIMATED;
    }
    let eps = offset_distance(point.position);
    let base = point.position + point.normal.normalize_or_zero() * eps;
    if !(base.abs() + Vec3::splat(eps)).is_finite() {
        // Within a few ulps of f32::MAX: a lifted origin could overflow.
        return Visibility::NOT_ESTIMATED;
    }
    let (cap, light) = match target {
        Target::Sun(cap) => (*cap, None),
        Target::Sphere(light) => match light.cap_from(base) {
            Some(cap) => (cap, Some(light)),
            None => return Visibility::NOT_ESTIMATED,
        },
    };
    let sequence = PointSequence::new(seed, index);
    let lit = |i: u32| {
        let dir = cap.direction(sequence.sample(i));
        let origin = base + dir * eps;
        let reach = light.map_or(f32::INFINITY, |l| l.distance_along(origin, dir));
        u32::from(!scene.occluded_within(origin, dir, reach))
    };
    if cap.is_point() {
        return Visibility {
            value: lit(0) as f32,
            std_error: 0.0,
            samples: 1,
        };
    }
    let mut visible: u32 = (0..budget.min).map(lit).sum();
    let mut samples = budget.min;
    if visible != 0 && visible != samples {
        visible += (budget.min..budget.max).map(lit).sum::<u32>();
        samples = budget.max;
    }
    let value = f64::from(visible) / f64::from(samples);
    Visibility {
        value: value as f32,
        std_error: (value * (1.0 - value) / f64::from(samples)).sqrt() as f32,
        samples,
    }
}

/// How far ray origins are lifted off a surface at `position`: 0.1 mm, plus 2^-21 of the
/// largest coordinate, which is between 4 and 8 ulps of it, so the lifted origin stays on the
/// lit side of the surface after rounding however far from the world origin it is (5 cm at
/// 1e5 m, where an f32 ulp is 8 mm).
fn offset_distance(position: Vec3) -> f32 {
    1e-4 + position.abs().max_element() * (1.0 / 2_097_152.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{cuboid, plane};
    use glam::{Vec2, Vec3};
    use std::sync::Mutex;

    fn points(ps: &[Vec3]) -> Vec<ReferencePoint> {
        ps.iter()
            .map(|&position| ReferencePoint {
                position,
                normal: Vec3::Y,
            })
            .collect()
    }

    const SUN_DOWN: SunDisc = SunDisc {
        direction: Vec3::new(0.0, -3.0, 0.0),
        angular_diameter: 0.05,
    };

    #[test]
    fn offset_distance_clears_several_ulps() {
        for x in [0.0f32, 1.0, 1000.0, 65_536.0, 100_000.0, 131_071.0, 1e7] {
            let eps = offset_distance(Vec3::new(x, -x, 0.5 * x));
            let lifted = x + eps;
            assert!(lifted > x, "{x}");
            let ulp = (x.max(f32::MIN_POSITIVE)).next_up() - x.max(f32::MIN_POSITIVE);
            assert!(eps >= 4.0 * ulp || x < 1.0, "{x}: {eps} vs ulp {ulp}");
            assert!(eps <= 1e-4 + 8.0 * ulp.max(1e-9) + 1e-6, "{x}: {eps}");
        }
    }

    #[test]
    fn adaptive_budget_and_point_sun() {
        let slab = plane(Vec2::splat(10.0));
        let scene = ReferenceScene::build([Caster {
            mesh: &slab,
            world_from_local: Mat4::from_translation(Vec3::new(5.0, 1.0, 0.0)),
            mask: None,
        }]);
        // Fully lit, fully shadowed, and on the edge (x = 0).
        let pts = points(&[Vec3::new(-3.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO]);
        let settings = ReferenceSettings {
            max_samples: 100,
            min_samples: 10,
            seed: 4,
        };
        let v = sun_visibility(&scene, &SUN_DOWN, &pts, &settings, &|_| {});
        assert_eq!(
            v[0],
            Visibility {
                value: 1.0,
                std_error: 0.0,
                samples: 10
            }
        );
        assert_eq!(
            v[1],
            Visibility {
                value: 0.0,
                std_error: 0.0,
                samples: 10
            }
        );
        assert_eq!(v[2].samples, 100);
        assert!((v[2].value - 0.5).abs() < 0.1, "{:?}", v[2]);
        let want = (v[2].value * (1.0 - v[2].value) / 100.0).sqrt();
        assert!((v[2].std_error - want).abs() < 1e-6);

        // min > max and zeroes are clamped.
        let odd = ReferenceSettings {
            max_samples: 0,
            min_samples: 50,
            seed: 4,
        };
        let v = sun_visibility(&scene, &SUN_DOWN, &pts, &odd, &|_| {});
        assert!(v.iter().all(|v| v.samples == 1));

        let point_sun = SunDisc {
            angular_diameter: 0.0,
            ..SUN_DOWN
        };
        let v = sun_visibility(&scene, &point_sun, &pts[..2], &settings, &|_| {});
        assert_eq!(
            v[0],
            Visibility {
                value: 1.0,
                std_error: 0.0,
                samples: 1
            }
        );
        assert_eq!(
            v[1],
            Visibility {
                value: 0.0,
                std_error: 0.0,
                samples: 1
            }
        );
    }

    #[test]
    fn back_facing_points_see_their_own_caster() {
        // A point on the bottom face of a box, normal down, sun above: rays go up through the
        // box, which shadows its own bottom. On top, the same sun is fully visible.
        let cube = cuboid(Vec3::ONE);
        let scene = ReferenceScene::build([Caster {
            mesh: &cube,
            world_from_local: Mat4::IDENTITY,
            mask: None,
        }]);
        let pts = [
            ReferencePoint {
                position: Vec3::new(0.1, -0.5, 0.2),
                normal: Vec3::NEG_Y,
            },
            ReferencePoint {
                position: Vec3::new(0.1, 0.5, 0.2),
                normal: Vec3::Y,
            },
        ];
        let v = sun_visibility(&scene, &SUN_DOWN, &pts, &ReferenceSettings::default(), &|_| {});
        assert_eq!(v[0].value, 0.0);
        assert_eq!(v[1].value, 1.0);
    }

    #[test]
    fn bad_sun_and_bad_points_are_not_estimated() {
        let scene = ReferenceScene::default();
        let pts = [
            ReferencePoint {
                position: Vec3::NAN,
                normal: Vec3::Y,
            },
            ReferencePoint {
                position: Vec3::ZERO,
                normal: Vec3::new(0.0, f32::INFINITY, 0.0),
            },
            ReferencePoint {
                position: Vec3::ZERO,
                normal: Vec3::ZERO,
            },
        ];
        let v = sun_visibility(&scene, &SUN_DOWN, &pts, &ReferenceSettings::default(), &|_| {});
        assert_eq!(v[0], Visibility::NOT_ESTIMATED);
        assert_eq!(v[1], Visibility::NOT_ESTIMATED);
        assert_eq!(v[2].samples, 16);
        // Overflowing origins, against a scene with triangles (obvhs debug-asserts finite rays).
        let slab = plane(Vec2::ONE);
        let scene = ReferenceScene::build([Caster {
            mesh: &slab,
            world_from_local: Mat4::IDENTITY,
            mask: None,
        }]);
        let extreme = points(&[
            Vec3::new(0.0, f32::MAX, 0.0),
            Vec3::new(f32::MAX, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -1e30),
        ]);
        let v = sun_visibility(&scene, &SUN_DOWN, &extreme, &ReferenceSettings::default(), &|_| {});
        assert_eq!(v[0], Visibility::NOT_ESTIMATED);
        assert_eq!(v[1], Visibility::NOT_ESTIMATED);
        assert_eq!(
            v[2],
            Visibility {
                value: 1.0,
                std_error: 0.0,
                samples: 16
            }
        );
        let no_sun = SunDisc {
            direction: Vec3::ZERO,
            angular_diameter: 0.01,
        };
        let v = sun_visibility(&scene, &no_sun, &pts, &ReferenceSettings::default(), &|_| {});
        assert!(v.iter().all(|v| *v == Visibility::NOT_ESTIMATED));
    }

    #[test]
    fn progress_reaches_the_point_count() {
        let scene = ReferenceScene::default();
        let pts = points(&vec![Vec3::ZERO; 1000]);
        let seen = Mutex::new(Vec::new());
        let v = sun_visibility(&scene, &SUN_DOWN, &pts, &ReferenceSettings::default(), &|n| {
            seen.lock().unwrap().push(n)
        });
        assert_eq!(v.len(), 1000);
        let seen = seen.into_inner().unwrap();
        assert_eq!(seen.last(), Some(&1000));
        assert!(seen.len() >= 2, "{seen:?}");
        assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
        let v = sun_visibility(&scene, &SUN_DOWN, &[], &ReferenceSettings::default(), &|n| {
            assert_eq!(n, 0)
        });
        assert!(v.is_empty());
    }
}
