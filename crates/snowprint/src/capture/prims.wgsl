// The capture's compute path for analytic deformers: a workgroup per 16 x 16 tile of a surface's
// capture region (its texels and the apron, write.wgsl) that its primitives reach (the plan's work
// list), every invocation one texel. The workgroup first
// gathers the primitives whose footprints reach its tile; each texel then ray-casts those whose
// footprint holds its centre and keeps the lowest, as the raster path's fragments do
// (`write.wgsl`, shared), and writes it once. The work list holds each tile once; for a region
// whose reached tiles are few it holds the tiles beside them too (`capture::tiles_reached`), and
// such a region (`whole`) is not cleared before: its workgroups write every texel, 0 where nothing
// presses, so every texel the update may read of it is written this frame. Surfaces that meshes press, or with more
// primitives than `COMPUTE_PRIMS_MAX`, take the raster path (`capture.wgsl`); their views have no
// primitives here and no entry in the work list.
//
// Dispatch: a workgroup an entry of the work list (x + y * 65535), each entry a tile that some
// primitive's footprint reaches on a surface of the compute path.
// Reads: `table` (the capture's views and the work list), `prims`, `ground`.
// Writes: `capture`, `tiles`, `tile_list`, as the raster path does.

// import capture_write

// The capture's view blocks (VIEW_WORDS words apart, as the raster path's uniform blocks lie), then
// the work list, two words an entry: the view and (tile y << 16 | tile x); the last two words give
// the list's first word and its length.
@group(0) @binding(0) var<storage, read> table: array<u32>;
@group(0) @binding(1) var<storage, read> prims: array<Primitive>;
@group(0) @binding(2) var<storage, read_write> capture: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> tiles: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> tile_list: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read> ground: array<vec2<f32>>;

// Words between two views in `table`: the uniform blocks' stride, 256 bytes.
const VIEW_WORDS: u32 = 64u;

fn float_at(i: u32) -> f32 {
    return bitcast<f32>(table[i]);
}

// View `k`, read word by word in `CaptureView`'s field order.
fn view_at(k: u32) -> CaptureView {
    let b = k * VIEW_WORDS;
    return CaptureView(
        vec2<f32>(float_at(b), float_at(b + 1u)),
        float_at(b + 2u),
        table[b + 3u],
        vec2<f32>(float_at(b + 4u), float_at(b + 5u)),
        vec2<f32>(float_at(b + 6u), float_at(b + 7u)),
        table[b + 8u],
        table[b + 9u],
        table[b + 10u],
        table[b + 11u],
        vec2<u32>(table[b + 12u], table[b + 13u]),
        table[b + 14u],
    );
}

// The primitives whose footprints reach this workgroup's tile, gathered once by the whole
// workgroup (a primitive an invocation), so that each texel ray-casts only those.
var<workgroup> hits: array<u32, 256>;
var<workgroup> hit_count: atomic<u32>;

@compute @workgroup_size(16, 16)
fn capture_prims(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    // Every return before the barriers depends on the workgroup alone.
    let n_words = arrayLength(&table);
    let list = table[n_words - 2u];
    // Rows of `groups.x` workgroups (gpu::resources::dispatch_rows).
    let entry = wg.x + wg.y * groups.x;
    if entry >= table[n_words - 1u] {
        return;
    }
    let v = view_at(table[list + 2u * entry]);
    let packed = table[list + 2u * entry + 1u];
    let tile = vec2<u32>(packed & 0xffffu, packed >> 16u);
    let size = region_of(v);
    let first = tile * TILE;
    let last = min(first + vec2<u32>(TILE - 1u), size - vec2<u32>(1u));
    // The tile's texel centres span [lo, hi] (local x, z).
    let lo = texel_center_of(v, vec2<f32>(first) + vec2<f32>(0.5));
    let hi = texel_center_of(v, vec2<f32>(last) + vec2<f32>(0.5));
    let cell = first + lid.xy;
    let inside = all(cell <= last);
    let c = vec2<f32>(cell) + vec2<f32>(0.5);
    let x = texel_center_of(v, c);
    let end = v.prims.x + v.prims.y;
    var hit = false;
    var best = 0u;
    for (var base = v.prims.x; base < end; base += 256u) {
        if li == 0u {
            atomicStore(&hit_count, 0u);
        }
        workgroupBarrier();
        let i = base + li;
        if i < end {
            let f = prim_footprint(prims[i]);
            if all(f.xy <= hi) && all(f.zw >= lo) {
                hits[atomicAdd(&hit_count, 1u)] = i;
            }
        }
        workgroupBarrier();
        let n = atomicLoad(&hit_count);
        for (var h = 0u; h < n && inside; h++) {
            let p = prims[hits[h]];
            // The raster path draws only the footprint's rectangle (clipped to the region): the
            // same texels here, and the ray cast decides as there.
            let f = prim_footprint(p);
            let reach = region_half_of(v);
            if any(x < max(f.xy, -reach)) || any(x > min(f.zw, reach)) {
                continue;
            }
            let code = prim_code(v, p, cell, c);
            if code != NO_HIT {
                hit = true;
                best = max(best, code);
            }
        }
        workgroupBarrier();
    }
    // The workgroup is the only one of the frame on its tile. Over a region that is not cleared
    // (`whole`) it writes every texel, 0 where nothing presses; over a cleared one, only where
    // something does.
    if inside && (hit || v.whole != 0u) {
        atomicStore(&capture[texel_index_of(v, cell)], best);
    }
    if inside && hit {
        mark_tiles_of(v, cell);
    }
}
