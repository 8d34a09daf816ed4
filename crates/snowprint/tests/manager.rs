//! The surface manager (issue 4): the planner's bounds as property tests (no GPU), and on the GPU
//! dragged spheres: trails made with a budget of 2 updates a frame against trails made with no
//! budget at all. The tests on a generated city and its walkers (the 20-walker test among them)
//! are in the demo crate, which owns the city generator: `crates/snowprint-demo/tests/city.rs`.

mod common;

use std::collections::HashMap;

use glam::{Quat, Vec3};
use proptest::prelude::*;
use snowprint::PoolFormat;
use snowprint::low_level::queue;
use snowprint::manager::{
    CameraView, CatchUp, Lookup, ManagedDeformer, ManagedId, ManagerConfig, Planner,
    ResidencyChange, SnowManager, UNLIMITED, ZoneId,
};

/// Pool bytes of a surface's slot in the managers' default format.
fn slot_bytes(layout: snowprint::SurfaceLayout) -> u64 {
    PoolFormat::default().slot_bytes(layout.width, layout.height)
}
use snowprint::{Camera, Deformer, Heightmap, Pose, Shape, SnowError, SurfaceDesc};

// ---------------------------------------------------------------------------------------------
// Random scenarios for the planner.

#[derive(Clone, Debug)]
struct Mover {
    surface: usize,
    shape: Shape,
    circle: f32,
    speed: f32,
    phase: f32,
    player: bool,
}

#[derive(Clone, Debug)]
struct Scenario {
    config: ManagerConfig,
    surfaces: Vec<(SurfaceDesc, ZoneId)>,
    movers: Vec<Mover>,
    camera: Option<CameraView>,
    zone_events: Vec<(u64, ZoneId, bool)>,
    frames: u64,
}

impl Scenario {
    fn pose(&self, m: &Mover, frame: u64) -> Pose {
        let s = &self.surfaces[m.surface % self.surfaces.len()].0;
        let a = m.phase + m.speed * frame as f32;
        let r = m.shape.bounding_radius().unwrap_or(0.1);
        let top = s.center + Vec3::Y * (s.snow_depth + r * 0.5);
        Pose {
            position: top + Vec3::new(a.cos(), 0.0, a.sin()) * m.circle,
            rotation: Quat::from_rotation_y(a),
        }
    }

    fn deformers(&self, frame: u64) -> Vec<ManagedDeformer> {
        self.movers
            .iter()
            .map(|m| {
                let pose = self.pose(m, frame);
                let deformer = if frame == 0 {
                    Deformer::new(m.shape, pose)
                } else {
                    Deformer::moving(m.shape, self.pose(m, frame - 1), pose)
                };
                ManagedDeformer {
                    deformer,
                    player: m.player,
                }
            })
            .collect()
    }

    fn planner(&self, lookup: Lookup) -> Planner {
        let mut p = Planner::new(&self.config).expect("valid config");
        p.set_lookup(lookup);
        for (desc, zone) in &self.surfaces {
            p.add_surface(desc, *zone)
                .expect("valid surface that fits the pool");
        }
        p
    }

    fn zone_events_at(&self, p: &mut Planner, frame: u64) {
        for &(f, zone, load) in &self.zone_events {
            if f == frame {
                if load {
                    p.load_zone(zone);
                } else {
                    p.unload_zone(zone);
                }
            }
        }
    }
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (0.05f32..0.4).prop_map(|radius| Shape::Sphere { radius }),
        (0.05f32..0.2, 0.0f32..0.3).prop_map(|(radius, half_height)| Shape::Capsule {
            radius,
            half_height
        }),
        (0.05f32..0.3, 0.05f32..0.3, 0.05f32..0.3).prop_map(|(x, y, z)| Shape::Box {
            half_extents: Vec3::new(x, y, z)
        }),
    ]
}

