//! `snowprint simulate --save/--load` and `snowprint inspect` end to end: the sixteen roofs
//! hold every trail at any frame count, a run saved at frame 50 and continued for 40 more dumps the
//! same bytes as a run straight to 90, and a save that is not one gets one sentence.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn snowprint(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_snowprint"))
        .args(args)
        .output()
        .expect("run snowprint")
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/roofs16.toml")
        .display()
        .to_string()
}

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snowprint-cli-saves-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn pressed_texels(png: &Path) -> usize {
    let map = snowprint::Heightmap::load_png(png).expect("a dumped heightmap");
    map.depression.iter().filter(|&&d| d > 30_000).count()
}

#[test]
fn a_run_saved_and_continued_equals_a_run_straight_through() {
    let dir = scratch();
    let d = |name: &str| dir.join(name).display().to_string();
    let scene = scene();
    ok(&snowprint(&[
        "simulate",
        "--scene",
        &scene,
        "--frames",
        "90",
        "--dump",
        &d("straight"),
    ]));
    let first = snowprint(&[
        "simulate",
        "--scene",
        &scene,
        "--frames",
        "50",
        "--dump",
        &d("first"),
        "--save",
        &d("at50.save"),
    ]);
    ok(&first);
    ok(&snowprint(&[
        "simulate",
        "--scene",
        &scene,
        "--frames",
        "40",
        "--load",
        &d("at50.save"),
        "--dump",
        &d("cont"),
    ]));
    for i in 0..16 {
        let name = format!("roof{i}.png");
        let (a, b) = (
            dir.join("straight").join(&name),
            dir.join("cont").join(&name),
        );
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{name}"
        );
        // Every roof holds its trail, at 50 frames (queued imprints landed before the dump) as at 90.
        assert!(pressed_texels(&a) > 500, "{name} at 90");
        assert!(
            pressed_texels(&dir.join("first").join(&name)) > 300,
            "{name} at 50"
        );
    }
    let inspect = snowprint(&["inspect", &d("at50.save")]);
    ok(&inspect);
    let text = String::from_utf8_lossy(&inspect.stdout);
    assert!(
        text.contains("clock: 50 frames") && text.contains("roof15"),
        "{text}"
    );
    assert!(text.contains("2 updates a frame"), "{text}");
    // Not a save, a damaged one, a missing one: one sentence each, exit 1.
    let mut damaged = std::fs::read(dir.join("at50.save")).unwrap();
    let n = damaged.len();
    damaged[n / 2] ^= 0x10;
    std::fs::write(dir.join("damaged.save"), damaged).unwrap();
    for (file, says) in [
        (
            dir.join("straight").join("roof0.png"),
            "not a snowprint save",
        ),
        (dir.join("damaged.save"), "damaged"),
        (dir.join("missing.save"), "cannot be read"),
    ] {
        let f = file.display().to_string();
        for args in [
            vec!["inspect", f.as_str()],
            vec![
                "simulate",
                "--scene",
                &scene,
                "--frames",
                "1",
                "--load",
                &f,
                "--dump",
                &d("bad"),
            ],
        ] {
            let out = snowprint(&args);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.contains(says) && err.trim().lines().count() == 1,
                "{args:?}: {err}"
            );
        }
    }
    // A save loaded with another scene is refused before the first frame.
    let other = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/walker.toml");
    let out = snowprint(&[
        "simulate",
        "--scene",
        &other.display().to_string(),
        "--frames",
        "1",
        "--load",
        &d("at50.save"),
        "--dump",
        &d("bad"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("the scene it was saved from"),
        "{err}"
    );
    // --save into a folder is refused before the first frame.
    let out = snowprint(&[
        "simulate",
        "--scene",
        &scene,
        "--frames",
        "1",
        "--dump",
        &d("x"),
        "--save",
        &d("straight"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("is a folder"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
