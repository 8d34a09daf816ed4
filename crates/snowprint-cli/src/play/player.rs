//! The person the player steers: the demo crate's articulated body, animated by its own gait,
//! slide and fall ([`snowprint_demo::anim`]), with the footfalls planned a step ahead from the
//! keys instead of from a script, and snowballs.
//!
//! The gait is the demo's [`Gait`] grown as the person walks: each step, the foot whose turn it is
//! gets a lift time and a new footfall where the pelvis will be at the middle of its stance if it
//! keeps its velocity; the footfall follows the keys while the foot swings and is fixed once it
//! strikes. The pelvis path is appended a key a frame. The body's clock is the person's own: the
//! caller runs it at the trudge pace of the snow under the feet ([`snowprint_demo::trudge`]), and
//! lowers the walking body by the trudge sink, so that the feet press part of the snow, not all.

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Vec2, Vec3};
use snowprint::{Deformer, MeshId, Pose, Shape};
use snowprint_demo::anim::{
    Action, Footfall, Gait, GaitStyle, Motion, PathKey, Segment, Slide, Strike, Topple, forward_of,
    right_of, yaw_of,
};
use snowprint_demo::skeleton::{BodyPose, Part, Side, dims};

/// Walking speed, m/s of the person's clock.
pub const WALK_SPEED: f32 = 1.3;
/// Running speed, m/s.
pub const RUN_SPEED: f32 = 3.2;
/// Ankles either side of the path, metres.
const LATERAL: f32 = 0.1;
/// Seconds between deciding a step and its toe leaving (the toe roll plays meanwhile).
const LIFT_LEAD: f32 = 0.12;
/// A snowball's radius, metres.
pub const BALL_RADIUS: f32 = 0.11;
/// Snowballs kept (the oldest goes).
const MAX_BALLS: usize = 8;

/// What the body is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Doing {
    Walking,
    /// On the ground (slide or fall) until the clock reaches `until`, then standing up.
    Down {
        until: f32,
    },
}

/// A thrown snowball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Centre now, world metres.
    pub position: Vec3,
    /// Centre at the previous frame.
    pub previous: Vec3,
    velocity: Vec3,
}

/// What the keys ask of the person this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Intent {
    /// Desired direction of travel on the ground (x, z), length 0 to 1.
    pub direction: Vec2,
    /// Run rather than walk.
    pub run: bool,
    /// Start a slide / a fall / a throw this frame.
    pub slide: bool,
    /// Fall onto the back this frame.
    pub fall: bool,
    /// Throw a snowball this frame.
    pub throw: bool,
}

/// The player's person.
#[derive(Clone, Debug)]
pub struct Player {
    /// The person's own clock, seconds.
    clock: f32,
    position: Vec2,
    velocity: Vec2,
    yaw: f32,
    /// World height of the ground under the snow, and of the snow's top.
    ground: f32,
    snow_top: f32,
    /// Where the pelvis may go: `[min, max]` in (x, z).
    bounds: [Vec2; 2],
    motion: Motion,
    doing: Doing,
    next_step: f32,
    next_side: Side,
    running: bool,
    /// How far the walking body is lowered into the snow, metres (smoothed).
    sink: f32,
    balls: Vec<Ball>,
    /// Every part's pose at the previous frame and now.
    previous_parts: Vec<Pose>,
    parts: Vec<Pose>,
}

/// Shortest signed difference `b - a` between two angles.
fn angle_diff(a: f32, b: f32) -> f32 {
    (b - a + PI).rem_euclid(TAU) - PI
}

impl Player {
    /// A person standing at `at` (x, z) facing `yaw`, on snow whose ground is at `ground` and top
    /// at `snow_top`, kept within `bounds`.
    pub fn new(at: Vec2, yaw: f32, ground: f32, snow_top: f32, bounds: [Vec2; 2]) -> Self {
        let mut p = Self {
            clock: 0.0,
            position: at,
            velocity: Vec2::ZERO,
            yaw,
            ground,
            snow_top,
            bounds,
            motion: Motion::default(),
            doing: Doing::Walking,
            next_step: 0.0,
            next_side: Side::Right,
            running: false,
            sink: 0.0,
            balls: Vec::new(),
            previous_parts: Vec::new(),
            parts: Vec::new(),
        };
        p.stand_up(0.0);
        p.parts = p.pose_parts();
        p.previous_parts = p.parts.clone();
        p
    }

