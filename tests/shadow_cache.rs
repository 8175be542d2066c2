//! Cached shadow views: a still scene draws its shadow maps once; every change a user can
//! make (a caster moving inside a view, out of it, a light turning, a setting, the camera)
//! draws again exactly the views it touches; and after every change the cached image equals
//! the image of a renderer that draws every map every frame.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::world::World;
use common::spawn_box;
use glam::{Quat, Vec3, Vec4};
use image::RgbaImage;
use penumbra::ecs::{Camera3d, DirectionalLight, ShadowViewKind, ShadowViews, SpotLight, Transform};
use penumbra::render::Renderer;
use penumbra::settings::{CascadeFit, ShadowSettings};

/// The same scene in two renderers: with the cache, and drawing every map every frame.
struct Pair {
    cached: App,
    fresh: App,
    cube: [Entity; 2],
}

fn app(scene: &str, cache: bool) -> (App, Entity) {
    let mut app = common::cached_scene(scene, cache);
    // NOTE: held cascades: a scrolling one draws a moved caster by region, not whole.
    common::hold_cascades(&mut app);
    let world = app.world_mut();
    let cube = spawn_box(
        world,
        Vec3::new(0.6, 1.2, 0.6),
        Vec4::new(0.9, 0.3, 0.3, 1.0),
        Vec3::new(-7.0, 0.6, -4.0),
    );
    app.update();
    (app, cube)
}

impl Pair {
    fn new(scene: &str) -> Self {
        let (cached, a) = app(scene, true);
        let (fresh, b) = app(scene, false);
        Self {
            cached,
            fresh,
            cube: [a, b],
        }
    }

    /// Applies `edit` to both worlds (with the cube's entity in each) and renders a frame.
    fn frame(&mut self, edit: impl Fn(&mut World, Entity)) {
        edit(self.cached.world_mut(), self.cube[0]);
        edit(self.fresh.world_mut(), self.cube[1]);
        self.cached.update();
        self.fresh.update();
    }

    fn drawn(&self) -> u32 {
        self.cached
            .world()
            .resource::<Renderer>()
            .last_report
            .shadow_views_drawn
    }

    /// Content versions of the cached world's views: (is spot, version).
    fn versions(&self) -> Vec<(bool, u64)> {
        let views = self.cached.world().resource::<ShadowViews>();
        views
            .views
            .iter()
            .map(|v| (v.kind == ShadowViewKind::SPOT, v.version))
            .collect()
    }

    /// Asserts the cached image equals the always-drawn one.
    fn same_image(&self, what: &str) {
        let image = |app: &App| -> RgbaImage { app.world().resource::<Renderer>().read_image() };
        let (a, b) = (image(&self.cached), image(&self.fresh));
        let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert_eq!(
            differing, 0,
            "{what}: {differing} pixels differ from a renderer without the cache"
        );
    }
}

/// Indices of the views whose version differs between two frames.
fn changed(before: &[(bool, u64)], after: &[(bool, u64)]) -> Vec<usize> {
    assert_eq!(before.len(), after.len());
    (0..before.len()).filter(|&i| before[i] != after[i]).collect()
}

fn move_cube(to: Vec3) -> impl Fn(&mut World, Entity) {
    move |world, cube| world.get_mut::<Transform>(cube).unwrap().translation = to
}

#[test]
fn a_still_scene_draws_its_shadow_maps_once() {
    let mut pair = Pair::new("assets/scenes/default.ron");
    assert_eq!(pair.drawn(), 4, "the first frame draws every cascade");
    for _ in 0..3 {
        pair.frame(|_, _| {});
        let report = &pair.cached.world().resource::<Renderer>().last_report;
        assert_eq!((report.shadow_views_drawn, report.shadow_draw_calls), (0, 0));
        let fresh = &pair.fresh.world().resource::<Renderer>().last_report;
        assert_eq!(fresh.shadow_views_drawn, 4, "without the cache every view is drawn");
    }
    pair.same_image("still frames");
}

