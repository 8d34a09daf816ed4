//! `snowprint demo`: the built-in demo world, simulated and rendered.
//!
//! Writes into `--out` (default `out/`): numbered frames `frame_0000.png`..., an animation
//! `demo.gif` (and `demo.mp4` when `ffmpeg` is on the PATH), `contact_sheet.png` of six frames, and
//! `report.json` (adapter, resolution, frames, tier, camera, per-pass GPU times or why there are
//! none, and which surfaces were drawn with the basic material). The folder is checked before the
//! first frame, and everything is written as one output set (`output.rs`): readers see the whole
//! set of this run or of the one before, and a run that fails leaves the one before untouched.
//!
//! The world comes from one function, [`build_scene`] (in the demo crate, `snowprint_demo::scene`),
//! returning a [`DemoScene`]: swap it for another world without touching the rest.

use std::path::PathBuf;
use std::time::Instant;

use snowprint::render::{
    DebugView, OpaquePath, RenderConfig, RenderFrame, Renderer, SurfaceShading, Tier,
};
use snowprint::{GpuContext, GpuOptions, SnowWorld, WorldConfig};

use snowprint_demo::scene::{DemoScene, build_scene};

use crate::output::OutputSet;
use crate::progress::Progress;

#[path = "contact_sheet.rs"]
pub(crate) mod contact_sheet;

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT, such as 1280x720"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (16..=8192).contains(&n))
            .ok_or_else(|| {
                format!("size {s:?}: {v:?} must be a whole number of pixels from 16 to 8192")
            })
    };
    Ok((parse(w)?, parse(h)?))
}

/// Arguments of `snowprint demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Frames to render (default: 240 on a GPU, 60 on a software adapter). One frame shows the end
    /// of the camera's clip.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::frames)]
    pub frames: Option<u32>,
    /// Frame size, WIDTHxHEIGHT (default: 1280x720 on a GPU, 800x450 on a software adapter).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Camera: flythrough, overview, closeup, run, fall, angel, slide or fight (the stand-in
    /// scene has flythrough, closeup, overview, street, angel, fall and slide; the shore
    /// flythrough, overview, closeup and mud; the mountain follow, overview and closing).
    #[arg(long, default_value = "flythrough")]
    pub camera: String,
    /// Snow tier: relief (the talk's relief mapping), pom (parallax occlusion mapping) or
    /// tessellated (real displaced geometry diced on the GPU, banks, the snow in the shadow map).
    #[arg(long, default_value = "relief")]
    pub tier: Tier,
    /// How the scene is shaded: forward (per fragment) or visibility (the opaque meshes' and the
    /// snow's hits in a visibility buffer, shaded in compute passes, which on GPUs with few
    /// graphics units costs far less: `docs/PERFORMANCE.md`). Default: visibility on a GPU,
    /// forward on a software adapter (the goldens' path). The report's `opaque` says which.
    #[arg(long)]
    pub opaque: Option<OpaquePath>,
    /// Samples per pixel along each axis, 1 to 4 (default: 2 on a GPU, 1 on a software adapter).
    #[arg(long, allow_negative_numbers = true)]
    pub supersample: Option<u32>,
    /// What the frames show: shaded, materials, depression, occlusion, normals or taps.
    #[arg(long, default_value = "shaded")]
    pub debug_view: DebugView,
    /// No falling snow.
    #[arg(long)]
    pub no_snowfall: bool,
    /// Start of the clip, seconds of action (default: the camera's); within the scene's action.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::moment)]
    pub from: Option<f32>,
    /// End of the clip, seconds of action (default: the camera's); at most the end of the
    /// scene's action (the simulation runs up to it, so a later end would only cost time).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::moment)]
    pub to: Option<f32>,
    /// Simulation steps per second, whatever the frame count (default: 60 on a GPU, 30 on a
    /// software adapter; deformers are swept between steps, so trails stay continuous).
    #[arg(long, allow_negative_numbers = true)]
    pub sim_hz: Option<u32>,
    /// Which demo: `rooftops` (the library's demo world, rendered), `skinned` (the rooftops with
    /// one person pressing the snow with its own skinned glTF mesh, rendered), `standin` (the
    /// renderer's small stand-in world, rendered), `shore` (wet and dry sand, a muddy track and a
    /// snowy bank, people walking across, rendered), `mountain` (a valley on real ground: hills, a
    /// frozen lake, trees, a cabin with a pitched roof, a hiker walking a long loop; rendered) or
    /// `city` (several hundred surfaces under the
    /// surface manager's budget: heightmaps, a report, a pool plot and a map; not rendered).
    #[arg(long, default_value = "rooftops")]
    pub scene: String,
    /// Also render the last frame in the relief and the tessellated tiers and write them side by
    /// side (relief left, tessellated right) to `compare_tiers.png`.
    #[arg(long)]
    pub compare_tiers: bool,
    /// Leave out the kicked-up snow (the world's spray particles, on by default).
    #[arg(long)]
    pub no_spray: bool,
    /// Side of each of the moon's two shadow cascades, texels. Default on a GPU: fitted to the
    /// view, a texel no larger than a pixel of the scene at the near cascade's focus for the
    /// clip's narrowest field of view (`RenderConfig::shadow_map_size_for_view`; 3072 at 1080p
    /// and 50 degrees); 2048 on a software adapter. The report's `shadow_map_size` says which,
    /// and `shadow_last_frame.view_pixel_m` against `texel_m` how dense the view needs the near
    /// one.
    #[arg(long)]
    pub shadow_map_size: Option<u32>,
    /// Bits of the shadow map's depth, 16 or 32 (`RenderConfig::shadow_depth_bits`). Default: 16
    /// on a GPU (half the bytes the shadow pass clears and writes; the goldens' views stay within
    /// their bounds), 32 on a software adapter (the goldens' setting). The report's
    /// `shadow_depth_bits` says which.
    #[arg(long, value_parser = crate::args::depth_bits)]
    pub shadow_depth_bits: Option<u32>,
    /// Draw every shadow caster each frame instead of keeping the still scenery's shadow depth
    /// while the cascade holds still (`RenderConfig::shadow_cache`; the pictures are the same).
    /// The report's `shadow_cache` says which, and `shadow_cache_frames` how many frames each
    /// cascade copied its still casters in.
    #[arg(long)]
    pub no_shadow_cache: bool,
}

