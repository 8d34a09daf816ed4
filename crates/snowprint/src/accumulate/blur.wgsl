// Stage 1: turn the capture into a depression (0 = untouched, 1 = pressed to the ground) and
// soften it with a 4-tap bilinear Poisson blur.
// Reads: `capture` (the atlas rectangles of batch `params.batch`), `records`.
// Writes: `scratch` (one f32 per texel of each captured surface).
// CPU reference: accumulate::cpu::blur.

struct BlurParams {
    batch: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var capture: texture_depth_2d;
@group(0) @binding(2) var<storage, read_write> scratch: array<f32>;
@group(0) @binding(3) var<uniform> params: BlurParams;

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
    let z = textureLoad(capture, vec2<i32>(i32(rec.atlas_x) + cx, i32(rec.atlas_y) + cy), 0);
    if rec.mode == MODE_MASK {
        return select(0.0, rec.mask_fraction, z < 1.0);
    }
    let h = z * rec.frustum_height;
    return clamp((rec.snow_depth - h) / rec.snow_depth, 0.0, 1.0);
}

fn bilinear(rec: SurfaceRecord, p: vec2<f32>) -> f32 {
    let q = p - vec2<f32>(0.5);
    let base = floor(q);
    let f = q - base;
    let i = vec2<i32>(base);
    let a = depression(rec, i.x, i.y);
    let b = depression(rec, i.x + 1, i.y);
    let c = depression(rec, i.x, i.y + 1);
    let d = depression(rec, i.x + 1, i.y + 1);
    let top = a * (1.0 - f.x) + b * f.x;
    let bottom = c * (1.0 - f.x) + d * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}

@compute @workgroup_size(8, 8, 1)
fn blur(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if rec.batch != params.batch || gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    let p = vec2<f32>(gid.xy) + vec2<f32>(0.5);
    var sum = 0.0;
    for (var t = 0; t < 4; t++) {
        sum += bilinear(rec, p + TAPS[t]);
    }
    scratch[rec.scratch + gid.y * rec.width + gid.x] = sum * 0.25;
}
