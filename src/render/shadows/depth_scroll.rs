//! The depth pass's scrolling views (clipmap levels, [`crate::ecs::clipmap_scroll`]): a layer
//! that holds the view's content version at last frame's window keeps it, and only the view's
//! regions are drawn, each cleared and drawn under its scissor rectangle. A layer that wraps
//! ([`wrap_origin`]) keeps every texel where it is: a region is drawn where the window's texels
//! lie in it ([`wrapped_parts`]); any other layer is moved by whole texels
//! ([`LevelShift`](crate::render::shadows::shift::LevelShift)). A layer that does not hold
//! the view is drawn whole (in up to four parts where it wraps with its window elsewhere than
//! at its first texel).

use glam::{I64Vec2, IVec2, Vec2};

use super::DepthPass;
use crate::ecs::view_list::Scroll;
use crate::math::clipmap::wrapped_parts;
use crate::math::footprint::{ClipRect, TexelRect, TileMask};
use crate::render::draw::{draw_batches, draw_culled};
use crate::render::frame::FrameContext;
use crate::render::scene_gpu::IndexList;
use crate::render::shadows::casters::CasterKey;
use crate::render::shadows::gpu::{CasterViewGpu, wrap_origin};
use crate::render::shadows::shift::ShiftTarget;

/// What a scrolling view draws into its layer by rectangle.
#[derive(Clone, Copy)]
enum Parts {
    /// Its regions this frame.
    Regions(Scroll),
    /// The whole window, from the view's draw group.
    Whole,
}

/// Where a wrapping layer that held the window starting at grid texel `from` with its first
/// texel at `origin` holds the window moved by `d` grid texels (`side` texels a side).
fn advanced(origin: [u32; 2], d: I64Vec2, side: u32) -> [u32; 2] {
    let n = i64::from(side.max(1));
    [
        (i64::from(origin[0]) + d.x).rem_euclid(n) as u32,
        (i64::from(origin[1]) - d.y).rem_euclid(n) as u32,
    ]
}

impl DepthPass {
    /// Whether scrolling view `v`'s layer holds its version at last frame's window where
    /// this frame's wrap origin expects it (for a layer that does not wrap: at its first
    /// texel), with the window moved by less than a layer; and its wrap origin.
    fn held_window(&mut self, ctx: &FrameContext<'_>, v: usize) -> (bool, Option<[u32; 2]>) {
        let view = &ctx.shadow_views.views[v];
        let Some(scroll) = view.scroll else {
            return (false, None);
        };
        let (kind, version, resolution, slot) = (view.kind, view.version, view.resolution, view.slot);
        let storage = self.storage(kind);
        let wrap = wrap_origin(view, storage.side);
        let (id, layers) = &mut self.held[kind.storage.index()];
        if *id != storage.id {
            *id = storage.id;
            layers.clear();
        }
        let held = layers.get(slot as usize).copied().unwrap_or_default();
        let d = scroll.to - scroll.from;
        // NOTE: a wrapping layer is kept only where its texels lie where this frame's origin
        // says; a moved one only where it holds its window at its first texel.
        let placed = match wrap {
            Some(origin) => advanced(held.origin, d, resolution) == origin,
            None => held.origin == [0, 0],
        };
        let kept = self.cache
            && held.version == version
            && held.window == Some(scroll.from)
            && d.abs().max_element() < i64::from(resolution)
            && placed;
        (kept, wrap)
    }

    /// Claims scrolling view `v`, whose casters the GPU culls, for a whole draw: when its
    /// version is new, or its layer cannot be kept by wrapping (it holds another window, or
    /// it would have to move). Called before the culling, which then culls the view.
    pub(super) fn claim_scrolled(&mut self, ctx: &FrameContext<'_>, v: usize) -> bool {
        if self.claim(ctx, v) {
            return true;
        }
        let (kept, wrap) = self.held_window(ctx, v);
        let moved = ctx.shadow_views.views[v].scroll.is_some_and(|s| s.from != s.to);
        if kept && (wrap.is_some() || !moved) {
            return false;
        }
        self.forget(ctx, v);
        self.claim(ctx, v)
    }

    /// Marks `v`'s layer as holding nothing it can keep.
    fn forget(&mut self, ctx: &FrameContext<'_>, v: usize) {
        let view = &ctx.shadow_views.views[v];
        if let Some(layer) = self.held[view.kind.storage.index()].1.get_mut(view.slot as usize) {
            layer.version = 0;
        }
    }

