// Stage 1: turn the capture into a depression (0 = untouched, 1 = pressed to the ground) and
// soften it with a 4-tap bilinear Poisson blur.
// Reads: `capture` and `winding` (written by the capture pass at each record's `scratch`
// offset), `records`.
// Writes: `scratch` (one f32 per texel of each captured surface).
// CPU reference: accumulate::cpu::blur. Maths: maths.wgsl, capture_read.wgsl.

// import maths, capture_read

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read> winding: array<i32>;
@group(0) @binding(3) var<storage, read_write> scratch: array<f32>;

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn blur(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if rec.batch == NO_CAPTURE || gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    scratch[rec.scratch + gid.y * rec.width + gid.x] = blur_taps(
        depression(rec, x - 1, y - 1), depression(rec, x, y - 1), depression(rec, x + 1, y - 1),
        depression(rec, x - 1, y), depression(rec, x, y), depression(rec, x + 1, y),
        depression(rec, x - 1, y + 1), depression(rec, x, y + 1), depression(rec, x + 1, y + 1),
    );
}
