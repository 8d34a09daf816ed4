//! Fuzzing of the glTF loader (`Mesh::from_gltf_slice`): valid glTF and GLB seeds mutated byte-wise
//! (flips, JSON tokens, deletions, duplications, line splices) and as JSON structure (a value of any
//! node replaced by an edge value, keys deleted, array elements duplicated, children and indices
//! rewired), and files generated from their structure (node graphs with cycles and shared
//! children, accessors with edge counts, offsets and strides, URIs that try to leave the folder).
//! Every input must be answered without a panic, within a time limit, with a valid mesh or one line;
//! the process's peak memory must stay under a stated bound.
//!
//! `SNOWPRINT_FUZZ_CASES=1000000 cargo test --release -p snowprint --test fuzz_gltf` makes a long
//! run (`docs/RELIABILITY.md`, "Fuzzing: scene parser and glTF loader").

mod fuzz_support;
mod skin_support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use fuzz_support::{Edit, Watchdog, apply, cases, config, edit, finish};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
use serde_json::Value;
use snowprint::{Mesh, SkinnedMesh, SnowError};

/// Time one input may take (loading is microseconds; this only catches hangs).
const LIMIT: Duration = Duration::from_secs(10);

const TOKENS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "0",
    "-1",
    "1e308",
    "4294967295",
    "18446744073709551615",
    "null",
    "true",
    "\"children\": [0]",
    "\"children\": [0, 0]",
    "\"mesh\": 0",
    "\"uri\": \"../../etc/passwd\"",
    "\"uri\": \"/etc/passwd\"",
    "\"uri\": \"file:///etc/passwd\"",
    "\"uri\": \"data:,\"",
    "\"byteStride\": 0",
    "\"byteStride\": 4",
    "\"count\": 0",
    "\"count\": 4294967295",
    "\"byteOffset\": 4294967295",
    "\"sparse\": {}",
    "\"mode\": 4",
    "\"scene\": 7",
    "\"matrix\": [0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]",
    "\"scale\": [-1, 1, 1]",
];

/// The folder the loader may read from: `root/` holds the tetrahedron's buffer `tet.bin`, and the
/// fuzzed files are "in" `root/sub/`. Outside the root, `secret.bin` must never be read.
fn folders() -> &'static (PathBuf, PathBuf) {
    static DIRS: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    DIRS.get_or_init(|| {
        let top = fuzz_support::temp_dir("fuzz-gltf");
        let root = top.join("root");
        let sub = root.join("sub");
        std::fs::create_dir_all(&sub).expect("mkdir");
        std::fs::write(root.join("tet.bin"), fuzz_support::tetrahedron_bytes()).expect("write");
        std::fs::write(sub.join("tet.bin"), fuzz_support::tetrahedron_bytes()).expect("write");
        std::fs::write(top.join("secret.bin"), fuzz_support::tetrahedron_bytes()).expect("write");
        (sub, root)
    })
}

fn seeds() -> &'static [Vec<u8>] {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let mut seeds = vec![
            fuzz_support::tetrahedron_gltf().into_bytes(),
            fuzz_support::tetrahedron_glb(),
            fuzz_support::tetrahedron_json(
                r#"[ { "mesh": 0, "children": [1], "scale": [-1, 1, 1] }, { "mesh": 0, "rotation": [0, 0.7071068, 0, 0.7071068] } ]"#,
                "[0]",
                Some("tet.bin"),
            )
            .into_bytes(),
            fuzz_support::tetrahedron_json(r#"[ { "mesh": 0 } ]"#, "[0]", Some("../tet.bin"))
                .into_bytes(),
            fuzz_support::tetrahedron_json(r#"[ { "mesh": 0 } ]"#, "[0]", Some("../../secret.bin"))
                .into_bytes(),
        ];
        let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile/gltf");
        if let Ok(entries) = std::fs::read_dir(&corpus) {
            let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
            files.sort();
            for f in files {
                if f.extension().is_some_and(|e| e == "gltf" || e == "glb") {
                    seeds.push(std::fs::read(&f).expect("read seed"));
                }
            }
        }
        // Skinned seeds, read by both loaders: the hand-built two-joint file (skin, three kinds
        // of channel) and RiggedFigure.
        seeds.push(skin_support::two_joints(&skin_support::TwoJoints::default()));
        seeds.push(std::fs::read(skin_support::rigged_figure()).expect("read RiggedFigure"));
        seeds
    })
}

