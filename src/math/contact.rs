//! Contact shadows' screen-space march, the CPU mirror of `shaders/contact.wgsl`: from a
//! surface point, samples along a short segment towards the light; one that lies behind the
//! depth seen at its pixel's centre is compared with the plane of the surface seen there (its
//! depth and normal from the depth prepass). A sample behind that plane by more than a
//! rounding tolerance and less than the thickness is inside an occluder. Marches that leave the screen, pass behind the camera
//! or reach the sky find nothing.

use glam::{IVec2, Mat4, UVec2, Vec2, Vec3, Vec4Swizzles};

/// Below this cosine between the camera's ray and the plane seen at a sample, the plane is
/// edge-on: the sample is compared by distance to the camera instead.
pub const EDGE_ON_COSINE: f32 = 0.05;
/// A sample must lie this many pixel footprints behind the seen surface to count as occluded.
pub const DEPTH_TOLERANCE_PIXELS: f32 = 0.5;

/// What the camera's depth prepass saw, as the march reads it.
pub struct SeenDepth<'a> {
    /// Clip space from world space (reverse-Z).
    pub clip_from_world: Mat4,
    /// Its inverse.
    pub world_from_clip: Mat4,
    /// Camera position, world space.
    pub camera_position: Vec3,
    /// Target size in pixels.
    pub size: UVec2,
    /// The reverse-Z depth (0 = nothing drawn) and unit normal seen at a pixel of the target.
    pub seen: &'a dyn Fn(IVec2) -> (f32, Vec3),
}

/// One march: `steps` samples over `reach` metres, `thickness` metres deep, darkening by
/// `intensity`; the start offset by `jitter` (0–1) of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct March {
    /// Metres towards the light.
    pub reach: f32,
    /// Samples along it.
    pub steps: u32,
    /// Largest depth behind a seen surface that still counts as inside it, metres.
    pub thickness: f32,
    /// Darkening of an occluded point, 0–1.
    pub intensity: f32,
    /// Start offset as a fraction of a step.
    pub jitter: f32,
}

/// Interleaved-gradient noise at a pixel (Jimenez 2014), in `[0, 1)`: the march's jitter.
pub fn interleaved_gradient_noise(pixel: Vec2) -> f32 {
    (52.982_92 * (pixel.dot(Vec2::new(0.067_110_56, 0.005_837_15))).fract()).fract()
}

impl SeenDepth<'_> {
    /// The world point at `pixel` (pixels from the top left) and reverse-Z `depth`.
    pub fn world_at(&self, pixel: Vec2, depth: f32) -> Vec3 {
        let size = self.size.as_vec2();
        let ndc = Vec2::new(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
        let h = self.world_from_clip * ndc.extend(depth).extend(1.0);
        h.xyz() / h.w
    }

    /// How far `point` lies behind the surface seen at `pixel` (depth `depth`, unit normal
    /// `normal`), metres along the camera's ray through `point`; negative in front of it.
    pub fn hidden_by(&self, point: Vec3, pixel: IVec2, depth: f32, normal: Vec3) -> f32 {
        let seen = self.world_at(pixel.as_vec2() + Vec2::splat(0.5), depth);
        let ray = point - self.camera_position;
        let ray_length = ray.length();
        let across = ray.dot(normal);
        if across.abs() > EDGE_ON_COSINE * ray_length {
            let crossing = (seen - self.camera_position).dot(normal) / across;
            return ray_length * (1.0 - crossing);
        }
        ray_length - seen.distance(self.camera_position)
    }

    /// Contact visibility of the surface point `position` (unit `normal`, seen at `pixel`
    /// with reverse-Z `depth`) towards unit `to_light`: `1 − intensity` where the march finds
    /// an occluder, 1 where it does not.
    pub fn contact_visibility(
        &self,
        march: &March,
        position: Vec3,
        normal: Vec3,
        to_light: Vec3,
        pixel: Vec2,
        depth: f32,
    ) -> f32 {
        if march.steps == 0 || march.reach <= 0.0 {
            return 1.0;
        }
        let footprint = self
            .world_at(pixel + Vec2::X, depth)
            .distance(self.world_at(pixel, depth));
        let eye_distance = position.distance(self.camera_position).max(1e-6);
        let origin = position + normal * (DEPTH_TOLERANCE_PIXELS * footprint);
        let step = march.reach / march.steps as f32;
        let origin_clip = self.clip_from_world * origin.extend(1.0);
        let step_clip = self.clip_from_world * (to_light * step).extend(0.0);
        let last = self.size.as_ivec2() - IVec2::ONE;
        for i in 0..march.steps {
            let along = i as f32 + march.jitter;
            let clip = origin_clip + step_clip * along;
            if clip.w <= 0.0 {
                break;
            }
            let ndc = clip.xy() / clip.w;
            if ndc.abs().max_element() > 1.0 {
                break;
            }
            let at = Vec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * self.size.as_vec2();
            let sample_pixel = at.floor().as_ivec2().clamp(IVec2::ZERO, last);
            let (seen_depth, seen_normal) = (self.seen)(sample_pixel);
            if clip.z / clip.w >= seen_depth {
                continue;
            }
            let point = origin + to_light * (along * step);
            let hidden = self.hidden_by(point, sample_pixel, seen_depth, seen_normal);
            let tolerance = DEPTH_TOLERANCE_PIXELS * footprint * point.distance(self.camera_position) / eye_distance;
            if hidden > tolerance && hidden < march.thickness {
                return 1.0 - march.intensity;
            }
        }
        1.0
    }
}

#[cfg(test)]
#[path = "contact_tests.rs"]
mod tests;
