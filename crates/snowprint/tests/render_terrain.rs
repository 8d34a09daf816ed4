//! Image tests of snow on ground that is not flat: a 30-degree plane and a patch of sine hills,
//! each with a short trail of prints pressed across it (one sphere a frame, each 0.12 m deep from
//! the local snow top), rendered at 256x144 in the relief, POM and tessellated tiers and compared
//! with NVIDIA FLIP against the goldens in `tests/golden/` (`terrain_relief.png`,
//! `terrain_pom.png`, `terrain_tessellated.png`; bounds in `tolerances.toml`). The same scene with
//! its ground switched off (the surfaces left flat, the same spheres pressed) fails all three, so
//! the check sees the ground; untouched snow on the ground is drawn by the deformable material
//! (the basic one draws a flat top). `scenes/pitched_roof.toml`'s trenches in the relief and
//! tessellated tiers against `roof_{relief,tessellated}.png`, failed by the roof drawn flat. The
//! tessellated tier's vertex stage against the ground field plus the heightfield on the CPU.
//!
//! `SNOWPRINT_TERRAIN_STILLS=DIR` also writes every render, and 960x540 stills of both scenes, to
//! `DIR` (the stills of `docs/RENDERING.md`, "Snow on its ground").
//!
//! `SNOWPRINT_BLESS=1 cargo test --release --test render_terrain` writes new goldens (refused when
//! `CI` is set).

mod common;
mod golden_support;

use glam::{Mat4, Quat, Vec3};
use golden_support::{check, score, tolerance};
use snowprint::render::{
    Environment, Instance, MeshMaterial, OpaquePath, RenderConfig, RenderFrame, RenderOutput,
    Renderer, Tier,
};
use snowprint::{
    Camera, Deformer, Ground, GroundMaterial, HeightGrid, Mesh, Pose, Shape, SlopeRule, SnowWorld,
    SurfaceDesc, SurfaceId, WorldConfig,
};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;
const DEPTH: f32 = 0.25;
const RADIUS: f32 = 0.12;
/// How deep each print is pressed below the local snow top, metres.
const PRESS: f32 = 0.12;

/// The 30-degree plane under the first surface (local metres, rising along x).
fn plane(x: f32, _z: f32) -> f32 {
    x * 30f32.to_radians().tan()
}

/// The sine hills under the second (at most 32 degrees: all the snow stays on).
fn hills(x: f32, z: f32) -> f32 {
    0.1 * (std::f32::consts::TAU * x / 1.0).sin() * (std::f32::consts::TAU * z / 1.6).cos()
}

struct Patch {
    desc: SurfaceDesc,
    ground: fn(f32, f32) -> f32,
    /// The trail's prints, local (x, z).
    prints: Vec<[f32; 2]>,
}

fn patches() -> [Patch; 2] {
    [
        Patch {
            desc: SurfaceDesc::new("slope", [-1.35, 0.0, 0.0], [2.4, 1.6], DEPTH),
            ground: plane,
            // Up the slope, left and right.
            prints: (0..5)
                .map(|i| {
                    [
                        -0.9 + 0.45 * i as f32,
                        if i % 2 == 0 { 0.15 } else { -0.15 },
                    ]
                })
                .collect(),
        },
        Patch {
            desc: SurfaceDesc::new("hills", [1.35, 0.0, 0.0], [2.0, 2.0], DEPTH),
            ground: hills,
            // Across the hills, diagonally.
            prints: (0..5)
                .map(|i| [-0.7 + 0.35 * i as f32, -0.5 + 0.25 * i as f32])
                .collect(),
        },
    ]
}

/// A grid with one sample per texel centre of `desc` of the heights `f(x, z)`, local metres.
fn grid_of(desc: &SurfaceDesc, f: fn(f32, f32) -> f32) -> HeightGrid {
    let l = desc.layout();
    let (w, h) = (l.width, l.height);
    let heights = (0..h)
        .flat_map(|r| (0..w).map(move |c| (c, r)))
        .map(|(c, r)| {
            let x = (c as f32 + 0.5) / w as f32 * desc.size.x - 0.5 * desc.size.x;
            let z = (r as f32 + 0.5) / h as f32 * desc.size.y - 0.5 * desc.size.y;
            f(x, z)
        })
        .collect();
    HeightGrid {
        columns: w,
        rows: h,
        heights,
    }
}

