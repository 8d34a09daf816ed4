//! The spatial lookup of the talk's update loop: "we use a quad tree look-up rather than keeping an
//! actor list for each surface".
//!
//! [`SurfaceIndex`] is a quad tree over the world-space XZ bounds of every surface's capture volume.
//! Each item also keeps its height range, and a query is a 3D box: a foot on a street does not find
//! the roof 20 m above it, and two roofs stacked at different heights are told apart.
//!
//! The tree is built once from all bounds (surfaces are added far less often than actors move) and
//! is rebuilt when the set changes. An item is stored in every leaf whose quadrant it overlaps, so a
//! small query walks one path from the root to a leaf and tests a handful of items; a per-item stamp
//! removes duplicates when a query spans several leaves. Routing uses closed intervals on both sides
//! of a split (`min <= centre` goes low, `max >= centre` goes high), for items and queries alike,
//! which is what makes the result exactly the brute-force answer (see the property test).

use glam::Vec3;

/// Most items a leaf holds before it is split (unless splitting would not separate them).
pub(crate) const LEAF_CAPACITY: usize = 8;
/// Deepest level of the tree.
pub(crate) const MAX_DEPTH: u32 = 14;

/// An axis-aligned box in world space, closed on every side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// A box from its corners.
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// Whether two boxes share at least one point (touching counts).
    #[inline]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        // Non-short-circuit `&`: one predictable branch instead of six (leaf tests are hot).
        (self.min.x <= other.max.x)
            & (self.max.x >= other.min.x)
            & (self.min.z <= other.max.z)
            & (self.max.z >= other.min.z)
            & (self.min.y <= other.max.y)
            & (self.max.y >= other.min.y)
    }

    /// Distance from a point to the box (0 inside).
    #[inline]
    pub fn distance_to(&self, p: Vec3) -> f32 {
        (self.min - p).max(p - self.max).max(Vec3::ZERO).length()
    }

    /// Whether every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }
}

/// Marks an inner node in [`Node::count`].
const INNER: u32 = u32::MAX;

/// A node: a leaf holds `count` items from `first` in [`SurfaceIndex::leaf`]; an inner node has its
/// four children at `first..first + 4`, child `k` covering `x >= cx` when `k & 1` and `z >= cz`
/// when `k & 2`.
#[derive(Clone, Copy, Debug)]
struct Node {
    cx: f32,
    cz: f32,
    first: u32,
    count: u32,
}

/// An item as stored in a leaf: its box inline, so a leaf test touches one cache line per item.
#[derive(Clone, Copy, Debug)]
struct LeafItem {
    bounds: Aabb,
    id: u32,
}

/// Levels covered by the jump table (a 64 x 64 grid of the nodes at level 6).
const JUMP_LEVELS: u32 = 6;

/// Quad tree over surface bounds (XZ split, height range checked). See the module docs.
///
/// A query that falls well inside one cell of a `2^6 x 2^6` grid over the root starts at the node
/// covering that cell (a jump table built with the tree), instead of walking down six levels.
#[derive(Clone, Debug, Default)]
pub struct SurfaceIndex {
    nodes: Vec<Node>,
    /// Root rectangle `[min x, min z, max x, max z]`.
    root: [f32; 4],
    /// Jump-table cells per metre along x and z.
    cells_per_metre: [f32; 2],
    /// Cells per side of the jump table (0 = no table).
    grid: u32,
    /// Per cell, row-major: the deepest node at most `JUMP_LEVELS` down that holds the whole cell.
    jump: Vec<u32>,
    leaf: Vec<LeafItem>,
    /// Per item id: the query stamp that last reported it.
    stamps: Vec<u32>,
    stamp: u32,
    items: usize,
    depth: u32,
}

