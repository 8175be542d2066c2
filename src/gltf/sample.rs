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

use ::gltf::json;
use ::gltf::json::validation::USize64;
use glam::{DQuat, Vec2, Vec3};
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::gltf::material::DIFFUSE_TRANSMISSION;

mod builder;
pub mod walker;

use builder::{Builder, Node};

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
