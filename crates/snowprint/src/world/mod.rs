//! The snow world: surfaces, deformers and the per-frame update.
//!
//! [`SnowWorld::step`] runs one frame: for every resident surface it culls the deformers against
//! the surface's capture volume, packs the surfaces that something touches into the capture atlas,
//! renders them from below (one render pass per atlas batch), and runs the accumulation chain with
//! one dispatch per stage over all updated surfaces. Surfaces that nothing touched and on which no
//! snow fell are left alone.
//!
//! The update is a plan, then an encode (`frame.rs`): validate the updates, build the pure
//! [`FramePlan`] on the CPU ([`plan`]: culling, sweeping, replenishment, atlas packing, records and
//! buffer sizes), upload its tables, record it with [`crate::capture::encode`] and
//! [`crate::accumulate::encode`] into an encoder (the caller's, with
//! [`SnowWorld::encode_update`]), and once it is submitted keep the plan's replenishment carries
//! ([`SnowWorld::submitted`]). The rest of the world is its surfaces and pool slots (here), mesh
//! deformers (`meshes.rs`; skinned ones in `skinned.rs`), snapshots (`snapshot.rs`) and readbacks
//! (`readback.rs`).

mod config;
mod footstep;
mod frame;
mod ground;
mod levels;
mod meshes;
mod nearby;
pub(crate) mod plan;
pub(crate) mod probe;
mod readback;
mod skinned;
mod snapshot;
mod spray;
mod staging;

pub use crate::capture::{CaptureConfig, CaptureMode, CapturePath};
pub use config::{
    CpuSteps, FrameStats, MemoryReport, PassMode, StageTimes, SurfaceUpdate, WorldConfig,
};
pub use footstep::Footstep;
pub use frame::PendingFrame;
pub(crate) use plan::FramePlan;
pub use probe::{
    MAX_PROBE_POINTS, MAX_UNCLAIMED_ANSWERS, PROBE_RING, ProbeSample, ProbeStatus, ProbeTicket,
};
pub use skinned::MeshAnimation;
pub use snapshot::{SnapshotRead, SurfaceSnapshot};

use crate::accumulate::AccumulatePipelines;
use crate::capture::{self, CaptureMesh, CapturePipelines};
use crate::error::{Result, SnowError};
use crate::gpu::resources::{Growable, UNIFORM_STRIDE};
use crate::gpu::ring::TimestampRing;
use crate::gpu::{Capabilities, GpuContext};
use crate::pool::{PoolFormat, Slot, SlotAllocator, SurfaceRecord};
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

struct SurfaceState {
    desc: SurfaceDesc,
    layout: SurfaceLayout,
    slot: Slot,
    /// Replenishment not yet applied, units (fraction kept between frames).
    carry: f64,
    /// How long and where a slumping material still relaxes (see [`crate::Material`]); not kept
    /// by snapshots (a surface paged back in has settled).
    settle: crate::relax::Settle,
    /// Its ground field and where it lies in the capture's ground buffer, when it is not flat
    /// (`ground.rs`).
    ground: Option<ground::SurfaceGround>,
    /// Toroidal storage offsets of its slot, `ox | oy << 16` (a terrain window's level,
    /// `crate::window`); 0 for every other surface.
    wrap: u32,
    /// The local rectangle a finer window level draws instead (`crate::window`).
    hole: Option<[f32; 4]>,
}

/// What the last frame did, for debug readbacks.
#[derive(Default)]
struct LastFrame {
    /// (surface index, record) of every captured surface.
    captured: Vec<(usize, SurfaceRecord)>,
    /// The compute path's work list (`[view, tile]`): the only tiles of its regions it wrote.
    written: Vec<[u32; 2]>,
}

