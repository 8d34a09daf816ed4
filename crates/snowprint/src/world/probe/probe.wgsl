// probe.wgsl: gameplay probes. For each queried point, the channels of the texel under it and the
// slope of the snow top there, read from the pool at the pool's precision (pool/texel.wgsl).
// Writes one vec4<u32> a point: (depression, displaced) as stored, then d(top)/dx and d(top)/dz in
// metres per metre of the surface's local frame (f32 bits), central differences over the texel's
// neighbours (one-sided at the heightmap's edges). A query of width 0 (no surface) writes zeros.
// CPU side: world/probe.rs (`ProbeQuery` must match `ProbeQuery` here, 32 bytes).

// import texel

struct ProbeQuery {
    // First word of the surface's heights region in the pool.
    base: u32,
    // Heightmap texels along local x and z; width 0: no surface under the point.
    width: u32,
    height: u32,
    // The texel under the point: column in the low 16 bits, row in the high 16.
    texel: u32,
    // The pool's precision, bits a channel (8, 16 or 32).
    bits: u32,
    // Texel sides along local x and z, metres.
    texel_x: f32,
    texel_z: f32,
    // Fresh snow depth of the surface, metres.
    snow_depth: f32,
    // Toroidal storage offsets of the heights region (pool/texel.wgsl).
    wrap: u32,
}

@group(0) @binding(0) var<storage, read> pool: array<u32>;
@group(0) @binding(1) var<storage, read> queries: array<ProbeQuery>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4<u32>>;

// Height of the snow top above the ground at texel (x, y), metres.
fn probe_top(q: ProbeQuery, x: u32, y: u32) -> f32 {
    let f = pool_fractions(q.bits, q.base, q.width, q.height, q.wrap, x, y);
    return q.snow_depth * (1.0 - f.x);
}

@compute @workgroup_size(64, 1, 1)
fn probe_points(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&queries) {
        return;
    }
    let q = queries[i];
    if q.width == 0u {
        results[i] = vec4<u32>(0u);
        return;
    }
    let x = q.texel & 0xffffu;
    let y = q.texel >> 16u;
    let c = pool_texel(q.bits, q.base, q.width, q.height, q.wrap, x, y);
    let x0 = select(x - 1u, 0u, x == 0u);
    let x1 = min(x + 1u, q.width - 1u);
    let y0 = select(y - 1u, 0u, y == 0u);
    let y1 = min(y + 1u, q.height - 1u);
    var dx = 0.0;
    if x1 > x0 {
        dx = (probe_top(q, x1, y) - probe_top(q, x0, y)) / (f32(x1 - x0) * q.texel_x);
    }
    var dz = 0.0;
    if y1 > y0 {
        dz = (probe_top(q, x, y1) - probe_top(q, x, y0)) / (f32(y1 - y0) * q.texel_z);
    }
    results[i] = vec4<u32>(c.x, c.y, bitcast<u32>(dx), bitcast<u32>(dz));
}
