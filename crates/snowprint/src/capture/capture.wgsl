// Capture from below: renders deformers through an orthographic frustum whose near plane is the
// ground under the snow and whose far plane is the snow top plus an ankle height. Depth 0 = ground,
// 1 = top of the frustum. Each fragment keeps the lowest point per texel with an atomic max on an
// encoded depth in a storage buffer, so no depth target has to be cleared or resolved: the render
// target only places each surface's viewport and is never read or written.
//
// Reads: `view` (one per surface, dynamic offset), `prims` (analytic deformers in surface-local
// coordinates), mesh vertex buffers and `draw` (mesh-to-surface-local transform, dynamic offset).
// Writes: `capture`, the surface's texels at `view.offset` (cleared to 0 = nothing before the pass),
// and `winding` at the same texels (cleared to 0): how many mesh solids contain the ground point
// under each texel; `tiles` at `view.tiles` (cleared to 0): 1 for every 16x16 tile of the update
// whose blur reads a texel written here, so the fused update skips the tiles nothing touched; and
// `tile_list` (count cleared to 0): each tile the first time it is flagged, as (record, tile), so
// the update can be dispatched over the flagged tiles alone.

// import constants, ground_texel

struct CaptureView {
    half_size: vec2<f32>,   // half the surface's sides, metres
    frustum_height: f32,    // metres
    offset: u32,            // first texel of the surface in `capture`
    origin: vec2<f32>,      // the surface's top-left texel in the atlas
    texels: vec2<f32>,      // the surface's heightmap width and height
    tiles: u32,             // first tile flag of the surface in `tiles`
    tiles_x: u32,           // tiles a row
    record: u32,            // the surface's record in the update, or NO_LIST
    ground: u32,            // first texel of the surface's ground field in `ground`, or NO_GROUND
}
// Must match `CaptureView` in capture/mod.rs.

struct Primitive {
    // kind.x: PRIM_CAPSULE (a sphere is a capsule with a == b) or PRIM_BOX.
    kind: vec4<u32>,
    // capsule: p0 = segment start (xyz) and radius (w), p1 = segment end.
    // box: p0 = centre, p1/p2/p3 = unit axes (xyz) and half extents (w).
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
    p3: vec4<f32>,
}
// Must match `GpuPrimitive` in capture/mod.rs.

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

// Base and bare depth under a fragment's texel; flat ground is (0, 0), which leaves the maths below
// exactly as on a flat surface.
fn ground_at(frag: vec2<f32>) -> vec2<f32> {
    if view.ground == NO_GROUND {
        return vec2<f32>(0.0);
    }
    let cell = vec2<u32>(frag - view.origin);
    return ground_texel(view.ground, u32(view.texels.x), cell.x, cell.y);
}

// Flag every tile holding a texel within one of this one (the blur's reach).
fn mark_tiles(frag: vec2<f32>) {
    let cell = vec2<i32>(frag - view.origin);
    let last = vec2<i32>(view.texels) - vec2<i32>(1);
    let t0 = vec2<u32>(clamp(cell - vec2<i32>(1), vec2<i32>(0), last)) / TILE;
    let t1 = vec2<u32>(clamp(cell + vec2<i32>(1), vec2<i32>(0), last)) / TILE;
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let i = view.tiles + ty * view.tiles_x + tx;
            if view.record == NO_LIST {
                atomicStore(&tiles[i], 1u);
                continue;
            }
            // Most fragments find their tiles flagged already: only the first lists a tile.
            if atomicLoad(&tiles[i]) == 0u && atomicExchange(&tiles[i], 1u) == 0u {
                let n = atomicAdd(&tile_list[3], 1u);
                atomicStore(&tile_list[4u + 2u * n], view.record);
                atomicStore(&tile_list[5u + 2u * n], (ty << 16u) | tx);
            }
        }
    }
}

