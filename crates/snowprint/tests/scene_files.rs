//! Scene files: parsing good files into the expected values, interpolating poses, and one clear
//! `file:line: ...; ...` message for every kind of mistake.

use std::path::{Path, PathBuf};

use glam::{EulerRot, Quat, Vec2, Vec3};
use snowprint::scene::{SCENE_VERSION, Scene, SceneShape};
use snowprint::{CaptureMode, SnowError};

/// The name every in-memory test scene is given.
const FILE: &str = "scenes/test.toml";

/// A valid scene with one of each shape but the mesh, and both ways of writing keys.
const GOOD: &str = r#"# A scene for the tests.
version = 1

[capture]
mode = "mask"
ankle_height = 0.3
mask_depth = 0.5

[[surface]]
name = "roof"
center = [0.0, 10.0, 0.0]
size = [8.0, 6.0]
yaw_degrees = 30
snow_depth = 0.3
replenish_rate = 0.05

[[surface]]
name = "step.1"
center = [5, 0, -2]
size = [2, 1]
snow_depth = 0.1

[[deformer]]
name = "left_foot"
shape = "capsule"
radius = 0.06
half_height = 0.08
keys = [ { t = 0.0, position = [0, 10.3, 0], rotation_degrees = [90, 0, 0] }, { t = 1.0, position = [1, 10.3, 0] } ]

[[deformer]]
name = "crate"
shape = "box"
half_extents = [0.1, 0.05, 0.15]

[[deformer.keys]]
t = 0.5
position = [1, 2, 3]

[[deformer.keys]]
t = 2.5
position = [2, 2, 3]
rotation_degrees = [0, 45, 0]

[[deformer]]
name = "ball"
shape = "sphere"
radius = 0.2
keys = [ { t = 0, position = [0, 0.1, 0] } ]
"#;

/// The smallest valid scene; error tests append to it or edit it.
const MINIMAL: &str = r#"version = 1

[[surface]]
name = "roof"
center = [0.0, 10.0, 0.0]
size = [8.0, 6.0]
snow_depth = 0.3
"#;

/// The error message of a scene that must fail.
fn error_of(text: &str) -> String {
    match Scene::parse(text, Path::new(FILE)) {
        Ok(scene) => panic!("the scene should not parse, but gave {scene:#?}\n{text}"),
        Err(SnowError::Scene(msg)) => msg,
        Err(other) => panic!("expected SnowError::Scene, got {other:?}"),
    }
}

/// 1-based line of the last line containing `needle`.
fn last_line_of(text: &str, needle: &str) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    lines
        .iter()
        .rposition(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("{needle:?} is not in the scene"))
        + 1
}

/// 1-based line of the first line containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("{needle:?} is not in the scene"))
        + 1
}

/// Assert `text` fails on line `line` with a one-line message that names the file and holds every
/// piece of `needles`.
fn assert_error_at(text: &str, line: usize, needles: &[&str]) -> String {
    let msg = error_of(text);
    let prefix = format!("{FILE}:{line}: ");
    assert!(
        msg.starts_with(&prefix),
        "message should start with {prefix:?}: {msg}"
    );
    assert!(!msg.contains('\n'), "message should be one line: {msg}");
    assert!(
        msg.contains("; "),
        "message should say what to do after '; ': {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "message should contain {n:?}: {msg}");
    }
    msg
}

/// Assert the scene fails on the line holding `at` (the first occurrence).
fn assert_error(text: &str, at: &str, needles: &[&str]) -> String {
    assert_error_at(text, line_of(text, at), needles)
}

/// MINIMAL with `old` replaced by `new` (which must happen).
fn minimal_with(old: &str, new: &str) -> String {
    assert!(MINIMAL.contains(old), "{old:?} not in MINIMAL");
    MINIMAL.replacen(old, new, 1)
}

