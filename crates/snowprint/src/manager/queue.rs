//! The imprint queue of one surface: everything that touched it since its last update, so that a
//! surface updated only every few frames still receives every footprint (issue 4's "no imprint is
//! lost").
//!
//! An entry is a [`Deformer`] as it was in one frame, with its `previous` pose: the swept shape of
//! that frame. When the surface's turn comes the whole queue is captured in one pass: the capture
//! keeps the lowest point of anything per texel, so capturing the union of the frames' shapes at
//! once presses every texel at least as deep as capturing them frame by frame (exactly as deep
//! where the frames' prints do not meet within the blur's reach; see `docs/MANAGER.md`).
//!
//! The queue is kept short without changing the union it captures:
//! - an entry whose swept shape lies inside one already queued (a foot standing still, or lifted
//!   straight back up the way it came down), or inside one applied at the surface's last update
//!   when no snow falls on it, is redundant and not queued;
//! - an entry whose swept shape holds a queued one replaces it;
//! - a sphere that keeps moving in a straight line extends its queued sweep.
//!
//! Only past [`crate::manager::ManagerConfig::queue_cap`] entries does the queue give something up:
//! a continuing motion is merged into its predecessor as one straight sweep (the trail is
//! straightened between the kept points, not lost); failing that, the oldest entry is dropped and
//! counted.

use std::collections::VecDeque;

use glam::Vec3;

use crate::deformer::{Deformer, Pose, Shape};

/// How many of the newest queued entries a push compares itself with.
pub const SCAN: usize = 8;

/// Distance, metres, under which two points are taken as the same in containment and straightness
/// tests (0.001 mm: far below a texel and below 1 unit of depression for any usable snow depth).
pub const EPS: f32 = 1e-6;

/// What a push did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Push {
    /// Appended.
    Queued,
    /// Already covered by a queued or just-applied entry: nothing to add.
    Redundant,
    /// Replaced or extended a queued entry without changing the union of shapes.
    Absorbed,
    /// The queue was full: merged into its predecessor as one straight sweep (lossy: straightened).
    Merged,
    /// The queue was full and nothing could be merged: the oldest entry was dropped (lossy).
    DroppedOldest,
}

/// Start pose of an entry's sweep.
fn start(d: &Deformer) -> Pose {
    d.previous.unwrap_or(d.pose)
}

/// The cheap, exact form of [`contains`] that covers most pushes: `d` is `q` again, or `d` rests
/// (no motion) where `q`'s sweep ends or starts. Positions are compared first, so most entries are
/// rejected by one comparison.
#[inline]
fn covers_exactly(q: &Deformer, d: &Deformer, resting: bool) -> bool {
    let p = d.pose.position;
    let (at_end, at_start) = (q.pose.position == p, start(q).position == p);
    if !(at_end || at_start) || q.shape != d.shape {
        return false;
    }
    if q == d {
        return true;
    }
    resting
        && ((at_end && q.pose == d.pose)
            || (at_start && !matches!(d.shape, Shape::Mesh(_)) && start(q) == d.pose))
}

/// Distance from `p` to the segment `a..b`.
fn point_segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 <= 0.0 {
        return p.distance(a);
    }
    let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// Whether the swept shape of `inner` lies inside the swept shape of `outer`.
