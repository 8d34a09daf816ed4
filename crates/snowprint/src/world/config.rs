//! A world's settings and what it reports: pass settings, frame statistics, memory (the capture
//! settings live with the capture: [`crate::capture::CaptureConfig`]).

use crate::capture::{CaptureConfig, CapturePath};
use crate::deformer::Deformer;
use crate::pool::PoolFormat;
use crate::surface::SurfaceId;

#[cfg(doc)]
use super::SnowWorld;

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
    /// With [`PassMode::Fused`], the fewest words of heights (4 bytes each) of the surfaces that
    /// refill snow in one update from which their snowfall is refilled by a pass of its own
    /// streaming whole regions (then the fused pass visits only the tiles the capture reached);
    /// below it, the fused pass refills every tile of theirs itself. The refill pass moves bytes
    /// faster than a copy (it writes back only what changed) but costs a few microseconds more in
    /// all: default 2 Mi words (8 MiB, thirty-two 512^2 surfaces at 16 bits), where the two ways
    /// cost the same on the H100 (`docs/PERFORMANCE.md`). 0 always streams; `u32::MAX` never does.
    pub refill_stream_from: u32,
    /// With [`CapturePath::Update`], the fewest tiles (16x16 texels) the update ray-casts itself
    /// in one frame from which each is taken by a workgroup of 128 invocations rather than 256.
    /// Half the invocations a tile holds twice as many tiles resident at once, which pays where
    /// the tiles wait on their reads in many waves, and lengthens each tile's own time, which is
    /// the whole pass's where they are few: default 512, between the H100's figures at 256 tiles
    /// (256 invocations the faster) and 1024 (128 the faster; `docs/PERFORMANCE.md`). 0 always;
    /// `u32::MAX` never.
    pub cast_many_from: u32,
    /// How heightmaps are stored: bits a channel, and whether normals are kept.
    pub format: PoolFormat,
    /// Which path captures analytic deformers: `Update` leaves them to the fused update, which
    /// ray-casts them itself where its blur reads them, `Compute` ray-casts them into the capture
    /// in one dispatch for every surface that meshes do not press, `Raster` renders every surface
    /// in its viewport, and [`CapturePath::Auto`] (the default) takes `Update` on a GPU and
    /// `Raster` on a software adapter. All give the same heights.
    pub capture_path: CapturePath,
    /// Kicked-up snow: particles spawned where an update deepens a print fast (`spray/`). `None`
    /// (the default): no spray pass, the update exactly as without it.
    pub spray: Option<crate::spray::SprayConfig>,
    /// Threads that plan a frame of many surfaces (128 or more) on the CPU, each a run of them:
    /// the plan is the same whatever the count. 0 (the default): the machine's available
    /// parallelism, up to 8; 1: on the calling thread alone. The calling thread is one of them;
    /// the others are a pool the world makes at the first frame that needs it and keeps, parked
    /// between frames, until it is dropped.
    pub plan_threads: usize,
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
            refill_stream_from: 1 << 21,
            cast_many_from: 512,
            format: PoolFormat::default(),
            capture_path: CapturePath::Auto,
            spray: None,
            plan_threads: 0,
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
    /// The snowfall streamed over whole heights regions before the fused pass (see
    /// [`WorldConfig::refill_stream_from`]), when it runs.
    pub refill_ms: f64,
    /// The relaxation of slumping materials (see [`crate::Material`]).
    pub relax_ms: f64,
    /// The kicked-up snow's pass (simulate, spawn, fold, place), with [`WorldConfig::spray`].
    pub spray_ms: f64,
}

impl StageTimes {
    /// Sum of the stages.
    pub fn total_ms(&self) -> f64 {
        self.capture_ms
            + self.blur_ms
            + self.merge_ms
            + self.normals_ms
            + self.fused_ms
            + self.refill_ms
            + self.relax_ms
            + self.spray_ms
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
    /// Bytes of the capture buffer cleared before the capture: the raster path's regions (every
    /// captured region with [`PassMode::Separate`]; the compute path writes all it may be read
    /// at). The clear is recorded before the first pass, outside [`FrameStats::gpu`]'s times.
    pub cleared_capture_bytes: u64,
    /// CPU time spent building and encoding the frame, milliseconds.
    pub cpu_encode_ms: f64,
    /// Where that time went, step by step.
    pub cpu_steps: CpuSteps,
    /// The world's number of this frame: 1 for its first update, one more for each after.
    pub frame: u64,
    /// Per-stage GPU times of an earlier frame (number [`FrameStats::gpu_frame`]), when
    /// profiling is on and the adapter has timestamp queries. They are read back without waiting
    /// for the GPU, so a frame's times arrive with the stats of a later frame, usually the next
    /// or the one after; [`SnowWorld::take_gpu_times`] collects the last ones.
    pub gpu: Option<StageTimes>,
    /// The number ([`FrameStats::frame`]) of the frame that [`FrameStats::gpu`] measured.
    pub gpu_frame: Option<u64>,
}

impl FrameStats {
    /// Add the counts of one more layer of the frame (see the manager's catch-up).
    pub(crate) fn add_layer(&mut self, layer: &FrameStats) {
        self.updated += layer.updated;
        self.captured += layer.captured;
        self.capture_batches += layer.capture_batches;
        self.primitives += layer.primitives;
        self.mesh_draws += layer.mesh_draws;
        self.cleared_capture_bytes += layer.cleared_capture_bytes;
    }
}

/// Where the CPU time of a frame's encode ([`FrameStats::cpu_encode_ms`]) went, milliseconds,
/// summed over the frame's layers (the manager's catch-up records several).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct CpuSteps {
    /// Checking the updates (their time steps, surfaces and deformers).
    pub check_ms: f64,
    /// Planning the surfaces: replenishment, culling, sweeping, the footstep test (on the
    /// world's threads for a frame of many surfaces, [`WorldConfig::plan_threads`]).
    pub plan_ms: f64,
    /// Gathering a split plan's runs into one (their primitives copied into the staging memory
    /// of the frame's first write meanwhile); 0 for a plan on one thread.
    pub gather_ms: f64,
    /// The frame's own work once every surface is planned: ordering, the capture atlas, the
    /// surface records and capture views.
    pub tables_ms: f64,
    /// Growing the frame's buffers and writing its tables to the GPU (`queue.write_buffer`).
    pub upload_ms: f64,
    /// Recording the capture and accumulation passes into the encoder.
    pub record_ms: f64,
}

impl CpuSteps {
    /// The steps of one more layer added to these.
    pub(crate) fn add(&mut self, other: &CpuSteps) {
        self.check_ms += other.check_ms;
        self.plan_ms += other.plan_ms;
        self.gather_ms += other.gather_ms;
        self.tables_ms += other.tables_ms;
        self.upload_ms += other.upload_ms;
        self.record_ms += other.record_ms;
    }
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
