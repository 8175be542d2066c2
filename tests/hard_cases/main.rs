//! Numerical hard cases. Each one renders a small scene at an extreme (on lavapipe in CI) with
//! PCF and with PCSS, every shadow setting at its default, and asserts: finite cascade
//! matrices, no NaN in the per-pixel shadow factor, at least a stated number of pixels judged,
//! and — scored against the ray-traced reference — acne on the ground and on the casters' lit
//! faces, and leaks in the umbrae, within the limits in [`judge`].

mod judge;
mod scenes;

use bevy_app::App;
use glam::Vec3;
use penumbra::analysis::shimmer::shimmer;
use penumbra::app::spawn_scene;
use penumbra::bench::session::SceneSession;
use penumbra::ecs::{
    FrameLights, Mesh3d, RenderInstances, ShadowDiagnostics, ShadowPlugin, ShadowStats, Transform, ViewportSize,
};
use penumbra::render::frame::FrameInputs;
use penumbra::render::probe::ProbeGpu;
use penumbra::render::shadows::storage::depth_texel_bytes;
use penumbra::render::{RenderOptions, Renderer, SunDepth};
use penumbra::settings::ShadowSettings;

use judge::{Floors, Limits, TARGET, judge, judge_with, sun_at_elevation};
use scenes::{Case, SUN, load};

/// How much worse (mean absolute error) a scene far from the origin may score than the same
/// scene at the origin.
const FAR_MAE_MARGIN: f64 = 0.01;

#[test]
fn sun_straight_down() {
    let down = judge("sun straight down", &Case::sun(Vec3::NEG_Y).desc(), 96, 64);
    down.assert_judged(&Floors {
        judged: 3000,
        ground_lit: 2000,
        caster_lit: 250,
        umbra: 350,
    });
}

#[test]
fn sun_straight_up() {
    // Seen from above, nothing faces a sun below the ground: no pixel is evaluated, so there
    // is no rate to judge; every drawn pixel must be left dark (n·l = 0, shadow not sampled).
    let above = judge("sun straight up, from above", &Case::sun(Vec3::Y).desc(), 96, 64);
    assert!(above.drawn >= 4000, "{} pixels drawn", above.drawn);
    assert_eq!(above.evaluated, 0, "a surface facing away from the sun was shaded");
    let a = &above.analysis;
    let dark = (0..a.shadow.len())
        .filter(|&i| a.position[i].is_finite() && a.n_dot_l[i] == 0.0 && !a.evaluated[i])
        .count() as u64;
    assert_eq!(dark, above.drawn, "every drawn pixel is unlit");
}

#[test]
fn sun_two_degrees_above_the_horizon() {
    let case = Case::sun(sun_at_elevation(2.0));
    judge("sun 2° above the horizon", &case.desc(), 128, 96).assert_judged(&Floors {
        judged: 6000,
        ground_lit: 5000,
        caster_lit: 500,
        umbra: 300,
    });
}

#[test]
fn thirty_two_bit_sun_depth_meets_the_same_limits() {
    // Straight down, 2° above the horizon, and 100 km from the origin: the same floors and
    // limits as with the default 16-bit depth (the tests above), with the layers in
    // `Depth32Float`.
    let options = RenderOptions {
        sun_depth: SunDepth::Float32,
        ..RenderOptions::default()
    };
    let down = Case::sun(Vec3::NEG_Y).desc();
    judge_with("32-bit: sun straight down", &down, (96, 64), options).assert_judged(&Floors {
        judged: 3000,
        ground_lit: 2000,
        caster_lit: 250,
        umbra: 350,
    });
    let low = Case::sun(sun_at_elevation(2.0)).desc();
    judge_with("32-bit: sun 2° above the horizon", &low, (128, 96), options).assert_judged(&Floors {
        judged: 6000,
        ground_lit: 5000,
        caster_lit: 500,
        umbra: 300,
    });
    let shift = Vec3::new(1.0e5, 0.0, 1.0e5);
    let mut far = Case::default().desc();
    far.camera.position += shift;
    far.camera.target += shift;
    for object in &mut far.objects {
        object.translation += shift;
    }
    judge_with("32-bit: 100 km from the origin", &far, (96, 64), options).assert_judged(&Floors {
        judged: 3000,
        ground_lit: 2400,
        caster_lit: 300,
        umbra: 250,
    });
}

