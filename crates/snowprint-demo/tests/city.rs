//! The surface manager on the demo crate's generated city and walkers: the planner fed by a
//! generated city, issue 4's 20-walker test (trails made with a budget of 2 updates a frame equal
//! the trails made with no budget at all) and a city inside the default 2 MiB pool.

mod common;

use glam::Vec3;
use snowprint::manager::{
    CameraView, ManagedDeformer, ManagedId, ManagerConfig, Planner, SnowManager, UNLIMITED, ZoneId,
};
use snowprint::{Camera, Heightmap, SurfaceDesc};
use snowprint_demo::city::{self, WalkerPath};

#[test]
fn city_generation_feeds_the_planner() {
    let c = city::generate(11, 500, 40);
    let mut p = Planner::new(&ManagerConfig::default()).unwrap();
    for s in &c.surfaces {
        p.add_surface(&s.desc, s.zone).unwrap();
    }
    let dt = 1.0 / 60.0;
    let mut touched_max = 0;
    for frame in 0..120 {
        let cam = CameraView::new(&c.player_camera(frame as f32 * dt), 16.0 / 9.0);
        let plan = p.tick(dt, Some(&cam), &c.deformers(frame, dt)).unwrap();
        assert!(plan.updates.len() <= 2);
        assert!(plan.stats.pool_bytes_used <= 2 << 20);
        touched_max = touched_max.max(plan.stats.touched);
    }
    assert!(touched_max >= 20, "walkers touch surfaces: {touched_max}");
}

// ---------------------------------------------------------------------------------------------
// On the GPU.

const DT: f32 = 1.0 / 30.0;

/// 20 surfaces: 5 rows of 4 segments, 3 m x 2.4 m each; rows 0 and 1 (and 2 and 3) are stacked,
/// 3 m apart. 20 walkers, one per lane, 4 lanes a row, each starting on its own segment and
/// crossing onto the next.
fn twenty() -> (Vec<SurfaceDesc>, Vec<WalkerPath>) {
    let mut surfaces = Vec::new();
    let mut walkers = Vec::new();
    for row in 0..5 {
        let (y, z) = ((row % 2) as f32 * 3.0, (row / 2) as f32 * 3.0);
        for seg in 0..4 {
            surfaces.push(SurfaceDesc::new(
                &format!("r{row}s{seg}"),
                [-4.5 + 3.0 * seg as f32, y, z],
                [3.0, 2.4],
                0.2,
            ));
        }
        for lane in 0..4 {
            let x0 = -4.8 + 3.0 * lane as f32 + 0.3 * row as f32;
            let lz = z - 0.9 + 0.6 * lane as f32;
            let top = y + 0.2;
            let mut w = WalkerPath::new(
                &format!("w{row}_{lane}"),
                vec![Vec3::new(x0, top, lz), Vec3::new(x0 + 20.0, top, lz)],
                false,
            );
            w.player = row == 0 && lane == 0;
            walkers.push(w);
        }
    }
    (surfaces, walkers)
}

fn run_twenty(updates_per_frame: usize, frames: u64) -> (Vec<Heightmap>, u64, usize) {
    let (surfaces, walkers) = twenty();
    let config = ManagerConfig {
        updates_per_frame,
        ..ManagerConfig::default()
    };
    let mut m = SnowManager::new(common::gpu(), config).expect("manager");
    let ids: Vec<ManagedId> = surfaces
        .into_iter()
        .map(|s| m.add_surface(s, ZoneId(0)).expect("surface"))
        .collect();
    let cam = CameraView::new(
        &Camera {
            eye: Vec3::new(0.0, 18.0, 14.0),
            target: Vec3::new(0.0, 1.0, 3.0),
            fov_y_degrees: 60.0,
        },
        1.5,
    );
    let mut max_wait = 0;
    let mut most = 0;
    let mut frame = 0;
    loop {
        let deformers: Vec<ManagedDeformer> = if frame < frames {
            walkers.iter().flat_map(|w| w.feet(frame, DT)).collect()
        } else {
            Vec::new()
        };
        let stats = m.tick(DT, Some(&cam), &deformers).expect("tick");
        assert_eq!(stats.resident, 20, "the default 2 MiB pool holds all 20");
        assert!(stats.pool_bytes_used <= stats.pool_bytes_budget);
        assert_eq!(stats.pool_bytes_used, m.world().memory().pool_used);
        assert!(stats.updated.len() <= updates_per_frame);
        most = most.max(stats.updated.len());
        max_wait = max_wait.max(stats.max_wait_frames);
        frame += 1;
        if frame >= frames && m.planner().pending_surfaces() == 0 {
            break;
        }
        assert!(frame < frames + 200, "queues never drained");
    }
    let maps = ids
        .iter()
        .map(|&id| m.read_heightmap(id).expect("readback"))
        .collect();
    (maps, max_wait, most)
}

