//! No imprint is lost (docs/MANAGER.md, "No lost imprints"): a budget, eviction, inactivity,
//! zones and crowds change when a trail is pressed, never what it presses. Each test runs the
//! same inputs through a manager under pressure and through one with no budget and a pool that
//! holds everything, and compares the heightmaps texel for texel on the GPU (software Vulkan in
//! CI).

mod common;

use glam::Vec3;
use snowprint::manager::{
    CameraView, ManagedDeformer, ManagedId, ManagerConfig, SnowManager, UNLIMITED, ZoneId,
};
use snowprint::{Camera, Deformer, Heightmap, Mesh, Pose, Shape, SurfaceDesc};

const DT: f32 = 1.0 / 60.0;

/// The unlimited settings: every due surface updated every frame, a pool that holds everything.
fn unlimited() -> ManagerConfig {
    ManagerConfig {
        updates_per_frame: UNLIMITED,
        pool_bytes: 64 << 20,
        active_distance: 500.0,
        ..ManagerConfig::default()
    }
}

fn manager(config: ManagerConfig, surfaces: &[SurfaceDesc]) -> (SnowManager, Vec<ManagedId>) {
    let mut m = SnowManager::new(common::gpu(), config).expect("manager");
    let ids = surfaces
        .iter()
        .map(|s| m.add_surface(s.clone(), ZoneId(0)).expect("surface"))
        .collect();
    (m, ids)
}

fn read_all(m: &SnowManager, ids: &[ManagedId]) -> Vec<Heightmap> {
    ids.iter()
        .map(|&id| m.read_heightmap(id).expect("read"))
        .collect()
}

/// Texels where two heightmaps differ, as `(surface, texel, a, b)` of the first few.
fn differences(a: &[Heightmap], b: &[Heightmap]) -> Vec<(usize, usize, u16, u16)> {
    let mut out = Vec::new();
    for (s, (x, y)) in a.iter().zip(b).enumerate() {
        for (t, (p, q)) in x
            .depression
            .iter()
            .zip(&y.depression)
            .chain(x.displaced.iter().zip(&y.displaced))
            .enumerate()
        {
            if p != q && out.len() < 8 {
                out.push((s, t, *p, *q));
            }
        }
    }
    out
}

/// The 16 roofs: 4 m x 4 m in a 5-wide grid 6 m apart, snow 0.15 m, no snowfall; on each
/// a sphere of radius 0.3 m, its centre 0.35 m above the roof, crosses along x in 1.4 s.
fn sixteen_roofs() -> Vec<SurfaceDesc> {
    (0..16)
        .map(|i| {
            let (cx, cz) = ((i % 5) as f32 * 6.0, (i / 5) as f32 * 6.0);
            SurfaceDesc::new(&format!("roof{i}"), [cx, 4.0, cz], [4.0, 4.0], 0.15)
        })
        .collect()
}

fn crossing_spheres(roofs: &[SurfaceDesc], frame: u32) -> Vec<ManagedDeformer> {
    let at = |f: u32, r: &SurfaceDesc| {
        let t = (f as f32 * DT / 1.4).min(1.0);
        Pose::at([
            r.center.x - 2.6 + 5.2 * t,
            r.center.y + 0.35,
            r.center.z + 0.3,
        ])
    };
    roofs
        .iter()
        .map(|r| {
            ManagedDeformer::new(Deformer::moving(
                Shape::Sphere { radius: 0.3 },
                at(frame.saturating_sub(1), r),
                at(frame, r),
            ))
        })
        .collect()
}