struct Scene {
    world: SnowWorld,
    renderer: Renderer,
    surfaces: Vec<SurfaceId>,
    instances: Vec<Instance>,
}

/// The two patches on their ground (or, `on_ground` false, on flat ground), with their trails
/// pressed (`pressed`) or untouched.
fn scene(on_ground: bool, pressed: bool) -> Scene {
    scene_with(on_ground, pressed, SlopeRule::default())
}

/// [`scene`] with the ground's slopes holding snow by `slope`.
fn scene_with(on_ground: bool, pressed: bool, slope: SlopeRule) -> Scene {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let mut surfaces = Vec::new();
    for p in patches() {
        let id = world.add_surface(p.desc.clone()).expect("surface");
        if on_ground {
            let grid = Ground::Grid(grid_of(&p.desc, p.ground));
            world.set_ground(id, &grid, slope).expect("ground");
        }
        surfaces.push(id);
    }
    if pressed {
        for p in patches() {
            for [x, z] in &p.prints {
                // The sphere's bottom PRESS below the local snow top (ground + depth).
                let y = (p.ground)(*x, *z) + DEPTH - PRESS + RADIUS;
                let c = p.desc.center + Vec3::new(*x, y, *z);
                let d = Deformer::new(Shape::Sphere { radius: RADIUS }, Pose::at(c.into()));
                world.step(1.0 / 30.0, &[d]).expect("step");
            }
        }
    }
    let mut config = RenderConfig::new(WIDTH, HEIGHT, Tier::Relief);
    config.shadow_map_size = 1024;
    let mut renderer = Renderer::new(gpu, config).expect("renderer");
    let block = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .expect("mesh");
    // A dark yard far under the patches, so that what shows under their edges is not sky.
    let instances = vec![
        Instance::new(
            block,
            Mat4::from_scale_rotation_translation(
                Vec3::new(8.0, 0.2, 5.0),
                Quat::IDENTITY,
                Vec3::new(0.0, -1.0, 0.0),
            ),
            [0.2, 0.19, 0.18],
        )
        .with_material(MeshMaterial::Concrete),
    ];
    Scene {
        world,
        renderer,
        surfaces,
        instances,
    }
}

fn render(scene: &mut Scene, tier: Tier) -> RenderOutput {
    render_on(scene, tier, GroundMaterial::Concrete)
}

/// [`render`] with the surfaces' ground drawn as `ground`.
fn render_on(scene: &mut Scene, tier: Tier, ground: GroundMaterial) -> RenderOutput {
    scene.renderer.set_tier(tier);
    let surfaces: Vec<_> = scene.surfaces.iter().map(|&id| (id, ground)).collect();
    let frame = RenderFrame {
        camera: Camera {
            eye: Vec3::new(0.0, 2.3, 3.0),
            target: Vec3::new(0.0, 0.1, 0.0),
            fov_y_degrees: 50.0,
        },
        time: 1.0,
        surfaces: &surfaces,
        instances: &scene.instances,
        lights: &[],
        environment: Environment::moonlit_night(),
        snowfall: false,
    };
    scene.renderer.render(&scene.world, &frame).expect("render")
}

const TIERS: [(Tier, &str); 3] = [
    (Tier::Relief, "terrain_relief"),
    (Tier::Pom, "terrain_pom"),
    (Tier::Tessellated, "terrain_tessellated"),
];

/// Where `SNOWPRINT_TERRAIN_STILLS` names a folder, write the render there too (to look at).
fn keep(name: &str, out: &RenderOutput) {
    if let Some(dir) = std::env::var_os("SNOWPRINT_TERRAIN_STILLS") {
        golden_support::save_png(&std::path::Path::new(&dir).join(format!("{name}.png")), out);
    }
}

/// A renderer of the scene's size drawing through the visibility buffer (the deformable snow
/// traced in its fragments and shaded in compute), with the scene's one mesh.
fn visibility_renderer() -> Renderer {
    let mut config = RenderConfig::new(WIDTH, HEIGHT, Tier::Relief);
    config.shadow_map_size = 1024;
    config.opaque = OpaquePath::Visibility;
    let mut renderer = Renderer::new(common::gpu(), config).expect("renderer");
    renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .expect("mesh");
    renderer
}

