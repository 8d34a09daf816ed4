//! The tessellated tier on the GPU: the diced mesh read back from the vertex and index buffers has
//! no cracks and its density follows the size on screen; the banks conserve the volume they say
//! they do, and agree with their CPU reference; settings are checked.

mod common;

use std::collections::HashMap;

use glam::{Quat, Vec2, Vec3};
use snowprint::reference::tessellate as cpu;
use snowprint::render::{BankSettings, DicedKind, DicedMesh, SurfaceGeometry};
use snowprint::render::{
    DebugView, Environment, RenderConfig, RenderError, RenderFrame, RenderOutput, Renderer,
    SurfaceMesh, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId, WorldConfig,
};

/// A 4 x 3 m roof with 15 cm of snow and a trench a body slid along, to the ground.
fn trench_world() -> (SnowWorld, SurfaceId) {
    let mut world = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let roof = world
        .add_surface(SurfaceDesc::new("roof", [0.0, 2.0, 0.0], [4.0, 3.0], 0.15))
        .expect("roof");
    let lying = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let steps = 8;
    for k in 0..steps {
        let pose = |u: f32| Pose {
            position: Vec3::new(-1.4 + 2.4 * u, 2.12, -0.2),
            rotation: lying,
        };
        let d = [Deformer::moving(
            Shape::Capsule {
                radius: 0.15,
                half_height: 0.55,
            },
            pose(k as f32 / steps as f32),
            pose((k + 1) as f32 / steps as f32),
        )];
        world.step(1.0 / 30.0, &d).expect("step");
    }
    (world, roof)
}

/// The trench's middle, where the cameras look.
const TRENCH: Vec3 = Vec3::new(0.0, 2.0, -0.2);

fn render(
    renderer: &mut Renderer,
    world: &SnowWorld,
    roof: SurfaceId,
    eye: Vec3,
    target: Vec3,
) -> RenderOutput {
    let surfaces = [(roof, GroundMaterial::Concrete)];
    renderer
        .render(
            world,
            &RenderFrame {
                camera: Camera {
                    eye,
                    target,
                    fov_y_degrees: 50.0,
                },
                time: 0.0,
                surfaces: &surfaces,
                instances: &[],
                lights: &[],
                environment: Environment::moonlit_night(),
                snowfall: false,
            },
        )
        .expect("render")
}

fn renderer(world: &SnowWorld) -> Renderer {
    let _ = world;
    let mut config = RenderConfig::new(256, 144, Tier::Tessellated);
    config.shadow_map_size = 512;
    Renderer::new(common::gpu(), config).expect("renderer")
}

