//! The `walk` example in a real window: an X server without a screen (Xvfb, installed by
//! `scripts/ensure-xvfb.sh`, which `make test` runs), Bevy on whatever Vulkan driver the machine
//! has (lavapipe in CI), scripted keys walking the person, and the screenshot checked in pixels:
//! the strip of snow along the walked path differs from untouched snow beside it, by the bounds
//! of `tests/walk_trail.json`; the probes under the planted boots answer the prints' depth. Bad
//! flags get one sentence and exit code 2.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use bevy::math::{Mat4, Vec2, Vec3, Vec4};

/// The example, which `cargo test` builds with the tests (examples are built for `test`).
fn walk() -> Command {
    Command::new(example_path())
}

/// `target/<profile>/examples/walk` next to this test's own binary (`target/<profile>/deps/`).
fn example_path() -> PathBuf {
    let me = std::env::current_exe().expect("the test's path");
    let profile = me
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>");
    profile.join("examples").join("walk")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bevy-snowprint-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An Xvfb server on a free display, stopped when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
}

/// Start Xvfb on the first free display from 140 (offset by the process id, so that test runs
/// side by side, and snowprint-cli's window test from 90, do not meet); `None` when Xvfb is not
/// installed.
fn xvfb() -> Option<Xvfb> {
    if !on_path("Xvfb") {
        return None;
    }
    let base = 140 + std::process::id() % 50;
    for n in base..base + 40 {
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{n}"));
        if socket.exists() || Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            continue;
        }
        let mut child = Command::new("Xvfb")
            .arg(format!(":{n}"))
            .args(["-screen", "0", "1024x768x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start Xvfb");
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(15) {
            if socket.exists() {
                return Some(Xvfb {
                    child,
                    display: format!(":{n}"),
                });
            }
            if let Ok(Some(_)) = child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = child.kill();
        let _ = child.wait();
    }
    panic!(
        "Xvfb is installed but no display from :{base} to :{} started",
        base + 39
    );
}

/// The bounds of `walk_trail.json`.
struct Bounds {
    deviation: f32,
    trail_min: f32,
    control_max: f32,
    samples_min: usize,
    probe_depression_min: f32,
}

fn bounds() -> Bounds {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/walk_trail.json");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let f = |k: &str| {
        v[k].as_f64()
            .unwrap_or_else(|| panic!("{k} in walk_trail.json")) as f32
    };
    Bounds {
        deviation: f("deviation"),
        trail_min: f("trail_min"),
        control_max: f("control_max"),
        samples_min: f("samples_min") as usize,
        probe_depression_min: f("probe_depression_min"),
    }
}

/// The screenshot seen through the report's camera.
struct Shot {
    image: image::RgbImage,
    clip: Mat4,
    top: f32,
}

impl Shot {
    /// The pixel a world point falls on.
    fn project(&self, p: Vec3) -> Option<(u32, u32)> {
        let c = self.clip * Vec4::from((p, 1.0));
        if c.w <= 0.0 {
            return None;
        }
        let ndc = c.truncate() / c.w;
        let (w, h) = self.image.dimensions();
        let x = (ndc.x * 0.5 + 0.5) * w as f32;
        let y = (0.5 - ndc.y * 0.5) * h as f32;
        if x < 0.0 || y < 0.0 || x >= w as f32 || y >= h as f32 {
            return None;
        }
        Some((x as u32, y as u32))
    }

    /// Mark a strip (for the picture a run leaves behind).
    fn mark(&self, image: &mut image::RgbImage, at: Vec2, across: Vec2, rgb: [u8; 3]) {
        for i in 0..=20 {
            let p = at + across * (i as f32 / 20.0 - 0.5) * 0.5;
            if let Some((x, y)) = self.project(Vec3::new(p.x, self.top, p.y)) {
                image.put_pixel(x, y, image::Rgb(rgb));
            }
        }
    }

    fn pixel(&self, p: Vec3) -> Option<f32> {
        let (x, y) = self.project(p)?;
        let px = self.image.get_pixel(x, y);
        Some((0.2126 * px[0] as f32 + 0.7152 * px[1] as f32 + 0.0722 * px[2] as f32) / 255.0)
    }

