//! The cast: who does what, where and when.
//!
//! | name | roof | what | when (s) |
//! |---|---|---|---|
//! | `walker` | walk roof | trudges out of the roof door along the roof, knees high | 0.3 – 7.2 |
//! | `runner` | run roof | runs the length of the roof and stops | 1.0 – 4.7 |
//! | `faller` | high roof's parapet, then low roof | teeters (0 – 1.6), falls 4 m onto its back | 0 – 3.1 |
//! | `angel` | low roof | drops backwards into the snow (1.8 – 2.7), sweeps a snow angel | 1.2 – 6.5 |
//! | `slider` | yard roof | runs and slides feet first (2.95 – 4.63) | 1.6 – 5.4 |
//! | `brawler`, `thug` | yard roof | circle trading jabs; the brawler shoves (4.5) the thug to the ground | 0.3 – 5.6 |

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{Vec2, Vec3};

use super::anim::{
    Action, Angel, Footfall, Gait, GaitStyle, Motion, Segment, Slide, StepPlan, Strike, Topple,
    smoothstep, yaw_of,
};
use super::skeleton::{BodyPose, Outfit, Side};
use super::world::{self, surface};

/// A procedural person.
#[derive(Clone, Debug, PartialEq)]
pub struct Person {
    /// Name (`walker`, `runner`, `faller`, `angel`, `slider`, `brawler`, `thug`).
    pub name: &'static str,
    /// The surface (index into [`super::DemoWorld::surfaces`]) the person's snow prints are on.
    pub surface: usize,
    /// Clothes.
    pub outfit: Outfit,
    /// The animation.
    pub motion: Motion,
}

impl Person {
    /// The body at time `t`.
    pub fn pose_at(&self, t: f32) -> BodyPose {
        self.motion.pose(t)
    }

    /// Every time a foot is planted (including the feet already standing at the start).
    pub fn footfalls(&self) -> Vec<Footfall> {
        self.motion.footfalls()
    }

    /// The slide, if the person slides.
    pub fn slide(&self) -> Option<&Slide> {
        self.motion.segments.iter().find_map(|s| match &s.action {
            Action::Slide(a) => Some(a),
            _ => None,
        })
    }

    /// The fall onto the back, if the person falls (and when it starts).
    pub fn topple(&self) -> Option<(f32, &Topple)> {
        self.motion.segments.iter().find_map(|s| match &s.action {
            Action::Topple(a) => Some((s.start, a)),
            _ => None,
        })
    }

    /// The snow angel, if the person makes one (and when its sweeps start).
    pub fn angel(&self) -> Option<(f32, &Angel)> {
        self.motion.segments.iter().find_map(|s| match &s.action {
            Action::Angel(a) => Some((s.start, a)),
            _ => None,
        })
    }
}

const SKIN: [[f32; 3]; 3] = [[0.80, 0.60, 0.47], [0.55, 0.38, 0.26], [0.33, 0.21, 0.13]];
const TROUSERS: [f32; 3] = [0.07, 0.08, 0.12];
const BOOTS: [f32; 3] = [0.10, 0.07, 0.05];

fn outfit(skin: usize, jacket: [f32; 3]) -> Outfit {
    Outfit {
        skin: SKIN[skin % SKIN.len()],
        jacket,
        trousers: TROUSERS,
        boots: BOOTS,
    }
}

/// A straight path from `from` to `to`, starting at `t0`, accelerating for `ramp` seconds to
/// `speed`, cruising and (if `stop`) braking over the last `ramp` seconds. Returns the path and
/// the time it arrives (or, without `stop`, the time it would).
fn straight(
    from: Vec2,
    to: Vec2,
    t0: f32,
    speed: f32,
    ramp: f32,
    stop: bool,
) -> (impl Fn(f32) -> (Vec2, f32), f32) {
    let total = from.distance(to);
    let dir = (to - from) / total.max(1e-6);
    let accel = speed / ramp;
    let ramp_dist = 0.5 * speed * ramp;
    let cruise = (total - if stop { 2.0 } else { 1.0 } * ramp_dist).max(0.0) / speed;
    let end = t0 + cruise + if stop { 2.0 } else { 1.0 } * ramp;
    let yaw = yaw_of(dir);
    let path = move |t: f32| {
        let tau = (t - t0).max(0.0);
        let d = if tau < ramp {
            0.5 * accel * tau * tau
        } else if tau < ramp + cruise || !stop {
            ramp_dist + speed * (tau - ramp)
        } else {
            let b = (tau - ramp - cruise).min(ramp);
            ramp_dist + speed * cruise + speed * b - 0.5 * accel * b * b
        };
        let d = if stop { d.min(total) } else { d };
        (from + dir * d, yaw)
    };
    (path, end)
}

fn ground(surface: usize) -> f32 {
    world::surfaces()[surface].desc.center.y
}

