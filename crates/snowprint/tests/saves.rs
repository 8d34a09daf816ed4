//! Saves (docs/SAVES.md): the whole snow state written and read back bit for bit at every
//! precision, a run saved at frame N and continued to M equal to a run straight to M, and every
//! damaged file refused with one sentence, leaving the running world as it was.

mod common;

use glam::Vec3;
use snowprint::manager::SaveFile;
use snowprint::manager::{ManagedDeformer, ManagedId, ManagerConfig, SnowManager, ZoneId};
use snowprint::{
    Deformer, Heightmap, Mesh, MeshId, PoolFormat, Pose, Precision, Shape, SnowError, SurfaceDesc,
};

const DT: f32 = 1.0 / 60.0;

/// Four surfaces in two zones, a pool for two (so some are paged out), one surface with snowfall.
fn world(precision: Precision) -> (SnowManager, Vec<ManagedId>, MeshId) {
    let format = PoolFormat::new(precision);
    let config = ManagerConfig {
        updates_per_frame: 1,
        pool_bytes: 2 * format.slot_bytes(50, 50) + 256,
        ..ManagerConfig::default()
    };
    let mut m = SnowManager::new(common::gpu(), config).unwrap();
    let ids = (0..4)
        .map(|i| {
            let mut d = SurfaceDesc::new(
                &format!("s{i}"),
                [i as f32 * 3.0, 0.0, 0.0],
                [2.0, 2.0],
                0.2,
            );
            if i == 3 {
                d.replenish_rate = 0.3;
            }
            m.add_surface(d, ZoneId(i / 2)).unwrap()
        })
        .collect();
    let cube = Mesh::cuboid(Vec3::splat(0.1));
    let mesh = m.add_mesh("cube", &cube).unwrap();
    (m, ids, mesh)
}

/// Frame `f`: a sphere walks along the row of surfaces, the cube slides across surface 1 and is
/// re-posed (stretched) every four frames.
fn step(m: &mut SnowManager, mesh: MeshId, f: u32) {
    if f.is_multiple_of(4) {
        let s = 1.0 + 0.2 * ((f / 4) % 3) as f32;
        let cube = Mesh::cuboid(Vec3::new(0.1 * s, 0.1, 0.1)).positions;
        m.pose_mesh(mesh, &cube).unwrap();
    }
    let sphere = |f: u32| Pose::at([-0.8 + f as f32 * 0.12, 0.17, 0.3]);
    let cube = |f: u32| Pose::at([2.2 + (f % 30) as f32 * 0.05, 0.15, -0.4]);
    let ds = [
        ManagedDeformer::player(Deformer::moving(
            Shape::Sphere { radius: 0.1 },
            sphere(f.saturating_sub(1)),
            sphere(f),
        )),
        ManagedDeformer::new(Deformer::moving(
            Shape::Mesh(mesh),
            cube(f.saturating_sub(1)),
            cube(f),
        )),
    ];
    if f == 50 {
        m.unload_zone(ZoneId(0)).unwrap();
    }
    if f == 70 {
        m.load_zone(ZoneId(0));
    }
    m.tick(DT, None, &ds).unwrap();
}

fn maps(m: &SnowManager, ids: &[ManagedId]) -> Vec<Heightmap> {
    ids.iter()
        .map(|&id| m.read_heightmap(id).unwrap())
        .collect()
}

