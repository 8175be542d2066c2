//! Host mirrors of the WGSL structs in `shaders/`. Each is `#[repr(C)]` + `Pod`, and the test
//! at the bottom compares every field offset and struct size with the layout naga computes for
//! the WGSL declaration, so a mismatch fails `cargo test` instead of corrupting a frame.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use crate::math::cascades::CascadeSet;
use crate::settings::{MAX_CASCADES, ShadowDebugView, ShadowSettings};

/// Mirror of WGSL `ShadowCascade`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ShadowCascadeGpu {
    /// Light clip space from world space.
    pub clip_from_world: Mat4,
    /// x: texel world size, y: light size in UV per metre, z: PCSS scale, w: UV aspect.
    pub params: Vec4,
    /// x: near split, y: far split, z: depth range in metres, w: unused.
    pub range: Vec4,
}

/// Mirror of WGSL `ShadowUniforms`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ShadowUniformsGpu {
    /// One entry per cascade; entries past `cascade_count` are unused.
    pub cascades: [ShadowCascadeGpu; MAX_CASCADES],
    /// Direction the light travels.
    pub light_direction: Vec3,
    /// Active cascades.
    pub cascade_count: u32,
    /// 1 / resolution.
    pub texel_size: f32,
    /// Normal offset in texels.
    pub normal_offset: f32,
    /// Where shadows end (view depth).
    pub max_distance: f32,
    /// Cascade blend fraction.
    pub blend_width: f32,
    /// Distance fade fraction.
    pub fade_width: f32,
    /// PCF radius.
    pub pcf_radius: u32,
    /// `SHADOW_FLAG_*` bits.
    pub flags: u32,
    /// Frame counter for temporal rotation.
    pub frame_index: u32,
}

/// Shadows are on.
pub const SHADOW_FLAG_ENABLED: u32 = 1;
/// PCSS blocker early-out.
pub const SHADOW_FLAG_BLOCKER_EARLY_OUT: u32 = 2;
/// Receiver-plane depth bias.
pub const SHADOW_FLAG_RECEIVER_PLANE: u32 = 4;
/// Temporal rotation of the Poisson patterns.
pub const SHADOW_FLAG_TEMPORAL: u32 = 8;

impl ShadowUniformsGpu {
    /// Packs one frame's cascades and settings. `settings` must already be sanitized.
    pub fn new(set: &CascadeSet, settings: &ShadowSettings, light_direction: Vec3, frame_index: u32) -> Self {
        let mut cascades = [ShadowCascadeGpu::default(); MAX_CASCADES];
        for (gpu, c) in cascades.iter_mut().zip(&set.cascades[..set.count]) {
            *gpu = ShadowCascadeGpu {
                clip_from_world: c.clip_from_world,
                params: Vec4::new(c.texel_world_size, c.light_size_uv, c.pcss_scale, c.uv_scale_y),
                range: Vec4::new(c.near, c.far, c.depth_range, 0.0),
            };
        }
        let mut flags = if set.count > 0 { SHADOW_FLAG_ENABLED } else { 0 };
        if settings.blocker_early_out {
            flags |= SHADOW_FLAG_BLOCKER_EARLY_OUT;
        }
        if settings.receiver_plane_bias {
            flags |= SHADOW_FLAG_RECEIVER_PLANE;
        }
        if settings.temporal_rotation {
            flags |= SHADOW_FLAG_TEMPORAL;
        }
        Self {
            cascades,
            light_direction,
            cascade_count: set.count as u32,
            texel_size: 1.0 / settings.resolution as f32,
            normal_offset: settings.normal_offset,
            max_distance: set.splits[set.count.max(1)],
            blend_width: settings.blend_width,
            fade_width: settings.distance_fade_width,
            pcf_radius: settings.pcf_radius,
            flags,
            frame_index,
        }
    }

    /// Uniforms that disable shadowing (no light casts shadows this frame).
    pub fn disabled() -> Self {
        Self::default()
    }
}

