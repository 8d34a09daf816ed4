//! Managed surfaces on ground that is not flat: the manager lays each admitted surface on its
//! ground, so a trail pressed across a slope and a hill comes back texel for texel after its
//! surface was paged out, reads from the local snow top, answers probes from its page by the
//! ground, and survives a save.

mod common;

use glam::Vec3;
use snowprint::manager::{
    ManagedDeformer, ManagedId, ManagedProbeStatus, ManagedSample, ManagerConfig, SaveFile,
    SnowManager, UNLIMITED, ZoneId,
};
use snowprint::reference::capture as cap_cpu;
use snowprint::{Deformer, Ground, HeightGrid, Heightmap, Pose, Shape, SlopeRule, SurfaceDesc};

const DT: f32 = 1.0 / 60.0;
const DEPTH: f32 = 0.2;
const RADIUS: f32 = 0.12;
/// How far below the local snow top the walker's sphere reaches, metres.
const SINK: f32 = 0.08;

/// The three surfaces' grounds, local metres: a 30-degree plane rising along x, sine hills
/// (slopes up to 31 degrees, so every texel holds the whole depth), flat.
fn ground_height(k: usize, x: f32, z: f32) -> f32 {
    match k {
        0 => x * 30f32.to_radians().tan(),
        1 => 0.3 * (2.0 * x).sin() * (1.5 * z).cos(),
        _ => 0.0,
    }
}

fn surfaces() -> Vec<SurfaceDesc> {
    (0..3)
        .map(|i| {
            SurfaceDesc::new(
                &format!("s{i}"),
                [i as f32 * 5.0, 0.0, 0.0],
                [3.0, 3.0],
                DEPTH,
            )
        })
        .collect()
}

/// One sample per texel, so that sampling the grid at texel centres is exact.
fn grid(desc: &SurfaceDesc, k: usize) -> HeightGrid {
    let l = desc.layout();
    let half = desc.size * 0.5;
    let mut heights = Vec::new();
    for r in 0..l.height {
        for c in 0..l.width {
            let p = cap_cpu::texel_center(c, r, l.width, l.height, half);
            heights.push(ground_height(k, p.x, p.y));
        }
    }
    HeightGrid {
        columns: l.width,
        rows: l.height,
        heights,
    }
}

fn manager(config: ManagerConfig, descs: &[SurfaceDesc]) -> (SnowManager, Vec<ManagedId>) {
    let mut m = SnowManager::new(common::gpu(), config).expect("manager");
    let ids: Vec<ManagedId> = descs
        .iter()
        .map(|s| m.add_surface(s.clone(), ZoneId(0)).expect("surface"))
        .collect();
    for (k, (&id, desc)) in ids.iter().zip(descs).enumerate().take(2) {
        m.set_ground(id, &Ground::Grid(grid(desc, k)), SlopeRule::default())
            .expect("ground");
    }
    (m, ids)
}

fn unlimited() -> ManagerConfig {
    ManagerConfig {
        updates_per_frame: UNLIMITED,
        pool_bytes: 64 << 20,
        active_distance: 500.0,
        ..ManagerConfig::default()
    }
}

/// A pool of two surfaces' slots: the third surface a walker reaches evicts one.
fn two_slots() -> ManagerConfig {
    let slot = snowprint::PoolFormat::default().slot_bytes(75, 75);
    ManagerConfig {
        pool_bytes: 2 * slot + 256,
        ..ManagerConfig::default()
    }
}

/// Where the walker's path on surface `k` runs: along x at local `z`.
fn lane(k: usize, frame: u32) -> f32 {
    if k == 0 && frame >= 80 { 0.7 } else { -0.4 }
}

/// A walker crossing surface `k = (f / 20) % 4` (the fourth crossing back on surface 0, on
/// another lane) along x, its sphere `SINK` below the local snow top.
fn walker(f: u32) -> Vec<ManagedDeformer> {
    let k = match (f / 20) % 4 {
        3 => 0,
        k => k as usize,
    };
    let z = lane(k, f);
    let at = |f: u32| {
        let t = (f % 20) as f32 / 20.0;
        let x = -1.2 + 2.4 * t;
        let y = ground_height(k, x, z) + DEPTH - SINK + RADIUS;
        Pose::at([k as f32 * 5.0 + x, y, z])
    };
    let prev = if f.is_multiple_of(20) {
        at(f)
    } else {
        at(f - 1)
    };
    vec![ManagedDeformer::player(Deformer::moving(
        Shape::Sphere { radius: RADIUS },
        prev,
        at(f),
    ))]
}

