//! The meshes a frame draws: registered meshes on the GPU, and each frame's instances uploaded
//! grouped by mesh (all of them for the opaque pass, then the shadow casters for the shadow pass).

use glam::{Mat3, Vec3};

use super::cull;
use super::error::{RenderError, RenderResult};
use super::geometry;
use super::gpu::{InstanceRaw, MeshVertexRaw};
use super::inputs::{Instance, RenderMeshId};
use super::shadow::sphere_rect;
use crate::gpu::resources::Growable;
use crate::mesh::Mesh;

pub(super) struct GpuMesh {
    pub index_count: u32,
    /// Where the mesh lies in the set's one index buffer and one vertex buffer (its indices count
    /// from its own first vertex).
    pub first_index: u32,
    pub base_vertex: u32,
    pub radius: f32,
    /// The vertices and indices uploaded, kept to rebuild the set's buffers when a mesh is added
    /// or replaced by one of another size.
    pub source: (Vec<MeshVertexRaw>, Vec<u32>),
}

/// Which of the frame's draws: the opaque pass's, or a shadow cascade's still or moving casters
/// ([`Instance::still`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DrawSet {
    Opaque,
    Still(usize),
    Moving(usize),
}

/// Draws of one mesh: its index and a range of instances.
type Run = (u32, std::ops::Range<u32>);

/// Registered meshes and the frame's instances.
pub(super) struct MeshSet {
    pub meshes: Vec<GpuMesh>,
    /// Every mesh's vertices, then every mesh's indices, in one buffer each: a pass binds them
    /// once and draws each run of instances with one command (a buffer bound per mesh cost three,
    /// each validated and tracked as the frame's commands are encoded).
    vertices: Growable,
    indices: Growable,
    /// The `version` the two buffers hold (`None`: every mesh to be laid out and written again),
    /// and the meshes replaced since by meshes of the same size, to be written in place.
    uploaded: Option<u64>,
    replaced: Vec<u32>,
    instances: Growable,
    /// This frame's draws: every instance, then the shadow casters.
    draws: Vec<Run>,
    /// Per cascade of the moon's shadow map, the still casters that reach it, then the moving.
    shadow_draws: [[Vec<Run>; 2]; 2],
    /// Per cascade, what its still casters' depth depends on: their meshes and transforms, the
    /// meshes' version and the cascade's projection (equal keys: the same depth).
    pub still_keys: [Option<u64>; 2],
    /// Per cascade, the texels its moving casters can cover (`shadow::sphere_rect`).
    pub moving_rects: [Vec<[u32; 4]>; 2],
    /// The mesh of each instance of `draws`, in the instance buffer's order.
    pub instance_meshes: Vec<u32>,
    /// Instances of the frame outside the view, not drawn by the opaque pass.
    pub culled: usize,
    /// Shadow casters drawn into each cascade this frame.
    pub cascade_casters: [usize; 2],
    /// Counts the changes to `meshes` (the visibility path rebuilds its buffers on a change).
    pub version: u64,
}

