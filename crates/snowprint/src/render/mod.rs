//! The renderer: snow surfaces shaded as in the talk's "Stage 3 - Shading", with the meshes of a
//! world (rooftops, props, people), a moonlit sky, shadows and falling snow.
//!
//! A frame is a fixed graph of explicit passes ([`PASSES`]), each naming what it reads and writes:
//!
//! | pass | reads | writes |
//! |---|---|---|
//! | `classify` (compute) | heightmap pool, surface table | surface state: material flag, indirect args |
//! | `heightfield` (compute, indirect) | pool, surface state | per deformed surface: depression, normal, AO texture |
//! | `shadow` | instances | the moon's shadow map |
//! | `opaque` | instances, shadow map | scene colour (HDR), depth |
//! | `snow` (indirect) | surface state, heightfields, shadow map | scene colour, depth |
//! | `sky` | depth | scene colour |
//! | `snowfall` | depth | scene colour |
//! | `tonemap` | scene colour, depth | the output |
//!
//! Each snow surface is drawn as the box of its snow slab. A surface whose heightmap is all zero
//! gets the talk's **basic** material (untouched snow, no heightmap reads); any other the
//! **deformable** one: the view ray is traced through the heightfield by relief mapping (linear
//! taps and a binary refinement; [`Tier::Pom`] uses parallax occlusion mapping with self-shadowing
//! instead), and the hit blends untouched snow with the flattened ground (roof tiles or concrete)
//! by the heightmap, normals by Reoriented Normal Mapping, the transition tinted with the sky. The
//! choice is made on the GPU by `classify` and costs no readback; [`RenderOutput`] reports it.
//!
//! The material is the WGSL module [`SNOW_WGSL`], which another renderer can import (see the
//! header of `snow.wgsl` and `docs/RENDERING.md`). Its maths have CPU references in [`cpu`].
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

pub mod cpu;
pub mod geometry;
pub mod gpu;
pub mod graph;
pub mod shaders;
pub mod tessellate;

use crate::gpu::resources::{Growable, bind_group, compute_storage, uniform, uniform_block};
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::Instant;

use glam::{Mat3, Mat4, Vec3};

use crate::error::SnowError;
use crate::gpu::GpuContext;
use crate::mesh::Mesh;
use crate::surface::SurfaceId;
use crate::view::{Camera, GroundMaterial};
use crate::world::SnowWorld;
use gpu::{
    BOX_VERTICES, ClassifyRecord, FrameUniform, HeightfieldParams, InstanceRaw, MAX_POINT_LIGHTS,
    PointLightRaw, STATE_BASIC_DRAW, STATE_DEEPEST, STATE_DEFORMABLE_DRAW,
    STATE_HEIGHTFIELD_DISPATCH, STATE_TOUCHED, STATE_WORDS, SurfaceUniform, UNIFORM_STRIDE,
};
use graph::pass;
pub use graph::{PASSES, PassInfo, PassKind, Resource};
pub use tessellate::{
    BankSettings, DiceSettings, DicedKind, DicedMesh, DicedVertex, SurfaceFields, SurfaceGeometry,
    SurfaceMesh,
};

/// The snow material as a WGSL module (no bindings, no entry points), for renderers of your own.
pub const SNOW_WGSL: &str = shaders::SNOW;

/// Format of the offscreen output ([`Renderer::render`]).
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const HEIGHTFIELD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const NEAR: f32 = 0.05;
/// Side of the near shadow cascade, metres.
const NEAR_CASCADE: f32 = 12.0;

/// The moon's two shadow projections and their texels in metres.
struct ShadowCascades {
    near: Mat4,
    far: Mat4,
    near_texel: f32,
    far_texel: f32,
}
const FAR: f32 = 600.0;

/// What the renderer can report instead of panicking.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A setting of [`RenderConfig`] is not usable.
    #[error("render setting {what} is {value}, but it must be {expected}")]
    InvalidConfig {
        /// Which setting.
        what: &'static str,
        /// The value given.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// Something in a [`RenderFrame`] is not usable.
    #[error("render frame: {what} is {value}, but it must be {expected}")]
    InvalidFrame {
        /// Which part of the frame.
        what: String,
        /// The value given.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A mesh handle that this renderer did not give out.
    #[error("render mesh handle {index} does not belong to this renderer")]
    StaleMesh {
        /// The handle's index.
        index: u32,
    },
    /// The target view given to [`Renderer::render_to_view`] does not have the configured size.
    #[error(
        "the target is {got:?} pixels but the renderer is configured for {expected:?}; call Renderer::resize first"
    )]
    TargetSize {
        /// The target's size.
        got: (u32, u32),
        /// The configured size.
        expected: (u32, u32),
    },
    /// The world refused a request (a stale surface handle, an invalid mesh).
    #[error(transparent)]
    World(#[from] SnowError),
    /// The GPU did not finish or a readback failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// The GPU refused a pipeline or a frame (a driver that cannot compile a shader, a limit
    /// exceeded); wgpu's message is kept.
    #[error("the GPU refused the renderer's work: {0}")]
    Gpu(String),
}

/// Result of the renderer.
pub type RenderResult<T> = Result<T, RenderError>;

/// How snow surfaces are drawn: traced by the talk's relief mapping, or by parallax occlusion
/// mapping (the talk's "replace with POM?"), which takes more taps, interpolates the hit and
/// self-shadows; or as real displaced geometry diced on the GPU (the talk's tessellation path).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// Relief mapping: few linear taps, binary refinement.
    #[default]
    Relief,
    /// Parallax occlusion mapping: more taps, secant refinement, self-shadowing.
    Pom,
    /// Real geometry: each surface's mesh diced on the GPU by screen size and relief, displaced by
    /// the heightmap, banks and macro waves, drawn into the shadow map ([`tessellate`]).
    Tessellated,
}

impl Tier {
    /// Lower-case name (`relief`, `pom`).
    pub fn name(self) -> &'static str {
        match self {
            Tier::Relief => "relief",
            Tier::Pom => "pom",
            Tier::Tessellated => "tessellated",
        }
    }
}

impl std::str::FromStr for Tier {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "relief" => Ok(Tier::Relief),
            "pom" => Ok(Tier::Pom),
            "tessellated" | "tess" => Ok(Tier::Tessellated),
            _ => Err(format!(
                "unknown tier {s:?}; use relief, pom or tessellated"
            )),
        }
    }
}

impl std::fmt::Display for Tier {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What the image shows: the shaded frame, or one of the material's terms.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum DebugView {
    /// The shaded frame.
    #[default]
    Shaded,
    /// Basic material green; deformable orange, ground brown, transition blue.
    Materials,
    /// Depression of the heightmap at the hit.
    Depression,
    /// Ambient occlusion from the heightmap.
    Occlusion,
    /// Normals (local frame for snow, world for meshes).
    Normals,
    /// Heightfield taps per pixel (0 to 48).
    Taps,
}

impl DebugView {
    fn code(self) -> u32 {
        match self {
            DebugView::Shaded => 0,
            DebugView::Materials => 1,
            DebugView::Depression => 2,
            DebugView::Occlusion => 3,
            DebugView::Normals => 4,
            DebugView::Taps => 5,
        }
    }
}

impl std::str::FromStr for DebugView {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "shaded" => Ok(DebugView::Shaded),
            "materials" => Ok(DebugView::Materials),
            "depression" => Ok(DebugView::Depression),
            "occlusion" | "ao" => Ok(DebugView::Occlusion),
            "normals" => Ok(DebugView::Normals),
            "taps" => Ok(DebugView::Taps),
            _ => Err(format!(
                "unknown debug view {s:?}; use shaded, materials, depression, occlusion, normals or taps"
            )),
        }
    }
}

/// The heightfield search. Taps scale with the heightmap texels a ray crosses, so the same settings
/// suit a 4 cm roof and a 6 cm street, and a ray looking straight down costs `min_taps`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SearchSettings {
    /// Linear taps per heightmap texel crossed horizontally.
    pub taps_per_texel: f32,
    /// Fewest linear taps.
    pub min_taps: u32,
    /// Most linear taps.
    pub max_taps: u32,
    /// Refinement taps after the linear search: binary steps (relief mapping) or false-position
    /// steps (POM).
    pub refine_taps: u32,
    /// Self-shadow taps towards the moon (parallax occlusion mapping).
    pub shadow_taps: u32,
}

impl SearchSettings {
    /// The defaults of a tier: relief mapping takes a tap every two texels (4 to 12) and 5 binary
    /// steps; POM a tap per texel (8 to 40), 3 false-position steps and 10 self-shadow taps.
    pub fn for_tier(tier: Tier) -> Self {
        match tier {
            // Surfaces not tessellated in the tessellated tier are relief mapped.
            Tier::Relief | Tier::Tessellated => Self {
                taps_per_texel: 0.5,
                min_taps: 4,
                max_taps: 12,
                refine_taps: 5,
                shadow_taps: 0,
            },
            Tier::Pom => Self {
                taps_per_texel: 1.0,
                min_taps: 8,
                max_taps: 40,
                refine_taps: 3,
                shadow_taps: 10,
            },
        }
    }
}

/// How the two stages of the deformable material meet.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SnowLook {
    /// Depression (fraction of the snow depth) where the ground starts to show.
    pub ground_from: f32,
    /// Depression where only the ground shows.
    pub ground_full: f32,
    /// Strength of the heightmap's ambient occlusion (0 to 1).
    pub occlusion: f32,
    /// The sky's tint of the walls and rims of prints (on by default; off only to see what it
    /// adds, as the image tests do).
    pub sky_tint: bool,
    /// Reoriented normal mapping of detail onto the heightmap's normal (on by default; off, the
    /// detail is blended linearly, which flattens it).
    pub rnm: bool,
}

impl Default for SnowLook {
    fn default() -> Self {
        Self {
            ground_from: 0.66,
            ground_full: 0.9,
            occlusion: 0.85,
            sky_tint: true,
            rnm: true,
        }
    }
}

impl SnowLook {
    /// The switched-off terms as `snow.wgsl` reads them (`SNOW_NO_SKY_TINT`, `SNOW_NO_RNM`).
    fn switch_bits(&self) -> u32 {
        u32::from(!self.sky_tint) | (u32::from(!self.rnm) << 1)
    }
}