    /// A gait standing with both feet under the pelvis, starting now, blending in over `blend`.
    fn stand_up(&mut self, blend: f32) {
        let style = GaitStyle::trudge();
        let footfalls = [Side::Right, Side::Left]
            .map(|side| Footfall {
                side,
                strike: f32::NEG_INFINITY,
                lift: f32::INFINITY,
                ankle: self.ankle_at(side, self.position, self.yaw, &style),
                yaw: self.yaw,
            })
            .to_vec();
        let gait = Gait {
            footfalls,
            path: vec![self.path_key(&style)],
            style,
            strikes: Vec::new(),
        };
        self.push_segment(blend, Action::Gait(gait));
        self.doing = Doing::Walking;
        self.velocity = Vec2::ZERO;
        self.next_step = self.clock;
    }

    fn push_segment(&mut self, blend: f32, action: Action) {
        // The previous segment stays for the blend; older ones are no longer looked at.
        let keep = self.motion.segments.len().saturating_sub(1);
        self.motion.segments.drain(..keep);
        self.motion.segments.push(Segment {
            start: self.clock,
            blend,
            action,
        });
    }

    fn ankle_at(&self, side: Side, pelvis: Vec2, yaw: f32, style: &GaitStyle) -> Vec3 {
        Vec3::new(
            pelvis.x,
            self.snow_top + style.sole + dims::ANKLE_HEIGHT,
            pelvis.y,
        ) + right_of(yaw) * side.sign() * LATERAL
    }

    fn path_key(&self, style: &GaitStyle) -> PathKey {
        PathKey {
            time: self.clock,
            position: Vec3::new(
                self.position.x,
                self.snow_top + style.hip_height,
                self.position.y,
            ),
            yaw: self.yaw,
        }
    }

    /// Pelvis position on the ground plane (x, z) and heading.
    pub fn position(&self) -> (Vec2, f32) {
        (self.position, self.yaw)
    }

    /// Whether the person is on the ground (sliding, fallen, getting up).
    pub fn is_down(&self) -> bool {
        matches!(self.doing, Doing::Down { .. })
    }

    /// The snowballs.
    pub fn balls(&self) -> &[Ball] {
        &self.balls
    }

    /// Every body part's pose now (in [`Part::ALL`] order).
    pub fn parts(&self) -> &[Pose] {
        &self.parts
    }

    /// The ankles now, left then right (where the snow under the feet is probed).
    pub fn feet(&self) -> [Vec3; 2] {
        [Side::Left, Side::Right].map(|side| {
            self.parts
                .get(Part::foot(side).index())
                .map_or(Vec3::ZERO, |p| p.position)
        })
    }

    /// Advance: the person's clock by `clock_dt` (the trudge pace applied), the snowballs by the
    /// world's `dt`; `sink` is how far the snow under the feet lets the walking body down.
    pub fn advance(&mut self, clock_dt: f32, dt: f32, sink: f32, intent: Intent) {
        let clock_dt = clock_dt.clamp(0.0, 0.25);
        self.clock += clock_dt;
        if intent.throw && !self.is_down() {
            self.throw();
        }
        match self.doing {
            Doing::Walking if intent.slide => self.slide(),
            Doing::Walking if intent.fall => self.fall(),
            Doing::Walking => self.walk(clock_dt, intent),
            Doing::Down { until } if self.clock >= until => {
                let root = self.motion.pose(self.clock).root;
                self.position = self.clamp(Vec2::new(root.x, root.z));
                self.stand_up(0.9);
            }
            Doing::Down { .. } => {
                let root = self.motion.pose(self.clock).root;
                self.position = Vec2::new(root.x, root.z);
            }
        }
        // The body sinks only while walking; the slide and the fall lie on the ground already.
        let target = if self.is_down() { 0.0 } else { sink };
        self.sink += (target - self.sink) * (1.0 - (-6.0 * clock_dt).exp());
        self.fly_balls(dt);
        let now = self.pose_parts();
        self.previous_parts = std::mem::replace(&mut self.parts, now);
    }

