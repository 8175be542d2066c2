//! [`FrameReport`]: what a rendered frame cost (pass timings, draw calls, shadow views
//! drawn, memory).

use crate::render::timer::PassTiming;

/// What the last frame cost on the GPU.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// Time of each timed pass of the newest frame whose timings have arrived (timings are
    /// read back without waiting, so they lag a frame or two; empty when the adapter has no
    /// timestamp queries or none has arrived yet).
    pub passes: Vec<PassTiming>,
    /// The frame `passes` belong to (see [`Renderer::frames_rendered`](crate::render::Renderer::frames_rendered)).
    pub timed_frame: u64,
    /// Draw commands recorded (a multi-draw of many batches counts once).
    pub draw_calls: u32,
    /// Instanced draws recorded, one per batch, in multi-draws or one by one.
    pub draws: u32,
    /// The prepass's pixels of untextured materials were lit in one pass, and the lighting
    /// pass drew only the other materials ([`crate::render::deferred`]).
    pub deferred_lighting: bool,
    /// Shadow views drawn (a view whose layer still holds its content is not).
    pub shadow_views_drawn: u32,
    /// Draw calls of the shadow views.
    pub shadow_draw_calls: u32,
    /// Shadow-map texels cleared before drawing: a redrawn layer clears only the rectangle
    /// its last draw wrote (a whole layer when that is not known or most of it).
    pub shadow_cleared_texels: u64,
    /// Clipmap levels whose layer was moved by whole texels with their window and drawn only
    /// where the window newly reached or casters changed.
    pub shadow_views_scrolled: u32,
    /// Clipmap levels drawn whole from a caster list made for an earlier window (their layer
    /// was lost: a new allocation, the cache off): the next frame culls them again and draws
    /// them once more.
    pub shadow_views_resynced: u32,
    /// Shadow-map texels drawn: every texel of a view drawn whole, the regions of a scrolled
    /// one.
    pub shadow_drawn_texels: u64,
    /// Skinned meshes posed on the GPU this frame (those whose pose changed).
    pub skinned_meshes_posed: u32,
    /// The depth prepass drew nothing: its textures held what it would draw, kept from an
    /// earlier frame ([`crate::render::prepass_keep`]).
    pub prepass_kept: bool,
    /// Bytes of shadow-map memory.
    pub shadow_memory: u64,
    /// What a paged sun's pages did, where the frame was read back for it (headless renders
    /// read every frame; None without a paged sun).
    pub pages: Option<PageStats>,
    /// Instances the camera view's occlusion culling drew in its early and late phases, where
    /// the frame was read back for it (headless renders read every frame; None where the
    /// culling did not run).
    pub occlusion_drawn: Option<(u64, u64)>,
    /// Bytes of the resolved visibility (a 4-byte texel per pixel and shadowed light).
    pub resolved_memory: u64,
    /// Fragment-shader invocations of the lighting pass, while counted
    /// ([`Renderer::count_forward_fragments`](crate::render::Renderer::count_forward_fragments)).
    pub forward_fragments: Option<u64>,
}

impl FrameReport {
    /// Sum of the shadow-map passes (every view of every light: the passes named
    /// `shadow …`), in milliseconds.
    pub fn shadow_ms(&self) -> f64 {
        self.passes
            .iter()
            .filter(|p| p.name.starts_with("shadow"))
            .map(|p| p.ms)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::resolve::RESOLVE_NAME;

    #[test]
    fn shadow_ms_sums_the_shadow_maps_and_not_the_resolve() {
        let pass = |name: &str, ms| PassTiming {
            name: name.to_owned(),
            ms,
        };
        let report = FrameReport {
            passes: vec![
                pass("shadow cascade 0", 1.0),
                pass("shadow spot 0", 0.5),
                pass(RESOLVE_NAME, 4.0),
                pass("forward", 8.0),
            ],
            ..Default::default()
        };
        assert_eq!(report.shadow_ms(), 1.5);
    }
}

/// What a paged sun's pages did in one frame ([`Renderer::read_page_stats`](crate::render::Renderer::read_page_stats)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct PageStats {
    /// Pages some visible pixel reads.
    pub needed: u32,
    /// Pages of the pool holding a page after the allocation.
    pub resident: u32,
    /// Pages drawn: newly mapped, or resident but made stale by a moving caster or the light.
    pub drawn: u32,
    /// Pages evicted to make room.
    pub evicted: u32,
    /// Needed pages the pool had no room for (their pixels read a coarser level).
    pub overflowed: u32,
    /// Pages of the pool.
    pub pool: u32,
}
