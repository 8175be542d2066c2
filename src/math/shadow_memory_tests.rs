//! Unit and property tests of the shadow-memory arithmetic and the budget fit.

use proptest::prelude::*;

use super::*;

const MIB: u64 = 1 << 20;

fn costs() -> MemoryCosts {
    MemoryCosts {
        vsm_texel: 16,
        sun_depth_texel: 4,
        support: MomentSupport {
            fp32_filterable: true,
            unorm16: true,
        },
    }
}

fn spot(resolution: u32, coverage: f32) -> LightRequest {
    LightRequest {
        kind: LightKind::Spot,
        resolution,
        views: 1,
        moments: MomentUse::None,
        coverage,
        scrolls: false,
        wraps: false,
    }
}

fn point_vsm(resolution: u32, coverage: f32) -> LightRequest {
    LightRequest {
        kind: LightKind::Point,
        resolution,
        views: 6,
        moments: MomentUse::Vsm { blur: true },
        coverage,
        scrolls: false,
        wraps: false,
    }
}

fn sun(resolution: u32, cascades: u32, moments: MomentUse) -> LightRequest {
    LightRequest {
        kind: LightKind::Directional,
        resolution,
        views: cascades,
        moments,
        coverage: f32::INFINITY,
        scrolls: false,
        wraps: false,
    }
}

#[test]
fn a_point_light_with_blurred_vsm_at_4096_needs_its_depth_moments_and_a_cube_of_scratch() {
    let [cascades, spots, points] = storage_bytes(&[point_vsm(4096, 1.0)], &[4096], &costs());
    let face = 4096u64 * 4096;
    assert_eq!(cascades, StorageBytes::default());
    assert_eq!(spots.total(), 0);
    assert_eq!(points.depth, 6 * face * 4);
    assert_eq!(points.moments, 6 * face * 16);
    assert_eq!(points.scratch, 6 * face * 16);
    // 3.4 GiB: more than software Vulkan can give a scene.
    assert_eq!(points.total(), 3456 * MIB);
    assert_eq!(points.per_layer(), face * 20);
}

#[test]
fn moments_cover_every_layer_of_their_array_and_mips_follow_contact_hardening() {
    let msm = MomentUse::Sun {
        msm: true,
        fp32: false,
        blur: false,
        hardening: true,
    };
    // Two suns: the second filters PCF, but its layers get moments like the first's.
    let requests = [sun(2048, 4, msm), sun(1024, 2, MomentUse::None)];
    let [c, _, _] = storage_bytes(&requests, &[2048, 1024], &costs());
    assert_eq!((c.side, c.layers), (2048, 6));
    let mips: u64 = (0..7).map(|l| (2048u64 >> l).pow(2)).sum();
    // 16-bit MSM alone is stored in Rgba16Unorm, 8 bytes a texel.
    assert_eq!(c.moments, mips * 6 * 8);
    // Without a blur the scratch is a 1×1 stand-in.
    assert_eq!(c.scratch, 8);
    // A 32-bit EVSM sun with a fixed blur: no mips, a one-layer scratch.
    let evsm = MomentUse::Sun {
        msm: false,
        fp32: true,
        blur: true,
        hardening: false,
    };
    let [c, _, _] = storage_bytes(&[sun(1024, 3, evsm)], &[1024], &costs());
    assert_eq!(c.moments, 1024 * 1024 * 3 * 16);
    assert_eq!(c.scratch, 1024 * 1024 * 16);
    // Without 32-bit filtering, 32 bits asked for are stored in 16.
    let half = MemoryCosts {
        vsm_texel: 8,
        sun_depth_texel: 4,
        support: MomentSupport::default(),
    };
    let [c, _, _] = storage_bytes(&[sun(1024, 3, evsm)], &[1024], &half);
    assert_eq!(c.moments, 1024 * 1024 * 3 * 8);
}

