//! A frame of many surfaces planned on several threads. The surfaces are cut into contiguous
//! runs, several a thread ([`RUNS_A_THREAD`]); each thread takes the next run not yet taken and
//! plans it into a partial plan of its own (the per-surface work: replenishment, culling,
//! sweeping, the footstep test, the tiles reached), so that a thread slowed by another process
//! leaves its share to the others. The threads are kept, parked, from frame to frame
//! ([`Planners`]). The runs are then gathered on the threads too, each part's vectors copied to
//! their place in the plan's, their ranges shifted ([`FramePlan::gather`]), before the frame's own
//! work (`FramePlan::finish`). The primitives, most of a frame's bytes, are not appended: they
//! stay in the parts, after the first run's, and are copied from there straight into the GPU's
//! staging memory when the caller gives it ([`PrimsTarget`]), each run's by the thread that
//! gathers it, else written to the GPU from the parts ([`FramePlan::prims`]); either way copied
//! once rather than twice. The plan is the one [`FramePlan::rebuild`] makes of the same surfaces,
//! vector for vector and byte for byte
//! (`tests.rs`, `split_plan_is_the_serial_plan`).

use super::{FramePlan, Job, PlanMeshes, PlanSettings, PlanSurface};
use crate::capture::{GpuPrimitive, MeshDraw};
use crate::gpu::resources::fill_runs;
use crate::mesh::MeshId;
use crate::relax::Settle;
use crate::world::Footstep;

/// Fewest surfaces in a frame from which its plan is split over threads: below it, waking the
/// threads and gathering their runs cost more than the work they share (about a microsecond a
/// surface). With the threads kept between frames ([`Planners`]), on the H100's 16-core host 128
/// surfaces took 0.17 to 0.21 ms split against 0.24 to 0.27 on one thread, 256 surfaces 0.24 to
/// 0.28 against 0.37 to 0.47 (`docs/PERFORMANCE.md`, "Plan threads kept between frames"); 64
/// took 0.07 ms to plan on one thread, too little to share.
pub(crate) const SPLIT_FROM: usize = 128;

/// Fewest surfaces a split plan has a thread for: a frame of `n` surfaces is planned on at most
/// `n / RUN_MIN` threads (each of which may take more or fewer, as the runs come).
pub(crate) const RUN_MIN: usize = 32;

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

/// Start `threads - 1` threads running `work` besides this one: half of them by a new thread,
/// which starts half of its own likewise, and so on, so that the last thread starts after a few
/// spawns rather than one spawn a thread (tens of microseconds each on the H100's host).
fn start_others<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    mut threads: usize,
    work: &'scope (impl Fn() + Sync),
) {
    while threads > 1 {
        let later = threads / 2;
        threads -= later;
        scope.spawn(move || {
            start_others(scope, later, work);
            work();
        });
    }
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
/// `planners`'), each taking the next item not yet taken; this thread runs `first` before it takes
/// any.
fn in_parallel<W: Send>(
    planners: &mut Planners,
    threads: usize,
    work: impl Iterator<Item = W> + Send,
    each: impl Fn(W) + Sync,
    first: impl FnOnce(),
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
            first();
            take();
        }),
        None => std::thread::scope(|scope| {
            start_others(scope, threads, &take);
            first();
            take();
        }),
    }
}

