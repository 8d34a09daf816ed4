// engine.wgsl: reading a surface's heightmap straight from the pool, for an engine's own shaders.
// Self-contained: every identifier starts with `snowprint_`, and the importer defines nothing.
// Rust composes it with the importer's choice of binding (`wgsl::engine_module`); as stored here
// the pool is at group 0, binding 0.
//
// Binding contract: one read-only storage buffer, the world's pool (`FrameView::pool_buffer`,
// bound whole), and per surface a `snowprint_Surface` filled by `SurfaceUniform::for_surface`
// (a uniform, a storage element or a function argument: the functions take it by value).
//
// Texel (column, row) covers local x in [-half_size.x + column * texel_x, ... + texel_x], z alike:
// column 0 / row 0 at the smallest x / z. UVs run 0..1 across the surface (u along local +x, v
// along local +z); uv (column + 0.5) / width is the middle of a texel. Depressions are fractions of
// the snow depth (0 untouched, 1 pressed to the ground). CPU reference: `Heightmap::fraction`
// of `SnowWorld::read_heightmap`.

// One snow surface. Must match `SurfaceUniform` in src/render/gpu.rs (and `SnowSurface` in
// render/snow/snow.wgsl, the same layout); a test checks both with naga.
struct snowprint_Surface {
    local_to_world: mat4x4<f32>,
    world_to_local: mat4x4<f32>,
    half_size: vec2<f32>,   // half the sides along local x and z, metres
    snow_depth: f32,        // metres of fresh snow over the ground
    texel: f32,             // the larger texel side, metres
    grid: vec2<f32>,        // width and height, texels (as floats)
    ground: u32,            // the renderer's ground material (0 tiles, 1 concrete)
    index: u32,             // the surface's slot index
    search: vec4<f32>,      // the renderer's relief search (snow.wgsl)
    look: vec4<f32>,        // the renderer's look (snow.wgsl)
    pattern: vec4<f32>,     // the renderer's pattern offset and switches (snow.wgsl)
    heights: u32,           // word offset of the heights region in the pool
    row_words: u32,         // words a row of the heights region (a plane's, at 32 bits)
    bits: u32,              // bits a channel: 8, 16 or 32
    channel_max: f32,       // the value of a channel pressed to the ground (2^bits - 1)
    width: u32,             // texels along local x
    height: u32,            // texels along local z
    texel_x: f32,           // texel side along local x, metres
    texel_z: f32,           // texel side along local z, metres
    albedo: vec4<f32>,      // the material's look (snow.wgsl): untouched albedo, dry roughness
    disturbed: vec4<f32>,   // disturbed albedo, wet roughness
    grain: vec4<f32>,       // grain, sparkle, wetness, water depth (metres, 0: none)
    translucency: vec4<f32>, // translucency; y, z: the material's ground blend (0: the renderer's); w: room for rims above the top (m)
    terrain: u32,           // first texel of the ground field (the renderer's), or 0xffffffff on flat ground
    terrain_low: f32,       // lowest base of the snow columns (0 on flat ground)
    terrain_top: f32,       // highest untouched snow top (the snow depth on flat ground)
    wrap: u32,              // toroidal storage offsets of the heights, ox | oy << 16 (0: none)
    hole: vec4<f32>,        // local (x0, z0, x1, z1) a finer terrain window level draws instead
}

@group(0) @binding(0) var<storage, read> snowprint_pool: array<u32>;

// Raw (depression, displaced) channels of texel (column, row), clamped to the grid. Layouts as in
// src/pool/mod.rs: 8 bits two texels a word (16 bits each, depression low byte), 16 bits a word a
// texel (depression low half), 32 bits two planes (depressions, then displaced).
fn snowprint_texel_raw(s: snowprint_Surface, texel: vec2<u32>) -> vec2<u32> {
    // A terrain window's level is stored wrapped: logical (x, y) at ((x + ox) mod width,
    // (y + oy) mod height), as pool/texel.wgsl maps it (this module stands alone).
    var x = min(texel.x, s.width - 1u);
    var y = min(texel.y, s.height - 1u);
    if s.wrap != 0u {
        x = (x + (s.wrap & 0xffffu)) % s.width;
        y = (y + (s.wrap >> 16u)) % s.height;
    }
    if s.bits == 8u {
        let word = snowprint_pool[s.heights + y * s.row_words + x / 2u];
        let v = (word >> (16u * (x & 1u))) & 0xffffu;
        return vec2<u32>(v & 0xffu, v >> 8u);
    }
    let i = s.heights + y * s.row_words + x;
    if s.bits == 16u {
        let word = snowprint_pool[i];
        return vec2<u32>(word & 0xffffu, word >> 16u);
    }
    return vec2<u32>(snowprint_pool[i], snowprint_pool[i + s.row_words * s.height]);
}

