// Blur and merge in one pass, in place, for GPUs where a pass costs more than its memory
// traffic. A workgroup (16x16 invocations; `fused_cast_many`'s, CAST_THREADS) stages the
// depressions of its tile with a one-texel apron (18x18) in workgroup memory, then merges its units
// (two texels along x at 8 bits, one otherwise; 16 is even, so a unit never straddles tiles) into
// the heights region, each texel blurred from there as it is merged.
// A texel's new value depends only on its own old value, so updating in place is safe whatever
// order the workgroups run in.
// Snowfall: a record marked MODE_REFILLED was refilled over its whole region by refill.wgsl
// before this pass, so here it replenishes nothing and changes only where the capture reached
// (deepening a refilled texel equals merging with the refill: accumulate::cpu::refill_word);
// any other record that refills snow has every tile refilled here.
// Four entry points share that work: `fused`, a grid over every tile of a run of records, from
// the one the tile list's header names (a tile with nothing to deepen or refill leaves at once),
// and `fused_listed`, one workgroup per tile in the capture's tile list for the records whose
// every tile the grid does not take (a record refilled here and not by refill.wgsl), dispatched
// indirectly (seal.wgsl writes the arguments). A record marked MODE_CAST has no capture:
// `fused_cast` or `fused_cast_many` takes its tiles from the plan's entries at the head of the
// tile list, and ray-casts its primitives itself (cast.wgsl).
// Reads: `records`, `tiles`, `tile_list`, `capture`, `winding`, `prims`, `ground`, each record's
// heights in `pool`.
// Writes: the same heights regions.
// CPU reference: accumulate::cpu::blur then merge_channels. Maths: maths.wgsl, capture_read.wgsl,
// cast.wgsl.

// import maths, capture_read, texel_write, update_cast

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read_write> pool: array<u32>;
@group(0) @binding(3) var<storage, read> winding: array<i32>;
@group(0) @binding(4) var<storage, read> tiles: array<u32>;
@group(0) @binding(5) var<storage, read> tile_list: array<u32>;
@group(0) @binding(6) var<storage, read> prims: array<Primitive>;
@group(0) @binding(7) var<storage, read> ground: array<vec2<f32>>;

const SIDE: i32 = i32(TILE);
const DEP: i32 = 18;    // SIDE + 1 texel of apron on each side
var<workgroup> depressions: array<f32, 324>;   // DEP * DEP
// `fused_cast_many`'s workgroup: half a tile's units an invocation, so that twice as many of its
// tiles, each waiting on a chain of dependent reads (entry, record, primitives), are resident at
// once. Measured on the H100 against 64, 96, 192 and 256 (docs/PERFORMANCE.md): 64 is faster
// only from about 20,000 tiles (a frame of 1024 surfaces of 128^2), slower below. The workgroup
// memory is kept small for the same reason (the depressions, and cast.wgsl's footprints: no
// blurred copy, no primitives).
const CAST_THREADS: u32 = 128u;
// The most units an invocation takes (SIDE * SIDE / CAST_THREADS).
const UNIT_SLOTS: u32 = 2u;
const_assert UNIT_SLOTS * CAST_THREADS == TILE * TILE;
// cast_mask (cast.wgsl) tests a primitive an invocation.
const_assert CAST_PRIMS_MAX <= CAST_THREADS;

@compute @workgroup_size(TILE, TILE, 1)
fn fused(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
) {
    // The grid covers the records from the one the list's header names (before it: cast records
    // that refill snow, whose tiles are `fused_cast`'s, as those of every cast record).
    let rec = records[tile_list[TILE_LIST_GRID_FIRST] + wid.z];
    // Whole workgroups past the surface leave together, before any barrier.
    let past = i32(wid.x) * SIDE >= i32(rec.width) || i32(wid.y) * SIDE >= i32(rec.height);
    if past || (rec.mode & MODE_CAST) != 0u {
        return;
    }
    var has_capture = rec.batch != NO_CAPTURE;
    if has_capture {
        let tiles_x = (rec.width + u32(SIDE) - 1u) / u32(SIDE);
        has_capture = tiles[rec.tiles + wid.y * tiles_x + wid.x] != 0u;
    }
    // Nothing to deepen and nothing to refill: the tile stays as it is (uniform per workgroup,
    // before any barrier).
    let rep = replenished(rec);
    if !has_capture && rep == 0u {
        return;
    }
    update_tile(rec, wid.xy, has_capture, false, rep, lid, TILE * TILE);
}

