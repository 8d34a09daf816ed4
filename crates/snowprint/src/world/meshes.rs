//! Mesh deformers: registered once, posed each frame, drawn by the capture.

use super::SnowWorld;
use crate::capture::CaptureMesh;
use crate::error::{Result, SnowError};
use crate::mesh::{Mesh, MeshId};

impl SnowWorld {
    /// Register a closed triangle mesh as a deformer shape.
    pub fn add_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<MeshId> {
        mesh.validate(name)?;
        use wgpu::util::DeviceExt;
        let vertices = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("deformer mesh vertices"),
                contents: bytemuck::cast_slice(&mesh.positions),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            });
        let indices = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("deformer mesh indices"),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
        self.meshes.push(Some(CaptureMesh {
            vertices,
            indices,
            index_count: mesh.indices.len() as u32,
            vertex_count: mesh.positions.len(),
            radius: mesh.bounding_radius(),
        }));
        let index = self.meshes.len() - 1;
        self.probes.keep_mesh(index, &mesh.positions);
        Ok(MeshId(index as u32))
    }

    /// Replace a mesh's vertex positions (an animated mesh posed for this frame). The count must
    /// match the mesh; the triangles stay.
    pub fn pose_mesh(&mut self, id: MeshId, positions: &[glam::Vec3]) -> Result<()> {
        let mesh = self
            .meshes
            .get_mut(id.0 as usize)
            .and_then(Option::as_mut)
            .ok_or(SnowError::StaleHandle {
                what: "mesh",
                index: id.0,
            })?;
        if positions.len() != mesh.vertex_count {
            return Err(SnowError::PoseMismatch {
                mesh: id.0,
                got: positions.len(),
                expected: mesh.vertex_count,
            });
        }
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(SnowError::InvalidMesh {
                name: format!("mesh {}", id.0),
                reason: format!("posed vertex {:?} is not finite", p.to_array()),
            });
        }
        mesh.radius = positions.iter().map(|p| p.length()).fold(0.0, f32::max);
        self.queue
            .write_buffer(&mesh.vertices, 0, bytemuck::cast_slice(positions));
        self.probes.keep_mesh(id.0 as usize, positions);
        Ok(())
    }

    /// Remove a mesh deformer shape and free its buffers.
    pub fn remove_mesh(&mut self, id: MeshId) -> Result<()> {
        self.meshes
            .get_mut(id.0 as usize)
            .and_then(Option::take)
            .map(|_| ())
            .ok_or(SnowError::StaleHandle {
                what: "mesh",
                index: id.0,
            })?;
        self.probes.forget_mesh(id.0 as usize);
        self.skins.forget(id.0 as usize);
        Ok(())
    }
}
