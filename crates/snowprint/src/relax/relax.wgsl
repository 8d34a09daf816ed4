// relax.wgsl: materials slump back to their angle of repose (sand, powder). One Jacobi step of a
// conservative flow between each texel and its 4 neighbours, in channel units of the pool's
// PRECISION: the top of the material at a texel is `channel_max - depression` above the ground;
// between two neighbours whose tops differ by `d` units, more than `threshold` (the repose slope
// over one texel, less 7 units so that a settled step never exceeds it), `(d - threshold) / 8`
// units (floored) flow from the higher to the lower. Both texels compute the same flow with
// opposite signs, so the sum of depressions is kept exactly; a texel gives at most half of its
// top away and takes at most half of its neighbours' excess, so tops stay between the ground and
// the fresh snow top. The displaced channel is left as it is.
// Steps alternate: `relax_from_pool` reads the pool and writes the step's depressions into
// `scratch` (one u32 a texel of the record's rectangle), `relax_to_pool` reads `scratch` and writes
// the pool, so an even number of steps ends in the pool. `z` of the dispatch is the record.
// Only the record's rectangle runs: the world makes it the texels that may be unsettled grown by
// the update's steps, so texels outside it do not change in a relaxation of the whole surface
// either (a step moves material one texel), and neighbours outside it are read from the pool.
// CPU reference: relax::cpu::step (the same integer arithmetic).

// import shared, texel_write

// Must match `RelaxRecord` in relax/mod.rs.
struct RelaxRecord {
    heights: u32,     // word offset of the heights region in the pool
    width: u32,
    height: u32,
    scratch: u32,     // first u32 of the surface's depressions in `scratch`
    threshold_x: u32, // largest top difference between x neighbours that stands, channel units
    threshold_z: u32, // same between z neighbours
    x0: u32,          // the rectangle that relaxes: first column and row, columns and rows
    y0: u32,
    rect_width: u32,
    rect_height: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> relax_records: array<RelaxRecord>;
@group(0) @binding(1) var<storage, read_write> pool: array<u32>;
@group(0) @binding(2) var<storage, read_write> scratch: array<u32>;

// Flow of material from a texel with top `a` to a neighbour with top `b`: (out, in) units.
fn flow(a: u32, b: u32, threshold: u32) -> vec2<u32> {
    if a > b && a - b > threshold {
        return vec2<u32>((a - b - threshold) / 8u, 0u);
    }
    if b > a && b - a > threshold {
        return vec2<u32>(0u, (b - a - threshold) / 8u);
    }
    return vec2<u32>(0u);
}

fn top_in_pool(r: RelaxRecord, x: u32, y: u32) -> u32 {
    return channel_max(PRECISION) - pool_texel(PRECISION, r.heights, r.width, r.height, x, y).x;
}

fn in_rect(r: RelaxRecord, x: u32, y: u32) -> bool {
    return x >= r.x0 && y >= r.y0 && x < r.x0 + r.rect_width && y < r.y0 + r.rect_height;
}

fn scratch_index(r: RelaxRecord, x: u32, y: u32) -> u32 {
    return r.scratch + (y - r.y0) * r.rect_width + (x - r.x0);
}

// A neighbour's top after the last step: in `scratch` inside the rectangle, unchanged in the pool
// outside it.
fn top_in_scratch(r: RelaxRecord, x: u32, y: u32) -> u32 {
    if !in_rect(r, x, y) {
        return top_in_pool(r, x, y);
    }
    return channel_max(PRECISION) - scratch[scratch_index(r, x, y)];
}

// The texel's top after one step, its neighbours' tops read by `from_pool` or from `scratch`.
fn relaxed_top(r: RelaxRecord, x: u32, y: u32, from_pool: bool) -> u32 {
    var tops: array<u32, 5>;
    let xs = array<u32, 5>(x, x - 1u, x + 1u, x, x);
    let ys = array<u32, 5>(y, y, y, y - 1u, y + 1u);
    let inside = array<bool, 5>(true, x > 0u, x + 1u < r.width, y > 0u, y + 1u < r.height);
    for (var k = 0u; k < 5u; k++) {
        if inside[k] {
            if from_pool {
                tops[k] = top_in_pool(r, xs[k], ys[k]);
            } else {
                tops[k] = top_in_scratch(r, xs[k], ys[k]);
            }
        }
    }
    var out = 0u;
    var inn = 0u;
    for (var k = 1u; k < 5u; k++) {
        if inside[k] {
            let f = flow(tops[0], tops[k], select(r.threshold_z, r.threshold_x, k < 3u));
            out += f.x;
            inn += f.y;
        }
    }
    return tops[0] - out + inn;
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn relax_from_pool(@builtin(global_invocation_id) gid: vec3<u32>) {
    let r = relax_records[gid.z];
    if gid.x >= r.rect_width || gid.y >= r.rect_height {
        return;
    }
    let x = r.x0 + gid.x;
    let y = r.y0 + gid.y;
    let top = relaxed_top(r, x, y, true);
    scratch[scratch_index(r, x, y)] = channel_max(PRECISION) - top;
}

// The unit's texel (x, y) with its depression from `scratch`, its displaced channel kept.
fn settled(r: RelaxRecord, x: u32, y: u32) -> vec2<u32> {
    if x >= r.width {
        return vec2<u32>(0u); // the padding texel of an odd 8-bit row
    }
    let old = pool_texel(PRECISION, r.heights, r.width, r.height, x, y);
    if !in_rect(r, x, y) {
        return old; // the other texel of an 8-bit unit, outside the rectangle: unchanged
    }
    let top = relaxed_top(r, x, y, false);
    return vec2<u32>(channel_max(PRECISION) - top, old.y);
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn relax_to_pool(@builtin(global_invocation_id) gid: vec3<u32>) {
    let r = relax_records[gid.z];
    // Units start at even columns at 8 bits: from the unit holding the rectangle's first column.
    let first = r.x0 / unit_texels(PRECISION) * unit_texels(PRECISION);
    let x = first + gid.x * unit_texels(PRECISION);
    let y = r.y0 + gid.y;
    if x >= r.x0 + r.rect_width || gid.y >= r.rect_height {
        return;
    }
    let a = settled(r, x, y);
    var b = vec2<u32>(0u);
    if unit_texels(PRECISION) == 2u {
        b = settled(r, x + 1u, y);
    }
    pool_store_unit(PRECISION, r.heights, r.width, r.height, x, y, a, b);
}
