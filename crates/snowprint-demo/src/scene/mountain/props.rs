//! What the mountain draws besides its snow and its people: the valley floor beyond the snow,
//! trees, rocks, the outcrop's rock, the cabin and its lit window.

use glam::{Mat4, Quat, Vec2, Vec3};
use snowprint::Mesh;
use snowprint::render::{Instance, MeshMaterial, PointLight, Renderer};

use super::super::standin::build::{cone, cylinder};
use super::terrain::{self, CABIN, hash};

fn rerr(e: snowprint::render::RenderError) -> String {
    e.to_string()
}

/// Every static instance of the valley. `clear` says where a tree may stand (off the paths).
pub fn build(
    renderer: &mut Renderer,
    clear: impl Fn(Vec2) -> bool,
) -> Result<Vec<Instance>, String> {
    let mut v = Vec::new();
    // The floor: under the snow and snow-covered beyond it, out to the ridges. Under the snow it
    // lies a little more than the snow's depth down (where prints reach the ground it is the
    // surfaces' own ground that shows). It casts the valley's shadows (the outcrop's across the
    // slope below it) into the shadow map, which the relief tier's snow is not drawn into; lying
    // under the snow's top, it does not shade the snow over it.
    let floor = renderer
        .add_mesh(&terrain::floor_mesh(150.0, 1.0, 0.35))
        .map_err(rerr)?;
    let mut ground = Instance::new(floor, Mat4::IDENTITY, [0.78, 0.8, 0.86]);
    ground.roughness = 0.85;
    ground.snow_cover = 1.0;
    v.push(ground);
    v.extend(trees(renderer, clear)?);
    v.extend(rocks(renderer)?);
    v.extend(cabin(renderer)?);
    Ok(v)
}

/// Firs: a trunk and three cones, dark green with snow on their upper faces.
fn trees(renderer: &mut Renderer, clear: impl Fn(Vec2) -> bool) -> Result<Vec<Instance>, String> {
    let trunk = renderer.add_mesh(&cylinder(0.18, 1.2, 10)).map_err(rerr)?;
    let crown = renderer.add_mesh(&cone(1.6, 2.6, 14)).map_err(rerr)?;
    let mut v = Vec::new();
    for (k, (p, scale)) in terrain::tree_spots(clear).into_iter().enumerate() {
        let base = Vec3::new(p.x, terrain::height(p) - 0.1, p.y);
        let turn = Quat::from_rotation_y(hash(900 + k as u32) * std::f32::consts::TAU);
        let at = |up: f32, s: f32| {
            Mat4::from_scale_rotation_translation(
                Vec3::splat(scale * s),
                turn,
                base + Vec3::Y * up * scale,
            )
        };
        let mut t = Instance::new(trunk, at(0.0, 1.0), [0.16, 0.1, 0.06]);
        t.roughness = 0.9;
        v.push(t);
        for (i, (up, s)) in [(0.9, 1.0), (2.0, 0.78), (3.0, 0.55)]
            .into_iter()
            .enumerate()
        {
            let mut c = Instance::new(crown, at(up, s), [0.04, 0.1, 0.06]).with_seed(k as f32);
            c.roughness = 0.85;
            c.snow_cover = 0.55 + 0.15 * i as f32;
            v.push(c);
        }
    }
    Ok(v)
}

/// Boulders around the outcrop and by the lake, half sunk in the ground.
fn rocks(renderer: &mut Renderer) -> Result<Vec<Instance>, String> {
    let rock = renderer
        .add_mesh(&Mesh::uv_sphere(1.0, 8, 12))
        .map_err(rerr)?;
    let mut v = Vec::new();
    for k in 0..14u32 {
        let around = if k < 8 {
            terrain::OUTCROP
        } else {
            terrain::LAKE.0
        };
        let reach = if k < 8 { 6.0 } else { terrain::LAKE.1 + 3.0 };
        let a = hash(500 + k) * std::f32::consts::TAU;
        let p = around + Vec2::new(a.cos(), a.sin()) * (reach + 2.0 * hash(600 + k));
        // Boulders of 0.8 to 2 m, sunk to a third of their height so that none floats on a slope.
        let size = Vec3::new(1.3, 0.9, 1.1) * (0.6 + 0.9 * hash(700 + k));
        let m = Mat4::from_scale_rotation_translation(
            size,
            Quat::from_rotation_y(a),
            Vec3::new(p.x, terrain::height(p) - 0.3 * size.y, p.y),
        );
        let mut r =
            Instance::new(rock, m, [0.27, 0.26, 0.25]).with_material(MeshMaterial::Concrete);
        r.roughness = 0.9;
        r.snow_cover = 0.8;
        v.push(r.with_seed(k as f32));
    }
    Ok(v)
}

