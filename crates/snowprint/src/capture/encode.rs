//! Recording a frame's capture: what to draw where ([`CapturePlan`], built on the CPU by the
//! world's frame plan) into render passes over the atlas, one per batch.

use std::ops::Range;

use super::{CapturePipelines, CaptureView, GpuPrimitive, MeshDraw};
use crate::gpu::resources::{UNIFORM_STRIDE, bind_group, uniform_block};
use crate::gpu::timestamps::StageQueries;
use crate::mesh::MeshId;
use crate::pool::TILE_LIST_HEADER;

/// A mesh deformer's GPU buffers, as the capture draws it.
#[derive(Debug)]
pub struct CaptureMesh {
    /// Vertex positions (`Float32x3`), posed each frame by the caller.
    pub vertices: wgpu::Buffer,
    /// Triangle indices (`Uint32`).
    pub indices: wgpu::Buffer,
    /// Indices to draw.
    pub index_count: u32,
    /// Vertices the mesh has (a pose must give as many).
    pub vertex_count: usize,
    /// Largest distance of a vertex from the mesh's origin, metres (for culling and sub-steps).
    pub radius: f32,
}

/// One captured surface: its capture region's rectangle of the atlas ([`super::region`]: the
/// surface's texels and the apron) and what is drawn in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CapturedSurface {
    /// The surface's record in the frame's update.
    pub record: u32,
    /// Which pass over the atlas.
    pub batch: u32,
    /// Left texel of the region in the atlas.
    pub x: u32,
    /// Top texel of the region in the atlas.
    pub y: u32,
    /// Heightmap width, texels.
    pub width: u32,
    /// Heightmap height, texels.
    pub height: u32,
    /// The surface's analytic primitives in [`CapturePlan::prims`].
    pub prims: Range<u32>,
    /// The surface's mesh draws in [`CapturePlan::draws`].
    pub draws: Range<u32>,
    /// Whether the compute path captures it (its view's `prims` and `rect`; no viewport).
    pub compute: bool,
    /// Whether its region is cleared before the capture: always on the raster path; on the compute
    /// path unless its work list took the tiles beside the reached ones (`capture::tiles_reached`).
    pub cleared: bool,
}

/// What a frame's capture draws: one [`CapturedSurface`] and one [`CaptureView`] per captured
/// surface (the view's index is its dynamic offset), the primitives and mesh draws they name,
/// and the sizes of the buffers the capture writes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CapturePlan {
    /// Captured surfaces, in view order.
    pub surfaces: Vec<CapturedSurface>,
    /// Their views, as uploaded.
    pub views: Vec<CaptureView>,
    /// Every analytic primitive of the frame, surface-local, culled and swept.
    pub prims: Vec<GpuPrimitive>,
    /// Every mesh draw of the frame.
    pub draws: Vec<MeshDraw>,
    /// The mesh of each draw.
    pub draw_meshes: Vec<MeshId>,
    /// Side of the atlas, texels.
    pub atlas_side: u32,
    /// Render passes over the atlas.
    pub batches: u32,
    /// The compute path's work: `[view, tile y << 16 | tile x]` for every tile a surface's
    /// primitives reach (empty: no surface takes the compute path).
    pub work: Vec<[u32; 2]>,
    /// Texels of the capture buffer (every captured surface's region, one after the other).
    pub texels: u32,
    /// Tile flags of the captured surfaces.
    pub tile_flags: u32,
    /// Clear the capture over every captured region (the separate passes blur every texel of
    /// them); else only over those marked `cleared`.
    pub clear_all: bool,
    /// The capture buffer's ranges cleared before the capture, `(first texel, texels)`
    /// ([`CapturePlan::plan_clears`]).
    pub clears: Vec<(u32, u32)>,
    /// The update's tiles of the surfaces it ray-casts itself ([`super::CapturePath::Update`]),
    /// listed by the plan when the update takes its tiles from the list: `[record, tile y << 16 |
    /// tile x]`. They are uploaded as the list's first entries, with its header; the capture
    /// appends its own after them.
    pub listed: Vec<[u32; 2]>,
    /// The first record of the fused pass's grid, in the list's header
    /// (`TILE_LIST_GRID_FIRST`): the records before it are cast by the update and refill snow.
    pub grid_first: u32,
    /// Ground codes copied into the winding buffer before the capture, for the surfaces on ground
    /// that is not flat that meshes press (the second half of their regions, `MODE_GROUND`; the
    /// codes are laid out as the capture regions, apron included):
    /// `(first code in the ground codes buffer, first word in the winding buffer, texels)`.
    pub ground_copies: Vec<(u32, u32, u32)>,
}

