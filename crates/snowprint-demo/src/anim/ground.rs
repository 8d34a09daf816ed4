//! The actions on the ground: falling onto the back ([`Topple`]), sliding on it ([`Slide`]) and
//! making a snow angel ([`Angel`]).

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Quat, Vec2, Vec3};

use super::*;
use crate::skeleton::{BodyPose, Part, Side, abduct, dims, flex};

/// Falling backwards onto the back, like a plank pivoting about the heels; from a ledge, the
/// body leaves it and falls freely, turning to land flat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Topple {
    /// World point under the heels (the pivot), on what the person stands on.
    pub pivot: Vec3,
    /// Heading the person faces (they fall the other way).
    pub yaw: f32,
    /// Seconds of teetering (windmilling arms) before the fall.
    pub teeter: f32,
    /// Seconds to tip from upright to `release`.
    pub tip_time: f32,
    /// Angle from upright at which the feet leave the pivot (`PI / 2`: the body pivots all the way
    /// to the ground).
    pub release: f32,
    /// World height of the ground under the snow where the body lands.
    pub land: f32,
    /// Windmill the arms while teetering (otherwise stand still with the arms held out).
    pub windmill: bool,
    /// How far the arms are spread (abduction, radians) when the body lands.
    pub arms_out: f32,
}

/// Where a body lying on its back rests: its pelvis centre above the ground under the snow
/// (a little into it, so that the back presses through the snow).
pub const LYING_HEIGHT: f32 = dims::BACK_DEPTH - 0.01;

impl Topple {
    fn standing_root(&self) -> Vec3 {
        let fwd = forward_of(self.yaw);
        self.pivot + fwd * dims::HEEL_BACK + Vec3::Y * dims::PELVIS_HEIGHT
    }

    /// World rotation tipping the body backwards by `angle`.
    fn tilt(&self, angle: f32) -> Quat {
        yaw_rotation(self.yaw) * flex(angle)
    }

    /// Rigid rotation about the pivot: the pelvis position after tipping by `angle`.
    fn tipped_root(&self, angle: f32) -> Vec3 {
        let r = self.tilt(angle) * yaw_rotation(self.yaw).inverse();
        self.pivot + r * (self.standing_root() - self.pivot)
    }

    /// Free-fall duration after the release and the pelvis's launch state.
    fn flight(&self) -> (f32, Vec3, Vec3) {
        let p1 = self.tipped_root(self.release);
        if self.release >= FRAC_PI_2 - 1e-3 {
            return (0.0, p1, Vec3::ZERO);
        }
        // Angular speed at release of a uniformly accelerated tip: 2 * angle / time.
        let omega = 2.0 * self.release / self.tip_time.max(1e-3);
        let axis = yaw_rotation(self.yaw) * Vec3::Z;
        let v = omega * axis.cross(p1 - self.pivot);
        let target = self.land + LYING_HEIGHT;
        let drop = (p1.y - target).max(0.0);
        let g = 0.5 * GRAVITY;
        let t = (v.y + (v.y * v.y + 4.0 * g * drop).sqrt()) / (2.0 * g);
        (t, p1, v)
    }

    /// Seconds from the start of the segment to the body lying flat.
    pub fn duration(&self) -> f32 {
        self.teeter + self.tip_time + self.flight().0
    }

    /// Pelvis position and rotation of the landed body.
    pub fn lying_root(&self) -> (Vec3, Quat) {
        let (t, p1, v) = self.flight();
        let mut p = p1 + v * t;
        p.y = self.land + LYING_HEIGHT;
        (p, self.tilt(FRAC_PI_2))
    }