/// Mirror of WGSL `FrameUniforms`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct FrameUniformsGpu {
    /// Camera clip space from world space (reverse-Z perspective).
    pub clip_from_world: Mat4,
    /// Camera view space from world space.
    pub view_from_world: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// Linear exposure multiplier.
    pub exposure: f32,
    /// Direction the sun's light travels.
    pub sun_direction: Vec3,
    /// Sun intensity multiplier.
    pub sun_illuminance: f32,
    /// Sun colour (linear RGB).
    pub sun_color: Vec3,
    /// Frame counter.
    pub frame_index: u32,
    /// Ambient light (linear RGB).
    pub ambient: Vec3,
    /// [`ShadowDebugView`] as an integer.
    pub debug_view: u32,
}

impl FrameUniformsGpu {
    /// Encodes a debug view for the shader.
    pub fn debug_view_code(view: ShadowDebugView) -> u32 {
        match view {
            ShadowDebugView::None => 0,
            ShadowDebugView::Cascades => 1,
        }
    }
}

/// Mirror of WGSL `Instance`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct InstanceGpu {
    /// World from local transform.
    pub world_from_local: Mat4,
    /// Inverse transpose of the upper 3×3 (in a 4×4 for alignment).
    pub normal_from_local: Mat4,
    /// Base colour factor (linear RGBA).
    pub base_color: Vec4,
    /// Alpha cutoff for masked materials, 0 for opaque.
    pub alpha_cutoff: f32,
    /// `INSTANCE_FLAG_*` bits.
    pub flags: u32,
    /// Padding to the WGSL size.
    pub _pad: [u32; 2],
}

/// The instance receives shadows.
pub const INSTANCE_FLAG_RECEIVE_SHADOWS: u32 = 1;

/// Mirror of WGSL `CascadeView` in `caster.wgsl`, padded to the 256-byte dynamic-offset
/// alignment every adapter accepts.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CascadeViewGpu {
    /// Light clip space from world space.
    pub clip_from_world: Mat4,
    /// Padding to 256 bytes.
    pub _pad: [Vec4; 12],
}

#[cfg(test)]
mod tests {
    use std::mem::{offset_of, size_of};

    use naga::proc::Layouter;

    use super::*;
    use crate::shader::{ForwardVariant, ShaderLibrary};

