//! `snowprint bench`: GPU time of the deformation update per stage, swept over surfaces per frame,
//! resolution and deformers per surface, against a plain copy of the same bytes measured in the
//! same run.

use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;
use snowprint::{
    CapturePath, Deformer, GpuContext, GpuOptions, PassMode, PoolFormat, Pose, Precision, Shape,
    SnowWorld, StageTimes, SurfaceDesc, SurfaceSnapshot, SurfaceUpdate, WorldConfig,
};

mod baseline;
mod configs;

use crate::output::OutputSet;
use crate::progress::Progress;
use baseline::{ClearTimer, ComputeCopyTimer, CopyTimer};
use configs::{Config, configs};

/// Arguments of `snowprint bench`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for `bench.json` and the SVG plots.
    #[arg(long, default_value = "out/bench")]
    pub out: PathBuf,
    /// Frames measured per configuration (after the warm-up), 1 or more.
    #[arg(long, default_value_t = 60, allow_negative_numbers = true, value_parser = crate::args::frames)]
    pub frames: u32,
    /// Frames run before measuring.
    #[arg(long, default_value_t = 10, allow_negative_numbers = true)]
    pub warmup: u32,
    /// Small sweeps only (what a software adapter can run in seconds).
    #[arg(long)]
    pub quick: bool,
}

/// One measured configuration.
#[derive(Serialize, Debug, Clone)]
pub struct Row {
    /// Which sweep it belongs to.
    pub sweep: &'static str,
    /// Surfaces updated per frame.
    pub surfaces: u32,
    /// Heightmap side, texels.
    pub resolution: u32,
    /// Deformers over each surface.
    pub deformers_per_surface: u32,
    /// The capture's path for the spheres: what `Auto` takes on this adapter (`update` on a GPU:
    /// the update ray-casts them itself, with no capture), or `compute` (the sweep `compute_surf`
    /// and the rows so marked: the capture's compute path) or `raster` (the sweep `raster_surf`,
    /// the same surfaces rendered in viewports).
    pub capture_path: &'static str,
    /// Blur and merge fused in one pass (else separate passes).
    pub fused: bool,
    /// Bits a channel of the pool.
    pub precision_bits: u32,
    /// Snow refilling (30 % of the depth a second, at least a unit a frame), so every texel is
    /// read every frame (else only the tiles the deformers reach are updated). A texel of
    /// untouched snow stays as it is and is not written back.
    pub snowing: bool,
    /// Every texel starts pressed to the ground, so that with snow falling every texel changes and
    /// is written every frame: the update's worst case, byte for byte what a copy moves.
    pub pressed: bool,
    /// Median GPU time of the whole update, microseconds (or whole frames timed on the CPU).
    pub update_us: f64,
    /// Median GPU time per stage, microseconds.
    pub stages_us: Option<StageTimesUs>,
    /// Median CPU time to build and encode the frame, microseconds.
    pub cpu_encode_us: f64,
    /// Bytes of heightmap the update rewrites (the heights regions of the surfaces).
    pub heightmap_bytes: u64,
    /// Median GPU time of a plain buffer copy of `heightmap_bytes`, microseconds.
    pub copy_us: f64,
    /// `update_us / copy_us`.
    pub ratio_to_copy: f64,
    /// Median GPU time of a compute pass streaming the same bytes in and out with 16-byte loads
    /// and stores, microseconds.
    pub compute_copy_us: f64,
    /// `update_us / compute_copy_us`.
    pub ratio_to_compute_copy: f64,
    /// Median GPU time of a clear of as many bytes as the update cleared of its capture buffer
    /// (`FrameStats::cleared_capture_bytes`: the raster path's regions, every region with
    /// separate passes), which it records before its first pass, outside the passes' timestamps
    /// and so outside `update_us`, microseconds (0 when nothing was cleared).
    pub capture_clear_us: f64,
    /// `(update_us + capture_clear_us) / compute_copy_us`: the update with its capture cleared.
    pub ratio_with_clear_to_compute_copy: f64,
    /// Pool bytes of the surfaces.
    pub pool_bytes: u64,
    /// Bytes per surface in the pool (both channels, slot alignment included).
    pub bytes_per_surface: u64,
    /// Every GPU allocation of the world: pool, scratch, capture buffers, viewport target, tables.
    pub memory: snowprint::MemoryReport,
}