/// Positions as exact bit patterns: welding by them finds cracks a tolerance would hide.
fn key(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

/// Check a diced mesh has no cracks: the top's edges (by exact positions) are used by two
/// triangles, except on the border of the surface where one triangle and one skirt meet; every
/// skirt hangs from a border edge of the top.
fn check_crack_free(mesh: &DicedMesh, half: Vec2) -> usize {
    let mut top_edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    let mut skirt_edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    let mut tops = 0;
    for t in &mesh.triangles {
        let v = t.map(|i| mesh.vertices[i as usize]);
        let kinds = v.map(|x| x.kind);
        let is_top = kinds.iter().all(|&k| k == DicedKind::Top);
        assert!(
            is_top || kinds.iter().all(|&k| k != DicedKind::Top),
            "a triangle mixes the top and a skirt: {v:?}"
        );
        if is_top {
            tops += 1;
        }
        for e in 0..3 {
            let (a, b) = (v[e], v[(e + 1) % 3]);
            let (ka, kb) = (key(a.position), key(b.position));
            let k = if ka < kb { (ka, kb) } else { (kb, ka) };
            if is_top {
                *top_edges.entry(k).or_insert(0) += 1;
            } else if a.kind == DicedKind::SkirtTop && b.kind == DicedKind::SkirtTop {
                *skirt_edges.entry(k).or_insert(0) += 1;
            }
        }
    }
    let on_border = |k: &[u32; 3]| {
        let p = Vec3::new(
            f32::from_bits(k[0]),
            f32::from_bits(k[1]),
            f32::from_bits(k[2]),
        );
        (p.x.abs() - half.x).abs() < 1e-5 || (p.z.abs() - half.y).abs() < 1e-5
    };
    let mut border = 0;
    for (k, uses) in &top_edges {
        let border_edge = on_border(&k.0) && on_border(&k.1) && {
            let (a, b) = (f32::from_bits(k.0[0]), f32::from_bits(k.1[0]));
            let (c, d) = (f32::from_bits(k.0[2]), f32::from_bits(k.1[2]));
            (a == b && (a.abs() - half.x).abs() < 1e-5)
                || (c == d && (c.abs() - half.y).abs() < 1e-5)
        };
        if border_edge {
            border += 1;
            assert_eq!(*uses, 1, "border edge {k:?} used {uses} times");
            assert_eq!(
                skirt_edges.get(k),
                Some(&1),
                "border edge {k:?} has no skirt hanging from it"
            );
        } else {
            assert_eq!(*uses, 2, "inner edge {k:?} used {uses} times: a crack");
        }
    }
    assert_eq!(border, skirt_edges.len(), "skirts off the border");
    tops
}

#[test]
fn diced_mesh_is_crack_free_and_denser_closer() {
    let (world, roof) = trench_world();
    let mut r = renderer(&world);
    let half = Vec2::new(2.0, 1.5);
    let far = render(&mut r, &world, roof, Vec3::new(0.5, 7.0, 9.0), TRENCH);
    let far_mesh = r.read_diced_mesh(roof).expect("diced mesh");
    let far_tops = check_crack_free(&far_mesh, half);
    let near = render(&mut r, &world, roof, Vec3::new(0.3, 3.2, 2.2), TRENCH);
    let near_mesh = r.read_diced_mesh(roof).expect("diced mesh");
    let near_tops = check_crack_free(&near_mesh, half);
    // The report counts the same triangles (skirts included).
    let reported = |o: &RenderOutput| o.surfaces[0].triangles as usize;
    assert_eq!(reported(&far), far_mesh.triangles.len());
    assert_eq!(reported(&near), near_mesh.triangles.len());
    assert_eq!(far.dice_overflow + near.dice_overflow, 0);
    eprintln!("top triangles: far {far_tops}, near {near_tops}");
    assert!(
        near_tops as f32 > 2.0 * far_tops as f32,
        "closer should be denser: far {far_tops}, near {near_tops}"
    );
    // Where the trench is, the mesh is finer than on the untouched snow (relief term): compare
    // the density of top triangles within 0.3 m of the trench's line and far from it.
    let density = |mesh: &DicedMesh, near_trench: bool| {
        let mut count = 0.0;
        for t in &mesh.triangles {
            let v = t.map(|i| mesh.vertices[i as usize]);
            if v.iter().any(|x| x.kind != DicedKind::Top) {
                continue;
            }
            let c = (v[0].position + v[1].position + v[2].position) / 3.0;
            let band = (c.z + 0.2).abs() < 0.3 && c.x.abs() < 1.0;
            let open = (c.z - 1.0).abs() < 0.3 && c.x.abs() < 1.0;
            if (near_trench && band) || (!near_trench && open) {
                count += 1.0;
            }
        }
        count
    };
    // Seen from above, half-way between the two bands, so that both are about as big on screen.
    render(
        &mut r,
        &world,
        roof,
        Vec3::new(0.0, 5.0, 0.9),
        Vec3::new(0.0, 2.0, 0.4),
    );
    let above = r.read_diced_mesh(roof).expect("diced mesh");
    check_crack_free(&above, half);
    let (trench, open) = (density(&above, true), density(&above, false));
    eprintln!("from above: {trench} triangles over the trench, {open} over as much open snow");
    assert!(trench > 1.5 * open, "trench {trench}, open {open}");

    // Behind the camera but inside the moon's near shadow cascade (a 12 m square around what the
    // camera looks at): still diced, because its snow shadows what the camera sees.
    render(
        &mut r,
        &world,
        roof,
        Vec3::new(0.0, 3.0, 2.5),
        Vec3::new(0.0, 2.5, 5.0),
    );
    let behind = r.read_diced_mesh(roof).expect("mesh");
    eprintln!(
        "behind the camera, in the shadow cascade: {} triangles",
        behind.triangles.len()
    );
    assert!(!behind.triangles.is_empty());

    // Looking away, the shadow cascade far from the roof too: everything is culled.
    render(
        &mut r,
        &world,
        roof,
        Vec3::new(0.0, 3.0, 8.0),
        Vec3::new(0.0, 3.0, 20.0),
    );
    assert!(r.read_diced_mesh(roof).expect("mesh").triangles.is_empty());
}

#[test]
fn a_user_mesh_is_diced_crack_free() {
    let (world, roof) = trench_world();
    let mut r = renderer(&world);
    // A fan of 6 triangles around an off-centre point, a pitched ridge along x (y up to 0.2 m).
    let ring = [
        Vec3::new(-2.0, 0.0, -1.5),
        Vec3::new(0.3, 0.2, -1.5),
        Vec3::new(2.0, 0.0, -1.5),
        Vec3::new(2.0, 0.0, 1.5),
        Vec3::new(-0.4, 0.1, 1.5),
        Vec3::new(-2.0, 0.0, 1.5),
    ];
    let mut positions = vec![Vec3::new(0.4, 0.15, 0.1)];
    positions.extend(ring);
    let triangles = (0..6u32).map(|i| [0, 1 + (i + 1) % 6, 1 + i]).collect();
    r.set_surface_geometry(
        &world,
        roof,
        SurfaceGeometry {
            mesh: Some(SurfaceMesh {
                positions,
                triangles,
            }),
            ..Default::default()
        },
    )
    .expect("geometry");
    render(&mut r, &world, roof, Vec3::new(0.3, 3.6, 3.0), TRENCH);
    let mesh = r.read_diced_mesh(roof).expect("mesh");
    let tops = check_crack_free(&mesh, Vec2::new(2.0, 1.5));
    assert!(tops > 6 * 9, "{tops} top triangles");
}

/// Snow on a gable roof (a user mesh pitched along x) shades as sloped: in the normals view, the
/// slope facing +z and the one facing -z differ in the normal's z, though nothing pressed the snow
/// (the heightmap alone would make both flat).
#[test]
fn snow_on_a_pitched_mesh_shades_with_its_slope() {
    let world = {
        let mut w = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
        w.add_surface(SurfaceDesc::new("gable", [0.0; 3], [4.0, 3.0], 0.15))
            .expect("roof");
        w
    };
    let roof = world.surfaces().next().expect("a surface").0;
    let mut r = renderer(&world);
    r.set_debug_view(DebugView::Normals);
    // Eaves at z = -1.5 and 1.5, ridge at z = 0, 0.4 m up.
    let positions = vec![
        Vec3::new(-2.0, 0.0, -1.5),
        Vec3::new(2.0, 0.0, -1.5),
        Vec3::new(2.0, 0.4, 0.0),
        Vec3::new(-2.0, 0.4, 0.0),
        Vec3::new(2.0, 0.0, 1.5),
        Vec3::new(-2.0, 0.0, 1.5),
    ];
    let triangles = vec![[0, 2, 1], [0, 3, 2], [3, 4, 2], [3, 5, 4]];
    r.set_surface_geometry(
        &world,
        roof,
        SurfaceGeometry {
            mesh: Some(SurfaceMesh {
                positions,
                triangles,
            }),
            ..Default::default()
        },
    )
    .expect("geometry");
    let camera = Camera {
        eye: Vec3::new(0.0, 7.0, 0.5),
        target: Vec3::ZERO,
        fov_y_degrees: 50.0,
    };
    let out = render(&mut r, &world, roof, camera.eye, camera.target);
    let view_proj =
        camera.projection(out.width as f32 / out.height as f32, 0.05, 600.0) * camera.view();
    // Mean blue (the normal's z) of a 5 x 5 patch around a point of the snow on each slope.
    let blue = |p: Vec3| {
        let c = view_proj.project_point3(p);
        let (x, y) = (
            ((c.x * 0.5 + 0.5) * out.width as f32) as i32,
            ((0.5 - c.y * 0.5) * out.height as f32) as i32,
        );
        let mut sum = 0.0;
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (px, py) = ((x + dx) as u32, (y + dy) as u32);
                sum += out.rgba8[((py * out.width + px) * 4 + 2) as usize] as f32;
            }
        }
        sum / 25.0
    };
    let (back, front) = (
        blue(Vec3::new(0.0, 0.2 + 0.15, -0.75)),
        blue(Vec3::new(0.0, 0.2 + 0.15, 0.75)),
    );
    eprintln!("normals view, blue: slope facing -z {back:.1}, facing +z {front:.1}");
    assert!(
        front > back + 20.0,
        "the two slopes shade alike: blue {back:.1} and {front:.1}"
    );
}

