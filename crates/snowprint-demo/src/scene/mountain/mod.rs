//! The mountain (`snowprint demo --scene mountain`): a valley of rolling hills under 0.3 m of
//! snow, a frozen lake in a hollow, a rock outcrop too steep to hold snow, a stand of trees and a
//! scatter of them up the sides, rocks, and a cabin whose pitched roof carries snow of its own. One
//! hiker walks a loop of about 180 m around the valley and back to where it started, a few walkers
//! cross by the cabin and the lake, and the cameras follow the hiker, look over the valley, and
//! watch the loop close over the start of its own trail.
//!
//! The snow lies on the ground: the valley is a terrain-wide layer ([`snowprint::Terrain`]) on
//! its heights (`terrain.rs`) whose windows follow the hiker (a near level of 1024^2 texels of
//! 5 cm, a far one of 512^2 of 40 cm): the start of the loop is paged out of the near level while
//! the hiker is away and paged back in when it returns; the cabin's roof is a surface laid on its
//! mesh. Prints are measured from the local snow top and never dig into the ground.

mod hike;
mod props;
mod snow;
pub mod terrain;

use glam::{Vec2, Vec3};
use snowprint::render::{Instance, PointLight, Renderer};
use snowprint::{Camera, Deformer, GroundMaterial, SnowWorld, SurfaceId, Terrain};

use super::DemoScene;
use super::standin::body::BodyMeshes;
use super::standin::build::body_meshes;
use hike::{Hiker, Path};

/// Snow on the valley, metres.
pub const SNOW_DEPTH: f32 = 0.3;
/// How far below the snow's top a boot's sole comes down, metres.
const SINK: f32 = 0.16;
/// The hiker's pace, m/s.
const HIKING: f32 = 1.4;

/// Cameras of the mountain.
const CAMERAS: &[&str] = &["follow", "overview", "closing"];

/// The mountain, ready to simulate and draw.
pub struct Mountain {
    valley: Terrain,
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
    statics: Vec<Instance>,
    lights: Vec<PointLight>,
    hiker: Hiker,
    walkers: Vec<Hiker>,
    body: BodyMeshes,
}

/// The loop's control points around the valley (x, z), clockwise seen from above: past the
/// outcrop, up by the cabin, round the lake's north shore and back.
fn loop_controls() -> Vec<Vec2> {
    [
        (-4.0, -26.0),
        (12.0, -28.0),
        (28.0, -10.0),
        (27.0, 8.0),
        (15.0, 27.0),
        (-2.0, 30.0),
        (-18.0, 27.0),
        (-30.0, 12.0),
        (-27.0, -8.0),
        (-16.0, -22.0),
    ]
    .into_iter()
    .map(|(x, z)| Vec2::new(x, z))
    .collect()
}

/// The walk plane of everyone's boots at `(x, z)`: the ground, the snow, less the sink.
fn walk_plane(p: Vec2) -> f32 {
    snow::top(p) - SINK
}

impl Mountain {
    /// Build the valley: its snow into `world`, its meshes into `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let hiker = {
            let path = Path::through(&loop_controls(), true);
            let seconds = path.length() / HIKING + 4.0;
            Hiker::new(path, 0.0, HIKING, 0.0, seconds)
        };
        let (valley, surfaces) = snow::lay(world, focus(&hiker, 0.0))?;
        let walkers = walkers();
        let clear = |p: Vec2| {
            let near = |h: &Hiker| {
                (0..(h.path.length() as u32)).any(|s| (h.path.at(s as f32).0 - p).length() < 3.0)
            };
            !near(&hiker) && !walkers.iter().any(near)
        };
        let statics = crate::scene::held_still(props::build(renderer, clear)?);
        Ok(Self {
            valley,
            surfaces,
            statics,
            lights: props::lights(),
            hiker,
            walkers,
            body: body_meshes(renderer)?,
        })
    }

    /// The valley's snow (its levels' surfaces, what scrolling cost).
    pub fn valley(&self) -> &Terrain {
        &self.valley
    }

    /// The seconds the hiker takes to close the loop.
    pub fn loop_seconds(&self) -> f32 {
        self.hiker.path.length() / HIKING
    }

    fn everyone(&self) -> impl Iterator<Item = &Hiker> {
        std::iter::once(&self.hiker).chain(&self.walkers)
    }
}

