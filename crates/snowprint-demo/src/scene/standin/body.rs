//! The stand-in world's people: capsule bodies posed as skeletons, the gait of walkers and
//! runners, sliding, falling and the snow angel; each part both drawn and pressed into the snow.

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{Instance, RenderMeshId};
use snowprint::{Pose, Shape};

use super::{PI, TAU};

/// Limb dimensions, metres.
pub(in crate::scene) const THIGH: f32 = 0.45;
pub(in crate::scene) const SHIN: f32 = 0.44;
pub(in crate::scene) const UPPER_ARM: f32 = 0.30;
pub(in crate::scene) const FOREARM: f32 = 0.28;
pub(in crate::scene) const TORSO: f32 = 0.50;
pub(in crate::scene) const FOOT: f32 = 0.27;

/// The drawn parts of a person.
#[derive(Clone, Copy)]
pub(in crate::scene) struct BodyMeshes {
    pub(in crate::scene) torso: RenderMeshId,
    pub(in crate::scene) head: RenderMeshId,
    pub(in crate::scene) upper_arm: RenderMeshId,
    pub(in crate::scene) forearm: RenderMeshId,
    pub(in crate::scene) thigh: RenderMeshId,
    pub(in crate::scene) shin: RenderMeshId,
    pub(in crate::scene) boot: RenderMeshId,
}

/// A posed person: joints in world space and the frame of each foot.
#[derive(Clone, Copy, Debug)]
pub(in crate::scene) struct Skeleton {
    pub(in crate::scene) pelvis: Vec3,
    pub(in crate::scene) neck: Vec3,
    pub(in crate::scene) head: Vec3,
    pub(in crate::scene) shoulders: [Vec3; 2],
    pub(in crate::scene) elbows: [Vec3; 2],
    pub(in crate::scene) hands: [Vec3; 2],
    pub(in crate::scene) hips: [Vec3; 2],
    pub(in crate::scene) knees: [Vec3; 2],
    pub(in crate::scene) ankles: [Vec3; 2],
    /// Heel point on the sole and the unit forward and up of each foot.
    pub(in crate::scene) feet: [(Vec3, Vec3, Vec3); 2],
}

pub(in crate::scene) fn segment_pose(a: Vec3, b: Vec3) -> Pose {
    let d = b - a;
    Pose {
        position: (a + b) * 0.5,
        rotation: Quat::from_rotation_arc(Vec3::Y, d.normalize_or(Vec3::Y)),
    }
}

pub(in crate::scene) fn pose_matrix(p: &Pose) -> Mat4 {
    Mat4::from_rotation_translation(p.rotation, p.position)
}

pub(in crate::scene) fn foot_rotation(fwd: Vec3, up: Vec3) -> Quat {
    let side = fwd.cross(up).normalize();
    Quat::from_mat3(&glam::Mat3::from_cols(fwd, up, side))
}

/// The parts of a skeleton as capsules (a: start, b: end, radius) and the feet.
impl Skeleton {
    pub(in crate::scene) fn capsules(&self) -> Vec<(Vec3, Vec3, f32)> {
        let mut v = vec![(self.pelvis, self.neck, 0.16)];
        for i in 0..2 {
            v.push((self.shoulders[i], self.elbows[i], 0.05));
            v.push((self.elbows[i], self.hands[i], 0.045));
            v.push((self.hips[i], self.knees[i], 0.075));
            v.push((self.knees[i], self.ankles[i], 0.06));
        }
        v
    }

    /// Deformer shapes of the feet, a boot sole in three flat blocks: the heel, the ball and the
    /// arch between (1.5 cm higher, so prints show heel and toe), and a rounded toe.
    pub(in crate::scene) fn foot_shapes(&self) -> Vec<(Shape, Pose)> {
        let mut v = Vec::new();
        for &(heel, fwd, up) in &self.feet {
            let rotation = foot_rotation(fwd, up);
            let block = |along: f32, lift: f32, half: Vec3| {
                (
                    Shape::Box { half_extents: half },
                    Pose {
                        position: heel + fwd * along + up * (lift + half.y),
                        rotation,
                    },
                )
            };
            v.push(block(0.045, 0.0, Vec3::new(0.045, 0.02, 0.045)));
            v.push(block(0.185, 0.0, Vec3::new(0.065, 0.02, 0.05)));
            v.push(block(0.115, 0.015, Vec3::new(0.04, 0.015, 0.035)));
            v.push((
                Shape::Sphere { radius: 0.045 },
                Pose {
                    position: heel + fwd * 0.235 + up * 0.045,
                    rotation: Quat::IDENTITY,
                },
            ));
        }
        v
    }