fn walker() -> Person {
    let g = ground(surface::WALK_ROOF);
    let (path, end) = straight(
        Vec2::new(-16.6, -11.0),
        Vec2::new(-10.4, -11.0),
        0.3,
        1.0,
        0.7,
        true,
    );
    let plan = StepPlan {
        start: 0.3,
        end,
        step_time: 0.6,
        duty: 0.6,
        // Prints centred on texel rows (the path runs along a row edge), so that each is sampled
        // symmetrically.
        lateral: 0.14,
        stagger: 0.0,
        min_stride: 0.5,
        first: Side::Right,
        ground: g,
    };
    let gait = Gait::plan(plan, GaitStyle::trudge(), &path);
    Person {
        name: "walker",
        surface: surface::WALK_ROOF,
        outfit: outfit(0, [0.60, 0.08, 0.06]),
        motion: Motion {
            segments: vec![Segment {
                start: 0.0,
                blend: 0.0,
                action: Action::Gait(gait),
            }],
        },
    }
}

fn runner() -> Person {
    let g = ground(surface::RUN_ROOF);
    let (path, end) = straight(
        Vec2::new(-17.2, 10.0),
        Vec2::new(-7.2, 10.0),
        1.0,
        3.8,
        1.0,
        true,
    );
    let plan = StepPlan {
        start: 1.0,
        end,
        step_time: 0.34,
        duty: 0.26,
        // The path runs along a row edge: prints centred on rows.
        lateral: 0.1,
        stagger: 0.0,
        min_stride: 0.5,
        first: Side::Left,
        ground: g,
    };
    let gait = Gait::plan(plan, GaitStyle::run(), &path);
    Person {
        name: "runner",
        surface: surface::RUN_ROOF,
        outfit: outfit(1, [0.10, 0.22, 0.62]),
        motion: Motion {
            segments: vec![Segment {
                start: 0.0,
                blend: 0.0,
                action: Action::Gait(gait),
            }],
        },
    }
}

fn faller() -> Person {
    let topple = Topple {
        // Heels on the outer edge of the high roof's parapet, facing the high roof: the back
        // is to the 4 m drop onto the low roof.
        pivot: Vec3::new(0.28, world::parapet_top(surface::HIGH_ROOF), -11.0),
        yaw: PI,
        teeter: 1.6,
        tip_time: 0.6,
        release: 0.5,
        land: ground(surface::LOW_ROOF),
        windmill: true,
        arms_out: 1.2,
    };
    Person {
        name: "faller",
        surface: surface::LOW_ROOF,
        outfit: outfit(2, [0.72, 0.55, 0.10]),
        motion: Motion {
            segments: vec![Segment {
                start: 0.0,
                blend: 0.0,
                action: Action::Topple(topple),
            }],
        },
    }
}

fn angel() -> Person {
    let g = ground(surface::LOW_ROOF);
    let topple = Topple {
        pivot: Vec3::new(10.4, g + GaitStyle::trudge().sole, -11.0),
        yaw: 0.0,
        teeter: 0.6,
        tip_time: 0.9,
        release: FRAC_PI_2,
        land: g,
        windmill: false,
        // Arms at the sides, where the angel's sweeps start.
        arms_out: super::anim::ANGEL_ARMS.0,
    };
    let start = 1.2;
    let (root, rotation) = topple.lying_root();
    let angel = Angel {
        root,
        rotation,
        sweeps: 2,
        period: 1.8,
        sweeping: true,
    };
    Person {
        name: "angel",
        surface: surface::LOW_ROOF,
        outfit: outfit(0, [0.85, 0.45, 0.55]),
        motion: Motion {
            segments: vec![
                Segment {
                    start,
                    blend: 0.0,
                    action: Action::Topple(topple),
                },
                Segment {
                    start: start + topple.duration() + 0.2,
                    blend: 0.2,
                    action: Action::Angel(angel),
                },
            ],
        },
    }
}

fn slider() -> Person {
    let g = ground(surface::YARD_ROOF);
    let (t0, speed, slide_at) = (1.6, 4.2, 2.95);
    let (path, _) = straight(
        Vec2::new(-0.4, 13.5),
        Vec2::new(12.0, 13.5),
        t0,
        speed,
        0.9,
        false,
    );
    let (start, yaw) = path(slide_at);
    let plan = StepPlan {
        start: t0,
        end: slide_at + 1.0,
        step_time: 0.34,
        duty: 0.26,
        lateral: 0.1,
        stagger: 0.0,
        min_stride: 0.5,
        first: Side::Right,
        ground: g,
    };
    let gait = Gait::plan(plan, GaitStyle::run(), &path);
    let slide = Slide {
        start,
        yaw,
        ground: g,
        drop_from: GaitStyle::run().hip_height,
        drop_time: 0.3,
        speed,
        decel: 2.5,
    };
    Person {
        name: "slider",
        surface: surface::YARD_ROOF,
        outfit: outfit(1, [0.15, 0.45, 0.15]),
        motion: Motion {
            segments: vec![
                Segment {
                    start: 0.0,
                    blend: 0.0,
                    action: Action::Gait(gait),
                },
                Segment {
                    start: slide_at,
                    blend: 0.15,
                    action: Action::Slide(slide),
                },
            ],
        },
    }
}

