//! The frame plan: everything one update decides on the CPU, before a GPU command is recorded.
//!
//! [`FramePlan::build`] culls each surface's deformers against its capture volume, sweeps the
//! analytic ones into primitives (sub-steps along their motion) and the meshes into draws,
//! counts the snow each surface refills (carrying the fraction), packs the captured surfaces into
//! the atlas, writes the surface records and capture views, and sizes every per-frame buffer. It
//! needs no GPU, so it is tested on its own (`plan/tests.rs`); [`crate::capture::encode`] and
//! [`crate::accumulate::encode`] then record it.

use std::ops::Range;

use glam::{Vec2, Vec3};

use super::footstep::{Footstep, footstep};
use super::nearby::{INDEX_FROM, NearbyDeformers, surface_rect};
use super::{FrameStats, PassMode, WorldConfig};
use crate::accumulate::AccumulatePlan;
use crate::capture::{
    self, CaptureConfig, CapturePlan, CaptureView, CaptureVolume, CapturedSurface,
};
use crate::deformer::Deformer;
use crate::gpu::resources::UNIFORM_STRIDE;
use crate::ground::GroundField;
use crate::mesh::MeshId;
use crate::pool::{
    MODE_CAST, MODE_GROUND, MODE_REFILLED, NO_CAPTURE, NO_NORMALS, PoolFormat, SurfaceRecord,
    TILE_LIST_HEADER, TILE_SIDE,
};
use crate::relax::{Rect, RelaxPlan, RelaxRecord, Settle};
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

mod parallel;
mod sizes;
mod surface;
#[cfg(test)]
mod tests;

pub(crate) use parallel::{NoPrims, Opened, PrimsTarget, plan_threads};

pub use sizes::BufferSizes;
pub use surface::replenish;
use surface::{Way, pressed_rect, record_mode, refused, way};

/// The settings of a world that a plan follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanSettings {
    /// Capture settings.
    pub capture: CaptureConfig,
    /// How the pool stores heightmaps.
    pub format: PoolFormat,
    /// Fused or separate accumulation ([`PassMode::Auto`] is fused).
    pub passes: PassMode,
    /// See [`WorldConfig::list_tiles_from`].
    pub list_tiles_from: u32,
    /// See [`WorldConfig::refill_stream_from`].
    pub refill_stream_from: u32,
    /// See [`WorldConfig::cast_many_from`].
    pub cast_many_from: u32,
    /// Largest side of the capture atlas, texels.
    pub atlas_side: u32,
    /// Which path captures analytic deformers.
    pub capture_path: capture::CapturePath,
    /// Whether kicked-up snow is spawned from the capture (then every surface is captured).
    pub spray: bool,
}

impl PlanSettings {
    /// The settings of a world's configuration.
    pub fn of(config: &WorldConfig) -> Self {
        Self {
            capture: config.capture,
            format: config.format,
            passes: config.passes,
            list_tiles_from: config.list_tiles_from,
            refill_stream_from: config.refill_stream_from,
            cast_many_from: config.cast_many_from,
            atlas_side: config.atlas_side,
            capture_path: config.capture_path,
            spray: config.spray.is_some(),
        }
    }

    fn fused(&self) -> bool {
        self.passes != PassMode::Separate
    }

    /// Whether the update ray-casts a surface's analytic primitives itself (`Way::Cast`) where it
    /// has few enough: the world asks for it, the update is fused and no spray reads the capture.
    pub(crate) fn casts(&self) -> bool {
        self.capture_path == capture::CapturePath::Update && self.fused() && !self.spray
    }
}

/// What a plan knows of the world's meshes.
pub trait PlanMeshes {
    /// The bounding radius of a registered mesh (`None`: not registered; its deformers are
    /// skipped).
    fn radius(&self, id: MeshId) -> Option<f32>;

