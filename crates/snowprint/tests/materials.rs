//! Materials that move like themselves: a sand print slumps toward its angle of repose on the GPU
//! exactly as the CPU reference says, keeping the volume pressed out to the unit, and ends with no
//! step between neighbours steeper than the repose, its rim slumped into a wider pit; the talk's snow does not move; scene files
//! name materials and refuse unknown ones with one sentence.

mod common;

use std::path::Path;

use snowprint::reference::relax;
use snowprint::{
    Deformer, Material, PoolFormat, Pose, Precision, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    WorldConfig,
};

const DT: f32 = 1.0 / 60.0;
const DEPTH: f32 = 0.2;

fn world(precision: Precision) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            format: PoolFormat::new(precision),
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .unwrap()
}

/// A 1 m square yard of `material` (25 x 25 texels of 4 cm), 0.2 m deep.
fn yard(w: &mut SnowWorld, material: Material) -> SurfaceId {
    let mut desc = SurfaceDesc::new("yard", [0.0, 0.0, 0.0], [1.0, 1.0], DEPTH);
    desc.material = material;
    w.add_surface(desc).unwrap()
}

/// A ball pressed 0.15 m deep off the yard's centre: steep walls.
fn press() -> Deformer {
    Deformer::new(
        Shape::Sphere { radius: 0.2 },
        Pose::at([0.1, DEPTH - 0.15 + 0.2, -0.05]),
    )
}

fn sum(v: &[u32]) -> u64 {
    v.iter().map(|&x| x as u64).sum()
}

/// The relaxation's thresholds for the yard at `precision`.
fn thresholds(material: &Material, precision: Precision) -> [u32; 2] {
    let t = relax::threshold(
        material.repose_degrees.unwrap(),
        0.04,
        DEPTH,
        precision.channel_max(),
    );
    [t, t]
}

#[test]
fn sand_slumps_as_the_cpu_reference_says_keeping_its_volume() {
    let sand = Material::sand();
    for precision in Precision::ALL {
        // Snow keeps the print as pressed: what sand starts from before it slumps.
        let mut snow = world(precision);
        let mut sandy = world(precision);
        let (s, d) = (yard(&mut snow, Material::snow()), yard(&mut sandy, sand));
        snow.step(DT, &[press()]).unwrap();
        sandy.step(DT, &[press()]).unwrap();
        let (pressed, displaced) = snow.read_channels(s).unwrap();
        let max = precision.channel_max();
        let t = thresholds(&sand, precision);
        let mut expect = pressed.clone();
        // Three updates: the one that pressed, and two that only settle.
        for update in 0..3 {
            if update > 0 {
                sandy.step(DT, &[]).unwrap();
            }
            for _ in 0..sand.steps() {
                expect = relax::step(&expect, 25, 25, max, t);
            }
            let (got, got_displaced) = sandy.read_channels(d).unwrap();
            assert_eq!(
                got, expect,
                "{precision:?}, update {update}: GPU against CPU"
            );
            assert_eq!(
                got_displaced, displaced,
                "the displaced channel is left as it is"
            );
            assert_eq!(
                sum(&got),
                sum(&pressed),
                "{precision:?}: the volume pressed out is kept"
            );
        }
        assert_ne!(expect, pressed, "{precision:?}: the print slumped");
        // The snow did not move while the sand settled.
        snow.step(DT, &[]).unwrap();
        assert_eq!(snow.read_channels(s).unwrap().0, pressed);
    }
}

