//! Image tests of the materials' looks (`MaterialLook`) in the relief tier: one small scene per
//! material, a surface with a shallow print (4 cm) and a deep one (11 cm) under the moon and a
//! lantern, compared with NVIDIA FLIP against goldens in `tests/golden/` (`material_*.png`), with
//! tolerances as data in `tests/golden/tolerances.toml`. The goldens are blessed as those of
//! `render_golden.rs` (`SNOWPRINT_BLESS=1`). Also: mud's water fills the deep print and not the
//! shallow one, and a render with a term of a material's look switched off (sand's grain, mud's
//! water, powder's sparkle) fails its golden's bound.

mod common;
mod golden_support;

use glam::{Vec3, Vec4};
use golden_support::{bless, check, score, tolerance};
use snowprint::render::{
    DebugView, Environment, OpaquePath, PointLight, RenderConfig, RenderFrame, RenderOutput,
    Renderer, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Material, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    WorldConfig,
};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;
/// Depth of the material over the ground, metres.
const DEPTH: f32 = 0.15;
/// Depths of the two prints, metres: either side of mud's water depth (6 cm).
const SHALLOW: f32 = 0.04;
const DEEP: f32 = 0.11;
/// Centres (x, z) of the two prints and the half extents of the soles that press them.
const SHALLOW_AT: [f32; 2] = [-0.35, 0.0];
const DEEP_AT: [f32; 2] = [0.35, 0.0];
const SOLE: Vec3 = Vec3::new(0.16, 0.04, 0.08);
/// Height of mud's water surface over the ground (its water depth is 6 cm).
const WATER_LEVEL: f32 = DEPTH - 0.06;

struct Scene {
    world: SnowWorld,
    renderer: Renderer,
    surfaces: Vec<(SurfaceId, GroundMaterial)>,
}

/// A 2 m x 1.4 m surface of `material` with the two prints pressed over 8 steps, then 40 steps of
/// settling (sand and powder slump back into the prints), drawn in the relief tier.
fn scene(material: Material) -> Scene {
    scene_in(material, Tier::Relief)
}

/// The same, drawn in `tier`.
fn scene_in(material: Material, tier: Tier) -> Scene {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 2 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let mut desc = SurfaceDesc::new("ground", [0.0, 0.0, 0.0], [2.0, 1.4], DEPTH);
    desc.material = material;
    let id = world.add_surface(desc).expect("surface");
    let soles: Vec<Deformer> = [(SHALLOW_AT, SHALLOW), (DEEP_AT, DEEP)]
        .into_iter()
        .map(|([x, z], depth)| {
            Deformer::new(
                Shape::Box { half_extents: SOLE },
                Pose::at([x, DEPTH - depth + SOLE.y, z]),
            )
        })
        .collect();
    for _ in 0..8 {
        world.step(1.0 / 30.0, &soles).expect("step");
    }
    for _ in 0..40 {
        world.step(1.0 / 30.0, &[]).expect("settle");
    }
    let mut config = RenderConfig::new(WIDTH, HEIGHT, tier);
    config.shadow_map_size = 1024;
    let renderer = Renderer::new(gpu, config).expect("renderer");
    Scene {
        world,
        renderer,
        surfaces: vec![(id, GroundMaterial::Concrete)],
    }
}

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 1.1, 1.25),
        target: Vec3::new(0.0, 0.1, 0.0),
        fov_y_degrees: 50.0,
    }
}

fn render(scene: &mut Scene) -> RenderOutput {
    let lights = [PointLight {
        position: Vec3::new(-0.9, 0.9, 0.7),
        color: Vec3::new(1.0, 0.85, 0.7) * 1.2,
        radius: 4.0,
    }];
    let frame = RenderFrame {
        camera: camera(),
        time: 1.0,
        surfaces: &scene.surfaces,
        instances: &[],
        lights: &lights,
        environment: Environment::moonlit_night(),
        snowfall: false,
    };
    scene.renderer.render(&scene.world, &frame).expect("render")
}