#[test]
fn banks_conserve_the_pushed_volume_on_the_gpu() {
    let (world, roof) = trench_world();
    let mut r = renderer(&world);
    let banks = BankSettings {
        fraction: 0.4,
        width: 0.25,
    };
    r.set_surface_geometry(
        &world,
        roof,
        SurfaceGeometry {
            banks,
            ..Default::default()
        },
    )
    .expect("geometry");
    render(&mut r, &world, roof, Vec3::new(0.5, 5.0, 5.0), TRENCH);
    let fields = r.read_surface_fields(roof).expect("fields");
    let heightmap = world.read_heightmap(roof).expect("heightmap");
    let desc = world.surface(roof).expect("surface");
    let texel = Vec2::new(
        desc.size.x / fields.width as f32,
        desc.size.y / fields.height as f32,
    );
    let area = (texel.x * texel.y) as f64;
    // The pushed volume from the pool itself (16-bit units), not from the GPU's copy.
    let pushed: f64 = heightmap
        .displaced
        .iter()
        .map(|&d| d as f64 / 65535.0)
        .sum::<f64>()
        * desc.snow_depth as f64
        * area;
    let bank: f64 = fields.bank.iter().map(|&b| b as f64).sum::<f64>() * area;
    let want = banks.fraction as f64 * pushed;
    let error = (bank - want).abs() / want;
    eprintln!(
        "pushed {:.5} m3, banks {:.5} m3, fraction x pushed {:.5} m3: relative error {error:.2e}",
        pushed, bank, want
    );
    assert!(pushed > 0.02, "the trench pushed {pushed} m3");
    // Half floats keep 11 bits: the stated tolerance is 1 % of the volume.
    assert!(error < 0.01, "banks {bank} m3 against {want} m3");

    // The GPU's field against the CPU reference on the same inputs.
    let reference = cpu::bank_field(
        fields.width,
        fields.height,
        &fields.depression,
        &fields.displaced,
        texel,
        desc.snow_depth,
        banks,
    );
    let peak = reference.iter().copied().fold(0.0f32, f32::max);
    let worst = reference
        .iter()
        .zip(&fields.bank)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    eprintln!("bank peak {peak:.4} m, worst |GPU - CPU| {worst:.2e} m");
    assert!(peak > 0.01, "banks of {peak} m");
    assert!(worst < 2e-3 * peak.max(0.01), "worst {worst} m of {peak} m");
    // Banks stand beside the trench: higher 25 cm off its middle than in it.
    let at = |x: f32, z: f32| {
        let c = ((x + 2.0) / texel.x) as usize;
        let row = ((z + 1.5) / texel.y) as usize;
        fields.bank[row * fields.width as usize + c]
    };
    assert!(
        at(0.0, 0.08) > 5.0 * at(0.0, -0.2),
        "{} {}",
        at(0.0, 0.08),
        at(0.0, -0.2)
    );
}

