//! `snowprint simulate --report`: a scene run through the surface manager (budget, pool and
//! priorities), with its per-frame statistics and a plot.

use std::path::{Path, PathBuf};

use snowprint::manager::{
    CameraView, ManagedDeformer, ManagedId, ManagerConfig, SnowManager, ZoneId,
};
use snowprint::scene::Scene;
use snowprint::{Deformer, GpuContext, GpuOptions, Ground, Heightmap, Shape, SlopeRule};

use crate::progress::Progress;
use crate::simulate::{Done, Outputs};

/// Aspect ratio the manager's visibility test assumes for a scene camera.
const ASPECT: f32 = 16.0 / 9.0;

/// The manager's settings for a scene: the scene's `[budget]` over the talk's defaults.
pub fn manager_config(scene: &Scene) -> ManagerConfig {
    let mut config = ManagerConfig {
        capture: scene.capture,
        ..ManagerConfig::default()
    };
    if let Some(b) = scene.budget {
        if let Some(k) = b.updates_per_frame {
            config.updates_per_frame = k as usize;
        }
        if let Some(bytes) = b.pool_bytes {
            config.pool_bytes = bytes;
        }
        if let Some(d) = b.active_distance {
            config.active_distance = d;
        }
        if let Some(p) = b.precision {
            config.format.precision = p;
        }
    }
    config
}

/// Where a managed run's state comes from and goes to.
pub struct Persist {
    /// Save the state after the last frame here.
    pub save: Option<PathBuf>,
    /// Start from this save instead of fresh snow.
    pub load: Option<PathBuf>,
}

/// The manager for a run: loaded from a save (checked against the scene), or fresh with the
/// scene's surfaces. Returns it with the handles of the scene's surfaces, in scene order.
fn start(
    ctx: &GpuContext,
    scene: &Scene,
    config: ManagerConfig,
    load: Option<&Path>,
) -> Result<(SnowManager, Vec<ManagedId>), String> {
    let Some(path) = load else {
        let mut snow = SnowManager::new(ctx, config).map_err(|e| e.to_string())?;
        let mut ids = Vec::new();
        for (desc, &zone) in scene.surfaces.iter().zip(&scene.zones) {
            ids.push(
                snow.add_surface(desc.clone(), ZoneId(zone))
                    .map_err(|e| e.to_string())?,
            );
        }
        lay_grounds(&mut snow, scene, &ids, None)?;
        return Ok((snow, ids));
    };
    let snow = SnowManager::load(ctx, path).map_err(|e| e.to_string())?;
    let saved: Vec<(ManagedId, String)> = snow
        .surface_names()
        .map(|(id, name)| (id, name.to_owned()))
        .collect();
    let mut ids = Vec::new();
    for desc in &scene.surfaces {
        let found = saved.iter().find(|(_, n)| *n == desc.name).map(|s| s.0);
        let Some(id) = found else {
            return Err(format!(
                "--load {}: the save has no surface {:?} of {}; load it with the scene it was saved from",
                path.display(),
                desc.name,
                scene.path.display()
            ));
        };
        if snow.surface(id).map_err(|e| e.to_string())? != desc {
            return Err(format!(
                "--load {}: surface {:?} differs between the save and {}; load it with the scene it was saved from",
                path.display(),
                desc.name,
                scene.path.display()
            ));
        }
        ids.push(id);
    }
    if saved.len() != ids.len() {
        return Err(format!(
            "--load {}: the save holds {} surfaces, {} has {}; load it with the scene it was saved from",
            path.display(),
            saved.len(),
            scene.path.display(),
            ids.len()
        ));
    }
    let mut snow = snow;
    lay_grounds(&mut snow, scene, &ids, Some(path))?;
    Ok((snow, ids))
}

