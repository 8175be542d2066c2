//! What the sun moment tests share: every moment technique with the device it runs on, a
//! casting ground, casters standing on it with probes around their feet, the focus sun's
//! visibility at probe points, and the ray-cast truth of a sun disc over boxes.

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

/// Casters standing at y = 0: a 1 m cube, 4 m and 6 m pillars, a 10 cm post and a wall.
pub const STANDING: [Aabb; 5] = [
    Aabb {
        min: Vec3::new(-0.5, 0.0, -0.5),
        max: Vec3::new(0.5, 1.0, 0.5),
    },
    Aabb {
        min: Vec3::new(2.5, 0.0, -1.5),
        max: Vec3::new(3.5, 4.0, -0.5),
    },
    Aabb {
        min: Vec3::new(-3.5, 0.0, -2.5),
        max: Vec3::new(-2.5, 6.0, -1.5),
    },
    Aabb {
        min: Vec3::new(1.45, 0.0, 2.45),
        max: Vec3::new(1.55, 2.5, 2.55),
    },
    Aabb {
        min: Vec3::new(-3.0, 0.0, 1.85),
        max: Vec3::new(0.0, 1.5, 2.15),
    },
];

/// Where the light travels: a sun about 44° up.
pub const TRAVEL: Vec3 = Vec3::new(-0.6, -0.7, -0.4);

/// Ground probes every 2 cm within 30 cm of a caster's footprint, outside every footprint.
pub fn probes_near_the_feet() -> Vec<(Vec3, Vec3)> {
    let near_a_foot = |p: Vec3| {
        let outside = |b: &Aabb| p.x < b.min.x || p.x > b.max.x || p.z < b.min.z || p.z > b.max.z;
        let within = |b: &Aabb| {
            let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
            let dz = (b.min.z - p.z).max(p.z - b.max.z).max(0.0);
            dx.hypot(dz) <= 0.3
        };
        STANDING.iter().all(outside) && STANDING.iter().any(within)
    };
    (-250..=250)
        .flat_map(|i| (-200..=200).map(move |j| Vec3::new(i as f32 * 0.02, 0.0, j as f32 * 0.02)))
        .filter(|&p| near_a_foot(p))
        .map(|p| (p, Vec3::Y))
        .collect()
}
