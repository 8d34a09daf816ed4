//! GPU skinning against the CPU reference: the skinning pass's vertices at several animation times
//! of the RiggedFigure sample and of the hand-built two-joint file; a figure moved by its
//! deformer's pose captured as the CPU ray cast captures the CPU-skinned mesh; and a figure walked
//! across a surface leaving its prints where its CPU-posed feet are, frame by frame.
//!
//! RiggedFigure's one animation moves its arms, torso and head; its legs keep their pose (the
//! leg joints' keys equal their rest rotations), so the feet move with the deformer's keys only.

mod common;
mod skin_support;

use glam::{Mat4, Quat, Vec2, Vec3};
use snowprint::low_level::capture::CaptureVolume;
use snowprint::reference::capture as cap_cpu;
use snowprint::reference::skin::skin_vertices;
use snowprint::{
    CaptureConfig, CaptureMode, Deformer, MeshAnimation, Playback, Pose, Shape, SkinnedMesh,
    SnowWorld, SurfaceDesc, WorldConfig,
};

/// GPU and CPU skinned positions agree to 1e-5 m. Both blend the same f32 joint matrices (the GPU
/// sums the weighted matrices, then transforms; the CPU transforms, then sums the weighted
/// points): about 20 roundings of values below 2 m, each at most 2^-23 x 2 m = 2.4e-7 m, so under
/// 5e-6 m; 1e-5 m is a hundredth of a millimetre, far below a texel (a few millimetres) and far
/// below what a wrong joint, weight or time moves a vertex (centimetres, checked below).
const SKIN_TOLERANCE: f32 = 1e-5;

const ANKLE: f32 = 0.25;

fn world() -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            capture: CaptureConfig {
                mode: CaptureMode::Depth,
                ankle_height: ANKLE,
                mask_depth: 0.6,
            },
            pool_bytes: 16 << 20,
            ..Default::default()
        },
    )
    .unwrap()
}

fn figure() -> SkinnedMesh {
    SkinnedMesh::load_gltf(&skin_support::rigged_figure()).unwrap_or_else(|e| panic!("{e}"))
}

fn cpu_posed(m: &SkinnedMesh, t: f32) -> Vec<Vec3> {
    let joints = m.pose(Some(0), t, Playback::Loop);
    skin_vertices(&m.mesh.positions, &m.influences, &joints)
}

fn largest_gap(a: &[Vec3], b: &[Vec3]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

#[test]
fn gpu_skinning_matches_the_cpu_reference_at_several_times() {
    let mut w = world();
    let m = figure();
    let id = w.add_skinned_mesh("figure", &m).unwrap();
    // Before any pose, the buffer holds the rest pose.
    let rest = skin_vertices(
        &m.mesh.positions,
        &m.influences,
        &m.pose(None, 0.0, Playback::Clamp),
    );
    assert!(largest_gap(&w.read_skinned_vertices(id).unwrap(), &rest) <= SKIN_TOLERANCE);
    // Times across the 1.25 s animation, one past its end (looped to 0.75 s).
    let mut previous: Option<Vec<Vec3>> = None;
    for t in [0.0, 0.31, 0.625, 1.1, 2.0] {
        w.animate_meshes(&[MeshAnimation {
            mesh: id,
            animation: Some(0),
            time: t,
            playback: Playback::Loop,
        }])
        .unwrap();
        let gpu = w.read_skinned_vertices(id).unwrap();
        let cpu = cpu_posed(&m, t);
        let gap = largest_gap(&gpu, &cpu);
        assert!(
            gap <= SKIN_TOLERANCE,
            "t = {t}: GPU and CPU differ by {gap} m"
        );
        // The comparison can fail: the pose at another time is centimetres away.
        if let Some(p) = previous {
            assert!(
                largest_gap(&gpu, &p) > 0.01,
                "t = {t} looks like the time before"
            );
        }
        previous = Some(cpu);
    }
}

#[test]
fn gpu_skinning_matches_the_hand_computed_two_joint_file() {
    let mut w = world();
    let bytes = skin_support::two_joints(&skin_support::TwoJoints::default());
    let m = SkinnedMesh::from_gltf_slice(&bytes, std::path::Path::new("two.gltf"), None).unwrap();
    let id = w.add_skinned_mesh("two joints", &m).unwrap();
    w.animate_meshes(&[MeshAnimation {
        mesh: id,
        animation: m.animation_index("bend"),
        time: 1.0,
        playback: Playback::Clamp,
    }])
    .unwrap();
    // As derived in tests/skinning.rs: hip at (2, 0, 0), knee turned 45 degrees about Z.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let knee = Vec3::new(2.0, 1.0, 0.0);
    let want = [
        Vec3::new(2.0, 0.5, 0.0),
        knee + Vec3::new(-0.5 * s, 0.5 * s, 0.0),
        (Vec3::new(3.0, 1.5, 0.0) + knee + Vec3::new(0.5 * s, 1.5 * s, 0.0)) * 0.5,
    ];
    let gap = largest_gap(&w.read_skinned_vertices(id).unwrap(), &want);
    assert!(gap <= SKIN_TOLERANCE, "{gap}");
    // Explicit joint matrices of the wrong count are refused.
    let e = w.skin_meshes(&[(id, &[Mat4::IDENTITY][..])]).unwrap_err();
    assert!(
        matches!(
            e,
            snowprint::SnowError::JointCount {
                got: 1,
                expected: 2,
                ..
            }
        ),
        "{e:?}"
    );
}

fn volume(desc: &SurfaceDesc) -> CaptureVolume {
    CaptureVolume {
        world_to_local: desc.world_to_local(),
        half_size: desc.size * 0.5,
        frustum_height: desc.snow_depth + ANKLE,
        ground: (0.0, 0.0),
    }
}

/// The CPU capture of `vertices` (mesh space) placed by `pose`.
fn cpu_capture(desc: &SurfaceDesc, m: &SkinnedMesh, vertices: &[Vec3], pose: &Pose) -> Vec<f32> {
    let vol = volume(desc);
    let to_local =
        vol.world_to_local * Mat4::from_rotation_translation(pose.rotation, pose.position);
    let local: Vec<Vec3> = vertices
        .iter()
        .map(|p| to_local.transform_point3(*p))
        .collect();
    let tris: Vec<[Vec3; 3]> = m
        .mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            [
                local[t[0] as usize],
                local[t[1] as usize],
                local[t[2] as usize],
            ]
        })
        .collect();
    let l = desc.layout();
    cap_cpu::capture(
        l.width,
        l.height,
        vol.half_size,
        vol.frustum_height,
        &[],
        &tris,
    )
}

