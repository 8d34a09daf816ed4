// strip.wgsl: a terrain window's strips moved between a level's heights in the pool and a strip
// buffer, through the pool's toroidal mapping (pool/texel.wgsl, the one place it is made):
// `strip_out` gathers the logical rectangle that leaves the window, `strip_in` scatters the one
// that enters. The strip buffer holds two words a texel, (depression, displaced) as channel
// values, in the rectangle's row-major logical order from texel `first`. `strip_in` adds the pool
// bytes each store writes to `written[0]`, so that a scroll's cost is counted where it is paid.
// One dispatch a rectangle (the leaving and entering strips of a scroll are the same storage).
// CPU side: window/strip.rs (`StripParams` must match), window/plan.rs (the rectangles).

// import shared, texel_write

struct StripParams {
    heights: u32,    // word offset of the level's heights region in the pool
    width: u32,      // the level's texels along x and z
    height: u32,
    wrap: u32,       // its toroidal offsets, ox | oy << 16, when the strip moves
    x0: u32,         // the logical rectangle: first column and row, columns and rows
    y0: u32,
    columns: u32,
    rows: u32,
    first: u32,      // texel of the strip buffer where the rectangle starts
    unit_bytes: u32, // pool bytes a unit's store writes
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read_write> pool: array<u32>;
@group(0) @binding(1) var<uniform> params: StripParams;
@group(0) @binding(2) var<storage, read_write> strip: array<u32>;
@group(0) @binding(3) var<storage, read_write> written: array<atomic<u32>>;

// The unit at (column, row) of the dispatch, or false past the rectangle.
fn unit_of(gid: vec3<u32>) -> vec3<u32> {
    let u = unit_texels(PRECISION);
    let c = gid.x * u;
    let inside = select(0u, 1u, c < params.columns && gid.y < params.rows);
    return vec3<u32>(c, gid.y, inside);
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn strip_out(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = unit_of(gid);
    if at.z == 0u {
        return;
    }
    for (var k = 0u; k < unit_texels(PRECISION); k++) {
        let c = at.x + k;
        if c < params.columns {
            let t = pool_texel(PRECISION, params.heights, params.width, params.height, params.wrap,
                params.x0 + c, params.y0 + at.y);
            let i = 2u * (params.first + at.y * params.columns + c);
            strip[i] = t.x;
            strip[i + 1u] = t.y;
        }
    }
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn strip_in(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = unit_of(gid);
    if at.z == 0u {
        return;
    }
    let i = 2u * (params.first + at.y * params.columns + at.x);
    let a = vec2<u32>(strip[i], strip[i + 1u]);
    // At 8 bits the rectangle's columns are even (window/plan.rs snaps them), so b is inside.
    var b = vec2<u32>(0u);
    if unit_texels(PRECISION) == 2u {
        b = vec2<u32>(strip[i + 2u], strip[i + 3u]);
    }
    pool_store_unit(PRECISION, params.heights, params.width, params.height, params.wrap,
        params.x0 + at.x, params.y0 + at.y, a, b);
    atomicAdd(&written[0], params.unit_bytes);
}

// A finer level's leaving strip folded into this (coarser) level: each channel becomes the
// larger of what is stored and the strip's (the deepest fine texel over the coarse one, summed
// up on the CPU: window/mod.rs), so the far level keeps the broad shape of trails the near level
// pages out even where its own coarse capture missed them.
@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn strip_max(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = unit_of(gid);
    if at.z == 0u {
        return;
    }
    let i = 2u * (params.first + at.y * params.columns + at.x);
    let x = params.x0 + at.x;
    let y = params.y0 + at.y;
    let a = max(vec2<u32>(strip[i], strip[i + 1u]),
        pool_texel(PRECISION, params.heights, params.width, params.height, params.wrap, x, y));
    var b = vec2<u32>(0u);
    if unit_texels(PRECISION) == 2u {
        b = max(vec2<u32>(strip[i + 2u], strip[i + 3u]),
            pool_texel(PRECISION, params.heights, params.width, params.height, params.wrap, x + 1u, y));
    }
    pool_store_unit(PRECISION, params.heights, params.width, params.height, params.wrap, x, y, a, b);
    atomicAdd(&written[0], params.unit_bytes);
}
