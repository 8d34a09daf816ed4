//! What the plan decides of one surface on its own: how its analytic deformers reach the update
//! ([`Way`]), the rectangle they may press, its replenishment, and whether a deformer of its list
//! is refused.

use glam::{Vec2, Vec3};

use super::{PlanMeshes, PlanSettings};
use crate::capture::{self, CaptureMode, CapturePlan, CaptureVolume};
use crate::deformer::{Deformer, Shape};
use crate::pool::{MODE_GROUND, MODE_MESHES};
use crate::relax::Rect;
use crate::surface::SurfaceLayout;

/// The texels a surface (of half sides `half_size`) that its primitives (in its local frame) can
/// press, with a margin for the capture's blur.
pub(super) fn pressed_rect(
    prims: &[capture::GpuPrimitive],
    half_size: Vec2,
    layout: SurfaceLayout,
) -> Rect {
    const BLUR_MARGIN: f32 = 3.0;
    let (w, h) = (layout.width, layout.height);
    let texel = half_size * 2.0 / Vec2::new(w as f32, h as f32);
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for p in prims {
        let (a, b, r) = if p.kind[0] == capture::PRIM_BOX {
            let c = Vec2::new(p.p0[0], p.p0[2]);
            let r = Vec3::new(p.p1[3], p.p2[3], p.p3[3]).length();
            (c, c, r)
        } else {
            (
                Vec2::new(p.p0[0], p.p0[2]),
                Vec2::new(p.p1[0], p.p1[2]),
                p.p0[3],
            )
        };
        lo = lo.min(a.min(b) - r);
        hi = hi.max(a.max(b) + r);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Rect::default();
    }
    let to_texel = |v: Vec2| (v + half_size) / texel;
    let (a, b) = (to_texel(lo) - BLUR_MARGIN, to_texel(hi) + BLUR_MARGIN);
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
    Rect {
        x0: clamp(a.x.floor(), w),
        y0: clamp(a.y.floor(), h),
        x1: clamp(b.x.ceil(), w),
        y1: clamp(b.y.ceil(), h),
    }
}

/// Whether the world refuses a deformer: invalid, or a mesh not registered.
pub(super) fn refused(d: &Deformer, meshes: &impl PlanMeshes) -> bool {
    d.validate_named(String::new).is_err()
        || matches!(d.shape, Shape::Mesh(id) if meshes.radius(id).is_none())
}

/// How a surface's analytic deformers reach the update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Way {
    /// Rendered in its viewport of the atlas (and so are its meshes).
    Raster,
    /// Ray-cast into the capture by the compute path.
    Compute,
    /// Ray-cast by the fused update itself ([`capture::CapturePath::Update`]).
    Cast,
}

/// How a surface with `prims` primitives (and mesh draws when `meshes`) is captured: rendered when
/// meshes press it, when it has no primitives or more than the compute path takes, or when the
/// world asks for the raster path; cast by the update when the world asks for that, the update is
/// fused, no spray reads the capture and it has few enough; else the compute path.
pub(super) fn way(settings: &PlanSettings, prims: u32, meshes: bool) -> Way {
    use capture::CapturePath;
    if settings.capture_path == CapturePath::Raster
        || meshes
        || prims == 0
        || prims > capture::COMPUTE_PRIMS_MAX
    {
        return Way::Raster;
    }
    if settings.casts() && prims <= capture::CAST_PRIMS_MAX {
        return Way::Cast;
    }
    Way::Compute
}

/// A surface record's `mode` bits: the capture mode, and whether meshes press it
/// ([`MODE_MESHES`]) on ground that is not flat ([`MODE_GROUND`]).
pub(super) fn record_mode(capture: CaptureMode, meshes: bool, ground: bool) -> u32 {
    let mode = match capture {
        CaptureMode::Depth => 0,
        CaptureMode::Mask => 1,
    };
    match (meshes, ground) {
        (false, _) => mode,
        (true, false) => mode | MODE_MESHES,
        (true, true) => mode | MODE_MESHES | MODE_GROUND,
    }
}

/// Add a surface's replenishment over `elapsed` seconds to its carry: `(new carry, whole units
/// refilled now)`, units of `1 / channel_max` of the snow depth.
pub fn replenish(carry: f64, rate: f32, elapsed: f32, channel_max: u32) -> (f64, u32) {
    let carry = carry + rate as f64 * elapsed as f64 * channel_max as f64;
    let units = carry.floor().min(u32::MAX as f64);
    (carry - units, units as u32)
}

impl CapturePlan {
    /// Append what one deformer draws over `volume`: its primitives, or a registered mesh's draws.
    pub(super) fn push_deformer(
        &mut self,
        d: &Deformer,
        volume: &CaptureVolume,
        meshes: &impl PlanMeshes,
    ) {
        match d.shape {
            Shape::Mesh(id) => {
                if let Some(radius) = meshes.radius(id) {
                    capture::push_mesh_draws(
                        d,
                        id,
                        radius,
                        volume,
                        &mut self.draws,
                        &mut self.draw_meshes,
                    );
                }
            }
            _ => capture::push_primitives(d, volume, &mut self.prims),
        }
    }
}
