//! The demo world, built in code: snowy flat roofs above a street, and procedural articulated
//! people who walk, run, fall, slide, make a snow angel and fight on them.
//!
//! The crate produces geometry, animation and deformers; it renders nothing. A renderer draws
//! [`DemoWorld::surfaces`] (with the heightmaps of a [`snowprint::SnowWorld`] fed by
//! [`DemoWorld::deformers_at`]), [`DemoWorld::props`], and every [`PartPose`] of
//! [`DemoWorld::parts_at`] with the mesh `part_meshes[part]`.
//!
//! ```no_run
//! use snowprint_demo::DemoWorld;
//! use snowprint::{GpuContext, GpuOptions, SnowWorld, WorldConfig};
//! # fn main() -> snowprint::Result<()> {
//! let demo = DemoWorld::build();
//! let gpu = GpuContext::new(&GpuOptions::default())?;
//! let mut world = SnowWorld::new(&gpu, WorldConfig::default())?;
//! let surfaces = demo
//!     .surfaces
//!     .iter()
//!     .map(|s| world.add_surface(s.desc.clone()))
//!     .collect::<snowprint::Result<Vec<_>>>()?;
//! let parts = demo
//!     .part_meshes
//!     .iter()
//!     .enumerate()
//!     .map(|(i, m)| world.add_mesh(&format!("part{i}"), m))
//!     .collect::<snowprint::Result<Vec<_>>>()?;
//! let dt = 1.0 / 30.0;
//! for frame in 1..=(demo.duration / dt).ceil() as u32 {
//!     world.step(dt, &demo.deformers_at(frame as f32 * dt, dt, &parts))?;
//! }
//! let walk_roof = world.read_heightmap(surfaces[1])?;
//! # let _ = walk_roof;
//! # Ok(()) }
//! ```
//!
//! See `docs/DEMO.md` for the world, the skeleton, each animation and the cameras.
//!
//! This crate is the demo content of the workspace, not published: the library `snowprint` is
//! what a game links, and builds without it. Beside the demo world above it holds the city
//! generator of the surface manager's demo and benchmarks ([`city`]), the SVG plot of the
//! manager's statistics ([`plot`]) and the worlds the command's rendered demo draws ([`scene`]).

pub mod anim;
pub mod camera;
pub mod city;
pub mod export;
pub mod people;
pub mod plot;
pub mod scene;
pub mod skeleton;
pub mod trudge;
pub mod world;

use glam::Mat4;

pub use anim::{Footfall, Motion};
pub use people::Person;
pub use skeleton::{BodyPose, PART_COUNT, Part, Side};

use snowprint::SurfaceDesc;
use snowprint::{Camera, GroundMaterial};
use snowprint::{Deformer, Pose, Shape};
use snowprint::{Mesh, MeshId};

/// A snow surface of the demo and what lies under its snow.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoSurface {
    /// The surface.
    pub desc: SurfaceDesc,
    /// Roof tiles or concrete, shown where the snow is pressed away.
    pub ground: GroundMaterial,
}

/// Static scenery, drawn but never pressing snow.
#[derive(Clone, Debug, PartialEq)]
pub struct Prop {
    /// The mesh, in its own frame.
    pub mesh: Mesh,
    /// Its frame in the world.
    pub transform: Mat4,
    /// Linear albedo.
    pub albedo: [f32; 3],
}

/// Where one body part of one person is at some time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartPose {
    /// Index of the person in [`DemoWorld::people`].
    pub person: usize,
    /// Index of the part's mesh in [`DemoWorld::part_meshes`] (a [`Part`] as `usize`).
    pub part: usize,
    /// Rigid pose of the part's mesh.
    pub pose: Pose,
    /// Linear albedo of the part.
    pub albedo: [f32; 3],
}

