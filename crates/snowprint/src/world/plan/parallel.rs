//! A frame of many surfaces planned on several threads. The surfaces are cut into contiguous
//! runs, several a thread ([`RUNS_A_THREAD`]); each thread takes the next run not yet taken and
//! plans it into a partial plan of its own (the per-surface work: replenishment, culling,
//! sweeping, the footstep test, the tiles reached), so that a thread slowed by another process
//! leaves its share to the others. The threads are kept, parked, from frame to frame
//! ([`Planners`]). The runs are then appended in order, their ranges shifted,
//! before the frame's own work (`FramePlan::finish`). The primitives, most of a frame's bytes,
//! are not appended: they stay in the parts, after the first run's, and are written to the GPU
//! from there ([`FramePlan::prims`]), copied once rather than twice. The plan is the one
//! [`FramePlan::rebuild`] makes of the same surfaces, vector for vector and byte for byte
//! (`tests.rs`, `split_plan_is_the_serial_plan`).

use super::{FramePlan, PlanMeshes, PlanSettings, PlanSurface};
use crate::capture::GpuPrimitive;

/// Fewest surfaces in a frame from which its plan is split over threads: below it, starting the
/// threads costs more than the work they share (tens of microseconds, against about a microsecond
/// a surface). On the H100's 16-core host two threads of 128 surfaces took 0.30 to 0.34 ms
/// against one thread's 0.25 to 0.26 (`docs/PERFORMANCE.md`, "The CPU's frame build and encode on
/// the H100's host").
pub(crate) const SPLIT_FROM: usize = 512;

/// Fewest surfaces a split plan has a thread for: a frame of `n` surfaces is planned on at most
/// `n / RUN_MIN` threads (each of which may take more or fewer, as the runs come).
pub(crate) const RUN_MIN: usize = 128;

/// Runs a split plan cuts its surfaces into, a thread (runs of [`RUN_MIN`] / 4 surfaces at least).
pub(crate) const RUNS_A_THREAD: usize = 8;

/// Most threads a plan is split over when the world leaves the count to the machine
/// ([`crate::WorldConfig::plan_threads`] 0): past it, the serial work of the frame (the appends,
/// the tables, the upload) leaves little to gain.
pub(crate) const AUTO_THREADS_MAX: usize = 8;

/// The threads to plan over when the world's configuration asks for `threads` (0: the machine's
/// available parallelism, up to [`AUTO_THREADS_MAX`]).
pub(crate) fn plan_threads(threads: usize) -> usize {
    // Asked once a process: on Linux the answer reads the cgroup's quota from files.
    static AUTO: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    if threads > 0 {
        return threads;
    }
    *AUTO.get_or_init(|| {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(AUTO_THREADS_MAX)
    })
}

/// Run `work` on `threads` threads, this one among them: half of the others are started by a
/// new thread, which starts half of its own likewise, and so on, so that the last thread starts
/// after a few spawns rather than one spawn a thread (tens of microseconds each on the H100's
/// host).
fn fan_out<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    mut threads: usize,
    work: &'scope (impl Fn() + Sync),
) {
    while threads > 1 {
        let later = threads / 2;
        threads -= later;
        scope.spawn(move || fan_out(scope, later, work));
    }
    work();
}

/// The threads a split plan runs on, kept from frame to frame: a pool of `threads - 1` parked
/// workers (the calling thread is the last), made at the first frame that splits over `threads`
/// and again when the count changes. Waking a parked thread costs a fraction of starting one: on
/// the H100's host, 4096 surfaces planned on 8 threads took 2.5 to 2.8 ms a frame with the pool
/// against 3.1 to 3.8 ms with threads started each frame, 1024 surfaces 0.7 against 1.3 to 1.5
/// (`docs/PERFORMANCE.md`, "Plan threads kept between frames"). Without a pool (one could not be
/// made) the threads are started for the frame, as scoped threads.
#[derive(Clone, Debug, Default)]
pub(crate) struct Planners {
    pool: Option<(usize, std::sync::Arc<rayon::ThreadPool>)>,
}

impl Planners {
    /// The pool for `threads` threads (`None`: start them for this frame).
    fn pool(&mut self, threads: usize) -> Option<&rayon::ThreadPool> {
        if threads < 2 {
            return None;
        }
        if self.pool.as_ref().is_none_or(|(n, _)| *n != threads) {
            self.pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads - 1)
                .thread_name(|i| format!("snowprint plan {i}"))
                .build()
                .ok()
                .map(|pool| (threads, std::sync::Arc::new(pool)));
        }
        self.pool.as_ref().map(|(_, pool)| &**pool)
    }
}

/// Run `each` on every item of `work`, on `threads` threads (this one among them; the others
/// `planners`'), each taking the next item not yet taken.
fn in_parallel<W: Send>(
    planners: &mut Planners,
    threads: usize,
    work: impl Iterator<Item = W> + Send,
    each: impl Fn(W) + Sync,
) {
    let work = std::sync::Mutex::new(work);
    let next = || {
        let mut work = work
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        work.next()
    };
    let take = || {
        while let Some(w) = next() {
            each(w);
        }
    };
    match planners.pool(threads) {
        Some(pool) => pool.in_place_scope(|scope| {
            for _ in 1..threads {
                scope.spawn(|_| take());
            }
            take();
        }),
        None => std::thread::scope(|scope| fan_out(scope, threads, &take)),
    }
}

