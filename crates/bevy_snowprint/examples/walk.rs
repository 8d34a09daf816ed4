//! Walk through snow in Bevy: a person (simple shapes) with two boots that press the snow,
//! WASD to walk and turn, a camera that follows, the trail left behind drawn by the snow
//! material. The window title shows the snow under the boots, answered by `SnowProbes`.
//!
//! ```text
//! make walk        # or: cargo +1.97.1 run --release --example walk (in crates/bevy_snowprint)
//! ```
//!
//! For tests and pictures, a scripted run: `--script w:2s,a:0.5s,w:1s` (keys held one after the
//! other, `w`, `a`, `s`, `d` or several at once, `wa`; `-` for none), simulated at `--dt` seconds
//! a frame (1/30 by default) whatever the machine's speed, then `--screenshot shot.png` of the
//! window once the person has stood still a few frames, `--report report.json` (the camera's
//! clip-from-world matrix, the snow's top, the boots' prints and the probes' answers), and exit.
//! `--size 640x360` sets the window; `--frames-dir DIR` also saves every `--every N`th frame of
//! the script there (`frame_0000.png`, ..., for a GIF). Bad flags get one sentence and exit
//! code 2.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured, save_to_disk};
use bevy::time::TimeUpdateStrategy;
use bevy::window::{PresentMode, WindowResolution};
use bevy::winit::{UpdateMode, WinitSettings};
use bevy_snowprint::{
    SnowDeformer, SnowFootstep, SnowProbes, SnowStatus, SnowSurface, SnowprintPlugin,
};

/// Depth of the yard's snow, metres.
const SNOW_DEPTH: f32 = 0.3;
/// Side of the yard, metres.
const YARD: f32 = 14.0;
/// How high above the ground a planted boot's sole stands: prints 0.3 - 0.08 = 22 cm deep.
const SOLE: f32 = 0.08;
/// A boot: a capsule lying along the walk.
const BOOT_RADIUS: f32 = 0.06;
const BOOT_HALF_LENGTH: f32 = 0.07;
/// How far a swinging boot travels from print to print, and how high it is lifted.
const STEP: f32 = 0.7;
const LIFT: f32 = 0.32;
/// Half the distance between the boots' tracks.
const HALF_TRACK: f32 = 0.12;
const SPEED: f32 = 1.3;
const TURN: f32 = 1.6;