    /// Draws scrolling view `v`, whose casters the GPU culls: whole from the culled list
    /// where it was claimed for that ([`Self::claim_scrolled`]), else its regions into its
    /// kept layer.
    pub(super) fn draw_gpu_scrolled(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: usize,
    ) {
        let view = &ctx.shadow_views.views[v];
        let Some(scroll) = view.scroll else { return };
        let origin = wrap_origin(view, self.storage(view.kind).side).unwrap_or_default();
        let added = if self.gpu_drawn[v] {
            self.draw_whole(ctx, encoder, v, origin)
        } else {
            Some(self.draw_regions(ctx, encoder, v, scroll, origin))
        };
        self.mark_held(ctx, v, (scroll.to, origin), added);
    }

    /// Draws claimed scrolling view `v` whole into its layer, which holds the window's first
    /// texel at `origin`; returns the tiles it adds to what the layer held: none to add where
    /// `draw` recorded them (at the layer's first texel, cleared only where it held casters),
    /// None (not known) where the window wraps round the layer.
    fn draw_whole(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: usize,
        origin: [u32; 2],
    ) -> Option<TileMask> {
        if origin == [0, 0] {
            let group = &ctx.shadow_views.groups[v];
            self.draw(ctx, encoder, v, 1, group);
            return Some(TileMask::EMPTY);
        }
        ctx.shadow_views_drawn += 1;
        self.draw_parts(ctx, encoder, v, Parts::Whole, origin);
        None
    }

    /// Draws `scroll`'s regions of view `v` into its kept layer (window's first texel at
    /// `origin`), where its window moved or it lists any; returns the tiles drawn.
    fn draw_regions(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: usize,
        scroll: Scroll,
        origin: [u32; 2],
    ) -> TileMask {
        if scroll.from == scroll.to && scroll.region_count == 0 {
            return TileMask::EMPTY;
        }
        ctx.shadow_views_scrolled += 1;
        self.draw_parts(ctx, encoder, v, Parts::Regions(scroll), origin)
    }

    /// Records that `v`'s layer holds the window starting at grid texel `to` with its first
    /// texel at `origin`, and the tiles `added` to what it held (None: which tiles hold
    /// casters is no longer known).
    fn mark_held(
        &mut self,
        ctx: &FrameContext<'_>,
        v: usize,
        (to, origin): (I64Vec2, [u32; 2]),
        added: Option<TileMask>,
    ) {
        let view = &ctx.shadow_views.views[v];
        if let Some(layer) = self.held[view.kind.storage.index()].1.get_mut(view.slot as usize) {
            layer.window = Some(to);
            layer.origin = origin;
            layer.written = layer.written.zip(added).map(|(w, a)| w.union(a));
        }
    }

