//! Host mirrors of the shadow library's WGSL structs (`shaders/shadows/types.wgsl`) and the
//! pure packing of a frame's lights and shadow views into them. The layout test in
//! `render::gpu_types` compares every field with naga's layout of the WGSL.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::{ShadowView, ShadowViews};
use crate::render::shadows::sun_moments::{
    MomentSupport, cascade_moment_format, cascade_moments, msm_bias, msm_quantised, paged_moment_format,
};
use crate::settings::{ShadowDebugView, ShadowMode, ShadowSettings};

pub use crate::shader::contract::{
    LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT, RESOLVE_NONE, SHADOW_FILTER_EVSM2, SHADOW_FILTER_EVSM4,
    SHADOW_FILTER_MSM, SHADOW_FILTER_PCF, SHADOW_FILTER_PCSS, SHADOW_FILTER_VSM, SHADOW_FLAG_BLOCKER_EARLY_OUT,
    SHADOW_FLAG_CLIPMAP, SHADOW_FLAG_CONTACT_ONLY, SHADOW_FLAG_MOMENT_HARDENING, SHADOW_FLAG_PAGED,
    SHADOW_FLAG_RECEIVER_PLANE, SHADOW_FLAG_TEMPORAL,
};

/// Lights in the uniform light list (WGSL `MAX_LIGHTS`); the rest go to a storage buffer that
/// grows with the scene.
pub const MAX_LIGHTS: usize = crate::shader::contract::MAX_LIGHTS as usize;
/// Capacity of the shadow-view list (WGSL `MAX_SHADOW_VIEWS`).
pub const MAX_SHADOW_VIEWS: usize = crate::shader::contract::MAX_SHADOW_VIEWS as usize;

/// Mirror of WGSL `Light`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightGpu {
    /// Colour times intensity.
    pub color: Vec3,
    /// `LIGHT_*`.
    pub kind: u32,
    /// Position (spot, point).
    pub position: Vec3,
    /// Range (spot, point).
    pub range: f32,
    /// Direction the light travels (sun, spot).
    pub direction: Vec3,
    /// Angular diameter (sun) or radius (spot, point).
    pub size: f32,
    /// Spot cone: cos(outer), 1 / (cos(inner) − cos(outer)); VSM (spot, point): minimum
    /// variance, light-bleed reduction. Sun moments: x = MSM bias, y = 1 where MSM moments are
    /// stored quantised, z = minimum variance (m²), w = light-bleed reduction.
    pub cone: Vec4,
    /// Normal offset (texels), max distance, blend width, fade width.
    pub shadow_params: Vec4,
    /// First shadow view.
    pub first_view: u32,
    /// Number of shadow views (0: unshadowed).
    pub view_count: u32,
    /// `SHADOW_FILTER_*`.
    pub shadow_filter: u32,
    /// `SHADOW_FLAG_*` bits.
    pub flags: u32,
    /// PCF radius, texels.
    pub pcf_radius: u32,
    /// Layer of the resolved visibility ([`RESOLVE_NONE`]: filtered in the lighting pass).
    pub resolve_layer: u32,
    /// PCSS sample counts ([`pcss_samples`]).
    pub pcss_samples: u32,
    /// Contact shadows: steps of the march (0: off).
    pub contact_steps: u32,
    /// Contact shadows: length (metres), thickness (metres), intensity.
    pub contact: Vec3,
    /// Padding to the WGSL size.
    pub _pad: u32,
}

/// Mirror of WGSL `ShadowView`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ShadowViewGpu {
    /// Light clip space from world.
    pub clip_from_world: Mat4,
    /// Per kind, see the WGSL.
    pub params: Vec4,
    /// Cascade: split range, depth range, and where a moment sun's receivers start in depth.
    pub range: Vec4,
    /// UV offset and scale of the view in its layer.
    pub rect: Vec4,
    /// Layer of its storage.
    pub layer: u32,
    /// 1 / side of its map.
    pub texel_size: f32,
    /// A sun's moments (EVSM): the positive and negative warp exponents of this cascade.
    pub exponents: Vec2,
    /// A paged level: xy the grid page of its window's first page, z its page side in texels
    /// (0 for a view that is not paged). A level whose layer wraps: w = 1, xy the UV of its
    /// window's first texel in the layer ([`wrap_origin`]).
    pub page: Vec4,
}

/// Mirror of WGSL `CasterView` in `caster.wgsl`, padded to the 256-byte dynamic-offset
/// alignment every adapter accepts: one per shadow view, bound at `index * 256`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CasterViewGpu {
    /// Light clip space from world.
    pub clip_from_world: Mat4,
    /// The view's bit in a single-pass entry's cascade mask (`1 << cascade`; 0 for other views).
    pub view_bit: u32,
    /// Padding to 256 bytes (the dynamic-offset alignment).
    pub _pad: [u32; 47],
}

impl CasterViewGpu {
    /// The entry of a view with `clip_from_world` and single-pass bit `view_bit`.
    pub fn new(clip_from_world: Mat4, view_bit: u32) -> Self {
        Self {
            clip_from_world,
            view_bit,
            _pad: [0; 47],
        }
    }
}

