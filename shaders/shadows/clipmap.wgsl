// A sun's clipmap levels (penumbra::math::clipmap): concentric squares in the light's frame
// centred on the camera, each twice the side of the one below with as many texels, drawn and
// sampled as cascades are. A receiver samples the finest level whose window holds it with
// room for the widest filter, and blends into the next level across a band of
// `blend_width` of the window's half side (a paged sun's receiver reads no level finer than
// its pixel); shadows fade out over `distance_fade_width` of the last level's half side
// before its edge.
#define_import_path penumbra::shadows::clipmap

#import penumbra::contract::{MAX_PENUMBRA_TEXELS, SHADOW_FLAG_PAGED}
#import penumbra::shadows::bindings::shadow_views
#import penumbra::shadows::types::Light

// Which level a receiver samples and how far it is into the band towards the next (0 in the
// last level); `index` is `view_count` past the last level.
struct LevelSelection {
    index: u32,
    blend: f32,
}

// Texels kept clear of a window's edge: the widest filter (PCSS's, MAX_PENUMBRA_TEXELS) and
// a bilinear footprint.
const LEVEL_MARGIN_TEXELS: f32 = MAX_PENUMBRA_TEXELS + 2.0;

// How far (NDC) a receiver at `position` is inside level `index`'s usable window (negative
// outside it).
fn level_inset(light: Light, index: u32, position: vec3<f32>) -> f32 {
    let view = shadow_views.items[light.first_view + index];
    let clip = view.clip_from_world * vec4<f32>(position, 1.0);
    let margin = 2.0 * LEVEL_MARGIN_TEXELS * view.texel_size;
    return 1.0 - margin - max(abs(clip.x), abs(clip.y));
}

// The first level a receiver at `view_depth` may read: for a paged sun the finest whose
// texel (`params.x`) is at least its pixel (`Light::range` per metre of view depth, as
// penumbra::math::pages::density_level), else 0.
fn density_level(light: Light, view_depth: f32) -> u32 {
    if (light.flags & SHADOW_FLAG_PAGED) == 0u {
        return 0u;
    }
    let pixel = light.range * view_depth;
    for (var i = 0u; i < light.view_count; i++) {
        if shadow_views.items[light.first_view + i].params.x >= pixel {
            return i;
        }
    }
    return light.view_count - 1u;
}

// The finest level, from `density_level` on, whose window holds `position` with the margin,
// and its blend towards the next level.
fn select_level(light: Light, position: vec3<f32>, view_depth: f32) -> LevelSelection {
    let count = light.view_count;
    let band = max(light.shadow_params.z, 1e-4);
    for (var i = density_level(light, view_depth); i < count; i++) {
        let inset = level_inset(light, i, position);
        if inset >= 0.0 {
            let blend = select(saturate(1.0 - inset / band), 0.0, i + 1u == count);
            return LevelSelection(i, blend);
        }
    }
    return LevelSelection(count, 0.0);
}

// 1 where the clipmap's shadows are at full strength, falling to 0 at the last level's
// usable edge over `distance_fade_width` of its half side.
fn clipmap_fade(light: Light, position: vec3<f32>) -> f32 {
    let inset = level_inset(light, light.view_count - 1u, position);
    let width = light.shadow_params.w;
    if width <= 0.0 {
        return select(0.0, 1.0, inset >= 0.0);
    }
    return smoothstep(0.0, width, inset);
}
