//! Heightmap storage at 8, 16 and 32 bits a channel: the talk's memory figure in a real pool, and
//! the error each precision makes against 32 bits over many frames of moving deformers and
//! refilling snow, bounded by what its quantization allows.

mod common;

use glam::Vec3;
use snowprint::{
    Deformer, PoolFormat, Pose, Precision, Shape, SnowError, SnowWorld, SurfaceDesc, WorldConfig,
};

fn world(format: PoolFormat, pool_bytes: u64) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes,
            format,
            ..Default::default()
        },
    )
    .expect("world")
}

/// Four 512^2 surfaces, both channels each, fill the talk's 2 MiB pool exactly at 8 bits; a fifth
/// is refused; all four update and keep what pressed them.
#[test]
fn four_512_surfaces_fit_the_talks_2_mib_pool_at_8_bits() {
    let mut w = world(PoolFormat::new(Precision::Bits8), 2 << 20);
    let side = 512.0 * 0.04;
    let x = |i: usize| i as f32 * (side + 1.0);
    let ids: Vec<_> = (0..4)
        .map(|i| {
            w.add_surface(SurfaceDesc::new(
                "roof",
                [x(i), 0.0, 0.0],
                [side, side],
                0.3,
            ))
            .expect("fits")
        })
        .collect();
    assert_eq!(w.layout(ids[0]).unwrap().width, 512);
    assert_eq!(w.memory().pool_used, 2 << 20);
    let fifth = w.add_surface(SurfaceDesc::new(
        "roof",
        [x(4), 0.0, 0.0],
        [side, side],
        0.3,
    ));
    assert!(matches!(fifth, Err(SnowError::PoolExhausted { .. })));
    let spheres: Vec<Deformer> = (0..4)
        .map(|i| Deformer::new(Shape::Sphere { radius: 0.3 }, Pose::at([x(i), 0.0, 0.0])))
        .collect();
    let stats = w.step(0.0, &spheres).unwrap();
    assert_eq!(stats.updated, 4);
    for id in ids {
        let map = w.read_heightmap(id).unwrap();
        // The sphere's lowest point is at the ground: the centre texels are pressed through.
        let centre = map.depression[(256 * 512 + 256) as usize];
        assert_eq!(centre, 65535, "8-bit 255 reads back as a whole snow depth");
        assert!(map.pressed_volume() > 50.0);
    }
}

/// Moving spheres over a surface whose snow refills at 5% of its depth a second.
fn scenario(precision: Precision, frames: u32) -> (Vec<f64>, Vec<f64>) {
    let mut w = world(PoolFormat::new(precision), 1 << 20);
    let mut desc = SurfaceDesc::new("s", [0.0; 3], [4.0, 3.0], 0.3);
    desc.replenish_rate = 0.05;
    let id = w.add_surface(desc).unwrap();
    for f in 0..frames {
        let t = f as f32 / 60.0;
        let deformers: Vec<Deformer> = (0..6)
            .map(|k| {
                let k = k as f32;
                let at = |t: f32| {
                    Vec3::new(
                        -1.6 + 0.5 * k + 0.9 * t,
                        0.05 + 0.04 * k,
                        -1.0 + 0.35 * k + 0.3 * (3.0 * t + k).sin(),
                    )
                };
                Deformer::moving(
                    Shape::Sphere {
                        radius: 0.12 + 0.02 * k,
                    },
                    Pose::at(at(t - 1.0 / 60.0).into()),
                    Pose::at(at(t).into()),
                )
            })
            .collect();
        w.step(1.0 / 60.0, &deformers).unwrap();
    }
    let (d, p) = w.read_channels(id).unwrap();
    let max = precision.channel_max() as f64;
    (
        d.iter().map(|&v| v as f64 / max).collect(),
        p.iter().map(|&v| v as f64 / max).collect(),
    )
}

/// Against 32 bits, a depression is off by at most 1.5 units of its precision: half a unit from
/// rounding the capture, one from whole-unit refills (the fraction is carried, so refills never
/// drift further), plus the f32 blur's last places. Displaced snow sums what each frame pushed, so
/// its error may grow by a unit a frame; it is measured and bounded by that.
#[test]
fn each_precision_errs_within_its_quantization() {
    let frames = 40;
    let reference = scenario(Precision::Bits32, frames);
    assert!(
        reference.0.iter().any(|&v| v > 0.5),
        "the spheres pressed deep prints"
    );
    for precision in [Precision::Bits8, Precision::Bits16] {
        let got = scenario(precision, frames);
        let unit = 1.0 / precision.channel_max() as f64;
        let worst = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let mean = |a: &[f64], b: &[f64]| {
            a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64
        };
        let (dep, disp) = (worst(&got.0, &reference.0), worst(&got.1, &reference.1));
        eprintln!(
            "{precision}: depression max {dep:.2e} (mean {:.2e}), displaced max {disp:.2e} (mean {:.2e}), unit {unit:.2e}",
            mean(&got.0, &reference.0),
            mean(&got.1, &reference.1)
        );
        assert!(
            dep <= 1.5 * unit + 1e-5,
            "{precision}: depression off by {dep} (> 1.5 units of {unit})"
        );
        assert!(
            disp <= frames as f64 * 1.5 * unit + 1e-5,
            "{precision}: displaced snow off by {disp}"
        );
    }
}