/// Issue 4's test: 20 walkers on 20 surfaces with a budget of 2 updates a frame leave the same
/// trails (every texel within 1 unit of 65535) as the same run with no budget.
#[test]
fn twenty_walkers_on_a_budget_of_two_lose_no_footprint() {
    let frames = 60;
    let (budget, wait, most_budget) = run_twenty(2, frames);
    let (free, _, most_free) = run_twenty(UNLIMITED, frames);
    assert_eq!(most_budget, 2);
    assert!(
        most_free > 2,
        "the unlimited run updates more than 2 a frame: {most_free}"
    );
    assert!(wait > 0, "the budget made surfaces wait");
    let unit = 65535.0;
    for (i, (b, f)) in budget.iter().zip(&free).enumerate() {
        // A real trail: several footprints, each pressing up to 6 cm of the 20 cm.
        let pressed = f
            .depression
            .iter()
            .filter(|&&v| v as f32 > 0.1 * unit)
            .count();
        assert!(pressed >= 20, "surface {i}: {pressed} pressed texels");
        let mut worst = 0;
        for (t, (&x, &y)) in b.depression.iter().zip(&f.depression).enumerate() {
            let d = (x as i32 - y as i32).abs();
            worst = worst.max(d);
            assert!(
                d <= 1,
                "surface {i} texel {t}: {x} with the budget, {y} without"
            );
        }
        for (&x, &y) in b.displaced.iter().zip(&f.displaced) {
            assert!(
                (x as i32 - y as i32).abs() <= 1,
                "surface {i}: displaced {x} vs {y}"
            );
        }
    }
}

/// A city on the default 2 MiB pool: the manager evicts, never exceeds the budget, and a surface
/// without a slot reads back from its page (or as untouched snow when it never held one).
#[test]
fn a_city_runs_inside_two_mebibytes() {
    let c = city::generate(5, 60, 12);
    let mut m = SnowManager::new(common::gpu(), ManagerConfig::default()).unwrap();
    let ids: Vec<ManagedId> = c
        .surfaces
        .iter()
        .map(|s| m.add_surface(s.desc.clone(), s.zone).unwrap())
        .collect();
    let dt = 1.0 / 30.0;
    for frame in 0..30 {
        let cam = CameraView::new(&c.player_camera(frame as f32 * dt), 16.0 / 9.0);
        let stats = m.tick(dt, Some(&cam), &c.deformers(frame, dt)).unwrap();
        assert!(stats.updated.len() <= 2);
        assert!(stats.pool_bytes_used <= stats.pool_bytes_budget);
        assert_eq!(stats.pool_bytes_budget, 2 << 20);
        assert_eq!(stats.pool_bytes_used, m.world().memory().pool_used);
    }
    let resident = ids
        .iter()
        .filter(|&&id| m.planner().is_resident(id))
        .count();
    assert!(resident > 0 && resident < ids.len());
    let paged = ids.iter().filter(|&&id| m.planner().is_paged(id)).count();
    assert!(paged > 0, "the city evicted something");
    assert_eq!(m.stats().paged_surfaces, paged);
    assert_eq!(m.pages().len(), paged);
    for &id in &ids {
        assert_eq!(
            m.world_id(id).is_some(),
            m.planner().is_resident(id),
            "a world heightmap exactly for the resident surfaces"
        );
        m.read_heightmap(id).unwrap();
    }
    let json = serde_json::to_string(m.stats()).unwrap();
    for key in [
        "\"frame\"",
        "\"updated\"",
        "\"active\"",
        "\"resident\"",
        "\"evicted\"",
        "\"pool_bytes_used\"",
        "\"pool_bytes_budget\"",
        "\"max_wait_frames\"",
    ] {
        assert!(json.contains(key), "{json}");
    }
    // Unloading every zone frees the whole pool and pages every heightmap that was resident.
    let before: Vec<Heightmap> = ids
        .iter()
        .map(|&id| m.read_heightmap(id).unwrap())
        .collect();
    for s in &c.surfaces {
        m.unload_zone(s.zone).unwrap();
    }
    assert_eq!(m.world().memory().pool_used, 0);
    for (&id, map) in ids.iter().zip(&before) {
        assert_eq!(&m.read_heightmap(id).unwrap(), map, "paged bit for bit");
    }
}