/// MINIMAL plus more text.
fn minimal_plus(more: &str) -> String {
    format!("{MINIMAL}{more}")
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

fn quat_close(a: Quat, b: Quat) -> bool {
    // q and -q are the same rotation.
    let d = (a.x - b.x)
        .abs()
        .max((a.y - b.y).abs())
        .max((a.z - b.z).abs())
        .max((a.w - b.w).abs());
    let e = (a.x + b.x)
        .abs()
        .max((a.y + b.y).abs())
        .max((a.z + b.z).abs())
        .max((a.w + b.w).abs());
    d.min(e) < 1e-5
}

// ---------------------------------------------------------------------------------------------
// Good files

#[test]
fn good_scene_parses_into_the_expected_values() {
    let scene = Scene::parse(GOOD, Path::new(FILE)).expect("GOOD parses");
    assert_eq!(SCENE_VERSION, 1);
    assert_eq!(scene.path, PathBuf::from(FILE));
    assert_eq!(scene.capture.mode, CaptureMode::Mask);
    assert_eq!(scene.capture.ankle_height, 0.3);
    assert_eq!(scene.capture.mask_depth, 0.5);

    assert_eq!(scene.surfaces.len(), 2);
    let roof = &scene.surfaces[0];
    assert_eq!(roof.name, "roof");
    assert_eq!(roof.center, Vec3::new(0.0, 10.0, 0.0));
    assert_eq!(roof.size, Vec2::new(8.0, 6.0));
    assert_eq!(roof.yaw_degrees, 30.0);
    assert_eq!(roof.snow_depth, 0.3);
    assert_eq!(roof.replenish_rate, 0.05);
    let step = &scene.surfaces[1];
    assert_eq!(step.name, "step.1");
    assert_eq!(step.center, Vec3::new(5.0, 0.0, -2.0));
    assert_eq!(step.size, Vec2::new(2.0, 1.0));
    assert_eq!(step.yaw_degrees, 0.0, "yaw defaults to 0");
    assert_eq!(step.replenish_rate, 0.0, "replenish_rate defaults to 0");

    assert_eq!(scene.deformers.len(), 3);
    let foot = &scene.deformers[0];
    assert_eq!(foot.name, "left_foot");
    assert_eq!(
        foot.shape,
        SceneShape::Capsule {
            radius: 0.06,
            half_height: 0.08
        }
    );
    assert_eq!(foot.keys.len(), 2);
    assert_eq!(foot.keys[0].t, 0.0);
    assert_eq!(foot.keys[0].position, Vec3::new(0.0, 10.3, 0.0));
    assert_eq!(foot.keys[0].rotation_degrees, Vec3::new(90.0, 0.0, 0.0));
    assert_eq!(foot.keys[1].t, 1.0);
    assert_eq!(foot.keys[1].position, Vec3::new(1.0, 10.3, 0.0));
    assert_eq!(
        foot.keys[1].rotation_degrees,
        Vec3::ZERO,
        "rotation defaults to 0"
    );

    let crate_ = &scene.deformers[1];
    assert_eq!(crate_.name, "crate");
    assert_eq!(
        crate_.shape,
        SceneShape::Box {
            half_extents: Vec3::new(0.1, 0.05, 0.15)
        }
    );
    let times: Vec<f32> = crate_.keys.iter().map(|k| k.t).collect();
    assert_eq!(times, [0.5, 2.5], "[[deformer.keys]] tables are read too");
    assert_eq!(crate_.keys[1].position, Vec3::new(2.0, 2.0, 3.0));
    assert_eq!(crate_.keys[1].rotation_degrees, Vec3::new(0.0, 45.0, 0.0));

    let ball = &scene.deformers[2];
    assert_eq!(ball.shape, SceneShape::Sphere { radius: 0.2 });
    assert!(ball.is_static());
    assert!(!foot.is_static());
    assert_eq!(scene.duration(), 2.5);
}

#[test]
fn defaults_without_capture_table() {
    let scene = Scene::parse(MINIMAL, Path::new(FILE)).expect("MINIMAL parses");
    assert_eq!(scene.capture, snowprint::CaptureConfig::default());
    assert_eq!(scene.capture.mode, CaptureMode::Depth);
    assert_eq!(scene.capture.ankle_height, 0.25);
    assert_eq!(scene.capture.mask_depth, 1.0);
    assert!(scene.deformers.is_empty());
    assert_eq!(scene.duration(), 0.0);
}

#[test]
fn pose_at_interpolates_by_hand() {
    let text = minimal_plus(
        r#"
[[deformer]]
name = "d"
shape = "sphere"
radius = 0.1
keys = [
    { t = 1.0, position = [0, 10, 0] },
    { t = 3.0, position = [2, 10.5, -4], rotation_degrees = [0, 90, 0] },
    { t = 5.0, position = [2, 10.5, -4], rotation_degrees = [90, 90, 0] },
]
"#,
    );
    let scene = Scene::parse(&text, Path::new(FILE)).expect("parses");
    let d = &scene.deformers[0];
    // Midpoint between the first two keys.
    let p = d.pose_at(2.0);
    assert!(close(p.position, Vec3::new(1.0, 10.25, -2.0)), "{p:?}");
    // A quarter of the way.
    assert!(close(d.pose_at(1.5).position, Vec3::new(0.5, 10.125, -1.0)));
    // Before the first key: the first key; after the last: the last.
    assert!(close(d.pose_at(0.0).position, Vec3::new(0.0, 10.0, 0.0)));
    assert!(quat_close(d.pose_at(0.0).rotation, Quat::IDENTITY));
    assert!(close(d.pose_at(99.0).position, Vec3::new(2.0, 10.5, -4.0)));
    // Rotation at the midpoint: 45 degrees about Y, computed by hand:
    // (x, y, z, w) = (0, sin 22.5, 0, cos 22.5).
    let q = d.pose_at(2.0).rotation;
    let want = Quat::from_xyzw(0.0, 0.382_683_43, 0.0, 0.923_879_5);
    assert!(quat_close(q, want), "{q:?} vs {want:?}");
    // Midpoint of the second pair: degrees [45, 90, 0], YXZ order: q = qy(90) * qx(45).
    // qy(90) = (0, s, 0, c) with s = c = sqrt(1/2); qx(45) = (sin 22.5, 0, 0, cos 22.5) = (a, 0, 0, b).
    // Product (w1 w2 - v1.v2, w1 v2 + w2 v1 + v1 x v2) = (c a, s b, -s a, c b).
    let (s, a, b) = (
        std::f32::consts::FRAC_1_SQRT_2,
        0.382_683_43_f32,
        0.923_879_5_f32,
    );
    let want = Quat::from_xyzw(s * a, s * b, -s * a, s * b);
    let q = d.pose_at(4.0).rotation;
    assert!(quat_close(q, want), "{q:?} vs {want:?}");
    assert!(quat_close(
        q,
        Quat::from_euler(EulerRot::YXZ, 90f32.to_radians(), 45f32.to_radians(), 0.0)
    ));
    // At a key exactly.
    assert!(quat_close(
        d.pose_at(3.0).rotation,
        Quat::from_rotation_y(90f32.to_radians())
    ));
    assert_eq!(scene.duration(), 5.0);
}

#[test]
fn rotation_convention_lays_a_capsule_along_z_or_x() {
    let text = minimal_plus(
        r#"
[[deformer]]
name = "d"
shape = "capsule"
radius = 0.05
half_height = 0.09
keys = [ { t = 0, position = [0, 10, 0], rotation_degrees = [90, 0, 0] },
         { t = 1, position = [0, 10, 0], rotation_degrees = [0, 0, 90] } ]
"#,
    );
    let scene = Scene::parse(&text, Path::new(FILE)).expect("parses");
    let d = &scene.deformers[0];
    assert!(close(d.keys[0].rotation() * Vec3::Y, Vec3::Z));
    assert!(close(d.keys[1].rotation() * Vec3::Y, -Vec3::X));
}

// ---------------------------------------------------------------------------------------------
// Example scenes

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn every_example_scene_loads() {
    let mut count = 0;
    let entries = std::fs::read_dir(scenes_dir()).expect("scenes/ exists");
    for entry in entries {
        let path = entry.expect("readable entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(
                !(scene.surfaces.is_empty() && scene.terrains.is_empty()),
                "{}",
                path.display()
            );
            count += 1;
        }
    }
    assert!(
        count >= 2,
        "expected walker.toml and drag.toml, found {count} scenes"
    );
}

