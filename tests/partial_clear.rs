//! Partial clears of shadow layers: a redrawn layer clears only the rectangle its last draw
//! wrote. After a caster moves (leaving texels behind that must go back to the far depth) and
//! after the light turns, every layer must equal the layer a fresh renderer draws from
//! scratch (whole-layer clears), texel by texel, for cascades and spot lights.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::world::World;
use common::{spawn_box, still_scene};
use glam::{Quat, Vec3, Vec4};
use penumbra::ecs::{DirectionalLight, ShadowStorage, SpotLight, Transform};
use penumbra::render::Renderer;

/// Where the test puts things: the cube and a turn of the scene's lights.
#[derive(Clone, Copy)]
struct State {
    cube: Vec3,
    turn: f32,
}

/// `scene` with a cube at `state`, after `frames` frames.
fn app(scene: &str, state: State) -> (App, Entity) {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, scene);
    let world = app.world_mut();
    let cube = spawn_box(
        world,
        Vec3::new(0.8, 1.6, 0.8),
        Vec4::new(0.3, 0.4, 0.9, 1.0),
        state.cube,
    );
    apply(world, cube, state);
    app.update();
    (app, cube)
}

/// Moves the cube and turns every light about the vertical by `state.turn` radians.
fn apply(world: &mut World, cube: Entity, state: State) {
    world.get_mut::<Transform>(cube).unwrap().translation = state.cube;
    let turn = Quat::from_rotation_y(state.turn);
    let mut suns = world.query::<(&DirectionalLight, &mut Transform)>();
    for (_, mut t) in suns.iter_mut(world) {
        t.rotation = turn * t.rotation;
    }
    let mut spots = world.query::<(&SpotLight, &mut Transform)>();
    for (_, mut t) in spots.iter_mut(world) {
        t.rotation = turn * t.rotation;
    }
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// Every layer of the cascades' or the spot lights' storage.
fn maps(app: &App, storage: ShadowStorage) -> Vec<Vec<f32>> {
    (0..)
        .map_while(|layer| renderer(app).read_shadow_map(storage, layer))
        .collect()
}

/// Runs `steps` on one app and, after each, compares its maps with a fresh app's; returns
/// the texels the kept app cleared and the texels of its layers, over all steps.
fn follow(scene: &str, storage: ShadowStorage, steps: &[State]) -> (u64, u64) {
    let (mut kept, cube) = app(scene, steps[0]);
    let (mut cleared, mut layer_texels) = (0, 0);
    for (i, &state) in steps.iter().enumerate().skip(1) {
        // Light turns apply on top of the last: give the kept app only this step's turn.
        let delta = State {
            turn: state.turn - steps[i - 1].turn,
            ..state
        };
        apply(kept.world_mut(), cube, delta);
        kept.update();
        let report = &renderer(&kept).last_report;
        cleared += report.shadow_cleared_texels;
        let fresh_state = State {
            turn: state.turn,
            ..state
        };
        let (fresh, _) = app(scene, fresh_state);
        let (a, b) = (maps(&kept, storage), maps(&fresh, storage));
        let covered: usize = common::equal_layers(&format!("{scene} step {i}"), &a, &b).iter().sum();
        layer_texels += a.iter().map(|l| l.len() as u64).sum::<u64>();
        assert!(
            covered >= 1000,
            "{scene} step {i}: only {covered} covered texels to judge"
        );
    }
    (cleared, layer_texels)
}

#[test]
fn cascades_after_a_caster_moves_and_the_sun_turns_equal_a_fresh_draw() {
    let at = |x: f32, z: f32, turn: f32| State {
        cube: Vec3::new(x, 0.8, z),
        turn,
    };
    let steps = [
        at(2.0, -3.0, 0.0),
        at(3.5, -3.0, 0.0),
        at(1.0, -9.0, 0.0),
        at(1.0, -9.0, 0.05),
    ];
    let (cleared, texels) = follow("assets/bench/boxes.ron", ShadowStorage::Cascades, &steps);
    // The moves clear far less than whole layers would (the turn moves every footprint).
    assert!(cleared < texels / 2, "cleared {cleared} of {texels} texels");
}

#[test]
fn spot_lights_after_a_caster_moves_and_the_lights_turn_equal_a_fresh_draw() {
    let at = |x: f32, z: f32, turn: f32| State {
        cube: Vec3::new(x, 0.8, z),
        turn,
    };
    // Under the red spot light of lights.ron, at (-6, 5, -3).
    let steps = [at(-7.0, -4.0, 0.0), at(-6.2, -3.5, 0.0), at(-6.2, -3.5, 0.1)];
    let (cleared, texels) = follow("assets/scenes/lights.ron", ShadowStorage::Spots, &steps);
    // The spot lights' casters cover much of their maps: some layers are cleared whole.
    assert!(cleared < texels, "cleared {cleared} of {texels} texels");
}
