//! Saves and paging: writing and reading the snow state of 64 surfaces of 512 x 512 texels, and
//! paging one 512 x 512 heightmap out (read back, compressed) and in (decompressed, written).
//!
//! `cargo bench -p snowprint --bench saves -- --warm-up-time 1 --measurement-time 5`; the sizes
//! (compressed against raw) are printed first. Results: `docs/PERFORMANCE.md`, "Saves and paging".

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use snowprint::low_level::pages::Page;
use snowprint::manager::SaveFile;
use snowprint::manager::{ManagedDeformer, ManagerConfig, SnowManager, UNLIMITED, ZoneId};
use snowprint::{
    Deformer, GpuContext, GpuOptions, PoolFormat, Pose, Shape, SnowWorld, SurfaceDesc, WorldConfig,
};

const SURFACES: usize = 64;
/// 20.48 m at the talk's 4 cm a texel: 512 x 512.
const SIDE: f32 = 20.48;

/// 64 surfaces of 512^2 at 16 bits, each with a dragged trench and a walk of footprints.
fn pressed_manager(gpu: &GpuContext) -> SnowManager {
    let slot = PoolFormat::default().slot_bytes(512, 512);
    let mut m = SnowManager::new(
        gpu,
        ManagerConfig {
            updates_per_frame: UNLIMITED,
            pool_bytes: SURFACES as u64 * slot,
            ..ManagerConfig::default()
        },
    )
    .expect("manager");
    for i in 0..SURFACES {
        let c = [(i % 8) as f32 * 25.0, 0.0, (i / 8) as f32 * 25.0];
        m.add_surface(
            SurfaceDesc::new(&format!("s{i}"), c, [SIDE, SIDE], 0.3),
            ZoneId(0),
        )
        .expect("surface");
    }
    for f in 0..60u32 {
        let t = f as f32 / 60.0;
        let ds: Vec<ManagedDeformer> = (0..SURFACES)
            .flat_map(|i| {
                let (x, z) = ((i % 8) as f32 * 25.0, (i / 8) as f32 * 25.0);
                let drag = |t: f32| Pose::at([x - 9.0 + 18.0 * t, 0.3, z - 3.0 + 2.0 * t]);
                let foot = Pose::at([x - 9.0 + 18.0 * t, 0.25, z + 4.0 + (f % 2) as f32 * 0.3]);
                [
                    ManagedDeformer::new(Deformer::moving(
                        Shape::Sphere { radius: 0.4 },
                        drag((t - 1.0 / 60.0).max(0.0)),
                        drag(t),
                    )),
                    ManagedDeformer::new(Deformer::new(Shape::Sphere { radius: 0.12 }, foot)),
                ]
            })
            .collect();
        m.tick(1.0 / 60.0, None, &ds).expect("tick");
    }
    m
}

fn saves(c: &mut Criterion) {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    let mut m = pressed_manager(&gpu);
    let bytes = m.to_save_bytes().expect("save");
    let raw = SURFACES as u64 * PoolFormat::default().heights_bytes(512, 512);
    println!(
        "saves: {SURFACES} surfaces of 512^2 at 16 bits on {}: {} bytes saved for {} bytes of \
         heightmaps ({:.2} %)",
        gpu.info.name,
        bytes.len(),
        raw,
        bytes.len() as f64 * 100.0 / raw as f64
    );
    let mut g = c.benchmark_group("saves");
    g.sample_size(10);
    g.bench_function("save 64 x 512^2 (to bytes)", |b| {
        b.iter(|| black_box(m.to_save_bytes().expect("save")))
    });
    g.bench_function("load 64 x 512^2 (parse + from_save)", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let start = Instant::now();
                let file = SaveFile::parse(&bytes).expect("parse");
                let loaded = SnowManager::from_save(&gpu, file).expect("load");
                // Wait for the uploads: the load is done when the GPU holds the heightmaps.
                loaded
                    .world()
                    .read_packed(loaded.world().surfaces().next().expect("one").0)
                    .expect("read");
                total += start.elapsed();
            }
            total
        })
    });
    g.finish();

    // Paging one 512^2 heightmap (a pressed one) out and in, in a world of its own.
    let page = Page::compress(
        m.world()
            .snapshot_surfaces(&[m.world().surfaces().next().expect("one").0])
            .expect("snapshot")
            .remove(0),
    );
    println!(
        "paging: one 512^2 heightmap pages to {} bytes of {} ({:.2} %)",
        page.bytes(),
        page.raw_bytes,
        page.bytes() as f64 * 100.0 / page.raw_bytes as f64
    );
    let mut world = SnowWorld::new(
        &gpu,
        WorldConfig {
            pool_bytes: 4 << 20,
            ..WorldConfig::default()
        },
    )
    .expect("world");
    let snap = page.decompress().expect("page");
    let mut id = world.restore_surface(&snap, None).expect("restore");
    let mut g = c.benchmark_group("paging");
    g.sample_size(20);
    g.bench_function("page out 512^2 (read back + compress)", |b| {
        b.iter(|| {
            let s = world.snapshot_surfaces(&[id]).expect("snapshot").remove(0);
            black_box(Page::compress(s))
        })
    });
    g.bench_function("page in 512^2 (decompress + write)", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                world.remove_surface(id).expect("remove");
                let start = Instant::now();
                let s = page.decompress().expect("page");
                id = world.restore_surface(&s, None).expect("restore");
                world.read_packed(id).expect("wait");
                total += start.elapsed();
            }
            total
        })
    });
    g.finish();
}

criterion_group!(benches, saves);
criterion_main!(benches);
