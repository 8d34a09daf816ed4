//! The demo's body as a skinned glTF (`snowprint_demo::export`, `scenes/Trudger.glb`): the file is
//! what the exporter writes; loaded by the library's glTF loader and posed on the CPU at its keys it
//! is the demo's part meshes posed by the same motion; and walked across snow as one skinned mesh
//! deformer, posed on the GPU each frame, it leaves the prints the fifteen part shapes leave, each
//! with a heel and a ball either side of the arch.

mod common;

use glam::Vec3;
use snowprint::reference::skin::skin_vertices;
use snowprint::{
    Deformer, Heightmap, MeshAnimation, MeshId, Playback, Pose, Shape, SkinnedMesh, SnowWorld,
    SurfaceDesc, SurfaceUpdate, WorldConfig,
};
use snowprint_demo::anim::Footfall;
use snowprint_demo::export::{KEYS_PER_SECOND, TRUDGER_SECONDS, trudger_glb, trudger_motion};
use snowprint_demo::skeleton::part_mesh;
use snowprint_demo::{DemoSurface, DemoWorld, Part};

const DT: f32 = 1.0 / 30.0;

fn committed() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/Trudger.glb")
}

fn trudger() -> SkinnedMesh {
    SkinnedMesh::from_gltf_slice(&trudger_glb(), std::path::Path::new("Trudger.glb"), None)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_committed_trudger_is_what_the_exporter_writes() {
    let made = trudger_glb();
    if std::env::var("SNOWPRINT_BLESS").is_ok_and(|v| v == "1") && std::env::var_os("CI").is_none()
    {
        std::fs::write(committed(), &made).expect("write scenes/Trudger.glb");
    }
    let file = std::fs::read(committed()).expect("scenes/Trudger.glb");
    assert!(
        file == made,
        "scenes/Trudger.glb differs from what snowprint_demo::export::trudger_glb writes; \
         rewrite it with SNOWPRINT_BLESS=1 cargo test -p snowprint-demo --test skinned_export"
    );
    let m = SkinnedMesh::load_gltf(&committed()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.animation_index("walk"), Some(0));
    assert_eq!(m.joints.len(), 15);
}

/// At every key the loaded figure, skinned on the CPU by the library's reference, is the demo's
/// part meshes posed by the motion (forward kinematics of `BodyPose::world`), to 2e-5 m: both are
/// a rotation and a translation of the same f32 vertices, through a few more roundings on the
/// skinned side (bind, inverse bind, joint chain), each below 1e-6 m at these sizes.
#[test]
fn the_loaded_figure_poses_as_the_parts_do() {
    let m = trudger();
    let motion = trudger_motion();
    let walk = m.animation_index("walk").expect("walk");
    for key in [0, 13, 42, 75, 118, 160, 210] {
        let t = key as f32 / KEYS_PER_SECOND as f32;
        let joints = m.pose(Some(walk), t, Playback::Clamp);
        let skinned = skin_vertices(&m.mesh.positions, &m.influences, &joints);
        let world = motion.pose(t).world();
        let parts: Vec<Vec3> = Part::ALL
            .iter()
            .flat_map(|&p| {
                let w = world[p.index()];
                part_mesh(p)
                    .positions
                    .into_iter()
                    .map(move |v| w.position + w.rotation * v)
            })
            .collect();
        assert_eq!(skinned.len(), parts.len());
        let gap = skinned
            .iter()
            .zip(&parts)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f32::max);
        assert!(gap < 2e-5, "t = {t}: a vertex is {gap} m from its part's");
    }
}

/// A surface 8 m x 2 m, 4 cm texels, its ground 0.1 m under the ground the walk plans on, with
/// 0.35 m of snow (as the boot's test, tests/footprint.rs).
fn surface() -> SurfaceDesc {
    SurfaceDesc::new("print", [0.0, -0.1, 0.0], [8.0, 2.0], 0.35)
}

/// The walk pressed by the fifteen part shapes, each swept from its pose a frame ago.
fn pressed_by_parts(desc: &SurfaceDesc) -> Heightmap {
    let mut demo = DemoWorld::build();
    let mut person = demo.people[0].clone();
    person.motion = trudger_motion();
    demo.people = vec![person];
    demo.surfaces = vec![DemoSurface {
        desc: desc.clone(),
        ground: Default::default(),
    }];
    let mut world = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
    let id = world.add_surface(desc.clone()).expect("surface");
    let parts: Vec<MeshId> = demo
        .part_meshes
        .iter()
        .zip(Part::ALL)
        .map(|(m, p)| world.add_mesh(p.name(), m).expect("part"))
        .collect();
    let ankle = snowprint::CaptureConfig::default().ankle_height;
    for f in 1..=frames() {
        let sorted = demo.surface_deformers(f as f32 * DT, DT, &parts, ankle);
        let updates: Vec<SurfaceUpdate<'_>> = sorted
            .iter()
            .map(|(_, d)| SurfaceUpdate {
                surface: id,
                elapsed: DT,
                deformers: d,
            })
            .collect();
        world.update(&updates).expect("update");
    }
    world.read_heightmap(id).expect("readback")
}

