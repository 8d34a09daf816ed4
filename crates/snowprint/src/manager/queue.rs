//! The imprint queue of one surface: everything that touched it since its last update, so that a
//! surface updated only every few frames still receives every footprint (issue 4's "no imprint is
//! lost").
//!
//! An entry ([`Imprint`]) is a [`Deformer`] as it was in one frame, with its `previous` pose (the
//! swept shape of that frame) and the frame's number. When the surface's turn comes the queue is
//! captured frame by frame, in order (one capture and update per frame that queued something), so
//! the heightmap goes through the same steps as if the surface had been updated every frame.
//!
//! The queue is kept short without changing what it presses:
//! - an entry whose swept shape lies inside one already queued (a foot standing still, or lifted
//!   straight back up the way it came down), or inside one applied at the surface's last update
//!   when no snow falls on it, is redundant and not queued;
//! - an entry whose swept shape holds a queued one replaces it (in its own frame).
//!
//! Moving an entry out of its frame changes what that frame captured together, and the update blurs
//! each frame's capture as a whole: two prints within the blur's reach of each other (a texel) in
//! one frame press deeper between them than either does alone. So an entry leaves its frame only
//! when it is isolated there, no other entry of that frame within [`Isolation::reach`] of its
//! sweep (dropping `d` from this tick needs it apart from this tick's other deformers; absorbing a
//! queued entry needs it apart from the other entries of its frame). Within one frame both are
//! always exact: the frame's capture is the union of its entries.
//!
//! Nothing is ever dropped. A surface updated in a frame takes its whole queue, however long.
//! Only the queue of a surface that waits (for the budget or for memory) is bounded, by
//! [`crate::manager::ManagerConfig::queue_cap`]: past it, [`bound`] merges neighbouring entries
//! into one sphere swept along a segment whose capsule holds both (conservative: what it keeps
//! presses at least everywhere the merged entries pressed, and a little more around them).

use std::collections::VecDeque;

use glam::Vec3;

use crate::deformer::{Deformer, Pose, Shape};

/// How many of the newest queued entries a push compares itself with.
pub const SCAN: usize = 8;

/// Distance, metres, under which two points are taken as the same in containment and straightness
/// tests (0.001 mm: far below a texel and below 1 unit of depression for any usable snow depth).
pub const EPS: f32 = 1e-6;

/// One queued entry: what pressed a surface in one frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Imprint {
    /// The tick it was queued in (captured with the other imprints of that tick).
    pub frame: u64,
    /// The shape, its pose and its previous pose.
    pub deformer: Deformer,
}

/// What a push did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Push {
    /// Appended.
    Queued,
    /// Already covered by a queued or just-applied entry: nothing to add.
    Redundant,
    /// Replaced a queued entry it holds.
    Absorbed,
}

/// The bounds of an entry's swept shape: a ball of radius `r` swept from `a` to `b`.
pub type Sweep = (Vec3, Vec3, f32);

/// What a push needs to know to move an entry out of its frame exactly (see the module docs).
pub struct Isolation<'a> {
    /// The sweeps of every deformer of this tick.
    pub tick: &'a [Sweep],
    /// Which of them is the one pushed.
    pub index: usize,
    /// The sweep of a queued entry.
    pub sweep: &'a dyn Fn(&Deformer) -> Sweep,
    /// Distance, metres, within which two prints of one frame interact through the blur.
    pub reach: f32,
}

impl Isolation<'_> {
    /// Whether the pushed deformer is apart from the tick's other deformers.
    fn pushed_alone(&self) -> bool {
        let me = self.tick[self.index];
        self.tick
            .iter()
            .enumerate()
            .all(|(k, &o)| k == self.index || !near(me, o, self.reach))
    }

    /// Whether the queued entry at `i` is apart from the other entries of its frame.
    fn queued_alone(&self, queue: &VecDeque<Imprint>, i: usize) -> bool {
        let me = (self.sweep)(&queue[i].deformer);
        queue.iter().enumerate().all(|(k, e)| {
            k == i || e.frame != queue[i].frame || !near(me, (self.sweep)(&e.deformer), self.reach)
        })
    }
}

