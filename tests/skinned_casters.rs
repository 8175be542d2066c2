//! Skinned, animated casters on the GPU (lavapipe): the walker scene's shadows, with every
//! walker skinned by the compute pass, equal the shadows of the same walkers posed on the CPU
//! into static meshes, at several times of the walk (so neither the skinning nor the bounds
//! from the animated joints lose a shadow); the shadows move with the animation; and a moving
//! walker redraws only the shadow views it touches, a paused one none. Alpha-masked skinned
//! materials go through the masked pipelines from the same posed vertices, and the sun's
//! clipmap and paged clipmap draw the same posed vertices as its cascades.

use bevy_ecs::entity::Entity;
use bevy_ecs::world::World;
use glam::Vec3;
use penumbra::bench::session::SceneSession;
use penumbra::ecs::{
    AlphaMode, AnimationPlayer, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, RenderInstances, SkinSources,
    SkinnedMesh,
};
use penumbra::math::skinning::{skin_normal, skin_position};
use penumbra::mesh::{MeshData, Vertex};
use penumbra::render::Renderer;
use penumbra::render::frame::FrameInputs;
use penumbra::scene::SceneDesc;
use penumbra::settings::{DEFAULT_PAGE_SIZE, DEFAULT_POOL_PAGES, DEFAULT_VIRTUAL_RESOLUTION, SunLayout};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
const SCENE: &str = "assets/scenes/walkers.ron";

fn renderer() -> Renderer {
    Renderer::headless_with_analysis(WIDTH, HEIGHT)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)")
}

/// The walkers' skinned entities (two primitives each), each paused at `time`.
fn pause_walkers(world: &mut World, time: f32) -> Vec<Entity> {
    let mut q = world.query::<(Entity, &mut AnimationPlayer)>();
    q.iter_mut(world)
        .map(|(e, mut p)| {
            p.time = time;
            p.paused = true;
            e
        })
        .collect()
}

/// Replaces every walker's skin by a static mesh of its vertices posed on the CPU.
fn pose_on_the_cpu(world: &mut World, walkers: &[Entity]) {
    for &e in walkers {
        let skin = world.get::<SkinnedMesh>(e).expect("a skinned walker").clone();
        let source = world
            .resource::<SkinSources>()
            .get(skin.source)
            .expect("its bind pose")
            .clone();
        let mesh = world.get::<Mesh3d>(e).expect("a mesh").0;
        let indices = world.resource::<Meshes>().get(mesh).expect("its mesh").indices.clone();
        let vertices: Vec<Vertex> = source
            .vertices
            .iter()
            .zip(&source.influences)
            .map(|(v, i)| Vertex {
                position: skin_position(Vec3::from(v.position), i, &skin.joint_matrices).to_array(),
                normal: skin_normal(Vec3::from(v.normal), i, &skin.joint_matrices).to_array(),
                uv: v.uv,
            })
            .collect();
        let posed = world.resource_mut::<Meshes>().add(MeshData { vertices, indices });
        world
            .entity_mut(e)
            .remove::<(SkinnedMesh, AnimationPlayer)>()
            .insert(Mesh3d(posed));
    }
}

/// The shadow factor of every pixel of one frame of `session`.
fn shadow(session: &mut SceneSession, renderer: &mut Renderer) -> Vec<f32> {
    session.update();
    renderer.render(&FrameInputs::from_world(session.app.world(), 0));
    renderer.read_analysis().expect("analysis targets").shadow
}

/// Gives every walker one alpha-masked material (cutoff 0.5, opaque texels: the cut keeps all).
fn mask_walkers(world: &mut World, walkers: &[Entity]) {
    let masked = world.resource_mut::<Materials>().add(Material {
        base_color: glam::Vec4::new(0.8, 0.3, 0.2, 1.0),
        alpha_mode: AlphaMode::Mask(0.5),
        ..Material::default()
    });
    for &e in walkers {
        world.entity_mut(e).insert(MeshMaterial3d(masked));
    }
}