    /// Its vertices as last posed, for the footstep test (`None`: its deformers never land).
    fn vertices(&self, _id: MeshId) -> Option<&[Vec3]> {
        None
    }
}

/// A function giving a mesh's radius, and no vertices.
impl<F: Fn(MeshId) -> Option<f32>> PlanMeshes for F {
    fn radius(&self, id: MeshId) -> Option<f32> {
        self(id)
    }
}

/// One surface to update, as the plan sees it: its description, its place in the pool, the
/// replenishment it carried, and what touched it.
#[derive(Clone, Copy, Debug)]
pub struct PlanSurface<'a> {
    /// The world's index of the surface (carried to the plan's outputs).
    pub index: usize,
    /// Its handle (named by its footsteps).
    pub id: SurfaceId,
    /// The surface.
    pub desc: &'a SurfaceDesc,
    /// Its heightmap resolution.
    pub layout: SurfaceLayout,
    /// Word offset of its heights in the pool.
    pub heights_word: u32,
    /// Word offset of its normals, when the pool keeps them.
    pub normals_word: Option<u32>,
    /// Its toroidal storage offsets (`pool::wrapped`; 0 for an ordinary surface).
    pub wrap: u32,
    /// Replenishment carried from earlier updates, units (a fraction in `[0, 1)`).
    pub carry: f64,
    /// Seconds since its last update.
    pub elapsed: f32,
    /// Everything that touched it since then.
    pub deformers: &'a [Deformer],
    /// How long and where it still slumps after the last update that pressed it (see
    /// [`crate::Material`]).
    pub settle: Settle,
    /// Its ground field in the capture's ground buffer, or `None` on flat ground.
    pub ground: Option<PlanGround>,
    /// The ground field itself, for the footstep test (`None` on flat ground).
    pub ground_field: Option<&'a GroundField>,
}

/// Where a surface's ground field lies for the capture, and the heights it spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanGround {
    /// First texel of the field in the ground buffer.
    pub offset: u32,
    /// First of its capture codes in the ground codes buffer, one per texel of the surface's
    /// capture region ([`capture::region`]: the apron's ground extrapolated,
    /// [`GroundField::region_columns`]).
    pub codes: u32,
    /// The lowest base and the highest ground of the field, local metres
    /// ([`crate::GroundField::range`]).
    pub range: (f32, f32),
}

/// A surface the plan updates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlannedSurface {
    /// The world's index of the surface.
    pub index: usize,
    /// Whether something is captured on it (else it only refills snow).
    pub captured: bool,
}

/// One surface's work while the plan is built.
#[derive(Clone, Debug)]
struct Job {
    surface: PlannedSurface,
    record: SurfaceRecord,
    half_size: Vec2,
    /// First texel of the ground field, or [`capture::NO_GROUND`].
    ground_offset: u32,
    /// First of its capture codes (one per texel of its capture region) in the ground codes
    /// buffer (0 on flat ground: never read).
    ground_codes: u32,
    prims: Range<u32>,
    draws: Range<u32>,
    /// How its analytic deformers reach the update.
    way: Way,
    /// In a split plan, the tiles its primitives reach, in the plan's `reached` (computed with
    /// the rest of the surface's own work, so that it is spread over threads with it:
    /// `reach_tiles`), and whether the compute path takes the tiles beside them
    /// (`capture::tiles_reached`); else empty.
    tiles: Range<u32>,
    sparse: bool,
    /// Relaxation steps this update (0: none), the material's repose angle (degrees) and the
    /// rectangle that relaxes.
    relax: (u32, f32, Rect),
}

