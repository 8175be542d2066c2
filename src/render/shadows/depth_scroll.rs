//! The depth pass's scrolling views (clipmap levels, [`crate::ecs::clipmap_scroll`]): a layer
//! that holds the view's content version at last frame's window is moved by whole texels
//! ([`LevelShift`](crate::render::shadows::shift::LevelShift)) and only the view's regions
//! are drawn, each cleared and drawn under its scissor rectangle; any other layer is drawn
//! whole.

use glam::IVec2;

use super::DepthPass;
use crate::ecs::view_list::Scroll;
use crate::render::draw::draw_batches;
use crate::render::frame::FrameContext;
use crate::render::shadows::casters::CasterKey;
use crate::render::shadows::gpu::CasterViewGpu;
use crate::render::shadows::shift::ShiftTarget;

impl DepthPass {
    /// Draws scrolling view `v`: moved and drawn by region where its layer allows, else whole.
    pub(super) fn scroll_or_draw(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder, v: usize) {
        let view = &ctx.shadow_views.views[v];
        let Some(scroll) = view.scroll else { return };
        let (kind, version, resolution, slot) = (view.kind, view.version, view.resolution, view.slot);
        let storage = self.storage(kind);
        let (id, layers) = &mut self.held[kind.storage.index()];
        if *id != storage.id {
            *id = storage.id;
            layers.clear();
        }
        let held = layers.get(slot as usize).copied().unwrap_or_default();
        let kept = self.cache
            && held.version == version
            && held.window == Some(scroll.from)
            && (scroll.to - scroll.from).abs().max_element() < i64::from(resolution);
        let moved = scroll.from != scroll.to;
        let shifted = kept
            && (!moved || {
                let d = scroll.to - scroll.from;
                // NOTE: target texel + offset = source texel; layer rows grow downwards.
                let offset = IVec2::new(d.x as i32, -d.y as i32);
                let (device, queue) = (&ctx.gpu.device, &ctx.gpu.queue);
                let name = &mut self.names[v];
                super::view_name(ctx.lights, &ctx.shadow_views.views[v], name);
                name.push_str(" shift");
                let timing = ctx.timer.pass(name);
                ctx.shadows.shift_scratch.as_ref().is_some_and(|scratch| {
                    let target = ShiftTarget {
                        storage: &storage,
                        scratch,
                        layer: slot,
                        resolution,
                    };
                    self.shift
                        .shift(device, queue, ctx.library, encoder, target, offset, timing)
                })
            });
        if !shifted {
            if self.claim(ctx, v) {
                let group = &ctx.shadow_views.groups[v];
                self.draw(ctx, encoder, v, 1, group);
            }
            let Some(layer) = self.held[kind.storage.index()].1.get_mut(slot as usize) else {
                return;
            };
            layer.window = Some(scroll.to);
            if !scroll.fresh {
                // NOTE: the list was made for an earlier window and may miss casters of this
                // one: culling makes it again next frame, and the layer, holding nothing it
                // can keep, is drawn whole from it.
                let view = &ctx.shadow_views.views[v];
                ctx.scroll_resync.push((view.entity, view.kind.index));
                *layer = Default::default();
            }
            return;
        }
        if moved || scroll.region_count > 0 {
            ctx.shadow_views_scrolled += 1;
            self.draw_regions(ctx, encoder, v, scroll);
        }
        if let Some(layer) = self.held[kind.storage.index()].1.get_mut(slot as usize) {
            layer.window = Some(scroll.to);
            // NOTE: what the moved layer holds is no longer the footprint of one draw.
            layer.written = None;
        }
    }

    /// Clears and draws the regions of scrolling view `v` into its layer.
    fn draw_regions(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: usize,
        scroll: Scroll,
    ) {
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return;
        };
        let view = &ctx.shadow_views.views[v];
        let Some(settings) = ctx.lights.view_settings(view) else {
            return;
        };
        let first = scroll.first_region as usize;
        let regions = &ctx.shadow_views.regions[first..first + scroll.region_count as usize];
        if regions.is_empty() {
            return;
        }
        let unclipped = ctx.gpu.unclipped_depth;
        let mut built = 0;
        let mut pipeline = |masked| {
            let key = CasterKey::new(settings, masked, unclipped);
            self.pipelines
                .get(&ctx.gpu.device, ctx.layouts, ctx.library, key, &mut built)
                .clone()
        };
        let opaque = pipeline(false);
        let masked = regions
            .iter()
            .any(|r| !r.group.masked.is_empty())
            .then(|| pipeline(true));
        ctx.counters.caster_pipelines += built;
        let clear = self.clears.get(&ctx.gpu.device, ctx.library, 0).clone();
        let storage = self.storage(view.kind);
        let name = &mut self.names[v];
        super::view_name(ctx.lights, view, name);
        name.push_str(" regions");
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name.as_str()),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &storage.layer_views[view.slot as usize],
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
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
        let mut calls = 0;
        for region in regions {
            let r = region.rect;
            if r.area() == 0 {
                continue;
            }
            ctx.shadow_drawn_texels += r.area();
            ctx.shadow_cleared_texels += r.area();
            pass.set_scissor_rect(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0);
            pass.set_pipeline(&clear);
            pass.draw(0..6, 0..1);
            pass.set_bind_group(0, &ctx.shadows.caster_group, &[offset]);
            pass.set_bind_group(1, &ctx.scene.shadow_instances_group, &[]);
            pass.set_pipeline(&opaque);
            calls += draw_batches(&mut pass, ctx.scene, &region.group.opaque, (false, &[]), ctx.draw_args);
            if let Some(masked) = &masked {
                pass.set_pipeline(masked);
                calls += draw_batches(&mut pass, ctx.scene, &region.group.masked, (true, &[]), ctx.draw_args);
            }
        }
        ctx.draw_calls += calls;
        ctx.shadow_draw_calls += calls;
    }
}
