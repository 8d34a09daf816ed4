//! Building the stand-in world: its surfaces, the meshes it draws, the buildings, the water
//! tower, the street lamps and the people with what each of them does.

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{Instance, MeshMaterial, PointLight, RenderMeshId, Renderer};
use snowprint::{GroundMaterial, Mesh, SnowWorld, SurfaceDesc, SurfaceId};

use super::body::{Act, BodyMeshes, FOOT, FOREARM, Gait, Person, SHIN, THIGH, TORSO, UPPER_ARM};
use super::{ROOF_A, ROOF_B, ROOF_C, StandIn, TAU};

fn rerr(e: snowprint::render::RenderError) -> String {
    e.to_string()
}

/// A closed cylinder along +Y from y = 0 to `height`.
pub(in crate::scene) fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
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
pub(in crate::scene) fn cone(radius: f32, height: f32, segments: u32) -> Mesh {
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

/// The renderer's meshes of the set (the body's are [`BodyMeshes`]).
#[derive(Clone, Copy)]
struct SetMeshes {
    unit_box: RenderMeshId,
    tank: RenderMeshId,
    tank_roof: RenderMeshId,
    pole: RenderMeshId,
    bulb: RenderMeshId,
}

impl SetMeshes {
    /// A box of `half` extents at `center` (the unit box, scaled).
    fn block(
        &self,
        center: Vec3,
        half: Vec3,
        albedo: [f32; 3],
        material: MeshMaterial,
        seed: f32,
    ) -> Instance {
        Instance::new(self.unit_box, boxed(center, half), albedo)
            .with_material(material)
            .with_seed(seed)
    }
}

impl StandIn {
    /// Build the world: surfaces into `world`, meshes into `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let surfaces = surfaces(world)?;
        let set = set_meshes(renderer)?;
        let body = body_meshes(renderer)?;
        let mut statics = buildings(&set);
        water_tower(&set, &mut statics);
        let lights = street_lamps(&set, &mut statics);
        Ok(Self {
            surfaces,
            statics: crate::scene::held_still(statics),
            lights,
            people: people(),
            body,
        })
    }
}

/// The three roofs and the street.
fn surfaces(world: &mut SnowWorld) -> Result<Vec<(SurfaceId, GroundMaterial)>, String> {
    let err = |e: snowprint::SnowError| e.to_string();
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
    Ok(surfaces)
}

fn set_meshes(renderer: &mut Renderer) -> Result<SetMeshes, String> {
    let unit_box = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .map_err(rerr)?;
    let tank = renderer.add_mesh(&cylinder(1.25, 2.3, 32)).map_err(rerr)?;
    let tank_roof = renderer.add_mesh(&cone(1.4, 0.9, 32)).map_err(rerr)?;
    let pole = renderer.add_mesh(&cylinder(0.07, 4.6, 10)).map_err(rerr)?;
    let bulb = renderer
        .add_mesh(&Mesh::uv_sphere(0.16, 8, 16))
        .map_err(rerr)?;
    Ok(SetMeshes {
        unit_box,
        tank,
        tank_roof,
        pole,
        bulb,
    })
}

pub(in crate::scene) fn body_meshes(renderer: &mut Renderer) -> Result<BodyMeshes, String> {
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
    Ok(body)
}

/// The buildings under the roofs and across the street, parapets, sidewalks, a vent and a chimney.
fn buildings(set: &SetMeshes) -> Vec<Instance> {
    let brick = [0.36, 0.16, 0.11];
    let dark_brick = [0.24, 0.14, 0.11];
    let stone = [0.42, 0.40, 0.37];
    let mut statics = Vec::new();
    let block =
        |center, half, albedo, material, seed| set.block(center, half, albedo, material, seed);
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
    statics
}

/// The water tower on roof A: legs standing in the snow, a tank, a conical roof.
fn water_tower(set: &SetMeshes, statics: &mut Vec<Instance>) {
    let tower = Vec3::new(-3.6, ROOF_A, -2.3);
    for (dx, dz) in [(-0.9, -0.9), (0.9, -0.9), (-0.9, 0.9), (0.9, 0.9)] {
        statics.push(set.block(
            tower + Vec3::new(dx, 1.3, dz),
            Vec3::new(0.08, 1.3, 0.08),
            [0.18, 0.16, 0.15],
            MeshMaterial::Metal,
            0.0,
        ));
    }
    statics.push(set.block(
        tower + Vec3::new(0.0, 2.65, 0.0),
        Vec3::new(1.3, 0.06, 1.3),
        [0.2, 0.17, 0.15],
        MeshMaterial::Metal,
        0.0,
    ));
    statics.push(
        Instance::new(
            set.tank,
            Mat4::from_translation(tower + Vec3::Y * 2.7),
            [0.32, 0.2, 0.14],
        )
        .with_material(MeshMaterial::Metal),
    );
    statics.push(
        Instance::new(
            set.tank_roof,
            Mat4::from_translation(tower + Vec3::Y * 5.0),
            [0.22, 0.16, 0.12],
        )
        .with_material(MeshMaterial::Metal),
    );
}

/// Street lamps, sodium orange (poles, arms and bulbs into `statics`), and a lamp by the roof door
/// of roof A.
fn street_lamps(set: &SetMeshes, statics: &mut Vec<Instance>) -> Vec<PointLight> {
    let mut lights = Vec::new();
    for x in [-13.0, -3.0, 7.0, 17.0] {
        let base = Vec3::new(x, 0.0, 5.6);
        statics.push(
            Instance::new(set.pole, Mat4::from_translation(base), [0.08, 0.08, 0.09])
                .with_material(MeshMaterial::Metal),
        );
        let head = base + Vec3::new(0.0, 4.6, 0.5);
        statics.push(set.block(
            base + Vec3::new(0.0, 4.65, 0.25),
            Vec3::new(0.05, 0.04, 0.3),
            [0.08, 0.08, 0.09],
            MeshMaterial::Metal,
            0.0,
        ));
        statics.push(
            Instance::new(set.bulb, Mat4::from_translation(head), [1.0, 0.62, 0.28])
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
    lights
}

/// The people and what each does.
fn people() -> Vec<Person> {
    let coat = |r, g, b| [r, g, b];
    vec![
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
    ]
}
