//! The meshes a frame draws: registered meshes on the GPU, and each frame's instances uploaded
//! grouped by mesh (all of them for the opaque pass, then the shadow casters for the shadow pass:
//! first those that rest, exactly as they were in the previous frame, then those that moved, so
//! that the shadow pass can keep what the resting ones cast).

use std::collections::HashSet;
use std::hash::{Hash, Hasher};

use glam::{Mat3, Vec3};

use super::error::{RenderError, RenderResult};
use super::geometry;
use super::gpu::InstanceRaw;
use super::inputs::{Instance, RenderMeshId};
use crate::gpu::resources::Growable;
use crate::mesh::Mesh;

pub(super) struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    pub radius: f32,
}

/// Draws of one mesh: its index and a range of instances.
type Run = (u32, std::ops::Range<u32>);

/// A shadow caster as the previous frame drew it: its mesh and transform, bit for bit.
type CasterKey = (u32, [u32; 16]);

fn caster_key(inst: &Instance) -> CasterKey {
    (
        inst.mesh.0,
        inst.transform.to_cols_array().map(f32::to_bits),
    )
}

/// Which of the frame's draws to record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Draws {
    /// Every instance (the opaque pass).
    All,
    /// Every shadow caster.
    Casters,
    /// Shadow casters exactly as they were in the previous frame.
    Resting,
    /// The other shadow casters.
    Moving,
}

/// Registered meshes and the frame's instances.
pub(super) struct MeshSet {
    pub meshes: Vec<GpuMesh>,
    instances: Growable,
    /// This frame's draws: every instance, then the resting and the moving shadow casters.
    draws: Vec<Run>,
    resting_draws: Vec<Run>,
    moving_draws: Vec<Run>,
    /// The resting casters, as one number: equal between frames when the same casters rest.
    pub resting_key: u64,
    /// The previous frame's casters.
    previous: HashSet<CasterKey>,
}

impl MeshSet {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        Self {
            meshes: Vec::new(),
            instances: Growable::new(
                device,
                "mesh instances",
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                144 * 64,
            ),
            draws: Vec::new(),
            resting_draws: Vec::new(),
            moving_draws: Vec::new(),
            resting_key: 0,
            previous: HashSet::new(),
        }
    }

    /// Register a mesh; normals are computed here (smooth, split at creases).
    pub(super) fn add(&mut self, device: &wgpu::Device, mesh: &Mesh) -> RenderResult<RenderMeshId> {
        let gpu = upload(device, mesh)?;
        self.meshes.push(gpu);
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
        Ok(())
    }

    /// Upload the frame's instances: all of them grouped by mesh, then the resting shadow casters
    /// and the moving ones, each grouped by mesh.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &[Instance],
    ) {
        let mut order: Vec<usize> = (0..frame.len()).collect();
        order.sort_by_key(|&i| frame[i].mesh.0);
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
        let casters: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| frame[i].casts_shadow)
            .collect();
        let (resting, moving): (Vec<usize>, Vec<usize>) = casters
            .iter()
            .partition(|&&i| self.previous.contains(&caster_key(&frame[i])));
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        for &i in &resting {
            caster_key(&frame[i]).hash(&mut hasher);
        }
        self.resting_key = hasher.finish();
        self.previous = casters.iter().map(|&i| caster_key(&frame[i])).collect();
        instances.extend(resting.iter().map(|&i| raw(&frame[i])));
        instances.extend(moving.iter().map(|&i| raw(&frame[i])));
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
        self.resting_draws = runs(&resting, order.len() as u32);
        self.moving_draws = runs(&moving, (order.len() + resting.len()) as u32);
        if !instances.is_empty() {
            self.instances
                .ensure(device, std::mem::size_of_val(instances.as_slice()) as u64);
            queue.write_buffer(&self.instances.buffer, 0, bytemuck::cast_slice(&instances));
        }
    }

    fn runs(&self, which: Draws) -> impl Iterator<Item = &Run> {
        let (a, b): (&[Run], &[Run]) = match which {
            Draws::All => (&self.draws, &[]),
            Draws::Casters => (&self.resting_draws, &self.moving_draws),
            Draws::Resting => (&self.resting_draws, &[]),
            Draws::Moving => (&self.moving_draws, &[]),
        };
        a.iter().chain(b)
    }

    /// Whether the frame has instances of `which` to draw.
    pub(super) fn has_draws(&self, which: Draws) -> bool {
        self.runs(which).next().is_some()
    }

    /// Draw the frame's instances of `which` with the pass's pipeline and bind groups set.
    pub(super) fn draw(&self, p: &mut wgpu::RenderPass<'_>, which: Draws) {
        p.set_vertex_buffer(1, self.instances.buffer.slice(..));
        for (mesh, range) in self.runs(which) {
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
    })
}
