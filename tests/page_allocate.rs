//! The paged clipmap's allocation on a real wgpu device (lavapipe in CI) against its CPU
//! mirror (`math::pages::VirtualPages::allocate`) on recorded frames: a walk whose windows
//! move and whose needed pages come and go, with a pool too small for some frames (pages are
//! evicted and overflow), still frames between, and pages invalidated by a moving caster and
//! by the light turning. After every frame the GPU's tables and pool equal the mirror's entry
//! for entry, and so do the counts and the pages to draw.

// NOTE: this test draws only raw bits from the shared generator.
#[allow(dead_code)]
#[path = "common/xorshift.rs"]
mod xorshift;

use glam::I64Vec2;
use penumbra::math::pages::{PageKey, PageLayout, PageRect, VirtualPages};
use penumbra::render::GpuContext;
use penumbra::render::shadows::page_allocate::{NONE, PageAllocator};
use penumbra::shader::ShaderLibrary;
use xorshift::Xorshift;

const LEVELS: u32 = 3;
const POOL: u32 = 300;

/// One recorded frame: each level's window (its first page) and the pages needed.
struct Frame {
    windows: Vec<I64Vec2>,
    needed: Vec<PageKey>,
}

/// A walk of `count` frames: the finest window moves up to 2 pages a frame (each coarser
/// level half as far), and each level needs the pages within 2–8 pages of a point near its
/// centre; every fourth frame repeats the one before (a still frame).
fn walk(layout: &PageLayout, count: usize) -> Vec<Frame> {
    let mut rng = Xorshift(0x9e37_79b9_7f4a_7c15);
    let mut pick = |lo: i64, hi: i64| lo + (rng.next() % (hi - lo + 1) as u64) as i64;
    let n = i64::from(layout.pages_per_side());
    let mut camera = I64Vec2::ZERO;
    let mut frames: Vec<Frame> = Vec::new();
    for f in 0..count {
        if f % 4 == 3 {
            let last = frames.last().expect("a frame before");
            let repeat = Frame {
                windows: last.windows.clone(),
                needed: last.needed.clone(),
            };
            frames.push(repeat);
            continue;
        }
        camera += I64Vec2::new(pick(-2, 2), pick(-2, 2));
        let mut windows = Vec::new();
        let mut needed = Vec::new();
        for level in 0..LEVELS {
            let centre = camera.div_euclid(I64Vec2::splat(1 << level));
            let first = centre - I64Vec2::splat(n / 2);
            let at = centre + I64Vec2::new(pick(-3, 3), pick(-3, 3));
            let radius = pick(2, 8);
            let near = PageRect {
                min: at - I64Vec2::splat(radius),
                max: at + I64Vec2::splat(radius),
            };
            needed.extend(near.pages().map(|p| PageKey::new(level, p)));
            windows.push(first);
        }
        // NOTE: the GPU serves the pages in level then table-entry order.
        // NOTE: the coarsest level first, as the GPU ranks them.
        needed.sort_by_key(|k| (std::cmp::Reverse(k.level), layout.entry(k.grid())));
        frames.push(Frame { windows, needed });
    }
    frames
}

