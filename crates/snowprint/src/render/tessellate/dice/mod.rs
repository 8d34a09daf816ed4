//! The `dice` pass (compute, `dice.wgsl`): each diced surface's base mesh into displaced-ready
//! vertices and indices, one workgroup per base triangle, with edge levels from the camera; then
//! `seal` closes the surface's run of indices and writes its indexed indirect draw. The pass owns
//! the base meshes, the diced mesh and the counters (which every tier clears, so every surface's
//! draw arguments start at zero).

use std::collections::HashMap;

use glam::Mat4;

use super::VERTEX_BYTES;
use super::gpu::counters_bytes;
use super::seams;
use super::{ARGS_BASE, ARGS_STRIDE, DiceParams, DicedKind, DicedMesh, DicedVertex, SurfaceMesh};
use crate::gpu::resources::{Growable, KeptGroups, uniform_block};
use crate::render::config::RenderConfig;
use crate::render::error::RenderResult;
use crate::render::frame::{FAR, FrameSurface, NEAR};
use crate::render::gpu::{FrameUniform, UNIFORM_STRIDE};
use crate::render::heightfield::HeightfieldPass;
use crate::render::inputs::RenderFrame;
use crate::render::pipeline;
use crate::render::readback::{Timestamps, compute_pass, read_back};
use crate::surface::SurfaceId;

/// A surface's base mesh on the GPU.
struct BaseMeshGpu {
    /// Kept and written again when the mesh changes (a window level's hole moves with every
    /// scroll); grown when the new mesh is larger.
    buffer: Growable,
    triangles: u32,
    key: BaseMeshKey,
}

/// What a base mesh on the GPU was built for: the surface's half sides and hole (bits), and the
/// geometry's version.
#[derive(Clone, Copy, PartialEq)]
struct BaseMeshKey {
    half: [u32; 2],
    version: u64,
    hole: Option<[u32; 4]>,
}

pub(in crate::render) struct DicePass {
    layout: wgpu::BindGroupLayout,
    dice: wgpu::ComputePipeline,
    seal: wgpu::ComputePipeline,
    /// Per surface: `DiceParams` in a uniform block.
    params: Growable,
    /// Diced vertices (two vec4 each), indices, counters and draw arguments.
    pub vertices: Growable,
    pub indices: Growable,
    pub counters: Growable,
    base_meshes: HashMap<SurfaceId, BaseMeshGpu>,
    /// This frame's bind group and base triangles per surface; `None` where it is not diced.
    bind_groups: Vec<Option<(wgpu::BindGroup, u32)>>,
    /// The groups by surface slot, kept while what they bind stays.
    kept: KeptGroups,
}