    fn clamp(&self, p: Vec2) -> Vec2 {
        p.clamp(self.bounds[0], self.bounds[1])
    }

    /// Move the pelvis by the keys and plan the feet.
    fn walk(&mut self, dt: f32, intent: Intent) {
        self.running = intent.run;
        let want = intent.direction.clamp_length_max(1.0)
            * if intent.run { RUN_SPEED } else { WALK_SPEED };
        // Reach the wanted velocity in about a quarter of a second.
        self.velocity += (want - self.velocity) * (1.0 - (-8.0 * dt).exp());
        if self.velocity.length() < 0.02 && want == Vec2::ZERO {
            self.velocity = Vec2::ZERO;
        }
        let moved = self.clamp(self.position + self.velocity * dt);
        if dt > 0.0 {
            self.velocity = (moved - self.position) / dt;
        }
        self.position = moved;
        if self.velocity.length() > 0.1 {
            let goal = yaw_of(self.velocity);
            self.yaw += angle_diff(self.yaw, goal) * (1.0 - (-10.0 * dt).exp());
        }
        let clock = self.clock;
        let moving = want != Vec2::ZERO || self.velocity.length() > 0.2;
        let (step_time, duty) = if self.running {
            (0.3, 0.4)
        } else {
            (0.5, 0.62)
        };
        let stride = 2.0 * step_time;
        let (swing, stance) = ((1.0 - duty) * stride, duty * stride);
        let style = if self.running {
            GaitStyle::run()
        } else {
            GaitStyle::trudge()
        };
        let key = self.path_key(&style);
        let (position, velocity, yaw) = (self.position, self.velocity, self.yaw);
        let ankle_y = self.snow_top + style.sole + dims::ANKLE_HEIGHT;
        let place = move |side: Side, at: f32| {
            let p = position + velocity * (at - clock).max(0.0);
            Vec3::new(p.x, ankle_y, p.y) + right_of(yaw) * side.sign() * LATERAL
        };
        let next_side = self.next_side;
        let step_due = moving && clock >= self.next_step;
        let Some(Segment {
            action: Action::Gait(gait),
            ..
        }) = self.motion.segments.last_mut()
        else {
            return;
        };
        gait.style = style;
        gait.path.push(key);
        gait.path.retain(|k| k.time >= clock - 2.0);
        // A swinging foot follows the keys until it strikes.
        for f in gait.footfalls.iter_mut().filter(|f| f.strike > clock) {
            f.ankle = place(f.side, f.strike + 0.5 * stance);
            f.yaw = yaw;
        }
        if step_due {
            let planted = gait
                .footfalls
                .iter_mut()
                .rev()
                .find(|f| f.side == next_side)
                .filter(|f| f.strike <= clock && f.lift.is_infinite());
            if let Some(f) = planted {
                let lift = clock + LIFT_LEAD;
                f.lift = lift;
                let strike = lift + swing;
                gait.footfalls.push(Footfall {
                    side: next_side,
                    strike,
                    lift: f32::INFINITY,
                    ankle: place(next_side, strike + 0.5 * stance),
                    yaw,
                });
                self.next_side = next_side.other();
                self.next_step = clock + step_time;
            }
        } else if !moving {
            self.next_step = clock;
        }
        // Each side keeps the footfall it swings from and the one it swings to.
        for side in [Side::Left, Side::Right] {
            let n = gait.footfalls.iter().filter(|f| f.side == side).count();
            let mut drop = n.saturating_sub(2);
            gait.footfalls.retain(|f| {
                let old = f.side == side && drop > 0;
                drop -= usize::from(old);
                !old
            });
        }
    }

