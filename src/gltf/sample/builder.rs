//! The sample's glTF writer: nodes built in a chain of setters, and a builder that fills the
//! JSON root and the binary buffer (materials, buffer views, accessors, meshes, nodes).

use std::collections::BTreeMap;

use ::gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use ::gltf::json::buffer::Target;
use ::gltf::json::material::{AlphaCutoff, AlphaMode, PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor};
use ::gltf::json::mesh::{Mode, Semantic};
use ::gltf::json::scene::UnitQuaternion;
use ::gltf::json::validation::{Checked, USize64};
use ::gltf::json::{self, Index};
use glam::{DQuat, Vec3};

use crate::gltf::material::DIFFUSE_TRANSMISSION;
use crate::gltf::sample::{Geometry, LEAF_TRANSMISSION};

/// A node under construction.
pub(super) struct Node(json::Node);

impl Node {
    pub(super) fn new(name: &str) -> Self {
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

    pub(super) fn mesh(mut self, mesh: Index<json::Mesh>) -> Self {
        self.0.mesh = Some(mesh);
        self
    }

    pub(super) fn translation(mut self, t: [f32; 3]) -> Self {
        self.0.translation = Some(t);
        self
    }

    /// Rotation computed in f64 and rounded once, so libm differences in the last bit
    /// of a sine do not change the file.
    pub(super) fn rotation(mut self, q: DQuat) -> Self {
        self.0.rotation = Some(UnitQuaternion(q.as_quat().to_array()));
        self
    }

    pub(super) fn scale(mut self, s: [f32; 3]) -> Self {
        self.0.scale = Some(s);
        self
    }
}

/// The JSON root and the binary buffer being filled.
#[derive(Default)]
pub(super) struct Builder {
    pub(super) root: json::Root,
    pub(super) bin: Vec<u8>,
}

/// A float as JSON, printed with the fewest digits that read back as the same `f32`.
fn short_number(x: f32) -> json::Value {
    json::Value::from(x.to_string().parse::<f64>().unwrap_or_default())
}

impl Builder {
    pub(super) fn material(
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
    pub(super) fn view(&mut self, bytes: &[u8], target: Target) -> Index<json::buffer::View> {
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

    /// Appends `bytes` as a buffer view of non-vertex data (inverse bind matrices, animation
    /// keys), 4-byte aligned.
    pub(super) fn data_view(&mut self, bytes: &[u8]) -> Index<json::buffer::View> {
        let view = self.view(bytes, Target::ArrayBuffer);
        self.root.buffer_views[view.value()].target = None;
        view
    }

    /// An accessor of `values` (`per` floats an element, of `type_`) in a view of its own.
    pub(super) fn floats(&mut self, values: &[f32], type_: Type, per: usize, bounds: bool) -> Index<json::Accessor> {
        let bytes: Vec<u8> = values.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.data_view(&bytes);
        let accessor = self.accessor(view, values.len() / per, ComponentType::F32, type_, None);
        if bounds {
            let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            let a = &mut self.root.accessors[accessor.value()];
            a.min = Some(json::Value::from(vec![short_number(lo)]));
            a.max = Some(json::Value::from(vec![short_number(hi)]));
        }
        accessor
    }

    /// [`Builder::primitive`] with each vertex's four joints and weights (`JOINTS_0` as
    /// unsigned bytes, `WEIGHTS_0` as floats).
    pub(super) fn skinned_primitive(
        &mut self,
        g: &Geometry,
        joints: &[[u8; 4]],
        weights: &[[f32; 4]],
        material: Index<json::Material>,
    ) -> json::mesh::Primitive {
        let mut primitive = self.primitive(g, material);
        let n = g.positions.len();
        let v = self.view(&joints.concat(), Target::ArrayBuffer);
        let joints = self.accessor(v, n, ComponentType::U8, Type::Vec4, None);
        let flat: Vec<f32> = weights.iter().flatten().copied().collect();
        let bytes: Vec<u8> = flat.iter().flat_map(|f| f.to_le_bytes()).collect();
        let v = self.view(&bytes, Target::ArrayBuffer);
        let weights = self.accessor(v, n, ComponentType::F32, Type::Vec4, None);
        primitive.attributes.insert(Checked::Valid(Semantic::Joints(0)), joints);
        primitive
            .attributes
            .insert(Checked::Valid(Semantic::Weights(0)), weights);
        primitive
    }

    pub(super) fn accessor(
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

    pub(super) fn primitive(&mut self, g: &Geometry, material: Index<json::Material>) -> json::mesh::Primitive {
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

    pub(super) fn mesh(&mut self, name: &str, primitives: Vec<json::mesh::Primitive>) -> Index<json::Mesh> {
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.into()),
            primitives,
            weights: None,
        })
    }

    pub(super) fn node(&mut self, node: Node) -> Index<json::Node> {
        self.root.push(node.0)
    }

    /// Adds `node` as the last child of `parent`.
    pub(super) fn child(&mut self, parent: Index<json::Node>, node: Node) -> Index<json::Node> {
        let index = self.node(node);
        self.root.nodes[parent.value()]
            .children
            .get_or_insert_with(Vec::new)
            .push(index);
        index
    }
}