/// Settings of a [`Renderer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderConfig {
    /// Output width, pixels.
    pub width: u32,
    /// Output height, pixels.
    pub height: u32,
    /// Relief mapping or POM.
    pub tier: Tier,
    /// Samples per output pixel along each axis (1 to 4): the scene is drawn this much larger and
    /// averaged down (anti-aliasing).
    pub supersample: u32,
    /// Side of the moon's shadow map, texels.
    pub shadow_map_size: u32,
    /// Falling flakes drawn when a frame asks for snowfall.
    pub snowflakes: u32,
    /// What the image shows.
    pub debug_view: DebugView,
    /// The heightfield search; `None` takes the tier's defaults.
    pub search: Option<SearchSettings>,
    /// How snow and ground meet.
    pub look: SnowLook,
    /// The tessellated tier's dicing.
    pub dice: DiceSettings,
}

impl RenderConfig {
    /// A configuration with the defaults: no supersampling, a 2048 shadow map, 6000 flakes.
    pub fn new(width: u32, height: u32, tier: Tier) -> Self {
        Self {
            width,
            height,
            tier,
            supersample: 1,
            shadow_map_size: 2048,
            snowflakes: 6000,
            debug_view: DebugView::Shaded,
            search: None,
            look: SnowLook::default(),
            dice: DiceSettings::default(),
        }
    }

    /// The search in use.
    pub fn search_settings(&self) -> SearchSettings {
        self.search
            .unwrap_or_else(|| SearchSettings::for_tier(self.tier))
    }

    fn validate(&self, device: &wgpu::Device) -> RenderResult<()> {
        let max = device.limits().max_texture_dimension_2d;
        let bad = |what, value: String, expected| {
            Err(RenderError::InvalidConfig {
                what,
                value,
                expected,
            })
        };
        if !(1..=4).contains(&self.supersample) {
            return bad("supersample", self.supersample.to_string(), "1, 2, 3 or 4");
        }
        for (what, v) in [("width", self.width), ("height", self.height)] {
            if v == 0 || v * self.supersample > max {
                return bad(
                    what,
                    format!("{v} (x{} supersampling)", self.supersample),
                    "at least 1 and, times the supersampling, within the device's largest texture",
                );
            }
        }
        if self.shadow_map_size < 64 || self.shadow_map_size > max {
            return bad(
                "shadow_map_size",
                self.shadow_map_size.to_string(),
                "at least 64 and within the device's largest texture",
            );
        }
        let s = self.search_settings();
        if !(s.taps_per_texel.is_finite() && s.taps_per_texel > 0.0)
            || s.min_taps == 0
            || s.min_taps > s.max_taps
            || s.max_taps > 256
        {
            return bad(
                "search",
                format!("{s:?}"),
                "taps_per_texel above 0 and 1 <= min_taps <= max_taps <= 256",
            );
        }
        self.dice.validate()?;
        let vertex_bytes = self.dice.max_triangles as u64 * tessellate::VERTEX_BYTES;
        if vertex_bytes > device.limits().max_storage_buffer_binding_size {
            return bad(
                "dice.max_triangles",
                self.dice.max_triangles.to_string(),
                "small enough that its vertex buffer fits the device's largest storage buffer",
            );
        }
        let l = self.look;
        if !(0.0..1.0).contains(&l.ground_from)
            || l.ground_full <= l.ground_from
            || l.ground_full > 1.0
        {
            return bad(
                "look",
                format!("{l:?}"),
                "0 <= ground_from < ground_full <= 1",
            );
        }
        Ok(())
    }
}

/// The light of the night: the moon, the sky and the haze.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Unit direction towards the moon.
    pub moon_direction: Vec3,
    /// Moonlight: the radiance a white Lambertian surface facing the moon reflects (linear RGB).
    pub moon_color: Vec3,
    /// The moon's angular radius on the sky, degrees (drawn larger than life).
    pub moon_radius_degrees: f32,
    /// Sky overhead (linear RGB radiance).
    pub sky_zenith: Vec3,
    /// Sky at the horizon.
    pub sky_horizon: Vec3,
    /// Light bounced up from the ground and the city.
    pub ground_bounce: Vec3,
    /// Strength of the city's orange glow on the horizon.
    pub city_glow: f32,
    /// Light from the whole sky on a surface facing up (what lights the snow in shadow).
    pub sky_ambient: Vec3,
    /// Tint of the snow's transition zone (the fake subsurface scattering), luminance about 1.
    pub sss_tint: Vec3,
    /// Strength of that tint (0 to 1).
    pub sss_strength: f32,
    /// Exposure before the filmic curve.
    pub exposure: f32,
    /// Haze density per metre.
    pub fog_density: f32,
}

impl Environment {
    /// A clear, cold night with a low moon.
    pub fn moonlit_night() -> Self {
        Self {
            moon_direction: Vec3::new(0.8, 0.42, 0.42).normalize(),
            moon_color: Vec3::new(0.55, 0.68, 1.0),
            moon_radius_degrees: 1.6,
            sky_zenith: Vec3::new(0.010, 0.018, 0.045),
            sky_horizon: Vec3::new(0.040, 0.055, 0.090),
            ground_bounce: Vec3::new(0.030, 0.032, 0.040),
            city_glow: 0.05,
            sky_ambient: Vec3::new(0.07, 0.10, 0.19),
            sss_tint: Vec3::new(0.72, 0.9, 1.25),
            sss_strength: 0.6,
            exposure: 0.75,
            fog_density: 0.012,
        }
    }
}

impl Default for Environment {
    fn default() -> Self {
        Self::moonlit_night()
    }
}

/// A point light (a street lamp, a lit window).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// World position.
    pub position: Vec3,
    /// Linear colour times intensity: the radiance a white surface facing it at 1 m reflects.
    pub color: Vec3,
    /// Distance where its light ends, metres.
    pub radius: f32,
}

/// The procedural material of a mesh instance. Every material but `Plain` and `Emissive` gathers
/// snow on faces that look up (see [`Instance::snow_cover`]).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum MeshMaterial {
    /// The albedo as given (people, clothes, props).
    #[default]
    Plain,
    /// Brick courses tinted by the albedo.
    Brick,
    /// Brick with a grid of windows, some of them lit.
    Facade,
    /// Concrete tinted by the albedo.
    Concrete,
    /// Painted metal with rust streaks (water towers, vents).
    Metal,
    /// Glowing (lamp bulbs): albedo times the instance's emission.
    Emissive,
}

impl MeshMaterial {
    /// Must match the `MATERIAL_*` constants of `mesh.wgsl`.
    fn code(self) -> f32 {
        match self {
            MeshMaterial::Plain => 0.0,
            MeshMaterial::Brick => 1.0,
            MeshMaterial::Facade => 2.0,
            MeshMaterial::Concrete => 3.0,
            MeshMaterial::Metal => 4.0,
            MeshMaterial::Emissive => 5.0,
        }
    }
}

/// Handle of a mesh registered with [`Renderer::add_mesh`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderMeshId(u32);

/// One placed mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh.
    pub mesh: RenderMeshId,
    /// Mesh frame to world.
    pub transform: Mat4,
    /// Base colour (linear RGB, 0 to 1).
    pub albedo: [f32; 3],
    /// Procedural material.
    pub material: MeshMaterial,
    /// Perceptual roughness (0 to 1).
    pub roughness: f32,
    /// Light emitted, as a multiple of the albedo.
    pub emission: f32,
    /// How much snow lies on its upward faces (0 to 1).
    pub snow_cover: f32,
    /// Whether it casts the moon's shadow.
    pub casts_shadow: bool,
    /// Varies the procedural patterns between instances of the same material.
    pub seed: f32,
}

impl Instance {
    /// A plain, shadow-casting instance with roughness 0.6.
    pub fn new(mesh: RenderMeshId, transform: Mat4, albedo: [f32; 3]) -> Self {
        Self {
            mesh,
            transform,
            albedo,
            material: MeshMaterial::Plain,
            roughness: 0.6,
            emission: 0.0,
            snow_cover: 0.0,
            casts_shadow: true,
            seed: 0.0,
        }
    }

    /// The same instance with another material; building materials gather snow on top.
    pub fn with_material(mut self, material: MeshMaterial) -> Self {
        self.material = material;
        self.snow_cover = match material {
            MeshMaterial::Plain | MeshMaterial::Emissive => 0.0,
            _ => 1.0,
        };
        self
    }

    /// The same instance glowing.
    pub fn with_emission(mut self, emission: f32) -> Self {
        self.emission = emission;
        self
    }

    /// The same instance with a shadow or without.
    pub fn with_shadow(mut self, casts_shadow: bool) -> Self {
        self.casts_shadow = casts_shadow;
        self
    }

    /// The same instance with a pattern seed.
    pub fn with_seed(mut self, seed: f32) -> Self {
        self.seed = seed;
        self
    }
}

/// Everything one frame shows.
#[derive(Clone, Copy, Debug)]
pub struct RenderFrame<'a> {
    /// The camera.
    pub camera: Camera,
    /// Seconds (animates falling snow).
    pub time: f32,
    /// Snow surfaces of the world to draw, with the ground under each.
    pub surfaces: &'a [(SurfaceId, GroundMaterial)],
    /// Meshes to draw.
    pub instances: &'a [Instance],
    /// Point lights; beyond 8, the 8 nearest the camera are used.
    pub lights: &'a [PointLight],
    /// Moon, sky and haze.
    pub environment: Environment,
    /// Whether snow is falling.
    pub snowfall: bool,
}

/// GPU time of one pass.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PassTime {
    /// The pass's name in [`PASSES`].
    pub name: &'static str,
    /// Milliseconds.
    pub gpu_ms: f64,
}

/// Which snow material a surface was drawn with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SnowMaterialKind {
    /// The basic material: nothing has pressed the surface.
    Basic,
    /// The deformable material.
    Deformable,
}

/// How one surface was drawn.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SurfaceShading {
    /// The surface (its index).
    #[serde(serialize_with = "serialize_surface_id")]
    pub surface: SurfaceId,
    /// The material the GPU chose.
    pub material: SnowMaterialKind,
    /// The deepest print, as a fraction of the snow depth.
    pub deepest: f32,
    /// Triangles the dicing pass made for it (the tessellated tier; 0 otherwise or when culled).
    pub triangles: u32,
}

fn serialize_surface_id<S: serde::Serializer>(id: &SurfaceId, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u32(id.index())
}

/// What the GPU reported about a frame.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameReport {
    /// GPU time per pass, in [`PASSES`] order; empty when the adapter has no timestamp queries.
    pub pass_times: Vec<PassTime>,
    /// Each surface drawn and its material.
    pub surfaces: Vec<SurfaceShading>,
    /// Base triangles the dicing pass dropped for want of room
    /// ([`DiceSettings::max_triangles`]); 0 when everything fit.
    pub dice_overflow: u32,
}

