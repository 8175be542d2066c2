//! Clipmap levels whose layers wrap (lavapipe): after a walk that moved every level's window,
//! each level of a depth-filtered sun (PCF, PCSS) holds its window's first texel away from its
//! layer's first texel, and the image equals the image of a renderer that drew the same view
//! fresh (every layer holding its window at its first texel); a sun filtering moments moves its
//! layers instead.

mod common;

use bevy_app::App;
use common::clipmap::{long_field_filtered, long_field_unrendered, walk};
use glam::Vec3;
use penumbra::ecs::{Camera3d, ShadowViews, Transform};
use penumbra::layout::ShadowStorage;
use penumbra::render::Renderer;
use penumbra::settings::ShadowMode;

/// The origins of `app`'s scrolling views this frame (None: moved, not wrapped).
fn origins(app: &App) -> Vec<Option<[u32; 2]>> {
    let views = app.world().resource::<ShadowViews>();
    views.views.iter().filter_map(|v| v.scroll).map(|s| s.origin).collect()
}

/// The camera's transform.
fn camera(app: &mut App) -> Transform {
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<&Transform, bevy_ecs::query::With<Camera3d>>();
    *cameras.single(world).expect("one camera")
}

/// Walks `mode`'s clipmap, then renders the same view fresh; returns both apps.
fn walked_and_fresh(mode: ShadowMode) -> (App, App) {
    let mut walked = long_field_filtered(512, true, mode);
    for step in [
        Vec3::new(0.4, 0.0, -1.3),
        Vec3::new(-0.9, 0.0, -0.6),
        Vec3::new(0.2, 0.0, -1.7),
        Vec3::new(1.1, 0.0, 0.3),
    ] {
        walk(&mut walked, step, 0.0);
        walked.update();
    }
    let at = camera(&mut walked);
    let mut fresh = long_field_unrendered(512, true, mode);
    let world = fresh.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, bevy_ecs::query::With<Camera3d>>();
    for mut t in cameras.iter_mut(world) {
        *t = at;
    }
    fresh.update();
    (walked, fresh)
}

/// The largest difference of any channel between two apps' images, and how many pixels
/// differ by more than one level; prints both.
fn compare(name: &str, a: &App, b: &App) -> (u8, usize) {
    let (a, b) = (
        a.world().resource::<Renderer>().read_image(),
        b.world().resource::<Renderer>().read_image(),
    );
    let (mut largest, mut over_one) = (0, 0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        largest = largest.max(d);
        over_one += usize::from(d > 1);
    }
    println!(
        "{name}: largest difference {largest}, {over_one} of {} pixels over 1",
        a.len() / 4
    );
    (largest, over_one)
}

/// Checks that PCF and PCSS levels wrap after a walk (every level's origin away from the
/// layer's first texel, none drawn whole, each holding casters) and shade as levels drawn
/// fresh at the same camera.
#[test]
fn wrapped_levels_shade_as_levels_drawn_fresh() {
    for mode in [ShadowMode::Pcf, ShadowMode::Pcss] {
        let (walked, fresh) = walked_and_fresh(mode);
        let (moved, start) = (origins(&walked), origins(&fresh));
        println!("{mode:?}: origins after the walk {moved:?}, fresh {start:?}");
        assert_eq!(moved.len(), 6, "{mode:?}: {moved:?}");
        assert!(
            moved.iter().all(|o| o.is_some_and(|o| o != [0, 0])),
            "{mode:?}: a level did not wrap: {moved:?}"
        );
        assert!(start.iter().all(|o| *o == Some([0, 0])), "{mode:?}: {start:?}");
        let report = &walked.world().resource::<Renderer>().last_report;
        assert_eq!(report.shadow_views_drawn, 0, "{mode:?}: a level was drawn whole");
        let renderer = walked.world().resource::<Renderer>();
        for slot in 0..6 {
            let layer = renderer
                .read_shadow_map(ShadowStorage::Cascades, slot)
                .expect("a level");
            let covered = layer.iter().filter(|&&d| d > 0.0).count();
            assert!(
                covered > 1000,
                "{mode:?}: level {slot} holds only {covered} caster texels"
            );
        }
        let (largest, over_one) = compare(&format!("{mode:?}"), &walked, &fresh);
        assert!(
            largest <= 1 && over_one == 0,
            "{mode:?}: the wrapped levels shade differently: up to {largest} ({over_one} pixels over 1)"
        );
    }
}

/// Checks that a sun filtering moments keeps moving its layers (no origin).
#[test]
fn moment_levels_move_instead() {
    let (walked, _) = walked_and_fresh(ShadowMode::Evsm);
    let moved = origins(&walked);
    assert_eq!(moved.len(), 6);
    assert!(moved.iter().all(Option::is_none), "{moved:?}");
}
