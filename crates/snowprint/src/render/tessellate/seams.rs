//! Where one surface's diced snow meets another's (pure, no device).
//!
//! Two meshes diced apart never share their vertices, so where they meet their tops differ by a
//! little (the macro waves and the heightfields are interpolated between different points). The
//! open edges there are **seams**: their skirts close the step, whichever side is higher, and are
//! shaded as the snow's top, not as a cut through it. The edges that are seams:
//!
//! - a terrain window level's hole (the extent of the finer level inside it): its rectangle is
//!   diced with the hole cut out ([`rectangle_triangles`]), so the hole's sides are edges of its
//!   own, with skirts;
//! - the four sides of a finer level inside a coarser level's hole ([`enclosed`]);
//! - a side linked to a surface beside it (`heightfield::sides`).
//!
//! A base triangle carries, for each edge, which of these it can be (`BaseTriangle::ids` w); the
//! dicing pass's parameters say which of the rectangle's sides are seams this frame
//! ([`seam_sides`]).

use glam::{Vec2, Vec3};

use super::BaseTriangle;
use crate::extract::SurfaceView;

/// An edge of the rectangle's side `k` (local -x, +x, -z, +z) is marked `SEAM_SIDE + k`.
pub(crate) const SEAM_SIDE: u32 = crate::wgsl::consts::SEAM_SIDE;
/// An edge of the hole is marked this.
pub(crate) const SEAM_HOLE: u32 = crate::wgsl::consts::SEAM_HOLE;
/// Bit of the first edge's mark in `BaseTriangle::ids` w (four bits an edge).
pub(crate) const SEAM_SHIFT: u32 = crate::wgsl::consts::SEAM_SHIFT;

/// Hole lines nearer than this to a line of the rectangle's cells replace it (no sliver cells),
/// metres.
const SNAP: f32 = 1e-3;

/// The base triangles of a surface's rectangle of half sides `half` with `hole` (local
/// `(x0, z0, x1, z1)`, clipped to the rectangle) cut out: [`super::SurfaceMesh::rectangle`]'s cells, cut
/// again along the hole's lines, less the cells inside it. Every border edge is marked with the
/// side it lies on, or as the hole's.
pub(crate) fn rectangle_triangles(half: Vec2, hole: Option<[f32; 4]>) -> Vec<BaseTriangle> {
    let (mut xs, mut zs) = super::rectangle_lines(half);
    let cut = hole.and_then(|h| {
        let lo = Vec2::new(h[0].max(-half.x), h[1].max(-half.y));
        let hi = Vec2::new(h[2].min(half.x), h[3].min(half.y));
        (lo.x < hi.x && lo.y < hi.y).then_some((lo, hi))
    });
    if let Some((lo, hi)) = cut {
        xs = with_lines(&xs, [lo.x, hi.x]);
        zs = with_lines(&zs, [lo.y, hi.y]);
    }
    let (nx, nz) = (xs.len() as u32 - 1, zs.len() as u32 - 1);
    let id = |c: u32, r: u32| r * (nx + 1) + c;
    let at = |c: u32, r: u32| Vec3::new(xs[c as usize], 0.0, zs[r as usize]);
    let inside = |c: u32, r: u32| {
        cut.is_some_and(|(lo, hi)| {
            let m = 0.5 * (at(c, r) + at(c + 1, r + 1));
            m.x > lo.x && m.x < hi.x && m.z > lo.y && m.z < hi.y
        })
    };
    // Which side or hole an edge between grid points lies on, when it is a border.
    let mark = |a: (u32, u32), b: (u32, u32)| -> u32 {
        let side = if a.0 == b.0 && a.0 == 0 {
            0
        } else if a.0 == b.0 && a.0 == nx {
            1
        } else if a.1 == b.1 && a.1 == 0 {
            2
        } else if a.1 == b.1 && a.1 == nz {
            3
        } else {
            return SEAM_HOLE;
        };
        SEAM_SIDE + side
    };
    // A cell's edge is a border where the cell beside it is missing (past the rectangle, or in
    // the hole): known from the grid, without counting the edges' uses.
    let kept = |c: i64, r: i64| {
        (0..nx as i64).contains(&c) && (0..nz as i64).contains(&r) && !inside(c as u32, r as u32)
    };
    let corner = |(c, r): (u32, u32)| {
        let p = at(c, r);
        [p.x, p.y, p.z, 0.0]
    };
    let mut base = Vec::new();
    for r in 0..nz {
        for c in 0..nx {
            if inside(c, r) {
                continue;
            }
            let (ci, ri) = (c as i64, r as i64);
            // As SurfaceMesh::rectangle: counter-clockwise seen from above; each triangle's
            // edges in order, with the cell beside each (none beside the diagonal).
            let cells: [(Corners, Beside); 2] = [
                (
                    [(c, r), (c, r + 1), (c + 1, r + 1)],
                    [Some((ci - 1, ri)), Some((ci, ri + 1)), None],
                ),
                (
                    [(c, r), (c + 1, r + 1), (c + 1, r)],
                    [None, Some((ci + 1, ri)), Some((ci, ri - 1))],
                ),
            ];
            for (t, beside) in cells {
                let mut w = 0;
                for e in 0..3 {
                    if beside[e].is_some_and(|(c, r)| !kept(c, r)) {
                        w |= 1 << e | mark(t[e], t[(e + 1) % 3]) << (SEAM_SHIFT + 4 * e as u32);
                    }
                }
                let [a, b, c] = t;
                base.push(BaseTriangle {
                    a: corner(a),
                    b: corner(b),
                    c: corner(c),
                    ids: [id(a.0, a.1), id(b.0, b.1), id(c.0, c.1), w],
                });
            }
        }
    }
    base
}