/// Centre of the fight on the yard roof, and how far each fighter's pelvis stays from it.
const RING: (Vec2, f32) = (Vec2::new(8.8, 10.0), 0.8);
/// The fighters stop circling, the brawler closes in, shoves, and the thug falls.
const CLOSE_IN: f32 = 3.6;
const SHOVE: f32 = 4.5;

/// Where a fighter stands on the ring at `t`: opposite fighters are half a turn apart; the
/// brawler (`closes`) steps in on the thug after [`CLOSE_IN`].
fn ring_position(t: f32, offset: f32, closes: bool) -> (Vec2, f32) {
    let (center, radius) = RING;
    // Half a turn apart; by the close-in the thug stands west of the centre, so that the shove
    // throws it onto open snow.
    let angle = 0.45 * (t.min(CLOSE_IN) - CLOSE_IN) + offset;
    let dir = Vec2::new(angle.cos(), angle.sin());
    let r = if closes {
        radius - 0.45 * smoothstep((t - CLOSE_IN) / (SHOVE - 0.1 - CLOSE_IN))
    } else {
        radius
    };
    (center + dir * r, yaw_of(-dir))
}

fn fighters() -> [Person; 2] {
    let g = ground(surface::YARD_ROOF);
    let base = StepPlan {
        start: 0.3,
        end: SHOVE - 0.1,
        step_time: 0.45,
        duty: 0.7,
        lateral: 0.15,
        stagger: 0.12,
        min_stride: 0.0,
        first: Side::Left,
        ground: g,
    };
    let mut a = Gait::plan(base, GaitStyle::fighter(), &|t| ring_position(t, 0.0, true));
    a.strikes = vec![
        Strike {
            time: 0.9,
            side: Some(Side::Left),
        },
        Strike {
            time: 1.25,
            side: Some(Side::Right),
        },
        Strike {
            time: 2.6,
            side: Some(Side::Left),
        },
        Strike {
            time: 3.3,
            side: Some(Side::Right),
        },
        Strike {
            time: SHOVE,
            side: None,
        },
    ];
    let thug_plan = StepPlan {
        start: 0.5,
        end: SHOVE,
        first: Side::Right,
        ..base
    };
    let mut b = Gait::plan(thug_plan, GaitStyle::fighter(), &|t| {
        ring_position(t, PI, false)
    });
    b.strikes = vec![
        Strike {
            time: 1.7,
            side: Some(Side::Left),
        },
        Strike {
            time: 2.0,
            side: Some(Side::Right),
        },
        Strike {
            time: 3.0,
            side: Some(Side::Left),
        },
    ];
    let (at, yaw) = ring_position(SHOVE, PI, false);
    let topple = Topple {
        pivot: Vec3::new(at.x, g + GaitStyle::fighter().sole, at.y)
            - super::anim::forward_of(yaw) * super::skeleton::dims::HEEL_BACK,
        yaw,
        teeter: 0.0,
        tip_time: 0.75,
        release: FRAC_PI_2,
        land: g,
        windmill: false,
        arms_out: 1.0,
    };
    [
        Person {
            name: "brawler",
            surface: surface::YARD_ROOF,
            outfit: outfit(2, [0.06, 0.06, 0.07]),
            motion: Motion {
                segments: vec![Segment {
                    start: 0.0,
                    blend: 0.0,
                    action: Action::Gait(a),
                }],
            },
        },
        Person {
            name: "thug",
            surface: surface::YARD_ROOF,
            outfit: outfit(0, [0.80, 0.36, 0.06]),
            motion: Motion {
                segments: vec![
                    Segment {
                        start: 0.0,
                        blend: 0.0,
                        action: Action::Gait(b),
                    },
                    Segment {
                        start: SHOVE + 0.05,
                        blend: 0.15,
                        action: Action::Topple(topple),
                    },
                ],
            },
        },
    ]
}

/// People whose actions are timed against each other (the brawler's shove meets the thug at
/// `SHOVE`): a trudging crowd ([`crate::trudge::Crowd`]) gives each pair one clock.
pub const PARTNERS: &[(&str, &str)] = &[("brawler", "thug")];

/// Everyone, in a fixed order.
pub fn cast() -> Vec<Person> {
    let mut out = vec![walker(), runner(), faller(), angel(), slider()];
    out.extend(fighters());
    out
}