/// Whether two sweeps come within `reach` of each other.
fn near(x: Sweep, y: Sweep, reach: f32) -> bool {
    segment_distance((x.0, x.1), (y.0, y.1)) <= x.2 + y.2 + reach
}

/// Distance between the segments `p.0..p.1` and `q.0..q.1` (closest points, clamped to both).
fn segment_distance(p: (Vec3, Vec3), q: (Vec3, Vec3)) -> f32 {
    let (d1, d2, r) = (p.1 - p.0, q.1 - q.0, p.0 - q.0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let (s, t) = if a <= EPS * EPS && e <= EPS * EPS {
        (0.0, 0.0)
    } else if a <= EPS * EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= EPS * EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p.0 + d1 * s).distance(q.0 + d2 * t)
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
/// either end of the other's sweep or an identical entry; for meshes (drawn at sub-steps along
/// their motion, always at its end, not at its start), the same entry or one resting where the
/// other's motion ends. A re-posed mesh has a new [`crate::MeshId`] in the queue (see
/// [`crate::manager::SnowManager::pose_mesh`]), so its new posture is never taken for the old.
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
        Shape::Mesh(_) => {
            outer == inner || (start(inner) == inner.pose && inner.pose == outer.pose)
        }
        _ => {
            if outer == inner || (start(outer) == start(inner) && outer.pose == inner.pose) {
                return true;
            }
            let resting = start(inner) == inner.pose;
            resting && (inner.pose == start(outer) || inner.pose == outer.pose)
        }
    }
}

/// Push one frame's deformer into a surface's queue. `applied` is what the surface's last update
/// captured; it is consulted only when `skip_applied` (no snowfall on the surface, so pressing the
/// same shape again cannot change the heightmap). An entry leaves its frame only when `isolation`
/// says it is alone there (see the module docs). Nothing is dropped: see [`bound`] for how a
/// waiting surface's queue is kept short.
pub fn push(
    queue: &mut VecDeque<Imprint>,
    applied: &[Deformer],
    skip_applied: bool,
    frame: u64,
    d: Deformer,
    isolation: &Isolation<'_>,
) -> Push {
    let scan_from = queue.len().saturating_sub(SCAN);
    // Whether `d` may leave this tick (be dropped as held by an entry of another frame): asked
    // only of a push that could be dropped, and at most once (it compares `d` with the tick's
    // every deformer).
    let alone_once = std::cell::OnceCell::new();
    let alone = || *alone_once.get_or_init(|| isolation.pushed_alone());
    let may_drop = |q: &Imprint| q.frame == frame || alone();
    // The common case first, by exact comparison: a deformer resting where a queued sweep of the
    // same shape ends or starts (a planted foot), or the same entry again.
    let resting = start(&d) == d.pose;
    if queue
        .range(scan_from..)
        .rev()
        .any(|q| covers_exactly(&q.deformer, &d, resting) && may_drop(q))
        || (skip_applied
            && alone()
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
        if q.deformer.shape != d.shape {
            continue;
        }
        if contains(&q.deformer, &d) && may_drop(q) {
            return Push::Redundant;
        }
        if contains(&d, &q.deformer) && (q.frame == frame || isolation.queued_alone(queue, i)) {
            // It presses all the held entry did: the held one goes, `d` is queued in its frame.
            queue.remove(i);
            queue.push_back(Imprint { frame, deformer: d });
            return Push::Absorbed;
        }
    }
    if skip_applied && applied.iter().rev().take(SCAN).any(|q| contains(q, &d)) && alone() {
        return Push::Redundant;
    }
    queue.push_back(Imprint { frame, deformer: d });
    Push::Queued
}

