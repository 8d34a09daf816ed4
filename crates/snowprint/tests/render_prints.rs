//! Image tests of a small print scene: the skinned trudger of `scenes/Trudger.glb` (the demo's body
//! walking, skinned on the GPU each frame) leaves four boot prints, heel, arch and ball, in 0.35 m
//! of snow on a 3 m x 1 m path; rendered at 256x144 in the relief and tessellated tiers without the
//! figure (it has walked off the path) and compared with NVIDIA FLIP against the goldens in
//! `tests/golden/` (`prints_relief.png`, `prints_tessellated.png`; bounds in `tolerances.toml`).
//! The untouched path fails both goldens, so the check sees the prints.
//!
//! `SNOWPRINT_BLESS=1 cargo test --release --test render_prints` writes new goldens (refused when
//! `CI` is set).

mod common;
mod golden_support;

use glam::{Mat4, Quat, Vec3};
use golden_support::{check, score, tolerance};
use snowprint::render::{
    Environment, Instance, MeshMaterial, PointLight, RenderConfig, RenderFrame, RenderOutput,
    Renderer, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, MeshAnimation, Playback, Pose, Shape, SkinnedMesh,
    SnowWorld, SurfaceDesc, SurfaceId, WorldConfig,
};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;
const DT: f32 = 1.0 / 30.0;

struct Scene {
    world: SnowWorld,
    renderer: Renderer,
    path: SurfaceId,
    instances: Vec<Instance>,
}

/// The path, walked for `seconds` (0: untouched).
fn scene(seconds: f32) -> Scene {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    // Its ground 0.1 m under the ground the walk was planned on: the flat sole stops 0.17 m down
    // in the 0.35 m of snow, the heel and ball dig 2 cm more.
    let path = world
        .add_surface(SurfaceDesc::new(
            "path",
            [-1.5, -0.1, 0.0],
            [3.0, 1.0],
            0.35,
        ))
        .expect("path");
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/Trudger.glb");
    let figure = SkinnedMesh::load_gltf(&file).unwrap_or_else(|e| panic!("{e}"));
    let mesh = world.add_skinned_mesh("trudger", &figure).expect("figure");
    let walk = figure.animation_index("walk");
    let deformer = Deformer::new(Shape::Mesh(mesh), Pose::at([0.0; 3]));
    for f in 1..=(seconds / DT).round() as u32 {
        world
            .animate_meshes(&[MeshAnimation {
                mesh,
                animation: walk,
                time: f as f32 * DT,
                playback: Playback::Clamp,
            }])
            .expect("animate");
        world
            .step(DT, std::slice::from_ref(&deformer))
            .expect("step");
    }
    let mut config = RenderConfig::new(WIDTH, HEIGHT, Tier::Relief);
    config.shadow_map_size = 1024;
    let mut renderer = Renderer::new(gpu, config).expect("renderer");
    let block = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .expect("mesh");
    // The roof under the path.
    let instances = vec![
        Instance::new(
            block,
            Mat4::from_scale_rotation_translation(
                Vec3::new(3.4, 1.0, 1.4),
                Quat::IDENTITY,
                Vec3::new(-1.5, -0.6, 0.0),
            ),
            [0.35, 0.17, 0.12],
        )
        .with_material(MeshMaterial::Brick),
    ];
    Scene {
        world,
        renderer,
        path,
        instances,
    }
}

fn render(scene: &mut Scene, tier: Tier) -> RenderOutput {
    scene.renderer.set_tier(tier);
    let lights = [PointLight {
        position: Vec3::new(-2.6, 1.4, 1.0),
        color: Vec3::new(1.0, 0.55, 0.22) * 1.2,
        radius: 5.0,
    }];
    let surfaces = [(scene.path, GroundMaterial::Concrete)];
    let frame = RenderFrame {
        camera: Camera {
            eye: Vec3::new(-1.0, 1.5, 1.5),
            target: Vec3::new(-1.35, 0.15, 0.0),
            fov_y_degrees: 50.0,
        },
        time: 1.0,
        surfaces: &surfaces,
        instances: &scene.instances,
        lights: &lights,
        environment: Environment::moonlit_night(),
        snowfall: false,
    };
    scene.renderer.render(&scene.world, &frame).expect("render")
}

/// The four prints of the first 3.3 s, in both tiers.
#[test]
fn boot_prints_match_their_goldens() {
    let mut scene = scene(3.3);
    for (tier, name) in [
        (Tier::Relief, "prints_relief"),
        (Tier::Tessellated, "prints_tessellated"),
    ] {
        let out = render(&mut scene, tier);
        assert!(out.basic_material_surfaces.is_empty(), "{name}");
        check(name, &out);
    }
}

/// The untouched path scores well past both bounds of both goldens: the check sees the prints.
#[test]
fn the_untouched_path_fails_the_print_goldens() {
    if golden_support::bless() {
        return;
    }
    let mut scene = scene(0.0);
    for (tier, name) in [
        (Tier::Relief, "prints_relief"),
        (Tier::Tessellated, "prints_tessellated"),
    ] {
        let out = render(&mut scene, tier);
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        eprintln!("{name}, untouched: FLIP mean {mean:.5}, p99 {p99:.5}");
        assert!(
            mean > tol.mean || p99 > tol.p99,
            "{name}: the untouched path passes (mean {mean}, p99 {p99})"
        );
    }
}