@compute @workgroup_size(TILE, TILE, 1)
fn fused_listed(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let e = list_entry(wid, groups);
    if !e.listed {
        return;
    }
    let rec = records[e.record];
    // A record refilled here has all its tiles updated by `fused`; a cast record's listed tiles
    // are `fused_cast`'s.
    let rep = replenished(rec);
    if rep != 0u || (rec.mode & MODE_CAST) != 0u {
        return;
    }
    update_tile(rec, e.tile, true, false, 0u, lid, TILE * TILE);
}

// The tiles of the cast records, which the plan lists first in `tile_list` (all of a record's
// tiles where this pass refills it, else those its primitives' footprints reach, a margin
// around), one workgroup an entry; dispatched over those entries alone, so an entry past them
// (the capture's, of a record that is not cast) leaves at once. Two entry points: `fused_cast`,
// a 16x16 workgroup a tile, for a few tiles (the whole list resident at once: each tile's chain
// of reads is the pass's time, and more invocations a tile shorten it), and `fused_cast_many`,
// CAST_THREADS a tile, for many (`WorldConfig::cast_many_from`).
@compute @workgroup_size(TILE, TILE, 1)
fn fused_cast(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    cast_tile(lid, wid, groups, TILE * TILE);
}

@compute @workgroup_size(CAST_THREADS, 1, 1)
fn fused_cast_many(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    cast_tile(lid, wid, groups, CAST_THREADS);
}

// The cast tile of workgroup `wid`, by a workgroup of `threads` invocations.
fn cast_tile(lid: u32, wid: vec3<u32>, groups: vec3<u32>, threads: u32) {
    let e = list_entry(wid, groups);
    if !e.listed {
        return;
    }
    let rec = records[e.record];
    if (rec.mode & MODE_CAST) == 0u {
        return;
    }
    update_tile(rec, e.tile, true, true, replenished(rec), lid, threads);
}

// An entry of the tile list: its record and tile, where the workgroup's index is within the
// list's count.
struct Entry {
    listed: bool,
    record: u32,
    tile: vec2<u32>,
}

// The entry of workgroup `wid` of a dispatch over the list of `groups.x` workgroups a row (x + y
// * groups.x: gpu::resources::dispatch_rows, seal.wgsl).
fn list_entry(wid: vec3<u32>, groups: vec3<u32>) -> Entry {
    let i = wid.x + wid.y * groups.x;
    if i >= tile_list[3] {
        return Entry(false, 0u, vec2<u32>(0u));
    }
    let t = tile_list[TILE_LIST_HEADER + 1u + 2u * i];
    return Entry(true, tile_list[TILE_LIST_HEADER + 2u * i], vec2<u32>(t & 0xffffu, t >> 16u));
}

// Units this pass replenishes a record by: none where refill.wgsl refilled it.
fn replenished(rec: SurfaceRecord) -> u32 {
    return select(rec.replenish_units, 0u, (rec.mode & MODE_REFILLED) != 0u);
}

