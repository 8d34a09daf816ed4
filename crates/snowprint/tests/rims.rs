//! Compressibility: of the volume a print presses out, `1 - compressibility` rises in rims beside
//! it (the banks, from the displaced channel). A ball pressed into sand, powder and snow: the
//! volume pressed out against the spherical cap computed by hand, the rims' volume against the
//! material's share of it on the GPU, and the rims' field against the CPU reference of the banks;
//! the relief tier draws the rims too, around the print and nowhere else.

mod common;

use glam::{Vec2, Vec3};
use snowprint::reference::tessellate as cpu;
use snowprint::render::{BankSettings, Environment, RenderConfig, RenderFrame, Renderer, Tier};
use snowprint::{
    Camera, Deformer, GroundMaterial, Material, Pose, Shape, SnowWorld, SurfaceDesc, WorldConfig,
};

const DEPTH: f32 = 0.2;
/// The ball's radius and how deep it presses below the untouched top.
const RADIUS: f32 = 0.2;
const PRESSED: f32 = 0.12;

/// Volume of the cap of a ball of radius `r` cut `h` deep: pi h^2 (3r - h) / 3.
fn cap_volume(r: f64, h: f64) -> f64 {
    std::f64::consts::PI * h * h * (3.0 * r - h) / 3.0
}

struct Rims {
    /// Volume pressed out, m^3, from the pool's displaced channel.
    pushed: f64,
    /// Volume of the rims, m^3, from the GPU's bank field.
    rims: f64,
    /// Largest difference between the GPU's bank field and the CPU reference's, and its peak (m).
    worst: f32,
    peak: f32,
    /// Bank heights (m) on the rim beside the print and in its middle.
    beside: f32,
    middle: f32,
}

const WIDTH: u32 = 128;
const HEIGHT: u32 = 72;

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.5, 2.5, 2.5),
        target: Vec3::ZERO,
        fov_y_degrees: 50.0,
    }
}

/// A 2 m square yard of `material` with the ball pressed into its middle once, and a renderer of
/// `tier`.
fn yard(material: Material, tier: Tier) -> (SnowWorld, snowprint::SurfaceId, Renderer) {
    let mut world = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let mut desc = SurfaceDesc::new("yard", [0.0, 0.0, 0.0], [2.0, 2.0], DEPTH);
    desc.material = material;
    let yard = world.add_surface(desc).expect("yard");
    let ball = Deformer::new(
        Shape::Sphere { radius: RADIUS },
        Pose::at([0.0, DEPTH - PRESSED + RADIUS, 0.0]),
    );
    world.step(1.0 / 60.0, &[ball]).expect("press");
    let mut config = RenderConfig::new(WIDTH, HEIGHT, tier);
    config.shadow_map_size = 256;
    let renderer = Renderer::new(common::gpu(), config).expect("renderer");
    (world, yard, renderer)
}

fn render(world: &SnowWorld, yard: snowprint::SurfaceId, renderer: &mut Renderer) -> Vec<u8> {
    let surfaces = [(yard, GroundMaterial::Concrete)];
    renderer
        .render(
            world,
            &RenderFrame {
                camera: camera(),
                time: 0.0,
                surfaces: &surfaces,
                instances: &[],
                lights: &[],
                environment: Environment::moonlit_night(),
                snowfall: false,
            },
        )
        .expect("render")
        .rgba8
}

/// The ball pressed into `material`, drawn in the tessellated tier with the renderer's default
/// banks, measured.
fn pressed(material: Material) -> Rims {
    let (world, yard, mut renderer) = yard(material, Tier::Tessellated);
    render(&world, yard, &mut renderer);
    let fields = renderer.read_surface_fields(yard).expect("fields");
    let heightmap = world.read_heightmap(yard).expect("heightmap");
    let texel = Vec2::new(2.0 / fields.width as f32, 2.0 / fields.height as f32);
    let area = (texel.x * texel.y) as f64;
    let pushed = heightmap
        .displaced
        .iter()
        .map(|&d| d as f64 / 65535.0)
        .sum::<f64>()
        * DEPTH as f64
        * area;
    let rims = fields.bank.iter().map(|&b| b as f64).sum::<f64>() * area;
    let banks = BankSettings {
        fraction: material
            .rim_fraction()
            .unwrap_or(BankSettings::default().fraction),
        ..Default::default()
    };
    let reference = cpu::bank_field(
        fields.width,
        fields.height,
        &fields.depression,
        &fields.displaced,
        texel,
        DEPTH,
        banks,
    );
    let peak = reference.iter().copied().fold(0.0f32, f32::max);
    let worst = reference
        .iter()
        .zip(&fields.bank)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    // The print's rim is sqrt(h (2r - h)) = 18 cm from its middle; the bank peaks just outside.
    let at = |x: f32| {
        let c = ((x + 1.0) / texel.x) as usize;
        let row = fields.height as usize / 2;
        fields.bank[row * fields.width as usize + c]
    };
    Rims {
        pushed,
        rims,
        worst,
        peak,
        beside: at(0.24),
        middle: at(0.0),
    }
}

