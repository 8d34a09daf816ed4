//! Skinned meshes under the manager: a surface the budget leaves waiting is pressed later frame by
//! frame, and each queued frame must press with the pose the figure had in that frame. The skinned
//! trudger of `scenes/Trudger.glb` crosses a path while balls roll on three roofs; with one update
//! a frame the four take turns, so the path catches up several frames at a time. It must end
//! texel for texel as with no budget; pressed in its rest pose (not animated) it leaves something
//! else; and the manager's CPU-posed figure presses what a plain world's GPU-skinned one does.

mod common;

use snowprint::manager::{ManagedDeformer, ManagerConfig, SnowManager, UNLIMITED, ZoneId};
use snowprint::{
    Deformer, Heightmap, MeshAnimation, Playback, Pose, Shape, SkinnedMesh, SnowWorld, SurfaceDesc,
    WorldConfig,
};

const DT: f32 = 1.0 / 30.0;
const FRAMES: u32 = 99;

fn figure() -> SkinnedMesh {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/Trudger.glb");
    SkinnedMesh::load_gltf(&file).unwrap_or_else(|e| panic!("{e}"))
}

fn path() -> SurfaceDesc {
    SurfaceDesc::new("path", [-1.5, -0.1, 0.0], [3.0, 1.0], 0.35)
}

/// Three roofs beside the path, a ball rolling on each.
fn roof(k: u32) -> SurfaceDesc {
    SurfaceDesc::new(
        &format!("roof {k}"),
        [6.0, 0.0, 3.0 * k as f32],
        [2.0, 2.0],
        0.2,
    )
}

fn ball(k: u32, f: u32) -> ManagedDeformer {
    let at = |f: u32| Pose::at([5.2 + 1.6 * f as f32 / FRAMES as f32, 0.12, 3.0 * k as f32]);
    ManagedDeformer::new(Deformer::moving(
        Shape::Sphere { radius: 0.12 },
        at(f.saturating_sub(1)),
        at(f),
    ))
}

/// The path after the walk under a manager with `updates` updates a frame; `animate`: pose the
/// figure each frame (else it presses in its rest pose).
fn managed(updates: usize, animate: bool) -> Heightmap {
    let mut m = SnowManager::new(
        common::gpu(),
        ManagerConfig {
            updates_per_frame: updates,
            pool_bytes: 8 << 20,
            active_distance: 500.0,
            ..Default::default()
        },
    )
    .expect("manager");
    let id = m.add_surface(path(), ZoneId(0)).expect("path");
    for k in 0..3 {
        m.add_surface(roof(k), ZoneId(0)).expect("roof");
    }
    let skinned = figure();
    let mesh = m.add_skinned_mesh("trudger", &skinned).expect("figure");
    let walk = skinned.animation_index("walk");
    let trudger = Deformer::new(Shape::Mesh(mesh), Pose::at([0.0; 3]));
    let mut waited = 0;
    for f in 1..=FRAMES {
        if animate {
            m.animate_meshes(&[MeshAnimation {
                mesh,
                animation: walk,
                time: f as f32 * DT,
                playback: Playback::Clamp,
            }])
            .expect("animate");
        }
        let stats = m
            .tick(
                DT,
                None,
                &[
                    ManagedDeformer::new(trudger),
                    ball(0, f),
                    ball(1, f),
                    ball(2, f),
                ],
            )
            .expect("tick");
        waited = waited.max(stats.max_wait_frames);
    }
    if updates == 1 {
        assert!(waited >= 2, "the path never waited: {waited}");
    }
    m.flush().expect("flush");
    m.read_heightmap(id).expect("read")
}

/// The same walk in a plain world, the figure skinned on the GPU.
fn world() -> Heightmap {
    let mut w = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
    let id = w.add_surface(path()).expect("path");
    let skinned = figure();
    let mesh = w.add_skinned_mesh("trudger", &skinned).expect("figure");
    let trudger = Deformer::new(Shape::Mesh(mesh), Pose::at([0.0; 3]));
    for f in 1..=FRAMES {
        w.animate_meshes(&[MeshAnimation {
            mesh,
            animation: skinned.animation_index("walk"),
            time: f as f32 * DT,
            playback: Playback::Clamp,
        }])
        .expect("animate");
        w.step(DT, std::slice::from_ref(&trudger)).expect("step");
    }
    w.read_heightmap(id).expect("read")
}

/// Texels differing by more than 0.05 of the depth, and the most any differs.
fn differ(a: &Heightmap, b: &Heightmap) -> (usize, f32) {
    let d: Vec<f32> = (0..a.height)
        .flat_map(|r| (0..a.width).map(move |c| (c, r)))
        .map(|(c, r)| (a.fraction(c, r) - b.fraction(c, r)).abs())
        .collect();
    (
        d.iter().filter(|&&x| x > 0.05).count(),
        d.iter().copied().fold(0.0, f32::max),
    )
}

#[test]
fn a_waiting_path_is_pressed_with_each_frames_pose() {
    let free = managed(UNLIMITED, true);
    let budgeted = managed(1, true);
    // Frame by frame, the waiting path goes through the steps the free one took. A mesh is
    // rasterised wherever its surface lands in the capture atlas, which differs between the runs
    // (other surfaces share the batch), so a texel may round one unit (of 65535) the other way;
    // a pose a frame late moves a texel by thousands.
    let units = |m: &Heightmap| -> Vec<i32> { m.depression.iter().map(|&d| d as i32).collect() };
    let (b, f) = (units(&budgeted), units(&free));
    let worst = b
        .iter()
        .zip(&f)
        .map(|(x, y)| (x - y).abs())
        .max()
        .unwrap_or(0);
    let moved = b.iter().zip(&f).filter(|(x, y)| x != y).count();
    assert!(
        worst <= 2 && moved * 50 < b.len(),
        "the path caught up frame by frame differs from the path updated every frame: {moved} texels, by up to {worst} units"
    );
    let pressed = (0..free.height)
        .flat_map(|r| (0..free.width).map(move |c| (c, r)))
        .filter(|&(c, r)| free.fraction(c, r) > 0.05)
        .count();
    assert!(pressed > 150, "the walk pressed {pressed} texels");
    // In the rest pose the figure stands at the path's end and slides nowhere: another trail.
    let (rest, _) = differ(&managed(1, false), &free);
    assert!(
        rest > pressed / 2,
        "the rest pose differs in only {rest} of {pressed} texels"
    );
    // The CPU-posed figure presses what the GPU-skinned one does, to the rounding of a vertex
    // (the two skin the same f32 matrices in another order: 1e-5 m, far under a texel).
    let (off, worst) = differ(&free, &world());
    assert!(
        off == 0 && worst < 0.05,
        "manager and world differ: {off} texels over 0.05, worst {worst}"
    );
}