/// CPU memory one update reuses from the last, so that its cost does not grow with allocations.
#[derive(Default)]
struct FrameScratch {
    /// The frame's plan.
    plan: FramePlan,
    /// Which surfaces an update lists (to refuse duplicates).
    seen: Vec<bool>,
    /// Uniform blocks being uploaded, [`UNIFORM_STRIDE`] apart.
    blocks: Vec<u8>,
    /// A pending frame's carries and captures, given back when it is submitted.
    carries: Vec<(usize, f64)>,
    /// The settle states before a pending frame (see `carries`).
    settles: Vec<(usize, crate::relax::Settle)>,
    captured: Vec<(usize, SurfaceRecord)>,
    /// A pending frame's compute work list (see `LastFrame::written`).
    written: Vec<[u32; 2]>,
    /// By surface index, whether `carries` ([`KEPT_CARRY`]) and `settles` ([`KEPT_SETTLE`])
    /// already hold its state from before the frame (a flag a surface, not a search of the lists:
    /// a frame of thousands of surfaces would be quadratic).
    kept: Vec<u8>,
}

/// A flag of [`FrameScratch::kept`]: the surface's carry is remembered.
const KEPT_CARRY: u8 = 1;
/// A flag of [`FrameScratch::kept`]: the surface's settle state is remembered.
const KEPT_SETTLE: u8 = 2;

/// The frame encoded and not yet reported submitted.
#[derive(Clone, Copy, Debug)]
struct InFlight {
    /// Its number.
    frame: u64,
    /// The timestamp ring's slot it resolves into.
    timestamp_slot: Option<usize>,
}

/// The snow world: every surface's heightmap in one GPU pool, updated by [`SnowWorld::step`].
pub struct SnowWorld {
    device: wgpu::Device,
    queue: wgpu::Queue,
    caps: Capabilities,
    config: WorldConfig,
    capture_pipes: CapturePipelines,
    acc: AccumulatePipelines,
    relax: crate::relax::RelaxGpu,
    pool: wgpu::Buffer,
    alloc: SlotAllocator,
    surfaces: Vec<Option<SurfaceState>>,
    /// Generation of each slot of `surfaces`: bumped when its surface is removed, so that old
    /// handles to the slot are refused (see [`SurfaceId`]).
    generations: Vec<u32>,
    meshes: Vec<Option<CaptureMesh>>,
    /// Skinned meshes' skeletons and GPU state, by mesh index (`skinned.rs`).
    skins: skinned::Skins,
    atlases: Vec<(u32, wgpu::Texture, wgpu::TextureView)>,
    records: Growable,
    views: Growable,
    prims: Growable,
    /// Mapped buffers a split plan copies its primitives into, copied from into `prims`.
    staging: staging::StagingRing,
    draws: Growable,
    capture: Growable,
    winding: Growable,
    /// One flag per 16x16 tile of each captured surface: set by the capture where it wrote.
    tiles: Growable,
    /// The flagged tiles as a list with its indirect dispatch (see `accumulate::TILE_LIST_HEADER`).
    tile_list: Growable,
    scratch: Growable,
    /// The ground fields of the surfaces that are not on flat ground, `[base, bare]` per texel.
    grounds: Growable,
    /// The capture code of the ground at each texel of those fields, parallel to `grounds`.
    ground_codes: Growable,
    /// Bytes written into `grounds` and `ground_codes` so far.
    ground_bytes_written: u64,
    /// The ground mesh rasterisation, built the first time a mesh ground is set.
    ground_raster: Option<crate::ground::raster::GroundRaster>,
    last: LastFrame,
    scratch_cpu: FrameScratch,
    profiling: bool,
    timestamps: Option<TimestampRing>,
    /// Which world this is, so that a [`PendingFrame`] is given back to its own.
    id: u64,
    /// Frames encoded so far.
    frames: u64,
    in_flight: Option<InFlight>,
    /// Slots of surfaces removed while a frame was in flight, freed once it is submitted: the
    /// frame still writes them.
    deferred_frees: Vec<Slot>,
    /// Gameplay probes, their ring and cache, and the last update's footsteps.
    probes: probe::Probes,
    /// Kicked-up snow, when [`WorldConfig::spray`] asks for it.
    spray: Option<crate::spray::SprayGpu>,
}