/// Statistics of one pass over the frames.
#[derive(serde::Serialize)]
struct PassStats {
    pass: &'static str,
    median_ms: f64,
    mean_ms: f64,
    max_ms: f64,
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Outputs of an earlier version that wrote plain files: replaced as a whole by a new set.
fn legacy_output(name: &str) -> bool {
    (name.starts_with("frame_") && name.ends_with(".png"))
        || [
            "demo.gif",
            "demo.mp4",
            "contact_sheet.png",
            "compare_tiers.png",
            "report.json",
        ]
        .contains(&name)
}

/// Run the demo and write its outputs.
pub fn run(gpu: &GpuOptions, args: &Args) -> Result<(), String> {
    if args.scene == "city" {
        return crate::city::run(gpu, &args.out, args.frames);
    }
    let wall = Instant::now();
    // The output folder is checked (and created) before anything runs.
    let mut staging =
        OutputSet::prepare(&args.out, "demo", &format!("--out {}", args.out.display()))?
            .with_legacy(legacy_output);
    for name in ["demo.gif", "report.json", "contact_sheet.png"] {
        staging.check_name(name)?;
    }
    let ctx = GpuContext::new(gpu).map_err(|e| e.to_string())?;
    let mut settings = Settings::new(&ctx, args)?;

    let config = WorldConfig {
        spray: (!args.no_spray).then(snowprint::SprayConfig::default),
        ..WorldConfig::default()
    };
    let mut world = SnowWorld::new(&ctx, config).map_err(|e| e.to_string())?;
    let mut renderer =
        Renderer::new(&ctx, settings.render_config(args)).map_err(|e| e.to_string())?;
    let mut scene = build_scene(&args.scene, &mut world, &mut renderer)?;
    let clip = Clip::new(scene.as_ref(), args, settings.frames)?;
    if let Some(size) = settings.fitted_shadow_map(scene.as_ref(), args, &clip) {
        renderer
            .set_shadow_map_size(size)
            .map_err(|e| e.to_string())?;
    }
    let mut demo = Demo {
        args,
        scene: scene.as_mut(),
        world: &mut world,
        renderer: &mut renderer,
        staging: &mut staging,
    };
    let measured = demo.render_frames(&mut settings, &clip)?;
    let report = demo.report(&ctx, &settings, &clip, &measured, &wall);
    let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
    staging.write("report.json", text)?;
    let files = staging.names().len();
    staging.publish()?;
    eprintln!(
        "snowprint: {} frames of {}x{} ({}, camera {}) in {:.0} s on {}: {} files in {}",
        settings.frames,
        settings.width,
        settings.height,
        args.tier,
        args.camera,
        wall.elapsed().as_secs_f64(),
        ctx.info.name,
        files,
        args.out.display()
    );
    Ok(())
}

/// Frames, sizes and rates of a run: the arguments, or defaults for the adapter (smaller on a
/// software one, with a note saying so).
struct Settings {
    software: bool,
    frames: u32,
    width: u32,
    height: u32,
    supersample: u32,
    sim_hz: u32,
    notes: Vec<String>,
}

impl Settings {
    fn new(ctx: &GpuContext, args: &Args) -> Result<Self, String> {
        let software = ctx.info.device_type == wgpu::DeviceType::Cpu;
        let (default_frames, default_size, default_ss) = if software {
            (60, (800, 450), 1)
        } else {
            (240, (1280, 720), 2)
        };
        let frames = args.frames.unwrap_or(default_frames);
        let (width, height) = args.size.unwrap_or(default_size);
        let supersample = args.supersample.unwrap_or(default_ss);
        let sim_hz = args.sim_hz.unwrap_or(if software { 30 } else { 60 });
        if !(1..=1000).contains(&sim_hz) {
            return Err(format!(
                "--sim-hz {sim_hz}: give 1 to 1000 steps per second"
            ));
        }
        let mut notes = Vec::new();
        if software && (args.frames.is_none() || args.size.is_none() || args.supersample.is_none())
        {
            let note = format!(
                "{} is a software adapter: defaults scaled down to {frames} frames of {width}x{height}, no supersampling, 30 simulation steps per second (a GPU gets 240 frames of 1280x720, 2x2 supersampled, 60 steps per second); pass --frames/--size/--supersample/--sim-hz to change",
                ctx.info.name
            );
            eprintln!("snowprint: {note}");
            notes.push(note);
        }
        Ok(Self {
            software,
            frames,
            width,
            height,
            supersample,
            sim_hz,
            notes,
        })
    }