    /// The body `tau` seconds after the segment starts.
    pub fn pose(&self, tau: f32) -> BodyPose {
        let mut pose = BodyPose::standing(self.standing_root(), self.yaw);
        if tau < self.teeter && !self.windmill {
            for side in [Side::Right, Side::Left] {
                let out = 0.1 + 0.5 * smoothstep(1.0 + (tau - self.teeter) / 0.5);
                pose.set(Part::upper_arm(side), abduct(side, out));
            }
            return pose;
        }
        if tau < self.teeter {
            // Windmilling arms, swaying back and forth.
            let sway = 0.06 * (TAU * 1.5 * tau).sin();
            let r = self.tilt(sway) * yaw_rotation(self.yaw).inverse();
            pose.root = self.pivot + r * (self.standing_root() - self.pivot);
            pose.set(Part::Pelvis, self.tilt(sway));
            for side in [Side::Right, Side::Left] {
                let a = TAU * 1.2 * tau + if side == Side::Right { 0.0 } else { PI };
                pose.set(
                    Part::upper_arm(side),
                    abduct(side, 0.5 + 0.3 * a.cos()) * flex(1.6 + 1.2 * a.sin()),
                );
                pose.set(Part::forearm(side), flex(0.3));
            }
            return pose;
        }
        let tau = tau - self.teeter;
        let (flight, p1, v) = self.flight();
        let (root, angle) = if tau < self.tip_time {
            let u = tau / self.tip_time.max(1e-3);
            let angle = self.release * u * u;
            let mut root = self.tipped_root(angle);
            if flight == 0.0 {
                // Pivoting all the way down: settle onto the back at the end.
                let target = self.land + LYING_HEIGHT;
                let end = self.tipped_root(FRAC_PI_2);
                root.y += (target - end.y) * u.powi(4);
            }
            (root, angle)
        } else if tau < self.tip_time + flight {
            let s = tau - self.tip_time;
            let root = p1 + v * s - Vec3::Y * (0.5 * GRAVITY * s * s);
            let angle = self.release + (FRAC_PI_2 - self.release) * (s / flight);
            (root, angle)
        } else {
            (self.lying_root().0, FRAC_PI_2)
        };
        pose.root = root;
        pose.set(Part::Pelvis, self.tilt(angle));
        // Arms fly out to the sides, legs bend a little while falling and straighten on impact.
        let fall = smoothstep(tau / (self.tip_time + flight).max(1e-3));
        let landed = smoothstep((tau - self.tip_time - flight) / 0.25);
        for side in [Side::Right, Side::Left] {
            pose.set(
                Part::upper_arm(side),
                abduct(side, 0.1 + (self.arms_out - 0.1) * fall)
                    * flex(0.9 * fall * (1.0 - landed) - 0.2 * landed),
            );
            pose.set(Part::forearm(side), flex(0.5 * fall * (1.0 - landed) + 0.1));
            let bend = 0.5 * fall * (1.0 - landed);
            pose.set(
                Part::thigh(side),
                abduct(side, ANGEL_LEGS.0 * fall) * flex(bend + 0.05),
            );
            pose.set(Part::shin(side), flex(-1.2 * bend));
            pose.set(Part::foot(side), flex(-0.5 * fall));
        }
        pose.set(Part::Head, flex(-0.5 * fall * (1.0 - landed) - 0.1));
        pose
    }
}

/// A feet-first slide on the back: a drop from running onto the back, legs shooting forward,
/// then a decelerating glide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slide {
    /// Pelvis position (horizontal) where the slide starts.
    pub start: Vec2,
    /// Heading of the slide (the feet lead).
    pub yaw: f32,
    /// World height of the ground under the snow.
    pub ground: f32,
    /// Pelvis height above the ground when the drop starts (the gait's hip height).
    pub drop_from: f32,
    /// Seconds from upright to lying back.
    pub drop_time: f32,
    /// Speed at the start, m/s.
    pub speed: f32,
    /// Deceleration, m/s².
    pub decel: f32,
}

/// Pelvis pitch (backwards) of the sliding body, radians.
const SLIDE_PITCH: f32 = 1.38;

impl Slide {
    /// Distance the pelvis slides before it stops, metres.
    pub fn length(&self) -> f32 {
        self.speed * self.speed / (2.0 * self.decel)
    }

    /// Seconds from the start to the stop.
    pub fn duration(&self) -> f32 {
        self.speed / self.decel
    }

