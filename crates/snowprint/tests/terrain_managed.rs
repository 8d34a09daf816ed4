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
    assert_eq!(file.version, 2);
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
