//! The snow world: surfaces, deformers and the per-frame update.
//!
//! [`SnowWorld::step`] runs one frame: for every resident surface it culls the deformers against
//! the surface's capture volume, packs the surfaces that something touches into the capture atlas,
//! renders them from below (one render pass per atlas batch), and runs the accumulation chain with
//! one dispatch per stage over all updated surfaces. Surfaces that nothing touched and on which no
//! snow fell are left alone.

use std::time::Instant;

use glam::{Mat4, Vec2};

use crate::accumulate::{self, AccumulatePipelines, FUSED_WORKGROUP, WORKGROUP};
use crate::capture::{
    self, AtlasPlacement, CapturePipelines, CaptureView, CaptureVolume, GpuPrimitive, MeshDraw,
};
use crate::deformer::{Deformer, Shape};
use crate::error::{Result, SnowError};
use crate::gpu::resources::{Growable, UNIFORM_STRIDE, bind_group, uniform_block};
use crate::gpu::{Capabilities, GpuContext};
use crate::heightmap::Heightmap;
use crate::mesh::{Mesh, MeshId};
use crate::pool::{NO_CAPTURE, NO_NORMALS, PoolFormat, Slot, SlotAllocator, SurfaceRecord};
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

/// Which of the talk's two capture paths to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CaptureMode {
    /// The talk's PC path: the lowest point of any deformer per texel, a minimum-height field.
    #[default]
    Depth,
    /// The talk's console path: clear black, deformers white, a fixed imprint depth.
    Mask,
}

/// How surfaces are captured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaptureConfig {
    /// Depth or mask capture.
    pub mode: CaptureMode,
    /// Height of the frustum above the snow top, metres (default 0.25).
    pub ankle_height: f32,
    /// In mask mode, the fraction of the snow depth a covered texel is pressed down (default 1).
    pub mask_depth: f32,
}

impl Default for CaptureConfig {
    fn default() -> Self {
        Self {
            mode: CaptureMode::Depth,
            ankle_height: 0.25,
            mask_depth: 1.0,
        }
    }
}

/// Settings of a world.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldConfig {
    /// Capture settings.
    pub capture: CaptureConfig,
    /// Bytes of GPU memory for heightmaps (the pool). Clamped to the device's largest storage
    /// binding, with a warning.
    pub pool_bytes: u64,
    /// Largest side of the capture atlas, texels (clamped to the device's limit).
    pub atlas_side: u32,
    /// Largest heightmap side, texels: 512 as in the talk; benchmarks raise it.
    pub max_resolution: u32,
    /// How blur, merge and normals are dispatched.
    pub passes: PassMode,
    /// With [`PassMode::Fused`], the fewest tiles (16x16 texels) of captured surfaces that do not
    /// refill snow for which the update is dispatched over the capture's list of touched tiles
    /// rather than over every tile (where untouched ones leave at once). The list costs a fixed
    /// few microseconds (an extra dispatch and an indirect one), a skipped tile under a
    /// nanosecond: default 16384 (sixteen 512^2 surfaces), from the H100 figures in
    /// `docs/PERFORMANCE.md`. 0 always lists; `u32::MAX` never does.
    pub list_tiles_from: u32,
    /// How heightmaps are stored: bits a channel, and whether normals are kept.
    pub format: PoolFormat,
}

/// How the accumulation chain is dispatched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum PassMode {
    /// The default: fused, which is the faster on every adapter measured (an H100 and llvmpipe:
    /// `docs/PERFORMANCE.md`).
    #[default]
    Auto,
    /// Blur and merge in one pass: one dispatch instead of two and no scratch round trip, at the
    /// price of staging each tile's capture apron in workgroup memory, which suits GPUs, where a
    /// pass costs more than its memory traffic. (Normals, when kept, follow in their own pass.)
    Fused,
    /// Separate passes; [`SnowWorld::read_last_blurred`] can then show stage 1's output.
    Separate,
}

impl Default for WorldConfig {
    fn default() -> Self {
        Self {
            capture: CaptureConfig::default(),
            pool_bytes: 32 << 20,
            atlas_side: 2048,
            max_resolution: crate::surface::MAX_RESOLUTION,
            passes: PassMode::Auto,
            list_tiles_from: 16384,
            format: PoolFormat::default(),
        }
    }
}

/// GPU time of each stage of one frame, milliseconds (from timestamp queries).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct StageTimes {
    /// All capture render passes.
    pub capture_ms: f64,
    /// All blur dispatches.
    pub blur_ms: f64,
    /// The merge dispatch.
    pub merge_ms: f64,
    /// The normals dispatch.
    pub normals_ms: f64,
    /// The fused blur + merge dispatch (when [`PassMode::Fused`]).
    pub fused_ms: f64,
}

impl StageTimes {
    /// Sum of the stages.
    pub fn total_ms(&self) -> f64 {
        self.capture_ms + self.blur_ms + self.merge_ms + self.normals_ms + self.fused_ms
    }
}

/// What one [`SnowWorld::step`] did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FrameStats {
    /// Surfaces whose heightmap was updated.
    pub updated: u32,
    /// Of those, surfaces something was captured on.
    pub captured: u32,
    /// Capture atlas passes.
    pub capture_batches: u32,
    /// Analytic primitives drawn (after sweeping and culling).
    pub primitives: u32,
    /// Mesh draws.
    pub mesh_draws: u32,
    /// CPU time spent building and encoding the frame, milliseconds.
    pub cpu_encode_ms: f64,
    /// Per-stage GPU times, when profiling is on and the adapter has timestamp queries.
    pub gpu: Option<StageTimes>,
}

/// Bytes of GPU memory the world holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct MemoryReport {
    /// The pool's budget.
    pub pool_budget: u64,
    /// Pool bytes in slots now.
    pub pool_used: u64,
    /// Most pool bytes ever in slots.
    pub pool_high_water: u64,
    /// Scratch buffer (blurred captures of one frame, shared by every surface updated in it).
    pub scratch: u64,
    /// Capture atlas textures.
    pub capture_atlas: u64,
    /// Per-frame tables (records, views, primitives, mesh draws, capture and winding buffers).
    pub frame_tables: u64,
    /// How the pool stores heightmaps.
    pub format: PoolFormat,
}

