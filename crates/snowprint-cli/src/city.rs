//! `snowprint demo --scene city`: several hundred rooftops and streets, many walkers, two surface
//! updates a frame inside the talk's 2 MiB pool. Writes the manager's statistics, the pool plot and
//! a top-down map of every surface's snow.

use std::path::Path;

use glam::Vec3;
use snowprint::manager::{CameraView, ManagerConfig, SnowManager};
use snowprint::{GpuContext, GpuOptions};
use snowprint_demo::city::{self, SurfaceKind};

use crate::output::OutputSet;
use crate::progress::Progress;
use crate::report::StatsStream;

/// Surfaces and walkers of the city demo.
pub const SURFACES: usize = 400;
/// Walkers of the city demo (the first is the player).
pub const WALKERS: usize = 60;
/// Seed of the city.
pub const SEED: u64 = 2014;
/// Map scale: metres per pixel.
const MAP_METRES_PER_PIXEL: f32 = 0.1;

/// Run the city for `frames` frames (default 10 s at 60 Hz) and write `city_report.json`,
/// `city_pool.svg` and `city_map.png` into `out`.
pub fn run(gpu: &GpuOptions, out: &Path, frames: Option<u32>) -> Result<(), String> {
    let mut set = OutputSet::prepare(out, "city", &format!("--out {}", out.display()))?;
    for name in ["city_report.json", "city_pool.svg", "city_map.png"] {
        set.check_name(name)?;
    }
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let frames = frames.unwrap_or(600);
    let dt = 1.0 / 60.0;
    let city = city::generate(SEED, SURFACES, WALKERS);
    let config = ManagerConfig::default();
    let budget = config.updates_per_frame;
    let mut snow = SnowManager::new(&ctx, config).map_err(|e| e.to_string())?;
    let mut ids = Vec::new();
    for s in &city.surfaces {
        ids.push(
            snow.add_surface(s.desc.clone(), s.zone)
                .map_err(|e| e.to_string())?,
        );
    }
    let mut stream = StatsStream::create(set.path("city_report.json"), set.path("city_pool.svg"))?;
    let mut progress = Progress::new(frames as u64, "city", "frames")?;
    let (mut evictions, mut longest_wait, mut resident) = (0, 0, 0);
    for f in 0..frames {
        let t = f as f32 * dt;
        let camera = CameraView::new(&city.player_camera(t), 16.0 / 9.0);
        let deformers = city.deformers(f as u64, dt);
        let stats = snow
            .tick(dt, Some(&camera), &deformers)
            .map_err(|e| format!("city: frame {f} failed: {e}"))?;
        evictions += stats.evicted.len();
        longest_wait = longest_wait.max(stats.max_wait_frames);
        resident = stats.resident;
        stream.push(&stats)?;
        crate::log_memory(f as u64 + 1);
        progress.inc(1);
    }
    progress.finish();
    stream.finish(
        &format!(
            "city: {} surfaces, {} walkers, {budget} updates a frame, 2 MiB pool",
            city.surfaces.len(),
            city.walkers.len()
        ),
        Some(budget),
    )?;
    let map = city_map(&snow, &city, &ids)?;
    set.write("city_map.png", map)?;
    set.publish()?;
    eprintln!(
        "snowprint: city of {} surfaces and {} walkers, {frames} frames: {resident} surfaces hold a heightmap at the end, {evictions} evictions, longest wait {longest_wait} frames; wrote city_report.json, city_pool.svg and city_map.png to {}",
        city.surfaces.len(),
        city.walkers.len(),
        out.display()
    );
    Ok(())
}

/// A top-down map (PNG bytes): streets grey, roofs brick, snow white where untouched and blue
/// where pressed, surfaces without a heightmap shaded darker.
fn city_map(
    snow: &SnowManager,
    city: &city::City,
    ids: &[snowprint::manager::ManagedId],
) -> Result<Vec<u8>, String> {
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for s in &city.surfaces {
        let r = s.desc.size.length() * 0.5;
        lo = lo.min(s.desc.center - Vec3::splat(r));
        hi = hi.max(s.desc.center + Vec3::splat(r));
    }
    let width = (((hi.x - lo.x) / MAP_METRES_PER_PIXEL).ceil() as u32).clamp(1, 4096);
    let height = (((hi.z - lo.z) / MAP_METRES_PER_PIXEL).ceil() as u32).clamp(1, 4096);
    let scale = ((hi.x - lo.x) / width as f32).max((hi.z - lo.z) / height as f32);
    let mut rgb = vec![18u8; (width * height * 3) as usize];
    // Streets first, roofs over them (roofs are higher).
    let mut order: Vec<usize> = (0..city.surfaces.len()).collect();
    order.sort_by(|&a, &b| {
        city.surfaces[a]
            .desc
            .center
            .y
            .total_cmp(&city.surfaces[b].desc.center.y)
    });
    for i in order {
        let s = &city.surfaces[i];
        let map = snow.read_heightmap(ids[i]).map_err(|e| e.to_string())?;
        let layout = s.desc.layout();
        let to_world = s.desc.local_to_world();
        // Surfaces without a slot (paged out, or never touched) are drawn greyer.
        let resident = snow.world_id(ids[i]).is_some();
        for row in 0..layout.height {
            for col in 0..layout.width {
                let local = Vec3::new(
                    -0.5 * s.desc.size.x + (col as f32 + 0.5) * s.desc.size.x / layout.width as f32,
                    0.0,
                    -0.5 * s.desc.size.y
                        + (row as f32 + 0.5) * s.desc.size.y / layout.height as f32,
                );
                let w = to_world.transform_point3(local);
                let px = ((w.x - lo.x) / scale) as u32;
                let pz = ((w.z - lo.z) / scale) as u32;
                if px >= width || pz >= height {
                    continue;
                }
                let d = map.depression[(row * layout.width + col) as usize] as f32 / 65535.0;
                let ground = match s.kind {
                    SurfaceKind::Roof => [150.0, 72.0, 58.0],
                    SurfaceKind::Street => [92.0, 92.0, 98.0],
                };
                let fresh = if resident {
                    [236.0, 242.0, 250.0]
                } else {
                    [170.0, 176.0, 188.0]
                };
                let trail = [70.0, 110.0, 200.0];
                // Untouched snow, then blue as it is pressed, then the ground at the bottom.
                let c: Vec<f32> = (0..3)
                    .map(|k| {
                        if d < 0.85 {
                            fresh[k] + (trail[k] - fresh[k]) * (d / 0.85)
                        } else {
                            trail[k] + (ground[k] - trail[k]) * ((d - 0.85) / 0.15)
                        }
                    })
                    .collect();
                let o = ((pz * width + px) * 3) as usize;
                for k in 0..3 {
                    // Keep the deepest print a pixel covers.
                    let v = c[k].clamp(0.0, 255.0) as u8;
                    rgb[o + k] = if d > 0.0 { v.min(rgb[o + k].max(v)) } else { v };
                }
            }
        }
    }
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(&rgb).map_err(|e| e.to_string())?;
    }
    Ok(bytes)
}
