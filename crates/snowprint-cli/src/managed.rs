//! `snowprint simulate --report`: a scene run through the surface manager (budget, pool and
//! priorities), with its per-frame statistics and a plot.

use std::path::Path;

use snowprint::manager::{CameraView, ManagedDeformer, ManagerConfig, SnowManager, ZoneId, plot};
use snowprint::scene::Scene;
use snowprint::{Deformer, GpuContext, GpuOptions};

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

/// Run the scene through a [`SnowManager`] and dump what each surface holds at the end; write the
/// statistics of every frame to `report` (JSON) and a plot beside it (SVG).
pub fn simulate(
    gpu: &GpuOptions,
    scene: &Scene,
    frames: u32,
    dt: f32,
    dump: &Path,
    report: Option<&Path>,
) -> Result<(), String> {
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let config = manager_config(scene);
    let budget = config.updates_per_frame;
    let mut snow = SnowManager::new(&ctx, config).map_err(|e| e.to_string())?;
    let mut ids = Vec::new();
    for (desc, &zone) in scene.surfaces.iter().zip(&scene.zones) {
        ids.push(
            snow.add_surface(desc.clone(), ZoneId(zone))
                .map_err(|e| e.to_string())?,
        );
    }
    let shapes = crate::simulate::scene_shapes(scene, |name, mesh| snow.add_mesh(name, mesh))?;
    let mut stats = Vec::new();
    let bar = crate::simulate::frame_bar(frames, "simulate (managed)")?;
    for f in 1..=frames {
        let t = f as f32 * dt;
        let deformers: Vec<ManagedDeformer> = scene
            .deformers
            .iter()
            .zip(&shapes)
            .map(|(d, &shape)| {
                let deformer = Deformer::moving(shape, d.pose_at(t - dt), d.pose_at(t));
                if d.player {
                    ManagedDeformer::player(deformer)
                } else {
                    ManagedDeformer::new(deformer)
                }
            })
            .collect();
        let camera = scene
            .camera
            .as_ref()
            .map(|c| CameraView::new(&c.at(t), ASPECT));
        stats.push(
            snow.tick(dt, camera.as_ref(), &deformers)
                .map_err(|e| e.to_string())?,
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    // Let the imprints still queued land before reading the heightmaps.
    snow.flush().map_err(|e| e.to_string())?;
    let merged = snow.planner().imprints_merged();
    if merged > 0 {
        eprintln!(
            "snowprint: {merged} queued imprints were merged into covering sweeps because a waiting \
             surface's queue passed queue_cap: those trails are pressed at least as deep as made, \
             and a little wider"
        );
    }
    let maps = ids
        .iter()
        .map(|&id| snow.read_heightmap(id).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, String>>()?;
    crate::simulate::write_dump(scene, &maps, frames, dt, dump)?;
    if let Some(path) = report {
        let json = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
        write_atomic(path, &(json + "\n"))?;
        let svg = path.with_extension("svg");
        plot::write_svg(
            &svg,
            &stats,
            &format!("{}: pool use and updates per frame", scene.path.display()),
            Some(budget),
        )
        .map_err(|e| e.to_string())?;
        eprintln!("snowprint: wrote {} and {}", path.display(), svg.display());
    }
    Ok(())
}

fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}
