//! One tick of the surface manager's planner (spatial lookup, activity, residency, budget) in a
//! generated city of 10,000 surfaces with 1,000 deformers (500 walkers, two feet each), beside the
//! same tick with the lookup replaced by brute force (every deformer against every surface, every
//! surface against the camera), measured in the same run.
//!
//! Two groups: `wall` (criterion's wall clock) and `cpu` (the CPU time of the benchmark's own
//! thread, from `/proc/thread-self/schedstat`), which does not count the time other processes
//! took the core from it, on a machine shared with others. The kernel updates that counter at
//! scheduler events only (every few milliseconds), so the `cpu` group takes 10 long samples of
//! equal size rather than criterion's usual 100 growing ones.
//!
//! `cargo bench -p snowprint --bench manager_tick -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;
use std::time::Instant;

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use snowprint::manager::{CameraView, Lookup, ManagedDeformer, ManagerConfig, Planner};
use snowprint_demo::city;

const SURFACES: usize = 10_000;
const WALKERS: usize = 500;
/// Frames of motion precomputed and cycled through (4 s at 60 Hz).
const FRAMES: u64 = 240;
const DT: f32 = 1.0 / 60.0;

struct Run {
    planner: Planner,
    frames: Vec<(CameraView, Vec<ManagedDeformer>)>,
    next: usize,
}

impl Run {
    fn new(lookup: Lookup) -> Self {
        let c = city::generate(2014, SURFACES, WALKERS);
        let mut planner = Planner::new(&ManagerConfig::default()).expect("default config");
        planner.set_lookup(lookup);
        for s in &c.surfaces {
            planner.add_surface(&s.desc, s.zone).expect("city surface");
        }
        let frames: Vec<_> = (0..FRAMES)
            .map(|f| {
                let cam = CameraView::new(&c.player_camera(f as f32 * DT), 16.0 / 9.0);
                (cam, c.deformers(f, DT))
            })
            .collect();
        assert_eq!(frames[0].1.len(), 2 * WALKERS);
        let mut run = Self {
            planner,
            frames,
            next: 0,
        };
        // Build the quad tree and reach a steady state before measuring.
        for _ in 0..FRAMES {
            run.tick();
        }
        run
    }

    fn tick(&mut self) -> usize {
        let (cam, deformers) = &self.frames[self.next];
        self.next = (self.next + 1) % self.frames.len();
        let plan = self
            .planner
            .tick(DT, Some(cam), deformers)
            .expect("valid frame");
        plan.updates.len() + plan.stats.touched
    }
}

/// CPU time of the calling thread, nanoseconds (wall time where `/proc` is missing).
fn thread_cpu_ns() -> u64 {
    static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| EPOCH.get_or_init(Instant::now).elapsed().as_nanos() as u64)
}

/// Criterion measurement: the thread's CPU time.
struct ThreadCpuTime;

struct Nanoseconds;

impl ValueFormatter for Nanoseconds {
    fn scale_values(&self, typical: f64, values: &mut [f64]) -> &'static str {
        let (div, unit) = if typical < 1e3 {
            (1.0, "ns")
        } else if typical < 1e6 {
            (1e3, "µs")
        } else {
            (1e6, "ms")
        };
        values.iter_mut().for_each(|v| *v /= div);
        unit
    }

    fn scale_throughputs(&self, _: f64, _: &Throughput, _: &mut [f64]) -> &'static str {
        "ns"
    }

    fn scale_for_machines(&self, _: &mut [f64]) -> &'static str {
        "ns"
    }
}

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;

    fn start(&self) -> u64 {
        thread_cpu_ns()
    }

    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns().saturating_sub(start)
    }

    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }

    fn zero(&self) -> u64 {
        0
    }

    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        &Nanoseconds
    }
}

fn ticks<M: Measurement>(c: &mut Criterion<M>, group: &str, long_samples: bool) {
    let mut group = c.benchmark_group(group);
    if long_samples {
        group
            .sample_size(10)
            .sampling_mode(criterion::SamplingMode::Flat);
    }
    let mut fast = Run::new(Lookup::QuadTree);
    let stats = fast.planner.last_plan().stats.clone();
    eprintln!(
        "steady state: {} touched, {} active, {} resident, {} due, {} waiting for memory, pool {} of {} bytes",
        stats.touched,
        stats.active,
        stats.resident,
        stats.due,
        stats.waiting_for_memory,
        stats.pool_bytes_used,
        stats.pool_bytes_budget
    );
    group.bench_function("quad_tree", |b| b.iter(|| black_box(fast.tick())));
    // Brute force takes milliseconds a tick: 10 samples of equal size keep the run short.
    group
        .sample_size(10)
        .sampling_mode(criterion::SamplingMode::Flat);
    // Built here so that filtering it out (`-- quad_tree`) skips its slow warm-up.
    group.bench_function("brute_force", |b| {
        let mut slow = Run::new(Lookup::BruteForce);
        b.iter(|| black_box(slow.tick()))
    });
    group.finish();
}

fn wall(c: &mut Criterion) {
    ticks(c, "manager_tick_wall", false);
}

fn cpu(c: &mut Criterion<ThreadCpuTime>) {
    ticks(c, "manager_tick_cpu", true);
}

criterion_group!(wall_clock, wall);
criterion_group! {
    name = cpu_time;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = cpu
}
criterion_main!(wall_clock, cpu_time);