#[test]
fn bad_geometry_is_refused_with_a_sentence() {
    let (world, roof) = trench_world();
    let mut r = renderer(&world);
    let bad = SurfaceGeometry {
        banks: BankSettings {
            fraction: 1.5,
            width: 0.2,
        },
        ..Default::default()
    };
    let e = r.set_surface_geometry(&world, roof, bad).unwrap_err();
    assert!(matches!(e, RenderError::InvalidFrame { .. }));
    assert!(e.to_string().contains("banks.fraction"), "{e}");
    let outside = SurfaceGeometry {
        mesh: Some(SurfaceMesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(5.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0),
            ],
            triangles: vec![[0, 1, 2]],
        }),
        ..Default::default()
    };
    let e = r.set_surface_geometry(&world, roof, outside).unwrap_err();
    assert!(
        e.to_string().contains("within the surface's rectangle"),
        "{e}"
    );
    let mut config = RenderConfig::new(64, 64, Tier::Tessellated);
    config.dice.max_level = 0;
    let e = Renderer::new(common::gpu(), config).unwrap_err();
    assert!(e.to_string().contains("dice"), "{e}");
}

/// A surface that nothing of the frame shows (behind the camera, far from the moon's near
/// cascade around what it looks at) gets no heightfield, bank or dicing work: its fields are
/// still the fresh renderer's zeros, and it is diced into no triangle; turned towards it, the
/// same renderer computes its fields as a renderer that always saw it.
#[test]
fn a_surface_nothing_shows_is_not_shaded() {
    let (world, roof) = trench_world();
    let mut r = renderer(&world);
    let away = render(
        &mut r,
        &world,
        roof,
        Vec3::new(0.0, 3.0, 40.0),
        Vec3::new(0.0, 3.0, 80.0),
    );
    assert_eq!(away.surfaces[0].triangles, 0);
    let fields = r.read_surface_fields(roof).expect("fields");
    assert!(
        fields
            .depression
            .iter()
            .chain(&fields.bank)
            .all(|&v| v == 0.0),
        "the unseen roof's fields were computed"
    );
    let eye = Vec3::new(0.5, 5.0, 5.0);
    render(&mut r, &world, roof, eye, TRENCH);
    let turned = r.read_surface_fields(roof).expect("fields");
    let mut always = renderer(&world);
    render(&mut always, &world, roof, eye, TRENCH);
    let seen = always.read_surface_fields(roof).expect("fields");
    assert!(
        turned.depression.iter().any(|&d| d > 0.5),
        "no trench in the fields"
    );
    assert_eq!(turned, seen);
}
