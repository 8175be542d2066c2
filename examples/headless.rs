//! Builds a small scene in code (no scene file), renders it headless with PCSS and writes
//! `out/example_headless.png`.
//!
//! Run with `cargo run --release --example headless`.

use penumbra::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let renderer = Renderer::headless(800, 450)?;
    let mut app = headless_app(renderer);
    let world = app.world_mut();

    let (ground_mesh, box_mesh, ball_mesh) = {
        let mut meshes = world.resource_mut::<Meshes>();
        (
            meshes.add(plane(Vec2::splat(60.0))),
            meshes.add(cuboid(Vec3::new(1.0, 3.0, 1.0))),
            meshes.add(sphere(0.7, 32, 16)),
        )
    };
    let (grey, orange) = {
        let mut materials = world.resource_mut::<Materials>();
        (
            materials.add(Material {
                base_color: Vec4::new(0.7, 0.7, 0.7, 1.0),
                ..Default::default()
            }),
            materials.add(Material {
                base_color: Vec4::new(0.9, 0.5, 0.2, 1.0),
                base_color_texture: None,
                alpha_mode: AlphaMode::Opaque,
                double_sided: false,
                transmission: 0.0,
            }),
        )
    };
    world.insert_resource(AmbientLight {
        color: Vec3::splat(0.08),
    });
    world.spawn((
        Camera3d::default(),
        Transform::from_translation(Vec3::new(0.0, 4.0, 10.0)).looking_at(Vec3::new(0.0, 1.0, 0.0), Vec3::Y),
    ));
    world.spawn((
        DirectionalLight {
            illuminance: 2.5,
            ..Default::default()
        },
        Transform::default().looking_at(Vec3::new(-0.6, -1.0, -0.4), Vec3::Y),
        ShadowSettings {
            map: ShadowMapSettings {
                max_distance: 50.0,
                ..Default::default()
            },
            filter: ShadowFilterSettings {
                mode: ShadowMode::Pcss,
                ..Default::default()
            },
            ..Default::default()
        },
    ));
    world.spawn((
        Transform::default(),
        Mesh3d(ground_mesh),
        MeshMaterial3d(grey),
        NotShadowCaster,
    ));
    for i in 0..5 {
        let x = i as f32 * 2.0 - 4.0;
        world.spawn((
            Transform::from_translation(Vec3::new(x, 1.5, 0.0)),
            Mesh3d(box_mesh),
            MeshMaterial3d(orange),
        ));
        world.spawn((
            Transform::from_translation(Vec3::new(x, 0.7 + i as f32 * 0.6, 3.0)),
            Mesh3d(ball_mesh),
            MeshMaterial3d(orange),
        ));
    }

    app.update();
    let world = app.world();
    let renderer = world.resource::<Renderer>();
    std::fs::create_dir_all("out")?;
    renderer.read_image().save("out/example_headless.png")?;
    let stats = world.resource::<ShadowStats>();
    println!(
        "wrote out/example_headless.png; casters per shadow view {:?}",
        stats.casters_per_view
    );
    for pass in &renderer.last_report.passes {
        println!("{:<17} {:.3} ms", pass.name, pass.ms);
    }
    Ok(())
}