/// One surface's share of a [`SnowWorld::update`].
#[derive(Clone, Copy, Debug)]
pub struct SurfaceUpdate<'a> {
    /// The surface.
    pub surface: SurfaceId,
    /// Seconds since the surface was last updated (for replenishment).
    pub elapsed: f32,
    /// Everything that touched it since then, with motion (`previous`) where known.
    pub deformers: &'a [Deformer],
}

/// A surface's stored state on the CPU (see [`SnowWorld::snapshot_surfaces`]): what the manager
/// pages out and what saves hold.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSnapshot {
    /// The surface.
    pub desc: SurfaceDesc,
    /// Heightmap texels along local x.
    pub width: u32,
    /// Heightmap texels along local z.
    pub height: u32,
    /// How `words` are laid out (see [`crate::pool`]).
    pub format: PoolFormat,
    /// Replenishment not yet applied, units at the format's precision (a fraction in `[0, 1)`).
    pub carry: f64,
    /// The slot's words as stored: the heights region, then the normals when the format keeps
    /// them.
    pub words: Vec<u32>,
}

impl SurfaceSnapshot {
    /// The heightmap in 16-bit units (as [`SnowWorld::read_heightmap`] gives it).
    pub fn heightmap(&self) -> Result<Heightmap> {
        let heights = self.format.heights_bytes(self.width, self.height) as usize / 4;
        let words = self
            .words
            .get(..heights)
            .ok_or_else(|| SnowError::Snapshot {
                name: self.desc.name.clone(),
                reason: format!(
                    "it holds {} words, its heights need {heights}",
                    self.words.len()
                ),
            })?;
        let (depression, displaced) = self.format.decode(self.width, self.height, words)?;
        Ok(Heightmap::from_channels(
            self.width,
            self.height,
            self.format.precision,
            &depression,
            &displaced,
        ))
    }
}

struct SurfaceState {
    desc: SurfaceDesc,
    layout: SurfaceLayout,
    slot: Slot,
    /// Replenishment not yet applied, units (fraction kept between frames).
    carry: f64,
}

impl SurfaceState {
    fn texel(&self) -> Vec2 {
        self.desc.size / Vec2::new(self.layout.width as f32, self.layout.height as f32)
    }
}

struct MeshGpu {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    vertex_count: usize,
    radius: f32,
}

/// One surface's work in a frame.
struct Job {
    surface: usize,
    record: SurfaceRecord,
    captured: bool,
    prims: std::ops::Range<u32>,
    draws: std::ops::Range<u32>,
}

/// What the last frame did, for debug readbacks.
#[derive(Default)]
struct LastFrame {
    /// (surface index, record, placement) of every captured job.
    captured: Vec<(usize, SurfaceRecord, AtlasPlacement)>,
}

struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f32,
    capacity: u32,
}

/// Which stage a pair of timestamps measured.
#[derive(Clone, Copy)]
enum Stage {
    Capture,
    Blur,
    Merge,
    Normals,
    Fused,
}

/// The snow world: every surface's heightmap in one GPU pool, updated by [`SnowWorld::step`].
pub struct SnowWorld {
    device: wgpu::Device,
    queue: wgpu::Queue,
    caps: Capabilities,
    config: WorldConfig,
    capture_pipes: CapturePipelines,
    acc: AccumulatePipelines,
    pool: wgpu::Buffer,
    alloc: SlotAllocator,
    surfaces: Vec<Option<SurfaceState>>,
    /// Generation of each slot of `surfaces`: bumped when its surface is removed, so that old
    /// handles to the slot are refused (see [`SurfaceId`]).
    generations: Vec<u32>,
    meshes: Vec<Option<MeshGpu>>,
    atlases: Vec<(u32, wgpu::Texture, wgpu::TextureView)>,
    records: Growable,
    views: Growable,
    prims: Growable,
    draws: Growable,
    capture: Growable,
    winding: Growable,
    /// One flag per 16x16 tile of each captured surface: set by the capture where it wrote.
    tiles: Growable,
    /// The flagged tiles as a list with its indirect dispatch (see `accumulate::TILE_LIST_HEADER`).
    tile_list: Growable,
    scratch: Growable,
    last: LastFrame,
    profiling: bool,
    timestamps: Option<Timestamps>,
}

impl std::fmt::Debug for SnowWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SnowWorld")
            .field("surfaces", &self.surfaces.iter().flatten().count())
            .field("pool_used", &self.alloc.used())
            .finish()
    }
}