impl SurfaceIndex {
    /// Build the tree over `bounds[id]` for every `Some` entry; `None` entries (removed surfaces)
    /// are left out. Bounds must be finite.
    pub fn build(bounds: &[Option<Aabb>]) -> Self {
        let mut index = Self {
            stamps: vec![0; bounds.len()],
            ..Self::default()
        };
        let items: Vec<LeafItem> = bounds
            .iter()
            .enumerate()
            .filter_map(|(i, b)| {
                b.map(|bounds| LeafItem {
                    bounds,
                    id: i as u32,
                })
            })
            .collect();
        index.items = items.len();
        if items.is_empty() {
            return index;
        }
        let (mut lo, mut hi) = (items[0].bounds.min, items[0].bounds.max);
        for it in &items {
            lo = lo.min(it.bounds.min);
            hi = hi.max(it.bounds.max);
        }
        index.nodes.push(Node {
            cx: 0.0,
            cz: 0.0,
            first: 0,
            count: 0,
        });
        index.build_node(0, items, [lo.x, lo.z], [hi.x, hi.z], 0);
        index.root = [lo.x, lo.z, hi.x, hi.z];
        index.build_jump_table();
        index
    }

    /// For each cell of the grid, walk down from the root with the tree's own split centres
    /// (following the cell's centre) for at most `JUMP_LEVELS` levels.
    fn build_jump_table(&mut self) {
        let [x0, z0, x1, z1] = self.root;
        if !(x1 > x0 && z1 > z0) {
            return;
        }
        let levels = JUMP_LEVELS.min(self.depth);
        let grid = 1u32 << levels;
        let (w, h) = ((x1 - x0) / grid as f32, (z1 - z0) / grid as f32);
        self.jump = Vec::with_capacity((grid * grid) as usize);
        for cz in 0..grid {
            for cx in 0..grid {
                let (px, pz) = (x0 + (cx as f32 + 0.5) * w, z0 + (cz as f32 + 0.5) * h);
                let mut at = 0usize;
                for _ in 0..levels {
                    let n = self.nodes[at];
                    if n.count != INNER {
                        break;
                    }
                    at = n.first as usize + (px >= n.cx) as usize + 2 * (pz >= n.cz) as usize;
                }
                self.jump.push(at as u32);
            }
        }
        self.cells_per_metre = [grid as f32 / (x1 - x0), grid as f32 / (z1 - z0)];
        self.grid = grid;
    }

    /// Where a query may start: the jump table's node when the query lies inside one cell with a
    /// margin (so that float differences between the grid and the tree's split centres cannot
    /// matter), else the root.
    #[inline]
    fn start_node(&self, query: &Aabb) -> usize {
        if self.grid == 0 {
            return 0;
        }
        let [x0, z0, ..] = self.root;
        let g = self.grid as f32;
        let [sx, sz] = self.cells_per_metre;
        let (ax, bx) = ((query.min.x - x0) * sx, (query.max.x - x0) * sx);
        let (az, bz) = ((query.min.z - z0) * sz, (query.max.z - z0) * sz);
        if !(ax >= 0.0 && az >= 0.0 && bx < g && bz < g) {
            return 0;
        }
        // Non-negative here, so truncation is the floor (and needs no call into libm).
        let (ix, iz) = (ax as u32, az as u32);
        let (cx, cz) = (ix as f32, iz as f32);
        const MARGIN: f32 = 1e-3;
        let inside = (ax - cx >= MARGIN)
            & (bx <= cx + 1.0 - MARGIN)
            & (az - cz >= MARGIN)
            & (bz <= cz + 1.0 - MARGIN);
        if inside {
            self.jump[(iz * self.grid + ix) as usize] as usize
        } else {
            0
        }
    }