/// Shadowed pixels of the CPU-posed walkers' frame at `time`, and pixels where the GPU-skinned
/// frame differs from it (alpha-masked walkers with `masked`).
fn compare_with_cpu_posing(desc: &SceneDesc, time: f32, masked: bool) -> (usize, usize) {
    let mut skinned = SceneSession::new(desc, WIDTH, HEIGHT).expect("spawns");
    let walkers = pause_walkers(skinned.app.world_mut(), time);
    if masked {
        mask_walkers(skinned.app.world_mut(), &walkers);
    }
    assert_eq!(walkers.len(), 12, "six walkers of two skinned primitives");
    let mut r = renderer();
    let gpu = shadow(&mut skinned, &mut r);
    let instances = skinned.app.world().resource::<RenderInstances>();
    let masked_casters = instances.casters.len() - instances.opaque_casters;
    assert_eq!(
        masked_casters,
        if masked { 12 } else { 0 },
        "t {time} s: masked casters"
    );

    let mut posed = SceneSession::new(desc, WIDTH, HEIGHT).expect("spawns");
    let walkers = pause_walkers(posed.app.world_mut(), time);
    if masked {
        mask_walkers(posed.app.world_mut(), &walkers);
    }
    posed.update();
    pose_on_the_cpu(posed.app.world_mut(), &walkers);
    let mut r = renderer();
    let cpu = shadow(&mut posed, &mut r);

    let shadowed = cpu.iter().filter(|&&v| v < 0.5).count();
    let differ = gpu.iter().zip(&cpu).filter(|(a, b)| (*a - *b).abs() > 0.05).count();
    eprintln!("t {time} s (masked {masked}): {shadowed} shadowed pixels, {differ} differ");
    (shadowed, differ)
}

#[test]
fn gpu_skinned_shadows_equal_cpu_posed_shadows_through_the_walk() {
    let desc = SceneDesc::load(SCENE).expect("the walkers scene loads");
    let mut total_shadowed = 0;
    for (k, time) in [0.0, 0.6, 1.3, 2.7, 5.1].into_iter().enumerate() {
        // Every other time with an alpha-masked material.
        let (shadowed, differ) = compare_with_cpu_posing(&desc, time, k % 2 == 1);
        assert!(shadowed > 400, "t {time} s: only {shadowed} shadowed pixels compared");
        assert!(
            differ <= 3,
            "t {time} s: {differ} pixels differ between GPU and CPU skinning"
        );
        total_shadowed += shadowed;
    }
    assert!(total_shadowed > 2500);
}

#[test]
fn skinned_shadows_equal_cpu_posed_shadows_in_the_clipmap_and_the_paged_clipmap() {
    let mut desc = SceneDesc::load(SCENE).expect("the walkers scene loads");
    let layouts = [
        SunLayout::Clipmap {
            levels: 4,
            level0_extent: 8.0,
        },
        SunLayout::VirtualClipmap {
            levels: 4,
            level0_extent: 8.0,
            virtual_resolution: DEFAULT_VIRTUAL_RESOLUTION,
            page_size: DEFAULT_PAGE_SIZE,
            pool_pages: DEFAULT_POOL_PAGES,
        },
    ];
    for layout in layouts {
        desc.shadows.map.layout = layout;
        let (shadowed, differ) = compare_with_cpu_posing(&desc, 1.3, false);
        assert!(shadowed > 400, "{layout:?}: only {shadowed} shadowed pixels compared");
        assert!(
            differ <= 3,
            "{layout:?}: {differ} pixels differ between GPU and CPU skinning"
        );
    }
}

#[test]
fn the_shadows_move_with_the_walk() {
    let desc = SceneDesc::load(SCENE).expect("the walkers scene loads");
    let mut images = Vec::new();
    for time in [0.0, 2.0] {
        let mut session = SceneSession::new(&desc, WIDTH, HEIGHT).expect("spawns");
        pause_walkers(session.app.world_mut(), time);
        let mut r = renderer();
        images.push(shadow(&mut session, &mut r));
    }
    let moved = images[0]
        .iter()
        .zip(&images[1])
        .filter(|(a, b)| (*a - *b).abs() > 0.5)
        .count();
    assert!(moved > 300, "only {moved} pixels changed shadow in 2 s of walking");
}

#[test]
fn a_moving_walker_redraws_only_the_views_it_touches() {
    let desc = SceneDesc::load(SCENE).expect("the walkers scene loads");
    let mut session = SceneSession::new(&desc, WIDTH, HEIGHT).expect("spawns");
    let mut r = renderer();
    // Every walker but one paused; two frames to settle the cache.
    let walkers = pause_walkers(session.app.world_mut(), 1.0);
    for _ in 0..2 {
        shadow(&mut session, &mut r);
    }
    shadow(&mut session, &mut r);
    let still = r.last_report.shadow_views_drawn;
    let views = session.app.world().resource::<penumbra::ecs::ShadowViews>().views.len() as u32;
    assert_eq!(still, 0, "a still frame redrew {still} of {views} views");
    session
        .app
        .world_mut()
        .get_mut::<AnimationPlayer>(walkers[0])
        .expect("a player")
        .paused = false;
    shadow(&mut session, &mut r);
    let moving = r.last_report.shadow_views_drawn;
    eprintln!("{moving} of {views} views redrawn for one walking caster");
    assert!(moving > 0, "the walking caster redrew no view");
    assert!(moving < views, "the walking caster redrew all {views} views");
}