/// GPU and CPU captures agree (`agree`: within 1e-4 of what the ray cast gives at the texel or
/// with the figure moved by the rasteriser's coarsest sub-texel step) except on texels whose
/// centre lies on a triangle's edge, and there the GPU's value is one the ray cast finds within a
/// texel of it (as `tests/gpu_core.rs` checks mesh captures); at most 2 % of the touched texels
/// may differ.
fn assert_captures_agree(
    gpu: &[f32],
    cpu: &[f32],
    agree: &[bool],
    width: u32,
    height: u32,
    what: &str,
) {
    let mut mismatch = 0;
    for row in 0..height {
        for col in 0..width {
            let i = (row * width + col) as usize;
            let (g, c) = (gpu[i], cpu[i]);
            if agree[i] {
                continue;
            }
            mismatch += 1;
            let mut range = (f32::MAX, f32::MIN);
            for dr in -1i32..=1 {
                for dc in -1i32..=1 {
                    let (r, q) = (row as i32 + dr, col as i32 + dc);
                    if r >= 0 && q >= 0 && (r as u32) < height && (q as u32) < width {
                        let v = cpu[(r as u32 * width + q as u32) as usize];
                        range = (range.0.min(v), range.1.max(v));
                    }
                }
            }
            assert!(
                g >= range.0 - 1e-4 && g <= range.1 + 1e-4,
                "{what}: texel ({col}, {row}): GPU {g}, ray cast {c}, neighbours {range:?}"
            );
        }
    }
    let touched = cpu.iter().filter(|&&c| c < 1.0).count();
    assert!(
        touched > 20,
        "{what}: the figure touches only {touched} texels"
    );
    assert!(
        mismatch * 50 <= touched,
        "{what}: {mismatch} of {touched} touched texels differ"
    );
}

/// The figure's feet a few centimetres above the ground at every time sampled: the height of the
/// pose's origin above the ground.
fn standing_height(m: &SkinnedMesh, times: &[f32]) -> f32 {
    let lowest = times
        .iter()
        .flat_map(|&t| cpu_posed(m, t))
        .map(|p| p.y)
        .fold(f32::MAX, f32::min);
    0.05 - lowest
}

