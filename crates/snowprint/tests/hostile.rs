//! The library's share of the hostile corpus: bad glTF files (`tests/hostile/gltf/`) and bad scene
//! files (`tests/hostile/scenes/`), each with the one-line answer expected for it in a `.expect`
//! file beside it (the corpus folder's path written as `<hostile>`). Every file must get exactly
//! that answer: no hang, no panic, no file read outside the allowed folder. A few files are odd but
//! valid (inputs that once crashed the loader, found by `fuzz_gltf.rs`): their answer is
//! `(accepted)`.
//!
//! `SNOWPRINT_BLESS=1` rewrites the `.expect` files from the answers given (review the diff); it is
//! refused when `CI` is set.

mod fuzz_support;

use std::path::{Path, PathBuf};

use snowprint::scene::Scene;
use snowprint::{Mesh, SnowError};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile")
}

/// The answer with the corpus folder's path (as given and canonical) written as `<hostile>`.
fn normalize(msg: &str) -> String {
    let dir = corpus();
    let mut out = msg.to_owned();
    if let Ok(canonical) = dir.canonicalize() {
        out = out.replace(&canonical.display().to_string(), "<hostile>");
    }
    out.replace(&dir.display().to_string(), "<hostile>")
}

fn bless() -> bool {
    let asked = std::env::var_os("SNOWPRINT_BLESS").is_some_and(|v| v == "1");
    assert!(
        !(asked && std::env::var_os("CI").is_some()),
        "SNOWPRINT_BLESS is refused when CI is set: expected answers are reviewed, never rewritten by CI"
    );
    asked
}

