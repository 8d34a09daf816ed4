//! The relaxation pass on the CPU, with the same integer arithmetic as `relax.wgsl`: the
//! reference the GPU pass is tested against, and the rule stated in plain Rust.

/// Flow from a texel with top `a` to a neighbour with top `b`: (out, in) units.
fn flow(a: u32, b: u32, threshold: u32) -> (u32, u32) {
    if a > b && a - b > threshold {
        ((a - b - threshold) / 8, 0)
    } else if b > a && b - a > threshold {
        (0, (b - a - threshold) / 8)
    } else {
        (0, 0)
    }
}

/// One relaxation step of a `width` x `height` depression channel (row-major) whose channel
/// maximum is `max`, with the thresholds along x and z in channel units.
pub fn step(
    depression: &[u32],
    width: u32,
    height: u32,
    max: u32,
    threshold: [u32; 2],
) -> Vec<u32> {
    let (w, h) = (width as usize, height as usize);
    let top = |x: usize, y: usize| max - depression[y * w + x];
    let mut out = vec![0; depression.len()];
    for y in 0..h {
        for x in 0..w {
            let t = top(x, y);
            let mut neighbours = [(None, 0); 4];
            if x > 0 {
                neighbours[0] = (Some(top(x - 1, y)), threshold[0]);
            }
            if x + 1 < w {
                neighbours[1] = (Some(top(x + 1, y)), threshold[0]);
            }
            if y > 0 {
                neighbours[2] = (Some(top(x, y - 1)), threshold[1]);
            }
            if y + 1 < h {
                neighbours[3] = (Some(top(x, y + 1)), threshold[1]);
            }
            let (mut gone, mut came) = (0u32, 0u32);
            for (n, th) in neighbours {
                if let Some(n) = n {
                    let (o, i) = flow(t, n, th);
                    gone += o;
                    came += i;
                }
            }
            out[y * w + x] = max - (t - gone + came);
        }
    }
    out
}

/// The threshold, channel units, for a repose slope of `degrees` over a texel of `texel` metres
/// in snow `depth` metres deep: the rise the slope allows over one texel, less the 7 units that a
/// settled step can keep above it (flows are floored eighths), so that settled steps never exceed
/// the repose slope.
pub fn threshold(degrees: f32, texel: f32, depth: f32, max: u32) -> u32 {
    if degrees >= 90.0 {
        // Walls stand at any slope.
        return max;
    }
    let rise = (degrees as f64).to_radians().tan() * texel as f64 / depth as f64 * max as f64;
    (rise.floor().clamp(0.0, max as f64) as u32).saturating_sub(7)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pit one texel wide, 1000 units deep, in flat material with threshold 100: after enough
    /// steps the depression's sum is what it was, and no step between neighbours exceeds 107.
    #[test]
    fn a_pit_slumps_keeping_its_volume_to_the_repose_slope() {
        let (w, h) = (21u32, 21u32);
        let mut d = vec![0u32; (w * h) as usize];
        d[(10 * w + 10) as usize] = 60_000;
        d[(10 * w + 11) as usize] = 40_000;
        let sum: u64 = d.iter().map(|&v| v as u64).sum();
        for _ in 0..4000 {
            d = step(&d, w, h, 65_535, [100, 100]);
        }
        assert_eq!(d.iter().map(|&v| v as u64).sum::<u64>(), sum);
        let steepest = steepest_step(&d, w, h);
        assert!(steepest <= 107, "steepest step {steepest} units");
        assert!(d[(10 * w + 10) as usize] < 60_000 / 4, "the pit filled in");
    }

    /// Two neighbours by hand: tops 1000 and 800, threshold 40: 20 units flow.
    #[test]
    fn one_flow_by_hand() {
        let d = step(&[0, 200], 2, 1, 1000, [40, 40]);
        assert_eq!(d, vec![20, 180]);
        // Under the threshold nothing moves.
        assert_eq!(step(&[0, 40], 2, 1, 1000, [40, 40]), vec![0, 40]);
    }

    #[test]
    fn thresholds_from_the_slope() {
        // 45 degrees over a 4 cm texel in 0.2 m: a fifth of the channel (13107 units; tan 45 is
        // a hair under 1 in floating point, so the floor may take one unit), less 7.
        let t = threshold(45.0, 0.04, 0.2, 65_535);
        assert!((13_099..=13_100).contains(&t), "{t}");
        // Vertical walls stand: nothing ever flows.
        assert_eq!(threshold(90.0, 0.04, 0.2, 255), 255);
        assert_eq!(threshold(0.0, 0.04, 0.2, 255), 0);
    }

    fn steepest_step(d: &[u32], w: u32, h: u32) -> u32 {
        let at = |x: u32, y: u32| d[(y * w + x) as usize];
        let mut m = 0;
        for y in 0..h {
            for x in 0..w {
                if x + 1 < w {
                    m = m.max(at(x, y).abs_diff(at(x + 1, y)));
                }
                if y + 1 < h {
                    m = m.max(at(x, y).abs_diff(at(x, y + 1)));
                }
            }
        }
        m
    }
}