#[test]
fn the_gpu_allocates_pages_as_its_cpu_mirror_does() {
    let gpu = GpuContext::headless()
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut library = ShaderLibrary::new().unwrap();
    let layout = PageLayout::new(4096, 128).unwrap();
    let per_level = layout.entries();
    let allocator = PageAllocator::new(device, queue, &mut library, layout, LEVELS, POOL);
    let mut mirror = VirtualPages::new(layout, LEVELS, POOL);
    let (mut drawn, mut evicted, mut overflowed, mut still, mut invalidated) = (0, 0, 0, 0, 0);
    for (f, frame) in walk(&layout, 24).iter().enumerate() {
        // NOTE: a caster moving over the window's centre in the levels it reaches, every
        // fifth frame that is not a still one, and the light turning once.
        let centre = frame.windows[0] + I64Vec2::splat(i64::from(layout.pages_per_side()) / 2);
        let caster: Vec<(u32, PageRect)> = (0..2)
            .map(|level| {
                let at = frame.windows[level as usize] + (centre - frame.windows[0]) / (1 << level);
                let rect = PageRect {
                    min: at - I64Vec2::new(1, 2),
                    max: at + I64Vec2::new(2, 1),
                };
                (level, rect)
            })
            .collect();
        let (moved, all): (&[(u32, PageRect)], bool) = match f {
            10 => (&[], true),
            _ if f % 5 == 1 && f % 4 != 3 => (&caster, false),
            _ => (&[], false),
        };
        let mut marked = 0;
        for (level, rect) in moved {
            marked += mirror.invalidate(*level, rect);
        }
        if all {
            marked += mirror.invalidate_all();
        }
        invalidated += marked;
        let number = f as u32 + 1;
        let rects: Vec<PageRect> = frame.windows.iter().map(|w| layout.window(*w * 128)).collect();
        let cpu = mirror.allocate(u64::from(number), &frame.needed, &rects);
        for &(_, p) in &cpu.draw {
            mirror.mark_drawn(p);
        }
        let mut bits = vec![0u32; (LEVELS as usize * per_level).div_ceil(32)];
        for key in &frame.needed {
            let i = key.level as usize * per_level + layout.entry(key.grid());
            bits[i / 32] |= 1 << (i % 32);
        }
        queue.write_buffer(&allocator.needed, 0, bytemuck::cast_slice(&bits));
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        if all || !moved.is_empty() {
            allocator.record_invalidation(queue, &mut encoder, moved, all);
        }
        allocator.record(queue, &mut encoder, (number, &frame.windows), None);
        queue.submit([encoder.finish()]);
        let (table, pool, got) = allocator.read(device, queue).expect("the buffers read back");
        let key_of = |k: &PageKey| k.level << 24 | layout.entry(k.grid()) as u32;
        let mut want: Vec<(u32, u32)> = cpu.draw.iter().map(|(k, p)| (key_of(k), *p)).collect();
        let mut draws = got.draws.clone();
        want.sort();
        draws.sort();
        println!(
            "frame {number}: {} needed, kept {}, drawn {}, evicted {}, overflowed {}",
            frame.needed.len(),
            got.kept,
            draws.len(),
            got.evicted,
            got.overflowed
        );
        assert_eq!(draws, want, "frame {number}: the pages to draw");
        assert_eq!(
            (got.kept, got.evicted, got.overflowed),
            (cpu.kept, cpu.evicted.len() as u32, cpu.overflowed.len() as u32),
            "frame {number}: kept, evicted, overflowed"
        );
        for (level, entries) in mirror.tables.iter().enumerate() {
            for (e, entry) in entries.iter().enumerate() {
                let g = table[level * per_level + e];
                let gpu_entry =
                    (g.physical != NONE).then_some((g.physical, I64Vec2::new(g.page_x.into(), g.page_y.into())));
                let cpu_entry = entry.map(|x| (x.physical, x.page));
                assert_eq!(gpu_entry, cpu_entry, "frame {number}: level {level} entry {e}");
            }
        }
        for (p, page) in mirror.pool.iter().enumerate() {
            let g = pool[p];
            let owner = (g.owner != NONE).then_some((g.owner >> 24, g.owner & 0xff_ffff));
            assert_eq!(owner, page.owner, "frame {number}: owner of physical page {p}");
            if owner.is_some() {
                assert_eq!(
                    u64::from(g.last_needed),
                    page.last_needed,
                    "frame {number}: page {p} last needed"
                );
                assert_eq!(g.drawn == 1, page.drawn, "frame {number}: page {p} drawn");
            }
        }
        drawn += draws.len();
        evicted += got.evicted;
        overflowed += got.overflowed;
        if f % 4 == 3 {
            still += 1;
            assert!(
                draws.is_empty(),
                "frame {number}: a still frame drew {} pages",
                draws.len()
            );
        }
    }
    println!(
        "{drawn} pages drawn, {evicted} evicted, {overflowed} overflowed, {invalidated} invalidated, {still} still frames"
    );
    assert!(invalidated > 100, "only {invalidated} drawn pages invalidated");
    assert!(drawn > 1000, "only {drawn} pages drawn over the walk");
    assert!(evicted > 50, "only {evicted} pages evicted: the pool was never full");
    assert!(overflowed > 0, "no page overflowed");
    assert_eq!(still, 6);
}