/// The terrain's goldens drawn through the visibility buffer (the ground's slope and the hills
/// under the snow read by the shading in compute, in every tier) pass as the forward path does.
#[test]
fn the_terrain_goldens_hold_through_the_visibility_buffer() {
    if golden_support::bless() {
        return;
    }
    let mut scene = scene(true, true);
    scene.renderer = visibility_renderer();
    for (tier, name) in TIERS {
        check(name, &render(&mut scene, tier));
    }
}

/// A camera standing inside a surface's box (on ground that rises metres across a valley the box
/// is metres tall) sees the snow: the box's back faces are drawn, the rays starting at the eye.
/// Through the visibility buffer it sees the same, within 2 of 255 but for one pixel in a hundred.
#[test]
fn a_camera_inside_the_box_sees_the_snow() {
    let mut scene = scene(true, true);
    scene.renderer.set_tier(Tier::Relief);
    let slope = patches()[0].desc.clone();
    // 0.3 m above the local snow top, half way up the plane: inside its box, which runs from the
    // lowest base to the highest top plus the ankle room.
    let x = 0.3;
    let top = plane(x, 0.0) + DEPTH;
    let eye = slope.center + Vec3::new(x, top + 0.3, 0.0);
    assert!(
        top + 0.3 < plane(1.2, 0.0) + DEPTH,
        "the eye must be inside the box"
    );
    let frame = |renderer: &mut Renderer, surfaces: &[(SurfaceId, GroundMaterial)]| {
        let frame = RenderFrame {
            camera: Camera {
                eye,
                target: slope.center + Vec3::new(-0.9, plane(-0.9, 0.0), 0.0),
                fov_y_degrees: 60.0,
            },
            time: 1.0,
            surfaces,
            instances: &scene.instances,
            lights: &[],
            environment: Environment::moonlit_night(),
            snowfall: false,
        };
        renderer.render(&scene.world, &frame).expect("render").rgba8
    };
    let snow = [(scene.surfaces[0], GroundMaterial::Concrete)];
    let with = frame(&mut scene.renderer, &snow);
    let without = frame(&mut scene.renderer, &[]);
    let differ = with
        .chunks_exact(4)
        .zip(without.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count();
    let share = differ as f32 / (with.len() / 4) as f32;
    assert!(
        share > 0.5,
        "only {share} of the pixels show the snow the eye stands in"
    );
    let visible = frame(&mut visibility_renderer(), &snow);
    let apart = with
        .chunks_exact(4)
        .zip(visible.chunks_exact(4))
        .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 2))
        .count();
    assert!(
        apart * 100 <= with.len() / 4,
        "{apart} pixels differ through the visibility buffer"
    );
}

/// Mean luminance (0 to 255) over the slope patch's part of the image, and the share of its pixels
/// that differ from their right neighbour by more than 40 (speckle).
fn slope_patch(out: &RenderOutput) -> (f32, f32) {
    let (w, h) = (out.width as usize, out.height as usize);
    let lum = |x: usize, y: usize| {
        let p = &out.rgba8[4 * (y * w + x)..4 * (y * w + x) + 3];
        0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32
    };
    let (mut sum, mut jumps, mut n) = (0.0, 0, 0);
    for y in h * 35 / 100..h * 75 / 100 {
        for x in w * 12 / 100..w * 40 / 100 {
            sum += lum(x, y);
            jumps += usize::from((lum(x, y) - lum(x + 1, y)).abs() > 40.0);
            n += 1;
        }
    }
    (sum / n as f32, jumps as f32 / n as f32)
}