    fn build_node(
        &mut self,
        at: usize,
        items: Vec<LeafItem>,
        min: [f32; 2],
        max: [f32; 2],
        depth: u32,
    ) {
        let (cx, cz) = ((min[0] + max[0]) * 0.5, (min[1] + max[1]) * 0.5);
        self.depth = self.depth.max(depth);
        let make_leaf = |index: &mut Self, items: Vec<LeafItem>| {
            index.nodes[at] = Node {
                cx,
                cz,
                first: index.leaf.len() as u32,
                count: items.len() as u32,
            };
            index.leaf.extend(items);
        };
        if items.len() <= LEAF_CAPACITY || depth >= MAX_DEPTH {
            make_leaf(self, items);
            return;
        }
        let mut quads: [Vec<LeafItem>; 4] = Default::default();
        for it in &items {
            let (b, lo_x, hi_x) = (&it.bounds, it.bounds.min.x <= cx, it.bounds.max.x >= cx);
            let (lo_z, hi_z) = (b.min.z <= cz, b.max.z >= cz);
            for (k, quad) in quads.iter_mut().enumerate() {
                let x_ok = if k & 1 == 0 { lo_x } else { hi_x };
                let z_ok = if k & 2 == 0 { lo_z } else { hi_z };
                if x_ok && z_ok {
                    quad.push(*it);
                }
            }
        }
        // Every item straddles the centre: splitting separates nothing.
        if quads.iter().all(|q| q.len() == items.len()) {
            make_leaf(self, items);
            return;
        }
        let first = self.nodes.len();
        self.nodes[at] = Node {
            cx,
            cz,
            first: first as u32,
            count: INNER,
        };
        for _ in 0..4 {
            self.nodes.push(Node {
                cx: 0.0,
                cz: 0.0,
                first: 0,
                count: 0,
            });
        }
        for (k, quad) in quads.into_iter().enumerate() {
            let x = if k & 1 == 0 {
                [min[0], cx]
            } else {
                [cx, max[0]]
            };
            let z = if k & 2 == 0 {
                [min[1], cz]
            } else {
                [cz, max[1]]
            };
            self.build_node(first + k, quad, [x[0], z[0]], [x[1], z[1]], depth + 1);
        }
    }

    /// Items in the tree.
    pub fn len(&self) -> usize {
        self.items
    }

    /// Whether the tree holds no item.
    pub fn is_empty(&self) -> bool {
        self.items == 0
    }

