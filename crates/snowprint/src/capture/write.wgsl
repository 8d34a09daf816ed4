// write.wgsl: what the capture's two paths share: the writes of one texel (the lowest depth, by an
// atomic max on the order-preserving code of cast.wgsl, and the tiles its blur reaches). The raster
// path (`capture.wgsl`, a fragment per texel of a primitive's rectangle or a mesh's face) and the
// compute path (`prims.wgsl`, a workgroup per 16 x 16 tile its primitives reach) ray-cast with the
// same functions (cast.wgsl) on the same texel centres, so they write the same bits. The importer
// declares `capture`, `tiles`, `tile_list` (read_write atomics) and `ground` (read).
//
// A surface's capture covers its capture region: its texels and an apron of APRON texels beyond
// each side (capture::region), so that the update's blur reads the field one texel beyond the
// surface as one surface over both would. A `cell` here is a texel of the region (cell - APRON is
// the surface's logical texel); the view's sizes are the surface's.

// import capture_cast

// Flag every tile of the surface holding a texel within one of region texel `cell` (the blur's
// reach): a texel of the apron flags the tile of the surface's texel beside it.
fn mark_tiles_of(v: CaptureView, cell_u: vec2<u32>) {
    let cell = vec2<i32>(cell_u) - vec2<i32>(i32(APRON));
    let last = vec2<i32>(v.texels) - vec2<i32>(1);
    let t0 = vec2<u32>(clamp(cell - vec2<i32>(1), vec2<i32>(0), last)) / TILE;
    let t1 = vec2<u32>(clamp(cell + vec2<i32>(1), vec2<i32>(0), last)) / TILE;
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let i = v.tiles + ty * v.tiles_x + tx;
            if v.record == NO_LIST {
                atomicStore(&tiles[i], 1u);
                continue;
            }
            // Most texels find their tiles flagged already: only the first lists a tile.
            if atomicLoad(&tiles[i]) == 0u && atomicExchange(&tiles[i], 1u) == 0u {
                let n = atomicAdd(&tile_list[3], 1u);
                atomicStore(&tile_list[TILE_LIST_HEADER + 2u * n], v.record);
                atomicStore(&tile_list[TILE_LIST_HEADER + 1u + 2u * n], (ty << 16u) | tx);
            }
        }
    }
}

fn texel_index_of(v: CaptureView, cell: vec2<u32>) -> u32 {
    return v.offset + cell.y * region_of(v).x + cell.x;
}

// Keep a depth at region texel `cell`: its tiles flagged, the lowest code kept.
fn keep_lowest_of(v: CaptureView, cell: vec2<u32>, depth: f32) {
    mark_tiles_of(v, cell);
    atomicMax(&capture[texel_index_of(v, cell)], depth_code(depth));
}

// Ray-cast primitive `p` under region texel `cell` (its centre `c` = cell + 0.5) and keep what it
// presses (the raster path's fragment).
fn capture_prim(v: CaptureView, p: Primitive, cell: vec2<u32>, c: vec2<f32>) {
    let code = prim_code(v, p, cell, c);
    if code != NO_HIT {
        mark_tiles_of(v, cell);
        atomicMax(&capture[texel_index_of(v, cell)], code);
    }
}