///
/// Exact cases only: the same shape and a sweep whose ends lie on the other's sweep for spheres
/// (a swept sphere is a capsule along the segment); for other analytic shapes, a resting entry at
/// either end of the other's sweep or an identical entry; for meshes (captured at their pose, not
/// swept), the same pose.
pub fn contains(outer: &Deformer, inner: &Deformer) -> bool {
    if outer.shape != inner.shape {
        return false;
    }
    match outer.shape {
        Shape::Sphere { .. } => {
            let (a, b) = (start(outer).position, outer.pose.position);
            let (p, q) = (start(inner).position, inner.pose.position);
            // Cheap rejection first: both ends must lie in the segment's box.
            let (lo, hi) = (a.min(b) - Vec3::splat(EPS), a.max(b) + Vec3::splat(EPS));
            let inside = |v: Vec3| v.cmpge(lo).all() && v.cmple(hi).all();
            if !(inside(p) && inside(q)) {
                return false;
            }
            let on = |v: Vec3| v == a || v == b || point_segment_distance(v, a, b) <= EPS;
            on(p) && on(q)
        }
        Shape::Mesh(_) => outer.pose == inner.pose,
        _ => {
            if outer == inner || (start(outer) == start(inner) && outer.pose == inner.pose) {
                return true;
            }
            let resting = start(inner) == inner.pose;
            resting && (inner.pose == start(outer) || inner.pose == outer.pose)
        }
    }
}

/// For a sphere continuing in a straight line (`next` starts where `prev` ends and heads the same
/// way), the single sweep covering both.
fn straight_extension(prev: &Deformer, next: &Deformer) -> Option<Deformer> {
    let Shape::Sphere { .. } = prev.shape else {
        return None;
    };
    if prev.shape != next.shape || prev.pose.position != start(next).position {
        return None;
    }
    let (a, b, c) = (start(prev).position, prev.pose.position, next.pose.position);
    let (ab, bc) = (b - a, c - b);
    if ab.length_squared() == 0.0 || bc.length_squared() == 0.0 || ab.dot(bc) <= 0.0 {
        return None;
    }
    // c within EPS of the line through a and b.
    if ab.cross(c - a).length() > EPS * ab.length() {
        return None;
    }
    Some(Deformer::moving(prev.shape, start(prev), next.pose))
}