fn scenario() -> impl Strategy<Value = Scenario> {
    let surfaces = prop::collection::vec(
        (
            -25f32..25.0,
            0u32..3,
            -25f32..25.0,
            1f32..6.0,
            1f32..6.0,
            -45f32..45.0,
            0.1f32..0.4,
            prop::bool::weighted(0.3),
            0u32..3,
        ),
        1..30,
    )
    .prop_map(|v| {
        v.into_iter()
            .enumerate()
            .map(|(i, (x, level, z, sx, sz, yaw, depth, snowing, zone))| {
                let desc = SurfaceDesc {
                    yaw_degrees: yaw,
                    replenish_rate: if snowing { 0.5 } else { 0.0 },
                    ..SurfaceDesc::new(
                        &format!("s{i}"),
                        [x, level as f32 * 4.0, z],
                        [sx, sz],
                        depth,
                    )
                };
                (desc, ZoneId(zone))
            })
            .collect::<Vec<_>>()
    });
    let config = (
        1usize..5,
        300_000u64..2_500_000,
        0u32..10,
        0usize..3,
        any::<bool>(),
        1usize..20,
        5f32..80.0,
    )
        .prop_map(
            |(k, pool, slack, player_slots, page_limit, cap, reach)| ManagerConfig {
                updates_per_frame: k,
                pool_bytes: pool,
                distance_slack_frames: slack,
                player_slots,
                // A page store that holds about two slots, or no limit.
                page_bytes: if page_limit { 200_000 } else { u64::MAX },
                queue_cap: cap,
                active_distance: reach,
                replenish_interval: 0.05,
                ..ManagerConfig::default()
            },
        );
    let movers = prop::collection::vec(
        (0usize..64, shape(), 0f32..3.0, 0f32..0.3, 0f32..6.3),
        0..12,
    )
    .prop_map(|v| {
        v.into_iter()
            .enumerate()
            .map(|(i, (surface, shape, circle, speed, phase))| Mover {
                surface,
                shape,
                circle,
                speed,
                phase,
                player: i == 0,
            })
            .collect::<Vec<_>>()
    });
    let camera = prop::option::of((
        -30f32..30.0,
        1f32..30.0,
        -30f32..30.0,
        -20f32..20.0,
        -20f32..20.0,
    ))
    .prop_map(|c| {
        c.map(|(x, y, z, tx, tz)| {
            CameraView::new(
                &Camera {
                    eye: Vec3::new(x, y, z),
                    target: Vec3::new(tx, 0.0, tz),
                    fov_y_degrees: 70.0,
                },
                1.5,
            )
        })
    });
    let events = prop::collection::vec((0u64..40, 0u32..3, any::<bool>()), 0..4).prop_map(|v| {
        v.into_iter()
            .map(|(f, z, l)| (f, ZoneId(z), l))
            .collect::<Vec<_>>()
    });
    (config, surfaces, movers, camera, events).prop_map(
        |(config, surfaces, movers, camera, zone_events)| Scenario {
            config,
            surfaces,
            movers,
            camera,
            zone_events,
            frames: 40,
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Every tick: at most K updates, only of resident surfaces, each once; pool bytes exactly the
    /// sum of the resident slots and never over the budget; a heightmap is given up only for
    /// memory (an eviction in a tick that admits another surface) or a zone unload, and then
    /// paged, within the page store's budget; and no resident surface waits longer than the
    /// stated bound `S + floor((n - 1) / (K - reserved))`.
    #[test]
    fn budget_pool_and_starvation_bounds_hold(sc in scenario()) {
        let mut p = sc.planner(Lookup::QuadTree);
        let k = sc.config.updates_per_frame;
        let mut due_history: Vec<usize> = Vec::new();
        let dt = 1.0 / 30.0;
        for frame in 0..sc.frames {
            sc.zone_events_at(&mut p, frame);
            let deformers = sc.deformers(frame);
            let plan = p.tick(dt, sc.camera.as_ref(), &deformers).expect("valid input").clone();
            due_history.push(plan.stats.due);
            let evictions = plan.changes.iter().filter(|c| matches!(c, ResidencyChange::Evict(_))).count();
            let admissions = plan.changes.iter().filter(|c| matches!(c, ResidencyChange::Admit(_))).count();
            prop_assert!(evictions == 0 || admissions > 0, "evicted {} without admitting anything", evictions);
            for c in &plan.changes {
                if let ResidencyChange::Evict(id) = c {
                    prop_assert!(p.is_paged(*id), "an evicted heightmap is paged");
                }
            }
            let paged: u64 = (0..sc.surfaces.len() as u32)
                .map(ManagedId::from_index)
                .filter(|&id| p.is_paged(id))
                .map(|id| slot_bytes(p.surface(id).unwrap().layout()))
                .sum();
            // Evictions stay within the page store's budget; a zone unload pages whatever it
            // must (the game asked for it), and later evictions then wait for room.
            let unloaded = sc.zone_events.iter().any(|&(f, _, load)| !load && f <= frame);
            prop_assert!(unloaded || paged <= sc.config.page_bytes, "{} paged bytes over {}", paged, sc.config.page_bytes);
            prop_assert_eq!(plan.stats.frame, frame);
            prop_assert!(plan.updates.len() <= k, "{} updates with a budget of {}", plan.updates.len(), k);
            let mut seen = std::collections::HashSet::new();
            for u in &plan.updates {
                prop_assert!(seen.insert(u.surface), "surface updated twice");
                prop_assert!(p.is_resident(u.surface));
                let first = (frame - u.wait_frames) as usize;
                let n = due_history[first..].iter().copied().max().unwrap_or(1);
                prop_assert!(u.wait_frames <= p.wait_bound(n),
                    "waited {} frames, bound {} (n = {})", u.wait_frames, p.wait_bound(n), n);
            }
            let resident: Vec<ManagedId> = p.resident().collect();
            let bytes: u64 = resident.iter().map(|&id| slot_bytes(p.surface(id).unwrap().layout())).sum();
            prop_assert_eq!(bytes, p.pool_used());
            prop_assert_eq!(plan.stats.pool_bytes_used, bytes);
            prop_assert!(bytes <= p.pool_budget());
            prop_assert_eq!(plan.stats.resident, resident.len());
            for &id in &resident {
                prop_assert!(!p.is_paged(id));
                prop_assert!(p.zone_loaded(sc.surfaces[id.index() as usize].1));
                // Still waiting: within the bound too.
                if let Some(since) = p.due_since(id) {
                    let n = due_history[since as usize..].iter().copied().max().unwrap_or(1);
                    prop_assert!(frame - since <= p.wait_bound(n));
                }
            }
            prop_assert!(plan.stats.max_wait_frames <= p.wait_bound(due_history.iter().copied().max().unwrap_or(1)));
        }
    }

    /// The quad tree changes nothing but speed: the same plans as brute force, tick for tick.
    #[test]
    fn quad_tree_and_brute_force_plan_alike(sc in scenario()) {
        let mut fast = sc.planner(Lookup::QuadTree);
        let mut slow = sc.planner(Lookup::BruteForce);
        for frame in 0..sc.frames {
            sc.zone_events_at(&mut fast, frame);
            sc.zone_events_at(&mut slow, frame);
            let deformers = sc.deformers(frame);
            let a = fast.tick(0.02, sc.camera.as_ref(), &deformers).unwrap().clone();
            let b = slow.tick(0.02, sc.camera.as_ref(), &deformers).unwrap();
            prop_assert_eq!(&a, b);
        }
    }

    /// No imprint is lost: every deformer that reaches into a surface's capture volume, in any
    /// frame, is covered by an imprint later handed to that surface's update (with a pool that holds
    /// everything and queues that never overflow).
    #[test]
    fn every_touch_reaches_an_update(mut sc in scenario()) {
        sc.config.pool_bytes = 64 << 20;
        sc.config.queue_cap = 100_000;
        sc.zone_events.clear();
        let mut p = sc.planner(Lookup::QuadTree);
        let ankle = sc.config.capture.ankle_height;
        let mut applied: HashMap<ManagedId, Vec<Deformer>> = HashMap::new();
        let mut touches: Vec<(ManagedId, Deformer)> = Vec::new();
        let mut frame = 0;
        loop {
            let deformers = if frame < sc.frames { sc.deformers(frame) } else { Vec::new() };
            for (i, (desc, _)) in sc.surfaces.iter().enumerate() {
                for d in &deformers {
                    if reaches_into(desc, ankle, &d.deformer) {
                        touches.push((ManagedId::from_index(i as u32), d.deformer));
                    }
                }
            }
            let plan = p.tick(0.02, sc.camera.as_ref(), &deformers).unwrap();
            prop_assert_eq!(plan.stats.imprints_merged, 0);
            for u in &plan.updates {
                applied.entry(u.surface).or_default().extend_from_slice(&u.imprints);
            }
            frame += 1;
            if frame >= sc.frames && p.pending_surfaces() == 0 {
                break;
            }
            prop_assert!(frame < sc.frames + 2000, "queues never drained");
        }
        for (id, d) in &touches {
            let got = applied.get(id).map(Vec::as_slice).unwrap_or(&[]);
            prop_assert!(got.iter().any(|e| queue::contains(e, d)), "touch of {:?} by {:?} was lost", id, d);
        }
    }
}

/// The oracle of what touches a surface: the ball holding the deformer's shape, swept from its
/// previous pose (sampled finely), comes within its radius of the capture volume (a box in the
/// surface's frame). Whatever the real shape presses, this ball presses too.
fn reaches_into(desc: &SurfaceDesc, ankle: f32, d: &Deformer) -> bool {
    let to_local = desc.world_to_local();
    let half = desc.size * 0.5;
    let hi = Vec3::new(half.x, desc.snow_depth + ankle, half.y);
    let lo = Vec3::new(-half.x, 0.0, -half.y);
    let r = d.shape.bounding_radius().unwrap_or(0.0);
    let (a, b) = (d.previous.unwrap_or(d.pose).position, d.pose.position);
    (0..=64).any(|k| {
        let p = to_local.transform_point3(a.lerp(b, k as f32 / 64.0));
        (lo - p).max(p - hi).max(Vec3::ZERO).length() < r - 1e-4
    })
}

// ---------------------------------------------------------------------------------------------
// Planner behaviour by hand.

fn flat(name: &str, x: f32, y: f32, z: f32) -> SurfaceDesc {
    SurfaceDesc::new(name, [x, y, z], [4.0, 4.0], 0.2)
}

fn foot(p: [f32; 3]) -> Deformer {
    Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at(p))
}

fn looking_down_at(x: f32, z: f32) -> CameraView {
    CameraView::new(
        &Camera {
            eye: Vec3::new(x, 30.0, z + 0.01),
            target: Vec3::new(x, 0.0, z),
            fov_y_degrees: 60.0,
        },
        1.0,
    )
}

#[test]
fn the_players_surface_goes_first_then_the_nearest() {
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    let ids: Vec<ManagedId> = (0..6)
        .map(|i| {
            p.add_surface(&flat(&format!("s{i}"), i as f32 * 5.0, 0.0, 0.0), ZoneId(0))
                .unwrap()
        })
        .collect();
    // Everyone but the player stands on surfaces 0..5; the player on surface 5, far away.
    let mut ds: Vec<ManagedDeformer> = (0..5)
        .map(|i| ManagedDeformer::new(foot([i as f32 * 5.0, 0.25, 0.0])))
        .collect();
    ds.push(ManagedDeformer::player(foot([25.0, 0.25, 0.0])));
    let plan = p.tick(0.02, None, &ds).unwrap();
    assert_eq!(plan.stats.touched, 6);
    assert_eq!(plan.updates.len(), 2);
    assert_eq!(plan.updates[0].surface, ids[5], "player's first");
    // Then the nearest to the player (the focus): surface 4.
    assert_eq!(plan.updates[1].surface, ids[4]);
    assert_eq!(plan.stats.updated, vec!["s5".to_owned(), "s4".to_owned()]);
}

/// Ten surfaces, each under a sphere that keeps moving (so each is due every frame), a budget of 2
/// with 1 slot reserved for the player, no distance slack: the player's surface is updated every
/// frame, the other nine take turns on the one slot left, and the longest wait (8) stays within the
/// stated bound `0 + floor((10 - 1) / 1) = 9`.
#[test]
fn the_starvation_bound_is_met_and_nearly_tight() {
    let config = ManagerConfig {
        distance_slack_frames: 0,
        ..ManagerConfig::default()
    };
    let mut p = Planner::new(&config).unwrap();
    let ids: Vec<ManagedId> = (0..10)
        .map(|i| {
            p.add_surface(&flat(&format!("s{i}"), i as f32 * 5.0, 0.0, 0.0), ZoneId(0))
                .unwrap()
        })
        .collect();
    let at = |i: usize, f: u64| {
        Pose::at([
            i as f32 * 5.0 + 0.3 * (f as f32 * 0.7).cos(),
            0.25,
            0.3 * (f as f32 * 0.7).sin(),
        ])
    };
    let mut last_update = [0u64; 10];
    let mut worst = 0;
    for f in 1..200u64 {
        let ds: Vec<ManagedDeformer> = (0..10)
            .map(|i| ManagedDeformer {
                deformer: Deformer::moving(Shape::Sphere { radius: 0.1 }, at(i, f - 1), at(i, f)),
                player: i == 0,
            })
            .collect();
        let plan = p.tick(0.02, None, &ds).unwrap();
        assert_eq!(plan.stats.due, 10);
        assert_eq!(plan.updates.len(), 2);
        assert_eq!(
            plan.updates[0].surface, ids[0],
            "the player's surface every frame"
        );
        for u in &plan.updates {
            last_update[u.surface.index() as usize] = f;
            worst = worst.max(u.wait_frames);
        }
        assert!(plan.stats.max_wait_frames <= p.wait_bound(10));
    }
    assert_eq!(p.wait_bound(10), 9);
    assert_eq!(worst, 8);
    assert!(
        last_update.iter().all(|&f| f >= 190),
        "nobody starves: {last_update:?}"
    );
}

#[test]
fn stacked_surfaces_are_told_apart() {
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    let street = p
        .add_surface(&flat("street", 0.0, 0.0, 0.0), ZoneId(0))
        .unwrap();
    let roof = p
        .add_surface(&flat("roof", 0.0, 8.0, 0.0), ZoneId(0))
        .unwrap();
    let plan = p
        .tick(0.02, None, &[ManagedDeformer::new(foot([0.5, 8.25, 0.5]))])
        .unwrap();
    assert_eq!(plan.updates.len(), 1);
    assert_eq!(plan.updates[0].surface, roof);
    assert!(p.is_resident(roof) && !p.is_resident(street));
}

#[test]
fn unloading_a_zone_pages_its_surfaces_out_and_loading_pages_them_back_in() {
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    let a = p.add_surface(&flat("a", 0.0, 0.0, 0.0), ZoneId(1)).unwrap();
    let b = p
        .add_surface(&flat("b", 10.0, 0.0, 0.0), ZoneId(2))
        .unwrap();
    let cam = looking_down_at(5.0, 0.0);
    p.tick(0.02, Some(&cam), &[]).unwrap();
    assert!(p.is_resident(a) && p.is_resident(b));
    let used = p.pool_used();
    assert_eq!(p.unload_zone(ZoneId(1)), vec![a]);
    assert!(!p.is_resident(a) && p.is_paged(a));
    assert_eq!(
        p.pool_used(),
        used - slot_bytes(p.surface(a).unwrap().layout())
    );
    let plan = p
        .tick(
            0.02,
            Some(&cam),
            &[ManagedDeformer::new(foot([0.0, 0.25, 0.0]))],
        )
        .unwrap();
    assert_eq!(
        plan.stats.evicted,
        vec!["a".to_owned()],
        "reported by the next tick"
    );
    assert_eq!(plan.stats.touched, 0, "unloaded surfaces are not looked up");
    assert!(!p.is_resident(a));
    p.load_zone(ZoneId(1));
    // Paged back in at once, even where no camera sees it.
    let plan = p.tick(0.02, None, &[]).unwrap();
    assert_eq!(plan.changes, vec![ResidencyChange::Admit(a)]);
    assert!(p.is_resident(a) && !p.is_paged(a));
}

#[test]
fn a_full_pool_evicts_the_least_useful_and_never_goes_over() {
    // Room for exactly two 4 m x 4 m surfaces.
    let one = PoolFormat::default().slot_bytes(100, 100);
    let config = ManagerConfig {
        pool_bytes: 2 * one + 1000,
        ..ManagerConfig::default()
    };
    let mut p = Planner::new(&config).unwrap();
    let s: Vec<ManagedId> = (0..4)
        .map(|i| {
            p.add_surface(
                &flat(&format!("s{i}"), i as f32 * 10.0, 0.0, 0.0),
                ZoneId(0),
            )
            .unwrap()
        })
        .collect();
    // Touch s0 then s1: both resident.
    p.tick(0.02, None, &[ManagedDeformer::new(foot([0.0, 0.25, 0.0]))])
        .unwrap();
    p.tick(0.02, None, &[ManagedDeformer::new(foot([10.0, 0.25, 0.0]))])
        .unwrap();
    assert!(p.is_resident(s[0]) && p.is_resident(s[1]));
    // Both go inactive and keep their heightmaps; s2 is touched: the least recently useful (s0) is
    // paged out.
    let plan = p
        .tick(0.02, None, &[ManagedDeformer::new(foot([20.0, 0.25, 0.0]))])
        .unwrap();
    assert_eq!(plan.stats.evicted, vec!["s0".to_owned()]);
    assert!(p.is_paged(s[0]));
    assert!(p.is_resident(s[1]) && p.is_resident(s[2]));
    assert!(p.pool_used() <= p.pool_budget());
    // s2 (touched) and s3 (touched by the player): s1, inactive, goes; nothing touched is evicted.
    let plan = p
        .tick(
            0.02,
            None,
            &[
                ManagedDeformer::new(foot([20.0, 0.25, 0.0])),
                ManagedDeformer::player(foot([30.0, 0.25, 0.0])),
            ],
        )
        .unwrap();
    assert_eq!(plan.stats.evicted, vec!["s1".to_owned()]);
    assert!(p.is_resident(s[2]) && p.is_resident(s[3]));
    // A third touched surface, farther from the player than both residents: it waits for memory
    // with its imprint queued, and gets it once s2 is left alone.
    let plan = p
        .tick(
            0.02,
            None,
            &[
                ManagedDeformer::new(foot([20.0, 0.25, 0.0])),
                ManagedDeformer::player(foot([30.0, 0.25, 0.0])),
                ManagedDeformer::new(foot([0.0, 0.25, 0.0])),
            ],
        )
        .unwrap();
    assert_eq!(plan.stats.waiting_for_memory, 1);
    assert!(!p.is_resident(s[0]));
    assert_eq!(p.queued_imprints(s[0]), 1);
    let stats = p
        .tick(
            0.02,
            None,
            &[ManagedDeformer::player(foot([30.0, 0.25, 0.0]))],
        )
        .unwrap()
        .stats
        .clone();
    assert!(p.is_resident(s[0]), "{stats:?}");
    assert_eq!(stats.waiting_for_memory, 0);
    assert_eq!(
        stats.updated,
        vec!["s0".to_owned()],
        "its queued imprint applied at once"
    );
}

#[test]
fn inactive_surfaces_keep_their_heightmaps_while_the_pool_has_room() {
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    let a = p.add_surface(&flat("a", 0.0, 0.0, 0.0), ZoneId(0)).unwrap();
    p.tick(0.02, None, &[ManagedDeformer::new(foot([0.0, 0.25, 0.0]))])
        .unwrap();
    assert!(p.is_resident(a));
    // Nothing touches it, no camera sees it: inactive, and still holding its heightmap.
    for _ in 0..5 {
        let plan = p.tick(0.02, None, &[]).unwrap();
        assert!(plan.stats.evicted.is_empty() && plan.changes.is_empty());
    }
    assert!(p.is_resident(a) && !p.is_active(a));
    let cam = looking_down_at(0.0, 0.0);
    let far = CameraView {
        eye: Vec3::new(200.0, 30.0, 0.0),
        target: Vec3::new(0.0, 0.0, 0.0),
        ..cam
    };
    p.tick(0.02, Some(&far), &[]).unwrap();
    assert!(p.is_resident(a), "beyond active_distance, kept");
    let behind = CameraView {
        eye: Vec3::new(10.0, 2.0, 0.0),
        target: Vec3::new(20.0, 2.0, 0.0),
        ..cam
    };
    p.tick(0.02, Some(&behind), &[]).unwrap();
    assert!(p.is_resident(a), "behind the camera, kept");
    assert!(!p.is_paged(a));
}

#[test]
fn a_full_page_store_keeps_heightmaps_in_the_pool() {
    // Room for one 4 m x 4 m surface in the pool and none in the page store: the second surface
    // touched waits rather than evict (and lose) the first one's heightmap.
    let one = PoolFormat::default().slot_bytes(100, 100);
    let config = ManagerConfig {
        pool_bytes: one + 1000,
        page_bytes: one - 1,
        ..ManagerConfig::default()
    };
    let mut p = Planner::new(&config).unwrap();
    let a = p.add_surface(&flat("a", 0.0, 0.0, 0.0), ZoneId(0)).unwrap();
    let b = p
        .add_surface(&flat("b", 10.0, 0.0, 0.0), ZoneId(0))
        .unwrap();
    p.tick(0.02, None, &[ManagedDeformer::new(foot([0.0, 0.25, 0.0]))])
        .unwrap();
    p.tick(0.02, None, &[]).unwrap();
    let plan = p
        .tick(0.02, None, &[ManagedDeformer::new(foot([10.0, 0.25, 0.0]))])
        .unwrap();
    assert!(plan.changes.is_empty(), "{:?}", plan.changes);
    assert_eq!(plan.stats.waiting_for_memory, 1);
    assert!(p.is_resident(a) && !p.is_resident(b));
    assert_eq!(p.queued_imprints(b), 1);
}

#[test]
fn a_surface_larger_than_the_pool_is_refused() {
    // A 4 m x 4 m surface needs 100 x 100 texels x 4 bytes = 40,000 bytes.
    let config = ManagerConfig {
        pool_bytes: 30_000,
        ..ManagerConfig::default()
    };
    let mut p = Planner::new(&config).unwrap();
    let e = p
        .add_surface(&flat("big", 0.0, 0.0, 0.0), ZoneId(0))
        .unwrap_err();
    assert!(matches!(e, SnowError::PoolExhausted { .. }), "{e}");
}

#[test]
fn bad_input_is_an_error_and_changes_nothing() {
    assert!(
        Planner::new(&ManagerConfig {
            updates_per_frame: 0,
            ..ManagerConfig::default()
        })
        .is_err()
    );
    assert!(
        Planner::new(&ManagerConfig {
            active_distance: f32::NAN,
            ..ManagerConfig::default()
        })
        .is_err()
    );
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    p.add_surface(&flat("a", 0.0, 0.0, 0.0), ZoneId(0)).unwrap();
    let ok = [ManagedDeformer::new(foot([0.0, 0.25, 0.0]))];
    assert!(matches!(
        p.tick(f32::NAN, None, &ok),
        Err(SnowError::InvalidTimeStep { .. })
    ));
    let bad = [ManagedDeformer::new(Deformer::new(
        Shape::Sphere { radius: -1.0 },
        Pose::at([0.0; 3]),
    ))];
    let e = p.tick(0.02, None, &bad).unwrap_err().to_string();
    assert!(e.contains("#0") && e.contains("radius"), "{e}");
    let cam = CameraView {
        target: Vec3::new(0.0, 30.0, 0.01),
        ..looking_down_at(0.0, 0.0)
    };
    assert!(p.tick(0.02, Some(&cam), &ok).is_err(), "eye == target");
    assert_eq!(p.next_frame(), 0, "nothing ticked");
    assert!(p.surface(ManagedId::from_index(7)).is_err());
}

#[test]
fn a_standing_player_does_not_hog_the_budget() {
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    p.add_surface(&flat("a", 0.0, 0.0, 0.0), ZoneId(0)).unwrap();
    let still = [ManagedDeformer::player(foot([0.0, 0.25, 0.0]))];
    assert_eq!(p.tick(0.02, None, &still).unwrap().updates.len(), 1);
    // Pressing the same shape again changes nothing without snowfall: no update is spent on it.
    for _ in 0..5 {
        assert_eq!(p.tick(0.02, None, &still).unwrap().updates.len(), 0);
    }
}

// ---------------------------------------------------------------------------------------------
// On the GPU.

const DT: f32 = 1.0 / 30.0;

/// Spheres dragged along curves (no lifting). Caught up frame by frame (the default), the budgeted
/// trails equal the unlimited ones exactly; with `CatchUp::Union` the budget captures several frames
/// of a drag in one pass: the trail is never shallower anywhere, and deeper only where two frames'
/// sweeps meet within the blur's reach (see docs/MANAGER.md).
#[test]
fn dragged_spheres_on_a_budget_press_at_least_as_deep() {
    let run = |k: usize, catch_up: CatchUp| -> Vec<Heightmap> {
        let mut m = SnowManager::new(
            common::gpu(),
            ManagerConfig {
                updates_per_frame: k,
                catch_up,
                ..ManagerConfig::default()
            },
        )
        .unwrap();
        let ids: Vec<ManagedId> = (0..6)
            .map(|i| {
                m.add_surface(
                    SurfaceDesc::new(
                        &format!("s{i}"),
                        [i as f32 * 3.0, 0.0, 0.0],
                        [2.8, 2.8],
                        0.2,
                    ),
                    ZoneId(0),
                )
                .unwrap()
            })
            .collect();
        let pos = |i: usize, f: u64| {
            let a = f as f32 * 0.12 + i as f32;
            Vec3::new(i as f32 * 3.0 + 0.9 * a.cos(), 0.2 + 0.05, 0.9 * a.sin())
        };
        let cam = CameraView::new(
            &Camera {
                eye: Vec3::new(7.5, 12.0, 8.0),
                target: Vec3::new(7.5, 0.0, 0.0),
                fov_y_degrees: 70.0,
            },
            2.0,
        );
        let mut f = 0;
        loop {
            let ds: Vec<ManagedDeformer> = if f < 30 {
                (0..6)
                    .map(|i| {
                        ManagedDeformer::new(Deformer::moving(
                            Shape::Sphere { radius: 0.1 },
                            Pose::at(pos(i, f).into()),
                            Pose::at(pos(i, f + 1).into()),
                        ))
                    })
                    .collect()
            } else {
                Vec::new()
            };
            m.tick(DT, Some(&cam), &ds).unwrap();
            f += 1;
            if f >= 30 && m.planner().pending_surfaces() == 0 {
                break;
            }
        }
        ids.iter()
            .map(|&id| m.read_heightmap(id).unwrap())
            .collect()
    };
    let free = run(UNLIMITED, CatchUp::FrameByFrame);
    assert_eq!(run(2, CatchUp::FrameByFrame), free, "frame by frame: exact");
    let budget = run(2, CatchUp::Union);
    assert_ne!(
        budget, free,
        "the union of a drag's frames presses a little deeper"
    );
    for (b, f) in budget.iter().zip(&free) {
        let (vb, vf) = (b.pressed_volume(), f.pressed_volume());
        assert!(vf > 50.0, "a real trench: {vf}");
        for (&x, &y) in b.depression.iter().zip(&f.depression) {
            assert!(x as i32 >= y as i32 - 1, "the budget lost depth: {x} < {y}");
            // Where nothing was pressed without a budget, nothing is with one.
            if y == 0 {
                assert!(x <= 1);
            }
        }
        assert!(vb <= vf * 1.05, "over-press stays small: {vb} vs {vf}");
    }
}
