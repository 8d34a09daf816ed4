//! The loader's own helpers on hand-made inputs (the files themselves are tested in
//! `tests/fuzz_gltf.rs`, `tests/hostile.rs` and `tests/scene_files.rs`).

use super::uri::{decode_base64, percent_decode, scheme};
use super::*;

#[test]
fn base64_decodes_known_values() {
    assert_eq!(decode_base64("TWFu").unwrap(), b"Man");
    assert_eq!(decode_base64("TWE=").unwrap(), b"Ma");
    assert_eq!(decode_base64("TQ==").unwrap(), b"M");
    assert_eq!(decode_base64("").unwrap(), b"");
    assert!(decode_base64("TQ=a").is_none());
    assert!(decode_base64("T*==").is_none());
}

#[test]
fn uris_with_a_scheme_are_told_from_relative_paths() {
    assert_eq!(scheme("file:///etc/passwd"), Some("file"));
    assert_eq!(scheme("http://x/y.bin"), Some("http"));
    assert_eq!(scheme("mesh.bin"), None);
    assert_eq!(scheme("a b/c:d.bin"), None);
    assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
    assert!(percent_decode("a%2").is_none());
}

#[test]
fn node_cycles_and_shared_children_are_refused() {
    let doc = |nodes: &str| {
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":{nodes}}}"#
        );
        gltf::Gltf::from_slice(text.as_bytes()).unwrap().document
    };
    let e = check_node_trees(&doc(r#"[{"children":[1]},{"children":[0]}]"#)).unwrap_err();
    assert!(e.contains("own ancestor") && e.contains("cycle"), "{e}");
    let e = check_node_trees(&doc(r#"[{"children":[0]}]"#)).unwrap_err();
    assert!(e.contains("node 0 lists itself"), "{e}");
    let e = check_node_trees(&doc(r#"[{"children":[1,2]},{"children":[2]},{}]"#)).unwrap_err();
    assert!(e.contains("node 2 is a child of both"), "{e}");
    assert!(check_node_trees(&doc(r#"[{"children":[1,2]},{"children":[3]},{},{}]"#)).is_ok());
    // A chain exactly MAX_GLTF_DEPTH deep is fine; one more level is not.
    let chain = |len: usize| {
        let nodes: Vec<String> = (0..len)
            .map(|i| {
                if i + 1 < len {
                    format!(r#"{{"children":[{}]}}"#, i + 1)
                } else {
                    "{}".to_owned()
                }
            })
            .collect();
        doc(&format!("[{}]", nodes.join(",")))
    };
    assert!(check_node_trees(&chain(MAX_GLTF_DEPTH)).is_ok());
    let e = check_node_trees(&chain(MAX_GLTF_DEPTH + 1)).unwrap_err();
    assert!(e.contains("levels deep"), "{e}");
}
