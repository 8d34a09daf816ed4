//! The visibility path's view of the meshes (`geometry.wgsl`): every registered mesh's vertices
//! and indices in one storage buffer each, and per instance of the frame its mesh's first index
//! and first vertex. The meshes' buffers are rebuilt when a mesh is added or replaced; the
//! instance table every frame.

use super::super::meshes::MeshSet;
use crate::gpu::resources::Growable;

pub(super) struct MeshGeometry {
    vertices: Growable,
    indices: Growable,
    instance_meshes: Growable,
    /// The mesh set's version the buffers hold (`None`: never built).
    version: Option<u64>,
    /// Per mesh: its first index and first vertex in the buffers.
    first: Vec<[u32; 2]>,
}

impl MeshGeometry {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        use wgpu::BufferUsages as U;
        let storage = |label| Growable::new(device, label, U::STORAGE | U::COPY_DST, 16);
        Self {
            vertices: storage("mesh vertices (visibility)"),
            indices: storage("mesh indices (visibility)"),
            instance_meshes: storage("instance meshes (visibility)"),
            version: None,
            first: Vec::new(),
        }
    }

    /// Upload the meshes if they changed, and the frame's instance table.
    pub(super) fn prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, meshes: &MeshSet) {
        if self.version != Some(meshes.version) {
            let (mut vertices, mut indices) = (Vec::new(), Vec::new());
            self.first.clear();
            for m in &meshes.meshes {
                self.first
                    .push([indices.len() as u32, vertices.len() as u32]);
                vertices.extend_from_slice(&m.source.0);
                indices.extend_from_slice(&m.source.1);
            }
            upload(
                device,
                queue,
                &mut self.vertices,
                bytemuck::cast_slice(&vertices),
            );
            upload(
                device,
                queue,
                &mut self.indices,
                bytemuck::cast_slice(&indices),
            );
            self.version = Some(meshes.version);
        }
        let table: Vec<[u32; 2]> = meshes
            .instance_meshes
            .iter()
            .map(|&m| self.first[m as usize])
            .collect();
        upload(
            device,
            queue,
            &mut self.instance_meshes,
            bytemuck::cast_slice(&table),
        );
    }

    /// Bindings 0 to 3 of `geometry.wgsl`'s group: instances, instance meshes, vertices, indices.
    pub(super) fn entries<'a>(
        &'a self,
        instances: &'a wgpu::Buffer,
    ) -> [wgpu::BindingResource<'a>; 4] {
        [
            instances.as_entire_binding(),
            self.instance_meshes.buffer.as_entire_binding(),
            self.vertices.buffer.as_entire_binding(),
            self.indices.buffer.as_entire_binding(),
        ]
    }
}

fn upload(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &mut Growable, bytes: &[u8]) {
    if !bytes.is_empty() {
        buffer.ensure(device, bytes.len() as u64);
        queue.write_buffer(&buffer.buffer, 0, bytes);
    }
}
