//! Reading mesh primitives into [`MeshData`]: attributes checked then read with the `gltf`
//! crate's reader, strips and fans turned into triangle lists, flat normals computed where
//! the file has none.

use ::gltf::Document;
use ::gltf::mesh::{Mode, Primitive};
use glam::{Vec2, Vec3};

use crate::gltf::accessor::{self, Expect};
use crate::gltf::load::Cx;
use crate::gltf::{GltfError, GltfMesh, GltfPrimitive, skin};
use crate::mesh::{MeshData, Vertex};

/// The most vertices one primitive may have once read (after un-welding for flat normals):
/// 128 MiB of vertex data.
pub const MAX_PRIMITIVE_VERTICES: usize = 1 << 22;

/// The most triangle-list indices one primitive may have once read (after strips and fans
/// become lists): 64 MiB of indices.
pub const MAX_PRIMITIVE_INDICES: usize = 1 << 24;

/// The most vertices all primitives of one model may have together: 256 MiB.
pub const MAX_MODEL_VERTICES: usize = 1 << 23;

/// The most indices all primitives of one model may have together: 128 MiB.
pub const MAX_MODEL_INDICES: usize = 1 << 25;

/// Vertices and indices planned so far, checked against the caps above before any
/// primitive is read (from accessor counts, so before anything is allocated).
#[derive(Default)]
struct Budget {
    vertices: usize,
    indices: usize,
}

impl Budget {
    /// Takes `vertices` and `indices` for the primitive `context`, or says which cap they pass.
    fn take(&mut self, cx: &Cx, context: &str, vertices: usize, indices: usize) -> Result<(), GltfError> {
        let over = |what: &str, n: usize, max: usize, per: &str| {
            cx.data(context, format!("{n} {what} once read; at most {max} {what} per {per}"))
        };
        if vertices > MAX_PRIMITIVE_VERTICES {
            return Err(over("vertices", vertices, MAX_PRIMITIVE_VERTICES, "primitive"));
        }
        if indices > MAX_PRIMITIVE_INDICES {
            return Err(over("indices", indices, MAX_PRIMITIVE_INDICES, "primitive"));
        }
        self.vertices += vertices;
        self.indices += indices;
        if self.vertices > MAX_MODEL_VERTICES {
            return Err(over("vertices", self.vertices, MAX_MODEL_VERTICES, "model"));
        }
        if self.indices > MAX_MODEL_INDICES {
            return Err(over("indices", self.indices, MAX_MODEL_INDICES, "model"));
        }
        Ok(())
    }
}

/// What reading `primitive` will allocate, from its accessor counts alone: vertices and
/// triangle-list indices (a strip or fan of n indices gives at most 3 (n - 2); computed
/// normals need one vertex per index). Zero for primitives that are skipped.
fn planned(primitive: &Primitive) -> (usize, usize) {
    let mode = primitive.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        return (0, 0);
    }
    let vertex_count = primitive.get(&::gltf::Semantic::Positions).map_or(0, |a| a.count());
    let raw = primitive.indices().map_or(vertex_count, |a| a.count());
    let listed = match mode {
        Mode::TriangleStrip | Mode::TriangleFan => raw.saturating_sub(2).saturating_mul(3),
        _ => raw / 3 * 3,
    };
    let has_normals = primitive.get(&::gltf::Semantic::Normals).is_some();
    let vertices = if has_normals {
        vertex_count
    } else {
        listed.max(vertex_count)
    };
    (vertices, listed.max(raw))
}

/// Reads every mesh of the document, after checking what all of them will allocate
/// against the caps.
pub(super) fn read_meshes(cx: &mut Cx, document: &Document, buffers: &[Vec<u8>]) -> Result<Vec<GltfMesh>, GltfError> {
    let mut budget = Budget::default();
    for mesh in document.meshes() {
        for primitive in mesh.primitives() {
            let (vertices, indices) = planned(&primitive);
            let context = format!("mesh {} primitive {}", mesh.index(), primitive.index());
            budget.take(cx, &context, vertices, indices)?;
        }
    }
    let mut meshes = Vec::new();
    for mesh in document.meshes() {
        let mut primitives = Vec::new();
        for primitive in mesh.primitives() {
            if let Some(p) = read_primitive(cx, mesh.index(), &primitive, buffers)? {
                primitives.push(p);
            }
        }
        meshes.push(GltfMesh {
            name: mesh.name().map(str::to_owned),
            primitives,
        });
    }
    Ok(meshes)
}