/// Left to settle, the sand print ends with no step between neighbours steeper than 34 degrees
/// (measured in metres between texel centres 4 cm apart), on the GPU, and the pit is wider.
#[test]
fn settled_sand_stands_at_its_angle_of_repose() {
    let sand = Material::sand();
    let mut w = world(Precision::Bits16);
    let id = yard(&mut w, sand);
    w.step(DT, &[press()]).unwrap();
    let first = w.read_channels(id).unwrap().0;
    for _ in 0..sand.settle_updates {
        w.step(DT, &[]).unwrap();
    }
    let settled = w.read_channels(id).unwrap().0;
    assert_eq!(sum(&settled), sum(&first));
    let metres = |units: u32| units as f64 / 65_535.0 * DEPTH as f64;
    let steepest = steepest_step(&settled, 25, 25);
    let tan = metres(steepest) / 0.04;
    let repose = 34f64.to_radians().tan();
    assert!(
        tan <= repose,
        "steepest slope {tan:.3} against tan 34 = {repose:.3}"
    );
    // As pressed (in snow, which does not slump), the print's walls were far steeper.
    let mut snow = world(Precision::Bits16);
    let s = yard(&mut snow, Material::snow());
    snow.step(DT, &[press()]).unwrap();
    let pressed = metres(steepest_step(&snow.read_channels(s).unwrap().0, 25, 25)) / 0.04;
    assert!(
        pressed > 1.5 * repose,
        "the print was pressed steep: {pressed:.3}"
    );
    // The rim slumped in: the same volume is spread over a wider pit.
    let pressed_texels = |d: &[u32]| d.iter().filter(|&&v| v > 0).count();
    assert!(
        pressed_texels(&settled) > pressed_texels(&first),
        "{} texels pressed after settling, {} before",
        pressed_texels(&settled),
        pressed_texels(&first)
    );
    // Settled: one more update that relaxes changes nothing.
    w.step(DT, &[press()]).unwrap();
    let after_press = w.read_channels(id).unwrap().0;
    let mut again = after_press.clone();
    for _ in 0..sand.steps() * 200 {
        again = relax::step(&again, 25, 25, 65_535, thresholds(&sand, Precision::Bits16));
    }
    let fixed = relax::step(&again, 25, 25, 65_535, thresholds(&sand, Precision::Bits16));
    assert_eq!(fixed, again, "the CPU rule reaches a fixed point");
}

/// The dispatches of several steps in workgroup memory against the CPU's one step over the whole
/// surface: two surfaces of several tiles (75 x 45 and 43 x 65 texels) pressed in four places,
/// one at an odd column and one against an edge, relaxing 2 steps an update (one dispatch and a
/// copy), 6 (two of three) and 10 (five of two and a copy), for five updates, at 8, 16 and 32 bits.
#[test]
fn many_steps_a_dispatch_match_the_cpu_over_several_tiles() {
    let balls = [
        ([-0.9, -0.2], 0.25),
        ([0.62, 0.3], 0.2),
        ([1.35, -0.7], 0.15),
        ([-0.1, 0.55], 0.3),
    ];
    let press = |center: [f32; 3]| -> Vec<Deformer> {
        balls
            .iter()
            .map(|&([x, z], r)| {
                Deformer::new(
                    Shape::Sphere { radius: r },
                    Pose::at([center[0] + x, DEPTH - 0.6 * r + r, center[2] + z]),
                )
            })
            .collect()
    };
    let sides = [
        ([0.0, 0.0, 0.0], [3.0, 1.8]),
        ([6.0, 0.0, 0.0], [1.72, 2.6]),
    ];
    for steps in [2, 6, 10] {
        let material = Material {
            relax_steps: steps,
            ..Material::sand()
        };
        for precision in Precision::ALL {
            let (mut snow, mut sandy) = (world(precision), world(precision));
            let mut ids = Vec::new();
            let mut deformers = Vec::new();
            for (center, size) in sides {
                let add = |w: &mut SnowWorld, m: Material| {
                    let mut desc = SurfaceDesc::new("dune", center, size, DEPTH);
                    desc.material = m;
                    w.add_surface(desc).unwrap()
                };
                ids.push((add(&mut snow, Material::snow()), add(&mut sandy, material)));
                deformers.extend(press(center));
            }
            snow.step(DT, &deformers).unwrap();
            sandy.step(DT, &deformers).unwrap();
            let max = precision.channel_max();
            for &(s, d) in &ids {
                let pressed = snow.read_channels(s).unwrap().0;
                let layout = sandy.layout(d).unwrap();
                let (w, h) = (layout.width, layout.height);
                let t = relax::threshold(34.0, 0.04, DEPTH, max);
                let mut expect = pressed.clone();
                for _ in 0..steps {
                    expect = relax::step(&expect, w, h, max, [t, t]);
                }
                let got = sandy.read_channels(d).unwrap().0;
                assert_eq!(got, expect, "{steps} steps, {precision:?}, {w} x {h}");
                assert_ne!(
                    got, pressed,
                    "{steps} steps, {precision:?}: the prints slumped"
                );
                assert_eq!(sum(&got), sum(&pressed));
            }
            // Four updates that only settle, both surfaces at once.
            let mut expects: Vec<Vec<u32>> = ids
                .iter()
                .map(|&(_, d)| sandy.read_channels(d).unwrap().0)
                .collect();
            for update in 1..5 {
                sandy.step(DT, &[]).unwrap();
                for (&(_, d), expect) in ids.iter().zip(&mut expects) {
                    let layout = sandy.layout(d).unwrap();
                    let (w, h) = (layout.width, layout.height);
                    let t = relax::threshold(34.0, 0.04, DEPTH, max);
                    for _ in 0..steps {
                        *expect = relax::step(expect, w, h, max, [t, t]);
                    }
                    let got = sandy.read_channels(d).unwrap().0;
                    assert_eq!(
                        &got, expect,
                        "{steps} steps, {precision:?}, update {update}"
                    );
                }
            }
        }
    }
}

