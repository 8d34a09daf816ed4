//! `snowprint simulate`: run a scene file and dump each surface's heightmap.

use std::path::{Path, PathBuf};

use snowprint::scene::{Scene, SceneShape};
use snowprint::{Deformer, GpuContext, GpuOptions, Heightmap, Shape, SnowWorld, WorldConfig};

use crate::output::OutputSet;
use crate::progress::Progress;

/// Arguments of `snowprint simulate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (TOML, see docs/SCENES.md).
    #[arg(long)]
    pub scene: PathBuf,
    /// Frames to run (1 or more).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::frames)]
    pub frames: u32,
    /// Seconds per frame (a finite number above 0).
    #[arg(long, default_value_t = 1.0 / 60.0, allow_negative_numbers = true, value_parser = crate::args::seconds)]
    pub dt: f32,
    /// Folder for `<surface>.png` (16-bit depression) and `<surface>.json`, created with its
    /// parents; published as a whole when the run ends (see docs/RELIABILITY.md).
    #[arg(long)]
    pub dump: PathBuf,
    /// Run the surface manager (budget, pool, priorities: the scene's `[budget]`, or the talk's
    /// defaults) and write its per-frame statistics to this JSON file, with a plot of pool use and
    /// updates per frame beside it (same name, `.svg`).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Save the whole snow state after the last frame to this file (imprints still queued
    /// included; see docs/SAVES.md), written atomically. Runs the surface manager.
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Continue a run from a save: the surfaces, heightmaps, queues and clock come from the file,
    /// the deformers and camera from the scene (at the save's time onwards); `--frames` more
    /// frames are run. The scene's surfaces must be the save's.
    #[arg(long)]
    pub load: Option<PathBuf>,
}

/// Run the scene for the frames asked and write `<surface>.png` and `<surface>.json` into the dump
/// folder. Every output path is checked and created before the first frame; the files appear as
/// one set when the run ends, or, when a frame fails, as the set of the frames done, marked
/// partial.
pub fn run(gpu: &GpuOptions, args: &Args) -> Result<(), String> {
    let scene = Scene::load(&args.scene).map_err(|e| e.to_string())?;
    let managed = args.report.is_some()
        || scene.budget.is_some()
        || args.save.is_some()
        || args.load.is_some();
    if !managed && let Some(camera) = &scene.camera {
        eprintln!(
            "snowprint: note: {}:{}: [camera] only decides what the surface manager counts as visible, and without [budget] or --report every surface is updated every frame, so this run does not use it; add a [budget] table or --report to run under the manager",
            scene.path.display(),
            camera.line
        );
    }
    let outputs = Outputs::prepare(&scene, &args.dump, args.report.as_deref())?;
    if let Some(save) = &args.save {
        crate::output::check_file_target(save, "--save")?;
    }
    if managed {
        let persist = crate::managed::Persist {
            save: args.save.clone(),
            load: args.load.clone(),
        };
        return crate::managed::simulate(gpu, &scene, args.frames, args.dt, outputs, persist);
    }
    simulate(gpu, &scene, args.frames, args.dt, outputs)
}

/// The output sets of a run, checked and opened before its first frame.
pub struct Outputs {
    /// The dump folder's set.
    pub dump: OutputSet,
    /// The report's set (its JSON and plot) and its streamed statistics.
    pub report: Option<(OutputSet, crate::report::StatsStream)>,
}

impl Outputs {
    /// Check and create the dump folder and the report's folder, and start the report file.
    pub fn prepare(scene: &Scene, dump: &Path, report: Option<&Path>) -> Result<Self, String> {
        let set = OutputSet::prepare(dump, "dump", &format!("--dump {}", dump.display()))?;
        for s in &scene.surfaces {
            for ext in ["png", "json"] {
                set.check_name(&format!("{}.{ext}", s.name))?;
            }
        }
        crate::terrain::check_names(scene, &set)?;
        let report = match report {
            None => None,
            Some(path) => {
                let what = format!("--report {}", path.display());
                if path.is_dir() {
                    return Err(format!(
                        "{what} is a folder; give a file path such as {}",
                        path.join("report.json").display()
                    ));
                }
                let (json, svg) = crate::report::file_names(path)?;
                let dir = path.parent().unwrap_or(Path::new(""));
                let mut rset = OutputSet::prepare(dir, &crate::output::report_key(path), &what)?;
                rset.check_name(&svg)?;
                let same_dir = dir.canonicalize().ok() == set.dir().canonicalize().ok();
                if same_dir
                    && let Some(s) = scene.surfaces.iter().find(|s| {
                        [format!("{}.json", s.name), format!("{}.png", s.name)]
                            .iter()
                            .any(|n| *n == json || *n == svg)
                    })
                {
                    return Err(format!(
                        "{what}: the dump writes a file of that name for surface {:?}; give the report another name",
                        s.name
                    ));
                }
                let stream = crate::report::StatsStream::create(rset.path(&json), rset.path(&svg))?;
                Some((rset, stream))
            }
        };
        Ok(Self { dump: set, report })
    }
}

