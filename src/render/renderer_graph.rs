//! How a [`Renderer`] sets up a frame's graph: the camera view's sample count (MSAA with its
//! fallback), and the graph's imports, declarations and transients.

use crate::layout::ShadowStorage;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphError};
use crate::render::options::Msaa;
use crate::render::prepass_keep::PrepassKey;
use crate::render::renderer::{Renderer, UploadProblems};
use crate::render::target::{DEPTH_FORMAT, TargetViews};

impl Renderer {
    /// Samples per pixel of this frame's camera view: what `msaa` asks for, or the largest
    /// count the device can multisample and resolve the target's format with (warned once
    /// per request and format); one for a target with analysis outputs (each analysis pixel
    /// holds one surface's values).
    pub(super) fn frame_samples(&mut self, msaa: Msaa, target: &TargetViews, problems: &mut UploadProblems) -> u32 {
        if target.analysis.is_some() {
            return 1;
        }
        let gpu = &self.gpu;
        let resolves = gpu
            .format_flags(target.format)
            .contains(wgpu::TextureFormatFeatureFlags::MULTISAMPLE_RESOLVE);
        let used = msaa
            .fallback(|n| resolves && gpu.supports_samples(target.format, n) && gpu.supports_samples(DEPTH_FORMAT, n));
        if used != msaa && self.msaa_warned != Some((msaa, target.format)) {
            self.msaa_warned = Some((msaa, target.format));
            problems.warnings.push(format!(
                "MSAA: {}× asked for, but `{}` cannot multisample {:?} that many times; using {}×",
                msaa.samples(),
                gpu.adapter_info.name,
                target.format,
                used.samples()
            ));
        }
        used.samples()
    }

    /// Declares this frame's graph: imports the target and the shadow storages, lets every
    /// node declare its work, and allocates the transients.
    pub(super) fn build_graph(
        &mut self,
        input: &FrameInputs<'_>,
        target: &TargetViews,
        (depth_prepass, samples, deferred_lighting): (bool, u32, bool),
    ) -> Result<u32, GraphError> {
        let graph = &mut self.graph;
        graph.begin_frame();
        let color = graph.import_texture("target colour", &target.color);
        let color_storage = target
            .storage
            .as_ref()
            .map(|view| graph.import_texture("target colour (storage)", view));
        let analysis = target.analysis.as_ref().map(|[shadow, position, normal]| {
            [
                graph.import_texture("analysis shadow", shadow),
                graph.import_texture("analysis position", position),
                graph.import_texture("analysis normal", normal),
            ]
        });
        let mut frame = FrameResources {
            color,
            color_storage,
            color_format: target.format,
            size: (target.width, target.height),
            samples,
            analysis,
            shadow_maps: ShadowStorage::ALL.map(|s| {
                let array = self.shadows.shared_array(s);
                graph.import_object(s.desc().label, array.array_view.clone(), array)
            }),
            shadow_moments: ShadowStorage::ALL.map(|s| {
                let moments = self.shadows.shared_moments(s);
                graph.import_object(s.desc().moments_label, moments.moments.sampled.clone(), moments)
            }),
            depth_prepass,
            depth: None,
            normals: None,
            visibility: self
                .shadows
                .resolved
                .as_ref()
                .map(|r| graph.import_texture("resolved visibility", &r.target.view)),
            deferred_lighting,
            shading_ids: None,
            prepass_kept: false,
        };
        // NOTE: the kept prepass's textures are imported as the graph's camera depth, normals
        // and ids, made for the targets the prepass node would create.
        let targets = (frame.visibility.is_some(), deferred_lighting);
        let kept = input.options.prepass_reuse && depth_prepass && samples == 1 && target.analysis.is_none();
        match kept.then(|| PrepassKey::of(input, frame.size, targets)).flatten() {
            Some(key) => {
                let (kept, held) = self.prepass_keep.begin(&self.gpu.device, key);
                frame.depth = Some(graph.import_texture("kept camera depth", &kept.depth));
                frame.normals = kept
                    .normals
                    .as_ref()
                    .map(|v| graph.import_texture("kept camera normals", v));
                frame.shading_ids = kept
                    .ids
                    .as_ref()
                    .map(|v| graph.import_texture("kept camera shading ids", v));
                frame.prepass_kept = held;
            }
            None => self.prepass_keep.release(),
        }
        graph.build(&self.gpu.device, &mut frame, input)
    }
}
