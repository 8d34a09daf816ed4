//! The articulated body: fifteen rigid parts in a tree of joints, their meshes, forward kinematics
//! and a two-bone leg solver.
//!
//! Every part is built in its own joint frame, so that a part's world [`Pose`] is the world frame of
//! its joint. The body frame (the rest pose, standing upright) has `+X` forward, `+Y` up and `+Z` to
//! the person's right. In that frame:
//!
//! * a rotation about `+Z` by a positive angle swings a hanging limb *forward* (hip and shoulder
//!   flexion, elbow flexion), tips the upright torso *backward*, and lifts the toes (dorsiflexion);
//! * limbs hang along `-Y` from their joint; the torso and head rise along `+Y`.

use glam::{Mat4, Quat, Vec3};

use snowprint::Mesh;
use snowprint::Pose;

/// Number of body parts.
pub const PART_COUNT: usize = 15;

/// A body part. Its index (`as usize`) is its index in [`crate::DemoWorld::part_meshes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Part {
    /// Hips; the root of the tree.
    Pelvis,
    /// Abdomen and chest, from the lower back to the shoulders.
    Torso,
    /// Neck and head.
    Head,
    /// Right upper arm, shoulder to elbow.
    UpperArmRight,
    /// Right forearm, elbow to wrist.
    ForearmRight,
    /// Right hand.
    HandRight,
    /// Left upper arm.
    UpperArmLeft,
    /// Left forearm.
    ForearmLeft,
    /// Left hand.
    HandLeft,
    /// Right thigh, hip to knee.
    ThighRight,
    /// Right shin, knee to ankle.
    ShinRight,
    /// Right foot (a boot with a heel, a narrow arch and a broad ball and toe).
    FootRight,
    /// Left thigh.
    ThighLeft,
    /// Left shin.
    ShinLeft,
    /// Left foot.
    FootLeft,
}

/// Left or right.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The person's right (`+Z` in the body frame).
    Right,
    /// The person's left (`-Z`).
    Left,
}

impl Side {
    /// `+1` for right, `-1` for left: the sign of the body-frame `z` of this side.
    pub fn sign(self) -> f32 {
        match self {
            Side::Right => 1.0,
            Side::Left => -1.0,
        }
    }

    /// The other side.
    pub fn other(self) -> Side {
        match self {
            Side::Right => Side::Left,
            Side::Left => Side::Right,
        }
    }
}

impl Part {
    /// Every part, in index order.
    pub const ALL: [Part; PART_COUNT] = [
        Part::Pelvis,
        Part::Torso,
        Part::Head,
        Part::UpperArmRight,
        Part::ForearmRight,
        Part::HandRight,
        Part::UpperArmLeft,
        Part::ForearmLeft,
        Part::HandLeft,
        Part::ThighRight,
        Part::ShinRight,
        Part::FootRight,
        Part::ThighLeft,
        Part::ShinLeft,
        Part::FootLeft,
    ];