/// The materials with a golden: (golden, material).
fn materials() -> [(&'static str, Material); 3] {
    [
        ("material_sand", Material::sand()),
        ("material_mud", Material::mud()),
        ("material_powder", Material::powder()),
    ]
}

#[test]
fn each_material_matches_its_golden() {
    for (name, material) in materials() {
        let mut scene = scene(material);
        let out = render(&mut scene);
        check(name, &out);
    }
}

/// The materials drawn through the visibility buffer (the deformable material traced in its
/// fragments, or diced, and shaded in compute: sand's and mud's rims, mud's water in both tiers,
/// powder) pass their goldens as the forward path does.
#[test]
fn each_material_through_the_visibility_buffer_matches_its_golden() {
    if bless() {
        return;
    }
    let visible = |tier| {
        let mut config = RenderConfig::new(WIDTH, HEIGHT, tier);
        config.shadow_map_size = 1024;
        config.opaque = OpaquePath::Visibility;
        Renderer::new(common::gpu(), config).expect("renderer")
    };
    for (name, material) in materials() {
        let mut scene = scene(material);
        scene.renderer = visible(Tier::Relief);
        check(name, &render(&mut scene));
    }
    let mut mud = scene_in(Material::mud(), Tier::Tessellated);
    mud.renderer = visible(Tier::Tessellated);
    check("material_mud_tessellated", &render(&mut mud));
}

/// Screen rectangle (pixels, min and max corners) of a print's sole scaled by `scale`, at height
/// `y` (its floor, or the water's surface).
fn print_pixels(at: [f32; 2], y: f32, scale: f32) -> ([f32; 2], [f32; 2]) {
    let c = camera();
    let view_proj = c.projection(WIDTH as f32 / HEIGHT as f32, 0.05, 100.0) * c.view();
    let (mut lo, mut hi) = ([f32::MAX; 2], [f32::MIN; 2]);
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = Vec4::new(
            at[0] + sx * SOLE.x * scale,
            y,
            at[1] + sz * SOLE.z * scale,
            1.0,
        );
        let clip = view_proj * p;
        let ndc = clip.truncate() / clip.w;
        let px = [
            (ndc.x * 0.5 + 0.5) * WIDTH as f32,
            (0.5 - ndc.y * 0.5) * HEIGHT as f32,
        ];
        for k in 0..2 {
            lo[k] = lo[k].min(px[k]);
            hi[k] = hi[k].max(px[k]);
        }
    }
    (lo, hi)
}

/// Pixels of `a` and `b` that differ inside a screen rectangle, and how many pixels it holds.
fn changed_in(
    a: &RenderOutput,
    b: &RenderOutput,
    (lo, hi): ([f32; 2], [f32; 2]),
) -> (usize, usize) {
    let (mut changed, mut total) = (0, 0);
    for y in lo[1].ceil() as u32..=(hi[1].floor() as u32).min(HEIGHT - 1) {
        for x in lo[0].ceil() as u32..=(hi[0].floor() as u32).min(WIDTH - 1) {
            let i = ((y * WIDTH + x) * 4) as usize;
            total += 1;
            if a.rgba8[i..i + 3] != b.rgba8[i..i + 3] {
                changed += 1;
            }
        }
    }
    (changed, total)
}

/// Whether a pixel of the materials debug view is water (cyan: no red, much green and blue).
fn is_water(p: &[u8]) -> bool {
    p[0] < 30 && p[1] > 120 && p[2] > 120
}

/// Water pixels (of the materials debug view) inside a screen rectangle, and how many it holds.
fn water_in(out: &RenderOutput, (lo, hi): ([f32; 2], [f32; 2])) -> (usize, usize) {
    let (mut water, mut total) = (0, 0);
    for y in lo[1].ceil() as u32..=(hi[1].floor() as u32).min(HEIGHT - 1) {
        for x in lo[0].ceil() as u32..=(hi[0].floor() as u32).min(WIDTH - 1) {
            let i = ((y * WIDTH + x) * 4) as usize;
            total += 1;
            water += usize::from(is_water(&out.rgba8[i..i + 3]));
        }
    }
    (water, total)
}

