//! The renderer's settings and errors: tiers, debug views, the material's look, and their checks.

use super::error::{RenderError, RenderResult};
use super::tessellate::{self, DiceSettings};

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
    /// the heightmap, banks and macro waves, drawn into the shadow map ([`crate::reference::tessellate`]).
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
    /// Basic material green; deformable orange, ground brown, transition blue, water cyan.
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
    pub(crate) fn code(self) -> u32 {
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
    pub(crate) fn switch_bits(&self) -> u32 {
        u32::from(!self.sky_tint) | (u32::from(!self.rnm) << 1)
    }
}

/// How the opaque meshes reach the scene's colour.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum OpaquePath {
    /// Rasterised and shaded per fragment (`opaque/mesh.wgsl`): the goldens' path.
    #[default]
    Forward,
    /// Rasterised into a visibility buffer (depth, and each pixel's instance, triangle and depth
    /// in an `Rgba32Uint` target), then, after the snow, shaded by a compute pass that finds the
    /// triangle again where the snow left it visible and shades it with the forward path's own
    /// function (`opaque/shade.wgsl`).
    Visibility,
}

impl OpaquePath {
    /// Lower-case name (`forward`, `visibility`).
    pub fn name(self) -> &'static str {
        match self {
            OpaquePath::Forward => "forward",
            OpaquePath::Visibility => "visibility",
        }
    }
}

impl std::str::FromStr for OpaquePath {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "forward" => Ok(OpaquePath::Forward),
            "visibility" | "vis" => Ok(OpaquePath::Visibility),
            _ => Err(format!(
                "unknown opaque path {s:?}; use forward or visibility"
            )),
        }
    }
}

/// Settings of a [`Renderer`](super::Renderer).
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
    /// Bits of the shadow map's depth: 32 (`Depth32Float`, the default) or 16 (`Depth16Unorm`:
    /// half the bytes to clear and write; on the H100 at 1080p the shadow pass takes 1.9 ms
    /// instead of 3.1, `docs/PERFORMANCE.md`). Fixed when the renderer is made.
    pub shadow_depth_bits: u32,
    /// Whether each shadow cascade keeps the depth of its still casters ([`Instance::still`](super::Instance::still))
    /// while they and the cascade hold still, and copies it in each frame instead of clearing the
    /// cascade and drawing them again (the default; the pictures are the same either way).
    pub shadow_cache: bool,
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
    /// How opaque meshes are drawn: forward (the default) or through a visibility buffer.
    pub opaque: OpaquePath,
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
            shadow_depth_bits: 32,
            shadow_cache: true,
            snowflakes: 6000,
            debug_view: DebugView::Shaded,
            search: None,
            look: SnowLook::default(),
            dice: DiceSettings::default(),
            opaque: OpaquePath::Forward,
        }
    }

    /// Side of the moon's shadow map, texels, that gives a texel no larger than a pixel of this
    /// configuration's scene (its height times the supersampling) where the near cascade is
    /// focused, for a camera of `fov_y_degrees`: a multiple of 256 from 512 to 8192. A larger map
    /// spends fill and memory on detail the view cannot show (on the H100, at 1080p and 50
    /// degrees, 4096 texels cost 5.5 ms a frame where the 3072 this gives cost 3.1 ms).
    pub fn shadow_map_size_for_view(&self, fov_y_degrees: f32) -> u32 {
        super::cascades::shadow_map_size_for_view(fov_y_degrees, self.height * self.supersample)
    }

    /// The shadow map's depth format ([`Self::shadow_depth_bits`]).
    pub(crate) fn shadow_depth_format(&self) -> wgpu::TextureFormat {
        if self.shadow_depth_bits == 16 {
            wgpu::TextureFormat::Depth16Unorm
        } else {
            wgpu::TextureFormat::Depth32Float
        }
    }

    /// The search in use.
    pub fn search_settings(&self) -> SearchSettings {
        self.search
            .unwrap_or_else(|| SearchSettings::for_tier(self.tier))
    }

    pub(crate) fn validate(&self, device: &wgpu::Device) -> RenderResult<()> {
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
        if !matches!(self.shadow_depth_bits, 16 | 32) {
            return bad(
                "shadow_depth_bits",
                self.shadow_depth_bits.to_string(),
                "16 or 32",
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
