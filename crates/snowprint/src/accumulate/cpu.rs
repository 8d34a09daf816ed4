//! CPU references of the accumulation passes: the same maths, in the same order, as the WGSL.

use glam::Vec3;

use crate::capture::CaptureMode;
use crate::pool::Precision;

/// Tap offsets of the blur, texels. Must match `TAPS` in `blur.wgsl`.
pub const TAPS: [[f32; 2]; 4] = [[-0.25, -0.75], [0.75, -0.25], [0.25, 0.75], [-0.75, 0.25]];
/// Settings the blur needs from a surface.
#[derive(Clone, Copy, Debug)]
pub struct BlurInput {
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Depth or mask.
    pub mode: CaptureMode,
    /// Mask imprint, fraction of snow depth.
    pub mask_fraction: f32,
    /// Snow depth, metres.
    pub snow_depth: f32,
    /// Snow depth plus ankle height, metres.
    pub frustum_height: f32,
}

/// Depression of the surface's texel `(x, y)` from a capture of its region (its texels and the
/// apron around them, [`crate::capture::region`]): `x` in `-1..=width`, `y` in `-1..=height`.
fn depression(inp: &BlurInput, region: &[f32], x: i32, y: i32) -> f32 {
    let a = crate::capture::APRON as i32;
    let (rw, rh) = crate::capture::region(inp.width, inp.height);
    assert!(
        (-a..rw as i32 - a).contains(&x) && (-a..rh as i32 - a).contains(&y),
        "texel ({x}, {y}) is beyond the apron of a {} x {} surface",
        inp.width,
        inp.height
    );
    let z = region[((y + a) as u32 * rw + (x + a) as u32) as usize];
    depression_at(inp, z)
}

/// Depression of a captured depth `z` (1 = nothing).
fn depression_at(inp: &BlurInput, z: f32) -> f32 {
    if inp.mode == CaptureMode::Mask {
        return if z < 1.0 { inp.mask_fraction } else { 0.0 };
    }
    let h = z * inp.frustum_height;
    ((inp.snow_depth - h) / inp.snow_depth).clamp(0.0, 1.0)
}

fn bilinear(inp: &BlurInput, capture: &[f32], px: f32, py: f32) -> f32 {
    let (qx, qy) = (px - 0.5, py - 0.5);
    let (bx, by) = (qx.floor(), qy.floor());
    let (fx, fy) = (qx - bx, qy - by);
    let (ix, iy) = (bx as i32, by as i32);
    let a = depression(inp, capture, ix, iy);
    let b = depression(inp, capture, ix + 1, iy);
    let c = depression(inp, capture, ix, iy + 1);
    let d = depression(inp, capture, ix + 1, iy + 1);
    let top = a * (1.0 - fx) + b * fx;
    let bottom = c * (1.0 - fx) + d * fx;
    top * (1.0 - fy) + bottom * fy
}

/// Stage 1: depression of a capture (depths, 1 = nothing) blurred by the 4-tap bilinear Poisson
/// kernel, `width x height` of it. `capture` covers the surface's capture region
/// ([`crate::capture::region`]: `(width + 2) x (height + 2)`, the apron of one texel around the
/// surface, [`crate::capture::cpu::capture_region`]), so that the blur of an edge texel reads the
/// capture one texel beyond the surface rather than the edge again.
pub fn blur(inp: &BlurInput, capture: &[f32]) -> Vec<f32> {
    assert_eq!(
        capture.len() as u32,
        crate::capture::region_texels(inp.width, inp.height),
        "the blur reads a capture of the surface's region, its texels and the apron"
    );
    let mut out = Vec::with_capacity((inp.width * inp.height) as usize);
    for y in 0..inp.height {
        for x in 0..inp.width {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let mut sum = 0.0;
            for t in TAPS {
                sum += bilinear(inp, capture, px + t[0], py + t[1]);
            }
            out.push(sum * 0.25);
        }
    }
    out
}

/// The unblurred depression of a `width x height` capture (used by analytic tests).
pub fn depression_of(inp: &BlurInput, capture: &[f32]) -> Vec<f32> {
    capture.iter().map(|&z| depression_at(inp, z)).collect()
}

/// Quantize a depression fraction to channel units the way `maths.wgsl` does (`to_units`).
pub fn to_units(d: f32, precision: Precision) -> u32 {
    let c = d.clamp(0.0, 1.0);
    if c >= 1.0 {
        return precision.channel_max();
    }
    (c * precision.channel_max() as f32 + 0.5).floor() as u32
}

/// Stage 2 on one texel: replenish `old` (depression, displaced) by `replenish_units`, then deepen
/// it by the blurred capture (when there is one); what a capture deepens is added to the displaced
/// channel, which saturates at a whole snow depth.
pub fn merge_channels(
    old: (u32, u32),
    blurred: Option<f32>,
    replenish_units: u32,
    precision: Precision,
) -> (u32, u32) {
    let depressed = old.0.max(replenish_units) - replenish_units;
    let displaced = old.1.max(replenish_units) - replenish_units;
    let captured = blurred.map_or(0, |b| to_units(b, precision));
    let new_depressed = depressed.max(captured);
    let pushed = new_depressed - depressed;
    let new_displaced = displaced
        .saturating_add(pushed)
        .min(precision.channel_max());
    (new_depressed, new_displaced)
}