/// The defect: with a budget of 2 and no camera, read at every frame from 1 to 120, a
/// roof never shows less than it showed before, equals the unlimited run once its queue is
/// empty, and every roof ends with its whole trail.
#[test]
fn sixteen_roofs_on_a_budget_of_two_never_read_as_untouched() {
    let roofs = sixteen_roofs();
    let (mut budget, ids) = manager(
        ManagerConfig {
            updates_per_frame: 2,
            pool_bytes: 2 << 20,
            active_distance: 500.0,
            ..ManagerConfig::default()
        },
        &roofs,
    );
    let (mut free, free_ids) = manager(unlimited(), &roofs);
    let mut last: Vec<Heightmap> = read_all(&budget, &ids);
    let mut compared = 0;
    for frame in 1..=120 {
        let ds = crossing_spheres(&roofs, frame);
        budget.tick(DT, None, &ds).unwrap();
        free.tick(DT, None, &ds).unwrap();
        let now = read_all(&budget, &ids);
        let reference = read_all(&free, &free_ids);
        for (s, (n, l)) in now.iter().zip(&last).enumerate() {
            for (t, (a, b)) in n.depression.iter().zip(&l.depression).enumerate() {
                assert!(
                    a >= b,
                    "frame {frame}: roof{s} texel {t} went from {b} to {a}"
                );
            }
            if budget.planner().queued_imprints(ids[s]) == 0 {
                assert_eq!(
                    differences(&now[s..=s], &reference[s..=s]),
                    vec![],
                    "frame {frame}: roof{s} with nothing queued differs from the unlimited run"
                );
                compared += 1;
            }
        }
        last = now;
    }
    // The crossing ends at frame 84; within a few frames every queue is empty and every read from
    // then on is compared.
    assert!(compared >= 16 * 31, "reads compared: {compared}");
    assert_eq!(budget.planner().pending_surfaces(), 0);
    for (s, map) in last.iter().enumerate() {
        let pressed = map.depression.iter().filter(|&&d| d > 30_000).count();
        assert!(pressed > 500, "roof{s} holds its trail: {pressed} texels");
    }
    assert_eq!(budget.stats().resident, 16);
}

/// A pool that holds 2 of 6 surfaces, walkers on all six in turn: every trail is intact at the
/// end, texel for texel, against an unlimited pool, and the heightmaps went out and came back in.
#[test]
fn evicted_trails_come_back_texel_for_texel() {
    let surfaces: Vec<SurfaceDesc> = (0..6)
        .map(|i| {
            SurfaceDesc::new(
                &format!("s{i}"),
                [i as f32 * 5.0, 0.0, 0.0],
                [3.0, 3.0],
                0.2,
            )
        })
        .collect();
    let slot = snowprint::PoolFormat::default().slot_bytes(75, 75);
    let (mut small, ids) = manager(
        ManagerConfig {
            pool_bytes: 2 * slot + 256,
            ..ManagerConfig::default()
        },
        &surfaces,
    );
    let (mut free, free_ids) = manager(unlimited(), &surfaces);
    // A walker crosses surface k during frames 20k..20k+20, then surface 0 again at the end.
    let foot = |f: u32| -> Vec<ManagedDeformer> {
        let k = (f / 20) as usize % 7;
        let k = if k == 6 { 0 } else { k };
        let t = (f % 20) as f32 / 20.0;
        let x = k as f32 * 5.0 - 1.2 + 2.4 * t;
        let z = if k == 0 && f >= 120 { 0.8 } else { -0.4 };
        let step = |x: f32| Pose::at([x, 0.17, z]);
        vec![ManagedDeformer::player(Deformer::moving(
            Shape::Sphere { radius: 0.12 },
            step(x - 2.4 / 20.0),
            step(x),
        ))]
    };
    let mut paged_in = 0;
    let mut paged_out = 0;
    for f in 0..140 {
        let s = small.tick(DT, None, &foot(f)).unwrap();
        paged_in += s.paged_in_bytes;
        paged_out += s.paged_out_bytes;
        assert!(s.pool_bytes_used <= 2 * slot + 256);
        free.tick(DT, None, &foot(f)).unwrap();
    }
    small.flush().unwrap();
    free.flush().unwrap();
    assert!(
        paged_out > 0 && paged_in > 0,
        "{paged_out} out, {paged_in} in"
    );
    let (a, b) = (read_all(&small, &ids), read_all(&free, &free_ids));
    assert_eq!(differences(&a, &b), vec![]);
    for (k, map) in a.iter().enumerate() {
        assert!(map.pressed_volume() > 20.0, "s{k} has its trail");
    }
    // Surface 0 was crossed twice, once before it was paged out and once after it came back.
    let rows = |m: &Heightmap, z: f32| {
        let row = ((z + 1.5) / 3.0 * 75.0) as u32;
        (0..75)
            .filter(|&c| m.depression[(row * 75 + c) as usize] > 30_000)
            .count()
    };
    assert!(rows(&a[0], -0.4) > 20 && rows(&a[0], 0.8) > 20);
}

