//! CPU mesh data: vertices, indices and local bounds, plus generators for the primitive
//! shapes scene files use. Pure data; the renderer uploads it.

mod primitives;
mod weld;

pub use primitives::{cuboid, plane, sphere};
pub use weld::position_indices;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::math::aabb::Aabb;

/// One vertex of a mesh: position, normal, UV (32 bytes, the layout of the vertex buffer).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
    /// Texture coordinate.
    pub uv: [f32; 2],
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertices.
    pub vertices: Vec<Vertex>,
    /// Triangle list indices (counter-clockwise front faces).
    pub indices: Vec<u32>,
}

impl MeshData {
    /// Local-space bounds of the vertices ([`Aabb::EMPTY`] for an empty mesh).
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for v in &self.vertices {
            let p = Vec3::from(v.position);
            b = b.with_point(p);
        }
        b
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}
