// dice.wgsl: runtime dicing of a snow surface's mesh on the GPU (the talk's tessellation, without
// hull and domain shaders). One workgroup per triangle of the surface's base mesh (the rectangle
// of the surface cut into cells, or a mesh the user gave, in the surface's local frame):
//   1. cull the triangle's box (base mesh up to the highest the snow can reach) against the view
//      and the moon's near shadow cascade (snow just out of view still shadows what is in it);
//   2. a level per edge, a function of the edge alone (its endpoints in a canonical order, lower
//      vertex id first): projected length in pixels over the target, scaled by the relief of the
//      heightfield along the edge (finer where there are prints and banks) and by how much the
//      ground field bends along it (finer over hills, not on a plane), at most one segment
//      per half texel and MAX level;
//   3. an inner level N = max(edge levels, 3): a uniform lattice of level N inside, whose outermost
//      ring is replaced by three strips stitched between each edge's own points and the inner
//      lattice. A shared edge is cut by both triangles into the same points, computed by the same
//      expression from the same canonical endpoints, so positions match bit for bit: no cracks,
//      no T-junctions;
//   4. skirts on the edges of the base mesh that no other triangle shares: a wall from the snow's
//      displaced top down to the base, so open edges never show a gap. Where the edge meets
//      another surface's snow (a seam: render/tessellate/seams.rs) the skirt closes the step
//      between the two tops and is marked to be shaded as the top.
// Vertices (two vec4 each: local position with the base height and a kind; the skirt's outward
// normal) and indices are appended with atomic counters; `seal` then writes the surface's
// indexed indirect draw. Displacement happens in the vertex stage (tess_surface.wgsl).
// Reads: dice params, base triangles, the heightfield and bank textures, the surface state, the
// ground fields.
// Writes: diced vertices, indices, counters and the surface's draw arguments.
// CPU reference of the topology: render::tessellate::cpu::dice_triangle.

// import constants, ground_texel

// Must match `DiceParams` in src/render/tessellate/mod.rs.
struct DiceParams {
    local_to_clip: mat4x4<f32>,
    eye: vec4<f32>,          // xyz: the camera in the surface's local frame; w: pixels per radian
    settings: vec4<f32>,     // x: target edge length in pixels, y: max level, z: shortest segment (m), w: detail floor
    extent: vec4<f32>,       // x: snow depth, y: how far above the snow top banks and waves reach, z: lowest base of the ground field, w: its highest ground (both 0 on flat ground)
    grid: vec4<u32>,         // xy: heightfield size, z: surface slot, w: base triangles
    capacity: vec4<u32>,     // x: vertex capacity, y: index capacity, z: first texel of the ground field (NO_GROUND on flat ground)
    half_size: vec4<f32>,    // xy: half the surface's sides
    local_to_shadow: mat4x4<f32>, // surface-local to the moon's near shadow cascade
}

// Must match `BaseTriangle` in mod.rs.
struct BaseTriangle {
    a: vec4<f32>,            // xyz local position (y: base height), w unused
    b: vec4<f32>,
    c: vec4<f32>,
    ids: vec4<u32>,          // xyz: vertex ids of a, b, c; w: bit e set when edge e is a border, its seam mark at bit SEAM_SHIFT + 4e
}

// Samples of the heightfield along an edge for its relief.
const DETAIL_SAMPLES: u32 = 16u;

const KIND_TOP: f32 = 0.0;
const KIND_SKIRT_TOP: f32 = 1.0;
const KIND_SKIRT_BOTTOM: f32 = 2.0;

@group(0) @binding(0) var<uniform> dice: DiceParams;
@group(0) @binding(1) var<storage, read> triangles: array<BaseTriangle>;
@group(0) @binding(2) var shape: texture_2d<f32>;
@group(0) @binding(3) var banks: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> state: array<u32>;
@group(0) @binding(5) var<storage, read_write> vertices: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> indices: array<u32>;
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>>;
// The world's ground fields (`ground_texel`); this surface's starts at `dice.capacity.z`.
@group(0) @binding(8) var<storage, read> ground: array<vec2<f32>>;

var<workgroup> levels: array<u32, 3>;
var<workgroup> inner_level: u32;
var<workgroup> vertex_base: u32;
var<workgroup> index_base: u32;
var<workgroup> keep: u32;

fn touched() -> bool {
    return state[dice.grid.z * STATE_WORDS + STATE_TOUCHED] != 0u;
}

