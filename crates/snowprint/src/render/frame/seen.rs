//! Which of a frame's surfaces anything of the frame can show (pure, no device): the work that
//! only feeds their pictures (the heightfield and bank passes, the dicing) is skipped for the
//! others.
//!
//! A surface is seen when its box (its rectangle, from the lowest base of its snow to the highest
//! its snow, rims, banks and waves can rise) is not wholly outside the camera's frustum, or, in
//! the tessellated tier, outside the moon's near shadow cascade (its diced snow shadows what is in
//! view; the dicing culls by the same two). A surface linked to one beside it is always seen: the
//! bank passes of the two read across the line. The test is conservative: all eight corners
//! outside one plane of the frustum, in homogeneous clip space (exact for corners behind the eye).

use glam::{Mat4, Vec3, Vec4};

use super::FrameSurface;

/// Mark each surface's `seen` for a frame drawn with `view_proj`, and with `shadow_near` (the
/// moon's near cascade) when the frame dices its snow.
pub(in crate::render) fn mark_seen(
    surfaces: &mut [FrameSurface<'_>],
    view_proj: Mat4,
    shadow_near: Option<Mat4>,
) {
    for s in surfaces {
        let corners = box_corners(s);
        let in_view = !outside(view_proj, &corners);
        let in_shadow = shadow_near.is_some_and(|m| !outside(m, &corners));
        s.seen = in_view || in_shadow || s.sides.iter().any(Option::is_some);
    }
}

/// The corners of a surface's box, world metres.
fn box_corners(s: &FrameSurface<'_>) -> [Vec3; 8] {
    let desc = s.view.desc;
    let (low, high) = s.view.ground_range;
    let depth = desc.snow_depth;
    let rims = crate::render::gpu::rim_room(&desc.material, depth);
    // As the snow pass's bound of the diced snow's rise (`tessellated_rise`), with the rims'.
    let top = high + depth + rims + depth + 0.1 * s.geometry.macro_waves.abs();
    let half = desc.size * 0.5;
    let to_world = desc.local_to_world();
    std::array::from_fn(|k| {
        let corner = Vec3::new(
            if k & 1 == 0 { -half.x } else { half.x },
            if k & 2 == 0 { low } else { top },
            if k & 4 == 0 { -half.y } else { half.y },
        );
        to_world.transform_point3(corner)
    })
}

/// Whether every corner lies outside one plane of the clip volume of `m` (`-w <= x, y <= w`,
/// `0 <= z <= w`).
fn outside(m: Mat4, corners: &[Vec3; 8]) -> bool {
    let clip: [Vec4; 8] = corners.map(|c| m * c.extend(1.0));
    let planes: [fn(Vec4) -> bool; 6] = [
        |c| c.x < -c.w,
        |c| c.x > c.w,
        |c| c.y < -c.w,
        |c| c.y > c.w,
        |c| c.z < 0.0,
        |c| c.z > c.w,
    ];
    planes.iter().any(|out| clip.iter().all(|&c| out(c)))
}

#[cfg(test)]
mod tests;
