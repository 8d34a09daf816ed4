//! Which surface lies beside each side of a surface, texel row for texel row (pure, no device).
//!
//! Two surfaces laid side by side on one texel grid (a terrain window's level and a roof or a
//! deck reached from it) are drawn as one surface over both would be: the heightfield pass reads
//! the texels beyond a surface's edge from the surface beside it, so the normals, the occlusion
//! and the moon's visibility at the line see the print across it, and the shading textures keep a
//! one-texel border holding the neighbour's first column, which every reader's bilinear filter
//! interpolates towards (`heightfield.wgsl`, `surface.wgsl`). Without a neighbour a side's border
//! repeats the edge, which filters exactly as clamping at the edge did.
//!
//! Two surfaces are linked when they have the same yaw, texel sides and snow depth, their snow
//! lies at the same height, one's edge lies on the other's (within a hundredth of a texel), and
//! their texel rows line up (an offset of whole texels). A side takes the surface that shares the
//! longest stretch of it.

use glam::{Vec2, Vec3};

use crate::extract::SurfaceView;

/// The sides of a surface, in the order of `HeightfieldParams::sides`: local -x, +x, -z, +z.
pub(crate) const SIDES: usize = 4;

/// The surface beside a side of a frame's surface.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Beside<'a> {
    /// The surface, as the world's extract gives it.
    pub view: &'a SurfaceView<'a>,
    /// Its texel along the side is this surface's plus `offset`.
    pub offset: i32,
}

/// The surfaces beside each side of each of `of` (ids of surfaces of `all`), among `all`.
pub(crate) fn besides<'a>(
    all: &'a [SurfaceView<'a>],
    of: impl Iterator<Item = crate::surface::SurfaceId>,
) -> Vec<[Option<Beside<'a>>; SIDES]> {
    let of: Vec<usize> = of
        .map(|id| {
            all.binary_search_by_key(&id.index(), |v| v.id.index())
                .unwrap_or(usize::MAX)
        })
        .collect();
    sides(all, &of)
        .into_iter()
        .map(|links| {
            links.map(|side| {
                side.map(|s| Beside {
                    view: &all[s.neighbour],
                    offset: s.offset,
                })
            })
        })
        .collect()
}

/// How far positions and sizes may be off the shared grid, as a fraction of a texel.
const GRID_SLACK: f32 = 0.01;

/// The surface beside one side: where its heights are and how its texels line up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Side {
    /// Index of the neighbour in the slice handed to [`sides`].
    pub neighbour: usize,
    /// The neighbour's texel along the side is this surface's plus `offset` (its row for the
    /// sides across x, its column for the sides across z).
    pub offset: i32,
}