/// Run every file of `folder` with one of `extensions` through `answer`, and compare.
fn check_folder(folder: &str, extensions: &[&str], answer: fn(&Path) -> Result<(), SnowError>) {
    let dir = corpus().join(folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| extensions.contains(&e))
        })
        .collect();
    files.sort();
    assert!(files.len() >= 5, "{}: too few corpus files", dir.display());
    let bless = bless();
    let mut failures = Vec::new();
    for file in &files {
        let expect_path = file.with_extension("expect");
        let got = match answer(file) {
            Ok(()) => "(accepted)".to_owned(),
            Err(e) => normalize(&e.to_string()),
        };
        assert!(
            !got.contains('\n'),
            "{}: not one line: {got}",
            file.display()
        );
        if bless {
            std::fs::write(&expect_path, format!("{got}\n")).expect("write .expect");
            continue;
        }
        let want = std::fs::read_to_string(&expect_path)
            .unwrap_or_else(|e| panic!("{}: {e}", expect_path.display()));
        if got != want.trim_end() {
            failures.push(format!(
                "{}\n  want: {}\n  got:  {got}",
                file.display(),
                want.trim_end()
            ));
        }
    }
    // Every answer has its file: a .expect left behind by a removed case fails.
    for e in std::fs::read_dir(&dir).expect("read corpus").flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "expect") {
            let has_case = extensions.iter().any(|x| p.with_extension(x).exists());
            assert!(has_case, "{} has no corpus file", p.display());
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn hostile_gltf_files_get_their_expected_answer() {
    check_folder("gltf", &["gltf", "glb"], |p| Mesh::load_gltf(p).map(|_| ()));
}

#[test]
fn hostile_scene_files_get_their_expected_answer() {
    check_folder("scenes", &["toml"], |p| Scene::load(p).map(|_| ()));
}

/// The corpus also names what must keep working: a GLB's binary chunk, a buffer beside the file,
/// and a buffer reached through `..` that stays under the allowed root.
#[test]
fn glb_and_buffers_inside_the_root_still_load() {
    let dir = fuzz_support::temp_dir("hostile-ok");
    std::fs::create_dir_all(dir.join("meshes")).expect("mkdir");
    std::fs::write(dir.join("meshes/tet.glb"), fuzz_support::tetrahedron_glb()).expect("write");
    std::fs::write(dir.join("tet.bin"), fuzz_support::tetrahedron_bytes()).expect("write");
    std::fs::write(
        dir.join("meshes/tet.bin"),
        fuzz_support::tetrahedron_bytes(),
    )
    .expect("write");
    let json = |uri: &str| fuzz_support::tetrahedron_json(r#"[ { "mesh": 0 } ]"#, "[0]", Some(uri));
    std::fs::write(dir.join("meshes/beside.gltf"), json("tet.bin")).expect("write");
    std::fs::write(dir.join("meshes/up.gltf"), json("../tet.bin")).expect("write");
    std::fs::write(dir.join("meshes/escaped.gltf"), json("tet%2Ebin")).expect("write");

    let glb = Mesh::load_gltf(&dir.join("meshes/tet.glb")).expect("GLB");
    assert_eq!((glb.positions.len(), glb.indices.len()), (4, 12));
    Mesh::load_gltf(&dir.join("meshes/beside.gltf")).expect("buffer beside the file");
    Mesh::load_gltf(&dir.join("meshes/escaped.gltf")).expect("%-escaped uri");
    // Under the file's own folder only, `../tet.bin` is outside; under the scene's folder it is in.
    match Mesh::load_gltf(&dir.join("meshes/up.gltf")) {
        Err(SnowError::MeshUri { uri, problem, .. }) => {
            assert_eq!(uri, "../tet.bin");
            assert!(problem.contains("outside"), "{problem}");
        }
        other => panic!("expected MeshUri, got {other:?}"),
    }
    Mesh::load_gltf_within(&dir.join("meshes/up.gltf"), &dir).expect("inside the root");
    // A scene's mesh path may wander as long as it stays under the scene's folder, and a glTF in a
    // subfolder may read a buffer beside the scene.
    let name = dir.file_name().and_then(|n| n.to_str()).expect("temp name");
    for path in [
        "meshes/tet.glb".to_owned(),
        "./meshes/../meshes/tet.glb".to_owned(),
        format!("../{name}/meshes/tet.glb"),
        "meshes/up.gltf".to_owned(),
    ] {
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!(
                "version = 1\n[[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [2, 2]\nsnow_depth = 0.3\n\
                 [[deformer]]\nname = \"boot\"\nshape = \"mesh\"\npath = \"{path}\"\nkeys = [ {{ t = 0, position = [0, 0.1, 0] }} ]\n"
            ),
        )
        .expect("write");
        Scene::load(&scene).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A symbolic link inside the folder that leads out of it is refused, for a buffer and for the
/// scene's mesh path.
#[cfg(unix)]
#[test]
fn symbolic_links_out_of_the_folder_are_refused() {
    let top = fuzz_support::temp_dir("hostile-link");
    let inside = top.join("mod");
    std::fs::create_dir_all(&inside).expect("mkdir");
    std::fs::write(top.join("secret.bin"), fuzz_support::tetrahedron_bytes()).expect("write");
    std::fs::write(top.join("outside.gltf"), fuzz_support::tetrahedron_gltf()).expect("write");
    std::os::unix::fs::symlink(top.join("secret.bin"), inside.join("tet.bin")).expect("symlink");
    std::os::unix::fs::symlink(top.join("outside.gltf"), inside.join("linked.gltf"))
        .expect("symlink");
    let json = fuzz_support::tetrahedron_json(r#"[ { "mesh": 0 } ]"#, "[0]", Some("tet.bin"));
    std::fs::write(inside.join("mesh.gltf"), json).expect("write");
    match Mesh::load_gltf(&inside.join("mesh.gltf")) {
        Err(e @ SnowError::MeshUri { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("buffer 0 has uri \"tet.bin\""), "{msg}");
            assert!(msg.contains("secret.bin, outside"), "{msg}");
        }
        other => panic!("expected MeshUri, got {other:?}"),
    }
    let scene = inside.join("scene.toml");
    std::fs::write(
        &scene,
        "version = 1\n[[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [2, 2]\nsnow_depth = 0.3\n\
         [[deformer]]\nname = \"boot\"\nshape = \"mesh\"\npath = \"linked.gltf\"\nkeys = [ { t = 0, position = [0, 0.1, 0] } ]\n",
    )
    .expect("write");
    match Scene::load(&scene) {
        Err(SnowError::Scene(msg)) => {
            assert!(
                msg.starts_with(&format!("{}:10: ", scene.display())),
                "{msg}"
            );
            assert!(
                msg.contains("leads outside the scene file's folder"),
                "{msg}"
            );
        }
        other => panic!("expected a scene error, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&top);
}
