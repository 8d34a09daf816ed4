//! Procedural animation: joint angles as functions of time.
//!
//! A person's [`Motion`] is a list of [`Segment`]s, each running one [`Action`] from its start time
//! until the next one starts; the first moments of a segment blend out of the pose the previous
//! one ended in. Actions:
//!
//! * [`Gait`]: walking, running, or the shuffling of fighters. Feet follow a plan of
//!   [`Footfall`]s: each foot strikes heel first (pitched up, rolling flat about the heel), stays
//!   flat, rolls onto the ball (heel up) and leaves; in between it swings along a high arc that
//!   clears the ankle-high capture zone, so that prints stay separate. The pelvis follows a path;
//!   the legs reach the feet through a two-bone solver; the arms swing against the legs.
//! * [`Topple`]: teetering, then falling backwards like a plank about the heels, optionally off a
//!   ledge in free fall, landing flat on the back.
//! * [`Slide`]: a feet-first slide on the back, decelerating to a stop.
//! * [`Angel`]: lying on the back, sweeping arms and legs open and closed.

use std::f32::consts::{PI, TAU};

use glam::{Quat, Vec2, Vec3};

use super::skeleton::{BodyPose, Part, Side, abduct, dims, flex, solve_leg};

mod ground;

pub use ground::{ANGEL_ARMS, ANGEL_LEGS, Angel, LYING_HEIGHT, Slide, Topple};

/// Standard gravity, m/s².
pub const GRAVITY: f32 = 9.81;

/// `0..1` easing with zero slope at both ends.
pub fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Rotation about world `+Y` that turns the body's forward axis (`+X`) to heading `yaw`.
pub fn yaw_rotation(yaw: f32) -> Quat {
    Quat::from_rotation_y(yaw)
}

/// The heading (yaw) that faces along a horizontal direction `(x, z)`.
pub fn yaw_of(dir: Vec2) -> f32 {
    (-dir.y).atan2(dir.x)
}

/// The horizontal unit vector a heading faces.
pub fn forward_of(yaw: f32) -> Vec3 {
    Vec3::new(yaw.cos(), 0.0, -yaw.sin())
}

/// The horizontal unit vector to the right of a heading.
pub fn right_of(yaw: f32) -> Vec3 {
    Vec3::new(yaw.sin(), 0.0, yaw.cos())
}

/// Shortest signed difference `b - a` between two angles.
fn angle_diff(a: f32, b: f32) -> f32 {
    (b - a + PI).rem_euclid(TAU) - PI
}

/// One foot planted once: from the heel strike to the toe leaving.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footfall {
    /// Which foot.
    pub side: Side,
    /// Time the heel touches down (`-inf` for a foot already standing when the gait starts).
    pub strike: f32,
    /// Time the toe leaves (`+inf` for a foot that stays).
    pub lift: f32,
    /// World position of the ankle while the foot is flat.
    pub ankle: Vec3,
    /// Heading of the foot.
    pub yaw: f32,
}

impl Footfall {
    /// World position of the middle of the sole (the centre of the print it leaves), on the sole
    /// plane.
    pub fn print_center(&self) -> Vec3 {
        let mid = 0.5 * (dims::BALL_FORWARD - dims::HEEL_BACK);
        self.ankle + forward_of(self.yaw) * mid - Vec3::Y * dims::ANKLE_HEIGHT
    }
}

/// A point of a pelvis path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathKey {
    /// Time, seconds.
    pub time: f32,
    /// Pelvis position (the height is the ground under it plus the gait's hip height).
    pub position: Vec3,
    /// Heading.
    pub yaw: f32,
}

/// How far ahead of or behind the pelvis a planted ankle may be, metres: well inside the legs'
/// reach at the gaits' hip heights.
const REACH: f32 = 0.3;

/// How a gait looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaitStyle {
    /// Pelvis centre above the ground when standing in this gait, metres.
    pub hip_height: f32,
    /// How far the pelvis dips at each heel strike, metres.
    pub bob: f32,
    /// Forward lean of the torso, radians.
    pub lean: f32,
    /// Peak lift of the ankle on a swing, metres.
    pub swing_height: f32,
    /// Fraction of the swing by which the foot is over its next print (it then steps down): low
    /// values swing the knee up and forward, as in a march.
    pub lead: f32,
    /// Pitch of the foot (toes up) at the heel strike, radians.
    pub heel_strike: f32,
    /// Pitch of the foot (heel up) when the toe leaves, radians.
    pub toe_off: f32,
    /// How much deeper than the flat foot the heel presses at the strike, metres.
    pub heel_dig: f32,
    /// How much deeper than the flat foot the ball and toes press at the push-off, metres.
    pub toe_dig: f32,
    /// How far the foot skids forward from the heel strike until it is flat, metres: it touches
    /// down this far behind where it comes to rest, so that a fast foot's print is longer.
    pub slip: f32,
    /// Height of the flat sole above the ground under the snow, metres (how far the flat foot
    /// sinks).
    pub sole: f32,
    /// Arm swing, radians of shoulder flexion per metre the opposite foot is ahead.
    pub arm_swing: f32,
    /// Elbow flexion, radians.
    pub elbow: f32,
    /// Fists up (a fighter's guard) instead of swinging arms.
    pub guard: bool,
}