// Base of the snow column at a local (x, z), nearest texel (on ground that is not flat).
fn ground_base(xz: vec2<f32>) -> f32 {
    let size = vec2<i32>(dice.grid.xy);
    let uv = (xz + dice.half_size.xy) / (2.0 * dice.half_size.xy);
    let t = clamp(vec2<i32>(floor(uv * vec2<f32>(size))), vec2<i32>(0), size - 1);
    return ground_texel(dice.capacity.z, dice.grid.x, u32(t.x), u32(t.y)).x;
}

// How far the ground bends away from the straight line between an edge's ends (a plane needs no
// more than its ends; hills do), as a fraction of a quarter of the snow depth, at most 1.
fn ground_bend(p0: vec3<f32>, p1: vec3<f32>) -> f32 {
    let g0 = ground_base(p0.xz);
    let g1 = ground_base(p1.xz);
    var bend = 0.0;
    for (var i = 1u; i < DETAIL_SAMPLES; i++) {
        let f = f32(i) / f32(DETAIL_SAMPLES);
        bend = max(bend, abs(ground_base(edge_point(p0, p1, i, DETAIL_SAMPLES).xz) - mix(g0, g1, f)));
    }
    return clamp(bend / (0.25 * dice.extent.x), 0.0, 1.0);
}

// Snow height (metres above the base) at a local (x, z), nearest texel: depression and banks.
fn field_height(xz: vec2<f32>) -> f32 {
    let size = vec2<i32>(dice.grid.xy);
    let uv = (xz + dice.half_size.xy) / (2.0 * dice.half_size.xy);
    // Both textures hold a border (heightfield.wgsl, banks.wgsl): on the far edges (uv = 1) the
    // nearest texel is the first past the line, which a surface beside reads as its edge's, so
    // that both dice the line alike.
    let t = clamp(vec2<i32>(floor(uv * vec2<f32>(size))), vec2<i32>(0), size) + HEIGHTFIELD_BORDER;
    let dep = textureLoad(shape, t, 0).x;
    return dice.extent.x * (1.0 - dep) + textureLoad(banks, t, 0).x;
}

// The one expression that places a point on an edge: both triangles sharing the edge call it with
// the same canonical endpoints and step, so the point is the same to the bit.
fn edge_point(p0: vec3<f32>, p1: vec3<f32>, k: u32, level: u32) -> vec3<f32> {
    let f = f32(k) / f32(level);
    return p0 * (1.0 - f) + p1 * f;
}

// Level of the edge p0 -> p1 (p0 the endpoint with the lower id): a function of the edge alone.
fn edge_level(p0: vec3<f32>, p1: vec3<f32>) -> u32 {
    let len = distance(p0, p1);
    // On ground that is not flat the snow lies somewhere in the field's range: its middle stands
    // for it (the level stays a function of the edge alone).
    let mid = 0.5 * (p0 + p1) + vec3<f32>(0.0, dice.extent.x + 0.5 * (dice.extent.z + dice.extent.w), 0.0);
    let dist = max(distance(mid, dice.eye.xyz), 1e-3);
    // Projected length by the distance to the middle: robust for edges behind the camera.
    let pixels = len / dist * dice.eye.w;
    var detail = 0.0;
    if touched() {
        var lo = 1e9;
        var hi = -1e9;
        for (var i = 0u; i <= DETAIL_SAMPLES; i++) {
            let q = edge_point(p0, p1, i, DETAIL_SAMPLES);
            let h = field_height(q.xz);
            lo = min(lo, h);
            hi = max(hi, h);
        }
        detail = clamp((hi - lo) / (0.25 * dice.extent.x), 0.0, 1.0);
    }
    if dice.capacity.z != NO_GROUND {
        detail = max(detail, ground_bend(p0, p1));
    }
    let want = pixels / dice.settings.x * mix(dice.settings.w, 1.0, detail);
    let finest = len / dice.settings.z;
    return u32(clamp(ceil(min(want, finest)), 1.0, dice.settings.y));
}

fn corner(t: BaseTriangle, i: u32) -> vec3<f32> {
    switch i {
        case 0u: { return t.a.xyz; }
        case 1u: { return t.b.xyz; }
        default: { return t.c.xyz; }
    }
}

fn corner_id(t: BaseTriangle, i: u32) -> u32 {
    switch i {
        case 0u: { return t.ids.x; }
        case 1u: { return t.ids.y; }
        default: { return t.ids.z; }
    }
}

