//! Saves of a manager that runs a terrain window (`docs/SAVES.md`, `TERR`): a hiker's loop that
//! leaves the near window is saved mid-walk, loaded into a fresh manager, and the saved manager
//! and the loaded one walk on alike, texel for texel, the strips paged out at the save coming
//! back into the window from the loaded store; a damaged `TERR` is one sentence, and version 2
//! files still load.

mod common;

use glam::Vec3;
use snowprint::manager::{
    ManagedDeformer, ManagedProbeStatus, ManagedSample, ManagedTerrainId, ManagerConfig, SaveFile,
    SnowManager, ZoneId,
};
use snowprint::{Deformer, LevelDesc, Material, Pose, Shape, SnowError, SurfaceDesc, TerrainDesc};

const DT: f32 = 1.0 / 60.0;
const DEPTH: f32 = 0.2;
const RADIUS: f32 = 0.12;
const SINK: f32 = 0.08;
/// The frame the walk is saved at: the hiker at the far end of the loop, the start of the trail
/// paged out of both levels' windows.
const SAVE_AT: u32 = 110;
/// The frame the walk ends at: back at the start, the outbound trail in the near window again.
const END: u32 = 220;

/// The valley: a near level of 48^2 texels of 5 cm (2.4 m) and a far one of 32^2 of 20 cm.
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

/// A pool of the valley's levels and two of the four roofs (the roofer pages them in and out).
fn config() -> ManagerConfig {
    let f = snowprint::PoolFormat::default();
    ManagerConfig {
        updates_per_frame: 3,
        pool_bytes: f.slot_bytes(48, 48) + f.slot_bytes(32, 32) + 2 * f.slot_bytes(50, 50) + 1024,
        active_distance: 500.0,
        ..ManagerConfig::default()
    }
}

/// Four 2 m roofs far from the valley.
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

/// Where the hiker is at frame `f`: out along x at z = 0 from x = -1 to 4 m, across to z = 0.6,
/// and back along x to -1 m.
fn hiker_at(f: u32) -> Vec3 {
    let (x, z) = match f {
        0..100 => (-1.0 + 0.05 * f as f32, 0.0),
        100..120 => (4.0, 0.03 * (f - 100) as f32),
        _ => (4.0 - 0.05 * (f - 120) as f32, 0.6),
    };
    Vec3::new(x, DEPTH - SINK + RADIUS, z)
}

/// The frame's deformers: the hiker (the player) and a roofer crossing roof `(f / 10) % 4`.
fn deformers(f: u32) -> Vec<ManagedDeformer> {
    let sphere = Shape::Sphere { radius: RADIUS };
    let hiker = Deformer::moving(
        sphere,
        Pose::at(hiker_at(f.saturating_sub(1)).to_array()),
        Pose::at(hiker_at(f).to_array()),
    );
    let k = ((f / 10) % 4) as f32;
    let x = 40.0 + 4.0 * k - 0.8 + 0.16 * (f % 10) as f32;
    let roofer = Deformer::new(sphere, Pose::at([x, DEPTH - SINK + RADIUS, 0.0]));
    vec![ManagedDeformer::player(hiker), ManagedDeformer::new(roofer)]
}

/// Frame `f` of the walk: the window follows the hiker, then the tick.
fn step(m: &mut SnowManager, t: ManagedTerrainId, f: u32) {
    m.follow_terrain(t, hiker_at(f)).expect("follow");
    m.tick(DT, None, &deformers(f)).expect("tick");
}

/// A manager with the roofs and, before the valley, a terrain added and removed (so that the
/// valley's handle is not the first).
fn start() -> (SnowManager, ManagedTerrainId) {
    let mut m = SnowManager::new(common::gpu(), config()).expect("manager");
    for r in roofs() {
        m.add_surface(r, ZoneId(0)).expect("roof");
    }
    let gone = TerrainDesc {
        name: "gone".into(),
        levels: vec![LevelDesc {
            texels: [16, 16],
            texel_size: 0.1,
        }],
        ..valley()
    };
    let g = m.add_terrain(gone, Vec3::ZERO).expect("terrain");
    m.remove_terrain(g).expect("remove");
    let t = m.add_terrain(valley(), hiker_at(0)).expect("terrain");
    assert_eq!(t.index(), 1);
    (m, t)
}

/// Every level's channels (depression, then displaced) in logical order, after the strips on
/// their way have landed.
fn levels(m: &mut SnowManager, t: ManagedTerrainId) -> Vec<Vec<u32>> {
    m.flush_terrain(t).expect("flush");
    m.terrain(t)
        .expect("terrain")
        .surfaces()
        .iter()
        .map(|&id| {
            let (d, s) = m.world().read_channels(id).expect("read");
            d.into_iter().chain(s).collect()
        })
        .collect()
}