#[test]
fn a_figure_moved_by_its_pose_is_captured_as_the_cpu_skinned_mesh() {
    let mut w = world();
    // Snow 1.3 m deep (the frustum 1.55 m high) holds the whole 1.45 m figure: RiggedFigure's
    // animation moves its arms, torso and head, and leaves its legs as they are.
    let desc = SurfaceDesc::new("roof", [1.0, 10.0, -0.5], [3.0, 2.5], 1.3);
    let surface = w.add_surface(desc.clone()).unwrap();
    let m = figure();
    let id = w.add_skinned_mesh("figure", &m).unwrap();
    let times = [0.2, 0.9];
    let lift = standing_height(&m, &times);
    let l = desc.layout();
    for (k, &t) in times.iter().enumerate() {
        // Keyed poses: two places on the roof, the figure turned about Y differently at each.
        let pose = Pose {
            position: Vec3::new(0.4 + 1.0 * k as f32, 10.0 + lift, -0.3 - 0.3 * k as f32),
            rotation: Quat::from_rotation_y(0.7 + 1.9 * k as f32),
        };
        w.animate_meshes(&[MeshAnimation {
            mesh: id,
            animation: Some(0),
            time: t,
            playback: Playback::Loop,
        }])
        .unwrap();
        w.step(1.0 / 60.0, &[Deformer::new(Shape::Mesh(id), pose)])
            .unwrap();
        let gpu = w.read_last_capture(surface).unwrap().expect("captured");
        let posed = cpu_posed(&m, t);
        let cpu = cpu_capture(&desc, &m, &posed, &pose);
        // The rasteriser places a triangle's corners on a grid of 1/16 texel at the coarsest
        // Vulkan allows (4 sub-pixel bits): the ray cast with the figure moved that much each way
        // along x and z gives the heights a GPU may rightly write (on steep triangles, more than
        // the 1e-4 of a frustum's height allowed below; an H100 wrote 9 of 89 texels there).
        let nudge = desc.size.x / l.width as f32 / 16.0;
        let nudged: Vec<Vec<f32>> = [
            Vec3::new(nudge, 0.0, 0.0),
            Vec3::new(-nudge, 0.0, 0.0),
            Vec3::new(0.0, 0.0, nudge),
            Vec3::new(0.0, 0.0, -nudge),
        ]
        .iter()
        .map(|&by| {
            let moved = Pose {
                position: pose.position + by,
                ..pose
            };
            cpu_capture(&desc, &m, &posed, &moved)
        })
        .collect();
        let agree: Vec<bool> = gpu
            .iter()
            .enumerate()
            .map(|(i, &g)| {
                std::iter::once(cpu[i])
                    .chain(nudged.iter().map(|n| n[i]))
                    .filter(|&c| (c < 1.0) == (g < 1.0))
                    .fold(None, |r: Option<(f32, f32)>, c| {
                        Some(r.map_or((c, c), |(lo, hi)| (lo.min(c), hi.max(c))))
                    })
                    .is_some_and(|(lo, hi)| g >= lo - 1e-4 && g <= hi + 1e-4)
            })
            .collect();
        assert_captures_agree(&gpu, &cpu, &agree, l.width, l.height, &format!("t = {t}"));
        // Against the rest pose instead, the capture differs: the animation is what was drawn.
        let rest = m.pose(None, 0.0, Playback::Clamp);
        let stale = cpu_capture(
            &desc,
            &m,
            &skin_vertices(&m.mesh.positions, &m.influences, &rest),
            &pose,
        );
        let differ = gpu
            .iter()
            .zip(&stale)
            .filter(|(g, s)| (*g - *s).abs() > 1e-3)
            .count();
        assert!(
            differ > 10,
            "t = {t}: only {differ} texels tell the pose from the rest pose"
        );
    }
}

/// Texel centres (surface-local x, z) of every texel whose capture is below 1 (touched).
fn touched(capture: &[f32], desc: &SurfaceDesc) -> Vec<(Vec2, f32)> {
    let l = desc.layout();
    let half = desc.size * 0.5;
    (0..l.height)
        .flat_map(|row| (0..l.width).map(move |col| (row, col)))
        .filter_map(|(row, col)| {
            let d = capture[(row * l.width + col) as usize];
            (d < 1.0).then(|| (cap_cpu::texel_center(col, row, l.width, l.height, half), d))
        })
        .collect()
}

