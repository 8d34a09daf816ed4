//! CPU time to plan and record a world's update, without submitting it: `SnowWorld::encode_step`
//! and `encode_update` into an encoder that is dropped, the frame then abandoned. Two ways to
//! hand deformers over for N surfaces of 128^2 with 10 moving spheres each: one shared list of all
//! of them (`encode_step`, every surface offered every deformer) and a list per surface
//! (`encode_update`, what `snowprint bench` does).
//!
//! Surfaces are captured by the compute path unless `--path update` (`CapturePath::Auto` would take
//! the raster path on a software adapter, which plans less on the CPU).
//!
//! `cargo bench -p snowprint --bench encode` (add `-- --quick` for a software adapter), with
//! `--surfaces 256,1024,4096` to choose the counts, `--path update` for the update's own ray cast
//! (what `snowprint bench` measures on a GPU), and `--texels 64` for smaller surfaces (a
//! software adapter binds at most 128 MiB, and the capture buffer holds 4 bytes a texel of every
//! captured surface: 2048 of 128^2 at most); `--frames N` and `--only shared|each` for a profile;
//! `--plan-threads N` for `WorldConfig::plan_threads` (default 0: the machine's, up to 8). The
//! list-per-surface frames' steps (`FrameStats::cpu_steps`, medians) follow each row.
//! Results: `docs/PERFORMANCE.md`, "CPU encode".

use std::time::Instant;

use snowprint::{
    CapturePath, CpuSteps, Deformer, GpuContext, GpuOptions, PoolFormat, Pose, Precision, Shape,
    SnowWorld, SurfaceDesc, SurfaceId, SurfaceUpdate, WorldConfig,
};

const SPHERES: u32 = 10;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn world(
    gpu: &GpuContext,
    (surfaces, texels, path, plan_threads): Case,
) -> (SnowWorld, Vec<(SurfaceId, [f32; 3])>) {
    // Texels of 4 cm, as `snowprint bench` has them, at 8 bits (the smallest pool).
    let metres = texels as f32 * 0.04;
    let format = PoolFormat::new(Precision::Bits8);
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: format.slot_bytes(texels, texels) * surfaces as u64,
            max_resolution: texels,
            capture_path: path,
            format,
            atlas_side: 8192.min(gpu.caps.max_texture_side),
            plan_threads,
            ..Default::default()
        },
    )
    .expect("world");
    let ids = (0..surfaces)
        .map(|i| {
            let c = [
                (i % 64) as f32 * (metres + 1.0),
                0.0,
                (i / 64) as f32 * (metres + 1.0),
            ];
            let desc = SurfaceDesc::new(&format!("s{i}"), c, [metres, metres], 0.3);
            (world.add_surface(desc).expect("surface"), c)
        })
        .collect();
    (world, ids)
}

/// Each surface's spheres at time `t`, moving along a small Lissajous curve over it.
fn spheres(c: [f32; 3], t: f32) -> impl Iterator<Item = Deformer> {
    (0..SPHERES).map(move |k| {
        let a = t + k as f32 * 0.9;
        let at = |a: f32| Pose::at([c[0] + 1.6 * a.cos(), 0.3, c[2] + 1.6 * (a * 1.3).sin()]);
        Deformer::moving(Shape::Sphere { radius: 0.15 }, at(a - 1.0 / 60.0), at(a))
    })
}

/// Submit nothing but the tables the abandoned frame wrote with `queue.write_buffer`, and wait:
/// their staging memory is given back as in an application that submits every frame (kept, it
/// would grow frame after frame, each frame's writes faulting in fresh pages).
fn flush(gpu: &GpuContext) {
    gpu.queue.submit([]);
    gpu.wait_idle().expect("wait");
}

/// Which ways of handing deformers over to measure: (shared list, a list per surface).
type Cases = (bool, bool);

/// A world measured: surfaces, their side in texels, the capture path and the plan's threads.
type Case = (u32, u32, CapturePath, usize);