    /// Luminance along a strip 0.5 m across the path at `at` (x, z), `across` its unit normal.
    fn strip(&self, at: Vec2, across: Vec2) -> Option<Vec<f32>> {
        (0..=20)
            .map(|i| {
                let p = at + across * (i as f32 / 20.0 - 0.5) * 0.5;
                self.pixel(Vec3::new(p.x, self.top, p.y))
            })
            .collect()
    }

    /// How far each pixel of the strip at `at + across * offset` is from the mean of the strips
    /// 1 m either side of it.
    fn deviations(&self, at: Vec2, across: Vec2, offset: f32) -> Option<Vec<f32>> {
        let strip = self.strip(at + across * offset, across)?;
        let mut side = self.strip(at + across * (offset - 1.0), across)?;
        side.extend(self.strip(at + across * (offset + 1.0), across)?);
        let mean = side.iter().sum::<f32>() / side.len() as f32;
        Some(strip.iter().map(|l| (l - mean).abs()).collect())
    }
}

/// The fraction of `v` above `threshold`, and `v`'s 90th percentile.
fn above(v: &[f32], threshold: f32) -> (f32, f32) {
    let mut sorted = v.to_vec();
    sorted.sort_by(f32::total_cmp);
    let p90 = sorted
        .get(sorted.len() * 9 / 10)
        .copied()
        .unwrap_or(f32::NAN);
    let n = v.iter().filter(|&&d| d > threshold).count();
    (n as f32 / v.len().max(1) as f32, p90)
}

fn v2(v: &serde_json::Value) -> Vec2 {
    Vec2::new(v[0].as_f64().unwrap() as f32, v[1].as_f64().unwrap() as f32)
}

