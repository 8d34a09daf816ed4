//! Compressibility: of the volume a print presses out, `1 - compressibility` rises in rims beside
//! it (the banks of the tessellated tier, from the displaced channel). A ball pressed into sand,
//! powder and snow: the volume pressed out against the spherical cap computed by hand, the rims'
//! volume against the material's share of it on the GPU, and the rims' field against the CPU
//! reference of the banks.

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

/// A 2 m square yard of `material` with the ball pressed into its middle once, drawn in the
/// tessellated tier with the renderer's default banks.
fn pressed(material: Material) -> Rims {
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
    let mut config = RenderConfig::new(128, 72, Tier::Tessellated);
    config.shadow_map_size = 256;
    let mut renderer = Renderer::new(common::gpu(), config).expect("renderer");
    let surfaces = [(yard, GroundMaterial::Concrete)];
    renderer
        .render(
            &world,
            &RenderFrame {
                camera: Camera {
                    eye: Vec3::new(0.5, 2.5, 2.5),
                    target: Vec3::ZERO,
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
        .expect("render");
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