/// The capsule `(a, b, radius)` that holds an entry's swept shape, given the radius of a ball
/// around the shape's origin that holds the shape.
fn capsule(d: &Deformer, radius: f32) -> (Vec3, Vec3, f32) {
    (start(d).position, d.pose.position, radius)
}

/// A sphere swept along a segment whose capsule holds both capsules. The capsule around a segment
/// is convex and a point's distance to a segment is convex along another segment, so holding both
/// ends of each capsule's segment (with their radii) holds the capsules.
fn cover(a: (Vec3, Vec3, f32), b: (Vec3, Vec3, f32)) -> (Vec3, Vec3, f32) {
    let ends = [(a.0, a.2), (a.1, a.2), (b.0, b.2), (b.1, b.2)];
    let (mut p, mut q, mut far) = (a.0, a.1, -1.0);
    for i in 0..4 {
        for j in i + 1..4 {
            let d = ends[i].0.distance_squared(ends[j].0);
            if d > far {
                (p, q, far) = (ends[i].0, ends[j].0, d);
            }
        }
    }
    let r = ends
        .iter()
        .map(|&(v, r)| point_segment_distance(v, p, q) + r)
        .fold(0.0, f32::max);
    // Rounding must never make the cover smaller than what it holds.
    (p, q, r * (1.0 + 1e-6) + EPS)
}

/// Volume of a capsule: what a merge adds is judged by it.
fn capsule_volume(c: (Vec3, Vec3, f32)) -> f32 {
    let r = c.2;
    std::f32::consts::PI * r * r * (c.0.distance(c.1) + 4.0 / 3.0 * r)
}

