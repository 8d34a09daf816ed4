// The whole accumulation chain in one pass: blur, replenish, merge and normals, for GPUs where a
// pass costs more than its memory traffic. Each invocation computes the new depression of its
// texel and of its four neighbours (the normals need them), so it reads the capture in a 5x5
// window without the corners and the history at five texels; neighbours' values are recomputed,
// not exchanged, and come out bit for bit as their own invocations compute them.
// Reads: `records`, `capture`, the `heights_read` half of each slot in `pool`.
// Writes: the `heights_write` half and the `normals` region.
// CPU reference: accumulate::cpu::blur, merge and normals in sequence. Maths: maths.wgsl, capture_read.wgsl.

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read_write> pool: array<u32>;

// The new packed texel at (x, y), clamped to the surface.
fn updated(rec: SurfaceRecord, x_in: i32, y_in: i32) -> u32 {
    let x = clamp(x_in, 0, i32(rec.width) - 1);
    let y = clamp(y_in, 0, i32(rec.height) - 1);
    let has_capture = rec.batch != NO_CAPTURE;
    var blurred = 0.0;
    if has_capture {
        blurred = blur_taps(
            depression(rec, x - 1, y - 1), depression(rec, x, y - 1), depression(rec, x + 1, y - 1),
            depression(rec, x - 1, y), depression(rec, x, y), depression(rec, x + 1, y),
            depression(rec, x - 1, y + 1), depression(rec, x, y + 1), depression(rec, x + 1, y + 1),
        );
    }
    let old = pool[rec.heights_read + u32(y) * rec.width + u32(x)];
    return merge_texel(old, blurred, has_capture, rec.replenish_units);
}

@compute @workgroup_size(8, 8, 1)
fn fused(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    let idx = gid.y * rec.width + gid.x;
    pool[rec.heights_write + idx] = updated(rec, x, y);
    pool[rec.normals + idx] = packed_normal(
        rec,
        snow_height(rec, updated(rec, x - 1, y) & 0xffffu),
        snow_height(rec, updated(rec, x + 1, y) & 0xffffu),
        snow_height(rec, updated(rec, x, y - 1) & 0xffffu),
        snow_height(rec, updated(rec, x, y + 1) & 0xffffu),
    );
}