// Point k (0..level) of the triangle's edge e, walking in the triangle's own direction.
fn outer_point(t: BaseTriangle, e: u32, k: u32) -> vec3<f32> {
    let s = (e + 0u) % 3u;
    let u = (e + 1u) % 3u;
    let level = levels[e];
    if k == 0u {
        return corner(t, s);
    }
    if k == level {
        return corner(t, u);
    }
    if corner_id(t, s) < corner_id(t, u) {
        return edge_point(corner(t, s), corner(t, u), k, level);
    }
    return edge_point(corner(t, u), corner(t, s), level - k, level);
}

// Local index of point k of edge e's outer polyline (k == level is the next edge's first point).
fn outer_index(e_in: u32, k_in: u32) -> u32 {
    var e = e_in;
    var k = k_in;
    if k == levels[e] {
        e = (e + 1u) % 3u;
        k = 0u;
    }
    var o = 0u;
    for (var i = 0u; i < e; i++) {
        o += levels[i];
    }
    return o + k;
}

fn outer_count() -> u32 {
    return levels[0] + levels[1] + levels[2];
}

// Inner lattice point (i, j) of level N, i, j >= 1, i + j <= N - 1: local index.
fn inner_index(i: u32, j: u32) -> u32 {
    let n = inner_level;
    let off = (j - 1u) * (n - 1u) - ((j - 1u) * j) / 2u;
    return outer_count() + off + (i - 1u);
}

fn inner_point(t: BaseTriangle, i: u32, j: u32) -> vec3<f32> {
    let n = f32(inner_level);
    let wb = f32(i) / n;
    let wc = f32(j) / n;
    return t.a.xyz * (1.0 - wb - wc) + t.b.xyz * wb + t.c.xyz * wc;
}

// Inner polyline of edge e (the inner lattice's side parallel to it, same direction): point m of
// N - 2, as lattice coordinates.
fn inner_side(e: u32, m: u32) -> vec2<u32> {
    let n = inner_level;
    switch e {
        case 0u: { return vec2<u32>(1u + m, 1u); }
        case 1u: { return vec2<u32>(n - 2u - m, 1u + m); }
        default: { return vec2<u32>(1u, n - 2u - m); }
    }
}

