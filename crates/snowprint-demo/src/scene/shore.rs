//! The shore (`snowprint demo --scene shore`): four strips of ground side by side along x, a
//! beach of wet sand by the sea, dry sand above it, a muddy track, and a snowy bank of fresh
//! powder, with people walking and running across all four (the stand-in world's capsule people,
//! [`super::standin`]). Each strip is a surface of its own material: wet sand (a `[[material]]`
//! of its own here: darker, glossier, steeper walls, more of it compacts), dry sand (slumps to 34
//! degrees and throws rims), mud (sharp prints, water in the deep ones) and powder (loose rims,
//! glints). The strips' tops stand at different heights, so that one walk plane presses each as
//! deep as its material gives: a few centimetres in wet sand, more in dry sand and mud (deeper
//! than its water depth), most in the powder.

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{Instance, PointLight, Renderer};
use snowprint::{
    Camera, Deformer, GroundMaterial, Material, MaterialLook, Mesh, SnowWorld, SprayLook,
    SurfaceDesc, SurfaceId,
};

use super::DemoScene;
use super::standin::body::{Act, BodyMeshes, Gait, Person};
use super::standin::build::body_meshes;

/// Strips along z: (name, material, z of the near and far edges, snow depth, top above the walk
/// plane), wet sand nearest the sea (-z).
fn strips() -> [(&'static str, Material, f32, f32, f32, f32); 4] {
    [
        ("wet_sand", wet_sand(), -7.0, -3.5, 0.2, 0.05),
        ("dry_sand", Material::sand(), -3.5, 0.5, 0.2, 0.08),
        ("mud_track", Material::mud(), 0.5, 3.0, 0.2, 0.11),
        ("snow_bank", Material::powder(), 3.0, 8.0, 0.35, 0.2),
    ]
}

/// Sand the sea has wetted: darker and glossier, holding steeper walls (60 degrees), more of a
/// print compacts (60 %) than in dry sand, and it throws clumps rather than a puff.
pub fn wet_sand() -> Material {
    Material {
        look: MaterialLook {
            albedo: [0.32, 0.22, 0.11],
            disturbed_albedo: [0.27, 0.19, 0.09],
            roughness: 0.6,
            wet_roughness: 0.35,
            grain: 0.5,
            wetness: 0.6,
            ..MaterialLook::sand()
        },
        repose_degrees: Some(60.0),
        relax_steps: 4,
        settle_updates: 60,
        compressibility: Some(0.6),
        // Wet grains stick: fewer, heavier clumps that fly on and drop.
        spray: SprayLook {
            amount: 0.4,
            drag: 0.6,
            radius: 0.012,
            albedo: [0.3, 0.21, 0.11],
            ..SprayLook::sand()
        },
    }
}

/// Half the strips' length along x, metres.
const HALF_X: f32 = 8.0;

/// Cameras of the shore.
const CAMERAS: &[&str] = &["flythrough", "overview", "closeup", "mud"];

/// The shore, ready to simulate and draw.
pub struct Shore {
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
    /// The sea and the land around the strips.
    statics: Vec<Instance>,
    lights: Vec<PointLight>,
    people: Vec<Person>,
    body: BodyMeshes,
}

impl Shore {
    /// Build the world: the four strips into `world`, the people's meshes into `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let mut surfaces = Vec::new();
        for (name, material, z0, z1, depth, top) in strips() {
            let ground = top - depth;
            let mut desc = SurfaceDesc::new(
                name,
                [0.0, ground, 0.5 * (z0 + z1)],
                [2.0 * HALF_X, z1 - z0],
                depth,
            );
            desc.material = material;
            desc.replenish_rate = 0.0;
            let id = world.add_surface(desc).map_err(|e| e.to_string())?;
            surfaces.push((id, GroundMaterial::Concrete));
        }
        let unit_box = renderer
            .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
            .map_err(|e| e.to_string())?;
        let block = |lo: Vec3, hi: Vec3, albedo: [f32; 3], roughness: f32| {
            let transform =
                Mat4::from_scale_rotation_translation(hi - lo, Quat::IDENTITY, 0.5 * (lo + hi));
            let mut i = Instance::new(unit_box, transform, albedo);
            i.roughness = roughness;
            i
        };
        let statics = vec![
            // The sea, still and dark, below the wet sand.
            block(
                Vec3::new(-60.0, -1.0, -60.0),
                Vec3::new(60.0, -0.02, -7.0),
                [0.015, 0.022, 0.03],
                0.08,
            ),
            // The land behind the bank, under snow, and the beach's ends.
            block(
                Vec3::new(-60.0, -1.0, 8.0),
                Vec3::new(60.0, 0.2, 60.0),
                [0.62, 0.66, 0.72],
                0.7,
            ),
            block(
                Vec3::new(-60.0, -1.0, -7.0),
                Vec3::new(-HALF_X, 0.02, 8.0),
                [0.2, 0.16, 0.11],
                0.9,
            ),
            block(
                Vec3::new(HALF_X, -1.0, -7.0),
                Vec3::new(60.0, 0.02, 8.0),
                [0.2, 0.16, 0.11],
                0.9,
            ),
        ];
        Ok(Self {
            surfaces,
            statics: super::held_still(statics),
            lights: vec![
                // A lantern on the bank, warm, and one down the beach.
                PointLight {
                    position: Vec3::new(-1.5, 1.6, 4.2),
                    color: Vec3::new(1.0, 0.75, 0.45) * 2.2,
                    radius: 9.0,
                },
                PointLight {
                    position: Vec3::new(4.5, 1.4, -4.0),
                    color: Vec3::new(1.0, 0.8, 0.55) * 1.6,
                    radius: 8.0,
                },
            ],
            people: people(),
            body: body_meshes(renderer)?,
        })
    }
}

