// relax.wgsl: materials slump back to their angle of repose (sand, powder). Jacobi steps of a
// conservative flow between each texel and its 4 neighbours, in channel units of the pool's
// PRECISION: the top of the material at a texel is `channel_max - depression` above the ground;
// between two neighbours whose tops differ by `d` units, more than `threshold` (the repose slope
// over one texel, less 7 units so that a settled step never exceeds it), `(d - threshold) / 8`
// units (floored) flow from the higher to the lower. Both texels compute the same flow with
// opposite signs, so the sum of depressions is kept exactly; a texel gives at most half of its
// top away and takes at most half of its neighbours' excess, so tops stay between the ground and
// the fresh snow top. The displaced channel is left as it is.
//
// Several steps a dispatch, in workgroup memory: a workgroup loads the tops of its RELAX_TILE^2
// texels and a halo of RELAX_HALO around them, takes the record's `dispatch_steps` steps (at most
// RELAX_HALO) over a window that shrinks by a texel a step (a step moves material one texel, so
// the tile's texels are exact after them), and writes its tile. A step that changes nothing in
// its window ends the workgroup's steps early: the next ones would change nothing either.
// Tiles that stand still are skipped: `relax_from_pool` flags each tile whose first step moved
// nothing (`relax_tiles`, one word a tile, 1: still). Its span is then a fixed point and the
// scratch holds the pool's values for it, so `relax_to_pool` skips a tile whose own and eight
// neighbours' flags are all still (its span is as it was, the pool already holds it, and it
// writes nothing another tile reads), and `relax_copy` a tile that is still itself.
// Dispatches alternate: `relax_from_pool` reads the pool and writes the rectangle's depressions
// into `scratch` (one u32 a texel), `relax_to_pool` reads `scratch` and writes the pool;
// `relax_copy` (no step) writes `scratch` back to the pool after an odd number of dispatches.
// Only the record's rectangle changes: the world makes it the texels that may be unsettled grown
// by the update's steps, so texels outside it do not change in a relaxation of the whole surface
// either, and they are read from the pool. `z` of the dispatch is the record.
// CPU reference: relax::cpu::step (the same integer arithmetic, one step over a whole surface).

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
    dispatch_steps: u32, // steps each dispatch of `relax_from_pool` and `relax_to_pool` takes
    tiles: u32,       // first word of the record's tile flags in `relax_tiles`
    wrap: u32,        // toroidal storage offsets (pool/texel.wgsl)
}

@group(0) @binding(0) var<storage, read> relax_records: array<RelaxRecord>;
@group(0) @binding(1) var<storage, read_write> pool: array<u32>;
@group(0) @binding(2) var<storage, read_write> scratch: array<u32>;
@group(0) @binding(3) var<storage, read_write> relax_tiles: array<u32>;

const RELAX_SPAN: u32 = RELAX_TILE + 2u * RELAX_HALO;
const RELAX_CELLS: u32 = RELAX_SPAN * RELAX_SPAN;
const RELAX_THREADS: u32 = 256u;

// The tops of the workgroup's texels and halo, twice: the state before and after a step.
var<workgroup> tops: array<u32, 2u * RELAX_CELLS>;
var<workgroup> moved: atomic<u32>;
var<workgroup> moved_any: u32;
var<workgroup> skip_tile: u32;

// The record's tiles along x and z (the dispatch's workgroups that cover its rectangle).
fn tile_grid(r: RelaxRecord) -> vec2<u32> {
    let first = r.x0 / unit_texels(PRECISION) * unit_texels(PRECISION);
    return vec2<u32>((r.x0 - first + r.rect_width + RELAX_TILE - 1u) / RELAX_TILE, (r.rect_height + RELAX_TILE - 1u) / RELAX_TILE);
}

// Whether tile `t` of the record (and, with `around`, its eight neighbours within the grid) stood
// still in the last `relax_from_pool`.
fn tiles_still(r: RelaxRecord, t: vec2<u32>, around: bool) -> bool {
    let grid = vec2<i32>(tile_grid(r));
    let reach = select(0, 1, around);
    for (var dy = -reach; dy <= reach; dy++) {
        for (var dx = -reach; dx <= reach; dx++) {
            let n = vec2<i32>(t) + vec2<i32>(dx, dy);
            if all(n >= vec2<i32>(0)) && all(n < grid) {
                if relax_tiles[r.tiles + u32(n.y * grid.x + n.x)] == 0u {
                    return false;
                }
            }
        }
    }
    return true;
}

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