/// 10,000 small spheres on one 4 m x 4 m surface, each pressing its own spot, with a budget of
/// two updates a frame: all 10,000 spots are pressed, as without a budget.
#[test]
fn a_crowd_of_ten_thousand_presses_every_spot() {
    let roof = [SurfaceDesc::new("crowd", [0.0, 0.0, 0.0], [4.0, 4.0], 0.2)];
    let spots: Vec<Vec3> = (0..10_000)
        .map(|i| {
            // A 100 x 100 grid, one spot a texel (4 cm), a sphere of 1.5 cm each.
            let (c, r) = ((i % 100) as f32, (i / 100) as f32);
            Vec3::new(-2.0 + 0.04 * (c + 0.5), 0.2, -2.0 + 0.04 * (r + 0.5))
        })
        .collect();
    let crowd: Vec<ManagedDeformer> = spots
        .iter()
        .map(|&p| {
            ManagedDeformer::new(Deformer::new(
                Shape::Sphere { radius: 0.015 },
                Pose::at(p.into()),
            ))
        })
        .collect();
    let (mut m, ids) = manager(
        ManagerConfig {
            updates_per_frame: 2,
            ..ManagerConfig::default()
        },
        &roof,
    );
    for _ in 0..3 {
        let s = m.tick(DT, None, &crowd).unwrap();
        assert_eq!(s.imprints_merged, 0);
    }
    let map = m.read_heightmap(ids[0]).unwrap();
    let pressed = spots
        .iter()
        .filter(|p| {
            let (c, r) = (((p.x + 2.0) / 0.04) as u32, ((p.z + 2.0) / 0.04) as u32);
            map.depression[(r * 100 + c) as usize] > 0
        })
        .count();
    assert_eq!(pressed, 10_000);
}

mod reposing {
    use super::*;
    use proptest::prelude::*;

    /// One walker: a path over the row of surfaces, a shape, and whether it is a mesh that is
    /// re-posed (stretched) every few frames.
    #[derive(Clone, Debug)]
    struct Walker {
        start: Vec3,
        velocity: Vec3,
        radius: f32,
        mesh: bool,
        repose_every: u32,
    }

    fn walker() -> impl Strategy<Value = Walker> {
        (
            -2f32..14.0,
            -1.2f32..1.2,
            -0.05f32..0.05,
            -0.02f32..0.02,
            0.06f32..0.2,
            any::<bool>(),
            2u32..6,
        )
            .prop_map(|(x, z, vx, vz, radius, mesh, repose_every)| Walker {
                start: Vec3::new(x, 0.2, z),
                velocity: Vec3::new(vx * 4.0, 0.0, vz * 4.0),
                radius,
                mesh,
                repose_every,
            })
    }

    /// What the deformers of `walkers` are at `frame` (meshes get their handles from `meshes`).
    fn deformers(
        walkers: &[Walker],
        meshes: &[snowprint::MeshId],
        frame: u32,
    ) -> Vec<ManagedDeformer> {
        walkers
            .iter()
            .enumerate()
            .map(|(k, w)| {
                let at = |f: u32| Pose::at((w.start + w.velocity * f as f32).into());
                let shape = if w.mesh {
                    Shape::Mesh(meshes[k])
                } else {
                    Shape::Sphere { radius: w.radius }
                };
                ManagedDeformer::new(Deformer::moving(
                    shape,
                    at(frame.saturating_sub(1)),
                    at(frame),
                ))
            })
            .collect()
    }