/// Walkers and a runner crossing the strips, up the beach and back down.
fn people() -> Vec<Person> {
    let walk = |x: f32, z: f32, dir: Vec3, speed: f32, period: f32, t0: f32| Gait {
        start: Vec3::new(x, -0.02, z),
        dir: dir.normalize(),
        speed,
        period,
        stance: if speed > 2.0 { 0.42 } else { 0.62 },
        lift: 0.42,
        t0,
        t1: t0 + 14.0 / speed,
    };
    let person = |gait: Gait, coat: [f32; 3], trousers: [f32; 3]| Person {
        act: Act::Walk(gait),
        coat,
        trousers,
        leaves: None,
    };
    vec![
        person(
            walk(-3.0, -6.8, Vec3::Z, 1.25, 1.1, 0.0),
            [0.08, 0.09, 0.12],
            [0.06, 0.06, 0.07],
        ),
        person(
            walk(0.6, 7.6, -Vec3::Z, 1.15, 1.15, 0.5),
            [0.32, 0.12, 0.08],
            [0.07, 0.07, 0.09],
        ),
        person(
            walk(3.2, -6.8, Vec3::new(0.15, 0.0, 1.0), 3.4, 0.72, 2.0),
            [0.1, 0.2, 0.12],
            [0.1, 0.08, 0.06],
        ),
        person(
            walk(-6.0, 7.6, Vec3::new(0.3, 0.0, -1.0), 1.3, 1.05, 1.0),
            [0.3, 0.26, 0.2],
            [0.08, 0.08, 0.09],
        ),
    ]
}

impl DemoScene for Shore {
    fn name(&self) -> &str {
        "shore (wet sand, dry sand, a muddy track and a snowy bank)"
    }

    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)] {
        &self.surfaces
    }

    fn lights(&self) -> &[PointLight] {
        &self.lights
    }

    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
        let mut out = Vec::new();
        for p in &self.people {
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
        for p in &self.people {
            v.extend(p.act.skeleton(t).instances(&self.body, p.coat, p.trousers));
        }
        v
    }

    fn cameras(&self) -> &[&'static str] {
        CAMERAS
    }

    fn span(&self, camera: &str) -> (f32, f32) {
        match camera {
            "closeup" | "mud" => (6.0, 12.0),
            _ => (1.0, 13.0),
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
            // From the sea, rising over the beach towards the bank.
            "flythrough" => {
                let s = u * u * (3.0 - 2.0 * u);
                cam(
                    Vec3::new(-7.0 + 5.0 * s, 3.2 + 1.5 * s, -11.0 + 5.0 * s),
                    Vec3::new(-1.0, 0.0, -1.5 + 4.0 * s),
                    50.0,
                )
            }
            "overview" => cam(Vec3::new(-9.0, 9.0, -9.5), Vec3::new(0.0, 0.0, 0.5), 50.0),
            // Low along the first walker's track, from the dry sand over the mud to the bank.
            "closeup" => {
                let z = -2.5 + 3.0 * u;
                cam(
                    Vec3::new(-1.4, 1.3, z - 1.6),
                    Vec3::new(-3.0, 0.0, z + 1.2),
                    45.0,
                )
            }
            // The muddy track's prints and their water, from above.
            "mud" => cam(Vec3::new(-1.2, 2.0, -0.4), Vec3::new(-2.6, 0.0, 1.8), 45.0),
            _ => return None,
        })
    }
}
