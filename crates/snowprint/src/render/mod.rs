//! The renderer: snow surfaces shaded as in the talk's "Stage 3 - Shading", with the meshes of a
//! world (rooftops, props, people), a moonlit sky, shadows and falling snow.
//!
//! A frame is a fixed graph of explicit passes ([`PASSES`]), each naming what it reads and writes:
//!
//! | pass | reads | writes |
//! |---|---|---|
//! | `classify` (compute) | heightmap pool, surface table | surface state: material flag, indirect args |
//! | `heightfield` (compute, indirect) | pool, surface state | per deformed surface: depression, normal, AO texture |
//! | `shadow` | instances, each cascade's cache of still casters | the moon's shadow map (restored from the caches where they hold) |
//! | `opaque` | instances in view, shadow map | scene colour (HDR), depth; or depth and the visibility buffer ([`OpaquePath::Visibility`]) |
//! | `snow` (indirect) | surface state, heightfields, shadow map | scene colour, depth (on the visibility path: the deformable and diced snow's hits into the visibility buffer) |
//! | `snow_shade` (compute) | visibility buffer, hits, heightfields, shadow map, depth | scene colour where the snow's hit is visible (empty on the forward path) |
//! | `opaque_shade` (compute) | visibility buffer, instances, shadow map, depth | scene colour where the snow left the opaque visible (empty on the forward path) |
//! | `sky` | depth | scene colour |
//! | `snowfall` | depth | scene colour |
//! | `spray` | the world's spray ring, depth | scene colour |
//! | `tonemap` (compute; raster for a view that cannot be a storage texture) | scene colour, depth | the output |
//!
//! Each snow surface is drawn as the box of its snow slab. A surface whose heightmap is all zero
//! gets the talk's **basic** material (untouched snow, no heightmap reads); any other the
//! **deformable** one: the view ray is traced through the heightfield by relief mapping (linear
//! taps and a binary refinement; [`Tier::Pom`] uses parallax occlusion mapping with self-shadowing
//! instead), and the hit blends untouched snow with the flattened ground (roof tiles or concrete)
//! by the heightmap, normals by Reoriented Normal Mapping, the transition tinted with the sky. The
//! choice is made on the GPU by `classify` and costs no readback; [`RenderOutput`] reports it.
//!
//! Each pass is a module with its WGSL beside it (`classify/`, `heightfield/`, `shadow/`,
//! `opaque/`, `snow/`, `tessellate/{banks,dice,snow_shadow}/`, `sky/`, `snowfall/`, `spray/`, `tonemap/`),
//! owning its layouts, pipelines and buffers, with `new`, `prepare` (the frame's uploads and bind
//! groups) and `encode`. What they share has small modules of its own: `frame/` (the frame
//! uniform and `frame.wgsl`), `targets`, `cascades` (the shadow cascades' maths), `meshes`,
//! `stats` (the report's readback) and `readback` (buffer readbacks and timestamps). A frame reads
//! the world once, through [`SnowWorld::frame_view`](crate::SnowWorld::frame_view).
//!
//! The material is the WGSL module [`SNOW_WGSL`], which another renderer can import (see the
//! header of `snow.wgsl` and `docs/RENDERING.md`). Its maths have CPU references in [`crate::reference::material`].
//!
//! ```no_run
//! use glam::{Mat4, Vec3};
//! use snowprint::render::{Environment, Instance, RenderConfig, RenderFrame, Renderer, Tier};
//! use snowprint::{Camera, GpuContext, GpuOptions, GroundMaterial, Mesh, SnowWorld, SurfaceDesc, WorldConfig};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let gpu = GpuContext::new(&GpuOptions::default())?;
//! let mut world = SnowWorld::new(&gpu, WorldConfig::default())?;
//! let roof = world.add_surface(SurfaceDesc::new("roof", [0.0, 10.0, 0.0], [8.0, 6.0], 0.3))?;
//! let mut renderer = Renderer::new(&gpu, RenderConfig::new(640, 360, Tier::Relief))?;
//! let ball = renderer.add_mesh(&Mesh::uv_sphere(0.2, 16, 32))?;
//! let out = renderer.render(
//!     &world,
//!     &RenderFrame {
//!         camera: Camera { eye: Vec3::new(0.0, 12.0, 6.0), target: Vec3::new(0.0, 10.0, 0.0), fov_y_degrees: 50.0 },
//!         time: 0.0,
//!         surfaces: &[(roof, GroundMaterial::RoofTiles)],
//!         instances: &[Instance::new(ball, Mat4::from_translation(Vec3::new(0.0, 10.4, 0.0)), [0.6, 0.1, 0.1])],
//!         lights: &[],
//!         environment: Environment::moonlit_night(),
//!         snowfall: true,
//!     },
//! )?;
//! assert_eq!(out.rgba8.len(), 640 * 360 * 4);
//! # Ok(()) }
//! ```