// Fraction of the snow depth pressed down at texel (column, row).
fn snowprint_depression(s: snowprint_Surface, texel: vec2<u32>) -> f32 {
    return f32(snowprint_texel_raw(s, texel).x) / s.channel_max;
}

// Snow pushed down past the current depression by the captures, accumulated (the talk's projected
// displacement), as a fraction of the snow depth, at texel (column, row).
fn snowprint_displaced(s: snowprint_Surface, texel: vec2<u32>) -> f32 {
    return f32(snowprint_texel_raw(s, texel).y) / s.channel_max;
}

// Depression at a signed texel, clamped to the grid.
fn snowprint_depression_clamped(s: snowprint_Surface, c: vec2<i32>) -> f32 {
    let top = vec2<i32>(i32(s.width) - 1, i32(s.height) - 1);
    return snowprint_depression(s, vec2<u32>(clamp(c, vec2<i32>(0), top)));
}

// Depression at `uv`, bilinear between texel centres (clamped at the edges).
fn snowprint_depression_uv(s: snowprint_Surface, uv: vec2<f32>) -> f32 {
    let p = uv * vec2<f32>(f32(s.width), f32(s.height)) - 0.5;
    let i = floor(p);
    let f = p - i;
    let c = vec2<i32>(i);
    let a = mix(snowprint_depression_clamped(s, c), snowprint_depression_clamped(s, c + vec2<i32>(1, 0)), f.x);
    let b = mix(snowprint_depression_clamped(s, c + vec2<i32>(0, 1)), snowprint_depression_clamped(s, c + vec2<i32>(1, 1)), f.x);
    return mix(a, b, f.y);
}

// Snow left above the ground at `uv`, metres (bilinear).
fn snowprint_snow_depth_at(s: snowprint_Surface, uv: vec2<f32>) -> f32 {
    return s.snow_depth * (1.0 - snowprint_depression_uv(s, uv));
}

// Unit normal of the snow's top at `uv` in the surface's local frame (+y up), from central
// differences of the bilinear height one texel apart.
fn snowprint_normal(s: snowprint_Surface, uv: vec2<f32>) -> vec3<f32> {
    let du = vec2<f32>(1.0 / f32(s.width), 0.0);
    let dv = vec2<f32>(0.0, 1.0 / f32(s.height));
    let dx = snowprint_snow_depth_at(s, uv + du) - snowprint_snow_depth_at(s, uv - du);
    let dz = snowprint_snow_depth_at(s, uv + dv) - snowprint_snow_depth_at(s, uv - dv);
    return normalize(vec3<f32>(-dx / (2.0 * s.texel_x), 1.0, -dz / (2.0 * s.texel_z)));
}

// The UV of a local (x, z), metres.
fn snowprint_uv(s: snowprint_Surface, local_xz: vec2<f32>) -> vec2<f32> {
    return (local_xz + s.half_size) / (2.0 * s.half_size);
}

// The surface-local position of a world position (the ground at y = 0, untouched snow at
// y = snow_depth).
fn snowprint_to_local(s: snowprint_Surface, world: vec3<f32>) -> vec3<f32> {
    return (s.world_to_local * vec4<f32>(world, 1.0)).xyz;
}

// The world position of a surface-local position.
fn snowprint_to_world(s: snowprint_Surface, local: vec3<f32>) -> vec3<f32> {
    return (s.local_to_world * vec4<f32>(local, 1.0)).xyz;
}