/// A triangle's corners as grid points (column, row).
type Corners = [(u32, u32); 3];
/// The cell beside each of a triangle's edges (none beside the cell's diagonal).
type Beside = [Option<(i64, i64)>; 3];

/// `lines` (sorted, the rectangle's first and last included) with `extra` added: an inner line
/// within [`SNAP`] of one of `extra` gives way to it; one of `extra` within [`SNAP`] of the first
/// or last line is that line.
fn with_lines(lines: &[f32], extra: [f32; 2]) -> Vec<f32> {
    let (first, last) = (lines[0], lines[lines.len() - 1]);
    let extra: Vec<f32> = extra
        .into_iter()
        .filter(|&e| e - first > SNAP && last - e > SNAP)
        .collect();
    let mut out: Vec<f32> = lines
        .iter()
        .copied()
        .filter(|&l| l == first || l == last || extra.iter().all(|&e| (l - e).abs() > SNAP))
        .chain(extra.iter().copied())
        .collect();
    out.sort_by(f32::total_cmp);
    out
}

/// Whether `inner` lies in a hole of one of `drawn`: a coarser level of its terrain window drawn
/// around it (the same yaw; the hole within a texel of `inner`'s rectangle).
pub(crate) fn enclosed(inner: &SurfaceView<'_>, drawn: &[&SurfaceView<'_>]) -> bool {
    let d = inner.desc;
    let texel = d.size.x / inner.layout.width as f32;
    drawn.iter().any(|outer| {
        let Some(h) = outer.hole else {
            return false;
        };
        if outer.id == inner.id || outer.desc.yaw_degrees != d.yaw_degrees {
            return false;
        }
        let c = outer.desc.world_to_local().transform_point3(d.center);
        let c = Vec2::new(c.x, c.z);
        let (lo, hi) = (c - 0.5 * d.size, c + 0.5 * d.size);
        [lo.x, lo.y, hi.x, hi.y]
            .iter()
            .zip(h)
            .all(|(e, h)| (e - h).abs() <= texel)
    })
}

/// The sides (bits 0-3: local -x, +x, -z, +z) whose skirts are seams this frame: every side of
/// a level inside a coarser one, and each side linked to a surface beside it.
pub(crate) fn seam_sides(enclosed: bool, linked: [bool; 4]) -> u32 {
    if enclosed {
        return 0b1111;
    }
    (0..4).filter(|&k| linked[k]).map(|k| 1 << k).sum()
}

#[cfg(test)]
mod tests;
