//! The paged clipmap's allocation on the GPU (`shaders/pages_allocate.wgsl`): from the bitset
//! of pages the frame needs, one compute dispatch keeps the resident pages, frees those that
//! left their window, maps the others to free or least recently needed pool pages and lists
//! the pages to draw, by the rules of [`crate::math::pages`] (the mirror the tests compare it
//! with). The page table and the pool stay on the GPU from frame to frame.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use glam::I64Vec2;

use crate::math::pages::{MAX_PAGE_AGE, PageLayout, PageRect};
use crate::render::readback::read_buffer;
use crate::render::shadows::jobs::{buffer_group, compute_pipeline, storage_entry, uniform_entry};
use crate::shader::ShaderLibrary;

/// Levels the allocation's uniforms hold (WGSL `MAX_LEVELS`).
pub const MAX_PAGED_LEVELS: usize = 8;
/// A table entry or pool page that holds nothing (WGSL `NONE`).
pub const NONE: u32 = u32::MAX;
/// Rectangles one invalidation holds (WGSL `MAX_INVALIDATIONS`).
pub const MAX_INVALIDATIONS: usize = 64;

/// Mirror of WGSL `Invalidations`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct InvalidationsGpu {
    count: u32,
    all: u32,
    _pad: [u32; 2],
    rects: [[i32; 4]; MAX_INVALIDATIONS],
    levels: [[u32; 4]; MAX_INVALIDATIONS / 4],
}

/// Mirror of WGSL `Params`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ParamsGpu {
    frame: u32,
    levels: u32,
    pages_per_side: u32,
    pool_pages: u32,
    max_age: u32,
    _pad: [u32; 3],
    windows: [[i32; 4]; MAX_PAGED_LEVELS],
}

/// Mirror of WGSL `Entry`: a level's table entry.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct EntryGpu {
    /// Its physical page, or [`NONE`].
    pub physical: u32,
    /// The grid page it maps.
    pub page_x: i32,
    /// See `page_x`.
    pub page_y: i32,
    _pad: u32,
}

impl EntryGpu {
    /// An entry holding no page.
    pub const EMPTY: Self = Self {
        physical: NONE,
        page_x: 0,
        page_y: 0,
        _pad: 0,
    };
}

/// Mirror of WGSL `Page`: a page of the pool.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct PageGpu {
    /// `level << 24 | entry` of the entry that maps it, or [`NONE`].
    pub owner: u32,
    /// The last frame it was needed.
    pub last_needed: u32,
    /// 1 when it holds its page's depth.
    pub drawn: u32,
    _pad: u32,
}

/// What one allocation did, read back.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AllocationGpu {
    /// Needed pages resident and drawn.
    pub kept: u32,
    /// Pages to draw: (`level << 24 | entry`, physical page), in no particular order.
    pub draws: Vec<(u32, u32)>,
    /// Pages evicted.
    pub evicted: u32,
    /// Needed pages left unmapped.
    pub overflowed: u32,
}

/// The allocation's pipeline and buffers: the needed bitset, every level's table, the pool,
/// the pool's order, the counters and the draw list.
pub struct PageAllocator {
    layout: PageLayout,
    levels: u32,
    pool_pages: u32,
    pipeline: wgpu::ComputePipeline,
    /// The counters of a frame that repeats the last (`still`).
    still: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    invalidate: (wgpu::ComputePipeline, wgpu::BindGroup, wgpu::Buffer),
    params: wgpu::Buffer,
    /// The pages needed this frame, a bit per table entry (level by level).
    pub needed: wgpu::Buffer,
    table: wgpu::Buffer,
    pool: wgpu::Buffer,
    counters: wgpu::Buffer,
    draws: wgpu::Buffer,
}

