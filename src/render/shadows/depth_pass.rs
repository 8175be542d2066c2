//! The depth pass: renders the casters of every shadow view of the frame whose layer does not
//! already hold it into its layer of its kind's storage. A layer remembers the content
//! version ([`ShadowView::version`]) it was last drawn with and the storage allocation it
//! belongs to; a view whose version is already there is skipped (a still scene draws no
//! shadow map after its first frame). Per view drawn: clear the layer to the reverse-Z far value (0), restrict the
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
    /// Per storage (cascades, spot lights): the allocation `held` refers to, and the content
    /// version each layer holds (0: nothing).
    held: [(u64, Vec<u64>); 2],
    /// Views whose layer holds them are skipped ([`RenderOptions::shadow_cache`](crate::render::RenderOptions)).
    cache: bool,
}

/// Index of a view kind's storage in [`DepthPass::held`].
fn storage_index(kind: ShadowViewKind) -> usize {
    match kind {
        ShadowViewKind::Cascade(_) => 0,
        ShadowViewKind::Spot => 1,
    }
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
    /// belong to that storage); with no shadow view nothing is written and the node is
    /// culled. Which views are drawn is decided while recording, when the storage is known.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.cache = inputs.options.shadow_cache;
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
            let storage = ctx.shadows.storage(view.kind);
            // NOTE: a new allocation holds nothing; every layer of it is drawn again.
            let (id, layers) = &mut self.held[storage_index(view.kind)];
            if *id != storage.id {
                *id = storage.id;
                layers.clear();
            }
            let slot = view.slot as usize;
            if self.cache && layers.get(slot) == Some(&view.version) {
                continue;
            }
            let Some(settings) = view_settings(ctx.lights, view) else {
                continue;
            };
            let Some(target) = storage.layer_views.get(slot) else {
                continue;
            };
            if layers.len() <= slot {
                layers.resize(slot + 1, 0);
            }
            layers[slot] = view.version;
            ctx.shadow_views_drawn += 1;
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
            let mut calls = draw_batches(&mut pass, ctx.scene, &group.opaque, false);
            if let Some(masked) = &masked {
                pass.set_pipeline(masked);
                calls += draw_batches(&mut pass, ctx.scene, &group.masked, true);
            }
            ctx.draw_calls += calls;
            ctx.shadow_draw_calls += calls;
        }
    }
}