    /// Index of the part (in [`Part::ALL`] and in the part meshes).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name, for files and logs.
    pub fn name(self) -> &'static str {
        match self {
            Part::Pelvis => "pelvis",
            Part::Torso => "torso",
            Part::Head => "head",
            Part::UpperArmRight => "upper_arm_right",
            Part::ForearmRight => "forearm_right",
            Part::HandRight => "hand_right",
            Part::UpperArmLeft => "upper_arm_left",
            Part::ForearmLeft => "forearm_left",
            Part::HandLeft => "hand_left",
            Part::ThighRight => "thigh_right",
            Part::ShinRight => "shin_right",
            Part::FootRight => "foot_right",
            Part::ThighLeft => "thigh_left",
            Part::ShinLeft => "shin_left",
            Part::FootLeft => "foot_left",
        }
    }

    /// The part this one hangs from (`None` for the pelvis). Parents come before children in
    /// [`Part::ALL`].
    pub fn parent(self) -> Option<Part> {
        use Part::*;
        Some(match self {
            Pelvis => return None,
            Torso | ThighRight | ThighLeft => Pelvis,
            Head | UpperArmRight | UpperArmLeft => Torso,
            ForearmRight => UpperArmRight,
            HandRight => ForearmRight,
            ForearmLeft => UpperArmLeft,
            HandLeft => ForearmLeft,
            ShinRight => ThighRight,
            FootRight => ShinRight,
            ShinLeft => ThighLeft,
            FootLeft => ShinLeft,
        })
    }

    /// The upper arm of a side.
    pub fn upper_arm(side: Side) -> Part {
        match side {
            Side::Right => Part::UpperArmRight,
            Side::Left => Part::UpperArmLeft,
        }
    }

    /// The forearm of a side.
    pub fn forearm(side: Side) -> Part {
        match side {
            Side::Right => Part::ForearmRight,
            Side::Left => Part::ForearmLeft,
        }
    }

    /// The hand of a side.
    pub fn hand(side: Side) -> Part {
        match side {
            Side::Right => Part::HandRight,
            Side::Left => Part::HandLeft,
        }
    }

    /// The thigh of a side.
    pub fn thigh(side: Side) -> Part {
        match side {
            Side::Right => Part::ThighRight,
            Side::Left => Part::ThighLeft,
        }
    }

    /// The shin of a side.
    pub fn shin(side: Side) -> Part {
        match side {
            Side::Right => Part::ShinRight,
            Side::Left => Part::ShinLeft,
        }
    }

    /// The foot of a side.
    pub fn foot(side: Side) -> Part {
        match side {
            Side::Right => Part::FootRight,
            Side::Left => Part::FootLeft,
        }
    }

    /// What the part is dressed in, for its colour.
    pub fn garment(self) -> Garment {
        use Part::*;
        match self {
            Head | HandRight | HandLeft => Garment::Skin,
            Torso | UpperArmRight | UpperArmLeft | ForearmRight | ForearmLeft => Garment::Jacket,
            Pelvis | ThighRight | ThighLeft | ShinRight | ShinLeft => Garment::Trousers,
            FootRight | FootLeft => Garment::Boots,
        }
    }
}

/// What covers a part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Garment {
    /// Face and hands.
    Skin,
    /// Torso and arms.
    Jacket,
    /// Pelvis and legs.
    Trousers,
    /// Feet.
    Boots,
}

/// Colours (linear albedo) of one person's clothes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outfit {
    /// Face and hands.
    pub skin: [f32; 3],
    /// Torso and arms.
    pub jacket: [f32; 3],
    /// Pelvis and legs.
    pub trousers: [f32; 3],
    /// Feet.
    pub boots: [f32; 3],
}

impl Outfit {
    /// The albedo of a part.
    pub fn albedo(&self, part: Part) -> [f32; 3] {
        match part.garment() {
            Garment::Skin => self.skin,
            Garment::Jacket => self.jacket,
            Garment::Trousers => self.trousers,
            Garment::Boots => self.boots,
        }
    }
}

