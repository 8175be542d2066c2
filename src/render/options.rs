//! [`RenderOptions`]: how frames are rendered, as an ECS resource the application (or the
//! viewer's inspector) changes between frames.

use bevy_ecs::resource::Resource;

/// Whether the camera's depth is written in a prepass before the lighting pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthPrepass {
    /// On while the camera's view has fewer triangles than the target has pixels
    /// ([`prepass_pays`]): then the lighting pass's saved shading outweighs drawing the
    /// geometry twice; past it the view is bound by its vertices and the prepass would double
    /// that work.
    #[default]
    Auto,
    /// Always.
    On,
    /// Never: the lighting pass writes depth itself and may shade a pixel more than once.
    Off,
}

/// Render-wide switches; a world without this resource renders with the defaults.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// The depth prepass (default [`DepthPrepass::Auto`]). A forward material with its own
    /// vertex stage (instead of `penumbra::forward_io::forward_vertex`) must turn it off, or
    /// its pixels may not match the prepass depth.
    pub depth_prepass: DepthPrepass,
    /// Keep shadow maps whose view and casters did not change instead of drawing them again
    /// (default on). Off, every view is drawn every frame, as when everything moves: what
    /// the benchmark times.
    pub shadow_cache: bool,
    /// Evaluate every shadowed light's filter per pixel in a compute pass after the depth
    /// prepass, and let the lighting pass read the result (`penumbra::lights::
    /// shadow_visibility` does it for any material). Only when the prepass runs. Default on:
    /// on the H100 it takes the boxes scene's PCSS High frame from 5.59 to 2.64 ms (every map
    /// drawn) — fragment-shader filtering is far slower there than the same work in compute.
    pub visibility_resolve: bool,
    /// Render the cascades of a sun that must be drawn again in one multiview pass, one
    /// instanced draw per batch, where the device has `MULTIVIEW` (each cascade in its own
    /// pass elsewhere, or while off). Each instance is still drawn only into the cascades
    /// whose casters it is: the vertex stage drops it from the others. Default off: on the
    /// H100 it saved draw calls but no GPU time on small scenes and took the 100k field's
    /// shadow maps from 17.4 to 90.3 ms (every view runs the vertices of the whole list).
    /// lavapipe draws primitives its clipper splits into the pass's first layer, so casters
    /// crossing a cascade's bounds land in the wrong cascade there.
    pub single_pass_cascades: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            depth_prepass: DepthPrepass::Auto,
            shadow_cache: true,
            visibility_resolve: true,
            single_pass_cascades: false,
        }
    }
}

/// Whether [`DepthPrepass::Auto`] runs the prepass for a view of `triangles` visible
/// triangles on a target of `pixels` pixels.
pub fn prepass_pays(triangles: u64, pixels: u64) -> bool {
    triangles < pixels
}

impl DepthPrepass {
    /// Whether the prepass runs for a view of `triangles` triangles on `pixels` pixels.
    pub fn runs(self, triangles: impl FnOnce() -> u64, pixels: u64) -> bool {
        match self {
            Self::On => true,
            Self::Off => false,
            Self::Auto => prepass_pays(triangles(), pixels),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_runs_the_prepass_only_below_one_triangle_per_pixel() {
        let pixels = 1920 * 1080;
        assert!(DepthPrepass::Auto.runs(|| 60_000, pixels));
        assert!(!DepthPrepass::Auto.runs(|| 20_000_000, pixels));
        assert!(DepthPrepass::On.runs(|| u64::MAX, pixels));
        assert!(!DepthPrepass::Off.runs(|| 0, pixels));
    }
}