/// Reads one primitive; `None` for point and line primitives, which are skipped.
fn read_primitive(
    cx: &mut Cx,
    m: usize,
    primitive: &Primitive,
    buffers: &[Vec<u8>],
) -> Result<Option<GltfPrimitive>, GltfError> {
    let p = primitive.index();
    let context = format!("mesh {m} primitive {p}");
    let mode = primitive.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        cx.warn(format!(
            "{context}: {mode:?} primitive skipped (only triangles are drawn)"
        ));
        return Ok(None);
    }
    if primitive.morph_targets().next().is_some() {
        cx.warn(format!("{context}: morph targets ignored"));
    }

    let Some(position) = primitive.get(&::gltf::Semantic::Positions) else {
        return Err(GltfError::MissingPosition {
            path: cx.path.to_path_buf(),
            mesh: m,
            primitive: p,
        });
    };
    accessor::check(cx, &context, "POSITION", &position, Expect::Vec3F32)?;
    let vertex_count = position.count();
    if u32::try_from(vertex_count).is_err() {
        return Err(cx.data(&context, format!("{vertex_count} vertices do not fit 32-bit indices")));
    }
    let normal = primitive.get(&::gltf::Semantic::Normals);
    let tex_coord = primitive.get(&::gltf::Semantic::TexCoords(0));
    for (semantic, acc, expect) in [
        ("NORMAL", &normal, Expect::Vec3F32),
        ("TEXCOORD_0", &tex_coord, Expect::TexCoord),
    ] {
        if let Some(acc) = acc {
            accessor::check(cx, &context, semantic, acc, expect)?;
            if acc.count() != vertex_count {
                return Err(cx.data(
                    &context,
                    format!(
                        "{semantic} (accessor {}) has {} elements, POSITION has {vertex_count}",
                        acc.index(),
                        acc.count()
                    ),
                ));
            }
        }
    }
    if let Some(indices) = primitive.indices() {
        accessor::check(cx, &context, "indices", &indices, Expect::Index)?;
    }

    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let unreadable = |cx: &Cx, semantic: &str| cx.data(&context, format!("{semantic} could not be read"));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| unreadable(cx, "POSITION"))?
        .map(Vec3::from)
        .collect();
    if positions.len() != vertex_count {
        return Err(unreadable(cx, "POSITION"));
    }
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(cx.data(
            &context,
            format!("POSITION of vertex {v} is not finite: {}", positions[v]),
        ));
    }
    let uvs: Vec<Vec2> = match (&tex_coord, reader.read_tex_coords(0)) {
        (None, _) => vec![Vec2::ZERO; vertex_count],
        (Some(_), Some(read)) => read.into_f32().map(Vec2::from).collect(),
        (Some(_), None) => return Err(unreadable(cx, "TEXCOORD_0")),
    };
    if uvs.len() != vertex_count {
        return Err(unreadable(cx, "TEXCOORD_0"));
    }
    if let Some(v) = uvs.iter().position(|uv| !uv.is_finite()) {
        return Err(cx.data(&context, format!("TEXCOORD_0 of vertex {v} is not finite")));
    }
    let raw_indices: Vec<u32> = match (primitive.indices(), reader.read_indices()) {
        (None, _) => (0..vertex_count as u32).collect(),
        (Some(_), Some(read)) => read.into_u32().collect(),
        (Some(_), None) => return Err(unreadable(cx, "indices")),
    };
    if let Some(&index) = raw_indices.iter().find(|&&i| i as usize >= vertex_count) {
        return Err(GltfError::IndexOutOfRange {
            path: cx.path.to_path_buf(),
            mesh: m,
            primitive: p,
            index,
            vertices: vertex_count,
        });
    }
    let indices = match mode {
        Mode::TriangleStrip => strip_to_list(&raw_indices),
        Mode::TriangleFan => fan_to_list(&raw_indices),
        _ => {
            let mut list = raw_indices;
            if !list.len().is_multiple_of(3) {
                cx.warn(format!(
                    "{context}: {} indices is not a multiple of 3; the last {} dropped",
                    list.len(),
                    list.len() % 3
                ));
                list.truncate(list.len() / 3 * 3);
            }
            list
        }
    };

    let influences = skin::read_influences(cx, &context, primitive, buffers, vertex_count)?;
    let mesh = match (&normal, reader.read_normals()) {
        (Some(_), Some(read)) => {
            let normals: Vec<[f32; 3]> = read.collect();
            if normals.len() != vertex_count {
                return Err(unreadable(cx, "NORMAL"));
            }
            let mut zero = 0;
            let mut vertices = Vec::with_capacity(vertex_count);
            for (v, ((position, normal), uv)) in positions.iter().zip(normals).zip(&uvs).enumerate() {
                let normal = Vec3::from(normal);
                if !normal.is_finite() {
                    return Err(cx.data(&context, format!("NORMAL of vertex {v} is not finite")));
                }
                let normal = normal.try_normalize().unwrap_or_else(|| {
                    zero += 1;
                    Vec3::Y
                });
                vertices.push(Vertex {
                    position: position.to_array(),
                    normal: normal.to_array(),
                    uv: uv.to_array(),
                });
            }
            if zero > 0 {
                cx.warn(format!("{context}: {zero} zero-length normals replaced by +Y"));
            }
            MeshData { vertices, indices }
        }
        (Some(_), None) => return Err(unreadable(cx, "NORMAL")),
        (None, _) => {
            cx.warn(format!("{context}: no NORMAL attribute; flat normals computed"));
            // NOTE: flat normals give each triangle corner its own vertex, in index order.
            let unwelded = influences
                .as_ref()
                .map(|i| indices.iter().map(|&v| i[v as usize]).collect::<Vec<_>>());
            return Ok(Some(GltfPrimitive {
                mesh: flat_normals(&positions, &uvs, &indices),
                material: primitive.material().index(),
                influences: unwelded,
            }));
        }
    };
    Ok(Some(GltfPrimitive {
        mesh,
        material: primitive.material().index(),
        influences,
    }))
}