/// Body dimensions, metres. Every person of the demo shares them (and so the part meshes).
pub mod dims {
    /// Ankle joint above the sole of the boot.
    pub const ANKLE_HEIGHT: f32 = 0.08;
    /// Knee to ankle.
    pub const SHIN: f32 = 0.40;
    /// Hip to knee.
    pub const THIGH: f32 = 0.44;
    /// Hip joints below the pelvis centre.
    pub const HIP_DROP: f32 = 0.05;
    /// Hip joints either side of the pelvis centre.
    pub const HIP_SPREAD: f32 = 0.09;
    /// Pelvis centre above the soles when standing straight.
    pub const PELVIS_HEIGHT: f32 = ANKLE_HEIGHT + SHIN + THIGH + HIP_DROP;
    /// Lower back (torso joint) above the pelvis centre.
    pub const SPINE: f32 = 0.08;
    /// Shoulders above the torso joint.
    pub const SHOULDER_RISE: f32 = 0.40;
    /// Shoulder joints either side of the spine.
    pub const SHOULDER_SPREAD: f32 = 0.19;
    /// Neck (head joint) above the torso joint.
    pub const NECK: f32 = 0.44;
    /// Shoulder to elbow.
    pub const UPPER_ARM: f32 = 0.29;
    /// Elbow to wrist.
    pub const FOREARM: f32 = 0.25;
    /// Heel contact point behind the ankle (the pivot of the heel strike).
    pub const HEEL_BACK: f32 = 0.06;
    /// Ball contact point ahead of the ankle (the pivot of the toe roll).
    pub const BALL_FORWARD: f32 = 0.15;
    /// Foot length, heel to toe tip (the boot of `foot_mesh`).
    pub const FOOT_LENGTH: f32 = 0.335;
    /// Widest part of the foot (the ball).
    pub const FOOT_WIDTH: f32 = 0.096;
    /// Half the depth of the torso (chest to back) at the lower back, where a body lying on its
    /// back rests.
    pub const BACK_DEPTH: f32 = 0.11;
    /// Standing height, soles to the top of the head.
    pub const HEIGHT: f32 = PELVIS_HEIGHT + SPINE + NECK + 0.30;
    /// Shoulder width.
    pub const SHOULDER_WIDTH: f32 = 2.0 * SHOULDER_SPREAD + 0.10;
}

use dims::*;

/// Offset of a part's joint in its parent's joint frame.
pub fn joint_offset(part: Part) -> Vec3 {
    use Part::*;
    match part {
        Pelvis => Vec3::ZERO,
        Torso => Vec3::new(0.0, SPINE, 0.0),
        Head => Vec3::new(0.0, NECK, 0.0),
        UpperArmRight => Vec3::new(0.0, SHOULDER_RISE, SHOULDER_SPREAD),
        UpperArmLeft => Vec3::new(0.0, SHOULDER_RISE, -SHOULDER_SPREAD),
        ForearmRight | ForearmLeft => Vec3::new(0.0, -UPPER_ARM, 0.0),
        HandRight | HandLeft => Vec3::new(0.0, -FOREARM, 0.0),
        ThighRight => Vec3::new(0.0, -HIP_DROP, HIP_SPREAD),
        ThighLeft => Vec3::new(0.0, -HIP_DROP, -HIP_SPREAD),
        ShinRight | ShinLeft => Vec3::new(0.0, -THIGH, 0.0),
        FootRight | FootLeft => Vec3::new(0.0, -SHIN, 0.0),
    }
}

/// A pose of the whole body: where the pelvis is, and every joint's rotation relative to its
/// parent (`local[0]` is the pelvis's rotation in the world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPose {
    /// World position of the pelvis centre.
    pub root: Vec3,
    /// Rotation of each part's joint frame in its parent's frame, indexed by [`Part::index`].
    pub local: [Quat; PART_COUNT],
}

impl BodyPose {
    /// Standing upright, arms hanging, at `root`, facing `yaw` (radians about `+Y`; 0 faces `+X`).
    pub fn standing(root: Vec3, yaw: f32) -> Self {
        let mut local = [Quat::IDENTITY; PART_COUNT];
        local[0] = Quat::from_rotation_y(yaw);
        let mut p = Self { root, local };
        for side in [Side::Right, Side::Left] {
            p.set(Part::upper_arm(side), abduct(side, 0.08));
            p.set(Part::forearm(side), flex(0.15));
        }
        p
    }

    /// Set one joint's local rotation.
    pub fn set(&mut self, part: Part, q: Quat) {
        self.local[part.index()] = q;
    }

    /// One joint's local rotation.
    pub fn get(&self, part: Part) -> Quat {
        self.local[part.index()]
    }

