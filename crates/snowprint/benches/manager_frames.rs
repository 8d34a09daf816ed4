//! What capturing queued imprints frame by frame costs on the GPU: the sixteen roofs of
//! `scenes/roofs16.toml` (a sphere crossing each in 1.4 s) run for 120 frames under a budget of 2
//! updates a frame, where a roof waits about 8 frames and then catches up frame by frame, against
//! the same run with no budget (every roof updated every frame), and with `CatchUp::Union` (one
//! update per roof whatever it waited), each to a flush and the GPU idle.
//!
//! `cargo bench -p snowprint --bench manager_frames -- --warm-up-time 1 --measurement-time 10`.
//! Results: `docs/PERFORMANCE.md`, "Frame-by-frame catch-up".

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use snowprint::manager::{CatchUp, ManagedDeformer, ManagerConfig, SnowManager, UNLIMITED, ZoneId};
use snowprint::{Deformer, GpuContext, GpuOptions, Pose, Shape, SurfaceDesc};

const DT: f32 = 1.0 / 60.0;
const FRAMES: u32 = 120;

fn roofs() -> Vec<SurfaceDesc> {
    (0..16)
        .map(|i| {
            let (x, z) = ((i % 5) as f32 * 6.0, (i / 5) as f32 * 6.0);
            SurfaceDesc::new(&format!("roof{i}"), [x, 4.0, z], [4.0, 4.0], 0.15)
        })
        .collect()
}

fn spheres(roofs: &[SurfaceDesc], f: u32) -> Vec<ManagedDeformer> {
    let at = |f: u32, r: &SurfaceDesc| {
        let t = (f as f32 * DT / 1.4).min(1.0);
        Pose::at([r.center.x - 2.6 + 5.2 * t, 4.35, r.center.z + 0.3])
    };
    roofs
        .iter()
        .map(|r| {
            ManagedDeformer::new(Deformer::moving(
                Shape::Sphere { radius: 0.3 },
                at(f.saturating_sub(1), r),
                at(f, r),
            ))
        })
        .collect()
}

/// One whole run; returns the world updates it recorded (frames captured, summed over ticks).
fn run(gpu: &GpuContext, updates_per_frame: usize, catch_up: CatchUp) -> usize {
    let roofs = roofs();
    let mut m = SnowManager::new(
        gpu,
        ManagerConfig {
            updates_per_frame,
            catch_up,
            active_distance: 500.0,
            ..ManagerConfig::default()
        },
    )
    .expect("manager");
    let ids: Vec<_> = roofs
        .iter()
        .map(|r| m.add_surface(r.clone(), ZoneId(0)).expect("surface"))
        .collect();
    let mut updated = 0;
    for f in 1..=FRAMES {
        updated += m
            .tick(DT, None, &spheres(&roofs, f))
            .expect("tick")
            .updated
            .len();
    }
    m.flush().expect("flush");
    // Wait for the GPU: the run is done when the last heightmap can be read.
    black_box(m.read_heightmap(ids[15]).expect("read"));
    updated
}

fn frames(c: &mut Criterion) {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    println!(
        "manager_frames on {}: surface updates in a run: budget 2 {}, no budget {}",
        gpu.info.name,
        run(&gpu, 2, CatchUp::FrameByFrame),
        run(&gpu, UNLIMITED, CatchUp::FrameByFrame)
    );
    let mut g = c.benchmark_group("manager_frames");
    g.sample_size(10);
    g.bench_function(
        "16 roofs, 120 frames, budget 2 (catching up frame by frame)",
        |b| b.iter(|| run(&gpu, 2, CatchUp::FrameByFrame)),
    );
    g.bench_function("16 roofs, 120 frames, budget 2, CatchUp::Union", |b| {
        b.iter(|| run(&gpu, 2, CatchUp::Union))
    });
    g.bench_function("16 roofs, 120 frames, no budget", |b| {
        b.iter(|| run(&gpu, UNLIMITED, CatchUp::FrameByFrame))
    });
    g.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