/// Where a slope is too steep to hold snow its ground shows: the 30-degree plane under a rule
/// that bares it (none held from 20 degrees) draws darker than under one that keeps all its snow,
/// and without the speckle a division by the little snow held would make, as concrete and as
/// rock (whose relief image is a golden).
#[test]
fn a_bare_slope_shows_its_rock() {
    let bare = SlopeRule {
        full_degrees: 10.0,
        bare_degrees: 20.0,
    };
    for tier in [Tier::Relief, Tier::Pom] {
        let (snowy, _) = slope_patch(&render(
            &mut scene_with(true, false, SlopeRule::NEVER_BARE),
            tier,
        ));
        for ground in [GroundMaterial::Concrete, GroundMaterial::Rock] {
            let out = render_on(&mut scene_with(true, false, bare), tier, ground);
            keep(&format!("bare_{tier:?}_{ground:?}"), &out);
            if (tier, ground) == (Tier::Relief, GroundMaterial::Rock) {
                // The rock's own look (mottled, cracked, no joints), held by a golden.
                check("terrain_bare_rock", &out);
            }
            let (rock, speckle) = slope_patch(&out);
            eprintln!("{tier:?} {ground:?}: snow {snowy:.1}, bare {rock:.1}, speckle {speckle:.4}");
            assert!(
                rock < 0.7 * snowy,
                "{tier:?} {ground:?}: the bare slope reads {rock}, its snow {snowy}"
            );
            assert!(
                speckle < 0.02,
                "{tier:?} {ground:?}: {speckle} of the bare slope's pixels jump"
            );
        }
    }
}

/// The trails on the slope and the hills, in every tier. With `SNOWPRINT_TERRAIN_STILLS` set,
/// 960x540 stills of every tier are written there too.
#[test]
fn prints_on_a_slope_and_on_hills_match_their_goldens() {
    let mut scene = scene(true, true);
    for (tier, name) in TIERS {
        let out = render(&mut scene, tier);
        keep(name, &out);
        assert!(out.basic_material_surfaces.is_empty(), "{name}");
        check(name, &out);
    }
    if std::env::var_os("SNOWPRINT_TERRAIN_STILLS").is_some() {
        scene.renderer.resize(960, 540, 1).expect("resize");
        for (tier, name) in TIERS {
            keep(&format!("{name}_960"), &render(&mut scene, tier));
        }
    }
}

/// The same spheres pressed into the same surfaces left flat score past both bounds of every
/// golden: the goldens see the ground.
#[test]
fn the_scene_drawn_flat_fails_the_terrain_goldens() {
    if golden_support::bless() {
        return;
    }
    let mut scene = scene(false, true);
    for (tier, name) in TIERS {
        let out = render(&mut scene, tier);
        keep(&format!("{name}_flat"), &out);
        let (_, mean, p99) = score(name, &out);
        eprintln!("{name}, drawn flat: FLIP mean {mean:.4}, p99 {p99:.4}");
        let tol = tolerance(name);
        assert!(
            mean > tol.mean && p99 > tol.p99,
            "{name}: the flat scene scores mean {mean:.4} / p99 {p99:.4}, within the bounds {} / {}",
            tol.mean,
            tol.p99
        );
    }
}

/// Untouched snow on ground that is not flat: nothing pressed it, yet it is drawn by the deformable
/// material (the basic one draws a flat top) and shows its ground's shape: it fails the goldens of
/// the pressed trails less than the flat scene does, yet it is no flat slab (the flat untouched
/// scene draws both surfaces with the basic material).
#[test]
fn untouched_snow_on_the_ground_is_drawn_on_its_ground() {
    if golden_support::bless() {
        return;
    }
    let mut on_ground = scene(true, false);
    let mut flat = scene(false, false);
    for (tier, name) in TIERS {
        let a = render(&mut on_ground, tier);
        let b = render(&mut flat, tier);
        keep(&format!("{name}_untouched"), &a);
        assert!(a.basic_material_surfaces.is_empty(), "{name}");
        assert_eq!(b.basic_material_surfaces.len(), 2, "{name}");
        let (_, mean_ground, _) = score(name, &a);
        let (_, mean_flat, _) = score(name, &b);
        eprintln!("{name}, untouched: on its ground {mean_ground:.4}, flat {mean_flat:.4}");
        assert!(
            mean_ground < mean_flat,
            "{name}: untouched on its ground {mean_ground:.4}, flat {mean_flat:.4}"
        );
    }
}

