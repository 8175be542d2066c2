//! Choosing which lights cast shadows when a scene has more shadowed lights of a kind than
//! the budget allows: the lights that cover most of the screen first (a light whose sphere of
//! influence holds the camera covers all of it), then the nearest, then the earliest. The
//! choice is returned whole, so the caller can report exactly which lights lost their
//! shadows and why — never a silent drop.

use glam::Vec3;

/// The kinds of shadowed light, each with its own budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LightKind {
    /// A directional light (sun): no position, always covers the screen.
    Directional,
    /// A spot light.
    Spot,
    /// A point light.
    Point,
}

/// One light that asks for shadows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightCandidate {
    /// The caller's identifier (an index into its own list).
    pub id: usize,
    /// Which budget it counts against.
    pub kind: LightKind,
    /// Its sphere of influence (centre and range) for positional lights; None for a
    /// directional light.
    pub bounds: Option<(Vec3, f32)>,
}

/// How many lights of each kind may cast shadows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowBudget {
    /// Most shadowed directional lights.
    pub directional: usize,
    /// Most shadowed spot lights.
    pub spot: usize,
    /// Most shadowed point lights.
    pub point: usize,
}

impl LightKind {
    /// The word messages use for the kind: `directional`, `spot` or `point`.
    pub fn word(self) -> &'static str {
        match self {
            LightKind::Directional => "directional",
            LightKind::Spot => "spot",
            LightKind::Point => "point",
        }
    }
}

impl ShadowBudget {
    /// The budget for `kind`.
    pub fn of(&self, kind: LightKind) -> usize {
        match kind {
            LightKind::Directional => self.directional,
            LightKind::Spot => self.spot,
            LightKind::Point => self.point,
        }
    }
}

/// The viewpoint the lights are ranked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankingView {
    /// Camera position, world space.
    pub position: Vec3,
    /// `tan(fov_y / 2)` of the camera.
    pub tan_half_fov_y: f32,
}

/// The lights that keep their shadows and those that lose them, each in ranking order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BudgetChoice {
    /// Ids of the lights that cast shadows.
    pub shadowed: Vec<usize>,
    /// Ids of the lights over budget, per kind, best ranked first.
    pub dropped: Vec<(LightKind, usize)>,
}

/// The share of the screen's height a sphere covers from `view` (1 or more for a sphere that
/// holds the camera or fills the view, 0 for a non-finite or empty one).
pub fn screen_coverage(view: &RankingView, center: Vec3, radius: f32) -> f32 {
    let distance = center.distance(view.position);
    if !(distance.is_finite() && radius.is_finite() && radius > 0.0) {
        return 0.0;
    }
    if distance <= radius {
        return f32::INFINITY;
    }
    let tan = view.tan_half_fov_y.max(f32::MIN_POSITIVE);
    // NOTE: the sphere's angular radius is asin(r / d); its share of the half-height is that
    // angle's tangent over the field's.
    let s = radius / distance;
    (s / (1.0 - s * s).sqrt() / tan).min(f32::MAX)
}

/// Reused buffers of [`choose_shadowed_lights_into`].
#[derive(Clone, Debug, Default)]
pub struct RankScratch {
    /// Per candidate: kind, coverage, distance, input order, id.
    ranked: Vec<(LightKind, f32, f32, usize, usize)>,
}

/// Splits `candidates` into the lights that fit `budget` and those that do not, ranking each
/// kind by screen coverage (largest first), then distance (nearest first), then input order.
pub fn choose_shadowed_lights(
    candidates: &[LightCandidate],
    budget: &ShadowBudget,
    view: &RankingView,
) -> BudgetChoice {
    let mut choice = BudgetChoice::default();
    choose_shadowed_lights_into(candidates, budget, view, &mut RankScratch::default(), &mut choice);
    choice
}

