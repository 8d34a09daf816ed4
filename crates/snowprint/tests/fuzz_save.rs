//! Fuzzing of the save loader (`SaveFile::parse`, then `SnowManager::from_save` for what parses):
//! a real save mutated byte-wise (flips, insertions, deletions, cuts, splices), and mutated inside
//! its sections with every length and checksum fixed up afterwards, so that the inputs reach the
//! settings, the planner's state, the meshes, the heightmaps and the terrain window rather than stopping at a
//! checksum. Every input runs under the fuzzers' watchdog (`fuzz_support`: a panic or a hang fails
//! it) and must be answered with a manager or one sentence; the process's peak memory must stay
//! under `fuzz_support::RSS_BOUND`.
//!
//! `SNOWPRINT_FUZZ_CASES=1000000 cargo test --release -p snowprint --test fuzz_save` makes a long
//! run (`docs/RELIABILITY.md`, "Fuzzing: the save loader").

mod common;
mod fuzz_support;

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use fuzz_support::{Watchdog, cases, config, finish};

use glam::Vec3;
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
use snowprint::manager::SaveFile;
use snowprint::manager::{ManagedDeformer, ManagerConfig, SnowManager, ZoneId};
use snowprint::{Deformer, Mesh, Pose, Shape, SurfaceDesc};

/// Time one input may take (a parse is microseconds, a load a few milliseconds).
const LIMIT: Duration = Duration::from_secs(10);

/// A small real save: three surfaces (one paged out), queued imprints, a mesh re-posed while
/// queued (so an earlier posing is saved too), and a terrain window of one 16^2 level that
/// follows the sphere (so its store holds pages).
fn seed() -> &'static [u8] {
    static SEED: OnceLock<Vec<u8>> = OnceLock::new();
    SEED.get_or_init(|| {
        let f = snowprint::PoolFormat::default();
        let config = ManagerConfig {
            updates_per_frame: 2,
            pool_bytes: 2 * f.slot_bytes(25, 25) + f.slot_bytes(16, 16) + 256,
            ..ManagerConfig::default()
        };
        let mut m = SnowManager::new(common::gpu(), config).unwrap();
        let valley = snowprint::TerrainDesc {
            name: "valley".into(),
            ground_height: 0.0,
            ground: None,
            snow_depth: 0.2,
            replenish_rate: 0.0,
            material: snowprint::Material::snow(),
            levels: vec![snowprint::LevelDesc {
                texels: [16, 16],
                texel_size: 0.1,
            }],
        };
        let t = m.add_terrain(valley, Vec3::new(-0.4, 0.0, 0.0)).unwrap();
        for i in 0..3 {
            let d = SurfaceDesc::new(
                &format!("s{i}"),
                [i as f32 * 2.0, 0.0, 0.0],
                [1.0, 1.0],
                0.2,
            );
            m.add_surface(d, ZoneId(i)).unwrap();
        }
        let tet = Mesh {
            positions: vec![
                Vec3::new(0.0, 0.1, 0.0),
                Vec3::new(0.1, -0.1, 0.1),
                Vec3::new(-0.1, -0.1, 0.1),
                Vec3::new(0.0, -0.1, -0.1),
            ],
            indices: vec![0, 2, 1, 0, 3, 2, 0, 1, 3, 1, 2, 3],
        };
        let mesh = m.add_mesh("tet", &tet).unwrap();
        for f in 0..8 {
            let x = f as f32 * 0.6 - 0.4;
            m.follow_terrain(t, Vec3::new(x, 0.0, 0.0)).unwrap();
            let ds = [
                ManagedDeformer::new(Deformer::new(
                    Shape::Sphere { radius: 0.1 },
                    Pose::at([x, 0.17, 0.0]),
                )),
                ManagedDeformer::new(Deformer::new(Shape::Mesh(mesh), Pose::at([x, 0.15, 0.2]))),
            ];
            m.tick(1.0 / 60.0, None, &ds).unwrap();
            let s = 1.0 + f as f32 * 0.1;
            let posed: Vec<Vec3> = tet.positions.iter().map(|p| *p * s).collect();
            m.pose_mesh(mesh, &posed).unwrap();
        }
        m.to_save_bytes().unwrap()
    })
}

/// The sections of a save as `(tag, data)`, decompressed (the seed always parses).
fn sections(bytes: &[u8]) -> Vec<([u8; 4], Vec<u8>)> {
    SaveFile::parse(bytes)
        .unwrap()
        .sections
        .into_iter()
        .map(|s| (s.tag, s.data))
        .collect()
}

/// JSON fragments the text sections are mutated with.
const TOKENS: &[&str] = &[
    "null",
    "0",
    "-1",
    "1e39",
    "4294967296",
    "18446744073709551615",
    "[]",
    "{}",
    "\"\"",
    "true",
    "1.5",
    "-0.0",
    "[0,0]",
    "{\"Mesh\":7}",
    "{\"Sphere\":{\"radius\":-1}}",
    "[[0,1]]",
];

