//! The window's event loop and the frame: keys and script to intent, the person's trudge through
//! the probe cache, the world's update and the renderer's passes recorded into one encoder, the
//! present, and the outputs of a scripted run.

use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

use glam::{Vec2, Vec3};
use snowprint::render::{DebugView, RenderConfig, RenderFrame, Renderer, Tier};
use snowprint::{GpuOptions, SnowWorld, WorldConfig};
use snowprint_demo::trudge::Trudge;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::hud::{Hud, Placement};
use super::player::{Intent, Player};
use super::script::Key;
use super::window::{Gfx, Readback, Rgba};
use super::yard::{Orbit, SIDE, SNOW_DEPTH, Yard};
use super::{Checked, Script};
use crate::demo::contact_sheet::GifWriter;

/// Keys to the trudge's probe cache (the feet).
const TRUDGE_KEYS: u64 = 1;
/// Camera turn of the arrow keys, radians a second, and of a mouse drag, radians a pixel.
const ARROW_TURN: f32 = 1.6;
const DRAG_TURN: f32 = 0.006;
/// The GIF keeps every third frame (a few megabytes a minute at 320x180).
const GIF_EVERY: u32 = 3;
/// Frames of the person's path kept for the report (an hour at 60 frames a second).
const MAX_PATH: usize = 216_000;

fn key_of(code: KeyCode) -> Option<Key> {
    Some(match code {
        KeyCode::KeyW => Key::Forward,
        KeyCode::KeyS => Key::Back,
        KeyCode::KeyA => Key::Left,
        KeyCode::KeyD => Key::Right,
        KeyCode::ShiftLeft | KeyCode::ShiftRight => Key::Run,
        KeyCode::KeyC => Key::Slide,
        KeyCode::KeyF => Key::Fall,
        KeyCode::Space => Key::Throw,
        KeyCode::KeyT => Key::Tier,
        KeyCode::KeyV => Key::View,
        KeyCode::ArrowLeft => Key::OrbitLeft,
        KeyCode::ArrowRight => Key::OrbitRight,
        KeyCode::ArrowUp => Key::OrbitUp,
        KeyCode::ArrowDown => Key::OrbitDown,
        _ => return None,
    })
}

fn next_tier(t: Tier) -> Tier {
    match t {
        Tier::Relief => Tier::Pom,
        Tier::Pom => Tier::Tessellated,
        _ => Tier::Relief,
    }
}

fn next_view(v: DebugView) -> DebugView {
    match v {
        DebugView::Shaded => DebugView::Materials,
        DebugView::Materials => DebugView::Depression,
        DebugView::Depression => DebugView::Occlusion,
        DebugView::Occlusion => DebugView::Normals,
        DebugView::Normals => DebugView::Taps,
        _ => DebugView::Shaded,
    }
}

/// The same frame rendered offscreen and read back (a surface that cannot be copied).
fn offscreen(
    renderer: &mut Renderer,
    world: &SnowWorld,
    frame: &RenderFrame<'_>,
) -> Result<Rgba, String> {
    let out = renderer.render(world, frame).map_err(|e| e.to_string())?;
    Rgba::from_raw(out.width, out.height, out.rgba8)
        .ok_or_else(|| "the renderer returned a frame of the wrong size".into())
}

/// Everything a running window holds.
struct Game {
    window: Arc<Window>,
    gfx: Gfx,
    world: SnowWorld,
    renderer: Renderer,
    yard: Yard,
    player: Player,
    trudge: Trudge,
    orbit: Orbit,
    /// Keys held on the keyboard, and action keys pressed since the last frame.
    held: HashSet<Key>,
    pressed: Vec<Key>,
    drag: Option<(f64, f64)>,
    /// Seconds of play, frames shown, and when the last frame started.
    time: f32,
    frames: u32,
    last: Instant,
    frame_ms: Vec<f64>,
    title_at: Instant,
    /// The heads-up line (frame time, tier, view) and its pass.
    hud: Hud,
    hud_text: String,
    gif: Option<GifWriter>,
    snowfall: bool,
    /// The pelvis (x, z) at every frame, for the report.
    path: Vec<[f32; 2]>,
    report: Option<std::path::PathBuf>,
}

/// The winit application: the checked arguments, then the game once the window exists.
struct App {
    gpu: GpuOptions,
    checked: Checked,
    game: Option<Game>,
    result: Result<(), String>,
}