    fn render_config(&self, args: &Args) -> RenderConfig {
        let mut config = RenderConfig::new(self.width, self.height, args.tier);
        config.supersample = self.supersample;
        config.debug_view = args.debug_view;
        config.opaque = args.opaque.unwrap_or(if self.software {
            OpaquePath::Forward
        } else {
            OpaquePath::Visibility
        });
        if self.software {
            config.snowflakes = 3000;
        }
        if let Some(size) = args.shadow_map_size {
            config.shadow_map_size = size;
        }
        config.shadow_depth_bits =
            args.shadow_depth_bits
                .unwrap_or(if self.software { 32 } else { 16 });
        config.shadow_cache = !args.no_shadow_cache;
        config
    }

    /// On a GPU, unless `--shadow-map-size` says: the shadow map that gives a texel a pixel at
    /// the near cascade's focus for the clip's narrowest field of view.
    fn fitted_shadow_map(&self, scene: &dyn DemoScene, args: &Args, clip: &Clip) -> Option<u32> {
        if self.software || args.shadow_map_size.is_some() {
            return None;
        }
        let fov = clip
            .times
            .iter()
            .filter_map(|&t| scene.camera(&args.camera, t))
            .map(|c| c.fov_y_degrees)
            .reduce(f32::min)?;
        Some(self.render_config(args).shadow_map_size_for_view(fov))
    }
}

/// The seconds of action the frames show: the camera's clip, or `--from`/`--to` within the
/// scene's action; one moment a frame.
struct Clip {
    t0: f32,
    t1: f32,
    times: Vec<f32>,
}

impl Clip {
    fn new(scene: &dyn DemoScene, args: &Args, frames: u32) -> Result<Self, String> {
        if !scene.cameras().contains(&args.camera.as_str()) {
            return Err(format!(
                "unknown camera {:?}; this demo has {}",
                args.camera,
                scene.cameras().join(", ")
            ));
        }
        let (mut t0, mut t1) = scene.span(&args.camera);
        if let Some(f) = args.from {
            t0 = f;
        }
        if let Some(t) = args.to {
            t1 = t;
        }
        let (_, end) = scene.span(&args.camera);
        let end = end.max(
            scene
                .cameras()
                .iter()
                .map(|c| scene.span(c).1)
                .fold(0.0, f32::max),
        );
        if t1 > end {
            return Err(format!(
                "--to {}: the action of this demo ends at {end} s; give --to at most {end}",
                if t1 >= 1e6 {
                    format!("{t1:e}")
                } else {
                    t1.to_string()
                }
            ));
        }
        if !(t0.is_finite() && t1.is_finite() && t0 >= 0.0 && t1 >= t0) {
            return Err(format!(
                "--from {t0} / --to {t1}: give 0 <= from <= to seconds"
            ));
        }
        let times: Vec<f32> = (0..frames)
            .map(|k| {
                if frames == 1 {
                    t1
                } else {
                    t0 + (t1 - t0) * k as f32 / (frames - 1) as f32
                }
            })
            .collect();
        Ok(Self { t0, t1, times })
    }
}

/// What the frames measured, for the report.
struct Measured {
    sim_ms: f64,
    render_ms: Vec<f64>,
    /// CPU time to build and submit each frame (no readback, no image encoding).
    encode_ms: Vec<f64>,
    pass_ms: Vec<(&'static str, Vec<f64>)>,
    /// Each frame's CPU steps (`RenderOutput::cpu_phases`), by name.
    phase_ms: Vec<(&'static str, Vec<f64>)>,
    first_surfaces: Option<Vec<SurfaceShading>>,
    last_surfaces: Vec<SurfaceShading>,
    last_overflow: u32,
    instances_count: usize,
    culled_last: usize,
    shadow_last: snowprint::render::ShadowStats,
    /// Frames whose near and far cascades copied their still casters in from the cache.
    cache_frames: [usize; 2],
    mp4: bool,
}

/// A run of the rendered demo: the scene, the world it presses, the renderer and the output set.
struct Demo<'a> {
    args: &'a Args,
    scene: &'a mut dyn DemoScene,
    world: &'a mut SnowWorld,
    renderer: &'a mut Renderer,
    staging: &'a mut OutputSet,
}

impl Demo<'_> {
    /// Simulate up to each moment of the clip, render it and write the frame, the GIF, the contact
    /// sheet and (with ffmpeg) the MP4.
    fn render_frames(&mut self, settings: &mut Settings, clip: &Clip) -> Result<Measured, String> {
        let (args, frames) = (self.args, settings.frames);
        let sim_dt = 1.0 / settings.sim_hz as f32;
        let sheet_frames = contact_sheet::pick(frames as usize, 6);
        let mut sheet_images = Vec::new();
        let gif_path = self.staging.path("demo.gif");
        let delay_ms = if frames > 1 {
            ((clip.t1 - clip.t0) / (frames - 1) as f32 * 1000.0).clamp(20.0, 200.0) as u32
        } else {
            1000
        };
        // The GIF keeps at most 120 frames (every k-th), so that it stays a few megabytes.
        let gif_every = frames.div_ceil(120) as usize;
        let mut gif = contact_sheet::GifWriter::create(
            &gif_path,
            settings.width,
            settings.height,
            delay_ms * gif_every as u32,
        )?;

        let mut bar = Progress::new(frames as u64, "demo", "frames")?;
        bar.set_message("simulating");

        let mut sim_t = 0.0f32;
        let mut m = Measured {
            sim_ms: 0.0,
            render_ms: Vec::new(),
            encode_ms: Vec::new(),
            pass_ms: Vec::new(),
            phase_ms: Vec::new(),
            first_surfaces: None,
            last_surfaces: Vec::new(),
            last_overflow: 0,
            instances_count: 0,
            culled_last: 0,
            shadow_last: Default::default(),
            cache_frames: [0, 0],
            mp4: false,
        };
        for (k, &t) in clip.times.iter().enumerate() {
            bar.set_message("simulating");
            let start = Instant::now();
            while sim_t + sim_dt <= t + 1e-4 {
                self.scene.advance(self.world, sim_t, sim_t + sim_dt)?;
                sim_t += sim_dt;
            }
            m.sim_ms += start.elapsed().as_secs_f64() * 1e3;
            bar.set_message("rendering");
            let camera = self
                .scene
                .camera(&args.camera, t)
                .ok_or_else(|| format!("camera {:?} has no view at {t} s", args.camera))?;
            let instances = self.scene.instances(t);
            m.instances_count = instances.len();
            // Copies, so that the frame borrows nothing of `self` (the scene is advanced through
            // it, and `compare_tiers` renders through it).
            let (surfaces, lights) = (self.scene.surfaces().to_vec(), self.scene.lights().to_vec());
            let frame = RenderFrame {
                camera,
                time: t,
                surfaces: &surfaces,
                instances: &instances,
                lights: &lights,
                environment: self.scene.environment(),
                snowfall: !args.no_snowfall,
            };
            let out = self
                .renderer
                .render(self.world, &frame)
                .map_err(|e| e.to_string())?;
            m.render_ms.push(out.cpu_ms);
            m.encode_ms.push(out.cpu_encode_ms);
            for p in &out.cpu_phases {
                match m.phase_ms.iter_mut().find(|(n, _)| *n == p.name) {
                    Some((_, v)) => v.push(p.ms),
                    None => m.phase_ms.push((p.name, vec![p.ms])),
                }
            }
            for p in &out.pass_times {
                match m.pass_ms.iter_mut().find(|(n, _)| *n == p.name) {
                    Some((_, v)) => v.push(p.gpu_ms),
                    None => m.pass_ms.push((p.name, vec![p.gpu_ms])),
                }
            }
            if m.first_surfaces.is_none() {
                m.first_surfaces = Some(out.surfaces.clone());
            }
            m.last_surfaces = out.surfaces.clone();
            m.last_overflow = out.dice_overflow;
            m.culled_last = out.culled_instances;
            m.shadow_last = out.shadow;
            for (n, &cached) in m.cache_frames.iter_mut().zip(&out.shadow.from_cache) {
                *n += usize::from(cached);
            }
            let image = image::RgbaImage::from_raw(out.width, out.height, out.rgba8)
                .ok_or("the renderer returned a frame of the wrong size")?;
            if args.compare_tiers && k + 1 == clip.times.len() {
                self.compare_tiers(&frame)?;
            }
            self.staging
                .write_with(&format!("frame_{k:04}.png"), |path| image.save(path))?;
            if k % gif_every == 0 {
                gif.add(&image)?;
            }
            if sheet_frames.contains(&k) {
                sheet_images.push((k, t, image));
            }
            bar.inc(1);
        }
        bar.set_message("encoding");
        gif.finish()?;
        let sheet = contact_sheet::compose(&sheet_images);
        self.staging
            .write_with("contact_sheet.png", |path| sheet.save(path))?;
        m.mp4 = frames > 1 && self.encode_mp4(delay_ms, &mut settings.notes);
        bar.finish();
        Ok(m)
    }

