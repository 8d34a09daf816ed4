//! The tiles a surface's analytic primitives reach, as the CPU lists them: the capture's compute
//! path's work ([`tiles_reached`], tiles of the capture region) and the update's own ray cast
//! ([`update_tiles_reached`], tiles of the update).

use std::ops::RangeInclusive;

use super::{APRON, GpuPrimitive, footprint, region};

/// Append to `work` an entry `[view, tile y << 16 | tile x]` for every 16 x 16 tile of the
/// capture [`region`] of a `width` x `height` surface of half sides `half` that a footprint of
/// `prims` reaches (a texel of margin around each, so that rounding never leaves out a texel the
/// ray cast would hit), and then, when they are few ([`SPARSE_TILES`]), every tile beside one of
/// those: the update reads the capture one texel around the tiles the writes flag, and the compute
/// path writes every texel of the tiles it takes, so that such a region needs no clear. Returns
/// whether it took them (else the region is cleared). `seen` is scratch. The tiles are the
/// region's (its first row and column are the apron), as the compute path's workgroups cover it.
pub fn tiles_reached(
    prims: &[GpuPrimitive],
    (width, height): (u32, u32),
    half: glam::Vec2,
    view: u32,
    seen: &mut Vec<bool>,
    work: &mut Vec<[u32; 2]>,
) -> bool {
    let tile = crate::pool::TILE_SIDE;
    let first = work.len();
    let (rw, rh) = region(width, height);
    let (tx, ty) = (rw.div_ceil(tile), rh.div_ceil(tile));
    seen.clear();
    seen.resize((tx * ty) as usize, false);
    let texel = half * 2.0 / glam::Vec2::new(width as f32, height as f32);
    // The region reaches a texel beyond each side.
    let reach = half + texel * APRON as f32;
    // The region's cell of a local coordinate: the surface's cell, floored, plus the apron. Left
    // of the surface's first texel the floor is -1 or less, which the clamp takes to the region's
    // column 0 whatever it is (and `floor` is a libm call on the baseline x86-64 target).
    let to_cell = |v: f32, h: f32, t: f32, n: u32| {
        let q = (v + h) / t;
        let cell = if q < 0.0 { 0 } else { q as i64 + APRON as i64 };
        cell.clamp(0, n as i64 - 1) as u32
    };
    for p in prims {
        let [x0, z0, x1, z1] = footprint(p);
        if x1 < -reach.x || z1 < -reach.y || x0 > reach.x || z0 > reach.y {
            continue;
        }
        let (c0, c1) = (
            to_cell(x0 - texel.x, half.x, texel.x, rw),
            to_cell(x1 + texel.x, half.x, texel.x, rw),
        );
        let (r0, r1) = (
            to_cell(z0 - texel.y, half.y, texel.y, rh),
            to_cell(z1 + texel.y, half.y, texel.y, rh),
        );
        let tiles = (c0 / tile..=c1 / tile, r0 / tile..=r1 / tile);
        push_unseen(view, tiles, tx, seen, work);
    }
    let reached = work.len();
    for k in first..reached {
        let (c, r) = (work[k][1] & 0xffff, work[k][1] >> 16);
        let beside = (
            c.saturating_sub(1)..=(c + 1).min(tx - 1),
            r.saturating_sub(1)..=(r + 1).min(ty - 1),
        );
        push_unseen(view, beside, tx, seen, work);
    }
    let sparse = (work.len() - reached) as u64 * SPARSE_TILES < (tx * ty) as u64;
    if !sparse {
        work.truncate(reached);
    }
    sparse
}

/// Append to `list` an entry `[record, tile y << 16 | tile x]` for every 16 x 16 tile of the
/// update of a `width` x `height` surface of half sides `half` whose blur may read a texel that a
/// footprint of `prims` reaches: the footprint grown by two texels (the blur's one, and one of
/// margin so that rounding never leaves out a texel the ray cast would hit), clamped to the
/// surface. `seen` is scratch. The update ([`super::CapturePath::Update`]) tests each listed tile against
/// the footprints again, so a tile listed in the margin costs a workgroup and changes nothing.
pub fn update_tiles_reached(
    prims: &[GpuPrimitive],
    (width, height): (u32, u32),
    half: glam::Vec2,
    record: u32,
    seen: &mut Vec<bool>,
    list: &mut Vec<[u32; 2]>,
) {
    let tile = crate::pool::TILE_SIDE;
    let (tx, ty) = (width.div_ceil(tile), height.div_ceil(tile));
    seen.clear();
    seen.resize((tx * ty) as usize, false);
    let texel = half * 2.0 / glam::Vec2::new(width as f32, height as f32);
    let margin = texel * (APRON as f32 + 1.0);
    // The surface's texel of a local coordinate, clamped to the surface (left of its first texel
    // the quotient is negative, which the clamp takes to column 0).
    let to_texel = |v: f32, h: f32, t: f32, n: u32| {
        let q = (v + h) / t;
        if q < 0.0 {
            0
        } else {
            (q as u64).min(n as u64 - 1) as u32
        }
    };
    for p in prims {
        let [x0, z0, x1, z1] = footprint(p);
        let (lo, hi) = (
            glam::Vec2::new(x0, z0) - margin,
            glam::Vec2::new(x1, z1) + margin,
        );
        if hi.x < -half.x || hi.y < -half.y || lo.x > half.x || lo.y > half.y {
            continue;
        }
        let tiles = (
            to_texel(lo.x, half.x, texel.x, width) / tile
                ..=to_texel(hi.x, half.x, texel.x, width) / tile,
            to_texel(lo.y, half.y, texel.y, height) / tile
                ..=to_texel(hi.y, half.y, texel.y, height) / tile,
        );
        push_unseen(record, tiles, tx, seen, list);
    }
}

/// Append `[id, tile y << 16 | tile x]` for each tile of the `(columns, rows)` ranges of a grid
/// `tx` tiles wide that `seen` does not hold yet, marking it.
fn push_unseen(
    id: u32,
    (columns, rows): (RangeInclusive<u32>, RangeInclusive<u32>),
    tx: u32,
    seen: &mut [bool],
    out: &mut Vec<[u32; 2]>,
) {
    for r in rows {
        for c in columns.clone() {
            let i = (r * tx + c) as usize;
            if !seen[i] {
                seen[i] = true;
                out.push([id, (r << 16) | c]);
            }
        }
    }
}

/// A compute region takes the tiles beside its reached ones, instead of being cleared, while they
/// are fewer than its tiles over this: on the H100 a workgroup over a tile costs about nine times
/// a clear of the tile's bytes (`docs/PERFORMANCE.md`, "The capture cleared only where needed").
pub const SPARSE_TILES: u64 = 9;
