// The arguments of one indexed indirect draw, as `draw_indexed_indirect` reads them, with the
// instance count atomic so a culling pass can count the instances it lists (the Rust side is
// `render::draw_args::IndexedArgs`).

#define_import_path penumbra::indirect

struct DrawArgs {
    index_count: u32,
    instance_count: atomic<u32>,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}