// Depths in [0, 1] are stored as ONE_BITS - bits(depth) (constants.wgsl): 0 (the cleared value) means nothing was
// captured, and a larger value is a lower point, so atomicMax keeps the lowest. Non-negative
// floats order like their bit patterns, so the code is exact and monotonic.

fn texel_index(frag: vec2<f32>) -> u32 {
    let cell = vec2<u32>(frag - view.origin);
    return view.offset + cell.y * u32(view.texels.x) + cell.x;
}

fn keep_lowest(frag: vec2<f32>, depth: f32) {
    mark_tiles(frag);
    atomicMax(&capture[texel_index(frag)], ONE_BITS - bitcast<u32>(clamp(depth, 0.0, 1.0)));
}

const BIG: f32 = 1e30;

struct PrimOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local_xz: vec2<f32>,
    @location(1) @interpolate(flat) index: u32,
}

fn to_clip(local_xz: vec2<f32>, depth: f32) -> vec4<f32> {
    // Column 0 is the smallest x and row 0 the smallest z: NDC y is +1 at row 0.
    return vec4<f32>(local_xz.x / view.half_size.x, -local_xz.y / view.half_size.y, depth, 1.0);
}

@vertex
fn vs_prim(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> PrimOut {
    let p = prims[ii];
    var lo: vec2<f32>;
    var hi: vec2<f32>;
    if p.kind.x == PRIM_CAPSULE {
        let r = p.p0.w;
        lo = min(p.p0.xz, p.p1.xz) - vec2<f32>(r);
        hi = max(p.p0.xz, p.p1.xz) + vec2<f32>(r);
    } else {
        let e = abs(p.p1.xz) * p.p1.w + abs(p.p2.xz) * p.p2.w + abs(p.p3.xz) * p.p3.w;
        lo = p.p0.xz - e;
        hi = p.p0.xz + e;
    }
    // Only the surface is drawn: a footprint far larger than the surface would otherwise reach
    // clip coordinates where rasterizers lose precision (a sphere of radius 1e8 over a 2 m surface
    // filled half of it).
    lo = max(lo, -view.half_size);
    hi = min(hi, view.half_size);
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

// Heights where the vertical line through (x, z) is inside the sphere. With d the line's distance
// from the centre and s = sqrt(r^2 - d^2), the ends c.y -+ s are computed as
// (c.y -+ r) +- d^2 / (r + s): c.y - r is where the sphere's bottom is (exact when the sphere rests
// near the ground, as c.y and r are then close), and the correction is small and has no
// cancellation, so a sphere much larger than the snow depth is still placed to the last bits
// rather than to the spacing of floats near r^2 (the naive c.y - sqrt(r^2 - d^2) is off by up to
// ulp(r^2) / 2r: 31 um at r = 1000, 0.4 mm at r = 1e4).
fn sphere_interval(c: vec3<f32>, r: f32, x: f32, z: f32) -> vec2<f32> {
    let dx = x - c.x;
    let dz = z - c.z;
    let d2 = dx * dx + dz * dz;
    let d = sqrt(d2);
    if d > r {
        return vec2<f32>(BIG, -BIG);
    }
    let s = sqrt((r - d) * (r + d));
    let sag = d2 / (r + s);
    return vec2<f32>((c.y - r) + sag, (c.y + r) - sag);
}

// Heights where the vertical line through (x, z) is inside the capsule (empty when x > y).
fn capsule_interval(a: vec3<f32>, b: vec3<f32>, r: f32, x: f32, z: f32) -> vec2<f32> {
    let ia = sphere_interval(a, r, x, z);
    let ib = sphere_interval(b, r, x, z);
    var iv = vec2<f32>(min(ia.x, ib.x), max(ia.y, ib.y));
    let ab = b - a;
    let len = length(ab);
    if len > 1e-6 {
        let u = ab / len;
        let w = vec3<f32>(x, 0.0, z) - a;
        let wu = dot(w, u);
        let e_perp = vec3<f32>(0.0, 1.0, 0.0) - u.y * u;
        let w_perp = w - wu * u;
        let qa = dot(e_perp, e_perp);
        if qa > 1e-6 {
            let qb = dot(e_perp, w_perp);
            let qc = dot(w_perp, w_perp) - r * r;
            let disc = qb * qb - qa * qc;
            if disc >= 0.0 {
                // The numerically stable pair of roots of qa y^2 + 2 qb y + qc = 0: no
                // cancellation when the capsule stands nearly upright (qa small).
                let sq = sqrt(disc);
                let q = -(qb + select(-sq, sq, qb >= 0.0));
                let r0 = q / qa;
                let r1 = select(qc / q, r0, q == 0.0);
                var y0 = min(r0, r1);
                var y1 = max(r0, r1);
                if abs(u.y) > 1e-6 {
                    let ya = -wu / u.y;
                    let yb = (len - wu) / u.y;
                    y0 = max(y0, min(ya, yb));
                    y1 = min(y1, max(ya, yb));
                } else if wu < 0.0 || wu > len {
                    y0 = BIG;
                    y1 = -BIG;
                }
                if y0 <= y1 {
                    iv = vec2<f32>(min(iv.x, y0), max(iv.y, y1));
                }
            }
        }
    }
    return iv;
}

fn box_interval(c: vec3<f32>, ax: vec4<f32>, ay: vec4<f32>, az: vec4<f32>, x: f32, z: f32) -> vec2<f32> {
    let o = vec3<f32>(x, 0.0, z) - c;
    var lo = -BIG;
    var hi = BIG;
    var axes = array<vec4<f32>, 3>(ax, ay, az);
    for (var i = 0; i < 3; i++) {
        let axis = axes[i];
        let oi = dot(o, axis.xyz);
        let ei = axis.y;
        let h = axis.w;
        if abs(ei) < 1e-7 {
            if abs(oi) > h {
                return vec2<f32>(BIG, -BIG);
            }
        } else {
            let t1 = (-h - oi) / ei;
            let t2 = (h - oi) / ei;
            lo = max(lo, min(t1, t2));
            hi = min(hi, max(t1, t2));
        }
    }
    return vec2<f32>(lo, hi);
}

// The local (x, z) of the texel centre under a fragment, computed from the fragment's position
// (exactly k + 0.5) the same way the CPU reference computes texel centres, rather than from an
// interpolated varying, whose rounding a ray cast near a silhouette would amplify.
fn texel_center(frag: vec2<f32>) -> vec2<f32> {
    let cell = frag - view.origin;
    return -view.half_size + cell / view.texels * 2.0 * view.half_size;
}

@fragment
fn fs_prim(in: PrimOut) {
    let p = prims[in.index];
    let c = texel_center(in.clip.xy);
    var iv: vec2<f32>;
    if p.kind.x == PRIM_CAPSULE {
        iv = capsule_interval(p.p0.xyz, p.p1.xyz, p.p0.w, c.x, c.y);
    } else {
        iv = box_interval(p.p0.xyz, p.p1, p.p2, p.p3, c.x, c.y);
    }
    // Heights above the texel's base. Keep only the part inside the frustum: a solid reaching below
    // the ground (the bare depth above the base) is clamped to the ground, one entirely below it or
    // above the frustum leaves nothing.
    let g = ground_at(in.clip.xy);
    iv -= vec2<f32>(g.x);
    if iv.x > iv.y || iv.y < g.y || iv.x >= view.frustum_height {
        return;
    }
    keep_lowest(in.clip.xy, max(iv.x, g.y) / view.frustum_height);
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
    let g = ground_at(in.clip.xy);
    let height = in.height - g.x;
    if height < g.y {
        mark_tiles(in.clip.xy);
        atomicAdd(&winding[texel_index(in.clip.xy)], select(-1, 1, front));
    } else if front && height <= view.frustum_height {
        keep_lowest(in.clip.xy, height / view.frustum_height);
    }
}