fn in_surface(r: RelaxRecord, p: vec2<i32>) -> bool {
    return p.x >= 0 && p.y >= 0 && p.x < i32(r.width) && p.y < i32(r.height);
}

fn in_rect(r: RelaxRecord, p: vec2<i32>) -> bool {
    return p.x >= i32(r.x0) && p.y >= i32(r.y0) && p.x < i32(r.x0 + r.rect_width) && p.y < i32(r.y0 + r.rect_height);
}

fn scratch_index(r: RelaxRecord, p: vec2<i32>) -> u32 {
    return r.scratch + (u32(p.y) - r.y0) * r.rect_width + (u32(p.x) - r.x0);
}

fn top_in_pool(r: RelaxRecord, p: vec2<i32>) -> u32 {
    return channel_max(PRECISION) - pool_texel(PRECISION, r.heights, r.width, r.height, r.wrap, u32(p.x), u32(p.y)).x;
}

// The workgroup's first texel: its tile's corner (at 8 bits, on an even column, so that the
// tile's units are whole).
fn tile_origin(r: RelaxRecord, wg: vec3<u32>) -> vec2<i32> {
    let first = r.x0 / unit_texels(PRECISION) * unit_texels(PRECISION);
    return vec2<i32>(i32(first + wg.x * RELAX_TILE), i32(r.y0 + wg.y * RELAX_TILE));
}

// The texel of cell `c` of the workgroup's span (tile and halo).
fn cell_texel(origin: vec2<i32>, c: u32) -> vec2<i32> {
    return origin - vec2<i32>(i32(RELAX_HALO)) + vec2<i32>(i32(c % RELAX_SPAN), i32(c / RELAX_SPAN));
}

// One step over the cells within `margin` of the span's edge: each texel of the rectangle from
// its top and its neighbours' in `tops[src..]`, into `tops[dst..]`; `moved` set where a top changed.
fn relax_step(r: RelaxRecord, origin: vec2<i32>, lid: u32, src: u32, dst: u32, margin: u32) {
    for (var c = lid; c < RELAX_CELLS; c += RELAX_THREADS) {
        let i = c % RELAX_SPAN;
        let j = c / RELAX_SPAN;
        if i < margin || j < margin || i >= RELAX_SPAN - margin || j >= RELAX_SPAN - margin {
            continue;
        }
        let p = cell_texel(origin, c);
        let t = tops[src + c];
        if !in_surface(r, p) || !in_rect(r, p) {
            tops[dst + c] = t;
            continue;
        }
        var out = 0u;
        var inn = 0u;
        let steps = array<vec2<i32>, 4>(vec2<i32>(-1, 0), vec2<i32>(1, 0), vec2<i32>(0, -1), vec2<i32>(0, 1));
        let cells = array<i32, 4>(-1, 1, -i32(RELAX_SPAN), i32(RELAX_SPAN));
        for (var k = 0u; k < 4u; k++) {
            if in_surface(r, p + steps[k]) {
                let f = flow(t, tops[src + u32(i32(c) + cells[k])], select(r.threshold_z, r.threshold_x, k < 2u));
                out += f.x;
                inn += f.y;
            }
        }
        let next = t - out + inn;
        tops[dst + c] = next;
        if next != t {
            atomicStore(&moved, 1u);
        }
    }
}

// The unit's texel `p` as the pool keeps it after the steps: its depression from the final tops
// `tops[at..]` inside the rectangle, its displaced channel kept; unchanged outside it.
fn settled(r: RelaxRecord, origin: vec2<i32>, at: u32, p: vec2<i32>) -> vec2<u32> {
    if p.x >= i32(r.width) {
        return vec2<u32>(0u); // the padding texel of an odd 8-bit row
    }
    let old = pool_texel(PRECISION, r.heights, r.width, r.height, r.wrap, u32(p.x), u32(p.y));
    if !in_rect(r, p) {
        return old;
    }
    let q = p - origin + vec2<i32>(i32(RELAX_HALO));
    let c = u32(q.y) * RELAX_SPAN + u32(q.x);
    return vec2<u32>(channel_max(PRECISION) - tops[at + c], old.y);
}