fn roof_maps(m: &SnowManager) -> Vec<snowprint::Heightmap> {
    let ids: Vec<_> = m.surface_names().map(|s| s.0).collect();
    ids.iter()
        .map(|&id| m.read_heightmap(id).unwrap())
        .collect()
}

/// The manager's answers at `points`, each with the level that gave it (by its place in the
/// terrain, as the two managers' world handles differ).
fn probe(
    m: &mut SnowManager,
    t: ManagedTerrainId,
    points: &[Vec3],
) -> Vec<(Option<usize>, ManagedSample)> {
    let ticket = m.probe(points).expect("probe");
    for _ in 0..3 {
        m.tick(0.0, None, &[]).expect("tick");
        if let ManagedProbeStatus::Ready(s) = m.probe_result(ticket).expect("result") {
            let levels = m.terrain(t).expect("terrain").surfaces();
            return s
                .into_iter()
                .map(|a| {
                    let level = a
                        .sample
                        .surface
                        .and_then(|id| levels.iter().position(|&l| l == id));
                    let mut a = a;
                    a.sample.surface = None;
                    (level, a)
                })
                .collect();
        }
    }
    panic!("not answered in three ticks");
}

/// The heart of it: saved mid-walk with the start of the trail paged out of both windows, the
/// loaded manager and the saved one walk back to the start alike, every texel of both levels
/// and every probe the same, and the outbound trail pressed where the near window holds it
/// again (it came back from the loaded page store).
#[test]
fn a_saved_walk_goes_on_alike_and_brings_back_the_trail_paged_out() {
    let (mut m, t) = start();
    for f in 0..SAVE_AT {
        step(&mut m, t, f);
    }
    let bytes = m.to_save_bytes().expect("save");
    let file = SaveFile::parse(&bytes).expect("parse");
    assert_eq!(file.version, 4);
    assert_eq!(file.terrains.len(), 1);
    let saved = &file.terrains[0];
    assert_eq!((saved.index, saved.desc.clone()), (1, valley()));
    assert_eq!(
        saved.origins(),
        vec![
            m.terrain(t).unwrap().origin(0).unwrap(),
            m.terrain(t).unwrap().origin(1).unwrap()
        ]
    );
    assert!(saved.chunks() > 0, "strips were paged out by the save");
    let mut loaded = SnowManager::from_save(common::gpu(), file).expect("load");
    // Handles: the valley's as it was, the removed terrain's stale.
    let found: Vec<(ManagedTerrainId, String)> = loaded
        .terrain_ids()
        .map(|(id, n)| (id, n.to_owned()))
        .collect();
    assert_eq!(found, vec![(t, "valley".to_owned())]);
    assert_eq!(loaded.terrain_named("valley"), Some(t));
    assert!(matches!(
        loaded.terrain(ManagedTerrainId::from_index(0)),
        Err(SnowError::StaleHandle { .. })
    ));
    // As loaded: the same levels, windows, statistics, roofs and pool accounting.
    assert_eq!(levels(&mut loaded, t), levels(&mut m, t));
    let (a, b) = (m.terrain(t).unwrap(), loaded.terrain(t).unwrap());
    assert_eq!((a.origin(0), a.origin(1)), (b.origin(0), b.origin(1)));
    assert_eq!(a.stats(), b.stats());
    assert!(a.stats().store_chunks > 0);
    assert_eq!(roof_maps(&loaded), roof_maps(&m));
    assert_eq!(loaded.planner().pool_used(), m.planner().pool_used());
    assert_eq!(loaded.planner().budget(), m.planner().budget());

    for f in SAVE_AT..END {
        step(&mut m, t, f);
        step(&mut loaded, t, f);
    }
    let (ours, theirs) = (levels(&mut m, t), levels(&mut loaded, t));
    for (i, (x, y)) in ours.iter().zip(&theirs).enumerate() {
        let differ = x.iter().zip(y).filter(|(p, q)| p != q).count();
        assert_eq!(
            differ, 0,
            "level {i}: {differ} channels differ after the load"
        );
    }
    assert_eq!(
        m.terrain(t).unwrap().stats(),
        loaded.terrain(t).unwrap().stats()
    );
    assert!(m.terrain(t).unwrap().stats().texels_paged_in > 0);
    assert_eq!(roof_maps(&loaded), roof_maps(&m));
    // Probes: on the outbound trail (paged out at the save, in the near window now), on the
    // return trail, untouched snow beside them, and in the far level.
    let points: Vec<Vec3> = [
        (-0.8, 0.0),
        (-0.5, 0.0),
        (-0.2, 0.0),
        (0.1, 0.0),
        (-0.5, 0.6),
        (-0.5, 0.3),
        (2.0, 0.0),
    ]
    .iter()
    .map(|&(x, z)| Vec3::new(x, 1.0, z))
    .collect();
    let (ours, theirs) = (probe(&mut m, t, &points), probe(&mut loaded, t, &points));
    assert_eq!(ours, theirs);
    for (k, (level, a)) in ours.iter().enumerate() {
        let want = if k < 6 { Some(0) } else { Some(1) };
        assert_eq!(*level, want, "point {k}: {a:?}");
        if k < 6 {
            let pressed = a.sample.depression_m > 0.03;
            assert_eq!(pressed, k != 5, "point {k}: {a:?}");
        }
    }
}

