//! The pure plan of a window's scroll: where each level's window stands for a focus, and which
//! logical rectangles leave and enter when it moves. No GPU; unit-tested below.
//!
//! A level of `w x h` texels of side `s` covers world texels `[ix, ix + w) x [iz, iz + h)`
//! (texel `(i, j)` is world x in `[i s, (i + 1) s)`, z likewise); its logical texel `(x, y)` is
//! world texel `(ix + x, iz + y)` and is stored at `((ix + x) mod w, (iz + y) mod h)` of its
//! slot, so its toroidal offsets are `(ix mod w, iz mod h)`: a world texel never moves in the
//! pool while it stays in the window, and only the strips that enter are written.

/// A rectangle of a level's logical texels and the world texel of its first one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strip {
    /// First logical column and row.
    pub x0: u32,
    /// See `x0`.
    pub y0: u32,
    /// Columns and rows.
    pub columns: u32,
    /// See `columns`.
    pub rows: u32,
    /// World texel of logical `(x0, y0)`.
    pub world: [i64; 2],
}

impl Strip {
    /// Texels it holds.
    pub fn texels(&self) -> u64 {
        self.columns as u64 * self.rows as u64
    }
}

/// One step of a scroll: the rectangle that leaves (in the old window's logical texels, paged out
/// before the offsets move) and the one that enters (in the new window's, written after).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScrollStep {
    /// Leaves the window.
    pub leaving: Strip,
    /// Enters it.
    pub entering: Strip,
    /// The window's first world texel after this step.
    pub origin: [i64; 2],
    /// The toroidal offsets after this step, packed (`crate::pool::pack_wrap`).
    pub wrap: u32,
}

/// The first world texel of a `size`-texel window of texel side `texel` centred on world
/// `focus` (x, z), snapped to whole texels and, along x, to multiples of `snap_x` (2 at 8 bits,
/// where a pool word holds two neighbours).
pub fn origin_for(focus: [f64; 2], texel: f64, size: [u32; 2], snap_x: u32) -> [i64; 2] {
    let snap = snap_x.max(1) as i64;
    let ix = (focus[0] / texel - size[0] as f64 / 2.0).round() as i64;
    let iz = (focus[1] / texel - size[1] as f64 / 2.0).round() as i64;
    [ix.div_euclid(snap) * snap, iz]
}

/// The toroidal offsets of a window whose first world texel is `origin`, packed.
pub fn wrap_for(origin: [i64; 2], size: [u32; 2]) -> u32 {
    crate::pool::pack_wrap(
        origin[0].rem_euclid(size[0] as i64) as u32,
        origin[1].rem_euclid(size[1] as i64) as u32,
    )
}

/// The steps that move a `size` window from `from` to `to`: along x first (over the old rows),
/// then along z (over the new columns); none when it does not move. A move of a whole window or
/// more replaces every texel in one step a direction.
pub fn scroll(from: [i64; 2], to: [i64; 2], size: [u32; 2]) -> Vec<ScrollStep> {
    let mut steps = Vec::new();
    let mut at = from;
    for axis in 0..2 {
        let d = to[axis] - at[axis];
        if d == 0 {
            continue;
        }
        let mut next = at;
        next[axis] = to[axis];
        steps.push(step(at, next, axis, d, size));
        at = next;
    }
    steps
}

