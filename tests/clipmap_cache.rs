//! A sun's clipmap keeping its levels on a real wgpu device (lavapipe in CI): a level drawn
//! whole from a caster list of an earlier window (its layer lost) is drawn again from a fresh
//! list the next frame; and a clipmap whose levels are smaller than the layers of the storage
//! it shares with a cascaded sun still scrolls, and holds what levels drawn whole hold.

mod common;

use common::clipmap::{first_sun_levels, long_field_with, walk};
use glam::Vec3;

#[test]
fn a_level_drawn_from_an_earlier_windows_list_is_drawn_again_the_next_frame() {
    use penumbra::ecs::Transform;
    use penumbra::ecs::components::DirectionalLight;
    use penumbra::render::Renderer;
    use penumbra::settings::ShadowSettings;
    let resolution = 512;
    let mut scrolled = long_field_with(resolution, true);
    let mut whole = long_field_with(resolution, false);
    for _ in 0..4 {
        for app in [&mut scrolled, &mut whole] {
            walk(app, Vec3::new(0.0, 0.0, -6.0), 0.0);
            app.update();
        }
    }
    // NOTE: a second sun grows the cascades' storage, so every level's layer is lost while
    // its caster list is still the one culled for the first window.
    let mut sun = None;
    for app in [&mut scrolled, &mut whole] {
        let world = app.world_mut();
        let mut suns = world.query::<(bevy_ecs::entity::Entity, &DirectionalLight, &ShadowSettings)>();
        let (entity, light, settings) = suns.iter(world).next().expect("the field's sun");
        let (light, settings) = (*light, *settings);
        sun = Some(entity);
        let transform = Transform::from_translation(Vec3::ZERO).looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y);
        world.spawn((light, settings, transform));
        app.update();
    }
    let sun = sun.unwrap();
    let report = &scrolled.world().resource::<Renderer>().last_report;
    let resynced = report.shadow_views_resynced;
    println!(
        "the frame the storage grew: {} views drawn, {resynced} from an earlier window's list",
        report.shadow_views_drawn
    );
    assert!(resynced >= 1, "no level was drawn from an earlier window's list");
    for app in [&mut scrolled, &mut whole] {
        app.update();
    }
    let report = &scrolled.world().resource::<Renderer>().last_report;
    assert_eq!(report.shadow_views_resynced, 0, "a list was still stale");
    assert!(
        report.shadow_views_drawn >= resynced,
        "{} views drawn again, {resynced} had stale lists",
        report.shadow_views_drawn
    );
    let (kept, fresh) = (first_sun_levels(&scrolled, sun), first_sun_levels(&whole, sun));
    assert_eq!(kept.len(), 6, "the first sun's levels");
    for (level, (kept, fresh)) in kept.iter().zip(&fresh).enumerate() {
        let covered = fresh.iter().filter(|&&d| d > 0.0).count();
        let differ = kept.iter().zip(fresh).filter(|(x, y)| (**x - **y).abs() > 2e-6).count();
        println!("level {level}: {covered} texels hold a caster, {differ} differ");
        assert!(covered > 1000, "level {level}: only {covered} texels hold a caster");
        assert_eq!(
            differ, 0,
            "level {level}: {differ} texels differ from the level drawn whole"
        );
    }
}

#[test]
fn a_clipmap_sharing_its_storage_with_larger_cascades_still_scrolls() {
    use penumbra::ecs::Transform;
    use penumbra::ecs::components::DirectionalLight;
    use penumbra::layout::ShadowStorage;
    use penumbra::render::Renderer;
    use penumbra::settings::{ShadowSettings, SunLayout};
    let mut scrolled = long_field_with(512, true);
    let mut whole = long_field_with(512, false);
    // NOTE: a second sun on 1024² cascades makes the storage's layers twice the side of the
    // clipmap's levels, which live in their top-left corners.
    let mut sun = None;
    for app in [&mut scrolled, &mut whole] {
        let world = app.world_mut();
        let mut suns = world.query::<(bevy_ecs::entity::Entity, &DirectionalLight, &ShadowSettings)>();
        let (entity, light, settings) = suns.iter(world).next().expect("the field's sun");
        let (light, mut settings) = (*light, *settings);
        sun = Some(entity);
        settings.map.resolution = 1024;
        settings.map.layout = SunLayout::default();
        let transform = Transform::from_translation(Vec3::ZERO).looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y);
        world.spawn((light, settings, transform));
        app.update();
    }
    let sun = sun.unwrap();
    let mut moved = 0;
    for step in [
        Vec3::new(0.7, 0.0, -1.9),
        Vec3::new(-1.3, 0.0, -0.4),
        Vec3::new(0.2, 0.0, -2.6),
    ] {
        for app in [&mut scrolled, &mut whole] {
            walk(app, step, 0.0);
            app.update();
        }
        moved += scrolled
            .world()
            .resource::<Renderer>()
            .last_report
            .shadow_views_scrolled;
    }
    let side = scrolled
        .world()
        .resource::<Renderer>()
        .storage_resolution(ShadowStorage::Cascades);
    assert_eq!(side, Some(1024), "the storage's layers are the cascades' side");
    assert!(moved >= 6, "only {moved} levels scrolled over three steps");
    let (kept, fresh) = (first_sun_levels(&scrolled, sun), first_sun_levels(&whole, sun));
    assert_eq!(kept.len(), 6, "the clipmap's levels");
    for (level, (kept, fresh)) in kept.iter().zip(&fresh).enumerate() {
        let corner = |layer: &[f32]| -> Vec<f32> {
            (0..512)
                .flat_map(|y| layer[y * 1024..y * 1024 + 512].to_vec())
                .collect()
        };
        let (kept, fresh) = (corner(kept), corner(fresh));
        let covered = fresh.iter().filter(|&&d| d > 0.0).count();
        let differ = kept
            .iter()
            .zip(&fresh)
            .filter(|(x, y)| (**x - **y).abs() > 2e-6)
            .count();
        println!("level {level}: {covered} texels hold a caster, {differ} differ");
        assert!(covered > 1000, "level {level}: only {covered} texels hold a caster");
        assert_eq!(
            differ, 0,
            "level {level}: {differ} texels differ from the level drawn whole"
        );
    }
}