/// Load one file; `Err` only when the answer breaks the promise (a panic is caught by the
/// watchdog): a mesh must be valid, an error one line, and nothing outside the root may be read.
fn load_one(bytes: Vec<u8>) -> Result<(), String> {
    let (sub, root) = folders();
    let name = sub.join("fuzz.gltf");
    // The skinned loader reads the same file with its skins and animations: the same promise.
    let skinned = SkinnedMesh::from_gltf_slice(&bytes, &name, Some((sub, root)))
        .map(|s| s.mesh)
        .and_then(|m| m.validate("fuzzed skinned").map(|()| m));
    check_answer(skinned)?;
    check_answer(Mesh::from_gltf_slice(&bytes, &name, Some((sub, root))))
}

/// A loaded mesh must be valid and hold triangles, an error be one line of the loader's kinds.
fn check_answer(answer: snowprint::Result<Mesh>) -> Result<(), String> {
    match answer {
        Ok(mesh) => {
            mesh.validate("fuzzed")
                .map_err(|e| format!("a loaded mesh is not valid: {e}"))?;
            if mesh.indices.is_empty() {
                return Err("a loaded mesh has no triangles".into());
            }
            Ok(())
        }
        Err(
            e @ (SnowError::MeshFile { .. }
            | SnowError::MeshUri { .. }
            | SnowError::InvalidMesh { .. }),
        ) => {
            let msg = e.to_string();
            if msg.contains('\n') {
                Err(format!("not one line: {msg:?}"))
            } else {
                Ok(())
            }
        }
        Err(other) => Err(format!("an unexpected kind of error: {other}")),
    }
}

#[test]
fn byte_mutated_seeds_are_answered() {
    let n = cases(10_000);
    let start = Instant::now();
    let watchdog = Watchdog::new(load_one, LIMIT);
    let seeds = seeds();
    let strategy = (
        0..seeds.len(),
        0..seeds.len(),
        prop::collection::vec(edit(TOKENS.len()), 1..10),
    );
    TestRunner::new(config(n))
        .run(&strategy, |(a, b, edits): (usize, usize, Vec<Edit>)| {
            watchdog.check(apply(&seeds[a], &seeds[b], &edits, TOKENS))
        })
        .unwrap_or_else(|e| panic!("{e}"));
    finish("byte-mutated glTF", n, start);
}

/// A value to put anywhere in a glTF's JSON.
fn edge_value() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop::sample::select(vec![
            Value::from(0),
            Value::from(-1),
            Value::from(1),
            Value::from(2),
            Value::from(3),
            Value::from(4),
            Value::from(u32::MAX),
            Value::from(u64::MAX),
            Value::from(i64::MIN),
            Value::from(1e308),
            Value::from(-0.0),
            Value::from(5121),
            Value::from(5123),
            Value::from(5125),
            Value::from(5126),
            Value::from("VEC3"),
            Value::from("SCALAR"),
            Value::from("MAT4"),
            Value::from("../tet.bin"),
            Value::from("../../secret.bin"),
            Value::from("tet.bin"),
            Value::from("%2e%2e/%2e%2e/secret.bin"),
            Value::from("/etc/passwd"),
            Value::from("file:///etc/passwd"),
            Value::from("data:application/octet-stream;base64,AAAA"),
            Value::from("data:,x"),
            Value::from(""),
            Value::Null,
            Value::Bool(true),
            Value::Array(vec![]),
            Value::Object(Default::default()),
        ]),
        prop::collection::vec(0u64..8, 0..4).prop_map(Value::from),
        (-1.0e30f64..1.0e30).prop_map(Value::from),
    ]
}

