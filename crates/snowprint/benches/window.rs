//! What a terrain's sliding window costs a frame: a 1024^2 near level of 5 cm and a 512^2 far
//! level of 40 cm following a walker at a hiking (1.5 m/s) and a running (5 m/s) speed, each frame
//! `Terrain::follow` (the strips that leave read back and paged out, the entering ones written,
//! the leaving ones folded into the far level) and the world's update of both levels with the
//! walker's foot, to the GPU idle; against the same update with the window standing still (no
//! scroll), and against the copy baseline: moving a window that is not stored toroidally means
//! copying both levels whole, out and back (`copy_buffer_to_buffer` of their 5 MiB at 16 bits),
//! every frame it moves.
//!
//! And the CPU that moving the levels' ground fields costs: the same levels on hills, followed
//! one near texel a call with no update in between.
//!
//! `cargo bench -p snowprint --bench window -- --warm-up-time 1 --measurement-time 10`.
//! Each iteration runs 60 frames (a second of walking); divide by 60 for a frame.
//! Results: `docs/PERFORMANCE.md`, "The sliding window".

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use snowprint::{
    Deformer, GpuContext, GpuOptions, HeightGrid, LevelDesc, Material, Pose, Shape, SlopeRule,
    SnowWorld, Terrain, TerrainDesc, TerrainGround, WorldConfig,
};

const DT: f32 = 1.0 / 60.0;
const FRAMES: u32 = 60;

fn terrain() -> TerrainDesc {
    TerrainDesc {
        name: "valley".into(),
        ground_height: 0.0,
        ground: None,
        snow_depth: 0.3,
        replenish_rate: 0.0,
        material: Material::snow(),
        levels: vec![
            LevelDesc {
                texels: [1024, 1024],
                texel_size: 0.05,
            },
            LevelDesc {
                texels: [512, 512],
                texel_size: 0.4,
            },
        ],
    }
}

struct Walk {
    world: SnowWorld,
    terrain: Terrain,
    /// Metres walked so far.
    x: f32,
}

impl Walk {
    fn new(gpu: &GpuContext) -> Self {
        let mut world = SnowWorld::new(
            gpu,
            WorldConfig {
                pool_bytes: 8 << 20,
                ..WorldConfig::default()
            },
        )
        .expect("world");
        let terrain = Terrain::new(&mut world, terrain(), Vec3::ZERO).expect("terrain");
        Self {
            world,
            terrain,
            x: 0.0,
        }
    }

    /// One second at `speed` m/s; the window follows when `follow`, else stands where it is
    /// (the foot walks back and forth 2 m inside it).
    fn second(&mut self, speed: f32, follow: bool) {
        for _ in 0..FRAMES {
            let before = self.x;
            self.x += speed * DT;
            let at = |x: f32| {
                let x = if follow { x } else { x % 2.0 };
                Pose::at([x, 0.2, 0.1])
            };
            let foot = Deformer::moving(Shape::Sphere { radius: 0.12 }, at(before), at(self.x));
            if follow {
                self.terrain
                    .follow(&mut self.world, Vec3::new(self.x, 0.0, 0.0))
                    .expect("follow");
            }
            self.world.step(DT, &[foot]).expect("step");
        }
        self.terrain.flush(&mut self.world).expect("flush");
        let id = self.terrain.surfaces()[1];
        black_box(self.world.read_packed(id).expect("read"));
    }
}

/// The copy baseline: both levels' slots copied out and back once a frame, to the GPU idle.
fn copies(world: &SnowWorld, scratch: &wgpu::Buffer, bytes: u64) {
    for _ in 0..FRAMES {
        let mut enc = world.device().create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(world.pool_buffer(), 0, scratch, 0, bytes);
        enc.copy_buffer_to_buffer(scratch, 0, world.pool_buffer(), 0, bytes);
        world.queue().submit([enc.finish()]);
        world
            .device()
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
    }
}

/// The terrain on hills: sine hills over 200 m x 200 m of the world, a grid of 257^2 heights.
fn on_hills() -> TerrainDesc {
    let n = 257u32;
    let hill = |i: u32| {
        let (x, z) = ((i % n) as f32 * 0.78, (i / n) as f32 * 0.78);
        3.0 * (x * 0.05).sin() * (z * 0.04).cos() + 0.5 * (x * 0.6).sin()
    };
    TerrainDesc {
        ground: Some(TerrainGround {
            grid: HeightGrid {
                columns: n,
                rows: n,
                heights: (0..n * n).map(hill).collect(),
            },
            origin: [-100.0, -100.0],
            size: [200.0, 200.0],
            slope: SlopeRule::default(),
        }),
        ..terrain()
    }
}

/// The CPU of `Terrain::follow` on hills, the focus moving one near texel (5 cm) a call along x
/// (the far level moves every eighth call), 60 calls; the strips' GPU work is left to run.
fn follow_on_hills(world: &mut SnowWorld, terrain: &mut Terrain, x: &mut f32) {
    for _ in 0..FRAMES {
        *x += 0.05;
        terrain
            .follow(world, Vec3::new(*x, 0.0, 0.0))
            .expect("follow");
    }
    terrain.flush(world).expect("flush");
}

fn window(c: &mut Criterion) {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("GPU");
    let mut g = c.benchmark_group("window");
    g.sample_size(10);
    {
        let mut world = SnowWorld::new(
            &gpu,
            WorldConfig {
                pool_bytes: 8 << 20,
                ..WorldConfig::default()
            },
        )
        .expect("world");
        let mut terrain = Terrain::new(&mut world, on_hills(), Vec3::ZERO).expect("terrain");
        let mut x = 0.0;
        g.bench_function(
            "1024^2 + 512^2 on hills, 60 follows of one near texel: follow only",
            |b| b.iter(|| follow_on_hills(&mut world, &mut terrain, &mut x)),
        );
    }
    for (name, speed) in [("hiking 1.5 m/s", 1.5), ("running 5 m/s", 5.0)] {
        let mut walk = Walk::new(&gpu);
        g.bench_function(
            format!("1024^2 + 512^2, {name}, 60 frames: follow + update"),
            |b| b.iter(|| walk.second(speed, true)),
        );
        let s = walk.terrain.stats();
        println!(
            "window {name} on {}: {} scrolls, {} bytes written, {} folded, {} texels paged in, store {} bytes",
            gpu.info.name,
            s.scrolls,
            s.bytes_written,
            s.bytes_folded,
            s.texels_paged_in,
            s.store_bytes
        );
    }
    let mut still = Walk::new(&gpu);
    g.bench_function(
        "1024^2 + 512^2, standing window, 60 frames: update only",
        |b| b.iter(|| still.second(1.5, false)),
    );
    let f = still.world.pool_format();
    let bytes = f.slot_bytes(1024, 1024) + f.slot_bytes(512, 512);
    let scratch = still.world.device().create_buffer(&wgpu::BufferDescriptor {
        label: Some("copy baseline"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    g.bench_function("copy baseline: both levels out and back, 60 frames", |b| {
        b.iter(|| copies(&still.world, &scratch, bytes))
    });
    g.finish();
}

criterion_group!(benches, window);
criterion_main!(benches);
