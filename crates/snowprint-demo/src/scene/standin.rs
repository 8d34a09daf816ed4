//! The stand-in demo world (`snowprint demo --scene standin`), built in code before the demo crate's
//! own demo world ([`crate::DemoWorld`]) existed and kept as a small, self-contained second world:
//! three flat roofs at different heights (concrete, roof tiles, and one nobody walks on, so
//! it keeps the basic material), a street with lamps, facades with lit windows, a water tower, and
//! capsule people: one walks (heel, ball, arch and toe blocks per boot), one runs down the street, one
//! slides feet-first, one falls onto its back from standing, one makes a snow angel. Each body part
//! is both drawn and pressed into the snow, as in the talk.

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{Instance, MeshMaterial, PointLight, RenderMeshId, Renderer};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
};

use super::DemoScene;

const TAU: f32 = std::f32::consts::TAU;
const PI: f32 = std::f32::consts::PI;

/// A closed cylinder along +Y from y = 0 to `height`.
fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, height, 0.0)];
    for s in 0..segments {
        let a = TAU * s as f32 / segments as f32;
        let (x, z) = (radius * a.cos(), radius * a.sin());
        positions.push(Vec3::new(x, 0.0, z));
        positions.push(Vec3::new(x, height, z));
    }
    let mut indices = Vec::new();
    let ring = |s: u32, top: u32| 2 + 2 * (s % segments) + top;
    for s in 0..segments {
        let (b0, t0, b1, t1) = (ring(s, 0), ring(s, 1), ring(s + 1, 0), ring(s + 1, 1));
        // Outward, counter-clockwise seen from outside (theta grows towards -z x +x = ... see mesh.rs).
        indices.extend_from_slice(&[b0, t0, t1, b0, t1, b1]);
        indices.extend_from_slice(&[0, b0, b1]);
        indices.extend_from_slice(&[1, t1, t0]);
    }
    Mesh { positions, indices }
}

/// A cone along +Y from a base of `radius` at y = 0 to the apex at `height`.
fn cone(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, height, 0.0)];
    for s in 0..segments {
        let a = TAU * s as f32 / segments as f32;
        positions.push(Vec3::new(radius * a.cos(), 0.0, radius * a.sin()));
    }
    let mut indices = Vec::new();
    for s in 0..segments {
        let (a, b) = (2 + s, 2 + (s + 1) % segments);
        indices.extend_from_slice(&[a, 1, b, 0, a, b]);
    }
    Mesh { positions, indices }
}

fn boxed(center: Vec3, half: Vec3) -> Mat4 {
    Mat4::from_scale_rotation_translation(half * 2.0, Quat::IDENTITY, center)
}

/// Limb dimensions, metres.
const THIGH: f32 = 0.45;
const SHIN: f32 = 0.44;
const UPPER_ARM: f32 = 0.30;
const FOREARM: f32 = 0.28;
const TORSO: f32 = 0.50;
const FOOT: f32 = 0.27;

/// The drawn parts of a person.
#[derive(Clone, Copy)]
struct BodyMeshes {
    torso: RenderMeshId,
    head: RenderMeshId,
    upper_arm: RenderMeshId,
    forearm: RenderMeshId,
    thigh: RenderMeshId,
    shin: RenderMeshId,
    boot: RenderMeshId,
}

/// A posed person: joints in world space and the frame of each foot.
#[derive(Clone, Copy, Debug)]
struct Skeleton {
    pelvis: Vec3,
    neck: Vec3,
    head: Vec3,
    shoulders: [Vec3; 2],
    elbows: [Vec3; 2],
    hands: [Vec3; 2],
    hips: [Vec3; 2],
    knees: [Vec3; 2],
    ankles: [Vec3; 2],
    /// Heel point on the sole and the unit forward and up of each foot.
    feet: [(Vec3, Vec3, Vec3); 2],
}

fn segment_pose(a: Vec3, b: Vec3) -> Pose {
    let d = b - a;
    Pose {
        position: (a + b) * 0.5,
        rotation: Quat::from_rotation_arc(Vec3::Y, d.normalize_or(Vec3::Y)),
    }
}

fn pose_matrix(p: &Pose) -> Mat4 {
    Mat4::from_rotation_translation(p.rotation, p.position)
}