    /// The body `tau` seconds after the slide starts.
    pub fn pose(&self, tau: f32) -> BodyPose {
        let stop = self.duration();
        let s = tau.clamp(0.0, stop);
        let d = self.speed * s - 0.5 * self.decel * s * s;
        let fwd = forward_of(self.yaw);
        // Drop: the pelvis falls (accelerating) while the body tips back.
        let u = (tau / self.drop_time.max(1e-3)).clamp(0.0, 1.0);
        let rest = LYING_HEIGHT + 0.01;
        let height = self.drop_from + (rest - self.drop_from) * u * u;
        let pitch = SLIDE_PITCH * smoothstep(u);
        let root = Vec3::new(self.start.x, self.ground + height, self.start.y) + fwd * d;
        let mut pose = BodyPose::standing(root, self.yaw);
        pose.set(Part::Pelvis, yaw_rotation(self.yaw) * flex(pitch));
        // Legs forward, the feet kept a few centimetres above the ground: the angle of the leg
        // from straight down needed to clear it at this pelvis height.
        let leg = dims::THIGH + dims::SHIN + dims::ANKLE_HEIGHT;
        let clear = ((height - dims::HIP_DROP - 0.04) / leg)
            .clamp(-1.0, 1.0)
            .acos();
        let hip = (clear.max(SLIDE_PITCH + 0.18) - pitch).max(0.0);
        // Leaning far back, head and shoulders curled up to watch the feet; sitting up once
        // stopped.
        let sit_up = smoothstep((tau - stop - 0.2) / 0.6);
        pose.set(Part::Torso, flex(-0.1 - 0.5 * sit_up));
        pose.set(Part::Head, flex(-0.6));
        for side in [Side::Right, Side::Left] {
            pose.set(Part::thigh(side), abduct(side, 0.08) * flex(hip));
            pose.set(Part::shin(side), flex(-0.08));
            pose.set(Part::foot(side), flex(-0.4));
            // Hands folded on the belly, out of the snow.
            pose.set(Part::upper_arm(side), abduct(side, 0.15) * flex(0.5));
            pose.set(Part::forearm(side), flex(1.6));
        }
        pose
    }
}

/// Lying on the back, sweeping arms and legs: a snow angel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Angel {
    /// Pelvis position of the lying body.
    pub root: Vec3,
    /// Pelvis rotation of the lying body.
    pub rotation: Quat,
    /// Number of open-and-close sweeps.
    pub sweeps: u32,
    /// Seconds per sweep.
    pub period: f32,
    /// Whether the limbs sweep (false: the same body lying still, for comparisons).
    pub sweeping: bool,
}

/// Arm abduction of the snow angel at rest and fully open, radians.
pub const ANGEL_ARMS: (f32, f32) = (0.25, 2.7);
/// Leg abduction of the snow angel at rest and fully open, radians.
pub const ANGEL_LEGS: (f32, f32) = (0.05, 0.6);

impl Angel {
    /// Seconds of sweeping.
    pub fn duration(&self) -> f32 {
        self.sweeps as f32 * self.period
    }

    /// The body `tau` seconds after the sweeps start.
    pub fn pose(&self, tau: f32) -> BodyPose {
        let mut pose = BodyPose::standing(self.root, 0.0);
        pose.set(Part::Pelvis, self.rotation);
        let open = if self.sweeping && tau > 0.0 && tau < self.duration() {
            0.5 * (1.0 - (TAU * tau / self.period).cos())
        } else {
            0.0
        };
        for side in [Side::Right, Side::Left] {
            let arm = ANGEL_ARMS.0 + (ANGEL_ARMS.1 - ANGEL_ARMS.0) * open;
            let leg = ANGEL_LEGS.0 + (ANGEL_LEGS.1 - ANGEL_LEGS.0) * open;
            // Arms angled slightly down into the snow (negative flexion points them at the
            // ground when lying on the back).
            pose.set(Part::upper_arm(side), abduct(side, arm) * flex(-0.22));
            pose.set(Part::forearm(side), flex(0.1));
            // Palms down: the hand's broad side on the snow.
            pose.set(Part::hand(side), Quat::from_rotation_y(FRAC_PI_2));
            pose.set(Part::thigh(side), abduct(side, leg) * flex(-0.05));
            pose.set(Part::shin(side), flex(-0.05));
            pose.set(Part::foot(side), flex(-0.6));
        }
        pose.set(Part::Head, flex(-0.1));
        pose
    }
}
