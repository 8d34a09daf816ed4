//! The bench's configurations: what each row measures.

use snowprint::{CapturePath, PassMode, Precision};

/// One row's world and deformers.
pub(super) struct Config {
    pub(super) sweep: &'static str,
    pub(super) surfaces: u32,
    pub(super) resolution: u32,
    pub(super) deformers: u32,
    pub(super) passes: PassMode,
    pub(super) precision: Precision,
    pub(super) snowing: bool,
    pub(super) pressed: bool,
    pub(super) capture: CapturePath,
}

/// The configurations to measure: the talk's frame (fused and as separate passes, at each
/// precision), then the sweeps (`quick`: small ones only) and, unless quick, the 1024
/// surfaces of 512^2.
pub(super) fn configs(quick: bool) -> Vec<Config> {
    let cfg = |sweep, surfaces, resolution, deformers, passes| Config {
        sweep,
        surfaces,
        resolution,
        deformers,
        passes,
        precision: Precision::Bits16,
        snowing: false,
        pressed: false,
        capture: CapturePath::Auto,
    };
    let at = |precision, c: Config| Config { precision, ..c };
    let snowing = |c: Config| Config { snowing: true, ..c };
    // The talk's frame, fused and as separate passes, at each precision; the sweeps use the
    // device's default passes and 16 bits.
    let (auto, fused, separate) = (PassMode::Auto, PassMode::Fused, PassMode::Separate);
    let mut configs = vec![
        cfg("talk_budget", 2, 512, 10, fused),
        snowing(cfg("talk_budget", 2, 512, 10, fused)),
        snowing(cfg("talk_budget", 2, 512, 10, separate)),
        snowing(at(Precision::Bits8, cfg("talk_budget", 2, 512, 10, fused))),
        snowing(at(Precision::Bits32, cfg("talk_budget", 2, 512, 10, fused))),
        // The snowing frame with the spheres in the capture's compute path, for comparison.
        Config {
            capture: CapturePath::Compute,
            ..snowing(cfg("talk_budget", 2, 512, 10, fused))
        },
    ];
    let (counts, resolutions, deformers): (&[u32], &[u32], &[u32]) = if quick {
        (&[1, 4, 16], &[64, 128, 256], &[1, 10, 100])
    } else {
        (
            &[1, 4, 16, 64, 256, 1024, 4096],
            &[64, 128, 256, 512, 1024],
            &[1, 10, 100, 1000],
        )
    };
    // The sweeps keep snow falling so that every texel is read, as the copy baseline reads it.
    configs.extend(
        counts
            .iter()
            .map(|&n| snowing(cfg("surfaces", n, 128, 10, auto))),
    );
    // The largest and a middle count again with the spheres rendered in viewports: the capture's
    // compute path against the raster path in the same run.
    let raster = |c: Config| Config {
        capture: CapturePath::Raster,
        ..c
    };
    let compared: &[u32] = if quick { &[16] } else { &[256, 4096] };
    configs.extend(
        compared
            .iter()
            .map(|&n| raster(snowing(cfg("raster_surf", n, 128, 10, auto)))),
    );
    // Again with the spheres ray-cast into the capture by its compute path (`Auto` on a GPU
    // leaves them to the update, which ray-casts them itself): the capture pass, its memory and
    // its clear against none of them, in the same run.
    let computed = |c: Config| Config {
        capture: CapturePath::Compute,
        ..c
    };
    let computed_counts: &[u32] = if quick { &[16] } else { &[256, 1024, 4096] };
    configs.extend(
        computed_counts
            .iter()
            .map(|&n| computed(snowing(cfg("compute_surf", n, 128, 10, auto)))),
    );
    configs.extend(
        resolutions
            .iter()
            .map(|&r| snowing(cfg("resolution", 16, r, 10, auto))),
    );
    configs.extend(
        deformers
            .iter()
            .map(|&d| snowing(cfg("deformers", 2, 512, d, auto))),
    );
    if !quick {
        // The 1024 surfaces of 512^2: 1 GiB of heights at 16 bits, 512 MiB at 8.
        configs.push(cfg("many_512", 1024, 512, 1, fused));
        configs.push(snowing(cfg("many_512", 1024, 512, 1, fused)));
        configs.push(snowing(cfg("many_512", 1024, 512, 1, separate)));
        configs.push(snowing(at(
            Precision::Bits8,
            cfg("many_512", 1024, 512, 1, fused),
        )));
        configs.push(computed(snowing(cfg("many_512", 1024, 512, 1, fused))));
        // The same with every texel pressed: every word changes and is written every frame.
        let pressed = |c: Config| Config { pressed: true, ..c };
        configs.push(pressed(snowing(cfg("many_512", 1024, 512, 1, fused))));
        configs.push(pressed(snowing(at(
            Precision::Bits8,
            cfg("many_512", 1024, 512, 1, fused),
        ))));
    }
    configs
}