/// Saved at frame N = 40 and 60 (queues waiting, surfaces paged out, a zone unloaded), loaded
/// into a fresh manager and run on to M = 100, every surface equals the run straight to 100 at
/// every precision, and the load itself reads back what was saved.
#[test]
fn save_at_n_then_continue_equals_running_straight_at_every_precision() {
    for precision in [Precision::Bits8, Precision::Bits16, Precision::Bits32] {
        let (mut straight, ids, mesh) = world(precision);
        for f in 0..100 {
            step(&mut straight, mesh, f);
        }
        for n in [40, 60] {
            let (mut first, _, mesh) = world(precision);
            for f in 0..n {
                step(&mut first, mesh, f);
            }
            let bytes = first.to_save_bytes().unwrap();
            let file = SaveFile::parse(&bytes).unwrap();
            assert_eq!(file.frames(), n as u64);
            let mut loaded = SnowManager::from_save(common::gpu(), file).unwrap();
            assert_eq!(
                maps(&loaded, &ids),
                maps(&first, &ids),
                "{precision:?} at {n}"
            );
            for &id in &ids {
                assert_eq!(
                    loaded.planner().queued_imprints(id),
                    first.planner().queued_imprints(id)
                );
                assert_eq!(loaded.planner().is_paged(id), first.planner().is_paged(id));
            }
            if n == 60 {
                assert!(
                    ids.iter().any(|&id| loaded.planner().is_paged(id)),
                    "a zone is out"
                );
            }
            for f in n..100 {
                step(&mut loaded, mesh, f);
            }
            assert_eq!(
                maps(&loaded, &ids),
                maps(&straight, &ids),
                "{precision:?}: saved at {n}, continued to 100"
            );
        }
        let end = maps(&straight, &ids);
        assert!(
            end.iter().take(3).all(|m| m.pressed_volume() > 5.0),
            "{precision:?}: real trails"
        );
    }
}

/// Two runs of the same inputs on one adapter give the same bits.
#[test]
fn the_same_inputs_give_the_same_bits() {
    let run = || {
        let (mut m, ids, mesh) = world(Precision::Bits16);
        for f in 0..80 {
            step(&mut m, mesh, f);
        }
        m.to_save_bytes().unwrap().len();
        maps(&m, &ids)
    };
    assert_eq!(run(), run());
}

fn small_save() -> Vec<u8> {
    let (mut m, _, mesh) = world(Precision::Bits16);
    for f in 0..12 {
        step(&mut m, mesh, f);
    }
    m.to_save_bytes().unwrap()
}