#[test]
fn the_cascade_moment_format_follows_the_suns_and_the_device() {
    let all = MomentSupport {
        fp32_filterable: true,
        unorm16: true,
    };
    assert_eq!(cascade_moment_format([], all), None);
    assert_eq!(
        cascade_moment_format([(true, false)], all),
        Some(CascadeMomentFormat::Rgba16Unorm)
    );
    assert_eq!(
        cascade_moment_format([(true, false), (false, false)], all),
        Some(CascadeMomentFormat::Rgba16Float)
    );
    assert_eq!(
        cascade_moment_format([(true, false), (false, true)], all),
        Some(CascadeMomentFormat::Rgba32Float)
    );
    let no_unorm = MomentSupport { unorm16: false, ..all };
    assert_eq!(
        cascade_moment_format([(true, false)], no_unorm),
        Some(CascadeMomentFormat::Rgba32Float)
    );
    assert_eq!(
        cascade_moment_format([(true, false)], MomentSupport::default()),
        Some(CascadeMomentFormat::Rgba16Float)
    );
}

#[test]
fn within_budget_nothing_changes() {
    let requests = [sun(2048, 4, MomentUse::None), spot(1024, 0.2)];
    let fit = fit_budget(&requests, &costs(), u64::MAX);
    assert_eq!(fit.resolutions, [2048, 1024]);
    assert!(fit.lowered.is_empty() && fit.dropped.is_empty());
    assert_eq!(fit.total(), 2048 * 2048 * 4 * 4 + 1024 * 1024 * 4);
}

#[test]
fn the_lights_smallest_on_screen_are_lowered_first_and_suns_last() {
    let requests = [
        sun(2048, 4, MomentUse::None),
        point_vsm(1024, 0.5),
        spot(2048, 0.1),
        spot(1024, 0.9),
    ];
    let asked = total(&requests, &[2048, 1024, 2048, 1024], &costs());
    // Halving the spot array's largest layer (the small spot) frees 2 × (2048² − 1024²) × 4.
    let freed = 2 * (2048 * 2048 - 1024 * 1024) * 4;
    let fit = fit_budget(&requests, &costs(), asked - freed);
    assert_eq!(fit.resolutions, [2048, 1024, 1024, 1024]);
    assert_eq!(fit.lowered, [2]);
    assert_eq!(fit.total(), asked - freed);
    // Less: both spots now set their array's side, and the larger covers 0.9 of the screen;
    // the point light covers 0.5, so its cube is halved next.
    let fit = fit_budget(&requests, &costs(), asked - freed - 1);
    assert_eq!(fit.resolutions, [2048, 512, 1024, 1024]);
    assert_eq!(fit.lowered, [2, 1]);
    // Far less: everything positional reaches 256 before the sun's cascades are touched.
    let positional_at_floor = total(&requests, &[2048, 256, 256, 256], &costs());
    let fit = fit_budget(&requests, &costs(), positional_at_floor);
    assert_eq!(fit.resolutions, [2048, 256, 256, 256]);
    let fit = fit_budget(&requests, &costs(), positional_at_floor - 1);
    assert_eq!(fit.resolutions, [1024, 256, 256, 256]);
    assert!(fit.dropped.is_empty());
}

#[test]
fn past_the_smallest_resolution_the_lights_smallest_on_screen_lose_their_shadows() {
    let requests = [sun(4096, 4, MomentUse::None), spot(512, 0.3), spot(512, 0.1)];
    let floor = total(&requests, &[256, 256, 256], &costs());
    let fit = fit_budget(&requests, &costs(), floor - 1);
    assert_eq!(fit.dropped, [2]);
    assert_eq!(fit.resolutions, [256, 256, 0]);
    assert_eq!(fit.lowered, [1, 0]);
    assert!(fit.total() < floor);
    let fit = fit_budget(&requests, &costs(), 0);
    assert_eq!(fit.dropped, [2, 1, 0]);
    assert_eq!(fit.total(), 0);
    // A light asking for less than the floor keeps its size.
    let fit = fit_budget(&[spot(64, 1.0), spot(1024, 0.5)], &costs(), 256 * 256 * 4 * 2);
    assert_eq!(fit.resolutions, [64, 256]);
}

#[test]
fn alone_bytes_is_a_lights_own_cost() {
    assert_eq!(
        alone_bytes(&point_vsm(256, 1.0), 256, &costs()),
        256 * 256 * 6 * (4 + 16 + 16)
    );
    assert_eq!(alone_bytes(&spot(512, 1.0), 512, &costs()), 512 * 512 * 4);
}

