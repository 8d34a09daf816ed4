//! Fuzzing of the scene parser (`Scene::parse`): valid seed scenes mutated byte-wise and line-wise
//! (flips, insertions of TOML tokens, deletions, duplications, splices of lines between seeds), and
//! scenes generated from their structure with edge values. Every input must be answered without a
//! panic, within a time limit, with either a scene or one `file:line: ...` line; the process's peak
//! memory must stay under a stated bound.
//!
//! `SNOWPRINT_FUZZ_CASES=1000000 cargo test --release -p snowprint --test fuzz_scene` makes a long
//! run (`docs/RELIABILITY.md`, "Fuzzing: scene parser and glTF loader").

mod fuzz_support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use fuzz_support::{Edit, Watchdog, apply, cases, config, edgy_number, edit, finish};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
use snowprint::SnowError;
use snowprint::scene::Scene;

/// Time one input may take (parsing is microseconds; this only catches hangs).
const LIMIT: Duration = Duration::from_secs(10);

/// Tokens inserted by the mutator.
const TOKENS: &[&str] = &[
    "\n",
    "=",
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    ",",
    "\"",
    "'",
    "#",
    ".",
    "-",
    "1e39",
    "nan",
    "inf",
    "-1",
    "0",
    "1e308",
    "3e38",
    "\"\"\"",
    "\\u0000",
    "[[surface]]\n",
    "[[deformer]]\n",
    "[capture]\n",
    "[budget]\n",
    "[camera]\n",
    "[[deformer.keys]]\n",
    "[[camera.keys]]\n",
    "version = 1\n",
    "shape = \"mesh\"\n",
    "shape = \"sphere\"\n",
    "shape = \"box\"\n",
    "shape = \"capsule\"\n",
    "path = \"tet.gltf\"\n",
    "path = \"cycle.gltf\"\n",
    "path = \"../../etc/passwd\"\n",
    "path = \"/etc/passwd\"\n",
    "radius = 1e36\n",
    "keys = [ { t = 0, position = [0, 0, 0] } ]\n",
    "zone = 99999999999\n",
    "updates_per_frame = -1\n",
    "pool_bytes = 0\n",
    "precision_bits = 7\n",
    "name = \"\"\n",
    "size = [1e30, 1e30]\n",
    "snow_depth = 1e-30\n",
    "yaw_degrees = 1e30\n",
];

/// The folder the fuzzed scenes are "in": it holds a valid mesh and a cyclic one.
fn scene_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = fuzz_support::temp_dir("fuzz-scene");
        std::fs::write(dir.join("tet.gltf"), fuzz_support::tetrahedron_gltf()).expect("write");
        let cycle = fuzz_support::tetrahedron_json(
            r#"[{"mesh":0,"children":[1]},{"children":[0]}]"#,
            "[0]",
            Some(&format!(
                "data:application/octet-stream;base64,{}",
                fuzz_support::base64(&fuzz_support::tetrahedron_bytes())
            )),
        );
        std::fs::write(dir.join("cycle.gltf"), cycle).expect("write");
        dir
    })
}

/// Seed scenes: the repository's scenes, one with a mesh, and the hostile corpus's scenes.
fn seeds() -> &'static [String] {
    static SEEDS: OnceLock<Vec<String>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut seeds = Vec::new();
        for folder in [
            manifest.join("../../scenes"),
            manifest.join("tests/hostile/scenes"),
        ] {
            let Ok(entries) = std::fs::read_dir(&folder) else {
                continue;
            };
            let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
            files.sort();
            for f in files {
                if f.extension().is_some_and(|e| e == "toml") {
                    seeds.push(std::fs::read_to_string(&f).expect("read seed"));
                }
            }
        }
        seeds.push(
            "version = 1\n[capture]\nmode = \"mask\"\nankle_height = 0.3\nmask_depth = 0.5\n\
             [budget]\nupdates_per_frame = 2\npool_bytes = 1048576\nactive_distance = 20\nprecision_bits = 8\n\
             [camera]\ntarget = [0, 0, 0]\nfov_y_degrees = 50\nkeys = [ { t = 0, eye = [0, 5, 5] } ]\n\
             [[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [2, 2]\nsnow_depth = 0.3\nyaw_degrees = 30\nreplenish_rate = 0.1\nzone = 1\n\
             [[deformer]]\nname = \"boot\"\nshape = \"mesh\"\npath = \"tet.gltf\"\nplayer = true\n\
             [[deformer.keys]]\nt = 0\nposition = [0, 0.1, 0]\nrotation_degrees = [0, 45, 0]\n"
                .to_owned(),
        );
        assert!(seeds.len() >= 4, "the seed scenes were not found");
        seeds
    })
}

/// Parse one scene; `Err` only when the answer breaks the promise (a panic is caught by the
/// watchdog): a scene error must be one line starting with the file's name.
fn parse_one(text: String) -> Result<(), String> {
    let path = scene_dir().join("fuzz.toml");
    match Scene::parse(&text, &path) {
        Ok(_) => Ok(()),
        Err(SnowError::Scene(msg)) => {
            let prefix = format!("{}:", path.display());
            if msg.contains('\n') || !msg.starts_with(&prefix) {
                Err(format!("not one `file:line:` line: {msg:?}"))
            } else {
                Ok(())
            }
        }
        Err(other) => Err(format!("not a scene error: {other}")),
    }
}