/// How far a run got.
pub struct Done {
    /// Frames asked for.
    pub frames: u32,
    /// Frames run to the end.
    pub frames_done: u32,
    /// Seconds per frame.
    pub dt: f32,
}

/// One sentence for a frame that failed: the frame, the time, what went wrong and, where it can be
/// told, the scene line of the deformer or camera at fault.
pub fn frame_error(scene: &Scene, frame: u32, dt: f32, e: &snowprint::SnowError) -> String {
    let file = scene.path.display();
    let mut text = e.to_string();
    let culprit = match e {
        snowprint::SnowError::InvalidDeformer { name, .. } => {
            let by_index = name
                .strip_prefix('#')
                .and_then(|i| i.parse::<usize>().ok())
                .and_then(|i| scene.deformers.get(i));
            let d = by_index.or_else(|| scene.deformers.iter().find(|d| &d.name == name));
            if let (Some(d), Some(_)) = (d, by_index) {
                // The library names deformers of a frame by index: give the scene's name.
                text = text.replacen(&format!("{name:?}"), &format!("{:?}", d.name), 1);
            }
            d.map(|d| format!(" (deformer {:?}, {file}:{})", d.name, d.line))
        }
        snowprint::SnowError::Config {
            config: "camera", ..
        } => scene
            .camera
            .as_ref()
            .map(|c| format!(" ([camera], {file}:{})", c.line)),
        _ => None,
    };
    let e = text;
    format!(
        "{file}: frame {frame} (t = {:.4} s) failed{}: {e}",
        frame as f32 * dt,
        culprit.unwrap_or_default()
    )
}

/// What to add to a frame's error once the outputs of the frames before it are written.
pub fn partial_note(done: &Done, dump: &Path, written: Result<(), String>) -> String {
    match written {
        Ok(()) => format!(
            "; the {} frames before it are written to {} and marked partial (\"partial\": true, \"frames_done\": {})",
            done.frames_done,
            dump.display(),
            done.frames_done
        ),
        Err(e) => format!("; the frames before it could not be written either ({e})"),
    }
}

/// The library shape of each scene deformer, registering meshes through `add_mesh` (given the
/// deformer, so that an animated one can be registered as a skinned mesh).
pub fn scene_shapes(
    scene: &Scene,
    mut add_mesh: impl FnMut(
        &snowprint::scene::SceneDeformer,
        &snowprint::Mesh,
    ) -> snowprint::Result<snowprint::MeshId>,
) -> Result<Vec<Shape>, String> {
    scene
        .deformers
        .iter()
        .map(|d| {
            Ok(match &d.shape {
                SceneShape::Sphere { radius } => Shape::Sphere { radius: *radius },
                SceneShape::Capsule {
                    radius,
                    half_height,
                } => Shape::Capsule {
                    radius: *radius,
                    half_height: *half_height,
                },
                SceneShape::Box { half_extents } => Shape::Box {
                    half_extents: *half_extents,
                },
                SceneShape::Mesh { mesh, .. } => {
                    Shape::Mesh(add_mesh(d, mesh).map_err(|e| e.to_string())?)
                }
            })
        })
        .collect()
}