fn read_all(m: &SnowManager, ids: &[ManagedId]) -> Vec<Heightmap> {
    ids.iter()
        .map(|&id| m.read_heightmap(id).expect("read"))
        .collect()
}

fn differing(a: &[Heightmap], b: &[Heightmap]) -> usize {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            x.depression
                .iter()
                .zip(&y.depression)
                .chain(x.displaced.iter().zip(&y.displaced))
                .filter(|(p, q)| p != q)
                .count()
        })
        .sum()
}

/// The depression along a lane's centre texels, away from the path's ends, as fractions, with
/// the texel centres' local x.
fn lane_depths(map: &Heightmap, z: f32) -> Vec<(f32, f32)> {
    let row = ((z + 1.5) / 3.0 * map.height as f32) as u32;
    let (c0, c1) = (map.width / 2 - 20, map.width / 2 + 20);
    (c0..c1)
        .map(|c| {
            let x = (c as f32 + 0.5) / map.width as f32 * 3.0 - 1.5;
            (x, map.fraction(c, row))
        })
        .collect()
}

/// The depth, as a fraction, a sphere swept along a lane leaves under its path on ground `k` at
/// local `(x, z)`, by hand: the sphere's centre lies `R - SINK` above the local top, so it reaches
/// `R - (R - SINK) cos(a)` into the snow across the slope of angle `a`, and vertically `1 / cos(a)`
/// of that: `SINK + R (1 / cos(a) - 1)`, where `1 / cos(a) = sqrt(1 + |grad g|^2)`.
fn swept_depth(k: usize, x: f32, z: f32) -> f32 {
    let e = 1e-3;
    let gx = (ground_height(k, x + e, z) - ground_height(k, x - e, z)) / (2.0 * e);
    let gz = (ground_height(k, x, z + e) - ground_height(k, x, z - e)) / (2.0 * e);
    (SINK + RADIUS * ((1.0 + gx * gx + gz * gz).sqrt() - 1.0)) / DEPTH
}

#[test]
fn evicted_slopes_come_back_texel_for_texel_and_print_from_the_local_top() {
    let descs = surfaces();
    let (mut small, ids) = manager(two_slots(), &descs);
    let (mut free, free_ids) = manager(unlimited(), &descs);
    let (mut paged_out, mut paged_in) = (0, 0);
    for f in 0..100 {
        let s = small.tick(DT, None, &walker(f)).unwrap();
        paged_out += s.paged_out_bytes;
        paged_in += s.paged_in_bytes;
        free.tick(DT, None, &walker(f)).unwrap();
    }
    small.flush().unwrap();
    free.flush().unwrap();
    assert!(
        paged_out > 0 && paged_in > 0,
        "{paged_out} out, {paged_in} in"
    );
    let (a, b) = (read_all(&small, &ids), read_all(&free, &free_ids));
    assert_eq!(differing(&a, &b), 0, "paging changed texels");
    // Every lane is pressed from its local snow top as computed by hand (the blur takes a
    // little off the deepest texels): within [-0.1, +0.02] of the fraction. Were the ground not
    // laid, the rising plane's lane would read untouched where the ground is above the flat top
    // and pressed to the ground below it.
    for (k, z) in [(0, -0.4), (0, 0.7), (1, -0.4), (2, -0.4)] {
        for (x, d) in lane_depths(&a[k], z) {
            let want = swept_depth(k, x, z);
            assert!(
                d > want - 0.1 && d < want + 0.02,
                "surface {k}, lane {z}, x {x}: {d}, {want} by hand"
            );
        }
    }
}

/// Ticks until the ticket is answered; fails past three ticks.
fn answer(m: &mut SnowManager, points: &[Vec3]) -> Vec<ManagedSample> {
    let ticket = m.probe(points).unwrap();
    for _ in 0..3 {
        m.tick(DT, None, &[]).unwrap();
        m.flush().unwrap();
        if let ManagedProbeStatus::Ready(s) = m.probe_result(ticket).unwrap() {
            return s;
        }
    }
    panic!("not answered in three ticks");
}