/// Push one frame's deformer into a surface's queue. `applied` is what the surface's last update
/// captured; it is consulted only when `skip_applied` (no snowfall on the surface, so pressing the
/// same shape again cannot change the heightmap). `cap` is the most entries kept.
pub fn push(
    queue: &mut VecDeque<Deformer>,
    applied: &[Deformer],
    skip_applied: bool,
    d: Deformer,
    cap: usize,
) -> Push {
    let scan_from = queue.len().saturating_sub(SCAN);
    // The common case first, by exact comparison: a deformer resting where a queued sweep of the
    // same shape ends or starts (a planted foot), or the same entry again.
    let resting = start(&d) == d.pose;
    if queue
        .range(scan_from..)
        .rev()
        .any(|q| covers_exactly(q, &d, resting))
        || (skip_applied
            && applied
                .iter()
                .rev()
                .take(SCAN)
                .any(|q| covers_exactly(q, &d, resting)))
    {
        return Push::Redundant;
    }
    // Newest first: a foot standing still matches its own last entry.
    for i in (scan_from..queue.len()).rev() {
        let q = &queue[i];
        if q.shape != d.shape {
            continue;
        }
        if contains(q, &d) {
            return Push::Redundant;
        }
        if contains(&d, q) {
            // Whatever else the window holds, the union only grows by what `d` adds.
            queue[i] = d;
            return Push::Absorbed;
        }
        if let Some(longer) = straight_extension(q, &d) {
            queue[i] = longer;
            return Push::Absorbed;
        }
    }
    if skip_applied && applied.iter().rev().take(SCAN).any(|q| contains(q, &d)) {
        return Push::Redundant;
    }
    if queue.len() < cap.max(1) {
        queue.push_back(d);
        return Push::Queued;
    }
    // Full: merge a continuing motion into its predecessor as one sweep.
    if !matches!(d.shape, Shape::Mesh(_)) {
        let from = start(&d);
        for i in (scan_from..queue.len()).rev() {
            let q = queue[i];
            if q.shape == d.shape && q.pose == from {
                queue[i] = Deformer::moving(d.shape, start(&q), d.pose);
                return Push::Merged;
            }
        }
    }
    queue.pop_front();
    queue.push_back(d);
    Push::DroppedOldest
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(from: [f32; 3], to: [f32; 3]) -> Deformer {
        Deformer::moving(Shape::Sphere { radius: 0.1 }, Pose::at(from), Pose::at(to))
    }

    #[test]
    fn standing_still_and_lifting_back_are_redundant() {
        let mut q = VecDeque::new();
        let down = sphere([0.0, 1.0, 0.0], [0.0, 0.1, 0.0]);
        assert_eq!(push(&mut q, &[], false, down, 16), Push::Queued);
        let still = Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[], false, still, 16), Push::Redundant);
        let up = sphere([0.0, 0.1, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(push(&mut q, &[], false, up, 16), Push::Redundant);
        assert_eq!(q.len(), 1);
        // A different radius is a different shape.
        let big = Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[], false, big, 16), Push::Queued);
    }

    #[test]
    fn applied_entries_are_skipped_only_without_snowfall() {
        let mut q = VecDeque::new();
        let still = Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[still], true, still, 16), Push::Redundant);
        assert_eq!(push(&mut q, &[still], false, still, 16), Push::Queued);
    }

    #[test]
    fn straight_motion_extends_one_sweep() {
        let mut q = VecDeque::new();
        for k in 0..10 {
            let x = k as f32 * 0.25;
            push(
                &mut q,
                &[],
                false,
                sphere([x, 0.1, 0.0], [x + 0.25, 0.1, 0.0]),
                16,
            );
        }
        assert_eq!(q.len(), 1);
        assert_eq!(start(&q[0]).position, Vec3::new(0.0, 0.1, 0.0));
        assert_eq!(q[0].pose.position, Vec3::new(2.5, 0.1, 0.0));
        // A turn starts a new entry.
        push(
            &mut q,
            &[],
            false,
            sphere([2.5, 0.1, 0.0], [2.5, 0.1, 0.5]),
            16,
        );
        assert_eq!(q.len(), 2);
    }

    #[test]
    fn a_full_queue_merges_a_continuation_then_drops_the_oldest() {
        let mut q = VecDeque::new();
        let mut p = [0.0f32, 0.1, 0.0];
        // A zig-zag: nothing extends, everything queues until the cap.
        for k in 0..4 {
            let next = [p[0] + 0.2, 0.1, if k % 2 == 0 { 0.3 } else { 0.0 }];
            assert_eq!(push(&mut q, &[], false, sphere(p, next), 4), Push::Queued);
            p = next;
        }
        let next = [p[0] + 0.2, 0.1, 0.3];
        assert_eq!(push(&mut q, &[], false, sphere(p, next), 4), Push::Merged);
        assert_eq!(q.len(), 4);
        assert_eq!(q[3].pose.position, Vec3::from(next));
        let far = sphere([9.0, 0.1, 9.0], [9.5, 0.1, 9.3]);
        assert_eq!(push(&mut q, &[], false, far, 4), Push::DroppedOldest);
        assert_eq!(q.len(), 4);
        assert_eq!(q[3], far);
    }

    #[test]
    fn boxes_are_deduplicated_only_exactly() {
        let shape = Shape::Box {
            half_extents: Vec3::splat(0.1),
        };
        let mut q = VecDeque::new();
        let a = Deformer::moving(shape, Pose::at([0.0, 0.1, 0.0]), Pose::at([0.3, 0.1, 0.0]));
        push(&mut q, &[], false, a, 8);
        assert_eq!(
            push(
                &mut q,
                &[],
                false,
                Deformer::new(shape, Pose::at([0.3, 0.1, 0.0])),
                8
            ),
            Push::Redundant
        );
        assert_eq!(
            push(
                &mut q,
                &[],
                false,
                Deformer::new(shape, Pose::at([0.2, 0.1, 0.0])),
                8
            ),
            Push::Queued
        );
    }
}