impl FrameReport {
    /// Surfaces drawn with the basic material.
    pub fn basic_material_surfaces(&self) -> Vec<SurfaceId> {
        self.surfaces
            .iter()
            .filter(|s| s.material == SnowMaterialKind::Basic)
            .map(|s| s.surface)
            .collect()
    }
}

/// An offscreen frame.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Pixels, RGBA 8 bits per channel, sRGB, rows top to bottom, no padding.
    pub rgba8: Vec<u8>,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// GPU time per pass (empty without timestamp queries).
    pub pass_times: Vec<PassTime>,
    /// Surfaces drawn with the basic material.
    pub basic_material_surfaces: Vec<SurfaceId>,
    /// Each surface drawn and its material.
    pub surfaces: Vec<SurfaceShading>,
    /// Base triangles the dicing pass dropped for want of room (0 when everything fit).
    pub dice_overflow: u32,
    /// CPU time from the call to the pixels being back, milliseconds.
    pub cpu_ms: f64,
}

struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    radius: f32,
}

/// A deformed surface's shading textures, written by the heightfield pass.
struct HeightfieldTexture {
    size: (u32, u32),
    /// Depression, normal x and z, ambient occlusion.
    shape: wgpu::TextureView,
    /// Moon visibility, displaced snow.
    light: wgpu::TextureView,
    /// Room for banks around each texel (the bank passes' scratch).
    bank_scratch: wgpu::TextureView,
    /// Bank heights, metres.
    bank: wgpu::TextureView,
    /// The textures of shape, light and bank, for readbacks.
    textures: [wgpu::Texture; 3],
}

/// A surface's base mesh on the GPU, for the dicing pass.
struct BaseMeshGpu {
    buffer: wgpu::Buffer,
    triangles: u32,
    /// The surface's size and the geometry's version it was built for.
    key: ([u32; 2], u64),
}

struct Targets {
    size: (u32, u32),
    color_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
}

/// Map state of the stats readback buffer.
const MAP_IDLE: u8 = 0;
const MAP_PENDING: u8 = 1;
const MAP_READY: u8 = 2;
const MAP_FAILED: u8 = 3;

struct StatsReadback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// Surfaces of the frame being read, and whether timestamps were copied.
    surfaces: Vec<SurfaceId>,
    timestamps: bool,
}

struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    period_ns: f32,
}

/// What a frame's encoding needs after the passes.
struct Encoded {
    encoder: wgpu::CommandEncoder,
    surfaces: Vec<SurfaceId>,
}

/// The renderer. See the [module documentation](self).
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: RenderConfig,
    frame_layout: wgpu::BindGroupLayout,
    shadow_layout: wgpu::BindGroupLayout,
    surface_layout: wgpu::BindGroupLayout,
    tonemap_layout: wgpu::BindGroupLayout,
    classify_layout: wgpu::BindGroupLayout,
    heightfield_layout: wgpu::BindGroupLayout,
    classify_pipeline: wgpu::ComputePipeline,
    heightfield_pipeline: wgpu::ComputePipeline,
    /// One pipeline per cascade (the cascade is an override constant of `vs_shadow`).
    shadow_pipelines: [wgpu::RenderPipeline; 2],
    mesh_pipeline: wgpu::RenderPipeline,
    basic_pipeline: wgpu::RenderPipeline,
    deformable_pipeline: wgpu::RenderPipeline,
    sky_pipeline: wgpu::RenderPipeline,
    snowfall_pipeline: wgpu::RenderPipeline,
    tonemap_module: wgpu::ShaderModule,
    tonemap_pipeline_layout: wgpu::PipelineLayout,
    tonemap_pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    shadow_sampler: wgpu::Sampler,
    linear_sampler: wgpu::Sampler,
    frame_buffer: wgpu::Buffer,
    surface_buffer: Growable,
    classify_buffer: Growable,
    state_buffer: Growable,
    heightfield_params: Growable,
    instance_buffer: Growable,
    /// Both cascades, for sampling.
    shadow_view: wgpu::TextureView,
    /// Each cascade, for rendering into.
    cascade_views: [wgpu::TextureView; 2],
    shadow_size: u32,
    targets: Targets,
    heightfields: HashMap<SurfaceId, HeightfieldTexture>,
    /// The tessellated tier's pipelines and buffers.
    tess: tessellate::gpu::TessGpu,
    /// Per-surface settings of the tessellated tier, and their version.
    geometry: HashMap<SurfaceId, SurfaceGeometry>,
    geometry_version: u64,
    base_meshes: HashMap<SurfaceId, BaseMeshGpu>,
    /// The surfaces of the latest frame encoded, in slot order (for readbacks).
    last_surfaces: Vec<SurfaceId>,
    meshes: Vec<GpuMesh>,
    timestamps: Option<Timestamps>,
    stats: StatsReadback,
    latest: Option<FrameReport>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer")
            .field("config", &self.config)
            .field("meshes", &self.meshes.len())
            .field("timestamps", &self.timestamps.is_some())
            .finish()
    }
}

fn texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

fn storage_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: HEIGHTFIELD_FORMAT,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

fn depth_state(compare: wgpu::CompareFunction, write: bool) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    })
}

/// Depth state of everything drawn into the moon's shadow cascades (meshes, and the tessellated
/// tier's snow): nearest wins, biased against acne by slope.
fn shadow_depth_state() -> Option<wgpu::DepthStencilState> {
    depth_state(wgpu::CompareFunction::Less, true).map(|d| wgpu::DepthStencilState {
        bias: wgpu::DepthBiasState {
            constant: 2,
            slope_scale: 2.0,
            clamp: 0.0,
        },
        ..d
    })
}

fn create_targets(device: &wgpu::Device, width: u32, height: u32, supersample: u32) -> Targets {
    let texture = |label, w, h, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    use wgpu::TextureUsages as U;
    let (iw, ih) = (width * supersample, height * supersample);
    let color = texture(
        "scene colour",
        iw,
        ih,
        HDR_FORMAT,
        U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
    );
    let depth = texture(
        "scene depth",
        iw,
        ih,
        DEPTH_FORMAT,
        U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
    );
    let output = texture(
        "output",
        width,
        height,
        OUTPUT_FORMAT,
        U::RENDER_ATTACHMENT | U::COPY_SRC,
    );
    let padded_row = (width * 4).div_ceil(256) * 256;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("output readback"),
        size: padded_row as u64 * height as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    Targets {
        size: (width, height),
        color_view: color.create_view(&Default::default()),
        depth_view: depth.create_view(&Default::default()),
        output_view: output.create_view(&Default::default()),
        output,
        readback,
        padded_row,
    }
}

/// A half float's value.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let frac = (h & 0x3ff) as f32;
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 => f32::INFINITY,
        _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

fn finite_mat(m: &Mat4) -> bool {
    m.to_cols_array().iter().all(|v| v.is_finite())
}

