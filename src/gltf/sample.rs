//! The procedural sample model: a potted fern about 1.6 m tall standing on y = 0, written
//! to `assets/models/` by `cargo run --example make_sample_gltf`.
//!
//! The model exercises what the loader reads: a terracotta pot (one mesh, two primitives:
//! body and soil, two opaque materials), a stem, and alpha-masked, double-sided leaf cards
//! whose texture has cut-out leaflets and holes, so their shadows are lacy. The node
//! hierarchy is four levels deep (`fern` → `stem` → `crown` → `crown_top` → fronds), each
//! level rotated, translated or scaled. Everything is computed from constants with
//! IEEE-exact arithmetic (rotations in f64, rounded to f32), so [`build`] returns the same
//! bytes every time.

use std::collections::BTreeMap;

use ::gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use ::gltf::json::buffer::Target;
use ::gltf::json::material::{AlphaCutoff, AlphaMode, PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor};
use ::gltf::json::mesh::{Mode, Semantic};
use ::gltf::json::scene::UnitQuaternion;
use ::gltf::json::validation::{Checked, USize64};
use ::gltf::json::{self, Index};
use glam::{DQuat, Vec2, Vec3};
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::gltf::material::DIFFUSE_TRANSMISSION;

/// File name of the sample's glTF JSON.
pub const SAMPLE_GLTF: &str = "fern.gltf";
/// File name of the sample's binary buffer, referenced by [`SAMPLE_GLTF`].
pub const SAMPLE_BIN: &str = "fern.bin";
/// File name of the sample's leaf texture, referenced by [`SAMPLE_GLTF`].
pub const SAMPLE_PNG: &str = "fern_leaf.png";
/// Directory of the shipped sample, relative to the repository root.
pub const SAMPLE_DIR: &str = "assets/models";

/// Width of the leaf texture in pixels.
pub const LEAF_TEXTURE_WIDTH: u32 = 64;
/// Height of the leaf texture in pixels (the card is longer than wide).
pub const LEAF_TEXTURE_HEIGHT: u32 = 128;
/// Half the width of a leaf card, in metres (cards span x in ±this).
pub const FROND_HALF_WIDTH: f32 = 0.15;
/// Length of a leaf card from its base (mesh origin) to its tip at (0, this, 0), in metres.
pub const FROND_LENGTH: f32 = 0.7;
/// The fronds' diffuse transmission (`KHR_materials_diffuse_transmission`).
pub const LEAF_TRANSMISSION: f64 = 0.4;

/// The three files of the sample model, ready to write side by side.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SampleFiles {
    /// Contents of [`SAMPLE_GLTF`] (pretty-printed JSON, trailing newline).
    pub gltf: String,
    /// Contents of [`SAMPLE_BIN`].
    pub bin: Vec<u8>,
    /// Contents of [`SAMPLE_PNG`]: a 64×128 RGBA leaf, alpha 0 outside it.
    pub png: Vec<u8>,
}