// Slope of a base triangle's plane (dy/dx, dy/dz in the surface's frame), which top vertices carry
// so that the snow on a pitched roof shades as sloped (vertical triangles count as flat).
fn base_slope(t: BaseTriangle) -> vec2<f32> {
    var n = cross(t.b.xyz - t.a.xyz, t.c.xyz - t.a.xyz);
    if abs(n.y) < 1e-6 {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(-n.x / n.y, -n.z / n.y);
}

fn put_vertex(at: u32, p: vec3<f32>, kind: f32, n: vec2<f32>) {
    put_vertex_marked(at, p, kind, n, 0.0);
}

// A vertex whose second vec4 has `w` (1 on a seam's skirt: shaded as the top, `n` the base's slope).
fn put_vertex_marked(at: u32, p: vec3<f32>, kind: f32, n: vec2<f32>, w: f32) {
    vertices[2u * at] = vec4<f32>(p, kind);
    vertices[2u * at + 1u] = vec4<f32>(n.x, 0.0, n.y, w);
}

fn put_triangle(at: u32, a: u32, b: u32, c: u32) {
    indices[at] = vertex_base + a;
    indices[at + 1u] = vertex_base + b;
    indices[at + 2u] = vertex_base + c;
}

fn inner_vertices() -> u32 {
    let n = inner_level;
    return ((n - 1u) * (n - 2u)) / 2u;
}

fn inner_triangles() -> u32 {
    let n = inner_level;
    return (n - 3u) * (n - 3u);
}

fn strip_triangles(e: u32) -> u32 {
    return levels[e] + inner_level - 3u;
}

fn is_border(t: BaseTriangle, e: u32) -> bool {
    return (t.ids.w & (1u << e)) != 0u;
}

// Whether border edge e meets another surface's snow this frame (render/tessellate/seams.rs):
// the hole of a finer level, or a side the dicing parameters' mask (`capacity.w`) names.
fn is_seam(t: BaseTriangle, e: u32) -> bool {
    let mark = (t.ids.w >> (SEAM_SHIFT + 4u * e)) & 15u;
    if mark == SEAM_HOLE {
        return true;
    }
    return mark >= SEAM_SIDE && mark < SEAM_SIDE + 4u && ((dice.capacity.w >> (mark - SEAM_SIDE)) & 1u) != 0u;
}

// Whether the box of the triangle (from its base up to the highest snow, widened by the ground
// field's range) is outside both the view
// and the near shadow cascade: then it neither shows nor shadows anything that shows.
fn culled(t: BaseTriangle) -> bool {
    let lo = min(min(t.a.xyz, t.b.xyz), t.c.xyz) + vec3<f32>(0.0, dice.extent.z, 0.0);
    let hi = max(max(t.a.xyz, t.b.xyz), t.c.xyz) + vec3<f32>(0.0, dice.extent.x + dice.extent.y + dice.extent.w, 0.0);
    return outside(dice.local_to_clip, lo, hi) && outside(dice.local_to_shadow, lo, hi);
}

// Whether a box lies wholly beyond one plane of a clip space (depth 0 to w).
fn outside(to_clip: mat4x4<f32>, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    var out_l = true; var out_r = true; var out_b = true; var out_t = true; var out_n = true; var out_f = true;
    for (var i = 0u; i < 8u; i++) {
        let p = vec3<f32>(select(lo.x, hi.x, (i & 1u) != 0u), select(lo.y, hi.y, (i & 2u) != 0u), select(lo.z, hi.z, (i & 4u) != 0u));
        let q = to_clip * vec4<f32>(p, 1.0);
        out_l = out_l && q.x < -q.w;
        out_r = out_r && q.x > q.w;
        out_b = out_b && q.y < -q.w;
        out_t = out_t && q.y > q.w;
        out_n = out_n && q.z < 0.0;
        out_f = out_f && q.z > q.w;
    }
    return out_l || out_r || out_b || out_t || out_n || out_f;
}

@compute @workgroup_size(64, 1, 1)
fn dice_surface(
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    // Rows of `groups.x` workgroups (gpu::resources::dispatch_rows).
    let index = wg.x + wg.y * groups.x;
    if index >= dice.grid.w {
        return;
    }
    let t = triangles[index];
    if li < 3u {
        let s = li;
        let u = (li + 1u) % 3u;
        if corner_id(t, s) < corner_id(t, u) {
            levels[li] = edge_level(corner(t, s), corner(t, u));
        } else {
            levels[li] = edge_level(corner(t, u), corner(t, s));
        }
    }
    workgroupBarrier();
    if li == 0u {
        keep = select(1u, 0u, culled(t));
        let most = max(max(levels[0], levels[1]), levels[2]);
        inner_level = max(most, 3u);
        if most == 1u {
            inner_level = 1u;
        }
        var nv = 3u;
        var nt = 1u;
        if inner_level > 1u {
            nv = outer_count() + inner_vertices();
            nt = inner_triangles() + strip_triangles(0u) + strip_triangles(1u) + strip_triangles(2u);
        }
        for (var e = 0u; e < 3u; e++) {
            if is_border(t, e) {
                nv += 2u * (levels[e] + 1u);
                nt += 2u * levels[e];
            }
        }
        if keep == 1u {
            let vb = atomicAdd(&counters[COUNTER_VERTICES], nv);
            let ib = atomicAdd(&counters[COUNTER_INDICES], 3u * nt);
            vertex_base = vb;
            index_base = ib;
            if vb + nv > dice.capacity.x || ib + 3u * nt > dice.capacity.y {
                // Out of room: the triangle is dropped and counted; indices it reserved within the
                // buffer become degenerate triangles.
                keep = 2u;
                atomicAdd(&counters[COUNTER_OVERFLOW], 1u);
                let end = min(ib + 3u * nt, dice.capacity.y);
                for (var i = ib; i < end; i++) {
                    indices[i] = 0u;
                }
            }
        }
    }
    workgroupBarrier();
    if workgroupUniformLoad(&keep) != 1u {
        return;
    }
    let n = inner_level;
    var next_v = 0u;
    var next_i = index_base;
    if n == 1u {
        // Every edge at level 1: the base triangle itself.
        if li < 3u {
            put_vertex(vertex_base + li, corner(t, li), KIND_TOP, base_slope(t));
        }
        if li == 0u {
            put_triangle(next_i, 0u, 1u, 2u);
        }
        next_v = 3u;
        next_i += 3u;
    } else {
        // Outer ring points.
        let outer = outer_count();
        for (var k = li; k < outer; k += 64u) {
            var e = 0u;
            var kk = k;
            if kk >= levels[0] {
                kk -= levels[0];
                e = 1u;
                if kk >= levels[1] {
                    kk -= levels[1];
                    e = 2u;
                }
            }
            put_vertex(vertex_base + k, outer_point(t, e, kk), KIND_TOP, base_slope(t));
        }
        // Inner lattice points.
        for (var j = 1u; j <= n - 2u; j++) {
            for (var i = 1u + li; i <= n - 1u - j; i += 64u) {
                put_vertex(vertex_base + inner_index(i, j), inner_point(t, i, j), KIND_TOP, base_slope(t));
            }
        }
        // Inner triangles, up then down, row by row.
        var at = next_i;
        for (var j = 1u; j + 1u <= n - 2u; j++) {
            let ups = n - 2u - j;      // i = 1 .. n - 2 - j
            let downs = ups - 1u;
            for (var i = 1u + li; i <= ups; i += 64u) {
                put_triangle(at + 3u * (i - 1u), inner_index(i, j), inner_index(i + 1u, j), inner_index(i, j + 1u));
            }
            for (var i = 1u + li; i <= downs; i += 64u) {
                put_triangle(at + 3u * (ups + i - 1u), inner_index(i + 1u, j), inner_index(i + 1u, j + 1u), inner_index(i, j + 1u));
            }
            at += 3u * (ups + downs);
        }
        next_i += 3u * inner_triangles();
        // The three strips stitched between each edge and the inner lattice: one thread each.
        var strip_at = next_i;
        for (var e = 0u; e < 3u; e++) {
            if li == e {
                let l = levels[e];
                let m_count = n - 2u;
                var o = 0u;
                var m = 0u;
                var w = strip_at;
                loop {
                    if o == l && m + 1u == m_count {
                        break;
                    }
                    let im = inner_side(e, m);
                    let advance_outer = m + 1u == m_count || (o < l && (o + 1u) * 2u * n <= (2u * m + 5u) * l);
                    if advance_outer {
                        put_triangle(w, outer_index(e, o), outer_index(e, o + 1u), inner_index(im.x, im.y));
                        o += 1u;
                    } else {
                        let im1 = inner_side(e, m + 1u);
                        put_triangle(w, outer_index(e, o), inner_index(im1.x, im1.y), inner_index(im.x, im.y));
                        m += 1u;
                    }
                    w += 3u;
                }
            }
            strip_at += 3u * strip_triangles(e);
        }
        next_i = strip_at;
        next_v = outer + inner_vertices();
    }
    // Skirts on border edges: the edge's points twice, on the displaced top and on the base.
    for (var e = 0u; e < 3u; e++) {
        if is_border(t, e) {
            let l = levels[e];
            let s = corner(t, e);
            let u = corner(t, (e + 1u) % 3u);
            let opposite = corner(t, (e + 2u) % 3u);
            let d = normalize(u.xz - s.xz);
            var outward = vec2<f32>(d.y, -d.x);
            if dot(outward, opposite.xz - s.xz) > 0.0 {
                outward = -outward;
            }
            // A seam's skirt closes the step between two surfaces' tops and is shaded as the top.
            let seam = is_seam(t, e);
            let n = select(outward, base_slope(t), seam);
            let w = select(0.0, 1.0, seam);
            for (var k = li; k <= l; k += 64u) {
                let p = outer_point(t, e, k);
                put_vertex_marked(vertex_base + next_v + 2u * k, p, KIND_SKIRT_TOP, n, w);
                put_vertex_marked(vertex_base + next_v + 2u * k + 1u, p, KIND_SKIRT_BOTTOM, n, w);
            }
            for (var k = li; k < l; k += 64u) {
                let top0 = next_v + 2u * k;
                let at = next_i + 6u * k;
                put_triangle(at, top0, top0 + 1u, top0 + 2u);
                put_triangle(at + 3u, top0 + 2u, top0 + 1u, top0 + 3u);
            }
            next_v += 2u * (l + 1u);
            next_i += 6u * l;
        }
    }
}

// After a surface's dicing: its indexed indirect draw covers what it appended.
@compute @workgroup_size(1, 1, 1)
fn seal() {
    let end = min(atomicLoad(&counters[COUNTER_INDICES]), dice.capacity.y);
    let start = min(atomicLoad(&counters[COUNTER_SEALED]), end);
    let base = ARGS_BASE + ARGS_STRIDE * dice.grid.z;
    atomicStore(&counters[base + 0u], end - start);   // index count
    atomicStore(&counters[base + 1u], 1u);             // instances
    atomicStore(&counters[base + 2u], start);          // first index
    atomicStore(&counters[base + 3u], 0u);             // base vertex
    atomicStore(&counters[base + 4u], 0u);             // first instance
    atomicStore(&counters[COUNTER_SEALED], end);
}
