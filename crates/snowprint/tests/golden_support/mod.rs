//! The golden check shared by the image tests (`render_golden.rs`, `render_materials.rs`): the
//! goldens in `tests/golden/`, their FLIP tolerances as data (`tolerances.toml`), blessing with
//! `SNOWPRINT_BLESS=1`, and the error map written to `target/golden-diff/` on failure.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use snowprint::render::RenderOutput;

use crate::common;

pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

pub fn diff_dir() -> PathBuf {
    // CARGO_TARGET_TMPDIR is <target>/tmp.
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap_or(Path::new("target"))
        .join("golden-diff")
}

/// The bounds of one test, from `tolerances.toml`: one for any driver, one for the driver the
/// goldens were rendered on.
#[derive(Debug, serde::Deserialize)]
pub struct Bounds {
    /// Largest mean FLIP error over the image, any driver.
    mean: f64,
    /// Largest 99th percentile of the FLIP error, any driver.
    p99: f64,
    /// Largest mean on the goldens' own driver.
    same_driver_mean: f64,
    /// Largest 99th percentile on the goldens' own driver.
    same_driver_p99: f64,
}

#[derive(Debug, serde::Deserialize)]
pub struct Tolerances {
    /// Part of the adapter name the goldens were rendered on (`llvmpipe` for lavapipe).
    golden_adapter: String,
    #[serde(flatten)]
    tests: std::collections::HashMap<String, Bounds>,
}

/// The largest FLIP errors one comparison allows, and which bound they are.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    pub mean: f64,
    pub p99: f64,
    pub same_driver: bool,
}

pub fn tolerances() -> Tolerances {
    let path = golden_dir().join("tolerances.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether this test device is the driver the goldens were rendered on.
pub fn same_driver() -> bool {
    common::gpu()
        .info
        .name
        .contains(&tolerances().golden_adapter)
}

/// The tolerance of one test on this device: the tight same-driver bound where the goldens' driver
/// runs (as in CI), the cross-driver one elsewhere.
pub fn tolerance(name: &str) -> Tolerance {
    let path = golden_dir().join("tolerances.toml");
    let b = tolerances()
        .tests
        .remove(name)
        .unwrap_or_else(|| panic!("{} has no [{name}] table", path.display()));
    assert!(
        b.same_driver_mean <= b.mean && b.same_driver_p99 <= b.p99,
        "[{name}]: a same-driver bound is looser than the cross-driver one"
    );
    if same_driver() {
        Tolerance {
            mean: b.same_driver_mean,
            p99: b.same_driver_p99,
            same_driver: true,
        }
    } else {
        Tolerance {
            mean: b.mean,
            p99: b.p99,
            same_driver: false,
        }
    }
}

/// `SNOWPRINT_BLESS=1` asks for new goldens; refused when `CI` is set (CI compares, never blesses).
pub fn bless() -> bool {
    let asked = std::env::var("SNOWPRINT_BLESS").is_ok_and(|v| v == "1");
    assert!(
        !(asked && std::env::var_os("CI").is_some()),
        "SNOWPRINT_BLESS is refused when CI is set: goldens are blessed by a person who looked at them, never by CI"
    );
    asked
}

pub fn save_png(path: &Path, out: &RenderOutput) {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).expect("create folder");
    }
    image::save_buffer(
        path,
        &out.rgba8,
        out.width,
        out.height,
        image::ColorType::Rgba8,
    )
    .expect("write png");
}

pub fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The golden of `name`.
pub fn golden(name: &str, out: &RenderOutput) -> image::RgbImage {
    let golden = golden_dir().join(format!("{name}.png"));
    let reference = image::open(&golden)
        .unwrap_or_else(|e| {
            panic!(
                "no golden {} ({e}); run SNOWPRINT_BLESS=1 cargo test --release --test render_golden",
                golden.display()
            )
        })
        .to_rgb8();
    assert_eq!(
        reference.dimensions(),
        (out.width, out.height),
        "golden {} has another size",
        golden.display()
    );
    reference
}

/// FLIP error map of a render against the golden of `name`, with its mean and weighted 99th
/// percentile.
pub fn score(name: &str, out: &RenderOutput) -> (nv_flip::FlipImageFloat, f64, f64) {
    let reference = golden(name, out);
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(out.width, out.height, reference.as_raw()),
        nv_flip::FlipImageRgb8::with_data(out.width, out.height, &rgb(&out.rgba8)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let pool = nv_flip::FlipPool::from_image(&error);
    let (mean, p99) = (pool.mean() as f64, pool.get_weighted_percentile(0.99));
    (error, mean, p99)
}

/// Compare with the golden of `name` (or bless it).
pub fn check(name: &str, out: &RenderOutput) {
    if bless() {
        let golden = golden_dir().join(format!("{name}.png"));
        save_png(&golden, out);
        eprintln!("blessed {}", golden.display());
        return;
    }
    let (error, mean, p99) = score(name, out);
    let tol = tolerance(name);
    let which = if tol.same_driver {
        "same-driver"
    } else {
        "cross-driver"
    };
    eprintln!(
        "{name}: FLIP mean {mean:.5} (max {}), p99 {p99:.5} (max {}), {which} bound on {}",
        tol.mean,
        tol.p99,
        common::gpu().info.name
    );
    if mean > tol.mean || p99 > tol.p99 {
        let dir = diff_dir();
        std::fs::create_dir_all(&dir).expect("create diff folder");
        let map = error.apply_color_lut(&nv_flip::magma_lut());
        let diff = dir.join(format!("{name}-flip.png"));
        image::save_buffer(
            &diff,
            &map.to_vec(),
            out.width,
            out.height,
            image::ColorType::Rgb8,
        )
        .expect("write diff");
        save_png(&dir.join(format!("{name}-actual.png")), out);
        panic!(
            "{name}: FLIP mean {mean:.4} (allowed {}), 99th percentile {p99:.4} (allowed {}, {which}); error map {}, image {}; re-bless with SNOWPRINT_BLESS=1 if the change is intended",
            tol.mean,
            tol.p99,
            diff.display(),
            dir.join(format!("{name}-actual.png")).display()
        );
    }
}
