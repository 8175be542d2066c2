//! Generators for the primitive shapes: a horizontal plane, an axis-aligned box and a UV
//! sphere, all centred on the origin with outward normals and counter-clockwise fronts.

use glam::{Vec2, Vec3};

use crate::mesh::{MeshData, Vertex};

fn vertex(p: Vec3, n: Vec3, uv: Vec2) -> Vertex {
    Vertex {
        position: p.to_array(),
        normal: n.to_array(),
        uv: uv.to_array(),
    }
}

/// Appends a quad with corners `o`, `o+u`, `o+u+v`, `o+v` facing `u × v`.
fn push_quad(mesh: &mut MeshData, o: Vec3, u: Vec3, v: Vec3, uv_scale: Vec2) {
    let n = u.cross(v).normalize();
    let base = mesh.vertices.len() as u32;
    mesh.vertices.extend([
        vertex(o, n, Vec2::new(0.0, uv_scale.y)),
        vertex(o + u, n, Vec2::new(uv_scale.x, uv_scale.y)),
        vertex(o + u + v, n, Vec2::new(uv_scale.x, 0.0)),
        vertex(o + v, n, Vec2::ZERO),
    ]);
    mesh.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// A horizontal plane of `size.x` by `size.y` (along X and Z) facing +Y.
pub fn plane(size: Vec2) -> MeshData {
    let mut mesh = MeshData::default();
    let h = size * 0.5;
    push_quad(
        &mut mesh,
        Vec3::new(-h.x, 0.0, h.y),
        Vec3::new(size.x, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -size.y),
        Vec2::ONE,
    );
    mesh
}

/// An axis-aligned box of the given full size, centred on the origin. Each face maps the
/// whole texture, so a thin box makes a two-sided textured card.
pub fn cuboid(size: Vec3) -> MeshData {
    let mut mesh = MeshData::default();
    let h = size * 0.5;
    let (x, y, z) = (Vec3::X * size.x, Vec3::Y * size.y, Vec3::Z * size.z);
    let uv = Vec2::ONE;
    push_quad(&mut mesh, Vec3::new(h.x, -h.y, h.z), -z, y, uv); // +X
    push_quad(&mut mesh, Vec3::new(-h.x, -h.y, -h.z), z, y, uv); // -X
    push_quad(&mut mesh, Vec3::new(-h.x, h.y, h.z), x, -z, uv); // +Y
    push_quad(&mut mesh, Vec3::new(-h.x, -h.y, -h.z), x, z, uv); // -Y
    push_quad(&mut mesh, Vec3::new(-h.x, -h.y, h.z), x, y, uv); // +Z
    push_quad(&mut mesh, Vec3::new(h.x, -h.y, -h.z), -x, y, uv); // -Z
    mesh
}

/// A UV sphere with `segments` around and `rings` from pole to pole (minimums 3 and 2).
pub fn sphere(radius: f32, segments: u32, rings: u32) -> MeshData {
    let segments = segments.max(3);
    let rings = rings.max(2);
    let mut mesh = MeshData::default();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            // NOTE: the seam's two columns and each pole's copies lie at exactly the same
            // positions, so position-only index lists draw them as one vertex.
            let phi = if s == segments { 0.0 } else { u * std::f32::consts::TAU };
            let n = if r == 0 || r == rings {
                Vec3::new(0.0, if r == 0 { 1.0 } else { -1.0 }, 0.0)
            } else {
                Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin())
            };
            mesh.vertices.push(vertex(n * radius, n, Vec2::new(u, v)));
        }
    }
    let stride = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * stride + s;
            let b = a + stride;
            // The first ring's upper triangles and the last ring's lower ones would join two
            // copies of a pole: leave those degenerate triangles out.
            if r > 0 {
                mesh.indices.extend([a, b, a + 1]);
            }
            if r + 1 < rings {
                mesh.indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's winding agrees with its vertex normals (front faces outward).
    fn assert_outward(mesh: &MeshData) {
        for t in mesh.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(mesh.vertices[i as usize].position));
            let face = (b - a).cross(c - a);
            assert!(face.length() > 1e-6, "degenerate triangle {t:?}");
            let n = Vec3::from(mesh.vertices[t[0] as usize].normal);
            assert!(face.dot(n) > 0.0, "triangle {t:?} winds against its normal");
        }
    }

    #[test]
    fn primitives_wind_outward_and_have_the_right_bounds() {
        let p = plane(Vec2::new(4.0, 2.0));
        assert_outward(&p);
        assert_eq!(p.bounds().min, Vec3::new(-2.0, 0.0, -1.0));
        let c = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert_outward(&c);
        assert_eq!(c.triangle_count(), 12);
        assert_eq!(c.bounds().max, Vec3::new(0.5, 1.0, 1.5));
        let s = sphere(2.0, 16, 8);
        assert_outward(&s);
        assert!((s.bounds().max.y - 2.0).abs() < 1e-5);
        assert!(
            s.vertices
                .iter()
                .all(|v| (Vec3::from(v.position).length() - 2.0).abs() < 1e-4)
        );
    }
}
