//! CPU reference of the ground rasterisation: the vertical line through each texel centre against
//! every triangle, by barycentric coordinates (not by the rasteriser's edge functions), the highest
//! crossing kept.

use glam::{Mat4, Vec2, Vec3, Vec3Swizzles};

use crate::surface::SurfaceLayout;

/// Height of triangle `t` (local metres) over local `(x, z)`, or `None` where it does not lie over
/// the point (or is seen edge-on).
pub fn height_over(t: &[Vec3; 3], x: f32, z: f32) -> Option<f32> {
    let [a, b, c] = *t;
    let p = Vec2::new(x, z);
    let (a2, b2, c2) = (a.xz(), b.xz(), c.xz());
    let area = (b2 - a2).perp_dot(c2 - a2);
    if area.abs() < 1e-12 {
        return None;
    }
    let wa = (b2 - p).perp_dot(c2 - p) / area;
    let wb = (c2 - p).perp_dot(a2 - p) / area;
    let wc = 1.0 - wa - wb;
    // A centre on an edge shared by two faces is over both: let rounding not drop it from either.
    const EDGE: f32 = -1e-5;
    if wa < EDGE || wb < EDGE || wc < EDGE {
        return None;
    }
    Some(wa * a.y + wb * b.y + wc * c.y)
}

/// Reference of [`super::raster::GroundRaster::rasterise`]: world-space `triangles` over the texel centres
/// of a surface (`world_to_local`, sides `size`, `layout`), the highest face at each, row-major.
pub fn rasterise(
    triangles: &[[Vec3; 3]],
    world_to_local: Mat4,
    size: Vec2,
    layout: SurfaceLayout,
) -> Vec<Option<f32>> {
    let local: Vec<[Vec3; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| world_to_local.transform_point3(v)))
        .collect();
    let (w, h) = (layout.width, layout.height);
    let mut out = Vec::with_capacity((w * h) as usize);
    for r in 0..h {
        for c in 0..w {
            let x = -0.5 * size.x + (c as f32 + 0.5) / w as f32 * size.x;
            let z = -0.5 * size.y + (r as f32 + 0.5) / h as f32 * size.y;
            let best = local
                .iter()
                .filter_map(|t| height_over(t, x, z))
                .fold(None, |m: Option<f32>, y| Some(m.map_or(y, |m| m.max(y))));
            out.push(best);
        }
    }
    out
}