mod cascades;
mod classify;
mod config;
pub(crate) mod cpu;
mod cull;
mod error;
mod frame;
pub(crate) mod geometry;
pub(crate) mod gpu;
pub(crate) mod graph;
mod heightfield;
mod inputs;
mod meshes;
mod opaque;
mod pipeline;
mod readback;
mod report;
mod shadow;
mod sky;
mod snow;
mod snowfall;
mod spray;
mod stats;
mod targets;
pub(crate) mod tessellate;
mod tonemap;

use std::collections::HashMap;
use std::time::Instant;

use crate::gpu::GpuContext;
use crate::mesh::Mesh;
use crate::surface::SurfaceId;
use crate::world::SnowWorld;
use frame::{FrameLayouts, FrameResources};
use graph::pass;
use readback::Timestamps;
use stats::{StatsReadback, StatsSources};
use targets::Targets;
use tessellate::banks::BanksPass;
use tessellate::dice::DicePass;
use tessellate::snow_shadow::TessSurface;

pub use config::{DebugView, OpaquePath, RenderConfig, SearchSettings, SnowLook, Tier};
pub use error::{RenderError, RenderResult};
pub use graph::{PASSES, PassInfo, PassKind, Resource};
pub use inputs::{Environment, Instance, MeshMaterial, PointLight, RenderFrame, RenderMeshId};
pub use report::{
    CpuPhase, FrameReport, PassTime, RenderOutput, ShadowStats, SnowMaterialKind, SurfaceShading,
};
pub use targets::OUTPUT_FORMAT;
pub use tessellate::{
    BankSettings, DiceSettings, DicedKind, DicedMesh, DicedVertex, SurfaceFields, SurfaceGeometry,
    SurfaceMesh,
};

/// The snow material as a WGSL module (no bindings, no entry points), for renderers of your own.
pub const SNOW_WGSL: &str = crate::wgsl::files::SNOW;

/// A frame recorded into a caller's command encoder by [`Renderer::encode_to_view`], waiting
/// for the caller's `queue.submit`; give it to [`Renderer::submitted`] after submitting.
#[must_use = "give it to Renderer::submitted after submitting the encoder"]
#[derive(Debug)]
pub struct RenderPending {
    /// Whether the frame's report was copied for reading back.
    report_copied: bool,
}

/// The renderer. See the [module documentation](self).
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: RenderConfig,
    /// The frame uniform, its bind groups and the samplers every pass shares.
    frame: FrameResources,
    /// The passes, one per entry of [`PASSES`] (`snow_shadow` and the tessellated snow draw are
    /// `tess_surface`).
    classify: classify::ClassifyPass,
    heightfield: heightfield::HeightfieldPass,
    banks: BanksPass,
    dice: DicePass,
    shadow: shadow::ShadowPass,
    tess_surface: TessSurface,
    opaque: opaque::OpaquePass,
    snow: snow::SnowPass,
    sky: sky::SkyPass,
    snowfall: snowfall::SnowfallPass,
    spray: spray::SprayPass,
    tonemap: tonemap::TonemapPass,
    /// Registered meshes and the frame's instances.
    meshes: meshes::MeshSet,
    targets: Targets,
    /// Per-surface settings of the tessellated tier, and their version.
    geometry: HashMap<SurfaceId, SurfaceGeometry>,
    geometry_version: u64,
    /// What surfaces without settings get.
    default_geometry: SurfaceGeometry,
    /// The surfaces of the latest frame encoded, in slot order (for readbacks).
    last_surfaces: Vec<SurfaceId>,
    timestamps: Option<Timestamps>,
    stats: StatsReadback,
    latest: Option<FrameReport>,
    /// The latest frame's shadow cascades.
    shadow_stats: ShadowStats,
    /// The last frame's CPU steps.
    phases: Vec<CpuPhase>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer")
            .field("config", &self.config)
            .field("meshes", &self.meshes.meshes.len())
            .field("timestamps", &self.timestamps.is_some())
            .finish()
    }
}

