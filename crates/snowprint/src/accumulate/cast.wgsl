// cast.wgsl (module `update_cast`): the fused update's own ray cast, for the records marked
// MODE_CAST (`CapturePath::Update`): no capture pass runs for them and no capture buffer holds
// them; a tile's workgroup finds the record's primitives that reach the texels its blur reads
// and keeps their footprints in workgroup memory (`cast_mask`), and each texel staged for the blur
// ray-casts those whose footprints hold its centre (`cast_depression`) with the capture's own
// functions (capture/cast.wgsl) at the same region texel centres, keeping the
// lowest code as the capture's atomic max does. So the depressions, and everything after them, are
// the bits the capture's paths give (tests/capture_paths.rs).
// The importer declares `prims: array<Primitive>` and `ground: array<vec2<f32>>` (read).

// import shared, maths, capture_cast

// The capture view a cast record stands for: what prim_code reads of one.
fn cast_view(rec: SurfaceRecord) -> CaptureView {
    var v: CaptureView;
    v.half_size = vec2<f32>(rec.half_x, rec.half_z);
    v.frustum_height = rec.frustum_height;
    v.texels = vec2<f32>(f32(rec.width), f32(rec.height));
    v.ground = rec.ground;
    v.prims = vec2<u32>(rec.prims, rec.prim_count);
    return v;
}

// The region cell of logical texel (x, y), clamped to the region as capture_read.wgsl's
// `depression` clamps its reads (a workgroup's staging past the surface's last tile).
fn cast_cell(rec: SurfaceRecord, x: i32, y: i32) -> vec2<u32> {
    let a = i32(APRON);
    let last = vec2<i32>(i32(rec.width + 2u * APRON), i32(rec.height + 2u * APRON)) - vec2<i32>(1);
    return vec2<u32>(clamp(vec2<i32>(x + a, y + a), vec2<i32>(0), last));
}

var<workgroup> cast_bits: atomic<u32>;
var<workgroup> cast_mask_shared: u32;
// The record's primitives' footprints clipped to the region as the capture draws them, by their
// index in the record, kept for the workgroup's ray casts by `cast_mask`. The primitives
// themselves are read from `prims` where a footprint holds a texel's centre: a copy in workgroup
// memory would hold fewer workgroups resident (docs/PERFORMANCE.md).
var<workgroup> cast_rects: array<vec4<f32>, CAST_PRIMS_MAX>;

// The record's primitives whose footprints reach the texel centres of the staging rectangle
// [first, first + side) (logical texels, clamped to the region), a bit each. Every invocation
// of the workgroup calls it, in uniform control flow; the result is uniform.
fn cast_mask(rec: SurfaceRecord, first: vec2<i32>, side: i32, lid: u32) -> u32 {
    if lid == 0u {
        atomicStore(&cast_bits, 0u);
    }
    workgroupBarrier();
    let v = cast_view(rec);
    if lid < rec.prim_count {
        let lo = texel_center_of(v, vec2<f32>(cast_cell(rec, first.x, first.y)) + vec2<f32>(0.5));
        let end = first + vec2<i32>(side - 1);
        let hi = texel_center_of(v, vec2<f32>(cast_cell(rec, end.x, end.y)) + vec2<f32>(0.5));
        let p = prims[rec.prims + lid];
        let f = prim_footprint(p);
        let reach = region_half_of(v);
        let f_lo = max(f.xy, -reach);
        let f_hi = min(f.zw, reach);
        if all(f_lo <= hi) && all(f_hi >= lo) {
            atomicOr(&cast_bits, 1u << lid);
            cast_rects[lid] = vec4<f32>(f_lo, f_hi);
        }
    }
    workgroupBarrier();
    if lid == 0u {
        cast_mask_shared = atomicLoad(&cast_bits);
    }
    return workgroupUniformLoad(&cast_mask_shared);
}

// Depression at logical texel (x, y) of a cast record from the primitives in `mask`: as
// `depression` reads it from a capture the paths wrote (nothing pressed: 0).
fn cast_depression(rec: SurfaceRecord, mask: u32, x: i32, y: i32) -> f32 {
    let v = cast_view(rec);
    let cell = cast_cell(rec, x, y);
    let c = vec2<f32>(cell) + vec2<f32>(0.5);
    let centre = texel_center_of(v, c);
    var best = 0u;
    var bits = mask;
    while bits != 0u {
        let k = firstTrailingBit(bits);
        bits &= bits - 1u;
        let f = cast_rects[k];
        if any(centre < f.xy) || any(centre > f.zw) {
            continue;
        }
        let code = prim_code(v, prims[rec.prims + k], cell, c);
        if code != NO_HIT {
            best = max(best, code);
        }
    }
    return capture_depression(rec, best);
}