#[test]
fn camera_far_from_the_origin() {
    let floors = Floors {
        judged: 3000,
        ground_lit: 2400,
        caster_lit: 300,
        umbra: 250,
    };
    let origin = judge("at the origin", &Case::default().desc(), 96, 64);
    origin.assert_judged(&floors);
    for offset in [1.0e5f32, 1.0e6] {
        let shift = Vec3::new(offset, 0.0, offset);
        let mut desc = Case::default().desc();
        desc.camera.position += shift;
        desc.camera.target += shift;
        for object in &mut desc.objects {
            object.translation += shift;
        }
        let far = judge(&format!("{offset} m from the origin"), &desc, 96, 64);
        far.assert_judged(&floors);
        for (far_mae, origin_mae) in far.mae().into_iter().zip(origin.mae()) {
            assert!(
                far_mae <= origin_mae + FAR_MAE_MARGIN,
                "{offset} m: MAE {far_mae:.4} vs {origin_mae:.4} at the origin",
            );
        }
    }
}

#[test]
fn extreme_near_far_ratios() {
    // Everything a 1 m far plane can see: the edge of the slab's shadow, from 0.74 m away.
    let close = Case {
        camera: Vec3::new(3.25, 0.35, -0.3),
        target: Vec3::new(3.25, 0.0, -0.95),
        near: 1.0e-3,
        far: 1.0,
        ..Case::default()
    };
    // No caster face is in view: the floor on lit caster pixels is 0 here.
    // NOTE: its umbra is 270 pixels, one row of which borders the penumbra, where PCSS
    // Medium's 25 taps leave pixels at 0.08–0.12 (k/25 lit): 2 of them over 0.1 here
    // (0.74 %), 3 with cascades fitted to the receivers (1.11 %). The leak limit is 1.5 %
    // (4 pixels) for this case alone.
    judge("near 0.001, far 1", &close.desc(), 64, 48).assert_within(
        &Floors {
            judged: 1000,
            ground_lit: 900,
            caster_lit: 0,
            umbra: 150,
        },
        &Limits { leak: 0.015, ..TARGET },
    );
    for (near, far) in [(0.01f32, 1.0e3), (0.01, 1.0e5), (1.0e-3, 1.0e5)] {
        let case = Case {
            near,
            far,
            ..Case::default()
        };
        judge(&format!("near {near}, far {far}"), &case.desc(), 64, 48).assert_judged(&Floors {
            judged: 1500,
            ground_lit: 1200,
            caster_lit: 180,
            umbra: 150,
        });
    }
}

#[test]
fn camera_looking_along_and_against_the_light() {
    let sun = Vec3::new(0.0, -0.5, -1.0).normalize();
    // Along: from behind the casters, their shadows stretching away; against: from in front
    // of them, their shadows reaching towards the camera.
    let along = Floors {
        judged: 1700,
        ground_lit: 1500,
        caster_lit: 70,
        umbra: 60,
    };
    let against = Floors {
        judged: 1300,
        ground_lit: 1000,
        caster_lit: 15,
        umbra: 220,
    };
    let from_behind = Vec3::new(0.0, 3.0, 12.0);
    for (name, camera, target, floors) in [
        ("along", from_behind, from_behind + sun * 10.0, along),
        (
            "against",
            Vec3::new(0.0, 3.0, -12.0),
            Vec3::new(0.0, 0.0, -2.0),
            against,
        ),
    ] {
        let case = Case {
            sun,
            camera,
            target,
            far: 300.0,
            ..Case::default()
        };
        judge(&format!("looking {name} the light"), &case.desc(), 64, 48).assert_judged(&floors);
    }
}

