//! What skinning characters costs a frame: 1, 10 and 100 RiggedFigure deformers (370 vertices, 19
//! joints each) posed at a new animation time with `SnowWorld::animate_meshes` (the skeletons
//! sampled on the CPU, the joint matrices uploaded, one compute pass over every figure, submitted)
//! and waited for, so each iteration is the whole per-frame cost to the GPU being idle. A pass that
//! only skinned one figure would be dominated by the submit; the 1 / 10 / 100 rows show how the
//! cost grows with the figures.
//!
//! `cargo bench -p snowprint --bench skinning -- --warm-up-time 1 --measurement-time 5`.
//! Results: `docs/PERFORMANCE.md`, "GPU skinning".

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use snowprint::{GpuContext, GpuOptions, MeshAnimation, Playback, SkinnedMesh, SnowWorld};

fn skinning(c: &mut Criterion) {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU");
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/RiggedFigure.gltf");
    let figure = SkinnedMesh::load_gltf(&path).expect("RiggedFigure");
    let mut g = c.benchmark_group("skinning");
    for n in [1usize, 10, 100] {
        let mut world = SnowWorld::new(&gpu, Default::default()).expect("world");
        let ids: Vec<_> = (0..n)
            .map(|i| {
                world
                    .add_skinned_mesh(&format!("figure {i}"), &figure)
                    .expect("mesh")
            })
            .collect();
        let mut t = 0.0f32;
        g.bench_function(format!("{n} figures, animate_meshes to idle"), |b| {
            b.iter(|| {
                t += 1.0 / 60.0;
                let poses: Vec<MeshAnimation> = ids
                    .iter()
                    .enumerate()
                    .map(|(i, &mesh)| MeshAnimation {
                        mesh,
                        animation: Some(0),
                        time: t + i as f32 * 0.01,
                        playback: Playback::Loop,
                    })
                    .collect();
                world.animate_meshes(black_box(&poses)).expect("animate");
                gpu.device
                    .poll(snowprint::wgpu::PollType::wait_indefinitely())
                    .expect("poll");
            })
        });
    }
    g.finish();
}

criterion_group!(benches, skinning);
criterion_main!(benches);