#[test]
fn a_paged_slope_answers_probes_by_its_ground() {
    let descs = surfaces();
    let (mut m, ids) = manager(unlimited(), &descs);
    for f in 0..20 {
        m.tick(DT, None, &walker(f)).unwrap();
    }
    m.flush().unwrap();
    // On the plane: in the lane, on the lane's wall, and untouched up the slope.
    let on = |x: f32, z: f32| Vec3::new(x, ground_height(0, x, z) + 0.05, z);
    let points = [on(0.0, -0.4), on(0.3, -0.32), on(0.5, 1.0)];
    let resident = answer(&mut m, &points);
    m.unload_zone(ZoneId(0)).unwrap();
    let paged = answer(&mut m, &points);
    assert!(m.world_id(ids[0]).is_none() && m.pages().get(ids[0].index()).is_some());
    for (g, c) in resident.iter().zip(&paged) {
        assert_eq!(c.surface, Some(ids[0]));
        let (g, c) = (g.sample, c.sample);
        assert!(
            (g.depression_m - c.depression_m).abs() < 1e-6,
            "{g:?} {c:?}"
        );
        assert!((g.snow_depth_m - c.snow_depth_m).abs() < 1e-6);
        assert!((g.normal - c.normal).length() < 1e-5, "{g:?} {c:?}");
    }
    // The untouched point: the whole depth, and the snow's normal tilted 30 degrees with the
    // plane (by hand: (-sin 30, cos 30, 0)).
    let u = paged[2].sample;
    assert!((u.snow_depth_m - DEPTH).abs() < 1e-4, "{u:?}");
    let n = Vec3::new(-0.5, 3f32.sqrt() / 2.0, 0.0);
    assert!((u.normal - n).length() < 0.02, "{u:?} against {n}");
    assert!(paged[0].sample.depression_m > 0.05, "{:?}", paged[0]);
}

#[test]
fn saves_keep_the_ground_and_refuse_a_wrong_one() {
    let descs = surfaces();
    let (mut m, ids) = manager(two_slots(), &descs);
    for f in 0..50 {
        m.tick(DT, None, &walker(f)).unwrap();
    }
    m.flush().unwrap();
    let bytes = m.to_save_bytes().unwrap();
    let file = SaveFile::parse(&bytes).unwrap();
    assert_eq!(file.version, 4);
    assert_eq!(file.grounds.len(), 2, "two surfaces lie on ground");
    let mut loaded = SnowManager::from_save(common::gpu(), file).unwrap();
    for &id in &ids {
        assert_eq!(loaded.ground(id).unwrap(), m.ground(id).unwrap());
    }
    // Both go on: the walker comes back over the slope (paged out in both by now).
    for f in 50..100 {
        m.tick(DT, None, &walker(f)).unwrap();
        loaded.tick(DT, None, &walker(f)).unwrap();
    }
    m.flush().unwrap();
    loaded.flush().unwrap();
    assert_eq!(
        differing(&read_all(&m, &ids), &read_all(&loaded, &ids)),
        0,
        "the loaded manager went on differently"
    );

    // A ground of the wrong size, and a version 1 file with a ground, are one sentence each.
    let sections: Vec<([u8; 4], Vec<u8>)> = SaveFile::parse(&bytes)
        .unwrap()
        .sections
        .into_iter()
        .map(|s| (s.tag, s.data))
        .collect();
    let mut short = sections.clone();
    let g = short.iter_mut().find(|s| &s.0 == b"GRND").unwrap();
    g.1[4..8].copy_from_slice(&74u32.to_le_bytes());
    let err = SaveFile::parse(&common::assemble_save(2, &short)).unwrap_err();
    assert!(
        err.contains("GRND") && err.contains("74 x 75") && !err.contains('\n'),
        "{err}"
    );
    let err = SaveFile::parse(&common::assemble_save(1, &sections)).unwrap_err();
    assert!(err.contains("GRND") && err.contains("version 2"), "{err}");
}

