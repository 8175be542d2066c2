//! Counting the lighting pass's fragment-shader invocations with a pipeline-statistics query,
//! to show what the depth prepass saves: with it, each covered pixel is shaded once. A
//! measurement, off unless asked for ([`Renderer::count_forward_fragments`](crate::render::Renderer::count_forward_fragments));
//! reading the count waits for the GPU. Under MSAA the shader still runs once per pixel and
//! triangle, not per sample, so a pixel two triangles share counts twice.

use crate::render::readback::{QueryReadback, read_buffer};

/// The query and its buffers.
pub struct FragmentCounter {
    /// One pipeline-statistics query of fragment-shader invocations.
    pub query_set: wgpu::QuerySet,
    buffers: QueryReadback,
}

impl FragmentCounter {
    /// Creates the query (the device must have `PIPELINE_STATISTICS_QUERY`).
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("forward fragments"),
                ty: wgpu::QueryType::PipelineStatistics(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS),
                count: 1,
            }),
            buffers: QueryReadback::new(device, "forward fragments", 1),
        }
    }

    /// Records the copy of the count to the readback buffer; call after the lighting pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        self.buffers.record(encoder, &self.query_set, 1);
    }

    /// The count of the frame just submitted (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Option<u64> {
        let bytes = read_buffer(device, &self.buffers.readback, 8)?;
        Some(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?))
    }
}