// Blur and merge one tile of a surface, replenished by `rep` units, in place, by a workgroup of
// `threads` invocations (256 or CAST_THREADS, a constant of each entry point), invocation `lid`
// taking the tile's units lid, lid + threads, ... A cast record's (`casts`, a constant of each
// entry point, so that the others compile without the ray cast) depressions are ray-cast from its
// primitives that reach the tile, and it has a capture where one does. Called from uniform
// control flow.
fn update_tile(
    rec: SurfaceRecord, tile_id: vec2<u32>, captured: bool, casts: bool, rep: u32, lid: u32,
    threads: u32,
) {
    let tile = vec2<u32>(tile_id) * u32(SIDE);
    let per = unit_texels(PRECISION);
    // Where the depressions are read from a capture, the units' old texels are loaded first, so
    // that their reads wait beside the capture's rather than after the blur. A cast reads no
    // capture: its units are loaded after the cast, so that nothing is held through it.
    var old: array<Old, UNIT_SLOTS>;
    if !casts {
        for (var j = 0u; j < UNIT_SLOTS; j++) {
            old[j] = old_unit(rec, unit_of(rec, tile, per, lid + j * threads));
        }
    }
    let dep_origin = vec2<i32>(tile) - vec2<i32>(1);
    var has_capture = captured;
    var mask = 0u;
    if casts {
        mask = cast_mask(rec, dep_origin, DEP, lid);
        has_capture = mask != 0u;
        if !has_capture && rep == 0u {
            return;
        }
    }
    if has_capture {
        for (var k = i32(lid); k < DEP * DEP; k += i32(threads)) {
            let x = dep_origin.x + k % DEP;
            let y = dep_origin.y + k / DEP;
            if casts {
                depressions[k] = cast_depression(rec, mask, x, y);
            } else {
                depressions[k] = depression(rec, x, y);
            }
        }
    }
    workgroupBarrier();
    for (var j = 0u; j < UNIT_SLOTS; j++) {
        let u = unit_of(rec, tile, per, lid + j * threads);
        if !u.writes {
            continue;
        }
        if casts {
            old[j] = old_unit(rec, u);
        }
        let at = vec2<u32>(u.x, u.y) - tile;
        let a = merge_channels(old[j].a, blurred_at(at, has_capture), has_capture, rep);
        var b = vec2<u32>(0u);
        if u.pair {
            let right = blurred_at(at + vec2<u32>(1u, 0u), has_capture);
            b = merge_channels(old[j].b, right, has_capture, rep);
        }
        pool_store_unit(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, u.x, u.y, a, b);
    }
}

// A unit's old texels: its first, and its second where it has one.
struct Old {
    a: vec2<u32>,
    b: vec2<u32>,
}

// The old texels of unit `u` (zeros where it writes nothing).
fn old_unit(rec: SurfaceRecord, u: Unit) -> Old {
    var o = Old(vec2<u32>(0u), vec2<u32>(0u));
    if u.writes {
        o.a = pool_texel(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, u.x, u.y);
        if u.pair {
            o.b = pool_texel(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, u.x + 1u, u.y);
        }
    }
    return o;
}

// The blurred depression of texel `at` of the tile, from the staged depressions (where the tile
// has a capture; else 0, which no merge without one reads).
fn blurred_at(at: vec2<u32>, has_capture: bool) -> f32 {
    if !has_capture {
        return 0.0;
    }
    // Texel `at` of the tile sits one texel in, in the depression tile.
    let i = (i32(at.y) + 1) * DEP + i32(at.x) + 1;
    return blur_taps(
        depressions[i - DEP - 1], depressions[i - DEP], depressions[i - DEP + 1],
        depressions[i - 1], depressions[i], depressions[i + 1],
        depressions[i + DEP - 1], depressions[i + DEP], depressions[i + DEP + 1],
    );
}

// A unit of a tile: its first texel (x, y) of the surface, whether it is one to write (within
// the tile's units and the surface) and whether it has a second texel within the surface.
struct Unit {
    x: u32,
    y: u32,
    writes: bool,
    pair: bool,
}

// Unit `n` of the tile whose first texel is `tile`, `per` texels a unit (two texels along x at 8
// bits, one otherwise; 16 is even, so a unit never straddles tiles): row n / (SIDE / per), first
// column (n % (SIDE / per)) * per.
fn unit_of(rec: SurfaceRecord, tile: vec2<u32>, per: u32, n: u32) -> Unit {
    let row_units = u32(SIDE) / per;
    let x = tile.x + (n % row_units) * per;
    let y = tile.y + n / row_units;
    let writes = n < u32(SIDE * SIDE) / per && x < rec.width && y < rec.height;
    return Unit(x, y, writes, writes && per == 2u && x + 1u < rec.width);
}