    /// Everything that presses the snow, with its pose.
    pub(in crate::scene) fn shapes(&self) -> Vec<(Shape, Pose)> {
        let mut v: Vec<(Shape, Pose)> = self
            .capsules()
            .into_iter()
            .map(|(a, b, r)| {
                (
                    Shape::Capsule {
                        radius: r,
                        half_height: 0.5 * a.distance(b),
                    },
                    segment_pose(a, b),
                )
            })
            .collect();
        v.push((
            Shape::Sphere { radius: 0.11 },
            Pose {
                position: self.head,
                rotation: Quat::IDENTITY,
            },
        ));
        v.extend(self.foot_shapes());
        v
    }

    pub(in crate::scene) fn instances(
        &self,
        m: &BodyMeshes,
        coat: [f32; 3],
        trousers: [f32; 3],
    ) -> Vec<Instance> {
        let skin = [0.55, 0.38, 0.3];
        let boot = [0.05, 0.04, 0.035];
        let part =
            |mesh, a, b, albedo| Instance::new(mesh, pose_matrix(&segment_pose(a, b)), albedo);
        let mut v = vec![
            part(m.torso, self.pelvis, self.neck, coat),
            Instance::new(m.head, Mat4::from_translation(self.head), skin),
        ];
        for i in 0..2 {
            v.push(part(m.upper_arm, self.shoulders[i], self.elbows[i], coat));
            v.push(part(m.forearm, self.elbows[i], self.hands[i], coat));
            v.push(part(m.thigh, self.hips[i], self.knees[i], trousers));
            v.push(part(m.shin, self.knees[i], self.ankles[i], trousers));
            let (heel, fwd, up) = self.feet[i];
            let center = heel + fwd * (FOOT * 0.5) + up * 0.045;
            v.push(Instance::new(
                m.boot,
                Mat4::from_rotation_translation(foot_rotation(fwd, up), center),
                boot,
            ));
        }
        for inst in &mut v {
            inst.roughness = 0.8;
        }
        v
    }

    /// The same skeleton turned rigidly about `pivot` by `q`, then moved by `shift`.
    pub(in crate::scene) fn transformed(&self, pivot: Vec3, q: Quat, shift: Vec3) -> Skeleton {
        let p = |x: Vec3| pivot + q * (x - pivot) + shift;
        let mut s = *self;
        s.pelvis = p(s.pelvis);
        s.neck = p(s.neck);
        s.head = p(s.head);
        for i in 0..2 {
            s.shoulders[i] = p(s.shoulders[i]);
            s.elbows[i] = p(s.elbows[i]);
            s.hands[i] = p(s.hands[i]);
            s.hips[i] = p(s.hips[i]);
            s.knees[i] = p(s.knees[i]);
            s.ankles[i] = p(s.ankles[i]);
            let (h, f, u) = s.feet[i];
            s.feet[i] = (p(h), q * f, q * u);
        }
        s
    }
}

/// Knee of a two-bone leg from hip to ankle, bending towards `forward`.
pub(in crate::scene) fn knee(hip: Vec3, ankle: Vec3, forward: Vec3) -> Vec3 {
    let d = ankle - hip;
    let len = d.length().clamp(0.05, THIGH + SHIN - 1e-3);
    let dir = d.normalize_or(-Vec3::Y);
    // Distance along the hip-ankle line to the knee's foot point, and the knee's offset from it.
    let a = (THIGH * THIGH - SHIN * SHIN + len * len) / (2.0 * len);
    let h = (THIGH * THIGH - a * a).max(0.0).sqrt();
    let bend = (forward - dir * forward.dot(dir)).normalize_or(Vec3::Z);
    hip + dir * a + bend * h
}

/// A gait: walking or running along a straight path.
#[derive(Clone, Copy)]
pub(in crate::scene) struct Gait {
    pub(in crate::scene) start: Vec3,
    pub(in crate::scene) dir: Vec3,
    pub(in crate::scene) speed: f32,
    pub(in crate::scene) period: f32,
    pub(in crate::scene) stance: f32,
    pub(in crate::scene) lift: f32,
    pub(in crate::scene) t0: f32,
    pub(in crate::scene) t1: f32,
}

