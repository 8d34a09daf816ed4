//! Trudging: a person who sinks into the snow and slows down by the depth of snow under their
//! feet, read from the world's probe cache ([`SnowWorld::probe_keyed`], [`SnowWorld::under`]).
//!
//! Each frame a [`Trudge`] reads the samples under the person's feet, runs the person's own
//! animation clock at [`pace`] of the deeper of them (smoothed over [`DEPTH_SMOOTHING`]), sets the
//! body's [`sink`], and probes the feet where they now stand for the frames to come.
//! [`Trudge::parts_at`] poses the person at that clock, lowered by the sink: a walking body crouches
//! (the pelvis goes down, the legs bend, the planted feet stay on their prints, which already reach
//! the ground under the snow); any other body is lowered whole.
//!
//! Two ways to read the probes:
//!
//! * [`Trudge::new`], as a game would: the newest sample, whatever its age; never waits. How old
//!   the newest sample is depends on when the GPU finished, so two runs may differ slightly.
//! * [`Trudge::lockstep`], as the rendered demo does: each foot is probed under a key of its own
//!   for each of [`LAG`]` + 1` frames in turn, and a frame reads exactly the sample probed [`LAG`]
//!   updates earlier (checked by its age). When the GPU has not answered yet (rare: the world polls
//!   at every update), it polls until the answer is there. Same inputs, same frames, every run.
//!
//! The scripted demo ([`crate::DemoWorld::parts_at`]) does not trudge; [`Crowd`] trudges every
//! person of a [`DemoWorld`] through a [`SnowWorld`] frame by frame (the rendered demo,
//! `scene::rooftops`).

use std::time::{Duration, Instant};

use glam::Vec3;
use snowprint::{MeshId, Result, SnowError, SnowWorld, SurfaceId, SurfaceUpdate};

use crate::anim::Action;
use crate::skeleton::{BodyPose, Part, Side, joint_offset, solve_leg};
use crate::{DemoWorld, PartPose, Person};

/// Speed lost per metre of snow under the feet: the pace is `1 / (1 + DRAG_PER_METRE * depth)`.
pub const DRAG_PER_METRE: f32 = 3.0;
/// Fraction of the snow under the feet that the body sinks into.
pub const SINK_FRACTION: f32 = 0.5;
/// Time constant of the depth a trudge follows, seconds: the swinging foot passes over fresh snow
/// and the planted one stands in its print, so the raw depth jumps at every step; the body eases.
pub const DEPTH_SMOOTHING: f32 = 0.25;
/// Age, in world updates, of the samples a [`Trudge::lockstep`] reads.
pub const LAG: u64 = 2;
/// Longest a [`Trudge::lockstep`] waits for a late answer before giving up.
const LATE_ANSWER: Duration = Duration::from_secs(10);

/// How fast a person's animation runs in `depth_m` metres of snow (1 on bare ground).
pub fn pace(depth_m: f32) -> f32 {
    1.0 / (1.0 + DRAG_PER_METRE * depth_m.max(0.0))
}

/// How far a person sinks in `depth_m` metres of snow.
pub fn sink(depth_m: f32) -> f32 {
    SINK_FRACTION * depth_m.max(0.0)
}

/// A person's (or a group's) trudge state: its own clock and how far it has sunk.
#[derive(Clone, Debug, PartialEq)]
pub struct Trudge {
    /// The person's animation time, seconds (behind the world's in deep snow).
    pub clock: f32,
    /// How far the body is lowered, metres.
    pub sink: f32,
    /// The smoothed snow depth under the feet, metres (0 before the first answer).
    pub depth: f32,
    /// The deepest snow under the feet in the samples of the last read, metres.
    pub raw_depth: f32,
    /// The first probe-cache key; the trudge uses `feet * (LAG + 1)` keys from it.
    key_base: u64,
    /// Feet probed each frame.
    feet: usize,
    /// Read exactly [`LAG`]-old samples (and wait for late ones) instead of the newest.
    lockstep: bool,
    /// Frames probed so far.
    probes: u64,
    /// Frames read so far.
    reads: u64,
    /// Reads that found an answer not back yet and polled until it was (lockstep only).
    pub late: u64,
}

