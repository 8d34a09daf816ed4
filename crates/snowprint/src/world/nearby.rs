//! Which deformers of a long list can reach a surface: a uniform grid over the ground plane
//! (world `x`, `z`) of the squares around the deformers' swept balls.
//!
//! [`crate::SnowWorld::encode_step`] hands every surface the same list of every deformer. Testing
//! each surface against each deformer costs surfaces times deformers; the grid, built once a list,
//! offers each surface only the deformers in the cells its rectangle covers, in the list's order
//! and each once, so that the exact tests that follow (the capture's culling, the footstep test)
//! see the same deformers in the same order as before, less the ones they would have refused.
//!
//! The grid is a conservative filter: a deformer is offered whenever its square (the swept ball's
//! radius times `sqrt(2)`, see [`deformer_square`]) shares a cell with the surface's world
//! rectangle, which holds every deformer the capture's ball test or the footstep test can keep.
//! Meshes (whose reach the footstep test takes from vertices the grid does not see), deformers
//! far larger than a cell and any that are not finite are offered to every surface.

use glam::{Vec2, Vec3};

use crate::capture;
use crate::deformer::Deformer;
use crate::surface::SurfaceDesc;

/// Lists at least this long are indexed; shorter ones (a surface's own deformers) are walked.
pub(crate) const INDEX_FROM: usize = 64;

/// Most cells a side of the grid.
const MAX_CELLS_A_SIDE: f32 = 4096.0;

/// Most cells one deformer is entered in; a larger one is offered to every surface.
const MAX_CELLS_A_DEFORMER: u64 = 64;

/// A world-space rectangle of the ground plane: `[x0, z0, x1, z1]`.
pub(crate) type GroundRect = [f32; 4];

/// The ground-plane square that holds a deformer's reach for both tests the grid filters: the
/// capture's ball test (the swept ball against the surface's local rectangle grown by its radius,
/// which a yawed surface turns by up to 45 degrees: the radius times `sqrt(2)` in world axes) and
/// the footstep test (the lowest point at the pose, inside the ball). A margin covers rounding.
/// `None` for a mesh or a deformer that is not finite.
pub(crate) fn deformer_square(d: &Deformer) -> Option<GroundRect> {
    let (c, r) = capture::swept_ball(d)?;
    let reach = r * std::f32::consts::SQRT_2 * 1.001 + 1e-4 * (1.0 + c.abs().max_element());
    let square = [c.x - reach, c.z - reach, c.x + reach, c.z + reach];
    square.iter().all(|v| v.is_finite()).then_some(square)
}

/// The ground-plane rectangle holding a surface's (yawed) rectangle of half sides `h` (in a plan,
/// its capture region's: the surface grown by the apron), with a margin for rounding.
pub(crate) fn surface_rect(desc: &SurfaceDesc, h: Vec2) -> GroundRect {
    let m = desc.local_to_world();
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = m.transform_point3(Vec3::new(sx * h.x, 0.0, sz * h.y));
        lo = lo.min(Vec2::new(p.x, p.z));
        hi = hi.max(Vec2::new(p.x, p.z));
    }
    let margin = 1e-4 * (1.0 + lo.abs().max(hi.abs()).max_element());
    [lo.x - margin, lo.y - margin, hi.x + margin, hi.y + margin]
}

/// A uniform grid over one list of deformers, rebuilt when another list is asked about. Keeps its
/// memory between frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct NearbyDeformers {
    /// The list indexed (its address and length), while it is borrowed by the frame.
    key: Option<(usize, usize)>,
    /// World `(x, z)` of the grid's first corner.
    origin: Vec2,
    /// World `(x, z)` of the far corner of every square indexed.
    far: Vec2,
    /// Side of a cell, metres.
    cell: f32,
    /// Cells along `x` and `z`.
    cells: (u32, u32),
    /// Where each cell's entries start in `entries` (one more than the cells).
    starts: Vec<u32>,
    /// Deformer indices, cell after cell, ascending within a cell.
    entries: Vec<u32>,
    /// Deformers offered to every surface, ascending.
    everywhere: Vec<u32>,
    /// Each deformer's cell range, `[c0, r0, c1, r1]`, or `None` when it is everywhere.
    spans: Vec<Option<[u32; 4]>>,
    /// The query each deformer was last offered to (so that it is offered once).
    stamps: Vec<u32>,
    query: u32,
}

impl NearbyDeformers {
    /// Whether the grid is built over `deformers` in this frame.
    pub(crate) fn is_for(&self, deformers: &[Deformer]) -> bool {
        self.key == Some((deformers.as_ptr() as usize, deformers.len()))
    }

    /// Forget the list (its memory may hold another list next frame).
    pub(crate) fn forget(&mut self) {
        self.key = None;
    }