    /// Draws scrolling view `v`: kept (wrapped round or moved) and drawn by region where its
    /// layer allows, else whole.
    pub(super) fn scroll_or_draw(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder, v: usize) {
        let view = &ctx.shadow_views.views[v];
        let Some(scroll) = view.scroll else { return };
        let (kind, resolution, slot) = (view.kind, view.resolution, view.slot);
        let storage = self.storage(kind);
        let (kept, wrap) = self.held_window(ctx, v);
        let d = scroll.to - scroll.from;
        let moved = scroll.from != scroll.to;
        let shifted = kept
            && (wrap.is_some() || !moved || {
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
        let origin = wrap.unwrap_or_default();
        if !shifted {
            // NOTE: what the layer holds cannot be kept: draw it whole whatever its version.
            self.forget(ctx, v);
            let added = match self.claim(ctx, v) {
                true => self.draw_whole(ctx, encoder, v, origin),
                false => Some(TileMask::EMPTY),
            };
            self.mark_held(ctx, v, (scroll.to, origin), added);
            if !scroll.fresh {
                // NOTE: the list was made for an earlier window and may miss casters of this
                // one: culling makes it again next frame, and the layer, holding nothing it
                // can keep, is drawn whole from it.
                let view = &ctx.shadow_views.views[v];
                ctx.scroll_resync.push((view.entity, view.kind.index));
                if let Some(layer) = self.held[kind.storage.index()].1.get_mut(slot as usize) {
                    *layer = Default::default();
                }
            }
            return;
        }
        let added = self.draw_regions(ctx, encoder, v, scroll, origin);
        // NOTE: a wrapping layer's texels stay where they are, and the regions add theirs;
        // what a moved layer holds is no longer the footprint of one draw.
        let added = (wrap.is_some() || !moved).then_some(added);
        self.mark_held(ctx, v, (scroll.to, origin), added);
    }

    /// Clears and draws `parts` of scrolling view `v` into its layer, which holds the
    /// window's first texel at `origin` (wrapping round its edges; `[0, 0]` where it does not
    /// wrap); returns the layer's tiles it drew.
    fn draw_parts(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: usize,
        parts: Parts,
        origin: [u32; 2],
    ) -> TileMask {
        let mut tiles = TileMask::EMPTY;
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return tiles;
        };
        let view = &ctx.shadow_views.views[v];
        let Some(settings) = ctx.lights.view_settings(view) else {
            return tiles;
        };
        let whole = matches!(parts, Parts::Whole).then(|| {
            let full = TexelRect {
                x0: 0,
                y0: 0,
                x1: view.resolution,
                y1: view.resolution,
            };
            (full, &ctx.shadow_views.groups[v])
        });
        let listed = match parts {
            Parts::Regions(scroll) => {
                let first = scroll.first_region as usize;
                &ctx.shadow_views.regions[first..first + scroll.region_count as usize]
            }
            Parts::Whole => &[],
        };
        // NOTE: a view the GPU culled draws whole from the culling's arguments; its regions
        // from the lists culling made for them.
        let culled = ctx.shadow_cull.draws(v).filter(|_| whole.is_some());
        let rects = || {
            let whole = whole.into_iter().map(|(rect, group)| (rect, group, culled));
            whole.chain(listed.iter().map(|r| (r.rect, &r.group, None)))
        };
        if rects().next().is_none() {
            return tiles;
        }
        let unclipped = ctx.gpu.unclipped_depth;
        let format = self.storage(view.kind).format();
        let mut built = 0;
        let mut pipeline = |masked| {
            let key = CasterKey::new(settings, masked, unclipped, format);
            self.pipelines
                .get(&ctx.gpu.device, ctx.layouts, ctx.library, key, &mut built)
                .clone()
        };
        let opaque = pipeline(false);
        let masked = rects().any(|(_, g, _)| !g.masked.is_empty()).then(|| pipeline(true));
        ctx.counters.caster_pipelines += built;
        let clear = self.clears.get(&ctx.gpu.device, ctx.library, (0, format)).clone();
        let storage = self.storage(view.kind);
        let name = &mut self.names[v];
        super::view_name(ctx.lights, view, name);
        if matches!(parts, Parts::Regions(_)) {
            name.push_str(" regions");
        }
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
        let side = view.resolution;
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        let offset = (v * size_of::<CasterViewGpu>()) as u32;
        let mut calls = 0;
        for (rect, group, culled) in rects() {
            // NOTE: without wrapping (`origin` 0) the one part is the rectangle itself, drawn
            // with the window at the layer's first texel.
            for ([vx, vy], r) in wrapped_parts(rect, origin, side) {
                ctx.shadow_drawn_texels += r.area();
                ctx.shadow_cleared_texels += r.area();
                tiles.add_rect(&layer_clip_rect(r, side));
                pass.set_viewport(vx as f32, vy as f32, side as f32, side as f32, 0.0, 1.0);
                pass.set_scissor_rect(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0);
                pass.set_pipeline(&clear);
                pass.draw(0..6, 0..1);
                pass.set_bind_group(0, &ctx.shadows.caster_group, &[offset]);
                let instances = culled.map_or(&ctx.scene.shadow_instances_group, |(group, ..)| group);
                pass.set_bind_group(1, instances, &[]);
                let mut draw = |pass: &mut wgpu::RenderPass<'_>, batches, masked, first_arg| match culled {
                    Some((_, args, base)) => {
                        let args = (args, base + first_arg);
                        draw_culled(pass, ctx.scene, batches, (masked, &[]), args, ctx.draw_args)
                    }
                    None => {
                        let list = (ctx.scene, IndexList::for_caster(masked, false));
                        draw_batches(pass, list, batches, (masked, &[]), ctx.draw_args)
                    }
                };
                pass.set_pipeline(&opaque);
                calls += draw(&mut pass, &group.opaque, false, 0);
                if let Some(masked) = &masked {
                    pass.set_pipeline(masked);
                    calls += draw(&mut pass, &group.masked, true, group.opaque.len() as u32);
                }
            }
        }
        ctx.draw_calls += calls;
        ctx.shadow_draw_calls += calls;
        tiles
    }
}

/// Texels `r` of a layer `side` texels wide as a clip-space rectangle (row 0 at clip `y = 1`).
fn layer_clip_rect(r: TexelRect, side: u32) -> ClipRect {
    let at = |t: u32| 2.0 * t as f32 / side.max(1) as f32 - 1.0;
    ClipRect {
        min: Vec2::new(at(r.x0), -at(r.y1)),
        max: Vec2::new(at(r.x1), -at(r.y0)),
    }
}
