// Depth bounds for the sample-distribution (SDSM) cascade fit: reduces the camera's depth
// buffer to the view-depth range of the pixels it covered and, per band of view depth
// (logarithmic between the camera's near and far planes, penumbra::math::seen_depths), the
// world box of those pixels. Each workgroup reduces its 16×16 pixels in workgroup memory and
// merges the words it changed into the frame's buffer with atomic min and max on
// order-preserving float bits. The CPU writes the buffer's start values each frame: the band
// limits (words 0 and 1, plain f32 bits) and every minimum at 0xffffffff, maximum at 0.
//
// With MSAA (MULTISAMPLED) the depth is multisampled and each pixel is read at sample 0.
#import penumbra::frame::{frame, world_at}

const BANDS: u32 = 32u;
const WORDS: u32 = 196u;
const EMPTY_MIN: u32 = 0xffffffffu;

#ifdef MULTISAMPLED
@group(1) @binding(0) var camera_depth: texture_depth_multisampled_2d;
#else
@group(1) @binding(0) var camera_depth: texture_depth_2d;
#endif
@group(1) @binding(1) var<storage, read_write> seen: array<atomic<u32>, 196>;

var<workgroup> local: array<atomic<u32>, 196>;

// The float's bits mapped so that unsigned order is the float's order.
fn ordered(v: f32) -> u32 {
    let bits = bitcast<u32>(v);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

// Whether word `i` is a minimum (the depth's, or a band's min x, y, z).
fn is_minimum(i: u32) -> bool {
    return i == 2u || (i >= 4u && (i - 4u) % 6u < 3u);
}

@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    for (var i = li; i < WORDS; i += 256u) {
        atomicStore(&local[i], select(0u, EMPTY_MIN, is_minimum(i)));
    }
    workgroupBarrier();
    let size = textureDimensions(camera_depth);
    if id.x < size.x && id.y < size.y {
        // NOTE: the last argument is the mip level, or with MSAA the sample index: sample 0.
        let depth = textureLoad(camera_depth, vec2<i32>(id.xy), 0);
        // Reverse-Z: 0 is the far plane, where nothing was drawn.
        if depth > 0.0 {
            let pixel = vec2<f32>(id.xy) + 0.5;
            let world = world_at(pixel, depth, size);
            let view_depth = -(frame.view_from_world * vec4<f32>(world, 1.0)).z;
            let near = bitcast<f32>(atomicLoad(&seen[0]));
            let far = bitcast<f32>(atomicLoad(&seen[1]));
            let t = log(view_depth / near) / log(far / near);
            // NOTE: written so that a NaN or infinite depth or position is skipped.
            let finite = view_depth > 0.0 && view_depth < 3.0e38 && all(abs(world) < vec3<f32>(3.0e38));
            if finite {
                let band = u32(clamp(floor(t * f32(BANDS)), 0.0, f32(BANDS - 1u)));
                atomicMin(&local[2], ordered(view_depth));
                atomicMax(&local[3], ordered(view_depth));
                let b = 4u + 6u * band;
                for (var k = 0u; k < 3u; k++) {
                    atomicMin(&local[b + k], ordered(world[k]));
                    atomicMax(&local[b + 3u + k], ordered(world[k]));
                }
            }
        }
    }
    workgroupBarrier();
    for (var i = 2u + li; i < WORDS; i += 256u) {
        let v = atomicLoad(&local[i]);
        if is_minimum(i) {
            if v != EMPTY_MIN {
                atomicMin(&seen[i], v);
            }
        } else if v != 0u {
            atomicMax(&seen[i], v);
        }
    }
}