/// A pit slumping across a tile's edge while the tiles around settle and are skipped: a deep pit
/// 5 texels from the edge of the first tile (tiles start at the rectangle's first column, here the
/// surface's, since a ball also presses its left edge) spreads into the flat tile beside it; the
/// GPU matches the CPU's whole-surface steps after every one of 40 updates.
#[test]
fn slumping_crosses_into_a_still_tile_as_on_the_cpu() {
    let sand = Material::sand();
    let mut snow = world(Precision::Bits16);
    let mut sandy = world(Precision::Bits16);
    let add = |w: &mut SnowWorld, m: Material| {
        let mut desc = SurfaceDesc::new("strip", [0.0, 0.0, 0.0], [3.0, 1.0], DEPTH);
        desc.material = m;
        w.add_surface(desc).unwrap()
    };
    let (s, d) = (add(&mut snow, Material::snow()), add(&mut sandy, sand));
    // Texel x covers [-1.5 + 0.04 x, ...): the pit's centre at texel 22, its rim near 27; the
    // tile boundary at 32.
    let balls = [
        Deformer::new(
            Shape::Sphere { radius: 0.25 },
            Pose::at([-0.4, DEPTH - 0.19 + 0.25, 0.0]),
        ),
        Deformer::new(
            Shape::Sphere { radius: 0.1 },
            Pose::at([-1.5, DEPTH - 0.05 + 0.1, 0.3]),
        ),
    ];
    snow.step(DT, &balls).unwrap();
    sandy.step(DT, &balls).unwrap();
    let layout = sandy.layout(d).unwrap();
    let (w, h) = (layout.width, layout.height);
    let t = relax::threshold(34.0, 0.04, DEPTH, 65_535);
    let mut expect = snow.read_channels(s).unwrap().0;
    for update in 0..40 {
        if update > 0 {
            sandy.step(DT, &[]).unwrap();
        }
        for _ in 0..sand.steps() {
            expect = relax::step(&expect, w, h, 65_535, [t, t]);
        }
        assert_eq!(sandy.read_channels(d).unwrap().0, expect, "update {update}");
    }
    let reach = (0..w as usize)
        .filter(|&x| (0..h as usize).any(|y| expect[y * w as usize + x] > 0))
        .max()
        .unwrap_or(0);
    eprintln!("the slump reaches column {reach}");
    assert!(
        reach > 33,
        "the slump reached past the tile's edge: column {reach}"
    );
}

fn steepest_step(d: &[u32], w: usize, h: usize) -> u32 {
    let mut m = 0;
    for y in 0..h {
        for x in 0..w {
            if x + 1 < w {
                m = m.max(d[y * w + x].abs_diff(d[y * w + x + 1]));
            }
            if y + 1 < h {
                m = m.max(d[y * w + x].abs_diff(d[(y + 1) * w + x]));
            }
        }
    }
    m
}