impl Renderer {
    /// Create a renderer on a GPU context (pipelines are built here, once).
    pub fn new(gpu: &GpuContext, config: RenderConfig) -> RenderResult<Self> {
        let device = gpu.device.clone();
        config.validate(&device)?;
        // Pipelines are checked by naga in the tests; a driver that still refuses one is reported
        // as an error rather than wgpu's default panic.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let filterable = gpu.caps.filterable_rgba16f;
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;

        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[
                uniform(0, vf),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(if filterable {
                        wgpu::SamplerBindingType::Filtering
                    } else {
                        wgpu::SamplerBindingType::NonFiltering
                    }),
                    count: None,
                },
            ],
        });
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow frame"),
            entries: &[uniform(0, wgpu::ShaderStages::VERTEX)],
        });
        let surface_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("snow surface"),
            entries: &[
                uniform(0, vf),
                texture_entry(1, wgpu::TextureSampleType::Float { filterable }),
                texture_entry(2, wgpu::TextureSampleType::Float { filterable }),
            ],
        });
        let tonemap_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap inputs"),
            entries: &[
                texture_entry(0, wgpu::TextureSampleType::Float { filterable: false }),
                texture_entry(1, wgpu::TextureSampleType::Depth),
            ],
        });
        let classify_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("classify"),
            entries: &[
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
            ],
        });
        let heightfield_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("heightfield"),
                entries: &[
                    compute_storage(0, true),
                    uniform(1, wgpu::ShaderStages::COMPUTE),
                    storage_texture_entry(2),
                    storage_texture_entry(3),
                ],
            });

        let module = |label: &str, source: String| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        };
        let surface_module = module("surface.wgsl", shaders::surface());
        let mesh_module = module("mesh.wgsl", shaders::mesh());
        let sky_module = module("sky.wgsl", shaders::sky());
        let snowfall_module = module("snowfall.wgsl", shaders::snowfall());
        let tonemap_module = module("tonemap.wgsl", shaders::tonemap());
        let classify_module = module("classify.wgsl", shaders::classify());
        let heightfield_module = module("heightfield.wgsl", shaders::heightfield());

        let layout = |label: &str, groups: &[&wgpu::BindGroupLayout]| {
            let groups: Vec<Option<&wgpu::BindGroupLayout>> =
                groups.iter().map(|g| Some(*g)).collect();
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &groups,
                immediate_size: 0,
            })
        };
        let compute = |label: &str,
                       module: &wgpu::ShaderModule,
                       entry: &str,
                       groups: &[&wgpu::BindGroupLayout]| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(&layout(label, groups)),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let classify_pipeline = compute(
            "classify",
            &classify_module,
            "classify",
            &[&classify_layout],
        );
        let heightfield_pipeline = compute(
            "heightfield",
            &heightfield_module,
            "heightfield",
            &[&heightfield_layout],
        );

        let hdr_target = [Some(wgpu::ColorTargetState {
            format: HDR_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let blended_target = [Some(wgpu::ColorTargetState {
            format: HDR_FORMAT,
            blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let back_culled = wgpu::PrimitiveState {
            cull_mode: Some(wgpu::Face::Back),
            ..Default::default()
        };
        let mesh_buffers = gpu::mesh_vertex_layouts();
        let mesh_buffers: Vec<Option<wgpu::VertexBufferLayout>> =
            mesh_buffers.into_iter().map(Some).collect();

        let shadow_pipelines = [0.0, 1.0].map(|cascade| {
            let constants = [("SHADOW_CASCADE", cascade)];
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow"),
                layout: Some(&layout("shadow", &[&shadow_layout])),
                vertex: wgpu::VertexState {
                    module: &mesh_module,
                    entry_point: Some("vs_shadow"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    buffers: &mesh_buffers,
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: shadow_depth_state(),
                multisample: wgpu::MultisampleState::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        });
        let render = |label: &str,
                      module: &wgpu::ShaderModule,
                      vs: &str,
                      fs: &str,
                      buffers: &[Option<wgpu::VertexBufferLayout>],
                      groups: &[&wgpu::BindGroupLayout],
                      primitive: wgpu::PrimitiveState,
                      depth: Option<wgpu::DepthStencilState>,
                      targets: &[Option<wgpu::ColorTargetState>],
                      constants: &[(&str, f64)]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout(label, groups)),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive,
                depth_stencil: depth,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(fs),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants,
                        ..Default::default()
                    },
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::CompareFunction as C;
        let mesh_pipeline = render(
            "opaque meshes",
            &mesh_module,
            "vs_mesh",
            "fs_mesh",
            &mesh_buffers,
            &[&frame_layout],
            back_culled,
            depth_state(C::Less, true),
            &hdr_target,
            &[],
        );
        let manual: &[(&str, f64)] = if filterable {
            &[]
        } else {
            &[("MANUAL_FILTER", 1.0)]
        };
        let basic_pipeline = render(
            "snow basic",
            &surface_module,
            "vs_surface",
            "fs_basic",
            &[],
            &[&frame_layout, &surface_layout],
            back_culled,
            depth_state(C::LessEqual, true),
            &hdr_target,
            &[],
        );
        let deformable_pipeline = render(
            "snow deformable",
            &surface_module,
            "vs_surface",
            "fs_deformable",
            &[],
            &[&frame_layout, &surface_layout],
            back_culled,
            depth_state(C::LessEqual, true),
            &hdr_target,
            manual,
        );
        let sky_pipeline = render(
            "sky",
            &sky_module,
            "vs_sky",
            "fs_sky",
            &[],
            &[&frame_layout],
            wgpu::PrimitiveState::default(),
            depth_state(C::LessEqual, false),
            &hdr_target,
            &[],
        );
        let snowfall_pipeline = render(
            "snowfall",
            &snowfall_module,
            "vs_flake",
            "fs_flake",
            &[],
            &[&frame_layout],
            wgpu::PrimitiveState::default(),
            depth_state(C::Less, false),
            &blended_target,
            &[],
        );
        let tonemap_pipeline_layout = layout("tonemap", &[&frame_layout, &tonemap_layout]);

        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let filter = if filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        let linear_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("heightfield"),
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        use wgpu::BufferUsages as U;
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        let shadow_size = config.shadow_map_size;
        let shadow_texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("moon shadow cascades"),
            size: wgpu::Extent3d {
                width: shadow_size,
                height: shadow_size,
                depth_or_array_layers: 2,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_view = shadow_texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let cascade_views = [0, 1].map(|layer| {
            shadow_texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        });
        let timestamps = gpu.caps.timestamps.then(|| {
            let count = 2 * PASSES.len() as u32;
            Timestamps {
                set: device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("render pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count,
                }),
                resolve: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("render timestamp resolve"),
                    size: count as u64 * 8,
                    usage: U::QUERY_RESOLVE | U::COPY_SRC,
                    mapped_at_creation: false,
                }),
                period_ns: gpu.queue.get_timestamp_period(),
            }
        });
        let stats = StatsReadback {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render stats readback"),
                size: 1024,
                usage: U::MAP_READ | U::COPY_DST,
                mapped_at_creation: false,
            }),
            state: Arc::new(AtomicU8::new(MAP_IDLE)),
            surfaces: Vec::new(),
            timestamps: false,
        };
        let targets = create_targets(&device, config.width, config.height, config.supersample);
        let tess = tessellate::gpu::TessGpu::new(
            &device,
            &frame_layout,
            &shadow_layout,
            filterable,
            HDR_FORMAT,
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        Ok(Self {
            surface_buffer: Growable::new(
                &device,
                "snow surfaces",
                U::UNIFORM | U::COPY_DST,
                UNIFORM_STRIDE * 8,
            ),
            classify_buffer: Growable::new(
                &device,
                "classify records",
                U::STORAGE | U::COPY_DST,
                std::mem::size_of::<ClassifyRecord>() as u64 * 8,
            ),
            state_buffer: Growable::new(
                &device,
                "surface state",
                U::STORAGE | U::INDIRECT | U::COPY_SRC,
                STATE_WORDS * 4 * 8,
            ),
            heightfield_params: Growable::new(
                &device,
                "heightfield params",
                U::UNIFORM | U::COPY_DST,
                UNIFORM_STRIDE * 8,
            ),
            instance_buffer: Growable::new(
                &device,
                "mesh instances",
                U::VERTEX | U::COPY_DST,
                144 * 64,
            ),
            queue: gpu.queue.clone(),
            device,
            config,
            frame_layout,
            shadow_layout,
            surface_layout,
            tonemap_layout,
            classify_layout,
            heightfield_layout,
            classify_pipeline,
            heightfield_pipeline,
            shadow_pipelines,
            mesh_pipeline,
            basic_pipeline,
            deformable_pipeline,
            sky_pipeline,
            snowfall_pipeline,
            tonemap_module,
            tonemap_pipeline_layout,
            tonemap_pipelines: HashMap::new(),
            shadow_sampler,
            linear_sampler,
            frame_buffer,
            shadow_view,
            cascade_views,
            shadow_size,
            targets,
            heightfields: HashMap::new(),
            tess,
            geometry: HashMap::new(),
            geometry_version: 0,
            base_meshes: HashMap::new(),
            last_surfaces: Vec::new(),
            meshes: Vec::new(),
            timestamps,
            stats,
            latest: None,
        })
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
        let desc = world.surface(surface)?;
        let layout = world.layout(surface)?;
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
        self.targets = create_targets(&self.device, width, height, supersample);
        Ok(())
    }

    /// Register a mesh to draw; normals are computed here (smooth, split at creases).
    pub fn add_mesh(&mut self, mesh: &Mesh) -> RenderResult<RenderMeshId> {
        let gpu = self.upload_mesh(mesh)?;
        self.meshes.push(gpu);
        Ok(RenderMeshId(self.meshes.len() as u32 - 1))
    }

    /// Replace a registered mesh (an animated one, re-posed).
    pub fn update_mesh(&mut self, id: RenderMeshId, mesh: &Mesh) -> RenderResult<()> {
        if id.0 as usize >= self.meshes.len() {
            return Err(RenderError::StaleMesh { index: id.0 });
        }
        let gpu = self.upload_mesh(mesh)?;
        self.meshes[id.0 as usize] = gpu;
        Ok(())
    }

    fn upload_mesh(&self, mesh: &Mesh) -> RenderResult<GpuMesh> {
        mesh.validate("render mesh")?;
        let (vertices, indices) = geometry::shade_normals(mesh, geometry::CREASE_DEGREES);
        use wgpu::util::DeviceExt;
        Ok(GpuMesh {
            vertices: self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("render mesh vertices"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
            indices: self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("render mesh indices"),
                    contents: bytemuck::cast_slice(&indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
            index_count: indices.len() as u32,
            radius: mesh.bounding_radius(),
        })
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
        let Encoded {
            mut encoder,
            surfaces,
        } = self.encode(world, frame, &output_view, OUTPUT_FORMAT)?;
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
        self.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        self.start_stats_map();

        let slice = self.targets.readback.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| RenderError::Readback(e.to_string()))?
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        let mut rgba8 = Vec::with_capacity((w * h * 4) as usize);
        {
            let data = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Readback(format!("{e:?}")))?;
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
        })
    }

    /// Render a frame into a caller's texture view (a window's surface texture) of the configured
    /// size and the given format, without waiting for the GPU. Returns the report of the latest
    /// earlier frame whose GPU results have come back, if any.
    pub fn render_to_view(
        &mut self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> RenderResult<Option<FrameReport>> {
        let t = target.texture();
        let expected = self.targets.size;
        if (t.width(), t.height()) != expected {
            return Err(RenderError::TargetSize {
                got: (t.width(), t.height()),
                expected,
            });
        }
        self.finish_stats(false)?;
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let Encoded {
            mut encoder,
            surfaces,
        } = self.encode(world, frame, target, format)?;
        let copied = self.stats.state.load(Ordering::Acquire) == MAP_IDLE;
        if copied {
            self.copy_stats(&mut encoder, surfaces);
        }
        self.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        if copied {
            self.start_stats_map();
        }
        Ok(self.latest.clone())
    }

    /// Copy `size` bytes of a buffer at `offset` back to the CPU (waits for the GPU).
    fn read_back(&self, buffer: &wgpu::Buffer, offset: u64, size: u64) -> RenderResult<Vec<u8>> {
        let size = size.div_ceil(4) * 4;
        if size == 0 {
            return Ok(Vec::new());
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("render readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        self.map_staging(&staging)
    }

    fn map_staging(&self, staging: &wgpu::Buffer) -> RenderResult<Vec<u8>> {
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| RenderError::Readback(e.to_string()))?
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Readback(format!("{e:?}")))?
            .to_vec();
        staging.unmap();
        Ok(data)
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
        let words = |b: &[u8]| -> Vec<u32> {
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        };
        let args_at = (tessellate::ARGS_BASE + tessellate::ARGS_STRIDE * s as u64) * 4;
        let args = words(&self.read_back(&self.tess.counters.buffer, args_at, 20)?);
        let (count, first) = (args[0] as u64, args[2] as u64);
        if count == 0 {
            return Ok(DicedMesh {
                vertices: Vec::new(),
                triangles: Vec::new(),
            });
        }
        let indices = words(&self.read_back(&self.tess.indices.buffer, first * 4, count * 4)?);
        let lo = indices.iter().copied().min().unwrap_or(0) as u64;
        let hi = indices.iter().copied().max().unwrap_or(0) as u64;
        let raw = self.read_back(
            &self.tess.vertices.buffer,
            lo * tessellate::VERTEX_BYTES,
            (hi + 1 - lo) * tessellate::VERTEX_BYTES,
        )?;
        let floats: Vec<f32> = raw
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let vertices = floats
            .chunks_exact(8)
            .map(|v| DicedVertex {
                position: Vec3::new(v[0], v[1], v[2]),
                kind: match v[3] as u32 {
                    0 => DicedKind::Top,
                    1 => DicedKind::SkirtTop,
                    _ => DicedKind::SkirtBottom,
                },
            })
            .collect();
        let triangles = indices
            .chunks_exact(3)
            .map(|t| [t[0] - lo as u32, t[1] - lo as u32, t[2] - lo as u32])
            .collect();
        Ok(DicedMesh {
            vertices,
            triangles,
        })
    }

    /// A surface's smoothed depression, displaced channel and bank heights as the latest frame's
    /// heightfield and bank passes wrote them (the banks only in the tessellated tier, and only
    /// for a deformed surface; otherwise what an earlier frame left, or zeros).
    pub fn read_surface_fields(&self, surface: SurfaceId) -> RenderResult<SurfaceFields> {
        self.last_slot(surface)?;
        let tex = self
            .heightfields
            .get(&surface)
            .ok_or_else(|| RenderError::Readback("the surface has no heightfield yet".into()))?;
        let (w, h) = tex.size;
        let row = (w * 8).div_ceil(256) * 256;
        let mut channels = Vec::new();
        for (texture, channel) in [
            (&tex.textures[0], 0),
            (&tex.textures[1], 1),
            (&tex.textures[2], 0),
        ] {
            let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("field readback"),
                size: (row * h) as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut encoder = self.device.create_command_encoder(&Default::default());
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &staging,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
            self.queue.submit([encoder.finish()]);
            let data = self.map_staging(&staging)?;
            let mut values = Vec::with_capacity((w * h) as usize);
            for r in 0..h {
                for c in 0..w {
                    let o = (r * row + c * 8 + channel * 2) as usize;
                    values.push(f16_to_f32(u16::from_le_bytes([data[o], data[o + 1]])));
                }
            }
            channels.push(values);
        }
        let bank = channels.pop().unwrap_or_default();
        let displaced = channels.pop().unwrap_or_default();
        let depression = channels.pop().unwrap_or_default();
        Ok(SurfaceFields {
            width: w,
            height: h,
            depression,
            displaced,
            bank,
        })
    }

    /// The report of the latest frame whose GPU results have come back.
    pub fn latest_report(&self) -> Option<&FrameReport> {
        self.latest.as_ref()
    }

    fn copy_stats(&mut self, encoder: &mut wgpu::CommandEncoder, surfaces: Vec<SurfaceId>) {
        let state_bytes = surfaces.len() as u64 * STATE_WORDS * 4;
        let dice_bytes = tessellate::gpu::counters_bytes(surfaces.len());
        let ts_bytes = if self.timestamps.is_some() {
            PASSES.len() as u64 * 16
        } else {
            0
        };
        let need = (state_bytes + dice_bytes + ts_bytes).max(16);
        if self.stats.buffer.size() < need {
            self.stats.buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render stats readback"),
                size: need.next_power_of_two(),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
        }
        if state_bytes > 0 {
            encoder.copy_buffer_to_buffer(
                &self.state_buffer.buffer,
                0,
                &self.stats.buffer,
                0,
                state_bytes,
            );
        }
        encoder.copy_buffer_to_buffer(
            &self.tess.counters.buffer,
            0,
            &self.stats.buffer,
            state_bytes,
            dice_bytes,
        );
        if let Some(ts) = &self.timestamps {
            encoder.resolve_query_set(&ts.set, 0..2 * PASSES.len() as u32, &ts.resolve, 0);
            encoder.copy_buffer_to_buffer(
                &ts.resolve,
                0,
                &self.stats.buffer,
                state_bytes + dice_bytes,
                ts_bytes,
            );
        }
        self.stats.surfaces = surfaces;
        self.stats.timestamps = self.timestamps.is_some();
    }

    fn start_stats_map(&mut self) {
        let state = self.stats.state.clone();
        state.store(MAP_PENDING, Ordering::Release);
        self.stats
            .buffer
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                state.store(
                    if r.is_ok() { MAP_READY } else { MAP_FAILED },
                    Ordering::Release,
                );
            });
    }

    /// Read the stats readback when it has arrived (waiting for it when `wait`).
    fn finish_stats(&mut self, wait: bool) -> RenderResult<()> {
        if self.stats.state.load(Ordering::Acquire) == MAP_IDLE {
            return Ok(());
        }
        let poll = if wait {
            wgpu::PollType::wait_indefinitely()
        } else {
            wgpu::PollType::Poll
        };
        self.device
            .poll(poll)
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        match self.stats.state.load(Ordering::Acquire) {
            MAP_READY => {}
            MAP_FAILED => {
                self.stats.state.store(MAP_IDLE, Ordering::Release);
                return Err(RenderError::Readback(
                    "mapping the frame report failed".into(),
                ));
            }
            _ => return Ok(()),
        }
        let n = self.stats.surfaces.len();
        let report = {
            let data = self
                .stats
                .buffer
                .slice(..)
                .get_mapped_range()
                .map_err(|e| RenderError::Readback(format!("{e:?}")))?;
            // Read by value: a mapped range promises no alignment.
            let word = |i: usize| {
                u32::from_le_bytes([
                    data[4 * i],
                    data[4 * i + 1],
                    data[4 * i + 2],
                    data[4 * i + 3],
                ])
            };
            let surfaces = self
                .stats
                .surfaces
                .iter()
                .enumerate()
                .map(|(s, &id)| {
                    let base = s * STATE_WORDS as usize;
                    let args = n * STATE_WORDS as usize
                        + (tessellate::ARGS_BASE + tessellate::ARGS_STRIDE * s as u64) as usize;
                    SurfaceShading {
                        surface: id,
                        material: if word(base + STATE_TOUCHED as usize) == 0 {
                            SnowMaterialKind::Basic
                        } else {
                            SnowMaterialKind::Deformable
                        },
                        deepest: f32::from_bits(word(base + STATE_DEEPEST as usize)),
                        triangles: word(args) / 3,
                    }
                })
                .collect();
            let mut pass_times = Vec::new();
            if let (true, Some(ts)) = (self.stats.timestamps, &self.timestamps) {
                let start =
                    n * STATE_WORDS as usize * 4 + tessellate::gpu::counters_bytes(n) as usize;
                let tick = |i: usize| {
                    let o = start + 8 * i;
                    let mut b = [0u8; 8];
                    b.copy_from_slice(&data[o..o + 8]);
                    u64::from_le_bytes(b)
                };
                for (i, p) in PASSES.iter().enumerate() {
                    let dt = tick(2 * i + 1).saturating_sub(tick(2 * i));
                    pass_times.push(PassTime {
                        name: p.name,
                        gpu_ms: dt as f64 * ts.period_ns as f64 * 1e-6,
                    });
                }
            }
            FrameReport {
                pass_times,
                surfaces,
                dice_overflow: word(
                    n * STATE_WORDS as usize + tessellate::COUNTER_OVERFLOW as usize,
                ),
            }
        };
        self.stats.buffer.unmap();
        self.stats.state.store(MAP_IDLE, Ordering::Release);
        self.latest = Some(report);
        Ok(())
    }

    fn check_frame(&self, frame: &RenderFrame<'_>) -> RenderResult<()> {
        let bad = |what: String, value: String, expected| {
            Err(RenderError::InvalidFrame {
                what,
                value,
                expected,
            })
        };
        let c = &frame.camera;
        if !(c.eye.is_finite() && c.target.is_finite()) || c.eye.distance(c.target) < 1e-4 {
            return bad(
                "camera".into(),
                format!(
                    "eye {:?}, target {:?}",
                    c.eye.to_array(),
                    c.target.to_array()
                ),
                "two finite, distinct points",
            );
        }
        if !(c.fov_y_degrees.is_finite() && c.fov_y_degrees > 1.0 && c.fov_y_degrees < 179.0) {
            return bad(
                "camera fov_y_degrees".into(),
                c.fov_y_degrees.to_string(),
                "between 1 and 179 degrees",
            );
        }
        if !frame.time.is_finite() {
            return bad("time".into(), frame.time.to_string(), "finite");
        }
        for (i, inst) in frame.instances.iter().enumerate() {
            if inst.mesh.0 as usize >= self.meshes.len() {
                return Err(RenderError::StaleMesh { index: inst.mesh.0 });
            }
            if !finite_mat(&inst.transform) || inst.transform.determinant().abs() < 1e-12 {
                return bad(
                    format!("instance {i} transform"),
                    format!("{:?}", inst.transform),
                    "finite and invertible (no zero scale)",
                );
            }
        }
        for (i, l) in frame.lights.iter().enumerate() {
            if !(l.position.is_finite()
                && l.color.is_finite()
                && l.radius.is_finite()
                && l.radius > 0.0)
            {
                return bad(
                    format!("light {i}"),
                    format!("{l:?}"),
                    "a finite position and colour and a radius above 0",
                );
            }
        }
        let e = &frame.environment;
        if !(e.moon_direction.is_finite()
            && e.moon_direction.length() > 1e-3
            && e.exposure.is_finite()
            && e.exposure > 0.0)
        {
            return bad(
                "environment".into(),
                format!("{e:?}"),
                "a moon direction of non-zero length and an exposure above 0",
            );
        }
        for (i, (id, _)) in frame.surfaces.iter().enumerate() {
            if frame.surfaces[..i].iter().any(|(other, _)| other == id) {
                return bad(
                    format!("surface {}", id.index()),
                    "listed twice".into(),
                    "listed once per frame",
                );
            }
        }
        Ok(())
    }

    /// The moon's two shadow cascades: the near one around what the camera looks at, the far one
    /// around the snow surfaces and every shadow caster.
    fn shadow_cascades(
        &self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
    ) -> RenderResult<ShadowCascades> {
        let mut lo = Vec3::splat(f32::MAX);
        let mut hi = Vec3::splat(f32::MIN);
        for (id, _) in frame.surfaces {
            let d = world.surface(*id)?;
            let m = d.local_to_world();
            let h = d.size * 0.5;
            for corner in [
                Vec3::new(-h.x, 0.0, -h.y),
                Vec3::new(h.x, 0.0, -h.y),
                Vec3::new(-h.x, d.snow_depth, h.y),
                Vec3::new(h.x, d.snow_depth, h.y),
            ] {
                let p = m.transform_point3(corner);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        // Receivers beyond the surfaces and the casters (a backdrop, a ground to the horizon) are
        // left out: they would spread the far cascade's texels over what casts no shadow.
        for inst in frame.instances.iter().filter(|i| i.casts_shadow) {
            let r = self.meshes[inst.mesh.0 as usize].radius;
            let (scale, _, t) = inst.transform.to_scale_rotation_translation();
            let r = r * scale.abs().max_element();
            lo = lo.min(t - Vec3::splat(r));
            hi = hi.max(t + Vec3::splat(r));
        }
        if lo.x > hi.x {
            lo = Vec3::splat(-1.0);
            hi = Vec3::splat(1.0);
        }
        // Snap the box outwards to whole metres so that moving characters do not shift the shadow
        // map every frame (that would make shadow edges crawl).
        lo = lo.floor() - Vec3::ONE;
        hi = hi.ceil() + Vec3::ONE;
        let center = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5;
        let dir = frame.environment.moon_direction.normalize();
        let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
        let view = glam::camera::rh::view::look_at_mat4(center + dir * radius * 2.0, center, up);
        let mut vlo = Vec3::splat(f32::MAX);
        let mut vhi = Vec3::splat(f32::MIN);
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let v = view.transform_point3(c);
            vlo = vlo.min(v);
            vhi = vhi.max(v);
        }
        let (near_z, far_z) = (-vhi.z - 1.0, -vlo.z + 1.0);
        let proj = glam::camera::rh::proj::directx::orthographic(
            vlo.x, vhi.x, vlo.y, vhi.y, near_z, far_z,
        );
        let far_texel = (vhi.x - vlo.x).max(vhi.y - vlo.y) / self.shadow_size as f32;

        // The near cascade: a square of NEAR_CASCADE metres around the point 40% of the way into
        // it along the view, with the far cascade's depth range (every caster still casts). Its
        // centre is snapped to whole texels in the moon's view so that a moving camera does not
        // make its shadow edges crawl.
        let cam = &frame.camera;
        let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
        let focus = view.transform_point3(cam.eye + forward * (NEAR_CASCADE * 0.4));
        let near_texel = NEAR_CASCADE / self.shadow_size as f32;
        let snap = |v: f32| (v / near_texel).round() * near_texel;
        let (cx, cy) = (snap(focus.x), snap(focus.y));
        let half = NEAR_CASCADE * 0.5;
        let near_proj = glam::camera::rh::proj::directx::orthographic(
            cx - half,
            cx + half,
            cy - half,
            cy + half,
            near_z,
            far_z,
        );
        Ok(ShadowCascades {
            near: near_proj * view,
            far: proj * view,
            near_texel,
            far_texel,
        })
    }

    fn tonemap_pipeline(&mut self, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
        let ss = self.config.supersample;
        if let Some(p) = self.tonemap_pipelines.get(&(format, ss)) {
            return p.clone();
        }
        let constants = [
            ("SUPERSAMPLE", ss as f64),
            ("ENCODE_SRGB", if format.is_srgb() { 0.0 } else { 1.0 }),
        ];
        let pipeline = self
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("tonemap"),
                layout: Some(&self.tonemap_pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &self.tonemap_module,
                    entry_point: Some("vs_tonemap"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &self.tonemap_module,
                    entry_point: Some("fs_tonemap"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
        self.tonemap_pipelines
            .insert((format, ss), pipeline.clone());
        pipeline
    }

    fn heightfield_texture(&mut self, id: SurfaceId, size: (u32, u32)) -> &HeightfieldTexture {
        let stale = self.heightfields.get(&id).is_none_or(|t| t.size != size);
        if stale {
            let texture = |label| {
                self.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: size.0,
                        height: size.1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: HEIGHTFIELD_FORMAT,
                    usage: wgpu::TextureUsages::STORAGE_BINDING
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
            };
            let view = |t: &wgpu::Texture| t.create_view(&Default::default());
            let shape = texture("snow heightfield");
            let light = texture("snow heightfield light");
            let bank = texture("snow banks");
            let scratch = texture("snow bank scratch");
            let entry = HeightfieldTexture {
                size,
                shape: view(&shape),
                light: view(&light),
                bank: view(&bank),
                bank_scratch: view(&scratch),
                textures: [shape, light, bank],
            };
            self.heightfields.insert(id, entry);
        }
        &self.heightfields[&id]
    }

    /// The tessellated tier's per-frame tables: which surfaces are diced (none in the other
    /// tiers), their base meshes, dicing and bank parameters, and room for the diced mesh.
    fn prepare_tessellation(
        &mut self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        uniform: &FrameUniform,
    ) -> RenderResult<Vec<bool>> {
        let n = frame.surfaces.len();
        let mut tessellated = vec![false; n];
        self.tess
            .counters
            .ensure(&self.device, tessellate::gpu::counters_bytes(n));
        self.last_surfaces = frame.surfaces.iter().map(|(id, _)| *id).collect();
        if self.config.tier != Tier::Tessellated {
            return Ok(tessellated);
        }
        let cfg = self.config;
        let (iw, ih) = (cfg.width * cfg.supersample, cfg.height * cfg.supersample);
        let proj = frame.camera.projection(iw as f32 / ih as f32, NEAR, FAR);
        let pixels_per_radian = ih as f32 * 0.5 * proj.y_axis.y;
        let view_proj = Mat4::from_cols_array_2d(&uniform.view_proj);
        let vertex_capacity = cfg.dice.max_triangles;
        let index_capacity = cfg.dice.max_triangles * 3;
        self.tess.vertices.ensure(
            &self.device,
            vertex_capacity as u64 * tessellate::VERTEX_BYTES,
        );
        self.tess
            .indices
            .ensure(&self.device, index_capacity as u64 * 4);
        let stride = UNIFORM_STRIDE as usize;
        let mut bank_bytes = vec![0u8; n.max(1) * stride];
        let mut dice_bytes = vec![0u8; n.max(1) * stride];
        for (s, (id, _)) in frame.surfaces.iter().enumerate() {
            let g = self.geometry.get(id).cloned().unwrap_or_default();
            if !g.tessellate {
                continue;
            }
            tessellated[s] = true;
            let desc = world.surface(*id)?;
            let layout = world.layout(*id)?;
            let texel = glam::Vec2::new(
                desc.size.x / layout.width as f32,
                desc.size.y / layout.height as f32,
            );
            let half = desc.size * 0.5;
            let key = ([half.x.to_bits(), half.y.to_bits()], self.geometry_version);
            if self.base_meshes.get(id).is_none_or(|b| b.key != key) {
                let mesh = match &g.mesh {
                    Some(m) => {
                        m.validate(half)?;
                        m.clone()
                    }
                    None => SurfaceMesh::rectangle(half),
                };
                let triangles = mesh.base_triangles();
                use wgpu::util::DeviceExt;
                let buffer = self
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("snow base mesh"),
                        contents: bytemuck::cast_slice(&triangles),
                        usage: wgpu::BufferUsages::STORAGE,
                    });
                self.base_meshes.insert(
                    *id,
                    BaseMeshGpu {
                        buffer,
                        triangles: triangles.len() as u32,
                        key,
                    },
                );
            }
            let base = &self.base_meshes[id];
            let local_to_world = desc.local_to_world();
            let eye = local_to_world.inverse().transform_point3(frame.camera.eye);
            let dice = tessellate::DiceParams {
                local_to_clip: (view_proj * local_to_world).to_cols_array_2d(),
                eye: [eye.x, eye.y, eye.z, pixels_per_radian],
                settings: [
                    cfg.dice.target_edge_pixels,
                    cfg.dice.max_level as f32,
                    0.5 * texel.min_element(),
                    cfg.dice.detail_floor,
                ],
                // Banks stay below the snow depth in practice; waves reach 5 cm at most.
                extent: [
                    desc.snow_depth,
                    desc.snow_depth + 0.05 * g.macro_waves,
                    0.0,
                    0.0,
                ],
                grid: [layout.width, layout.height, s as u32, base.triangles],
                capacity: [vertex_capacity, index_capacity, 0, 0],
                half_size: [half.x, half.y, 0.0, 0.0],
                local_to_shadow: (Mat4::from_cols_array_2d(&uniform.shadow_near) * local_to_world)
                    .to_cols_array_2d(),
            };
            let bank = tessellate::BankParams::new(
                layout.width,
                layout.height,
                texel,
                desc.snow_depth,
                g.banks,
            );
            let o = s * stride;
            dice_bytes[o..o + std::mem::size_of::<tessellate::DiceParams>()]
                .copy_from_slice(bytemuck::bytes_of(&dice));
            bank_bytes[o..o + std::mem::size_of::<tessellate::BankParams>()]
                .copy_from_slice(bytemuck::bytes_of(&bank));
        }
        self.tess
            .dice_params
            .ensure(&self.device, dice_bytes.len() as u64);
        self.queue
            .write_buffer(&self.tess.dice_params.buffer, 0, &dice_bytes);
        self.tess
            .bank_params
            .ensure(&self.device, bank_bytes.len() as u64);
        self.queue
            .write_buffer(&self.tess.bank_params.buffer, 0, &bank_bytes);
        Ok(tessellated)
    }

    fn frame_uniform(&self, frame: &RenderFrame<'_>, shadow: &ShadowCascades) -> FrameUniform {
        let cfg = &self.config;
        let (w, h) = (cfg.width * cfg.supersample, cfg.height * cfg.supersample);
        let aspect = w as f32 / h as f32;
        let view_proj = frame.camera.projection(aspect, NEAR, FAR) * frame.camera.view();
        let e = &frame.environment;
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        // The 8 lights nearest the camera.
        let mut lights: Vec<&PointLight> = frame.lights.iter().collect();
        lights.sort_by(|a, b| {
            a.position
                .distance_squared(frame.camera.eye)
                .total_cmp(&b.position.distance_squared(frame.camera.eye))
        });
        lights.truncate(MAX_POINT_LIGHTS);
        let mut raw = [PointLightRaw::default(); MAX_POINT_LIGHTS];
        for (r, l) in raw.iter_mut().zip(&lights) {
            *r = PointLightRaw {
                position_radius: v4(l.position, l.radius),
                color: v4(l.color, 0.0),
            };
        }
        // Surfaces the tessellated tier does not tessellate are relief mapped.
        let tier = match cfg.tier {
            Tier::Relief | Tier::Tessellated => 0,
            Tier::Pom => 1,
        };
        FrameUniform {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            shadow_near: shadow.near.to_cols_array_2d(),
            shadow_far: shadow.far.to_cols_array_2d(),
            shadow_texels: [shadow.near_texel, shadow.far_texel, 0.0, 0.0],
            eye: v4(frame.camera.eye, frame.time),
            moon_dir: v4(
                e.moon_direction.normalize(),
                e.moon_radius_degrees.to_radians().cos(),
            ),
            moon_color: v4(e.moon_color, 0.0),
            sky_zenith: v4(e.sky_zenith, e.exposure),
            sky_horizon: v4(e.sky_horizon, e.fog_density),
            ground_bounce: v4(e.ground_bounce, e.city_glow),
            sss_tint: v4(e.sss_tint, e.sss_strength),
            sky_ambient: v4(e.sky_ambient, 0.0),
            viewport: [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32],
            options: [
                cfg.debug_view.code(),
                lights.len() as u32,
                tier,
                if frame.snowfall { cfg.snowflakes } else { 0 },
            ],
            lights: raw,
        }
    }

    /// Upload the frame's tables and encode every pass of [`PASSES`] into one command encoder.
    fn encode(
        &mut self,
        world: &SnowWorld,
        frame: &RenderFrame<'_>,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> RenderResult<Encoded> {
        self.check_frame(frame)?;
        let shadow = self.shadow_cascades(world, frame)?;
        let uniform = self.frame_uniform(frame, &shadow);
        self.queue
            .write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&uniform));

        // Surface tables.
        let search = self.config.search_settings();
        let look = self.config.look;
        let n = frame.surfaces.len();
        let mut surface_bytes = vec![0u8; n.max(1) * UNIFORM_STRIDE as usize];
        let mut hf_bytes = vec![0u8; n.max(1) * UNIFORM_STRIDE as usize];
        let mut records = Vec::with_capacity(n);
        let mut sizes = Vec::with_capacity(n);
        let bits = world.pool_format().precision.bits();
        for (s, (id, ground)) in frame.surfaces.iter().enumerate() {
            let desc = world.surface(*id)?;
            let layout = world.layout(*id)?;
            let (heights, _normals) = world.gpu_offsets(*id)?;
            let texel_x = desc.size.x / layout.width as f32;
            let texel_z = desc.size.y / layout.height as f32;
            let local_to_world = desc.local_to_world();
            let u = SurfaceUniform {
                local_to_world: local_to_world.to_cols_array_2d(),
                world_to_local: local_to_world.inverse().to_cols_array_2d(),
                half_size: (desc.size * 0.5).to_array(),
                snow_depth: desc.snow_depth,
                texel: texel_x.max(texel_z),
                grid: [layout.width as f32, layout.height as f32],
                ground: match ground {
                    GroundMaterial::RoofTiles => 0,
                    GroundMaterial::Concrete => 1,
                },
                index: s as u32,
                search: [
                    search.taps_per_texel,
                    search.min_taps as f32,
                    search.max_taps as f32,
                    search.refine_taps as f32,
                ],
                look: [
                    look.ground_from,
                    look.ground_full,
                    look.occlusion,
                    search.shadow_taps as f32,
                ],
                pattern: [
                    desc.center.x,
                    desc.center.z,
                    look.switch_bits() as f32,
                    self.geometry
                        .get(id)
                        .map_or(1.0, |g: &SurfaceGeometry| g.macro_waves),
                ],
            };
            let o = s * UNIFORM_STRIDE as usize;
            surface_bytes[o..o + std::mem::size_of::<SurfaceUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
            let p = HeightfieldParams {
                heights,
                width: layout.width,
                height: layout.height,
                bits,
                snow_depth: desc.snow_depth,
                texel_x,
                texel_z,
                _pad2: 0.0,
                light: {
                    let l = local_to_world
                        .inverse()
                        .transform_vector3(frame.environment.moon_direction)
                        .normalize();
                    [l.x, l.y, l.z, 0.0]
                },
            };
            hf_bytes[o..o + std::mem::size_of::<HeightfieldParams>()]
                .copy_from_slice(bytemuck::bytes_of(&p));
            records.push(ClassifyRecord {
                heights,
                width: layout.width,
                height: layout.height,
                box_vertices: BOX_VERTICES,
                bits,
                _pad: [0; 3],
            });
            sizes.push((layout.width, layout.height));
        }
        self.surface_buffer
            .ensure(&self.device, surface_bytes.len() as u64);
        self.queue
            .write_buffer(&self.surface_buffer.buffer, 0, &surface_bytes);
        self.heightfield_params
            .ensure(&self.device, hf_bytes.len() as u64);
        self.queue
            .write_buffer(&self.heightfield_params.buffer, 0, &hf_bytes);
        if n > 0 {
            self.classify_buffer.ensure(
                &self.device,
                (n * std::mem::size_of::<ClassifyRecord>()) as u64,
            );
            self.queue.write_buffer(
                &self.classify_buffer.buffer,
                0,
                bytemuck::cast_slice(&records),
            );
        }
        self.state_buffer
            .ensure(&self.device, n.max(1) as u64 * STATE_WORDS * 4);
        let tessellated = self.prepare_tessellation(world, frame, &uniform)?;

        // Instances: all of them grouped by mesh, then the shadow casters grouped by mesh.
        let mut order: Vec<usize> = (0..frame.instances.len()).collect();
        order.sort_by_key(|&i| frame.instances[i].mesh.0);
        let raw = |inst: &Instance| {
            let normal = Mat3::from_mat4(inst.transform).inverse().transpose();
            let c = |v: Vec3| [v.x, v.y, v.z, 0.0];
            InstanceRaw {
                model: inst.transform.to_cols_array_2d(),
                normal: [c(normal.x_axis), c(normal.y_axis), c(normal.z_axis)],
                albedo_material: [
                    inst.albedo[0],
                    inst.albedo[1],
                    inst.albedo[2],
                    inst.material.code(),
                ],
                params: [inst.roughness, inst.emission, inst.snow_cover, inst.seed],
            }
        };
        let mut instances: Vec<InstanceRaw> =
            order.iter().map(|&i| raw(&frame.instances[i])).collect();
        let casters: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| frame.instances[i].casts_shadow)
            .collect();
        instances.extend(casters.iter().map(|&i| raw(&frame.instances[i])));
        let runs = |ids: &[usize], first: u32| {
            let mut out: Vec<(u32, std::ops::Range<u32>)> = Vec::new();
            for (k, &i) in ids.iter().enumerate() {
                let mesh = frame.instances[i].mesh.0;
                let at = first + k as u32;
                match out.last_mut() {
                    Some((m, r)) if *m == mesh => r.end = at + 1,
                    _ => out.push((mesh, at..at + 1)),
                }
            }
            out
        };
        let draws = runs(&order, 0);
        let shadow_draws = runs(&casters, order.len() as u32);
        if !instances.is_empty() {
            self.instance_buffer.ensure(
                &self.device,
                std::mem::size_of_val(instances.as_slice()) as u64,
            );
            self.queue.write_buffer(
                &self.instance_buffer.buffer,
                0,
                bytemuck::cast_slice(&instances),
            );
        }

        // Bind groups.
        for (s, (id, _)) in frame.surfaces.iter().enumerate() {
            self.heightfield_texture(*id, sizes[s]);
        }
        let dev = &self.device;
        let frame_bg = bind_group(
            dev,
            "frame",
            &self.frame_layout,
            &[
                self.frame_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&self.shadow_view),
                wgpu::BindingResource::Sampler(&self.shadow_sampler),
                wgpu::BindingResource::Sampler(&self.linear_sampler),
            ],
        );
        let shadow_bg = bind_group(
            dev,
            "shadow frame",
            &self.shadow_layout,
            &[self.frame_buffer.as_entire_binding()],
        );
        let classify_bg = (n > 0).then(|| {
            bind_group(
                dev,
                "classify",
                &self.classify_layout,
                &[
                    world.pool_buffer().as_entire_binding(),
                    self.classify_buffer.buffer.as_entire_binding(),
                    self.state_buffer.buffer.as_entire_binding(),
                ],
            )
        });
        let mut hf_bgs = Vec::with_capacity(n);
        let mut surface_bgs = Vec::with_capacity(n);
        for (s, (id, _)) in frame.surfaces.iter().enumerate() {
            let tex = &self.heightfields[id];
            let (shape, light) = (
                wgpu::BindingResource::TextureView(&tex.shape),
                wgpu::BindingResource::TextureView(&tex.light),
            );
            hf_bgs.push(bind_group(
                dev,
                "heightfield",
                &self.heightfield_layout,
                &[
                    world.pool_buffer().as_entire_binding(),
                    uniform_block(
                        &self.heightfield_params.buffer,
                        s,
                        std::mem::size_of::<HeightfieldParams>(),
                    ),
                    shape.clone(),
                    light.clone(),
                ],
            ));
            surface_bgs.push(bind_group(
                dev,
                "snow surface",
                &self.surface_layout,
                &[
                    uniform_block(
                        &self.surface_buffer.buffer,
                        s,
                        std::mem::size_of::<SurfaceUniform>(),
                    ),
                    shape,
                    light,
                ],
            ));
        }
        // The tessellated tier's bind groups, per diced surface: banks (two passes), dice, draw.
        struct TessGroups {
            norm: wgpu::BindGroup,
            gather: wgpu::BindGroup,
            dice: wgpu::BindGroup,
            draw: wgpu::BindGroup,
            triangles: u32,
        }
        let mut tess_bgs: Vec<Option<TessGroups>> = Vec::with_capacity(n);
        for (s, (id, _)) in frame.surfaces.iter().enumerate() {
            if !tessellated[s] {
                tess_bgs.push(None);
                continue;
            }
            let tex = &self.heightfields[id];
            let base = &self.base_meshes[id];
            let t = &self.tess;
            let bank_params = uniform_block(
                &t.bank_params.buffer,
                s,
                std::mem::size_of::<tessellate::BankParams>(),
            );
            let tv = wgpu::BindingResource::TextureView;
            let norm = bind_group(
                dev,
                "bank norm",
                &t.bank_layout,
                &[
                    bank_params.clone(),
                    tv(&tex.shape),
                    tv(&tex.light),
                    tv(&tex.bank),
                    tv(&tex.bank_scratch),
                ],
            );
            let gather = bind_group(
                dev,
                "bank gather",
                &t.bank_layout,
                &[
                    bank_params,
                    tv(&tex.shape),
                    tv(&tex.light),
                    tv(&tex.bank_scratch),
                    tv(&tex.bank),
                ],
            );
            let dice = bind_group(
                dev,
                "dice",
                &t.dice_layout,
                &[
                    uniform_block(
                        &t.dice_params.buffer,
                        s,
                        std::mem::size_of::<tessellate::DiceParams>(),
                    ),
                    base.buffer.as_entire_binding(),
                    tv(&tex.shape),
                    tv(&tex.bank),
                    self.state_buffer.buffer.as_entire_binding(),
                    t.vertices.buffer.as_entire_binding(),
                    t.indices.buffer.as_entire_binding(),
                    t.counters.buffer.as_entire_binding(),
                ],
            );
            let draw = bind_group(
                dev,
                "tessellated snow surface",
                &t.surface_layout,
                &[
                    uniform_block(
                        &self.surface_buffer.buffer,
                        s,
                        std::mem::size_of::<SurfaceUniform>(),
                    ),
                    tv(&tex.shape),
                    tv(&tex.light),
                    tv(&tex.bank),
                    self.state_buffer.buffer.as_entire_binding(),
                ],
            );
            tess_bgs.push(Some(TessGroups {
                norm,
                gather,
                dice,
                draw,
                triangles: base.triangles,
            }));
        }
        let tonemap_bg = bind_group(
            dev,
            "tonemap inputs",
            &self.tonemap_layout,
            &[
                wgpu::BindingResource::TextureView(&self.targets.color_view),
                wgpu::BindingResource::TextureView(&self.targets.depth_view),
            ],
        );
        let tonemap = self.tonemap_pipeline(format);

        // The passes, in the order of PASSES.
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("snowprint frame"),
            });
        let ts = self.timestamps.as_ref();
        let render_ts = |i: usize| {
            ts.map(|t| wgpu::RenderPassTimestampWrites {
                query_set: &t.set,
                beginning_of_pass_write_index: Some(2 * i as u32),
                end_of_pass_write_index: Some(2 * i as u32 + 1),
            })
        };
        let compute_ts = |i: usize| {
            ts.map(|t| wgpu::ComputePassTimestampWrites {
                query_set: &t.set,
                beginning_of_pass_write_index: Some(2 * i as u32),
                end_of_pass_write_index: Some(2 * i as u32 + 1),
            })
        };
        {
            let mut p = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASSES[pass::CLASSIFY].name),
                timestamp_writes: compute_ts(pass::CLASSIFY),
            });
            if let Some(bg) = &classify_bg {
                p.set_pipeline(&self.classify_pipeline);
                p.set_bind_group(0, bg, &[]);
                p.dispatch_workgroups(n as u32, 1, 1);
            }
        }
        {
            let mut p = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASSES[pass::HEIGHTFIELD].name),
                timestamp_writes: compute_ts(pass::HEIGHTFIELD),
            });
            p.set_pipeline(&self.heightfield_pipeline);
            for (s, bg) in hf_bgs.iter().enumerate() {
                p.set_bind_group(0, bg, &[]);
                p.dispatch_workgroups_indirect(
                    &self.state_buffer.buffer,
                    (s as u64 * STATE_WORDS + STATE_HEIGHTFIELD_DISPATCH) * 4,
                );
            }
        }
        {
            let mut p = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASSES[pass::BANKS].name),
                timestamp_writes: compute_ts(pass::BANKS),
            });
            // Both bank passes run over the deformed surfaces only (the heightfield's dispatch).
            for (pipeline, norm) in [
                (&self.tess.bank_norm, true),
                (&self.tess.bank_gather, false),
            ] {
                p.set_pipeline(pipeline);
                for (s, g) in tess_bgs.iter().enumerate() {
                    if let Some(g) = g {
                        p.set_bind_group(0, if norm { &g.norm } else { &g.gather }, &[]);
                        p.dispatch_workgroups_indirect(
                            &self.state_buffer.buffer,
                            (s as u64 * STATE_WORDS + STATE_HEIGHTFIELD_DISPATCH) * 4,
                        );
                    }
                }
            }
        }
        // Every surface's draw arguments start at zero, whatever the tier.
        encoder.clear_buffer(&self.tess.counters.buffer, 0, None);
        {
            let mut p = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASSES[pass::DICE].name),
                timestamp_writes: compute_ts(pass::DICE),
            });
            // One surface after the other: `seal` closes each surface's run of indices.
            for g in tess_bgs.iter().flatten() {
                p.set_bind_group(0, &g.dice, &[]);
                p.set_pipeline(&self.tess.dice);
                p.dispatch_workgroups(g.triangles.min(65535), g.triangles.div_ceil(65535), 1);
                p.set_pipeline(&self.tess.seal);
                p.dispatch_workgroups(1, 1, 1);
            }
        }
        let set_mesh = |p: &mut wgpu::RenderPass<'_>, mesh: &GpuMesh| {
            p.set_vertex_buffer(0, mesh.vertices.slice(..));
            p.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        };
        // The shadow pass: both cascades, the near one first; the pass's timestamps span both.
        for cascade in 0..2 {
            let writes = ts.map(|t| wgpu::RenderPassTimestampWrites {
                query_set: &t.set,
                beginning_of_pass_write_index: (cascade == 0).then_some(2 * pass::SHADOW as u32),
                end_of_pass_write_index: (cascade == 1).then_some(2 * pass::SHADOW as u32 + 1),
            });
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(if cascade == 0 {
                    "shadow (near cascade)"
                } else {
                    "shadow (far cascade)"
                }),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.cascade_views[cascade],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if !shadow_draws.is_empty() {
                p.set_pipeline(&self.shadow_pipelines[cascade]);
                p.set_bind_group(0, &shadow_bg, &[]);
                p.set_vertex_buffer(1, self.instance_buffer.buffer.slice(..));
                for (mesh, range) in &shadow_draws {
                    let m = &self.meshes[*mesh as usize];
                    set_mesh(&mut p, m);
                    p.draw_indexed(0..m.index_count, 0, range.clone());
                }
            }
        }
        // The displaced snow into both cascades, over the meshes' shadows.
        for cascade in 0..2 {
            let writes = ts.map(|t| wgpu::RenderPassTimestampWrites {
                query_set: &t.set,
                beginning_of_pass_write_index: (cascade == 0)
                    .then_some(2 * pass::SNOW_SHADOW as u32),
                end_of_pass_write_index: (cascade == 1).then_some(2 * pass::SNOW_SHADOW as u32 + 1),
            });
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(if cascade == 0 {
                    "snow shadow (near cascade)"
                } else {
                    "snow shadow (far cascade)"
                }),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.cascade_views[cascade],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if tess_bgs.iter().any(Option::is_some) {
                p.set_pipeline(&self.tess.shadow[cascade]);
                p.set_bind_group(0, &shadow_bg, &[]);
                p.set_vertex_buffer(0, self.tess.vertices.buffer.slice(..));
                p.set_index_buffer(
                    self.tess.indices.buffer.slice(..),
                    wgpu::IndexFormat::Uint32,
                );
                for (s, g) in tess_bgs.iter().enumerate() {
                    if let Some(g) = g {
                        p.set_bind_group(1, &g.draw, &[]);
                        p.draw_indexed_indirect(
                            &self.tess.counters.buffer,
                            (tessellate::ARGS_BASE + tessellate::ARGS_STRIDE * s as u64) * 4,
                        );
                    }
                }
            }
        }
        let color = |load| {
            [Some(wgpu::RenderPassColorAttachment {
                view: &self.targets.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })]
        };
        let depth = |ops: Option<wgpu::Operations<f32>>| {
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.targets.depth_view,
                depth_ops: ops,
                stencil_ops: None,
            })
        };
        let keep = Some(wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        });
        {
            let attachments = color(wgpu::LoadOp::Clear(wgpu::Color::BLACK));
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[pass::OPAQUE].name),
                color_attachments: &attachments,
                depth_stencil_attachment: depth(Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                })),
                timestamp_writes: render_ts(pass::OPAQUE),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if !draws.is_empty() {
                p.set_pipeline(&self.mesh_pipeline);
                p.set_bind_group(0, &frame_bg, &[]);
                p.set_vertex_buffer(1, self.instance_buffer.buffer.slice(..));
                for (mesh, range) in &draws {
                    let m = &self.meshes[*mesh as usize];
                    set_mesh(&mut p, m);
                    p.draw_indexed(0..m.index_count, 0, range.clone());
                }
            }
        }
        {
            let attachments = color(wgpu::LoadOp::Load);
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[pass::SNOW].name),
                color_attachments: &attachments,
                depth_stencil_attachment: depth(keep),
                // The pass's time spans this render pass and the tessellated one after it.
                timestamp_writes: ts.map(|t| wgpu::RenderPassTimestampWrites {
                    query_set: &t.set,
                    beginning_of_pass_write_index: Some(2 * pass::SNOW as u32),
                    end_of_pass_write_index: None,
                }),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_bind_group(0, &frame_bg, &[]);
            for (pipeline, offset) in [
                (&self.basic_pipeline, STATE_BASIC_DRAW),
                (&self.deformable_pipeline, STATE_DEFORMABLE_DRAW),
            ] {
                p.set_pipeline(pipeline);
                for (s, bg) in surface_bgs.iter().enumerate() {
                    if tessellated[s] {
                        continue;
                    }
                    p.set_bind_group(1, bg, &[]);
                    p.draw_indirect(
                        &self.state_buffer.buffer,
                        (s as u64 * STATE_WORDS + offset) * 4,
                    );
                }
            }
        }
        {
            let attachments = color(wgpu::LoadOp::Load);
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("snow (tessellated)"),
                color_attachments: &attachments,
                depth_stencil_attachment: depth(keep),
                timestamp_writes: ts.map(|t| wgpu::RenderPassTimestampWrites {
                    query_set: &t.set,
                    beginning_of_pass_write_index: None,
                    end_of_pass_write_index: Some(2 * pass::SNOW as u32 + 1),
                }),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if tess_bgs.iter().any(Option::is_some) {
                p.set_pipeline(&self.tess.draw);
                p.set_bind_group(0, &frame_bg, &[]);
                p.set_vertex_buffer(0, self.tess.vertices.buffer.slice(..));
                p.set_index_buffer(
                    self.tess.indices.buffer.slice(..),
                    wgpu::IndexFormat::Uint32,
                );
                for (s, g) in tess_bgs.iter().enumerate() {
                    if let Some(g) = g {
                        p.set_bind_group(1, &g.draw, &[]);
                        p.draw_indexed_indirect(
                            &self.tess.counters.buffer,
                            (tessellate::ARGS_BASE + tessellate::ARGS_STRIDE * s as u64) * 4,
                        );
                    }
                }
            }
        }
        {
            let attachments = color(wgpu::LoadOp::Load);
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[pass::SKY].name),
                color_attachments: &attachments,
                depth_stencil_attachment: depth(None),
                timestamp_writes: render_ts(pass::SKY),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_pipeline(&self.sky_pipeline);
            p.set_bind_group(0, &frame_bg, &[]);
            p.draw(0..3, 0..1);
        }
        {
            let attachments = color(wgpu::LoadOp::Load);
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[pass::SNOWFALL].name),
                color_attachments: &attachments,
                depth_stencil_attachment: depth(None),
                timestamp_writes: render_ts(pass::SNOWFALL),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let flakes = uniform.options[3];
            if flakes > 0 {
                p.set_pipeline(&self.snowfall_pipeline);
                p.set_bind_group(0, &frame_bg, &[]);
                p.draw(0..6, 0..flakes);
            }
        }
        {
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[pass::TONEMAP].name),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: render_ts(pass::TONEMAP),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_pipeline(&tonemap);
            p.set_bind_group(0, &frame_bg, &[]);
            p.set_bind_group(1, &tonemap_bg, &[]);
            p.draw(0..3, 0..1);
        }
        Ok(Encoded {
            encoder,
            surfaces: frame.surfaces.iter().map(|(id, _)| *id).collect(),
        })
    }
}
