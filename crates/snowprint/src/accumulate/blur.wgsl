// Stage 1: turn the capture into a depression (0 = untouched, 1 = pressed to the ground) and
// soften it with a 4-tap bilinear Poisson blur.
// Reads: `capture` (encoded depths written by the capture pass at each record's `scratch`
// offset), `records`.
// Writes: `scratch` (one f32 per texel of each captured surface).
// CPU reference: accumulate::cpu::blur.

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read_write> scratch: array<f32>;

// Must match `ONE_BITS` in capture.wgsl: a stored value v is the depth bitcast(ONE_BITS - v).
const ONE_BITS: u32 = 0x3f800000u;

// Tap offsets in texels: a rotated grid, so each bilinear tap mixes four texels with weights of
// 1/16, 3/16 and 9/16 and the four taps together spread over one texel in every direction.
const TAPS = array<vec2<f32>, 4>(
    vec2<f32>(-0.25, -0.75),
    vec2<f32>(0.75, -0.25),
    vec2<f32>(0.25, 0.75),
    vec2<f32>(-0.75, 0.25),
);

fn depression(rec: SurfaceRecord, x: i32, y: i32) -> f32 {
    let cx = clamp(x, 0, i32(rec.width) - 1);
    let cy = clamp(y, 0, i32(rec.height) - 1);
    let z = bitcast<f32>(ONE_BITS - capture[rec.scratch + u32(cy) * rec.width + u32(cx)]);
    if rec.mode == MODE_MASK {
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

@compute @workgroup_size(8, 8, 1)
fn blur(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if rec.batch == NO_CAPTURE || gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    // The four taps (TAPS) each mix a 2x2 block of the 3x3 texels around this one: load the nine
    // once. vXY is the texel at offset (X - 1, Y - 1). A tap at offset o from the texel centre
    // interpolates from texel floor(o) with weights fract(o), exactly as the CPU reference does.
    let x = i32(gid.x);
    let y = i32(gid.y);
    let v00 = depression(rec, x - 1, y - 1);
    let v10 = depression(rec, x, y - 1);
    let v20 = depression(rec, x + 1, y - 1);
    let v01 = depression(rec, x - 1, y);
    let v11 = depression(rec, x, y);
    let v21 = depression(rec, x + 1, y);
    let v02 = depression(rec, x - 1, y + 1);
    let v12 = depression(rec, x, y + 1);
    let v22 = depression(rec, x + 1, y + 1);
    let t0 = lerp2(v00, v10, v01, v11, fract(TAPS[0])); // (-0.25, -0.75): from (-1, -1)
    let t1 = lerp2(v10, v20, v11, v21, fract(TAPS[1])); // ( 0.75, -0.25): from ( 0, -1)
    let t2 = lerp2(v11, v21, v12, v22, fract(TAPS[2])); // ( 0.25,  0.75): from ( 0,  0)
    let t3 = lerp2(v01, v11, v02, v12, fract(TAPS[3])); // (-0.75,  0.25): from (-1,  0)
    scratch[rec.scratch + gid.y * rec.width + gid.x] = (t0 + t1 + t2 + t3) * 0.25;
}