#[test]
fn a_scripted_walk_leaves_a_trail_in_the_bevy_window() {
    let Some(x) = xvfb() else {
        eprintln!(
            "skipped: Xvfb is not installed, so no window can open here; scripts/ensure-xvfb.sh (run by make test) installs it"
        );
        return;
    };
    let out = std::env::var_os("BEVY_SNOWPRINT_KEEP")
        .map(PathBuf::from)
        .unwrap_or_else(|| scratch("walk"));
    std::fs::create_dir_all(&out).unwrap();
    let (shot, report) = (out.join("shot.png"), out.join("report.json"));
    let start = Instant::now();
    let run = walk()
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("RUST_LOG", "warn")
        .args(["--size", "480x270", "--dt", "0.05"])
        .args(["--script", "w:2.4s,wa:0.6s,w:0.6s"])
        .arg("--screenshot")
        .arg(&shot)
        .arg("--report")
        .arg(&report)
        .output()
        .expect("run the walk example");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "the walk example failed: {stderr}");
    eprintln!(
        "the walk example ran {:.1} s",
        start.elapsed().as_secs_f32()
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let clip: Vec<f32> = r["clip_from_world"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap() as f32)
        .collect();
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    assert_eq!(image.dimensions(), (480, 270));
    let shot = Shot {
        image,
        clip: Mat4::from_cols_slice(&clip),
        top: r["snow_top"].as_f64().unwrap() as f32,
    };
    let path: Vec<Vec2> = r["path"].as_array().unwrap().iter().map(v2).collect();
    let (first, last) = (path[0], *path.last().unwrap());
    assert!(
        first.distance(last) > 2.5,
        "the person walked {} m",
        first.distance(last)
    );

    // Gameplay's probes: under each planted boot, a print as deep as the boot pressed.
    let b = bounds();
    let sole = r["sole"].as_f64().unwrap() as f32;
    let probes = r["probes"].as_array().unwrap();
    assert_eq!(probes.len(), 2, "both boots' probes answered: {probes:?}");
    for p in probes {
        let depression = p["depression_m"].as_f64().unwrap() as f32;
        let left = p["snow_depth_m"].as_f64().unwrap() as f32;
        eprintln!("probe under a planted boot: {depression:.3} m pressed, {left:.3} m left");
        assert!(p["on_snow"].as_bool().unwrap(), "{p}");
        assert!(
            depression >= b.probe_depression_min,
            "the probe under a planted boot reads {depression} m pressed"
        );
        assert!(
            (left + depression - shot.top).abs() < 0.01,
            "the snow left {left} and the depression {depression} do not add up to the snow's depth {}",
            shot.top
        );
        assert!(
            left >= sole - 0.02,
            "{left} m left under a sole {sole} m above the ground"
        );
    }

    // Footsteps: every print the boots left was heard landing once, below the fresh top (how far
    // depends on where in the frame the falling boot crossed it) and no deeper than the snow.
    let prints = r["prints"].as_array().unwrap().len();
    let footsteps: Vec<f64> = r["footsteps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_f64().unwrap())
        .collect();
    eprintln!(
        "{} footsteps heard for {prints} prints, depths {footsteps:.3?}",
        footsteps.len()
    );
    assert!(
        footsteps.len() + 1 >= prints && footsteps.len() <= prints + 2,
        "{} footsteps heard for {prints} prints",
        footsteps.len()
    );
    assert!(
        footsteps
            .iter()
            .all(|&d| d > 0.0 && d <= f64::from(shot.top) + 1e-4),
        "a footstep above the snow or deeper than it: {footsteps:?}"
    );

    // Samples every 5 cm of the path, from 0.3 m after the start to 0.9 m before the person.
    let (mut trail, mut control) = (Vec::new(), Vec::new());
    let mut marked = shot.image.clone();
    let mut samples = 0;
    let mut travelled = 0.0;
    let mut next = 0.3;
    for w in path.windows(2) {
        let step = w[1] - w[0];
        travelled += step.length();
        if travelled < next || w[1].distance(last) < 0.9 || step.length() < 1e-4 {
            continue;
        }
        next += 0.05;
        let along = step.normalize();
        let across = Vec2::new(-along.y, along.x);
        let control_strip = shot
            .deviations(w[1], across, -2.0)
            .or_else(|| shot.deviations(w[1], across, 2.0));
        if let (Some(t), Some(c)) = (shot.deviations(w[1], across, 0.0), control_strip) {
            samples += 1;
            trail.extend(t);
            control.extend(c);
            shot.mark(&mut marked, w[1], across, [255, 0, 0]);
            for side in [-1.0, 1.0] {
                shot.mark(&mut marked, w[1] + across * side, across, [0, 200, 0]);
            }
        }
    }
    let (t, t90) = above(&trail, b.deviation);
    let (c, c90) = above(&control, b.deviation);
    eprintln!(
        "{samples} strips: {:.1} % of the trail's pixels and {:.1} % of untouched snow's deviate by more than {} (90th percentiles {t90:.3} and {c90:.3})",
        100.0 * t,
        100.0 * c,
        b.deviation
    );
    marked.save(out.join("strips.png")).unwrap();
    assert!(
        samples >= b.samples_min,
        "only {samples} strips of the path are on screen"
    );
    assert!(
        t >= b.trail_min,
        "only {:.1} % of the trail's pixels deviate",
        100.0 * t
    );
    assert!(
        c <= b.control_max,
        "{:.1} % of untouched snow deviates",
        100.0 * c
    );
    if std::env::var_os("BEVY_SNOWPRINT_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The first line of standard error, the exit code 2, no window opened (no display given).
fn refused(args: &[&str]) -> String {
    let out = walk()
        .args(args)
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("DISPLAY")
        .output()
        .expect("run the walk example");
    assert_eq!(out.status.code(), Some(2), "{args:?}: {out:?}");
    let err = String::from_utf8_lossy(&out.stderr).trim().to_owned();
    err.lines().next().unwrap_or_default().to_owned()
}

#[test]
fn bad_flags_get_one_sentence_before_any_window() {
    let e = refused(&["--script", "w:2s,jump"]);
    assert!(e.contains("`jump` is not KEYS:SECONDS"), "{e}");
    let e = refused(&["--script", "q:1s"]);
    assert!(e.contains("`q` is not one of the keys"), "{e}");
    let e = refused(&["--size", "12"]);
    assert!(e.contains("--size 12 is not WIDTHxHEIGHT"), "{e}");
    let e = refused(&[
        "--script",
        "w:1s",
        "--screenshot",
        "/no/such/folder/shot.png",
    ]);
    assert!(e.contains("does not exist"), "{e}");
    let e = refused(&["--screenshot", "shot.png"]);
    assert!(e.contains("need a --script"), "{e}");
    let e = refused(&["--script", "w:1s", "--every", "0"]);
    assert!(e.contains("--every 0 is not a number of frames"), "{e}");
    let e = refused(&["--dt", "-1"]);
    assert!(e.contains("--dt -1 is not a time step"), "{e}");
}
