//! People on the mountain: a stand-in walker's straight gait bent onto a path over the ground.
//! The gait is computed along +x on a flat walk plane (`super::super::standin::body::Gait`); each
//! joint is then carried to the path, `x` to the distance along it, `z` across it, and lifted to
//! the ground under that joint plus the snow's top less how far a boot sinks. On a path whose
//! bends are much wider than a stride the body keeps its shape; each foot is planted on the snow
//! under it.

use glam::{Quat, Vec2, Vec3};

use super::super::standin::body::{Gait, Skeleton};

/// A path over the valley: points a quarter metre apart along a Catmull-Rom curve through its
/// control points, and the distance to each.
pub(in crate::scene) struct Path {
    points: Vec<Vec2>,
    distance: Vec<f32>,
    closed: bool,
}

impl Path {
    /// The curve through `controls` (closed: back to the first).
    pub fn through(controls: &[Vec2], closed: bool) -> Self {
        let n = controls.len();
        let at = |i: isize| {
            if closed {
                controls[i.rem_euclid(n as isize) as usize]
            } else {
                controls[i.clamp(0, n as isize - 1) as usize]
            }
        };
        let spans = if closed { n } else { n - 1 };
        let mut points = Vec::new();
        for i in 0..spans as isize {
            let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            let steps = ((p2 - p1).length() / 0.25).ceil().max(1.0) as usize;
            for k in 0..steps {
                let t = k as f32 / steps as f32;
                let (t2, t3) = (t * t, t * t * t);
                points.push(
                    0.5 * (2.0 * p1
                        + (p2 - p0) * t
                        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3),
                );
            }
        }
        points.push(if closed {
            points[0]
        } else {
            at(n as isize - 1)
        });
        let mut distance = vec![0.0];
        for w in points.windows(2) {
            distance.push(distance.last().copied().unwrap_or(0.0) + (w[1] - w[0]).length());
        }
        Self {
            points,
            distance,
            closed,
        }
    }

    /// The path's length, metres.
    pub fn length(&self) -> f32 {
        self.distance.last().copied().unwrap_or(0.0)
    }

    /// The point `s` metres along and the unit direction there (wrapping on a closed path,
    /// clamped on an open one).
    pub fn at(&self, s: f32) -> (Vec2, Vec2) {
        let len = self.length();
        let s = if self.closed {
            s.rem_euclid(len)
        } else {
            s.clamp(0.0, len)
        };
        let i = self
            .distance
            .partition_point(|&d| d <= s)
            .clamp(1, self.points.len() - 1);
        let (a, b) = (self.points[i - 1], self.points[i]);
        let span = (self.distance[i] - self.distance[i - 1]).max(1e-6);
        let u = (s - self.distance[i - 1]) / span;
        (a.lerp(b, u), (b - a).normalize_or(Vec2::X))
    }
}

/// A walker on a path: its straight gait (along +x from the origin) and the path it is bent onto.
pub(in crate::scene) struct Hiker {
    pub(in crate::scene) gait: Gait,
    pub(in crate::scene) path: Path,
    pub(in crate::scene) coat: [f32; 3],
    pub(in crate::scene) trousers: [f32; 3],
}

impl Hiker {
    /// A hiker starting `offset` metres along `path` at `t0`, at `speed` m/s with a stride of
    /// `period` seconds, walking for `seconds`.
    pub fn new(path: Path, offset: f32, speed: f32, t0: f32, seconds: f32) -> Self {
        let period = if speed > 2.0 { 0.72 } else { 1.1 };
        Self {
            gait: Gait {
                start: Vec3::new(offset, 0.0, 0.0),
                dir: Vec3::X,
                speed,
                period,
                stance: if speed > 2.0 { 0.42 } else { 0.62 },
                lift: 0.3,
                t0,
                t1: t0 + seconds,
            },
            path,
            coat: [0.5, 0.12, 0.08],
            trousers: [0.08, 0.08, 0.1],
        }
    }