/// Where the windows centre: on the hiker, at the snow's top under it.
fn focus(hiker: &Hiker, t: f32) -> Vec3 {
    let (p, _) = hiker.position(t);
    Vec3::new(p.x, snow::top(p), p.y)
}

/// Two walkers by the cabin and one across the lake's ice, out and back.
fn walkers() -> Vec<Hiker> {
    let line = |a: (f32, f32), b: (f32, f32)| {
        Path::through(&[Vec2::new(a.0, a.1), Vec2::new(b.0, b.1)], false)
    };
    let mut v = vec![
        Hiker::new(line((-4.0, 12.0), (10.0, 16.0)), 0.0, 1.2, 1.0, 11.0),
        Hiker::new(line((16.0, 14.0), (2.0, 24.5)), 0.0, 1.3, 4.0, 12.0),
        Hiker::new(line((-22.0, 6.0), (-6.0, 18.0)), 0.0, 3.2, 6.0, 6.0),
    ];
    v[0].coat = [0.1, 0.18, 0.3];
    v[1].coat = [0.28, 0.26, 0.2];
    v[2].coat = [0.12, 0.25, 0.12];
    v
}

impl DemoScene for Mountain {
    fn name(&self) -> &str {
        "mountain (a valley on real ground: hills, a frozen lake, a cabin, a hiker's loop)"
    }

    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)] {
        &self.surfaces
    }

    fn lights(&self) -> &[PointLight] {
        &self.lights
    }

    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
        self.valley
            .follow(world, focus(&self.hiker, t1))
            .map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        for h in self.everyone() {
            let a = h.skeleton(t0, &walk_plane).shapes();
            let b = h.skeleton(t1, &walk_plane).shapes();
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
        for h in self.everyone() {
            v.extend(
                h.skeleton(t, &walk_plane)
                    .instances(&self.body, h.coat, h.trousers),
            );
        }
        v
    }

    fn cameras(&self) -> &[&'static str] {
        CAMERAS
    }

    fn span(&self, camera: &str) -> (f32, f32) {
        let end = self.loop_seconds();
        match camera {
            "closing" => (end - 14.0, end + 2.0),
            "overview" => (0.0, 24.0),
            _ => (2.0, 22.0),
        }
    }

    fn camera(&self, name: &str, t: f32) -> Option<Camera> {
        let (p, d) = self.hiker.position(t);
        let ground = |q: Vec2| snow::top(q);
        let at = |q: Vec2, up: f32| Vec3::new(q.x, ground(q) + up, q.y);
        Some(match name {
            // Behind and above the hiker, looking a few metres ahead of it.
            "follow" => {
                let eye = p - d * 6.5 + Vec2::new(-d.y, d.x) * 2.0;
                Camera {
                    eye: at(eye, 3.2),
                    target: at(p + d * 3.0, 0.6),
                    fov_y_degrees: 50.0,
                }
            }
            // High over the valley's south end, the loop, the lake and the cabin below.
            "overview" => Camera {
                eye: Vec3::new(8.0, 34.0, -62.0),
                target: Vec3::new(-2.0, 2.0, 4.0),
                fov_y_degrees: 50.0,
            },
            // From beside the loop's start, looking back up the way it came: the hiker comes in
            // over its own trail of two minutes before.
            "closing" => {
                let (start, dir) = self.hiker.path.at(0.0);
                let eye = start + dir * 9.0 + Vec2::new(dir.y, -dir.x) * 3.0;
                Camera {
                    eye: at(eye, 2.4),
                    target: at(start - dir * 6.0, 0.3),
                    fov_y_degrees: 55.0,
                }
            }
            _ => return None,
        })
    }
}