impl FramePlan {
    /// [`FramePlan::rebuild`] of the surfaces that `surface` makes of `items` (skipping those it
    /// gives `None` for), split over up to `threads` threads when there are at least
    /// [`SPLIT_FROM`] items: the same plan, made sooner. A split plan's primitives go to
    /// `prims` when it opens memory for them ([`FramePlan::prims_written`]).
    pub(crate) fn rebuild_split<'a, T: Sync>(
        &mut self,
        settings: &PlanSettings,
        items: &'a [T],
        surface: impl Fn(&'a T) -> Option<PlanSurface<'a>> + Sync,
        meshes: impl PlanMeshes + Sync,
        (threads, prims): (usize, Option<&mut impl PrimsTarget>),
    ) {
        let threads = threads.min(items.len() / RUN_MIN).max(1);
        if threads == 1 || items.len() < SPLIT_FROM {
            self.rebuild(settings, items.iter().filter_map(surface), meshes);
            return;
        }
        let start = std::time::Instant::now();
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
        in_parallel(&mut planners, threads, plans.zip(runs), each, || ());
        let planned = std::time::Instant::now();
        let runs = std::iter::once(&*self).chain(&parts);
        let lens: Vec<usize> = runs
            .map(|p| size_of_val(p.capture.prims.as_slice()))
            .collect();
        let out = prims.and_then(|p| p.open(&lens)).filter(|o| match o {
            Opened::Pieces(pieces) => pieces.len() == lens.len(),
            Opened::Whole(whole) => whole.len() == lens.iter().sum::<usize>(),
        });
        self.prims_written = out.is_some();
        self.gather(&mut planners, &parts, threads, out);
        self.planners = planners;
        self.laps = crate::CpuSteps {
            plan_ms: (planned - start).as_secs_f64() * 1e3,
            gather_ms: super::elapsed_ms(planned),
            ..Default::default()
        };
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

    /// Append the partial plans of the surfaces after this plan's, as if they had been planned
    /// here, on up to `threads` threads, a part at a time: their jobs' ranges of primitives, draws
    /// and tiles shifted past the runs' before them. `prims`, when given, holds a piece of memory
    /// for each run's primitives, this plan's first (`None` for a run without): the thread that
    /// gathers a part copies its primitives into its piece (they stay where they were planned,
    /// too).
    fn gather<P: PrimsPiece>(
        &mut self,
        planners: &mut Planners,
        parts: &[FramePlan],
        threads: usize,
        prims: Option<Opened<'_, P>>,
    ) {
        let own = &self.capture.prims;
        let (mut pieces_of, whole) = match prims {
            Some(Opened::Pieces(pieces)) => (Some(pieces.into_iter()), None),
            Some(Opened::Whole(whole)) => (None, Some(whole)),
            None => (None, None),
        };
        let mut next_piece = || pieces_of.as_mut().and_then(Iterator::next).flatten();
        let own_piece = next_piece();
        // This thread's share: its own run's piece, or every run into one piece of memory that
        // cannot be handed to another thread.
        let copy_own = move || {
            if let Some(piece) = own_piece {
                piece.fill(bytemuck::cast_slice(own));
            }
            if let Some(out) = whole {
                let runs = std::iter::once(own).chain(parts.iter().map(|p| &p.capture.prims));
                fill_runs(out, runs.map(|run| bytemuck::cast_slice(run)));
            }
        };
        let mut shift = [own.len(), self.capture.draws.len(), self.reached.len()];
        let c = (&mut self.capture.draws, &mut self.capture.draw_meshes);
        let mut jobs = pieces(&mut self.jobs, parts, |p| &p.jobs).into_iter();
        let mut draws = pieces(c.0, parts, |p| &p.capture.draws).into_iter();
        let mut meshes = pieces(c.1, parts, |p| &p.capture.draw_meshes).into_iter();
        let mut reached = pieces(&mut self.reached, parts, |p| &p.reached).into_iter();
        let mut carries = pieces(&mut self.carries, parts, |p| &p.carries).into_iter();
        let mut settles = pieces(&mut self.settles, parts, |p| &p.settles).into_iter();
        let mut footsteps = pieces(&mut self.footsteps, parts, |p| &p.footsteps).into_iter();
        let mut work = Vec::with_capacity(parts.len());
        for part in parts {
            let dest = Dest {
                jobs: jobs.next().unwrap_or_default(),
                draws: draws.next().unwrap_or_default(),
                draw_meshes: meshes.next().unwrap_or_default(),
                reached: reached.next().unwrap_or_default(),
                carries: carries.next().unwrap_or_default(),
                settles: settles.next().unwrap_or_default(),
                footsteps: footsteps.next().unwrap_or_default(),
                prims: next_piece(),
                shift: shift.map(|n| n as u32),
            };
            work.push((part, dest));
            shift[0] += part.capture.prims.len();
            shift[1] += part.capture.draws.len();
            shift[2] += part.reached.len();
            self.refused |= part.refused;
        }
        // The same threads as the planning (a pool of another size would be made anew).
        in_parallel(
            planners,
            threads,
            work.into_iter(),
            |(part, dest)| dest.fill(part),
            copy_own,
        );
    }
}

/// Memory for a split plan's primitives, opened once every run is planned: staging memory for the
/// frame's primitives buffer (`world/staging.rs`).
pub(crate) trait PrimsTarget {
    /// A piece of memory.
    type Piece: PrimsPiece;