impl Renderer {
    /// Create a renderer on a GPU context (pipelines are built here, once).
    ///
    /// The device is checked against [`crate::required_features`] and
    /// [`crate::required_limits`] first: [`crate::SnowError::DeviceLimit`] (as
    /// [`RenderError::World`]) when it falls short.
    pub fn new(gpu: &GpuContext, config: RenderConfig) -> RenderResult<Self> {
        crate::gpu::check_device(&gpu.device)?;
        let device = gpu.device.clone();
        config.validate(&device)?;
        // Pipelines are checked by naga in the tests; a driver that still refuses one, or a backend
        // that cannot translate a shader (wgpu's GL backend: an internal error), is reported as an
        // error rather than wgpu's default panic.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
        let filterable = gpu.caps.filterable_rgba16f;
        let layouts = FrameLayouts::new(&device, filterable);
        let mesh_module = opaque::mesh_module(&device);
        let shadow = shadow::ShadowPass::new(
            &device,
            &mesh_module,
            &layouts.shadow_layout,
            (config.shadow_map_size, config.shadow_depth_format()),
        );
        let frame = FrameResources::new(&device, layouts, &shadow.view, filterable);
        let snow = snow::SnowPass::new(&device, &frame.layout, filterable, config.opaque);
        // On the visibility path the diced snow's shading binds the snow pass's targets.
        let tess_surface = TessSurface::new(
            &device,
            &frame.layout,
            (&frame.shadow_layout, shadow.format),
            filterable,
            snow.shade_targets_layout(),
        );
        let renderer = Self {
            classify: classify::ClassifyPass::new(&device),
            heightfield: heightfield::HeightfieldPass::new(&device),
            banks: BanksPass::new(&device),
            dice: DicePass::new(&device),
            tess_surface,
            opaque: opaque::OpaquePass::new(&device, &mesh_module, &frame.layout, config.opaque),
            snow,
            sky: sky::SkyPass::new(&device, &frame.layout),
            snowfall: snowfall::SnowfallPass::new(&device, &frame.layout),
            spray: spray::SprayPass::new(&device, &frame.layout),
            tonemap: tonemap::TonemapPass::new(&device, &frame.layout),
            meshes: meshes::MeshSet::new(&device),
            targets: Targets::new(
                &device,
                config.width,
                config.height,
                config.supersample,
                config.opaque == OpaquePath::Visibility,
            ),
            timestamps: gpu
                .caps
                .timestamps
                .then(|| readback::new_timestamps(&device, &gpu.queue)),
            stats: StatsReadback::new(&device),
            shadow,
            frame,
            geometry: HashMap::new(),
            geometry_version: 0,
            default_geometry: SurfaceGeometry::default(),
            last_surfaces: Vec::new(),
            latest: None,
            shadow_stats: ShadowStats::default(),
            phases: Vec::new(),
            queue: gpu.queue.clone(),
            device,
            config,
        };
        let internal = pollster::block_on(internal.pop());
        let validation = pollster::block_on(scope.pop());
        if let Some(e) = internal.or(validation) {
            return Err(RenderError::Gpu(e));
        }
        Ok(renderer)
    }
    /// The settings in use.
    pub fn config(&self) -> &RenderConfig {
        &self.config
    }

