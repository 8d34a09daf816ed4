// Stage 2: merge the blurred capture into the heightmap history through the ping-pong pair, after
// replenishing it by the snow that fell since the last update. A capture can only deepen a
// depression, never make it shallower.
// Reads: `records`, `scratch` (blurred capture), the `heights_read` half of each slot in `pool`.
// Writes: the `heights_write` half: depression in the low 16 bits, displaced snow in the high 16
// (both in units of 1/65535 of the snow depth).
// CPU reference: accumulate::cpu::merge.

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
    let old = pool[rec.heights_read + idx];
    let rep = rec.replenish_units;
    // Saturating subtraction: snow refills up to the untouched top and no further.
    let depressed = max(old & 0xffffu, rep) - rep;
    let displaced = max(old >> 16u, rep) - rep;
    var captured = 0u;
    if rec.batch != NO_CAPTURE {
        captured = u32(floor(clamp(scratch[rec.scratch + idx], 0.0, 1.0) * UNITS + 0.5));
    }
    let new_depressed = max(depressed, captured);
    // The snow pushed out of this texel by this capture, kept for snow banks.
    let pushed = new_depressed - depressed;
    let new_displaced = min(displaced + pushed, 0xffffu);
    pool[rec.heights_write + idx] = new_depressed | (new_displaced << 16u);
}