impl GaitStyle {
    /// Trudging through deep snow: short steps, knees high so that each foot leaves the
    /// ankle-high zone between prints. The weight stops on 7 cm of compacted snow, so that the
    /// boot's heel, arch and ball show in the print rather than one hole to the ground.
    pub fn trudge() -> Self {
        Self {
            hip_height: 0.88,
            bob: 0.02,
            lean: 0.10,
            swing_height: 0.46,
            lead: 0.62,
            heel_strike: 0.35,
            toe_off: 0.55,
            heel_dig: 0.02,
            toe_dig: 0.02,
            slip: 0.0,
            sole: 0.07,
            arm_swing: 0.9,
            elbow: 0.35,
            guard: false,
        }
    }

    /// Running: long strides, flight phases, heels kicked high.
    pub fn run() -> Self {
        Self {
            hip_height: 0.9,
            bob: 0.04,
            lean: 0.22,
            swing_height: 0.5,
            lead: 0.88,
            // A runner lands lightly on the heel, skids 12 cm, and pushes off hard from the ball:
            // the flat foot stops 6 cm above the ground, the ball digs down to it.
            heel_strike: 0.2,
            toe_off: 0.7,
            heel_dig: 0.0,
            toe_dig: 0.06,
            slip: 0.12,
            sole: 0.06,
            arm_swing: 1.1,
            elbow: 1.5,
            guard: false,
        }
    }

    /// A fighter's stance: knees bent, fists up, low shuffling steps.
    pub fn fighter() -> Self {
        Self {
            hip_height: 0.86,
            bob: 0.015,
            lean: 0.12,
            swing_height: 0.16,
            lead: 0.7,
            heel_strike: 0.15,
            toe_off: 0.35,
            heel_dig: 0.02,
            toe_dig: 0.02,
            slip: 0.0,
            sole: 0.02,
            arm_swing: 0.0,
            elbow: 2.1,
            guard: true,
        }
    }
}

/// A moment when a fighter's arms strike out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strike {
    /// Time of full extension.
    pub time: f32,
    /// The arm (`None`: both arms shove).
    pub side: Option<Side>,
}

/// Walking, running or shuffling: a plan of footfalls and a pelvis path.
#[derive(Clone, Debug, PartialEq)]
pub struct Gait {
    /// Every footfall, each side's in time order; each side's first one has `strike = -inf`.
    pub footfalls: Vec<Footfall>,
    /// The pelvis path, in time order.
    pub path: Vec<PathKey>,
    /// How it looks.
    pub style: GaitStyle,
    /// Punches and shoves (fighters).
    pub strikes: Vec<Strike>,
}

/// Parameters of [`Gait::plan`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    /// When the first foot lifts.
    pub start: f32,
    /// When the path stops; the last steps bring the feet together under it.
    pub end: f32,
    /// Time between consecutive heel strikes (of alternate feet).
    pub step_time: f32,
    /// Fraction of a stride each foot is on the ground (above 0.5: walking, below: running).
    pub duty: f32,
    /// Ankles either side of the path, metres.
    pub lateral: f32,
    /// Left foot ahead of the path by this much, right foot behind (a fighter's stance).
    pub stagger: f32,
    /// Shortest distance between consecutive prints of one foot, metres (0: no limit).
    pub min_stride: f32,
    /// The foot that moves first.
    pub first: Side,
    /// World height of the ground under the snow.
    pub ground: f32,
}