#[test]
fn walker_takes_separate_straight_steps() {
    let scene = Scene::load(&scenes_dir().join("walker.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.surfaces.len(), 1);
    let roof = &scene.surfaces[0];
    assert_eq!(roof.center, Vec3::new(0.0, 10.0, 0.0));
    assert_eq!(roof.size, Vec2::new(8.0, 6.0));
    assert_eq!(roof.snow_depth, 0.3);
    assert_eq!(roof.yaw_degrees, 0.0);
    let d = scene.duration();
    assert!((3.5..=5.0).contains(&d), "walk takes {d} s");

    let planted = 10.0 + 0.05 + 0.05;
    let lifted = 10.0 + 0.3 + 0.25 + 0.1 + 0.05;
    assert_eq!(scene.deformers.len(), 2);
    let mut zs = Vec::new();
    for foot in &scene.deformers {
        assert_eq!(
            foot.shape,
            SceneShape::Capsule {
                radius: 0.05,
                half_height: 0.09
            }
        );
        // Laid along X.
        for k in &foot.keys {
            assert!(close(k.rotation() * Vec3::Y, -Vec3::X), "{k:?}");
        }
        // Only vertical moves near the snow; horizontal moves only when lifted.
        for w in foot.keys.windows(2) {
            let (a, b) = (w[0].position, w[1].position);
            assert!(
                (a.y - planted).abs() < 1e-4 || a.y >= lifted - 1e-4,
                "{} key at {a} neither planted nor lifted",
                foot.name
            );
            if (a.x - b.x).abs() > 1e-6 {
                assert!(
                    a.y >= lifted - 1e-4 && b.y >= lifted - 1e-4,
                    "{} drags from {a} to {b}",
                    foot.name
                );
            }
        }
        // Footprints: x of each planted stretch, 0.8 m apart, covering -3..3 between both feet.
        let mut prints: Vec<f32> = foot
            .keys
            .iter()
            .filter(|k| (k.position.y - planted).abs() < 1e-4)
            .map(|k| k.position.x)
            .collect();
        prints.dedup();
        for w in prints.windows(2) {
            assert!(
                ((w[1] - w[0]) - 0.8).abs() < 1e-4,
                "{} stride {}",
                foot.name,
                w[1] - w[0]
            );
        }
        assert!(
            prints.len() >= 7,
            "{} makes {} prints",
            foot.name,
            prints.len()
        );
        assert!(
            prints
                .iter()
                .all(|x| (-3.0 - 1e-4..=3.0 + 1e-4).contains(x))
        );
        zs.push(foot.keys[0].position.z);
    }
    assert!(((zs[0] - zs[1]).abs() - 0.2).abs() < 1e-5, "feet {zs:?}");
    // The feet take turns: never both in the air (above the snow) at once.
    let mut t = 0.0;
    while t <= d {
        let up = scene
            .deformers
            .iter()
            .filter(|f| f.pose_at(t).position.y > planted + 1e-3)
            .count();
        assert!(up < 2, "both feet lifted at t = {t}");
        t += 0.01;
    }
    let xs: Vec<f32> = scene
        .deformers
        .iter()
        .flat_map(|f| f.keys.iter().map(|k| k.position.x))
        .collect();
    let (lo, hi) = xs
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &x| (l.min(x), h.max(x)));
    assert!(
        (lo + 3.0).abs() < 1e-4 && (hi - 3.0).abs() < 1e-4,
        "{lo}..{hi}"
    );
}

#[test]
fn drag_ploughs_one_surface_only() {
    let scene = Scene::load(&scenes_dir().join("drag.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.surfaces.len(), 2);
    let yard = &scene.surfaces[0];
    assert_eq!(yard.size, Vec2::new(6.0, 4.0));
    assert_eq!(yard.snow_depth, 0.3);
    assert_eq!(scene.deformers.len(), 1);
    let ball = &scene.deformers[0];
    assert_eq!(ball.shape, SceneShape::Sphere { radius: 0.2 });
    for k in &ball.keys {
        assert!((k.position.y - (yard.center.y + 0.1)).abs() < 1e-5);
    }
    let (first, last) = (
        ball.keys[0].position,
        ball.keys[ball.keys.len() - 1].position,
    );
    assert!(first.x < -3.0 && last.x > 3.0, "crosses the whole yard");
    // The other surface stays clear of the ball's path (its z extent vs the ball's).
    let bench = &scene.surfaces[1];
    assert!(bench.center.z - bench.size.y / 2.0 > first.z.abs() + 0.2 + 0.25);
}

// ---------------------------------------------------------------------------------------------
// Errors: syntax and unknown keys

#[test]
fn toml_syntax_errors() {
    let text = minimal_plus("\n[[deformer]\nname = \"x\"\n");
    assert_error(&text, "[[deformer]", &["not valid TOML"]);
    let text = minimal_with("size = [8.0, 6.0]", "size = [8.0, 6.0");
    let msg = error_of(&text);
    assert!(msg.starts_with(&format!("{FILE}:")), "{msg}");
    assert!(msg.contains("not valid TOML"), "{msg}");
    let text = minimal_with("name = \"roof\"", "name = roof");
    assert_error(&text, "name = roof", &["not valid TOML"]);
    // A key given twice is a TOML error too.
    let text = minimal_with("snow_depth = 0.3", "snow_depth = 0.3\nsnow_depth = 0.4");
    assert_error(&text, "snow_depth = 0.4", &["not valid TOML"]);
}

#[test]
fn windows_line_endings_keep_line_numbers() {
    let text = minimal_with("snow_depth = 0.3", "snow_depth = -2").replace('\n', "\r\n");
    assert_error_at(&text, 7, &["snow_depth -2"]);
    let good = GOOD.replace('\n', "\r\n");
    assert!(Scene::parse(&good, Path::new(FILE)).is_ok());
}

#[test]
fn unknown_key_at_top_level() {
    let text = minimal_with("version = 1", "version = 1\ncolour = \"white\"");
    assert_error(
        &text,
        "colour",
        &["\"colour\"", "top level", "version, capture"],
    );
    // A key of another table is pointed to its home.
    let text = minimal_with("version = 1", "version = 1\nmode = \"mask\"");
    assert_error(&text, "mode = ", &["\"mode\"", "belongs in [capture]"]);
}

#[test]
fn unknown_key_in_capture() {
    let text = minimal_plus("\n[capture]\nankle = 0.2\n");
    assert_error(
        &text,
        "ankle = ",
        &["\"ankle\"", "[capture]", "did you mean \"ankle_height\""],
    );
}

#[test]
fn unknown_key_in_surface() {
    let text = minimal_with("size = [8.0, 6.0]", "sizes = [8.0, 6.0]");
    assert_error(
        &text,
        "sizes",
        &["\"sizes\"", "[[surface]]", "did you mean \"size\""],
    );
}

#[test]
fn unknown_key_in_deformer() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradios = 0.1\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n",
    );
    assert_error(
        &text,
        "radios",
        &["\"radios\"", "[[deformer]]", "did you mean \"radius\""],
    );
}

#[test]
fn unknown_key_in_inline_key() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n  { t = 0, position = [0, 0, 0] },\n  { t = 1, positon = [1, 0, 0] },\n]\n",
    );
    assert_error(
        &text,
        "positon",
        &["\"positon\"", "deformer key", "did you mean \"position\""],
    );
}

