//! Skinned meshes: the loader and the CPU reference on a tiny glTF built here, whose posed vertices
//! are computed by hand (two joints, a known rotation at a known time, step and cubic-spline
//! channels, loop and clamp); the same file as GLB and with an external buffer; the one-sentence
//! refusals. The GPU side is in `tests/skinned_gpu.rs`.

mod skin_support;

use glam::Vec3;
use serde_json::json;
use skin_support::{TwoJoints, glb, two_joints};
use snowprint::skeleton::Interpolation;
use snowprint::{Playback, SkinnedMesh, SnowError};
use std::path::Path;

/// Hand-computed positions are compared to 1e-5 m: the posing is a few f32 products of values
/// near 1 (about 1e-7 relative each), so a correct pose is within 1e-6; a wrong joint, time or
/// interpolation moves a vertex by centimetres at least.
const HAND_TOLERANCE: f32 = 1e-5;

fn load(bytes: &[u8]) -> SkinnedMesh {
    SkinnedMesh::from_gltf_slice(bytes, Path::new("two_joints.gltf"), None)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn refusal(bytes: &[u8]) -> String {
    match SkinnedMesh::from_gltf_slice(bytes, Path::new("two_joints.gltf"), None) {
        Ok(_) => panic!("the file was accepted"),
        Err(e) => {
            assert!(matches!(e, SnowError::MeshFile { .. }), "{e:?}");
            e.to_string()
        }
    }
}

fn assert_close(got: &[Vec3], want: &[Vec3], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            g.distance(*w) <= HAND_TOLERANCE,
            "{what}: vertex {i} is at {g}, by hand {w}"
        );
    }
}

fn posed(m: &SkinnedMesh, animation: &str, t: f32, playback: Playback) -> Vec<Vec3> {
    let a = m.animation_index(animation).expect("animation");
    let joints = m.pose(Some(a), t, playback);
    snowprint::reference::skin::skin_vertices(&m.mesh.positions, &m.influences, &joints)
}

const S: f32 = std::f32::consts::FRAC_1_SQRT_2;