#[test]
fn a_touch_volume_follows_the_ground() {
    // A ball 0.8 m above the flat surface's top presses nothing; laid on a plane that rises
    // there, the same ball is in the snow and the surface is queued and pressed.
    let desc = SurfaceDesc::new("ramp", [0.0, 0.0, 0.0], [3.0, 3.0], DEPTH);
    let (mut m, ids) = {
        let mut m = SnowManager::new(common::gpu(), unlimited()).unwrap();
        let id = m.add_surface(desc.clone(), ZoneId(0)).unwrap();
        (m, vec![id])
    };
    let x = 1.2;
    let ball = Deformer::new(
        Shape::Sphere { radius: RADIUS },
        Pose::at([x, ground_height(0, x, 0.0) + DEPTH - SINK + RADIUS, 0.0]),
    );
    m.tick(DT, None, &[ManagedDeformer::player(ball)]).unwrap();
    m.flush().unwrap();
    assert_eq!(m.read_heightmap(ids[0]).unwrap().pressed_volume(), 0.0);
    m.set_ground(ids[0], &Ground::Grid(grid(&desc, 0)), SlopeRule::default())
        .unwrap();
    assert!(m.planner().bounds(ids[0]).unwrap().max.y > 1.2 * 0.57 + DEPTH);
    m.tick(DT, None, &[ManagedDeformer::player(ball)]).unwrap();
    m.flush().unwrap();
    let map = m.read_heightmap(ids[0]).unwrap();
    let l = desc.layout();
    let col = ((x + 1.5) / 3.0 * l.width as f32) as u32;
    let d = map.fraction(col, l.height / 2);
    // Under a resting ball's centre the snow is pressed SINK from the local top (by hand; the
    // blur takes a little off).
    let want = SINK / DEPTH;
    assert!(d > want - 0.1 && d < want + 0.02, "{d}, {want} by hand");
}

/// Terrain windows run by the manager: their levels in its pool and under its budget.
mod windows {
    use super::*;
    use snowprint::manager::ManagedProbeStatus;
    use snowprint::{LevelDesc, Material, SnowError, SnowWorld, TerrainDesc, WorldConfig};

    fn valley() -> TerrainDesc {
        TerrainDesc {
            name: "valley".into(),
            ground_height: 0.0,
            ground: None,
            snow_depth: DEPTH,
            replenish_rate: 0.0005,
            material: Material::snow(),
            levels: vec![
                LevelDesc {
                    texels: [48, 48],
                    texel_size: 0.05,
                },
                LevelDesc {
                    texels: [32, 32],
                    texel_size: 0.2,
                },
            ],
        }
    }

    /// Four roofs far from the valley, each 2 m square (50 texels a side by the talk's rule).
    fn roofs() -> Vec<SurfaceDesc> {
        (0..4)
            .map(|i| {
                SurfaceDesc::new(
                    &format!("roof{i}"),
                    [40.0 + 4.0 * i as f32, 0.0, 0.0],
                    [2.0, 2.0],
                    DEPTH,
                )
            })
            .collect()
    }

    /// A pool of the valley's two levels and two roofs: the roofs' walker pages them in and out.
    fn config() -> ManagerConfig {
        let f = snowprint::PoolFormat::default();
        ManagerConfig {
            updates_per_frame: 3,
            pool_bytes: f.slot_bytes(48, 48)
                + f.slot_bytes(32, 32)
                + 2 * f.slot_bytes(50, 50)
                + 1024,
            active_distance: 500.0,
            ..ManagerConfig::default()
        }
    }

    /// The hiker's sphere in the valley at frame `f`, walking along x past the near level's edge.
    fn hiker(f: u32) -> Deformer {
        let at = |f: u32| {
            Pose::at([
                -1.0 + 0.04 * f as f32,
                DEPTH - SINK + RADIUS,
                0.3 * (f as f32 * 0.1).sin(),
            ])
        };
        Deformer::moving(
            Shape::Sphere { radius: RADIUS },
            at(f.saturating_sub(1)),
            at(f),
        )
    }

    /// A second walker crossing roof `(f / 10) % 4`, so the roofs take turns in the pool.
    fn roofer(f: u32) -> Deformer {
        let k = ((f / 10) % 4) as f32;
        let x = 40.0 + 4.0 * k - 0.8 + 0.16 * (f % 10) as f32;
        Deformer::new(
            Shape::Sphere { radius: RADIUS },
            Pose::at([x, DEPTH - SINK + RADIUS, 0.0]),
        )
    }

    /// A levels' depression channels in logical order.
    fn levels_of(w: &SnowWorld, t: &snowprint::Terrain) -> Vec<Vec<u32>> {
        t.surfaces()
            .iter()
            .map(|&id| w.read_channels(id).expect("read").0)
            .collect()
    }

