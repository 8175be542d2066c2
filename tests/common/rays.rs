//! Shadows judged against rays cast on the CPU: boxes in a scene written on the fly, the
//! focus light's shadow evaluated at probe points, and a slab test for each ray.

use glam::Vec3;
use penumbra::bench::session::SceneSession;
use penumbra::render::frame::FrameInputs;
use penumbra::render::probe::ProbeGpu;
use penumbra::render::{GpuContext, Renderer};
use penumbra::scene::SceneDesc;

pub fn scene(text: &str) -> SceneDesc {
    SceneDesc::from_str(text, "test.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// Evaluates the focus light's shadow at `probes` (position, normal) after one frame of `desc`;
/// each probe is seen at its own pixel (so filter patterns rotate from probe to probe).
pub fn evaluate(desc: &SceneDesc, probes: &[(Vec3, Vec3)]) -> Vec<f32> {
    evaluate_with(desc, probes, None, None)
}

/// [`evaluate`] with VSM moments stored in `moments_format` instead of the device's choice,
/// and every probe seen at `pixel` where given (one rotation of the filter patterns: no
/// per-pixel noise between probes).
pub fn evaluate_with(
    desc: &SceneDesc,
    probes: &[(Vec3, Vec3)],
    moments_format: Option<wgpu::TextureFormat>,
    pixel: Option<(u32, u32)>,
) -> Vec<f32> {
    evaluate_on(desc, probes, pixel, |gpu| {
        if let Some(format) = moments_format {
            gpu.moments_format = format;
        }
    })
}

/// [`evaluate`] on a device whose capabilities `limit` narrows (as a device without some
/// feature would have them), every probe seen at `pixel` where given.
pub fn evaluate_on(
    desc: &SceneDesc,
    probes: &[(Vec3, Vec3)],
    pixel: Option<(u32, u32)>,
    limit: impl Fn(&mut GpuContext),
) -> Vec<f32> {
    let (w, h) = (64, 48);
    let mut session = SceneSession::new(desc, w, h).unwrap_or_else(|e| panic!("{e}"));
    let mut gpu = GpuContext::headless()
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    limit(&mut gpu);
    let mut renderer = Renderer::new(gpu, w, h);
    session.update();
    let input = FrameInputs::from_world(session.app.world(), 0);
    renderer.render(&input);
    assert!(renderer.take_errors().is_empty());
    let probes: Vec<ProbeGpu> = probes
        .iter()
        .enumerate()
        .map(|(k, &(p, n))| ProbeGpu::new(p, n, pixel.unwrap_or((k as u32 % 64, k as u32 / 64))))
        .collect();
    renderer.evaluate_probes(&input, &probes)
}

/// An axis-aligned box.
#[derive(Clone, Copy)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// A cube of side `size` metres around `center`.
    pub fn cube(center: Vec3, size: f32) -> Self {
        Self::cuboid(center, Vec3::splat(size))
    }

    /// A box of `size` metres around `center`.
    pub fn cuboid(center: Vec3, size: Vec3) -> Self {
        Self {
            min: center - size * 0.5,
            max: center + size * 0.5,
        }
    }

    /// True when the segment from `a` to `b` passes through the box (slab test).
    pub fn blocks(&self, a: Vec3, b: Vec3) -> bool {
        let d = b - a;
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        for i in 0..3 {
            if d[i] == 0.0 {
                if !(self.min[i]..=self.max[i]).contains(&a[i]) {
                    return false;
                }
                continue;
            }
            let (mut near, mut far) = ((self.min[i] - a[i]) / d[i], (self.max[i] - a[i]) / d[i]);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        t0 <= t1
    }
}

pub fn scene_with(casters: &[Aabb], light: &str) -> SceneDesc {
    let objects: Vec<String> = casters
        .iter()
        .map(|b| {
            let (c, s) = ((b.min + b.max) * 0.5, b.max - b.min);
            format!(
                "(shape: Cuboid(size: ({}, {}, {})), material: \"m\", translation: ({}, {}, {})),",
                s.x, s.y, s.z, c.x, c.y, c.z
            )
        })
        .collect();
    scene(&format!(
        r#"Scene(
        camera: (position: (0, 9, 9), target: (0, 2, 0), fov: 60, near: 0.1, far: 100),
        lights: [{light}],
        materials: {{ "m": (base_color: (0.7, 0.7, 0.7, 1)) }},
        objects: [{}],
    )"#,
        objects.join("\n")
    ))
}
