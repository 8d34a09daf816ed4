//! What a frame reports: pass times, each surface's material, the dicing's overflow.

use crate::surface::SurfaceId;

/// GPU time of one pass.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PassTime {
    /// The pass's name in [`PASSES`](super::PASSES).
    pub name: &'static str,
    /// Milliseconds.
    pub gpu_ms: f64,
}

/// CPU time of one step of building a frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CpuPhase {
    /// In order: `surfaces` (the frame's surfaces, shadow cascades and uniform); the tables and
    /// bind groups of `classify`, `heightfield`, `snow`, `dice`, `banks`, `tess_surface` (the
    /// tessellated snow's draws), `meshes` (instances culled and uploaded for the shadow and
    /// opaque passes) and `opaque_tonemap`; `record` (every pass's commands); and for
    /// [`Renderer::render`](super::Renderer::render), `finish` (the command encoder finished:
    /// wgpu validates and encodes the recorded passes there) and `submit`.
    pub name: &'static str,
    /// Milliseconds.
    pub ms: f64,
}

/// Which snow material a surface was drawn with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SnowMaterialKind {
    /// The basic material: nothing has pressed the surface, and it lies on flat ground.
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
    /// GPU time per pass, in [`PASSES`](super::PASSES) order; empty when the adapter has no timestamp queries.
    pub pass_times: Vec<PassTime>,
    /// Each surface drawn and its material.
    pub surfaces: Vec<SurfaceShading>,
    /// Base triangles the dicing pass dropped for want of room
    /// ([`DiceSettings::max_triangles`](super::DiceSettings::max_triangles)); 0 when everything fit.
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
    /// CPU time to build the frame and submit it (every pass's tables written and its commands
    /// recorded), milliseconds: what a frame costs the CPU when nothing is read back.
    pub cpu_encode_ms: f64,
    /// Where `cpu_encode_ms` went, step by step, in order.
    pub cpu_phases: Vec<CpuPhase>,
    /// Instances of the frame outside the view's frustum, not drawn by the opaque pass (shadow
    /// casters among them still cast).
    pub culled_instances: usize,
    /// The moon's shadow cascades this frame: casters drawn and texel sizes.
    pub shadow: ShadowStats,
}

/// What the moon's two shadow cascades held in a frame, and the density the view asked of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ShadowStats {
    /// Shadow casters drawn into the near and the far cascade (those whose bounds reach its box).
    pub casters: [usize; 2],
    /// Whether each cascade's still casters came from its cache (copied in or restored, not
    /// drawn).
    pub from_cache: [bool; 2],
    /// Texels of each cascade restored from its cache (where the frame before's moving casters
    /// and displaced snow drew; overlaps counted twice).
    pub restored_texels: [u64; 2],
    /// Side of a texel of the near and the far cascade, metres.
    pub texel_m: [f32; 2],
    /// Side of a pixel of the scene (supersampled) at the near cascade's focus, metres: the
    /// texel the view would need there for one texel a pixel.
    pub view_pixel_m: f32,
}

/// CPU steps of a frame, each timed from the end of the one before.
pub(super) struct Laps {
    pub phases: Vec<CpuPhase>,
    last: std::time::Instant,
}

impl Laps {
    pub(super) fn start() -> Self {
        Self {
            phases: Vec::with_capacity(12),
            last: std::time::Instant::now(),
        }
    }

    pub(super) fn mark(&mut self, name: &'static str) {
        let now = std::time::Instant::now();
        self.phases.push(CpuPhase {
            name,
            ms: (now - self.last).as_secs_f64() * 1e3,
        });
        self.last = now;
    }
}