    /// Drop onto the back and slide feet first, faster than the person was going.
    fn slide(&mut self) {
        let speed = self.velocity.length().max(WALK_SPEED) + 2.0;
        let slide = Slide {
            start: self.position,
            yaw: self.yaw,
            ground: self.ground,
            drop_from: GaitStyle::trudge().hip_height + self.snow_top - self.ground - self.sink,
            drop_time: 0.3,
            speed,
            decel: 3.0,
        };
        let until = self.clock + slide.duration() + 1.0;
        self.push_segment(0.15, Action::Slide(slide));
        self.doing = Doing::Down { until };
    }

    /// Fall backwards like a plank, arms out, and lie a moment.
    fn fall(&mut self) {
        let topple = Topple {
            pivot: Vec3::new(self.position.x, self.snow_top - self.sink, self.position.y)
                - forward_of(self.yaw) * dims::HEEL_BACK,
            yaw: self.yaw,
            teeter: 0.25,
            tip_time: 0.8,
            release: FRAC_PI_2,
            land: self.ground,
            windmill: false,
            arms_out: 1.1,
        };
        let until = self.clock + topple.duration() + 1.2;
        self.push_segment(0.2, Action::Topple(topple));
        self.doing = Doing::Down { until };
    }

    /// Throw a snowball forward from the right shoulder (the right arm strikes out).
    fn throw(&mut self) {
        if let Some(Segment {
            action: Action::Gait(gait),
            ..
        }) = self.motion.segments.last_mut()
        {
            gait.strikes.retain(|s| s.time > self.clock - 1.0);
            gait.strikes.push(Strike {
                time: self.clock + 0.1,
                side: Some(Side::Right),
            });
        }
        let fwd = forward_of(self.yaw);
        let from = self
            .parts
            .get(Part::upper_arm(Side::Right).index())
            .map_or(Vec3::ZERO, |p| p.position)
            + fwd * 0.3;
        let v = self.velocity;
        let velocity = fwd * 6.0 + Vec3::Y * 2.5 + Vec3::new(v.x, 0.0, v.y);
        if self.balls.len() == MAX_BALLS {
            self.balls.remove(0);
        }
        self.balls.push(Ball {
            position: from,
            previous: from,
            velocity,
        });
    }

    /// Snowballs fly, plough through the snow they meet, and stop on the ground under it.
    fn fly_balls(&mut self, dt: f32) {
        let rest = self.ground + BALL_RADIUS * 0.8;
        for b in &mut self.balls {
            b.previous = b.position;
            if b.velocity == Vec3::ZERO {
                continue;
            }
            b.velocity.y -= snowprint_demo::anim::GRAVITY * dt;
            if b.position.y - BALL_RADIUS < self.snow_top {
                // In the snow: dragged to a stop within a few tens of centimetres.
                let drag = (-10.0 * dt).exp();
                b.velocity.x *= drag;
                b.velocity.z *= drag;
            }
            b.position += b.velocity * dt;
            if b.position.y <= rest {
                b.position.y = rest;
                b.velocity = Vec3::ZERO;
            }
        }
    }

    /// The body now: the motion at the person's clock, the walking body lowered by the sink.
    fn pose_parts(&self) -> Vec<Pose> {
        let mut body: BodyPose = self.motion.pose(self.clock);
        body.root.y -= self.sink;
        body.world().to_vec()
    }