    /// The passes of a frame, in order, with what each reads and writes.
    pub fn passes(&self) -> &'static [PassInfo] {
        &PASSES
    }

    /// Whether per-pass GPU times are measured (the adapter has timestamp queries).
    pub fn has_timestamps(&self) -> bool {
        self.timestamps.is_some()
    }

    /// Switch between relief mapping and POM (and their default search settings).
    pub fn set_tier(&mut self, tier: Tier) {
        self.config.tier = tier;
    }

    /// Show the shaded frame or one of the material's terms.
    pub fn set_debug_view(&mut self, view: DebugView) {
        self.config.debug_view = view;
    }

    /// Change how snow and ground meet, or switch a term of the material off (as the image tests
    /// do to show they see it); checked as [`Renderer::new`] checks its configuration.
    ///
    /// # Errors
    ///
    /// [`RenderError`] naming the look's value that is out of range; the look in use is kept.
    pub fn set_look(&mut self, look: SnowLook) -> RenderResult<()> {
        let mut config = self.config;
        config.look = look;
        config.validate(&self.device)?;
        self.config = config;
        Ok(())
    }

    /// How a surface is drawn in the tessellated tier: its mesh, whether it is tessellated at all,
    /// its banks and macro waves. Checked against the surface (a mesh must lie within its
    /// rectangle); surfaces never given one get [`SurfaceGeometry::default`].
    pub fn set_surface_geometry(
        &mut self,
        world: &SnowWorld,
        surface: SurfaceId,
        geometry: SurfaceGeometry,
    ) -> RenderResult<()> {
        let view = world.frame_view();
        let (desc, layout) = {
            let v = view.surface(surface)?;
            (v.desc, v.layout)
        };
        let texel = (desc.size.x / layout.width as f32).min(desc.size.y / layout.height as f32);
        geometry.validate(desc.size * 0.5, texel)?;
        self.geometry.insert(surface, geometry);
        self.geometry_version += 1;
        Ok(())
    }

    /// The tessellated-tier settings of a surface.
    pub fn surface_geometry(&self, surface: SurfaceId) -> SurfaceGeometry {
        self.geometry.get(&surface).cloned().unwrap_or_default()
    }

    /// Change the output size (and supersampling).
    pub fn resize(&mut self, width: u32, height: u32, supersample: u32) -> RenderResult<()> {
        let config = RenderConfig {
            width,
            height,
            supersample,
            ..self.config
        };
        config.validate(&self.device)?;
        self.config = config;
        self.targets = Targets::new(
            &self.device,
            width,
            height,
            supersample,
            config.opaque == OpaquePath::Visibility,
        );
        Ok(())
    }

    /// A moon's shadow map of `size` texels a side from the next frame on (each of its two
    /// cascades); [`RenderConfig::shadow_map_size_for_view`] gives the side a view needs.
    pub fn set_shadow_map_size(&mut self, size: u32) -> RenderResult<()> {
        let config = RenderConfig {
            shadow_map_size: size,
            ..self.config
        };
        config.validate(&self.device)?;
        self.config = config;
        if size != self.shadow.size {
            self.shadow.resize(&self.device, size);
            self.frame
                .rebind_shadow_map(&self.device, &self.shadow.view);
        }
        Ok(())
    }

    /// Register a mesh to draw; normals are computed here (smooth, split at creases).
    pub fn add_mesh(&mut self, mesh: &Mesh) -> RenderResult<RenderMeshId> {
        self.meshes.add(&self.device, mesh)
    }

    /// Replace a registered mesh (an animated one, re-posed).
    pub fn update_mesh(&mut self, id: RenderMeshId, mesh: &Mesh) -> RenderResult<()> {
        self.meshes.update(&self.device, id, mesh)
    }

    /// Render a frame offscreen and read it back (waits for the GPU).
    pub fn render(
        &mut self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
    ) -> RenderResult<RenderOutput> {
        let start = Instant::now();
        // A pending report readback of an earlier `render_to_view` must finish first: the buffer is
        // reused.
        self.finish_stats(true)?;
        let output_view = self.targets.output_view.clone();
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let encode_start = Instant::now();
        let mut encoder = self.frame_encoder();
        let surfaces = self.encode(&mut encoder, world, frame, &output_view, OUTPUT_FORMAT)?;
        let (w, h) = self.targets.size;
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.targets.output,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.targets.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.targets.padded_row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.copy_stats(&mut encoder, surfaces);
        let mut laps = report::Laps::start();
        let commands = encoder.finish();
        laps.mark("finish");
        self.queue.submit([commands]);
        self.shadow.confirm();
        laps.mark("submit");
        self.phases.extend(laps.phases);
        let cpu_encode_ms = encode_start.elapsed().as_secs_f64() * 1e3;
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e));
        }
        self.stats.start_map();

        let slice = self.targets.readback.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device.poll(wgpu::PollType::wait_indefinitely())?;
        rx.recv()
            .map_err(|e| RenderError::Readback(e.to_string()))??;
        let mut rgba8 = Vec::with_capacity((w * h * 4) as usize);
        {
            let data = slice.get_mapped_range()?;
            for row in 0..h as usize {
                let o = row * self.targets.padded_row as usize;
                rgba8.extend_from_slice(&data[o..o + w as usize * 4]);
            }
        }
        self.targets.readback.unmap();
        self.finish_stats(true)?;
        let report = self.latest.clone().unwrap_or_default();
        Ok(RenderOutput {
            rgba8,
            width: w,
            height: h,
            basic_material_surfaces: report.basic_material_surfaces(),
            pass_times: report.pass_times,
            surfaces: report.surfaces,
            dice_overflow: report.dice_overflow,
            cpu_ms: start.elapsed().as_secs_f64() * 1e3,
            cpu_encode_ms,
            cpu_phases: self.phases.clone(),
            culled_instances: self.meshes.culled,
            shadow: self.shadow_stats,
        })
    }

    /// Render a frame into a caller's texture view (a window's surface texture) of the configured
    /// size and the given format, without waiting for the GPU: [`Renderer::encode_to_view`] into
    /// an encoder of its own, submitted at once. Returns the report of the latest earlier frame
    /// whose GPU results have come back, if any.
    pub fn render_to_view(
        &mut self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> RenderResult<Option<FrameReport>> {
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = self.frame_encoder();
        let pending = self.encode_to_view(&mut encoder, world, frame, target, format)?;
        self.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e));
        }
        Ok(self.submitted(pending))
    }

    /// Record a frame's passes into the caller's `encoder` (between the engine's own passes),
    /// drawing into `target` (of the configured size, in `format`). The passes' tables are written
    /// with `queue.write_buffer`, so they land with the caller's next submission: record one
    /// frame a submission. Nothing waits for the GPU; after submitting the encoder, give the
    /// [`RenderPending`] to [`Renderer::submitted`].
    pub fn encode_to_view(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> RenderResult<RenderPending> {
        let t = target.texture();
        let expected = self.targets.size;
        if (t.width(), t.height()) != expected {
            return Err(RenderError::TargetSize {
                got: (t.width(), t.height()),
                expected,
            });
        }
        self.finish_stats(false)?;
        let surfaces = self.encode(encoder, world, frame, target, format)?;
        let report_copied = self.stats.is_idle();
        if report_copied {
            self.copy_stats(encoder, surfaces);
        }
        Ok(RenderPending { report_copied })
    }

    /// The caller submitted the encoder that `pending` was recorded into: start reading its
    /// report back (without waiting). Returns the report of the latest earlier frame whose GPU
    /// results have come back, if any.
    pub fn submitted(&mut self, pending: RenderPending) -> Option<FrameReport> {
        self.shadow.confirm();
        if pending.report_copied && self.stats.is_idle() {
            self.stats.start_map();
        }
        self.latest.clone()
    }

    fn frame_encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("snowprint frame"),
            })
    }

    /// Slot of a surface in the latest frame encoded.
    fn last_slot(&self, surface: SurfaceId) -> RenderResult<usize> {
        self.last_surfaces
            .iter()
            .position(|&id| id == surface)
            .ok_or_else(|| RenderError::InvalidFrame {
                what: format!("surface {}", surface.index()),
                value: "not drawn in the latest frame".into(),
                expected: "a surface of the latest frame rendered",
            })
    }

    /// The diced mesh of a surface in the latest frame (the tessellated tier), read back from the
    /// GPU's vertex and index buffers: its triangles and the vertices they use, before
    /// displacement. Empty when the surface was not diced (another tier, culled, or switched off).
    pub fn read_diced_mesh(&self, surface: SurfaceId) -> RenderResult<DicedMesh> {
        let s = self.last_slot(surface)?;
        self.dice.read_mesh(&self.device, &self.queue, s)
    }

    /// A surface's smoothed depression, displaced channel and bank heights as the latest frame's
    /// heightfield and bank passes wrote them (the banks only in the tessellated tier, and only
    /// for a deformed surface that the frame could show, `frame/seen.rs`; otherwise what an
    /// earlier frame left, or zeros).
    pub fn read_surface_fields(&self, surface: SurfaceId) -> RenderResult<SurfaceFields> {
        self.last_slot(surface)?;
        self.heightfield
            .read_fields(&self.device, &self.queue, surface)
    }

    /// The report of the latest frame whose GPU results have come back.
    pub fn latest_report(&self) -> Option<&FrameReport> {
        self.latest.as_ref()
    }

    /// Copy the frame's report (state words, counters, timestamps) for reading back.
    fn copy_stats(&mut self, encoder: &mut wgpu::CommandEncoder, surfaces: Vec<SurfaceId>) {
        let from = StatsSources {
            state: &self.classify.state.buffer,
            counters: &self.dice.counters.buffer,
            timestamps: self.timestamps.as_ref(),
        };
        self.stats.copy(&self.device, encoder, from, surfaces);
    }

    /// Take the report readback when it has arrived (waiting for it when `wait`).
    fn finish_stats(&mut self, wait: bool) -> RenderResult<()> {
        if let Some(report) = self
            .stats
            .finish(&self.device, self.timestamps.as_ref(), wait)?
        {
            self.latest = Some(report);
        }
        Ok(())
    }

    /// Check the frame, extract what it reads of the world ([`SnowWorld::frame_view`]), prepare
    /// every pass (uploads and bind groups), then record the passes in the order of [`PASSES`]
    /// into `encoder`.
    fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> RenderResult<Vec<SurfaceId>> {
        frame.check(self.meshes.meshes.len())?;
        let mut laps = report::Laps::start();
        let view = world.frame_view();
        let tessellated_tier = self.config.tier == Tier::Tessellated;
        let surfaces = frame::frame_surfaces(
            &view,
            frame,
            &self.geometry,
            &self.default_geometry,
            tessellated_tier,
        )?;
        let descs = surfaces.iter().map(|s| s.view.desc);
        let placed = (self.shadow.size, self.shadow.near_hold);
        let shadow = cascades::shadow_cascades(descs, frame, &self.meshes.meshes, placed);
        self.shadow.near_hold = Some(shadow.hold);
        let uniform = frame::frame_uniform(&self.config, frame, &shadow);
        self.frame.prepare(&self.queue, &uniform);
        let mut surfaces = surfaces;
        let near = glam::Mat4::from_cols_array_2d(&uniform.shadow_near);
        frame::seen::mark_seen(
            &mut surfaces,
            glam::Mat4::from_cols_array_2d(&uniform.view_proj),
            tessellated_tier.then_some(near),
        );
        laps.mark("surfaces");

        let (device, queue) = (&self.device, &self.queue);
        let (pool, ground) = (view.pool_buffer, view.ground_buffer);
        self.classify.prepare(device, queue, pool, &surfaces);
        laps.mark("classify");
        let moon = frame.environment.moon_direction;
        let state = &self.classify.state.buffer;
        self.heightfield
            .prepare(device, queue, (pool, ground, state), &surfaces, moon);
        laps.mark("heightfield");
        self.snow.prepare(
            device,
            queue,
            &self.config,
            &surfaces,
            &self.heightfield,
            ground,
            &self.targets,
            (
                frame.camera.eye,
                glam::Mat4::from_cols_array_2d(&uniform.view_proj),
            ),
        );
        laps.mark("snow");
        self.last_surfaces = surfaces.iter().map(|s| s.view.id).collect();
        self.dice.prepare(
            device,
            queue,
            tessellated_tier,
            &self.config,
            frame,
            &uniform,
            &surfaces,
            self.geometry_version,
            &self.heightfield,
            state,
            ground,
        )?;
        laps.mark("dice");
        self.banks.prepare(
            device,
            queue,
            tessellated_tier,
            (pool, state, &surfaces),
            &self.heightfield,
        );
        laps.mark("banks");
        let uniforms = &self.snow.uniforms.buffer;
        self.tess_surface.prepare(
            device,
            &surfaces,
            uniforms,
            &self.heightfield,
            state,
            ground,
        );
        laps.mark("tess_surface");
        let view_proj = glam::Mat4::from_cols_array_2d(&uniform.view_proj);
        self.meshes.prepare(
            device,
            queue,
            frame.instances,
            view_proj,
            ([shadow.near, shadow.far], self.shadow.size),
        );
        let snow_shadows = (self.snow).shadow_rects([shadow.near, shadow.far], self.shadow.size);
        let enabled = self.config.shadow_cache;
        (self.shadow).plan(device, queue, enabled, &mut self.meshes, snow_shadows);
        laps.mark("meshes");
        self.shadow_stats = ShadowStats {
            casters: self.meshes.cascade_casters,
            from_cache: self.shadow.cached(),
            restored_texels: self.shadow.restored_texels(),
            texel_m: [shadow.near_texel, shadow.far_texel],
            view_pixel_m: cascades::view_pixel(frame, self.config.height * self.config.supersample),
        };
        self.opaque
            .prepare(device, queue, &self.meshes, &self.targets);
        self.tonemap.prepare(
            device,
            &self.targets,
            target,
            format,
            self.config.supersample,
        );
        laps.mark("opaque_tonemap");

        // The table sets the order: pass `slot` of PASSES is recorded `slot`-th.
        let flakes = uniform.options[3];
        // The world's spray ring, read from the world directly (the extract predates it).
        let spray = world
            .spray_particles()
            .zip(world.config().spray.map(|s| s.capacity));
        for slot in 0..PASSES.len() {
            self.encode_pass(encoder, slot, target, flakes, spray);
        }
        laps.mark("record");
        self.phases = laps.phases;
        Ok(self.last_surfaces.clone())
    }

    /// Record pass `slot` of [`PASSES`] (its label and timestamp slots come from the table).
    fn encode_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        slot: usize,
        target: &wgpu::TextureView,
        flakes: u32,
        spray: spray::SprayRing<'_>,
    ) {
        let ts = self.timestamps.as_ref();
        let state = &self.classify.state.buffer;
        let (frame, shadow_frame) = (&self.frame.bind_group, &self.frame.shadow_bind_group);
        let targets = &self.targets;
        match slot {
            pass::CLASSIFY => self.classify.encode(encoder, ts, slot),
            pass::HEIGHTFIELD => self.heightfield.encode(encoder, ts, slot),
            pass::BANKS => self.banks.encode(encoder, ts, slot),
            pass::DICE => self.dice.encode(encoder, ts, slot),
            pass::SHADOW => self
                .shadow
                .encode(encoder, ts, slot, shadow_frame, &self.meshes),
            pass::SNOW_SHADOW => self.tess_surface.encode_shadow(
                encoder,
                ts,
                slot,
                shadow_frame,
                &self.shadow,
                &self.dice,
            ),
            pass::OPAQUE => self
                .opaque
                .encode(encoder, ts, slot, targets, frame, &self.meshes),
            pass::SNOW_SHADE => {
                self.snow
                    .encode_shade(encoder, ts, slot, frame, &self.tess_surface)
            }
            pass::OPAQUE_SHADE => self.opaque.encode_shade(encoder, ts, slot, frame),
            pass::SNOW => self.snow.encode(
                encoder,
                ts,
                slot,
                targets,
                frame,
                state,
                &self.tess_surface,
                &self.dice,
            ),
            pass::SKY => self.sky.encode(encoder, ts, slot, targets, frame),
            pass::SNOWFALL => self
                .snowfall
                .encode(encoder, ts, slot, targets, frame, flakes),
            pass::SPRAY => self.spray.encode(encoder, ts, slot, targets, frame, spray),
            pass::TONEMAP => self.tonemap.encode(encoder, ts, slot, target, frame),
            _ => unreachable!("pass {slot} of PASSES has no encoder"),
        }
    }
}