#[derive(Clone, Debug)]
enum JsonEdit {
    /// Replace the k-th value (pre-order) by another.
    Replace(usize, Value),
    /// Remove the k-th value from its object or array.
    Remove(usize),
    /// Duplicate an element of the k-th array.
    DuplicateIn(usize, usize),
    /// Add a `children` list to the k-th node.
    Children(usize, Vec<u64>),
}

fn json_edit() -> impl Strategy<Value = JsonEdit> {
    let k = any::<usize>();
    prop_oneof![
        4 => (k, edge_value()).prop_map(|(k, v)| JsonEdit::Replace(k, v)),
        2 => k.prop_map(JsonEdit::Remove),
        1 => (k, any::<usize>()).prop_map(|(k, i)| JsonEdit::DuplicateIn(k, i)),
        2 => (k, prop::collection::vec(0u64..4, 0..4)).prop_map(|(k, c)| JsonEdit::Children(k, c)),
    ]
}

/// Number of values in a JSON tree, pre-order.
fn count(v: &Value) -> usize {
    1 + match v {
        Value::Array(a) => a.iter().map(count).sum(),
        Value::Object(o) => o.values().map(count).sum(),
        _ => 0,
    }
}

/// The k-th value of a tree in pre-order (k < count).
fn nth(v: &mut Value, k: usize) -> &mut Value {
    if k == 0 {
        return v;
    }
    let mut k = k - 1;
    let children: Vec<&mut Value> = match v {
        Value::Array(a) => a.iter_mut().collect(),
        Value::Object(o) => o.values_mut().collect(),
        _ => unreachable!("k is within the tree"),
    };
    for c in children {
        let n = count(c);
        if k < n {
            return nth(c, k);
        }
        k -= n;
    }
    unreachable!("k is within the tree")
}

fn apply_json(doc: &mut Value, e: &JsonEdit) {
    let n = count(doc);
    match e {
        JsonEdit::Replace(k, value) => *nth(doc, k % n) = value.clone(),
        JsonEdit::Remove(k) => {
            // Remove the first element or key of the k-th container.
            match nth(doc, k % n) {
                Value::Array(a) if !a.is_empty() => {
                    a.remove(0);
                }
                Value::Object(o) => {
                    if let Some(key) = o.keys().next().cloned() {
                        o.remove(&key);
                    }
                }
                _ => {}
            }
        }
        JsonEdit::DuplicateIn(k, i) => {
            if let Value::Array(a) = nth(doc, k % n)
                && !a.is_empty()
            {
                let x = a[i % a.len()].clone();
                a.push(x);
            }
        }
        JsonEdit::Children(k, children) => {
            if let Some(Value::Array(nodes)) = doc.get_mut("nodes")
                && !nodes.is_empty()
            {
                let len = nodes.len();
                if let Value::Object(node) = &mut nodes[k % len] {
                    node.insert("children".into(), Value::from(children.clone()));
                }
            }
        }
    }
}

#[test]
fn json_mutated_seeds_are_answered() {
    let n = cases(10_000);
    let start = Instant::now();
    let watchdog = Watchdog::new(load_one, LIMIT);
    // The JSON seeds, and the GLB's JSON chunk re-wrapped with the binary chunk after edits.
    let json_seeds: Vec<Value> = seeds()
        .iter()
        .filter_map(|s| serde_json::from_slice(s).ok())
        .collect();
    assert!(json_seeds.len() >= 4, "the JSON seeds did not parse");
    let strategy = (
        0..json_seeds.len(),
        prop::collection::vec(json_edit(), 1..6),
        any::<bool>(),
    );
    TestRunner::new(config(n))
        .run(&strategy, |(s, edits, as_glb)| {
            let mut doc = json_seeds[s].clone();
            for e in &edits {
                apply_json(&mut doc, e);
            }
            let text = doc.to_string();
            let bytes = if as_glb {
                fuzz_support::glb(&text, &fuzz_support::tetrahedron_bytes())
            } else {
                text.into_bytes()
            };
            watchdog.check(bytes)
        })
        .unwrap_or_else(|e| panic!("{e}"));
    finish("JSON-mutated glTF", n, start);
}