#[test]
fn one_degree_field_of_view() {
    // A 0.24 m wide view of the edge of the slab's shadow on the ground; no caster in view.
    let narrow = Case {
        target: Vec3::new(3.25, 0.0, -0.95),
        fov: 1.0,
        ..Case::default()
    };
    judge("fov 1°", &narrow.desc(), 64, 48).assert_judged(&Floors {
        judged: 3000,
        ground_lit: 800,
        caster_lit: 0,
        umbra: 1000,
    });
}

#[test]
fn aspect_one_to_ten() {
    judge("aspect 1:10", &Case::default().desc(), 32, 320).assert_judged(&Floors {
        judged: 5000,
        ground_lit: 3500,
        caster_lit: 1200,
        umbra: 200,
    });
}

#[test]
fn scene_bounds_far_larger_than_the_cascades() {
    // A caster 3 km away stretches the scene bounds (and so every cascade's depth range).
    let case = Case {
        extra: r#"(shape: Cuboid(size: (50, 400, 50)), material: "m", translation: (3000, 200, -3000)),"#,
        ..Case::default()
    };
    judge("huge scene bounds", &case.desc(), 96, 64).assert_judged(&Floors {
        judged: 3000,
        ground_lit: 2400,
        caster_lit: 300,
        umbra: 250,
    });
}

#[test]
fn empty_scene_and_one_tiny_caster() {
    let empty = load(
        r#"Scene(camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
                 sun: (direction: (0, -1, 0)), objects: [])"#,
    );
    let nothing = judge("empty scene", &empty, 32, 32);
    assert_eq!(
        (nothing.drawn, nothing.evaluated),
        (0, 0),
        "an empty scene draws nothing"
    );
    let tiny = load(
        r#"Scene(camera: (position: (0, 0.05, 0.1), target: (0, 0, 0), fov: 60, near: 0.001, far: 100),
                 sun: (direction: (0.3, -1, 0)),
                 materials: { "m": () },
                 objects: [
                    (shape: Plane(size: (10, 10)), material: "m", cast_shadows: false),
                    (shape: Cuboid(size: (0.001, 0.001, 0.001)), material: "m", translation: (0, 0.01, 0)),
                 ])"#,
    );
    // The caster is smaller than a pixel: what is judged is that the ground around it stays
    // lit (no umbra pixel to judge leaks on).
    judge("one 1 mm caster", &tiny, 64, 48).assert_judged(&Floors {
        judged: 2000,
        ground_lit: 1700,
        caster_lit: 0,
        umbra: 0,
    });
}

#[test]
fn invalid_transforms_never_poison_the_frame() {
    let desc = Case::default().desc();
    // Scene files reject these; code can still produce them.
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.world_mut().insert_resource(ViewportSize { width: 64, height: 48 });
    spawn_scene(app.world_mut(), &desc).unwrap();
    let world = app.world_mut();
    let mut q = world.query_filtered::<(bevy_ecs::entity::Entity, &mut Transform), bevy_ecs::query::With<Mesh3d>>();
    let poisons: [fn(&mut Transform); 3] = [
        |t| t.translation.x = f32::NAN,
        |t| t.scale = Vec3::ZERO,
        |t| t.translation.y = f32::INFINITY,
    ];
    // The first mesh is the ground; poison three of the casters.
    let mut poisoned = Vec::new();
    for ((entity, mut t), poison) in q.iter_mut(world).skip(1).zip(poisons) {
        poison(&mut t);
        poisoned.push(entity);
    }
    // Scene objects are static: marked again, each is placed and synced once more.
    for entity in poisoned {
        world.entity_mut(entity).insert(penumbra::ecs::Static);
    }
    app.update();
    let world = app.world();
    assert_eq!(world.resource::<RenderInstances>().skipped, 3);
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    assert!(
        warnings.iter().any(|w| w.starts_with("3 mesh entities are not drawn")),
        "{warnings:?}"
    );
    let sun = *world.resource::<FrameLights>().sun().unwrap();
    assert!(sun.cascades.active().iter().all(|c| c.clip_from_world.is_finite()));
    assert!(world.resource::<ShadowStats>().casters_per_view.iter().any(|&c| c > 0));
    let mut renderer = Renderer::headless_with_analysis(64, 48).unwrap_or_else(|e| panic!("{e}"));
    renderer.render(&FrameInputs::from_world(world, 0));
    let a = renderer.read_analysis().unwrap();
    assert!(
        a.shadow.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
        "bad shadow factor"
    );
    let evaluated = a.evaluated.iter().filter(|&&e| e).count();
    assert!(
        evaluated >= 1000,
        "the rest of the scene is still shaded: {evaluated} pixels"
    );
}

