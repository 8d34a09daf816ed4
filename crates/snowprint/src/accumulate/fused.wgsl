// The whole accumulation chain in one pass: blur, replenish, merge and normals, for GPUs where a
// pass costs more than its memory traffic. A 16x16 workgroup stages the depressions of its tile
// with a two-texel apron (20x20) in workgroup memory, then the new heightmap values of the tile with
// a one-texel apron (18x18, which the normals need), so every capture and history texel is read
// from memory about once.
// Reads: `records`, `capture`, `winding`, the `heights_read` half of each slot in `pool`.
// Writes: the `heights_write` half and the `normals` region.
// CPU reference: accumulate::cpu::blur, merge and normals in sequence. Maths: maths.wgsl,
// capture_read.wgsl.

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read> winding: array<i32>;
@group(0) @binding(3) var<storage, read_write> pool: array<u32>;

const SIDE: i32 = 16;
const DEP: i32 = 20;    // SIDE + 2 texels of apron on each side
const NEW: i32 = 18;    // SIDE + 1 texel of apron on each side
var<workgroup> depressions: array<f32, 400>;   // DEP * DEP
var<workgroup> updated: array<u32, 324>;       // NEW * NEW

@compute @workgroup_size(16, 16, 1)
fn fused(
    @builtin(local_invocation_index) lid: u32,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(workgroup_id) wid: vec3<u32>,
) {
    let rec = records[wid.z];
    // Whole workgroups past the surface leave together, before any barrier.
    if i32(wid.x) * SIDE >= i32(rec.width) || i32(wid.y) * SIDE >= i32(rec.height) {
        return;
    }
    let w = i32(rec.width);
    let h = i32(rec.height);
    let has_capture = rec.batch != NO_CAPTURE;
    // Tile origins in surface texels: the new values start one texel before the tile, the
    // depressions two.
    let new_origin = vec2<i32>(wid.xy) * SIDE - vec2<i32>(1);
    let dep_origin = new_origin - vec2<i32>(1);
    if has_capture {
        for (var k = i32(lid); k < DEP * DEP; k += SIDE * SIDE) {
            depressions[k] = depression(rec, dep_origin.x + k % DEP, dep_origin.y + k / DEP);
        }
    }
    workgroupBarrier();
    for (var k = i32(lid); k < NEW * NEW; k += SIDE * SIDE) {
        // The new value at the clamped texel a (as the CPU reference clamps its neighbours).
        let a = clamp(new_origin + vec2<i32>(k % NEW, k / NEW), vec2<i32>(0), vec2<i32>(w - 1, h - 1));
        var blurred = 0.0;
        if has_capture {
            let c = a - dep_origin; // a's place in the depression tile, 1..18 on each axis
            let i = c.y * DEP + c.x;
            blurred = blur_taps(
                depressions[i - DEP - 1], depressions[i - DEP], depressions[i - DEP + 1],
                depressions[i - 1], depressions[i], depressions[i + 1],
                depressions[i + DEP - 1], depressions[i + DEP], depressions[i + DEP + 1],
            );
        }
        let old = pool[rec.heights_read + u32(a.y * w + a.x)];
        updated[k] = merge_texel(old, blurred, has_capture, rec.replenish_units);
    }
    workgroupBarrier();
    let p = vec2<i32>(wid.xy) * SIDE + vec2<i32>(local.xy);
    if p.x >= w || p.y >= h {
        return;
    }
    let idx = u32(p.y * w + p.x);
    pool[rec.heights_write + idx] = new_at(rec, new_origin, p);
    pool[rec.normals + idx] = packed_normal(
        rec,
        snow_height(rec, new_at(rec, new_origin, p - vec2<i32>(1, 0)) & 0xffffu),
        snow_height(rec, new_at(rec, new_origin, p + vec2<i32>(1, 0)) & 0xffffu),
        snow_height(rec, new_at(rec, new_origin, p - vec2<i32>(0, 1)) & 0xffffu),
        snow_height(rec, new_at(rec, new_origin, p + vec2<i32>(0, 1)) & 0xffffu),
    );
}

// The new value at texel q of the surface, clamped to its edges, from the staged tile.
fn new_at(rec: SurfaceRecord, new_origin: vec2<i32>, q: vec2<i32>) -> u32 {
    let limit = vec2<i32>(i32(rec.width) - 1, i32(rec.height) - 1);
    let t = clamp(q, vec2<i32>(0), limit) - new_origin;
    return updated[t.y * NEW + t.x];
}