    /// Memory for runs of `lens` bytes, laid end to end, or `None` (the primitives are then
    /// written from the parts, [`FramePlan::prims`]).
    fn open(&mut self, lens: &[usize]) -> Option<Opened<'_, Self::Piece>>;
}

/// Memory a [`PrimsTarget`] opened.
pub(crate) enum Opened<'m, P> {
    /// A piece a run, in order (`None` for an empty run), each filled by the thread that gathers
    /// its run.
    Pieces(Vec<Option<P>>),
    /// The runs' bytes together, filled by the calling thread (wgpu's `WriteOnly` memory cannot
    /// be handed to another thread).
    Whole(wgpu::WriteOnly<'m, [u8]>),
}

/// A piece of memory for one run's primitives, filled by the thread that gathers the run.
pub(crate) trait PrimsPiece: Send {
    /// Copy `bytes` here (exactly the piece's length).
    fn fill(self, bytes: &[u8]);
}

impl PrimsPiece for wgpu::BufferViewMut {
    fn fill(mut self, bytes: &[u8]) {
        self.copy_from_slice(bytes);
    }
}

/// No memory: a split plan's primitives stay in its parts.
pub(crate) struct NoPrims;

impl PrimsTarget for NoPrims {
    type Piece = wgpu::BufferViewMut;

    fn open(&mut self, _lens: &[usize]) -> Option<Opened<'_, Self::Piece>> {
        None
    }
}

/// The pieces of `v`, grown past its length by every part's elements (`of` a part), in the
/// parts' order: where [`FramePlan::gather`] copies each part's. The new elements hold a copy of
/// one of the parts' until then.
fn pieces<'d, T: Clone>(
    v: &'d mut Vec<T>,
    parts: &[FramePlan],
    of: impl Fn(&FramePlan) -> &[T],
) -> Vec<&'d mut [T]> {
    let start = v.len();
    if let Some(fill) = parts.iter().find_map(|p| of(p).first()) {
        let total = parts.iter().map(|p| of(p).len()).sum::<usize>();
        v.resize(start + total, fill.clone());
    }
    let mut rest = &mut v[start..];
    parts
        .iter()
        .map(|p| {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(of(p).len());
            rest = tail;
            head
        })
        .collect()
}

/// Where one part's vectors go in the plan's ([`FramePlan::gather`]), and its primitives, and how
/// far its jobs' ranges of primitives, draws and tiles shift.
struct Dest<'d, P> {
    jobs: &'d mut [Job],
    draws: &'d mut [MeshDraw],
    draw_meshes: &'d mut [MeshId],
    reached: &'d mut [[u32; 2]],
    carries: &'d mut [(usize, f64)],
    settles: &'d mut [(usize, Settle)],
    footsteps: &'d mut [Footstep],
    prims: Option<P>,
    shift: [u32; 3],
}

impl<P: PrimsPiece> Dest<'_, P> {
    /// Copy `part`'s vectors here, its jobs' ranges shifted.
    fn fill(self, part: &FramePlan) {
        let shifted = |r: &std::ops::Range<u32>, by: u32| r.start + by..r.end + by;
        let [prims, draws, tiles] = self.shift;
        for (to, job) in self.jobs.iter_mut().zip(&part.jobs) {
            to.clone_from(job);
            to.prims = shifted(&job.prims, prims);
            to.draws = shifted(&job.draws, draws);
            to.tiles = shifted(&job.tiles, tiles);
        }
        self.draws.copy_from_slice(&part.capture.draws);
        self.draw_meshes.copy_from_slice(&part.capture.draw_meshes);
        self.reached.copy_from_slice(&part.reached);
        self.carries.copy_from_slice(&part.carries);
        self.settles.copy_from_slice(&part.settles);
        self.footsteps.copy_from_slice(&part.footsteps);
        if let Some(piece) = self.prims {
            piece.fill(bytemuck::cast_slice(&part.capture.prims));
        }
    }
}

#[cfg(test)]
mod tests;