#[test]
fn mutated_seed_scenes_are_answered() {
    let n = cases(10_000);
    let start = Instant::now();
    let watchdog = Watchdog::new(parse_one, LIMIT);
    let seeds = seeds();
    let strategy = (
        0..seeds.len(),
        0..seeds.len(),
        prop::collection::vec(edit(TOKENS.len()), 1..12),
    );
    TestRunner::new(config(n))
        .run(&strategy, |(a, b, edits): (usize, usize, Vec<Edit>)| {
            let bytes = apply(seeds[a].as_bytes(), seeds[b].as_bytes(), &edits, TOKENS);
            watchdog.check(String::from_utf8_lossy(&bytes).into_owned())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    finish("mutated scenes", n, start);
}

/// A `key = value` line, the value often an edge number.
fn field(key: &'static str) -> impl Strategy<Value = String> {
    prop_oneof![
        3 => edgy_number().prop_map(move |v| format!("{key} = {v}\n")),
        1 => (edgy_number(), edgy_number(), edgy_number())
            .prop_map(move |(a, b, c)| format!("{key} = [{a}, {b}, {c}]\n")),
        1 => (edgy_number(), edgy_number()).prop_map(move |(a, b)| format!("{key} = [{a}, {b}]\n")),
        1 => Just(format!("{key} = \"x\"\n")),
        1 => Just(String::new()),
    ]
}

fn surface() -> impl Strategy<Value = String> {
    (
        "[a-z.é ]{0,8}",
        field("center"),
        field("size"),
        field("snow_depth"),
        field("yaw_degrees"),
        field("replenish_rate"),
        field("zone"),
    )
        .prop_map(|(name, a, b, c, d, e, f)| {
            format!("[[surface]]\nname = \"{name}\"\n{a}{b}{c}{d}{e}{f}")
        })
}

fn deformer() -> impl Strategy<Value = String> {
    let shape = prop::sample::select(vec!["sphere", "capsule", "box", "mesh", "cone", ""]);
    let path = prop::sample::select(vec![
        "tet.gltf",
        "cycle.gltf",
        "missing.glb",
        "../tet.gltf",
        "/etc/passwd",
        "",
        ".",
    ]);
    let key = (edgy_number(), field("position"), field("rotation_degrees"))
        .prop_map(|(t, p, r)| format!("[[deformer.keys]]\nt = {t}\n{p}{r}"));
    (
        "[a-z_]{0,6}",
        shape,
        field("radius"),
        field("half_height"),
        field("half_extents"),
        path,
        prop::collection::vec(key, 0..5),
    )
        .prop_map(|(name, shape, r, h, e, path, keys)| {
            format!(
                "[[deformer]]\nname = \"{name}\"\nshape = \"{shape}\"\n{r}{h}{e}path = \"{path}\"\n{}",
                keys.concat()
            )
        })
}

fn generated_scene() -> impl Strategy<Value = String> {
    (
        prop::sample::select(vec!["version = 1\n", "version = 2\n", ""]),
        prop::option::of((field("ankle_height"), field("mask_depth"))),
        prop::option::of((
            field("updates_per_frame"),
            field("pool_bytes"),
            field("active_distance"),
            field("precision_bits"),
        )),
        prop::option::of((field("target"), field("fov_y_degrees"), field("eye"))),
        prop::collection::vec(surface(), 0..4),
        prop::collection::vec(deformer(), 0..4),
    )
        .prop_map(|(version, capture, budget, camera, surfaces, deformers)| {
            let mut s = version.to_owned();
            if let Some((a, m)) = capture {
                s += &format!("[capture]\nmode = \"depth\"\n{a}{m}");
            }
            if let Some((u, p, a, b)) = budget {
                s += &format!("[budget]\n{u}{p}{a}{b}");
            }
            if let Some((t, f, e)) = camera {
                s += &format!("[camera]\n{t}{f}[[camera.keys]]\nt = 0\n{e}");
            }
            s + &surfaces.concat() + &deformers.concat()
        })
}

#[test]
fn generated_scenes_are_answered() {
    let n = cases(10_000);
    let start = Instant::now();
    let watchdog = Watchdog::new(parse_one, LIMIT);
    TestRunner::new(config(n))
        .run(&generated_scene(), |text| watchdog.check(text))
        .unwrap_or_else(|e| panic!("{e}"));
    finish("generated scenes", n, start);
}

/// The fuzzer itself can see what it claims: a panic and a hang in the function under test are
/// both reported as failures.
#[test]
fn the_watchdog_reports_panics_and_hangs() {
    fn panics(_: String) -> Result<(), String> {
        panic!("boom")
    }
    fn hangs(_: String) -> Result<(), String> {
        std::thread::sleep(Duration::from_secs(3600));
        Ok(())
    }
    let e = Watchdog::new(panics, LIMIT).run(String::new()).unwrap_err();
    assert!(e.contains("panicked: boom"), "{e}");
    let w = Watchdog::new(hangs, Duration::from_millis(50));
    let e = w.run(String::new()).unwrap_err();
    assert!(e.contains("did not finish"), "{e}");
    // A later input gets a fresh worker instead of queueing behind the stuck one.
    let e = w.run(String::new()).unwrap_err();
    assert!(e.contains("did not finish"), "{e}");
}