#[test]
fn cascade_count_and_resolution_change_between_frames() {
    let desc = Case::default().desc();
    let mut session = SceneSession::new(&desc, 64, 48).unwrap();
    let mut renderer = Renderer::headless_with_analysis(64, 48).unwrap_or_else(|e| panic!("{e}"));
    let changes: [fn(&mut ShadowSettings); 4] = [
        |s| s.map.cascades.count = 1,
        |s| {
            s.map.cascades.count = 4;
            s.map.resolution = 512;
        },
        |s| s.map.resolution = 2048,
        |s| s.map.cascades.count = 3,
    ];
    // The cascades' array is recreated for a new resolution or more cascades, never for
    // fewer: (side, layers) allocated so far.
    let mut allocated = (0u64, 0u64);
    for (frame, change) in changes.iter().enumerate() {
        session.apply_settings(*change);
        session.update();
        let report = renderer
            .render(&FrameInputs::from_world(session.app.world(), frame as u32))
            .clone();
        let a = renderer.read_analysis().unwrap();
        assert!(a.shadow.iter().all(|v| v.is_finite()), "frame {frame}: NaN");
        let count = session.lights().sun().unwrap().settings.map.cascades.count as u8;
        let shaded = a.cascade.iter().filter(|&&c| c < count).count();
        assert!(a.cascade.iter().all(|&c| c == 255 || c < count), "frame {frame}");
        assert!(shaded >= 1000, "frame {frame}: {shaded} pixels sampled a cascade");
        let resolution = session.lights().sun().unwrap().settings.map.resolution as u64;
        if allocated.0 != resolution || allocated.1 < u64::from(count) {
            allocated = (resolution, u64::from(count));
        }
        let (side, layers) = allocated;
        let texel = u64::from(depth_texel_bytes(RenderOptions::default().sun_depth.format()));
        assert_eq!(report.shadow_memory, side * side * texel * layers, "frame {frame}");
    }
}

#[test]
fn sub_texel_camera_translation_does_not_shimmer() {
    let mut desc = Case::sun(SUN).desc();
    desc.shadows.map.cascades.blend_width = 0.0;
    desc.shadows.filter.distance_fade_width = 0.0;
    let (w, h) = (96, 64);
    let mut session = SceneSession::new(&desc, w, h).unwrap();
    let mut renderer = Renderer::headless_with_analysis(w, h).unwrap_or_else(|e| panic!("{e}"));
    session.update();
    renderer.render(&FrameInputs::from_world(session.app.world(), 0));
    let a = renderer.read_analysis().unwrap();
    let probes: Vec<ProbeGpu> = (0..a.shadow.len())
        .filter(|&i| a.evaluated[i])
        .map(|i| ProbeGpu::new(a.position[i], a.normal[i], ((i as u32) % w, (i as u32) / w)))
        .collect();
    let texel = session.lights().sun().unwrap().cascades.cascades[0].texel_world_size;
    let mut frames = Vec::new();
    for k in 0..6 {
        let t = k as f32 * 0.15 * texel;
        session.move_camera(Vec3::new(t, 0.3 * t, -0.2 * t), 0.0);
        session.update();
        renderer.render(&FrameInputs::from_world(session.app.world(), 0));
        frames.push(renderer.evaluate_probes(&FrameInputs::from_world(session.app.world(), 0), &probes));
    }
    let spread = shimmer(&frames);
    assert!(spread.points > 500, "{} points followed", spread.points);
    assert!(
        spread.unstable_fraction < 0.002,
        "sub-texel moves change the shadow: {spread:?}"
    );
    assert!(spread.mean_spread < 1e-3, "{spread:?}");
}