// Load the span, take `steps` steps, write the tile: to the pool (`to_pool`) or to `scratch`.
// Reading `scratch`, skip the tile when the flags say it stands still (`around`: it and its
// neighbours, before steps; else itself, for the copy).
fn relax_tile(wg: vec3<u32>, lid: u32, from_scratch: bool, to_pool: bool, steps: u32, around: bool) {
    let r = relax_records[wg.z];
    let origin = tile_origin(r, wg);
    if origin.x >= i32(r.x0 + r.rect_width) || origin.y >= i32(r.y0 + r.rect_height) {
        return;
    }
    if from_scratch {
        if lid == 0u {
            skip_tile = select(0u, 1u, tiles_still(r, wg.xy, around));
        }
        if workgroupUniformLoad(&skip_tile) == 1u {
            return;
        }
    }
    for (var c = lid; c < RELAX_CELLS; c += RELAX_THREADS) {
        let p = cell_texel(origin, c);
        var t = 0u;
        if in_surface(r, p) {
            if from_scratch && in_rect(r, p) {
                t = channel_max(PRECISION) - scratch[scratch_index(r, p)];
            } else {
                t = top_in_pool(r, p);
            }
        }
        tops[c] = t;
    }
    var at = 0u;
    var still = false;
    for (var k = 0u; k < steps; k++) {
        if lid == 0u {
            atomicStore(&moved, 0u);
        }
        workgroupBarrier();
        relax_step(r, origin, lid, at, RELAX_CELLS - at, k + 1u);
        at = RELAX_CELLS - at;
        workgroupBarrier();
        if lid == 0u {
            moved_any = atomicLoad(&moved);
        }
        if workgroupUniformLoad(&moved_any) == 0u {
            still = k == 0u;
            break;
        }
    }
    if !from_scratch && lid == 0u {
        let grid = tile_grid(r);
        relax_tiles[r.tiles + wg.y * grid.x + wg.x] = select(0u, 1u, still);
    }
    workgroupBarrier();
    if to_pool {
        let unit = unit_texels(PRECISION);
        let units = RELAX_TILE / unit;
        for (var c = lid; c < units * RELAX_TILE; c += RELAX_THREADS) {
            let p = origin + vec2<i32>(i32((c % units) * unit), i32(c / units));
            if p.x >= i32(r.x0 + r.rect_width) || p.y >= i32(r.y0 + r.rect_height) || p.x + i32(unit) <= i32(r.x0) {
                continue;
            }
            let a = settled(r, origin, at, p);
            var b = vec2<u32>(0u);
            if unit == 2u {
                b = settled(r, origin, at, p + vec2<i32>(1, 0));
            }
            pool_store_unit(PRECISION, r.heights, r.width, r.height, r.wrap, u32(p.x), u32(p.y), a, b);
        }
    } else {
        for (var c = lid; c < RELAX_TILE * RELAX_TILE; c += RELAX_THREADS) {
            let p = origin + vec2<i32>(i32(c % RELAX_TILE), i32(c / RELAX_TILE));
            if in_rect(r, p) {
                let q = p - origin + vec2<i32>(i32(RELAX_HALO));
                scratch[scratch_index(r, p)] = channel_max(PRECISION) - tops[at + u32(q.y) * RELAX_SPAN + u32(q.x)];
            }
        }
    }
}

@compute @workgroup_size(16, 16, 1)
fn relax_from_pool(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    relax_tile(wg, lid, false, false, relax_records[wg.z].dispatch_steps, true);
}

@compute @workgroup_size(16, 16, 1)
fn relax_to_pool(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    relax_tile(wg, lid, true, true, relax_records[wg.z].dispatch_steps, true);
}

@compute @workgroup_size(16, 16, 1)
fn relax_copy(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    relax_tile(wg, lid, true, true, 0u, false);
}