fn storage_buffer(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl PageAllocator {
    /// Tables for `levels` levels (at most [`MAX_PAGED_LEVELS`]) cut by `layout`, and a pool
    /// of `pool_pages` pages, every entry and page empty.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        library: &mut ShaderLibrary,
        layout: PageLayout,
        levels: u32,
        pool_pages: u32,
    ) -> Self {
        let levels = levels.min(MAX_PAGED_LEVELS as u32);
        let entries = u64::from(levels) * layout.entries() as u64;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("page allocation params"),
            size: size_of::<ParamsGpu>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let needed = storage_buffer(device, "pages needed", entries.div_ceil(32) * 4);
        let table = storage_buffer(device, "page table", entries * size_of::<EntryGpu>() as u64);
        let pool = storage_buffer(device, "page pool", u64::from(pool_pages) * size_of::<PageGpu>() as u64);
        let order = storage_buffer(device, "page pool order", u64::from(pool_pages) * 4);
        let counters = storage_buffer(device, "page counters", 16);
        let draws = storage_buffer(device, "pages to draw", entries * 8);
        queue.write_buffer(
            &table,
            0,
            bytemuck::cast_slice(&vec![EntryGpu::EMPTY; entries as usize]),
        );
        let free = PageGpu {
            owner: NONE,
            ..PageGpu::default()
        };
        queue.write_buffer(&pool, 0, bytemuck::cast_slice(&vec![free; pool_pages as usize]));
        let module = library
            .pages_allocate()
            .expect("the shipped allocation shader composes (checked by tests)");
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("page allocation"),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let params_entry = uniform_entry(0, compute, false, size_of::<ParamsGpu>() as u64);
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page allocation"),
            entries: &[
                params_entry,
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
                storage_entry(3, compute, false),
                storage_entry(4, compute, false),
                storage_entry(5, compute, false),
                storage_entry(6, compute, false),
            ],
        });
        let buffers = [&params, &needed, &table, &pool, &order, &counters, &draws];
        let group = buffer_group(device, "page allocation", &group_layout, &buffers);
        let pipeline = compute_pipeline(device, "page allocation", &shader, &group_layout, "main");
        let still = compute_pipeline(device, "page allocation (still)", &shader, &group_layout, "still");
        let invalidations = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("page invalidations"),
            size: size_of::<InvalidationsGpu>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let invalidate_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page invalidation"),
            entries: &[
                params_entry,
                storage_entry(2, compute, false),
                storage_entry(3, compute, false),
                uniform_entry(7, compute, false, size_of::<InvalidationsGpu>() as u64),
            ],
        });
        let invalidate_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("page invalidation"),
            layout: &invalidate_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: table.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: pool.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: invalidations.as_entire_binding(),
                },
            ],
        });
        let invalidate_pipeline =
            compute_pipeline(device, "page invalidation", &shader, &invalidate_layout, "invalidate");
        let allocator = Self {
            layout,
            levels,
            pool_pages,
            pipeline,
            still,
            group,
            invalidate: (invalidate_pipeline, invalidate_group, invalidations),
            params,
            needed,
            table,
            pool,
            counters,
            draws,
        };
        // NOTE: the invalidation reads the tables' size from the parameters; each allocation
        // writes them again with its frame and windows.
        allocator.write_params(queue, 0, &[]);
        allocator
    }

    /// Records the invalidation of the drawn pages of each `(level, pages)` rectangle (the
    /// first [`MAX_INVALIDATIONS`]), or of every page with `all`: they are drawn again when
    /// next needed. Record it before the frame's allocation.
    pub fn record_invalidation(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        rects: &[(u32, PageRect)],
        all: bool,
    ) {
        let mut data = InvalidationsGpu {
            count: rects.len().min(MAX_INVALIDATIONS) as u32,
            all: u32::from(all),
            _pad: [0; 2],
            rects: [[0; 4]; MAX_INVALIDATIONS],
            levels: [[0; 4]; MAX_INVALIDATIONS / 4],
        };
        for (i, (level, r)) in rects.iter().take(MAX_INVALIDATIONS).enumerate() {
            data.rects[i] = [r.min.x as i32, r.min.y as i32, r.max.x as i32, r.max.y as i32];
            data.levels[i / 4][i % 4] = *level;
        }
        let (pipeline, group, buffer) = &self.invalidate;
        queue.write_buffer(buffer, 0, bytemuck::bytes_of(&data));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("page invalidation"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(self.pool_pages.div_ceil(64), 1, 1);
    }

    /// Records frame `frame`'s allocation with each level's window starting at grid page
    /// `windows[level]`, from the bitset in [`needed`](Self::needed), timed by `timestamps`.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        (frame, windows): (u32, &[I64Vec2]),
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        self.write_params(queue, frame, windows);
        encoder.clear_buffer(&self.counters, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("page allocation"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Records the counters of a frame whose marking and allocation would repeat the last
    /// one's (the caller skips them): every page drawn last frame is kept, none evicted, the
    /// overflow the same; the tables and the pool are left as they are.
    pub fn record_still(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("page allocation (still)"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.still);
        pass.set_bind_group(0, &self.group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    fn write_params(&self, queue: &wgpu::Queue, frame: u32, windows: &[I64Vec2]) {
        let mut params = ParamsGpu {
            frame,
            levels: self.levels,
            pages_per_side: self.layout.pages_per_side(),
            pool_pages: self.pool_pages,
            max_age: MAX_PAGE_AGE as u32,
            _pad: [0; 3],
            windows: [[0; 4]; MAX_PAGED_LEVELS],
        };
        for (w, first) in params.windows.iter_mut().zip(windows) {
            *w = [first.x as i32, first.y as i32, 0, 0];
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
    }

    /// Reads back the last allocation's counters (kept, drawn, evicted, overflowed) and how
    /// many pool pages hold a page: the pool and the counters only, not the tables (waits for
    /// the GPU; None when the device failed to map them).
    pub fn read_counts(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<([u32; 4], u32)> {
        let pool: Vec<PageGpu> = pods(&read_storage(device, queue, &self.pool)?);
        let counters: Vec<u32> = pods(&read_storage(device, queue, &self.counters)?);
        let resident = pool.iter().filter(|p| p.owner != NONE).count() as u32;
        Some(([counters[0], counters[1], counters[2], counters[3]], resident))
    }

    /// Reads back the tables, the pool and the last allocation (waits for the GPU; None when
    /// the device failed to map them).
    pub fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Option<(Vec<EntryGpu>, Vec<PageGpu>, AllocationGpu)> {
        let table: Vec<EntryGpu> = pods(&read_storage(device, queue, &self.table)?);
        let pool: Vec<PageGpu> = pods(&read_storage(device, queue, &self.pool)?);
        let counters: Vec<u32> = pods(&read_storage(device, queue, &self.counters)?);
        let draws: Vec<[u32; 2]> = pods(&read_storage(device, queue, &self.draws)?);
        let allocation = AllocationGpu {
            kept: counters[0],
            draws: draws[..counters[1] as usize].iter().map(|d| (d[0], d[1])).collect(),
            evicted: counters[2],
            overflowed: counters[3],
        };
        Some((table, pool, allocation))
    }
}

/// The `T`s in `bytes`.
fn pods<T: Pod>(bytes: &[u8]) -> Vec<T> {
    bytes
        .chunks_exact(size_of::<T>())
        .map(bytemuck::pod_read_unaligned)
        .collect()
}

impl PageAllocator {
    /// How its levels are cut into pages.
    pub fn layout(&self) -> PageLayout {
        self.layout
    }

    /// Pages in its pool.
    pub fn pool_pages(&self) -> u32 {
        self.pool_pages
    }

    /// The list of pages to draw, the counters (the second is the list's length) and the
    /// tables: what the page drawing reads.
    pub fn draw_buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer, &wgpu::Buffer) {
        (&self.draws, &self.counters, &self.table)
    }

    /// Reads back the bitset of needed pages (waits for the GPU).
    pub fn read_needed(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Vec<u32>> {
        Some(pods(&read_storage(device, queue, &self.needed)?))
    }
}

/// A copy of storage buffer `buffer` (waits for the GPU).
fn read_storage(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer) -> Option<Vec<u8>> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("page readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    read_buffer(device, &staging, buffer.size())
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;
    use crate::render::shadows::jobs::layout_check::wgsl_layout;

    #[test]
    fn the_uniforms_and_records_match_the_wgsl_layout() {
        let module = ShaderLibrary::new().unwrap().pages_allocate().unwrap();
        let fields = |list: &[(&str, usize)]| list.iter().map(|(n, o)| (n.to_string(), *o)).collect::<Vec<_>>();
        let params = [
            ("frame", offset_of!(ParamsGpu, frame)),
            ("levels", offset_of!(ParamsGpu, levels)),
            ("pages_per_side", offset_of!(ParamsGpu, pages_per_side)),
            ("pool_pages", offset_of!(ParamsGpu, pool_pages)),
            ("max_age", offset_of!(ParamsGpu, max_age)),
            ("windows", offset_of!(ParamsGpu, windows)),
        ];
        assert_eq!(
            wgsl_layout(&module, "Params"),
            (fields(&params), size_of::<ParamsGpu>())
        );
        let entry = [
            ("physical", offset_of!(EntryGpu, physical)),
            ("page_x", offset_of!(EntryGpu, page_x)),
            ("page_y", offset_of!(EntryGpu, page_y)),
        ];
        assert_eq!(wgsl_layout(&module, "Entry"), (fields(&entry), size_of::<EntryGpu>()));
        let page = [
            ("owner", offset_of!(PageGpu, owner)),
            ("last_needed", offset_of!(PageGpu, last_needed)),
            ("drawn", offset_of!(PageGpu, drawn)),
        ];
        assert_eq!(wgsl_layout(&module, "Page"), (fields(&page), size_of::<PageGpu>()));
        let invalidations = [
            ("count", offset_of!(InvalidationsGpu, count)),
            ("all", offset_of!(InvalidationsGpu, all)),
            ("rects", offset_of!(InvalidationsGpu, rects)),
            ("levels", offset_of!(InvalidationsGpu, levels)),
        ];
        assert_eq!(
            wgsl_layout(&module, "Invalidations"),
            (fields(&invalidations), size_of::<InvalidationsGpu>())
        );
    }
}
