//! Headless Bevy apps (no window: cameras render into images), two tests.
//!
//! **A device short of snowprint's limits** (`a_device_short_of_the_limits_is_said_in_one_sentence`):
//! Bevy's device constrained to four storage buffers a shader stage; the plugin refuses it with
//! the library's own check and says so in one sentence through `SnowProbes::status`, and the app
//! runs on without snow.
//!
//! **The plugin's snow against snowprint's own relief tier** on one scene: a 14 m x 12 m surface
//! filling the view, pressed by five boot soles and a ball held for eight frames, seen at 256x144
//! from above at an angle, lit by one directional light and an ambient term matched to the
//! library's moon and sky (`Environment` with the same direction, radiance and exposure; Bevy's
//! units converted through its camera exposure). The library renders it with `Renderer` (relief
//! tier, on a device of its own); the plugin in a headless Bevy app (no window: the camera
//! renders into an image, read back with Bevy's screenshot). The two are scored with NVIDIA FLIP
//! as the goldens are (`crates/snowprint/tests/golden_support`); the bounds, and why they are
//! wider than the goldens', are data in `tests/relief_compare.json`. Both images and the FLIP map
//! are written to `target/bevy/relief-compare/` to be looked at.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::time::TimeUpdateStrategy;
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use bevy_snowprint::snowprint::{self, glam as sg};
use bevy_snowprint::{SnowDeformer, SnowSurface, SnowprintPlugin};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;
const SURFACE: [f32; 2] = [14.0, 12.0];
const DEPTH: f32 = 0.15;
/// Frames the deformers press before they are lifted away.
const PRESS_FRAMES: u32 = 8;
const EYE: [f32; 3] = [0.0, 3.6, 1.8];
const TARGET: [f32; 3] = [0.0, 0.0, -0.4];
const FOV_Y_DEGREES: f32 = 52.0;
/// Towards the light (unnormalised), its radiance on white facing it, the sky's on white facing
/// up (both linear RGB, the library's units).
const LIGHT: [f32; 3] = [0.8, 0.6, 0.42];
const LIGHT_RADIANCE: [f32; 3] = [0.62, 0.66, 0.72];
const SKY_RADIANCE: [f32; 3] = [0.16, 0.19, 0.26];

/// The deformers: (shape, position), held still for the pressing frames.
fn deformers() -> Vec<(snowprint::Shape, [f32; 3])> {
    let mut d = vec![(snowprint::Shape::Sphere { radius: 0.3 }, [1.2, 0.2, -0.4])];
    for i in 0..5 {
        let side = if i % 2 == 0 { 0.1 } else { -0.1 };
        d.push((
            snowprint::Shape::Box {
                half_extents: sg::Vec3::new(0.13, 0.03, 0.05),
            },
            [-1.3 + 0.55 * i as f32, 0.03, 0.4 + side],
        ));
    }
    d
}