/// `scenes/pitched_roof.toml` (two 30-degree planes of a glTF roof, a ball dragged up one side
/// and over the ridge, another across a side) after its 4 s, on its roof or (`on_ground` false)
/// on flat ground, with the house under it: walls, the roof's faces and its gables.
fn roof_scene(on_ground: bool) -> Scene {
    let gpu = common::gpu();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/pitched_roof.toml");
    let file = snowprint::scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut world = SnowWorld::new(gpu, WorldConfig::default()).expect("world");
    let id = world.add_surface(file.surfaces[0].clone()).expect("roof");
    let ground = file.grounds[0].as_ref().expect("the roof mesh");
    if on_ground {
        world
            .set_ground(id, &ground.ground, ground.slope)
            .expect("ground");
    }
    let dt = 1.0 / 30.0;
    let mut prev: Vec<Option<Pose>> = vec![None; file.deformers.len()];
    for f in 1..=120 {
        let t = f as f32 * dt;
        let ds: Vec<Deformer> = file
            .deformers
            .iter()
            .zip(&mut prev)
            .map(|(d, p)| {
                let snowprint::scene::SceneShape::Sphere { radius } = d.shape else {
                    panic!("the roof's deformers are spheres")
                };
                let pose = d.pose_at(t);
                match p.replace(pose) {
                    Some(before) => Deformer::moving(Shape::Sphere { radius }, before, pose),
                    None => Deformer::new(Shape::Sphere { radius }, pose),
                }
            })
            .collect();
        world.step(dt, &ds).expect("step");
    }
    let mut config = RenderConfig::new(WIDTH, HEIGHT, Tier::Relief);
    config.shadow_map_size = 1024;
    let mut renderer = Renderer::new(gpu, config).expect("renderer");
    let Ground::Mesh(roof) = &ground.ground else {
        panic!("the roof is a mesh")
    };
    // The roof's faces, and the gables closing it at x = -4 and 4 (both windings).
    let mut positions: Vec<Vec3> = roof.triangles.iter().flatten().copied().collect();
    for x in [-4.0, 4.0] {
        let (a, b, c) = (
            Vec3::new(x, 10.0, -3.0),
            Vec3::new(x, 10.0 + 3.0 * 30f32.to_radians().tan(), 0.0),
            Vec3::new(x, 10.0, 3.0),
        );
        positions.extend([a, b, c, a, c, b]);
    }
    let indices = (0..positions.len() as u32).collect();
    let roof = renderer
        .add_mesh(&Mesh { positions, indices })
        .expect("roof mesh");
    let block = renderer
        .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
        .expect("block");
    let instances = vec![
        Instance::new(roof, Mat4::IDENTITY, [0.35, 0.16, 0.1]).with_material(MeshMaterial::Brick),
        Instance::new(
            block,
            Mat4::from_scale_rotation_translation(
                Vec3::new(8.0, 3.0, 6.0),
                Quat::IDENTITY,
                Vec3::new(0.0, 8.5, 0.0),
            ),
            [0.3, 0.28, 0.26],
        )
        .with_material(MeshMaterial::Brick),
    ];
    Scene {
        world,
        renderer,
        surfaces: vec![id],
        instances,
    }
}

fn render_roof(scene: &mut Scene, tier: Tier) -> RenderOutput {
    scene.renderer.set_tier(tier);
    let surfaces = [(scene.surfaces[0], GroundMaterial::RoofTiles)];
    let frame = RenderFrame {
        camera: Camera {
            eye: Vec3::new(-8.5, 14.5, -8.0),
            target: Vec3::new(-0.8, 10.6, -0.6),
            fov_y_degrees: 45.0,
        },
        time: 1.0,
        surfaces: &surfaces,
        instances: &scene.instances,
        lights: &[],
        environment: Environment::moonlit_night(),
        snowfall: false,
    };
    scene.renderer.render(&scene.world, &frame).expect("render")
}

const ROOF_TIERS: [(Tier, &str); 2] = [
    (Tier::Relief, "roof_relief"),
    (Tier::Tessellated, "roof_tessellated"),
];