    /// Where the hiker is along its path at `t` (the pelvis's distance), and the ground point.
    pub fn position(&self, t: f32) -> (Vec2, Vec2) {
        let s = self.gait.skeleton(t).pelvis.x;
        self.path.at(s)
    }

    /// The skeleton at `t` on the path, its walk plane `top(p)` at each joint's `(x, z)`.
    pub fn skeleton(&self, t: f32, top: &impl Fn(Vec2) -> f32) -> Skeleton {
        bend(&self.gait.skeleton(t), &self.path, top)
    }
}

/// Carry a skeleton walked along +x onto `path`: `x` becomes the distance along it, `z` the
/// offset across it (to the right of its direction, as +z is to the right of +x), and `y` the
/// height above the walk plane `top` under the carried point.
pub(in crate::scene) fn bend(s: &Skeleton, path: &Path, top: &impl Fn(Vec2) -> f32) -> Skeleton {
    let carry = |p: Vec3| -> Vec3 {
        let (c, d) = path.at(p.x);
        // +z is +x's right, seen from above: (x, z) -> (-z, x) turned; for d that is (-d.y, d.x).
        let right = Vec2::new(-d.y, d.x);
        let q = c + right * p.z;
        Vec3::new(q.x, top(q) + p.y, q.y)
    };
    let turn = |p: Vec3| -> Quat {
        let (_, d) = path.at(p.x);
        Quat::from_rotation_arc(Vec3::X, Vec3::new(d.x, 0.0, d.y))
    };
    let mut out = *s;
    out.pelvis = carry(s.pelvis);
    out.neck = carry(s.neck);
    out.head = carry(s.head);
    for i in 0..2 {
        out.shoulders[i] = carry(s.shoulders[i]);
        out.elbows[i] = carry(s.elbows[i]);
        out.hands[i] = carry(s.hands[i]);
        out.hips[i] = carry(s.hips[i]);
        out.knees[i] = carry(s.knees[i]);
        out.ankles[i] = carry(s.ankles[i]);
        let (heel, fwd, up) = s.feet[i];
        let q = turn(heel);
        out.feet[i] = (carry(heel), q * fwd, q * up);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_path_wraps_and_measures_its_length() {
        // Four points on a circle of radius 10: the curve passes through each, and is longer
        // than the chords between them (4 x 14.14) and within 5 % of the circle (62.8).
        let c = [
            Vec2::new(10.0, 0.0),
            Vec2::new(0.0, 10.0),
            Vec2::new(-10.0, 0.0),
            Vec2::new(0.0, -10.0),
        ];
        let p = Path::through(&c, true);
        let len = p.length();
        assert!(len > 4.0 * 14.14 && len < 1.05 * 62.83, "{len}");
        assert!((p.at(0.0).0 - c[0]).length() < 1e-4);
        assert!((p.at(len).0 - c[0]).length() < 1e-3);
        assert!((p.at(len + 1.0).0 - p.at(1.0).0).length() < 1e-3);
    }

    #[test]
    fn a_straight_path_carries_the_gait_unchanged_but_for_the_ground() {
        // Along +x from the origin on ground 2 m up, bending moves every joint by 2 m up only.
        let path = Path::through(&[Vec2::ZERO, Vec2::new(100.0, 0.0)], false);
        let h = Hiker::new(path, 0.0, 1.4, 0.0, 30.0);
        for t in [0.3, 5.0, 11.7] {
            let straight = h.gait.skeleton(t);
            let bent = h.skeleton(t, &|_| 2.0);
            assert!((bent.pelvis - straight.pelvis - Vec3::Y * 2.0).length() < 1e-3);
            for i in 0..2 {
                assert!((bent.feet[i].0 - straight.feet[i].0 - Vec3::Y * 2.0).length() < 1e-3);
                assert!((bent.feet[i].1 - straight.feet[i].1).length() < 1e-4);
            }
        }
    }
}