    /// Deepest level reached (0 = the root is a leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Nodes of the tree.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Append to `out` the id of every item whose box overlaps `query` (touching counts), each
    /// once, in no particular order.
    pub fn query(&mut self, query: &Aabb, out: &mut Vec<u32>) {
        if self.nodes.is_empty() {
            return;
        }
        // Fast path: a small query (a foot) usually falls in one child at every level, so it walks
        // a single path to one leaf, where every item is listed once: no stamps needed.
        let mut at = self.start_node(query);
        loop {
            let n = self.nodes[at];
            if n.count != INNER {
                let start = n.first as usize;
                for it in &self.leaf[start..start + n.count as usize] {
                    if it.bounds.overlaps(query) {
                        out.push(it.id);
                    }
                }
                return;
            }
            let (lo_x, hi_x) = (query.min.x <= n.cx, query.max.x >= n.cx);
            let (lo_z, hi_z) = (query.min.z <= n.cz, query.max.z >= n.cz);
            if lo_x == hi_x || lo_z == hi_z {
                // Straddles a split (or, with NaN, matches nothing): the general walk below.
                if !(lo_x || hi_x) || !(lo_z || hi_z) {
                    return;
                }
                break;
            }
            at = n.first as usize + (hi_x as usize) + 2 * (hi_z as usize);
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.stamps.iter_mut().for_each(|s| *s = 0);
            self.stamp = 1;
        }
        // Depth-first from where the path split; each inner node pushes at most 4 children, so the
        // stack never holds more than 3 * MAX_DEPTH + 4 nodes.
        let mut stack = [0u32; 3 * MAX_DEPTH as usize + 8];
        stack[0] = at as u32;
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let n = self.nodes[stack[sp] as usize];
            if n.count != INNER {
                let start = n.first as usize;
                for it in &self.leaf[start..start + n.count as usize] {
                    if it.bounds.overlaps(query) {
                        let s = &mut self.stamps[it.id as usize];
                        if *s != self.stamp {
                            *s = self.stamp;
                            out.push(it.id);
                        }
                    }
                }
                continue;
            }
            let (lo_x, hi_x) = (query.min.x <= n.cx, query.max.x >= n.cx);
            let (lo_z, hi_z) = (query.min.z <= n.cz, query.max.z >= n.cz);
            for (k, ok) in [lo_x && lo_z, hi_x && lo_z, lo_x && hi_z, hi_x && hi_z]
                .into_iter()
                .enumerate()
            {
                if ok {
                    stack[sp] = n.first + k as u32;
                    sp += 1;
                }
            }
        }
    }

    /// The same answer as [`SurfaceIndex::query`] by testing every item: the reference the tree is
    /// tested and benchmarked against.
    pub fn brute_force(bounds: &[Option<Aabb>], query: &Aabb, out: &mut Vec<u32>) {
        for (i, b) in bounds.iter().enumerate() {
            if let Some(b) = b
                && b.overlaps(query)
            {
                out.push(i as u32);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn boxes() -> impl Strategy<Value = Vec<Option<Aabb>>> {
        proptest::collection::vec(
            proptest::option::weighted(
                0.9,
                (
                    -100f32..100.0,
                    -5f32..30.0,
                    -100f32..100.0,
                    0f32..20.0,
                    0.05f32..1.0,
                    0f32..20.0,
                )
                    .prop_map(|(x, y, z, sx, sy, sz)| {
                        Aabb::new(Vec3::new(x, y, z), Vec3::new(x + sx, y + sy, z + sz))
                    }),
            ),
            0..400,
        )
    }

    fn query_box() -> impl Strategy<Value = Aabb> {
        (
            -120f32..120.0,
            -10f32..35.0,
            -120f32..120.0,
            0f32..30.0,
            0f32..5.0,
            0f32..30.0,
        )
            .prop_map(|(x, y, z, sx, sy, sz)| {
                Aabb::new(Vec3::new(x, y, z), Vec3::new(x + sx, y + sy, z + sz))
            })
    }

    proptest! {
        /// The tree returns exactly what testing every item returns.
        #[test]
        fn lookup_equals_brute_force(bounds in boxes(), queries in proptest::collection::vec(query_box(), 1..40)) {
            let mut index = SurfaceIndex::build(&bounds);
            prop_assert_eq!(index.len(), bounds.iter().flatten().count());
            for q in &queries {
                let (mut got, mut want) = (Vec::new(), Vec::new());
                index.query(q, &mut got);
                SurfaceIndex::brute_force(&bounds, q, &mut want);
                got.sort_unstable();
                prop_assert_eq!(got, want);
            }
        }
    }

    #[test]
    fn stacked_surfaces_are_told_apart_by_height() {
        let street = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 0.5, 4.0));
        let roof = Aabb::new(Vec3::new(0.0, 8.0, 0.0), Vec3::new(10.0, 8.5, 4.0));
        let mut index = SurfaceIndex::build(&[Some(street), Some(roof)]);
        let mut out = Vec::new();
        index.query(
            &Aabb::new(Vec3::new(2.0, 0.1, 1.0), Vec3::new(2.3, 0.4, 1.3)),
            &mut out,
        );
        assert_eq!(out, vec![0]);
        out.clear();
        index.query(
            &Aabb::new(Vec3::new(2.0, 8.1, 1.0), Vec3::new(2.3, 8.4, 1.3)),
            &mut out,
        );
        assert_eq!(out, vec![1]);
    }

    #[test]
    fn many_identical_items_do_not_recurse_forever() {
        let b = Some(Aabb::new(Vec3::ZERO, Vec3::ONE));
        let mut index = SurfaceIndex::build(&vec![b; 100]);
        let mut out = Vec::new();
        index.query(&Aabb::new(Vec3::splat(0.5), Vec3::splat(0.5)), &mut out);
        assert_eq!(out.len(), 100);
        assert_eq!(index.depth(), 0);
    }
}
