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

/// A texel's sliver of margin around a footprint, against rounding: the CPU's texel centres and
/// the GPU's may differ in their last places, never by this much.
const SLIVER: f32 = 1.0 / 64.0;

/// Append to `list` an entry `[record, tile y << 16 | tile x]` for every 16 x 16 tile of the
/// update of a `width` x `height` surface of half sides `half` whose blur reads a texel centre that
/// a footprint of `prims` reaches: its texels and one around them, the apron's included, against
/// the centres of the texels a footprint covers grown by a [`SLIVER`]. `seen` is scratch. The
/// update ([`super::CapturePath::Update`]) tests each listed tile against the footprints again,
/// and ray-casts each texel with those that reach it.
pub fn update_tiles_reached(
    prims: &[GpuPrimitive],
    (width, height): (u32, u32),
    half: glam::Vec2,
    record: u32,
    seen: &mut Vec<bool>,
    list: &mut Vec<[u32; 2]>,
) {
    let (tx, ty) = (width.div_ceil(TILE as u32), height.div_ceil(TILE as u32));
    seen.clear();
    seen.resize((tx * ty) as usize, false);
    let texel = half * 2.0 / glam::Vec2::new(width as f32, height as f32);
    for p in prims {
        let [x0, z0, x1, z1] = footprint(p);
        let Some(columns) = tiles_read(x0, x1, (half.x, texel.x), width, tx) else {
            continue;
        };
        let Some(rows) = tiles_read(z0, z1, (half.y, texel.y), height, ty) else {
            continue;
        };
        push_unseen(record, (columns, rows), tx, seen, list);
    }
}

/// Side of the update's tiles, texels (the shifts in `tiles_read` divide by it).
const TILE: i64 = crate::pool::TILE_SIDE as i64;
const _: () = assert!(TILE == 16);

/// The tiles of a side of `n` texels (`tiles` tiles) whose blur reads the centre of a texel that
/// a footprint from `lo` to `hi` (local metres; the side's half length and texel `(h, t)`)
/// reaches: the texels from the first centre at or past `lo` to the last at or before `hi`, a
/// [`SLIVER`] of margin, within the apron (-1 and `n`); tile `k` reads texels 16 k - 1 to
/// 16 k + 16.
fn tiles_read(
    lo: f32,
    hi: f32,
    (h, t): (f32, f32),
    n: u32,
    tiles: u32,
) -> Option<RangeInclusive<u32>> {
    let b = n as i64 + 2;
    // floor(v) for v clamped to [-n - 2, n + 2], without a libm call.
    let floor = |v: f32| (v.clamp(-b as f32, b as f32) + b as f32) as i64 - b;
    let first = (-floor(-((lo + h) / t - 0.5 - SLIVER))).max(-1);
    let last = floor((hi + h) / t - 0.5 + SLIVER).min(n as i64);
    // Tile k reads texel x where 16 k - 1 <= x <= 16 k + 16 (floor division by shifts).
    let k0 = (-((-first) >> 4) - 1).max(0);
    let k1 = ((last + 1) >> 4).min(tiles as i64 - 1);
    (first <= last && k0 <= k1).then_some(k0 as u32..=k1 as u32)
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