impl Trudge {
    /// A trudge starting at `clock` with `feet` feet, probing with keys from `key_base` on
    /// (`feet * (LAG + 1)` of them) and reading the newest samples. Never waits.
    pub fn new(clock: f32, key_base: u64, feet: usize) -> Self {
        Self {
            clock,
            sink: 0.0,
            depth: 0.0,
            raw_depth: 0.0,
            key_base,
            feet,
            lockstep: false,
            probes: 0,
            reads: 0,
            late: 0,
        }
    }

    /// As [`Trudge::new`], but each read takes the samples probed exactly [`LAG`] updates
    /// earlier, so that runs repeat frame for frame. Call [`Trudge::read`], then update the world
    /// once, then [`Trudge::probe`], every frame.
    pub fn lockstep(clock: f32, key_base: u64, feet: usize) -> Self {
        Self {
            lockstep: true,
            ..Self::new(clock, key_base, feet)
        }
    }

    /// The key of foot `foot` in probe round `round`.
    fn key(&self, round: u64, foot: usize) -> u64 {
        self.key_base + (round % (LAG + 1)) * self.feet as u64 + foot as u64
    }

    /// The deepest snow in the samples of probe round `round`, waiting for them when they are
    /// late (lockstep only).
    fn lagged_depth(&mut self, world: &mut SnowWorld, round: u64) -> Result<f32> {
        let start = Instant::now();
        let mut deepest = 0.0f32;
        let mut waited = false;
        for foot in 0..self.feet {
            let key = self.key(round, foot);
            let sample = loop {
                match world.under(key) {
                    Some((sample, age)) if age == LAG => break sample,
                    Some((_, age)) if age < LAG => {
                        return Err(SnowError::Readback(format!(
                            "trudge key {key} answered {age} updates after its probe, expected \
                             {LAG}: read, update the world once, then probe, every frame"
                        )));
                    }
                    _ if start.elapsed() > LATE_ANSWER => {
                        return Err(SnowError::Readback(format!(
                            "trudge key {key}: no answer {LAG} updates after its probe within \
                             {} s (the world must be updated once between read and probe)",
                            LATE_ANSWER.as_secs()
                        )));
                    }
                    _ => {
                        if !waited {
                            waited = true;
                            self.late += 1;
                        }
                        world.poll_probes();
                        std::thread::sleep(Duration::from_micros(200));
                    }
                }
            };
            if sample.surface.is_some() {
                deepest = deepest.max(sample.snow_depth_m);
            }
        }
        Ok(deepest)
    }

    /// Read the snow under the feet and move the clock `dt` world seconds on: at [`pace`] of the
    /// depth while `walking` (a gait: a fall or a slide keeps the world's time), and ease the
    /// sink towards [`sink`] of it (towards 0 when not walking).
    pub fn read(&mut self, world: &mut SnowWorld, dt: f32, walking: bool) -> Result<f32> {
        let raw = if self.lockstep {
            // Round `k` was probed after the world's update `k + 1`: LAG updates before this read
            // (the `reads`-th, after update `reads`), round `reads - 1 - LAG` was.
            match self.reads.checked_sub(LAG + 1) {
                Some(round) if round < self.probes => Some(self.lagged_depth(world, round)?),
                _ => None,
            }
        } else {
            let latest = self.probes.checked_sub(1);
            latest.map(|round| {
                (0..self.feet)
                    .filter_map(|foot| world.under(self.key(round, foot)))
                    .filter(|(s, _)| s.surface.is_some())
                    .map(|(s, _)| s.snow_depth_m)
                    .fold(0.0, f32::max)
            })
        };
        self.reads += 1;
        self.raw_depth = raw.unwrap_or(0.0);
        let target = if walking { self.raw_depth } else { 0.0 };
        let ease = 1.0 - (-dt.max(0.0) / DEPTH_SMOOTHING).exp();
        self.depth += (target - self.depth) * ease;
        self.clock += dt * if walking { pace(self.depth) } else { 1.0 };
        self.sink = sink(self.depth);
        Ok(self.clock)
    }

