// Stage 2: replenish each surface's heightmap by the snow that fell since the last update, then
// deepen it by the blurred capture, in place: a texel's new value depends only on its old value
// and its blurred capture, so no history is kept.
// Reads: `records`, `scratch` (blurred capture), each record's heights region in `pool`.
// Writes: the same heights region (both channels, at the pool's PRECISION; see texel.wgsl).
// One invocation per unit (two texels along x at 8 bits, one otherwise).
// CPU reference: accumulate::cpu::merge_channels. Maths: maths.wgsl.

// import maths, texel_write

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> scratch: array<f32>;
@group(0) @binding(2) var<storage, read_write> pool: array<u32>;

fn merged(rec: SurfaceRecord, x: u32, y: u32) -> vec2<u32> {
    if x >= rec.width {
        return vec2<u32>(0u); // the padding texel of an odd 8-bit row
    }
    let has_capture = rec.batch != NO_CAPTURE;
    var blurred = 0.0;
    if has_capture {
        blurred = scratch[rec.scratch + y * rec.width + x];
    }
    let old = pool_texel(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, x, y);
    return merge_channels(old, blurred, has_capture, rec.replenish_units);
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn merge(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    let x = gid.x * unit_texels(PRECISION);
    if x >= rec.width || gid.y >= rec.height {
        return;
    }
    let a = merged(rec, x, gid.y);
    var b = vec2<u32>(0u);
    if unit_texels(PRECISION) == 2u {
        b = merged(rec, x + 1u, gid.y);
    }
    pool_store_unit(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, x, gid.y, a, b);
}