impl MeshSet {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        use wgpu::BufferUsages as U;
        // Storage too: the visibility path pulls the vertices and indices in its own passes.
        let geometry =
            |label, usage| Growable::new(device, label, usage | U::STORAGE | U::COPY_DST, 16);
        Self {
            meshes: Vec::new(),
            vertices: geometry("render mesh vertices", U::VERTEX),
            indices: geometry("render mesh indices", U::INDEX),
            uploaded: None,
            replaced: Vec::new(),
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
            shadow_draws: Default::default(),
            still_keys: [None; 2],
            moving_rects: Default::default(),
            cascade_casters: [0, 0],
            instance_meshes: Vec::new(),
            culled: 0,
            version: 0,
        }
    }

    /// Register a mesh; normals are computed here (smooth, split at creases).
    pub(super) fn add(&mut self, device: &wgpu::Device, mesh: &Mesh) -> RenderResult<RenderMeshId> {
        let gpu = shade(mesh)?;
        room(
            self.meshes.iter().chain([&gpu]),
            device.limits().max_buffer_size,
        )?;
        self.meshes.push(gpu);
        self.uploaded = None;
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
        let Some(old) = self.meshes.get(id.0 as usize) else {
            return Err(RenderError::StaleMesh { index: id.0 });
        };
        let mut gpu = shade(mesh)?;
        let others = self
            .meshes
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != id.0 as usize);
        room(
            others.map(|(_, m)| m).chain([&gpu]),
            device.limits().max_buffer_size,
        )?;
        let sizes = |m: &GpuMesh| (m.source.0.len(), m.source.1.len());
        if sizes(&gpu) == sizes(old) {
            (gpu.first_index, gpu.base_vertex) = (old.first_index, old.base_vertex);
            self.replaced.push(id.0);
        } else {
            self.uploaded = None;
        }
        self.meshes[id.0 as usize] = gpu;
        self.version += 1;
        Ok(())
    }

    /// Bring the two buffers up to the registered meshes: after an addition or a change of size
    /// every mesh is laid out again (the buffers grown to hold them) and written, else only the
    /// replaced ones, in place.
    fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) {
        if self.uploaded == Some(self.version) {
            return;
        }
        let vertex = std::mem::size_of::<MeshVertexRaw>() as u64;
        if self.uploaded.is_none() {
            let (mut vertices, mut indices) = (0, 0);
            for m in &mut self.meshes {
                (m.first_index, m.base_vertex) = (indices, vertices);
                vertices += m.source.0.len() as u32;
                indices += m.index_count;
            }
            self.vertices.ensure(device, vertices as u64 * vertex);
            self.indices.ensure(device, indices as u64 * 4);
            self.replaced = (0..self.meshes.len() as u32).collect();
        }
        for &id in &self.replaced {
            let m = &self.meshes[id as usize];
            let at = (m.base_vertex as u64 * vertex, m.first_index as u64 * 4);
            let (vertices, indices) = (&self.vertices.buffer, &self.indices.buffer);
            queue.write_buffer(vertices, at.0, bytemuck::cast_slice(&m.source.0));
            queue.write_buffer(indices, at.1, bytemuck::cast_slice(&m.source.1));
        }
        self.replaced.clear();
        self.uploaded = Some(self.version);
    }

    /// The buffers of every registered mesh's vertices and indices (as of the last `prepare`).
    pub(super) fn geometry_buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.vertices.buffer, &self.indices.buffer)
    }

    /// Upload the frame's instances: those the view may see (`cull::visible` against
    /// `view_proj`) grouped by mesh, then the shadow casters that reach each of the moon's
    /// cascades (`cascades`, world to each cascade's clip space: the same test against its box),
    /// each cascade's grouped by mesh, the still ones first. A caster out of view can still shadow
    /// what is in it; one wholly outside a cascade's box leaves no texel in it.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &[Instance],
        view_proj: glam::Mat4,
        (cascades, shadow_size): ([glam::Mat4; 2], u32),
    ) {
        self.upload(device, queue);
        // Each instance's bounding sphere and its form for the GPU, once for the view and both
        // cascades.
        let spheres: Vec<_> = frame
            .iter()
            .map(|i| cull::bounding_sphere(i.transform, self.meshes[i.mesh.0 as usize].radius))
            .collect();
        let raws: Vec<InstanceRaw> = frame.iter().map(raw).collect();
        let visible = cull::visible(view_proj, &spheres);
        let in_cascade = cascades.map(|m| cull::visible(m, &spheres));
        let mut order: Vec<usize> = (0..frame.len()).collect();
        order.sort_by_key(|&i| frame[i].mesh.0);
        let casters = in_cascade.map(|inside| {
            order
                .iter()
                .copied()
                .filter(|&i| frame[i].casts_shadow && inside[i])
                .collect::<Vec<usize>>()
        });
        order.retain(|&i| visible[i]);
        self.culled = frame.len() - order.len();
        self.cascade_casters = casters.each_ref().map(Vec::len);
        let mut instances: Vec<InstanceRaw> = order.iter().map(|&i| raws[i]).collect();
        let runs = |ids: &[usize], first: usize| {
            let mut out: Vec<Run> = Vec::new();
            for (k, &i) in ids.iter().enumerate() {
                let mesh = frame[i].mesh.0;
                let at = (first + k) as u32;
                match out.last_mut() {
                    Some((m, r)) if *m == mesh => r.end = at + 1,
                    _ => out.push((mesh, at..at + 1)),
                }
            }
            out
        };
        self.draws = runs(&order, 0);
        self.instance_meshes = order.iter().map(|&i| frame[i].mesh.0).collect();
        for (cascade, ids) in casters.iter().enumerate() {
            let (still, moving): (Vec<usize>, Vec<usize>) =
                ids.iter().partition(|&&i| frame[i].still);
            self.still_keys[cascade] = (!still.is_empty())
                .then(|| still_key(frame, &still, self.version, cascades[cascade]));
            self.moving_rects[cascade] = moving
                .iter()
                .filter_map(|&i| {
                    let (at, radius) = spheres[i];
                    sphere_rect(cascades[cascade], at, radius, shadow_size)
                })
                .collect();
            for (k, ids) in [still, moving].iter().enumerate() {
                self.shadow_draws[cascade][k] = runs(ids, instances.len());
                instances.extend(ids.iter().map(|&i| raws[i]));
            }
        }
        if !instances.is_empty() {
            self.instances
                .write_whole(device, queue, bytemuck::cast_slice(&instances));
        }
    }

    /// Whether the frame has instances to draw in `set`.
    pub(super) fn has_draws(&self, set: DrawSet) -> bool {
        !self.runs(set).is_empty()
    }

    fn runs(&self, set: DrawSet) -> &[Run] {
        match set {
            DrawSet::Opaque => &self.draws,
            DrawSet::Still(c) => &self.shadow_draws[c][0],
            DrawSet::Moving(c) => &self.shadow_draws[c][1],
        }
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

    /// Draw the frame's instances of `set` with the pass's pipeline and bind groups set.
    pub(super) fn draw(&self, p: &mut wgpu::RenderPass<'_>, set: DrawSet) {
        p.set_vertex_buffer(0, self.vertices.buffer.slice(..));
        p.set_vertex_buffer(1, self.instances.buffer.slice(..));
        p.set_index_buffer(self.indices.buffer.slice(..), wgpu::IndexFormat::Uint32);
        for (mesh, range) in self.runs(set) {
            let m = &self.meshes[*mesh as usize];
            let indices = m.first_index..m.first_index + m.index_count;
            p.draw_indexed(indices, m.base_vertex as i32, range.clone());
        }
    }
}