impl Gait {
    /// Heel point, forward and up of foot `i` at time `t` (clamped to the walk).
    pub(in crate::scene) fn foot(&self, i: usize, t: f32) -> (Vec3, Vec3, Vec3) {
        let t = t.clamp(self.t0, self.t1) - self.t0;
        let side = self.dir.cross(Vec3::Y).normalize();
        let lateral = side * if i == 0 { -0.11 } else { 0.11 };
        let c = t / self.period + 0.5 * i as f32;
        let k = c.floor();
        let phase = c - k;
        // Where the foot is planted in cycle k: under the body at mid-stance.
        let plant = |k: f32| {
            let t_mid = (k - 0.5 * i as f32 + 0.5 * self.stance) * self.period;
            self.start + self.dir * (self.speed * t_mid.max(0.0)) + lateral
                - self.dir * (FOOT * 0.45)
        };
        let (mut heel, pitch_heel, pitch_ball) = if phase < self.stance {
            let u = phase / self.stance;
            // Heel strike: toe up, coming down; toe-off: heel up, pivoting on the ball.
            (
                plant(k),
                0.35 * (1.0 - (u / 0.2).min(1.0)).powi(2),
                0.6 * ((u - 0.7) / 0.3).clamp(0.0, 1.0).powi(2),
            )
        } else {
            let u = (phase - self.stance) / (1.0 - self.stance);
            let s = u * u * (3.0 - 2.0 * u);
            (
                plant(k).lerp(plant(k + 1.0), s) + Vec3::Y * (self.lift * (PI * u).sin()),
                0.35 * u.powi(4),
                0.6 * (1.0 - u).powi(3),
            )
        };
        let mut fwd = self.dir;
        let mut up = Vec3::Y;
        if pitch_heel > 0.0 {
            // Rotate about the heel: toe up.
            let q = Quat::from_axis_angle(side, pitch_heel);
            fwd = q * fwd;
            up = q * up;
        }
        if pitch_ball > 0.0 {
            // Rotate about the ball of the foot: heel up.
            let ball = heel + fwd * 0.19;
            let q = Quat::from_axis_angle(side, -pitch_ball);
            fwd = q * fwd;
            up = q * up;
            heel = ball - fwd * 0.19;
        }
        (heel, fwd, up)
    }

    pub(in crate::scene) fn skeleton(&self, t: f32) -> Skeleton {
        let tt = t.clamp(self.t0, self.t1) - self.t0;
        let side = self.dir.cross(Vec3::Y).normalize();
        let bob = 0.025 * (2.0 * TAU * tt / self.period).cos();
        let lean = if self.speed > 2.5 { 0.12 } else { 0.03 };
        let base = self.start + self.dir * (self.speed * tt);
        let pelvis = base + Vec3::Y * (0.92 + bob);
        let up = (Vec3::Y + self.dir * lean).normalize();
        let neck = pelvis + up * TORSO;
        let feet = [self.foot(0, t), self.foot(1, t)];
        let swing = 0.45 * (TAU * tt / self.period).sin() * (self.speed / 1.5).min(1.6);
        let mut s = Skeleton {
            pelvis,
            neck,
            head: neck + up * 0.17,
            shoulders: [
                neck - side * 0.19 - Vec3::Y * 0.04,
                neck + side * 0.19 - Vec3::Y * 0.04,
            ],
            elbows: [Vec3::ZERO; 2],
            hands: [Vec3::ZERO; 2],
            hips: [pelvis - side * 0.1, pelvis + side * 0.1],
            knees: [Vec3::ZERO; 2],
            ankles: [Vec3::ZERO; 2],
            feet,
        };
        for (i, &(heel, fwd, up)) in feet.iter().enumerate() {
            s.ankles[i] = heel + fwd * 0.06 + up * 0.09;
            s.knees[i] = knee(s.hips[i], s.ankles[i], self.dir);
            let a = if i == 0 { swing } else { -swing };
            let arm = Quat::from_axis_angle(side, -a);
            s.elbows[i] = s.shoulders[i] + arm * (-Vec3::Y * UPPER_ARM);
            let fore = Quat::from_axis_angle(side, -a - 0.5);
            s.hands[i] = s.elbows[i] + fore * (-Vec3::Y * FOREARM);
        }
        s
    }
}