fn main() -> ExitCode {
    let options = match Options::parse(std::env::args().skip(1)) {
        Ok(o) => o,
        Err(sentence) => {
            eprintln!("walk: {sentence}");
            return ExitCode::from(2);
        }
    };
    let mut app = App::new();
    let (width, height) = options.size;
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: Some(Window {
                    title: "bevy_snowprint: walk (WASD)".into(),
                    resolution: WindowResolution::new(width, height)
                        .with_scale_factor_override(1.0),
                    present_mode: PresentMode::AutoNoVsync,
                    resizable: options.script.is_none(),
                    ..default()
                }),
                ..default()
            })
            .set(bevy::render::RenderPlugin {
                // A scripted run's pictures must not depend on how fast the machine compiles
                // shaders: every pipeline is ready on the frame it is first asked for.
                synchronous_pipeline_compilation: options.script.is_some(),
                ..default()
            }),
        SnowprintPlugin::default(),
    ))
    // Under Xvfb the window may never have focus: keep updating regardless.
    .insert_resource(WinitSettings {
        focused_mode: UpdateMode::Continuous,
        unfocused_mode: UpdateMode::Continuous,
    })
    .insert_resource(ClearColor(Color::srgb(0.45, 0.55, 0.7)))
    .insert_resource(Outcome::default())
    .add_systems(Startup, setup)
    .add_systems(
        Update,
        (input, walk, follow, ask_probes, hear_footsteps, script_end).chain(),
    );
    if let Some(script) = &options.script {
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f32(
            script.dt,
        )));
    }
    app.insert_resource(options);
    // A failure is said in one sentence where it happens (`fail`) and ends the run with an error.
    if app.run().is_error() {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

/// Say why the run cannot go on, and end it with an error.
fn fail(sentence: String, outcome: &mut Outcome, exit: &mut MessageWriter<AppExit>) {
    if outcome.failure.is_none() {
        eprintln!("walk: {sentence}");
        outcome.failure = Some(sentence);
    }
    exit.write(AppExit::error());
}

/// The command line.
#[derive(Resource, Clone, Debug)]
struct Options {
    size: (u32, u32),
    script: Option<Script>,
}

/// A scripted run.
#[derive(Clone, Debug)]
struct Script {
    /// Keys held and for how many frames, one after the other.
    segments: Vec<(Keys, u32)>,
    dt: f32,
    screenshot: Option<PathBuf>,
    report: Option<PathBuf>,
    /// Where to save every `every`th frame, and `every`.
    frames_dir: Option<PathBuf>,
    every: u32,
}

impl Script {
    fn frames(&self) -> u32 {
        self.segments.iter().map(|s| s.1).sum()
    }

    fn keys_at(&self, frame: u32) -> Keys {
        let mut start = 0;
        for &(keys, n) in &self.segments {
            if frame < start + n {
                return keys;
            }
            start += n;
        }
        Keys::default()
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Keys {
    forward: bool,
    back: bool,
    left: bool,
    right: bool,
}

impl Options {
    fn parse(mut args: impl Iterator<Item = String>) -> Result<Self, String> {
        let mut size = (960, 540);
        let (mut script, mut dt, mut screenshot, mut report) = (None, 1.0 / 30.0, None, None);
        let (mut frames_dir, mut every) = (None, 3);
        while let Some(flag) = args.next() {
            let mut value = |what: &str| {
                args.next()
                    .ok_or_else(|| format!("{flag} needs {what} after it"))
            };
            match flag.as_str() {
                "--size" => size = parse_size(&value("WIDTHxHEIGHT, e.g. 640x360")?)?,
                "--script" => script = Some(value("keys and durations, e.g. w:2s,a:0.5s")?),
                "--dt" => {
                    let v = value("seconds a frame, e.g. 0.033")?;
                    dt = v
                        .parse::<f32>()
                        .ok()
                        .filter(|d| d.is_finite() && *d > 0.0 && *d <= 0.25)
                        .ok_or(format!(
                            "--dt {v} is not a time step: give seconds between 0 and 0.25"
                        ))?;
                }
                "--screenshot" => screenshot = Some(writable(&value("a PNG path")?)?),
                "--report" => report = Some(writable(&value("a JSON path")?)?),
                "--frames-dir" => {
                    let dir = PathBuf::from(value("a folder")?);
                    if !dir.is_dir() {
                        return Err(format!(
                            "--frames-dir {} is not a folder: create it first",
                            dir.display()
                        ));
                    }
                    frames_dir = Some(dir);
                }
                "--every" => {
                    let v = value("a number of frames, e.g. 3")?;
                    every = v.parse::<u32>().ok().filter(|n| *n >= 1).ok_or(format!(
                        "--every {v} is not a number of frames: give a whole number from 1"
                    ))?;
                }
                other => {
                    return Err(format!(
                        "unknown flag {other}: use --size, --script, --dt, --screenshot, --report, --frames-dir or --every"
                    ));
                }
            }
        }
        let script = match script {
            Some(text) => Some(Script {
                segments: parse_script(&text, dt)?,
                dt,
                screenshot,
                report,
                frames_dir,
                every,
            }),
            None if screenshot.is_some() || report.is_some() || frames_dir.is_some() => {
                return Err(
                    "--screenshot, --report and --frames-dir need a --script to know when to stop"
                        .into(),
                );
            }
            None => None,
        };
        Ok(Self { size, script })
    }
}

fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--size {text} is not WIDTHxHEIGHT between 64x64 and 4096x4096");
    let (w, h) = text.split_once('x').ok_or_else(bad)?;
    let (w, h) = (
        w.parse::<u32>().map_err(|_| bad())?,
        h.parse::<u32>().map_err(|_| bad())?,
    );
    if !(64..=4096).contains(&w) || !(64..=4096).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// A path whose folder exists.
fn writable(path: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(path);
    match p.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => Err(format!(
            "the folder of {path} does not exist: create it or write elsewhere"
        )),
        _ => Ok(p),
    }
}

fn parse_script(text: &str, dt: f32) -> Result<Vec<(Keys, u32)>, String> {
    text.split(',')
        .map(|segment| {
            let (keys, time) = segment.split_once(':').ok_or(format!(
                "script segment `{segment}` is not KEYS:SECONDS (e.g. w:2s)"
            ))?;
            let seconds = time
                .trim_end_matches('s')
                .parse::<f32>()
                .ok()
                .filter(|s| s.is_finite() && *s >= 0.0 && *s <= 600.0)
                .ok_or(format!(
                    "script segment `{segment}`: `{time}` is not a duration in seconds (e.g. 1.5s)"
                ))?;
            let mut k = Keys::default();
            for c in keys.chars() {
                match c {
                    'w' | 'W' => k.forward = true,
                    's' | 'S' => k.back = true,
                    'a' | 'A' => k.left = true,
                    'd' | 'D' => k.right = true,
                    '-' => {}
                    other => {
                        return Err(format!(
                            "script segment `{segment}`: `{other}` is not one of the keys w, a, s, d (or - for none)"
                        ));
                    }
                }
            }
            Ok((k, (seconds / dt).round() as u32))
        })
        .collect()
}

/// The person: where it stands on the ground, which way it faces, its boots.
#[derive(Component)]
struct Walker {
    heading: f32,
    keys: Keys,
    /// Prints of each boot (the planted boot's place), and which boot swings.
    planted: [Vec3; 2],
    swing: usize,
    /// How far the swinging boot has come from its last print (0 to 1).
    progress: f32,
    moved: f32,
}

/// A boot: which one (0 left, 1 right).
#[derive(Component)]
struct Boot(usize);

#[derive(Component)]
struct Body;

/// How the run ended, and what the report records.
#[derive(Resource, Default)]
struct Outcome {
    frame: u32,
    failure: Option<String>,
    prints: Vec<[f32; 3]>,
    /// The person's place on the ground each frame it moved (x, z).
    path: Vec<[f32; 2]>,
    /// The boots' landings heard (`SnowFootstep`): how deep below the fresh top each reached.
    footsteps: Vec<f32>,
    shot_requested: bool,
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        SnowSurface::new(Vec2::splat(YARD), SNOW_DEPTH),
        Transform::default(),
    ));
    // Frozen ground around the yard.
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(60.0, 60.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.25, 0.22, 0.2),
            perceptual_roughness: 0.9,
            ..default()
        })),
        Transform::from_xyz(0.0, -0.002, 0.0),
    ));
    // A few posts, to see the snow's scale.
    let post = meshes.add(Cylinder::new(0.08, 1.2));
    let wood = materials.add(StandardMaterial {
        base_color: Color::srgb(0.35, 0.22, 0.12),
        ..default()
    });
    for (x, z) in [(-3.0, -3.0), (3.0, -2.0), (-2.0, 3.5), (4.0, 4.0)] {
        commands.spawn((
            Mesh3d(post.clone()),
            MeshMaterial3d(wood.clone()),
            Transform::from_xyz(x, 0.6, z),
        ));
    }
    commands.spawn((
        DirectionalLight {
            illuminance: 9000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(-4.0, 5.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.insert_resource(GlobalAmbientLight {
        color: Color::srgb(0.75, 0.82, 1.0),
        brightness: 900.0,
        ..default()
    });

    let start = Vec3::new(-3.0, 0.0, 3.0);
    let heading = 0.9_f32;
    let (forward, right) = directions(heading);
    let walker = commands
        .spawn((
            Walker {
                heading,
                keys: Keys::default(),
                planted: [
                    start - right * HALF_TRACK + Vec3::Y * SOLE,
                    start + right * HALF_TRACK + forward * STEP * 0.5 + Vec3::Y * SOLE,
                ],
                swing: 0,
                progress: 0.0,
                moved: 0.0,
            },
            Transform::from_translation(start),
            Visibility::default(),
        ))
        .id();
    let coat = materials.add(StandardMaterial {
        base_color: Color::srgb(0.7, 0.12, 0.1),
        ..default()
    });
    commands.spawn((
        Mesh3d(meshes.add(Capsule3d::new(0.22, 0.7))),
        MeshMaterial3d(coat.clone()),
        Transform::from_xyz(0.0, 1.0, 0.0),
        Body,
        ChildOf(walker),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(0.14))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.9, 0.75, 0.6),
            ..default()
        })),
        Transform::from_xyz(0.0, 1.7, 0.0),
        ChildOf(walker),
    ));
    let boot_mesh = meshes.add(Capsule3d::new(BOOT_RADIUS, 2.0 * BOOT_HALF_LENGTH));
    let leather = materials.add(StandardMaterial {
        base_color: Color::srgb(0.15, 0.1, 0.08),
        ..default()
    });
    for i in 0..2 {
        commands.spawn((
            Mesh3d(boot_mesh.clone()),
            MeshMaterial3d(leather.clone()),
            SnowDeformer::capsule(BOOT_RADIUS, BOOT_HALF_LENGTH),
            Transform::default(),
            Boot(i),
        ));
    }
    commands.spawn((
        Camera3d::default(),
        // Bevy's default (TonyMcMapface) needs the tonemapping_luts feature; snowprint's own
        // renderer uses an ACES curve too.
        Tonemapping::AcesFitted,
        Transform::from_xyz(-8.0, 3.0, 6.0).looking_at(start, Vec3::Y),
    ));
}