/// A triangle strip as a triangle list with the strip's winding (glTF's rule: triangle `i`
/// is `v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]`). Degenerate triangles, which strips use
/// to join runs, are dropped.
pub(super) fn strip_to_list(strip: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(strip.len().saturating_sub(2) * 3);
    for (i, w) in strip.windows(3).enumerate() {
        let tri = if i % 2 == 0 {
            [w[0], w[1], w[2]]
        } else {
            [w[0], w[2], w[1]]
        };
        push_unless_degenerate(&mut out, tri);
    }
    out
}

/// A triangle fan as a triangle list (glTF's rule: triangle `i` is `v[i + 1], v[i + 2],
/// v[0]`), degenerate triangles dropped.
pub(super) fn fan_to_list(fan: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(fan.len().saturating_sub(2) * 3);
    if let Some((&hub, rim)) = fan.split_first() {
        for w in rim.windows(2) {
            push_unless_degenerate(&mut out, [w[0], w[1], hub]);
        }
    }
    out
}

fn push_unless_degenerate(out: &mut Vec<u32>, [a, b, c]: [u32; 3]) {
    if a != b && b != c && a != c {
        out.extend([a, b, c]);
    }
}

/// Un-welds a triangle list so each triangle has its own three vertices with the face's
/// normal (counter-clockwise front). Degenerate triangles get +Y. Indices must be in range.
pub(super) fn flat_normals(positions: &[Vec3], uvs: &[Vec2], indices: &[u32]) -> MeshData {
    let mut vertices = Vec::with_capacity(indices.len());
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let normal = (positions[b] - positions[a])
            .cross(positions[c] - positions[a])
            .try_normalize()
            .unwrap_or(Vec3::Y);
        for i in [a, b, c] {
            vertices.push(Vertex {
                position: positions[i].to_array(),
                normal: normal.to_array(),
                uv: uvs[i].to_array(),
            });
        }
    }
    let indices = (0..vertices.len() as u32).collect();
    MeshData { vertices, indices }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::{fan_to_list, flat_normals, strip_to_list};

    /// Twice the signed area of a triangle seen from +Z (positive: counter-clockwise).
    fn winding(p: &[Vec3], t: &[u32]) -> f32 {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| p[i as usize]);
        (b - a).cross(c - a).z
    }

    #[test]
    fn strip_keeps_winding() {
        // A zig-zag strip in the XY plane: 0 2 4 on the bottom, 1 3 5 on top.
        let p: Vec<Vec3> = (0..6).map(|i| Vec3::new((i / 2) as f32, (i % 2) as f32, 0.0)).collect();
        let list = strip_to_list(&[0, 1, 2, 3, 4, 5]);
        assert_eq!(list, vec![0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4]);
        for t in list.chunks(3) {
            assert!(winding(&p, t) < 0.0, "{t:?} winds like the first triangle");
        }
        assert!(strip_to_list(&[0, 1]).is_empty());
        assert!(strip_to_list(&[]).is_empty());
    }

    #[test]
    fn strip_drops_degenerate_joins() {
        // Two runs joined by repeating 3 and 4.
        let list = strip_to_list(&[0, 1, 2, 3, 3, 4, 4, 5, 6]);
        assert_eq!(list, vec![0, 1, 2, 1, 3, 2, 4, 5, 6]);
    }

    #[test]
    fn fan_around_first_vertex() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let list = fan_to_list(&[0, 1, 2, 3]);
        assert_eq!(list, vec![1, 2, 0, 2, 3, 0]);
        for t in list.chunks(3) {
            assert!(winding(&p, t) > 0.0);
        }
        assert!(fan_to_list(&[0, 1]).is_empty());
        assert!(fan_to_list(&[]).is_empty());
    }

    #[test]
    fn flat_normals_unweld() {
        // Two triangles sharing an edge, folded 90° along it: a floor and a wall.
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 1.0, 0.0)];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        let mesh = flat_normals(&p, &uv, &[0, 1, 2, 0, 1, 3]);
        assert_eq!(mesh.indices, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(mesh.vertices.len(), 6);
        for v in &mesh.vertices[..3] {
            assert_eq!(v.normal, [0.0, 1.0, 0.0]);
        }
        for v in &mesh.vertices[3..] {
            assert_eq!(v.normal, [0.0, 0.0, 1.0]);
        }
        assert_eq!(mesh.vertices[2].position, [0.0, 0.0, -1.0]);
        assert_eq!(mesh.vertices[5].uv, [1.0, 1.0]);
        // A degenerate triangle gets +Y rather than NaN.
        let mesh = flat_normals(&p, &uv, &[0, 1, 1]);
        assert_eq!(mesh.vertices[0].normal, [0.0, 1.0, 0.0]);
    }
}
