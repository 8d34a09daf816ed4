//! Render meshes from [`Mesh`]es: vertex normals computed here, smooth across gentle bends and split
//! at creases, so that a capsule shades round and a cuboid keeps its flat faces.

use std::collections::HashMap;

use glam::Vec3;

use crate::mesh::Mesh;
use crate::render::gpu::MeshVertexRaw;

/// Faces meeting at more than this angle keep separate normals.
pub const CREASE_DEGREES: f32 = 40.0;

/// Vertices with normals and the triangle list over them. Each corner of a triangle takes the
/// area-weighted mean of the normals of the triangles around its vertex that bend less than
/// `crease_degrees` away from its own; corners that end up with the same vertex and normal share
/// one output vertex. Degenerate triangles are kept but contribute no normal.
pub fn shade_normals(mesh: &Mesh, crease_degrees: f32) -> (Vec<MeshVertexRaw>, Vec<u32>) {
    let tris: Vec<[usize; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
        .collect();
    // Area-weighted face normals (twice the area).
    let face: Vec<Vec3> = tris
        .iter()
        .map(|t| {
            let (a, b, c) = (
                mesh.positions[t[0]],
                mesh.positions[t[1]],
                mesh.positions[t[2]],
            );
            (b - a).cross(c - a)
        })
        .collect();
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); mesh.positions.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            around[v].push(f);
        }
    }
    let cos_crease = crease_degrees.to_radians().cos();
    let mut vertices = Vec::new();
    let mut indices = Vec::with_capacity(mesh.indices.len());
    let mut seen: HashMap<(usize, [i32; 3]), u32> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        let own = face[f].normalize_or_zero();
        for &v in t {
            let mut n = Vec3::ZERO;
            for &g in &around[v] {
                if face[g].normalize_or_zero().dot(own) >= cos_crease {
                    n += face[g];
                }
            }
            let n = n.try_normalize().or(own.try_normalize()).unwrap_or(Vec3::Y);
            let key = (v, (n * 1e4).round().as_ivec3().to_array());
            let index = *seen.entry(key).or_insert_with(|| {
                vertices.push(MeshVertexRaw {
                    position: mesh.positions[v].to_array(),
                    normal: n.to_array(),
                });
                vertices.len() as u32 - 1
            });
            indices.push(index);
        }
    }
    (vertices, indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cuboid_keeps_flat_faces() {
        let (v, i) = shade_normals(&Mesh::cuboid(Vec3::new(1.0, 2.0, 3.0)), CREASE_DEGREES);
        assert_eq!(v.len(), 24, "4 corners per face");
        assert_eq!(i.len(), 36);
        for vert in &v {
            let n = Vec3::from(vert.normal);
            let p = Vec3::from(vert.position);
            // Each normal is an axis, pointing the way the vertex lies on it.
            assert!((n.abs().max_element() - 1.0).abs() < 1e-5);
            assert!(n.dot(p) > 0.0);
        }
    }

    #[test]
    fn a_sphere_is_smooth_and_outward() {
        let (v, _) = shade_normals(&Mesh::uv_sphere(1.0, 16, 32), CREASE_DEGREES);
        for vert in &v {
            let n = Vec3::from(vert.normal);
            let p = Vec3::from(vert.position).normalize();
            assert!(n.dot(p) > 0.97, "{n} at {p}");
        }
    }
}