fn library_render() -> image::RgbImage {
    use snowprint::render::{Environment, RenderConfig, RenderFrame, Renderer, Tier};
    let gpu = snowprint::GpuContext::new(&snowprint::GpuOptions::default()).expect("a GPU");
    let mut world =
        snowprint::SnowWorld::new(&gpu, snowprint::WorldConfig::default()).expect("world");
    let surface = world
        .add_surface(snowprint::SurfaceDesc::new(
            "yard", [0.0; 3], SURFACE, DEPTH,
        ))
        .expect("surface");
    let pressing: Vec<snowprint::Deformer> = deformers()
        .into_iter()
        .map(|(shape, at)| snowprint::Deformer::new(shape, snowprint::Pose::at(at)))
        .collect();
    for _ in 0..PRESS_FRAMES {
        world.step(1.0 / 30.0, &pressing).expect("step");
    }
    world.step(1.0 / 30.0, &[]).expect("step");
    let mut renderer =
        Renderer::new(&gpu, RenderConfig::new(WIDTH, HEIGHT, Tier::Relief)).expect("renderer");
    let environment = Environment {
        moon_direction: sg::Vec3::from(LIGHT).normalize(),
        moon_color: sg::Vec3::from(LIGHT_RADIANCE),
        sky_ambient: sg::Vec3::from(SKY_RADIANCE),
        ground_bounce: sg::Vec3::from(SKY_RADIANCE),
        exposure: 1.0,
        fog_density: 0.0,
        city_glow: 0.0,
        ..Environment::moonlit_night()
    };
    let frame = RenderFrame {
        camera: snowprint::Camera {
            eye: sg::Vec3::from(EYE),
            target: sg::Vec3::from(TARGET),
            fov_y_degrees: FOV_Y_DEGREES,
        },
        time: 1.0,
        surfaces: &[(surface, snowprint::GroundMaterial::RoofTiles)],
        instances: &[],
        lights: &[],
        environment,
        snowfall: false,
    };
    let out = renderer.render(&world, &frame).expect("render");
    let rgb = out
        .rgba8
        .chunks(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    image::RgbImage::from_raw(out.width, out.height, rgb).expect("image")
}

#[derive(Resource)]
struct Run {
    frame: u32,
    target: Handle<Image>,
    shot: Arc<Mutex<Option<image::RgbImage>>>,
    requested: bool,
}

/// A headless app: Bevy's default plugins without winit, looping as fast as it can, the plugin.
fn headless_app(render: bevy::render::RenderPlugin, log: bool) -> App {
    let mut app = App::new();
    let plugins = DefaultPlugins
        .set(WindowPlugin {
            primary_window: None,
            exit_condition: ExitCondition::DontExit,
            ..default()
        })
        .set(render)
        .disable::<WinitPlugin>();
    // One global logger a process: the second app of a test binary goes without.
    let plugins = if log {
        plugins
    } else {
        plugins.disable::<bevy::log::LogPlugin>()
    };
    app.add_plugins((
        plugins,
        ScheduleRunnerPlugin::run_loop(Duration::ZERO),
        SnowprintPlugin::default(),
    ));
    app
}

#[test]
fn a_device_short_of_the_limits_is_said_in_one_sentence() {
    use bevy::render::settings::{WgpuLimits, WgpuSettings};
    let settings = WgpuSettings {
        constrained_limits: Some(WgpuLimits {
            max_storage_buffers_per_shader_stage: 4,
            ..WgpuLimits::default()
        }),
        ..default()
    };
    let mut app = headless_app(
        bevy::render::RenderPlugin {
            render_creation: settings.into(),
            ..default()
        },
        false,
    );
    let status = Arc::new(Mutex::new(None));
    let seen = status.clone();
    let mut frames = 0;
    app.add_systems(
        Update,
        move |probes: Res<bevy_snowprint::SnowProbes>, mut exit: MessageWriter<AppExit>| {
            frames += 1;
            let s = probes.status();
            if s != bevy_snowprint::SnowStatus::Starting || frames > 200 {
                *seen.lock().unwrap() = Some(s);
                exit.write(AppExit::Success);
            }
        },
    );
    app.run();
    let status = status.lock().unwrap().take();
    match status {
        Some(bevy_snowprint::SnowStatus::Unavailable(sentence)) => {
            eprintln!("{sentence}");
            assert!(
                sentence.contains("max_storage_buffers_per_shader_stage to be at least 8")
                    && sentence.contains("has 4")
                    && sentence.contains("WgpuSettings"),
                "{sentence}"
            );
            assert_eq!(sentence.lines().count(), 1, "{sentence}");
        }
        other => panic!("a device with four storage buffers a stage was not refused: {other:?}"),
    }
}

/// A Bevy mesh (a 0.4 m cube) pressing the snow as a deformer leaves the print an analytic box of
/// the same size leaves beside it: the probes under both read the same depression, the box's
/// bottom 10 cm below the snow's top.
#[test]
fn a_mesh_deformer_presses_as_the_same_box_does() {
    let mut app = headless_app(bevy::render::RenderPlugin::default(), false);
    let top = 0.3;
    let half = 0.2;
    let centre_y = top - 0.1 + half;
    let (at_mesh, at_box) = (
        Vec3::new(-1.0, centre_y, 0.0),
        Vec3::new(1.0, centre_y, 0.0),
    );
    let answers = Arc::new(Mutex::new(Vec::new()));
    let seen = answers.clone();
    app.add_systems(
        Startup,
        move |mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>| {
            commands.spawn((
                SnowSurface::new(Vec2::new(6.0, 4.0), top),
                Transform::default(),
            ));
            commands.spawn((
                SnowDeformer::mesh(meshes.add(Cuboid::from_length(2.0 * half))),
                Transform::from_translation(at_mesh),
            ));
            commands.spawn((
                SnowDeformer::cuboid(Vec3::splat(half)),
                Transform::from_translation(at_box),
            ));
        },
    );
    let mut frames = 0;
    app.add_systems(
        Update,
        move |mut probes: ResMut<bevy_snowprint::SnowProbes>, mut exit: MessageWriter<AppExit>| {
            frames += 1;
            probes.ask(1, Vec3::new(at_mesh.x, 0.0, at_mesh.z));
            probes.ask(2, Vec3::new(at_box.x, 0.0, at_box.z));
            // Twenty frames of pressing, then answers no older than the last of them.
            if let (true, Some(m), Some(b)) = (frames > 20, probes.under(1), probes.under(2)) {
                *seen.lock().unwrap() = vec![m, b];
                exit.write(AppExit::Success);
            }
            if frames > 400 {
                exit.write(AppExit::error());
            }
        },
    );
    app.run();
    let answers = answers.lock().unwrap().clone();
    assert_eq!(
        answers.len(),
        2,
        "the probes did not answer within 400 frames"
    );
    let (mesh, cuboid) = (answers[0], answers[1]);
    eprintln!(
        "under the mesh cube {:.4} m pressed, under the analytic box {:.4} m",
        mesh.depression_m, cuboid.depression_m
    );
    for u in [mesh, cuboid] {
        assert!(u.on_snow);
        assert!(
            (u.depression_m - 0.1).abs() < 0.01,
            "{} m pressed where the box's bottom is 0.1 m below the top",
            u.depression_m
        );
    }
    assert!(
        (mesh.depression_m - cuboid.depression_m).abs() < 0.002,
        "the mesh pressed {} m, the same box as a shape {} m",
        mesh.depression_m,
        cuboid.depression_m
    );
}

/// A skinned Bevy mesh as a deformer: a 0.4 m cube whose every vertex follows one joint, the
/// skinned entity at the origin and the joint moved to where the cube presses 10 cm into the snow
/// (Bevy skins by the joints' transforms, not the entity's). The probe under the joint reads the
/// same depression as under the same box as an analytic shape; under the skinned entity's own
/// place, none.
#[test]
fn a_skinned_mesh_deformer_follows_its_joints() {
    use bevy::mesh::VertexAttributeValues;
    use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
    let mut app = headless_app(bevy::render::RenderPlugin::default(), false);
    let top = 0.3;
    let half = 0.2;
    let centre_y = top - 0.1 + half;
    let (at_joint, at_box) = (
        Vec3::new(-1.0, centre_y, 0.5),
        Vec3::new(1.0, centre_y, 0.5),
    );
    let answers = Arc::new(Mutex::new(Vec::new()));
    let seen = answers.clone();
    app.add_systems(
        Startup,
        move |mut commands: Commands,
              mut meshes: ResMut<Assets<Mesh>>,
              mut bindposes: ResMut<Assets<SkinnedMeshInverseBindposes>>| {
            commands.spawn((
                SnowSurface::new(Vec2::new(6.0, 4.0), top),
                Transform::default(),
            ));
            let mut cube = Cuboid::from_length(2.0 * half).mesh().build();
            let n = cube.count_vertices();
            cube.insert_attribute(
                Mesh::ATTRIBUTE_JOINT_INDEX,
                VertexAttributeValues::Uint16x4(vec![[0, 0, 0, 0]; n]),
            );
            cube.insert_attribute(
                Mesh::ATTRIBUTE_JOINT_WEIGHT,
                vec![[1.0_f32, 0.0, 0.0, 0.0]; n],
            );
            let joint = commands.spawn(Transform::from_translation(at_joint)).id();
            commands.spawn((
                SnowDeformer::mesh(meshes.add(cube)),
                SkinnedMesh {
                    inverse_bindposes: bindposes.add(vec![Mat4::IDENTITY]),
                    joints: vec![joint],
                },
                Transform::from_xyz(0.0, centre_y, -1.0),
            ));
            commands.spawn((
                SnowDeformer::cuboid(Vec3::splat(half)),
                Transform::from_translation(at_box),
            ));
        },
    );
    let mut frames = 0;
    app.add_systems(
        Update,
        move |mut probes: ResMut<bevy_snowprint::SnowProbes>, mut exit: MessageWriter<AppExit>| {
            frames += 1;
            probes.ask(1, Vec3::new(at_joint.x, 0.0, at_joint.z));
            probes.ask(2, Vec3::new(at_box.x, 0.0, at_box.z));
            probes.ask(3, Vec3::new(0.0, 0.0, -1.0));
            if let (true, Some(j), Some(b), Some(e)) = (
                frames > 20,
                probes.under(1),
                probes.under(2),
                probes.under(3),
            ) {
                *seen.lock().unwrap() = vec![j, b, e];
                exit.write(AppExit::Success);
            }
            if frames > 400 {
                exit.write(AppExit::error());
            }
        },
    );
    app.run();
    let answers = answers.lock().unwrap().clone();
    assert_eq!(
        answers.len(),
        3,
        "the probes did not answer within 400 frames"
    );
    let (joint, cuboid, entity) = (answers[0], answers[1], answers[2]);
    eprintln!(
        "under the skinned cube's joint {:.4} m pressed, under the analytic box {:.4} m, under the skinned entity's own place {:.4} m",
        joint.depression_m, cuboid.depression_m, entity.depression_m
    );
    assert!(
        (joint.depression_m - 0.1).abs() < 0.01,
        "{} m pressed under the joint, where the cube's bottom is 0.1 m below the top",
        joint.depression_m
    );
    assert!(
        (joint.depression_m - cuboid.depression_m).abs() < 0.002,
        "the skinned cube pressed {} m, the same box as a shape {} m",
        joint.depression_m,
        cuboid.depression_m
    );
    assert!(
        entity.depression_m.abs() < 1e-3,
        "{} m pressed under the skinned entity's own transform",
        entity.depression_m
    );
}

fn bevy_render() -> image::RgbImage {
    let shot = Arc::new(Mutex::new(None));
    let mut app = headless_app(
        bevy::render::RenderPlugin {
            // Every pipeline ready on the frame it is first asked for: the picture does not
            // depend on how fast this machine compiles shaders.
            synchronous_pipeline_compilation: true,
            ..default()
        },
        true,
    );
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f32(
        1.0 / 30.0,
    )))
    .insert_resource(ClearColor(Color::BLACK))
    .add_systems(Startup, setup)
    .add_systems(Update, drive);
    let target = {
        let mut images = app.world_mut().resource_mut::<Assets<Image>>();
        images.add(Image::new_target_texture(
            WIDTH,
            HEIGHT,
            TextureFormat::Rgba8UnormSrgb,
            None,
        ))
    };
    app.insert_resource(Run {
        frame: 0,
        target,
        shot: shot.clone(),
        requested: false,
    });
    app.run();
    let image = shot.lock().unwrap().take();
    image.expect("the screenshot came back")
}

