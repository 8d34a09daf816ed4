//! What capturing analytic deformers costs on each of the capture's paths: the compute path (one
//! dispatch for every surface, `CapturePath::Compute`) against the raster path (a viewport and a draw
//! per surface, `CapturePath::Raster`), for many small surfaces of 128^2 with 10 moving spheres
//! each and the talk's frame (2 x 512^2, 10 each), from the world's per-pass GPU timestamps and
//! the CPU time of the update's encoding (each surface handed its own spheres): medians over the
//! measured frames, both paths in one run.
//!
//! `cargo bench -p snowprint --bench capture` (prints a table; needs timestamp queries);
//! `-- --quick` measures fewer frames and surfaces (for software Vulkan); `-- --wall` also times
//! each frame waited for on the CPU.
//! Results: `docs/PERFORMANCE.md`, "The capture in compute".

use snowprint::{
    CapturePath, Deformer, GpuContext, GpuOptions, PoolFormat, Pose, Shape, SnowWorld, StageTimes,
    SurfaceDesc, SurfaceUpdate, WorldConfig,
};

/// Frames run before measuring, and measured: full and `--quick`.
const FULL: (u32, u32) = (20, 100);
const QUICK: (u32, u32) = (5, 20);

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Median (capture, whole update, CPU encode) milliseconds of `surfaces` surfaces of `side`
/// texels, each pressed by `spheres` moving spheres, captured by `path`.
fn run(
    gpu: &GpuContext,
    (warmup, frames): (u32, u32),
    (surfaces, side, spheres): (u32, u32, u32),
    path: CapturePath,
    wall_clock: bool,
) -> (f64, f64, f64, f64) {
    let format = PoolFormat::default();
    let metres = side as f32 * 0.04;
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: format.slot_bytes(side, side) * surfaces as u64,
            atlas_side: 8192.min(gpu.caps.max_texture_side),
            max_resolution: side.max(512),
            format,
            capture_path: path,
            ..Default::default()
        },
    )
    .expect("world");
    world.set_profiling(true);
    let (mut centers, mut ids) = (Vec::new(), Vec::new());
    for i in 0..surfaces {
        let c = [
            (i % 64) as f32 * (metres + 1.0),
            0.0,
            (i / 64) as f32 * (metres + 1.0),
        ];
        ids.push(
            world
                .add_surface(SurfaceDesc::new(&format!("s{i}"), c, [metres, metres], 0.3))
                .expect("surface"),
        );
        centers.push(c);
    }
    let mut times: Vec<(u64, StageTimes)> = Vec::new();
    let mut cpu = Vec::new();
    let mut wall = Vec::new();
    let mut first_measured = 0;
    let reach = metres * 0.4;
    for f in 0..warmup + frames {
        if f == warmup {
            first_measured = f as u64 + 1;
        }
        let t = f as f32 / 60.0;
        // Each surface is handed its own spheres, as a game that knows which surface a body
        // stands on does (`SnowWorld::step` would offer every surface every sphere).
        let lists: Vec<Vec<Deformer>> = centers
            .iter()
            .map(|c| {
                (0..spheres)
                    .map(|k| {
                        let a = t + k as f32 * 0.9;
                        let at = |a: f32| {
                            Pose::at([c[0] + reach * a.cos(), 0.3, c[2] + reach * (a * 1.3).sin()])
                        };
                        Deformer::moving(Shape::Sphere { radius: 0.15 }, at(a - 1.0 / 60.0), at(a))
                    })
                    .collect()
            })
            .collect();
        let updates: Vec<SurfaceUpdate<'_>> = ids
            .iter()
            .zip(&lists)
            .map(|(&surface, deformers)| SurfaceUpdate {
                surface,
                elapsed: 1.0 / 60.0,
                deformers,
            })
            .collect();
        let start = std::time::Instant::now();
        let stats = world.update(&updates).expect("update");
        if f >= warmup {
            cpu.push(stats.cpu_encode_ms);
            if wall_clock {
                gpu.wait_idle().expect("idle");
                wall.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        if let (Some(frame), Some(g)) = (stats.gpu_frame, stats.gpu) {
            times.push((frame, g));
        }
    }
    gpu.wait_idle().expect("idle");
    while let Some(late) = world.take_gpu_times().expect("times") {
        times.push(late);
    }
    let measured = times.iter().filter(|(f, _)| *f >= first_measured);
    let (mut capture, mut total): (Vec<f64>, Vec<f64>) =
        measured.map(|(_, t)| (t.capture_ms, t.total_ms())).unzip();
    (
        median(&mut capture),
        median(&mut total),
        median(&mut cpu),
        median(&mut wall),
    )
}

fn main() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    if !gpu.caps.timestamps {
        eprintln!("capture: this adapter has no timestamp queries; nothing to measure");
        return;
    }
    let quick = std::env::args().any(|a| a == "--quick");
    // Each frame waited for, timed on the CPU: what a software adapter's time is spent on, where
    // the passes' timestamps do not say.
    let wall_clock = std::env::args().any(|a| a == "--wall");
    let counts = if quick { QUICK } else { FULL };
    let frames: &[(u32, u32, u32)] = if quick {
        &[(2, 512, 10), (16, 128, 10), (64, 128, 10)]
    } else {
        &[
            (2, 512, 10),
            (256, 128, 10),
            (1024, 128, 10),
            (4096, 128, 10),
        ]
    };
    println!("capture on {}", gpu.info.name);
    println!(
        "{:<22} {:>12} {:>12} {:>8} {:>12} {:>12} {:>10} {:>10}",
        "frame",
        "compute_us",
        "raster_us",
        "ratio",
        "upd_comp_us",
        "upd_rast_us",
        "cpu_comp",
        "cpu_rast"
    );
    for &(surfaces, side, spheres) in frames {
        let shape = (surfaces, side, spheres);
        let (cc, ct, cu, cw) = run(&gpu, counts, shape, CapturePath::Compute, wall_clock);
        let (rc, rt, ru, rw) = run(&gpu, counts, shape, CapturePath::Raster, wall_clock);
        println!(
            "{:<22} {:>12.1} {:>12.1} {:>8.2} {:>12.1} {:>12.1} {:>10.3} {:>10.3}",
            format!("{surfaces} x {side}^2, {spheres} each"),
            cc * 1e3,
            rc * 1e3,
            cc / rc,
            ct * 1e3,
            rt * 1e3,
            cu,
            ru
        );
        if wall_clock {
            println!(
                "{:<22} wall ms a frame (step + wait): compute {cw:.2}, raster {rw:.2}",
                ""
            );
        }
    }
}