impl Gait {
    /// Plan footfalls along a pelvis path `path(t) -> (horizontal position (x, z), heading)`: each
    /// foot lands where the path will be at the middle of its stance, beside it, so that the pelvis
    /// passes over every foot. Before `plan.start` both feet stand under the path's start; the
    /// path is sampled every 50 ms.
    pub fn plan(plan: StepPlan, style: GaitStyle, path: &dyn Fn(f32) -> (Vec2, f32)) -> Gait {
        let t_of = |t: f32| t.clamp(plan.start, plan.end);
        let place = |side: Side, t: f32| {
            let (p, yaw) = path(t_of(t));
            let lateral = right_of(yaw) * side.sign() * plan.lateral;
            let stagger = forward_of(yaw) * -side.sign() * plan.stagger;
            let ankle = Vec3::new(p.x, plan.ground + style.sole + dims::ANKLE_HEIGHT, p.y)
                + lateral
                + stagger;
            (ankle, yaw)
        };
        let stride = 2.0 * plan.step_time;
        let swing = (1.0 - plan.duty) * stride;
        let stance = plan.duty * stride;
        let mut footfalls = Vec::new();
        // Both feet standing at the start; the first foot lifts at `start`, the other one step
        // later.
        for (side, lift) in [
            (plan.first, plan.start),
            (plan.first.other(), plan.start + plan.step_time),
        ] {
            let (ankle, yaw) = place(side, plan.start);
            footfalls.push(Footfall {
                side,
                strike: f32::NEG_INFINITY,
                lift,
                ankle,
                yaw,
            });
        }
        let mut done = [false; 2];
        let mut previous: [Option<Vec3>; 2] = [None; 2];
        for f in &footfalls {
            previous[(f.side == Side::Left) as usize] = Some(f.ankle);
        }
        let (end_right, _) = place(Side::Right, plan.end);
        let (end_left, end_yaw) = place(Side::Left, plan.end);
        let mut k = 0u32;
        while !(done[0] && done[1]) {
            let strike = plan.start + swing + k as f32 * plan.step_time;
            let side = if k.is_multiple_of(2) {
                plan.first
            } else {
                plan.first.other()
            };
            k += 1;
            let s = (side == Side::Left) as usize;
            if done[s] {
                continue;
            }
            let mut strike = strike;
            let lift = strike + stance;
            let (mut ankle, mut yaw) = place(side, strike + 0.5 * stance);
            let stop = if side == Side::Right {
                end_right
            } else {
                end_left
            };
            // A foot whose next swing would start after the path ends, or that would land
            // within a stride of where the feet stop, lands there and stays.
            let last = lift > plan.end || ankle.distance(stop) < plan.min_stride;
            if last {
                ankle = stop;
                yaw = end_yaw;
                // Land only once the pelvis has come within reach of the spot.
                let (goal, _) = path(plan.end);
                while strike < plan.end && path(strike).0.distance(goal) > REACH {
                    strike += 0.01;
                }
            } else if let Some(prev) = previous[s] {
                // No step shorter than `min_stride`, so that prints stay apart when starting.
                let fwd = forward_of(yaw);
                let along = (ankle - prev).dot(fwd);
                if along < plan.min_stride {
                    ankle += fwd * (plan.min_stride - along);
                }
            }
            previous[s] = Some(ankle);
            done[s] = last;
            footfalls.push(Footfall {
                side,
                strike,
                lift: if last { f32::INFINITY } else { lift },
                ankle,
                yaw,
            });
        }
        let mut path_keys = Vec::new();
        let mut t = plan.start - 0.05;
        while t <= plan.end + 0.1 {
            let (p, yaw) = path(t_of(t));
            path_keys.push(PathKey {
                time: t,
                position: Vec3::new(p.x, plan.ground + style.hip_height, p.y),
                yaw,
            });
            t += 0.05;
        }
        Gait {
            footfalls,
            path: path_keys,
            style,
            strikes: Vec::new(),
        }
    }

    /// Pelvis position and heading on the path at `t` (held before the first and after the last
    /// key).
    fn path_at(&self, t: f32) -> (Vec3, f32) {
        let keys = &self.path;
        let Some(first) = keys.first() else {
            return (Vec3::ZERO, 0.0);
        };
        if t <= first.time {
            return (first.position, first.yaw);
        }
        for w in keys.windows(2) {
            let (a, b) = (w[0], w[1]);
            if t <= b.time {
                let u = (t - a.time) / (b.time - a.time).max(1e-6);
                return (
                    a.position.lerp(b.position, u),
                    a.yaw + angle_diff(a.yaw, b.yaw) * u,
                );
            }
        }
        let last = keys[keys.len() - 1];
        (last.position, last.yaw)
    }

    /// The footfalls of one side, in time order.
    fn side_footfalls(&self, side: Side) -> impl Iterator<Item = &Footfall> {
        self.footfalls.iter().filter(move |f| f.side == side)
    }

