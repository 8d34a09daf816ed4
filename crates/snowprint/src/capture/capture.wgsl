// Capture from below: renders deformers through an orthographic frustum whose near plane is the
// ground under the snow and whose far plane is the snow top plus an ankle height. Depth 0 = ground,
// 1 = top of the frustum. Each fragment keeps the lowest point per texel with an atomic max on an
// encoded depth in a storage buffer, so no depth target has to be cleared or resolved: the render
// target only places each surface's viewport and is never read or written.
//
// Reads: `view` (one per surface, dynamic offset), `prims` (analytic deformers in surface-local
// coordinates), mesh vertex buffers and `draw` (mesh-to-surface-local transform, dynamic offset).
// The viewport is the surface's capture region: its texels and the apron around them (write.wgsl).
// Writes: `capture`, the region's texels at `view.offset` (cleared to 0 = nothing before the pass),
// and `winding` at the same texels (cleared to 0): how many mesh solids contain the ground point
// under each texel; `tiles` at `view.tiles` (cleared to 0): 1 for every 16x16 tile of the update
// whose blur reads a texel written here, so the fused update skips the tiles nothing touched; and
// `tile_list` (count cleared to 0): each tile the first time it is flagged, as (record, tile), so
// the update can be dispatched over the flagged tiles alone.

// import capture_write

@group(0) @binding(0) var<uniform> view: CaptureView;
@group(0) @binding(1) var<storage, read> prims: array<Primitive>;
@group(0) @binding(2) var<storage, read_write> capture: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> winding: array<atomic<i32>>;
@group(0) @binding(4) var<storage, read_write> tiles: array<atomic<u32>>;
// Words 0-2: indirect dispatch arguments (written by the update's seal pass); 3: entries; from 4:
// two words an entry, the record and (tile y << 16 | tile x). TILE_LIST_HEADER is 4.
@group(0) @binding(5) var<storage, read_write> tile_list: array<atomic<u32>>;
// Per texel of each surface on ground that is not flat (ground/mod.rs, `GroundField::columns`):
// the base of the snow column (local metres: depth 0 of the frustum is there) and its bare depth
// (the rock between the base and the ground, where a slope holds less snow).
@group(0) @binding(6) var<storage, read> ground: array<vec2<f32>>;

// The region texel under a fragment of the surface's viewport.
fn cell_of(frag: vec2<f32>) -> vec2<u32> {
    return vec2<u32>(frag - view.origin);
}

struct PrimOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local_xz: vec2<f32>,
    @location(1) @interpolate(flat) index: u32,
}

fn to_clip(local_xz: vec2<f32>, depth: f32) -> vec4<f32> {
    // Column 0 is the smallest x and row 0 the smallest z: NDC y is +1 at row 0. The viewport
    // spans the region, the surface grown by the apron.
    let reach = region_half_of(view);
    return vec4<f32>(local_xz.x / reach.x, -local_xz.y / reach.y, depth, 1.0);
}

@vertex
fn vs_prim(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> PrimOut {
    let p = prims[ii];
    let f = prim_footprint(p);
    var lo = f.xy;
    var hi = f.zw;
    // Only the region is drawn: a footprint far larger than the surface would otherwise reach
    // clip coordinates where rasterizers lose precision (a sphere of radius 1e8 over a 2 m surface
    // filled half of it).
    let reach = region_half_of(view);
    lo = max(lo, -reach);
    hi = min(hi, reach);
    // Two triangles covering the footprint's bounding rectangle.
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
    );
    let xz = mix(lo, hi, corners[vi]);
    var out: PrimOut;
    out.clip = to_clip(xz, 0.5);
    out.local_xz = xz;
    out.index = ii;
    return out;
}

// The texel centre comes from the fragment's position (exactly k + 0.5) rather than from an
// interpolated varying, whose rounding a ray cast near a silhouette would amplify.
@fragment
fn fs_prim(in: PrimOut) {
    capture_prim(view, prims[in.index], cell_of(in.clip.xy), in.clip.xy - view.origin);
}

struct MeshDraw {
    to_local: mat4x4<f32>,
}
// Must match `MeshDraw` in capture/mod.rs.

@group(1) @binding(0) var<uniform> draw: MeshDraw;

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) height: f32,
}

@vertex
fn vs_mesh(@location(0) position: vec3<f32>) -> MeshOut {
    let local = draw.to_local * vec4<f32>(position, 1.0);
    var out: MeshOut;
    // No near or far clipping: the parts below the ground are needed to tell whether the ground
    // point lies inside the solid, and the fragment shader ignores what is above the frustum.
    out.clip = to_clip(local.xz, 0.5);
    out.height = local.y;
    return out;
}

@fragment
fn fs_mesh(in: MeshOut, @builtin(front_facing) front: bool) {
    // Meshes are closed and wound outward. Going up the vertical line under a texel, a face turned
    // towards the camera (down) enters a solid and a face turned away leaves one; below the ground
    // their signed count is the number of solids that contain the ground point, and where it is
    // positive the snow is pressed to the ground (depth clamping), however high the rest of the
    // solid reaches. Above the ground, the lowest entering face is the lowest point of the solids
    // that start there. A solid wholly inside the frustum presses exactly to its lowest point.
    // On ground that is not flat, heights are measured from the texel's base and "below the
    // ground" is below its bare depth.
    let cell = cell_of(in.clip.xy);
    let g = ground_of(view, cell);
    let height = in.height - g.x;
    if height < g.y {
        mark_tiles_of(view, cell);
        atomicAdd(&winding[texel_index_of(view, cell)], select(-1, 1, front));
    } else if front && height <= view.frustum_height {
        keep_lowest_of(view, cell, height / view.frustum_height);
    }
}
