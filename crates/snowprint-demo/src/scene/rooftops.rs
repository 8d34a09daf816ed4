//! The demo world ([`crate::DemoWorld`]) as a [`DemoScene`] for the renderer:
//! its surfaces go into the `SnowWorld`, its props and body-part meshes into the `Renderer`, and
//! each step moves the people as a trudging [`Crowd`]: every person on a clock of their own, slowed
//! and lowered by the snow under their feet (read from the world's probes a fixed number of
//! updates late, so that every run gives the same frames), pressing the snow with the per-surface
//! deformers of what moved (`DemoWorld::deformers_by_surface` and `SnowWorld::update`, so a body
//! at rest costs nothing). The demo world draws nothing and has
//! no materials or lights of its own; this adapter picks a procedural material for each prop from
//! its shape (buildings get brick facades with windows, parapets concrete, the rest gathers snow on
//! top) and adds sodium street lamps along the street.

use crate::trudge::Crowd;
use crate::{DemoWorld, PART_COUNT, Part};
use glam::{Mat4, Vec3};
use snowprint::render::{Instance, MeshMaterial, PointLight, RenderMeshId, Renderer};
use snowprint::{Camera, GroundMaterial, Mesh, MeshId, SnowWorld, SurfaceId};

use super::DemoScene;

/// The library's demo world, ready to simulate and draw.
pub struct LibraryDemo {
    demo: DemoWorld,
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
    statics: Vec<Instance>,
    lights: Vec<PointLight>,
    part_world: Vec<MeshId>,
    part_render: Vec<RenderMeshId>,
    /// The people, trudging; advanced by each step.
    crowd: Crowd,
}

/// A closed cylinder along +Y from y = 0 to `height` (lamp poles).
fn pole(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, height, 0.0)];
    for s in 0..segments {
        let a = std::f32::consts::TAU * s as f32 / segments as f32;
        positions.push(Vec3::new(radius * a.cos(), 0.0, radius * a.sin()));
        positions.push(Vec3::new(radius * a.cos(), height, radius * a.sin()));
    }
    let ring = |s: u32, top: u32| 2 + 2 * (s % segments) + top;
    let mut indices = Vec::new();
    for s in 0..segments {
        let (b0, t0, b1, t1) = (ring(s, 0), ring(s, 1), ring(s + 1, 0), ring(s + 1, 1));
        indices.extend_from_slice(&[b0, t0, t1, b0, t1, b1, 0, b0, b1, 1, t1, t0]);
    }
    Mesh { positions, indices }
}

/// The world-space bounds of a transformed mesh.
fn bounds(mesh: &Mesh, transform: Mat4) -> (Vec3, Vec3) {
    mesh.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| {
            let q = transform.transform_point3(p);
            (lo.min(q), hi.max(q))
        },
    )
}

/// A material for a prop of the demo world, from its size: tall, wide blocks are buildings;
/// thin, low walls are parapets; everything else (doors, chimneys, water towers) is drawn in its
/// own colour and gathers snow on top.
fn material_for(size: Vec3) -> MeshMaterial {
    let thin = size.x.min(size.z);
    if size.y > 3.0 && thin > 2.0 {
        MeshMaterial::Facade
    } else if thin <= 0.4 && size.y <= 1.5 && size.x.max(size.z) > 2.0 {
        MeshMaterial::Concrete
    } else {
        MeshMaterial::Plain
    }
}

/// What every scene on the rooftops shares: the demo world's surfaces in the `SnowWorld`, its props
/// with materials, the ground and distant buildings around the block, and the street lamps.
pub(super) struct Scenery {
    pub(super) surfaces: Vec<(SurfaceId, GroundMaterial)>,
    pub(super) statics: Vec<Instance>,
    pub(super) lights: Vec<PointLight>,
}

