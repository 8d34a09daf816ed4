//! The visibility path's view of the meshes (`geometry.wgsl`): every registered mesh's vertices
//! and indices, in the mesh set's one buffer each, and per instance of the frame its mesh's first
//! index and first vertex, written every frame.

use super::super::meshes::MeshSet;
use crate::gpu::resources::Growable;

pub(super) struct MeshGeometry {
    instance_meshes: Growable,
}

impl MeshGeometry {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        use wgpu::BufferUsages as U;
        Self {
            instance_meshes: Growable::new(
                device,
                "instance meshes (visibility)",
                U::STORAGE | U::COPY_DST,
                16,
            ),
        }
    }

    /// Upload the frame's instance table (after the mesh set's `prepare`).
    pub(super) fn prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, meshes: &MeshSet) {
        let table: Vec<[u32; 2]> = meshes
            .instance_meshes
            .iter()
            .map(|&m| {
                let m = &meshes.meshes[m as usize];
                [m.first_index, m.base_vertex]
            })
            .collect();
        let bytes: &[u8] = bytemuck::cast_slice(&table);
        if !bytes.is_empty() {
            self.instance_meshes.write_whole(device, queue, bytes);
        }
    }

    /// Bindings 0 to 3 of `geometry.wgsl`'s group: instances, instance meshes, vertices, indices.
    pub(super) fn entries<'a>(&'a self, meshes: &'a MeshSet) -> [wgpu::BindingResource<'a>; 4] {
        let (vertices, indices) = meshes.geometry_buffers();
        [
            meshes.instance_buffer().as_entire_binding(),
            self.instance_meshes.buffer.as_entire_binding(),
            vertices.as_entire_binding(),
            indices.as_entire_binding(),
        ]
    }
}