    /// Ankle position and foot rotation of a planted foot at `t` (heel roll, flat, toe roll).
    fn stance_foot(&self, f: &Footfall, t: f32) -> (Vec3, Quat) {
        let s = &self.style;
        let yaw = yaw_rotation(f.yaw);
        let stance = if f.strike.is_finite() && f.lift.is_finite() {
            f.lift - f.strike
        } else {
            0.6
        };
        let heel_roll = (0.3 * stance).min(0.15);
        let toe_roll = (0.35 * stance).min(0.2);
        let heel = Vec3::new(-dims::HEEL_BACK, -dims::ANKLE_HEIGHT, 0.0);
        let ball = Vec3::new(dims::BALL_FORWARD, -dims::ANKLE_HEIGHT, 0.0);
        // Rotate the foot by `pitch` about a contact point of the flat foot, pressed `dig` deeper.
        let about = |contact: Vec3, pitch: f32, dig: f32| {
            let rot = yaw * flex(pitch);
            let world_contact = f.ankle + yaw * contact - Vec3::Y * dig;
            (world_contact - rot * contact, rot)
        };
        if f.strike.is_finite() && t < f.strike + heel_roll {
            let u = smoothstep((t - f.strike) / heel_roll);
            let (ankle, rot) = about(heel, s.heel_strike * (1.0 - u), s.heel_dig * (1.0 - u));
            return (ankle - forward_of(f.yaw) * (s.slip * (1.0 - u)), rot);
        }
        if f.lift.is_finite() && t > f.lift - toe_roll {
            let along = ((t - (f.lift - toe_roll)) / toe_roll).clamp(0.0, 1.0);
            // The ball is pressed in fully by the first third of the roll and stays in while the
            // heel rises, so that a frame samples the deepest push-off even in a runner's brief
            // one (60 ms: two frames at 30 Hz).
            return about(
                ball,
                -s.toe_off * smoothstep(along),
                s.toe_dig * smoothstep(3.0 * along),
            );
        }
        (f.ankle, yaw)
    }

    /// Ankle position and foot rotation of one foot at `t`.
    pub fn foot_at(&self, side: Side, t: f32) -> (Vec3, Quat) {
        let mut prev: Option<&Footfall> = None;
        for f in self.side_footfalls(side) {
            if f.strike > t {
                let Some(p) = prev else {
                    return self.stance_foot(f, t);
                };
                // Swinging from `p` to `f`.
                let (a0, r0) = self.stance_foot(p, p.lift);
                let (a1, r1) = self.stance_foot(f, f.strike);
                let span = (f.strike - p.lift).max(1e-3);
                let s = ((t - p.lift) / span).clamp(0.0, 1.0);
                // Up first, across while high, down last: horizontal motion only once the foot
                // is well above the snow.
                let across = smoothstep((s - 0.1) / (self.style.lead - 0.1).max(0.05));
                let bump = 1.0 - (2.0 * s - 1.0).abs().powi(6);
                let mut ankle = a0.lerp(a1, across);
                ankle.y = a0.y + (a1.y - a0.y) * s + self.style.swing_height * bump;
                // Turn only once clear of the snow, so that the toe does not scrape forward.
                let rot = r0.slerp(r1, smoothstep((s - 0.1) / 0.8)).normalize();
                return (ankle, rot);
            }
            if t <= f.lift {
                return self.stance_foot(f, t);
            }
            prev = Some(f);
        }
        match prev {
            Some(p) => self.stance_foot(p, p.lift),
            None => (Vec3::ZERO, Quat::IDENTITY),
        }
    }

    /// Fraction `0..1` of the current step (from the latest heel strike to the next).
    fn step_phase(&self, t: f32) -> f32 {
        let mut strikes: Vec<f32> = self
            .footfalls
            .iter()
            .map(|f| f.strike)
            .filter(|s| s.is_finite())
            .collect();
        strikes.sort_by(f32::total_cmp);
        for w in strikes.windows(2) {
            if t >= w[0] && t < w[1] {
                return (t - w[0]) / (w[1] - w[0]);
            }
        }
        0.5
    }