impl Scenery {
    pub(super) fn build(
        demo: &DemoWorld,
        world: &mut SnowWorld,
        renderer: &mut Renderer,
    ) -> Result<Self, String> {
        let werr = |e: snowprint::SnowError| e.to_string();
        let rerr = |e: snowprint::render::RenderError| e.to_string();
        let mut surfaces = Vec::new();
        for s in &demo.surfaces {
            surfaces.push((world.add_surface(s.desc.clone()).map_err(werr)?, s.ground));
        }
        let mut statics = Vec::new();
        for (i, prop) in demo.props.iter().enumerate() {
            let mesh = renderer.add_mesh(&prop.mesh).map_err(rerr)?;
            let (lo, hi) = bounds(&prop.mesh, prop.transform);
            let mut inst = Instance::new(mesh, prop.transform, prop.albedo)
                .with_material(material_for(hi - lo))
                .with_seed(i as f32 * 0.173);
            inst.snow_cover = 1.0;
            statics.push(inst);
        }
        // Around the block: snowy ground to the horizon and a ring of distant buildings with lit
        // windows (drawn only: they cast no shadow and press no snow).
        let unit = renderer
            .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
            .map_err(rerr)?;
        let mut ground = Instance::new(
            unit,
            Mat4::from_scale_rotation_translation(
                Vec3::new(400.0, 1.0, 400.0),
                glam::Quat::IDENTITY,
                Vec3::new(0.0, -0.52, 0.0),
            ),
            [0.3, 0.3, 0.3],
        )
        .with_material(MeshMaterial::Concrete)
        .with_shadow(false);
        // Trodden, dirty snow: half the cover of a roof's.
        ground.snow_cover = 0.5;
        statics.push(ground);
        for k in 0..14 {
            let a = std::f32::consts::TAU * (k as f32 + 0.3) / 14.0;
            let r = 62.0 + 9.0 * ((k * 7) % 5) as f32;
            let height = 18.0 + 5.0 * ((k * 3) % 7) as f32;
            let size = Vec3::new(16.0 + 2.0 * (k % 3) as f32, height, 12.0);
            let center = Vec3::new(a.cos() * r, height * 0.5, a.sin() * r);
            let turn = glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2 - a);
            let shade = 0.16 + 0.03 * (k % 4) as f32;
            statics.push(
                Instance::new(
                    unit,
                    Mat4::from_scale_rotation_translation(size, turn, center),
                    [shade + 0.08, shade, shade * 0.9],
                )
                .with_material(MeshMaterial::Facade)
                .with_shadow(false)
                .with_seed(0.37 * k as f32),
            );
        }
        // Sodium lamps along both sides of the street, standing in its snow.
        let street = demo.surfaces.first().map(|s| s.desc.clone());
        let mut lights = Vec::new();
        if let Some(street) = street {
            let shaft = renderer.add_mesh(&pole(0.07, 4.6, 10)).map_err(rerr)?;
            let bulb = renderer
                .add_mesh(&Mesh::uv_sphere(0.16, 8, 16))
                .map_err(rerr)?;
            let half = street.size * 0.5;
            let mut x = -half.x + 4.0;
            let mut side = 1.0;
            while x < half.x - 2.0 {
                let base = street.local_to_world().transform_point3(Vec3::new(
                    x,
                    0.0,
                    side * (half.y - 0.5),
                ));
                let head = base + Vec3::new(0.0, 4.6, -side * 0.4);
                statics.push(
                    Instance::new(shaft, Mat4::from_translation(base), [0.08, 0.08, 0.09])
                        .with_material(MeshMaterial::Metal),
                );
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
                x += 10.0;
                side = -side;
            }
        }
        Ok(Self {
            surfaces,
            statics: super::held_still(statics),
            lights,
        })
    }
}

impl LibraryDemo {
    /// Build the world: surfaces and part meshes into `world`, meshes into `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let demo = DemoWorld::build();
        let scenery = Scenery::build(&demo, world, renderer)?;
        let werr = |e: snowprint::SnowError| e.to_string();
        let rerr = |e: snowprint::render::RenderError| e.to_string();
        let mut part_world = Vec::new();
        let mut part_render = Vec::new();
        for (i, m) in demo.part_meshes.iter().enumerate() {
            part_world.push(world.add_mesh(&format!("body part {i}"), m).map_err(werr)?);
            part_render.push(renderer.add_mesh(m).map_err(rerr)?);
        }
        Ok(Self {
            surfaces: scenery.surfaces,
            statics: scenery.statics,
            lights: scenery.lights,
            part_world,
            part_render,
            // Probe keys of their own, far from any a game beside the demo would pick.
            crowd: Crowd::new(&demo, 1 << 40),
            demo,
        })
    }
}

impl DemoScene for LibraryDemo {
    fn name(&self) -> &str {
        // The name the report has always given this world (kept for readers of report.json).
        "snowprint::demo (DemoWorld::build)"
    }

    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)] {
        &self.surfaces
    }

    fn lights(&self) -> &[PointLight] {
        &self.lights
    }

    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
        let ids: Vec<SurfaceId> = self.surfaces.iter().map(|s| s.0).collect();
        self.crowd
            .step(&self.demo, world, t1 - t0, &ids, &self.part_world)
            .map_err(|e| e.to_string())
    }

    /// The scenery, and the people as the last [`DemoScene::advance`] left them (their own clocks
    /// are not the world's time `t`).
    fn instances(&self, _t: f32) -> Vec<Instance> {
        let mut v = self.statics.clone();
        for &p in self.crowd.parts() {
            if let Some(&mesh) = self.part_render.get(p.part) {
                let mut inst = Instance::new(
                    mesh,
                    Mat4::from_rotation_translation(p.pose.rotation, p.pose.position),
                    p.albedo,
                );
                inst.roughness = 0.8;
                v.push(inst);
            }
        }
        v
    }

    fn cameras(&self) -> &[&'static str] {
        DemoWorld::camera_names()
    }

    fn span(&self, _camera: &str) -> (f32, f32) {
        (0.0, self.demo.duration)
    }

    /// The demo's cameras; those that follow the walker or the runner follow the trudging one.
    fn camera(&self, name: &str, t: f32) -> Option<Camera> {
        let parts = self.crowd.parts();
        let root = |who: &str| {
            let i = self.demo.person_index(who)?;
            Some(
                parts
                    .get(i * PART_COUNT + Part::Pelvis.index())?
                    .pose
                    .position,
            )
        };
        crate::camera::camera_following(&self.demo, name, t, &root)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn props_get_materials_by_shape() {
        assert_eq!(
            material_for(Vec3::new(12.0, 10.0, 6.0)),
            MeshMaterial::Facade
        );
        assert_eq!(
            material_for(Vec3::new(12.6, 0.65, 0.3)),
            MeshMaterial::Concrete
        );
        assert_eq!(material_for(Vec3::new(1.0, 2.3, 2.4)), MeshMaterial::Plain);
    }

    #[test]
    fn every_prop_and_lamp_is_drawn_with_snow_on_top() {
        let demo = DemoWorld::build();
        assert!(demo.props.iter().any(|p| {
            let (lo, hi) = bounds(&p.mesh, p.transform);
            material_for(hi - lo) == MeshMaterial::Facade
        }));
        let m = pole(0.1, 2.0, 8);
        m.validate("pole").unwrap();
    }
}