/// One mutation.
#[derive(Clone, Debug)]
enum Mutation {
    /// Raw bytes: flip, insert, delete, cut.
    Flip(usize, u8),
    Insert(usize, u8),
    Delete(usize, usize),
    Cut(usize),
    /// Inside section `s` (checksums fixed up): flip a byte, overwrite a 4- or 8-byte number
    /// with an edge value, put a JSON token over a span, drop or repeat the section.
    SectionFlip(usize, usize, u8),
    SectionNumber(usize, usize, u64, bool),
    SectionToken(usize, usize, usize, usize),
    DropSection(usize),
    RepeatSection(usize),
    Version(u32),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let edge = prop_oneof![
        Just(0u64),
        Just(1),
        Just(u32::MAX as u64),
        Just(u64::MAX),
        Just(1 << 31),
        Just(f32::NAN.to_bits() as u64),
        Just(f32::INFINITY.to_bits() as u64),
        Just(f64::NAN.to_bits()),
        Just(1e300f64.to_bits()),
        any::<u64>(),
    ];
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<usize>(), 1usize..64).prop_map(|(i, n)| Mutation::Delete(i, n)),
        any::<usize>().prop_map(Mutation::Cut),
        (any::<usize>(), any::<usize>(), 1u8..=255)
            .prop_map(|(s, i, b)| Mutation::SectionFlip(s, i, b)),
        (any::<usize>(), any::<usize>(), edge, any::<bool>())
            .prop_map(|(s, i, v, wide)| Mutation::SectionNumber(s, i, v, wide)),
        (any::<usize>(), any::<usize>(), 0usize..12, 0..TOKENS.len())
            .prop_map(|(s, i, n, t)| Mutation::SectionToken(s, i, n, t)),
        any::<usize>().prop_map(Mutation::DropSection),
        any::<usize>().prop_map(Mutation::RepeatSection),
        prop_oneof![Just(0u32), Just(2), any::<u32>()].prop_map(Mutation::Version),
    ]
}

fn apply(bytes: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut secs = sections(bytes);
    // The seed's own version, unless a mutation changes it.
    let mut version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    let mut raw: Vec<&Mutation> = Vec::new();
    for m in muts {
        let n = secs.len().max(1);
        match *m {
            Mutation::SectionFlip(s, i, b) => {
                let d = &mut secs[s % n].1;
                if !d.is_empty() {
                    let k = i % d.len();
                    d[k] ^= b;
                }
            }
            Mutation::SectionNumber(s, i, v, wide) => {
                let d = &mut secs[s % n].1;
                let w = if wide { 8 } else { 4 };
                if d.len() >= w {
                    let k = i % (d.len() - w + 1);
                    d[k..k + w].copy_from_slice(&v.to_le_bytes()[..w]);
                }
            }
            Mutation::SectionToken(s, i, len, t) => {
                let d = &mut secs[s % n].1;
                let k = i % (d.len() + 1);
                let end = (k + len).min(d.len());
                d.splice(k..end, TOKENS[t].bytes());
            }
            Mutation::DropSection(s) => {
                if !secs.is_empty() {
                    secs.remove(s % n);
                }
            }
            Mutation::RepeatSection(s) => {
                if !secs.is_empty() {
                    let c = secs[s % n].clone();
                    secs.push(c);
                }
            }
            Mutation::Version(v) => version = v,
            _ => raw.push(m),
        }
    }
    let mut out = common::assemble_save(version, &secs);
    for m in raw {
        let n = out.len().max(1);
        match *m {
            Mutation::Flip(i, b) if !out.is_empty() => out[i % n] ^= b,
            Mutation::Insert(i, b) => out.insert(i % (out.len() + 1), b),
            Mutation::Delete(i, len) => {
                let k = i % n;
                let end = (k + len).min(out.len());
                out.drain(k.min(end)..end);
            }
            Mutation::Cut(i) => out.truncate(i % n),
            _ => {}
        }
    }
    out
}

/// `SNOWPRINT_FUZZ_LOADS`: at most this many inputs that parse are also loaded on the GPU
/// (loading builds a world and its terrain, about a fifth of a second on lavapipe); the others
/// are parsed only. 60 by default keeps the test near ten seconds.
fn max_loads() -> u64 {
    std::env::var("SNOWPRINT_FUZZ_LOADS")
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(60)
}

static PARSED: AtomicU64 = AtomicU64::new(0);
static LOADED: AtomicU64 = AtomicU64::new(0);

/// One input, on the watchdog's worker: parse it, and load what parses (up to the load count).
/// Every answer must be one line.
fn load_one(input: Vec<u8>) -> Result<(), String> {
    let one_line = |e: String| {
        if e.is_empty() || e.contains('\n') {
            Err(format!("not one line: {e:?}"))
        } else {
            Ok(())
        }
    };
    let file = match SaveFile::parse(&input) {
        Ok(file) => file,
        Err(e) => return one_line(e),
    };
    if PARSED.fetch_add(1, Ordering::Relaxed) >= max_loads() {
        return Ok(());
    }
    LOADED.fetch_add(1, Ordering::Relaxed);
    match SnowManager::from_save(common::gpu(), file) {
        Ok(m) => {
            // What loaded is usable: read every surface.
            for (id, _) in m.surface_names().collect::<Vec<_>>() {
                let _ = m.read_heightmap(id);
            }
            Ok(())
        }
        Err(e) => one_line(e.to_string()),
    }
}

#[test]
fn the_save_loader_answers_every_input() {
    let seed = seed();
    // The re-assembled seed is a valid save: the fix-up is right, so mutations go deep.
    let file = SaveFile::parse(&common::assemble_save(4, &sections(seed))).unwrap();
    assert!(file.terrains.len() == 1 && file.terrains[0].chunks() > 0);
    let n = cases(2000);
    let start = Instant::now();
    let watchdog = Watchdog::new(load_one, LIMIT);
    TestRunner::new(config(n))
        .run(&proptest::collection::vec(mutation(), 1..4), |muts| {
            watchdog.check(apply(seed, &muts))
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let (parsed, loaded) = (
        PARSED.load(Ordering::Relaxed),
        LOADED.load(Ordering::Relaxed),
    );
    println!("fuzz_save: {parsed} inputs parsed, {loaded} of them loaded or refused by from_save");
    finish("fuzz_save", n, start);
    assert!(
        parsed > 0,
        "the structure-aware mutations reach past the checksums"
    );
}
