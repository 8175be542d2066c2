//! The depth pass: renders the casters of every shadow view of the frame into its layer of
//! its kind's storage. Per view: clear the layer to the reverse-Z far value (0), restrict the
//! viewport to the view's resolution, draw the opaque group with the depth-only pipeline (no
//! fragment stage), then the alpha-masked group with the alpha-test pipeline, both with the
//! light's slope-scaled depth bias and, where the adapter allows, unclipped depth so casters
//! in front of the near plane are flattened onto it.

use std::fmt::Write;

use crate::ecs::frame_lights::FrameLights;
use crate::ecs::shadow_views::{ShadowView, ShadowViewKind};
use crate::render::draw::draw_batches;
use crate::render::frame::{FrameContext, FrameInputs};
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode};
use crate::render::shadows::casters::{CasterKey, CasterPipelines};
use crate::render::shadows::gpu::CasterViewGpu;
use crate::settings::ShadowSettings;

/// The shadow-map node.
#[derive(Default)]
pub struct DepthPass {
    pipelines: CasterPipelines,
    /// Timing names, one per view, reused between frames.
    names: Vec<String>,
}

/// Writes the timing name of `view` into `name`: `shadow cascade c` for the first sun's
/// cascades (as before several suns existed), `shadow sun k cascade c` for the others,
/// `shadow spot k` for spot lights.
pub fn view_name(lights: &FrameLights, view: &ShadowView, name: &mut String) {
    name.clear();
    let light = view.light as usize;
    // NOTE: writing to a String cannot fail.
    let _ = match view.kind {
        ShadowViewKind::Cascade(c) if light == 0 => write!(name, "shadow cascade {c}"),
        ShadowViewKind::Cascade(c) => write!(name, "shadow sun {light} cascade {c}"),
        ShadowViewKind::Spot => write!(name, "shadow spot {}", light.saturating_sub(lights.suns.len())),
    };
}

/// The settings of the light a view belongs to.
fn view_settings<'a>(lights: &'a FrameLights, view: &ShadowView) -> Option<&'a ShadowSettings> {
    match view.kind {
        ShadowViewKind::Cascade(_) => lights.sun_at(view.light).map(|s| &s.settings),
        ShadowViewKind::Spot => lights.spot_at(view.light).map(|s| &s.settings),
    }
}

impl RenderNode for DepthPass {
    fn name(&self) -> &'static str {
        "shadow"
    }

    /// Writes each storage that has a view this frame (the layer views it renders into
    /// belong to that storage); with no shadow view nothing is written and the node is culled.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        let views = &inputs.shadow_views.views;
        if views.iter().any(|v| matches!(v.kind, ShadowViewKind::Cascade(_))) {
            pass.write(frame.cascade_maps);
        }
        if views.iter().any(|v| v.kind == ShadowViewKind::Spot) {
            pass.write(frame.spot_maps);
        }
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, _: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return;
        };
        let views = ctx.shadow_views;
        if self.names.len() < views.views.len() {
            self.names.resize_with(views.views.len(), String::new);
        }
        for (v, (view, group)) in views.views.iter().zip(&views.groups).enumerate() {
            let Some(settings) = view_settings(ctx.lights, view) else {
                continue;
            };
            let storage = ctx.shadows.storage(view.kind);
            let Some(target) = storage.layer_views.get(view.slot as usize) else {
                continue;
            };
            let unclipped = ctx.gpu.unclipped_depth;
            let mut built = 0;
            let device = &ctx.gpu.device;
            let opaque = self
                .pipelines
                .get(
                    device,
                    ctx.layouts,
                    ctx.library,
                    CasterKey::new(settings, false, unclipped),
                    &mut built,
                )
                .clone();
            let masked = (!group.masked.is_empty()).then(|| {
                self.pipelines
                    .get(
                        device,
                        ctx.layouts,
                        ctx.library,
                        CasterKey::new(settings, true, unclipped),
                        &mut built,
                    )
                    .clone()
            });
            ctx.counters.caster_pipelines += built;
            view_name(ctx.lights, view, &mut self.names[v]);
            let name = self.names[v].as_str();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(name),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: target,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: ctx.timer.pass(name),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if view.resolution < storage.side {
                let side = view.resolution as f32;
                pass.set_viewport(0.0, 0.0, side, side, 0.0, 1.0);
            }
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            let offset = (v * size_of::<CasterViewGpu>()) as u32;
            pass.set_bind_group(0, &ctx.shadows.caster_group, &[offset]);
            pass.set_bind_group(1, &ctx.scene.shadow_instances_group, &[]);
            pass.set_pipeline(&opaque);
            ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.opaque, false);
            if let Some(masked) = &masked {
                pass.set_pipeline(masked);
                ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.masked, true);
            }
        }
    }
}