#[test]
fn unknown_key_in_key_table() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\n\n[[deformer.keys]]\nt = 0\nposition = [0, 0, 0]\nrotation = [0, 90, 0]\n",
    );
    assert_error(
        &text,
        "rotation =",
        &[
            "\"rotation\"",
            "deformer key",
            "t, position and rotation_degrees",
        ],
    );
}

#[test]
fn wrong_types_name_the_key_and_show_an_example() {
    let text = minimal_with("size = [8.0, 6.0]", "size = \"big\"");
    assert_error(&text, "size = ", &["size = \"big\"", "size = [8.0, 6.0]"]);
    let text = minimal_with("snow_depth = 0.3", "snow_depth = \"deep\"");
    assert_error(&text, "snow_depth", &["snow_depth = \"deep\"", "number"]);
    // [surface] with one pair of brackets.
    let text = "version = 1\n\n[surface]\nname = \"roof\"\n";
    assert_error(text, "[surface]", &["[surface]", "[[surface]]"]);
}

// ---------------------------------------------------------------------------------------------
// Errors: missing keys and versions

#[test]
fn missing_version() {
    let text = MINIMAL.replacen("version = 1\n", "\n", 1);
    assert_error_at(&text, 1, &["no version", "version = 1"]);
}

#[test]
fn wrong_version() {
    let text = minimal_with("version = 1", "version = 2");
    assert_error(&text, "version", &["version is 2", "version = 1"]);
    let text = minimal_with("version = 1", "version = \"1\"");
    assert_error(&text, "version", &["version = \"1\"", "integer"]);
}

#[test]
fn missing_required_surface_keys() {
    for key in ["name", "center", "size", "snow_depth"] {
        let text: String = MINIMAL
            .lines()
            .filter(|l| !l.starts_with(key))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_error(
            &text,
            "[[surface]]",
            &[&format!("no {key}"), &format!("add {key}")],
        );
    }
}

#[test]
fn missing_required_deformer_keys() {
    let sphere = "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n";
    for (key, needle) in [
        ("name", "no name"),
        ("shape", "deformer \"b\" has no shape"),
        ("radius", "deformer \"b\" is a sphere but has no radius"),
        ("keys", "deformer \"b\" has no keys"),
    ] {
        let text = minimal_plus(
            &sphere
                .lines()
                .filter(|l| !l.starts_with(key))
                .map(|l| format!("{l}\n"))
                .collect::<String>(),
        );
        assert_error(&text, "[[deformer]]", &[needle]);
    }
    let capsule = "\n[[deformer]]\nname = \"c\"\nshape = \"capsule\"\nradius = 0.1\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n";
    assert_error(
        &minimal_plus(capsule),
        "[[deformer]]",
        &[
            "\"c\" is a capsule but has no half_height",
            "add half_height",
        ],
    );
    let b = "\n[[deformer]]\nname = \"c\"\nshape = \"box\"\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n";
    assert_error(&minimal_plus(b), "[[deformer]]", &["no half_extents"]);
    let m = "\n[[deformer]]\nname = \"c\"\nshape = \"mesh\"\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n";
    assert_error(&minimal_plus(m), "[[deformer]]", &["no path"]);
}

#[test]
fn missing_key_fields_and_empty_keys() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n  { t = 0, position = [0, 0, 0] },\n  { position = [1, 0, 0] },\n]\n",
    );
    assert_error(&text, "{ position = [1", &["no t", "\"b\""]);
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n  { t = 0, rotation_degrees = [0, 0, 0] },\n]\n",
    );
    assert_error(&text, "{ t = 0, rotation", &["no position", "\"b\""]);
    let text =
        minimal_plus("\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nkeys = []\n");
    assert_error(&text, "keys = []", &["empty keys", "at least one key"]);
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\n\n[[deformer.keys]]\nposition = [1, 0, 0]\n",
    );
    assert_error(&text, "[[deformer.keys]]", &["no t"]);
}

