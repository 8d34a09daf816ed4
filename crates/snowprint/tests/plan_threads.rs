//! A frame of many surfaces planned on several threads (`WorldConfig::plan_threads`) updates the
//! snow exactly as one planned on the calling thread: the same heights, the same footsteps.

mod common;

use snowprint::{
    CapturePath, Deformer, PoolFormat, Pose, Precision, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    SurfaceUpdate, WorldConfig,
};

/// Surfaces of 16 x 16 texels (0.64 m at 4 cm), a row of them.
const SURFACES: u32 = 520;

fn world(plan_threads: usize, capture_path: CapturePath) -> (SnowWorld, Vec<SurfaceId>) {
    let format = PoolFormat::new(Precision::Bits8);
    let mut world = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: format.slot_bytes(16, 16) * SURFACES as u64,
            capture_path,
            format,
            plan_threads,
            ..Default::default()
        },
    )
    .expect("world");
    let ids = (0..SURFACES)
        .map(|i| {
            let c = [(i % 20) as f32, 0.0, (i / 20) as f32];
            let mut desc = SurfaceDesc::new(&format!("s{i}"), c, [0.64, 0.64], 0.3);
            desc.replenish_rate = if i.is_multiple_of(3) { 0.2 } else { 0.0 };
            desc.yaw_degrees = (i % 7) as f32 * 10.0;
            world.add_surface(desc).expect("surface")
        })
        .collect();
    (world, ids)
}

/// Frame `f`'s deformers of surface `i`: a ball stepping down into the snow (0.3 m deep, its
/// lowest point at 0.37, 0.31, 0.25 and 0.19 m: it lands in frame 1), none over every fifth
/// surface.
fn feet(i: u32, f: u32) -> Vec<Deformer> {
    if i.is_multiple_of(5) {
        return Vec::new();
    }
    let c = [(i % 20) as f32, 0.0, (i / 20) as f32];
    let at = |k: u32| {
        let t = (i + k) as f32 * 0.37;
        Pose::at([
            c[0] + 0.2 * t.cos(),
            0.47 - 0.06 * k as f32,
            c[2] + 0.2 * t.sin(),
        ])
    };
    vec![Deformer::moving(
        Shape::Sphere { radius: 0.1 },
        at(f),
        at(f + 1),
    )]
}

#[test]
fn many_surfaces_planned_on_threads_update_as_on_one() {
    for path in [CapturePath::Update, CapturePath::Compute] {
        let (mut one, ids) = world(1, path);
        let (mut three, _) = world(3, path);
        for f in 0..3 {
            let lists: Vec<Vec<Deformer>> = (0..SURFACES).map(|i| feet(i, f)).collect();
            let updates: Vec<SurfaceUpdate<'_>> = ids
                .iter()
                .zip(&lists)
                .map(|(&surface, deformers)| SurfaceUpdate {
                    surface,
                    elapsed: 0.1,
                    deformers,
                })
                .collect();
            let a = one.update(&updates).expect("update");
            let b = three.update(&updates).expect("update");
            assert_eq!((a.updated, a.primitives), (b.updated, b.primitives));
            assert!(a.primitives > 0);
            // The steps account for the encode's time, and only a split plan gathers.
            for (stats, gathers) in [(&a, false), (&b, true)] {
                let s = stats.cpu_steps;
                let steps = [s.check_ms, s.plan_ms, s.gather_ms, s.tables_ms];
                let steps = steps.into_iter().chain([s.upload_ms, s.record_ms]);
                assert!(steps.clone().all(|ms| ms >= 0.0));
                assert!(steps.sum::<f64>() <= stats.cpu_encode_ms, "{s:?}");
                assert!(s.plan_ms > 0.0 && s.record_ms > 0.0, "{s:?}");
                assert_eq!(s.gather_ms > 0.0, gathers, "{s:?}");
            }
            assert_eq!(one.footsteps(), three.footsteps(), "{path:?}, frame {f}");
            assert_eq!(one.footsteps().is_empty(), f != 1);
        }
        for &id in &ids {
            assert_eq!(
                one.read_packed(id).expect("heights"),
                three.read_packed(id).expect("heights"),
                "{path:?}"
            );
        }
    }
}

/// Frame `f`'s deformers of every surface: `feet`, each ball 24 times (so that the frame's
/// primitives, 0.8 MB, go through the world's staging buffers, from 0.5 MB).
fn frame_lists(f: u32) -> Vec<Vec<Deformer>> {
    (0..SURFACES).map(|i| feet(i, f).repeat(24)).collect()
}

fn updates<'a>(ids: &[SurfaceId], lists: &'a [Vec<Deformer>]) -> Vec<SurfaceUpdate<'a>> {
    ids.iter()
        .zip(lists)
        .map(|(&surface, deformers)| SurfaceUpdate {
            surface,
            elapsed: 0.1,
            deformers,
        })
        .collect()
}

/// A split frame whose primitives went to a staging buffer of the world's but that is then
/// abandoned, or refused once planned (a deformer it cannot take), leaves nothing behind: the
/// frames after it update the snow as a world planning on one thread, frame after frame (more
/// frames than the world keeps staging buffers, so that they are used again).
#[test]
fn abandoned_and_refused_split_frames_leave_the_next_ones_whole() {
    let gpu = common::gpu();
    let (mut one, ids) = world(1, CapturePath::Update);
    let (mut three, _) = world(3, CapturePath::Update);
    // Abandoned: encoded into an encoder that is dropped.
    let lists = frame_lists(0);
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    let pending = three.encode_update(&mut encoder, &updates(&ids, &lists));
    drop((pending.expect("encode"), encoder));
    three.abandon_pending();
    // Refused: the last surface's sphere has a negative radius.
    let mut bad = frame_lists(1);
    bad[SURFACES as usize - 1] = vec![Deformer::new(
        Shape::Sphere { radius: -1.0 },
        Pose::at([0.0, 0.0, 0.0]),
    )];
    assert!(three.update(&updates(&ids, &bad)).is_err());
    for f in 0..6 {
        let lists = frame_lists(f);
        let a = one.update(&updates(&ids, &lists)).expect("update");
        let b = three.update(&updates(&ids, &lists)).expect("update");
        assert_eq!(
            (a.primitives, b.cpu_steps.gather_ms > 0.0),
            (b.primitives, true)
        );
        assert!(b.primitives as usize * 80 > 512 << 10, "{}", b.primitives);
    }
    for &id in &ids {
        assert_eq!(
            one.read_packed(id).expect("heights"),
            three.read_packed(id).expect("heights")
        );
    }
}