#[test]
fn the_file_is_read_as_written() {
    let m = load(&two_joints(&TwoJoints::default()));
    assert_eq!(m.mesh.positions.len(), 3);
    assert_eq!(m.mesh.indices, vec![0, 1, 2]);
    assert_eq!(m.joints.len(), 2);
    // Normalized unsigned bytes: 255 is 1; 128 and 128 sum to 256/255 and are made to sum to 1.
    assert_eq!(m.influences[0].weights, [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(m.influences[2].weights, [0.5, 0.5, 0.0, 0.0]);
    assert_eq!(m.influences[2].joints, [0, 1, 0, 0]);
    assert_eq!(m.animations.len(), 2);
    assert_eq!(m.animations[0].duration, 2.0);
    assert_eq!(
        m.animations[1].channels[0].interpolation,
        Interpolation::CubicSpline
    );
    assert_eq!(m.animation_index("bend"), Some(0));
    assert_eq!(m.animation_index("walk"), None);
    assert_eq!(m.animation_names(), "\"bend\", \"grow\"");
}

#[test]
fn rest_pose_ignores_the_skinned_nodes_own_transform() {
    let m = load(&two_joints(&TwoJoints::default()));
    // The mesh node is translated by (100, 0, 0), which glTF says a skinned mesh ignores; at rest
    // every joint matrix is the identity (global = inverse of the inverse bind).
    let joints = m.pose(None, 0.0, Playback::Clamp);
    let v = snowprint::reference::skin::skin_vertices(&m.mesh.positions, &m.influences, &joints);
    assert_close(&v, &m.mesh.positions, "rest pose");
}

#[test]
fn a_known_rotation_at_a_known_time() {
    let m = load(&two_joints(&TwoJoints::default()));
    // "bend" at t = 1: the hip (joint 0) has stepped to (2, 0, 0) (STEP keys at 0 and 1), the knee
    // (joint 1, 1 m above the hip) is halfway through a LINEAR quarter turn about Z: 45 degrees.
    // v0 (0, 0.5, 0) follows the hip: (2, 0.5, 0).
    // v1 (0, 1.5, 0) is 0.5 above the knee: rotated 45 degrees, (-0.5 s, 0.5 s), plus the knee
    //   at (2, 1, 0).
    // v2 (1, 1.5, 0), half hip (3, 1.5, 0), half knee ((1, 0.5) rotated: (s - 0.5 s, s + 0.5 s)
    //   plus (2, 1)).
    let knee = Vec3::new(2.0, 1.0, 0.0);
    let v2_knee = knee + Vec3::new(S - 0.5 * S, S + 0.5 * S, 0.0);
    let want = [
        Vec3::new(2.0, 0.5, 0.0),
        knee + Vec3::new(-0.5 * S, 0.5 * S, 0.0),
        (Vec3::new(3.0, 1.5, 0.0) + v2_knee) * 0.5,
    ];
    assert_close(&posed(&m, "bend", 1.0, Playback::Clamp), &want, "t = 1");
    // Looping, t = 3 is t = 1 again.
    assert_close(
        &posed(&m, "bend", 3.0, Playback::Loop),
        &want,
        "t = 3 looped",
    );
    // Clamped, t = 3 holds the end: a quarter turn, v1 at (2 - 0.5, 1, 0).
    let end = posed(&m, "bend", 3.0, Playback::Clamp);
    assert!(
        end[1].distance(Vec3::new(1.5, 1.0, 0.0)) <= HAND_TOLERANCE,
        "{}",
        end[1]
    );
    // Just before the step's second key the hip has not moved yet.
    let early = posed(&m, "bend", 0.5, Playback::Clamp);
    assert!(
        early[0].distance(Vec3::new(0.0, 0.5, 0.0)) <= HAND_TOLERANCE,
        "{}",
        early[0]
    );
}

#[test]
fn cubic_spline_uses_values_and_tangents() {
    let m = load(&two_joints(&TwoJoints::default()));
    // "grow": the hip's scale by a cubic spline over keys at 0 and 1, values 1 and 3, the first
    // key's out-tangent 1, the second's in-tangent 2. At s = 0.5:
    // (2s^3 - 3s^2 + 1) 1 + (s^3 - 2s^2 + s) 1 + (-2s^3 + 3s^2) 3 + (s^3 - s^2) 2
    // = 0.5 + 0.125 + 1.5 - 0.25 = 1.875. Every vertex follows the hip (the knee is its child):
    // scaled about the origin.
    let v = posed(&m, "grow", 0.5, Playback::Clamp);
    let want: Vec<Vec3> = m.mesh.positions.iter().map(|p| *p * 1.875).collect();
    assert_close(&v, &want, "cubic spline at 0.5");
}

#[test]
fn glb_and_external_buffers_read_the_same() {
    let gltf = two_joints(&TwoJoints::default());
    let from_json = load(&gltf);
    let from_glb = SkinnedMesh::from_gltf_slice(&glb(&gltf), Path::new("two_joints.glb"), None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(from_glb, from_json);

    // The buffer in a file beside the glTF.
    let dir = std::env::temp_dir().join(format!("snowprint-skin-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&gltf).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_owned();
    let data = skin_support::decode_data_uri(&uri);
    std::fs::write(dir.join("two_joints.bin"), data).unwrap();
    doc["buffers"][0]["uri"] = json!("two_joints.bin");
    let path = dir.join("two_joints.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let external = SkinnedMesh::load_gltf(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(external, from_json);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn what_cannot_be_posed_is_refused_in_one_sentence() {
    let cases: [(TwoJoints, &str); 6] = [
        (
            TwoJoints {
                joints_1: true,
                ..Default::default()
            },
            "more than 4 influences",
        ),
        (
            TwoJoints {
                morph_target: true,
                ..Default::default()
            },
            "morph targets",
        ),
        (
            TwoJoints {
                joint_index: 7,
                ..Default::default()
            },
            "joint 7, but its skin has 2 joints",
        ),
        (
            TwoJoints {
                times: [1.0, 1.0],
                ..Default::default()
            },
            "key times must increase strictly",
        ),
        (
            TwoJoints {
                knee_matrix: true,
                ..Default::default()
            },
            "whose transform is a matrix",
        ),
        (
            TwoJoints {
                weights_sum_zero: true,
                ..Default::default()
            },
            "every skinned vertex needs a positive weight",
        ),
    ];
    for (case, expect) in cases {
        let e = refusal(&two_joints(&case));
        assert!(e.contains(expect), "{e}");
        assert!(e.starts_with("mesh file two_joints.gltf: "), "{e}");
        assert!(e.contains("; "), "the sentence says what to do: {e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
}

#[test]
fn the_rigged_figure_reads_and_moves() {
    let m =
        SkinnedMesh::load_gltf(&skin_support::rigged_figure()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.mesh.positions.len(), 370);
    assert_eq!(m.mesh.indices.len(), 768);
    assert_eq!(m.joints.len(), 19);
    assert_eq!(m.animations.len(), 1);
    assert_eq!(m.animations[0].duration, 1.25);
    // Unnamed: found by its index.
    assert_eq!(m.animation_index("0"), Some(0));
    // The animation moves the figure: some vertex travels more than 5 cm between 0 and 0.6 s.
    let a = posed(&m, "0", 0.0, Playback::Loop);
    let b = posed(&m, "0", 0.6, Playback::Loop);
    let most = a
        .iter()
        .zip(&b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max);
    assert!(
        most > 0.05,
        "the animation moves vertices by at most {most} m"
    );
    // Standing in glTF's +Y up: about 1.45 m tall, feet at 0.
    let low = a.iter().map(|p| p.y).fold(f32::MAX, f32::min);
    let high = a.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    assert!(
        low.abs() < 0.05 && (high - 1.45).abs() < 0.1,
        "{low} .. {high}"
    );
}