impl SnowWorld {
    /// Create a world on a GPU context.
    pub fn new(gpu: &GpuContext, config: WorldConfig) -> Result<Self> {
        let device = gpu.device.clone();
        let mut config = config;
        let c = config.capture;
        if !(c.ankle_height.is_finite() && c.ankle_height > 0.0) {
            return Err(SnowError::Scene(format!(
                "capture ankle_height {} must be a finite number of metres above 0",
                c.ankle_height
            )));
        }
        if !(c.mask_depth.is_finite() && c.mask_depth > 0.0 && c.mask_depth <= 1.0) {
            return Err(SnowError::Scene(format!(
                "capture mask_depth {} must be a fraction in (0, 1]",
                c.mask_depth
            )));
        }
        let max_pool = gpu
            .caps
            .max_storage_binding
            .min(device.limits().max_buffer_size)
            / 256
            * 256;
        if config.pool_bytes > max_pool {
            tracing::warn!(
                "heightmap pool of {} bytes exceeds this device's largest storage binding; using {} bytes",
                config.pool_bytes,
                max_pool
            );
            config.pool_bytes = max_pool;
        }
        config.atlas_side = config.atlas_side.clamp(64, gpu.caps.max_texture_side);
        if config.passes == PassMode::Auto {
            config.passes = PassMode::Fused;
        }
        config.max_resolution = config.max_resolution.clamp(1, config.atlas_side);
        let alloc = SlotAllocator::new(config.pool_bytes);
        let pool = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("heightmap pool"),
            size: alloc.budget().max(256),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        use wgpu::BufferUsages as U;
        let timestamps = gpu.caps.timestamps.then(|| {
            let capacity = 256;
            Timestamps {
                set: device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("snowprint timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: capacity,
                }),
                resolve: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: capacity as u64 * 8,
                    usage: U::QUERY_RESOLVE | U::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp readback"),
                    size: capacity as u64 * 8,
                    usage: U::MAP_READ | U::COPY_DST,
                    mapped_at_creation: false,
                }),
                period_ns: gpu.queue.get_timestamp_period(),
                capacity,
            }
        });
        Ok(Self {
            capture_pipes: CapturePipelines::new(&device),
            acc: AccumulatePipelines::new(&device, config.format.precision),
            records: Growable::new(
                &device,
                "surface records",
                U::STORAGE | U::COPY_DST,
                64 * 64,
            ),
            views: Growable::new(
                &device,
                "capture views",
                U::UNIFORM | U::COPY_DST,
                UNIFORM_STRIDE * 16,
            ),
            prims: Growable::new(
                &device,
                "capture primitives",
                U::STORAGE | U::COPY_DST,
                80 * 64,
            ),
            draws: Growable::new(
                &device,
                "capture mesh draws",
                U::UNIFORM | U::COPY_DST,
                UNIFORM_STRIDE * 16,
            ),
            capture: Growable::new(
                &device,
                "capture",
                U::STORAGE | U::COPY_DST | U::COPY_SRC,
                4 * 4096,
            ),
            winding: Growable::new(
                &device,
                "capture winding",
                U::STORAGE | U::COPY_DST | U::COPY_SRC,
                4 * 4096,
            ),
            tiles: Growable::new(&device, "capture tiles", U::STORAGE | U::COPY_DST, 4 * 256),
            tile_list: Growable::new(
                &device,
                "capture tile list",
                U::STORAGE | U::INDIRECT | U::COPY_DST,
                4 * 512,
            ),
            scratch: Growable::new(&device, "scratch", U::STORAGE | U::COPY_SRC, 4 * 4096),
            queue: gpu.queue.clone(),
            caps: gpu.caps.clone(),
            device,
            config,
            pool,
            alloc,
            surfaces: Vec::new(),
            generations: Vec::new(),
            meshes: Vec::new(),
            atlases: Vec::new(),
            last: LastFrame::default(),
            profiling: false,
            timestamps,
        })
    }

    /// The world's settings (after clamping to the device).
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// Measure each stage with GPU timestamp queries (when the adapter has them). Each
    /// [`SnowWorld::step`] then waits for the GPU and reports [`FrameStats::gpu`].
    pub fn set_profiling(&mut self, on: bool) {
        self.profiling = on;
    }

    /// Whether per-stage GPU times can be measured on this device.
    pub fn has_timestamps(&self) -> bool {
        self.timestamps.is_some()
    }

    /// Add a surface; its heightmap starts untouched. Fails with [`SnowError::PoolExhausted`] when
    /// the pool has no room (a normal state: remove a surface or give the pool more bytes).
    pub fn add_surface(&mut self, desc: SurfaceDesc) -> Result<SurfaceId> {
        desc.validate()?;
        let layout = SurfaceLayout::for_size_capped(desc.size, self.config.max_resolution);
        let slot = self.reserve_slot(&desc.name, &layout, None)?;
        Ok(self.insert_state(SurfaceState {
            desc,
            layout,
            slot,
            carry: 0.0,
        }))
    }

    /// A cleared slot for a surface of `layout`: first fit, or at `at` in the pool.
    fn reserve_slot(
        &mut self,
        name: &str,
        layout: &SurfaceLayout,
        at: Option<u64>,
    ) -> Result<Slot> {
        let needed = self.config.format.slot_bytes(layout.width, layout.height);
        let slot = match at {
            Some(offset) => self.alloc.alloc_at(offset, needed),
            None => self.alloc.alloc(needed),
        }
        .ok_or_else(|| SnowError::PoolExhausted {
            name: name.to_owned(),
            needed,
            free: self.alloc.largest_free(),
            budget: self.alloc.budget(),
        })?;
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.pool, slot.offset, Some(slot.bytes));
        self.queue.submit([enc.finish()]);
        Ok(slot)
    }

    fn insert_state(&mut self, state: SurfaceState) -> SurfaceId {
        // A free slot whose generation is spent (u32::MAX removals) is retired, never reused.
        let free = (0..self.surfaces.len())
            .find(|&i| self.surfaces[i].is_none() && self.generations[i] != u32::MAX);
        let index = match free {
            Some(i) => {
                self.surfaces[i] = Some(state);
                i
            }
            None => {
                self.surfaces.push(Some(state));
                self.generations.push(0);
                self.surfaces.len() - 1
            }
        };
        SurfaceId(index as u32, self.generations[index])
    }

    /// Remove a surface and give its pool bytes back.
    pub fn remove_surface(&mut self, id: SurfaceId) -> Result<()> {
        self.state(id)?;
        let index = id.0 as usize;
        let state = self.surfaces[index].take().expect("checked live above");
        self.generations[index] = self.generations[index].saturating_add(1);
        self.alloc.free(state.slot);
        Ok(())
    }

    /// Copy the stored state of surfaces to the CPU in one GPU round trip: their slots' words
    /// (heights, and normals when the pool keeps them) and the replenishment carried between
    /// updates. What paging and saves keep of a surface; [`SnowWorld::restore_surface`] puts it
    /// back bit for bit.
    pub fn snapshot_surfaces(&self, ids: &[SurfaceId]) -> Result<Vec<SurfaceSnapshot>> {
        let mut spans = Vec::with_capacity(ids.len());
        let mut total = 0u64;
        for &id in ids {
            let s = self.state(id)?;
            let bytes = self.payload_bytes(&s.layout);
            spans.push((s, total, bytes));
            total += bytes;
        }
        if total == 0 {
            return Ok(Vec::new());
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("surface snapshots"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        for &(s, at, bytes) in &spans {
            enc.copy_buffer_to_buffer(&self.pool, s.slot.offset, &staging, at, bytes);
        }
        self.queue.submit([enc.finish()]);
        let data = self.read_buffer(&staging, 0, total)?;
        Ok(spans
            .into_iter()
            .map(|(s, at, bytes)| SurfaceSnapshot {
                desc: s.desc.clone(),
                width: s.layout.width,
                height: s.layout.height,
                format: self.config.format,
                carry: s.carry,
                words: bytemuck::cast_slice(&data[at as usize..(at + bytes) as usize]).to_vec(),
            })
            .collect())
    }

    /// Bytes of a slot that hold data (heights, then normals when kept): what a snapshot copies.
    fn payload_bytes(&self, layout: &SurfaceLayout) -> u64 {
        let f = &self.config.format;
        f.heights_bytes(layout.width, layout.height)
            + if f.normals { layout.texels() * 4 } else { 0 }
    }

    /// Whether a snapshot fits this world (its description valid, taken at this world's format,
    /// with its description's layout, word count and a carry in `[0, 1)`); returns the layout.
    pub fn check_snapshot(&self, snapshot: &SurfaceSnapshot) -> Result<SurfaceLayout> {
        let desc = &snapshot.desc;
        desc.validate()?;
        let layout = SurfaceLayout::for_size_capped(desc.size, self.config.max_resolution);
        let bad = |reason: String| {
            Err(SnowError::Snapshot {
                name: desc.name.clone(),
                reason,
            })
        };
        if snapshot.format != self.config.format {
            return bad(format!(
                "it was taken at {} bits a channel{}, this world stores {} bits{}",
                snapshot.format.precision.bits(),
                if snapshot.format.normals {
                    " with normals"
                } else {
                    ""
                },
                self.config.format.precision.bits(),
                if self.config.format.normals {
                    " with normals"
                } else {
                    ""
                },
            ));
        }
        if (snapshot.width, snapshot.height) != (layout.width, layout.height) {
            return bad(format!(
                "it holds {}x{} texels, the surface's size gives {}x{}",
                snapshot.width, snapshot.height, layout.width, layout.height
            ));
        }
        let payload = self.payload_bytes(&layout);
        if snapshot.words.len() as u64 * 4 != payload {
            return bad(format!(
                "it holds {} words, a {}x{} surface needs {}",
                snapshot.words.len(),
                layout.width,
                layout.height,
                payload / 4
            ));
        }
        if !(snapshot.carry.is_finite() && (0.0..1.0).contains(&snapshot.carry)) {
            return bad(format!(
                "its replenishment carry {} is not a fraction in [0, 1)",
                snapshot.carry
            ));
        }
        Ok(layout)
    }

    /// Add a surface with the state of a snapshot (its heights, normals and replenishment carry),
    /// at `at` in the pool when given (saves restore the pool's exact placement; `None`: first
    /// fit). Fails with [`SnowError::PoolExhausted`] when there is no room, and with
    /// [`SnowError::Snapshot`] when the snapshot does not fit this world's format or its
    /// description's layout; nothing changes then.
    pub fn restore_surface(
        &mut self,
        snapshot: &SurfaceSnapshot,
        at: Option<u64>,
    ) -> Result<SurfaceId> {
        let layout = self.check_snapshot(snapshot)?;
        let desc = &snapshot.desc;
        let slot = self.reserve_slot(&desc.name, &layout, at)?;
        self.queue.write_buffer(
            &self.pool,
            slot.offset,
            bytemuck::cast_slice(&snapshot.words),
        );
        Ok(self.insert_state(SurfaceState {
            desc: desc.clone(),
            layout,
            slot,
            carry: snapshot.carry,
        }))
    }

    /// The description of a surface.
    pub fn surface(&self, id: SurfaceId) -> Result<&SurfaceDesc> {
        Ok(&self.state(id)?.desc)
    }

    /// Heightmap resolution of a surface.
    pub fn layout(&self, id: SurfaceId) -> Result<SurfaceLayout> {
        Ok(self.state(id)?.layout)
    }

    /// Every live surface.
    pub fn surfaces(&self) -> impl Iterator<Item = (SurfaceId, &SurfaceDesc)> {
        self.surfaces.iter().enumerate().filter_map(|(i, s)| {
            s.as_ref()
                .map(|s| (SurfaceId(i as u32, self.generations[i]), &s.desc))
        })
    }

    fn state(&self, id: SurfaceId) -> Result<&SurfaceState> {
        let index = id.0 as usize;
        self.surfaces
            .get(index)
            .and_then(Option::as_ref)
            .filter(|_| self.generations[index] == id.1)
            .ok_or(SnowError::StaleHandle {
                what: "surface",
                index: id.0,
            })
    }

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
        self.meshes.push(Some(MeshGpu {
            vertices,
            indices,
            index_count: mesh.indices.len() as u32,
            vertex_count: mesh.positions.len(),
            radius: mesh.bounding_radius(),
        }));
        Ok(MeshId(self.meshes.len() as u32 - 1))
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
            })
    }

    /// Bytes of GPU memory held.
    pub fn memory(&self) -> MemoryReport {
        MemoryReport {
            pool_budget: self.alloc.budget(),
            pool_used: self.alloc.used(),
            pool_high_water: self.alloc.high_water(),
            scratch: self.scratch.buffer.size(),
            capture_atlas: self
                .atlases
                .iter()
                .map(|a| a.0 as u64 * a.0 as u64 * 2)
                .sum(),
            frame_tables: self.records.buffer.size()
                + self.views.buffer.size()
                + self.prims.buffer.size()
                + self.draws.buffer.size()
                + self.capture.buffer.size()
                + self.winding.buffer.size()
                + self.tiles.buffer.size()
                + self.tile_list.buffer.size(),
            format: self.config.format,
        }
    }

    fn atlas(&mut self, side: u32) -> usize {
        if let Some(i) = self.atlases.iter().position(|a| a.0 == side) {
            return i;
        }
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("capture atlas"),
            size: wgpu::Extent3d {
                width: side,
                height: side,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: capture::ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        self.atlases.push((side, texture, view));
        self.atlases.len() - 1
    }

    /// Advance every surface by `dt` seconds with the deformers as posed at the end of the frame.
    pub fn step(&mut self, dt: f32, deformers: &[Deformer]) -> Result<FrameStats> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(SnowError::InvalidTimeStep { dt });
        }
        for (i, d) in deformers.iter().enumerate() {
            d.validate(&format!("#{i}"))?;
        }
        let updates: Vec<SurfaceUpdate<'_>> = self
            .surfaces()
            .map(|(surface, _)| SurfaceUpdate {
                surface,
                elapsed: dt,
                deformers,
            })
            .collect();
        self.update(&updates)
    }

    /// Update chosen surfaces, each with its own deformers and the time since its last update
    /// (snow replenishes by that much). Surfaces not listed keep their heightmap untouched. This is
    /// what a manager with a per-frame budget calls; [`SnowWorld::step`] updates every surface.
    /// Everything is checked before anything changes.
    pub fn update(&mut self, updates: &[SurfaceUpdate<'_>]) -> Result<FrameStats> {
        let start = Instant::now();
        let mut seen = vec![false; self.surfaces.len()];
        for u in updates {
            let dt = u.elapsed;
            if !(dt.is_finite() && dt >= 0.0) {
                return Err(SnowError::InvalidTimeStep { dt });
            }
            self.state(u.surface)?;
            let flag = &mut seen[u.surface.0 as usize];
            if *flag {
                return Err(SnowError::DuplicateUpdate { index: u.surface.0 });
            }
            *flag = true;
            for (i, d) in u.deformers.iter().enumerate() {
                d.validate(&format!("#{i}"))?;
                if let Shape::Mesh(id) = d.shape
                    && self
                        .meshes
                        .get(id.0 as usize)
                        .and_then(Option::as_ref)
                        .is_none()
                {
                    return Err(SnowError::StaleHandle {
                        what: "mesh",
                        index: id.0,
                    });
                }
            }
        }
        let capture_cfg = self.config.capture;
        let mut jobs: Vec<Job> = Vec::new();
        let mut prims: Vec<GpuPrimitive> = Vec::new();
        let mut draws: Vec<(MeshDraw, MeshId)> = Vec::new();
        for u in updates {
            let index = u.surface.0 as usize;
            let (dt, deformers) = (u.elapsed, u.deformers);
            let Some(state) = self.surfaces[index].as_mut() else {
                continue;
            };
            state.carry += state.desc.replenish_rate as f64
                * dt as f64
                * self.config.format.precision.channel_max() as f64;
            let units = state.carry.floor().min(u32::MAX as f64);
            state.carry -= units;
            let units = units as u32;
            let frustum_height = state.desc.snow_depth + capture_cfg.ankle_height;
            let volume = CaptureVolume {
                world_to_local: state.desc.world_to_local(),
                half_size: state.desc.size * 0.5,
                frustum_height,
            };
            let p0 = prims.len() as u32;
            let d0 = draws.len() as u32;
            for d in deformers {
                match d.shape {
                    Shape::Mesh(id) => {
                        let Some(Some(mesh)) = self.meshes.get(id.0 as usize) else {
                            continue;
                        };
                        // A moving mesh is drawn at sub-steps along its motion, so that a fast
                        // hand or foot leaves a continuous sweep rather than a comb of copies.
                        let prev = d.previous.unwrap_or(d.pose);
                        let n = capture::mesh_substeps(&prev, &d.pose, mesh.radius);
                        for k in 1..=n {
                            let p = prev.lerp(&d.pose, k as f32 / n as f32);
                            if volume.overlaps_ball(p.position, mesh.radius) {
                                let model = Mat4::from_rotation_translation(p.rotation, p.position);
                                draws.push((
                                    MeshDraw {
                                        to_local: (volume.world_to_local * model)
                                            .to_cols_array_2d(),
                                    },
                                    id,
                                ));
                            }
                        }
                    }
                    _ => capture::push_primitives(d, &volume, &mut prims),
                }
            }
            let captured = prims.len() as u32 > p0 || draws.len() as u32 > d0;
            if !captured && units == 0 {
                continue;
            }
            let texel = state.texel();
            jobs.push(Job {
                surface: index,
                record: SurfaceRecord {
                    heights: state.slot.heights_word(),
                    normals: state
                        .slot
                        .normals_word(&self.config.format, state.layout.width, state.layout.height)
                        .unwrap_or(NO_NORMALS),
                    scratch: 0,
                    width: state.layout.width,
                    height: state.layout.height,
                    atlas_x: 0,
                    atlas_y: 0,
                    mode: match capture_cfg.mode {
                        CaptureMode::Depth => 0,
                        CaptureMode::Mask => 1,
                    } | if draws.len() as u32 > d0 {
                        crate::pool::MODE_MESHES
                    } else {
                        0
                    },
                    replenish_units: units,
                    batch: NO_CAPTURE,
                    mask_fraction: capture_cfg.mask_depth,
                    snow_depth: state.desc.snow_depth,
                    frustum_height,
                    texel_x: texel.x,
                    texel_z: texel.y,
                    tiles: 0,
                },
                captured,
                prims: p0..prims.len() as u32,
                draws: d0..draws.len() as u32,
            });
        }
        // Surfaces that refill snow first: the fused grid covers records 0..dense; the others are
        // updated only where the capture listed a tile.
        jobs.sort_by_key(|j| j.record.replenish_units == 0);
        let dense = jobs
            .iter()
            .take_while(|j| j.record.replenish_units > 0)
            .count() as u32;
        let still_tiles: u64 = jobs[dense as usize..]
            .iter()
            .filter(|j| j.captured)
            .map(|j| j.record.tile_count() as u64)
            .sum();
        let listed = self.config.passes == PassMode::Fused
            && still_tiles > 0
            && still_tiles >= self.config.list_tiles_from as u64;
        // Without the list, the grid covers every record.
        let grid = if listed { dense } else { jobs.len() as u32 };
        let mut stats = FrameStats {
            updated: jobs.len() as u32,
            primitives: prims.len() as u32,
            mesh_draws: draws.len() as u32,
            ..Default::default()
        };
        if jobs.is_empty() {
            // Nothing captured: the debug readbacks of the last step must not show an older one.
            self.last = LastFrame::default();
            stats.cpu_encode_ms = start.elapsed().as_secs_f64() * 1e3;
            return Ok(stats);
        }

        // Place captured surfaces in the atlas and the scratch buffer.
        let captured: Vec<usize> = (0..jobs.len()).filter(|&j| jobs[j].captured).collect();
        let rects: Vec<(u32, u32)> = captured
            .iter()
            .map(|&j| (jobs[j].record.width, jobs[j].record.height))
            .collect();
        // The atlas is cleared whole every pass, so keep it as small as the frame allows: the
        // smallest power-of-two side that holds every rectangle in one batch, up to the limit.
        let (placements, atlas_side) = capture::pack_atlas_compact(&rects, self.config.atlas_side);
        let batches = placements.iter().map(|p| p.batch + 1).max().unwrap_or(0);
        let mut scratch_len = 0u32;
        let mut tiles_len = 0u32;
        for (k, &j) in captured.iter().enumerate() {
            let r = &mut jobs[j].record;
            r.atlas_x = placements[k].x;
            r.atlas_y = placements[k].y;
            r.batch = placements[k].batch;
            r.scratch = scratch_len;
            scratch_len += r.width * r.height;
            r.tiles = tiles_len;
            tiles_len += r.tile_count();
        }
        stats.captured = captured.len() as u32;
        stats.capture_batches = batches;

        // Upload the frame's tables.
        let records: Vec<SurfaceRecord> = jobs.iter().map(|j| j.record).collect();
        self.records
            .ensure(&self.device, (records.len() * 64) as u64);
        self.queue
            .write_buffer(&self.records.buffer, 0, bytemuck::cast_slice(&records));
        let mut view_bytes = vec![0u8; captured.len().max(1) * UNIFORM_STRIDE as usize];
        for (k, &j) in captured.iter().enumerate() {
            let r = &jobs[j].record;
            let state = self.surfaces[jobs[j].surface]
                .as_ref()
                .expect("job of a live surface");
            let v = CaptureView {
                half_size: (state.desc.size * 0.5).to_array(),
                frustum_height: r.frustum_height,
                offset: r.scratch,
                origin: [r.atlas_x as f32, r.atlas_y as f32],
                texels: [r.width as f32, r.height as f32],
                tiles: r.tiles,
                tiles_x: r.width.div_ceil(FUSED_WORKGROUP),
                record: if listed { j as u32 } else { capture::NO_LIST },
                pad: 0,
            };
            let o = k * UNIFORM_STRIDE as usize;
            let size = std::mem::size_of::<CaptureView>();
            view_bytes[o..o + size].copy_from_slice(bytemuck::bytes_of(&v));
        }
        self.views.ensure(&self.device, view_bytes.len() as u64);
        self.queue.write_buffer(&self.views.buffer, 0, &view_bytes);
        if !prims.is_empty() {
            self.prims.ensure(&self.device, (prims.len() * 80) as u64);
            self.queue
                .write_buffer(&self.prims.buffer, 0, bytemuck::cast_slice(&prims));
        }
        if !draws.is_empty() {
            let mut bytes = vec![0u8; draws.len() * UNIFORM_STRIDE as usize];
            for (k, (d, _)) in draws.iter().enumerate() {
                let o = k * UNIFORM_STRIDE as usize;
                bytes[o..o + 64].copy_from_slice(bytemuck::bytes_of(d));
            }
            self.draws.ensure(&self.device, bytes.len() as u64);
            self.queue.write_buffer(&self.draws.buffer, 0, &bytes);
        }
        // The blurred capture goes through memory only when blur and merge are separate passes.
        if self.config.passes == PassMode::Separate {
            self.scratch
                .ensure(&self.device, (scratch_len.max(1) as u64) * 4);
        }
        self.capture
            .ensure(&self.device, (scratch_len.max(1) as u64) * 4);
        // Winding counts only mesh solids: a frame of analytic deformers needs none.
        let winding_len = if draws.is_empty() { 0 } else { scratch_len };
        if winding_len > 0 {
            self.winding.ensure(&self.device, winding_len as u64 * 4);
        }
        self.tiles
            .ensure(&self.device, (tiles_len.max(1) as u64) * 4);
        self.tile_list.ensure(
            &self.device,
            (accumulate::TILE_LIST_HEADER + 2 * tiles_len as u64) * 4,
        );

        let atlas_index = self.atlas(atlas_side);
        let atlas_view = &self.atlases[atlas_index].2;
        let max_w = jobs.iter().map(|j| j.record.width).max().unwrap_or(1);
        let max_h = jobs.iter().map(|j| j.record.height).max().unwrap_or(1);

        // One uniform block of each table per draw, chosen by dynamic offset.
        let view_bg = bind_group(
            &self.device,
            "capture view",
            &self.capture_pipes.view_layout,
            &[
                uniform_block(&self.views.buffer, 0, std::mem::size_of::<CaptureView>()),
                self.prims.buffer.as_entire_binding(),
                self.capture.buffer.as_entire_binding(),
                self.winding.buffer.as_entire_binding(),
                self.tiles.buffer.as_entire_binding(),
                self.tile_list.buffer.as_entire_binding(),
            ],
        );
        let draw_bg = bind_group(
            &self.device,
            "capture mesh draw",
            &self.capture_pipes.draw_layout,
            &[uniform_block(
                &self.draws.buffer,
                0,
                std::mem::size_of::<MeshDraw>(),
            )],
        );
        // Each pass binds whole buffers in binding order; the layouts name what it reads and writes.
        let (records, capture, winding, scratch, pool) = (
            &self.records.buffer,
            &self.capture.buffer,
            &self.winding.buffer,
            &self.scratch.buffer,
            &self.pool,
        );
        let blur_bg = bind_group(
            &self.device,
            "blur",
            &self.acc.blur_layout,
            &[
                records.as_entire_binding(),
                capture.as_entire_binding(),
                winding.as_entire_binding(),
                scratch.as_entire_binding(),
            ],
        );
        let merge_bg = bind_group(
            &self.device,
            "merge",
            &self.acc.merge_layout,
            &[
                records.as_entire_binding(),
                scratch.as_entire_binding(),
                pool.as_entire_binding(),
            ],
        );
        let normals_bg = bind_group(
            &self.device,
            "normals",
            &self.acc.normals_layout,
            &[records.as_entire_binding(), pool.as_entire_binding()],
        );
        let fused_bg = bind_group(
            &self.device,
            "fused",
            &self.acc.fused_layout,
            &[
                records.as_entire_binding(),
                capture.as_entire_binding(),
                pool.as_entire_binding(),
                winding.as_entire_binding(),
                self.tiles.buffer.as_entire_binding(),
                self.tile_list.buffer.as_entire_binding(),
            ],
        );
        let seal_bg = bind_group(
            &self.device,
            "seal",
            &self.acc.seal_layout,
            &[self.tile_list.buffer.as_entire_binding()],
        );
        let ts = if self.profiling {
            self.timestamps.as_ref()
        } else {
            None
        };
        let mut stages: Vec<Stage> = Vec::new();
        let next_query = |stage: Stage, stages: &mut Vec<Stage>| -> Option<u32> {
            let ts = ts?;
            let q = stages.len() as u32 * 2;
            if q + 2 > ts.capacity {
                return None;
            }
            stages.push(stage);
            Some(q)
        };

        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("snow update"),
            });
        // Nothing captured yet: 0 is the code of "no deformer over this texel".
        enc.clear_buffer(&self.capture.buffer, 0, Some(scratch_len.max(1) as u64 * 4));
        if winding_len > 0 {
            enc.clear_buffer(&self.winding.buffer, 0, Some(winding_len as u64 * 4));
        }
        enc.clear_buffer(&self.tiles.buffer, 0, Some(tiles_len.max(1) as u64 * 4));
        enc.clear_buffer(
            &self.tile_list.buffer,
            0,
            Some(accumulate::TILE_LIST_HEADER * 4),
        );
        for batch in 0..batches {
            let q = next_query(Stage::Capture, &mut stages);
            {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("capture"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: atlas_view,
                        // Only places the viewports: never cleared, read or written.
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: q.map(|q| wgpu::RenderPassTimestampWrites {
                        query_set: &ts.expect("query implies timestamps").set,
                        beginning_of_pass_write_index: Some(q),
                        end_of_pass_write_index: Some(q + 1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                for (k, &j) in captured.iter().enumerate() {
                    let job = &jobs[j];
                    let r = &job.record;
                    if r.batch != batch {
                        continue;
                    }
                    pass.set_viewport(
                        r.atlas_x as f32,
                        r.atlas_y as f32,
                        r.width as f32,
                        r.height as f32,
                        0.0,
                        1.0,
                    );
                    pass.set_scissor_rect(r.atlas_x, r.atlas_y, r.width, r.height);
                    pass.set_bind_group(0, &view_bg, &[(k as u64 * UNIFORM_STRIDE) as u32]);
                    if !job.prims.is_empty() {
                        pass.set_pipeline(&self.capture_pipes.primitives);
                        pass.draw(0..6, job.prims.clone());
                    }
                    if !job.draws.is_empty() {
                        pass.set_pipeline(&self.capture_pipes.meshes);
                        for d in job.draws.clone() {
                            let mesh = self.meshes[draws[d as usize].1.0 as usize]
                                .as_ref()
                                .expect("mesh checked at the start of the step");
                            pass.set_bind_group(1, &draw_bg, &[(d as u64 * UNIFORM_STRIDE) as u32]);
                            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                            pass.set_index_buffer(
                                mesh.indices.slice(..),
                                wgpu::IndexFormat::Uint32,
                            );
                            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
                        }
                    }
                }
            }
        }
        let mut passes = if self.config.passes == PassMode::Fused {
            vec![(Stage::Fused, &self.acc.fused, &fused_bg)]
        } else {
            vec![
                (Stage::Blur, &self.acc.blur, &blur_bg),
                (Stage::Merge, &self.acc.merge, &merge_bg),
            ]
        };
        if self.config.format.normals {
            passes.push((Stage::Normals, &self.acc.normals, &normals_bg));
        }
        // The merge writes a unit (two texels at 8 bits) per invocation.
        let unit = self.config.format.precision.unit_texels();
        for &(stage, pipeline, bg) in &passes {
            let q = next_query(stage, &mut stages);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(match stage {
                    Stage::Blur => "blur",
                    Stage::Merge => "merge",
                    Stage::Normals => "normals",
                    _ => "fused",
                }),
                timestamp_writes: q.map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: &ts.expect("query implies timestamps").set,
                    beginning_of_pass_write_index: Some(q),
                    end_of_pass_write_index: Some(q + 1),
                }),
            });
            pass.set_bind_group(0, bg, &[]);
            if matches!(stage, Stage::Fused) {
                // Every tile of the surfaces that refill snow; then only the listed tiles of the
                // others, as many workgroups as the capture listed.
                if grid > 0 {
                    pass.set_pipeline(pipeline);
                    pass.dispatch_workgroups(
                        max_w.div_ceil(FUSED_WORKGROUP),
                        max_h.div_ceil(FUSED_WORKGROUP),
                        grid,
                    );
                }
                if listed {
                    pass.set_pipeline(&self.acc.seal);
                    pass.set_bind_group(0, &seal_bg, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                    pass.set_pipeline(&self.acc.fused_listed);
                    pass.set_bind_group(0, bg, &[]);
                    pass.dispatch_workgroups_indirect(&self.tile_list.buffer, 0);
                }
                continue;
            }
            pass.set_pipeline(pipeline);
            let side = WORKGROUP;
            let units_w = if matches!(stage, Stage::Merge) {
                max_w.div_ceil(unit)
            } else {
                max_w
            };
            pass.dispatch_workgroups(
                units_w.div_ceil(side),
                max_h.div_ceil(side),
                jobs.len() as u32,
            );
        }
        if let (Some(ts), false) = (ts, stages.is_empty()) {
            let n = stages.len() as u32 * 2;
            enc.resolve_query_set(&ts.set, 0..n, &ts.resolve, 0);
            enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.readback, 0, n as u64 * 8);
        }
        self.queue.submit([enc.finish()]);
        stats.cpu_encode_ms = start.elapsed().as_secs_f64() * 1e3;

        self.last = LastFrame {
            captured: captured
                .iter()
                .enumerate()
                .map(|(k, &j)| (jobs[j].surface, jobs[j].record, placements[k]))
                .collect(),
        };
        if let (Some(ts), false) = (ts, stages.is_empty()) {
            let bytes = self.read_buffer(&ts.readback, 0, stages.len() as u64 * 16)?;
            let ticks: &[u64] = bytemuck::cast_slice(&bytes);
            let mut t = StageTimes::default();
            for (i, stage) in stages.iter().enumerate() {
                let ms = ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64
                    * ts.period_ns as f64
                    * 1e-6;
                match stage {
                    Stage::Capture => t.capture_ms += ms,
                    Stage::Blur => t.blur_ms += ms,
                    Stage::Merge => t.merge_ms += ms,
                    Stage::Normals => t.normals_ms += ms,
                    Stage::Fused => t.fused_ms += ms,
                }
            }
            stats.gpu = Some(t);
        }
        Ok(stats)
    }

    /// Map a buffer (MAP_READ) range and copy it out, waiting for the GPU.
    fn read_buffer(&self, buffer: &wgpu::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
        let slice = buffer.slice(offset..offset + size);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| SnowError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| SnowError::Readback(e.to_string()))?
            .map_err(|e| SnowError::Readback(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| SnowError::Readback(format!("{e:?}")))?
            .to_vec();
        buffer.unmap();
        Ok(data)
    }

    /// Copy `size` bytes of a GPU buffer to the CPU.
    fn download(&self, source: &wgpu::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(source, offset, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        self.read_buffer(&staging, 0, size)
    }

    /// The words of a surface's heights region as stored (layout per precision: see
    /// [`crate::pool`]; at 16 bits, depression in the low 16 bits and displaced in the high 16).
    pub fn read_packed(&self, id: SurfaceId) -> Result<Vec<u32>> {
        let s = self.state(id)?;
        let bytes = self.download(
            &self.pool,
            s.slot.offset,
            self.config
                .format
                .heights_bytes(s.layout.width, s.layout.height),
        )?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// A surface's `(depression, displaced)` channels in units of `1 / channel_max` of the snow
    /// depth at the pool's precision, row-major.
    pub fn read_channels(&self, id: SurfaceId) -> Result<(Vec<u32>, Vec<u32>)> {
        let s = self.state(id)?;
        let words = self.read_packed(id)?;
        self.config
            .format
            .decode(s.layout.width, s.layout.height, &words)
    }

    /// Read a surface's current heightmap back to the CPU (waits for the GPU), in 16-bit units
    /// whatever the pool's precision (exact at 8 and 16 bits, rounded to nearest at 32).
    pub fn read_heightmap(&self, id: SurfaceId) -> Result<Heightmap> {
        let s = self.state(id)?;
        let (depression, displaced) = self.read_channels(id)?;
        Ok(Heightmap::from_channels(
            s.layout.width,
            s.layout.height,
            self.config.format.precision,
            &depression,
            &displaced,
        ))
    }

    /// Read a surface's packed normals (see [`crate::accumulate::cpu::unpack_normal`]). Fails
    /// when the pool keeps no normals ([`PoolFormat::normals`]).
    pub fn read_normals_packed(&self, id: SurfaceId) -> Result<Vec<u32>> {
        let s = self.state(id)?;
        let Some(word) = s
            .slot
            .normals_word(&self.config.format, s.layout.width, s.layout.height)
        else {
            return Err(SnowError::Readback(
                "this world keeps no normals; set WorldConfig.format.normals to keep them".into(),
            ));
        };
        let bytes = self.download(&self.pool, word as u64 * 4, s.layout.texels() * 4)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// Read a surface's normals in its local frame.
    pub fn read_normals(&self, id: SurfaceId) -> Result<Vec<glam::Vec3>> {
        Ok(self
            .read_normals_packed(id)?
            .into_iter()
            .map(accumulate::cpu::unpack_normal)
            .collect())
    }

    /// Debug readback of the last step: the capture of a surface (depth per texel, 1 = nothing), when
    /// it was captured in that step; `None` otherwise.
    pub fn read_last_capture(&self, id: SurfaceId) -> Result<Option<Vec<f32>>> {
        self.state(id)?;
        let Some(&(_, r, _)) = self.last.captured.iter().find(|c| c.0 == id.0 as usize) else {
            return Ok(None);
        };
        let bytes = self.download(
            &self.capture.buffer,
            r.scratch as u64 * 4,
            (r.width * r.height) as u64 * 4,
        )?;
        // The winding buffer holds this surface's texels only when meshes were drawn over it.
        let winding = if r.mode & crate::pool::MODE_MESHES != 0 {
            self.download(
                &self.winding.buffer,
                r.scratch as u64 * 4,
                (r.width * r.height) as u64 * 4,
            )?
        } else {
            vec![0; (r.width * r.height) as usize * 4]
        };
        let codes: &[u32] = bytemuck::cast_slice(&bytes);
        let winding: &[i32] = bytemuck::cast_slice(&winding);
        // As capture_read.wgsl reads it: inside a mesh solid at the ground, depth 0.
        Ok(Some(
            codes
                .iter()
                .zip(winding)
                .map(|(&v, &n)| if n > 0 { 0.0 } else { capture::decode_depth(v) })
                .collect(),
        ))
    }

    /// Debug readback of the last step: the blurred capture (stage 1 output) of a surface, when it
    /// was captured in that step by separate stages ([`PassMode::Separate`]; the fused pass keeps
    /// stage 1's output in registers).
    pub fn read_last_blurred(&self, id: SurfaceId) -> Result<Option<Vec<f32>>> {
        self.state(id)?;
        if self.config.passes == PassMode::Fused {
            return Ok(None);
        }
        let Some(&(_, r, _)) = self.last.captured.iter().find(|c| c.0 == id.0 as usize) else {
            return Ok(None);
        };
        let bytes = self.download(
            &self.scratch.buffer,
            r.scratch as u64 * 4,
            (r.width * r.height) as u64 * 4,
        )?;
        Ok(Some(bytemuck::cast_slice(&bytes).to_vec()))
    }

    /// Pool placement of a surface's slot, for renderers that read the heightmap on the GPU:
    /// `(heights word offset, normals word offset when kept)`. Valid while the surface lives;
    /// read the heights with `pool/texel.wgsl` ([`crate::pool::TEXEL_WGSL`]) at
    /// [`SnowWorld::pool_format`]'s precision.
    pub fn gpu_offsets(&self, id: SurfaceId) -> Result<(u32, Option<u32>)> {
        let s = self.state(id)?;
        Ok((
            s.slot.heights_word(),
            s.slot
                .normals_word(&self.config.format, s.layout.width, s.layout.height),
        ))
    }

    /// How the pool stores heightmaps.
    pub fn pool_format(&self) -> PoolFormat {
        self.config.format
    }

    /// The pool buffer (`array<u32>` in WGSL), for renderers that sample heightmaps on the GPU.
    pub fn pool_buffer(&self) -> &wgpu::Buffer {
        &self.pool
    }

    /// The device's capabilities as checked at start.
    pub fn capabilities(&self) -> &Capabilities {
        &self.caps
    }
}
