//! The fixed scene of the image tests (`render_golden.rs`, `render_compute.rs`): a concrete roof
//! with prints, a trench and a body-sized dent, a tiled roof with a crater to the tiles, and an
//! untouched roof on the basic material, rendered at 256x144, and the views of its goldens.

#![allow(dead_code)]

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{
    Environment, Instance, MeshMaterial, PointLight, RenderConfig, RenderFrame, RenderOutput,
    Renderer, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    WorldConfig,
};

use crate::common;

pub const WIDTH: u32 = 256;
pub const HEIGHT: u32 = 144;

pub struct Scene {
    pub world: SnowWorld,
    pub renderer: Renderer,
    pub surfaces: Vec<(SurfaceId, GroundMaterial)>,
    pub fresh: SurfaceId,
    pub instances: Vec<Instance>,
    /// A person standing beside the trench (capsule and head), for the grazing view.
    pub person: Vec<Instance>,
}

/// The fixed scene: deformed over 8 steps of 1/30 s.
pub fn scene() -> Scene {
    scene_with(|_| {})
}

/// The fixed scene, its renderer's configuration changed by `configure` first.
pub fn scene_with(configure: impl FnOnce(&mut RenderConfig)) -> Scene {
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
    configure(&mut config);
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

/// The overview's camera.
pub fn overview_camera() -> Camera {
    Camera {
        eye: Vec3::new(0.6, 4.6, 4.4),
        target: Vec3::new(0.6, 1.8, -0.1),
        fov_y_degrees: 52.0,
    }
}

pub fn render(scene: &mut Scene, tier: Tier) -> RenderOutput {
    let instances = scene.instances.clone();
    render_view(scene, tier, overview_camera(), &instances)
}

/// The lantern every view of the scene is lit by.
pub fn lights() -> [PointLight; 1] {
    [PointLight {
        position: Vec3::new(-1.5, 3.2, 1.5),
        color: Vec3::new(1.0, 0.55, 0.22) * 1.5,
        radius: 6.0,
    }]
}

/// The frame of a view of the scene.
pub fn frame<'a>(
    surfaces: &'a [(SurfaceId, GroundMaterial)],
    camera: Camera,
    instances: &'a [Instance],
    lights: &'a [PointLight],
) -> RenderFrame<'a> {
    RenderFrame {
        camera,
        time: 1.0,
        surfaces,
        instances,
        lights,
        environment: Environment::moonlit_night(),
        snowfall: false,
    }
}

pub fn render_view(
    scene: &mut Scene,
    tier: Tier,
    camera: Camera,
    instances: &[Instance],
) -> RenderOutput {
    scene.renderer.set_tier(tier);
    let lights = lights();
    let frame = frame(&scene.surfaces, camera, instances, &lights);
    scene.renderer.render(&scene.world, &frame).expect("render")
}

/// The view of a golden: the overview in a tier, or the close grazing view across the trench.
pub fn render_golden_view(scene: &mut Scene, name: &str) -> RenderOutput {
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
pub fn grazing_camera() -> Camera {
    Camera {
        eye: Vec3::new(-1.5, 2.75, -1.4),
        target: Vec3::new(-0.6, 2.1, -0.45),
        fov_y_degrees: 50.0,
    }
}