impl CapturePlan {
    /// Empty it, keeping its memory.
    pub fn clear(&mut self) {
        self.surfaces.clear();
        self.views.clear();
        self.prims.clear();
        self.draws.clear();
        self.draw_meshes.clear();
        self.atlas_side = 0;
        self.batches = 0;
        self.work.clear();
        self.texels = 0;
        self.tile_flags = 0;
        self.ground_copies.clear();
        self.listed.clear();
        self.grid_first = 0;
        self.clear_all = false;
        self.clears.clear();
    }

    /// Fill [`CapturePlan::clears`] once the surfaces and views are planned: the regions of the
    /// surfaces marked `cleared` (all of them with `clear_all`), those that follow one another
    /// merged.
    pub fn plan_clears(&mut self) {
        self.clears.clear();
        if self.clear_all {
            self.clears.push((0, self.texels.max(1)));
            return;
        }
        for (s, v) in self.surfaces.iter().zip(&self.views) {
            if !s.cleared {
                continue;
            }
            let texels = super::region_texels(s.width, s.height);
            match self.clears.last_mut() {
                Some((start, len)) if *start + *len == v.offset => *len += texels,
                _ => self.clears.push((v.offset, texels)),
            }
        }
    }

    /// Whether the plan uploads the tile list's header (with its own entries, or a grid that does
    /// not start at record 0); else the capture clears it.
    pub fn uploads_list_header(&self) -> bool {
        !self.listed.is_empty() || self.grid_first != 0
    }

    /// Texels of the winding buffer: it counts only mesh solids, so a frame of analytic deformers
    /// needs none.
    pub fn winding_texels(&self) -> u32 {
        if self.draws.is_empty() {
            0
        } else {
            self.texels
        }
    }
}

/// The buffers a capture binds (each at least as large as its plan needs) and the atlas whose
/// viewports it draws into.
#[derive(Clone, Copy, Debug)]
pub struct CaptureBuffers<'a> {
    /// [`CaptureView`]s, one uniform block (256 bytes) each, then (when the compute path has
    /// work) [`CapturePlan::work`] and its first word and length (`work_table`).
    pub views: &'a wgpu::Buffer,
    /// [`GpuPrimitive`]s.
    pub prims: &'a wgpu::Buffer,
    /// [`MeshDraw`]s, one uniform block (256 bytes) each.
    pub draws: &'a wgpu::Buffer,
    /// Encoded depth per texel (written).
    pub capture: &'a wgpu::Buffer,
    /// Mesh winding per texel (written).
    pub winding: &'a wgpu::Buffer,
    /// Tile flags (written).
    pub tiles: &'a wgpu::Buffer,
    /// Tile list with its indirect dispatch (written).
    pub tile_list: &'a wgpu::Buffer,
    /// `[base, bare]` per texel of the surfaces on ground that is not flat (read; any buffer when
    /// every view's `ground` is [`super::NO_GROUND`]).
    pub ground: &'a wgpu::Buffer,
    /// The capture code of the ground at each texel of those surfaces, parallel to `ground` (the
    /// source of [`CapturePlan::ground_copies`]).
    pub ground_codes: &'a wgpu::Buffer,
    /// The atlas's depth view (places the viewports only).
    pub atlas: &'a wgpu::TextureView,
}