/// Each surface's neighbours on its four sides, among `all` (the world's live surfaces). `of`
/// indexes the surfaces to link into `all` (an index past its end has none). The candidates come
/// from the lines the sides run along ([`Lines`]), so a frame of many surfaces tests only those
/// whose sides could meet, not every pair.
pub(crate) fn sides(all: &[SurfaceView<'_>], of: &[usize]) -> Vec<[Option<Side>; SIDES]> {
    let lines = Lines::new(all);
    of.iter()
        .map(|&a| {
            let mut best: [Option<(Side, i32)>; SIDES] = [None; SIDES];
            let Some(this) = all.get(a) else {
                return [None; SIDES];
            };
            for b in lines.facing(this) {
                if b == a {
                    continue;
                }
                if let Some((side, link, shared)) = beside(this, &all[b], b)
                    && best[side].is_none_or(|(_, s)| shared > s)
                {
                    best[side] = Some((link, shared));
                }
            }
            best.map(|b| b.map(|(link, _)| link))
        })
        .collect()
}

/// Where a surface's sides run: for each, its yaw (thousandths of a degree), which side it is,
/// and the line in the yaw's frame (quarters of a texel), sorted, with the surface's index. Two
/// sides that meet face each other along one line, up to the slack of [`beside`], which the
/// lookups cover by the neighbouring keys.
struct Lines(Vec<((i64, usize, i64), usize)>);

impl Lines {
    fn new(all: &[SurfaceView<'_>]) -> Self {
        let mut keys = Vec::with_capacity(all.len() * SIDES);
        for (i, s) in all.iter().enumerate() {
            let (yaw, lines) = side_lines(s);
            for (k, line) in lines.into_iter().enumerate() {
                keys.push(((yaw, k, line), i));
            }
        }
        keys.sort_unstable();
        Self(keys)
    }

    /// The surfaces with a side facing one of `s`'s along its line, each once.
    fn facing(&self, s: &SurfaceView<'_>) -> Vec<usize> {
        let mut found = Vec::new();
        let (yaw, lines) = side_lines(s);
        for (k, line) in lines.into_iter().enumerate() {
            for dy in -1..=1 {
                let yaw = (yaw + dy).rem_euclid(YAW_STEPS);
                let (lo, hi) = ((yaw, k ^ 1, line - 1), (yaw, k ^ 1, line + 1));
                let first = self.0.partition_point(|(key, _)| *key < lo);
                let last = self.0.partition_point(|(key, _)| *key <= hi);
                found.extend(self.0[first..last].iter().map(|&(_, i)| i));
            }
        }
        found.sort_unstable();
        found.dedup();
        found
    }
}

/// Thousandths of a degree in a turn.
const YAW_STEPS: i64 = 360_000;

/// A surface's yaw key and the lines of its sides -x, +x, -z, +z (see [`Lines`]).
fn side_lines(s: &SurfaceView<'_>) -> (i64, [i64; SIDES]) {
    let yaw = (s.desc.yaw_degrees.rem_euclid(360.0) as f64 * 1000.0).round() as i64 % YAW_STEPS;
    let c = s.desc.rotation().inverse() * s.desc.center;
    let (half, quarter) = (0.5 * s.desc.size, 0.25 * texel(s));
    let line = |at: f32, step: f32| (at / step).round() as i64;
    let lines = [
        line(c.x - half.x, quarter.x),
        line(c.x + half.x, quarter.x),
        line(c.z - half.y, quarter.y),
        line(c.z + half.y, quarter.y),
    ];
    (yaw, lines)
}

/// Texel sides (x, z) of a surface, metres.
fn texel(s: &SurfaceView<'_>) -> Vec2 {
    Vec2::new(
        s.desc.size.x / s.layout.width as f32,
        s.desc.size.y / s.layout.height as f32,
    )
}

/// Whether `b` lies beside a side of `a` on `a`'s grid: the side, the link and how many texels of
/// the side they share.
fn beside(a: &SurfaceView<'_>, b: &SurfaceView<'_>, index: usize) -> Option<(usize, Side, i32)> {
    let (ta, tb) = (texel(a), texel(b));
    let same = |x: f32, y: f32| (x - y).abs() <= 1e-4 * x.abs().max(y.abs());
    let turn = (a.desc.yaw_degrees - b.desc.yaw_degrees).rem_euclid(360.0);
    if !(turn.min(360.0 - turn) <= 1e-3
        && same(ta.x, tb.x)
        && same(ta.y, tb.y)
        && same(a.desc.snow_depth, b.desc.snow_depth))
    {
        return None;
    }
    // b's centre in a's frame, in a's texels.
    let d: Vec3 = a.desc.rotation().inverse() * (b.desc.center - a.desc.center);
    if d.y.abs() > 1e-4 {
        return None;
    }
    let (dx, dz) = (d.x / ta.x, d.z / ta.y);
    let (wa, ha) = (a.layout.width as f32, a.layout.height as f32);
    let (wb, hb) = (b.layout.width as f32, b.layout.height as f32);
    let near = |x: f32, y: f32| (x - y).abs() <= GRID_SLACK;
    let whole = |x: f32| near(x, x.round()).then_some(x.round() as i32);
    // Across x the rows must line up: b's row = a's row + (hb - ha) / 2 - dz.
    let (side, offset, along_a, along_b) = if near(dx.abs(), (wa + wb) / 2.0) {
        (
            usize::from(dx > 0.0),
            whole((hb - ha) / 2.0 - dz)?,
            a.layout.height,
            b.layout.height,
        )
    } else if near(dz.abs(), (ha + hb) / 2.0) {
        (
            2 + usize::from(dz > 0.0),
            whole((wb - wa) / 2.0 - dx)?,
            a.layout.width,
            b.layout.width,
        )
    } else {
        return None;
    };
    // The texels of the side both hold: a's [0, along_a) and b's [-offset, along_b - offset).
    let shared = (along_a as i32).min(along_b as i32 - offset) - 0.max(-offset);
    (shared > 0).then_some((
        side,
        Side {
            neighbour: index,
            offset,
        },
        shared,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extract::SurfaceView;
    use crate::surface::SurfaceDesc;

    fn desc(center: [f32; 2], size: [f32; 2], yaw: f32) -> SurfaceDesc {
        SurfaceDesc {
            yaw_degrees: yaw,
            ..SurfaceDesc::new("s", [center[0], 1.0, center[1]], size, 0.2)
        }
    }

    fn view(desc: &SurfaceDesc, texels: [u32; 2]) -> SurfaceView<'_> {
        SurfaceView::for_test(desc, 0, texels, None)
    }

    #[test]
    fn a_surface_on_the_grid_beside_each_side_is_linked_with_its_row_offset() {
        // a: 64 x 48 texels of 0.04 m centred at the origin, x in [-1.28, 1.28], z in [-0.96, 0.96].
        let a = desc([0.0, 0.0], [2.56, 1.92], 0.0);
        // b: 32 x 16 texels beside +x, its z in [-0.48, 0.16]: its row 0 is a's row 12.
        let b = desc([1.28 + 0.64, -0.16], [1.28, 0.64], 0.0);
        // c: beside -z, 16 texels wide from a's column 60 (x from 1.12 to 1.76), its rows z < -0.96.
        let c = desc([1.44, -0.96 - 0.4], [0.64, 0.8], 0.0);
        // d: beside -x, off the grid by half a texel along z.
        let d = desc([-1.28 - 0.32, 0.02], [0.64, 0.64], 0.0);
        let all = [
            view(&a, [64, 48]),
            view(&b, [32, 16]),
            view(&c, [16, 20]),
            view(&d, [16, 16]),
        ];
        let links = sides(&all, &[0, 1, 2]);
        let link = |neighbour, offset| Some(Side { neighbour, offset });
        assert_eq!(links[0], [None, link(1, -12), link(2, -60), None]);
        // From b, a is on -x: a's row = b's row + 12.
        assert_eq!(links[1], [link(0, 12), None, None, None]);
        // From c, a is on +z: a's column = c's + 60.
        assert_eq!(links[2], [None, None, None, link(0, 60)]);
    }

    #[test]
    fn surfaces_that_differ_in_yaw_texel_depth_height_or_only_touch_a_corner_are_not_linked() {
        let a = desc([0.0, 0.0], [2.56, 1.92], 0.0);
        let turned = desc([1.28 + 0.64, 0.0], [1.28, 1.92], 90.0);
        let coarse = desc([1.28 + 0.64, 0.0], [1.28, 1.92], 0.0);
        let mut deeper = desc([1.28 + 0.64, 0.0], [1.28, 1.92], 0.0);
        deeper.snow_depth = 0.3;
        let mut higher = desc([1.28 + 0.64, 0.0], [1.28, 1.92], 0.0);
        higher.center.y += 0.05;
        let corner = desc([1.28 + 0.64, 0.96 + 0.32], [1.28, 0.64], 0.0);
        let apart = desc([1.28 + 0.64 + 0.04, 0.0], [1.28, 1.92], 0.0);
        let all = [
            view(&a, [64, 48]),
            view(&turned, [32, 48]),
            view(&coarse, [16, 24]),
            view(&deeper, [32, 48]),
            view(&higher, [32, 48]),
            view(&corner, [32, 16]),
            view(&apart, [32, 48]),
        ];
        assert_eq!(sides(&all, &[0]), vec![[None; SIDES]]);
    }

    #[test]
    fn a_yawed_pair_links_in_its_own_frame_and_the_longest_shared_side_wins() {
        // Both turned 30 degrees: b beside a's +z side, in a's frame.
        let a = desc([0.0, 0.0], [1.28, 1.28], 30.0);
        let rot = glam::Quat::from_rotation_y(30f32.to_radians());
        let at = |local: Vec3| {
            let w = rot * local;
            [w.x, w.z]
        };
        let short = desc(at(Vec3::new(0.48, 0.0, 0.64 + 0.16)), [0.32, 0.32], 30.0);
        let long = desc(at(Vec3::new(-0.16, 0.0, 0.64 + 0.32)), [0.96, 0.64], 30.0);
        let all = [
            view(&a, [32, 32]),
            view(&short, [8, 8]),
            view(&long, [24, 16]),
        ];
        // long covers a's x in [-0.64, 0.32]: its column 0 is a's column 0.
        assert_eq!(
            sides(&all, &[0])[0][3],
            Some(Side {
                neighbour: 2,
                offset: 0
            })
        );
    }
}