/// Forward and right on the ground for a heading (radians, counter-clockwise from +x seen from
/// above).
fn directions(heading: f32) -> (Vec3, Vec3) {
    let forward = Vec3::new(heading.cos(), 0.0, -heading.sin());
    (forward, Vec3::new(-forward.z, 0.0, forward.x))
}

fn input(
    keyboard: Res<ButtonInput<KeyCode>>,
    options: Res<Options>,
    mut outcome: ResMut<Outcome>,
    mut walker: Single<&mut Walker>,
    mut exit: MessageWriter<AppExit>,
) {
    if keyboard.just_pressed(KeyCode::Escape) {
        exit.write(AppExit::Success);
    }
    walker.keys = match &options.script {
        Some(script) => script.keys_at(outcome.frame),
        None => Keys {
            forward: keyboard.pressed(KeyCode::KeyW),
            back: keyboard.pressed(KeyCode::KeyS),
            left: keyboard.pressed(KeyCode::KeyA),
            right: keyboard.pressed(KeyCode::KeyD),
        },
    };
    outcome.frame += 1;
}

/// Turn, move, and step: the swinging boot travels from its print to the next, lifted over the
/// snow; the planted boot stays where it pressed.
fn walk(
    time: Res<Time>,
    mut outcome: ResMut<Outcome>,
    mut walker: Single<(&mut Walker, &mut Transform), Without<Boot>>,
    mut boots: Query<(&Boot, &mut Transform), Without<Walker>>,
) {
    let dt = time.delta_secs();
    let (w, transform) = &mut *walker;
    let turn = (w.keys.left as i32 - w.keys.right as i32) as f32;
    let go = (w.keys.forward as i32 - w.keys.back as i32) as f32;
    w.heading += turn * TURN * dt;
    let (forward, right) = directions(w.heading);
    let distance = go * SPEED * dt;
    let limit = YARD * 0.5 - 0.8;
    let next = transform.translation + forward * distance;
    if next.x.abs() < limit && next.z.abs() < limit {
        transform.translation = next;
        w.moved += distance.abs();
        if distance != 0.0 {
            outcome.path.push([next.x, next.z]);
        }
    }
    transform.rotation = Quat::from_rotation_y(w.heading);
    let side = |boot: usize| if boot == 0 { -HALF_TRACK } else { HALF_TRACK };
    let target = |boot: usize, at: Vec3| {
        at + forward * STEP * 0.5 * go.signum() + right * side(boot) + Vec3::Y * SOLE
    };
    if go != 0.0 {
        w.progress += distance.abs() / (STEP * 0.5);
        while w.progress >= 1.0 {
            let swing = w.swing;
            w.planted[swing] = target(swing, transform.translation);
            outcome.prints.push(w.planted[swing].to_array());
            w.swing = 1 - swing;
            w.progress -= 1.0;
        }
    }
    let lying = Quat::from_rotation_arc(Vec3::Y, forward);
    for (boot, mut t) in &mut boots {
        let i = boot.0;
        let mut at = w.planted[i] + Vec3::Y * BOOT_RADIUS;
        if i == w.swing && go != 0.0 {
            let p = w.progress;
            at = w.planted[i].lerp(target(i, transform.translation), p)
                + Vec3::Y * (BOOT_RADIUS + LIFT * (std::f32::consts::PI * p).sin());
        }
        t.translation = at;
        t.rotation = lying;
    }
}