/// A save's sections as `(tag, data)`.
type Sections = Vec<([u8; 4], Vec<u8>)>;

/// The sections of a save as `(tag, data)`.
fn sections(bytes: &[u8]) -> Sections {
    SaveFile::parse(bytes)
        .expect("parse")
        .sections
        .into_iter()
        .map(|s| (s.tag, s.data))
        .collect()
}

/// Where level 0's fields start in a `TERR` section: after the handle, the description and the
/// ground's heights (none: flat), and the level count.
fn level0(terr: &[u8]) -> usize {
    let json = u64::from_le_bytes(terr[4..12].try_into().unwrap()) as usize;
    12 + json + 8 + 4
}

/// A damaged `TERR` (each value below rewritten, the checksums made right again, or the section
/// cut short) is refused in one sentence that names the section and the value, before anything is
/// built; a version 2 file without windows still loads, and one with a `TERR` is refused.
#[test]
fn a_damaged_terrain_section_is_one_sentence_and_version_2_still_loads() {
    let (mut m, t) = start();
    for f in 0..60 {
        step(&mut m, t, f);
    }
    let bytes = m.to_save_bytes().expect("save");
    let secs = sections(&bytes);
    let k = secs.iter().position(|s| &s.0 == b"TERR").expect("a TERR");
    let terr = &secs[k].1;
    let at = level0(terr);
    let words = u64::from_le_bytes(terr[at + 32..at + 40].try_into().unwrap()) as usize;
    // A level: origin, slot, carry and word count (40 bytes), its words, its settle state.
    let settle0 = at + 40 + 4 * words;
    let pages = settle0
        + common::SETTLE_BYTES
        + {
            let l1 = settle0 + common::SETTLE_BYTES;
            let n = u64::from_le_bytes(terr[l1 + 32..l1 + 40].try_into().unwrap()) as usize;
            40 + 4 * n + common::SETTLE_BYTES
        }
        + 7 * 8;
    assert!(
        u64::from_le_bytes(terr[pages..pages + 8].try_into().unwrap()) > 0,
        "pages saved"
    );
    let page0_end =
        pages + 36 + u64::from_le_bytes(terr[pages + 28..pages + 36].try_into().unwrap()) as usize;
    let edit = |at: usize, with: &[u8]| {
        let mut s = secs.clone();
        s[k].1[at..at + with.len()].copy_from_slice(with);
        s
    };
    let cut = |len: usize| {
        let mut s = secs.clone();
        s[k].1.truncate(len);
        s
    };
    let cases: Vec<(Sections, &str)> = vec![
        (edit(at - 4, &3u32.to_le_bytes()), "3 levels saved"),
        (
            edit(at + 24, &2.0f64.to_le_bytes()),
            "carry 2 is not a fraction",
        ),
        (edit(at + 32, &(words as u64 - 1).to_le_bytes()), "words"),
        (edit(at + 16, &8u64.to_le_bytes()), "overlaps"),
        (edit(pages + 8, &9u32.to_le_bytes()), "page of level 9"),
        // Level 0's settle rectangle reaching past its 48 columns.
        (
            edit(settle0 + 12, &49u32.to_le_bytes()),
            "settling rectangle",
        ),
        (edit(settle0, &5000u32.to_le_bytes()), "at most"),
        // The last byte of the first page's LZ4: a literal, the top byte of a channel.
        (edit(page0_end - 1, &[1]), "above the pool's 65535"),
        (edit(13, b"}"), "description does not read"),
        (cut(at + 40 + 4 * words / 2), "a level's words claims"),
        (cut(pages + 4), "ends inside its pages"),
    ];
    for (s, says) in cases {
        let Err(e) = SaveFile::parse(&common::assemble_save(4, &s)) else {
            panic!("{says}: the damaged section was read");
        };
        assert!(
            e.contains("TERR") && e.contains(says) && e.contains("load an earlier one"),
            "{says}: {e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
    // Any cut of the section is refused.
    for len in (0..terr.len()).step_by(61) {
        assert!(SaveFile::parse(&common::assemble_save(4, &cut(len))).is_err());
    }
    // Through `load`: the file's name and the sentence, and no manager.
    let dir = std::env::temp_dir().join(format!("snowprint-terrain-saves-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("carry.snow");
    std::fs::write(
        &path,
        common::assemble_save(4, &edit(at + 24, &2.0f64.to_le_bytes())),
    )
    .unwrap();
    let e = SnowManager::load(common::gpu(), &path).unwrap_err();
    assert!(matches!(e, SnowError::SaveFile { .. }), "{e}");
    assert!(
        e.to_string().contains("carry.snow") && e.to_string().contains("TERR"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();

    // Version 2: a file with a TERR is refused; one without (the terrain removed) loads and
    // holds the roofs as they were.
    let e = SaveFile::parse(&common::assemble_save(2, &secs)).unwrap_err();
    assert!(e.contains("(from version 3) TERR"), "{e}");
    m.remove_terrain(t).expect("remove");
    let v3 = sections(&m.to_save_bytes().expect("save"));
    assert!(v3.iter().all(|s| &s.0 != b"TERR"));
    let file = SaveFile::parse(&common::assemble_save(2, &v3)).expect("a version 2 file");
    assert_eq!(file.version, 2);
    let loaded = SnowManager::from_save(common::gpu(), file).expect("load");
    assert_eq!(roof_maps(&loaded), roof_maps(&m));
    assert_eq!(loaded.terrain_ids().count(), 0);
}

/// A sand terrain saved in the update a box pressed a steep-walled pit into its level, while the
/// pit still slumps, and loaded into a fresh manager: with a pebble pressing the level's far
/// side after (so that the level is updated), the two levels are the same texel for texel, and
/// the pit's walls moved after the save (a level that loaded as settled would relax only around
/// the pebble).
#[test]
fn a_terrain_level_saved_while_it_slumps_slumps_on_after_a_load() {
    let dunes = TerrainDesc {
        name: "dunes".into(),
        material: Material::sand(),
        replenish_rate: 0.0,
        levels: vec![LevelDesc {
            texels: [48, 48],
            texel_size: 0.05,
        }],
        ..valley()
    };
    let mut m = SnowManager::new(common::gpu(), config()).expect("manager");
    let t = m.add_terrain(dunes, Vec3::ZERO).expect("terrain");
    let pit = ManagedDeformer::player(Deformer::new(
        Shape::Box {
            half_extents: Vec3::new(0.3, 0.3, 0.3),
        },
        Pose::at([-0.5, 0.3, 0.0]),
    ));
    let pebble = |f: u32| {
        ManagedDeformer::new(Deformer::new(
            Shape::Sphere { radius: 0.05 },
            Pose::at([0.9, 0.22 - 0.001 * f as f32, 0.9]),
        ))
    };
    m.follow_terrain(t, Vec3::ZERO).expect("follow");
    m.tick(DT, None, &[pit]).expect("tick");
    let bytes = m.to_save_bytes().expect("save");
    let mut loaded = SnowManager::from_save(common::gpu(), SaveFile::parse(&bytes).expect("parse"))
        .expect("load");
    let lt = loaded.terrain_named("dunes").expect("the terrain");
    let at_save = levels(&mut m, t);
    assert!(levels(&mut loaded, lt) == at_save);
    for f in 0..4 {
        for (mm, tt) in [(&mut m, t), (&mut loaded, lt)] {
            mm.follow_terrain(tt, Vec3::ZERO).expect("follow");
            mm.tick(DT, None, &[pebble(f)]).expect("tick");
        }
        let same = levels(&mut loaded, lt) == levels(&mut m, t);
        assert!(same, "update {f} after the load differs");
    }
    // The pit's half of the level (x < 0, depression channel) moved after the save.
    let now = levels(&mut m, t);
    let moved = (0..48 * 48)
        .filter(|&i| i % 48 < 24 && now[0][i] != at_save[0][i])
        .count();
    assert!(moved > 0, "the pit slumped on after the save");
}