/// The walk pressed by the one skinned mesh, skinned on the GPU at each frame's time.
fn pressed_by_skin(desc: &SurfaceDesc) -> Heightmap {
    let mut world = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
    let id = world.add_surface(desc.clone()).expect("surface");
    let m = trudger();
    let mesh = world.add_skinned_mesh("trudger", &m).expect("skinned");
    let figure = Deformer::new(Shape::Mesh(mesh), Pose::at([0.0; 3]));
    for f in 1..=frames() {
        world
            .animate_meshes(&[MeshAnimation {
                mesh,
                animation: m.animation_index("walk"),
                time: f as f32 * DT,
                playback: Playback::Clamp,
            }])
            .expect("animate");
        world.step(DT, std::slice::from_ref(&figure)).expect("step");
    }
    world.read_heightmap(id).expect("readback")
}

fn frames() -> u32 {
    (TRUDGER_SECONDS / DT) as u32
}

/// Depression (fraction of the snow) along a print's axis, -30 cm to +36 cm of its ankle.
fn profile(desc: &SurfaceDesc, map: &Heightmap, f: &Footfall) -> Vec<(f32, f32)> {
    let texel = desc.size.x / map.width as f32;
    let local = desc.world_to_local().transform_point3(f.ankle);
    let row = ((local.z + 0.5 * desc.size.y) / texel).floor() as u32;
    (0..map.width)
        .filter_map(|col| {
            let x = -0.5 * desc.size.x + (col as f32 + 0.5) * texel - local.x;
            (-0.3..=0.36)
                .contains(&x)
                .then(|| (x, map.fraction(col, row)))
        })
        .collect()
}

fn deepest(p: &[(f32, f32)], lo: f32, hi: f32) -> f32 {
    p.iter()
        .filter(|(x, _)| (lo..=hi).contains(x))
        .map(|s| s.1)
        .fold(-1.0, f32::max)
}

#[test]
fn the_skinned_figure_leaves_the_prints_of_its_parts() {
    let desc = surface();
    let (parts, skin) = (pressed_by_parts(&desc), pressed_by_skin(&desc));
    let bounds: serde_json::Value =
        serde_json::from_str(include_str!("skinned_export.json")).expect("skinned_export.json");
    let bound = |k: &str| bounds[k].as_f64().unwrap_or_else(|| panic!("{k}")) as f32;
    // Texel for texel: the same body, posed at the frame's end (the skin) or swept from the
    // frame's start (the parts), presses nearly the same snow.
    let diffs: Vec<f32> = (0..skin.height)
        .flat_map(|r| (0..skin.width).map(move |c| (c, r)))
        .map(|(c, r)| (skin.fraction(c, r) - parts.fraction(c, r)).abs())
        .collect();
    let worst = diffs.iter().copied().fold(0.0, f32::max);
    let off = diffs.iter().filter(|&&d| d > 0.05).count() as f32 / diffs.len() as f32;
    let pressed = (0..skin.height)
        .flat_map(|r| (0..skin.width).map(move |c| (c, r)))
        .filter(|&(c, r)| skin.fraction(c, r) > 0.05)
        .count();
    println!(
        "skin vs parts: worst {worst:.3}, {:.2} % of texels differ by more than 0.05; {pressed} texels pressed",
        100.0 * off
    );
    assert!(
        pressed > 400,
        "the skinned figure pressed only {pressed} texels"
    );
    assert!(worst <= bound("worst_texel"), "a texel differs by {worst}");
    assert!(
        off <= bound("differing_fraction"),
        "{off} of the texels differ by more than 0.05"
    );
    // Every print of the crossing, struck and lifted: a heel and a ball deeper than the arch.
    let demo_prints: Vec<Footfall> = trudger_motion()
        .footfalls()
        .into_iter()
        .filter(|f| f.strike.is_finite() && f.lift.is_finite())
        .collect();
    assert!(demo_prints.len() >= 8, "{} prints", demo_prints.len());
    for f in &demo_prints {
        let (s, p) = (profile(&desc, &skin, f), profile(&desc, &parts, f));
        let heel = deepest(&s, -0.12, 0.0);
        let ball = deepest(&s, 0.10, 0.22);
        let arch = s
            .iter()
            .filter(|(x, _)| (0.02..=0.08).contains(x))
            .map(|s| s.1)
            .fold(2.0, f32::min);
        assert!(
            heel - arch >= bound("heel_over_arch") && ball - arch >= bound("ball_over_arch"),
            "print at {}: heel {heel}, arch {arch}, ball {ball}",
            f.ankle
        );
        let (ph, pb) = (deepest(&p, -0.12, 0.0), deepest(&p, 0.10, 0.22));
        assert!(
            (heel - ph).abs() <= bound("print_depth") && (ball - pb).abs() <= bound("print_depth"),
            "print at {}: skin heel {heel} ball {ball}, parts heel {ph} ball {pb}",
            f.ankle
        );
    }
}