fn step(at: [i64; 2], next: [i64; 2], axis: usize, d: i64, size: [u32; 2]) -> ScrollStep {
    let n = size[axis] as i64;
    let k = d.unsigned_abs().min(n as u64) as u32;
    // Along `axis`: the old window loses [0, k) (moving up) or [n - k, n) (down); the new one
    // gains [n - k, n) or [0, k). The other axis spans the whole window.
    let (lose, gain) = if d > 0 {
        (0, n as u32 - k)
    } else {
        (n as u32 - k, 0)
    };
    let rect = |first: u32, origin: [i64; 2]| {
        let (mut x0, mut y0, mut columns, mut rows) = (0, 0, size[0], size[1]);
        if axis == 0 {
            (x0, columns) = (first, k);
        } else {
            (y0, rows) = (first, k);
        }
        Strip {
            x0,
            y0,
            columns,
            rows,
            world: [origin[0] + x0 as i64, origin[1] + y0 as i64],
        }
    };
    ScrollStep {
        leaving: rect(lose, at),
        entering: rect(gain, next),
        origin: next,
        wrap: wrap_for(next, size),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pool::wrapped;

    /// Where world texel (i, j) is stored in a window at `origin`, if inside.
    fn stored(origin: [i64; 2], size: [u32; 2], i: i64, j: i64) -> Option<(u32, u32)> {
        let (x, y) = (i - origin[0], j - origin[1]);
        if x < 0 || y < 0 || x >= size[0] as i64 || y >= size[1] as i64 {
            return None;
        }
        Some(wrapped(
            wrap_for(origin, size),
            size[0],
            size[1],
            x as u32,
            y as u32,
        ))
    }

    #[test]
    fn origins_snap_to_texels_and_to_words_at_8_bits() {
        assert_eq!(
            origin_for([10.02, -3.0], 0.05, [1024, 512], 1),
            [-312, -316]
        );
        assert_eq!(origin_for([10.07, 0.0], 0.05, [16, 16], 2), [192, -8]);
        assert_eq!(origin_for([10.12, 0.0], 0.05, [16, 16], 2), [194, -8]);
    }

    /// The heart of toroidal storage: a world texel inside both windows keeps its place in the
    /// slot, and the texels that enter take exactly the places of those that left.
    #[test]
    fn texels_that_stay_keep_their_storage_and_entering_ones_take_the_leaving_ones_places() {
        let size = [12u32, 8];
        for (from, to) in [
            ([0, 0], [3, 0]),
            ([5, -2], [1, 4]),
            ([0, 0], [-30, 2]),
            ([7, 7], [7, 5]),
        ] {
            let mut leaving = std::collections::HashSet::new();
            let mut entering = std::collections::HashSet::new();
            let mut at = from;
            for s in scroll(from, to, size) {
                for (strip, origin, set) in [
                    (s.leaving, at, &mut leaving),
                    (s.entering, s.origin, &mut entering),
                ] {
                    for y in strip.y0..strip.y0 + strip.rows {
                        for x in strip.x0..strip.x0 + strip.columns {
                            let (i, j) = (origin[0] + x as i64, origin[1] + y as i64);
                            assert_eq!(
                                (
                                    strip.world[0] + (x - strip.x0) as i64,
                                    strip.world[1] + (y - strip.y0) as i64
                                ),
                                (i, j)
                            );
                            set.insert(wrapped(wrap_for(origin, size), size[0], size[1], x, y));
                        }
                    }
                }
                at = s.origin;
            }
            assert_eq!(at, to);
            assert_eq!(leaving, entering, "{from:?} -> {to:?}");
            for i in from[0].min(to[0]) - 2..from[0].max(to[0]) + 14 {
                for j in from[1].min(to[1]) - 2..from[1].max(to[1]) + 10 {
                    if let (Some(a), Some(b)) = (stored(from, size, i, j), stored(to, size, i, j)) {
                        assert_eq!(a, b, "world texel ({i}, {j}) moved");
                        assert!(!entering.contains(&a), "world texel ({i}, {j}) rewritten");
                    }
                }
            }
        }
    }

    #[test]
    fn a_scroll_by_k_columns_moves_k_columns() {
        let steps = scroll([0, 0], [3, 0], [16, 8]);
        assert_eq!(steps.len(), 1);
        let s = steps[0];
        assert_eq!((s.leaving.x0, s.leaving.columns, s.leaving.rows), (0, 3, 8));
        assert_eq!(
            (s.entering.x0, s.entering.columns, s.entering.rows),
            (13, 3, 8)
        );
        assert_eq!(s.entering.world, [16, 0]);
        assert_eq!(s.wrap, 3);
        let back = scroll([3, 0], [1, -1], [16, 8]);
        assert_eq!(back.len(), 2);
        assert_eq!((back[0].leaving.x0, back[0].leaving.columns), (14, 2));
        assert_eq!((back[0].entering.x0, back[0].entering.world), (0, [1, 0]));
        assert_eq!(
            (
                back[1].entering.y0,
                back[1].entering.rows,
                back[1].entering.columns
            ),
            (0, 1, 16)
        );
        assert_eq!(back[1].wrap, 1 | 7 << 16);
        assert!(scroll([4, 4], [4, 4], [16, 8]).is_empty());
        // A jump past the window rewrites it whole, once.
        let far = scroll([0, 0], [100, 0], [16, 8]);
        assert_eq!(
            (far[0].entering.columns, far[0].entering.world),
            (16, [100, 0])
        );
    }
}