#[test]
fn no_surfaces() {
    let text = "version = 1\n";
    assert_error_at(text, 1, &["no [[surface]]"]);
}

// ---------------------------------------------------------------------------------------------
// Errors: values

#[test]
fn bad_sizes() {
    let text = minimal_with("size = [8.0, 6.0]", "size = [-1, 6]");
    let msg = assert_error(&text, "size = ", &[]);
    assert!(
        msg.starts_with(&format!(
            "{FILE}:6: surface \"roof\" has size [-1, 6]; sizes must be finite numbers of metres above 0"
        )),
        "{msg}"
    );
    for bad in [
        "[0, 6]",
        "[8, nan]",
        "[inf, 6]",
        "[8, -inf]",
        "[1e50, 6]",
        "[200000, 6]",
    ] {
        let text = minimal_with("size = [8.0, 6.0]", &format!("size = {bad}"));
        assert_error(&text, "size = ", &[&format!("size {bad}"), "above 0"]);
    }
    let text = minimal_with("size = [8.0, 6.0]", "size = [8, 6, 1]");
    assert_error(&text, "size = ", &["size [8, 6, 1]", "exactly two numbers"]);
}

#[test]
fn bad_depths_and_rates() {
    for bad in ["0", "-0.3", "nan", "inf", "-inf"] {
        let text = minimal_with("snow_depth = 0.3", &format!("snow_depth = {bad}"));
        assert_error(
            &text,
            "snow_depth",
            &[&format!("snow_depth {bad}"), "above 0"],
        );
    }
    let text = minimal_plus("replenish_rate = -0.1\n");
    assert_error(
        &text,
        "replenish_rate",
        &["replenish_rate -0.1", "0 or more"],
    );
    let text = minimal_plus("replenish_rate = nan\n");
    assert_error(&text, "replenish_rate", &["replenish_rate nan"]);
    let text = minimal_plus("yaw_degrees = inf\n");
    assert_error(&text, "yaw_degrees", &["yaw_degrees inf", "finite"]);
    let text = minimal_with("center = [0.0, 10.0, 0.0]", "center = [0.0, nan, 0.0]");
    assert_error(&text, "center", &["center [0.0, nan, 0.0]", "finite"]);
    let text = minimal_with("center = [0.0, 10.0, 0.0]", "center = [0.0, 10.0]");
    assert_error(&text, "center", &["center [0.0, 10.0]", "exactly three"]);
}

#[test]
fn bad_capture_values() {
    let text = minimal_plus("\n[capture]\nmode = \"wax\"\n");
    assert_error(&text, "mode", &["mode \"wax\"", "\"depth\"", "\"mask\""]);
    for bad in ["0", "-0.25", "nan", "inf"] {
        let text = minimal_plus(&format!("\n[capture]\nankle_height = {bad}\n"));
        assert_error(
            &text,
            "ankle_height",
            &[&format!("ankle_height {bad}"), "above 0"],
        );
    }
    for bad in ["0", "1.5", "-1", "nan"] {
        let text = minimal_plus(&format!(
            "\n[capture]\nmode = \"mask\"\nmask_depth = {bad}\n"
        ));
        assert_error(
            &text,
            "mask_depth",
            &[&format!("mask_depth {bad}"), "at most 1"],
        );
    }
}

fn deformer_with(shape_lines: &str) -> String {
    minimal_plus(&format!(
        "\n[[deformer]]\nname = \"foot\"\n{shape_lines}\nkeys = [ {{ t = 0, position = [0, 10.1, 0] }} ]\n"
    ))
}

#[test]
fn bad_radii_and_extents() {
    for bad in ["0", "-0.1", "nan", "inf"] {
        let text = deformer_with(&format!("shape = \"sphere\"\nradius = {bad}"));
        assert_error(
            &text,
            "radius",
            &["deformer \"foot\"", &format!("radius {bad}"), "above 0"],
        );
        let text = deformer_with(&format!(
            "shape = \"capsule\"\nradius = {bad}\nhalf_height = 0.1"
        ));
        assert_error(&text, "radius", &[&format!("radius {bad}")]);
        let text = deformer_with(&format!(
            "shape = \"box\"\nhalf_extents = [0.1, {bad}, 0.1]"
        ));
        assert_error(
            &text,
            "half_extents",
            &[&format!("half_extents [0.1, {bad}, 0.1]"), "above 0"],
        );
    }
    let text = deformer_with("shape = \"capsule\"\nradius = 0.1\nhalf_height = -0.1");
    assert_error(&text, "half_height", &["half_height -0.1", "0 or more"]);
    // Zero half-height is a sphere-like capsule and fine.
    let text = deformer_with("shape = \"capsule\"\nradius = 0.1\nhalf_height = 0");
    assert!(Scene::parse(&text, Path::new(FILE)).is_ok());
    let text = deformer_with("shape = \"box\"\nhalf_extents = [0.1, 0.1]");
    assert_error(&text, "half_extents", &["exactly three numbers"]);
}

#[test]
fn unknown_shape() {
    let text = deformer_with("shape = \"cone\"\nradius = 0.1");
    assert_error(
        &text,
        "shape",
        &[
            "deformer \"foot\" has shape \"cone\"",
            "\"sphere\", \"capsule\", \"box\" or \"mesh\"",
        ],
    );
}