/// A standing skeleton facing `dir` with its feet at `ground`, arms a little out.
pub(in crate::scene) fn standing(
    ground: Vec3,
    dir: Vec3,
    arms_out: f32,
    legs_out: f32,
) -> Skeleton {
    let side = dir.cross(Vec3::Y).normalize();
    let pelvis = ground + Vec3::Y * 0.93;
    let neck = pelvis + Vec3::Y * TORSO;
    let mut s = Skeleton {
        pelvis,
        neck,
        head: neck + Vec3::Y * 0.17,
        shoulders: [
            neck - side * 0.19 - Vec3::Y * 0.04,
            neck + side * 0.19 - Vec3::Y * 0.04,
        ],
        elbows: [Vec3::ZERO; 2],
        hands: [Vec3::ZERO; 2],
        hips: [pelvis - side * 0.1, pelvis + side * 0.1],
        knees: [Vec3::ZERO; 2],
        ankles: [Vec3::ZERO; 2],
        feet: [(Vec3::ZERO, dir, Vec3::Y); 2],
    };
    for i in 0..2 {
        let sgn = if i == 0 { -1.0 } else { 1.0 };
        let arm = Quat::from_axis_angle(dir, -sgn * arms_out);
        s.elbows[i] = s.shoulders[i] + arm * (-Vec3::Y * UPPER_ARM);
        s.hands[i] = s.elbows[i] + arm * (-Vec3::Y * FOREARM);
        let leg = Quat::from_axis_angle(dir, -sgn * legs_out);
        s.knees[i] = s.hips[i] + leg * (-Vec3::Y * THIGH);
        s.ankles[i] = s.knees[i] + leg * (-Vec3::Y * SHIN);
        let heel = s.ankles[i] - dir * 0.06 - Vec3::Y * 0.09;
        s.feet[i] = (heel, dir, Vec3::Y);
    }
    s
}

/// What one person does over time.
#[derive(Clone, Copy)]
pub(in crate::scene) enum Act {
    Walk(Gait),
    /// Lying on the back, sliding feet-first from `from` to `to` between t0 and t1.
    Slide {
        from: Vec3,
        to: Vec3,
        t0: f32,
        t1: f32,
    },
    /// Standing at `at` facing `dir`, falling backwards onto the back at `t_fall`.
    Fall {
        at: Vec3,
        dir: Vec3,
        t_fall: f32,
    },
    /// Lying on the back at `at`, head towards `dir`, sweeping arms and legs between t0 and t1.
    Angel {
        at: Vec3,
        dir: Vec3,
        t0: f32,
        t1: f32,
    },
}

/// A lying skeleton: a standing one, turned onto its back about the heels, head towards
/// `head_dir`, face up.
pub(in crate::scene) fn lying(
    ground: Vec3,
    head_dir: Vec3,
    arms_out: f32,
    legs_out: f32,
) -> Skeleton {
    // Standing facing away from the head direction, then turned backwards by 90 degrees: its up
    // goes to `head_dir`, its front to +Y.
    let facing = -head_dir;
    let s = standing(ground, facing, arms_out, legs_out);
    let side = facing.cross(Vec3::Y).normalize();
    let q = Quat::from_axis_angle(side, 0.5 * PI);
    s.transformed(ground, q, Vec3::Y * 0.13)
}

impl Act {
    pub(in crate::scene) fn skeleton(&self, t: f32) -> Skeleton {
        match *self {
            Act::Walk(g) => g.skeleton(t),
            Act::Slide { from, to, t0, t1 } => {
                let u = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                let d = 1.0 - (1.0 - u) * (1.0 - u);
                let dir = (to - from).normalize();
                // Feet first: the head points back along the slide.
                let body = lying(Vec3::ZERO, -dir, 0.35, 0.08);
                body.transformed(Vec3::ZERO, Quat::IDENTITY, from.lerp(to, d))
            }
            Act::Fall { at, dir, t_fall } => {
                let s = standing(at, dir, 0.25, 0.05);
                let u = ((t - t_fall) / 0.55).clamp(0.0, 1.0);
                let side = dir.cross(Vec3::Y).normalize();
                let angle = 0.5 * PI * u * u;
                let q = Quat::from_axis_angle(side, angle);
                // Falling backwards: pivot at the heels, body drops onto its back.
                s.transformed(at, q, Vec3::Y * (0.13 * u))
            }
            Act::Angel { at, dir, t0, t1 } => {
                let u = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                let sweep = 0.5 - 0.5 * (TAU * 2.0 * u).cos();
                let arms = 0.25 + 2.2 * sweep;
                let legs = 0.04 + 0.45 * sweep;
                lying(at, dir, arms, legs)
            }
        }
    }
}

pub(in crate::scene) struct Person {
    pub(in crate::scene) act: Act,
    pub(in crate::scene) coat: [f32; 3],
    pub(in crate::scene) trousers: [f32; 3],
    /// Leaves the scene at this time (the stand-in has no getting-up animation: the fallen person
    /// vanishes so that the imprint of the body can be seen).
    pub(in crate::scene) leaves: Option<f32>,
}

impl Person {
    pub(in crate::scene) fn present(&self, t: f32) -> bool {
        self.leaves.is_none_or(|l| t < l)
    }
}