/// Everything one update records, decided on the CPU. Kept by the world and rebuilt each frame
/// ([`FramePlan::rebuild`]) so that its vectors are reused.
#[derive(Clone, Debug, Default)]
pub struct FramePlan {
    /// The updated surfaces, parallel to `accumulate.records`: those that refill snow first.
    pub surfaces: Vec<PlannedSurface>,
    /// What the capture draws.
    pub capture: CapturePlan,
    /// What the accumulation runs over.
    pub accumulate: AccumulatePlan,
    /// The replenishment carry of every surface planned (updated or not), to keep once the frame
    /// is submitted: `(index, carry)`.
    pub carries: Vec<(usize, f64)>,
    /// What the relaxation runs over.
    pub relax: RelaxPlan,
    /// How long and where each surface planned still slumps after this update: `(index, settle)`.
    pub settles: Vec<(usize, Settle)>,
    /// What each per-frame buffer must hold.
    pub sizes: BufferSizes,
    /// Every deformer that landed on a surface, in the order of the surfaces and their deformers
    /// (see [`crate::SnowWorld::footsteps`]): the footstep test runs in the same walk over a
    /// surface's deformers as the capture's culling.
    pub footsteps: Vec<Footstep>,
    jobs: Vec<Job>,
    rects: Vec<(u32, u32)>,
    /// Scratch of the compute path's tiles, a flag a tile of one surface.
    seen: Vec<bool>,
    /// The tiles each job's primitives reach (`Job::tiles`), `[0, tile y << 16 | tile x]`: the
    /// view or record is set as the tables are written.
    reached: Vec<[u32; 2]>,
    /// Whether each surface lists its tiles into `reached` as it is planned (a split plan, so
    /// that the listing is spread over the threads), rather than as the tables are written (one
    /// copy fewer).
    tiles_early: bool,
    /// Partial plans of contiguous runs of surfaces, planned on threads of their own and then
    /// appended in order (`parallel.rs`); kept for their memory.
    parts: Vec<FramePlan>,
    /// The threads the parts are planned on, kept between frames.
    planners: parallel::Planners,
    /// How long the last rebuild took to plan, gather and finish (the world's
    /// [`crate::CpuSteps`]; its other steps are zero).
    pub(crate) laps: crate::CpuSteps,
    /// Whether the parts' primitives follow this plan's (a split plan): they are not appended,
    /// but written to the GPU from where they were planned ([`FramePlan::prims`]).
    prims_in_parts: bool,
    /// Whether a split plan's primitives were copied into the memory its caller opened for them
    /// ([`parallel::PrimsTarget`]): then they need no other write to the GPU than its copy.
    pub(crate) prims_written: bool,
    /// The grid over a long list of deformers shared by surfaces (`encode_step`'s), kept for the
    /// frame's footsteps; forgotten at the next rebuild.
    pub(crate) nearby: NearbyDeformers,
    /// Scratch: the deformers of a long list near one surface.
    near: Vec<u32>,
    /// Whether to check each deformer of a short list as it is walked (see `refused`): the world
    /// checks a frame's short lists in the plan's walk over them rather than in a pass of its own.
    pub(crate) check_short_lists: bool,
    /// Whether a deformer of a short list was refused ([`Deformer::validate`], or a mesh not
    /// registered): the plan is not to be used, and the world's own check names the deformer.
    pub(crate) refused: bool,
}