#[test]
fn rims_hold_what_the_material_does_not_compact() {
    let cap = cap_volume(RADIUS as f64, PRESSED as f64);
    let cases = [
        ("sand", Material::sand(), 0.8),
        ("powder", Material::powder(), 0.5),
        // Snow states no compressibility: the renderer's default banks, a quarter.
        ("snow", Material::snow(), 0.25),
    ];
    for (name, material, share) in cases {
        let r = pressed(material);
        let want = share * r.pushed;
        let error = (r.rims - want).abs() / want;
        eprintln!(
            "{name}: cap {cap:.5} m3 by hand, pushed {:.5} m3, rims {:.5} m3 = {:.3} of it \
             (want {share}), bank peak {:.4} m, worst |GPU - CPU| {:.2e} m",
            r.pushed,
            r.rims,
            r.rims / r.pushed,
            r.peak,
            r.worst
        );
        // The pressed volume is the ball's cap: the capture's blur keeps it, the 4 cm texels and
        // 16-bit units round it by a little.
        assert!(
            (r.pushed - cap).abs() < 0.03 * cap,
            "{name}: pushed {} m3 against the cap's {cap} m3",
            r.pushed
        );
        // Half floats keep 11 bits: 1 % of the volume, as for the banks of the talk's snow.
        assert!(error < 0.01, "{name}: rims {} m3 against {want} m3", r.rims);
        assert!(
            r.worst < 2e-3 * r.peak.max(0.01),
            "{name}: GPU against CPU, worst {} m of {} m",
            r.worst,
            r.peak
        );
        assert!(
            r.beside > 3.0 * r.middle,
            "{name}: the rim stands beside the print ({} m), not in it ({} m)",
            r.beside,
            r.middle
        );
    }
}

/// The pixel where a point of the yard's top lands on screen.
fn pixel(p: Vec3) -> (u32, u32) {
    let c = camera();
    let clip = c.projection(WIDTH as f32 / HEIGHT as f32, 0.05, 100.0) * c.view() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    (
        ((ndc.x * 0.5 + 0.5) * WIDTH as f32) as u32,
        ((0.5 - ndc.y * 0.5) * HEIGHT as f32) as u32,
    )
}

/// The relief tier draws sand's rims: the same yard without them (sand stating no
/// compressibility, so the relief tier has no banks) differs on pixels of the ring around the
/// print and on none of the yard farther than the banks reach (the print's 18 cm, the banks' 30
/// cm and the blur).
#[test]
fn the_relief_tier_raises_the_rims_beside_the_print() {
    let plain = Material {
        compressibility: None,
        ..Material::sand()
    };
    let mut shots = Vec::new();
    for material in [Material::sand(), plain] {
        let (world, yard, mut renderer) = yard(material, Tier::Relief);
        shots.push(render(&world, yard, &mut renderer));
    }
    // How far a pixel moved, the largest of its channels' differences.
    let moved = |(x, y): (u32, u32)| {
        let i = ((y * WIDTH + x) * 4) as usize;
        (0..3)
            .map(|c| shots[0][i + c].abs_diff(shots[1][i + c]))
            .max()
            .unwrap_or(0)
    };
    let (mut ring, mut far) = (Vec::new(), Vec::new());
    let mut seen = std::collections::HashSet::new();
    for k in 0..720 {
        let a = k as f32 * std::f32::consts::TAU / 720.0;
        for (r, near) in [(0.22, true), (0.3, true), (0.8, false), (0.9, false)] {
            let p = pixel(Vec3::new(r * a.cos(), DEPTH, r * a.sin()));
            if seen.insert((p, near)) {
                if near {
                    ring.push(moved(p))
                } else {
                    far.push(moved(p))
                }
            }
        }
    }
    let changed = |v: &[u8], by: u8| v.iter().filter(|&&d| d > by).count();
    let far_most = far.iter().copied().max().unwrap_or(0);
    eprintln!(
        "rims change {} of {} ring pixels by more than 8 levels; beyond: {} of {} changed, by {far_most} levels at most",
        changed(&ring, 8),
        ring.len(),
        changed(&far, 0),
        far.len()
    );
    assert!(
        ring.len() > 50 && changed(&ring, 8) * 2 > ring.len(),
        "{} of {} ring pixels changed",
        changed(&ring, 8),
        ring.len()
    );
    // Beyond the banks only the search's taps move (the slab is taller by the room for rims, so
    // the flat top is found a rounding away): a few pixels by a level or two.
    assert!(
        far_most <= 3 && changed(&far, 0) * 20 <= far.len(),
        "pixels beyond the banks' reach changed: {} of {}, by up to {far_most}",
        changed(&far, 0),
        far.len()
    );
}