/// Source of [`SnowWorld`] ids.
static NEXT_WORLD: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

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
    ///
    /// The device is checked against [`crate::required_features`] and
    /// [`crate::required_limits`] first (a hand-filled [`GpuContext`] too):
    /// [`SnowError::DeviceLimit`] or [`SnowError::DeviceFeature`] when it falls short.
    pub fn new(gpu: &GpuContext, config: WorldConfig) -> Result<Self> {
        crate::gpu::check_device(&gpu.device)?;
        let device = gpu.device.clone();
        let mut config = config;
        config.capture_path = config.capture_path.resolved(gpu.info.device_type);
        let c = config.capture;
        if !(c.ankle_height.is_finite() && c.ankle_height > 0.0) {
            return Err(SnowError::Config {
                config: "capture",
                what: "ankle_height",
                value: c.ankle_height.to_string(),
                expected: "a finite number of metres above 0",
            });
        }
        if !(c.mask_depth.is_finite() && c.mask_depth > 0.0 && c.mask_depth <= 1.0) {
            return Err(SnowError::Config {
                config: "capture",
                what: "mask_depth",
                value: c.mask_depth.to_string(),
                expected: "a fraction in (0, 1]",
            });
        }
        let max_pool = gpu
            .caps
            .max_storage_binding
            .min(device.limits().max_storage_buffer_binding_size)
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
        let max_side = gpu
            .caps
            .max_texture_side
            .min(device.limits().max_texture_dimension_2d);
        config.atlas_side = config.atlas_side.clamp(64, max_side);
        if config.passes == PassMode::Auto {
            config.passes = PassMode::Fused;
        }
        // A surface's capture region (its texels and the apron) must fit the atlas.
        let largest = config.atlas_side - 2 * crate::capture::APRON;
        config.max_resolution = config.max_resolution.clamp(1, largest);
        if let Some(spray) = &config.spray {
            spray.validate()?;
        }
        let spray = config
            .spray
            .map(|s| crate::spray::SprayGpu::new(&device, config.format.precision, s));
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
        let timestamps = (gpu.caps.timestamps
            && device.features().contains(wgpu::Features::TIMESTAMP_QUERY))
        .then(|| TimestampRing::new(&device, &gpu.queue, "snowprint timestamps", 256));
        Ok(Self {
            capture_pipes: CapturePipelines::new(&device),
            acc: accumulate_pipelines(&device, &config),
            relax: crate::relax::RelaxGpu::new(&device, config.format.precision),
            probes: probe::Probes::new(&device),
            records: Growable::new(
                &device,
                "surface records",
                U::STORAGE | U::COPY_DST,
                64 * 64,
            ),
            views: Growable::new(
                &device,
                "capture views",
                U::UNIFORM | U::STORAGE | U::COPY_DST,
                UNIFORM_STRIDE * 16,
            ),
            prims: Growable::new(
                &device,
                "capture primitives",
                U::STORAGE | U::COPY_DST,
                80 * 64,
            ),
            staging: staging::StagingRing::default(),
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
            grounds: Growable::new(&device, "ground fields", U::STORAGE | U::COPY_DST, 16),
            ground_codes: Growable::new(&device, "ground codes", U::COPY_SRC | U::COPY_DST, 16),
            ground_bytes_written: 0,
            ground_raster: None,
            queue: gpu.queue.clone(),
            caps: gpu.caps.clone(),
            device,
            config,
            pool,
            alloc,
            surfaces: Vec::new(),
            generations: Vec::new(),
            meshes: Vec::new(),
            skins: skinned::Skins::default(),
            atlases: Vec::new(),
            last: LastFrame::default(),
            scratch_cpu: FrameScratch::default(),
            profiling: false,
            timestamps,
            id: NEXT_WORLD.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            frames: 0,
            in_flight: None,
            deferred_frees: Vec::new(),
            spray,
        })
    }

    /// The world's settings (after clamping to the device).
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// Measure each stage with GPU timestamp queries (when the adapter has them). Nothing waits
    /// for the GPU: [`FrameStats::gpu`] reports the times of an earlier frame, as they arrive.
    pub fn set_profiling(&mut self, on: bool) {
        self.profiling = on;
    }

    /// The device the world runs on.
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The queue the world submits to.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// Whether per-stage GPU times can be measured on this device.
    pub fn has_timestamps(&self) -> bool {
        self.timestamps.is_some()
    }

    /// Add a surface; its heightmap starts untouched. Fails with [`SnowError::PoolExhausted`] when
    /// the pool has no room (a normal state: remove a surface or give the pool more bytes).
    pub fn add_surface(&mut self, desc: SurfaceDesc) -> Result<SurfaceId> {
        self.add_surface_with(desc, None)
    }

    /// [`SnowWorld::add_surface`], its slot cleared in `enc`'s order when given (after what the
    /// encoder recorded before, such as the page-out of the slot's last owner), else with the
    /// next submission.
    pub(crate) fn add_surface_with(
        &mut self,
        desc: SurfaceDesc,
        enc: Option<&mut wgpu::CommandEncoder>,
    ) -> Result<SurfaceId> {
        desc.validate()?;
        let layout = SurfaceLayout::for_size_capped(desc.size, self.config.max_resolution);
        let slot = self.reserve_slot(&desc.name, &layout, None)?;
        match enc {
            Some(enc) => enc.clear_buffer(&self.pool, slot.offset, Some(slot.bytes)),
            // Cleared with the next submission (before its command buffers), no encoder needed.
            None => {
                self.queue
                    .write_buffer(&self.pool, slot.offset, &vec![0u8; slot.bytes as usize])
            }
        }
        Ok(self.insert_state(SurfaceState {
            desc,
            layout,
            slot,
            carry: 0.0,
            settle: Default::default(),
            ground: None,
            wrap: 0,
            hole: None,
        }))
    }

    /// A slot for a surface of `layout`: first fit, or at `at` in the pool (its bytes are the
    /// caller's to write).
    fn reserve_slot(
        &mut self,
        name: &str,
        layout: &SurfaceLayout,
        at: Option<u64>,
    ) -> Result<Slot> {
        let needed = self.config.format.slot_bytes(layout.width, layout.height);
        match at {
            Some(offset) => self.alloc.alloc_at(offset, needed),
            None => self.alloc.alloc(needed),
        }
        .ok_or_else(|| SnowError::PoolExhausted {
            name: name.to_owned(),
            needed,
            free: self.alloc.largest_free(),
            budget: self.alloc.budget(),
        })
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
        if self.in_flight.is_some() {
            self.deferred_frees.push(state.slot);
        } else {
            self.alloc.free(state.slot);
        }
        Ok(())
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

    /// How long and where a surface of a slumping material still relaxes (a save keeps it).
    pub(crate) fn settle_of(&self, id: SurfaceId) -> Result<crate::relax::Settle> {
        Ok(self.state(id)?.settle)
    }

    /// Set a surface's settle state (a save's, checked against the surface by the save's reader).
    pub(crate) fn set_settle(&mut self, id: SurfaceId, settle: crate::relax::Settle) -> Result<()> {
        self.state(id)?;
        if let Some(s) = self.surfaces[id.0 as usize].as_mut() {
            s.settle = settle;
        }
        Ok(())
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

    /// Pool placement of a surface's slot, for renderers that read the heightmap on the GPU:
    /// `(heights word offset, normals word offset when kept)`. Valid while the surface lives;
    /// read the heights with `pool/texel.wgsl` (`wgsl::libraries::TEXEL`) at
    /// [`SnowWorld::pool_format`]'s precision.
    pub fn gpu_offsets(&self, id: SurfaceId) -> Result<(u32, Option<u32>)> {
        let s = self.state(id)?;
        Ok((
            s.slot.heights_word(),
            s.slot
                .normals_word(&self.config.format, s.layout.width, s.layout.height),
        ))
    }

    /// A surface's toroidal storage offsets, `ox | oy << 16` (`pool::wrapped`): 0 for
    /// every surface but a terrain window's levels (`crate::Terrain`).
    pub fn wrap(&self, id: SurfaceId) -> Result<u32> {
        Ok(self.state(id)?.wrap)
    }

    /// The rectangle of a surface's local xz that a finer level of its terrain window draws
    /// instead (see [`crate::SurfaceView::hole`]).
    pub fn hole(&self, id: SurfaceId) -> Result<Option<[f32; 4]>> {
        Ok(self.state(id)?.hole)
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

/// The accumulation's pipelines for a world of `config` (its capture path resolved): the fused
/// pass's cast entry points compiled up front where the plan casts, so that no frame waits on
/// them.
fn accumulate_pipelines(device: &wgpu::Device, config: &WorldConfig) -> AccumulatePipelines {
    let pipes = AccumulatePipelines::new(device, config.format.precision);
    if plan::PlanSettings::of(config).casts() {
        pipes.compile_casts(device);
    }
    pipes
}