fn foot_rotation(fwd: Vec3, up: Vec3) -> Quat {
    let side = fwd.cross(up).normalize();
    Quat::from_mat3(&glam::Mat3::from_cols(fwd, up, side))
}

/// The parts of a skeleton as capsules (a: start, b: end, radius) and the feet.
impl Skeleton {
    fn capsules(&self) -> Vec<(Vec3, Vec3, f32)> {
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
    fn foot_shapes(&self) -> Vec<(Shape, Pose)> {
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
    fn shapes(&self) -> Vec<(Shape, Pose)> {
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

    fn instances(&self, m: &BodyMeshes, coat: [f32; 3], trousers: [f32; 3]) -> Vec<Instance> {
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
    fn transformed(&self, pivot: Vec3, q: Quat, shift: Vec3) -> Skeleton {
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
fn knee(hip: Vec3, ankle: Vec3, forward: Vec3) -> Vec3 {
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
struct Gait {
    start: Vec3,
    dir: Vec3,
    speed: f32,
    period: f32,
    stance: f32,
    lift: f32,
    t0: f32,
    t1: f32,
}

impl Gait {
    /// Heel point, forward and up of foot `i` at time `t` (clamped to the walk).
    fn foot(&self, i: usize, t: f32) -> (Vec3, Vec3, Vec3) {
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

    fn skeleton(&self, t: f32) -> Skeleton {
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
fn standing(ground: Vec3, dir: Vec3, arms_out: f32, legs_out: f32) -> Skeleton {
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
enum Act {
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
fn lying(ground: Vec3, head_dir: Vec3, arms_out: f32, legs_out: f32) -> Skeleton {
    // Standing facing away from the head direction, then turned backwards by 90 degrees: its up
    // goes to `head_dir`, its front to +Y.
    let facing = -head_dir;
    let s = standing(ground, facing, arms_out, legs_out);
    let side = facing.cross(Vec3::Y).normalize();
    let q = Quat::from_axis_angle(side, 0.5 * PI);
    s.transformed(ground, q, Vec3::Y * 0.13)
}

impl Act {
    fn skeleton(&self, t: f32) -> Skeleton {
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

struct Person {
    act: Act,
    coat: [f32; 3],
    trousers: [f32; 3],
    /// Leaves the scene at this time (the stand-in has no getting-up animation: the fallen person
    /// vanishes so that the imprint of the body can be seen).
    leaves: Option<f32>,
}

impl Person {
    fn present(&self, t: f32) -> bool {
        self.leaves.is_none_or(|l| t < l)
    }
}

/// The stand-in world.
pub struct StandIn {
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
    statics: Vec<Instance>,
    lights: Vec<PointLight>,
    people: Vec<Person>,
    body: BodyMeshes,
}

/// Ground heights of the roofs and the street.
const ROOF_A: f32 = 12.0;
const ROOF_B: f32 = 9.0;
const ROOF_C: f32 = 6.0;

impl StandIn {
    /// Build the world: surfaces into `world`, meshes into `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let err = |e: snowprint::SnowError| e.to_string();
        let rerr = |e: snowprint::render::RenderError| e.to_string();
        let mut surfaces = Vec::new();
        let mut add = |desc: SurfaceDesc, ground| -> Result<(), String> {
            surfaces.push((world.add_surface(desc).map_err(err)?, ground));
            Ok(())
        };
        add(
            SurfaceDesc::new("roof_a", [0.0, ROOF_A, 0.0], [12.0, 8.0], 0.16),
            GroundMaterial::Concrete,
        )?;
        add(
            SurfaceDesc::new("roof_b", [11.3, ROOF_B, 0.5], [9.0, 7.0], 0.14),
            GroundMaterial::RoofTiles,
        )?;
        add(
            SurfaceDesc::new("roof_c", [-11.5, ROOF_C, 0.0], [8.0, 7.0], 0.25),
            GroundMaterial::RoofTiles,
        )?;
        add(
            SurfaceDesc::new("street", [2.0, 0.0, 9.5], [44.0, 8.0], 0.12),
            GroundMaterial::Concrete,
        )?;

        let unit_box = renderer
            .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
            .map_err(rerr)?;
        let tank = renderer.add_mesh(&cylinder(1.25, 2.3, 32)).map_err(rerr)?;
        let tank_roof = renderer.add_mesh(&cone(1.4, 0.9, 32)).map_err(rerr)?;
        let pole = renderer.add_mesh(&cylinder(0.07, 4.6, 10)).map_err(rerr)?;
        let bulb = renderer
            .add_mesh(&Mesh::uv_sphere(0.16, 8, 16))
            .map_err(rerr)?;
        let capsule = |r: f32, len: f32| Mesh::capsule(r, len * 0.5, 8, 12);
        let body = BodyMeshes {
            torso: renderer.add_mesh(&capsule(0.16, TORSO)).map_err(rerr)?,
            head: renderer
                .add_mesh(&Mesh::uv_sphere(0.11, 10, 16))
                .map_err(rerr)?,
            upper_arm: renderer.add_mesh(&capsule(0.05, UPPER_ARM)).map_err(rerr)?,
            forearm: renderer.add_mesh(&capsule(0.045, FOREARM)).map_err(rerr)?,
            thigh: renderer.add_mesh(&capsule(0.075, THIGH)).map_err(rerr)?,
            shin: renderer.add_mesh(&capsule(0.06, SHIN)).map_err(rerr)?,
            boot: renderer
                .add_mesh(&Mesh::cuboid(Vec3::new(FOOT * 0.5, 0.045, 0.05)))
                .map_err(rerr)?,
        };

        let brick = [0.36, 0.16, 0.11];
        let dark_brick = [0.24, 0.14, 0.11];
        let stone = [0.42, 0.40, 0.37];
        let mut statics = Vec::new();
        let block =
            |center: Vec3, half: Vec3, albedo: [f32; 3], material: MeshMaterial, seed: f32| {
                Instance::new(unit_box, boxed(center, half), albedo)
                    .with_material(material)
                    .with_seed(seed)
            };
        // Building A under roof A (12 x 8 of snow inside 0.3 m parapets).
        statics.push(block(
            Vec3::new(0.0, ROOF_A * 0.5, 0.0),
            Vec3::new(6.3, ROOF_A * 0.5, 4.3),
            brick,
            MeshMaterial::Facade,
            0.1,
        ));
        // Building B under roof B, building C under roof C.
        statics.push(block(
            Vec3::new(11.3, ROOF_B * 0.5, 0.5),
            Vec3::new(4.8, ROOF_B * 0.5, 3.8),
            dark_brick,
            MeshMaterial::Facade,
            0.4,
        ));
        statics.push(block(
            Vec3::new(-11.5, ROOF_C * 0.5, 0.0),
            Vec3::new(4.3, ROOF_C * 0.5, 3.8),
            [0.3, 0.22, 0.17],
            MeshMaterial::Facade,
            0.7,
        ));
        // Parapets.
        let parapet = |cx: f32, cz: f32, y: f32, hx: f32, hz: f32| {
            (Vec3::new(cx, y + 0.45, cz), Vec3::new(hx, 0.45, hz))
        };
        for (c, h) in [
            parapet(0.0, -4.15, ROOF_A, 6.3, 0.15),
            parapet(0.0, 4.15, ROOF_A, 6.3, 0.15),
            parapet(-6.15, 0.0, ROOF_A, 0.15, 4.0),
            parapet(6.15, 0.0, ROOF_A, 0.15, 4.0),
            parapet(11.3, 4.15, ROOF_B, 4.8, 0.15),
            parapet(11.3, -3.15, ROOF_B, 4.8, 0.15),
            parapet(15.95, 0.5, ROOF_B, 0.15, 3.5),
            parapet(-11.5, 3.65, ROOF_C, 4.3, 0.15),
            parapet(-11.5, -3.65, ROOF_C, 4.3, 0.15),
            parapet(-15.65, 0.0, ROOF_C, 0.15, 3.5),
            parapet(-7.35, 0.0, ROOF_C, 0.15, 3.5),
        ] {
            statics.push(block(c, h, stone, MeshMaterial::Concrete, 0.0));
        }
        // Sidewalks along the fronts, and the buildings across the street.
        statics.push(block(
            Vec3::new(2.0, 0.08, 5.0),
            Vec3::new(22.0, 0.08, 0.5),
            [0.35, 0.35, 0.34],
            MeshMaterial::Concrete,
            0.0,
        ));
        statics.push(block(
            Vec3::new(2.0, 0.08, 14.0),
            Vec3::new(22.0, 0.08, 0.5),
            [0.35, 0.35, 0.34],
            MeshMaterial::Concrete,
            0.0,
        ));
        statics.push(block(
            Vec3::new(-10.0, 9.0, 20.5),
            Vec3::new(8.0, 9.0, 6.0),
            [0.3, 0.2, 0.15],
            MeshMaterial::Facade,
            0.2,
        ));
        statics.push(block(
            Vec3::new(6.0, 12.0, 20.5),
            Vec3::new(8.0, 12.0, 6.0),
            [0.4, 0.25, 0.18],
            MeshMaterial::Facade,
            0.5,
        ));
        statics.push(block(
            Vec3::new(19.0, 7.5, 20.5),
            Vec3::new(5.0, 7.5, 6.0),
            [0.28, 0.26, 0.24],
            MeshMaterial::Facade,
            0.9,
        ));
        // Beyond: a dark wall of the city.
        statics.push(block(
            Vec3::new(2.0, 15.0, -14.0),
            Vec3::new(30.0, 15.0, 6.0),
            [0.2, 0.15, 0.13],
            MeshMaterial::Facade,
            0.3,
        ));
        // A vent and a chimney on roof A (clear of the walkers' paths).
        statics.push(block(
            Vec3::new(4.6, ROOF_A + 0.6, -2.9),
            Vec3::new(0.6, 0.6, 0.5),
            [0.35, 0.36, 0.38],
            MeshMaterial::Metal,
            0.0,
        ));
        statics.push(block(
            Vec3::new(-5.2, ROOF_A + 1.1, 3.2),
            Vec3::new(0.35, 1.1, 0.35),
            brick,
            MeshMaterial::Brick,
            0.6,
        ));

        // The water tower on roof A: legs standing in the snow, a tank, a conical roof.
        let tower = Vec3::new(-3.6, ROOF_A, -2.3);
        for (dx, dz) in [(-0.9, -0.9), (0.9, -0.9), (-0.9, 0.9), (0.9, 0.9)] {
            statics.push(block(
                tower + Vec3::new(dx, 1.3, dz),
                Vec3::new(0.08, 1.3, 0.08),
                [0.18, 0.16, 0.15],
                MeshMaterial::Metal,
                0.0,
            ));
        }
        statics.push(block(
            tower + Vec3::new(0.0, 2.65, 0.0),
            Vec3::new(1.3, 0.06, 1.3),
            [0.2, 0.17, 0.15],
            MeshMaterial::Metal,
            0.0,
        ));
        statics.push(
            Instance::new(
                tank,
                Mat4::from_translation(tower + Vec3::Y * 2.7),
                [0.32, 0.2, 0.14],
            )
            .with_material(MeshMaterial::Metal),
        );
        statics.push(
            Instance::new(
                tank_roof,
                Mat4::from_translation(tower + Vec3::Y * 5.0),
                [0.22, 0.16, 0.12],
            )
            .with_material(MeshMaterial::Metal),
        );

        // Street lamps: sodium orange.
        let mut lights = Vec::new();
        for x in [-13.0, -3.0, 7.0, 17.0] {
            let base = Vec3::new(x, 0.0, 5.6);
            statics.push(
                Instance::new(pole, Mat4::from_translation(base), [0.08, 0.08, 0.09])
                    .with_material(MeshMaterial::Metal),
            );
            let head = base + Vec3::new(0.0, 4.6, 0.5);
            statics.push(block(
                base + Vec3::new(0.0, 4.65, 0.25),
                Vec3::new(0.05, 0.04, 0.3),
                [0.08, 0.08, 0.09],
                MeshMaterial::Metal,
                0.0,
            ));
            statics.push(
                Instance::new(bulb, Mat4::from_translation(head), [1.0, 0.62, 0.28])
                    .with_material(MeshMaterial::Emissive)
                    .with_emission(6.0)
                    .with_shadow(false),
            );
            lights.push(PointLight {
                position: head - Vec3::Y * 0.25,
                color: Vec3::new(1.0, 0.55, 0.22) * 7.0,
                radius: 14.0,
            });
        }
        // A warm window light spilling onto roof B from the taller building A? A lamp by the roof
        // door of roof A instead.
        lights.push(PointLight {
            position: Vec3::new(5.4, ROOF_A + 2.2, 3.4),
            color: Vec3::new(1.0, 0.7, 0.4) * 1.6,
            radius: 7.0,
        });

        let coat = |r, g, b| [r, g, b];
        let people = vec![
            // Walks across roof A, left to right, behind the camera's close-up.
            Person {
                act: Act::Walk(Gait {
                    start: Vec3::new(-5.2, ROOF_A - 0.03, 1.4),
                    dir: Vec3::X,
                    speed: 1.25,
                    period: 1.1,
                    stance: 0.62,
                    lift: 0.42,
                    t0: 0.0,
                    t1: 8.2,
                }),
                coat: coat(0.08, 0.09, 0.12),
                trousers: coat(0.06, 0.06, 0.07),
                leaves: None,
            },
            // Runs down the street.
            Person {
                act: Act::Walk(Gait {
                    start: Vec3::new(-16.0, -0.03, 8.6),
                    dir: Vec3::new(1.0, 0.0, 0.08).normalize(),
                    speed: 3.6,
                    period: 0.72,
                    stance: 0.42,
                    lift: 0.45,
                    t0: 0.5,
                    t1: 10.0,
                }),
                coat: coat(0.35, 0.05, 0.04),
                trousers: coat(0.07, 0.07, 0.1),
                leaves: None,
            },
            // Slides feet-first across roof B.
            Person {
                act: Act::Slide {
                    from: Vec3::new(9.6, ROOF_B, 1.6),
                    to: Vec3::new(14.4, ROOF_B, 1.2),
                    t0: 1.5,
                    t1: 4.0,
                },
                coat: coat(0.12, 0.2, 0.1),
                trousers: coat(0.1, 0.08, 0.06),
                leaves: None,
            },
            // Falls onto its back on roof A.
            Person {
                act: Act::Fall {
                    at: Vec3::new(-1.3, ROOF_A + 0.02, -0.5),
                    dir: Vec3::new(0.0, 0.0, 1.0),
                    t_fall: 4.5,
                },
                coat: coat(0.3, 0.26, 0.2),
                trousers: coat(0.08, 0.08, 0.09),
                leaves: Some(6.5),
            },
            // Makes a snow angel on roof A.
            Person {
                act: Act::Angel {
                    at: Vec3::new(2.6, ROOF_A, -1.2),
                    dir: Vec3::new(0.0, 0.0, -1.0),
                    t0: 0.5,
                    t1: 6.5,
                },
                coat: coat(0.1, 0.18, 0.35),
                trousers: coat(0.06, 0.06, 0.08),
                leaves: None,
            },
        ];
        Ok(Self {
            surfaces,
            statics,
            lights,
            people,
            body,
        })
    }
}

fn catmull_rom(points: &[Vec3], u: f32) -> Vec3 {
    let n = points.len();
    if n == 1 {
        return points[0];
    }
    let f = u.clamp(0.0, 1.0) * (n - 1) as f32;
    let i = (f.floor() as usize).min(n - 2);
    let t = f - i as f32;
    let p = |k: isize| points[(i as isize + k).clamp(0, n as isize - 1) as usize];
    let (p0, p1, p2, p3) = (p(-1), p(0), p(1), p(2));
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t * t * t)
}

/// Cameras of the stand-in world.
const CAMERAS: &[&str] = &[
    "flythrough",
    "closeup",
    "overview",
    "street",
    "angel",
    "fall",
    "slide",
];

impl DemoScene for StandIn {
    fn name(&self) -> &str {
        "stand-in (crates/snowprint-cli/src/standin.rs)"
    }

    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)] {
        &self.surfaces
    }

    fn lights(&self) -> &[PointLight] {
        &self.lights
    }

    fn advance(&self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
        let mut out = Vec::new();
        for p in self.people.iter().filter(|p| p.present(t1)) {
            let a = p.act.skeleton(t0).shapes();
            let b = p.act.skeleton(t1).shapes();
            for ((shape, prev), (_, pose)) in a.into_iter().zip(b) {
                out.push(Deformer::moving(shape, prev, pose));
            }
        }
        world
            .step(t1 - t0, &out)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    fn instances(&self, t: f32) -> Vec<Instance> {
        let mut v = self.statics.clone();
        for p in self.people.iter().filter(|p| p.present(t)) {
            v.extend(p.act.skeleton(t).instances(&self.body, p.coat, p.trousers));
        }
        v
    }

    fn cameras(&self) -> &[&'static str] {
        CAMERAS
    }

    fn span(&self, camera: &str) -> (f32, f32) {
        match camera {
            "closeup" => (3.5, 8.5),
            "angel" | "fall" | "slide" => (4.0, 8.0),
            _ => (2.0, 10.0),
        }
    }

    fn camera(&self, name: &str, t: f32) -> Option<Camera> {
        let (t0, t1) = self.span(name);
        let u = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let cam = |eye: Vec3, target: Vec3, fov: f32| Camera {
            eye,
            target,
            fov_y_degrees: fov,
        };
        Some(match name {
            "flythrough" => {
                // Over the street, down to the slide on roof B, across to the snow angel, the fall
                // and the walker's prints on roof A.
                let eyes = [
                    Vec3::new(-13.0, 17.0, 12.0),
                    Vec3::new(-2.0, 16.5, 11.0),
                    Vec3::new(8.0, 14.5, 8.0),
                    Vec3::new(6.5, 14.6, 3.6),
                    Vec3::new(1.5, 14.3, 2.6),
                    Vec3::new(-2.6, 14.0, 3.8),
                ];
                let targets = [
                    Vec3::new(2.0, 9.0, 0.0),
                    Vec3::new(8.0, 9.5, 1.0),
                    Vec3::new(11.0, 9.0, 0.8),
                    Vec3::new(2.8, 12.0, -1.4),
                    Vec3::new(-1.4, 12.0, -2.6),
                    Vec3::new(0.4, 12.1, 1.0),
                ];
                let s = u * u * (3.0 - 2.0 * u);
                cam(catmull_rom(&eyes, s), catmull_rom(&targets, s), 50.0)
            }
            "closeup" => {
                // A slow dolly along the walker's prints on roof A.
                let x = -3.4 + 2.4 * u;
                cam(
                    Vec3::new(x, ROOF_A + 2.3, 3.6),
                    Vec3::new(x + 0.9, ROOF_A + 0.1, 1.0),
                    45.0,
                )
            }
            "angel" => cam(
                Vec3::new(0.6, ROOF_A + 2.6, 0.4),
                Vec3::new(2.7, ROOF_A, -2.0),
                50.0,
            ),
            "fall" => cam(
                Vec3::new(0.4, ROOF_A + 2.3, 1.2),
                Vec3::new(-1.4, ROOF_A, -1.4),
                50.0,
            ),
            "slide" => cam(
                Vec3::new(9.0, ROOF_B + 2.3, 3.9),
                Vec3::new(12.6, ROOF_B, 1.2),
                50.0,
            ),
            "overview" => cam(Vec3::new(0.0, 34.0, 16.0), Vec3::new(2.0, 8.0, 1.0), 50.0),
            "street" => cam(Vec3::new(-13.0, 1.7, 12.2), Vec3::new(2.0, 0.8, 8.0), 55.0),
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walking_foot_is_planted_then_swings() {
        let g = Gait {
            start: Vec3::ZERO,
            dir: Vec3::X,
            speed: 1.25,
            period: 1.1,
            stance: 0.62,
            lift: 0.4,
            t0: 0.0,
            t1: 10.0,
        };
        // Mid-stance of the left foot in cycle 2: flat on the ground.
        let (heel, fwd, up) = g.foot(0, 1.1 * 2.3);
        assert!(
            heel.y.abs() < 1e-4
                && (fwd - Vec3::X).length() < 1e-4
                && (up - Vec3::Y).length() < 1e-4
        );
        // Mid-swing: in the air.
        let (heel, _, _) = g.foot(0, 1.1 * 2.8);
        assert!(heel.y > 0.3);
        let s = g.skeleton(3.0);
        for i in 0..2 {
            assert!((s.hips[i].distance(s.knees[i]) - THIGH).abs() < 1e-3);
        }
    }

    #[test]
    fn generated_meshes_are_closed_and_outward() {
        for m in [cylinder(1.0, 2.0, 16), cone(1.0, 1.0, 16)] {
            m.validate("m").unwrap();
            let v = m.signed_volume();
            assert!(v > 0.0, "volume {v}");
        }
    }
}