/// A camera under the roof, 1.6 m above its shadow, so that very wide views still see the
/// shadows large. Views wider than 120° pull the cascade splits in (`wide_view_splits`):
/// with the PSSM splits alone cascade 0 of the 150° view had 3.4 cm texels and of the 170° view
/// 10.5 cm, against a 5.8 cm penumbra, and blurred every shadow edge over lit pixels.
const WIDE_CAMERA: Vec3 = Vec3::new(-2.5, 1.6, 2.0);
/// What the wide views look at.
const WIDE_TARGET: Vec3 = Vec3::new(-1.5, 0.0, 0.5);

#[test]
fn one_hundred_and_fifty_degree_field_of_view() {
    let wide = Case {
        fov: 150.0,
        camera: WIDE_CAMERA,
        target: WIDE_TARGET,
        ..Case::default()
    };
    judge("fov 150°", &wide.desc(), 128, 96).assert_judged(&Floors {
        judged: 4500,
        ground_lit: 1500,
        caster_lit: 130,
        umbra: 3000,
    });
}

#[test]
fn aspect_ten_to_one() {
    let wide = Case {
        camera: WIDE_CAMERA,
        target: WIDE_TARGET,
        ..Case::default()
    };
    // NOTE: 960×96 so that the casters' lit faces, a thin strip of this view, cover over 600
    // pixels (at 320×32 they covered 70, where one pixel was 1.4 %).
    judge("aspect 10:1", &wide.desc(), 960, 96).assert_judged(&Floors {
        judged: 60_000,
        ground_lit: 50_000,
        caster_lit: 500,
        umbra: 9_000,
    });
}

#[test]
fn sun_half_a_degree_above_the_horizon() {
    let case = Case::sun(sun_at_elevation(0.5));
    // The casters' top faces meet the light at 0.5°, a slope of 115 that the receiver-plane
    // bias clamps at 40: PCSS compares its wide search and kernel with the true plane too.
    judge("sun 0.5° above the horizon", &case.desc(), 128, 96).assert_judged(&Floors {
        judged: 6000,
        ground_lit: 5000,
        caster_lit: 500,
        umbra: 300,
    });
}

#[test]
fn sun_straight_up_seen_from_below() {
    // Under the roof, looking up at its underside over the box: the undersides face a sun
    // straight up, and the box (0.85 m below) shades a 2 × 0.5 m patch of the roof's underside.
    // NOTE: this framing judges about 750 umbra pixels; the view from under the ground judged
    // 25, where one pixel was 4 %.
    let below = Case {
        sun: Vec3::Y,
        camera: Vec3::new(0.0, 1.8, 2.0),
        target: Vec3::new(0.0, 2.85, 0.75),
        ..Case::default()
    };
    judge("sun straight up, from below", &below.desc(), 96, 64).assert_judged(&Floors {
        judged: 2500,
        ground_lit: 0,
        caster_lit: 1800,
        umbra: 500,
    });
}

#[test]
fn one_hundred_and_seventy_degree_field_of_view() {
    let wide = Case {
        fov: 170.0,
        camera: WIDE_CAMERA,
        target: WIDE_TARGET,
        ..Case::default()
    };
    judge("fov 170°", &wide.desc(), 128, 96).assert_judged(&Floors {
        judged: 4000,
        ground_lit: 1300,
        caster_lit: 100,
        umbra: 2500,
    });
}