/// Views one single-pass (multiview) caster binding covers: a sun's cascades.
pub const SINGLE_PASS_VIEWS: usize = crate::settings::MAX_CASCADES;

/// `Light::pcss_samples` of a light's settings: its PCSS quality's blocker-search taps in bits
/// 0–7 and filter taps in bits 8–15, so each light samples as many as it asks for.
pub fn pcss_samples(settings: &ShadowSettings) -> u32 {
    let quality = settings.filter.pcss_quality;
    quality.blocker_samples() | quality.filter_samples() << 8
}

/// The filter and flag bits a light's settings select, with the moment technique of its
/// kind ([`ShadowMode::effective`]; `positional`: spot and point lights).
fn filter_and_flags(settings: &ShadowSettings, positional: bool) -> (u32, u32) {
    let filter = match settings.filter.mode.effective(!positional) {
        ShadowMode::Pcf => SHADOW_FILTER_PCF,
        ShadowMode::Pcss => SHADOW_FILTER_PCSS,
        ShadowMode::Vsm => SHADOW_FILTER_VSM,
        ShadowMode::Evsm => SHADOW_FILTER_EVSM2,
        ShadowMode::Evsm4 => SHADOW_FILTER_EVSM4,
        ShadowMode::Msm => SHADOW_FILTER_MSM,
    };
    let mut flags = 0;
    if settings.filter.blocker_early_out {
        flags |= SHADOW_FLAG_BLOCKER_EARLY_OUT;
    }
    if settings.filter.receiver_plane_bias {
        flags |= SHADOW_FLAG_RECEIVER_PLANE;
    }
    if settings.filter.temporal_rotation {
        flags |= SHADOW_FLAG_TEMPORAL;
    }
    if settings.filter.moments.contact_hardening {
        flags |= SHADOW_FLAG_MOMENT_HARDENING;
    }
    if settings.filter.debug_view == ShadowDebugView::Contact {
        flags |= SHADOW_FLAG_CONTACT_ONLY;
    }
    (filter, flags)
}

/// Packs every light (suns, then spots, then points) into `out`, pointing each shadowed one
/// at its views in `views`; `support`: the moment formats of the device. Contact shadows are
/// packed for the first [`MAX_LIGHTS`] lights alone.
pub fn pack_lights(lights: &FrameLights, views: &ShadowViews, support: MomentSupport, out: &mut Vec<LightGpu>) {
    out.clear();
    let cascade_format = cascade_moment_format(lights, support).unwrap_or(wgpu::TextureFormat::Rgba16Float);
    let paged_format = paged_moment_format(lights, support).unwrap_or(cascade_format);
    for sun in &lights.suns {
        // NOTE: a paged sun's moments are in its pool's format.
        let moments_format = if sun.paged.is_some() {
            paged_format
        } else {
            cascade_format
        };
        let (filter, mut flags) = filter_and_flags(&sun.settings, false);
        let s = &sun.settings;
        let set = &sun.cascades;
        if set.clipmap {
            flags |= SHADOW_FLAG_CLIPMAP;
        }
        if sun.paged.is_some() {
            flags |= SHADOW_FLAG_PAGED;
        }
        out.push(LightGpu {
            color: sun.light.color * sun.light.illuminance,
            kind: LIGHT_DIRECTIONAL,
            direction: sun.direction,
            size: sun.light.angular_diameter,
            cone: Vec4::new(
                msm_bias(moments_format),
                if msm_quantised(moments_format) { 1.0 } else { 0.0 },
                s.filter.moments.min_variance,
                s.filter.moments.bleed_reduction,
            ),
            shadow_params: Vec4::new(
                s.bias.normal_offset,
                set.end,
                s.map.cascades.blend_width,
                s.filter.distance_fade_width,
            ),
            shadow_filter: filter,
            flags,
            pcf_radius: s.filter.pcf_radius,
            pcss_samples: pcss_samples(s),
            ..LightGpu::default()
        });
    }
    for spot in &lights.spots {
        let (filter, flags) = filter_and_flags(&spot.settings, true);
        let l = &spot.light;
        let (cos_outer, cos_inner) = (l.outer_angle.cos(), l.inner_angle.min(l.outer_angle).cos());
        out.push(LightGpu {
            color: l.color * l.intensity,
            kind: LIGHT_SPOT,
            position: spot.position,
            range: l.range,
            direction: spot.direction,
            size: l.radius,
            cone: Vec4::new(
                cos_outer,
                1.0 / (cos_inner - cos_outer).max(1e-4),
                spot.settings.filter.vsm.min_variance,
                spot.settings.filter.vsm.bleed_reduction,
            ),
            shadow_params: Vec4::new(spot.settings.bias.normal_offset, 0.0, 0.0, 0.0),
            shadow_filter: filter,
            flags,
            pcf_radius: spot.settings.filter.pcf_radius,
            pcss_samples: pcss_samples(&spot.settings),
            ..LightGpu::default()
        });
    }
    for point in &lights.points {
        let (filter, flags) = filter_and_flags(&point.settings, true);
        out.push(LightGpu {
            color: point.light.color * point.light.intensity,
            kind: LIGHT_POINT,
            position: point.position,
            range: point.light.range,
            size: point.light.radius,
            cone: Vec4::new(
                0.0,
                0.0,
                point.settings.filter.vsm.min_variance,
                point.settings.filter.vsm.bleed_reduction,
            ),
            shadow_params: Vec4::new(point.settings.bias.normal_offset, 0.0, 0.0, 0.0),
            shadow_filter: filter,
            flags,
            pcf_radius: point.settings.filter.pcf_radius,
            pcss_samples: pcss_samples(&point.settings),
            ..LightGpu::default()
        });
    }
    // NOTE: contact shadows are marched for the uniform list's lights only (see resolve.wgsl).
    for (gpu, settings) in out.iter_mut().zip(lights.all_settings()).take(MAX_LIGHTS) {
        let contact = settings.filter.contact;
        if contact.enabled() {
            gpu.contact_steps = contact.steps;
            gpu.contact = Vec3::new(contact.length, contact.thickness, contact.intensity);
        }
    }
    // NOTE: views past the list's capacity are not uploaded, so no light points at them.
    for (v, view) in views.views.iter().enumerate().take(MAX_SHADOW_VIEWS) {
        let Some(light) = out.get_mut(view.light as usize) else {
            continue;
        };
        if light.view_count == 0 {
            light.first_view = v as u32;
        }
        light.view_count += 1;
    }
}