    /// Render `frame` again in the relief and the tessellated tiers and write them side by side.
    fn compare_tiers(&mut self, frame: &RenderFrame) -> Result<(), String> {
        let mut pair = Vec::new();
        for tier in [Tier::Relief, Tier::Tessellated] {
            self.renderer.set_tier(tier);
            let o = self
                .renderer
                .render(self.world, frame)
                .map_err(|e| e.to_string())?;
            pair.push(
                image::RgbaImage::from_raw(o.width, o.height, o.rgba8)
                    .ok_or("the renderer returned a frame of the wrong size")?,
            );
        }
        self.renderer.set_tier(self.args.tier);
        let sheet = contact_sheet::side_by_side(&pair[0], &pair[1], "relief", "tessellated");
        self.staging
            .write_with("compare_tiers.png", |path| sheet.save(path))?;
        Ok(())
    }

    /// The frames as `demo.mp4` when ffmpeg is on the PATH; otherwise a note and no file.
    fn encode_mp4(&mut self, delay_ms: u32, notes: &mut Vec<String>) -> bool {
        let fps = (1000.0 / delay_ms as f32).round().max(1.0);
        let dir = self.staging.staging().to_owned();
        let made = contact_sheet::encode_mp4(&dir, &self.staging.path("demo.mp4"), fps);
        if !made {
            let _ = std::fs::remove_file(dir.join("demo.mp4"));
            self.staging.forget("demo.mp4");
            notes.push("ffmpeg is not on the PATH (or failed): no demo.mp4".into());
        }
        made
    }