/// The whole demo: surfaces, scenery, people, and their part meshes.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoWorld {
    /// Snow surfaces, in [`world::surface`] order (the street first).
    pub surfaces: Vec<DemoSurface>,
    /// Buildings, parapets, doors, chimneys, water towers.
    pub props: Vec<Prop>,
    /// The people.
    pub people: Vec<Person>,
    /// One closed mesh per body part (in [`Part::ALL`] order), in the part's joint frame; shared
    /// by every person.
    pub part_meshes: Vec<Mesh>,
    /// Seconds from the first event to the last.
    pub duration: f32,
}

impl DemoWorld {
    /// Build the demo. Deterministic: every call returns the same world.
    pub fn build() -> DemoWorld {
        DemoWorld {
            surfaces: world::surfaces(),
            props: world::props(),
            people: people::cast(),
            part_meshes: skeleton::part_meshes(),
            duration: 10.0,
        }
    }

    /// A person by name.
    pub fn person(&self, name: &str) -> Option<&Person> {
        self.people.iter().find(|p| p.name == name)
    }

    /// Index of a person by name.
    pub fn person_index(&self, name: &str) -> Option<usize> {
        self.people.iter().position(|p| p.name == name)
    }

    /// Every body part of every person at time `t` (person by person, parts in [`Part::ALL`]
    /// order).
    pub fn parts_at(&self, t: f32) -> Vec<PartPose> {
        let mut out = Vec::with_capacity(self.people.len() * PART_COUNT);
        for (i, person) in self.people.iter().enumerate() {
            let world = person.pose_at(t).world();
            for part in Part::ALL {
                out.push(PartPose {
                    person: i,
                    part: part.index(),
                    pose: world[part.index()],
                    albedo: person.outfit.albedo(part),
                });
            }
        }
        out
    }

    /// One deformer per body part (in [`DemoWorld::parts_at`] order), moving from its pose at
    /// `t - dt` to its pose at `t`. `part_mesh_ids[i]` is the id of `part_meshes[i]` in the
    /// [`snowprint::SnowWorld`]; parts without an id are left out.
    pub fn deformers_at(&self, t: f32, dt: f32, part_mesh_ids: &[MeshId]) -> Vec<Deformer> {
        let before = self.parts_at(t - dt);
        let now = self.parts_at(t);
        before
            .iter()
            .zip(&now)
            .filter_map(|(a, b)| {
                let id = *part_mesh_ids.get(b.part)?;
                Some(Deformer::moving(Shape::Mesh(id), a.pose, b.pose))
            })
            .collect()
    }

    /// The deformers of [`DemoWorld::deformers_at`] sorted by surface, ready for
    /// [`snowprint::SnowWorld::update`]: for each surface (index into [`DemoWorld::surfaces`]), the
    /// parts whose bounding ball reaches into its capture volume (the snow plus `ankle_height`)
    /// and that moved during the frame (in the first frame, from `t - dt <= 0`, every one of them).
    /// A part at rest presses nothing it has not already pressed,
    /// so a lying body stops costing updates; surfaces that replenish keep their resting parts and
    /// are listed even when nobody is on them. Surfaces left out need no update this frame.
    pub fn surface_deformers(
        &self,
        t: f32,
        dt: f32,
        part_mesh_ids: &[MeshId],
        ankle_height: f32,
    ) -> Vec<(usize, Vec<Deformer>)> {
        // The first frame presses everything: a foot standing still from the start has pressed
        // nothing yet.
        self.deformers_by_surface(
            &self.parts_at(t - dt),
            &self.parts_at(t),
            part_mesh_ids,
            ankle_height,
            t - dt <= 0.0,
        )
    }

