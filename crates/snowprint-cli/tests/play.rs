//! `snowprint play` in a real window: an X server without a screen (Xvfb, installed by
//! `scripts/ensure-xvfb.sh`, which `make test` runs), the command on whatever Vulkan driver the
//! machine has (lavapipe in CI), scripted keys walking the person, and the screenshot checked in
//! pixels: the strip of snow along the walked path differs from untouched snow beside it, by the
//! bounds of `tests/play_trail.json`. Bad flags get one sentence and a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3, Vec4};

fn snowprint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_snowprint"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snowprint-play-{name}-{}", std::process::id()));
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

/// Start Xvfb on the first free display from 90 (offset by the process id, so that test runs side
/// by side do not meet); `None` when Xvfb is not installed.
fn xvfb() -> Option<Xvfb> {
    if !on_path("Xvfb") {
        return None;
    }
    let base = 90 + std::process::id() % 50;
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

/// The bounds of `play_trail.json`.
struct Bounds {
    deviation: f32,
    trail_min: f32,
    control_max: f32,
    samples_min: usize,
}

fn bounds() -> Bounds {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/play_trail.json");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let f = |k: &str| {
        v[k].as_f64()
            .unwrap_or_else(|| panic!("{k} in play_trail.json")) as f32
    };
    Bounds {
        deviation: f("deviation"),
        trail_min: f("trail_min"),
        control_max: f("control_max"),
        samples_min: f("samples_min") as usize,
    }
}

/// The screenshot seen through the report's camera.
struct Shot {
    image: image::RgbaImage,
    clip: glam::Mat4,
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

    /// Mark a strip (for the picture a failure leaves behind).
    fn mark(&self, image: &mut image::RgbaImage, at: Vec2, across: Vec2, rgb: [u8; 3]) {
        for i in 0..=20 {
            let p = at + across * (i as f32 / 20.0 - 0.5) * 0.5;
            if let Some((x, y)) = self.project(Vec3::new(p.x, self.top, p.y)) {
                image.put_pixel(x, y, image::Rgba([rgb[0], rgb[1], rgb[2], 255]));
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

#[test]
fn a_scripted_walk_leaves_a_trail_in_the_window() {
    let Some(x) = xvfb() else {
        eprintln!(
            "skipped: Xvfb is not installed, so no window can open here; scripts/ensure-xvfb.sh (run by make test) installs it"
        );
        return;
    };
    let out = scratch("walk");
    let (shot, report) = (out.join("shot.png"), out.join("report.json"));
    let start = Instant::now();
    let run = snowprint()
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .args(["play", "--size", "480x270", "--no-snowfall", "--dt", "0.05"])
        .args(["--script", "w:2.6s,left:0.8s", "--seconds", "3.4"])
        .arg("--screenshot")
        .arg(&shot)
        .arg("--report")
        .arg(&report)
        .output()
        .expect("run snowprint play");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "snowprint play failed: {stderr}");
    eprintln!(
        "snowprint play ran {:.1} s: {stderr}",
        start.elapsed().as_secs_f32()
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let v3 = |v: &serde_json::Value| {
        Vec3::new(
            v[0].as_f64().unwrap() as f32,
            v[1].as_f64().unwrap() as f32,
            v[2].as_f64().unwrap() as f32,
        )
    };
    let camera = snowprint::Camera {
        eye: v3(&r["camera"]["eye"]),
        target: v3(&r["camera"]["target"]),
        fov_y_degrees: r["camera"]["fov_y_degrees"].as_f64().unwrap() as f32,
    };
    let image = image::open(&shot).expect("the screenshot").to_rgba8();
    assert_eq!(image.dimensions(), (480, 270));
    let clip = camera.projection(480.0 / 270.0, 0.1, 500.0) * camera.view();
    let shot = Shot {
        image,
        clip,
        top: r["snow_top"].as_f64().unwrap() as f32,
    };
    let path: Vec<Vec2> = r["path"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| Vec2::new(p[0].as_f64().unwrap() as f32, p[1].as_f64().unwrap() as f32))
        .collect();
    let (first, last) = (path[0], *path.last().unwrap());
    assert!(
        first.distance(last) > 1.5,
        "the person walked {} m",
        first.distance(last)
    );
    // Samples every 0.15 m of the path, from 0.3 m after the start to 0.6 m before the person.
    let (mut trail, mut control) = (Vec::new(), Vec::new());
    let mut marked = shot.image.clone();
    let mut samples = 0;
    let mut travelled = 0.0;
    let mut next = 0.3;
    for w in path.windows(2) {
        let step = w[1] - w[0];
        travelled += step.length();
        if travelled < next || w[1].distance(last) < 0.6 || step.length() < 1e-4 {
            continue;
        }
        next += 0.05;
        let along = step.normalize();
        let across = Vec2::new(-along.y, along.x);
        // The control on whichever side of the path is on screen.
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
    let b = bounds();
    let (t, t90) = above(&trail, b.deviation);
    let (c, c90) = above(&control, b.deviation);
    eprintln!(
        "{samples} strips: {:.1} % of the trail's pixels and {:.1} % of untouched snow's deviate by more than {} (90th percentiles {t90:.3} and {c90:.3})",
        100.0 * t,
        100.0 * c,
        b.deviation
    );
    // The strips measured, drawn on the screenshot: the trail's red, its references green.
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
    let _ = std::fs::remove_dir_all(&out);
}

/// The first line of standard error (clap adds a line on `--help` after its own), the exit code
/// non-zero.
fn refused(args: &[&str], display: Option<&str>) -> String {
    let mut cmd = snowprint();
    cmd.arg("play").args(args).env_remove("WAYLAND_DISPLAY");
    match display {
        Some(d) => cmd.env("DISPLAY", d),
        None => cmd.env_remove("DISPLAY"),
    };
    let out = cmd.output().expect("run snowprint play");
    assert!(!out.status.success(), "{args:?} was accepted");
    let err = String::from_utf8_lossy(&out.stderr).trim().to_owned();
    err.lines().next().unwrap_or_default().to_owned()
}

#[test]
fn bad_flags_get_one_sentence_before_any_window() {
    let dir = scratch("bad");
    let missing = dir.join("no/such/shot.png");
    let e = refused(&["--screenshot", missing.to_str().unwrap()], None);
    assert!(e.contains("does not exist"), "{e}");
    let e = refused(&["--script", "w:2s,jump"], None);
    assert!(e.contains("unknown key \"jump\""), "{e}");
    let e = refused(&["--seconds", "-1"], None);
    assert!(e.contains("not above 0"), "{e}");
    let e = refused(&["--frames", "0"], None);
    assert!(e.contains("at least 1"), "{e}");
    let e = refused(&["--supersample", "9"], None);
    assert!(e.contains("1 to 4"), "{e}");
    let e = refused(&["--gif", "walk.mp4"], None);
    assert!(e.contains(".gif"), "{e}");
    // Good flags without a display: the one sentence says what is missing.
    let e = refused(&["--frames", "1"], None);
    assert!(e.contains("DISPLAY"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