#[test]
fn every_change_draws_again_exactly_the_views_it_touches() {
    // Two suns (4 + 3 cascades), then four spot lights: 11 views.
    let mut pair = Pair::new("assets/scenes/lights.ron");
    let spots = |v: &[(bool, u64)]| (0..v.len()).filter(|&i| v[i].0).collect::<Vec<_>>();
    // The view of the red spot light at (-6, 5, -3), over the cube.
    let world = pair.cached.world_mut();
    let mut lights = world.query::<(Entity, &SpotLight, &Transform)>();
    let red = lights
        .iter(world)
        .find(|(_, _, t)| t.translation.distance(Vec3::new(-6.0, 5.0, -3.0)) < 1e-3)
        .expect("the red spot light")
        .0;
    let views = &pair.cached.world().resource::<ShadowViews>().views;
    let over_cube = views.iter().position(|v| v.entity == red).expect("its view");
    pair.frame(|_, _| {});
    assert_eq!(pair.drawn(), 0);

    // The cube moves a little under the red spot light: that spot view is drawn again (and
    // the cascades over it), the three other spot lights are not.
    let before = pair.versions();
    pair.frame(move_cube(Vec3::new(-6.5, 0.6, -4.2)));
    let moved = changed(&before, &pair.versions());
    assert!(moved.contains(&over_cube), "{moved:?}");
    let others: Vec<usize> = spots(&before).into_iter().filter(|&s| s != over_cube).collect();
    assert_eq!(others.len(), 3);
    assert!(others.iter().all(|s| !moved.contains(s)), "{moved:?}");
    assert_eq!(pair.drawn() as usize, moved.len());
    pair.same_image("a caster moved inside a spot light");
    pair.frame(|_, _| {});
    assert_eq!(pair.drawn(), 0, "nothing changed since");

    // Out of every view: the views it left are drawn again without it.
    let before = pair.versions();
    pair.frame(move_cube(Vec3::new(500.0, 0.6, 500.0)));
    let left = changed(&before, &pair.versions());
    assert!(left.contains(&over_cube), "{left:?}");
    assert_eq!(pair.drawn() as usize, left.len());
    pair.same_image("a caster left the views");

    // The second sun turns: its three cascades only.
    let before = pair.versions();
    pair.frame(|world, _| {
        let mut suns = world.query::<(&DirectionalLight, &mut Transform)>();
        let mut second = suns.iter_mut(world).nth(1).expect("two suns").1;
        second.rotation = Quat::from_rotation_y(0.2) * second.rotation;
    });
    let turned = changed(&before, &pair.versions());
    assert_eq!(turned.len(), 3, "{turned:?}");
    assert!(turned.iter().all(|&i| !before[i].0), "a spot view changed: {turned:?}");
    pair.same_image("a sun turned");

    // A spot light's settings: its view only.
    let before = pair.versions();
    pair.frame(|world, _| {
        let mut spots = world.query::<(&SpotLight, &mut ShadowSettings)>();
        let (_, mut s) = spots.iter_mut(world).next().expect("a spot light with settings");
        s.bias.slope_bias += 1.0;
    });
    let set = changed(&before, &pair.versions());
    assert_eq!(set.len(), 1, "{set:?}");
    assert!(before[set[0]].0);
    assert_eq!(pair.drawn(), 1);
    pair.same_image("a spot light's settings");

    // The first sun's resolution: the cascades' storage is allocated again (its side is the
    // largest cascade's), so every cascade of both suns is drawn into it; no spot view is.
    pair.frame(|world, _| {
        let mut suns = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
        let (_, mut s) = suns.iter_mut(world).next().expect("a sun");
        s.map.resolution = 1024;
    });
    assert_eq!(pair.drawn(), 7);
    pair.same_image("a sun's resolution");
    pair.frame(|_, _| {});
    assert_eq!(pair.drawn(), 0);

    // The camera moves: the cascades follow it (tight fit), the spot views stay.
    let before = pair.versions();
    pair.frame(|world, _| {
        let mut cameras = world.query::<(&Camera3d, &mut Transform)>();
        let (_, mut t) = cameras.iter_mut(world).next().expect("a camera");
        t.translation += Vec3::new(0.5, 0.0, 0.3);
    });
    let followed = changed(&before, &pair.versions());
    assert!(!followed.is_empty());
    assert!(
        followed.iter().all(|&i| !before[i].0),
        "a spot view changed: {followed:?}"
    );
    pair.same_image("the camera moved");
}

#[test]
fn a_camera_turn_that_moves_no_stable_cascade_draws_nothing() {
    // Stable cascades do not change when the camera turns in place, while the
    // receiver-bounded cull boxes follow its view (in whole cells of the cascades' grid: a
    // turn of 0.01 rad moves them, one of 0.002 rad no longer does). The casters found are
    // the same, so no map is drawn; tight cascades follow the view and are drawn again.
    for (fit, redrawn) in [(CascadeFit::Stable, false), (CascadeFit::Tight, true)] {
        let mut pair = Pair::new("assets/scenes/default.ron");
        pair.frame(|world, _| {
            let mut suns = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
            for (_, mut s) in suns.iter_mut(world) {
                s.map.cascades.fit = fit;
            }
        });
        pair.frame(|_, _| {});
        assert_eq!(pair.drawn(), 0, "{fit:?}: still");
        let volumes = |pair: &Pair| -> Vec<_> {
            let views = pair.cached.world().resource::<ShadowViews>();
            views.views.iter().map(|v| v.cull).collect()
        };
        let before = volumes(&pair);
        pair.frame(|world, _| {
            let mut cameras = world.query::<(&Camera3d, &mut Transform)>();
            let (_, mut t) = cameras.iter_mut(world).next().expect("a camera");
            t.rotation = Quat::from_rotation_y(0.01) * t.rotation;
        });
        assert_ne!(before, volumes(&pair), "{fit:?}: the cull boxes follow the view");
        assert_eq!(pair.drawn() > 0, redrawn, "{fit:?}: drawn {}", pair.drawn());
        pair.same_image("a small camera turn");
    }
}