#[test]
fn a_walking_figure_prints_where_its_feet_are() {
    let mut w = world();
    let desc = SurfaceDesc::new("roof", [0.0, 5.0, 0.0], [4.0, 2.0], 0.3);
    let surface = w.add_surface(desc.clone()).unwrap();
    let m = figure();
    let id = w.add_skinned_mesh("walker", &m).unwrap();
    let dt = 1.0 / 10.0;
    let times: Vec<f32> = (0..12).map(|f| f as f32 * dt).collect();
    let lift = standing_height(&m, &times);
    let vol = volume(&desc);
    let texel = desc.size.x / desc.layout().width as f32;
    for &t in &times {
        // Keys: walking along +x at 1 m/s, facing +x.
        let pose = Pose {
            position: Vec3::new(-1.2 + t, 5.0 + lift, 0.1),
            rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        };
        w.animate_meshes(&[MeshAnimation {
            mesh: id,
            animation: Some(0),
            time: t,
            playback: Playback::Loop,
        }])
        .unwrap();
        w.step(dt, &[Deformer::new(Shape::Mesh(id), pose)]).unwrap();
        let gpu = w.read_last_capture(surface).unwrap().expect("captured");
        let prints = touched(&gpu, &desc);
        // The CPU-posed vertices in the surface's frame; those inside the capture volume are the
        // feet and ankles.
        let to_local =
            vol.world_to_local * Mat4::from_rotation_translation(pose.rotation, pose.position);
        let local: Vec<Vec3> = cpu_posed(&m, t)
            .iter()
            .map(|p| to_local.transform_point3(*p))
            .collect();
        let feet: Vec<Vec3> = local
            .iter()
            .copied()
            .filter(|p| p.y < vol.frustum_height)
            .collect();
        assert!(
            !feet.is_empty() && !prints.is_empty(),
            "t = {t}: no feet or no prints"
        );
        // Every print texel lies under the feet: within the feet's extent, plus a texel.
        let lo = feet
            .iter()
            .fold(Vec2::MAX, |a, p| a.min(Vec2::new(p.x, p.z)));
        let hi = feet
            .iter()
            .fold(Vec2::MIN, |a, p| a.max(Vec2::new(p.x, p.z)));
        for (c, _) in &prints {
            assert!(
                c.cmpge(lo - texel).all() && c.cmple(hi + texel).all(),
                "t = {t}: a print at {c} lies outside the feet's extent {lo} .. {hi}"
            );
        }
        // The lowest vertex has a print texel within a texel and a half of it, and the deepest
        // print is as low as the lowest vertex (to the 2 cm a sole's slope can change over a
        // texel), never lower.
        let lowest = local
            .iter()
            .copied()
            .min_by(|a, b| a.y.total_cmp(&b.y))
            .unwrap();
        let near = prints
            .iter()
            .map(|(c, _)| c.distance(Vec2::new(lowest.x, lowest.z)))
            .fold(f32::MAX, f32::min);
        assert!(
            near <= 1.5 * texel,
            "t = {t}: the lowest vertex {lowest} is {near} m from a print"
        );
        let deepest = prints.iter().map(|p| p.1).fold(1.0, f32::min) * vol.frustum_height;
        assert!(
            deepest >= lowest.y - 1e-3 && deepest <= lowest.y + 0.02,
            "t = {t}: deepest print at {deepest} m, lowest vertex at {} m",
            lowest.y
        );
    }
}

/// In an engine's frame: the skinning recorded into the caller's encoder ahead of the step leaves
/// the vertices and the print that `animate_meshes` then `step` leave; while the frame is pending
/// another skinning is refused.
#[test]
fn skinning_recorded_into_the_callers_encoder_equals_the_wrapper() {
    let gpu = common::gpu();
    let m = figure();
    let desc = SurfaceDesc::new("roof", [0.0, 0.0, 0.0], [3.0, 3.0], 0.3);
    let mut results = Vec::new();
    for encoded in [false, true] {
        let mut w = world();
        let id = w.add_skinned_mesh("figure", &m).unwrap();
        let roof = w.add_surface(desc.clone()).unwrap();
        let pose = MeshAnimation {
            mesh: id,
            animation: Some(0),
            time: 0.4,
            playback: Playback::Loop,
        };
        let foot = Deformer::new(Shape::Mesh(id), Pose::at([0.0, 0.1, 0.0]));
        if encoded {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            w.encode_animate_meshes(&mut enc, &[pose]).unwrap();
            let pending = w.encode_step(&mut enc, 1.0 / 60.0, &[foot]).unwrap();
            assert!(matches!(
                w.encode_animate_meshes(&mut enc, &[pose]),
                Err(snowprint::SnowError::FramePending)
            ));
            gpu.queue.submit([enc.finish()]);
            w.submitted(pending).unwrap();
        } else {
            w.animate_meshes(&[pose]).unwrap();
            w.step(1.0 / 60.0, &[foot]).unwrap();
        }
        results.push((
            w.read_skinned_vertices(id).unwrap(),
            w.read_channels(roof).unwrap(),
        ));
    }
    assert_eq!(results[0].0, results[1].0);
    assert_eq!(results[0].1, results[1].1);
    assert!(
        results[0].1.0.iter().any(|&d| d > 0),
        "the figure pressed the roof"
    );
}
