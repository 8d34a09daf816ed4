//! The meshes a frame draws: registered meshes on the GPU, and each frame's instances uploaded
//! grouped by mesh (all of them for the opaque pass, then the shadow casters for the shadow pass).

use glam::{Mat3, Vec3};

use super::cull;
use super::error::{RenderError, RenderResult};
use super::geometry;
use super::gpu::{InstanceRaw, MeshVertexRaw};
use super::inputs::{Instance, RenderMeshId};
use crate::gpu::resources::Growable;
use crate::mesh::Mesh;

pub(super) struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    pub index_count: u32,
    pub radius: f32,
    /// The vertices and indices uploaded, kept for the visibility path's one buffer of every
    /// mesh (`opaque::geometry`).
    pub source: (Vec<MeshVertexRaw>, Vec<u32>),
}

/// Draws of one mesh: its index and a range of instances.
type Run = (u32, std::ops::Range<u32>);

/// Registered meshes and the frame's instances.
pub(super) struct MeshSet {
    pub meshes: Vec<GpuMesh>,
    instances: Growable,
    /// This frame's draws: every instance, then the shadow casters.
    draws: Vec<Run>,
    shadow_draws: Vec<Run>,
    /// The mesh of each instance of `draws`, in the instance buffer's order.
    pub instance_meshes: Vec<u32>,
    /// Instances of the frame outside the view, not drawn by the opaque pass.
    pub culled: usize,
    /// Counts the changes to `meshes` (the visibility path rebuilds its buffers on a change).
    pub version: u64,
}

impl MeshSet {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        Self {
            meshes: Vec::new(),
            instances: Growable::new(
                device,
                "mesh instances",
                // Storage too: the visibility path reads the instances in its own passes.
                wgpu::BufferUsages::VERTEX
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                144 * 64,
            ),
            draws: Vec::new(),
            shadow_draws: Vec::new(),
            instance_meshes: Vec::new(),
            culled: 0,
            version: 0,
        }
    }

    /// Register a mesh; normals are computed here (smooth, split at creases).
    pub(super) fn add(&mut self, device: &wgpu::Device, mesh: &Mesh) -> RenderResult<RenderMeshId> {
        let gpu = upload(device, mesh)?;
        self.meshes.push(gpu);
        self.version += 1;
        Ok(RenderMeshId(self.meshes.len() as u32 - 1))
    }

    /// Replace a registered mesh.
    pub(super) fn update(
        &mut self,
        device: &wgpu::Device,
        id: RenderMeshId,
        mesh: &Mesh,
    ) -> RenderResult<()> {
        if id.0 as usize >= self.meshes.len() {
            return Err(RenderError::StaleMesh { index: id.0 });
        }
        self.meshes[id.0 as usize] = upload(device, mesh)?;
        self.version += 1;
        Ok(())
    }

    /// Upload the frame's instances: those the view may see (`cull::visible` against
    /// `view_proj`) grouped by mesh, then every shadow caster grouped by mesh (a caster out of
    /// view can shadow what is in it).
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &[Instance],
        view_proj: glam::Mat4,
    ) {
        let radii = frame
            .iter()
            .map(|i| (i.transform, self.meshes[i.mesh.0 as usize].radius));
        let visible = cull::visible(view_proj, radii);
        let mut order: Vec<usize> = (0..frame.len()).collect();
        order.sort_by_key(|&i| frame[i].mesh.0);
        let casters: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| frame[i].casts_shadow)
            .collect();
        order.retain(|&i| visible[i]);
        self.culled = frame.len() - order.len();
        let raw = |inst: &Instance| {
            let normal = Mat3::from_mat4(inst.transform).inverse().transpose();
            let c = |v: Vec3| [v.x, v.y, v.z, 0.0];
            InstanceRaw {
                model: inst.transform.to_cols_array_2d(),
                normal: [c(normal.x_axis), c(normal.y_axis), c(normal.z_axis)],
                albedo_material: [
                    inst.albedo[0],
                    inst.albedo[1],
                    inst.albedo[2],
                    inst.material.code(),
                ],
                params: [inst.roughness, inst.emission, inst.snow_cover, inst.seed],
            }
        };
        let mut instances: Vec<InstanceRaw> = order.iter().map(|&i| raw(&frame[i])).collect();
        instances.extend(casters.iter().map(|&i| raw(&frame[i])));
        let runs = |ids: &[usize], first: u32| {
            let mut out: Vec<Run> = Vec::new();
            for (k, &i) in ids.iter().enumerate() {
                let mesh = frame[i].mesh.0;
                let at = first + k as u32;
                match out.last_mut() {
                    Some((m, r)) if *m == mesh => r.end = at + 1,
                    _ => out.push((mesh, at..at + 1)),
                }
            }
            out
        };
        self.draws = runs(&order, 0);
        self.instance_meshes = order.iter().map(|&i| frame[i].mesh.0).collect();
        self.shadow_draws = runs(&casters, order.len() as u32);
        if !instances.is_empty() {
            self.instances
                .ensure(device, std::mem::size_of_val(instances.as_slice()) as u64);
            queue.write_buffer(&self.instances.buffer, 0, bytemuck::cast_slice(&instances));
        }
    }

    /// Whether the frame has instances (`shadow`: shadow casters) to draw.
    pub(super) fn has_draws(&self, shadow: bool) -> bool {
        !if shadow {
            &self.shadow_draws
        } else {
            &self.draws
        }
        .is_empty()
    }

    /// The instance buffer (all of the frame's instances first, in `instance_meshes`' order).
    pub(super) fn instance_buffer(&self) -> &wgpu::Buffer {
        &self.instances.buffer
    }

    /// Draw every instance without vertex or index buffers: `index_count` vertices an instance,
    /// which the pipeline pulls from storage (the visibility path).
    pub(super) fn draw_pulled(&self, p: &mut wgpu::RenderPass<'_>) {
        for (mesh, range) in &self.draws {
            p.draw(0..self.meshes[*mesh as usize].index_count, range.clone());
        }
    }

    /// Draw the frame's instances (`shadow`: the shadow casters) with the pass's pipeline and
    /// bind groups set.
    pub(super) fn draw(&self, p: &mut wgpu::RenderPass<'_>, shadow: bool) {
        p.set_vertex_buffer(1, self.instances.buffer.slice(..));
        let runs = if shadow {
            &self.shadow_draws
        } else {
            &self.draws
        };
        for (mesh, range) in runs {
            let m = &self.meshes[*mesh as usize];
            p.set_vertex_buffer(0, m.vertices.slice(..));
            p.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
            p.draw_indexed(0..m.index_count, 0, range.clone());
        }
    }
}

fn upload(device: &wgpu::Device, mesh: &Mesh) -> RenderResult<GpuMesh> {
    mesh.validate("render mesh")?;
    let (vertices, indices) = geometry::shade_normals(mesh, geometry::CREASE_DEGREES);
    use wgpu::util::DeviceExt;
    Ok(GpuMesh {
        vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("render mesh vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        }),
        indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("render mesh indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        }),
        index_count: indices.len() as u32,
        radius: mesh.bounding_radius(),
        source: (vertices, indices),
    })
}
