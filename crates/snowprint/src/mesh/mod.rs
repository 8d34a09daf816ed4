//! Triangle meshes used as deformers: closed, wound counter-clockwise seen from outside (the glTF
//! convention). The capture relies on that winding to fill what lies below the ground (see
//! `capture/capture.wgsl`).

pub(crate) mod gltf_file;

use glam::{Mat4, Vec3};

use crate::error::{Result, SnowError};

pub use gltf_file::{
    MAX_GLTF_DEPTH, MAX_GLTF_FILE_BYTES, MAX_GLTF_NODES, MAX_GLTF_TRIANGLES, MAX_GLTF_VERTICES,
};

/// Farthest a vertex may lie from the mesh's origin, metres: the reach of any deformer,
/// `MAX_DEFORMER_SIZE`. Kept here so that meshes do not depend on deformers (deformers name
/// meshes); a unit test checks that the two agree.
const MAX_VERTEX_DISTANCE: f32 = 1000.0;

/// Handle of a mesh registered with a [`crate::SnowWorld`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct MeshId(pub(crate) u32);

/// An indexed triangle list in the mesh's own frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, metres.
    pub positions: Vec<Vec3>,
    /// Three indices per triangle, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Volume enclosed, by the divergence theorem: positive for a closed mesh wound outward
    /// (counter-clockwise seen from outside), as the capture's winding count needs.
    pub fn signed_volume(&self) -> f32 {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let p = |i: u32| self.positions.get(i as usize).copied().unwrap_or_default();
                p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0
            })
            .sum()
    }

    /// Check indices are in range and positions finite.
    pub fn validate(&self, name: &str) -> Result<()> {
        let err = |reason: String| {
            Err(SnowError::InvalidMesh {
                name: name.to_owned(),
                reason,
            })
        };
        if self.indices.is_empty() || !self.indices.len().is_multiple_of(3) {
            return err(format!(
                "has {} indices; a triangle list needs a positive multiple of 3",
                self.indices.len()
            ));
        }
        if let Some(i) = self
            .indices
            .iter()
            .find(|&&i| i as usize >= self.positions.len())
        {
            return err(format!(
                "index {i} is out of range for {} vertices",
                self.positions.len()
            ));
        }
        if let Some(p) = self.positions.iter().find(|p| !p.is_finite()) {
            return err(format!("vertex {:?} is not finite", p.to_array()));
        }
        let limit = MAX_VERTEX_DISTANCE;
        if let Some(p) = self.positions.iter().find(|p| p.length() > limit) {
            return err(format!(
                "vertex {:?} lies {} m from the mesh's origin, farther than the {limit} m (MAX_DEFORMER_SIZE) a deformer may reach; model the mesh around its origin and at most {limit} m across",
                p.to_array(),
                p.length()
            ));
        }
        Ok(())
    }

    /// Radius of the ball around the mesh origin that holds every vertex.
    pub fn bounding_radius(&self) -> f32 {
        self.positions
            .iter()
            .map(|p| p.length())
            .fold(0.0, f32::max)
    }

    /// The mesh with every vertex transformed.
    pub fn transformed(&self, m: Mat4) -> Mesh {
        Mesh {
            positions: self
                .positions
                .iter()
                .map(|&p| m.transform_point3(p))
                .collect(),
            indices: self.indices.clone(),
        }
    }

    /// Append another mesh.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// A UV sphere of `radius` with `rings` latitude bands and `segments` longitude slices.
    pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
        Self::capsule(radius, 0.0, rings.max(2) & !1, segments)
    }

    /// A capsule along `Y`: inner segment `-half_height..half_height`, `radius`; `rings` bands over
    /// the two hemispheres together (even), `segments` slices.
    pub fn capsule(radius: f32, half_height: f32, rings: u32, segments: u32) -> Mesh {
        let rings = rings.max(2) & !1;
        let segments = segments.max(3);
        let mut positions = Vec::new();
        // Top pole, ring vertices from top to bottom, bottom pole.
        positions.push(Vec3::new(0.0, half_height + radius, 0.0));
        for r in 1..rings {
            let phi = std::f32::consts::PI * r as f32 / rings as f32;
            let y = radius * phi.cos()
                + if r <= rings / 2 {
                    half_height
                } else {
                    -half_height
                };
            let ring_r = radius * phi.sin();
            for s in 0..segments {
                let theta = std::f32::consts::TAU * s as f32 / segments as f32;
                positions.push(Vec3::new(ring_r * theta.cos(), y, ring_r * theta.sin()));
            }
            if r == rings / 2 && half_height > 0.0 {
                // Duplicate the equator ring at the bottom of the cylinder.
                for s in 0..segments {
                    let theta = std::f32::consts::TAU * s as f32 / segments as f32;
                    positions.push(Vec3::new(
                        ring_r * theta.cos(),
                        y - 2.0 * half_height,
                        ring_r * theta.sin(),
                    ));
                }
            }
        }
        positions.push(Vec3::new(0.0, -half_height - radius, 0.0));
        let ring_count = rings - 1 + u32::from(half_height > 0.0);
        let bottom = positions.len() as u32 - 1;
        let ring = |k: u32, s: u32| 1 + k * segments + (s % segments);
        let mut indices = Vec::new();
        for s in 0..segments {
            // Seen from above (outside at the top pole), counter-clockwise is decreasing theta
            // when x = cos, z = sin (because +Y x +X points to -Z).
            indices.extend_from_slice(&[0, ring(0, s + 1), ring(0, s)]);
        }
        for k in 0..ring_count - 1 {
            for s in 0..segments {
                let (a, b, c, d) = (
                    ring(k, s),
                    ring(k, s + 1),
                    ring(k + 1, s),
                    ring(k + 1, s + 1),
                );
                indices.extend_from_slice(&[a, b, d, a, d, c]);
            }
        }
        let last = ring_count - 1;
        for s in 0..segments {
            indices.extend_from_slice(&[bottom, ring(last, s), ring(last, s + 1)]);
        }
        Mesh { positions, indices }
    }

    /// An axis-aligned box centred on the origin.
    pub fn cuboid(half_extents: Vec3) -> Mesh {
        let h = half_extents;
        let positions = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect();
        // Each face as a quad (a, b, c, d) counter-clockwise seen from outside.
        let faces = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        let mut indices = Vec::new();
        for [a, b, c, d] in faces {
            indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
        Mesh { positions, indices }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_meshes_are_closed_and_outward() {
        let s = Mesh::uv_sphere(1.0, 32, 64);
        s.validate("sphere").unwrap();
        let v = s.signed_volume();
        let exact = 4.0 / 3.0 * std::f32::consts::PI;
        assert!(v > 0.97 * exact && v < exact, "sphere volume {v}");

        let c = Mesh::capsule(0.5, 1.0, 16, 32);
        let v = c.signed_volume();
        let exact = 4.0 / 3.0 * std::f32::consts::PI * 0.125 + std::f32::consts::PI * 0.25 * 2.0;
        assert!(
            v > 0.97 * exact && v < exact,
            "capsule volume {v} vs {exact}"
        );

        let b = Mesh::cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!((b.signed_volume() - 48.0).abs() < 1e-4);
    }

    #[test]
    fn vertices_reach_as_far_as_deformers() {
        assert_eq!(MAX_VERTEX_DISTANCE, crate::deformer::MAX_DEFORMER_SIZE);
    }
}
