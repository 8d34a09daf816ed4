//! Image tests of the renderer: a fixed small scene (a concrete roof with prints, a trench and a
//! body-sized dent, a tiled roof with a crater to the tiles, and an untouched roof on the basic
//! material) rendered at 256x144 for each tier and compared with NVIDIA FLIP against the goldens in
//! `tests/golden/`. The largest FLIP error each test allows is data, in `tests/golden/tolerances.toml`.
//!
//! On failure the FLIP error map and the image rendered are written to `target/golden-diff/`.
//! `SNOWPRINT_BLESS=1 cargo test --release --test render_golden` writes new goldens instead (refused
//! when `CI` is set). Each test has a tight bound for the goldens' own driver (lavapipe, as in CI) and
//! a looser one for any other; `broken_renders_fail_the_golden_check` shows which broken looks each
//! can see.

mod common;
mod golden_scene;
mod golden_support;

use golden_scene::{grazing_camera, render, render_golden_view, render_view, scene};
use golden_support::{bless, check, same_driver, score, tolerance};
use snowprint::render::{SnowLook, Tier};

#[test]
fn both_tiers_match_their_goldens() {
    let mut scene = scene();
    for (tier, name) in [(Tier::Relief, "relief"), (Tier::Pom, "pom")] {
        let out = render(&mut scene, tier);
        // The untouched roof is drawn with the basic material, the others with the deformable one.
        assert_eq!(out.basic_material_surfaces, vec![scene.fresh], "{name}");
        assert_eq!(out.surfaces.len(), 3);
        check(name, &out);
    }
}

#[test]
fn the_tessellated_tier_matches_its_goldens() {
    let mut scene = scene();
    let out = render(&mut scene, Tier::Tessellated);
    assert_eq!(out.basic_material_surfaces, vec![scene.fresh]);
    assert_eq!(out.dice_overflow, 0);
    // Every surface in view was diced, the untouched one too.
    assert!(
        out.surfaces.iter().all(|s| s.triangles > 0),
        "{:?}",
        out.surfaces
    );
    check("tessellated", &out);

    // Close and grazing, across the trench: the banks beside it, a standing person behind it whose
    // shadow comes across the trench and bends into it.
    // (Without the body that slid, so the trench is empty.)
    let mut instances = scene.instances[..2].to_vec();
    instances.extend(scene.person.iter().copied());
    let camera = grazing_camera();
    let out = render_view(&mut scene, Tier::Tessellated, camera, &instances);
    check("tessellated_grazing", &out);
    let relief = render_view(&mut scene, Tier::Relief, camera, &instances);
    check("relief_grazing", &relief);
}

/// The golden check sees what it claims to: renders with one term of the material switched off
/// (the sky tint of prints' walls, RNM, the heightmap's ambient occlusion) fail the bound in force.
/// RNM against the linear blend it replaces shows only where walls are seen at grazing angles, and
/// less than drivers differ (lavapipe: relief_grazing mean 0.0011, p99 0.032; an H100 scores more
/// against the lavapipe goldens with everything on), so only the same-driver bound can see it: that
/// limit is data here (`cross_driver`), not a skipped test. Scores print with `--nocapture`.
#[test]
fn broken_renders_fail_the_golden_check() {
    if bless() {
        return;
    }
    let mut scene = scene();
    let intact = scene.renderer.config().look;
    let sky = SnowLook {
        sky_tint: false,
        ..intact
    };
    let rnm = SnowLook {
        rnm: false,
        ..intact
    };
    let ao = SnowLook {
        occlusion: 0.0,
        ..intact
    };
    // (switch, look, golden, whether the cross-driver bound sees it too)
    let cases = [
        ("sky tint off", sky, "relief", true),
        ("sky tint off", sky, "pom", true),
        ("sky tint off", sky, "relief_grazing", true),
        ("AO off", ao, "relief", true),
        ("AO off", ao, "pom", true),
        ("AO off", ao, "relief_grazing", true),
        ("RNM off", rnm, "relief_grazing", false),
        ("RNM off", rnm, "tessellated_grazing", false),
    ];
    let same = same_driver();
    let mut checked = 0;
    for (what, look, name, cross_driver) in cases {
        scene.renderer.set_look(look).expect("look");
        let out = render_golden_view(&mut scene, name);
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        eprintln!(
            "{what}, {name}: FLIP mean {mean:.5} (max {}), p99 {p99:.5} (max {})",
            tol.mean, tol.p99
        );
        if !same && !cross_driver {
            eprintln!(
                "{what}, {name}: below what the cross-driver bound can see (known, see above)"
            );
            continue;
        }
        assert!(
            mean > tol.mean || p99 > tol.p99,
            "{what} passes the {name} golden check (mean {mean:.5} <= {}, p99 {p99:.5} <= {}): the check cannot see it",
            tol.mean,
            tol.p99
        );
        checked += 1;
    }
    // The intact render still passes: the failures above are the switches', not the scene's.
    scene.renderer.set_look(intact).expect("look");
    for name in ["relief", "relief_grazing"] {
        let out = render_golden_view(&mut scene, name);
        let (_, mean, p99) = score(name, &out);
        let tol = tolerance(name);
        assert!(
            mean <= tol.mean && p99 <= tol.p99,
            "intact {name}: {mean} {p99}"
        );
    }
    assert_eq!(checked, if same { 8 } else { 6 });
}