    /// Build the grid over `deformers`, unless it is built over them already. The list must stay
    /// borrowed, unchanged, until [`NearbyDeformers::forget`].
    pub(crate) fn index(&mut self, deformers: &[Deformer]) {
        if self.is_for(deformers) {
            return;
        }
        self.key = Some((deformers.as_ptr() as usize, deformers.len()));
        self.everywhere.clear();
        self.spans.clear();
        self.stamps.clear();
        self.stamps.resize(deformers.len(), 0);
        self.query = 0;
        let squares = deformers.iter().map(deformer_square);
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        let (mut sides, mut placed) = (0.0f64, 0usize);
        for s in squares.clone().flatten() {
            lo = lo.min(Vec2::new(s[0], s[1]));
            hi = hi.max(Vec2::new(s[2], s[3]));
            sides += (s[2] - s[0]) as f64;
            placed += 1;
        }
        // About as many cells as deformers, each at least as wide as a deformer's mean square.
        let extent = (hi - lo).max(Vec2::splat(1e-3));
        let mean = if placed > 0 {
            (sides / placed as f64) as f32
        } else {
            1.0
        };
        let cell = mean
            .max((extent.x * extent.y / placed.max(1) as f32).sqrt())
            .max(extent.max_element() / MAX_CELLS_A_SIDE);
        self.origin = lo;
        self.far = hi;
        self.cell = cell;
        self.cells = (
            ((extent.x / cell).ceil() as u32).max(1),
            ((extent.y / cell).ceil() as u32).max(1),
        );
        let n_cells = (self.cells.0 * self.cells.1) as usize;
        // Counting sort: count a cell's entries, place the starts, then fill in list order.
        self.starts.clear();
        self.starts.resize(n_cells + 1, 0);
        for (i, square) in squares.enumerate() {
            let span = square.map(|s| self.span(s)).filter(|&[c0, r0, c1, r1]| {
                (c1 - c0 + 1) as u64 * (r1 - r0 + 1) as u64 <= MAX_CELLS_A_DEFORMER
            });
            match span {
                Some([c0, r0, c1, r1]) => {
                    for r in r0..=r1 {
                        for c in c0..=c1 {
                            self.starts[(r * self.cells.0 + c) as usize + 1] += 1;
                        }
                    }
                }
                None => self.everywhere.push(i as u32),
            }
            self.spans.push(span);
        }
        for k in 1..=n_cells {
            self.starts[k] += self.starts[k - 1];
        }
        self.entries.clear();
        self.entries.resize(self.starts[n_cells] as usize, 0);
        let mut fill: Vec<u32> = self.starts[..n_cells].to_vec();
        for (i, span) in self.spans.iter().enumerate() {
            let Some([c0, r0, c1, r1]) = *span else {
                continue;
            };
            for r in r0..=r1 {
                for c in c0..=c1 {
                    let at = &mut fill[(r * self.cells.0 + c) as usize];
                    self.entries[*at as usize] = i as u32;
                    *at += 1;
                }
            }
        }
    }

    /// The cells `[c0, r0, c1, r1]` a ground rectangle covers, clamped to the grid: monotonic in
    /// each bound, so two rectangles that overlap cover a common cell.
    fn span(&self, [x0, z0, x1, z1]: GroundRect) -> [u32; 4] {
        let cell = |v: f32, o: f32, n: u32| {
            // `as` saturates (and takes NaN to 0); the clamp keeps it in the grid.
            (((v - o) / self.cell) as i64).clamp(0, n as i64 - 1) as u32
        };
        [
            cell(x0, self.origin.x, self.cells.0),
            cell(z0, self.origin.y, self.cells.1),
            cell(x1, self.origin.x, self.cells.0),
            cell(z1, self.origin.y, self.cells.1),
        ]
    }

    /// The indices of the indexed list's deformers that may reach `rect`, ascending, each once.
    pub(crate) fn near(&mut self, rect: GroundRect, out: &mut Vec<u32>) {
        out.clear();
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.stamps.fill(0);
            self.query = 1;
        }
        let [c0, r0, c1, r1] = self.span(rect);
        // Clamped to the grid, a rectangle beside it would cover its edge's cells: none then (nor
        // when a bound that is not a number reverses it).
        let [x0, z0, x1, z1] = rect;
        let beside = x1 < self.origin.x || z1 < self.origin.y || x0 > self.far.x || z0 > self.far.y;
        if c0 <= c1 && !beside {
            for r in r0..=r1 {
                let row = (r * self.cells.0) as usize;
                let (a, b) = (
                    self.starts[row + c0 as usize],
                    self.starts[row + c1 as usize + 1],
                );
                for &i in &self.entries[a as usize..b as usize] {
                    let stamp = &mut self.stamps[i as usize];
                    if *stamp != self.query {
                        *stamp = self.query;
                        out.push(i);
                    }
                }
            }
        }
        out.extend_from_slice(&self.everywhere);
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests;