fn request() -> impl Strategy<Value = LightRequest> {
    (0..3usize, 1u32..=4096, 0..4usize, 0.0f32..4.0).prop_map(|(kind, resolution, moments, coverage)| {
        let (kind, views) = match kind {
            0 => (LightKind::Directional, 1 + resolution % 4),
            1 => (LightKind::Spot, 1),
            _ => (LightKind::Point, 6),
        };
        let moments = match (kind, moments) {
            (_, 0) => MomentUse::None,
            (LightKind::Directional, m) => MomentUse::Sun {
                msm: m == 1,
                fp32: m == 2,
                blur: m == 3,
                hardening: m != 3,
            },
            (_, m) => MomentUse::Vsm { blur: m == 2 },
        };
        let coverage = if kind == LightKind::Directional {
            f32::INFINITY
        } else {
            coverage
        };
        LightRequest {
            kind,
            resolution,
            views,
            moments,
            coverage,
            scrolls: false,
            wraps: false,
        }
    })
}

proptest! {
    #[test]
    fn a_fit_holds_the_budget_and_never_raises_a_resolution(
        requests in prop::collection::vec(request(), 0..12),
        budget in 0u64..(4 << 30),
    ) {
        let fit = fit_budget(&requests, &costs(), budget);
        prop_assert!(fit.total() <= budget, "{} > {budget}", fit.total());
        prop_assert_eq!(fit.total(), total(&requests, &fit.resolutions, &costs()));
        for (i, (r, &got)) in requests.iter().zip(&fit.resolutions).enumerate() {
            prop_assert!(got <= r.resolution);
            if got == 0 {
                prop_assert!(fit.dropped.contains(&i));
            } else if got < r.resolution {
                prop_assert!(got >= MIN_BUDGET_RESOLUTION && fit.lowered.contains(&i));
            }
        }
        // Nothing is dropped while a lower resolution could still free memory.
        if !fit.dropped.is_empty() {
            prop_assert!(fit.resolutions.iter().all(|&g| g <= MIN_BUDGET_RESOLUTION));
        }
    }
}

#[test]
fn a_scrolling_sun_adds_one_depth_layer_to_move_through() {
    let costs = MemoryCosts {
        vsm_texel: 16,
        sun_depth_texel: 4,
        support: MomentSupport::default(),
    };
    let plain = sun(1024, 6, MomentUse::None);
    let scrolling = LightRequest { scrolls: true, ..plain };
    let [a, ..] = storage_bytes(&[plain], &[1024], &costs);
    let [b, ..] = storage_bytes(&[scrolling], &[1024], &costs);
    assert_eq!(a.shift, 0);
    assert_eq!(b.total() - a.total(), 1024 * 1024 * 4);
    // Wrapping layers move nothing, unless a larger light's layers leave them a corner.
    let wrapping = LightRequest {
        wraps: true,
        ..scrolling
    };
    let [c, ..] = storage_bytes(&[wrapping], &[1024], &costs);
    assert_eq!(c.shift, 0);
    let larger = sun(2048, 4, MomentUse::None);
    let [d, ..] = storage_bytes(&[wrapping, larger], &[1024, 2048], &costs);
    assert_eq!(d.shift, 2048 * 2048 * 4);
}

#[test]
fn sixteen_bit_sun_depth_halves_the_suns_depth_and_nothing_else() {
    let float = costs();
    let unorm = MemoryCosts {
        sun_depth_texel: 2,
        ..float
    };
    let requests = [
        sun(2048, 4, MomentUse::None),
        LightRequest {
            scrolls: true,
            ..sun(1024, 6, MomentUse::None)
        },
        spot(1024, 0.5),
    ];
    let [a, b, ..] = storage_bytes(&requests, &[2048, 1024, 1024], &float);
    let [c, d, ..] = storage_bytes(&requests, &[2048, 1024, 1024], &unorm);
    assert_eq!((a.depth, a.shift), (2048 * 2048 * 10 * 4, 2048 * 2048 * 4));
    assert_eq!((c.depth, c.shift), (a.depth / 2, a.shift / 2));
    assert_eq!(d, b, "the spot light's array keeps 32-bit depth");
}
