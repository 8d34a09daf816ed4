//! Per-surface state of the planner: the hot status line, the touch volume, the cold rest, and
//! the rank by which surfaces compete for memory.

use std::collections::VecDeque;

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::TOUCH_MARGIN;
use crate::deformer::{Deformer, Shape};
use crate::manager::quadtree::Aabb;
use crate::manager::queue::Imprint;
use crate::pool::Slot;
use crate::surface::SurfaceDesc;

/// A candidate for a slot evicts a resident of its own class only when the resident is farther by
/// this factor ...
pub(super) const HYSTERESIS_FACTOR: f32 = 1.25;
/// ... plus this many metres (so that two surfaces at similar distances do not trade one slot
/// back and forth as the focus moves).
pub(super) const HYSTERESIS_METRES: f32 = 1.0;

/// Usefulness of a surface for memory: which class, then distance (or, for inactive surfaces that
/// keep their slot, when they were last active).
#[derive(Clone, Copy, Debug)]
pub(super) struct Rank {
    /// 0 inactive (kept), 1 active, 2 touched or with queued imprints, 3 touched by the player.
    pub(super) class: u8,
    pub(super) dist: f32,
    pub(super) last_active: u64,
    pub(super) index: u32,
}

impl Rank {
    /// Order from least to most useful: class, then (inactive) least recently active first or
    /// (active) farthest first, then index.
    pub(super) fn least_useful_first(a: &Rank, b: &Rank) -> std::cmp::Ordering {
        a.class
            .cmp(&b.class)
            .then_with(|| {
                if a.class == 0 {
                    a.last_active.cmp(&b.last_active)
                } else {
                    b.dist.total_cmp(&a.dist)
                }
            })
            .then(b.index.cmp(&a.index))
    }

    /// Whether a candidate for a slot may evict this resident.
    pub(super) fn evictable_for(&self, candidate: &Rank) -> bool {
        self.class < candidate.class
            || (self.class == candidate.class
                && self.class > 0
                && self.dist > candidate.dist * HYSTERESIS_FACTOR + HYSTERESIS_METRES)
    }
}

/// A [`Rank`] ordered by usefulness (most useful is greatest), for the candidates' heap.
#[derive(Clone, Copy, Debug)]
pub(super) struct ByUse(pub(super) Rank);

impl PartialEq for ByUse {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for ByUse {}

impl PartialOrd for ByUse {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByUse {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        Rank::least_useful_first(&self.0, &other.0)
    }
}

pub(super) const RESIDENT: u8 = 1;
pub(super) const REMOVED: u8 = 2;
/// Listed in [`Planner::queued`].
pub(super) const LISTED: u8 = 4;
/// Snow falls on it (replenish rate above 0).
pub(super) const SNOWFALL: u8 = 8;
/// Its heightmap is in the page store (it was evicted, or its zone unloaded).
pub(super) const PAGED: u8 = 16;
/// Resident when its zone was unloaded: paged back in as soon as the zone loads and there is room.
pub(super) const WANTED: u8 = 32;
/// Its page is on its way from the GPU (paged out in a tick not yet read back): not admitted
/// until it has arrived.
pub(super) const ARRIVING: u8 = 64;

/// What the per-tick passes over touched, active and waiting surfaces read and write, in one cache
/// line per surface: a city with hundreds of surfaces waiting for memory is walked several times a
/// tick, and the rest of a surface's state (its description, queue, slot) stays cold.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Status {
    pub(super) bounds: Aabb,
    /// Tick stamps: last touched, last touched by the player, last active.
    pub(super) touched: u64,
    pub(super) player: u64,
    pub(super) active: u64,
    /// Pool bytes of its slot (at most 4 MiB: 512 x 512 texels at 32 bits with normals).
    pub(super) bytes: u32,
    pub(super) zone: u32,
    pub(super) queue_len: u32,
    pub(super) flags: u8,
}

impl Status {
    pub(super) fn has(&self, flag: u8) -> bool {
        self.flags & flag != 0
    }

    pub(super) fn set(&mut self, flag: u8, on: bool) {
        if on {
            self.flags |= flag;
        } else {
            self.flags &= !flag;
        }
    }
}

/// The rest of a surface's state.
#[derive(Clone, Debug)]
pub(super) struct Managed {
    pub(super) desc: SurfaceDesc,
    pub(super) slot: Option<Slot>,
    /// Position in [`Planner::resident`] while resident.
    pub(super) resident_pos: usize,
    pub(super) queue: VecDeque<Imprint>,
    /// What the last update captured (cleared when the heightmap is lost).
    pub(super) applied: Vec<Deformer>,
    pub(super) due_since: Option<u64>,
    pub(super) last_update_time: f64,
    /// Until when (seconds) snowfall still has something to refill.
    pub(super) pressed_until: f64,
}

impl Managed {
    pub(super) fn new(desc: SurfaceDesc) -> Self {
        Self {
            desc,
            slot: None,
            resident_pos: 0,
            queue: VecDeque::new(),
            applied: Vec::new(),
            due_since: None,
            last_update_time: 0.0,
            pressed_until: 0.0,
        }
    }
}

/// What the touch test reads of a surface, in one cache line: a tick tests thousands of candidates
/// and few of them are touched.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct TouchVolume {
    /// The first three rows of the world-to-local transform.
    pub(super) rows: [Vec4; 3],
    pub(super) half: Vec2,
    /// Snow depth plus ankle height: the capture frustum's height.
    pub(super) top: f32,
    pub(super) zone: u32,
}

impl TouchVolume {
    pub(super) fn new(to_local: Mat4, half: Vec2, top: f32, zone: u32) -> Self {
        let t = to_local.transpose();
        Self {
            rows: [t.x_axis, t.y_axis, t.z_axis],
            half,
            top,
            zone,
        }
    }

    #[inline]
    pub(super) fn local(&self, p: Vec3) -> Vec3 {
        let p = p.extend(1.0);
        Vec3::new(
            self.rows[0].dot(p),
            self.rows[1].dot(p),
            self.rows[2].dot(p),
        )
    }

    /// The world's culling test, made conservative: a ball of radius `r` swept from `a` to `b`
    /// against the capture volume, in the surface's frame.
    #[inline]
    pub(super) fn touched_by(&self, a: Vec3, b: Vec3, r: f32) -> bool {
        let (la, lb) = (self.local(a), self.local(b));
        let e = Vec3::splat(r + TOUCH_MARGIN);
        let (lo, hi) = (la.min(lb) - e, la.max(lb) + e);
        hi.x >= -self.half.x
            && lo.x <= self.half.x
            && hi.z >= -self.half.y
            && lo.z <= self.half.y
            && hi.y >= 0.0
            && lo.y < self.top
    }
}

/// A quick check that a deformer's numbers are usable (finite, sizes above 0); the full check, with
/// its message, runs only when this one fails.
pub(super) fn plausible(d: &Deformer) -> bool {
    let sizes = match d.shape {
        Shape::Sphere { radius } => radius > 0.0 && radius.is_finite(),
        Shape::Capsule {
            radius,
            half_height,
        } => radius > 0.0 && (radius + half_height).is_finite() && half_height >= 0.0,
        Shape::Box { half_extents } => half_extents.min_element() > 0.0 && half_extents.is_finite(),
        Shape::Mesh(_) => true,
    };
    let prev = d.previous.unwrap_or(d.pose);
    sizes
        && d.pose.position.is_finite()
        && prev.position.is_finite()
        && d.pose.rotation.is_finite()
        && prev.rotation.is_finite()
}