    /// [`DemoWorld::surface_deformers`] for any two sets of part poses (in
    /// [`DemoWorld::parts_at`] order), the parts moving from `before` to `now`: what a caller that
    /// poses the people itself (a [`trudge::Crowd`]) presses the snow with. `first`: the first
    /// frame, where parts at rest press too (nothing has pressed the snow before it).
    pub fn deformers_by_surface(
        &self,
        before: &[PartPose],
        now: &[PartPose],
        part_mesh_ids: &[MeshId],
        ankle_height: f32,
        first: bool,
    ) -> Vec<(usize, Vec<Deformer>)> {
        let radius: Vec<f32> = self.part_meshes.iter().map(Mesh::bounding_radius).collect();
        let mut out = Vec::new();
        for (index, surface) in self.surfaces.iter().enumerate() {
            let desc = &surface.desc;
            let replenishes = desc.replenish_rate > 0.0;
            let to_local = desc.world_to_local();
            let half = desc.size * 0.5;
            let top = desc.snow_depth + ankle_height;
            let deformers: Vec<Deformer> = before
                .iter()
                .zip(now)
                .filter_map(|(a, b)| {
                    let id = *part_mesh_ids.get(b.part)?;
                    let r = radius.get(b.part).copied().unwrap_or(0.0);
                    let c = to_local.transform_point3(b.pose.position);
                    let over = c.x.abs() <= half.x + r
                        && c.z.abs() <= half.y + r
                        && c.y >= -r
                        && c.y <= top + r;
                    let moved = a.pose != b.pose;
                    (over && (moved || replenishes || first))
                        .then(|| Deformer::moving(Shape::Mesh(id), a.pose, b.pose))
                })
                .collect();
            if !deformers.is_empty() || replenishes {
                out.push((index, deformers));
            }
        }
        out
    }

    /// A camera by name (see [`DemoWorld::camera_names`]) at time `t`.
    pub fn camera(&self, name: &str, t: f32) -> Option<Camera> {
        camera::camera(self, name, t)
    }