/// The cabin: log walls, a door, a lit window, the roof's two planes under its snow, a chimney.
fn cabin(renderer: &mut Renderer) -> Result<Vec<Instance>, String> {
    let unit = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .map_err(rerr)?;
    let (c, half, wall, _) = CABIN;
    let floor = terrain::height(c);
    let block = |lo: Vec3, hi: Vec3, albedo: [f32; 3]| {
        Instance::new(
            unit,
            Mat4::from_scale_rotation_translation(hi - lo, Quat::IDENTITY, 0.5 * (lo + hi)),
            albedo,
        )
    };
    let lo = Vec3::new(c.x - half.x, floor - 0.5, c.y - half.y);
    let hi = Vec3::new(c.x + half.x, floor + wall, c.y + half.y);
    let mut v = vec![block(lo, hi, [0.22, 0.13, 0.07])];
    // The door and the window on the south wall (-z), the window lit.
    let z = c.y - half.y - 0.03;
    v.push(block(
        Vec3::new(c.x - 1.9, floor, z - 0.02),
        Vec3::new(c.x - 1.0, floor + 2.0, z + 0.05),
        [0.1, 0.06, 0.03],
    ));
    v.push(
        block(
            Vec3::new(c.x + 0.4, floor + 1.0, z - 0.02),
            Vec3::new(c.x + 1.6, floor + 1.8, z + 0.05),
            [1.0, 0.72, 0.4],
        )
        .with_material(MeshMaterial::Emissive)
        .with_emission(2.5)
        .with_shadow(false),
    );
    // The roof's planes, a slab under each (the snow lies on their top faces).
    let (roof, _) = terrain::roof_triangles();
    let mut mesh = Mesh::default();
    for t in &roof.triangles {
        let n = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(t);
        mesh.indices.extend_from_slice(&[n, n + 1, n + 2]);
        // The underside, 12 cm below, wound the other way.
        mesh.positions.extend(t.iter().map(|p| *p - Vec3::Y * 0.12));
        mesh.indices.extend_from_slice(&[n + 3, n + 5, n + 4]);
    }
    let roof_mesh = renderer.add_mesh(&mesh).map_err(rerr)?;
    let mut r = Instance::new(
        roof_mesh,
        Mat4::from_translation(-Vec3::Y * 0.02),
        [0.2, 0.1, 0.08],
    );
    r.roughness = 0.8;
    v.push(r);
    // The gables: the walls' ends up to the ridge, as wedges of the unit box's faces is more than
    // the demo needs; a chimney stands through the roof instead.
    v.push(
        block(
            Vec3::new(c.x + 1.4, floor + wall, c.y + 0.5),
            Vec3::new(c.x + 2.0, floor + wall + 2.4, c.y + 1.1),
            [0.3, 0.28, 0.26],
        )
        .with_material(MeshMaterial::Brick),
    );
    Ok(v)
}

/// The cabin's window light on the snow in front of it, and a lantern by the lake.
pub fn lights() -> Vec<PointLight> {
    let (c, half, _, _) = CABIN;
    let floor = terrain::height(c);
    let lake = terrain::LAKE.0 + Vec2::new(terrain::LAKE.1 + 1.0, -2.0);
    vec![
        PointLight {
            position: Vec3::new(c.x + 1.0, floor + 1.4, c.y - half.y - 0.6),
            color: Vec3::new(1.0, 0.72, 0.42) * 2.4,
            radius: 10.0,
        },
        PointLight {
            position: Vec3::new(lake.x, terrain::height(lake) + 1.8, lake.y),
            color: Vec3::new(1.0, 0.8, 0.55) * 1.8,
            radius: 9.0,
        },
    ]
}
