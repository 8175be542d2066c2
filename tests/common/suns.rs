//! What the sun moment tests share: every moment technique with the device it runs on, a
//! casting ground, the focus sun's visibility at probe points, and the ray-cast truth of a
//! sun disc over boxes.

use glam::Vec3;
use penumbra::math::light_space::light_rotation;

use crate::common::rays::{Aabb, evaluate_on, scene_with};

/// What the device may store moments in.
#[derive(Clone, Copy, PartialEq)]
pub enum Device {
    /// Whatever it has (lavapipe: 32-bit filtering and 16-bit unorm).
    Full,
    /// Neither 16-bit unorm textures nor 32-bit filtering: 16-bit MSM falls back to half
    /// floats.
    HalfFloatsOnly,
}

/// Every sun moment technique: name, settings, and the device it runs on.
pub const TECHNIQUES: [(&str, &str, Device); 6] = [
    ("evsm-fp16", "mode: Evsm, moment_precision: Fp16", Device::Full),
    ("evsm-fp32", "mode: Evsm, moment_precision: Fp32", Device::Full),
    ("evsm4", "mode: Evsm4", Device::Full),
    ("msm-unorm16", "mode: Msm, moment_precision: Fp16", Device::Full),
    ("msm-half", "mode: Msm, moment_precision: Fp16", Device::HalfFloatsOnly),
    ("msm-fp32", "mode: Msm, moment_precision: Fp32", Device::Full),
];

/// A ground slab that casts (its top at y = 0).
pub const GROUND: Aabb = Aabb {
    min: Vec3::new(-40.0, -0.2, -100.0),
    max: Vec3::new(40.0, 0.0, 40.0),
};

/// The focus sun's visibility at `probes` for one technique.
pub fn visibility(boxes: &[Aabb], sun: &str, settings: &str, device: Device, probes: &[(Vec3, Vec3)]) -> Vec<f32> {
    let light = format!("Directional({sun}, shadows: ({settings}))");
    let desc = scene_with(boxes, &light);
    evaluate_on(&desc, probes, None, |gpu| {
        if device == Device::HalfFloatsOnly {
            gpu.unorm16_moments = false;
            gpu.moments_format = wgpu::TextureFormat::Rgba16Float;
        }
    })
}

/// The visible fraction of a sun disc of `diameter` degrees, shining along `travel`, from
/// `p` (a point on a surface facing up) past `boxes`: 32 × 32 rays stratified over the disc.
pub fn disc_visibility(boxes: &[Aabb], travel: Vec3, diameter: f32, p: Vec3) -> f32 {
    let to_light = -travel.normalize();
    let rotation = light_rotation(travel.normalize()).transpose();
    let tan = (0.5 * diameter.to_radians()).tan();
    let (n, mut inside, mut lit) = (32, 0u32, 0u32);
    for i in 0..n {
        for j in 0..n {
            let u = (i as f32 + 0.5) / n as f32 * 2.0 - 1.0;
            let v = (j as f32 + 0.5) / n as f32 * 2.0 - 1.0;
            if u * u + v * v > 1.0 {
                continue;
            }
            inside += 1;
            let dir = (to_light + rotation * Vec3::new(u * tan, v * tan, 0.0)).normalize();
            let origin = p + Vec3::Y * 1e-3;
            lit += u32::from(!boxes.iter().any(|b| b.blocks(origin, origin + dir * 100.0)));
        }
    }
    lit as f32 / inside as f32
}

/// The width (metres) over which `values` along `probes` (a line across a shadow edge, in
/// +x) rise from 0.1 to 0.9; NaN when they do not.
pub fn penumbra_width(probes: &[(Vec3, Vec3)], values: &[f32]) -> f32 {
    let at = |level: f32| {
        probes
            .iter()
            .zip(values)
            .find(|(_, v)| **v >= level)
            .map_or(f32::NAN, |((p, _), _)| p.x)
    };
    (at(0.9) - at(0.1)).abs()
}