/// The world's steps of a list-per-surface frame ([`CpuSteps`]), in order, with their names.
fn steps(s: &CpuSteps) -> [(&'static str, f64); 6] {
    [
        ("check", s.check_ms),
        ("plan", s.plan_ms),
        ("gather", s.gather_ms),
        ("tables", s.tables_ms),
        ("upload", s.upload_ms),
        ("record", s.record_ms),
    ]
}

/// Median milliseconds to encode a frame: (shared list, a list per surface), NaN for a case not
/// measured; and the medians of the list-per-surface frames' steps.
fn run(gpu: &GpuContext, case: Case, frames: u32, cases: Cases) -> (f64, f64, Vec<f64>) {
    let (mut world, ids) = world(gpu, case);
    let (mut shared, mut each) = (Vec::new(), Vec::new());
    let mut each_steps: Vec<Vec<f64>> = vec![Vec::new(); 6];
    for f in 0..frames {
        let t = f as f32 / 60.0;
        let all: Vec<Deformer> = ids.iter().flat_map(|&(_, c)| spheres(c, t)).collect();
        let lists: Vec<Vec<Deformer>> = ids.iter().map(|&(_, c)| spheres(c, t).collect()).collect();
        let updates: Vec<SurfaceUpdate<'_>> = ids
            .iter()
            .zip(&lists)
            .map(|(&(surface, _), deformers)| SurfaceUpdate {
                surface,
                elapsed: 1.0 / 60.0,
                deformers,
            })
            .collect();
        if cases.0 {
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            let start = Instant::now();
            let pending = world
                .encode_step(&mut encoder, 1.0 / 60.0, &all)
                .expect("encode");
            shared.push(start.elapsed().as_secs_f64() * 1e3);
            drop((pending, encoder));
            world.abandon_pending();
            flush(gpu);
        }
        if !cases.1 {
            continue;
        }
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let start = Instant::now();
        let pending = world.encode_update(&mut encoder, &updates).expect("encode");
        each.push(start.elapsed().as_secs_f64() * 1e3);
        for (v, (_, ms)) in each_steps.iter_mut().zip(steps(&pending.stats().cpu_steps)) {
            v.push(ms);
        }
        drop((pending, encoder));
        world.abandon_pending();
        flush(gpu);
    }
    let each_steps = each_steps.iter_mut().map(|v| median(v)).collect();
    (median(&mut shared), median(&mut each), each_steps)
}

fn main() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    let quick = std::env::args().any(|a| a == "--quick");
    let (mut counts, mut frames): (Vec<u32>, u32) = if quick {
        (vec![16, 256, 1024], 5)
    } else {
        (vec![16, 256, 1024, 4096], 30)
    };
    let args: Vec<String> = std::env::args().collect();
    let value = |name: &str| {
        let i = args.iter().position(|a| a == name)?;
        args.get(i + 1).map(String::as_str)
    };
    if let Some(list) = value("--surfaces") {
        counts = list
            .split(',')
            .map(|n| {
                n.trim()
                    .parse()
                    .expect("--surfaces takes counts like 256,1024")
            })
            .collect();
    }
    if let Some(n) = value("--frames") {
        frames = n.parse().expect("--frames takes a count");
    }
    // `--only shared` or `--only each` (for a profile of one case).
    let cases = match value("--only") {
        Some("shared") => (true, false),
        Some("each") => (false, true),
        _ => (true, true),
    };
    let texels: u32 = value("--texels").map_or(128, |t| t.parse().expect("--texels takes a side"));
    // `--path update`: the update's own ray cast (what `CapturePath::Auto` takes on a GPU, and
    // `snowprint bench` measures), no capture planned.
    let path = match value("--path") {
        Some("update") => CapturePath::Update,
        Some("compute") | None => CapturePath::Compute,
        Some(other) => panic!("--path takes update or compute, not {other}"),
    };
    let threads: usize =
        value("--plan-threads").map_or(0, |t| t.parse().expect("--plan-threads takes a count"));
    println!(
        "encode on {}, surfaces of {texels}^2, {path:?}, plan threads {threads}",
        gpu.info.name
    );
    let names = steps(&CpuSteps::default()).map(|(name, _)| format!("{name:>8}"));
    println!(
        "{:<10} {:>16} {:>16} {}",
        "surfaces",
        "shared_list_ms",
        "per_surface_ms",
        names.join(" ")
    );
    for n in counts {
        let (shared, each, each_steps) = run(&gpu, (n, texels, path, threads), frames, cases);
        let each_steps: Vec<String> = each_steps.iter().map(|ms| format!("{ms:>8.3}")).collect();
        println!(
            "{n:<10} {shared:>16.3} {each:>16.3} {}",
            each_steps.join(" ")
        );
    }
}
