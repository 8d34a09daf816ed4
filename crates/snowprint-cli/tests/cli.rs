//! The `snowprint` command end to end: a walker leaves footprints you can count, and bad input
//! gives one sentence, a non-zero exit and no output that looks complete.

use std::path::{Path, PathBuf};
use std::process::Command;

fn snowprint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_snowprint"))
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snowprint-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Connected groups (4-neighbour) of texels pressed more than half way, with their texel counts.
fn prints(map: &snowprint::Heightmap) -> Vec<usize> {
    let (w, h) = (map.width as usize, map.height as usize);
    let pressed = |i: usize| map.depression[i] > 32768;
    let mut seen = vec![false; w * h];
    let mut sizes = Vec::new();
    for start in 0..w * h {
        if seen[start] || !pressed(start) {
            continue;
        }
        let mut stack = vec![start];
        seen[start] = true;
        let mut size = 0;
        while let Some(i) = stack.pop() {
            size += 1;
            let (x, y) = (i % w, i / w);
            let mut visit = |j: usize| {
                if !seen[j] && pressed(j) {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w);
            }
            if y + 1 < h {
                visit(i + w);
            }
        }
        sizes.push(size);
    }
    sizes
}

#[test]
fn walker_leaves_one_print_per_step() {
    let out = scratch("walker");
    let status = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/walker.toml"))
        .args(["--frames", "280", "--dump"])
        .arg(&out)
        .status()
        .expect("run snowprint");
    assert!(status.success());
    let map = snowprint::Heightmap::load_png(&out.join("roof.png")).expect("roof.png");
    assert_eq!((map.width, map.height), (200, 150));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("roof.json")).unwrap()).unwrap();
    assert_eq!(meta["resolution"], serde_json::json!([200, 150]));
    // The scene plants each foot 8 times (left at x = -3.0 .. 2.6, right at -2.6 .. 3.0, 0.8 m
    // strides): 16 separate prints.
    let sizes = prints(&map);
    assert_eq!(sizes.len(), 16, "print sizes {sizes:?}");
    // A capsule foot of radius 5 cm and 28 cm long, pressed to 5 cm above the ground in 30 cm of
    // snow, covers roughly 0.28 m x 0.08 m = 14 texels of 4 cm: each print is of that order.
    assert!(
        sizes.iter().all(|&s| (6..=40).contains(&s)),
        "print sizes {sizes:?}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_scene_is_one_sentence_and_leaves_no_output() {
    let dir = scratch("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("roof.toml");
    std::fs::write(
        &scene,
        "version = 1\n\n[[surface]]\nname = \"roof\"\ncenter = [0, 10, 0]\nsize = [-1, 6]\nsnow_depth = 0.3\n",
    )
    .unwrap();
    let dump = dir.join("dump");
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(&scene)
        .args(["--frames", "3", "--dump"])
        .arg(&dump)
        .output()
        .expect("run snowprint");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let line = err
        .lines()
        .find(|l| l.starts_with("snowprint:"))
        .expect("a message");
    assert!(
        line.contains("roof.toml:6") && line.contains("[-1, 6]"),
        "{err}"
    );
    assert!(!dump.exists() || std::fs::read_dir(&dump).unwrap().next().is_none());
    // A bad time step too.
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/walker.toml"))
        .args(["--frames", "3", "--dt=-1", "--dump"])
        .arg(&dump)
        .output()
        .expect("run snowprint");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--dt") && err.contains("-1 is not above 0"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn managed_run_reports_every_frame_within_the_budget() {
    let out = scratch("managed");
    let report = out.join("report.json");
    let status = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/rooftops.toml"))
        .args(["--frames", "120", "--dump"])
        .arg(&out)
        .arg("--report")
        .arg(&report)
        .status()
        .expect("run snowprint");
    assert!(status.success());
    let frames: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(frames.len(), 120);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(f["frame"], i as u64);
        for key in [
            "updated",
            "active",
            "resident",
            "evicted",
            "pool_bytes_used",
            "pool_bytes_budget",
            "max_wait_frames",
        ] {
            assert!(f.get(key).is_some(), "frame {i} has no {key}");
        }
        // The scene's [budget]: 2 updates a frame, 2 MiB.
        assert!(f["updated"].as_array().unwrap().len() <= 2);
        assert!(f["pool_bytes_used"].as_u64().unwrap() <= 2 * 1024 * 1024);
        assert_eq!(f["pool_bytes_budget"], 2 * 1024 * 1024);
    }
    let svg = std::fs::read_to_string(out.join("report.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.contains("<svg"));
    // The player's roof and the street were pressed; the balcony over the street was not.
    let pressed = |name: &str| {
        let map = snowprint::Heightmap::load_png(&out.join(format!("{name}.png"))).unwrap();
        map.depression.iter().filter(|&&v| v > 32768).count()
    };
    assert!(pressed("roof_a") > 50 && pressed("street") > 50);
    assert_eq!(pressed("balcony"), 0);
    let _ = std::fs::remove_dir_all(&out);
}