impl FramePlan {
    /// Plan a frame of `surfaces` (each listed once). `meshes` gives the bounding radius of a
    /// registered mesh (`None`: not registered; its deformers are skipped), and its vertices for
    /// the footstep test.
    pub fn build<'a>(
        settings: &PlanSettings,
        surfaces: impl IntoIterator<Item = PlanSurface<'a>>,
        meshes: impl PlanMeshes,
    ) -> Self {
        let mut plan = Self::default();
        plan.rebuild(settings, surfaces, meshes);
        plan
    }

    /// [`FramePlan::build`] into this plan, reusing its memory.
    pub fn rebuild<'a>(
        &mut self,
        settings: &PlanSettings,
        surfaces: impl IntoIterator<Item = PlanSurface<'a>>,
        meshes: impl PlanMeshes,
    ) {
        let start = std::time::Instant::now();
        self.clear();
        self.tiles_early = false;
        for s in surfaces {
            self.plan_surface(settings, &s, &meshes);
        }
        self.laps = crate::CpuSteps {
            plan_ms: elapsed_ms(start),
            ..Default::default()
        };
        self.finish(settings);
    }

    /// Order the jobs, pack the atlas and write the tables: the work of the whole frame, once
    /// every surface is planned.
    fn finish(&mut self, settings: &PlanSettings) {
        // Surfaces that refill snow first (the refill pass streams records 0..dense), those the
        // update casts first among them and last among the others, so that the fused grid covers
        // a run of records that it captures (`accumulation_shape`).
        let order = |j: &Job| match (j.record.replenish_units > 0, j.way == Way::Cast) {
            (true, true) => 0,
            (true, false) => 1,
            (false, false) => 2,
            (false, true) => 3,
        };
        // A stable sort takes scratch memory of half the jobs: not when they are in order already
        // (a frame whose surfaces all take one way, say).
        let start = std::time::Instant::now();
        if !self.jobs.is_sorted_by_key(order) {
            self.jobs.sort_by_key(order);
        }
        self.pack_atlas(settings);
        self.write_tables(settings);
        self.laps.tables_ms = elapsed_ms(start);
    }

    /// Whether nothing is updated (no GPU work at all).
    pub fn is_empty(&self) -> bool {
        self.surfaces.is_empty()
    }

    /// What the frame does, as [`FrameStats`] counts them (times left at zero).
    pub fn stats(&self) -> FrameStats {
        FrameStats {
            updated: self.surfaces.len() as u32,
            captured: self.surfaces.iter().filter(|s| s.captured).count() as u32,
            capture_batches: self.capture.batches,
            primitives: self.prims_len() as u32,
            mesh_draws: self.capture.draws.len() as u32,
            cleared_capture_bytes: self.capture.clears.iter().map(|c| c.1 as u64 * 4).sum(),
            ..Default::default()
        }
    }

    fn clear(&mut self) {
        self.surfaces.clear();
        self.capture.clear();
        self.accumulate.clear();
        self.carries.clear();
        self.relax.clear();
        self.settles.clear();
        self.sizes = BufferSizes::default();
        self.footsteps.clear();
        self.refused = false;
        self.jobs.clear();
        self.rects.clear();
        self.reached.clear();
        self.prims_in_parts = false;
        self.prims_written = false;
        self.nearby.forget();
    }

    /// Replenishment, culling and sweeping of one surface; a job when there is anything to do.
    fn plan_surface(
        &mut self,
        settings: &PlanSettings,
        s: &PlanSurface<'_>,
        meshes: &impl PlanMeshes,
    ) {
        let (carry, units) = replenish(
            s.carry,
            s.desc.replenish_rate,
            s.elapsed,
            settings.format.precision.channel_max(),
        );
        self.carries.push((s.index, carry));
        let frustum_height = s.desc.snow_depth + settings.capture.ankle_height;
        let half_size = s.desc.size * 0.5;
        // Deformers are culled against the capture region, the surface grown by the apron: one
        // that presses only a neighbour's edge column still reaches this surface's blur.
        let volume = CaptureVolume {
            world_to_local: s.desc.world_to_local(),
            half_size: CaptureVolume::of_region(half_size, s.layout.width, s.layout.height),
            frustum_height,
            ground: s.ground.map_or((0.0, 0.0), |g| g.range),
        };
        let p0 = self.capture.prims.len() as u32;
        let d0 = self.capture.draws.len() as u32;
        let (capture, footsteps) = (&mut self.capture, &mut self.footsteps);
        let mut visit = |i: usize, d: &Deformer| {
            capture.push_deformer(d, &volume, meshes);
            let on = (s.id, s.desc, &volume.world_to_local);
            let vertices = |id| meshes.vertices(id);
            footsteps.extend(footstep(i, d, on, s.ground_field, s.elapsed, vertices));
        };
        if s.deformers.len() >= INDEX_FROM {
            // A long list (every deformer of the world): only those in the grid's cells near the
            // surface, in the list's order.
            self.nearby.index(s.deformers);
            self.nearby
                .near(surface_rect(s.desc, volume.half_size), &mut self.near);
            for &i in &self.near {
                visit(i as usize, &s.deformers[i as usize]);
            }
        } else {
            let check = self.check_short_lists;
            for (i, d) in s.deformers.iter().enumerate() {
                visit(i, d);
                if check && refused(d, meshes) {
                    self.refused = true;
                }
            }
        }
        let prims = &self.capture.prims;
        let (p1, d1) = (prims.len() as u32, self.capture.draws.len() as u32);
        let captured = p1 > p0 || d1 > d0;
        // A slumping material relaxes in every update that presses it and for `settle_updates`
        // after the last, over what may be unsettled (what it pressed, and what earlier updates
        // left moving) grown by the update's steps: a step moves material one texel, so nothing
        // outside that rectangle would move in a relaxation of the whole surface either.
        let material = &s.desc.material;
        let (w, h) = (s.layout.width, s.layout.height);
        let steps = material.steps();
        let pressed = if d1 > d0 {
            Rect {
                x0: 0,
                y0: 0,
                x1: w,
                y1: h,
            }
        } else {
            pressed_rect(&prims[p0 as usize..p1 as usize], half_size, s.layout)
        };
        let (relaxes, settle) = match (material.slumps(), captured) {
            (false, _) => (false, 0),
            (true, true) => (true, material.settle_updates),
            (true, false) => (s.settle.updates > 0, s.settle.updates.saturating_sub(1)),
        };
        let kept = if s.settle.updates > 0 {
            s.settle.rect
        } else {
            Rect::default()
        };
        let rect = if relaxes {
            kept.union(if captured { pressed } else { Rect::default() })
                .grown(steps, w, h)
        } else {
            Rect::default()
        };
        self.settles.push((
            s.index,
            Settle {
                updates: if relaxes { settle } else { 0 },
                rect,
            },
        ));
        if !captured && units == 0 && !relaxes {
            return;
        }
        let texel = s.desc.size / Vec2::new(s.layout.width as f32, s.layout.height as f32);
        let way = way(settings, p1 - p0, d1 > d0);
        let (tiles, sparse) = if self.tiles_early {
            self.reach_tiles(way, p0..p1, s.layout, half_size)
        } else {
            (0..0, false)
        };
        let mode = record_mode(settings.capture.mode, d1 > d0, s.ground.is_some());
        self.jobs.push(Job {
            surface: PlannedSurface {
                index: s.index,
                captured,
            },
            record: SurfaceRecord {
                heights: s.heights_word,
                normals: s.normals_word.unwrap_or(NO_NORMALS),
                scratch: 0,
                width: s.layout.width,
                height: s.layout.height,
                atlas_x: 0,
                atlas_y: 0,
                mode,
                replenish_units: units,
                batch: NO_CAPTURE,
                mask_fraction: settings.capture.mask_depth,
                snow_depth: s.desc.snow_depth,
                frustum_height,
                texel_x: texel.x,
                texel_z: texel.y,
                tiles: 0,
                wrap: s.wrap,
                // The update's ray cast, set when it takes the surface (`pack_atlas`).
                half_x: 0.0,
                half_z: 0.0,
                prims: 0,
                prim_count: 0,
                ground: capture::NO_GROUND,
            },
            half_size,
            ground_offset: s.ground.map_or(capture::NO_GROUND, |g| g.offset),
            ground_codes: s.ground.map_or(0, |g| g.codes),
            prims: p0..p1,
            draws: d0..d1,
            way,
            tiles,
            sparse,
            relax: if relaxes && !rect.is_empty() {
                (steps, material.repose_degrees.unwrap_or(90.0), rect)
            } else {
                (0, 90.0, Rect::default())
            },
        });
    }

    /// The tiles that a surface's primitives `prims` reach, appended to `reached`: the update's
    /// ([`capture::update_tiles_reached`]) when it casts them, the capture region's
    /// ([`capture::tiles_reached`], with whether it takes the tiles beside them) on the compute
    /// path, none on the raster path.
    fn reach_tiles(
        &mut self,
        way: Way,
        prims: Range<u32>,
        layout: SurfaceLayout,
        half_size: Vec2,
    ) -> (Range<u32>, bool) {
        let t0 = self.reached.len() as u32;
        let prims = &self.capture.prims[prims.start as usize..prims.end as usize];
        let size = (layout.width, layout.height);
        let (seen, reached) = (&mut self.seen, &mut self.reached);
        let sparse = match way {
            Way::Raster => false,
            Way::Cast => {
                capture::update_tiles_reached(prims, size, half_size, 0, seen, reached);
                false
            }
            Way::Compute => capture::tiles_reached(prims, size, half_size, 0, seen, reached),
        };
        (t0..self.reached.len() as u32, sparse)
    }

    /// Place captured surfaces in the atlas (those the raster path captures), the capture buffer
    /// and the tile flags.
    fn pack_atlas(&mut self, settings: &PlanSettings) {
        let rendered = |j: &Job| j.surface.captured && j.way == Way::Raster;
        self.rects.extend(
            self.jobs
                .iter()
                .filter(|j| rendered(j))
                .map(|j| capture::region(j.record.width, j.record.height)),
        );
        // The atlas is cleared whole every pass, so keep it as small as the frame allows: the
        // smallest power-of-two side that holds every rectangle in one batch, up to the limit.
        let (placements, atlas_side) =
            capture::pack_atlas_compact(&self.rects, settings.atlas_side);
        let c = &mut self.capture;
        c.atlas_side = atlas_side;
        c.batches = placements.iter().map(|p| p.batch + 1).max().unwrap_or(0);
        let mut placed = placements.iter();
        for job in self.jobs.iter_mut().filter(|j| j.surface.captured) {
            let r = &mut job.record;
            if job.way == Way::Cast {
                // Nothing of it in the capture: the update casts its primitives.
                r.batch = capture::CAST;
                r.mode |= MODE_CAST;
                (r.half_x, r.half_z) = (job.half_size.x, job.half_size.y);
                (r.prims, r.prim_count) = (job.prims.start, job.prims.len() as u32);
                r.ground = job.ground_offset;
                continue;
            }
            if job.way == Way::Compute {
                r.batch = capture::COMPUTED;
            } else if let Some(p) = placed.next() {
                r.atlas_x = p.x;
                r.atlas_y = p.y;
                r.batch = p.batch;
            }
            // The surface's capture region: its texels and the apron around them.
            let region = capture::region_texels(r.width, r.height);
            r.scratch = c.texels;
            c.texels += region;
            if r.mode & MODE_GROUND != 0 {
                // The winding region's second half: the ground's codes (laid out as the region),
                // copied before the capture.
                c.ground_copies.push((job.ground_codes, c.texels, region));
                c.texels += region;
            }
            r.tiles = c.tile_flags;
            c.tile_flags += r.tile_count();
        }
    }

    /// The accumulation's dispatch shape: which records the refill streams, whether the fused
    /// pass lists its tiles, what its grid covers, and whether every capture region is cleared.
    fn accumulation_shape(&mut self, settings: &PlanSettings) {
        let dense = self
            .jobs
            .iter()
            .take_while(|j| j.record.replenish_units > 0)
            .count();
        let fused = settings.fused();
        let words = |j: &Job| {
            settings
                .format
                .heights_bytes(j.record.width, j.record.height)
                / 4
        };
        let refill_words: u64 = self.jobs[..dense].iter().map(words).sum();
        // Snowfall over many words is refilled by the streaming pass (the records so marked);
        // over few, by the fused pass: its grid over every tile of the refilling records it
        // captures, and the plan's list of every tile of those it casts.
        let stream = fused && dense > 0 && refill_words >= settings.refill_stream_from as u64;
        let cast_first = self.jobs[..dense]
            .iter()
            .take_while(|j| j.way == Way::Cast)
            .count();
        let captured_end = dense
            + self.jobs[dense..]
                .iter()
                .take_while(|j| j.way != Way::Cast)
                .count();
        let tiled = if stream { cast_first } else { dense };
        // The fused pass visits the other records' tiles only where the capture reached (those it
        // casts, where the plan lists them).
        let flagged: u64 = self.jobs[tiled..captured_end]
            .iter()
            .filter(|j| j.surface.captured)
            .map(|j| j.record.tile_count() as u64)
            .sum();
        let listed = fused && flagged > 0 && flagged >= settings.list_tiles_from as u64;
        self.capture.clear_all = !fused;
        let a = &mut self.accumulate;
        a.fused = fused;
        a.normals = settings.format.normals;
        a.unit_texels = settings.format.precision.unit_texels();
        a.refill = if stream { dense as u32 } else { 0 };
        a.refill_words = self.jobs[..a.refill as usize]
            .iter()
            .map(|j| words(j) as u32)
            .max()
            .unwrap_or(0);
        a.listed = listed;
        // Without the list, the grid covers every record it captures; with it, the records whose
        // every tile it refills. It starts after the cast records that refill snow.
        self.capture.grid_first = cast_first as u32;
        a.grid = if listed { tiled } else { captured_end }.saturating_sub(cast_first) as u32;
        a.max_width = self.jobs.iter().map(|j| j.record.width).max().unwrap_or(1);
        a.max_height = self.jobs.iter().map(|j| j.record.height).max().unwrap_or(1);
    }

    /// Records, views, the accumulation's dispatch shape and the buffer sizes.
    fn write_tables(&mut self, settings: &PlanSettings) {
        self.accumulation_shape(settings);
        let prims = self.prims_len() * std::mem::size_of::<capture::GpuPrimitive>();
        let a = &mut self.accumulate;
        let c = &mut self.capture;
        for (j, job) in self.jobs.iter().enumerate() {
            self.surfaces.push(job.surface);
            let mut record = job.record;
            if j < a.refill as usize {
                record.mode |= MODE_REFILLED;
            }
            a.records.push(record);
            if job.way == Way::Cast {
                let r = &record;
                if r.replenish_units > 0 && r.mode & MODE_REFILLED == 0 {
                    // The fused pass refills it: every tile.
                    let tiles_x = r.width.div_ceil(TILE_SIDE);
                    c.listed.extend(
                        (0..r.tile_count())
                            .map(|t| [j as u32, ((t / tiles_x) << 16) | (t % tiles_x)]),
                    );
                } else if self.tiles_early {
                    let tiles = &self.reached[job.tiles.start as usize..job.tiles.end as usize];
                    c.listed
                        .extend(tiles.iter().map(|&[_, tile]| [j as u32, tile]));
                } else {
                    let prims = &c.prims[job.prims.start as usize..job.prims.end as usize];
                    let (size, seen) = ((r.width, r.height), &mut self.seen);
                    let (half, list) = (job.half_size, &mut c.listed);
                    capture::update_tiles_reached(prims, size, half, j as u32, seen, list);
                }
            }
            if !job.surface.captured || job.way == Way::Cast {
                continue;
            }
            let r = &job.record;
            c.surfaces.push(CapturedSurface {
                record: j as u32,
                batch: r.batch,
                x: r.atlas_x,
                y: r.atlas_y,
                width: r.width,
                height: r.height,
                prims: job.prims.clone(),
                draws: job.draws.clone(),
                compute: job.way == Way::Compute,
                cleared: true,
            });
            let mut whole = 0;
            if job.way == Way::Compute {
                let view = c.views.len() as u32;
                let sparse = if self.tiles_early {
                    let tiles = &self.reached[job.tiles.start as usize..job.tiles.end as usize];
                    c.work.extend(tiles.iter().map(|&[_, tile]| [view, tile]));
                    job.sparse
                } else {
                    let prims = &c.prims[job.prims.start as usize..job.prims.end as usize];
                    let (size, seen) = ((r.width, r.height), &mut self.seen);
                    capture::tiles_reached(prims, size, job.half_size, view, seen, &mut c.work)
                };
                if let Some(s) = c.surfaces.last_mut() {
                    s.cleared = !sparse;
                }
                whole = u32::from(sparse);
            }
            c.views.push(CaptureView {
                half_size: job.half_size.to_array(),
                frustum_height: r.frustum_height,
                offset: r.scratch,
                origin: [r.atlas_x as f32, r.atlas_y as f32],
                texels: [r.width as f32, r.height as f32],
                tiles: r.tiles,
                tiles_x: r.width.div_ceil(TILE_SIDE),
                record: if a.listed { j as u32 } else { capture::NO_LIST },
                ground: job.ground_offset,
                prims: if job.way == Way::Compute {
                    [job.prims.start, job.prims.len() as u32]
                } else {
                    [0, 0]
                },
                whole,
                _pad: 0,
            });
        }
        a.cast_tiles = c.listed.len() as u32;
        a.cast_many = a.cast_tiles >= settings.cast_many_from;
        c.plan_clears();
        if self.jobs.is_empty() {
            return;
        }
        let max = settings.format.precision.channel_max();
        for job in self.jobs.iter().filter(|j| j.relax.0 > 0) {
            let r = &job.record;
            let (steps, repose, rect) = job.relax;
            let (rw, rh) = rect.size();
            let threshold = |texel| crate::relax::cpu::threshold(repose, texel, r.snow_depth, max);
            self.relax.push(
                RelaxRecord {
                    heights: r.heights,
                    width: r.width,
                    height: r.height,
                    scratch: 0,
                    threshold_x: threshold(r.texel_x),
                    threshold_z: threshold(r.texel_z),
                    rect: [rect.x0, rect.y0, rw, rh],
                    dispatch_steps: 0,
                    tiles: 0,
                    wrap: r.wrap,
                },
                steps,
                settings.format.precision.unit_texels(),
            );
        }
        self.relax.schedule();
        let texels = c.texels.max(1) as u64 * 4;
        self.sizes = BufferSizes {
            records: (a.records.len() * std::mem::size_of::<SurfaceRecord>()) as u64,
            views: c.views.len().max(1) as u64 * UNIFORM_STRIDE
                + if c.work.is_empty() {
                    0
                } else {
                    capture::work_table_bytes(c) - c.views.len() as u64 * UNIFORM_STRIDE
                },
            prims: prims as u64,
            draws: c.draws.len() as u64 * UNIFORM_STRIDE,
            // The blurred capture goes through memory only when blur and merge are separate.
            scratch: if self.accumulate.fused { 0 } else { texels },
            capture: texels,
            winding: c.winding_texels() as u64 * 4,
            tiles: c.tile_flags.max(1) as u64 * 4,
            tile_list: (TILE_LIST_HEADER + 2 * (c.tile_flags as u64 + c.listed.len() as u64)) * 4,
            relax_records: std::mem::size_of_val(self.relax.records.as_slice()) as u64,
            relax_scratch: self.relax.scratch_words as u64 * 4,
            relax_tiles: self.relax.tile_words as u64 * 4,
        };
    }
}

/// Milliseconds since `start`.
pub(crate) fn elapsed_ms(start: std::time::Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