/// [`choose_shadowed_lights`] into reused buffers: allocates nothing once they have grown to
/// the number of candidates.
pub fn choose_shadowed_lights_into(
    candidates: &[LightCandidate],
    budget: &ShadowBudget,
    view: &RankingView,
    scratch: &mut RankScratch,
    choice: &mut BudgetChoice,
) {
    let ranked = &mut scratch.ranked;
    ranked.clear();
    ranked.extend(candidates.iter().enumerate().map(|(order, c)| {
        let (coverage, distance) = match c.bounds {
            None => (f32::INFINITY, 0.0),
            Some((center, radius)) => {
                let d = center.distance(view.position);
                (
                    screen_coverage(view, center, radius),
                    if d.is_finite() { d } else { f32::INFINITY },
                )
            }
        };
        (c.kind, coverage, distance, order, c.id)
    }));
    // NOTE: an unstable sort allocates nothing, and the input order breaks every tie, so the
    // result is deterministic. Coverage is never NaN (bad input maps to 0); distances may be
    // infinite.
    ranked.sort_unstable_by(|a, b| {
        a.0.cmp(&b.0)
            .then(b.1.total_cmp(&a.1))
            .then(a.2.total_cmp(&b.2))
            .then(a.3.cmp(&b.3))
    });
    choice.shadowed.clear();
    choice.dropped.clear();
    let mut taken = [0usize; 3];
    for &(kind, _, _, _, id) in ranked.iter() {
        let slot = &mut taken[kind as usize];
        if *slot < budget.of(kind) {
            *slot += 1;
            choice.shadowed.push(id);
        } else {
            choice.dropped.push((kind, id));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> RankingView {
        RankingView {
            position: Vec3::ZERO,
            tan_half_fov_y: 1.0,
        }
    }

    fn spot(id: usize, x: f32, range: f32) -> LightCandidate {
        LightCandidate {
            id,
            kind: LightKind::Spot,
            bounds: Some((Vec3::new(x, 0.0, 0.0), range)),
        }
    }

    #[test]
    fn coverage_grows_with_size_and_nearness() {
        let v = view();
        assert!(screen_coverage(&v, Vec3::X * 10.0, 2.0) > screen_coverage(&v, Vec3::X * 10.0, 1.0));
        assert!(screen_coverage(&v, Vec3::X * 5.0, 1.0) > screen_coverage(&v, Vec3::X * 10.0, 1.0));
        assert_eq!(screen_coverage(&v, Vec3::X, 2.0), f32::INFINITY, "the camera is inside");
        assert_eq!(screen_coverage(&v, Vec3::NAN, 2.0), 0.0);
        assert_eq!(screen_coverage(&v, Vec3::X, -1.0), 0.0);
        // A sphere seen under 45° (tan 1) with a 90° field covers the half-height.
        let r = 10.0 * (std::f32::consts::FRAC_PI_4).sin();
        assert!((screen_coverage(&v, Vec3::X * 10.0, r) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn over_budget_lights_are_the_smallest_on_screen_and_are_all_reported() {
        let lights = [
            spot(10, 50.0, 1.0),
            spot(11, 5.0, 1.0),
            spot(12, 0.5, 1.0), // holds the camera
            spot(13, 20.0, 8.0),
            LightCandidate {
                id: 20,
                kind: LightKind::Directional,
                bounds: None,
            },
            LightCandidate {
                id: 21,
                kind: LightKind::Directional,
                bounds: None,
            },
        ];
        let budget = ShadowBudget {
            directional: 1,
            spot: 2,
            point: 4,
        };
        let choice = choose_shadowed_lights(&lights, &budget, &view());
        assert_eq!(choice.shadowed, [20, 12, 13]);
        assert_eq!(
            choice.dropped,
            [
                (LightKind::Directional, 21),
                (LightKind::Spot, 11),
                (LightKind::Spot, 10)
            ]
        );
        // Every light is in exactly one list.
        assert_eq!(choice.shadowed.len() + choice.dropped.len(), lights.len());
    }

    #[test]
    fn ties_go_to_the_nearest_then_the_first() {
        let lights = [
            spot(1, 10.0, 0.0),
            spot(2, 3.0, 0.0),
            spot(3, 3.0, 0.0),
            spot(4, f32::NAN, 1.0),
        ];
        let budget = ShadowBudget {
            directional: 0,
            spot: 2,
            point: 0,
        };
        let choice = choose_shadowed_lights(&lights, &budget, &view());
        assert_eq!(choice.shadowed, [2, 3]);
        assert_eq!(choice.dropped, [(LightKind::Spot, 1), (LightKind::Spot, 4)]);
        let none = choose_shadowed_lights(&[], &budget, &view());
        assert_eq!(none, BudgetChoice::default());
    }
}