impl DicePass {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let layout = crate::wgsl::DICE.bind_group_layout(device, "dice", 0);
        let module = pipeline::shader(device, "dice.wgsl", crate::wgsl::DICE.wgsl());
        let dice = pipeline::compute(device, "dice", &module, "dice_surface", &[&layout]);
        let seal = pipeline::compute(device, "dice seal", &module, "seal", &[&layout]);
        use wgpu::BufferUsages as U;
        Self {
            params: Growable::new(device, "dice params", U::UNIFORM | U::COPY_DST, 256 * 8),
            vertices: Growable::new(
                device,
                "diced vertices",
                U::STORAGE | U::VERTEX | U::COPY_SRC,
                16,
            ),
            indices: Growable::new(
                device,
                "diced indices",
                U::STORAGE | U::INDEX | U::COPY_SRC,
                16,
            ),
            counters: Growable::new(
                device,
                "dice counters",
                U::STORAGE | U::INDIRECT | U::COPY_SRC | U::COPY_DST,
                counters_bytes(8),
            ),
            layout,
            dice,
            seal,
            base_meshes: HashMap::new(),
            bind_groups: Vec::new(),
            kept: KeptGroups::default(),
        }
    }

    /// Whether any surface is diced this frame.
    pub(crate) fn any(&self) -> bool {
        self.bind_groups.iter().any(Option::is_some)
    }

    /// Make room for the counters of every surface and, in the tessellated tier (`active`), for
    /// the diced mesh; upload the diced surfaces' base meshes (when their size or geometry
    /// changed) and dicing parameters, and bind them.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        active: bool,
        cfg: &RenderConfig,
        frame: &RenderFrame<'_>,
        uniform: &FrameUniform,
        surfaces: &[FrameSurface<'_>],
        geometry_version: u64,
        heightfields: &HeightfieldPass,
        state: &wgpu::Buffer,
        ground: &wgpu::Buffer,
    ) -> RenderResult<()> {
        let n = surfaces.len();
        self.counters.ensure(device, counters_bytes(n));
        self.bind_groups.clear();
        if !active {
            return Ok(());
        }
        let (iw, ih) = (cfg.width * cfg.supersample, cfg.height * cfg.supersample);
        let proj = frame.camera.projection(iw as f32 / ih as f32, NEAR, FAR);
        let pixels_per_radian = ih as f32 * 0.5 * proj.y_axis.y;
        let view_proj = Mat4::from_cols_array_2d(&uniform.view_proj);
        let vertex_capacity = cfg.dice.max_triangles;
        let index_capacity = cfg.dice.max_triangles * 3;
        self.vertices
            .ensure(device, vertex_capacity as u64 * VERTEX_BYTES);
        self.indices.ensure(device, index_capacity as u64 * 4);
        let stride = UNIFORM_STRIDE as usize;
        let mut bytes = vec![0u8; n.max(1) * stride];
        for (s, surface) in surfaces.iter().enumerate() {
            if !(surface.tessellated && surface.seen) {
                continue;
            }
            let (desc, layout, g) = (surface.view.desc, surface.view.layout, surface.geometry);
            let texel = surface.texel();
            let half = desc.size * 0.5;
            let hole = surface.view.hole;
            let key = BaseMeshKey {
                half: [half.x.to_bits(), half.y.to_bits()],
                version: geometry_version,
                hole: hole.map(|h| h.map(f32::to_bits)),
            };
            let id = surface.view.id;
            self.upload_base_mesh((device, queue), id, g.mesh.as_ref(), half, hole, key)?;
            let base = &self.base_meshes[&id];
            let local_to_world = desc.local_to_world();
            let eye = local_to_world.inverse().transform_point3(frame.camera.eye);
            let dice = DiceParams {
                local_to_clip: (view_proj * local_to_world).to_cols_array_2d(),
                eye: [eye.x, eye.y, eye.z, pixels_per_radian],
                settings: [
                    cfg.dice.target_edge_pixels,
                    cfg.dice.max_level as f32,
                    0.5 * texel.min_element(),
                    cfg.dice.detail_floor,
                ],
                // Banks stay below the snow depth in practice; waves reach 5 cm at most. The
                // ground field's range widens the box (0, 0 on flat ground).
                extent: [
                    desc.snow_depth,
                    desc.snow_depth + 0.05 * g.macro_waves,
                    surface.view.ground_range.0,
                    surface.view.ground_range.1,
                ],
                grid: [layout.width, layout.height, s as u32, base.triangles],
                capacity: [
                    vertex_capacity,
                    index_capacity,
                    surface.view.ground,
                    seams::seam_sides(surface.enclosed, surface.sides.map(|s| s.is_some())),
                ],
                half_size: [half.x, half.y, 0.0, 0.0],
                local_to_shadow: (Mat4::from_cols_array_2d(&uniform.shadow_near) * local_to_world)
                    .to_cols_array_2d(),
            };
            bytes[s * stride..s * stride + std::mem::size_of::<DiceParams>()]
                .copy_from_slice(bytemuck::bytes_of(&dice));
        }
        self.params.write_whole(device, queue, &bytes);
        let tv = wgpu::BindingResource::TextureView;
        self.kept.truncate(n);
        for (s, surface) in surfaces.iter().enumerate() {
            let tex = heightfields.texture(surface.view.id);
            let (true, Some(tex)) = (surface.tessellated && surface.seen, tex) else {
                self.bind_groups.push(None);
                continue;
            };
            let base = &self.base_meshes[&surface.view.id];
            let group = self.kept.get(
                device,
                "dice",
                &self.layout,
                s,
                &[
                    uniform_block(&self.params.buffer, s, std::mem::size_of::<DiceParams>()),
                    base.buffer.buffer.as_entire_binding(),
                    tv(&tex.shape),
                    tv(&tex.bank),
                    state.as_entire_binding(),
                    self.vertices.buffer.as_entire_binding(),
                    self.indices.buffer.as_entire_binding(),
                    self.counters.buffer.as_entire_binding(),
                    ground.as_entire_binding(),
                ],
            );
            self.bind_groups.push(Some((group, base.triangles)));
        }
        Ok(())
    }

    /// Upload a surface's base mesh (its own, or its rectangle with its `hole` cut out) unless
    /// the one on the GPU was built for the same `key`.
    fn upload_base_mesh(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        id: SurfaceId,
        mesh: Option<&SurfaceMesh>,
        half: glam::Vec2,
        hole: Option<[f32; 4]>,
        key: BaseMeshKey,
    ) -> RenderResult<()> {
        if self.base_meshes.get(&id).is_some_and(|b| b.key == key) {
            return Ok(());
        }
        let triangles = match mesh {
            Some(m) => {
                m.validate(half)?;
                m.base_triangles()
            }
            None => seams::rectangle_triangles(half, hole),
        };
        let bytes: &[u8] = bytemuck::cast_slice(&triangles);
        let base = self.base_meshes.entry(id).or_insert_with(|| BaseMeshGpu {
            buffer: Growable::new(
                device,
                "snow base mesh",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                bytes.len() as u64,
            ),
            triangles: 0,
            key,
        });
        base.buffer.ensure(device, bytes.len() as u64);
        queue.write_buffer(&base.buffer.buffer, 0, bytes);
        base.triangles = triangles.len() as u32;
        base.key = key;
        Ok(())
    }

    /// Clear the counters (every tier: all draw arguments start at zero), then dice one surface
    /// after the other: `seal` closes each surface's run of indices.
    pub(crate) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
    ) {
        encoder.clear_buffer(&self.counters.buffer, 0, None);
        let mut p = compute_pass(encoder, ts, slot);
        for (group, triangles) in self.bind_groups.iter().flatten() {
            p.set_bind_group(0, group, &[]);
            p.set_pipeline(&self.dice);
            let (x, y) = crate::gpu::resources::dispatch_rows(*triangles);
            p.dispatch_workgroups(x, y, 1);
            p.set_pipeline(&self.seal);
            p.dispatch_workgroups(1, 1, 1);
        }
    }

    /// Byte offset of surface slot `s`'s indexed indirect draw in the counters.
    pub(crate) fn args_offset(s: usize) -> u64 {
        (ARGS_BASE + ARGS_STRIDE * s as u64) * 4
    }

    /// Draw each diced surface's mesh: `groups` holds the draw's bind group 1 per surface slot
    /// (`None`: not diced); the pass's pipeline and group 0 are set.
    pub(crate) fn draw(&self, p: &mut wgpu::RenderPass<'_>, groups: &[Option<wgpu::BindGroup>]) {
        p.set_vertex_buffer(0, self.vertices.buffer.slice(..));
        p.set_index_buffer(self.indices.buffer.slice(..), wgpu::IndexFormat::Uint32);
        for (s, g) in groups.iter().enumerate() {
            if let Some(g) = g {
                p.set_bind_group(1, g, &[]);
                p.draw_indexed_indirect(&self.counters.buffer, Self::args_offset(s));
            }
        }
    }

    /// The diced mesh of surface slot `s` in the latest frame, read back from the GPU.
    pub(crate) fn read_mesh(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        s: usize,
    ) -> RenderResult<DicedMesh> {
        let words = |b: &[u8]| -> Vec<u32> {
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        };
        let args = words(&read_back(
            device,
            queue,
            &self.counters.buffer,
            Self::args_offset(s),
            20,
        )?);
        let (count, first) = (args[0] as u64, args[2] as u64);
        if count == 0 {
            return Ok(DicedMesh {
                vertices: Vec::new(),
                triangles: Vec::new(),
            });
        }
        let indices = words(&read_back(
            device,
            queue,
            &self.indices.buffer,
            first * 4,
            count * 4,
        )?);
        let lo = indices.iter().copied().min().unwrap_or(0) as u64;
        let hi = indices.iter().copied().max().unwrap_or(0) as u64;
        let raw = read_back(
            device,
            queue,
            &self.vertices.buffer,
            lo * VERTEX_BYTES,
            (hi + 1 - lo) * VERTEX_BYTES,
        )?;
        let floats: Vec<f32> = raw
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let vertices = floats
            .chunks_exact(8)
            .map(|v| DicedVertex {
                position: glam::Vec3::new(v[0], v[1], v[2]),
                kind: match v[3] as u32 {
                    0 => DicedKind::Top,
                    1 => DicedKind::SkirtTop,
                    _ => DicedKind::SkirtBottom,
                },
            })
            .collect();
        let triangles = indices
            .chunks_exact(3)
            .map(|t| [t[0] - lo as u32, t[1] - lo as u32, t[2] - lo as u32])
            .collect();
        Ok(DicedMesh {
            vertices,
            triangles,
        })
    }
}