/// The camera follows behind and above, smoothly.
fn follow(
    time: Res<Time>,
    walker: Single<(&Walker, &Transform), Without<Camera3d>>,
    mut camera: Single<&mut Transform, With<Camera3d>>,
) {
    let (w, t) = *walker;
    let (forward, right) = directions(w.heading);
    let eye = t.translation - forward * 4.5 + right * 1.2 + Vec3::Y * 2.6;
    let k = 1.0 - (-3.0 * time.delta_secs()).exp();
    camera.translation = camera.translation.lerp(eye, k);
    let look = t.translation + Vec3::Y * 0.2 - forward * 0.8;
    camera.look_at(look, Vec3::Y);
}

/// Ask what is under each planted boot; show the answers in the title.
fn ask_probes(
    mut probes: ResMut<SnowProbes>,
    walker: Single<&Walker>,
    mut window: Single<&mut Window>,
    mut outcome: ResMut<Outcome>,
    options: Res<Options>,
    mut exit: MessageWriter<AppExit>,
) {
    if let SnowStatus::Unavailable(sentence) = probes.status() {
        fail(sentence, &mut outcome, &mut exit);
        return;
    }
    for boot in 0..2 {
        probes.ask(boot as u64, walker.planted[boot]);
    }
    if options.script.is_none()
        && let (Some(l), Some(r)) = (probes.under(0), probes.under(1))
    {
        window.title = format!(
            "bevy_snowprint: walk (WASD) | snow under the boots {:.2} m, {:.2} m",
            l.snow_depth_m, r.snow_depth_m
        );
    }
}

