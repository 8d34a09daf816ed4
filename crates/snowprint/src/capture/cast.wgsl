// cast.wgsl (module `capture_cast`): the vertical ray casts through the analytic primitives,
// as pure functions of a surface's view and a texel: what a primitive presses under a texel of the
// surface's capture region (its texels and an apron of APRON texels beyond each side,
// capture::region), as the order-preserving code the capture stores. The capture's two paths
// (write.wgsl) and the update's own ray cast (accumulate/cast.wgsl, `CapturePath::Update`) call
// the same functions on the same texel centres, so all three give the same bits. A `cell` here is
// a texel of the region (cell - APRON is the surface's logical texel); the view's sizes are the
// surface's. The importer declares `ground` (read).
// CPU reference: capture::cpu.

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
    prims: vec2<u32>,       // compute path: its primitives (first, count); count 0 on the raster path
    whole: u32,             // compute path: 1 where its region is not cleared (each tile written whole)
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

// The region's sides, texels.
fn region_of(v: CaptureView) -> vec2<u32> {
    return vec2<u32>(v.texels) + vec2<u32>(2u * APRON);
}

// The ground field's column (base, bare) at logical texel `x` of row `y` (within the field),
// extended past the field's side by linear extrapolation from the two texels there (exact on a
// plane; the edge texel's own value on a field one texel wide). `2 a - b` rounds once whether or
// not it is fused, as the CPU's (`GroundField::region_columns`).
fn ground_row(v: CaptureView, x: i32, y: u32) -> vec2<f32> {
    let w = i32(v.texels.x);
    let n = u32(w);
    if x < 0 && w > 1 {
        return 2.0 * ground_texel(v.ground, n, 0u, y) - ground_texel(v.ground, n, 1u, y);
    }
    if x >= w && w > 1 {
        return 2.0 * ground_texel(v.ground, n, n - 1u, y) - ground_texel(v.ground, n, n - 2u, y);
    }
    return ground_texel(v.ground, n, u32(clamp(x, 0, w - 1)), y);
}

// Base and bare depth under region texel `cell` of a surface; flat ground is (0, 0), which leaves
// the maths below exactly as on a flat surface. In the apron the field is extrapolated along x,
// then along y (`ground_row`), and the bare depth kept at 0 or more.
fn ground_of(v: CaptureView, cell: vec2<u32>) -> vec2<f32> {
    if v.ground == NO_GROUND {
        return vec2<f32>(0.0);
    }
    let l = vec2<i32>(cell) - vec2<i32>(i32(APRON));
    let h = i32(v.texels.y);
    var g: vec2<f32>;
    if l.y < 0 && h > 1 {
        g = 2.0 * ground_row(v, l.x, 0u) - ground_row(v, l.x, 1u);
    } else if l.y >= h && h > 1 {
        g = 2.0 * ground_row(v, l.x, u32(h - 1)) - ground_row(v, l.x, u32(h - 2));
    } else {
        g = ground_row(v, l.x, u32(clamp(l.y, 0, h - 1)));
    }
    return vec2<f32>(g.x, max(g.y, 0.0));
}

// Depths in [0, 1] are stored as ONE_BITS - bits(depth) (constants.wgsl): 0 (the cleared value) means nothing was
// captured, and a larger value is a lower point, so atomicMax keeps the lowest (write.wgsl). Non-negative
// floats order like their bit patterns, so the code is exact and monotonic.

// The code of a depth in [0, 1].
fn depth_code(depth: f32) -> u32 {
    return ONE_BITS - bitcast<u32>(clamp(depth, 0.0, 1.0));
}

const BIG: f32 = 1e30;

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

// The local (x, z) of the centre of region texel `cell`, from `c` = cell + 0.5 (exact in f32, as
// a fragment's position less the viewport's origin is), the same way the CPU reference computes
// texel centres: `c - APRON` is the surface's logical texel centre (exact too), so the surface's
// own texels have the centres they had before the apron.
fn texel_center_of(v: CaptureView, c: vec2<f32>) -> vec2<f32> {
    return -v.half_size + (c - vec2<f32>(f32(APRON))) / v.texels * 2.0 * v.half_size;
}

// Half the sides of the capture region, local metres: the surface's grown by the apron.
fn region_half_of(v: CaptureView) -> vec2<f32> {
    return v.half_size + 2.0 * v.half_size / v.texels * f32(APRON);
}

// What primitive `p` presses under region texel `cell` (its centre `c` = cell + 0.5): the code of
// its lowest point in the frustum, or NO_HIT where it leaves nothing (a code may be 0, a point at
// the frustum's top, which still flags its tiles).
fn prim_code(v: CaptureView, p: Primitive, cell: vec2<u32>, c: vec2<f32>) -> u32 {
    let x = texel_center_of(v, c);
    var iv: vec2<f32>;
    if p.kind.x == PRIM_CAPSULE {
        iv = capsule_interval(p.p0.xyz, p.p1.xyz, p.p0.w, x.x, x.y);
    } else {
        iv = box_interval(p.p0.xyz, p.p1, p.p2, p.p3, x.x, x.y);
    }
    // Heights above the texel's base. Keep only the part inside the frustum: a solid reaching below
    // the ground (the bare depth above the base) is clamped to the ground, one entirely below it or
    // above the frustum leaves nothing.
    let g = ground_of(v, cell);
    iv -= vec2<f32>(g.x);
    if iv.x > iv.y || iv.y < g.y || iv.x >= v.frustum_height {
        return NO_HIT;
    }
    return depth_code(max(iv.x, g.y) / v.frustum_height);
}

// A primitive's footprint on the surface (local x, z): its bounding rectangle's corners.
fn prim_footprint(p: Primitive) -> vec4<f32> {
    if p.kind.x == PRIM_CAPSULE {
        let r = p.p0.w;
        return vec4<f32>(min(p.p0.xz, p.p1.xz) - vec2<f32>(r), max(p.p0.xz, p.p1.xz) + vec2<f32>(r));
    }
    let e = abs(p.p1.xz) * p.p1.w + abs(p.p2.xz) * p.p2.w + abs(p.p3.xz) * p.p3.w;
    return vec4<f32>(p.p0.xz - e, p.p0.xz + e);
}