/// The pitched roof's trenches, drawn on the roof in both tiers; the roof drawn flat (its snow a
/// slab at the eaves' height, inside the house) fails both goldens. With
/// `SNOWPRINT_TERRAIN_STILLS` set, 960x540 stills of both tiers are written there too.
#[test]
fn the_pitched_roof_scene_matches_its_goldens_and_fails_them_flat() {
    let mut scene = roof_scene(true);
    for (tier, name) in ROOF_TIERS {
        let out = render_roof(&mut scene, tier);
        keep(name, &out);
        assert!(out.basic_material_surfaces.is_empty(), "{name}");
        check(name, &out);
    }
    if std::env::var_os("SNOWPRINT_TERRAIN_STILLS").is_some() {
        scene.renderer.resize(960, 540, 1).expect("resize");
        for (tier, name) in ROOF_TIERS {
            keep(&format!("{name}_960"), &render_roof(&mut scene, tier));
        }
    }
    if golden_support::bless() {
        return;
    }
    let mut flat = roof_scene(false);
    for (tier, name) in ROOF_TIERS {
        let out = render_roof(&mut flat, tier);
        keep(&format!("{name}_flat"), &out);
        let (_, mean, p99) = score(name, &out);
        eprintln!("{name}, drawn flat: FLIP mean {mean:.4}, p99 {p99:.4}");
        let tol = tolerance(name);
        assert!(
            mean > tol.mean && p99 > tol.p99,
            "{name}: the flat roof scores mean {mean:.4} / p99 {p99:.4}, within the bounds"
        );
    }
}