/// The refill pass (refill.wgsl) on one word of a heights region: every channel the word holds
/// (four 8-bit lanes, two 16-bit lanes or one 32-bit word) replenished by `replenish_units`,
/// saturating at the untouched top. Followed by [`merge_channels`] with no replenishment, it gives
/// what `merge_channels` with the replenishment gives.
pub fn refill_word(word: u32, replenish_units: u32, precision: Precision) -> u32 {
    let lane = |v: u32| v.max(replenish_units) - replenish_units;
    match precision {
        Precision::Bits8 => (0..4).fold(0, |out, k| {
            out | (lane((word >> (8 * k)) & 0xff) << (8 * k))
        }),
        Precision::Bits16 => lane(word & 0xffff) | (lane(word >> 16) << 16),
        Precision::Bits32 => lane(word),
    }
}

/// Stage 2 over a heightmap of channels (row-major depression and displaced).
pub fn merge(
    depression: &[u32],
    displaced: &[u32],
    blurred: Option<&[f32]>,
    replenish_units: u32,
    precision: Precision,
) -> (Vec<u32>, Vec<u32>) {
    (0..depression.len())
        .map(|i| {
            merge_channels(
                (depression[i], displaced[i]),
                blurred.map(|b| b[i]),
                replenish_units,
                precision,
            )
        })
        .unzip()
}

/// WGSL's `pack2x16snorm`.
pub fn pack2x16snorm(a: f32, b: f32) -> u32 {
    let q = |v: f32| ((0.5 + 32767.0 * v.clamp(-1.0, 1.0)).floor() as i32 as i16) as u16 as u32;
    q(a) | (q(b) << 16)
}

/// WGSL's `unpack2x16snorm`.
pub fn unpack2x16snorm(v: u32) -> (f32, f32) {
    let q = |bits: u32| ((bits as u16 as i16) as f32 / 32767.0).max(-1.0);
    (q(v & 0xffff), q(v >> 16))
}

/// A normal from its packed `x` and `z` (y from unit length).
pub fn unpack_normal(v: u32) -> Vec3 {
    let (x, z) = unpack2x16snorm(v);
    Vec3::new(x, (1.0 - x * x - z * z).max(0.0).sqrt(), z)
}