    /// Blend towards `other` by `w` (0 = self): positions linearly, rotations spherically.
    pub fn blend(&self, other: &BodyPose, w: f32) -> BodyPose {
        let mut local = self.local;
        for (a, b) in local.iter_mut().zip(other.local.iter()) {
            // Keep the shorter arc so that blends never spin the long way round.
            let b = if a.dot(*b) < 0.0 { -*b } else { *b };
            *a = a.slerp(b, w).normalize();
        }
        BodyPose {
            root: self.root.lerp(other.root, w),
            local,
        }
    }

    /// World pose of every part's joint frame (forward kinematics).
    pub fn world(&self) -> [Pose; PART_COUNT] {
        let mut out = [Pose {
            position: self.root,
            rotation: self.local[0],
        }; PART_COUNT];
        for part in Part::ALL.iter().skip(1) {
            let i = part.index();
            let parent = out[part.parent().map_or(0, Part::index)];
            out[i] = Pose {
                position: parent.position + parent.rotation * joint_offset(*part),
                rotation: (parent.rotation * self.local[i]).normalize(),
            };
        }
        out
    }
}

/// Flexion: a rotation about the body's lateral axis (`+Z`). Positive swings a hanging limb
/// forward, lifts the toes, and tips an upright torso or head backward.
pub fn flex(angle: f32) -> Quat {
    Quat::from_rotation_z(angle)
}

/// Abduction: a rotation about the forward axis that raises a hanging limb of `side` sideways,
/// away from the body.
pub fn abduct(side: Side, angle: f32) -> Quat {
    Quat::from_rotation_x(-side.sign() * angle)
}