/// Open the window and run the event loop until the game ends.
pub fn run(gpu: &GpuOptions, checked: Checked) -> Result<(), String> {
    let event_loop = EventLoop::new().map_err(|e| {
        format!("cannot open a window ({e}); play needs a display: set DISPLAY (under Xvfb for a machine without a screen)")
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        gpu: gpu.clone(),
        checked,
        game: None,
        result: Ok(()),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| format!("the window's event loop failed: {e}"))?;
    app.result?;
    Ok(())
}

impl App {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<Game, String> {
        let args = &self.checked.args;
        let (w, h) = args.size.unwrap_or((960, 540));
        let attributes = Window::default_attributes()
            .with_title("snowprint play")
            .with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| format!("cannot open a window: {e}"))?,
        );
        let mut gfx = Gfx::new(window.clone(), self.gpu.adapter.as_deref())?;
        let software = gfx.ctx.info.device_type == wgpu::DeviceType::Cpu;
        if software && args.size.is_none() {
            // A software adapter draws a smaller window at a playable rate.
            let _ = window.request_inner_size(winit::dpi::PhysicalSize::new(640u32, 360u32));
            gfx.resize(640, 360);
        }
        let mut config = RenderConfig::new(gfx.config.width, gfx.config.height, args.tier);
        config.supersample = args.supersample.unwrap_or(if software { 1 } else { 2 });
        config.debug_view = args.debug_view;
        if software {
            config.snowflakes = 3000;
        } else {
            // As `snowprint demo` on a GPU: the scene shaded in compute through the visibility
            // buffer, and half the shadow map's bytes.
            config.opaque = snowprint::render::OpaquePath::Visibility;
            config.shadow_depth_bits = 16;
        }
        let mut world = SnowWorld::new(
            &gfx.ctx,
            WorldConfig {
                spray: Some(snowprint::SprayConfig::default()),
                ..WorldConfig::default()
            },
        )
        .map_err(|e| e.to_string())?;
        let mut renderer = Renderer::new(&gfx.ctx, config).map_err(|e| e.to_string())?;
        let yard = Yard::new(&mut world, &mut renderer)?;
        let half = Vec2::splat(SIDE * 0.5 - 0.6);
        let player = Player::new(Vec2::new(0.0, 3.0), 0.0, 0.0, SNOW_DEPTH, [-half, half]);
        let orbit = Orbit::new(Vec3::new(0.0, 1.0, 3.0));
        let gif = match &args.gif {
            Some(path) => Some(GifWriter::create(
                path,
                gfx.config.width,
                gfx.config.height,
                // Every second frame: real time when the step is fixed.
                args.dt
                    .map_or(66, |dt| (2000.0 * dt).clamp(20.0, 200.0) as u32),
            )?),
            None => None,
        };
        eprintln!(
            "snowprint: playing on {} ({}), {}x{}, {} tier; screenshots {}",
            gfx.ctx.info.name,
            if software { "software" } else { "GPU" },
            gfx.config.width,
            gfx.config.height,
            args.tier,
            if gfx.copyable {
                "copy the window's own surface texture"
            } else {
                "render the same frame offscreen (this surface cannot be copied)"
            }
        );
        let hud = Hud::new(&gfx.ctx.device, gfx.config.format);
        Ok(Game {
            window,
            gfx,
            world,
            renderer,
            yard,
            player,
            trudge: Trudge::new(0.0, TRUDGE_KEYS, 2),
            orbit,
            held: HashSet::new(),
            pressed: Vec::new(),
            drag: None,
            time: 0.0,
            frames: 0,
            last: Instant::now(),
            frame_ms: Vec::new(),
            title_at: Instant::now(),
            hud,
            hud_text: String::new(),
            gif,
            snowfall: !args.no_snowfall,
            path: Vec::new(),
            report: args.report.clone(),
        })
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: String) {
        if self.result.is_ok() {
            self.result = Err(e);
        }
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.game.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(g) => self.game = Some(g),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(game) = self.game.as_mut() else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                game.gfx.resize(size.width, size.height);
                let ss = game.renderer.config().supersample;
                let (w, h) = (game.gfx.config.width, game.gfx.config.height);
                if let Err(e) = game.renderer.resize(w, h, ss) {
                    self.fail(event_loop, e.to_string());
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                if code == KeyCode::Escape {
                    event_loop.exit();
                    return;
                }
                let Some(key) = key_of(code) else { return };
                match event.state {
                    ElementState::Pressed if !event.repeat => {
                        game.held.insert(key);
                        if key.is_action() {
                            game.pressed.push(key);
                        }
                    }
                    ElementState::Pressed => {}
                    ElementState::Released => {
                        game.held.remove(&key);
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => game.drag = (state == ElementState::Pressed).then_some((f64::NAN, f64::NAN)),
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = game.drag {
                    if x.is_finite() {
                        let (dx, dy) = ((position.x - x) as f32, (position.y - y) as f32);
                        game.orbit.turn(-dx * DRAG_TURN, dy * DRAG_TURN);
                    }
                    game.drag = Some((position.x, position.y));
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                game.orbit.distance = (game.orbit.distance * 0.9f32.powf(lines)).clamp(2.0, 20.0);
            }
            WindowEvent::RedrawRequested => {
                let script = self.checked.script.as_ref();
                match game.frame(script, &self.checked.args) {
                    Ok(true) => {}
                    Ok(false) => event_loop.exit(),
                    Err(e) => self.fail(event_loop, e),
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(g) = &self.game {
            g.window.request_redraw();
        }
    }

    fn exiting(&mut self, _: &ActiveEventLoop) {
        if let Some(game) = self.game.take()
            && let Err(e) = game.finish()
            && self.result.is_ok()
        {
            self.result = Err(e);
        }
    }
}

impl Game {
    /// The keys held now and the actions pressed since the last frame, from the keyboard and the
    /// script (between `t0` and `t1` seconds of play).
    fn input(&mut self, script: Option<&Script>, t0: f32, t1: f32) -> (HashSet<Key>, Vec<Key>) {
        let mut held = self.held.clone();
        let mut pressed = std::mem::take(&mut self.pressed);
        if let Some(s) = script {
            held.extend(s.held(t1).iter().copied());
            pressed.extend(s.presses(if t0 <= 0.0 { -1.0 } else { t0 }, t1));
        }
        (held, pressed)
    }

    /// One frame; `Ok(false)` when the run is over.
    fn frame(&mut self, script: Option<&Script>, args: &super::Args) -> Result<bool, String> {
        let now = Instant::now();
        let wall = now.duration_since(self.last).as_secs_f32();
        self.last = now;
        if self.frames > 0 {
            self.frame_ms.push(f64::from(wall) * 1e3);
        }
        let dt = args.dt.unwrap_or(wall.clamp(1e-3, 0.1));
        let t0 = self.time;
        self.time += dt;
        let (held, pressed) = self.input(script, t0, self.time);
        for key in &pressed {
            match key {
                Key::Tier => self
                    .renderer
                    .set_tier(next_tier(self.renderer.config().tier)),
                Key::View => self
                    .renderer
                    .set_debug_view(next_view(self.renderer.config().debug_view)),
                _ => {}
            }
        }
        let axis = |a: Key, b: Key| f32::from(held.contains(&a)) - f32::from(held.contains(&b));
        self.orbit.turn(
            axis(Key::OrbitLeft, Key::OrbitRight) * ARROW_TURN * dt,
            axis(Key::OrbitUp, Key::OrbitDown) * ARROW_TURN * 0.5 * dt,
        );
        let direction = self.orbit.forward() * axis(Key::Forward, Key::Back)
            + self.orbit.right() * axis(Key::Right, Key::Left);
        let intent = Intent {
            direction: direction.normalize_or_zero(),
            run: held.contains(&Key::Run),
            slide: pressed.contains(&Key::Slide),
            fall: pressed.contains(&Key::Fall),
            throw: pressed.contains(&Key::Throw),
        };
        // The person's clock runs at the trudge pace of the snow under the feet (the probe
        // cache's answer of a frame or two ago; nothing waits).
        let before = self.trudge.clock;
        // Only a gait slows: a slide or a fall keeps the world's time.
        let walking = !self.player.is_down();
        let clock = self
            .trudge
            .read(&mut self.world, dt, walking)
            .map_err(|e| e.to_string())?;
        self.trudge
            .probe(&mut self.world, &self.player.feet())
            .map_err(|e| e.to_string())?;
        self.player
            .advance(clock - before, dt, self.trudge.sink, intent);
        let (at, _) = self.player.position();
        if self.path.len() < MAX_PATH {
            self.path.push(at.to_array());
        }
        let pelvis = self.player.parts().first().map_or(1.0, |p| p.position.y);
        self.orbit
            .follow(Vec3::new(at.x, (pelvis + 0.2).max(0.6), at.y), dt);
        // A script without --frames or --seconds ends the run when it ends.
        let script_end = script
            .filter(|_| args.frames.is_none() && args.seconds.is_none())
            .map(Script::duration);
        let last = args.frames.is_some_and(|n| self.frames + 1 >= n)
            || args.seconds.is_some_and(|s| self.time >= s)
            || script_end.is_some_and(|end| self.time >= end);
        let shown = self.draw(
            dt,
            last || self.gif.is_some() && self.frames.is_multiple_of(GIF_EVERY),
        )?;
        if let Some(image) = shown {
            if let Some(gif) = &mut self.gif {
                gif.add(&image)?;
            }
            if last && let Some(path) = &args.screenshot {
                image
                    .save(path)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            }
        }
        self.frames += 1;
        self.title();
        Ok(!last)
    }

    /// Step the world and draw into the window, in one encoder; with `read`, also return the
    /// frame shown.
    fn draw(&mut self, dt: f32, read: bool) -> Result<Option<Rgba>, String> {
        let deformers = self.player.deformers(&self.yard.part_world);
        let instances = self.yard.instances(&self.player);
        let frame = RenderFrame {
            camera: self.orbit.camera(),
            time: self.time,
            surfaces: &self.yard.surfaces,
            instances: &instances,
            lights: &self.yard.lights,
            environment: snowprint::render::Environment::moonlit_night(),
            snowfall: self.snowfall,
        };
        let device = self.gfx.ctx.device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("snowprint play frame"),
        });
        let snow = self
            .world
            .encode_step(&mut encoder, dt, &deformers)
            .map_err(|e| e.to_string())?;
        let Some(texture) = self.gfx.acquire()? else {
            // No texture this frame: the snow still goes in.
            self.gfx.ctx.queue.submit([encoder.finish()]);
            self.world.submitted(snow).map_err(|e| e.to_string())?;
            return if read {
                offscreen(&mut self.renderer, &self.world, &frame).map(Some)
            } else {
                Ok(None)
            };
        };
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let pic = self
            .renderer
            .encode_to_view(
                &mut encoder,
                &self.world,
                &frame,
                &view,
                self.gfx.config.format,
            )
            .map_err(|e| e.to_string())?;
        let size = (self.gfx.config.width, self.gfx.config.height);
        self.hud.encode(
            &self.gfx.ctx.queue,
            &mut encoder,
            &view,
            size,
            Placement::corner(size.1),
            &self.hud_text,
        );
        let copy = (read && self.gfx.copyable)
            .then(|| Readback::record(&device, &mut encoder, &texture.texture));
        self.gfx.ctx.queue.submit([encoder.finish()]);
        self.world.submitted(snow).map_err(|e| e.to_string())?;
        let _ = self.renderer.submitted(pic);
        self.window.pre_present_notify();
        self.gfx.ctx.queue.present(texture);
        match copy {
            Some(c) => c.read(&device).map(Some),
            None if read => offscreen(&mut self.renderer, &self.world, &frame).map(Some),
            None => Ok(None),
        }
    }

    /// The frame time and the state in the window's title and its heads-up line, twice a second.
    fn title(&mut self) {
        if self.title_at.elapsed().as_secs_f32() < 0.5 {
            return;
        }
        self.title_at = Instant::now();
        let recent = &self.frame_ms[self.frame_ms.len().saturating_sub(30)..];
        let ms = recent.iter().sum::<f64>() / recent.len().max(1) as f64;
        let c = self.renderer.config();
        self.hud_text = format!(
            "{ms:.1} ms {:.0} fps {} {}",
            1000.0 / ms.max(1e-3),
            c.tier,
            format!("{:?}", c.debug_view).to_lowercase()
        );
        self.window.set_title(&format!(
            "snowprint play: {ms:.1} ms/frame ({:.0} fps) | {} | {:?} | WASD walk, Shift run, C slide, F fall, Space throw, T tier, V view, drag orbit",
            1000.0 / ms.max(1e-3),
            c.tier,
            c.debug_view,
        ));
    }

    /// The run is over: finish the GIF and say how fast the frames came.
    fn finish(mut self) -> Result<(), String> {
        if let Some(gif) = self.gif.take() {
            gif.finish()?;
        }
        let mut ms = self.frame_ms.clone();
        ms.sort_by(f64::total_cmp);
        let median = ms.get(ms.len() / 2).copied().unwrap_or(0.0);
        eprintln!(
            "snowprint: {} frames, {:.1} s of play, median frame {median:.1} ms",
            self.frames, self.time
        );
        if let Some(path) = &self.report {
            let camera = self.orbit.camera();
            let c = self.renderer.config();
            let report = serde_json::json!({
                "adapter": self.gfx.ctx.info.name,
                "software": self.gfx.ctx.info.device_type == wgpu::DeviceType::Cpu,
                "size": [self.gfx.config.width, self.gfx.config.height],
                "tier": c.tier,
                "debug_view": c.debug_view,
                "frames": self.frames,
                "seconds": self.time,
                "median_frame_ms": median,
                "screenshot_source": if self.gfx.copyable { "surface texture" } else { "offscreen render" },
                "camera": {
                    "eye": camera.eye.to_array(),
                    "target": camera.target.to_array(),
                    "fov_y_degrees": camera.fov_y_degrees,
                },
                "snow_top": SNOW_DEPTH,
                "path": self.path,
            });
            let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
            std::fs::write(path, text)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
        Ok(())
    }
}