    /// What presses the snow this frame: every body part (its mesh `part_meshes[i]`) from its
    /// previous pose, and every snowball.
    pub fn deformers(&self, part_meshes: &[MeshId]) -> Vec<Deformer> {
        let mut out: Vec<Deformer> = self
            .previous_parts
            .iter()
            .zip(&self.parts)
            .zip(part_meshes)
            .map(|((a, b), &id)| Deformer::moving(Shape::Mesh(id), *a, *b))
            .collect();
        out.extend(self.balls.iter().map(|b| {
            Deformer::moving(
                Shape::Sphere {
                    radius: BALL_RADIUS,
                },
                Pose::at(b.previous.to_array()),
                Pose::at(b.position.to_array()),
            )
        }));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn yard() -> Player {
        let b = [Vec2::splat(-9.0), Vec2::splat(9.0)];
        Player::new(Vec2::ZERO, 0.0, 0.0, 0.25, b)
    }

    fn run(p: &mut Player, seconds: f32, intent: Intent) {
        let dt = 1.0 / 30.0;
        for _ in 0..(seconds / dt).round() as u32 {
            p.advance(dt, dt, 0.1, intent);
        }
    }

    #[test]
    fn walking_moves_the_pelvis_and_plants_feet_ahead() {
        let mut p = yard();
        let east = Intent {
            direction: Vec2::X,
            ..Intent::default()
        };
        run(&mut p, 3.0, east);
        let (at, yaw) = p.position();
        // A quarter of a second to reach walking speed, then 1.3 m/s.
        assert!(at.x > 3.0 && at.x < 3.0 * WALK_SPEED, "{at}");
        assert!(at.y.abs() < 1e-3 && yaw.abs() < 1e-3);
        // Both feet near the pelvis, within the legs' reach, and never below the sunk snow top.
        for foot in p.feet() {
            assert!((foot.x - at.x).abs() < 0.7, "{foot} vs {at}");
            assert!(foot.y > 0.25 - 0.1 - 0.05, "{foot}");
        }
        // Stopping brings the body to rest.
        run(&mut p, 2.0, Intent::default());
        let (stop, _) = p.position();
        run(&mut p, 1.0, Intent::default());
        assert_eq!(p.position().0, stop);
        assert_eq!(p.parts(), p.previous_parts.as_slice());
    }

    #[test]
    fn the_yard_keeps_the_walker_in() {
        let mut p = yard();
        let north = Intent {
            direction: -Vec2::Y,
            run: true,
            ..Intent::default()
        };
        run(&mut p, 6.0, north);
        assert_eq!(p.position().0.y, -9.0);
    }

    #[test]
    fn slide_and_fall_lie_down_and_get_up() {
        for action in ["slide", "fall"] {
            let mut p = yard();
            let mut i = Intent {
                direction: Vec2::X,
                ..Intent::default()
            };
            run(&mut p, 1.0, i);
            let before = p.position().0;
            i.slide = action == "slide";
            i.fall = action == "fall";
            run(&mut p, 1.0 / 30.0, i);
            assert!(p.is_down(), "{action}");
            run(&mut p, 1.2, Intent::default());
            // The pelvis lies on the ground under the snow: the body presses the snow away.
            let pelvis = p.parts()[Part::Pelvis.index()].position;
            assert!(pelvis.y < 0.25, "{action}: pelvis at {pelvis}");
            run(&mut p, 6.0, Intent::default());
            assert!(!p.is_down(), "{action}: still down");
            let moved = p.position().0 - before;
            if action == "slide" {
                // Feet first, on along the way the person walked.
                assert!(moved.x > 1.5, "the slide went {moved}");
            } else {
                // Backwards, like a plank about the heels: the pelvis lands behind them.
                assert!(moved.x < -0.5 && moved.x > -1.5, "the fall went {moved}");
            }
        }
    }

    #[test]
    fn a_snowball_flies_and_stops_on_the_ground() {
        let mut p = yard();
        run(
            &mut p,
            1.0 / 30.0,
            Intent {
                throw: true,
                ..Intent::default()
            },
        );
        assert_eq!(p.balls().len(), 1);
        assert_eq!(p.deformers(&[]).len(), 1, "the ball presses snow");
        run(&mut p, 3.0, Intent::default());
        let b = p.balls()[0];
        assert_eq!(b.velocity, Vec3::ZERO);
        assert!(b.position.x > 1.5, "thrown forward: {}", b.position);
        assert!((b.position.y - BALL_RADIUS * 0.8).abs() < 1e-5);
    }
}