/// Mud's water fills the print deeper than its water depth (11 cm against 6 cm) and not the
/// shallow one (4 cm), in the relief tier (traced) and in the tessellated one (a flat top of the
/// diced mesh). Seen in the materials debug view, where water is cyan: most of the deep print's
/// floor is water, none of the shallow print's, and no pixel outside the deep print's rectangle
/// (grown by its walls) is. In the shaded view, the same mud without water differs from it nowhere
/// in the shallow print.
#[test]
fn mud_water_fills_only_prints_deeper_than_its_threshold() {
    for tier in [Tier::Relief, Tier::Tessellated] {
        mud_water_in(tier);
    }
}

fn mud_water_in(tier: Tier) {
    let mut wet = scene_in(Material::mud(), tier);
    let mut dry_material = Material::mud();
    dry_material.look.water_depth = None;
    let mut dry = scene_in(dry_material, tier);
    let (a, b) = (render(&mut wet), render(&mut dry));
    let shaded = changed_in(&a, &b, print_pixels(SHALLOW_AT, DEPTH - SHALLOW, 0.6));
    assert_eq!(
        shaded.0, 0,
        "{tier:?}: the shallow print's shading changed with water: {shaded:?}"
    );

    wet.renderer.set_debug_view(DebugView::Materials);
    let view = render(&mut wet);
    // The tessellated tier raises banks (a quarter of the pushed volume, mud stating no
    // compressibility) on the print's walls as well as beside it, so its water reaches less far
    // up them: all of the floor's middle, 0.45 of the sole (0.5: 68 of 85 pixels on lavapipe).
    let floor = if tier == Tier::Tessellated { 0.45 } else { 0.6 };
    let deep = water_in(&view, print_pixels(DEEP_AT, WATER_LEVEL, floor));
    let shallow = water_in(&view, print_pixels(SHALLOW_AT, DEPTH - SHALLOW, 1.3));
    let around = water_in(&view, print_pixels(DEEP_AT, WATER_LEVEL, 1.6));
    let everywhere = water_in(
        &view,
        ([0.0, 0.0], [WIDTH as f32 - 1.0, HEIGHT as f32 - 1.0]),
    );
    eprintln!(
        "{tier:?}: water pixels: deep print {deep:?}, shallow print {shallow:?}, around the deep one {around:?}, image {everywhere:?}"
    );
    assert!(
        deep.1 > 40 && shallow.1 > 40,
        "{tier:?}: prints too small on screen: {deep:?} {shallow:?}"
    );
    assert!(
        deep.0 * 10 > deep.1 * 9,
        "{tier:?}: water covers too little of the deep print: {deep:?}"
    );
    assert_eq!(
        shallow.0, 0,
        "{tier:?}: water in the shallow print: {shallow:?}"
    );
    assert_eq!(
        around.0, everywhere.0,
        "{tier:?}: water outside the deep print: {around:?} {everywhere:?}"
    );
}

/// Mud in the tessellated tier against its golden: the deep print's water a flat mirror of the
/// sky in the diced surface.
#[test]
fn tessellated_mud_matches_its_golden() {
    let out = render(&mut scene_in(Material::mud(), Tier::Tessellated));
    check("material_mud_tessellated", &out);
}

/// The golden check sees each material's own term: a render with it switched off (sand without
/// grain, mud without water in both tiers, powder without sparkle) fails the bound in force.
#[test]
fn material_terms_switched_off_fail_their_goldens() {
    if bless() {
        return;
    }
    let mut sand = Material::sand();
    sand.look.grain = 0.0;
    let mut mud = Material::mud();
    mud.look.water_depth = None;
    let mut powder = Material::powder();
    powder.look.sparkle = 0.0;
    for (what, name, material, tier) in [
        ("grain off", "material_sand", sand, Tier::Relief),
        ("water off", "material_mud", mud, Tier::Relief),
        (
            "water off",
            "material_mud_tessellated",
            mud,
            Tier::Tessellated,
        ),
        ("sparkle off", "material_powder", powder, Tier::Relief),
    ] {
        let out = render(&mut scene_in(material, tier));
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        eprintln!(
            "{what}, {name}: FLIP mean {mean:.5} (max {}), p99 {p99:.5} (max {})",
            tol.mean, tol.p99
        );
        assert!(
            mean > tol.mean || p99 > tol.p99,
            "{what} passes the {name} golden check (mean {mean:.5}, p99 {p99:.5}): the check cannot see it"
        );
    }
}
