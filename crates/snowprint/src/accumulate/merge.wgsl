// Stage 2: merge the blurred capture into the heightmap history through the ping-pong pair, after
// replenishing it by the snow that fell since the last update.
// Reads: `records`, `scratch` (blurred capture), the `heights_read` half of each slot in `pool`.
// Writes: the `heights_write` half: depression in the low 16 bits, displaced snow in the high 16
// (both in units of 1/65535 of the snow depth).
// CPU reference: accumulate::cpu::merge. Maths: maths.wgsl.

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> scratch: array<f32>;
@group(0) @binding(2) var<storage, read_write> pool: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn merge(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    let idx = gid.y * rec.width + gid.x;
    let has_capture = rec.batch != NO_CAPTURE;
    var blurred = 0.0;
    if has_capture {
        blurred = scratch[rec.scratch + idx];
    }
    pool[rec.heights_write + idx] =
        merge_texel(pool[rec.heights_read + idx], blurred, has_capture, rec.replenish_units);
}