fn setup(mut commands: Commands, run: Res<Run>) {
    commands.spawn((
        SnowSurface::new(Vec2::from(SURFACE), DEPTH),
        Transform::default(),
    ));
    for (shape, at) in deformers() {
        let deformer = match shape {
            snowprint::Shape::Sphere { radius } => SnowDeformer::sphere(radius),
            snowprint::Shape::Box { half_extents } => {
                SnowDeformer::cuboid(Vec3::from_array(half_extents.to_array()))
            }
            _ => unreachable!("the scene has spheres and boxes"),
        };
        commands.spawn((deformer, Transform::from_translation(Vec3::from(at))));
    }
    // Bevy lights in lux and scales by the camera's exposure; a white Lambertian surface facing a
    // directional light reflects illuminance / pi times that exposure, its ambient term
    // brightness times it: matched to the library's radiances.
    let exposure = bevy::camera::Exposure::default().exposure();
    let light = Vec3::from(LIGHT_RADIANCE);
    let sky = Vec3::from(SKY_RADIANCE);
    commands.spawn((
        DirectionalLight {
            color: Color::linear_rgb(light.x, light.y, light.z).with_luminance(1.0),
            illuminance: 0.0,
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::default().looking_to(-Vec3::from(LIGHT).normalize(), Vec3::Y),
        LightRadiance(light, exposure),
    ));
    commands.insert_resource(GlobalAmbientLight {
        color: Color::linear_rgb(
            sky.x / sky.max_element(),
            sky.y / sky.max_element(),
            sky.z / sky.max_element(),
        ),
        brightness: sky.max_element() / exposure,
        ..default()
    });
    commands.spawn((
        Camera3d::default(),
        RenderTarget::Image(run.target.clone().into()),
        // Linear out (clamped to 1, sRGB encoded); the test applies the library's ACES curve
        // (`library_curve`): Bevy's own ACES fit (Hill's) is another curve, darker in the
        // mid-tones, which is not the material's doing.
        Tonemapping::None,
        bevy::core_pipeline::tonemapping::DebandDither::Disabled,
        Projection::Perspective(PerspectiveProjection {
            fov: FOV_Y_DEGREES.to_radians(),
            ..default()
        }),
        Transform::from_translation(Vec3::from(EYE)).looking_at(Vec3::from(TARGET), Vec3::Y),
    ));
}

/// The light's radiance and the exposure it is converted with.
#[derive(Component)]
struct LightRadiance(Vec3, f32);

fn drive(
    mut commands: Commands,
    mut run: ResMut<Run>,
    deformers: Query<Entity, With<SnowDeformer>>,
    mut lights: Query<(&mut DirectionalLight, &LightRadiance)>,
) {
    for (mut light, radiance) in &mut lights {
        // Per channel the colour carries the ratio; the illuminance the largest channel.
        let c = radiance.0 / radiance.0.max_element();
        light.color = Color::linear_rgb(c.x, c.y, c.z);
        light.illuminance = std::f32::consts::PI * radiance.0.max_element() / radiance.1;
    }
    run.frame += 1;
    if run.frame == PRESS_FRAMES + 1 {
        for e in &deformers {
            commands.entity(e).despawn();
        }
    }
    if run.frame == PRESS_FRAMES + 6 && !run.requested {
        run.requested = true;
        let shot = run.shot.clone();
        commands
            .spawn(Screenshot::image(run.target.clone()))
            .observe(
                move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                    let image = captured
                        .image
                        .clone()
                        .try_into_dynamic()
                        .expect("an RGBA8 image");
                    *shot.lock().unwrap() = Some(image.to_rgb8());
                    exit.write(AppExit::Success);
                },
            );
    }
    if run.frame > PRESS_FRAMES + 300 {
        panic!("the screenshot did not come back within 300 frames");
    }
}