/// Normals of the snow top of a depression channel at `precision`, packed as `normals.wgsl`
/// packs them.
pub fn normals(
    depression: &[u32],
    precision: Precision,
    width: u32,
    height: u32,
    snow_depth: f32,
    texel_x: f32,
    texel_z: f32,
) -> Vec<u32> {
    let h = |x: i32, y: i32| {
        let cx = x.clamp(0, width as i32 - 1) as usize;
        let cy = y.clamp(0, height as i32 - 1) as usize;
        -(depression[cy * width as usize + cx] as f32) / precision.channel_max() as f32 * snow_depth
    };
    let mut out = Vec::with_capacity(depression.len());
    for y in 0..height as i32 {
        for x in 0..width as i32 {
            let dhdx = (h(x + 1, y) - h(x - 1, y)) / (2.0 * texel_x);
            let dhdz = (h(x, y + 1) - h(x, y - 1)) / (2.0 * texel_z);
            let n = Vec3::new(-dhdx, 1.0, -dhdz).normalize();
            out.push(pack2x16snorm(n.x, n.z));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_preserves_constants_and_spreads_one_texel() {
        let inp = BlurInput {
            width: 9,
            height: 7,
            mode: CaptureMode::Depth,
            mask_fraction: 1.0,
            snow_depth: 0.3,
            frustum_height: 0.55,
        };
        // The capture covers the region: 11 x 9, the surface's texel (x, y) at (x + 1, y + 1).
        // Ground everywhere: depression 1, blurred 1.
        let flat = vec![0.0; 99];
        assert!(blur(&inp, &flat).iter().all(|&v| (v - 1.0).abs() < 1e-6));
        // One pressed texel in the middle: the blur keeps its mass and spreads it over the 3x3
        // neighbourhood only.
        let mut one = vec![1.0; 99];
        one[4 * 11 + 5] = 0.0;
        let b = blur(&inp, &one);
        let total: f32 = b.iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        for y in 0..7 {
            for x in 0..9 {
                if (x as i32 - 4).abs() > 1 || (y as i32 - 3).abs() > 1 {
                    assert_eq!(b[y * 9 + x], 0.0);
                }
            }
        }
        // Summing the bilinear weights of the four taps (each divided by 4) gives the kernel, in
        // 64ths: corners 3, edges 10, centre 12 (3 x 4 + 10 x 4 + 12 = 64).
        let at = |x: usize, y: usize| b[y * 9 + x] * 64.0;
        for (x, y, w) in [
            (4, 3, 12.0),
            (5, 3, 10.0),
            (4, 2, 10.0),
            (3, 3, 10.0),
            (4, 4, 10.0),
            (5, 4, 3.0),
            (3, 2, 3.0),
        ] {
            assert!(
                (at(x, y) - w).abs() < 1e-4,
                "({x},{y}): {} / 64, expected {w}",
                at(x, y)
            );
        }
    }

    /// A texel pressed one beyond the surface's edge (in the apron only) reaches the edge column
    /// through the blur with the kernel's weights, as on one wider surface: 10/64 beside it, 3/64
    /// on the two diagonals, nothing further in. Clamping at the edge would leave it nothing.
    #[test]
    fn blur_reads_the_apron_beyond_the_edge() {
        let inp = BlurInput {
            width: 9,
            height: 7,
            mode: CaptureMode::Depth,
            mask_fraction: 1.0,
            snow_depth: 0.3,
            frustum_height: 0.55,
        };
        // Region texel (0, 4): the surface's (-1, 3), left of column 0.
        let mut beyond = vec![1.0; 99];
        beyond[4 * 11] = 0.0;
        let b = blur(&inp, &beyond);
        for y in 0..7 {
            for x in 0..9 {
                let expected = match (x, y) {
                    (0, 3) => 10.0,
                    (0, 2) | (0, 4) => 3.0,
                    _ => 0.0,
                };
                let got = b[y * 9 + x] * 64.0;
                assert!(
                    (got - expected).abs() < 1e-4,
                    "({x},{y}): {got} / 64, expected {expected}"
                );
            }
        }
    }

    #[test]
    fn merge_never_shallower_and_replenishes() {
        let p = Precision::Bits16;
        let (dep, disp) = merge(&[1000, 500, 0], &[0; 3], Some(&[0.0, 0.5, 0.01]), 100, p);
        assert_eq!(dep[0], 900);
        assert_eq!(dep[1], to_units(0.5, p));
        assert_eq!(disp[1], to_units(0.5, p) - 400);
        assert_eq!(dep[2], to_units(0.01, p));
        // Replenishment saturates at untouched snow.
        assert_eq!(merge(&[50], &[50], None, 100, p), (vec![0], vec![0]));
    }

    /// Quantization by hand at each precision: 0.5 rounds to half the range, 1 is the maximum
    /// exactly, and the displaced channel saturates instead of wrapping (at 32 bits too).
    #[test]
    fn units_and_saturation_at_each_precision() {
        assert_eq!(to_units(0.5, Precision::Bits8), 128); // 127.5 + 0.5
        assert_eq!(to_units(0.5, Precision::Bits16), 32768);
        assert_eq!(to_units(0.5, Precision::Bits32), 1 << 31);
        for p in Precision::ALL {
            assert_eq!(to_units(1.0, p), p.channel_max());
            assert_eq!(to_units(2.0, p), p.channel_max());
            let max = p.channel_max();
            let out = merge_channels((0, max - 1), Some(1.0), 0, p);
            assert_eq!(out, (max, max), "{p}");
        }
    }

    /// Refilling the stored words, then merging without replenishment, equals merging with it, at
    /// every precision, on a row of odd width (8-bit padding included) whose channels span the
    /// range: what lets the fused pass leave the replenishment to the refill pass.
    #[test]
    fn refilled_words_then_merge_equal_the_merge_with_refill() {
        use crate::pool::PoolFormat;
        for p in Precision::ALL {
            let max = p.channel_max();
            let depression = [0, 1, 99, 100, 101, max / 2, max - 1, max, 7, 0, max];
            let displaced = [max, 0, 100, 3, 250, max / 3, 1, max, 0, 101, 5];
            let blurred = [0.0, 0.3, 0.0, 1.0, 0.5, 0.01, 0.9, 0.2, 0.0, 0.7, 0.5];
            let format = PoolFormat::new(p);
            let w = depression.len() as u32;
            let words = format.encode(w, 1, &depression, &displaced).unwrap();
            for rep in [0, 1, 100, 255, max / 2, max] {
                let refilled: Vec<u32> = words.iter().map(|&v| refill_word(v, rep, p)).collect();
                let (d, g) = format.decode(w, 1, &refilled).unwrap();
                for i in 0..depression.len() {
                    let old = (depression[i], displaced[i]);
                    let b = Some(blurred[i]);
                    assert_eq!(
                        merge_channels((d[i], g[i]), b, 0, p),
                        merge_channels(old, b, rep, p),
                        "{p}, {rep} units, texel {i}"
                    );
                }
                // The 8-bit row's padding texel stays zero.
                if p == Precision::Bits8 {
                    assert_eq!(refilled.last().unwrap() >> 16, 0);
                }
            }
        }
    }

    #[test]
    fn snorm_round_trip() {
        let v = pack2x16snorm(-0.5, 1.0);
        let (a, b) = unpack2x16snorm(v);
        assert!((a + 0.5).abs() < 1e-4 && (b - 1.0).abs() < 1e-6);
    }
}