/// Builds the sample model's files.
pub fn build() -> SampleFiles {
    let mut b = Builder::default();

    let terracotta = b.material("terracotta", [0.60, 0.22, 0.10, 1.0], None);
    let soil = b.material("soil", [0.10, 0.06, 0.035, 1.0], None);
    let stem_material = b.material("stem", [0.16, 0.24, 0.06, 1.0], None);
    let image = b.root.push(json::Image {
        buffer_view: None,
        mime_type: None,
        name: Some("fern_leaf".into()),
        uri: Some(SAMPLE_PNG.into()),
        extensions: None,
        extras: Default::default(),
    });
    let texture = b.root.push(json::Texture {
        name: Some("fern_leaf".into()),
        sampler: None,
        source: image,
        extensions: None,
        extras: Default::default(),
    });
    let leaf = b.material("frond", [1.0, 1.0, 1.0, 1.0], Some(texture));

    let pot_body = b.primitive(&pot_body(), terracotta);
    let pot_soil = b.primitive(&pot_soil(), soil);
    let pot = b.mesh("pot", vec![pot_body, pot_soil]);
    let stem_primitive = b.primitive(&stem(), stem_material);
    let stem = b.mesh("stem", vec![stem_primitive]);
    let frond_primitive = b.primitive(&frond(), leaf);
    let frond = b.mesh("frond", vec![frond_primitive]);

    // The hierarchy, parents first: fern → pot, stem → crown → fronds, crown_top → fronds.
    let root_node = b.node(Node::new("fern").rotation(DQuat::from_rotation_y(90f64.to_radians())));
    b.child(
        root_node,
        Node::new("pot")
            .mesh(pot)
            .rotation(DQuat::from_rotation_y(45f64.to_radians())),
    );
    let stem_node = b.child(root_node, Node::new("stem").mesh(stem).translation([0.0, 0.3, 0.0]));
    let crown = b.child(
        stem_node,
        Node::new("crown")
            .translation([0.0, 0.6, 0.0])
            .rotation(DQuat::from_rotation_y(30f64.to_radians())),
    );
    // Lower ring: six fronds leaning 60° out from the vertical, varied in size.
    for (k, s) in [1.0, 0.9, 1.1, 0.95, 1.05, 0.85].into_iter().enumerate() {
        let turn = DQuat::from_rotation_y((60.0 * k as f64).to_radians());
        let lean = DQuat::from_rotation_x(60f64.to_radians());
        b.child(
            crown,
            Node::new(&format!("frond_{k}"))
                .mesh(frond)
                .rotation(turn * lean)
                .scale([s; 3]),
        );
    }
    // Upper ring: three more upright fronds under a raised, turned and shrunk crown.
    let crown_top = b.child(
        crown,
        Node::new("crown_top")
            .translation([0.0, 0.25, 0.0])
            .rotation(DQuat::from_rotation_y(30f64.to_radians()))
            .scale([0.8; 3]),
    );
    for k in 0..3 {
        let turn = DQuat::from_rotation_y((120.0 * k as f64).to_radians());
        let lean = DQuat::from_rotation_x(30f64.to_radians());
        b.child(
            crown_top,
            Node::new(&format!("top_frond_{k}")).mesh(frond).rotation(turn * lean),
        );
    }
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some("fern".into()),
        nodes: vec![root_node],
    });
    b.root.scene = Some(scene);
    b.root.asset.generator = Some("penumbra::gltf::sample".into());
    b.root.extensions_used.push(DIFFUSE_TRANSMISSION.to_owned());
    b.root.buffers.push(json::Buffer {
        byte_length: USize64::from(b.bin.len()),
        name: Some("fern".into()),
        uri: Some(SAMPLE_BIN.into()),
        extensions: None,
        extras: Default::default(),
    });

    let mut gltf = json::serialize::to_string_pretty(&b.root).expect("the sample's JSON serializes");
    gltf.push('\n');
    SampleFiles {
        gltf,
        bin: b.bin,
        png: leaf_png(),
    }
}

/// Geometry of one primitive before it is written: counter-clockwise triangles.
#[derive(Default)]
struct Geometry {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<u16>,
}

