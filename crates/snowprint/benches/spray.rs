//! What kicked-up snow costs a frame: 1, 10 and 100 characters, each the skinned trudger of
//! `scenes/Trudger.glb` (the demo's body walking its 7 s loop, skinned on the GPU every frame) on a
//! roof of its own (8 m x 2 m, 4 cm texels, 0.35 m of snow), with the world's spray on (the
//! default ring of 16384 grains) and off, from the world's per-pass GPU timestamps: medians over
//! the measured frames of the spray pass and of the whole update, and the grains spawned and
//! dropped a frame.
//!
//! `cargo bench -p snowprint --bench spray` (prints a table; needs timestamp queries).
//! Results: `docs/PERFORMANCE.md`, "Kicked-up snow".

use snowprint::{
    Deformer, GpuContext, GpuOptions, MeshAnimation, Playback, Pose, Shape, SkinnedMesh, SnowWorld,
    SprayConfig, StageTimes, SurfaceDesc, WorldConfig,
};

const WARMUP: u32 = 30;
const FRAMES: u32 = 240;
const DT: f32 = 1.0 / 60.0;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

struct Row {
    spray_ms: f64,
    update_ms: f64,
    spawned: f64,
    dropped: f64,
}

fn run(gpu: &GpuContext, figure: &SkinnedMesh, n: u32, spray: Option<SprayConfig>) -> Row {
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 64 << 20,
            spray,
            ..Default::default()
        },
    )
    .expect("world");
    world.set_profiling(true);
    let walk = figure.animation_index("walk");
    let mut figures = Vec::new();
    for i in 0..n {
        let c = [(i % 10) as f32 * 9.0, 0.0, (i / 10) as f32 * 3.0];
        world
            .add_surface(SurfaceDesc::new(&format!("roof {i}"), c, [8.0, 2.0], 0.35))
            .expect("surface");
        let mesh = world
            .add_skinned_mesh(&format!("trudger {i}"), figure)
            .expect("figure");
        figures.push((mesh, Deformer::new(Shape::Mesh(mesh), Pose::at(c))));
    }
    let mut times: Vec<(u64, StageTimes)> = Vec::new();
    let mut first_measured = 0;
    let mut spawned_before = 0;
    let mut dropped_before = 0;
    for f in 0..WARMUP + FRAMES {
        if f == WARMUP {
            first_measured = f as u64 + 1;
            if let Some((c, _)) = world.read_spray().expect("spray") {
                (spawned_before, dropped_before) = (c.spawned_total, c.dropped_total);
            }
        }
        // Each figure a little later in its loop, so their steps do not fall together.
        let poses: Vec<MeshAnimation> = figures
            .iter()
            .enumerate()
            .map(|(i, (mesh, _))| MeshAnimation {
                mesh: *mesh,
                animation: walk,
                time: f as f32 * DT + i as f32 * 0.37,
                playback: Playback::Loop,
            })
            .collect();
        world.animate_meshes(&poses).expect("animate");
        let deformers: Vec<Deformer> = figures.iter().map(|f| f.1).collect();
        let stats = world.step(DT, &deformers).expect("step");
        if let (Some(frame), Some(g)) = (stats.gpu_frame, stats.gpu) {
            times.push((frame, g));
        }
    }
    gpu.wait_idle().expect("idle");
    while let Some(late) = world.take_gpu_times().expect("times") {
        times.push(late);
    }
    let measured = times.iter().filter(|(f, _)| *f >= first_measured);
    let (mut spray_ms, mut update_ms): (Vec<f64>, Vec<f64>) =
        measured.map(|(_, t)| (t.spray_ms, t.total_ms())).unzip();
    let (spawned, dropped) = match world.read_spray().expect("spray") {
        Some((c, _)) => (
            (c.spawned_total - spawned_before) as f64 / FRAMES as f64,
            (c.dropped_total - dropped_before) as f64 / FRAMES as f64,
        ),
        None => (0.0, 0.0),
    };
    Row {
        spray_ms: median(&mut spray_ms),
        update_ms: median(&mut update_ms),
        spawned,
        dropped,
    }
}

fn main() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    if !gpu.caps.timestamps {
        eprintln!("spray: this adapter has no timestamp queries; nothing to measure");
        return;
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/Trudger.glb");
    let figure = SkinnedMesh::load_gltf(&path).expect("Trudger.glb");
    println!("spray on {}", gpu.info.name);
    println!(
        "{:<12} {:>10} {:>16} {:>17} {:>16} {:>15}",
        "characters", "spray_us", "update_on_us", "update_off_us", "spawned/frame", "dropped/frame"
    );
    for n in [1, 10, 100] {
        let on = run(&gpu, &figure, n, Some(SprayConfig::default()));
        let off = run(&gpu, &figure, n, None);
        println!(
            "{n:<12} {:>10.1} {:>16.1} {:>17.1} {:>16.1} {:>15.1}",
            on.spray_ms * 1e3,
            on.update_ms * 1e3,
            off.update_ms * 1e3,
            on.spawned,
            on.dropped
        );
    }
}