#[test]
fn scene_files_name_materials_and_refuse_unknown_ones() {
    let scene = |material: &str| {
        format!(
            "version = 1\n[[surface]]\nname = \"beach\"\ncenter = [0.0, 0.0, 0.0]\nsize = [4.0, 4.0]\nsnow_depth = 0.2\nmaterial = \"{material}\"\n"
        )
    };
    let ok = snowprint::scene::Scene::parse(&scene("sand"), Path::new("beach.toml")).unwrap();
    assert_eq!(ok.surfaces[0].material, Material::sand());
    let err = snowprint::scene::Scene::parse(&scene("gravel"), Path::new("beach.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("beach.toml:7:"), "{err}");
    assert!(
        err.contains("\"gravel\"") && err.contains("\"sand\""),
        "{err}"
    );
}

#[test]
fn scene_files_define_their_own_materials() {
    let scene = |tables: &str, material: &str| {
        format!(
            "version = 1\n{tables}[[surface]]\nname = \"dune\"\ncenter = [0.0, 0.0, 0.0]\nsize = [4.0, 4.0]\nsnow_depth = 0.2\nmaterial = \"{material}\"\n"
        )
    };
    let parse = |text: String| snowprint::scene::Scene::parse(&text, Path::new("dune.toml"));
    // A preset with keys changed.
    let wet = "[[material]]\nname = \"wet_sand\"\nlike = \"sand\"\nrepose_degrees = 45.0\nrelax_steps = 2\n";
    let s = parse(scene(wet, "wet_sand")).unwrap();
    let expect = Material {
        repose_degrees: Some(45.0),
        relax_steps: 2,
        ..Material::sand()
    };
    assert_eq!(s.surfaces[0].material, expect);
    // From snow, a repose angle alone makes it slump with sand's steps.
    let crumbly = "[[material]]\nname = \"crust\"\nrepose_degrees = 70.0\n";
    let s = parse(scene(crumbly, "crust")).unwrap();
    assert!(s.surfaces[0].material.slumps());
    assert_eq!(s.surfaces[0].material.repose_degrees, Some(70.0));
    // One sentence each, with the file and line, for what is wrong.
    let err = |text: String| parse(text).unwrap_err().to_string();
    let e = err(scene("[[material]]\nname = \"sand\"\n", "sand"));
    assert!(e.starts_with("dune.toml:3:") && e.contains("preset"), "{e}");
    let e = err(scene(
        "[[material]]\nname = \"x\"\nrepose_degrees = 120.0\n",
        "x",
    ));
    assert!(
        e.starts_with("dune.toml:4:") && e.contains("0 to 90"),
        "{e}"
    );
    let e = err(scene("[[material]]\nname = \"x\"\nrepose = 30.0\n", "x"));
    assert!(e.contains("repose_degrees"), "did you mean: {e}");
    let e = err(scene(wet, "dry_sand"));
    assert!(e.contains("wet_sand") && e.contains("\"sand\""), "{e}");
    assert!(!e.contains('\n'), "one line: {e}");
    // Compressibility and the look's keys.
    let custom = "[[material]]\nname = \"beach\"\nlike = \"sand\"\ncompressibility = 0.6\nalbedo = [0.3, 0.2, 0.1]\nwetness = 0.5\nground_from = 0.8\nwater_depth = 0.05\n";
    let m = parse(scene(custom, "beach")).unwrap().surfaces[0].material;
    assert_eq!(m.compressibility, Some(0.6));
    assert_eq!(m.rim_fraction(), Some(1.0 - 0.6));
    assert_eq!(m.look.albedo, [0.3, 0.2, 0.1]);
    assert_eq!(
        (m.look.wetness, m.look.ground_from, m.look.water_depth),
        (0.5, Some(0.8), Some(0.05))
    );
    assert_eq!(
        m.look.grain,
        Material::sand().look.grain,
        "the rest from sand"
    );
    for (bad, line, says) in [
        ("compressibility = 1.5", "dune.toml:4:", "from 0 to 1"),
        ("albedo = [0.3, 0.2]", "dune.toml:4:", "three numbers"),
        ("albedo = [0.3, 2.0, 0.1]", "dune.toml:4:", "from 0 to 1"),
        ("ground_from = 1.0", "dune.toml:4:", "below 1"),
        ("water_depth = -0.1", "dune.toml:4:", "above 0"),
    ] {
        let e = err(scene(&format!("[[material]]\nname = \"x\"\n{bad}\n"), "x"));
        assert!(e.starts_with(line) && e.contains(says), "{bad}: {e}");
    }
}

/// The looks are data: every preset's look is valid, snow's is the talk's constants (what
/// `snow.wgsl` drew before materials, so the old goldens hold bit for bit), and a wrong field is
/// refused by name.
#[test]
fn material_looks_are_valid_data_and_snow_keeps_the_talks_look() {
    for name in ["snow", "packed_snow", "powder", "sand", "mud"] {
        let m = Material::named(name).expect("preset");
        m.validate(name).expect("valid preset");
    }
    let snow = Material::snow().look;
    assert_eq!(snow.albedo, [0.86, 0.89, 0.93]);
    assert_eq!(snow.disturbed_albedo, [0.66, 0.71, 0.78]);
    assert_eq!((snow.roughness, snow.wet_roughness), (0.62, 0.5));
    assert_eq!((snow.grain, snow.sparkle, snow.wetness), (0.0, 0.0, 0.0));
    assert_eq!((snow.translucency, snow.water_depth), (1.0, None));
    assert!(Material::mud().look.water_depth.is_some());
    let mut bad = Material::sand();
    bad.look.sparkle = 1.5;
    let e = bad.validate("beach").expect_err("sparkle 1.5");
    assert!(e.to_string().contains("sparkle"), "{e}");
    let mut bad = Material::mud();
    bad.look.water_depth = Some(-0.1);
    let e = bad.validate("track").expect_err("negative water depth");
    assert!(e.to_string().contains("water_depth"), "{e}");
}
