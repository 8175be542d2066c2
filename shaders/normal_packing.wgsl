// A unit normal and two flags in one u32: the normal octahedron-encoded (two 16-bit snorm,
// Cigolle et al. 2014), the receiver flag in the lowest bit (taken from x's last bit) and the
// transmission flag in bit 16 (y's last bit). What the depth prepass writes for the compute
// resolve: half the bytes of an Rgba16Float.
#define_import_path penumbra::normal_packing

// Folds the lower hemisphere of the octahedron over its upper one.
fn octahedron_wrap(v: vec2<f32>) -> vec2<f32> {
    return (1.0 - abs(v.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

const FLAG_BITS: u32 = 0x10001u;

// Packs unit `normal`, `receives` (shadows) and `transmits` (light to its other side).
fn pack_normal(normal: vec3<f32>, receives: bool, transmits: bool) -> u32 {
    var p = normal.xy / (abs(normal.x) + abs(normal.y) + abs(normal.z));
    if normal.z < 0.0 {
        p = octahedron_wrap(p);
    }
    return (pack2x16snorm(p) & ~FLAG_BITS) | select(0u, 1u, receives) | select(0u, 0x10000u, transmits);
}

// Whether the packed surface passes light to its other side (a material with diffuse
// transmission).
fn packed_transmits(packed: u32) -> bool {
    return (packed & 0x10000u) != 0u;
}

// xyz: the unit normal, w: 1 where the pixel receives shadows.
fn unpack_normal(packed: u32) -> vec4<f32> {
    let f = unpack2x16snorm(packed & ~FLAG_BITS);
    var n = vec3<f32>(f, 1.0 - abs(f.x) - abs(f.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return vec4<f32>(normalize(n), f32(packed & 1u));
}