/// What the depth of a cascade's still casters (`ids` of `frame`) depends on, hashed: each one's
/// mesh and transform, the registered meshes' `version` and the cascade's `projection`.
fn still_key(frame: &[Instance], ids: &[usize], version: u64, projection: glam::Mat4) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    version.hash(&mut h);
    let bits = |m: &glam::Mat4| m.to_cols_array().map(f32::to_bits);
    bits(&projection).hash(&mut h);
    for &i in ids {
        frame[i].mesh.0.hash(&mut h);
        bits(&frame[i].transform).hash(&mut h);
    }
    h.finish()
}

/// The instance as the mesh pipelines read it.
fn raw(inst: &Instance) -> InstanceRaw {
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
}

/// Whether `meshes` fit the one vertex and one index buffer of a device whose buffers hold at
/// most `max` bytes.
fn room<'a>(meshes: impl Iterator<Item = &'a GpuMesh>, max: u64) -> RenderResult<()> {
    let (mut vertices, mut indices) = (0u64, 0u64);
    for m in meshes {
        vertices += std::mem::size_of_val(m.source.0.as_slice()) as u64;
        indices += std::mem::size_of_val(m.source.1.as_slice()) as u64;
    }
    for (what, bytes) in [("vertices", vertices), ("indices", indices)] {
        if bytes > max {
            return Err(RenderError::MeshesTooLarge { what, bytes, max });
        }
    }
    Ok(())
}

fn shade(mesh: &Mesh) -> RenderResult<GpuMesh> {
    mesh.validate("render mesh")?;
    let (vertices, indices) = geometry::shade_normals(mesh, geometry::CREASE_DEGREES);
    Ok(GpuMesh {
        index_count: indices.len() as u32,
        first_index: 0,
        base_vertex: 0,
        radius: mesh.bounding_radius(),
        source: (vertices, indices),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two cubes (24 vertices, split at the creases, and 36 indices each) fit in 48 vertices'
    /// bytes and no fewer, refused by their vertices; 100 indices alone fit in 400 bytes and no
    /// fewer, refused by their indices.
    #[test]
    fn meshes_past_the_device_s_largest_buffer_are_refused_with_the_bytes() {
        let cube = shade(&Mesh::cuboid(Vec3::ONE)).expect("cube");
        let vertex = std::mem::size_of::<MeshVertexRaw>() as u64;
        assert_eq!((cube.source.0.len(), cube.source.1.len()), (24, 36));
        let two = [&cube, &cube];
        assert!(room(two.into_iter(), 48 * vertex).is_ok());
        match room(two.into_iter(), 48 * vertex - 1) {
            Err(RenderError::MeshesTooLarge { what, bytes, .. }) => {
                assert_eq!((what, bytes), ("vertices", 48 * vertex));
            }
            other => panic!("expected the vertices refused, got {other:?}"),
        }
        // Indices alone past the limit: they are what is refused.
        let strip = GpuMesh {
            source: (Vec::new(), vec![0; 100]),
            ..shade(&Mesh::cuboid(Vec3::ONE)).expect("cube")
        };
        let e = room([&strip].into_iter(), 399).unwrap_err().to_string();
        assert!(
            e.contains("indices would take 400 bytes") && e.contains("at most 399"),
            "{e}"
        );
        assert!(room([&strip].into_iter(), 400).is_ok());
    }
}