/// Record a frame's capture: clear what it writes, then one render pass per atlas batch, each
/// surface in its viewport, primitives then meshes. `meshes` is indexed by [`MeshId`].
pub fn encode(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &CapturePipelines,
    plan: &CapturePlan,
    buffers: &CaptureBuffers<'_>,
    meshes: &[Option<CaptureMesh>],
    queries: &mut StageQueries<'_>,
) {
    // One uniform block of each table per draw, chosen by dynamic offset.
    let view_bg = bind_group(
        device,
        "capture view",
        &pipes.view_layout,
        &[
            uniform_block(buffers.views, 0, std::mem::size_of::<CaptureView>()),
            buffers.prims.as_entire_binding(),
            buffers.capture.as_entire_binding(),
            buffers.winding.as_entire_binding(),
            buffers.tiles.as_entire_binding(),
            buffers.tile_list.as_entire_binding(),
            buffers.ground.as_entire_binding(),
        ],
    );
    let draw_bg = bind_group(
        device,
        "capture mesh draw",
        &pipes.draw_layout,
        &[uniform_block(
            buffers.draws,
            0,
            std::mem::size_of::<MeshDraw>(),
        )],
    );
    // Nothing captured yet: 0 is the code of "no deformer over this texel".
    for &(first, texels) in &plan.clears {
        enc.clear_buffer(buffers.capture, first as u64 * 4, Some(texels as u64 * 4));
    }
    let winding = plan.winding_texels();
    if winding > 0 {
        enc.clear_buffer(buffers.winding, 0, Some(winding as u64 * 4));
    }
    for &(from, to, texels) in &plan.ground_copies {
        enc.copy_buffer_to_buffer(
            buffers.ground_codes,
            from as u64 * 4,
            buffers.winding,
            to as u64 * 4,
            texels as u64 * 4,
        );
    }
    enc.clear_buffer(buffers.tiles, 0, Some(plan.tile_flags.max(1) as u64 * 4));
    // A list that starts with the plan's entries was uploaded with its header.
    if !plan.uploads_list_header() {
        enc.clear_buffer(buffers.tile_list, 0, Some(TILE_LIST_HEADER * 4));
    }
    if !plan.work.is_empty() {
        encode_compute(device, enc, pipes, plan, buffers, queries);
    }
    for batch in 0..plan.batches {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("capture"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: buffers.atlas,
                // Only places the viewports: never cleared, read or written.
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: queries.render("capture"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        for (k, s) in plan.surfaces.iter().enumerate() {
            if s.compute || s.batch != batch {
                continue;
            }
            // The viewport is the surface's capture region: its texels and the apron.
            let (rw, rh) = super::region(s.width, s.height);
            pass.set_viewport(s.x as f32, s.y as f32, rw as f32, rh as f32, 0.0, 1.0);
            pass.set_scissor_rect(s.x, s.y, rw, rh);
            pass.set_bind_group(0, &view_bg, &[(k as u64 * UNIFORM_STRIDE) as u32]);
            if !s.prims.is_empty() {
                pass.set_pipeline(&pipes.primitives);
                pass.draw(0..6, s.prims.clone());
            }
            if !s.draws.is_empty() {
                pass.set_pipeline(&pipes.meshes);
                for d in s.draws.clone() {
                    let mesh = meshes[plan.draw_meshes[d as usize].0 as usize]
                        .as_ref()
                        .expect("meshes are checked before a frame is planned");
                    pass.set_bind_group(1, &draw_bg, &[(d as u64 * UNIFORM_STRIDE) as u32]);
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..mesh.index_count, 0, 0..1);
                }
            }
        }
    }
}

/// The words that follow the view blocks in the views buffer for the compute path: the work
/// list, then its first word and its length. Appends them to `bytes`, which holds the view blocks.
pub fn append_work_table(plan: &CapturePlan, bytes: &mut Vec<u8>) {
    let first = plan.views.len() as u64 * UNIFORM_STRIDE / 4;
    bytes.extend_from_slice(bytemuck::cast_slice(&plan.work));
    bytes.extend_from_slice(bytemuck::cast_slice(&[
        first as u32,
        plan.work.len() as u32,
    ]));
}

/// Bytes of the views buffer the compute path binds: the view blocks and
/// [`append_work_table`]'s words.
pub fn work_table_bytes(plan: &CapturePlan) -> u64 {
    plan.views.len() as u64 * UNIFORM_STRIDE + (plan.work.len() as u64 * 2 + 2) * 4
}

/// The compute path: a workgroup an entry of the work list.
fn encode_compute(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &CapturePipelines,
    plan: &CapturePlan,
    buffers: &CaptureBuffers<'_>,
    queries: &mut StageQueries<'_>,
) {
    let bytes = work_table_bytes(plan);
    let bg = bind_group(
        device,
        "capture compute",
        &pipes.compute_layout,
        &[
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: buffers.views,
                offset: 0,
                size: std::num::NonZeroU64::new(bytes),
            }),
            buffers.prims.as_entire_binding(),
            buffers.capture.as_entire_binding(),
            buffers.tiles.as_entire_binding(),
            buffers.tile_list.as_entire_binding(),
            buffers.ground.as_entire_binding(),
        ],
    );
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("capture compute"),
        timestamp_writes: queries.compute("capture"),
    });
    pass.set_pipeline(&pipes.compute);
    pass.set_bind_group(0, &bg, &[]);
    let n = plan.work.len() as u32;
    let (x, y) = crate::gpu::resources::dispatch_rows(n);
    pass.dispatch_workgroups(x, y, 1);
}