#[test]
fn fields_of_another_shape() {
    let text = deformer_with("shape = \"sphere\"\nradius = 0.1\nhalf_extents = [0.1, 0.1, 0.1]");
    assert_error(
        &text,
        "half_extents",
        &[
            "is a sphere",
            "half_extents [0.1, 0.1, 0.1]",
            "only applies to boxes",
        ],
    );
    let text = deformer_with("shape = \"sphere\"\nradius = 0.1\nhalf_height = 0.1");
    assert_error(&text, "half_height", &["only applies to capsules"]);
    let text = deformer_with("shape = \"box\"\nhalf_extents = [0.1, 0.1, 0.1]\nradius = 0.1");
    assert_error(
        &text,
        "radius",
        &["is a box", "only applies to spheres and capsules"],
    );
    let text =
        deformer_with("shape = \"capsule\"\nradius = 0.1\nhalf_height = 0.1\npath = \"a.glb\"");
    assert_error(&text, "path", &["path \"a.glb\"", "only applies to meshes"]);
}

#[test]
fn duplicate_names() {
    let text = minimal_plus(
        "\n[[surface]]\nname = \"roof\"\ncenter = [0, 0, 0]\nsize = [1, 1]\nsnow_depth = 0.1\n",
    );
    assert_error_at(
        &text,
        last_line_of(&text, "name = \"roof\""),
        &[
            "surface name \"roof\" is used twice (first at line 4)",
            "own name",
        ],
    );
    let one = "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [ { t = 0, position = [0, 0, 0] } ]\n";
    let text = minimal_plus(&format!("{one}{one}"));
    assert_error_at(
        &text,
        last_line_of(&text, "name = \"foot\""),
        &["deformer name \"foot\" is used twice", "own name"],
    );
}

#[test]
fn surface_names_must_be_file_names() {
    for (bad, shown) in [
        ("my roof", "' '"),
        ("a/b", "'/'"),
        ("", "empty"),
        ("..", "only dots"),
    ] {
        let text = minimal_with("name = \"roof\"", &format!("name = \"{bad}\""));
        assert_error(
            &text,
            "name =",
            &[&format!("\"{bad}\""), shown, "file name"],
        );
    }
}

#[test]
fn keys_out_of_order() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n  { t = 0.0, position = [0, 0, 0] },\n  { t = 1.5, position = [1, 0, 0] },\n  { t = 1.0, position = [2, 0, 0] },\n]\n",
    );
    assert_error(
        &text,
        "t = 1.0",
        &[
            "deformer \"foot\"",
            "t = 1.0 after a key at t = 1.5",
            "increase strictly",
        ],
    );
    // Equal times too, in table form.
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\n[[deformer.keys]]\nt = 2\nposition = [0, 0, 0]\n[[deformer.keys]]\nt = 2.0\nposition = [1, 0, 0]\n",
    );
    assert_error(&text, "t = 2.0", &["t = 2.0 after a key at t = 2"]);
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [ { t = nan, position = [0, 0, 0] } ]\n",
    );
    assert_error(&text, "t = nan", &["t = nan", "finite"]);
}

#[test]
fn nan_in_positions_and_rotations() {
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [\n  { t = 0.0, position = [0, 0, 0] },\n  { t = 1.0, position = [0, nan, 0] },\n]\n",
    );
    assert_error(
        &text,
        "nan",
        &[
            "deformer \"foot\" at t = 1.0",
            "position [0, nan, 0]",
            "finite",
        ],
    );
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\n[[deformer.keys]]\nt = 0\nposition = [0, 0, 0]\nrotation_degrees = [0, inf, 0]\n",
    );
    assert_error(
        &text,
        "rotation_degrees",
        &["rotation_degrees [0, inf, 0]", "finite"],
    );
    let text = minimal_plus(
        "\n[[deformer]]\nname = \"foot\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [ { t = 0, position = [0, 0] } ]\n",
    );
    assert_error(&text, "keys", &["position [0, 0]", "exactly three"]);
}

// ---------------------------------------------------------------------------------------------
// Mesh deformers and files

/// A fresh empty folder under the system temp folder.
fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "snowprint-scene-{tag}-{}-{:?}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0)
    ));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A glTF file holding a unit tetrahedron (outward winding) in a node moved up by 1 m, with its
/// buffer embedded as base64.
fn tetrahedron_gltf() -> String {
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let indices: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let mut bytes = Vec::new();
    for p in positions {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    assert_eq!(bytes.len(), 72);
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [ {{ "nodes": [0] }} ],
  "nodes": [ {{ "mesh": 0, "translation": [0.0, 1.0, 0.0] }} ],
  "meshes": [ {{ "primitives": [ {{ "attributes": {{ "POSITION": 0 }}, "indices": 1 }} ] }} ],
  "buffers": [ {{ "byteLength": 72, "uri": "data:application/octet-stream;base64,{}" }} ],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 24, "target": 34963 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR" }}
  ]
}}
"#,
        base64(&bytes)
    )
}

fn mesh_scene(path: &str) -> String {
    minimal_plus(&format!(
        "\n[[deformer]]\nname = \"boot\"\nshape = \"mesh\"\npath = \"{path}\"\nkeys = [ {{ t = 0, position = [0, 10.1, 0] }} ]\n"
    ))
}

#[test]
fn base64_encoder_matches_known_values() {
    assert_eq!(base64(b"Man"), "TWFu");
    assert_eq!(base64(b"Ma"), "TWE=");
    assert_eq!(base64(b"M"), "TQ==");
}