/// The tessellated tier's vertex stage (`tess_local` of `tess_surface.wgsl`, run in a compute
/// harness over the renderer's own bindings) lifts each vertex of the top to the snow over the
/// ground: the bilinear base of the surface's ground field (`GroundField::columns`, as the world
/// built it) plus the snow depth less the bilinear depression of the heightfield, computed here
/// on the CPU, within 0.1 mm; a skirt's base vertex to the ground's base alone.
#[test]
fn tessellated_vertices_stand_on_the_ground_plus_the_snow() {
    let gpu = common::gpu();
    let dev = &gpu.device;
    let mut world = SnowWorld::new(gpu, WorldConfig::default()).expect("world");
    let p = &patches()[1];
    let id = world.add_surface(p.desc.clone()).expect("surface");
    world
        .set_ground(
            id,
            &Ground::Grid(grid_of(&p.desc, p.ground)),
            SlopeRule::default(),
        )
        .expect("ground");
    let field = world.ground(id).unwrap().unwrap().clone();
    let l = p.desc.layout();
    let (w, h) = (l.width, l.height);
    // A depression of k/8 (exact in half floats) in a pattern over the texels.
    let dep = |c: u32, r: u32| ((c * 3 + r * 5) % 8) as f32 / 8.0;
    let view = world.frame_view();
    let mut uniform = snowprint::SurfaceUniform::for_surface(&view, id).expect("uniform");
    uniform.pattern[3] = 0.0; // no macro waves
    let half_bits = |x: f32| -> u16 {
        if x == 0.0 {
            return 0;
        }
        let b = x.to_bits();
        ((((b >> 23) & 0xff) as u16 - 127 + 15) << 10) | ((b >> 13) & 0x3ff) as u16
    };
    // The renderer's textures hold a border around the heightmap's texels: the edge repeated,
    // with no surface beside this one.
    let b = snowprint::wgsl::consts::HEIGHTFIELD_BORDER;
    let (tw, th) = (w + 2 * b as u32, h + 2 * b as u32);
    let edge = |t: u32, n: u32| (t as i32 - b).clamp(0, n as i32 - 1) as u32;
    let texels: Vec<u16> = (0..th)
        .flat_map(|r| (0..tw).map(move |c| (edge(c, w), edge(r, h))))
        .flat_map(|(c, r)| [half_bits(dep(c, r)), 0, 0, 0])
        .collect();
    let texture = |data: &[u16]| {
        dev.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: tw,
                    height: th,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(data),
        )
        .create_view(&Default::default())
    };
    use wgpu::util::DeviceExt;
    let (shape, bank) = (texture(&texels), texture(&vec![0u16; texels.len()]));
    let buffer = |bytes: &[u8], usage| {
        dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytes,
            usage,
        })
    };
    let mut state = vec![0u32; snowprint::wgsl::consts::STATE_WORDS as usize];
    state[snowprint::wgsl::consts::STATE_TOUCHED as usize] = 1;
    // Points over the surface, edges included: tops (kind 0) and skirt bases (kind 2).
    let half = p.desc.size * 0.5;
    let points: Vec<[f32; 4]> = (0..=20)
        .flat_map(|i| (0..=20).map(move |j| (i, j)))
        .map(|(i, j)| {
            let x = -half.x + 2.0 * half.x * i as f32 / 20.0;
            let z = -half.y + 2.0 * half.y * j as f32 / 20.0;
            [x, 0.0, z, if (i + j) % 5 == 0 { 2.0 } else { 0.0 }]
        })
        .collect();
    let u = wgpu::BufferUsages::STORAGE;
    let (uni, ground, state, input) = (
        buffer(bytemuck::bytes_of(&uniform), wgpu::BufferUsages::UNIFORM),
        view.ground_buffer,
        buffer(bytemuck::cast_slice(&state), u),
        buffer(bytemuck::cast_slice(&points), u),
    );
    let output = dev.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (points.len() * 16) as u64,
        usage: u | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let source = format!(
        "{}\n{}",
        snowprint::wgsl::TESS_SURFACE.source,
        r#"
@group(2) @binding(0) var<storage, read> probe_in: array<vec4<f32>>;
@group(2) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;
@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&probe_in) {
        return;
    }
    var v: TessVertex;
    v.position = probe_in[id.x];
    v.outward = vec4<f32>(0.0);
    probe_out[id.x] = vec4<f32>(tess_local(v), 0.0);
}
"#
    );
    let module = dev.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("tess_local harness"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = dev.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("probe"),
        compilation_options: Default::default(),
        cache: None,
    });
    let group = |g: u32, resources: &[wgpu::BindingResource<'_>], bindings: &[u32]| {
        dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(g),
            entries: &resources
                .iter()
                .zip(bindings)
                .map(|(r, &binding)| wgpu::BindGroupEntry {
                    binding,
                    resource: r.clone(),
                })
                .collect::<Vec<_>>(),
        })
    };
    let g0 = group(0, &[], &[]);
    let g1 = group(
        1,
        &[
            uni.as_entire_binding(),
            wgpu::BindingResource::TextureView(&shape),
            wgpu::BindingResource::TextureView(&bank),
            ground.as_entire_binding(),
            state.as_entire_binding(),
        ],
        &[0, 1, 3, 4, 5],
    );
    let g2 = group(
        2,
        &[input.as_entire_binding(), output.as_entire_binding()],
        &[0, 1],
    );
    let readback = dev.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: output.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = dev.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        for (i, g) in [&g0, &g1, &g2].into_iter().enumerate() {
            pass.set_bind_group(i as u32, g, &[]);
        }
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &readback, 0, output.size());
    gpu.queue.submit([enc.finish()]);
    readback.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait_idle().expect("gpu");
    let got: Vec<[f32; 4]> =
        bytemuck::cast_slice(&readback.slice(..).get_mapped_range().expect("mapped")).to_vec();

    // Bilinear between texel centres, clamped at the edges.
    let bilinear = |f: &dyn Fn(u32, u32) -> f32, x: f32, z: f32| {
        let (fx, fz) = (
            (x + half.x) / (2.0 * half.x) * w as f32 - 0.5,
            (z + half.y) / (2.0 * half.y) * h as f32 - 0.5,
        );
        let (ix, iz) = (fx.floor(), fz.floor());
        let (tx, tz) = (fx - ix, fz - iz);
        let at = |c: f32, r: f32| {
            f(
                (c as i32).clamp(0, w as i32 - 1) as u32,
                (r as i32).clamp(0, h as i32 - 1) as u32,
            )
        };
        let a = at(ix, iz) * (1.0 - tx) + at(ix + 1.0, iz) * tx;
        let b = at(ix, iz + 1.0) * (1.0 - tx) + at(ix + 1.0, iz + 1.0) * tx;
        a * (1.0 - tz) + b * tz
    };
    let base = |c: u32, r: u32| field.columns[(r * w + c) as usize][0];
    let mut worst = 0.0f32;
    for (p, g) in points.iter().zip(&got) {
        let ground = bilinear(&base, p[0], p[2]);
        let want = if p[3] < 1.5 {
            ground + DEPTH * (1.0 - bilinear(&dep, p[0], p[2]))
        } else {
            ground
        };
        assert!(g[0] == p[0] && g[2] == p[2], "{p:?} moved to {g:?}");
        worst = worst.max((g[1] - want).abs());
    }
    eprintln!(
        "tess_local against the CPU: worst {worst:.2e} m over {} points",
        points.len()
    );
    assert!(worst < 1e-4, "worst |GPU - CPU| height {worst} m");
}