impl FramePlan {
    /// [`FramePlan::rebuild`] of the surfaces that `surface` makes of `items` (skipping those it
    /// gives `None` for), split over up to `threads` threads when there are at least
    /// [`SPLIT_FROM`] items: the same plan, made sooner.
    pub(crate) fn rebuild_split<'a, T: Sync>(
        &mut self,
        settings: &PlanSettings,
        items: &'a [T],
        surface: impl Fn(&'a T) -> Option<PlanSurface<'a>> + Sync,
        meshes: impl PlanMeshes + Sync,
        threads: usize,
    ) {
        let threads = threads.min(items.len() / RUN_MIN).max(1);
        if threads == 1 || items.len() < SPLIT_FROM {
            self.rebuild(settings, items.iter().filter_map(surface), meshes);
            return;
        }
        self.clear();
        self.tiles_early = true;
        // The first run is planned into the plan itself (nothing of it to copy), the others each
        // into a part of their own, appended after it.
        let run = items
            .len()
            .div_ceil(threads * RUNS_A_THREAD)
            .max(RUN_MIN / 4);
        let runs = items.chunks(run);
        let mut parts = std::mem::take(&mut self.parts);
        parts.resize_with(runs.len() - 1, FramePlan::default);
        for part in &mut parts {
            part.clear();
            part.check_short_lists = self.check_short_lists;
            part.tiles_early = true;
        }
        let (surface, meshes) = (&surface, &meshes);
        let plan_run = |plan: &mut FramePlan, run: &'a [T]| {
            for s in run.iter().filter_map(surface) {
                plan.plan_surface(settings, &s, meshes);
            }
        };
        let mut planners = std::mem::take(&mut self.planners);
        let plans = std::iter::once(&mut *self).chain(parts.iter_mut());
        let each = |(plan, run)| plan_run(plan, run);
        in_parallel(&mut planners, threads, plans.zip(runs), each);
        self.planners = planners;
        self.reserve_for(&parts);
        let mut prims = self.capture.prims.len();
        for part in &mut parts {
            self.append(part, prims);
            prims += part.capture.prims.len();
        }
        self.parts = parts;
        self.prims_in_parts = true;
        self.finish(settings);
    }

    /// The frame's primitives, in order, as runs of consecutive ones: the plan's own, then (a
    /// split plan) each part's. The jobs' ranges index their concatenation.
    pub(crate) fn prims(&self) -> impl Iterator<Item = &[GpuPrimitive]> {
        let parts = if self.prims_in_parts {
            &self.parts[..]
        } else {
            &[]
        };
        std::iter::once(&self.capture.prims[..]).chain(parts.iter().map(|p| &p.capture.prims[..]))
    }

    /// How many primitives the frame has ([`FramePlan::prims`]).
    pub(crate) fn prims_len(&self) -> usize {
        self.prims().map(<[GpuPrimitive]>::len).sum()
    }

    /// Make room for the parts' vectors at once (rather than growing as they are appended).
    fn reserve_for(&mut self, parts: &[FramePlan]) {
        let total = |f: fn(&FramePlan) -> usize| parts.iter().map(f).sum::<usize>();
        let c = &mut self.capture;
        c.draws.reserve(total(|p| p.capture.draws.len()));
        c.draw_meshes
            .reserve(total(|p| p.capture.draw_meshes.len()));
        self.reached.reserve(total(|p| p.reached.len()));
        self.carries.reserve(total(|p| p.carries.len()));
        self.settles.reserve(total(|p| p.settles.len()));
        self.footsteps.reserve(total(|p| p.footsteps.len()));
        self.jobs.reserve(total(|p| p.jobs.len()));
    }

    /// Append a partial plan of the surfaces after this plan's, as if they had been planned
    /// here: its jobs' ranges of draws and tiles shifted past this plan's, and of primitives past
    /// the `prims` of the runs before it (which stay where they were planned).
    fn append(&mut self, part: &mut FramePlan, prims: usize) {
        let shift = |r: &std::ops::Range<u32>, by: usize| r.start + by as u32..r.end + by as u32;
        let c = &mut self.capture;
        let (draws, tiles) = (c.draws.len(), self.reached.len());
        c.draws.extend_from_slice(&part.capture.draws);
        c.draw_meshes.extend_from_slice(&part.capture.draw_meshes);
        self.reached.extend_from_slice(&part.reached);
        self.carries.extend_from_slice(&part.carries);
        self.settles.extend_from_slice(&part.settles);
        self.footsteps.extend_from_slice(&part.footsteps);
        self.jobs.extend(part.jobs.drain(..).map(|mut job| {
            job.prims = shift(&job.prims, prims);
            job.draws = shift(&job.draws, draws);
            job.tiles = shift(&job.tiles, tiles);
            job
        }));
        self.refused |= part.refused;
    }
}

#[cfg(test)]
mod tests;