    /// Probe the feet where they stand now (world metres, up to the trudge's number of feet),
    /// for the reads to come. A lockstep trudge fails when the probe ring is full; the other one
    /// only skips this frame's probes.
    pub fn probe(&mut self, world: &mut SnowWorld, feet: &[Vec3]) -> Result<()> {
        let round = self.probes;
        self.probes += 1;
        for (foot, &point) in feet.iter().enumerate().take(self.feet) {
            match world.probe_keyed(self.key(round, foot), point) {
                Ok(()) => {}
                Err(SnowError::ProbeRingFull { .. }) if !self.lockstep => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    /// Every body part of `person` (index `index` in the demo) at the trudge's clock, lowered by
    /// the sink (see the module's documentation).
    pub fn parts_at(&self, person: &Person, index: usize) -> Vec<PartPose> {
        let world = sunk_pose(person, self.clock, self.sink).world();
        Part::ALL
            .iter()
            .map(|&part| PartPose {
                person: index,
                part: part.index(),
                pose: world[part.index()],
                albedo: person.outfit.albedo(part),
            })
            .collect()
    }
}

/// Whether `person` walks (a gait segment runs) at `t`.
pub fn walking_at(person: &Person, t: f32) -> bool {
    let segments = &person.motion.segments;
    let i = segments.iter().rposition(|s| s.start <= t).unwrap_or(0);
    segments
        .get(i)
        .is_some_and(|s| matches!(s.action, Action::Gait(_)))
}

/// The body of `person` at `t`, `sink` metres lower: walking, the pelvis goes down and the legs
/// are solved again so that the feet stay where the gait put them; otherwise the whole body.
pub fn sunk_pose(person: &Person, t: f32, sink: f32) -> BodyPose {
    let mut body = person.pose_at(t);
    if sink == 0.0 {
        return body;
    }
    if !walking_at(person, t) {
        body.root.y -= sink;
        return body;
    }
    let before = body.world();
    body.root.y -= sink;
    let pelvis = body.get(Part::Pelvis);
    for side in [Side::Right, Side::Left] {
        let foot = before[Part::foot(side).index()];
        let hip = body.root + pelvis * joint_offset(Part::thigh(side));
        let (hip_q, knee_q, _) = solve_leg(pelvis, hip, foot.position);
        body.set(Part::thigh(side), hip_q);
        body.set(Part::shin(side), knee_q);
        let shin = pelvis * hip_q * knee_q;
        body.set(
            Part::foot(side),
            (shin.inverse() * foot.rotation).normalize(),
        );
    }
    body
}

/// Every person of a [`DemoWorld`] trudging through a [`SnowWorld`], frame by frame, in
/// lockstep (see [`Trudge::lockstep`]): the rendered demo's people. People whose actions are timed
/// against each other ([`crate::people::PARTNERS`]) share one clock, read from all their feet, so
/// that a shove still meets its target.
#[derive(Clone, Debug, PartialEq)]
pub struct Crowd {
    /// One trudge per group of people.
    trudges: Vec<Trudge>,
    /// The people (indices into [`DemoWorld::people`]) of each trudge.
    members: Vec<Vec<usize>>,
    /// The index into `trudges` of each person.
    group: Vec<usize>,
    /// Every part of every person as of the last step (in [`DemoWorld::parts_at`] order).
    parts: Vec<PartPose>,
}

impl Crowd {
    /// Everyone standing at time 0, not sunk; probe keys from `key_base` on (two feet each, for
    /// [`LAG`]` + 1` frames: `6 * people` keys).
    pub fn new(demo: &DemoWorld, key_base: u64) -> Self {
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut group: Vec<usize> = Vec::with_capacity(demo.people.len());
        for (i, person) in demo.people.iter().enumerate() {
            let partner = crate::people::PARTNERS.iter().find_map(|&(a, b)| {
                let other = if person.name == a {
                    b
                } else if person.name == b {
                    a
                } else {
                    return None;
                };
                group
                    .iter()
                    .zip(&demo.people)
                    .find(|(_, p)| p.name == other)
                    .map(|(&g, _)| g)
            });
            match partner {
                Some(g) => {
                    members[g].push(i);
                    group.push(g);
                }
                None => {
                    group.push(members.len());
                    members.push(vec![i]);
                }
            }
        }
        let mut keys = key_base;
        let trudges = members
            .iter()
            .map(|m| {
                let t = Trudge::lockstep(0.0, keys, 2 * m.len());
                keys += 2 * m.len() as u64 * (LAG + 1);
                t
            })
            .collect();
        Self {
            trudges,
            members,
            group,
            parts: demo.parts_at(0.0),
        }
    }

    /// The trudge that moves person `person` (index into [`DemoWorld::people`]).
    pub fn trudge(&self, person: usize) -> Option<&Trudge> {
        self.trudges.get(*self.group.get(person)?)
    }

    /// Every part of every person as of the last [`Crowd::step`] (in [`DemoWorld::parts_at`]
    /// order).
    pub fn parts(&self) -> &[PartPose] {
        &self.parts
    }

    /// One frame of `dt` seconds: read each group's probes and move its clock, pose everyone,
    /// press the snow with what moved (one [`SnowWorld::update`] of the surfaces
    /// [`DemoWorld::deformers_by_surface`] lists; `surfaces[i]` is the world's id of
    /// `demo.surfaces[i]`, `part_mesh_ids[i]` of `demo.part_meshes[i]`), and probe the feet.
    pub fn step(
        &mut self,
        demo: &DemoWorld,
        world: &mut SnowWorld,
        dt: f32,
        surfaces: &[SurfaceId],
        part_mesh_ids: &[MeshId],
    ) -> Result<()> {
        for (trudge, members) in self.trudges.iter_mut().zip(&self.members) {
            let walking = members.iter().all(|&p| {
                demo.people
                    .get(p)
                    .is_some_and(|p| walking_at(p, trudge.clock))
            });
            trudge.read(world, dt, walking)?;
        }
        let mut now = Vec::with_capacity(self.parts.len());
        for (i, person) in demo.people.iter().enumerate() {
            if let Some(t) = self.trudge(i) {
                now.extend(t.parts_at(person, i));
            }
        }
        let ankle = world.config().capture.ankle_height;
        let first = self.trudges.first().is_some_and(|t| t.reads == 1);
        let sorted = demo.deformers_by_surface(&self.parts, &now, part_mesh_ids, ankle, first);
        let updates: Vec<SurfaceUpdate<'_>> = sorted
            .iter()
            .filter_map(|(index, deformers)| {
                Some(SurfaceUpdate {
                    surface: *surfaces.get(*index)?,
                    elapsed: dt,
                    deformers,
                })
            })
            .collect();
        world.update(&updates)?;
        self.parts = now;
        for (trudge, members) in self.trudges.iter_mut().zip(&self.members) {
            let feet: Vec<Vec3> = members
                .iter()
                .flat_map(|&p| [Side::Left, Side::Right].map(|s| (p, s)))
                .filter_map(|(p, side)| {
                    let part = self
                        .parts
                        .get(p * crate::PART_COUNT + Part::foot(side).index())?;
                    Some(part.pose.position)
                })
                .collect();
            trudge.probe(world, &feet)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use snowprint::{Deformer, GpuContext, GpuOptions, Pose, Shape, SurfaceDesc, WorldConfig};

    #[test]
    fn pace_and_sink_by_hand() {
        assert_eq!(pace(0.0), 1.0);
        assert!((pace(0.3) - 1.0 / 1.9).abs() < 1e-6);
        assert_eq!(sink(0.3), 0.15);
        assert_eq!((pace(-1.0), sink(-1.0)), (1.0, 0.0));
    }

    /// The feet of a walking body stay where the gait put them when it sinks; the pelvis goes
    /// down by the sink. A body that does not walk goes down whole.
    #[test]
    fn a_sunk_walker_crouches_over_its_feet() {
        let demo = DemoWorld::build();
        let walker = demo.person("walker").unwrap();
        for t in [0.0, 1.0, 1.3, 2.45, 4.0] {
            let upright = walker.pose_at(t).world();
            let sunk = sunk_pose(walker, t, 0.15).world();
            let pelvis = Part::Pelvis.index();
            assert!((upright[pelvis].position.y - sunk[pelvis].position.y - 0.15).abs() < 1e-5);
            for side in [Side::Left, Side::Right] {
                let f = Part::foot(side).index();
                assert!(sunk[f].position.distance(upright[f].position) < 1e-4, "{t}");
                assert!(sunk[f].rotation.angle_between(upright[f].rotation) < 1e-3);
                // The knee bends more.
                let (k0, k1) = (
                    upright[Part::shin(side).index()].position,
                    sunk[Part::shin(side).index()].position,
                );
                assert!(k1.y < k0.y, "{t}: knee {k1} vs {k0}");
            }
        }
        let faller = demo.person("faller").unwrap();
        assert!(!walking_at(faller, 1.0) && walking_at(walker, 1.0));
        let (a, b) = (faller.pose_at(2.0), sunk_pose(faller, 2.0, 0.1));
        assert_eq!(b.local, a.local);
        assert!((a.root.y - b.root.y - 0.1).abs() < 1e-6);
    }

    #[test]
    fn the_walker_slows_and_sinks_in_deep_snow_only() {
        let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (lavapipe)");
        let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
        let demo = DemoWorld::build();
        let walker = demo.person("walker").unwrap();
        let index = demo.person_index("walker").unwrap();
        // Deep snow, 0.4 m, under wherever the walker stands at the start; nothing elsewhere.
        let start = walker.pose_at(1.0).root;
        world
            .add_surface(SurfaceDesc::new(
                "drift",
                [start.x, start.y - 1.0, start.z],
                [6.0, 6.0],
                0.4,
            ))
            .unwrap();
        let busy = Deformer::new(
            Shape::Sphere { radius: 0.1 },
            Pose::at([start.x + 2.5, start.y - 0.6, start.z + 2.5]),
        );
        let dt = 1.0 / 30.0;
        let mut deep = Trudge::lockstep(1.0, 10, 2);
        // The same walk 100 m to the side: no surface under it.
        let mut bare = Trudge::lockstep(1.0, 20, 2);
        let aside = Vec3::X * 100.0;
        let feet = |t: &Trudge| {
            let parts = t.parts_at(walker, index);
            [Side::Left, Side::Right].map(|s| parts[Part::foot(s).index()].pose.position)
        };
        let frames = 40;
        for _ in 0..frames {
            deep.read(&mut world, dt, true).unwrap();
            bare.read(&mut world, dt, true).unwrap();
            world.step(dt, std::slice::from_ref(&busy)).unwrap();
            // Feet probed at the ground under the snow, where the drift's ground is.
            let f = feet(&deep).map(|f| Vec3::new(f.x, start.y - 1.0 + 0.01, f.z));
            deep.probe(&mut world, &f).unwrap();
            let f = feet(&bare).map(|f| f + aside);
            bare.probe(&mut world, &f).unwrap();
        }
        // Untouched 0.4 m from the third read on, eased over DEPTH_SMOOTHING: after 37 reads of
        // it the depth is 0.4 * (1 - exp(-37 dt / 0.25)).
        let eased = 0.4 * (1.0 - (-(frames - 3) as f32 * dt / DEPTH_SMOOTHING).exp());
        assert_eq!(deep.raw_depth, 0.4);
        assert!(
            (deep.depth - eased).abs() < 1e-4,
            "{} vs {eased}",
            deep.depth
        );
        assert_eq!(deep.sink, sink(deep.depth));
        let elapsed = frames as f32 * dt;
        assert!(deep.clock < 1.0 + elapsed * 0.75, "clock {}", deep.clock);
        assert!(deep.clock > 1.0 + elapsed * pace(0.4));
        // Over nothing, the walker keeps the world's time and its height.
        assert!((bare.clock - (1.0 + elapsed)).abs() < 1e-5);
        assert_eq!((bare.sink, bare.raw_depth), (0.0, 0.0));
        // The parts are the walker's at its own clock, the pelvis lowered by the sink.
        let parts = deep.parts_at(walker, index);
        let mut body = walker.pose_at(deep.clock);
        body.root.y -= deep.sink;
        assert_eq!(parts[0].pose, body.world()[0]);
        assert_eq!(parts[0].person, index);
    }
}
