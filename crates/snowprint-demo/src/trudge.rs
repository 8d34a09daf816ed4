//! Trudging: a person who sinks into the snow and slows down by the depth of snow under their
//! feet, read from the world's probe cache ([`SnowWorld::probe_keyed`], [`SnowWorld::under`]) so
//! that no frame waits for the GPU.
//!
//! Each frame [`Trudge::advance`] reads the latest samples under the person's two feet (a frame or
//! two old), runs the person's own animation clock at [`pace`] of the deeper of the two, sets the
//! body's [`sink`], and probes the feet where they now stand for the frames to come.
//! [`Trudge::parts_at`] poses the person at that clock, lowered by the sink. The scripted demo
//! ([`crate::DemoWorld::parts_at`]) does not trudge, so that its frames stay as they were.

use glam::Vec3;
use snowprint::{Result, SnowWorld};

use crate::skeleton::{Part, Side};
use crate::{PartPose, Person};

/// Speed lost per metre of snow under the feet: the pace is `1 / (1 + DRAG_PER_METRE * depth)`.
pub const DRAG_PER_METRE: f32 = 3.0;
/// Fraction of the snow under the feet that the body sinks into.
pub const SINK_FRACTION: f32 = 0.5;

/// How fast a person's animation runs in `depth_m` metres of snow (1 on bare ground).
pub fn pace(depth_m: f32) -> f32 {
    1.0 / (1.0 + DRAG_PER_METRE * depth_m.max(0.0))
}

/// How far a person sinks in `depth_m` metres of snow.
pub fn sink(depth_m: f32) -> f32 {
    SINK_FRACTION * depth_m.max(0.0)
}

/// A person's trudge state: its own clock and how far it has sunk.
#[derive(Clone, Debug, PartialEq)]
pub struct Trudge {
    /// The person's animation time, seconds (behind the world's in deep snow).
    pub clock: f32,
    /// How far the body is lowered, metres.
    pub sink: f32,
    /// Snow depth under the feet at the last advance, metres (0 before the first answer).
    pub depth: f32,
    /// Probe-cache keys of the left and right foot.
    keys: [u64; 2],
}

impl Trudge {
    /// A trudge starting at `clock`, probing with keys `key_base` and `key_base + 1`.
    pub fn new(clock: f32, key_base: u64) -> Self {
        Self {
            clock,
            sink: 0.0,
            depth: 0.0,
            keys: [key_base, key_base + 1],
        }
    }

    /// Advance one frame of `dt` seconds with the feet at `feet` (world metres, left then right):
    /// read the cached snow under them, move the clock and the sink, and probe the feet again.
    /// Never waits; a full probe ring only skips this frame's new probes.
    pub fn advance(&mut self, world: &mut SnowWorld, dt: f32, feet: [Vec3; 2]) -> Result<f32> {
        self.depth = self
            .keys
            .iter()
            .filter_map(|&k| world.under(k))
            .filter(|(s, _)| s.surface.is_some())
            .map(|(s, _)| s.snow_depth_m)
            .fold(0.0, f32::max);
        self.clock += dt * pace(self.depth);
        self.sink = sink(self.depth);
        for (&key, &foot) in self.keys.iter().zip(&feet) {
            match world.probe_keyed(key, foot) {
                Ok(()) | Err(snowprint::SnowError::ProbeRingFull { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        Ok(self.clock)
    }

    /// The person's feet (ankle joints) at its clock, lowered by the sink.
    pub fn feet(&self, person: &Person) -> [Vec3; 2] {
        let parts = self.parts_at(person, 0);
        [Side::Left, Side::Right].map(|side| parts[Part::foot(side).index()].pose.position)
    }

    /// Every body part of `person` (index `index` in the demo) at its clock, lowered by the sink.
    pub fn parts_at(&self, person: &Person, index: usize) -> Vec<PartPose> {
        let mut body = person.pose_at(self.clock);
        body.root.y -= self.sink;
        let world = body.world();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DemoWorld;
    use snowprint::{Deformer, GpuContext, GpuOptions, Pose, Shape, SurfaceDesc, WorldConfig};

    #[test]
    fn pace_and_sink_by_hand() {
        assert_eq!(pace(0.0), 1.0);
        assert!((pace(0.3) - 1.0 / 1.9).abs() < 1e-6);
        assert_eq!(sink(0.3), 0.15);
        assert_eq!((pace(-1.0), sink(-1.0)), (1.0, 0.0));
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
        let mut deep = Trudge::new(1.0, 10);
        // The same walk 100 m to the side: no surface under it.
        let mut bare = Trudge::new(1.0, 20);
        let aside = Vec3::X * 100.0;
        for _ in 0..8 {
            // Feet probed at the ground under the snow, where the drift's ground is.
            let feet = deep
                .feet(walker)
                .map(|f| Vec3::new(f.x, start.y - 1.0 + 0.01, f.z));
            deep.advance(&mut world, dt, feet).unwrap();
            let feet = bare.feet(walker).map(|f| f + aside);
            bare.advance(&mut world, dt, feet).unwrap();
            world.step(dt, std::slice::from_ref(&busy)).unwrap();
        }
        // Untouched 0.4 m: pace 1 / 2.2 once the first samples came back, sunk 0.2 m.
        assert_eq!(deep.depth, 0.4);
        assert_eq!(deep.sink, 0.2);
        assert!(deep.clock < 1.0 + 8.0 * dt * 0.75, "clock {}", deep.clock);
        assert!(deep.clock >= 1.0 + 8.0 * dt * pace(0.4));
        // Over nothing, the walker keeps the world's time and its height.
        assert!((bare.clock - (1.0 + 8.0 * dt)).abs() < 1e-5);
        assert_eq!(bare.sink, 0.0);
        // The parts are the walker's at its own clock, lowered by the sink.
        let parts = deep.parts_at(walker, index);
        let mut body = walker.pose_at(deep.clock);
        body.root.y -= 0.2;
        assert_eq!(parts[0].pose, body.world()[0]);
        assert_eq!(parts[0].person, index);
    }
}