impl Geometry {
    /// A quad from four corners in counter-clockwise order seen from the front, UVs from
    /// bottom-left (0, 1) round to top-left (0, 0).
    fn quad(&mut self, corners: [Vec3; 4], normal: Vec3) {
        let base = self.positions.len() as u16;
        let uvs = [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        for (p, uv) in corners.into_iter().zip(uvs) {
            self.positions.push(p);
            self.normals.push(normal);
            self.uvs.push(uv);
        }
        self.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    }
}

/// Pot half widths at the bottom and the top, and its height.
const POT_BOTTOM: f32 = 0.16;
const POT_TOP: f32 = 0.21;
const POT_HEIGHT: f32 = 0.34;

/// The pot's tapered sides and bottom (open at the top, where the soil closes it).
fn pot_body() -> Geometry {
    let mut g = Geometry::default();
    let (b, t, h) = (POT_BOTTOM, POT_TOP, POT_HEIGHT);
    // Side facing +X; the others are it turned about Y by 90° steps (exact swaps).
    let side = [
        Vec3::new(b, 0.0, b),
        Vec3::new(b, 0.0, -b),
        Vec3::new(t, h, -t),
        Vec3::new(t, h, t),
    ];
    let normal = Vec3::new(h, -(t - b), 0.0).normalize();
    let turn = |v: Vec3| Vec3::new(v.z, v.y, -v.x);
    let (mut corners, mut n) = (side, normal);
    for _ in 0..4 {
        g.quad(corners, n);
        corners = corners.map(turn);
        n = turn(n);
    }
    g.quad(
        [
            Vec3::new(-b, 0.0, -b),
            Vec3::new(b, 0.0, -b),
            Vec3::new(b, 0.0, b),
            Vec3::new(-b, 0.0, b),
        ],
        Vec3::NEG_Y,
    );
    g
}

/// The soil: the pot's top face.
fn pot_soil() -> Geometry {
    let mut g = Geometry::default();
    let (t, h) = (POT_TOP, POT_HEIGHT);
    g.quad(
        [
            Vec3::new(-t, h, t),
            Vec3::new(t, h, t),
            Vec3::new(t, h, -t),
            Vec3::new(-t, h, -t),
        ],
        Vec3::Y,
    );
    g
}

/// A thin square stem from y = 0 to 0.62 (its node lifts its base into the pot).
fn stem() -> Geometry {
    let mut g = Geometry::default();
    let (r, h) = (0.02, 0.62);
    let side = [
        Vec3::new(r, 0.0, r),
        Vec3::new(r, 0.0, -r),
        Vec3::new(r, h, -r),
        Vec3::new(r, h, r),
    ];
    let turn = |v: Vec3| Vec3::new(v.z, v.y, -v.x);
    let (mut corners, mut n) = (side, Vec3::X);
    for _ in 0..4 {
        g.quad(corners, n);
        corners = corners.map(turn);
        n = turn(n);
    }
    g.quad(
        [
            Vec3::new(-r, h, r),
            Vec3::new(r, h, r),
            Vec3::new(r, h, -r),
            Vec3::new(-r, h, -r),
        ],
        Vec3::Y,
    );
    g
}

/// A leaf card in the XY plane facing +Z, base at the origin, tip at (0, FROND_LENGTH, 0).
fn frond() -> Geometry {
    let mut g = Geometry::default();
    let (w, l) = (FROND_HALF_WIDTH, FROND_LENGTH);
    g.quad(
        [
            Vec3::new(-w, 0.0, 0.0),
            Vec3::new(w, 0.0, 0.0),
            Vec3::new(w, l, 0.0),
            Vec3::new(-w, l, 0.0),
        ],
        Vec3::Z,
    );
    g
}

/// The leaf texture: a frond seen flat, in card metres (x across, y from base to tip),
/// with leaflets slanting up from a central stalk, gaps between them and a few
/// round holes. Rows top (tip) to bottom (base).
fn leaf_rgba() -> Vec<u8> {
    let (width, height) = (LEAF_TEXTURE_WIDTH, LEAF_TEXTURE_HEIGHT);
    // Leaflet direction: out and up, (2, 1) / √5.
    let (dx, dy) = (0.894_427_2_f32, 0.447_213_6_f32);
    let holes = [(1, 1.0), (3, 1.0), (2, -1.0)];
    let mut rgba = Vec::with_capacity((width * height * 4) as usize);
    for row in 0..height {
        for col in 0..width {
            let u = (col as f32 + 0.5) / width as f32;
            let v = (row as f32 + 0.5) / height as f32;
            let (x, y) = ((u - 0.5) * 2.0 * FROND_HALF_WIDTH, (1.0 - v) * FROND_LENGTH);
            // Distance along a leaflet (0 at the stalk, 1 at its tip) where (x, y) is inside one.
            let mut inside: Option<f32> = None;
            let mut blade = |ax: f32, ay: f32, bx: f32, by: f32, half_width: f32| {
                let (ex, ey) = (bx - ax, by - ay);
                let q = (((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
                let (cx, cy) = (ax + q * ex - x, ay + q * ey - y);
                // Narrow where it joins the stalk, widest halfway, blunt at the tip.
                let w = half_width * (0.3 + 2.8 * q * (1.0 - q));
                if cx * cx + cy * cy < w * w {
                    inside = Some(inside.map_or(q, |o: f32| o.max(q)));
                }
            };
            for i in 0..9 {
                let base = 0.05 + i as f32 * 0.068;
                let length = 0.14 * (1.0 - base / 0.75);
                let half_width = 0.024 * (1.0 - base / 0.9);
                for side in [-1.0, 1.0] {
                    blade(0.0, base, side * dx * length, base + dy * length, half_width);
                }
            }
            blade(0.0, 0.6, 0.0, 0.69, 0.018);
            let stalk = x.abs() < 0.006 && y < 0.66;
            let holed = holes.iter().any(|&(i, side)| {
                let base = 0.05 + i as f32 * 0.068;
                let half = 0.07 * (1.0 - base / 0.75);
                let (hx, hy) = (x - side * dx * half, y - (base + dy * half));
                hx * hx + hy * hy < 0.009 * 0.009
            });
            let pixel = match (stalk, inside) {
                (true, _) => [80, 95, 35, 255],
                (false, Some(q)) if !holed => [(40.0 + 24.0 * q) as u8, (100.0 + 50.0 * q) as u8, 30, 255],
                _ => [46, 112, 38, 0],
            };
            rgba.extend(pixel);
        }
    }
    rgba
}

/// [`leaf_rgba`] encoded as PNG.
fn leaf_png() -> Vec<u8> {
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(
            &leaf_rgba(),
            LEAF_TEXTURE_WIDTH,
            LEAF_TEXTURE_HEIGHT,
            ExtendedColorType::Rgba8,
        )
        .expect("encoding a PNG into memory cannot fail");
    png
}

/// A node under construction.
struct Node(json::Node);

impl Node {
    fn new(name: &str) -> Self {
        Self(json::Node {
            camera: None,
            children: None,
            extensions: None,
            extras: Default::default(),
            matrix: None,
            mesh: None,
            name: Some(name.into()),
            rotation: None,
            scale: None,
            translation: None,
            skin: None,
            weights: None,
        })
    }

    fn mesh(mut self, mesh: Index<json::Mesh>) -> Self {
        self.0.mesh = Some(mesh);
        self
    }

    fn translation(mut self, t: [f32; 3]) -> Self {
        self.0.translation = Some(t);
        self
    }

    /// Rotation computed in f64 and rounded once, so libm differences in the last bit
    /// of a sine do not change the file.
    fn rotation(mut self, q: DQuat) -> Self {
        self.0.rotation = Some(UnitQuaternion(q.as_quat().to_array()));
        self
    }

    fn scale(mut self, s: [f32; 3]) -> Self {
        self.0.scale = Some(s);
        self
    }
}

/// The JSON root and the binary buffer being filled.
#[derive(Default)]
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

/// A float as JSON, printed with the fewest digits that read back as the same `f32`.
fn short_number(x: f32) -> json::Value {
    json::Value::from(x.to_string().parse::<f64>().unwrap_or_default())
}

impl Builder {
    fn material(
        &mut self,
        name: &str,
        color: [f32; 4],
        texture: Option<Index<json::Texture>>,
    ) -> Index<json::Material> {
        let masked = texture.is_some();
        // The leaves pass some light to their undersides.
        let extensions = masked.then(|| {
            let factor = json::Value::from(LEAF_TRANSMISSION);
            let extension =
                json::Value::Object([("diffuseTransmissionFactor".to_owned(), factor)].into_iter().collect());
            let others = [(DIFFUSE_TRANSMISSION.to_owned(), extension)].into_iter().collect();
            json::extensions::material::Material { others }
        });
        self.root.push(json::Material {
            extensions,
            alpha_cutoff: masked.then_some(AlphaCutoff(0.5)),
            alpha_mode: Checked::Valid(if masked { AlphaMode::Mask } else { AlphaMode::Opaque }),
            double_sided: masked,
            name: Some(name.into()),
            pbr_metallic_roughness: PbrMetallicRoughness {
                base_color_factor: PbrBaseColorFactor(color),
                base_color_texture: texture.map(|index| json::texture::Info {
                    index,
                    tex_coord: 0,
                    extensions: None,
                    extras: Default::default(),
                }),
                metallic_factor: StrengthFactor(0.0),
                roughness_factor: StrengthFactor(0.9),
                ..Default::default()
            },
            ..Default::default()
        })
    }

    /// Appends `bytes` as a buffer view, 4-byte aligned.
    fn view(&mut self, bytes: &[u8], target: Target) -> Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: Some(Checked::Valid(target)),
            extensions: None,
            extras: Default::default(),
        })
    }

    fn accessor(
        &mut self,
        view: Index<json::buffer::View>,
        count: usize,
        component: ComponentType,
        type_: Type,
        bounds: Option<(Vec3, Vec3)>,
    ) -> Index<json::Accessor> {
        let list = |v: Vec3| json::Value::from(v.to_array().map(short_number).to_vec());
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Checked::Valid(GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Checked::Valid(type_),
            min: bounds.map(|(lo, _)| list(lo)),
            max: bounds.map(|(_, hi)| list(hi)),
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    fn primitive(&mut self, g: &Geometry, material: Index<json::Material>) -> json::mesh::Primitive {
        let floats = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
        let lo = g.positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
        let hi = g.positions.iter().fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
        let n = g.positions.len();

        let v = self.view(
            &floats(&g.positions.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>()),
            Target::ArrayBuffer,
        );
        let position = self.accessor(v, n, ComponentType::F32, Type::Vec3, Some((lo, hi)));
        let v = self.view(
            &floats(&g.normals.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>()),
            Target::ArrayBuffer,
        );
        let normal = self.accessor(v, n, ComponentType::F32, Type::Vec3, None);
        let v = self.view(
            &floats(&g.uvs.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>()),
            Target::ArrayBuffer,
        );
        let uv = self.accessor(v, n, ComponentType::F32, Type::Vec2, None);
        let index_bytes: Vec<u8> = g.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let v = self.view(&index_bytes, Target::ElementArrayBuffer);
        let indices = self.accessor(v, g.indices.len(), ComponentType::U16, Type::Scalar, None);

        let attributes = BTreeMap::from([
            (Checked::Valid(Semantic::Positions), position),
            (Checked::Valid(Semantic::Normals), normal),
            (Checked::Valid(Semantic::TexCoords(0)), uv),
        ]);
        json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Checked::Valid(Mode::Triangles),
            targets: None,
        }
    }

    fn mesh(&mut self, name: &str, primitives: Vec<json::mesh::Primitive>) -> Index<json::Mesh> {
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.into()),
            primitives,
            weights: None,
        })
    }

    fn node(&mut self, node: Node) -> Index<json::Node> {
        self.root.push(node.0)
    }

    /// Adds `node` as the last child of `parent`.
    fn child(&mut self, parent: Index<json::Node>, node: Node) -> Index<json::Node> {
        let index = self.node(node);
        self.root.nodes[parent.value()]
            .children
            .get_or_insert_with(Vec::new)
            .push(index);
        index
    }
}
