//! The probe pass on the CPU: where a point falls on a surface, and the sample `probe.wgsl` reads
//! there, from a heightmap's channels as stored. The manager answers probes over paged-out
//! surfaces with it, and the tests hold the GPU pass to it.

use glam::{Vec2, Vec3};

use super::{GROUND_SLACK, PointInfo, ProbeQuery, ProbeSample, decode_over};
use crate::ground::GroundField;
use crate::pool::Precision;
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

/// Whether a point is over a surface: inside its rectangle and not below its ground (1 cm of
/// slack): the surface's centre height, or on a ground field its ground under the point's texel.
/// Returns that ground height.
pub(crate) fn over_on(desc: &SurfaceDesc, field: Option<&GroundField>, point: Vec3) -> Option<f32> {
    let ground = match field {
        None => desc.center.y,
        Some(f) => {
            let layout = SurfaceLayout {
                width: f.width,
                height: f.height,
            };
            let ([c, r], _) = texel_under(desc, &layout, point);
            desc.center.y + f.ground[(r * f.width + c) as usize]
        }
    };
    if ground > point.y + GROUND_SLACK {
        return None;
    }
    let local = desc.world_to_local().transform_point3(point);
    let half = desc.size * 0.5;
    Vec2::new(local.x, local.z)
        .abs()
        .cmple(half)
        .all()
        .then_some(ground)
}

/// [`over_on`], and not in `hole` (local `(x0, z0, x1, z1)`: a coarser terrain window level
/// leaves the finer one's extent to it, which answers there).
pub(crate) fn over_outside_hole(
    desc: &SurfaceDesc,
    field: Option<&GroundField>,
    hole: Option<[f32; 4]>,
    point: Vec3,
) -> Option<f32> {
    let ground = over_on(desc, field, point)?;
    let in_hole = hole.is_some_and(|h| {
        let local = desc.world_to_local().transform_point3(point);
        local.x >= h[0] && local.z >= h[1] && local.x < h[2] && local.z < h[3]
    });
    (!in_hole).then_some(ground)
}

/// The texel under a point over a surface (clamped to the heightmap) and the texel's sides,
/// metres.
pub(crate) fn texel_under(
    desc: &SurfaceDesc,
    layout: &SurfaceLayout,
    point: Vec3,
) -> ([u32; 2], Vec2) {
    let local = desc.world_to_local().transform_point3(point);
    let half = desc.size * 0.5;
    let (w, h) = (layout.width, layout.height);
    let texel = desc.size / Vec2::new(w as f32, h as f32);
    let column = (((local.x + half.x) / texel.x).floor() as i64).clamp(0, w as i64 - 1);
    let row = (((local.z + half.y) / texel.y).floor() as i64).clamp(0, h as i64 - 1);
    ([column as u32, row as u32], texel)
}

/// What the probe pass needs of a point over a surface whose heights start at `base` (a word of
/// the pool), and what decodes its result.
#[allow(clippy::too_many_arguments)]
pub(super) fn query(
    desc: &SurfaceDesc,
    layout: &SurfaceLayout,
    precision: Precision,
    base: u32,
    surface: Option<SurfaceId>,
    field: Option<&GroundField>,
    point: Vec3,
) -> (ProbeQuery, PointInfo) {
    let ([column, row], texel) = texel_under(desc, layout, point);
    let (bare, base_slope) =
        field.map_or((0.0, Vec2::ZERO), |f| ground_under(f, column, row, texel));
    let query = ProbeQuery {
        base,
        width: layout.width,
        height: layout.height,
        texel: column | row << 16,
        bits: precision.bits(),
        texel_x: texel.x,
        texel_z: texel.y,
        snow_depth: desc.snow_depth,
        wrap: 0,
    };
    let info = PointInfo {
        point,
        surface,
        snow_depth: desc.snow_depth,
        rotation: desc.rotation(),
        channel_max: precision.channel_max() as f64,
        bare,
        base_slope,
    };
    (query, info)
}

/// The sample `probe.wgsl` gives for a point over a surface whose channels (depression, then
/// displaced, row-major, at `precision`) are given: the same texel, the same central differences,
/// in the same f32 arithmetic. `surface` is what the sample names; `field` the surface's ground.
pub(crate) fn sample(
    desc: &SurfaceDesc,
    layout: &SurfaceLayout,
    precision: Precision,
    channels: (&[u32], &[u32]),
    (surface, field): (Option<SurfaceId>, Option<&GroundField>),
    point: Vec3,
) -> ProbeSample {
    let (q, info) = query(desc, layout, precision, 0, surface, field, point);
    let (w, h) = (q.width, q.height);
    let (x, y) = (q.texel & 0xffff, q.texel >> 16);
    let at = |x: u32, y: u32| (y * w + x) as usize;
    let max = precision.channel_max() as f32;
    let top = |x: u32, y: u32| q.snow_depth * (1.0 - channels.0[at(x, y)] as f32 / max);
    let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
    let dx = if x1 > x0 {
        (top(x1, y) - top(x0, y)) / ((x1 - x0) as f32 * q.texel_x)
    } else {
        0.0
    };
    let dz = if y1 > y0 {
        (top(x, y1) - top(x, y0)) / ((y1 - y0) as f32 * q.texel_z)
    } else {
        0.0
    };
    let raw = [
        channels.0[at(x, y)],
        channels.1[at(x, y)],
        dx.to_bits(),
        dz.to_bits(),
    ];
    decode_over(&info, raw)
}

/// The bare depth of texel `(x, y)` of a ground field and the slope of its column's base, by the
/// probe's own central differences (one-sided at the edges).
fn ground_under(f: &GroundField, x: u32, y: u32, texel: Vec2) -> (f32, Vec2) {
    let (w, h) = (f.width, f.height);
    let base = |x: u32, y: u32| f.columns[(y * w + x) as usize][0];
    let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
    let dx = if x1 > x0 {
        (base(x1, y) - base(x0, y)) / ((x1 - x0) as f32 * texel.x)
    } else {
        0.0
    };
    let dz = if y1 > y0 {
        (base(x, y1) - base(x, y0)) / ((y1 - y0) as f32 * texel.y)
    } else {
        0.0
    };
    (f.columns[(y * w + x) as usize][1], Vec2::new(dx, dz))
}

/// The sample over a surface that never held a heightmap: untouched snow, its normal the
/// surface's up.
pub(crate) fn untouched(desc: &SurfaceDesc, point: Vec3) -> ProbeSample {
    ProbeSample {
        point,
        surface: None,
        snow_depth_m: desc.snow_depth,
        depression_m: 0.0,
        displaced_m: 0.0,
        normal: desc.rotation() * Vec3::Y,
    }
}

/// [`untouched`] on a surface that may lie on a ground field: what the probe pass reads over
/// texels that were never pressed (the ground's bare depth and slope included).
pub(crate) fn untouched_on(
    desc: &SurfaceDesc,
    field: Option<&GroundField>,
    point: Vec3,
) -> ProbeSample {
    let Some(f) = field else {
        return untouched(desc, point);
    };
    let layout = SurfaceLayout {
        width: f.width,
        height: f.height,
    };
    // The channels' maximum does not matter: both are 0.
    let (_, info) = query(desc, &layout, Precision::Bits16, 0, None, field, point);
    decode_over(&info, [0, 0, 0f32.to_bits(), 0f32.to_bits()])
}

/// The sample of a point over no surface.
pub(crate) fn outside(point: Vec3) -> ProbeSample {
    ProbeSample::outside(point)
}