    /// The body at `t`.
    pub fn pose(&self, t: f32) -> BodyPose {
        let s = &self.style;
        let (mut root, yaw) = self.path_at(t);
        let phase = self.step_phase(t);
        // Lowest just after each strike, highest mid-step.
        root.y -= s.bob * 0.5 * (1.0 + (TAU * phase).cos());
        let mut pose = BodyPose::standing(root, yaw);
        let pelvis = yaw_rotation(yaw);
        pose.set(Part::Pelvis, pelvis);
        let fwd = forward_of(yaw);
        let mut ahead = [0.0f32; 2];
        for side in [Side::Right, Side::Left] {
            let (ankle, foot_rot) = self.foot_at(side, t);
            let hip = root + pelvis * super::skeleton::joint_offset(Part::thigh(side));
            let (hip_q, knee_q, _) = solve_leg(pelvis, hip, ankle);
            pose.set(Part::thigh(side), hip_q);
            pose.set(Part::shin(side), knee_q);
            let shin_world = pelvis * hip_q * knee_q;
            pose.set(
                Part::foot(side),
                (shin_world.inverse() * foot_rot).normalize(),
            );
            ahead[(side == Side::Left) as usize] = (ankle - root).dot(fwd);
        }
        pose.set(Part::Torso, flex(-s.lean));
        pose.set(Part::Head, flex(0.8 * s.lean));
        for side in [Side::Right, Side::Left] {
            let other = ahead[(side == Side::Right) as usize];
            let (mut shoulder, mut elbow, mut out) = if s.guard {
                (0.95, s.elbow, 0.3)
            } else {
                let sw = (s.arm_swing * other).clamp(-0.9, 0.9);
                (sw, s.elbow + 0.4 * sw.max(0.0), 0.1)
            };
            for k in &self.strikes {
                if k.side.is_some_and(|a| a != side) {
                    continue;
                }
                // Out in 0.15 s, back in 0.25 s.
                let d = t - k.time;
                let w = if d < 0.0 {
                    smoothstep(1.0 + d / 0.15)
                } else {
                    smoothstep(1.0 - d / 0.25)
                };
                shoulder += (1.45 - shoulder) * w;
                elbow += (0.15 - elbow) * w;
                out += (0.1 - out) * w;
            }
            pose.set(Part::upper_arm(side), abduct(side, out) * flex(shoulder));
            pose.set(Part::forearm(side), flex(elbow));
        }
        pose
    }
}

/// What a person does during a segment.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Walking, running, shuffling.
    Gait(Gait),
    /// Falling onto the back.
    Topple(Topple),
    /// Sliding feet first.
    Slide(Slide),
    /// Making a snow angel.
    Angel(Angel),
}

/// One action from a start time until the next segment starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// Start time, seconds.
    pub start: f32,
    /// Seconds over which the body blends out of the previous segment's last pose.
    pub blend: f32,
    /// The action.
    pub action: Action,
}

impl Segment {
    fn raw_pose(&self, t: f32) -> BodyPose {
        let tau = t - self.start;
        match &self.action {
            Action::Gait(g) => g.pose(t),
            Action::Topple(a) => a.pose(tau),
            Action::Slide(a) => a.pose(tau),
            Action::Angel(a) => a.pose(tau),
        }
    }
}

/// A person's whole animation.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Motion {
    /// Segments in time order.
    pub segments: Vec<Segment>,
}

impl Motion {
    /// The body at `t`.
    pub fn pose(&self, t: f32) -> BodyPose {
        let segs = &self.segments;
        let Some(first) = segs.first() else {
            return BodyPose::standing(Vec3::new(0.0, dims::PELVIS_HEIGHT, 0.0), 0.0);
        };
        let i = segs.iter().rposition(|s| s.start <= t).unwrap_or(0);
        let seg = &segs[i];
        let pose = seg.raw_pose(t.max(first.start.min(t)));
        if i == 0 || seg.blend <= 0.0 || t >= seg.start + seg.blend {
            return pose;
        }
        // Blend out of where the previous segment left the body: the posture eases over, and the
        // offset between the two roots at the switch fades, so nothing jumps.
        let from = segs[i - 1].raw_pose(seg.start);
        let to_start = seg.raw_pose(seg.start);
        let w = smoothstep((t - seg.start) / seg.blend);
        let mut out = from.blend(&pose, w);
        out.root = pose.root + (from.root - to_start.root) * (1.0 - w);
        out
    }

    /// Every footfall of the gait segments that happens before the segment ends.
    pub fn footfalls(&self) -> Vec<Footfall> {
        let mut out = Vec::new();
        for (i, seg) in self.segments.iter().enumerate() {
            let end = self.segments.get(i + 1).map_or(f32::INFINITY, |n| n.start);
            if let Action::Gait(g) = &seg.action {
                out.extend(g.footfalls.iter().filter(|f| f.strike < end).copied());
            }
        }
        out
    }
}