/// A glTF generated from its structure: `nodes` nodes with arbitrary children (cycles, shared
/// children, self-links), a mesh whose accessors have arbitrary counts, offsets and strides.
fn generated_gltf() -> impl Strategy<Value = Vec<u8>> {
    let node = (
        prop::option::of(0u32..2),
        prop::collection::vec(0u32..12, 0..3),
    );
    (
        prop::collection::vec(node, 1..12),
        prop::collection::vec(0u32..14, 0..3),
        (0u64..16, prop::option::of(0u64..32), 0u64..64),
        (0u64..40, 0u64..8),
        prop::sample::select(vec![5121u32, 5123, 5125, 5126]),
        prop::sample::select(vec!["tet.bin", "../tet.bin", "../../secret.bin", "data"]),
    )
        .prop_map(|(nodes, roots, (count, stride, offset), (icount, ioffset), itype, uri)| {
            let nodes: Vec<Value> = nodes
                .into_iter()
                .map(|(mesh, children)| {
                    let mut o = serde_json::Map::new();
                    if let Some(m) = mesh {
                        o.insert("mesh".into(), Value::from(m));
                    }
                    if !children.is_empty() {
                        o.insert("children".into(), Value::from(children));
                    }
                    Value::Object(o)
                })
                .collect();
            let uri = if uri == "data" {
                format!(
                    "data:application/octet-stream;base64,{}",
                    fuzz_support::base64(&fuzz_support::tetrahedron_bytes())
                )
            } else {
                uri.to_owned()
            };
            let mut view0 = serde_json::json!({ "buffer": 0, "byteOffset": 0, "byteLength": 48 });
            if let Some(s) = stride {
                view0["byteStride"] = Value::from(s);
            }
            serde_json::json!({
                "asset": { "version": "2.0" },
                "scenes": [ { "nodes": roots } ],
                "nodes": nodes,
                "meshes": [
                    { "primitives": [ { "attributes": { "POSITION": 0 }, "indices": 1 } ] },
                    { "primitives": [ { "attributes": { "POSITION": 0 } } ] }
                ],
                "buffers": [ { "byteLength": 72, "uri": uri } ],
                "bufferViews": [ view0, { "buffer": 0, "byteOffset": 48, "byteLength": 24 } ],
                "accessors": [
                    { "bufferView": 0, "byteOffset": offset, "componentType": 5126, "count": count, "type": "VEC3" },
                    { "bufferView": 1, "byteOffset": ioffset, "componentType": itype, "count": icount, "type": "SCALAR" }
                ]
            })
            .to_string()
            .into_bytes()
        })
}

#[test]
fn generated_gltf_files_are_answered() {
    let n = cases(10_000);
    let start = Instant::now();
    let watchdog = Watchdog::new(load_one, LIMIT);
    TestRunner::new(config(n))
        .run(&generated_gltf(), |bytes| watchdog.check(bytes))
        .unwrap_or_else(|e| panic!("{e}"));
    finish("generated glTF", n, start);
}

/// The seeds themselves are what the mutators start from: the valid ones load, and the one whose
/// buffer lies outside the root is refused (so a mutant that loads did not read `secret.bin`).
#[test]
fn seeds_load_and_the_outside_buffer_is_refused() {
    let (sub, root) = folders();
    let name = sub.join("seed.gltf");
    for (i, seed) in seeds().iter().take(4).enumerate() {
        let mesh = Mesh::from_gltf_slice(seed, &name, Some((sub, root)))
            .unwrap_or_else(|e| panic!("seed {i}: {e}"));
        assert_eq!(mesh.indices.len() % 12, 0, "seed {i}");
    }
    match Mesh::from_gltf_slice(&seeds()[4], &name, Some((sub, root))) {
        Err(SnowError::MeshUri { uri, problem, .. }) => {
            assert_eq!(uri, "../../secret.bin");
            assert!(problem.contains("outside"), "{problem}");
        }
        other => panic!("expected MeshUri, got {other:?}"),
    }
}
