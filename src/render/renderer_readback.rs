//! What a [`Renderer`] reads back from the GPU: the last frame's image, analysis targets and
//! shadow maps, shadow probes, and the depths its camera saw.

use glam::Vec3;
use image::RgbaImage;

use crate::ecs::assets::MeshHandle;
use crate::layout::ShadowStorage;
use crate::math::seen_depths::SeenDepths;
use crate::render::frame_inputs::FrameInputs;
use crate::render::probe::ProbeGpu;
use crate::render::renderer::Renderer;
use crate::render::report::PageStats;
use crate::render::shadows::page_pool::PagePool;
use crate::render::target::AnalysisImage;
use crate::render::variant::forward_variant;

impl Renderer {
    /// Instances the last frame's occlusion culling drew in its early and late phases (None
    /// when it did not run; waits for the GPU).
    pub fn read_occlusion_drawn(&self) -> Option<(u64, u64)> {
        self.occlusion.read_drawn(&self.gpu)
    }

    /// The instances each batch of the camera view drew in the last frame's early phase of
    /// its GPU culling, batch by batch (opaque, then masked; None when it did not run; waits
    /// for the GPU).
    pub fn read_gpu_culled(&self) -> Option<Vec<Vec<u32>>> {
        self.occlusion.read_early_lists(&self.gpu)
    }

    /// The casters the last frame's GPU culling listed for shadow view `v` (an index in
    /// [`ShadowViews::views`](crate::ecs::ShadowViews::views)) in each of its first `batches`
    /// batches (opaque, then masked), in list order (None for a view the CPU listed; waits
    /// for the GPU).
    pub fn read_shadow_culled(&self, v: usize, batches: usize) -> Option<Vec<Vec<u32>>> {
        self.shadow_cull.read_lists(&self.gpu, v, batches)
    }

    /// The occlusion culling's seen flag of each of the first `n` instances after the last
    /// frame (1: seen; empty before it ran; waits for the GPU).
    pub fn read_occlusion_seen(&self, n: usize) -> Vec<u32> {
        self.occlusion.read_seen(&self.gpu, n)
    }

    /// The occlusion culling's depth pyramid of the last frame, every level's width, height
    /// and depths (empty before it was built; waits for the GPU).
    pub fn read_occlusion_pyramid(&self) -> Vec<(u32, u32, Vec<f32>)> {
        self.occlusion.read_pyramid(&self.gpu)
    }

    /// The latest depths the camera saw that have come back from the GPU (frames that fit
    /// cascades with [`CascadeFit::DepthBounds`](crate::settings::CascadeFit) reduce them),
    /// with the render origin their world boxes are relative to.
    pub fn seen_depths(&self) -> Option<(SeenDepths, Vec3)> {
        self.seen.latest()
    }

    /// Waits until every depth reduction submitted so far has come back (for headless runs
    /// that want the next frame fitted to the last one); then [`seen_depths`](Self::seen_depths).
    pub fn wait_for_seen_depths(&mut self) -> Option<(SeenDepths, Vec3)> {
        self.seen.after_submit(&self.gpu.device, true);
        self.seen.latest()
    }

    /// Evaluates the focus light's shadow (see [`set_focus_light`](Self::set_focus_light)) at
    /// fixed world points with the filters and views of the last rendered frame (render a
    /// frame first). Values are what a material at that point would multiply into that
    /// light's term.
    pub fn evaluate_probes(&mut self, input: &FrameInputs<'_>, probes: &[ProbeGpu]) -> Vec<f32> {
        let variant = forward_variant(input.lights, false);
        let groups = [&self.scene.view_group, &self.shadows.group];
        self.probes
            .evaluate(&self.gpu, &self.layouts, &mut self.library, variant, groups, probes)
    }

    /// Reads the last frame's analysis targets back (None without analysis targets).
    pub fn read_analysis(&self) -> Option<AnalysisImage> {
        self.target.as_ref()?.read_analysis(&self.gpu.device, &self.gpu.queue)
    }

    /// The meshes whose opaque shadow casters the last frame drew from a position-only index
    /// list ([`MeshRange::position_first_index`](crate::render::scene_gpu::MeshRange::position_first_index)).
    pub fn position_listed_meshes(&self) -> Vec<MeshHandle> {
        let ranges = self.scene.mesh_ranges.iter().enumerate();
        ranges
            .filter(|(_, r)| r.position_first_index != r.first_index)
            .map(|(m, _)| MeshHandle(m as u32))
            .collect()
    }

    /// Reads layer `layer` of a shadow storage back (for point lights, layer `6·cube + face`):
    /// `side`² reverse-Z depths, row by row (None past the last layer or before any shadow map
    /// of that storage exists). A clipmap level whose layer wraps holds its window turned round
    /// its origin ([`Scroll::origin`](crate::ecs::view_list::Scroll::origin)). It waits for
    /// the GPU; for tests and debugging.
    pub fn read_shadow_map(&self, storage: ShadowStorage, layer: u32) -> Option<Vec<f32>> {
        let storage = self.shadows.array(storage);
        if storage.placeholder {
            return None;
        }
        storage.read_layer(&self.gpu.device, &self.gpu.queue, layer)
    }

    /// The paged sun's page pool (its allocator and what it was made for), while a sun is
    /// paged.
    pub fn page_pool(&self) -> Option<&PagePool> {
        self.shadows.pages.as_ref()
    }

    /// What the paged sun's last allocation did and how much of its pool is resident (None
    /// without a paged sun, or when the buffers did not read back). It waits for the GPU;
    /// for reports, tests and debugging.
    pub fn read_page_stats(&self) -> Option<PageStats> {
        let pool = self.shadows.pages.as_ref()?;
        let ([kept, drawn, evicted, overflowed], resident) =
            pool.allocator.read_counts(&self.gpu.device, &self.gpu.queue)?;
        Some(PageStats {
            needed: kept + drawn + overflowed,
            resident,
            drawn,
            evicted,
            overflowed,
            pool: pool.key.pool_pages,
        })
    }

    /// Reads the last rendered image back.
    pub fn read_image(&self) -> RgbaImage {
        match &self.target {
            Some(target) => target.read(&self.gpu.device, &self.gpu.queue),
            None => RgbaImage::new(1, 1),
        }
    }
}
