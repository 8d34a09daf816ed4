// The arithmetic of the accumulation chain, as pure functions of loaded values, shared by the
// separate passes (blur.wgsl, merge.wgsl, normals.wgsl) and the fused one (fused.wgsl) so that they
// cannot drift apart. CPU reference: accumulate::cpu.

// import shared, channels

// Tap offsets in texels: a rotated grid, so each bilinear tap mixes four texels and the four taps
// together spread over one texel in every direction (kernel in 64ths: corners 3, edges 10,
// centre 12).
const TAPS = array<vec2<f32>, 4>(
    vec2<f32>(-0.25, -0.75),
    vec2<f32>(0.75, -0.25),
    vec2<f32>(0.25, 0.75),
    vec2<f32>(-0.75, 0.25),
);

// Depression (0 = untouched, 1 = pressed to the ground) of a stored capture value.
fn capture_depression(rec: SurfaceRecord, code: u32) -> f32 {
    let z = bitcast<f32>(ONE_BITS - code);
    if (rec.mode & MODE_MASK) != 0u {
        return select(0.0, rec.mask_fraction, z < 1.0);
    }
    let h = z * rec.frustum_height;
    return clamp((rec.snow_depth - h) / rec.snow_depth, 0.0, 1.0);
}

fn lerp2(a: f32, b: f32, c: f32, d: f32, f: vec2<f32>) -> f32 {
    let top = a * (1.0 - f.x) + b * f.x;
    let bottom = c * (1.0 - f.x) + d * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}

// The 4-tap bilinear Poisson blur from the 3x3 depressions around a texel; vXY is the texel at
// offset (X - 1, Y - 1). A tap at offset o interpolates from texel floor(o) with weights fract(o).
fn blur_taps(
    v00: f32, v10: f32, v20: f32,
    v01: f32, v11: f32, v21: f32,
    v02: f32, v12: f32, v22: f32,
) -> f32 {
    let t0 = lerp2(v00, v10, v01, v11, fract(TAPS[0])); // (-0.25, -0.75): from (-1, -1)
    let t1 = lerp2(v10, v20, v11, v21, fract(TAPS[1])); // ( 0.75, -0.25): from ( 0, -1)
    let t2 = lerp2(v11, v21, v12, v22, fract(TAPS[2])); // ( 0.25,  0.75): from ( 0,  0)
    let t3 = lerp2(v01, v11, v02, v12, fract(TAPS[3])); // (-0.75,  0.25): from (-1,  0)
    return (t0 + t1 + t2 + t3) * 0.25;
}

// A depression fraction in channel units, rounded to nearest (1 = channel_max exactly).
fn to_units(d: f32) -> u32 {
    let c = clamp(d, 0.0, 1.0);
    if c >= 1.0 {
        return channel_max(PRECISION);
    }
    return u32(floor(c * f32(channel_max(PRECISION)) + 0.5));
}

// Replenish an old texel (depression, displaced) by `rep` units, then deepen it by a blurred
// capture (when there is one). A capture never makes a depression shallower; what it deepens is
// added to the displaced channel, which saturates at a whole snow depth.
fn merge_channels(old: vec2<u32>, blurred: f32, has_capture: bool, rep: u32) -> vec2<u32> {
    // Saturating subtraction: snow refills up to the untouched top and no further.
    let depressed = max(old.x, rep) - rep;
    let displaced = max(old.y, rep) - rep;
    var captured = 0u;
    if has_capture {
        captured = to_units(blurred);
    }
    let new_depressed = max(depressed, captured);
    let pushed = new_depressed - depressed;
    let cmax = channel_max(PRECISION);
    let new_displaced = select(displaced + pushed, cmax, displaced > cmax - pushed);
    return vec2<u32>(new_depressed, new_displaced);
}

// Height of the snow top (metres, 0 = untouched) of a depression in channel units.
fn snow_height(rec: SurfaceRecord, units: u32) -> f32 {
    return -f32(units) / f32(channel_max(PRECISION)) * rec.snow_depth;
}

// Packed normal (pack2x16snorm of local x and z) from the heights left, right, below (-z) and
// above (+z) a texel, by central differences.
fn packed_normal(rec: SurfaceRecord, left: f32, right: f32, back: f32, front: f32) -> u32 {
    let dhdx = (right - left) / (2.0 * rec.texel_x);
    let dhdz = (front - back) / (2.0 * rec.texel_z);
    let n = normalize(vec3<f32>(-dhdx, 1.0, -dhdz));
    return pack2x16snorm(n.xz);
}
