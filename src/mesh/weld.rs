//! Position-only index lists: a mesh's triangles with every vertex replaced by the first
//! vertex at the same position. A pass that reads only positions (a depth-only shadow
//! caster) draws the same triangles from fewer distinct vertices, so the GPU shades each
//! corner once however many normals or texture coordinates meet there (a box's 24 vertices
//! become 8).

use std::collections::HashMap;

use super::MeshData;

/// `mesh`'s indices with every vertex replaced by the first vertex (lowest index) whose
/// position is bit for bit the same: the same triangles in the same order, each corner at
/// the same position. None when no two referenced vertices share a position (the list would
/// equal the mesh's own). An index past the vertices is kept as it is.
pub fn position_indices(mesh: &MeshData) -> Option<Vec<u32>> {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.vertices.len());
    let mut welded = false;
    let canon: Vec<u32> = (0..mesh.vertices.len() as u32)
        .map(|i| {
            let key = mesh.vertices[i as usize].position.map(f32::to_bits);
            let c = *first.entry(key).or_insert(i);
            welded |= c != i;
            c
        })
        .collect();
    if !welded {
        return None;
    }
    let indices: Vec<u32> = mesh
        .indices
        .iter()
        .map(|&i| canon.get(i as usize).copied().unwrap_or(i))
        .collect();
    (indices != mesh.indices).then_some(indices)
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use glam::Vec3;

    use super::*;
    use crate::mesh::{Vertex, cuboid, sphere};

    /// Every welded corner lies where the original corner lay, in the same triangle order.
    fn same_positions(mesh: &MeshData, welded: &[u32]) {
        assert_eq!(welded.len(), mesh.indices.len());
        for (&w, &i) in welded.iter().zip(&mesh.indices) {
            assert_eq!(mesh.vertices[w as usize].position, mesh.vertices[i as usize].position);
        }
    }

    #[test]
    fn a_box_draws_its_12_triangles_from_8_corners() {
        let mesh = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(mesh.vertices.len(), 24);
        let welded = position_indices(&mesh).expect("a box's faces share corners");
        same_positions(&mesh, &welded);
        let used: HashSet<u32> = welded.iter().copied().collect();
        assert_eq!(used.len(), 8, "distinct vertices: {used:?}");
    }

    #[test]
    fn a_sphere_welds_its_seam_and_poles() {
        let mesh = sphere(1.0, 32, 16);
        let welded = position_indices(&mesh).expect("a UV sphere repeats its seam");
        same_positions(&mesh, &welded);
        let used = welded.iter().copied().collect::<HashSet<u32>>().len();
        let before = mesh.indices.iter().copied().collect::<HashSet<u32>>().len();
        // 32 segments × 15 inner rings + 2 poles.
        assert_eq!(used, 32 * 15 + 2, "{before} vertices before");
    }

    #[test]
    fn a_mesh_without_repeated_positions_has_no_list() {
        let v = |x: f32| Vertex {
            position: [x, 0.0, x * x],
            ..Vertex::default()
        };
        let mesh = MeshData {
            vertices: vec![v(0.0), v(1.0), v(2.0)],
            indices: vec![0, 1, 2],
        };
        assert_eq!(position_indices(&mesh), None);
    }

    #[test]
    fn an_unused_repeat_and_an_index_past_the_vertices_change_nothing() {
        let v = |x: f32| Vertex {
            position: [x, 1.0, 0.0],
            ..Vertex::default()
        };
        // Vertex 3 repeats vertex 0 but no triangle uses it; index 9 is past the vertices.
        let mesh = MeshData {
            vertices: vec![v(0.0), v(1.0), v(2.0), v(0.0)],
            indices: vec![0, 1, 2, 2, 1, 9],
        };
        assert_eq!(position_indices(&mesh), None);
        let mut repeated = mesh.clone();
        repeated.indices.extend([3, 1, 2]);
        assert_eq!(position_indices(&repeated), Some(vec![0, 1, 2, 2, 1, 9, 0, 1, 2]));
    }

    #[test]
    fn negative_zero_is_not_welded_to_zero() {
        let mesh = MeshData {
            vertices: vec![
                Vertex {
                    position: [0.0, 0.0, 0.0],
                    ..Vertex::default()
                },
                Vertex {
                    position: [-0.0, 0.0, 0.0],
                    ..Vertex::default()
                },
                Vertex {
                    position: [1.0, 0.0, 0.0],
                    ..Vertex::default()
                },
            ],
            indices: vec![0, 1, 2],
        };
        assert_eq!(position_indices(&mesh), None);
    }
}
