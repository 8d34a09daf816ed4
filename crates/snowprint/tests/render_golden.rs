//! Image tests of the renderer: a fixed small scene (a concrete roof with prints, a trench and a
//! body-sized dent, a tiled roof with a crater to the tiles, and an untouched roof on the basic
//! material) rendered at 256x144 for each tier and compared with NVIDIA FLIP against the goldens in
//! `tests/golden/`. The largest FLIP error each test allows is data, in `tests/golden/tolerances.toml`.
//!
//! On failure the FLIP error map and the image rendered are written to `target/golden-diff/`.
//! `SNOWPRINT_BLESS=1 cargo test --release --test render_golden` writes new goldens instead (refused
//! when `CI` is set). Each test has a tight bound for the goldens' own driver (lavapipe, as in CI) and
//! a looser one for any other; `broken_renders_fail_the_golden_check` shows which broken looks each
//! can see.

mod common;
mod golden_support;

use glam::{Mat4, Quat, Vec3};
use golden_support::{bless, check, same_driver, score, tolerance};
use snowprint::render::{
    Environment, Instance, MeshMaterial, PointLight, RenderConfig, RenderFrame, RenderOutput,
    Renderer, SnowLook, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    WorldConfig,
};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;

struct Scene {
    world: SnowWorld,
    renderer: Renderer,
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
    fresh: SurfaceId,
    instances: Vec<Instance>,
    /// A person standing beside the trench (capsule and head), for the grazing view.
    person: Vec<Instance>,
}

/// The fixed scene: deformed over 8 steps of 1/30 s.
fn scene() -> Scene {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let roof = world
        .add_surface(SurfaceDesc::new("roof", [0.0, 2.0, 0.0], [4.0, 3.0], 0.15))
        .expect("roof");
    let tiles = world
        .add_surface(SurfaceDesc::new("tiles", [3.7, 1.6, 0.0], [3.0, 3.0], 0.12))
        .expect("tiles");
    let fresh = world
        .add_surface(SurfaceDesc::new(
            "fresh",
            [-3.6, 1.8, 0.0],
            [3.0, 3.0],
            0.15,
        ))
        .expect("fresh");

    let mut config = RenderConfig::new(WIDTH, HEIGHT, Tier::Relief);
    config.shadow_map_size = 1024;
    let mut renderer = Renderer::new(gpu, config).expect("renderer");
    let block = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .expect("mesh");
    let ball = renderer
        .add_mesh(&Mesh::uv_sphere(0.3, 12, 24))
        .expect("mesh");
    let body = renderer
        .add_mesh(&Mesh::capsule(0.15, 0.55, 8, 16))
        .expect("mesh");

    let lying = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let steps = 8;
    for k in 0..steps {
        let u0 = k as f32 / steps as f32;
        let u1 = (k + 1) as f32 / steps as f32;
        let slide = |u: f32| Pose {
            position: Vec3::new(-1.4 + 2.4 * u, 2.12, -0.7),
            rotation: lying,
        };
        let mut d = vec![
            // A body sliding feet-first: a trench to the ground.
            Deformer::moving(
                Shape::Capsule {
                    radius: 0.15,
                    half_height: 0.55,
                },
                slide(u0),
                slide(u1),
            ),
            // A ball dropped onto the tiles, pressed to the tiles.
            Deformer::moving(
                Shape::Sphere { radius: 0.3 },
                Pose::at([3.6, 2.3 - 0.4 * u0, 0.3]),
                Pose::at([3.6, 2.3 - 0.4 * u1, 0.3]),
            ),
        ];
        // Boot prints: flat soles pressed to the ground.
        for i in 0..5 {
            let side = if i % 2 == 0 { 0.1 } else { -0.1 };
            d.push(Deformer::new(
                Shape::Box {
                    half_extents: Vec3::new(0.13, 0.03, 0.05),
                },
                Pose::at([-1.3 + 0.55 * i as f32, 2.0, 0.6 + side]),
            ));
        }
        world.step(1.0 / 30.0, &d).expect("step");
    }
    let instances = vec![
        Instance::new(
            block,
            Mat4::from_scale_rotation_translation(
                Vec3::new(4.6, 2.0, 3.6),
                Quat::IDENTITY,
                Vec3::new(0.0, 1.0, 0.0),
            ),
            [0.35, 0.17, 0.12],
        )
        .with_material(MeshMaterial::Brick),
        // The ball, thrown off its crater onto the concrete roof's edge.
        Instance::new(
            ball,
            Mat4::from_translation(Vec3::new(2.3, 2.3, 1.1)),
            [0.5, 0.08, 0.06],
        ),
        Instance::new(
            body,
            Mat4::from_rotation_translation(lying, Vec3::new(1.0, 2.12, -0.7)),
            [0.12, 0.2, 0.4],
        ),
    ];
    // A person standing on the snow beside the trench, in the moon's way: their shadow falls
    // across the trench and its bank.
    let person = vec![
        Instance::new(
            body,
            Mat4::from_translation(Vec3::new(0.2, 2.15 + 0.7, -0.1)),
            [0.25, 0.1, 0.08],
        ),
        Instance::new(
            ball,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(0.45),
                Quat::IDENTITY,
                Vec3::new(0.2, 2.15 + 1.5, -0.1),
            ),
            [0.6, 0.45, 0.35],
        ),
    ];
    Scene {
        world,
        renderer,
        person,
        surfaces: vec![
            (roof, GroundMaterial::Concrete),
            (tiles, GroundMaterial::RoofTiles),
            (fresh, GroundMaterial::RoofTiles),
        ],
        fresh,
        instances,
    }
}

