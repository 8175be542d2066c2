//! The standalone depth-only passes: renders one spot light's shadow map and one point light's
//! cube from a plain list of casters — no ECS, no scene file, no lighting pass — and writes
//! them as 16-bit greyscale images (`out/standalone_spot.png`, and the six cube faces side by
//! side in `out/standalone_point.png`, +X −X +Y −Y +Z −Z). The returned textures are ordinary
//! wgpu textures an application binds in its own passes (`map.view` as `texture_depth_2d`,
//! `cube.cube_view` as `texture_depth_cube`), with the matrices that project into them.
//!
//! Run with `cargo run --release --example standalone_shadows`.

use std::path::Path;

use glam::{Mat4, Vec3};
use penumbra::export::write_scalar_image;
use penumbra::math::spot::SpotInput;
use penumbra::mesh::{cuboid, sphere};
use penumbra::render::GpuContext;
use penumbra::render::shadows::standalone::{ShadowCaster, StandaloneShadows, read_depth_layer};
use penumbra::settings::ShadowSettings;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let gpu = GpuContext::headless()?;
    let mut pass = StandaloneShadows::new(&gpu);
    // A ring of boxes around a ball, all a few metres under and around the lights.
    let cube = cuboid(Vec3::splat(0.8));
    let ball = sphere(0.5, 32, 16);
    let mut casters: Vec<ShadowCaster<'_>> = (0..8)
        .map(|k| {
            let angle = k as f32 * std::f32::consts::FRAC_PI_4;
            let at = Vec3::new(2.5 * angle.cos(), 0.4 + 0.3 * k as f32, 2.5 * angle.sin());
            ShadowCaster {
                mesh: &cube,
                world_from_local: Mat4::from_translation(at),
            }
        })
        .collect();
    casters.push(ShadowCaster {
        mesh: &ball,
        world_from_local: Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
    });
    let settings = ShadowSettings::default();

    let spot = SpotInput {
        position: Vec3::new(0.0, 6.0, 0.0),
        direction: Vec3::NEG_Y,
        outer_angle: 50f32.to_radians(),
        range: 20.0,
        near: 0.05,
        resolution: 512,
    };
    let map = pass
        .render_spot(&gpu, &casters, &spot, &settings)
        .ok_or("the spot light has no shadow view")?;
    let depths = read_depth_layer(&gpu.device, &gpu.queue, &map.texture, 0).ok_or("no layer 0")?;
    let side = spot.resolution;
    write_scalar_image(Path::new("out/standalone_spot.png"), side, side, &depths)?;
    let covered = depths.iter().filter(|&&d| d > 0.0).count();
    println!("spot light: {side}² map, {covered} texels hold a caster -> out/standalone_spot.png");

    let side = 256;
    let cube_map = pass
        .render_point(&gpu, &casters, Vec3::new(0.0, 2.0, 0.0), 0.05, 15.0, side, &settings)
        .ok_or("the point light has no shadow view")?;
    // The six faces side by side.
    let width = side as usize * 6;
    let mut strip = vec![0.0; width * side as usize];
    for face in 0..6u32 {
        let depths = read_depth_layer(&gpu.device, &gpu.queue, &cube_map.texture, face).ok_or("missing face")?;
        for (row, values) in depths.chunks(side as usize).enumerate() {
            let start = row * width + face as usize * side as usize;
            strip[start..start + side as usize].copy_from_slice(values);
        }
    }
    write_scalar_image(Path::new("out/standalone_point.png"), width as u32, side, &strip)?;
    let covered = strip.iter().filter(|&&d| d > 0.0).count();
    println!("point light: six {side}² faces, {covered} texels hold a caster -> out/standalone_point.png");
    Ok(())
}