    /// A mesh walker's posing at `frame`: a box that changes height and width as it goes.
    fn posing(w: &Walker, frame: u32) -> Vec<Vec3> {
        let phase = (frame / w.repose_every) % 3;
        let h = Vec3::new(
            w.radius,
            w.radius * (0.5 + 0.4 * phase as f32),
            w.radius * 0.7,
        );
        Mesh::cuboid(h).positions
    }

    /// The heightmaps after a flush, the bytes paged out and the most imprints queued at once.
    fn run(
        walkers: &[Walker],
        config: ManagerConfig,
        camera_turns: bool,
    ) -> (Vec<Heightmap>, u64, usize) {
        let surfaces: Vec<SurfaceDesc> = (0..5)
            .map(|i| {
                SurfaceDesc::new(
                    &format!("s{i}"),
                    [i as f32 * 3.0, 0.0, 0.0],
                    [2.5, 2.5],
                    0.2,
                )
            })
            .collect();
        let (mut m, ids) = manager(config, &surfaces);
        let (mut paged, mut queued) = (0, 0);
        let meshes: Vec<snowprint::MeshId> = walkers
            .iter()
            .enumerate()
            .map(|(k, w)| {
                m.add_mesh(&format!("w{k}"), &Mesh::cuboid(Vec3::splat(w.radius)))
                    .unwrap()
            })
            .collect();
        for f in 0..36 {
            for (k, w) in walkers.iter().enumerate() {
                if w.mesh && f % w.repose_every == 0 {
                    m.pose_mesh(meshes[k], &posing(w, f)).unwrap();
                }
            }
            // A camera that looks at the row, then away from it, then back.
            let eye = Vec3::new(6.0, 8.0, 10.0);
            let target = if camera_turns && (12..24).contains(&f) {
                Vec3::new(6.0, 8.0, 30.0)
            } else {
                Vec3::new(6.0, 0.0, 0.0)
            };
            let cam = CameraView::new(
                &Camera {
                    eye,
                    target,
                    fov_y_degrees: 60.0,
                },
                1.5,
            );
            let s = m
                .tick(DT, Some(&cam), &deformers(walkers, &meshes, f))
                .unwrap();
            paged += s.paged_out_bytes;
            queued = queued.max(s.queued_imprints);
        }
        m.flush().unwrap();
        (read_all(&m, &ids), paged, queued)
    }

    fn pressured() -> ManagerConfig {
        let slot = snowprint::PoolFormat::default().slot_bytes(63, 63);
        ManagerConfig {
            updates_per_frame: 1,
            pool_bytes: 2 * slot + 256,
            active_distance: 500.0,
            ..ManagerConfig::default()
        }
    }

    /// The same with three walkers chosen to cross every surface: the pressured run really pages
    /// and queues.
    #[test]
    fn three_walkers_across_the_row_page_queue_and_lose_nothing() {
        let w = |x: f32, z: f32, mesh: bool| Walker {
            start: Vec3::new(x, 0.2, z),
            velocity: Vec3::new(0.4, 0.0, 0.0),
            radius: 0.15,
            mesh,
            repose_every: 3,
        };
        let walkers = [w(-1.0, -0.6, true), w(0.0, 0.0, false), w(1.0, 0.6, true)];
        let (a, paged, queued) = run(&walkers, pressured(), true);
        let (b, _, _) = run(&walkers, unlimited(), false);
        assert!(
            paged > 0 && queued >= 2,
            "paged {paged} bytes, queued {queued}"
        );
        assert_eq!(differences(&a, &b), vec![]);
        assert!(a.iter().all(|m| m.pressed_volume() > 10.0));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

        /// Moving and re-posed meshes and spheres, a camera that turns away, a budget of one
        /// update a frame and a pool of two surfaces (evictions, paging): after a flush every
        /// surface equals the unlimited run's, which captured every frame as it came (the oracle
        /// does not use the queue).
        #[test]
        fn budget_eviction_view_and_reposing_change_nothing(
            walkers in proptest::collection::vec(walker(), 1..6),
        ) {
            let (a, _, _) = run(&walkers, pressured(), true);
            let (b, _, _) = run(&walkers, unlimited(), false);
            prop_assert_eq!(differences(&a, &b), vec![]);
        }
    }
}