fn render(scene: &mut Scene, tier: Tier) -> RenderOutput {
    let camera = Camera {
        eye: Vec3::new(0.6, 4.6, 4.4),
        target: Vec3::new(0.6, 1.8, -0.1),
        fov_y_degrees: 52.0,
    };
    let instances = scene.instances.clone();
    render_view(scene, tier, camera, &instances)
}

fn render_view(
    scene: &mut Scene,
    tier: Tier,
    camera: Camera,
    instances: &[Instance],
) -> RenderOutput {
    scene.renderer.set_tier(tier);
    let lights = [PointLight {
        position: Vec3::new(-1.5, 3.2, 1.5),
        color: Vec3::new(1.0, 0.55, 0.22) * 1.5,
        radius: 6.0,
    }];
    let frame = RenderFrame {
        camera,
        time: 1.0,
        surfaces: &scene.surfaces,
        instances,
        lights: &lights,
        environment: Environment::moonlit_night(),
        snowfall: false,
    };
    scene.renderer.render(&scene.world, &frame).expect("render")
}

#[test]
fn both_tiers_match_their_goldens() {
    let mut scene = scene();
    for (tier, name) in [(Tier::Relief, "relief"), (Tier::Pom, "pom")] {
        let out = render(&mut scene, tier);
        // The untouched roof is drawn with the basic material, the others with the deformable one.
        assert_eq!(out.basic_material_surfaces, vec![scene.fresh], "{name}");
        assert_eq!(out.surfaces.len(), 3);
        check(name, &out);
    }
}

#[test]
fn the_tessellated_tier_matches_its_goldens() {
    let mut scene = scene();
    let out = render(&mut scene, Tier::Tessellated);
    assert_eq!(out.basic_material_surfaces, vec![scene.fresh]);
    assert_eq!(out.dice_overflow, 0);
    // Every surface in view was diced, the untouched one too.
    assert!(
        out.surfaces.iter().all(|s| s.triangles > 0),
        "{:?}",
        out.surfaces
    );
    check("tessellated", &out);

    // Close and grazing, across the trench: the banks beside it, a standing person behind it whose
    // shadow comes across the trench and bends into it.
    // (Without the body that slid, so the trench is empty.)
    let mut instances = scene.instances[..2].to_vec();
    instances.extend(scene.person.iter().copied());
    let camera = grazing_camera();
    let out = render_view(&mut scene, Tier::Tessellated, camera, &instances);
    check("tessellated_grazing", &out);
    let relief = render_view(&mut scene, Tier::Relief, camera, &instances);
    check("relief_grazing", &relief);
}

