//! `snowprint simulate`: run a scene file and dump each surface's heightmap.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use snowprint::scene::{Scene, SceneShape};
use snowprint::{Deformer, GpuContext, GpuOptions, Heightmap, Shape, SnowWorld, WorldConfig};

/// Arguments of `snowprint simulate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (TOML, see docs/SCENES.md).
    #[arg(long)]
    pub scene: PathBuf,
    /// Frames to run.
    #[arg(long)]
    pub frames: u32,
    /// Seconds per frame.
    #[arg(long, default_value_t = 1.0 / 60.0)]
    pub dt: f32,
    /// Folder for `<surface>.png` (16-bit depression) and `<surface>.json`.
    #[arg(long)]
    pub dump: PathBuf,
    /// Run the surface manager (budget, pool, priorities: the scene's `[budget]`, or the talk's
    /// defaults) and write its per-frame statistics to this JSON file, with a plot of pool use and
    /// updates per frame beside it (same name, `.svg`).
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Run the scene for the frames asked and write `<surface>.png` and `<surface>.json` into the dump
/// folder. Files appear only when the whole run succeeded.
pub fn run(gpu: &GpuOptions, args: &Args) -> Result<(), String> {
    if !(args.dt.is_finite() && args.dt > 0.0) {
        return Err(format!(
            "--dt {} is not usable; give a finite number of seconds above 0, such as 0.0166",
            args.dt
        ));
    }
    let scene = Scene::load(&args.scene).map_err(|e| e.to_string())?;
    if args.report.is_some() || scene.budget.is_some() {
        return crate::managed::simulate(
            gpu,
            &scene,
            args.frames,
            args.dt,
            &args.dump,
            args.report.as_deref(),
        );
    }
    simulate(gpu, &scene, args.frames, args.dt, &args.dump)
}

/// The library shape of each scene deformer, registering meshes through `add_mesh`.
pub fn scene_shapes(
    scene: &Scene,
    mut add_mesh: impl FnMut(&str, &snowprint::Mesh) -> snowprint::Result<snowprint::MeshId>,
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
                    Shape::Mesh(add_mesh(&d.name, mesh).map_err(|e| e.to_string())?)
                }
            })
        })
        .collect()
}

/// A progress bar over frames.
pub fn frame_bar(frames: u32, what: &str) -> Result<ProgressBar, String> {
    let bar = ProgressBar::new(frames as u64);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} frames {{elapsed}}"
        ))
        .map_err(|e| e.to_string())?
        .progress_chars("=> "),
    );
    Ok(bar)
}

/// Run a loaded scene, every surface every frame, and dump its heightmaps.
pub fn simulate(
    gpu: &GpuOptions,
    scene: &Scene,
    frames: u32,
    dt: f32,
    dump: &Path,
) -> Result<(), String> {
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let pool: u64 = scene
        .surfaces
        .iter()
        .map(|s| {
            let l = s.layout();
            snowprint::PoolFormat::default().slot_bytes(l.width, l.height)
        })
        .sum();
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
    for s in &scene.surfaces {
        ids.push(world.add_surface(s.clone()).map_err(|e| e.to_string())?);
    }
    let shapes = scene_shapes(scene, |name, mesh| world.add_mesh(name, mesh))?;
    let bar = frame_bar(frames, "simulate")?;
    for f in 1..=frames {
        let t = f as f32 * dt;
        let deformers: Vec<Deformer> = scene
            .deformers
            .iter()
            .zip(&shapes)
            .map(|(d, &shape)| Deformer::moving(shape, d.pose_at(t - dt), d.pose_at(t)))
            .collect();
        world.step(dt, &deformers).map_err(|e| e.to_string())?;
        bar.inc(1);
    }
    bar.finish_and_clear();

    let maps = ids
        .iter()
        .map(|&id| world.read_heightmap(id).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    write_dump(scene, &maps, frames, dt, dump)
}

/// Write each surface's heightmap and description into `dump`, through a staging folder so that an
/// error leaves no output that looks complete.
pub fn write_dump(
    scene: &Scene,
    maps: &[Heightmap],
    frames: u32,
    dt: f32,
    dump: &Path,
) -> Result<(), String> {
    std::fs::create_dir_all(dump)
        .map_err(|e| format!("cannot create the dump folder {}: {e}", dump.display()))?;
    let staging = dump.join(format!(".snowprint-partial-{}", std::process::id()));
    let result = write_staged(scene, maps, frames, dt, &staging, dump);
    let _ = std::fs::remove_dir_all(&staging);
    result
}

fn write_staged(
    scene: &Scene,
    maps: &[Heightmap],
    frames: u32,
    dt: f32,
    staging: &Path,
    dump: &Path,
) -> Result<(), String> {
    std::fs::create_dir_all(staging)
        .map_err(|e| format!("cannot write into {}: {e}", dump.display()))?;
    let mut files: Vec<PathBuf> = Vec::new();
    for (desc, map) in scene.surfaces.iter().zip(maps) {
        let png = staging.join(format!("{}.png", desc.name));
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
            "frames": frames,
            "dt": dt,
            "png": "16-bit greyscale depression: 0 = untouched, 65535 = pressed to the ground; column 0 = smallest x, row 0 = smallest z, before yaw",
        });
        let json = staging.join(format!("{}.json", desc.name));
        let text = serde_json::to_string_pretty(&meta).map_err(|e| e.to_string())?;
        std::fs::write(&json, text + "\n")
            .map_err(|e| format!("cannot write {}: {e}", json.display()))?;
        files.push(png);
        files.push(json);
    }
    for f in files {
        let name = f
            .file_name()
            .ok_or("internal: staged file without a name")?;
        let dest = dump.join(name);
        std::fs::rename(&f, &dest)
            .map_err(|e| format!("cannot move {} into place: {e}", dest.display()))?;
    }
    Ok(())
}