/// Gives shadowed lights (those with shadow views) a layer of the resolved visibility each,
/// in order, while the compute resolve runs (`resolve` is Some): every one when it resolves
/// the filters (`Some(true)`), else those with contact shadows, whose layer then holds their
/// contact shadows alone ([`SHADOW_FLAG_CONTACT_ONLY`], which a light whose debug view shows
/// them has already). The others get [`RESOLVE_NONE`]. Returns the number of layers.
pub fn assign_resolve_layers(lights: &mut [LightGpu], resolve: Option<bool>) -> u32 {
    let mut layers = 0;
    for light in lights {
        let contact_only = light.flags & SHADOW_FLAG_CONTACT_ONLY != 0;
        let layered = match resolve {
            Some(filters) => light.view_count > 0 && (filters || contact_only || light.contact_steps > 0),
            None => false,
        };
        light.resolve_layer = if layered {
            layers += 1;
            layers - 1
        } else {
            RESOLVE_NONE
        };
        if layered && resolve == Some(false) {
            light.flags |= SHADOW_FLAG_CONTACT_ONLY;
        }
    }
    layers
}

/// The GPU description of `view`, drawn at `view.resolution` texels in the top-left corner of
/// a layer `side` texels wide: what its layout wrote for its WGSL module
/// ([`ViewShading`](crate::ecs::view_list::ViewShading)), with, for a view whose light bakes
/// moments per view (a sun filtering EVSM or MSM), their exponents and depth start
/// (`support` as for [`pack_lights`]).
pub fn pack_view(lights: &FrameLights, view: &ShadowView, side: u32, support: MomentSupport) -> ShadowViewGpu {
    let scale = view.resolution as f32 / side.max(1) as f32;
    let mut gpu = ShadowViewGpu {
        clip_from_world: view.clip_from_world,
        rect: Vec4::new(0.0, 0.0, scale, scale),
        layer: view.slot,
        texel_size: 1.0 / view.resolution.max(1) as f32,
        params: view.shading.params,
        range: view.shading.range,
        ..ShadowViewGpu::default()
    };
    let baked = lights
        .sun_at(view.light)
        .and_then(|sun| cascade_moments(sun, view.kind.index as usize, support.fp32_filterable));
    if let Some(page) = view.shading.page {
        // NOTE: a paged level is its whole virtual window (`penumbra::shadows::page_table`).
        gpu.rect = Vec4::new(0.0, 0.0, 1.0, 1.0);
        let first = page.first_page.as_vec2();
        gpu.page = Vec4::new(first.x, first.y, page.page_size as f32, 0.0);
    }
    if let Some(origin) = wrap_origin(view, side) {
        // NOTE: the layer holds the window's first texel at `origin` (`penumbra::shadows::types`).
        let n = view.resolution as f32;
        gpu.page = Vec4::new(origin[0] as f32 / n, origin[1] as f32 / n, 0.0, 1.0);
    }
    if let Some(m) = baked {
        gpu.exponents = Vec2::new(m.c_positive, m.c_negative);
        gpu.range.w = m.depth_start;
    }
    gpu
}

/// Where a clipmap level's layer holds its window's first texel when the layer wraps: its
/// scroll asks for it and the view fills its layer (`side` texels); None where the layer is
/// moved with the window instead.
pub fn wrap_origin(view: &ShadowView, side: u32) -> Option<[u32; 2]> {
    view.scroll
        .and_then(|s| s.origin)
        .filter(|_| view.resolution == side && view.shading.page.is_none())
}