/// Per-stage medians, microseconds.
#[derive(Serialize, Debug, Clone, Copy)]
pub struct StageTimesUs {
    /// Capture render passes.
    pub capture: f64,
    /// Blur.
    pub blur: f64,
    /// Merge.
    pub merge: f64,
    /// Normals.
    pub normals: f64,
    /// Fused blur + merge.
    pub fused: f64,
    /// The snowfall streamed over whole regions before the fused pass (0 where it does not run).
    pub refill: f64,
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// A deterministic scatter of moving spheres over a surface of side `side` metres at ground 0.
fn deformers_over(center: Vec3, side: f32, count: u32, frame: u32) -> Vec<Deformer> {
    let mut out = Vec::with_capacity(count as usize);
    let mut seed = 0x9e37_79b9u32 ^ count;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    for _ in 0..count {
        let (x, z) = ((next() - 0.5) * side * 0.9, (next() - 0.5) * side * 0.9);
        let dir = Vec3::new(next() - 0.5, 0.0, next() - 0.5).normalize_or_zero() * 0.02;
        let p = center + Vec3::new(x, 0.12, z) + dir * frame as f32;
        out.push(Deformer::moving(
            Shape::Sphere { radius: 0.15 },
            Pose::at((p - dir).into()),
            Pose::at(p.into()),
        ));
    }
    out
}

/// A surface whose every texel is pressed to the ground (nothing displaced): 200 frames of the
/// bench's snowfall from untouched.
fn pressed(desc: SurfaceDesc, format: PoolFormat, side: u32) -> Result<SurfaceSnapshot, String> {
    let texels = (side * side) as usize;
    let max = format.precision.channel_max();
    let words = format
        .encode(side, side, &vec![max; texels], &vec![0; texels])
        .map_err(|e| e.to_string())?;
    Ok(SurfaceSnapshot {
        desc,
        width: side,
        height: side,
        format,
        carry: 0.0,
        words,
    })
}

fn measure(gpu: &GpuContext, c: &Config, args: &Args) -> Result<Row, String> {
    // Square surfaces at 4 cm texels have exactly `resolution` texels a side.
    let side = c.resolution as f32 * 0.04;
    let format = PoolFormat::new(c.precision);
    let slot = format.slot_bytes(c.resolution, c.resolution);
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: slot * c.surfaces as u64,
            max_resolution: c.resolution,
            passes: c.passes,
            format,
            atlas_side: 8192.min(gpu.caps.max_texture_side),
            capture_path: c.capture,
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let mut centers = Vec::new();
    let mut ids = Vec::new();
    for i in 0..c.surfaces {
        let center = Vec3::new(
            (i % 64) as f32 * (side + 1.0),
            0.0,
            (i / 64) as f32 * (side + 1.0),
        );
        let desc = SurfaceDesc {
            // 30% of the depth a second: at least one unit a frame at 60 Hz even at 8 bits.
            replenish_rate: if c.snowing { 0.3 } else { 0.0 },
            ..SurfaceDesc::new(&format!("s{i}"), center.into(), [side, side], 0.3)
        };
        let id = if c.pressed {
            world.restore_surface(&pressed(desc, format, c.resolution)?, None)
        } else {
            world.add_surface(desc)
        }
        .map_err(|e| e.to_string())?;
        ids.push(id);
        centers.push(center);
    }
    world.set_profiling(true);
    let timestamps = world.has_timestamps();
    let (mut total, mut cpu, mut cap, mut blur, mut merge, mut normals, mut fused) =
        (vec![], vec![], vec![], vec![], vec![], vec![], vec![]);
    let mut refill = vec![];
    let (mut gpu_times, mut measured_from, mut cleared) = (Vec::new(), u64::MAX, 0);
    for f in 0..args.warmup + args.frames {
        // Each surface is given the deformers over it, as a manager's spatial lookup would.
        let deformers: Vec<Vec<Deformer>> = centers
            .iter()
            .map(|&ctr| deformers_over(ctr, side, c.deformers, f))
            .collect();
        let updates: Vec<SurfaceUpdate<'_>> = ids
            .iter()
            .zip(&deformers)
            .map(|(&surface, d)| SurfaceUpdate {
                surface,
                elapsed: 1.0 / 60.0,
                deformers: d,
            })
            .collect();
        let start = Instant::now();
        let stats = world.update(&updates).map_err(|e| e.to_string())?;
        // Each frame runs alone on the GPU, as it did when profiling waited for its times: frames
        // that overlap would share the GPU (and, on a software adapter, the CPU that encodes).
        gpu.wait_idle().map_err(|e| e.to_string())?;
        let wall = start.elapsed().as_secs_f64() * 1e6;
        if f == args.warmup {
            measured_from = stats.frame;
        }
        // GPU times arrive a frame or two late, each with its frame's number.
        if let (Some(frame), Some(times)) = (stats.gpu_frame, stats.gpu) {
            gpu_times.push((frame, times));
        }
        if f < args.warmup {
            continue;
        }
        cpu.push(stats.cpu_encode_ms * 1e3);
        cleared = stats.cleared_capture_bytes;
        if !timestamps {
            total.push(wall);
        }
    }
    if timestamps {
        // The last frames' times are still on their way: wait for them here, outside the loop.
        gpu.wait_idle().map_err(|e| e.to_string())?;
        while let Some(late) = world.take_gpu_times().map_err(|e| e.to_string())? {
            gpu_times.push(late);
        }
    }
    for &(_, t) in gpu_times
        .iter()
        .filter(|(frame, _)| *frame >= measured_from)
    {
        let StageTimes {
            capture_ms,
            blur_ms,
            merge_ms,
            normals_ms,
            fused_ms,
            refill_ms,
            // The bench's surfaces are the talk's snow, which never relaxes.
            relax_ms: _,
            // Nor has spray.
            spray_ms: _,
        } = t;
        cap.push(capture_ms * 1e3);
        blur.push(blur_ms * 1e3);
        merge.push(merge_ms * 1e3);
        normals.push(normals_ms * 1e3);
        fused.push(fused_ms * 1e3);
        refill.push(refill_ms * 1e3);
        total.push(t.total_ms() * 1e3);
    }
    let bytes = c.surfaces as u64 * format.heights_bytes(c.resolution, c.resolution);
    let copy = CopyTimer::new(gpu, bytes);
    let compute_copy = ComputeCopyTimer::new(gpu, bytes);
    // What the update's last frame cleared of the capture buffer.
    let clear = ClearTimer::new(gpu, cleared);
    let (mut copies, mut compute_copies, mut clears) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..args.warmup + args.frames {
        let t = copy.time(gpu)?;
        let cc = compute_copy.time(gpu)?;
        let cl = clear.time(gpu)?;
        if i >= args.warmup {
            copies.push(t);
            compute_copies.push(cc);
            clears.push(cl);
        }
    }
    let update_us = median(&mut total);
    let copy_us = median(&mut copies);
    let compute_copy_us = median(&mut compute_copies);
    let capture_clear_us = median(&mut clears);
    Ok(Row {
        sweep: c.sweep,
        surfaces: c.surfaces,
        resolution: c.resolution,
        deformers_per_surface: c.deformers,
        capture_path: match c.capture.resolved(gpu.info.device_type) {
            CapturePath::Raster => "raster",
            CapturePath::Update => "update",
            _ => "compute",
        },
        fused: world.config().passes == PassMode::Fused,
        precision_bits: c.precision.bits(),
        snowing: c.snowing,
        pressed: c.pressed,
        update_us,
        stages_us: timestamps.then(|| StageTimesUs {
            capture: median(&mut cap),
            blur: median(&mut blur),
            merge: median(&mut merge),
            normals: median(&mut normals),
            fused: median(&mut fused),
            refill: median(&mut refill),
        }),
        cpu_encode_us: median(&mut cpu),
        heightmap_bytes: bytes,
        copy_us,
        ratio_to_copy: update_us / copy_us,
        compute_copy_us,
        ratio_to_compute_copy: update_us / compute_copy_us,
        capture_clear_us,
        ratio_with_clear_to_compute_copy: (update_us + capture_clear_us) / compute_copy_us,
        pool_bytes: world.memory().pool_used,
        bytes_per_surface: slot,
        memory: world.memory(),
    })
}

/// Run the sweeps and write the report.
pub fn run(gpu_options: &GpuOptions, args: &Args) -> Result<(), String> {
    // The output folder is checked (and created) before anything is measured.
    let mut outputs =
        OutputSet::prepare(&args.out, "bench", &format!("--out {}", args.out.display()))?;
    let files = [
        "bench.json",
        "bench_surfaces.svg",
        "bench_resolution.svg",
        "bench_deformers.svg",
    ];
    for name in files {
        outputs.check_name(name)?;
    }
    let gpu = GpuContext::new(gpu_options).map_err(|e| e.to_string())?;
    let software = gpu.info.device_type == wgpu::DeviceType::Cpu;
    let quick = args.quick || software;
    if software && !args.quick {
        eprintln!(
            "snowprint: {} is a software adapter: running the quick sweeps only",
            gpu.info.name
        );
    }
    let timestamps = gpu.caps.timestamps;
    if !timestamps {
        eprintln!(
            "snowprint: {} has no GPU timestamp queries: whole frames are timed on the CPU (submit to finish), not per stage",
            gpu.info.name
        );
    }
    let configs = configs(quick);
    let mut bar = Progress::new(configs.len() as u64, "bench", "configurations")?;
    let mut rows = Vec::new();
    for c in &configs {
        bar.set_message(&format!(
            "{} x {}^2, {} deformers",
            c.surfaces, c.resolution, c.deformers
        ));
        rows.push(measure(&gpu, c, args)?);
        bar.inc(1);
    }
    bar.finish();

    print_rows(&gpu, &rows);
    let (fits, errors) = talk_memory(&gpu, quick)?;
    let report = serde_json::json!({
        "memory_talk_pool": {
            "pool_bytes": 2u64 << 20,
            "layout": "depression and displaced snow per texel at the pool's precision, updated in place (no history per surface: the capture buffers of a frame are shared by every surface in it); normals not kept (the renderer derives them)",
            "fits": fits,
        },
        "precision_error_vs_32_bit": errors,
        "adapter": snowprint::low_level::gpu::describe(&gpu.info),
        "timestamps": timestamps,
        "frames": args.frames,
        "warmup": args.warmup,
        "statistic": "median",
        "rows": rows,
    });
    outputs.write(
        "bench.json",
        serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?,
    )?;
    write_plots(&mut outputs, &gpu.info.name, &rows)?;
    outputs.publish()?;
    eprintln!("snowprint: wrote {}", args.out.display());
    Ok(())
}

/// The rows as a table on stdout, under the adapter and how it was timed.
fn print_rows(gpu: &GpuContext, rows: &[Row]) {
    let timestamps = gpu.caps.timestamps;
    println!(
        "adapter: {}\ntimestamps: {}\n",
        snowprint::low_level::gpu::describe(&gpu.info),
        if timestamps {
            "per-pass GPU timestamps"
        } else {
            "none: whole frames timed on the CPU"
        }
    );
    println!(
        "{:<12} {:>5} {:>7} {:>4} {:>4} {:>8} {:>5} {:>5} {:>10} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>7} {:>9} {:>7} {:>9} {:>11}",
        "sweep",
        "mode",
        "capture",
        "bits",
        "snow",
        "surfaces",
        "res",
        "defs",
        "update_us",
        "capture",
        "blur",
        "merge",
        "normals",
        "fused",
        "refill",
        "cpu_us",
        "copy_us",
        "x_copy",
        "ccopy_us",
        "x_ccopy",
        "clear_us",
        "x_ccopy+clr"
    );
    for r in rows {
        let s = r.stages_us;
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
        println!(
            "{:<12} {:>5} {:>7} {:>4} {:>4} {:>8} {:>5} {:>5} {:>10.1} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8.1} {:>9.1} {:>7.2} {:>9.1} {:>7.2} {:>9.1} {:>11.2}",
            r.sweep,
            if r.fused { "fused" } else { "split" },
            r.capture_path,
            r.precision_bits,
            match (r.snowing, r.pressed) {
                (false, _) => "no",
                (true, false) => "yes",
                (true, true) => "all",
            },
            r.surfaces,
            r.resolution,
            r.deformers_per_surface,
            r.update_us,
            f(s.map(|s| s.capture)),
            f(s.map(|s| s.blur)),
            f(s.map(|s| s.merge)),
            f(s.map(|s| s.normals)),
            f(s.map(|s| s.fused)),
            f(s.map(|s| s.refill)),
            r.cpu_encode_us,
            r.copy_us,
            r.ratio_to_copy,
            r.compute_copy_us,
            r.ratio_to_compute_copy,
            r.capture_clear_us,
            r.ratio_with_clear_to_compute_copy
        );
    }
}

/// The talk's memory: how many 512^2 surfaces a real 2 MiB pool holds at each precision, and
/// what each precision costs in accuracy against 32 bits on the talk's frame (printed as well).
fn talk_memory(
    gpu: &GpuContext,
    quick: bool,
) -> Result<(Vec<PoolFit>, Vec<PrecisionError>), String> {
    let fits = Precision::ALL
        .into_iter()
        .map(|p| talk_pool_fit(gpu, p))
        .collect::<Result<Vec<_>, _>>()?;
    println!(
        "\nmemory: 512^2 surfaces (both channels, no history, no normals) in the talk's 2 MiB pool"
    );
    for f in &fits {
        println!(
            "  {:>2}-bit: {:>7} bytes a surface, {} fit and update",
            f.precision_bits, f.bytes_per_surface, f.surfaces
        );
    }
    let errors = precision_errors(gpu, if quick { 30 } else { 120 })?;
    println!(
        "\nprecision: {} frames of the talk's frame (2 x 512^2, 10 moving spheres each, snow refilling), against 32 bits",
        errors[0].frames
    );
    for e in &errors {
        println!(
            "  {:>2}-bit: depression max {:.2e} (mean {:.2e}) of the snow depth = {:.2} mm of 30 cm; displaced max {:.2e} (mean {:.2e})",
            e.precision_bits,
            e.depression_max,
            e.depression_mean,
            e.depression_max * 300.0,
            e.displaced_max,
            e.displaced_mean
        );
    }
    Ok((fits, errors))
}

/// One SVG plot a sweep: the update's time and the copy's against the swept quantity.
fn write_plots(outputs: &mut OutputSet, adapter: &str, rows: &[Row]) -> Result<(), String> {
    for sweep in ["surfaces", "resolution", "deformers"] {
        let pts: Vec<&Row> = rows.iter().filter(|r| r.sweep == sweep).collect();
        let x = |r: &Row| match sweep {
            "surfaces" => r.surfaces as f64,
            "resolution" => r.resolution as f64,
            _ => r.deformers_per_surface as f64,
        };
        let svg = snowprint_demo::plot::log_log_svg(
            &format!("update time vs {sweep} ({})", adapter),
            sweep,
            &[
                ("update", pts.iter().map(|r| (x(r), r.update_us)).collect()),
                (
                    "copy of the same bytes",
                    pts.iter().map(|r| (x(r), r.copy_us)).collect(),
                ),
            ],
        )?;
        outputs.write(&format!("bench_{sweep}.svg"), svg)?;
    }
    Ok(())
}

/// How many 512^2 surfaces fit a real 2 MiB pool at one precision.
#[derive(Serialize, Debug, Clone)]
pub struct PoolFit {
    /// Bits a channel.
    pub precision_bits: u32,
    /// Pool bytes of one 512^2 surface.
    pub bytes_per_surface: u64,
    /// Surfaces added before the pool refused one, all of which were then updated and read back
    /// pressed.
    pub surfaces: u32,
    /// Pool bytes in use with them.
    pub pool_used: u64,
    /// Bytes outside the pool the frame that updated them all used (scratch, capture and winding
    /// buffers, tables), shared by every surface updated in a frame.
    pub frame_bytes: u64,
}

/// Add 512^2 surfaces to a world with the talk's 2 MiB pool until it refuses one, then press each
/// with a sphere in one update and check every one was pressed.
fn talk_pool_fit(gpu: &GpuContext, precision: Precision) -> Result<PoolFit, String> {
    let format = PoolFormat::new(precision);
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 2 << 20,
            format,
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let side = 512.0 * 0.04;
    let mut ids = Vec::new();
    loop {
        let x = ids.len() as f32 * (side + 1.0);
        match world.add_surface(SurfaceDesc::new("talk", [x, 0.0, 0.0], [side, side], 0.3)) {
            Ok(id) => ids.push((id, x)),
            Err(snowprint::SnowError::PoolExhausted { .. }) => break,
            Err(e) => return Err(e.to_string()),
        }
    }
    let spheres: Vec<Vec<Deformer>> = ids
        .iter()
        .map(|&(_, x)| {
            vec![Deformer::new(
                Shape::Sphere { radius: 0.3 },
                Pose::at([x, 0.1, 0.0]),
            )]
        })
        .collect();
    let updates: Vec<SurfaceUpdate<'_>> = ids
        .iter()
        .zip(&spheres)
        .map(|(&(surface, _), d)| SurfaceUpdate {
            surface,
            elapsed: 0.0,
            deformers: d,
        })
        .collect();
    world.update(&updates).map_err(|e| e.to_string())?;
    for &(id, _) in &ids {
        let (depression, _) = world.read_channels(id).map_err(|e| e.to_string())?;
        if !depression.iter().any(|&v| v > 0) {
            return Err(format!(
                "a 512^2 surface at {precision} was not pressed: the pool is broken"
            ));
        }
    }
    let memory = world.memory();
    Ok(PoolFit {
        precision_bits: precision.bits(),
        bytes_per_surface: format.slot_bytes(512, 512),
        surfaces: ids.len() as u32,
        pool_used: memory.pool_used,
        frame_bytes: memory.scratch + memory.frame_tables + memory.capture_atlas,
    })
}

/// The error of one precision against 32 bits.
#[derive(Serialize, Debug, Clone)]
pub struct PrecisionError {
    /// Bits a channel.
    pub precision_bits: u32,
    /// Frames run.
    pub frames: u32,
    /// Largest difference in depression, fraction of the snow depth.
    pub depression_max: f64,
    /// Mean difference in depression over all texels.
    pub depression_mean: f64,
    /// Largest difference in displaced snow, fraction of the snow depth.
    pub displaced_max: f64,
    /// Mean difference in displaced snow.
    pub displaced_mean: f64,
}

/// Run the talk's frame (2 surfaces of 512^2, 10 moving spheres each, snow refilling at 2% of the
/// depth a second) for `frames` frames at 8, 16 and 32 bits, and compare the heightmaps with the
/// 32-bit ones.
fn precision_errors(gpu: &GpuContext, frames: u32) -> Result<Vec<PrecisionError>, String> {
    let side = 512.0 * 0.04;
    // Per surface, (depression, displaced) as fractions of the snow depth.
    type Fractions = (Vec<f64>, Vec<f64>);
    let run = |precision: Precision| -> Result<Vec<Fractions>, String> {
        let format = PoolFormat::new(precision);
        let mut world = SnowWorld::new(
            gpu,
            WorldConfig {
                pool_bytes: 2 * format.slot_bytes(512, 512),
                format,
                ..Default::default()
            },
        )
        .map_err(|e| e.to_string())?;
        let centers = [Vec3::ZERO, Vec3::new(side + 1.0, 0.0, 0.0)];
        let mut ids = Vec::new();
        for c in centers {
            let mut desc = SurfaceDesc::new("talk", c.into(), [side, side], 0.3);
            desc.replenish_rate = 0.02;
            ids.push(world.add_surface(desc).map_err(|e| e.to_string())?);
        }
        for f in 0..frames {
            let deformers: Vec<Vec<Deformer>> = centers
                .iter()
                .map(|&c| deformers_over(c, side, 10, f))
                .collect();
            let updates: Vec<SurfaceUpdate<'_>> = ids
                .iter()
                .zip(&deformers)
                .map(|(&surface, d)| SurfaceUpdate {
                    surface,
                    elapsed: 1.0 / 60.0,
                    deformers: d,
                })
                .collect();
            world.update(&updates).map_err(|e| e.to_string())?;
        }
        let max = precision.channel_max() as f64;
        ids.iter()
            .map(|&id| {
                let (d, p) = world.read_channels(id).map_err(|e| e.to_string())?;
                Ok((
                    d.iter().map(|&v| v as f64 / max).collect(),
                    p.iter().map(|&v| v as f64 / max).collect(),
                ))
            })
            .collect()
    };
    let reference = run(Precision::Bits32)?;
    let mut out = Vec::new();
    for precision in [Precision::Bits8, Precision::Bits16] {
        let got = run(precision)?;
        let (mut dm, mut ds, mut pm, mut ps, mut n) = (0.0f64, 0.0, 0.0f64, 0.0, 0.0);
        for (g, r) in got.iter().zip(&reference) {
            for i in 0..g.0.len() {
                let dd = (g.0[i] - r.0[i]).abs();
                let dp = (g.1[i] - r.1[i]).abs();
                dm = dm.max(dd);
                pm = pm.max(dp);
                ds += dd;
                ps += dp;
                n += 1.0;
            }
        }
        out.push(PrecisionError {
            precision_bits: precision.bits(),
            frames,
            depression_max: dm,
            depression_mean: ds / n,
            displaced_max: pm,
            displaced_mean: ps / n,
        });
    }
    Ok(out)
}