/// The boots' landings, for the report (a game would play a crunch here).
fn hear_footsteps(mut heard: MessageReader<SnowFootstep>, mut outcome: ResMut<Outcome>) {
    for step in heard.read() {
        outcome.footsteps.push(step.depth_m);
    }
}

/// In a scripted run: once the script is over and the person has stood still a few frames,
/// write the report, take the screenshot, and leave once it is saved.
fn script_end(
    mut commands: Commands,
    options: Res<Options>,
    mut outcome: ResMut<Outcome>,
    probes: Res<SnowProbes>,
    walker: Single<&Walker>,
    camera: Single<(&GlobalTransform, &Projection, &Camera)>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(script) = &options.script else {
        return;
    };
    if outcome.failure.is_some() {
        return;
    }
    let settle = script.frames() + 8;
    if let Some(dir) = &script.frames_dir
        && outcome.frame.is_multiple_of(script.every)
        // Not on the frame of the final screenshot: one capture a window a frame.
        && outcome.frame < settle
    {
        let path = dir.join(format!("frame_{:04}.png", outcome.frame / script.every));
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(path));
    }
    if outcome.frame > settle + 240 {
        let sentence =
            format!("the screenshot did not come back within 240 frames of frame {settle}");
        fail(sentence, &mut outcome, &mut exit);
        return;
    }
    if outcome.frame < settle || outcome.shot_requested {
        return;
    }
    outcome.shot_requested = true;
    let (transform, projection, cam) = *camera;
    let clip = projection.get_clip_from_view() * transform.to_matrix().inverse();
    let viewport = cam.logical_viewport_size().unwrap_or_default();
    let under: Vec<_> = (0..2u64)
        .filter_map(|k| probes.under(k))
        .map(|u| {
            serde_json::json!({
                "point": u.point.to_array(),
                "on_snow": u.on_snow,
                "snow_depth_m": u.snow_depth_m,
                "depression_m": u.depression_m,
                "age": u.age,
            })
        })
        .collect();
    let report = serde_json::json!({
        "clip_from_world": clip.to_cols_array(),
        "viewport": viewport.to_array(),
        "snow_top": SNOW_DEPTH,
        "sole": SOLE,
        "walked_m": walker.moved,
        "prints": outcome.prints,
        "path": outcome.path,
        "footsteps": outcome.footsteps,
        "planted": walker.planted.map(|p| p.to_array()),
        "probes": under,
        "snow_updates": probes.updates(),
        "frames": outcome.frame,
    });
    if let Some(path) = &script.report
        && let Err(e) = std::fs::write(path, report.to_string())
    {
        fail(
            format!("cannot write {}: {e}", path.display()),
            &mut outcome,
            &mut exit,
        );
        return;
    }
    match &script.screenshot {
        Some(path) => {
            let path = path.clone();
            commands.spawn(Screenshot::primary_window()).observe(
                move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                    let saved = captured
                        .image
                        .clone()
                        .try_into_dynamic()
                        .map_err(|e| e.to_string())
                        .and_then(|image| image.to_rgb8().save(&path).map_err(|e| e.to_string()));
                    match saved {
                        Ok(()) => {
                            exit.write(AppExit::Success);
                        }
                        Err(e) => {
                            eprintln!("walk: cannot save the screenshot {}: {e}", path.display());
                            exit.write(AppExit::error());
                        }
                    }
                },
            );
        }
        None => {
            exit.write(AppExit::Success);
        }
    }
}