/// Joint rotations of a leg whose hip is at `hip` (world) in a pelvis turned by `pelvis`, such that
/// the ankle lands on `ankle` with the knee bending forward. Returns `(hip, knee)` local rotations
/// and the ankle position actually reached (different from `ankle` only when it is out of reach).
pub fn solve_leg(pelvis: Quat, hip: Vec3, ankle: Vec3) -> (Quat, Quat, Vec3) {
    let v = pelvis.inverse() * (ankle - hip);
    // Turn the leg sideways about the forward axis so that the target lies in its swing plane.
    let sideways = v.z.atan2(-v.y);
    let roll = Quat::from_rotation_x(-sideways);
    let planar = roll.inverse() * v;
    let (l1, l2) = (THIGH, SHIN);
    let d = planar.length().clamp(1e-4, (l1 + l2) * 0.9999);
    let cos_knee = ((l1 * l1 + l2 * l2 - d * d) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
    let bend = std::f32::consts::PI - cos_knee.acos();
    let aim = planar.x.atan2(-planar.y);
    let cos_hip = ((l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d)).clamp(-1.0, 1.0);
    let hip_q = roll * flex(aim + cos_hip.acos());
    let knee_q = flex(-bend);
    let reached = hip + pelvis * (hip_q * (Vec3::NEG_Y * l1 + knee_q * Vec3::NEG_Y * l2));
    (hip_q, knee_q, reached)
}

/// An ellipsoid with semi-axes `r` centred at `c`.
fn ellipsoid(c: Vec3, r: Vec3, rings: u32, segments: u32) -> Mesh {
    Mesh::uv_sphere(1.0, rings, segments).transformed(Mat4::from_scale_rotation_translation(
        r,
        Quat::IDENTITY,
        c,
    ))
}

/// A capsule along `Y` from `y0` to `y1` (the spheres' centres), scaled by `squash` across.
fn limb(y0: f32, y1: f32, radius: f32, squash: Vec3) -> Mesh {
    let half = 0.5 * (y1 - y0).abs();
    Mesh::capsule(radius, half, 8, 12).transformed(Mat4::from_scale_rotation_translation(
        squash,
        Quat::IDENTITY,
        Vec3::new(0.0, 0.5 * (y0 + y1), 0.0),
    ))
}

/// A flattened ellipsoid with semi-axes `r` centred at `c`: elliptic seen from above, flat at the
/// top and the bottom with rounded edges (the superellipsoid of revolution `(x^2 + z^2)^(p/2) +
/// |y|^p = 1`, scaled; `p = 2` is the ellipsoid). Each vertex of a unit sphere keeps its direction
/// about `Y` while its distance from the axis and its height are raised to `2/p`, both increasing,
/// so that the mesh stays closed and wound outward.
fn flat_ellipsoid(c: Vec3, r: Vec3, p: f32, rings: u32, segments: u32) -> Mesh {
    let mut m = Mesh::uv_sphere(1.0, rings, segments);
    let e = 2.0 / p;
    for v in &mut m.positions {
        let rho = v.x.hypot(v.z);
        let spread = if rho > 0.0 { rho.powf(e) / rho } else { 0.0 };
        let bent = Vec3::new(v.x * spread, v.y.signum() * v.y.abs().powf(e), v.z * spread);
        *v = c + bent * r;
    }
    m
}

/// The boot, in the ankle's frame (`+X` forward, the sole 8 cm under the ankle):
///
/// | piece | shape | along the foot (from the ankle) | bottom above the sole |
/// |---|---|---|---|
/// | heel block | flattened ellipsoid, 11 x 9 cm | -11 to 0 cm, flat from about -9 to -2 | 0 |
/// | ankle | ellipsoid | -8 to +1 cm | 4 cm |
/// | upper, over the arch | ellipsoid | -5 to +17 cm | 9 cm |
/// | ball and toes | flattened ellipsoid, 14 x 9.6 cm | +7 to +21 cm, flat from about +9 to +19 | 0 |
/// | toe cap | ellipsoid | +15.5 to +22.5 cm | 0.5 cm |
///
/// Pressed flat into snow it leaves a flat-bottomed heel and a flat-bottomed ball and toe, 7 cm
/// apart, with the arch's snow, 9 cm shallower, between them. At the talk's 4 cm texels a heel
/// much smaller than this one is lost in the capture's blur.
pub fn foot_mesh() -> Mesh {
    let sole = -ANKLE_HEIGHT;
    let mut m = Mesh::default();
    // Heel block: flat-bottomed, so that the heel's print is one depth with steep sides.
    m.append(&flat_ellipsoid(
        Vec3::new(-0.055, sole + 0.045, 0.0),
        Vec3::new(0.055, 0.045, 0.045),
        6.0,
        12,
        16,
    ));
    // Ankle: over the heel, up into the shin; its bottom 4 cm above the sole, so that it stays
    // out of the arch's snow.
    m.append(&ellipsoid(
        Vec3::new(-0.035, 0.02, 0.0),
        Vec3::new(0.045, 0.06, 0.042),
        8,
        12,
    ));
    // Upper: from the heel over the arch to the ball; its bottom 9 cm above the sole.
    m.append(&ellipsoid(
        Vec3::new(0.06, sole + 0.125, 0.0),
        Vec3::new(0.11, 0.035, 0.045),
        8,
        12,
    ));
    // Ball and toes: the widest part, flat-bottomed.
    m.append(&flat_ellipsoid(
        Vec3::new(0.14, sole + 0.035, 0.0),
        Vec3::new(0.07, 0.035, FOOT_WIDTH * 0.5),
        3.0,
        12,
        16,
    ));
    // Toe cap: rounds the front of the print.
    m.append(&ellipsoid(
        Vec3::new(0.19, sole + 0.035, 0.0),
        Vec3::new(0.035, 0.03, 0.05),
        6,
        10,
    ));
    m
}

/// The mesh of a part in its joint frame (closed, counter-clockwise seen from outside).
pub fn part_mesh(part: Part) -> Mesh {
    use Part::*;
    let one = Vec3::ONE;
    match part {
        Pelvis => ellipsoid(
            Vec3::new(0.0, -0.01, 0.0),
            Vec3::new(0.11, 0.11, 0.17),
            8,
            14,
        ),
        Torso => {
            let mut m = ellipsoid(
                Vec3::new(0.0, 0.12, 0.0),
                Vec3::new(0.11, 0.15, 0.16),
                8,
                14,
            );
            m.append(&ellipsoid(
                Vec3::new(0.0, 0.30, 0.0),
                Vec3::new(0.12, 0.16, 0.21),
                8,
                14,
            ));
            m
        }
        Head => {
            let mut m = limb(0.0, 0.08, 0.05, one);
            m.append(&ellipsoid(
                Vec3::new(0.015, 0.185, 0.0),
                Vec3::new(0.10, 0.12, 0.08),
                10,
                14,
            ));
            m
        }
        UpperArmRight | UpperArmLeft => limb(0.0, -UPPER_ARM, 0.048, one),
        ForearmRight | ForearmLeft => limb(0.0, -FOREARM, 0.04, one),
        HandRight | HandLeft => ellipsoid(
            Vec3::new(0.0, -0.08, 0.0),
            Vec3::new(0.045, 0.085, 0.024),
            6,
            10,
        ),
        ThighRight | ThighLeft => limb(0.0, -THIGH, 0.075, one),
        // The shin stops short of the ankle so that the boot alone shapes the print.
        ShinRight | ShinLeft => limb(0.0, -SHIN + 0.06, 0.055, one),
        FootRight | FootLeft => foot_mesh(),
    }
}

/// The meshes of every part, in [`Part::ALL`] order.
pub fn part_meshes() -> Vec<Mesh> {
    Part::ALL.iter().map(|&p| part_mesh(p)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parents_come_first_and_standing_height_is_human() {
        for (i, p) in Part::ALL.iter().enumerate() {
            assert_eq!(p.index(), i);
            if let Some(parent) = p.parent() {
                assert!(parent.index() < i, "{p:?}");
            }
        }
        let pose = BodyPose::standing(Vec3::new(0.0, PELVIS_HEIGHT, 0.0), 0.0);
        let world = pose.world();
        let meshes = part_meshes();
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for (m, w) in meshes.iter().zip(world.iter()) {
            for &v in &m.positions {
                let y = (w.position + w.rotation * v).y;
                lo = lo.min(y);
                hi = hi.max(y);
            }
        }
        assert!(lo.abs() < 0.005, "soles at {lo}");
        assert!((1.74..1.86).contains(&(hi - lo)), "height {}", hi - lo);
        assert!((HEIGHT - (hi - lo)).abs() < 0.03, "{HEIGHT} vs {}", hi - lo);
    }

    #[test]
    fn leg_solver_reaches_its_target() {
        let pelvis = Quat::from_rotation_y(0.7) * flex(-0.1);
        let hip = Vec3::new(1.0, 0.9, 2.0);
        for target in [
            Vec3::new(1.2, 0.15, 2.1),
            Vec3::new(0.8, 0.3, 1.9),
            Vec3::new(1.0, 0.5, 2.3),
        ] {
            let (h, k, reached) = solve_leg(pelvis, hip, target);
            assert!(reached.distance(target) < 1e-4, "{reached} vs {target}");
            // Forward kinematics with the same rotations agrees.
            let fk = hip + pelvis * h * (Vec3::NEG_Y * THIGH + k * Vec3::NEG_Y * SHIN);
            assert!(fk.distance(target) < 1e-4);
            // The knee bends forward: the knee lies ahead of the hip-ankle line.
            let knee = hip + pelvis * h * Vec3::NEG_Y * THIGH;
            let fwd = pelvis * Vec3::X;
            let mid = 0.5 * (hip + target);
            assert!((knee - mid).dot(fwd) > 0.0);
        }
    }
}