    /// (WGSL member name, Rust offset) for each field, plus the Rust size.
    type Expected = (&'static str, Vec<(&'static str, usize)>, usize);

    fn check(module: &naga::Module, expected: &[Expected]) {
        let mut layouter = Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        for (name, fields, size) in expected {
            let (handle, ty) = module
                .types
                .iter()
                .find(|(_, t)| {
                    t.name
                        .as_deref()
                        .is_some_and(|n| n == *name || n.starts_with(&format!("{name}X_naga_oil")))
                })
                .unwrap_or_else(|| panic!("struct {name} not found in composed module"));
            let naga::TypeInner::Struct { members, span } = &ty.inner else {
                panic!("{name} is not a struct")
            };
            assert_eq!(*span as usize, *size, "size of {name}");
            assert_eq!(layouter[handle].size as usize, *size, "layout size of {name}");
            let wgsl: Vec<(&str, usize)> = members
                .iter()
                .map(|m| (m.name.as_deref().unwrap_or(""), m.offset as usize))
                .collect();
            assert_eq!(&wgsl, fields, "field offsets of {name}");
        }
    }

    #[test]
    fn host_structs_match_wgsl_layout() {
        let mut lib = ShaderLibrary::new().unwrap();
        let forward = lib.forward(ForwardVariant::all()[0]).unwrap();
        check(
            &forward,
            &[
                (
                    "ShadowCascade",
                    vec![
                        ("clip_from_world", offset_of!(ShadowCascadeGpu, clip_from_world)),
                        ("params", offset_of!(ShadowCascadeGpu, params)),
                        ("range", offset_of!(ShadowCascadeGpu, range)),
                    ],
                    size_of::<ShadowCascadeGpu>(),
                ),
                (
                    "ShadowUniforms",
                    vec![
                        ("cascades", offset_of!(ShadowUniformsGpu, cascades)),
                        ("light_direction", offset_of!(ShadowUniformsGpu, light_direction)),
                        ("cascade_count", offset_of!(ShadowUniformsGpu, cascade_count)),
                        ("texel_size", offset_of!(ShadowUniformsGpu, texel_size)),
                        ("normal_offset", offset_of!(ShadowUniformsGpu, normal_offset)),
                        ("max_distance", offset_of!(ShadowUniformsGpu, max_distance)),
                        ("blend_width", offset_of!(ShadowUniformsGpu, blend_width)),
                        ("fade_width", offset_of!(ShadowUniformsGpu, fade_width)),
                        ("pcf_radius", offset_of!(ShadowUniformsGpu, pcf_radius)),
                        ("flags", offset_of!(ShadowUniformsGpu, flags)),
                        ("frame_index", offset_of!(ShadowUniformsGpu, frame_index)),
                    ],
                    size_of::<ShadowUniformsGpu>(),
                ),
                (
                    "FrameUniforms",
                    vec![
                        ("clip_from_world", offset_of!(FrameUniformsGpu, clip_from_world)),
                        ("view_from_world", offset_of!(FrameUniformsGpu, view_from_world)),
                        ("camera_position", offset_of!(FrameUniformsGpu, camera_position)),
                        ("exposure", offset_of!(FrameUniformsGpu, exposure)),
                        ("sun_direction", offset_of!(FrameUniformsGpu, sun_direction)),
                        ("sun_illuminance", offset_of!(FrameUniformsGpu, sun_illuminance)),
                        ("sun_color", offset_of!(FrameUniformsGpu, sun_color)),
                        ("frame_index", offset_of!(FrameUniformsGpu, frame_index)),
                        ("ambient", offset_of!(FrameUniformsGpu, ambient)),
                        ("debug_view", offset_of!(FrameUniformsGpu, debug_view)),
                    ],
                    size_of::<FrameUniformsGpu>(),
                ),
                (
                    "Instance",
                    vec![
                        ("world_from_local", offset_of!(InstanceGpu, world_from_local)),
                        ("normal_from_local", offset_of!(InstanceGpu, normal_from_local)),
                        ("base_color", offset_of!(InstanceGpu, base_color)),
                        ("alpha_cutoff", offset_of!(InstanceGpu, alpha_cutoff)),
                        ("flags", offset_of!(InstanceGpu, flags)),
                        ("padding_a", offset_of!(InstanceGpu, _pad)),
                        ("padding_b", offset_of!(InstanceGpu, _pad) + 4),
                    ],
                    size_of::<InstanceGpu>(),
                ),
            ],
        );
        let caster = lib.caster().unwrap();
        let (_, ty) = caster
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("CascadeView"))
            .unwrap();
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!()
        };
        assert_eq!(members[0].offset as usize, offset_of!(CascadeViewGpu, clip_from_world));
        assert_eq!(size_of::<CascadeViewGpu>(), 256);
    }

    #[test]
    fn flag_bits_match_wgsl_constants() {
        let source = include_str!("../../shaders/shadow_types.wgsl");
        for (name, value) in [
            ("SHADOW_FLAG_ENABLED", SHADOW_FLAG_ENABLED),
            ("SHADOW_FLAG_BLOCKER_EARLY_OUT", SHADOW_FLAG_BLOCKER_EARLY_OUT),
            ("SHADOW_FLAG_RECEIVER_PLANE", SHADOW_FLAG_RECEIVER_PLANE),
            ("SHADOW_FLAG_TEMPORAL", SHADOW_FLAG_TEMPORAL),
        ] {
            assert!(
                source.contains(&format!("const {name}: u32 = {value}u;")),
                "{name} differs"
            );
        }
        let mesh = include_str!("../../shaders/mesh.wgsl");
        let line = format!("const INSTANCE_FLAG_RECEIVE_SHADOWS: u32 = {INSTANCE_FLAG_RECEIVE_SHADOWS}u;");
        assert!(mesh.contains(&line));
    }
}