    /// The hiker's trail in a terrain run by a manager whose budget and pool are busy with the
    /// roofs (paged in and out as a second walker crosses them) is the trail of the same walk in
    /// a plain world's terrain, texel for texel in both levels, the window moving with the hiker;
    /// every tick updates every level and at most `updates_per_frame` surfaces in all, the levels'
    /// slots are never given up, and the manager's pool accounting stays the world's.
    #[test]
    fn a_managed_terrain_holds_the_trail_a_plain_world_does() {
        let mut m = SnowManager::new(common::gpu(), config()).expect("manager");
        for r in roofs() {
            m.add_surface(r, ZoneId(0)).expect("roof");
        }
        let t = m.add_terrain(valley(), Vec3::ZERO).expect("terrain");
        let levels = m.terrain(t).unwrap().surfaces();
        let mut plain = SnowWorld::new(
            common::gpu(),
            WorldConfig {
                format: config().format,
                capture: config().capture,
                ..WorldConfig::default()
            },
        )
        .expect("world");
        let mut pt = snowprint::Terrain::new(&mut plain, valley(), Vec3::ZERO).expect("terrain");
        let names: Vec<String> = levels
            .iter()
            .map(|&l| m.world().surface(l).unwrap().name.clone())
            .collect();
        let mut evicted = 0;
        for f in 0..120u32 {
            let focus = hiker(f).pose.position;
            m.follow_terrain(t, focus).expect("follow");
            pt.follow(&mut plain, focus).expect("follow");
            let stats = m
                .tick(
                    DT,
                    None,
                    &[
                        ManagedDeformer::player(hiker(f)),
                        ManagedDeformer::new(roofer(f)),
                    ],
                )
                .expect("tick");
            plain.step(DT, &[hiker(f), roofer(f)]).expect("step");
            assert!(stats.updated.len() <= 3, "frame {f}: {:?}", stats.updated);
            for n in &names {
                assert!(
                    stats.updated.contains(n),
                    "frame {f}: {n} not updated: {:?}",
                    stats.updated
                );
            }
            assert_eq!(stats.pool_bytes_used, m.planner().pool_used(), "frame {f}");
            evicted += stats.evicted.len();
        }
        assert!(
            evicted >= 4,
            "the roofs were paged out only {evicted} times"
        );
        assert_eq!(
            m.terrain(t).unwrap().surfaces(),
            levels,
            "the levels kept their surfaces"
        );
        m.flush_terrain(t).unwrap();
        pt.flush(&mut plain).unwrap();
        assert_eq!(
            m.terrain(t).unwrap().origin(0),
            pt.origin(0),
            "the windows moved alike"
        );
        let (ours, theirs) = (
            levels_of(m.world(), m.terrain(t).unwrap()),
            levels_of(&plain, &pt),
        );
        let pressed = ours[0].iter().filter(|&&v| v > 0).count();
        assert!(
            pressed > 100,
            "the hiker pressed only {pressed} texels of the near level"
        );
        for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert_eq!(
                differ, 0,
                "level {i}: {differ} texels differ from the plain world's"
            );
        }
        // Probes over the levels: the manager answers as the plain world does, from the finest
        // level that holds the point (the near level where it reaches, the far one beyond).
        let end = hiker(119).pose.position;
        let points: Vec<Vec3> = (0..12)
            .map(|k| hiker(96 + 2 * k).pose.position)
            .chain([end + Vec3::new(2.5, 0.0, 0.0), Vec3::new(100.0, 1.0, 0.0)])
            .map(|p| p.with_y(1.0))
            .collect();
        let ticket = m.probe(&points).expect("probe");
        let mut managed = None;
        for _ in 0..3 {
            m.tick(0.0, None, &[]).expect("tick");
            if let ManagedProbeStatus::Ready(s) = m.probe_result(ticket).unwrap() {
                managed = Some(s);
                break;
            }
        }
        let managed = managed.expect("the manager answered within three ticks");
        let ticket = plain.probe(&points).expect("probe");
        let mut theirs = None;
        for _ in 0..3 {
            if let snowprint::ProbeStatus::Ready(s) = plain.probe_result(ticket).unwrap() {
                theirs = Some(s);
                break;
            }
            plain.step(0.0, &[]).expect("step");
        }
        let theirs = theirs.expect("the world answered within three steps");
        let level_of = |id: Option<snowprint::SurfaceId>, ids: &[snowprint::SurfaceId]| {
            id.and_then(|id| ids.iter().position(|&l| l == id))
        };
        let plain_levels = pt.surfaces();
        let mut pressed = 0;
        for (k, (a, b)) in managed.iter().zip(&theirs).enumerate() {
            let want = match k {
                0..12 => Some(0),
                12 => Some(1),
                _ => None,
            };
            assert_eq!(a.surface, None, "point {k}: over no managed surface");
            assert_eq!(level_of(a.sample.surface, &levels), want, "point {k}");
            assert_eq!(level_of(b.surface, &plain_levels), want, "point {k}");
            let (x, y) = (a.sample, *b);
            assert_eq!(
                (x.snow_depth_m, x.depression_m, x.displaced_m, x.normal),
                (y.snow_depth_m, y.depression_m, y.displaced_m, y.normal),
                "point {k}"
            );
            pressed += usize::from(x.depression_m > 0.02);
        }
        assert!(
            pressed >= 6,
            "only {pressed} of the trail's points were pressed"
        );
    }

    /// What the manager refuses of terrains, in one sentence each, with nothing changed.
    #[test]
    fn a_managed_terrain_is_refused_in_one_sentence() {
        // Two levels leave no update to a budget of 2.
        let mut m = SnowManager::new(
            common::gpu(),
            ManagerConfig {
                updates_per_frame: 2,
                ..config()
            },
        )
        .expect("manager");
        let e = m.add_terrain(valley(), Vec3::ZERO).unwrap_err();
        assert!(matches!(e, SnowError::InvalidTerrain { .. }), "{e}");
        assert!(e.to_string().contains("updates_per_frame"), "{e}");
        assert_eq!(m.world().surfaces().count(), 0);
        // A pool too small for the levels whatever it holds: refused before anything is added.
        let mut m = SnowManager::new(
            common::gpu(),
            ManagerConfig {
                pool_bytes: 4096,
                ..config()
            },
        )
        .expect("manager");
        let e = m.add_terrain(valley(), Vec3::ZERO).unwrap_err();
        assert!(matches!(e, SnowError::InvalidTerrain { .. }), "{e}");
        assert!(e.to_string().contains("pool"), "{e}");
        // A pool that two resident roofs leave too little room: the world's refusal, no slot kept.
        let f = snowprint::PoolFormat::default();
        let mut m = SnowManager::new(
            common::gpu(),
            ManagerConfig {
                pool_bytes: config().pool_bytes - f.slot_bytes(32, 32),
                ..config()
            },
        )
        .expect("manager");
        for r in roofs() {
            m.add_surface(r, ZoneId(0)).expect("roof");
        }
        for frame in [0, 10] {
            m.tick(DT, None, &[ManagedDeformer::new(roofer(frame))])
                .expect("tick");
        }
        let (surfaces, used) = (m.world().surfaces().count(), m.planner().pool_used());
        assert_eq!(surfaces, 2, "two roofs resident");
        let e = m.add_terrain(valley(), Vec3::ZERO).unwrap_err();
        assert!(matches!(e, SnowError::PoolExhausted { .. }), "{e}");
        assert_eq!(
            (m.world().surfaces().count(), m.planner().pool_used()),
            (surfaces, used)
        );
        // A save holds the window (`tests/terrain_saves.rs`); once the terrain is removed, its
        // slots are free and a save holds no window.
        let mut m = SnowManager::new(common::gpu(), config()).expect("manager");
        let t = m.add_terrain(valley(), Vec3::ZERO).expect("terrain");
        let used = m.planner().pool_used();
        assert!(used > 0);
        let file = SaveFile::parse(&m.to_save_bytes().expect("save")).expect("parse");
        assert_eq!(file.terrains.len(), 1);
        m.remove_terrain(t).expect("remove");
        assert_eq!(
            m.planner().pool_used(),
            0,
            "the levels gave their slots back"
        );
        assert!(matches!(
            m.follow_terrain(t, Vec3::ZERO),
            Err(SnowError::StaleHandle { .. })
        ));
        let file = SaveFile::parse(&m.to_save_bytes().expect("save")).expect("parse");
        assert!(file.terrains.is_empty());
        // No scroll while a tick is pending.
        let t = m.add_terrain(valley(), Vec3::ZERO).expect("terrain");
        assert_eq!(m.planner().pool_used(), used);
        let device = m.world().device().clone();
        let mut enc = device.create_command_encoder(&Default::default());
        let pending = m.encode_tick(&mut enc, DT, None, &[]).expect("tick");
        assert!(matches!(
            m.follow_terrain(t, Vec3::new(3.0, 0.0, 0.0)),
            Err(SnowError::FramePending)
        ));
        m.world().queue().submit([enc.finish()]);
        m.submitted(pending).expect("submitted");
        m.follow_terrain(t, Vec3::new(3.0, 0.0, 0.0))
            .expect("follow");
    }
}