/// Run a loaded scene, every surface every frame, and dump its heightmaps.
pub fn simulate(
    gpu: &GpuOptions,
    scene: &Scene,
    frames: u32,
    dt: f32,
    outputs: Outputs,
) -> Result<(), String> {
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let pool: u64 = scene
        .surfaces
        .iter()
        .map(|s| {
            let l = s.layout();
            snowprint::PoolFormat::default().slot_bytes(l.width, l.height)
        })
        .sum::<u64>()
        + crate::terrain::pool_bytes(scene, snowprint::PoolFormat::default());
    let mut world = SnowWorld::new(
        &ctx,
        WorldConfig {
            capture: scene.capture,
            pool_bytes: pool.max(1 << 20),
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let mut ids = Vec::new();
    for (i, s) in scene.surfaces.iter().enumerate() {
        let id = world.add_surface(s.clone()).map_err(|e| e.to_string())?;
        if let Some(g) = scene.grounds.get(i).and_then(Option::as_ref) {
            world
                .set_ground(id, &g.ground, g.slope)
                .map_err(|e| format!("{}:{}: {e}", scene.path.display(), g.line))?;
        }
        ids.push(id);
    }
    let mut windows = crate::terrain::Windows::new(&mut world, scene)?;
    let shapes = scene_shapes(scene, |d, mesh| match &d.animation {
        Some(a) => world.add_skinned_mesh(&d.name, &a.skinned),
        None => world.add_mesh(&d.name, mesh),
    })?;
    let mut progress = Progress::new(frames as u64, "simulate", "frames")?;
    let mut failure = None;
    let mut frames_done = 0;
    for f in 1..=frames {
        let t = f as f32 * dt;
        let deformers: Vec<Deformer> = scene
            .deformers
            .iter()
            .zip(&shapes)
            .map(|(d, &shape)| Deformer::moving(shape, d.pose_at(t - dt), d.pose_at(t)))
            .collect();
        // Animated meshes are skinned for this frame's time before the step draws them.
        let animations: Vec<snowprint::MeshAnimation> = scene
            .deformers
            .iter()
            .zip(&shapes)
            .filter_map(|(d, shape)| match (&d.animation, shape) {
                (Some(a), Shape::Mesh(id)) => Some(a.at(*id, t)),
                _ => None,
            })
            .collect();
        let stepped = windows
            .follow(&mut world, scene, t)
            .and_then(|()| world.animate_meshes(&animations))
            .and_then(|()| world.step(dt, &deformers));
        if let Err(e) = stepped {
            failure = Some(frame_error(scene, f, dt, &e));
            break;
        }
        frames_done = f;
        crate::log_memory(f as u64);
        progress.inc(1);
    }
    progress.finish();
    let done = Done {
        frames,
        frames_done,
        dt,
    };
    let dump_dir = outputs.dump.dir().to_owned();
    let mut set = outputs.dump;
    let written = windows
        .dump(&mut world, scene, &mut set)
        .and_then(|()| {
            ids.iter()
                .map(|&id| world.read_heightmap(id).map_err(|e| e.to_string()))
                .collect::<Result<Vec<_>, _>>()
        })
        .and_then(|maps| write_dump(scene, &maps, &done, set));
    match failure {
        None => written,
        Some(f) => Err(f + &partial_note(&done, &dump_dir, written)),
    }
}

/// Write each surface's heightmap and description into the dump's set and publish it.
pub fn write_dump(
    scene: &Scene,
    maps: &[Heightmap],
    done: &Done,
    mut set: OutputSet,
) -> Result<(), String> {
    for (desc, map) in scene.surfaces.iter().zip(maps) {
        let png = set.path(&format!("{}.png", desc.name));
        map.save_png(&png).map_err(|e| e.to_string())?;
        let layout = desc.layout();
        let meta = serde_json::json!({
            "name": desc.name,
            "resolution": [layout.width, layout.height],
            "texel_size": [desc.size.x / layout.width as f32, desc.size.y / layout.height as f32],
            "center": desc.center.to_array(),
            "size": desc.size.to_array(),
            "yaw_degrees": desc.yaw_degrees,
            "snow_depth": desc.snow_depth,
            "replenish_rate": desc.replenish_rate,
            "frames": done.frames,
            "frames_done": done.frames_done,
            "partial": done.frames_done < done.frames,
            "dt": done.dt,
            "png": "16-bit greyscale depression: 0 = untouched, 65535 = pressed to the ground; column 0 = smallest x, row 0 = smallest z, before yaw",
        });
        let text = serde_json::to_string_pretty(&meta).map_err(|e| e.to_string())?;
        set.write(&format!("{}.json", desc.name), text + "\n")?;
    }
    set.publish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        Scene::parse(
            "version = 1\n\n[camera]\ntarget = [0, 0, 0]\nkeys = [{ t = 0, eye = [0, 5, -5] }]\n\n\
             [[surface]]\nname = \"yard\"\ncenter = [0, 0, 0]\nsize = [1, 1]\nsnow_depth = 0.3\n\n\
             [[deformer]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 0.1\n\
             keys = [{ t = 0, position = [0, 0.1, 0] }]\n",
            Path::new("s.toml"),
        )
        .unwrap()
    }

    #[test]
    fn a_failed_frame_names_the_deformer_by_its_scene_name_and_line() {
        let e = snowprint::SnowError::InvalidDeformer {
            name: "#0".into(),
            what: "position",
            value: "[inf, 0.0, 0.0]".into(),
            expected: "finite",
        };
        assert_eq!(
            frame_error(&scene(), 7, 0.5, &e),
            "s.toml: frame 7 (t = 3.5000 s) failed (deformer \"ball\", s.toml:13): deformer \"ball\": position is [inf, 0.0, 0.0], but it must be finite"
        );
    }

    #[test]
    fn a_failed_frame_names_the_camera_line_and_nothing_for_other_errors() {
        let e = snowprint::SnowError::Config {
            config: "camera",
            what: "target",
            value: "[0, 0, 0]".into(),
            expected: "different from the eye",
        };
        assert!(
            frame_error(&scene(), 2, 0.5, &e)
                .contains("failed ([camera], s.toml:3): camera target")
        );
        let e = snowprint::SnowError::Readback("device lost".into());
        assert_eq!(
            frame_error(&scene(), 2, 0.5, &e),
            "s.toml: frame 2 (t = 1.0000 s) failed: GPU readback failed: device lost"
        );
    }
}