/// The golden check sees what it claims to: renders with one term of the material switched off
/// (the sky tint of prints' walls, RNM, the heightmap's ambient occlusion) fail the bound in force.
/// RNM against the linear blend it replaces shows only where walls are seen at grazing angles, and
/// less than drivers differ (lavapipe: relief_grazing mean 0.0011, p99 0.032; an H100 scores more
/// against the lavapipe goldens with everything on), so only the same-driver bound can see it: that
/// limit is data here (`cross_driver`), not a skipped test. Scores print with `--nocapture`.
#[test]
fn broken_renders_fail_the_golden_check() {
    if bless() {
        return;
    }
    let mut scene = scene();
    let intact = scene.renderer.config().look;
    let sky = SnowLook {
        sky_tint: false,
        ..intact
    };
    let rnm = SnowLook {
        rnm: false,
        ..intact
    };
    let ao = SnowLook {
        occlusion: 0.0,
        ..intact
    };
    // (switch, look, golden, whether the cross-driver bound sees it too)
    let cases = [
        ("sky tint off", sky, "relief", true),
        ("sky tint off", sky, "pom", true),
        ("sky tint off", sky, "relief_grazing", true),
        ("AO off", ao, "relief", true),
        ("AO off", ao, "pom", true),
        ("AO off", ao, "relief_grazing", true),
        ("RNM off", rnm, "relief_grazing", false),
        ("RNM off", rnm, "tessellated_grazing", false),
    ];
    let same = same_driver();
    let mut checked = 0;
    for (what, look, name, cross_driver) in cases {
        scene.renderer.set_look(look).expect("look");
        let out = render_golden_view(&mut scene, name);
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        eprintln!(
            "{what}, {name}: FLIP mean {mean:.5} (max {}), p99 {p99:.5} (max {})",
            tol.mean, tol.p99
        );
        if !same && !cross_driver {
            eprintln!(
                "{what}, {name}: below what the cross-driver bound can see (known, see above)"
            );
            continue;
        }
        assert!(
            mean > tol.mean || p99 > tol.p99,
            "{what} passes the {name} golden check (mean {mean:.5} <= {}, p99 {p99:.5} <= {}): the check cannot see it",
            tol.mean,
            tol.p99
        );
        checked += 1;
    }
    // The intact render still passes: the failures above are the switches', not the scene's.
    scene.renderer.set_look(intact).expect("look");
    for name in ["relief", "relief_grazing"] {
        let out = render_golden_view(&mut scene, name);
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        assert!(
            mean <= tol.mean && p99 <= tol.p99,
            "intact {name}: {mean} {p99}"
        );
    }
    assert_eq!(checked, if same { 8 } else { 6 });
}

/// The view of a golden: the overview in a tier, or the close grazing view across the trench.
fn render_golden_view(scene: &mut Scene, name: &str) -> RenderOutput {
    let (tier, grazing) = match name {
        "relief" => (Tier::Relief, false),
        "pom" => (Tier::Pom, false),
        "tessellated" => (Tier::Tessellated, false),
        "relief_grazing" => (Tier::Relief, true),
        "tessellated_grazing" => (Tier::Tessellated, true),
        other => panic!("no golden view {other}"),
    };
    if !grazing {
        return render(scene, tier);
    }
    let mut instances = scene.instances[..2].to_vec();
    instances.extend(scene.person.iter().copied());
    render_view(scene, tier, grazing_camera(), &instances)
}

/// Close and grazing, across the trench.
fn grazing_camera() -> Camera {
    Camera {
        eye: Vec3::new(-1.5, 2.75, -1.4),
        target: Vec3::new(-0.6, 2.1, -0.45),
        fov_y_degrees: 50.0,
    }
}