/// snowprint's tone curve (render/tonemap/tonemap.wgsl: Narkowicz's ACES fit, exposure 1, sRGB)
/// applied to Bevy's untonemapped picture: sRGB decoded to linear, the curve, encoded again.
fn library_curve(bevy: &image::RgbImage) -> image::RgbImage {
    let from_srgb = |c: f32| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let to_srgb = |c: f32| {
        if c <= 0.0031308 {
            c * 12.92
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let aces = |x: f32| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let mut out = bevy.clone();
    for p in out.pixels_mut() {
        for c in p.0.iter_mut() {
            *c = (to_srgb(aces(from_srgb(*c as f32 / 255.0))) * 255.0).round() as u8;
        }
    }
    out
}

/// FLIP's mean and 99th percentile, as `golden_support::score` computes them.
fn flip(
    reference: &image::RgbImage,
    test: &image::RgbImage,
) -> (nv_flip::FlipImageFloat, f32, f32) {
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(WIDTH, HEIGHT, reference.as_raw()),
        nv_flip::FlipImageRgb8::with_data(WIDTH, HEIGHT, test.as_raw()),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let pool = nv_flip::FlipPool::from_image(&error);
    (
        error,
        pool.mean(),
        pool.get_weighted_percentile(0.99) as f32,
    )
}

/// The mean of FLIP's error over the box of pixels around the prints (12 pixels beyond the
/// deformers' centres projected onto the snow's top): where the two renderers' prints are.
fn prints_mean(error: &nv_flip::FlipImageFloat) -> f32 {
    let camera = snowprint::Camera {
        eye: sg::Vec3::from(EYE),
        target: sg::Vec3::from(TARGET),
        fov_y_degrees: FOV_Y_DEGREES,
    };
    let clip = camera.projection(WIDTH as f32 / HEIGHT as f32, 0.1, 100.0) * camera.view();
    let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
    for (_, at) in deformers() {
        let c = clip * sg::Vec4::new(at[0], DEPTH, at[2], 1.0);
        let (x, y) = (
            (c.x / c.w * 0.5 + 0.5) * WIDTH as f32,
            (0.5 - c.y / c.w * 0.5) * HEIGHT as f32,
        );
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let (x0, y0) = ((x0 - 12.0).max(0.0) as u32, (y0 - 12.0).max(0.0) as u32);
    let (x1, y1) = (
        ((x1 + 12.0) as u32).min(WIDTH - 1),
        ((y1 + 12.0) as u32).min(HEIGHT - 1),
    );
    let values = error.to_vec();
    let mut sum = 0.0;
    for y in y0..=y1 {
        for x in x0..=x1 {
            sum += values[(y * WIDTH + x) as usize];
        }
    }
    sum / ((x1 - x0 + 1) * (y1 - y0 + 1)) as f32
}

fn out_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    let dir = target.join("relief-compare");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_plugins_snow_matches_the_librarys_relief_tier() {
    let library = library_render();
    let linear = bevy_render();
    assert_eq!(linear.dimensions(), (WIDTH, HEIGHT));
    let plugin = library_curve(&linear);
    let (error, mean, p99) = flip(&library, &plugin);
    let dir = out_dir();
    library.save(dir.join("library.png")).unwrap();
    plugin.save(dir.join("plugin.png")).unwrap();
    let map = error.apply_color_lut(&nv_flip::magma_lut());
    image::RgbImage::from_raw(WIDTH, HEIGHT, map.to_vec())
        .unwrap()
        .save(dir.join("flip.png"))
        .unwrap();
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/relief_compare.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let bound = |k: &str| {
        v[k].as_f64()
            .unwrap_or_else(|| panic!("{k} in relief_compare.json")) as f32
    };
    let (max_mean, max_p99, max_prints) = (bound("mean"), bound("p99"), bound("prints_mean"));
    let prints = prints_mean(&error);
    eprintln!(
        "FLIP of the plugin's snow against the library's relief tier: mean {mean:.4}, p99 {p99:.4}, around the prints {prints:.4} (bounds {max_mean}, {max_p99}, {max_prints}); images in {}",
        dir.display()
    );
    assert!(
        prints <= max_prints,
        "FLIP around the prints {prints} above {max_prints}"
    );
    assert!(mean <= max_mean, "FLIP mean {mean} above {max_mean}");
    assert!(p99 <= max_p99, "FLIP p99 {p99} above {max_p99}");
}