/// Lay the scene's surfaces on their grounds. After `--load`, the ground each surface was saved
/// with must be the scene's: it is laid again from the scene and compared.
fn lay_grounds(
    snow: &mut SnowManager,
    scene: &Scene,
    ids: &[ManagedId],
    loaded: Option<&Path>,
) -> Result<(), String> {
    for (i, &id) in ids.iter().enumerate() {
        let ground = scene.grounds.get(i).and_then(Option::as_ref);
        let saved = snow.ground(id).map_err(|e| e.to_string())?.cloned();
        let (g, slope, line) = match ground {
            Some(g) => (g.ground.clone(), g.slope, g.line),
            None if saved.is_none() => continue,
            None => (Ground::Flat, SlopeRule::default(), 0),
        };
        snow.set_ground(id, &g, slope)
            .map_err(|e| format!("{}:{line}: {e}", scene.path.display()))?;
        if let Some(path) = loaded
            && snow.ground(id).map_err(|e| e.to_string())? != saved.as_ref()
        {
            return Err(format!(
                "--load {}: the ground of surface {:?} differs between the save and {}; load it with the scene it was saved from",
                path.display(),
                scene.surfaces[i].name,
                scene.path.display()
            ));
        }
    }
    Ok(())
}

/// Run the scene through a [`SnowManager`] and dump what each surface holds at the end; stream
/// the statistics of every frame to the report (JSON) as they come and plot them at the end (SVG).
/// Nothing is kept per frame: memory stays flat however long the run.
pub fn simulate(
    gpu: &GpuOptions,
    scene: &Scene,
    frames: u32,
    dt: f32,
    outputs: Outputs,
    persist: Persist,
) -> Result<(), String> {
    let Outputs { dump, mut report } = outputs;
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let mut config = manager_config(scene);
    if scene.budget.is_none() && report.is_none() {
        // Saving or loading a scene without [budget]: every surface every frame, as a plain run.
        config.updates_per_frame = snowprint::manager::UNLIMITED;
        config.pool_bytes = scene
            .surfaces
            .iter()
            .map(|s| {
                let l = s.layout();
                config.format.slot_bytes(l.width, l.height)
            })
            .sum::<u64>()
            .max(1 << 20);
    }
    if scene.budget.is_none() {
        // The terrains' levels in a pool of the scene's own size: room for them as well.
        config.pool_bytes += crate::terrain::pool_bytes(scene, config.format);
    }
    if scene.budget.and_then(|b| b.updates_per_frame).is_none() {
        // No budget stated: the default's updates for the surfaces, and one a level besides
        // (every level is updated every frame).
        let levels: usize = scene.terrains.iter().map(|t| t.desc.levels.len()).sum();
        config.updates_per_frame = config.updates_per_frame.saturating_add(levels);
    }
    let budget = config.updates_per_frame;
    let (mut snow, ids) = start(&ctx, scene, config, persist.load.as_deref())?;
    // Frames continue from the save's clock.
    let first = snow.planner().next_frame();
    let windows = crate::terrain::ManagedWindows::new(
        &mut snow,
        scene,
        first as f32 * dt,
        persist.load.as_deref(),
    )?;
    // An animated mesh is posed each frame before the tick (on the CPU, so that a surface the
    // budget leaves waiting is pressed later with each frame's own pose); a save keeps a mesh's
    // last posing, and its skeleton is given back here.
    let shapes = crate::simulate::scene_shapes(scene, |d, mesh| {
        match (snow.mesh_named(&d.name), &d.animation) {
            (Some(id), Some(a)) if persist.load.is_some() => {
                snow.set_skin(id, &a.skinned).map(|()| id)
            }
            (Some(id), None) if persist.load.is_some() => Ok(id),
            (_, Some(a)) => snow.add_skinned_mesh(&d.name, &a.skinned),
            (_, None) => snow.add_mesh(&d.name, mesh),
        }
    })?;
    let mut progress = Progress::new(frames as u64, "simulate (managed)", "frames")?;
    let mut failure = None;
    let mut frames_done = 0;
    let mut deformers: Vec<ManagedDeformer> = Vec::with_capacity(scene.deformers.len());
    for f in 1..=frames {
        let t = (first + f as u64) as f32 * dt;
        deformers.clear();
        deformers.extend(scene.deformers.iter().zip(&shapes).map(|(d, &shape)| {
            let deformer = Deformer::moving(shape, d.pose_at(t - dt), d.pose_at(t));
            if d.player {
                ManagedDeformer::player(deformer)
            } else {
                ManagedDeformer::new(deformer)
            }
        }));
        let camera = scene
            .camera
            .as_ref()
            .map(|c| CameraView::new(&c.at(t), ASPECT));
        let animations: Vec<snowprint::MeshAnimation> = scene
            .deformers
            .iter()
            .zip(&shapes)
            .filter_map(|(d, shape)| match (&d.animation, shape) {
                (Some(a), Shape::Mesh(id)) => Some(a.at(*id, t)),
                _ => None,
            })
            .collect();
        match windows
            .follow(&mut snow, scene, t)
            .and_then(|()| snow.animate_meshes(&animations))
            .and_then(|()| snow.tick(dt, camera.as_ref(), &deformers))
        {
            Ok(stats) => {
                if let Some((_, stream)) = &mut report {
                    stream.push(&stats)?;
                }
            }
            Err(e) => {
                failure = Some(crate::simulate::frame_error(scene, f, dt, &e));
                break;
            }
        }
        frames_done = f;
        crate::log_memory(f as u64);
        progress.inc(1);
    }
    progress.finish();
    if failure.is_none()
        && let Some(path) = &persist.save
    {
        // The state after the last frame, queues and all: a run loaded from it continues exactly.
        match snow.save(path) {
            Ok(bytes) => eprintln!("snowprint: saved {} ({bytes} bytes)", path.display()),
            Err(e) => failure = Some(format!("--save {}: {e}", path.display())),
        }
    }
    if failure.is_none() {
        // Let the imprints still queued land before reading the heightmaps.
        if let Err(e) = snow.flush() {
            failure = Some(format!(
                "{}: after frame {frames}, landing the imprints still queued failed: {e}",
                scene.path.display()
            ));
        }
    }
    let waiting = snow.planner().pending_surfaces();
    if failure.is_none() && waiting > 0 {
        eprintln!(
            "snowprint: {waiting} surfaces still hold queued imprints that could not land (their \
             zone is unloaded, or the pool and page store have no room for them); they are kept \
             in a --save but not in this dump"
        );
    }
    let merged = snow.planner().imprints_merged();
    if merged > 0 {
        eprintln!(
            "snowprint: {merged} queued imprints were merged into covering sweeps because a \
             waiting surface's queue passed queue_cap: those trails are pressed at least as deep as \
             made, and a little wider"
        );
    }
    let done = Done {
        frames,
        frames_done,
        dt,
    };
    let dump_dir = dump.dir().to_owned();
    let mut dump = dump;
    let mut written = windows
        .dump(&mut snow, scene, &mut dump)
        .and_then(|()| read_maps(&snow, &ids))
        .and_then(|maps| crate::simulate::write_dump(scene, &maps, &done, dump));
    if let Some((set, stream)) = report {
        let partial = if frames_done < frames {
            format!(" (partial: {frames_done} of {frames} frames)")
        } else {
            String::new()
        };
        let title = format!(
            "{}: pool use and updates per frame{partial}",
            scene.path.display()
        );
        let (json, svg) = (
            set.dir().join(&set.names()[0]),
            set.dir().join(&set.names()[1]),
        );
        let result = stream
            .finish(&title, Some(budget))
            .and_then(|()| set.publish());
        match (&result, failure.is_none()) {
            (Ok(()), true) => {
                eprintln!("snowprint: wrote {} and {}", json.display(), svg.display());
            }
            (Ok(()), false) => eprintln!(
                "snowprint: wrote {} and {} for the {frames_done} frames done (partial)",
                json.display(),
                svg.display()
            ),
            _ => {}
        }
        written = written.and(result);
    }
    match failure {
        None => written,
        Some(f) => Err(f + &crate::simulate::partial_note(&done, &dump_dir, written)),
    }
}

/// What each surface holds now (resident, paged out, or untouched snow).
fn read_maps(snow: &SnowManager, ids: &[snowprint::ManagedId]) -> Result<Vec<Heightmap>, String> {
    ids.iter()
        .map(|&id| snow.read_heightmap(id).map_err(|e| e.to_string()))
        .collect()
}