    /// The names [`DemoWorld::camera`] accepts: `flythrough` (scripted, visits each event),
    /// `overview` (every roof), `closeup` (the walker's fresh prints), and one per event: `run`,
    /// `fall`, `angel`, `slide`, `fight`.
    pub fn camera_names() -> &'static [&'static str] {
        &camera::NAMES
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use glam::{Vec2, Vec3, Vec4};

    use super::anim::Action;
    use super::*;

    const HZ: f32 = 30.0;

    fn frames(d: &DemoWorld) -> impl Iterator<Item = f32> {
        (0..=(d.duration * HZ) as u32).map(|i| i as f32 / HZ)
    }

    #[test]
    fn build_is_deterministic() {
        assert_eq!(DemoWorld::build(), DemoWorld::build());
    }

    #[test]
    fn part_meshes_are_closed_and_outward() {
        let d = DemoWorld::build();
        assert_eq!(d.part_meshes.len(), PART_COUNT);
        for (m, part) in d.part_meshes.iter().zip(Part::ALL) {
            m.validate(part.name()).expect("valid");
            // Every directed edge once, and its reverse once: a closed, consistently wound mesh.
            let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
            for t in m.indices.chunks(3) {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    *edges.entry((a, b)).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "{}: edge {a}-{b} used {n} times", part.name());
                assert!(
                    edges.contains_key(&(b, a)),
                    "{}: open edge {a}-{b}",
                    part.name()
                );
            }
            let volume: f32 = m
                .indices
                .chunks(3)
                .map(|t| {
                    let p = |i: u32| m.positions[i as usize];
                    p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0
                })
                .sum();
            assert!(volume > 0.0, "{} is inside out", part.name());
        }
    }

    #[test]
    fn legs_reach_every_planted_foot() {
        let d = DemoWorld::build();
        for p in &d.people {
            for (i, seg) in p.motion.segments.iter().enumerate() {
                let Action::Gait(g) = &seg.action else {
                    continue;
                };
                let end = p
                    .motion
                    .segments
                    .get(i + 1)
                    .map_or(f32::INFINITY, |n| n.start);
                for t in frames(&d).filter(|&t| t >= seg.start + seg.blend && t < end) {
                    let world = p.pose_at(t).world();
                    for side in [Side::Right, Side::Left] {
                        let (target, _) = g.foot_at(side, t);
                        let got = world[Part::foot(side).index()].position;
                        assert!(
                            got.distance(target) < 1e-3,
                            "{}'s {side:?} foot misses its target by {} m at {t}",
                            p.name,
                            got.distance(target)
                        );
                    }
                }
            }
        }
    }

    /// Lowest world point of a part's mesh.
    fn lowest_point(d: &DemoWorld, part: usize, pose: &Pose) -> Vec3 {
        d.part_meshes[part]
            .positions
            .iter()
            .map(|&v| pose.position + pose.rotation * v)
            .fold(Vec3::splat(f32::MAX), |a, b| if b.y < a.y { b } else { a })
    }

    fn lowest(d: &DemoWorld, part: usize, pose: &Pose) -> f32 {
        lowest_point(d, part, pose).y
    }

    /// The walker and the runner touch the snow with their boots (and shins) only on their
    /// footfalls: between prints the swinging leg is above the snow top.
    #[test]
    fn feet_touch_the_snow_only_where_they_are_planted() {
        let d = DemoWorld::build();
        for name in ["walker", "runner"] {
            let (index, p) = (
                d.person_index(name).expect("person"),
                d.person(name).expect("person"),
            );
            let desc = &d.surfaces[p.surface].desc;
            let snow_top = desc.center.y + desc.snow_depth;
            let footfalls = p.footfalls();
            // A foot that skids on landing touches down `slip` behind its print's centre.
            let slip = match &p.motion.segments[0].action {
                Action::Gait(g) => g.style.slip,
                _ => 0.0,
            };
            for t in frames(&d) {
                for part in d.parts_at(t).iter().filter(|q| q.person == index) {
                    let low = lowest_point(&d, part.part, &part.pose);
                    if low.y >= snow_top {
                        continue;
                    }
                    let side = match Part::ALL[part.part] {
                        Part::FootRight | Part::ShinRight => Side::Right,
                        Part::FootLeft | Part::ShinLeft => Side::Left,
                        other => panic!("{name}'s {other:?} is in the snow at {t}"),
                    };
                    let planted = footfalls.iter().any(|f| {
                        let c = f.print_center();
                        f.side == side && Vec2::new(c.x - low.x, c.z - low.z).length() < 0.2 + slip
                    });
                    assert!(
                        planted,
                        "{name}'s {side:?} leg ploughs the snow at {t}: {low}"
                    );
                }
            }
        }
    }

    /// One mesh id a part, as a world would hand them out in order (`MeshId` is opaque outside
    /// the library; its serialized form is the index).
    fn part_ids() -> Vec<MeshId> {
        (0..PART_COUNT)
            .map(|i| serde_json::from_str(&i.to_string()).expect("a mesh id is its index"))
            .collect()
    }

    #[test]
    fn part_poses_are_rigid_and_every_part_deforms() {
        let d = DemoWorld::build();
        let ids = part_ids();
        for t in frames(&d) {
            let parts = d.parts_at(t);
            assert_eq!(parts.len(), d.people.len() * PART_COUNT);
            for p in &parts {
                assert!(p.pose.position.is_finite());
                assert!((p.pose.rotation.length() - 1.0).abs() < 1e-4);
            }
            let deformers = d.deformers_at(t, 1.0 / HZ, &ids);
            assert_eq!(deformers.len(), parts.len());
            for (def, p) in deformers.iter().zip(&parts) {
                assert_eq!(def.shape, Shape::Mesh(ids[p.part]));
                assert_eq!(def.pose, p.pose);
            }
        }
        // Parts without a mesh id are left out rather than panicking.
        assert!(d.deformers_at(1.0, 0.1, &ids[..3]).len() == 3 * d.people.len());
    }

    /// Every part that moved inside a surface's capture volume is handed to that surface.
    #[test]
    fn surface_deformers_hold_everything_that_moves_in_the_snow() {
        let d = DemoWorld::build();
        let ids = part_ids();
        let ankle = 0.25;
        let dt = 1.0 / HZ;
        for t in frames(&d).skip(1) {
            let sorted = d.surface_deformers(t, dt, &ids, ankle);
            let before = d.parts_at(t - dt);
            for (now, then) in d.parts_at(t).iter().zip(&before) {
                if now.pose == then.pose {
                    continue;
                }
                let low = lowest(&d, now.part, &now.pose);
                for (i, s) in d.surfaces.iter().enumerate() {
                    let local = s.desc.world_to_local().transform_point3(now.pose.position);
                    let inside = local.x.abs() < 0.5 * s.desc.size.x
                        && local.z.abs() < 0.5 * s.desc.size.y
                        && low - s.desc.center.y < s.desc.snow_depth + ankle;
                    if !inside {
                        continue;
                    }
                    let listed = sorted
                        .iter()
                        .any(|(j, defs)| *j == i && defs.iter().any(|x| x.pose == now.pose));
                    assert!(
                        listed,
                        "part {} of person {} missed on surface {i} at {t}",
                        now.part, now.person
                    );
                }
            }
        }
    }

    #[test]
    fn people_stay_on_their_roofs() {
        let d = DemoWorld::build();
        for p in &d.people {
            let desc = &d.surfaces[p.surface].desc;
            let inside = |w: Vec3, margin: f32| {
                let l = desc.world_to_local().transform_point3(w);
                l.x.abs() <= 0.5 * desc.size.x - margin && l.z.abs() <= 0.5 * desc.size.y - margin
            };
            for f in p.footfalls() {
                assert!(
                    inside(f.print_center(), 0.3),
                    "{} steps off its roof",
                    p.name
                );
            }
            if let Some((_, topple)) = p.topple() {
                let (root, rot) = topple.lying_root();
                let head = root + rot * Vec3::Y * (dims_height() - 0.9);
                assert!(
                    inside(root, 0.5) && inside(head, 0.3),
                    "{} lands off its roof",
                    p.name
                );
            }
        }
    }

    fn dims_height() -> f32 {
        skeleton::dims::HEIGHT
    }

    fn sees(cam: &Camera, p: Vec3) -> bool {
        let clip = cam.projection(16.0 / 9.0, 0.1, 500.0) * cam.view() * Vec4::from((p, 1.0));
        let ndc = clip.truncate() / clip.w;
        clip.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0
    }

    #[test]
    fn cameras_see_the_action() {
        let d = DemoWorld::build();
        assert!(d.camera("no such camera", 0.0).is_none());
        for t in frames(&d) {
            for name in DemoWorld::camera_names() {
                let cam = d.camera(name, t).expect("camera");
                assert!(cam.eye.is_finite() && cam.target.is_finite());
                assert!(cam.eye.distance(cam.target) > 1.0);
            }
            let overview = d.camera("overview", t).expect("overview");
            for (p, person) in d.people.iter().map(|p| (p.pose_at(t).root, p.name)) {
                assert!(sees(&overview, p), "the overview misses {person} at {t}");
            }
            for s in &d.surfaces[1..] {
                assert!(
                    sees(&overview, s.desc.center),
                    "the overview misses {}",
                    s.desc.name
                );
            }
            for (cam, who) in [
                ("closeup", "walker"),
                ("run", "runner"),
                ("fall", "faller"),
                ("angel", "angel"),
                ("fight", "brawler"),
                ("fight", "thug"),
            ] {
                let c = d.camera(cam, t).expect("camera");
                let p = d.person(who).expect("person").pose_at(t).root;
                assert!(sees(&c, p), "{cam} misses {who} at {t}");
            }
        }
        // The slide camera sees the whole slide.
        let slider = d.person("slider").expect("slider");
        let slide = slider.slide().expect("slide");
        let c = d.camera("slide", 4.0).expect("camera");
        let start = Vec3::new(slide.start.x, slide.ground, slide.start.y);
        let end = start + anim::forward_of(slide.yaw) * (slide.length() + 1.0);
        assert!(sees(&c, start) && sees(&c, end));
    }
}
