//! The stand-in demo world (`snowprint demo --scene standin`), built in code before the demo crate's
//! own demo world ([`crate::DemoWorld`]) existed and kept as a small, self-contained second world:
//! three flat roofs at different heights (concrete, roof tiles, and one nobody walks on, so
//! it keeps the basic material), a street with lamps, facades with lit windows, a water tower, and
//! capsule people: one walks (heel, ball, arch and toe blocks per boot), one runs down the street, one
//! slides feet-first, one falls onto its back from standing, one makes a snow angel. Each body part
//! is both drawn and pressed into the snow, as in the talk.

use glam::Vec3;
use snowprint::render::{Instance, PointLight};
use snowprint::{Camera, Deformer, GroundMaterial, SnowWorld, SurfaceId};

use super::DemoScene;

pub(super) mod body;
pub(super) mod build;

use body::{BodyMeshes, Person};

const TAU: f32 = std::f32::consts::TAU;
const PI: f32 = std::f32::consts::PI;

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

    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
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
    use super::body::{Gait, THIGH};
    use super::build::{cone, cylinder};
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