/// Every byte of a small save flipped, and every length it can be cut to: each is refused with
/// one sentence, before anything is built.
#[test]
fn every_flipped_byte_and_every_truncation_is_refused() {
    let bytes = small_save();
    assert!(SaveFile::parse(&bytes).is_ok());
    assert!(
        bytes.len() < 64 << 10,
        "a small save: {} bytes",
        bytes.len()
    );
    let mut damaged = bytes.clone();
    for i in 0..bytes.len() {
        damaged[i] ^= 0x5a;
        let e = SaveFile::parse(&damaged).expect_err("a flipped byte is found");
        assert!(!e.contains('\n') && !e.is_empty(), "one sentence: {e}");
        damaged[i] = bytes[i];
    }
    for len in 0..bytes.len() {
        assert!(
            SaveFile::parse(&bytes[..len]).is_err(),
            "cut to {len} bytes"
        );
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(
        SaveFile::parse(&longer)
            .unwrap_err()
            .contains("past its end")
    );
}

/// A damaged, foreign or newer file named to `SnowManager::load` is one sentence naming the
/// file; the manager already running is untouched.
#[test]
fn a_bad_save_file_leaves_the_running_world_as_it_was() {
    let dir = std::env::temp_dir().join(format!("snowprint-saves-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (mut running, ids, mesh) = world(Precision::Bits16);
    for f in 0..20 {
        step(&mut running, mesh, f);
    }
    let before = maps(&running, &ids);
    let good = dir.join("good.snow");
    running.save(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let mut newer = bytes.clone();
    newer[8..12].copy_from_slice(&5u32.to_le_bytes());
    let crc = crc32(&newer[..16]);
    newer[16..20].copy_from_slice(&crc.to_le_bytes());
    let cases: [(&str, Vec<u8>, &str); 4] = [
        (
            "damaged.snow",
            {
                let mut b = bytes.clone();
                let n = b.len();
                b[n - 3] ^= 1;
                b
            },
            "checksum",
        ),
        ("cut.snow", bytes[..bytes.len() / 2].to_vec(), "ends inside"),
        (
            "foreign.png",
            b"\x89PNG\r\n\x1a\n0000000000000000".to_vec(),
            "not a snowprint save",
        ),
        ("newer.snow", newer, "use a newer snowprint"),
    ];
    for (name, contents, says) in cases {
        let path = dir.join(name);
        std::fs::write(&path, contents).unwrap();
        let e = SnowManager::load(common::gpu(), &path).unwrap_err();
        assert!(matches!(e, SnowError::SaveFile { .. }), "{e}");
        let text = e.to_string();
        assert!(text.contains(name) && text.contains(says), "{name}: {text}");
    }
    assert_eq!(maps(&running, &ids), before);
    let loaded = SnowManager::load(common::gpu(), &good).unwrap();
    assert_eq!(maps(&loaded, &ids), before);
    // The save was written whole, with no temporary file left beside it.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(left.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// CRC-32 (IEEE), written out here so the test does not lean on the library's checksum code.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xedb8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// Every setting comes back from a save as it was, the catch-up mode included.
#[test]
fn a_save_keeps_every_setting() {
    let config = ManagerConfig {
        updates_per_frame: 3,
        pool_bytes: 1 << 20,
        active_distance: 42.5,
        distance_slack_frames: 5,
        player_slots: 2,
        queue_cap: 77,
        page_bytes: 123_456,
        replenish_interval: 0.125,
        catch_up: snowprint::manager::CatchUp::Union,
        format: PoolFormat::new(Precision::Bits8),
        ..ManagerConfig::default()
    };
    let mut m = SnowManager::new(common::gpu(), config.clone()).unwrap();
    let file = SaveFile::parse(&m.to_save_bytes().unwrap()).unwrap();
    assert_eq!(file.config, config);
}

/// A sand surface saved in the update a box pressed a steep-walled pit into it, while the pit
/// still slumps, and loaded into a fresh manager, slumps on as the original does: in the updates
/// after (a pebble pressing the far corner, so the manager updates the surface), the two
/// heightmaps are equal, and the pit's walls moved after the save (a loaded surface that counted
/// as settled would relax only around the pebble).
#[test]
fn a_surface_saved_while_it_slumps_slumps_on_after_a_load() {
    let config = ManagerConfig {
        updates_per_frame: 1,
        ..ManagerConfig::default()
    };
    let mut m = SnowManager::new(common::gpu(), config).unwrap();
    let mut d = SurfaceDesc::new("dune", [0.0, 0.0, 0.0], [2.0, 2.0], 0.2);
    d.material = snowprint::Material::sand();
    let id = m.add_surface(d, ZoneId(0)).unwrap();
    let pit = ManagedDeformer::player(Deformer::new(
        Shape::Box {
            half_extents: Vec3::new(0.3, 0.3, 0.3),
        },
        Pose::at([-0.3, 0.3, 0.0]),
    ));
    let pebble = |f: u32| {
        ManagedDeformer::player(Deformer::new(
            Shape::Sphere { radius: 0.05 },
            Pose::at([0.85, 0.22 - 0.001 * f as f32, 0.85]),
        ))
    };
    m.tick(DT, None, &[pit]).unwrap();
    let bytes = m.to_save_bytes().unwrap();
    let mut loaded =
        SnowManager::from_save(common::gpu(), SaveFile::parse(&bytes).unwrap()).unwrap();
    let at_save = m.read_heightmap(id).unwrap();
    assert!(loaded.read_heightmap(id).unwrap() == at_save);
    for f in 0..4 {
        m.tick(DT, None, &[pebble(f)]).unwrap();
        loaded.tick(DT, None, &[pebble(f)]).unwrap();
        let same = loaded.read_heightmap(id).unwrap() == m.read_heightmap(id).unwrap();
        assert!(same, "update {f} after the load differs");
    }
    // The pit's half of the surface (x < 0) moved after the save.
    let now = m.read_heightmap(id).unwrap();
    let w = now.width as usize;
    let moved = (0..now.depression.len())
        .filter(|&i| i % w < w / 2 && now.depression[i] != at_save.depression[i])
        .count();
    assert!(moved > 0, "the pit slumped on after the save");
}