    /// `report.json`: the adapter, the settings, the passes and their times, each surface's
    /// material, the notes and the outputs.
    fn report(
        &self,
        ctx: &GpuContext,
        settings: &Settings,
        clip: &Clip,
        m: &Measured,
        wall: &Instant,
    ) -> serde_json::Value {
        let (args, world, renderer) = (self.args, &*self.world, &*self.renderer);
        let surfaces_json: Vec<serde_json::Value> = self
            .scene
            .surfaces()
            .iter()
            .map(|(id, ground)| {
                let desc = world.surface(*id).ok();
                let first = m
                    .first_surfaces
                    .as_ref()
                    .and_then(|v| v.iter().find(|s| s.surface == *id))
                    .map(|s| s.material);
                let last = m.last_surfaces.iter().find(|s| s.surface == *id);
                serde_json::json!({
                    "index": id.index(),
                    "name": desc.map(|d| d.name.clone()),
                    "size_m": desc.map(|d| d.size.to_array()),
                    "snow_depth_m": desc.map(|d| d.snow_depth),
                    "heightmap": world.layout(*id).ok().map(|l| [l.width, l.height]),
                    "ground": ground,
                    "material_first_frame": first,
                    "material_last_frame": last.map(|s| s.material),
                    "deepest_print_last_frame": last.map(|s| s.deepest),
                    "diced_triangles_last_frame": last.map(|s| s.triangles),
                })
            })
            .collect();
        let basic_last: Vec<u32> = m
            .last_surfaces
            .iter()
            .filter(|s| s.material == snowprint::render::SnowMaterialKind::Basic)
            .map(|s| s.surface.index())
            .collect();
        let gpu_times: Vec<PassStats> = m
            .pass_ms
            .iter()
            .map(|(name, v)| PassStats {
                pass: name,
                mean_ms: v.iter().sum::<f64>() / v.len().max(1) as f64,
                max_ms: v.iter().copied().fold(0.0, f64::max),
                median_ms: median(&mut v.clone()),
            })
            .collect();
        let timestamps_note = if renderer.has_timestamps() {
            serde_json::Value::Null
        } else {
            serde_json::json!(format!(
                "{} has no GPU timestamp queries: per-pass GPU times are unavailable; CPU times per frame are reported instead",
                ctx.info.name
            ))
        };
        let mut outputs: Vec<String> = self.staging.names().to_vec();
        outputs.push("report.json".into());
        serde_json::json!({
            "adapter": {
                "name": ctx.info.name,
                "backend": format!("{:?}", ctx.info.backend),
                "device_type": format!("{:?}", ctx.info.device_type),
                "driver": format!("{} {}", ctx.info.driver, ctx.info.driver_info),
                "software": settings.software,
            },
            "resolution": [settings.width, settings.height],
            "supersample": settings.supersample,
            "frames": settings.frames,
            "tier": args.tier,
            "opaque": self.renderer.config().opaque,
            "camera": args.camera,
            "debug_view": args.debug_view,
            "scene": self.scene.name(),
            "clip_seconds": [clip.t0, clip.t1],
            "simulation_hz": settings.sim_hz,
            "instances_last_frame": m.instances_count,
            "instances_culled_last_frame": m.culled_last,
            "shadow_map_size": self.renderer.config().shadow_map_size,
            "shadow_depth_bits": self.renderer.config().shadow_depth_bits,
            "shadow_last_frame": m.shadow_last,
            "shadow_cache": self.renderer.config().shadow_cache,
            "shadow_cache_frames": m.cache_frames,
            "search": renderer.config().search_settings(),
            "passes": renderer.passes(),
            "gpu_pass_times_ms": gpu_times,
            "dice_overflow_last_frame": m.last_overflow,
            "gpu_pass_times_note": timestamps_note,
            "cpu_ms": {
                "simulation_total": m.sim_ms,
                "render_median_per_frame": median(&mut m.render_ms.clone()),
                "frame_build_median": median(&mut m.encode_ms.clone()),
                "frame_build_phases_median": m
                    .phase_ms
                    .iter()
                    .map(|(name, v)| serde_json::json!({"phase": name, "median_ms": median(&mut v.clone())}))
                    .collect::<Vec<_>>(),
                "render_total": m.render_ms.iter().sum::<f64>(),
            },
            "surfaces": surfaces_json,
            "basic_material_surfaces_last_frame": basic_last,
            "notes": settings.notes,
            "outputs": outputs,
            "mp4": m.mp4,
            "wall_seconds": wall.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn args(out: &Path) -> Args {
        Args {
            out: out.to_owned(),
            frames: Some(3),
            size: Some((64, 36)),
            camera: "closeup".into(),
            tier: Tier::Pom,
            opaque: None,
            supersample: Some(1),
            debug_view: DebugView::Shaded,
            no_snowfall: false,
            from: Some(1.0),
            to: Some(1.2),
            sim_hz: Some(10),
            scene: "rooftops".into(),
            compare_tiers: false,
            no_spray: false,
            shadow_map_size: None,
            shadow_depth_bits: None,
            no_shadow_cache: false,
        }
    }

    #[test]
    fn the_tessellated_tier_compares_with_relief_side_by_side() {
        let out = scratch("compare");
        let mut a = args(&out);
        a.tier = Tier::Tessellated;
        a.frames = Some(1);
        a.compare_tiers = true;
        run(&GpuOptions::default(), &a).unwrap();
        let sheet = image::open(out.join("compare_tiers.png")).unwrap();
        assert_eq!((sheet.width(), sheet.height()), (2 * 64 + 8, 36));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["tier"], "tessellated");
        assert_eq!(report["dice_overflow_last_frame"], 0);
        let passes: Vec<&str> = report["passes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        for name in ["banks", "dice", "snow_shadow"] {
            assert!(passes.contains(&name), "{passes:?}");
        }
        let diced: u64 = report["surfaces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["diced_triangles_last_frame"].as_u64().unwrap_or(0))
            .sum();
        assert!(diced > 0, "no surface was diced");
        let _ = std::fs::remove_dir_all(&out);
    }

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("snowprint-demo-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_run_writes_every_output_and_replaces_an_earlier_run() {
        let out = scratch("outputs");
        std::fs::create_dir_all(&out).unwrap();
        // Left by an earlier, longer run: must not survive next to the new frames.
        std::fs::write(out.join("frame_0009.png"), b"stale").unwrap();
        std::fs::write(out.join("notes.txt"), b"the user's").unwrap();
        run(&GpuOptions::default(), &args(&out)).unwrap();
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        // The set's own entries (its generation and the link to it) are hidden.
        names.retain(|n| n != "demo.mp4" && !n.starts_with(".snowprint-demo-"));
        assert_eq!(
            names,
            [
                "contact_sheet.png",
                "demo.gif",
                "frame_0000.png",
                "frame_0001.png",
                "frame_0002.png",
                "notes.txt",
                "report.json"
            ]
        );
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["frames"], 3);
        assert_eq!(report["resolution"], serde_json::json!([64, 36]));
        assert_eq!(report["tier"], "pom");
        assert_eq!(report["camera"], "closeup");
        assert!(report["adapter"]["name"].is_string());
        // The goldens' forward path and 32-bit shadow depth on a software adapter; on a GPU the
        // visibility buffer and half the shadow map's bytes.
        let software = report["adapter"]["software"].as_bool().unwrap();
        let expected = if software {
            serde_json::json!(["forward", 32])
        } else {
            serde_json::json!(["visibility", 16])
        };
        assert_eq!(
            serde_json::json!([report["opaque"], report["shadow_depth_bits"]]),
            expected,
            "{software}"
        );
        // Nobody walks on the street (surface 0) of the demo world: the basic material.
        let basic = report["basic_material_surfaces_last_frame"]
            .as_array()
            .unwrap();
        assert!(basic.contains(&serde_json::json!(0)), "{basic:?}");
        assert_eq!(report["scene"], "snowprint::demo (DemoWorld::build)");
        assert!(report["gpu_pass_times_ms"].is_array());
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn a_failed_run_leaves_nothing_that_looks_complete() {
        let out = scratch("failed");
        let mut a = args(&out);
        a.camera = "nowhere".into();
        let e = run(&GpuOptions::default(), &a).unwrap_err();
        assert!(e.contains("nowhere") && e.contains("closeup"), "{e}");
        assert!(!out.join("report.json").exists());
        let mut a = args(&out);
        a.from = Some(2.0);
        a.to = Some(1.0);
        assert!(
            run(&GpuOptions::default(), &a)
                .unwrap_err()
                .contains("--from")
        );
        assert!(!out.join("report.json").exists());
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert!(parse_size("1280").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(parse_size("0x10").unwrap_err().contains("16 to 8192"));
    }
}