/// Keep a waiting surface's queue to at most `cap` entries (once past it, merging down to three
/// quarters of it) by merging neighbours (in queue order,
/// which is the order of the frames) into covering swept spheres, cheapest first (the least added
/// capsule volume). `radius` gives the radius of a ball holding a shape around its origin (for
/// meshes, their registered bound). Returns the number of merges; every merged entry is held by
/// what replaces it, so nothing it pressed is lost.
pub fn bound(queue: &mut VecDeque<Imprint>, cap: usize, radius: impl Fn(&Shape) -> f32) -> usize {
    let cap = cap.max(1);
    if queue.len() <= cap {
        return 0;
    }
    // Down to three quarters of the cap, so that a queue that keeps growing is merged once every
    // `cap / 4` pushes rather than at every push.
    let target = (cap - cap / 4).max(1);
    let mut merges = 0;
    while queue.len() > target {
        let caps: Vec<(Vec3, Vec3, f32)> = queue
            .iter()
            .map(|d| capsule(&d.deformer, radius(&d.deformer.shape)))
            .collect();
        // The cost of merging each neighbour pair, cheapest first.
        let mut pairs: Vec<(f32, usize)> = (0..caps.len() - 1)
            .map(|i| {
                let c = cover(caps[i], caps[i + 1]);
                let cost =
                    capsule_volume(c) - capsule_volume(caps[i]) - capsule_volume(caps[i + 1]);
                (cost, i)
            })
            .collect();
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        // Merge disjoint pairs, as many as needed (at most half the queue each round).
        let mut need = queue.len() - target;
        let mut taken = vec![false; caps.len()];
        let mut merged: Vec<Option<(Vec3, Vec3, f32)>> = vec![None; caps.len()];
        for &(_, i) in &pairs {
            if need == 0 {
                break;
            }
            if taken[i] || taken[i + 1] {
                continue;
            }
            taken[i] = true;
            taken[i + 1] = true;
            merged[i] = Some(cover(caps[i], caps[i + 1]));
            need -= 1;
            merges += 1;
        }
        let old: Vec<Imprint> = std::mem::take(queue).into();
        let mut skip = false;
        for (i, d) in old.iter().enumerate() {
            if skip {
                skip = false;
                continue;
            }
            if let Some((a, b, r)) = merged[i] {
                // In the later frame: the queue stays in frame order.
                queue.push_back(Imprint {
                    frame: old[i + 1].frame,
                    deformer: Deformer::moving(
                        Shape::Sphere { radius: r },
                        Pose::at(a.to_array()),
                        Pose::at(b.to_array()),
                    ),
                });
                skip = true;
            } else {
                queue.push_back(*d);
            }
        }
    }
    merges
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(from: [f32; 3], to: [f32; 3]) -> Deformer {
        Deformer::moving(Shape::Sphere { radius: 0.1 }, Pose::at(from), Pose::at(to))
    }

    fn sweep(d: &Deformer) -> Sweep {
        let r = d.shape.bounding_radius().unwrap_or(1e6);
        (start(d).position, d.pose.position, r)
    }

    /// Push `d` as the only deformer of its tick.
    fn push(
        q: &mut VecDeque<Imprint>,
        applied: &[Deformer],
        skip: bool,
        frame: u64,
        d: Deformer,
    ) -> Push {
        push_among(q, applied, skip, frame, d, &[])
    }

    /// Push `d` in a tick whose other deformers are `others`.
    fn push_among(
        q: &mut VecDeque<Imprint>,
        applied: &[Deformer],
        skip: bool,
        frame: u64,
        d: Deformer,
        others: &[Deformer],
    ) -> Push {
        let tick: Vec<Sweep> = std::iter::once(&d).chain(others).map(sweep).collect();
        let isolation = Isolation {
            tick: &tick,
            index: 0,
            sweep: &sweep,
            reach: 0.08,
        };
        super::push(q, applied, skip, frame, d, &isolation)
    }

    /// A second deformer within the blur's reach in this tick keeps `d` in its frame, and one
    /// within reach of a queued entry in that entry's frame keeps the entry there; apart, both
    /// leave as before.
    #[test]
    fn an_entry_leaves_its_frame_only_when_alone_there() {
        let planted = sphere([0.0, 0.1, 0.0], [0.0, 0.1, 0.0]);
        let neighbour = sphere([0.25, 0.1, 0.0], [0.25, 0.1, 0.0]);
        let far = sphere([3.0, 0.1, 0.0], [3.0, 0.1, 0.0]);
        // A foot planted in tick 1 where tick 0's sweep ended: redundant alone or beside a far
        // ball, kept beside a near one (0.25 m apart: 0.05 m between the balls, within 0.08 m).
        let step_down = sphere([-0.2, 0.1, 0.0], [0.0, 0.1, 0.0]);
        for (other, expect) in [(far, Push::Redundant), (neighbour, Push::Queued)] {
            let mut q = VecDeque::new();
            assert_eq!(push(&mut q, &[], false, 0, step_down), Push::Queued);
            assert_eq!(push_among(&mut q, &[], false, 1, planted, &[other]), expect);
        }
        // A sweep in tick 1 that holds tick 0's entry absorbs it only if nothing of tick 0 lies
        // within reach of it.
        let sweep_on = sphere([0.0, 0.1, 0.0], [-0.2, 0.1, 0.0]);
        for (other, expect) in [(far, Push::Absorbed), (neighbour, Push::Queued)] {
            let mut q = VecDeque::new();
            assert_eq!(
                push_among(&mut q, &[], false, 0, planted, &[other]),
                Push::Queued
            );
            assert_eq!(
                push_among(&mut q, &[], false, 0, other, &[planted]),
                Push::Queued
            );
            assert_eq!(push(&mut q, &[], false, 1, sweep_on), expect);
        }
    }

    #[test]
    fn segment_distances_computed_by_hand() {
        let seg = |a: [f32; 3], b: [f32; 3]| (Vec3::from(a), Vec3::from(b));
        // Parallel, 1 m apart; crossing at right angles 2 m apart in y; point to segment.
        let d = segment_distance(
            seg([0.0; 3], [1.0, 0.0, 0.0]),
            seg([0.0, 0.0, 1.0], [1.0, 0.0, 1.0]),
        );
        assert!((d - 1.0).abs() < 1e-6, "{d}");
        let d = segment_distance(
            seg([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
            seg([0.0, 2.0, -1.0], [0.0, 2.0, 1.0]),
        );
        assert!((d - 2.0).abs() < 1e-6, "{d}");
        let d = segment_distance(
            seg([3.0, 4.0, 0.0], [3.0, 4.0, 0.0]),
            seg([0.0; 3], [1.0, 0.0, 0.0]),
        );
        assert!((d - (4.0f32 * 4.0 + 2.0 * 2.0).sqrt()).abs() < 1e-6, "{d}");
    }

    #[test]
    fn standing_still_and_lifting_back_are_redundant() {
        let mut q = VecDeque::new();
        let down = sphere([0.0, 1.0, 0.0], [0.0, 0.1, 0.0]);
        assert_eq!(push(&mut q, &[], false, 0, down), Push::Queued);
        let still = Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[], false, 0, still), Push::Redundant);
        let up = sphere([0.0, 0.1, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(push(&mut q, &[], false, 0, up), Push::Redundant);
        assert_eq!(q.len(), 1);
        // A different radius is a different shape.
        let big = Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[], false, 0, big), Push::Queued);
    }

    #[test]
    fn applied_entries_are_skipped_only_without_snowfall() {
        let mut q = VecDeque::new();
        let still = Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at([0.0, 0.1, 0.0]));
        assert_eq!(push(&mut q, &[still], true, 0, still), Push::Redundant);
        assert_eq!(push(&mut q, &[still], false, 0, still), Push::Queued);
    }

    #[test]
    fn each_frame_of_a_motion_keeps_its_own_entry_and_a_held_entry_moves_to_its_holder() {
        let mut q = VecDeque::new();
        for k in 0..10u64 {
            let x = k as f32 * 0.25;
            let d = sphere([x, 0.1, 0.0], [x + 0.25, 0.1, 0.0]);
            assert_eq!(push(&mut q, &[], false, k, d), Push::Queued);
        }
        assert_eq!(q.len(), 10);
        assert!(q.iter().enumerate().all(|(k, e)| e.frame == k as u64));
        // A sweep over the last two frames' path holds their entries... only the newest one is
        // compared first, and is replaced in the holder's frame (the queue stays in frame order).
        let long = sphere([2.25, 0.1, 0.0], [2.5, 0.1, 0.0]);
        assert_eq!(push(&mut q, &[], false, 10, long), Push::Redundant);
        let longer = sphere([2.0, 0.1, 0.0], [3.0, 0.1, 0.0]);
        assert_eq!(push(&mut q, &[], false, 11, longer), Push::Absorbed);
        assert_eq!(q.back().unwrap().frame, 11);
        assert!(
            q.iter()
                .zip(q.iter().skip(1))
                .all(|(a, b)| a.frame <= b.frame)
        );
    }

    /// Whether `p` lies in the capsule of a queue entry (a swept sphere) or of a resting sphere.
    fn in_capsule(d: &Deformer, r: f32, p: Vec3) -> bool {
        point_segment_distance(p, start(d).position, d.pose.position) <= r
    }

    #[test]
    fn bounding_a_queue_merges_neighbours_into_covers_and_loses_nothing() {
        let mut q = VecDeque::new();
        let mut p = [0.0f32, 0.1, 0.0];
        // A zig-zag: nothing extends, everything queues.
        for k in 0..40 {
            let next = [p[0] + 0.2, 0.1, if k % 2 == 0 { 0.3 } else { 0.0 }];
            assert_eq!(push(&mut q, &[], false, 0, sphere(p, next)), Push::Queued);
            p = next;
        }
        let before: Vec<Deformer> = q.iter().map(|e| e.deformer).collect();
        let radius = |s: &Shape| s.bounding_radius().unwrap();
        let merges = bound(&mut q, 8, radius);
        assert_eq!(q.len(), 6, "down to three quarters of the cap");
        assert_eq!(merges, 34);
        // Every point of every original capsule (sampled along it and around it) is inside a kept
        // entry's capsule.
        for d in &before {
            for k in 0..=20 {
                let t = k as f32 / 20.0;
                let c = start(d).position.lerp(d.pose.position, t);
                for off in [
                    Vec3::X,
                    -Vec3::X,
                    Vec3::Y,
                    -Vec3::Y,
                    Vec3::Z,
                    -Vec3::Z,
                    Vec3::ZERO,
                ] {
                    let pt = c + off * 0.1;
                    assert!(
                        q.iter()
                            .any(|e| in_capsule(&e.deformer, radius(&e.deformer.shape), pt)),
                        "{pt} of {d:?} is not covered"
                    );
                }
            }
        }
        // Within the cap, nothing changes.
        let kept: Vec<Imprint> = q.iter().copied().collect();
        assert_eq!(bound(&mut q, 8, radius), 0);
        assert_eq!(q.iter().copied().collect::<Vec<_>>(), kept);
    }

    #[test]
    fn a_cover_holds_two_capsules_computed_by_hand() {
        // Two unit-radius resting balls 4 m apart: the cover runs between their centres, radius 1.
        let (a, b, r) = cover(
            (Vec3::ZERO, Vec3::ZERO, 1.0),
            (Vec3::new(4.0, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0), 1.0),
        );
        assert_eq!((a, b), (Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0)));
        assert!((r - 1.0).abs() < 1e-5, "{r}");
        // A segment 0..4 along x (radius 0.5) and a ball of 0.2 at (2, 0, 1): the cover keeps the
        // segment and grows to hold the ball, 1 + 0.2.
        let (a, b, r) = cover(
            (Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), 0.5),
            (Vec3::new(2.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0), 0.2),
        );
        assert_eq!((a, b), (Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0)));
        assert!((r - 1.2).abs() < 1e-5, "{r}");
    }

    #[test]
    fn a_mesh_entry_is_held_only_by_the_same_motion_or_at_its_end() {
        let shape = Shape::Mesh(crate::mesh::MeshId(0));
        let a = Deformer::moving(shape, Pose::at([0.0, 0.0, 0.0]), Pose::at([1.0, 0.0, 0.0]));
        let b = Deformer::moving(shape, Pose::at([0.0, 0.0, 5.0]), Pose::at([1.0, 0.0, 0.0]));
        // The same end pose by another path is a different imprint.
        assert!(!contains(&a, &b));
        assert!(contains(&a, &a));
        assert!(contains(
            &a,
            &Deformer::new(shape, Pose::at([1.0, 0.0, 0.0]))
        ));
        // The start of a mesh's motion is not drawn by its entry.
        assert!(!contains(
            &a,
            &Deformer::new(shape, Pose::at([0.0, 0.0, 0.0]))
        ));
    }

    #[test]
    fn boxes_are_deduplicated_only_exactly() {
        let shape = Shape::Box {
            half_extents: Vec3::splat(0.1),
        };
        let mut q = VecDeque::new();
        let a = Deformer::moving(shape, Pose::at([0.0, 0.1, 0.0]), Pose::at([0.3, 0.1, 0.0]));
        push(&mut q, &[], false, 0, a);
        assert_eq!(
            push(
                &mut q,
                &[],
                false,
                0,
                Deformer::new(shape, Pose::at([0.3, 0.1, 0.0]))
            ),
            Push::Redundant
        );
        assert_eq!(
            push(
                &mut q,
                &[],
                false,
                0,
                Deformer::new(shape, Pose::at([0.2, 0.1, 0.0]))
            ),
            Push::Queued
        );
    }
}
