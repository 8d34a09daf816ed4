//! The `snowprint` command end to end: a walker leaves footprints you can count, and bad input
//! gives one sentence, a non-zero exit and no output that looks complete.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The tests of this file one at a time: the SIGINT test must see a dump being written, a window
/// of milliseconds that a 2-core machine busy with the other tests' software-Vulkan runs can hide.
fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

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
    let _serial = serial();
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

/// `scenes/valley_window.toml`: a ball ploughs 12 m out of the terrain's near window and back; the
/// near level's dump holds both trenches (the outbound one paged out and back in), the far level's
/// the loop; under the surface manager the levels come out the same, and a run saved halfway and
/// continued from the save comes out as the run straight through.
#[test]
fn a_terrain_window_follows_the_ball_and_dumps_its_levels() {
    let _serial = serial();
    let out = scratch("valley");
    let status = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/valley_window.toml"))
        .args(["--frames", "540", "--dump"])
        .arg(&out)
        .status()
        .expect("run snowprint");
    assert!(status.success());
    let near = snowprint::Heightmap::load_png(&out.join("valley.0.png")).expect("valley.0.png");
    let far = snowprint::Heightmap::load_png(&out.join("valley.1.png")).expect("valley.1.png");
    assert_eq!((near.width, far.width), (128, 128));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("valley.0.json")).unwrap()).unwrap();
    // Back at x = 0, z = 2: the near window's first texel is (-64, -24) of 5 cm.
    assert_eq!(meta["origin_texel"], serde_json::json!([-64, -24]));
    assert!(meta["scroll"]["texels_paged_in"].as_u64().unwrap() > 0);
    // Column 100 (x = 1.8 m): the outbound trench at z = 0 (row 24) and the return at z = 2 (row
    // 64), untouched between them.
    let at = |x: u32, y: u32| near.depression[(y * 128 + x) as usize];
    assert!(
        at(100, 24) > 32768 && at(100, 64) > 32768,
        "{} {}",
        at(100, 24),
        at(100, 64)
    );
    assert_eq!(at(100, 44), 0);
    // The far level (40 cm, first texel (-64, -59)) holds the outbound trench at x = 6 m, which
    // the near window paged out long ago: column 79, row 59 (z = 0 .. 0.4).
    let far_meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("valley.1.json")).unwrap()).unwrap();
    let o = &far_meta["origin_texel"];
    let (fx, fz) = (
        (15 - o[0].as_i64().unwrap()) as u32,
        (-o[1].as_i64().unwrap()) as u32,
    );
    let v = far.depression[(fz.saturating_sub(1) * 128 + fx) as usize]
        .max(far.depression[(fz * 128 + fx) as usize]);
    assert!(v > 16384, "far level at x = 6 m: {v}");

    // Under the surface manager (--report), in its pool and budget: the same levels, byte for
    // byte, and its report; a save, which does not hold windows yet, is refused in one sentence.
    let managed = scratch("valley-managed");
    let result = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/valley_window.toml"))
        .args(["--frames", "540", "--report"])
        .arg(managed.join("report/r.json"))
        .args(["--dump"])
        .arg(&managed)
        .output()
        .expect("run snowprint");
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    for level in ["valley.0.png", "valley.1.png"] {
        let (a, b) = (
            std::fs::read(out.join(level)).unwrap(),
            std::fs::read(managed.join(level)).unwrap(),
        );
        assert!(
            a == b,
            "{level}: the managed run's level differs from the plain run's"
        );
    }
    let report = std::fs::read_to_string(managed.join("report/r.json")).expect("the report");
    assert!(
        report.contains("valley.0"),
        "the report names the levels it updated"
    );
    let _ = std::fs::remove_dir_all(&out);
    // A save holds the window: saved after 270 frames (the ball at the loop's far end, the
    // outbound trench paged out of the near window) and continued from it for 270 more, the
    // levels and their descriptions (the window's place, the scroll statistics) are the
    // straight run's, byte for byte: the trench came back from the saved store.
    let save = managed.join("s.snow");
    for (frames, flag, dump) in [("270", "--save", "first"), ("270", "--load", "cont")] {
        let result = snowprint()
            .args(["simulate", "--scene"])
            .arg(repo().join("scenes/valley_window.toml"))
            .args(["--frames", frames, flag])
            .arg(&save)
            .args(["--dump"])
            .arg(managed.join(dump))
            .output()
            .expect("run snowprint");
        assert!(
            result.status.success(),
            "{flag}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
    for level in [
        "valley.0.png",
        "valley.1.png",
        "valley.0.json",
        "valley.1.json",
    ] {
        let (a, b) = (
            std::fs::read(managed.join(level)).unwrap(),
            std::fs::read(managed.join("cont").join(level)).unwrap(),
        );
        assert!(
            a == b,
            "{level}: the run saved at 270 and continued differs from the run straight to 540"
        );
    }
    let inspect = snowprint().arg("inspect").arg(&save).output().unwrap();
    let text = String::from_utf8_lossy(&inspect.stdout);
    assert!(
        text.contains("TERR") && text.contains("valley ") && text.contains("chunks paged out"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&managed);
}

#[test]
fn bad_scene_is_one_sentence_and_leaves_no_output() {
    let _serial = serial();
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
    let _serial = serial();
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

/// A scene of `n` small surfaces in a row under a budget, with a ball rolling over the first.
fn many_surfaces(n: usize) -> String {
    let mut s =
        String::from("version = 1\n\n[budget]\nupdates_per_frame = 4\npool_bytes = 67108864\n");
    for i in 0..n {
        s += &format!(
            "\n[[surface]]\nname = \"s{i:04}\"\ncenter = [{}.0, 0.0, 0.0]\nsize = [0.8, 0.8]\nsnow_depth = 0.3\n",
            i
        );
    }
    s += "\n[[deformer]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 0.1\nplayer = true\n\
          keys = [{ t = 0.0, position = [-0.3, 0.1, 0.0] }, { t = 1.0, position = [0.3, 0.1, 0.0] }]\n";
    s
}

/// The `frames` every JSON of a dump says, and whether any file was missing or unreadable.
fn dump_frames(dump: &Path, n: usize) -> Vec<u64> {
    (0..n)
        .map(|i| {
            let text = std::fs::read_to_string(dump.join(format!("s{i:04}.json")))
                .unwrap_or_else(|e| panic!("s{i:04}.json: {e}"));
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert!(dump.join(format!("s{i:04}.png")).is_file());
            v["frames"].as_u64().unwrap()
        })
        .collect()
}

fn partial_folders(dump: &Path) -> Vec<String> {
    std::fs::read_dir(dump)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial"))
        .collect()
}

/// Item 6: SIGINT while a dump is being written leaves the old set whole (or the new one), and
/// the next run removes what the interrupted run left.
#[test]
fn sigint_during_a_dump_leaves_the_old_set_or_the_new_one() {
    let _serial = serial();
    use std::os::unix::process::ExitStatusExt as _;
    const N: usize = 400;
    let dir = scratch("sigint");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("many.toml");
    std::fs::write(&scene, many_surfaces(N)).unwrap();
    let dump = dir.join("dump");
    let run = |frames: &str| {
        snowprint()
            .args(["simulate", "--scene"])
            .arg(&scene)
            .args(["--frames", frames, "--dump"])
            .arg(&dump)
            .env_remove("XDG_RUNTIME_DIR")
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("run snowprint")
    };
    assert!(run("1").wait().unwrap().success());
    assert!(dump_frames(&dump, N).iter().all(|&f| f == 1));
    // Interrupt the second run once its staging folder exists: its set is staged (the folder is
    // made before the first frame and published by one rename after the last file). Waiting for
    // files in it caught the writing itself only when the test ran alone: in a full clean-clone
    // run every dump finished unseen. With two frames the run also outran the signal in a clean
    // clone (twenty times in a row): forty frames keep it staging long after the folder appears.
    // Forty frames still outran the poll twenty times in a row in one clean clone (the run takes
    // under a second alone): four hundred keep it staging ten times as long, and it is killed as
    // soon as the folder appears, so the test takes no longer.
    let mut interrupted = false;
    for _attempt in 0..20 {
        let mut child = run("400");
        let staging = dump.join(format!(".snowprint-dump-partial-{}", child.id()));
        let start = std::time::Instant::now();
        let mut writing = false;
        while start.elapsed() < std::time::Duration::from_secs(60) {
            if staging.is_dir() {
                writing = true;
                break;
            }
            if child.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::yield_now();
        }
        if writing {
            let _ = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status();
        }
        let status = child.wait().unwrap();
        let frames = dump_frames(&dump, N);
        assert!(
            frames.iter().all(|&f| f == frames[0]),
            "a mix of sets after SIGINT: {frames:?}"
        );
        if status.signal() == Some(2) {
            interrupted = true;
            // The old set, with the dead run's staging beside it (or, had the signal come after
            // the swap, the new set).
            match frames[0] {
                1 => assert_eq!(
                    partial_folders(&dump).len(),
                    1,
                    "the interrupted run's staging"
                ),
                400 => {}
                other => panic!("frames {other}"),
            }
            break;
        }
        // It finished before the signal: start again from the first set.
        assert!(run("1").wait().unwrap().success());
    }
    assert!(
        interrupted,
        "twenty runs finished before SIGINT reached them"
    );
    // The next run publishes its set and removes the dead run's staging.
    assert!(run("3").wait().unwrap().success());
    assert!(dump_frames(&dump, N).iter().all(|&f| f == 3));
    assert_eq!(partial_folders(&dump), Vec::<String>::new());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 5: a frame that fails stops the run with the frame and the culprit's line, and the frames
/// done are written, marked partial, report included.
#[test]
fn a_failing_frame_writes_the_frames_done_marked_partial() {
    let _serial = serial();
    let dir = scratch("partial");
    let dump = dir.join("dump");
    let report = dir.join("report/r.json");
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile/runaway_camera.toml"))
        .args(["--frames", "30", "--dump"])
        .arg(&dump)
        .arg("--report")
        .arg(&report)
        .output()
        .expect("run snowprint");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("frame 6 ") && err.contains("runaway_camera.toml:7"),
        "{err}"
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dump.join("yard.json")).unwrap()).unwrap();
    assert_eq!(meta["partial"], true);
    assert_eq!(meta["frames_done"], 5);
    assert_eq!(meta["frames"], 30);
    let frames: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(frames.len(), 5);
    let svg = std::fs::read_to_string(report.with_extension("svg")).unwrap();
    assert!(svg.contains("partial: 5 of 30 frames"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Items 4 and 5: a report in a missing nested folder is created before the run; a [camera]
/// without [budget] is not silently ignored.
#[test]
fn nested_report_folders_are_created_and_an_unused_camera_is_named() {
    let _serial = serial();
    let dir = scratch("nested");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("cam.toml");
    std::fs::write(
        &scene,
        "version = 1\n\n[camera]\ntarget = [0, 0, 0]\nkeys = [{ t = 0, eye = [0, 5, -5] }]\n\n\
         [[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [1, 1]\nsnow_depth = 0.3\n",
    )
    .unwrap();
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(&scene)
        .args(["--frames", "2", "--dump"])
        .arg(dir.join("d"))
        .output()
        .expect("run snowprint");
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cam.toml:3: [camera]") && err.contains("does not use it"),
        "{err}"
    );
    let report = dir.join("a/b/c/report.json");
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(&scene)
        .args(["--frames", "2", "--dump"])
        .arg(dir.join("d"))
        .arg("--report")
        .arg(&report)
        .output()
        .expect("run snowprint");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("does not use it"));
    assert!(report.is_file() && report.with_extension("svg").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An adapter whose backend cannot translate the renderer's shaders (wgpu's GL backend cannot load
/// from a depth texture) gives an error and a non-zero exit, not a panic, and no demo output.
#[test]
fn an_adapter_that_cannot_build_the_renderer_is_an_error() {
    let _serial = serial();
    let dir = scratch("gl");
    let out = snowprint()
        .env("WGPU_BACKEND", "gl")
        .args(["demo", "--frames", "1", "--size", "64x36", "--out"])
        .arg(&dir)
        .output()
        .expect("run snowprint");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.join("report.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 7: a scene file over the limit is refused before it is parsed.
#[test]
fn a_huge_scene_is_refused_before_parsing() {
    let _serial = serial();
    let dir = scratch("huge");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("huge.toml");
    let mut text = String::from(
        "version = 1\n[[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [1, 1]\nsnow_depth = 0.3\n\
         [[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n",
    );
    let mut k = 0;
    while text.len() <= 4 << 20 {
        text += &format!("{{ t = {k}.0, position = [0.0, 0.1, 0.0] }},\n");
        k += 1;
    }
    text += "]\n";
    std::fs::write(&scene, &text).unwrap();
    let start = std::time::Instant::now();
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(&scene)
        .args(["--frames", "1", "--dump"])
        .arg(dir.join("d"))
        .output()
        .expect("run snowprint");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("at most 4194304 bytes"), "{err}");
    assert!(start.elapsed() < std::time::Duration::from_secs(5));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 8: a managed run holds flat memory (nothing kept per frame), with or without a report.
#[test]
fn a_managed_run_holds_flat_memory() {
    let _serial = serial();
    let dir = scratch("memory");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("m.toml");
    std::fs::write(&scene, many_surfaces(4)).unwrap();
    for report in [false, true] {
        let mut cmd = snowprint();
        cmd.args(["simulate", "--scene"])
            .arg(&scene)
            .args(["--frames", "8000", "--dump"])
            .arg(dir.join("d"))
            .env("SNOWPRINT_LOG", "info")
            .env("SNOWPRINT_MEMORY_EVERY", "1000");
        if report {
            cmd.arg("--report").arg(dir.join("r.json"));
        }
        let out = cmd.output().expect("run snowprint");
        assert!(out.status.success());
        let kib: Vec<u64> = String::from_utf8_lossy(&out.stderr)
            .lines()
            .filter_map(|l| l.split("resident memory ").nth(1))
            .map(|r| r.trim_end_matches(" KiB").parse().unwrap())
            .collect();
        assert_eq!(kib.len(), 8, "{kib:?}");
        // From frame 3000 on, the plot's summary (at most 2048 buckets) is full. Keeping each
        // frame's statistics, as the runs before did, grows 0.2 to 0.4 KB a frame: 1 to 2 MB over
        // the 5000 frames after it (measured: 264 KiB in 1500 frames on this scene).
        let growth = kib[7] as i64 - kib[2] as i64;
        assert!(growth < 64, "report {report}: resident KiB {kib:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 10: with stderr not a terminal, progress is a plain line (no bar, no escapes).
#[test]
fn progress_is_a_plain_line_when_stderr_is_not_a_terminal() {
    let _serial = serial();
    let dir = scratch("progress");
    let out = snowprint()
        .args(["simulate", "--scene"])
        .arg(repo().join("scenes/walker.toml"))
        .args(["--frames", "20", "--dump"])
        .arg(&dir)
        .env("SNOWPRINT_PROGRESS_SECONDS", "0")
        .output()
        .expect("run snowprint");
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("snowprint: simulate: "))
        .collect();
    assert_eq!(lines.len(), 19, "{err}");
    assert!(lines[9].contains("10/20 frames (50 %)") && lines[9].contains("frames/s, about"));
    assert!(!err.contains('\r') && !err.contains('\u{1b}'), "{err:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 9: `demo --camera`'s help lists the cameras that exist.
#[test]
fn demo_help_lists_the_real_cameras() {
    let _serial = serial();
    let out = snowprint()
        .args(["demo", "--help"])
        .output()
        .expect("run snowprint");
    let help = String::from_utf8_lossy(&out.stdout);
    let camera = help
        .split("--camera <CAMERA>")
        .nth(1)
        .and_then(|s| s.split("--tier").next())
        .expect("a --camera entry");
    let camera = camera.split_whitespace().collect::<Vec<_>>().join(" ");
    let (rooftops, standin) = camera.split_once("stand-in").expect("both scenes");
    for name in snowprint_demo::DemoWorld::camera_names() {
        assert!(rooftops.contains(name), "{name} missing from {camera}");
    }
    assert!(!rooftops.contains("street"), "{camera}");
    assert!(standin.contains("street"), "{camera}");
}

/// `snowprint demo --scene shore` renders the shore: its four strips of sand, mud and snow are in
/// the report, each printed by the people who crossed it by the frame.
#[test]
fn the_shore_demo_renders_its_four_strips() {
    let _serial = serial();
    let dir = scratch("shore");
    let out = snowprint()
        .args([
            "demo", "--scene", "shore", "--camera", "overview", "--frames", "1",
        ])
        .args([
            "--size", "96x54", "--sim-hz", "10", "--from", "7", "--to", "7",
        ])
        .args(["--no-snowfall", "--out"])
        .arg(&dir)
        .output()
        .expect("run snowprint");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    assert!(
        report["scene"].as_str().unwrap_or("").starts_with("shore"),
        "{}",
        report["scene"]
    );
    let surfaces = report["surfaces"].as_array().expect("surfaces");
    let names: Vec<&str> = surfaces.iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, ["wet_sand", "dry_sand", "mud_track", "snow_bank"]);
    for s in surfaces {
        assert!(
            s["deepest_print_last_frame"].as_f64().unwrap_or(0.0) > 0.2,
            "{s}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The pitched roof: `simulate` lays the surface on its glTF roof and the trench runs over the
/// ridge (the library's `tests/terrain.rs` checks its depths by hand); under the manager the same
/// run leaves the same heightmap, and a save taken half way and loaded goes on to it too.
#[test]
fn a_surface_on_a_roof_mesh_runs_alone_and_under_the_manager() {
    let _serial = serial();
    let out = scratch("roof");
    let run = |frames: &str, dump: &Path, extra: &[&std::ffi::OsStr]| {
        let run = snowprint()
            .args(["simulate", "--scene"])
            .arg(repo().join("scenes/pitched_roof.toml"))
            .args(["--frames", frames, "--dump"])
            .arg(dump)
            .args(extra)
            .output()
            .expect("run snowprint");
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        snowprint::Heightmap::load_png(&dump.join("roof.png")).expect("roof.png")
    };
    let map = run("240", &out.join("alone"), &[]);
    // Column 50 (x = -2) is pressed from row 5 (z = -2.8) to row 144 (z = 2.8), over the ridge.
    for row in [10, 40, 75, 110, 140] {
        assert!(
            map.fraction(50, row) > 0.35,
            "row {row}: {}",
            map.fraction(50, row)
        );
    }
    let report = out.join("report.json");
    let save = out.join("half.snowsave");
    let managed = run(
        "240",
        &out.join("managed"),
        &["--report".as_ref(), report.as_os_str()],
    );
    assert_eq!(managed.depression, map.depression, "managed run differs");
    run(
        "120",
        &out.join("half"),
        &["--save".as_ref(), save.as_os_str()],
    );
    let resumed = run(
        "120",
        &out.join("resumed"),
        &["--load".as_ref(), save.as_os_str()],
    );
    assert_eq!(resumed.depression, map.depression, "the loaded run differs");
    let _ = std::fs::remove_dir_all(&out);
}
