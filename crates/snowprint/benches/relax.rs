//! What the relaxation of a slumping material costs on the GPU: the talk's frame (2 surfaces of
//! 512^2, 10 moving spheres each) and 1024 surfaces of 512^2 (one sphere each), every surface of
//! sand (8 relaxation steps an update), against the same frames in snow (no relaxation), from the
//! world's per-pass GPU timestamps: medians over the measured frames.
//!
//! `cargo bench -p snowprint --bench relax` (prints a table; needs timestamp queries);
//! `-- --quick` measures fewer frames, and 64 surfaces instead of 1024 (for software Vulkan).
//! Results: `docs/PERFORMANCE.md`, "Relaxation".

use snowprint::{
    Deformer, GpuContext, GpuOptions, Material, PoolFormat, Pose, Shape, SnowWorld, StageTimes,
    SurfaceDesc, WorldConfig,
};

/// Frames run before measuring, and measured: full and `--quick`.
const FULL: (u32, u32) = (20, 100);
const QUICK: (u32, u32) = (5, 20);

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Median (relax, whole update) GPU milliseconds of `surfaces` 512^2 surfaces of `material`.
fn run(
    gpu: &GpuContext,
    (warmup, frames): (u32, u32),
    surfaces: u32,
    spheres: u32,
    material: Material,
) -> (f64, f64) {
    let format = PoolFormat::default();
    let side = 512.0 * 0.04;
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: format.slot_bytes(512, 512) * surfaces as u64,
            atlas_side: 8192.min(gpu.caps.max_texture_side),
            format,
            ..Default::default()
        },
    )
    .expect("world");
    world.set_profiling(true);
    let mut centers = Vec::new();
    for i in 0..surfaces {
        let c = [
            (i % 64) as f32 * (side + 1.0),
            0.0,
            (i / 64) as f32 * (side + 1.0),
        ];
        let mut desc = SurfaceDesc::new(&format!("s{i}"), c, [side, side], 0.3);
        desc.material = material;
        world.add_surface(desc).expect("surface");
        centers.push(c);
    }
    let mut times: Vec<(u64, StageTimes)> = Vec::new();
    let mut first_measured = 0;
    for f in 0..warmup + frames {
        if f == warmup {
            first_measured = f as u64 + 1;
        }
        let t = f as f32 / 60.0;
        let deformers: Vec<Deformer> = centers
            .iter()
            .flat_map(|c| {
                (0..spheres).map(move |k| {
                    let a = t + k as f32;
                    let at = |a: f32| {
                        Pose::at([c[0] + 6.0 * a.cos(), 0.3, c[2] + 6.0 * (a * 1.3).sin()])
                    };
                    Deformer::moving(Shape::Sphere { radius: 0.3 }, at(a - 1.0 / 60.0), at(a))
                })
            })
            .collect();
        let stats = world.step(1.0 / 60.0, &deformers).expect("step");
        if let (Some(frame), Some(g)) = (stats.gpu_frame, stats.gpu) {
            times.push((frame, g));
        }
    }
    gpu.wait_idle().expect("idle");
    while let Some(late) = world.take_gpu_times().expect("times") {
        times.push(late);
    }
    let measured = times.iter().filter(|(f, _)| *f >= first_measured);
    let (mut relax, mut total): (Vec<f64>, Vec<f64>) =
        measured.map(|(_, t)| (t.relax_ms, t.total_ms())).unzip();
    (median(&mut relax), median(&mut total))
}

fn main() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    if !gpu.caps.timestamps {
        eprintln!("relax: this adapter has no timestamp queries; nothing to measure");
        return;
    }
    let quick = std::env::args().any(|a| a == "--quick");
    let (counts, many) = if quick { (QUICK, 64) } else { (FULL, 1024) };
    println!("relax on {}", gpu.info.name);
    println!(
        "{:<28} {:>12} {:>14} {:>14}",
        "frame", "relax_us", "update_us", "snow_update_us"
    );
    for (name, surfaces, spheres) in [
        ("talk (2 x 512^2, 10 each)".to_owned(), 2, 10),
        (format!("{many} x 512^2 (1 each)"), many, 1),
    ] {
        let (relax, total) = run(&gpu, counts, surfaces, spheres, Material::sand());
        let (_, snow) = run(&gpu, counts, surfaces, spheres, Material::snow());
        println!(
            "{name:<28} {:>12.1} {:>14.1} {:>14.1}",
            relax * 1e3,
            total * 1e3,
            snow * 1e3
        );
    }
}