#[test]
fn mesh_deformer_loads_a_gltf_relative_to_the_scene() {
    let dir = temp_dir("mesh");
    std::fs::create_dir_all(dir.join("meshes")).expect("mkdir");
    std::fs::write(dir.join("meshes/tet.gltf"), tetrahedron_gltf()).expect("write gltf");
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, mesh_scene("meshes/tet.gltf")).expect("write scene");

    let scene = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
    let boot = &scene.deformers[0];
    let SceneShape::Mesh { path, mesh } = &boot.shape else {
        panic!("not a mesh: {:?}", boot.shape);
    };
    assert_eq!(path, &dir.join("meshes/tet.gltf"));
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.indices.len(), 12);
    // The node's translation is applied.
    assert!(mesh.positions.contains(&Vec3::new(0.0, 1.0, 0.0)));
    assert!(mesh.positions.contains(&Vec3::new(0.0, 2.0, 0.0)));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_mesh_file() {
    let dir = temp_dir("missing");
    let scene_path = dir.join("scene.toml");
    let text = mesh_scene("boots/left.glb");
    std::fs::write(&scene_path, &text).expect("write scene");
    let msg = match Scene::load(&scene_path) {
        Err(SnowError::Scene(msg)) => msg,
        other => panic!("expected a scene error, got {other:?}"),
    };
    let line = line_of(&text, "path =");
    let resolved = dir.join("boots/left.glb");
    assert!(
        msg.starts_with(&format!("{}:{line}: ", scene_path.display())),
        "{msg}"
    );
    assert!(msg.contains("\"boots/left.glb\""), "{msg}");
    assert!(msg.contains(&resolved.display().to_string()), "{msg}");
    assert!(msg.contains("does not exist"), "{msg}");
    assert!(msg.contains("relative to the scene file's folder"), "{msg}");
    // Through parse with a relative scene path, the mesh path resolves against its folder.
    assert_error(
        &mesh_scene("nope.glb"),
        "path =",
        &["scenes/nope.glb does not exist"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn invalid_mesh_file() {
    let dir = temp_dir("invalid");
    std::fs::write(dir.join("bad.gltf"), "this is not glTF").expect("write");
    std::fs::create_dir_all(dir.join("folder.glb")).expect("mkdir");
    let scene_path = dir.join("scene.toml");
    for (file, needle) in [
        ("bad.gltf", "cannot be used as a mesh"),
        ("folder.glb", "is not a file"),
    ] {
        let text = mesh_scene(file);
        std::fs::write(&scene_path, &text).expect("write scene");
        let msg = match Scene::load(&scene_path) {
            Err(SnowError::Scene(msg)) => msg,
            other => panic!("expected a scene error, got {other:?}"),
        };
        let line = line_of(&text, "path =");
        assert!(
            msg.starts_with(&format!("{}:{line}: ", scene_path.display())),
            "{msg}"
        );
        assert!(msg.contains(&format!("\"{file}\"")), "{msg}");
        assert!(msg.contains(needle), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_scene_file() {
    let path = Path::new("does/not/exist.toml");
    match Scene::load(path) {
        Err(SnowError::Scene(msg)) => {
            assert!(msg.starts_with("does/not/exist.toml: "), "{msg}");
            assert!(msg.contains("cannot be read"), "{msg}");
        }
        other => panic!("expected a scene error, got {other:?}"),
    }
}

#[test]
fn nothing_panics_on_garbage() {
    let inputs = [
        "",
        "\u{feff}",
        "version = 1\n[[surface]]\n",
        "version = 1\n[[deformer]]\n",
        "version = 1\n[capture]\n[capture]\n",
        "version = 1\nsurface = []\n",
        "version = 99999999999999999999\n",
        "version = -1\n",
        "[[[",
        "version = 1\n[[surface]]\nname = \"é\"\n",
        "version = 1\n[[surface]]\nname = \"r\"\ncenter = [1, 2, 3]\nsize = [1, 1]\nsnow_depth = 0.1\n[[deformer]]\nname = \"d\"\nshape = \"sphere\"\nradius = 0.1\nkeys = [ [1, 2] ]\n",
        "version = 1\n[[surface]]\nname = \"r\"\ncenter = [1, 2, 3]\nsize = [1, 1]\nsnow_depth = 0.1\n[[deformer]]\nname = \"d\"\nshape = 3\n",
    ];
    for text in inputs {
        let msg = error_of(text);
        assert!(msg.starts_with(&format!("{FILE}:")), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
    }
}

mod manager_keys {
    use std::path::Path;

    use snowprint::scene::Scene;

    const BASE: &str = "version = 1\n[[surface]]\nname = \"a\"\ncenter = [0, 0, 0]\nsize = [2, 2]\nsnow_depth = 0.3\n";

    fn parse(extra: &str) -> snowprint::Result<Scene> {
        Scene::parse(&format!("{BASE}{extra}"), Path::new("m.toml"))
    }

    #[test]
    fn budget_camera_player_and_zone_parse() {
        let s = parse(
            "zone = 3\n[budget]\nupdates_per_frame = 4\npool_bytes = 1048576\nactive_distance = 25.5\nprecision_bits = 8\n\
             [camera]\ntarget = [1, 2, 3]\nkeys = [{ t = 0, eye = [0, 10, 0] }, { t = 2, eye = [4, 10, 0] }]\n\
             [[deformer]]\nname = \"p\"\nshape = \"sphere\"\nradius = 0.1\nplayer = true\nkeys = [{ t = 0, position = [0, 0.1, 0] }]\n",
        )
        .unwrap();
        assert_eq!(s.zones, vec![3]);
        let b = s.budget.unwrap();
        assert_eq!(
            (b.updates_per_frame, b.pool_bytes, b.active_distance),
            (Some(4), Some(1 << 20), Some(25.5))
        );
        assert_eq!(b.precision, Some(snowprint::Precision::Bits8));
        let c = s.camera.unwrap();
        assert_eq!(c.fov_y_degrees, 50.0);
        // Halfway between the keys.
        assert_eq!(c.at(1.0).eye, glam::Vec3::new(2.0, 10.0, 0.0));
        assert_eq!(c.at(-1.0).eye, glam::Vec3::new(0.0, 10.0, 0.0));
        assert_eq!(c.at(9.0).eye, glam::Vec3::new(4.0, 10.0, 0.0));
        assert!(s.deformers[0].player);
    }

    #[test]
    fn manager_key_errors_name_line_and_value() {
        let cases = [
            (
                "[budget]\nupdates_per_frame = 0\n",
                "m.toml:8:",
                "updates_per_frame 0",
            ),
            ("[budget]\npool_bytes = -5\n", "m.toml:8:", "pool_bytes -5"),
            (
                "[budget]\nprecision_bits = 12\n",
                "m.toml:8:",
                "precision_bits 12",
            ),
            (
                "[budget]\nactive_distance = nan\n",
                "m.toml:8:",
                "active_distance nan",
            ),
            ("[budget]\nspeed = 1\n", "m.toml:8:", "speed"),
            (
                "[camera]\ntarget = [0, 0, 0]\nkeys = [{ t = 1, eye = [0, 1, 0] }, { t = 0.5, eye = [0, 2, 0] }]\n",
                "m.toml:9:",
                "t = 0.5",
            ),
            (
                "[camera]\nkeys = [{ t = 0, eye = [0, 1, 0] }]\n",
                "m.toml:7:",
                "target",
            ),
            (
                "[[deformer]]\nname = \"p\"\nshape = \"sphere\"\nradius = 0.1\nplayer = true\nkeys = [{ t = 0, position = [0, 0, 0] }]\n\
                 [[deformer]]\nname = \"q\"\nshape = \"sphere\"\nradius = 0.1\nplayer = true\nkeys = [{ t = 0, position = [0, 0, 0] }]\n",
                "m.toml:17:",
                "already deformer \"p\"",
            ),
        ];
        for (extra, line, value) in cases {
            let e = parse(extra).unwrap_err().to_string();
            assert!(e.contains(line) && e.contains(value), "{extra:?}: {e}");
        }
        let e = Scene::parse(
            &BASE.replace("snow_depth = 0.3\n", "snow_depth = 0.3\nzone = -1\n"),
            Path::new("m.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("m.toml:7:") && e.contains("zone -1"), "{e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Animated (skinned) mesh deformers

#[test]
fn skinned_walker_names_its_animation() {
    let scene =
        Scene::load(&scenes_dir().join("skinned_walker.toml")).unwrap_or_else(|e| panic!("{e}"));
    let figure = &scene.deformers[0];
    let a = figure.animation.as_ref().expect("animated");
    assert_eq!(a.index, 0);
    assert_eq!(a.name, "0");
    assert_eq!(a.speed, 1.0);
    assert_eq!(a.playback, snowprint::Playback::Loop);
    assert_eq!(a.skinned.joints.len(), 19);
    // The figure's time: scene seconds times the speed.
    // Any handle: `at` only carries it.
    let id = mesh_handle();
    assert_eq!(a.at(id, 2.0).time, 2.0);
    assert_eq!(a.at(id, 2.0).animation, Some(0));
}

/// A mesh handle for [`snowprint::scene::SceneAnimation::at`], from a world-free path: handles are
/// serializable, so one is read from its saved form.
fn mesh_handle() -> snowprint::MeshId {
    serde_json::from_str("0").expect("a MeshId is its index")
}

/// A scene in `scenes/` (so that `RiggedFigure.gltf` is beside it) with one figure deformer whose
/// extra lines are `extra`.
fn figure_scene(extra: &str) -> String {
    format!(
        "version = 1\n\n[[surface]]\nname = \"roof\"\ncenter = [0, 10, 0]\nsize = [8, 3]\nsnow_depth = 0.3\n\n\
         [[deformer]]\nname = \"figure\"\nshape = \"mesh\"\npath = \"RiggedFigure.gltf\"\n{extra}\n\
         keys = [{{ t = 0, position = [0, 10.05, 0] }}]\n"
    )
}

fn figure_error(text: &str) -> String {
    match Scene::parse(text, &scenes_dir().join("figure.toml")) {
        Err(SnowError::Scene(msg)) => msg,
        other => panic!("expected a scene error, got {other:?}"),
    }
}

#[test]
fn animation_keys_are_checked_with_file_and_line() {
    // An animation the file does not have: the line of `animation`, the names it has.
    let text = figure_scene("animation = \"walk\"");
    let msg = figure_error(&text);
    let line = line_of(&text, "animation =");
    assert!(msg.contains(&format!("figure.toml:{line}: ")), "{msg}");
    assert!(msg.contains("has animation \"walk\""), "{msg}");
    assert!(msg.contains("\"0\" (unnamed)"), "{msg}");
    // A speed that is not above 0.
    let text = figure_scene("animation = \"0\"\nanimation_speed = 0");
    let msg = figure_error(&text);
    assert!(
        msg.contains(&format!(":{}: ", line_of(&text, "animation_speed"))),
        "{msg}"
    );
    assert!(msg.contains("animation_speed must be"), "{msg}");
    // loop without an animation.
    let text = figure_scene("loop = false");
    let msg = figure_error(&text);
    assert!(msg.contains("has loop false but no animation"), "{msg}");
    // An animation on a sphere.
    let text = minimal_plus(
        "[[deformer]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 0.1\nanimation = \"0\"\nkeys = [{ t = 0, position = [0, 0, 0] }]\n",
    );
    let msg = error_of(&text);
    assert!(msg.contains("animation only applies to meshes"), "{msg}");
    // loop = false holds the last pose; a speed scales time.
    let text = figure_scene("animation = \"0\"\nanimation_speed = 0.5\nloop = false");
    let scene =
        Scene::parse(&text, &scenes_dir().join("figure.toml")).unwrap_or_else(|e| panic!("{e}"));
    let a = scene.deformers[0].animation.as_ref().unwrap();
    assert_eq!(a.playback, snowprint::Playback::Clamp);
    assert_eq!(a.at(mesh_handle(), 3.0).time, 1.5);
    // Without `animation` the mesh is static, as before.
    let scene = Scene::parse(&figure_scene(""), &scenes_dir().join("figure.toml")).unwrap();
    assert!(scene.deformers[0].animation.is_none());
}
