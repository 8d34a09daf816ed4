// snow.wgsl: the snow material of the talk ("Stage 3 - Shading"), as a WGSL module a renderer can
// import. It declares no bindings and no entry points.
//
// How to import it, the short way: `snowprint::wgsl::material_module(&ImportOptions { .. })` is
// this file with the engine module (wgsl/engine.wgsl) and the heightfield contract below filled
// from the pool; bind the pool where the options say and fill `SnowSurface` with
// `SurfaceUniform::for_surface`. The long way: put this file's text into your shader module (WGSL
// declarations may come in any order) and define the heightfield contract yourself, three
// functions that read one surface's heightmap:
//
//   // Fraction of the snow depth pressed down at `uv` (0 = untouched, 1 = ground), filtered.
//   // Called by the relief search, several times per pixel: make it one texture tap. Where the
//   // material has rims (`s.translucency.w` > 0, the room the slab rises by), subtract their
//   // height over the depth to draw them (surface.wgsl does, from the banks pass).
//   fn snow_depression(s: SnowSurface, uv: vec2<f32>) -> f32
//   // (depression, normal.x, normal.z, ambient occlusion) at `uv`, normal in the surface's local
//   // frame, as smooth as you can afford (the renderer uses a 4-tap bicubic B-spline). Called
//   // once per pixel, at the hit.
//   fn snow_heightfield(s: SnowSurface, uv: vec2<f32>) -> vec4<f32>
//   // How much of the moon reaches the snow at `uv` past the walls of the prints (1 = all), or
//   // 1.0 if you have no such term. Called once per pixel.
//   fn snow_light_visibility(s: SnowSurface, uv: vec2<f32>) -> f32
//   // The base of the snow column at `uv` (local y, metres; the snow top is the base plus the
//   // snow depth, less the depression): 0.0 on flat ground. Called by the search with
//   // `snow_depression`. A renderer without ground fields returns 0.0 (wgsl/engine_material.wgsl).
//   fn snow_ground_base(s: SnowSurface, uv: vec2<f32>) -> f32
//
// UVs run 0..1 across the surface: u along local +x, v along local +z (texel column 0 / row 0 at the
// smallest x / z, as the heightmap pool stores them). The snowprint renderer fills all three from
// textures that `heightfield.wgsl` derives from the pool each frame.
//
// Then, per pixel of the box drawn for a surface (top face at y = snow_top(s), the highest snow top raised by any room for rims, sides down to
// y = s.terrain_low, 0 on flat ground,
// in the surface's local frame; `tier` SNOW_TIER_RELIEF or SNOW_TIER_POM, `light_local` the unit
// direction towards the light in the local frame, `pixel` the pixel's footprint in metres):
//   let hit = snow_trace(s, local_position, local_view_direction, tier, light_local);
//   if hit.found == 0u { discard; }
//   let hf = snow_heightfield(s, snow_uv(s, hit.position.xz));
//   let m = snow_deformable(s, hit, hf, face_normal, sky_tint, pixel);
//   ... light m.albedo, m.roughness, m.normal (local frame), m.ao with your own lights, times
//   hit.shadow; add the material's glints (m.sparkle, `snow_sparkle`) and, on water
//   (m.mirror, hit.water), your sky mirrored through `snow_water_reflection` ...
// or, for a surface nothing has pressed yet, the cheaper `snow_basic(s, local_position,
// face_normal, sky_tint, pixel)`. Nothing here needs derivatives, so compute shaders may call it
// too (a `discard` is a fragment shader's; a compute shader tests `hit.found` instead).
//
// The maths have CPU references in src/render/cpu.rs, in the same form: keep them in step.

// One snow surface as the material sees it. Must match `SurfaceUniform` in src/render/gpu.rs and
// `snowprint_Surface` in src/wgsl/engine.wgsl (tests check both layouts with naga).
struct SnowSurface {
    local_to_world: mat4x4<f32>,
    world_to_local: mat4x4<f32>,
    half_size: vec2<f32>,   // half the sides along local x and z, metres
    snow_depth: f32,        // metres of fresh snow over the ground
    texel: f32,             // heightmap texel side, metres
    grid: vec2<f32>,        // heightmap width and height, texels
    ground: u32,            // SNOW_GROUND_TILES, SNOW_GROUND_CONCRETE or SNOW_GROUND_ROCK
    index: u32,             // the surface's slot in the renderer's per-surface tables
    search: vec4<f32>,      // x: linear taps per texel crossed, y: min taps, z: max taps, w: binary refinement taps
    look: vec4<f32>,        // x: depression where the ground starts to show, y: where it shows fully, z: AO strength, w: POM self-shadow taps
    pattern: vec4<f32>,     // xy: offset of the procedural patterns (metres), z: switches (SNOW_NO_*), w: macro wave strength
    // Where the heights lie in the pool (read by wgsl/engine.wgsl; the renderer reads textures).
    heights: u32,           // word offset of the heights region
    row_words: u32,         // words a row
    bits: u32,              // bits a channel
    channel_max: f32,       // a channel pressed to the ground
    width: u32,             // texels along x
    height: u32,            // texels along z
    texel_x: f32,           // texel side along x, metres
    texel_z: f32,           // texel side along z, metres
    // The surface's material look (`MaterialLook` in src/material.rs).
    albedo: vec4<f32>,      // xyz: untouched albedo, w: dry roughness
    disturbed: vec4<f32>,   // xyz: disturbed albedo at the bottom of prints, w: wet roughness
    grain: vec4<f32>,       // x: grain, y: sparkle, z: wetness, w: water depth below the top (m, 0: none)
    translucency: vec4<f32>, // x: translucency (sky tint of walls, diffuse wrap; 1 snow, 0 sand and mud), y: depression where the material's ground starts to show (0: look.x's), z: where it shows fully, w: room for rims above the snow top (m, 0: none)
    // The ground under the snow (ground/mod.rs): where its field lies, and the slab it spans.
    terrain: u32,           // first texel of the ground field, or SNOW_NO_GROUND on flat ground
    terrain_low: f32,       // lowest base of the snow columns, local y (0 on flat ground)
    terrain_top: f32,       // highest untouched snow top, local y (the snow depth on flat ground)
    wrap: u32,              // the heights' toroidal storage offsets (engine.wgsl, pool/texel.wgsl)
    hole: vec4<f32>,        // local (x0, z0, x1, z1) a finer terrain window level draws instead (empty: x1 < x0)
}

// Whether local xz lies in the surface's hole: a coarser terrain window level leaves the extent
// of the finer one to it, so that the two never draw over each other (no seam, no fight).
fn snow_in_hole(s: SnowSurface, xz: vec2<f32>) -> bool {
    return all(xz >= s.hole.xy) && all(xz < s.hole.zw);
}

const SNOW_GROUND_TILES: u32 = 0u;
const SNOW_GROUND_CONCRETE: u32 = 1u;
const SNOW_GROUND_ROCK: u32 = 2u;
const SNOW_TIER_RELIEF: u32 = 0u;
const SNOW_TIER_POM: u32 = 1u;
// `terrain` of a surface on flat ground. Must match NO_GROUND in wgsl/constants.wgsl.
const SNOW_NO_GROUND: u32 = 0xffffffffu;
// Slack of the inside test, metres. Must match `INSIDE_EPSILON` in cpu.rs.
const SNOW_EPSILON: f32 = 1e-4;
const SNOW_PI: f32 = 3.14159265;

// Where a view ray meets the snow.
struct SnowHit {
    position: vec3<f32>,    // surface-local, metres
    t: f32,                 // distance from the entry, metres
    found: u32,             // 0: the ray left the slab without meeting snow (discard)
    taps: u32,              // heightfield taps spent (debug view)
    side: u32,              // 1: met at the entry on a side face (a cut through the snow)
    shadow: f32,            // self-shadow of the heightfield towards the light, 1 = lit
    water: u32,             // 1: met the flat water filling a print deeper than the water depth
}

// What the material gives to lighting.
struct SnowSample {
    albedo: vec3<f32>,      // diffuse albedo, already tinted with the sky in the transition zone
    roughness: f32,         // perceptual roughness
    normal: vec3<f32>,      // surface-local, unit
    f0: f32,                // specular reflectance at normal incidence
    ao: f32,                // ambient occlusion from the heightmap
    ground: f32,            // weight of the flattened-ground stage (0 = snow)
    transition: f32,        // weight of the transition zone (the fake subsurface scattering)
    wrap: f32,              // diffuse wrap (light bleeding through snow), 0 for hard surfaces
    sparkle: f32,           // strength of the grains' glints here (`snow_sparkle`), 0 = none
    mirror: f32,            // weight of the sky's mirror reflection (1 on water)
}

// ---------------------------------------------------------------------------------------------
// Noise: integer hashing, so that every GPU (and the CPU) computes the same patterns.

fn snow_pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn snow_hash2(c: vec2<i32>) -> f32 {
    let h = snow_pcg(bitcast<u32>(c.x) + snow_pcg(bitcast<u32>(c.y)));
    return f32(h >> 8u) * (1.0 / 16777215.0);
}

// Value noise in [0, 1] and its gradient (x: value, yz: d/dp), quintic interpolation.
fn snow_noise(p: vec2<f32>) -> vec3<f32> {
    let i = floor(p);
    let f = p - i;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let du = 30.0 * f * f * (f * (f - 2.0) + 1.0);
    let c = vec2<i32>(i);
    let a = snow_hash2(c);
    let b = snow_hash2(c + vec2<i32>(1, 0));
    let d = snow_hash2(c + vec2<i32>(0, 1));
    let e = snow_hash2(c + vec2<i32>(1, 1));
    let k1 = b - a;
    let k2 = d - a;
    let k3 = a - b - d + e;
    return vec3<f32>(a + k1 * u.x + k2 * u.y + k3 * u.x * u.y, du * vec2<f32>(k1 + k3 * u.y, k2 + k3 * u.x));
}

// Three octaves of value noise at `freq` cycles per metre, each rotated to hide the lattice:
// (value in about [0, 1], gradient per metre). Octaves finer than about three pixels (`pixel` is the
// pixel's footprint in metres) fade out, so that distant snow does not sparkle and crawl.
fn snow_fbm(p: vec2<f32>, freq: f32, pixel: f32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    var q = p * freq;
    var f = freq;
    var amp = 0.5;
    // Rotation by about 37 degrees and its transpose for the gradient.
    let r = mat2x2<f32>(0.8, 0.6, -0.6, 0.8);
    var back = mat2x2<f32>(1.0, 0.0, 0.0, 1.0);
    for (var o = 0; o < 3; o++) {
        let n = snow_noise(q);
        let keep = 1.0 - smoothstep(0.15, 0.35, pixel * f);
        sum += vec3<f32>(amp * mix(0.5, n.x, keep), amp * keep * f * (back * n.yz));
        q = r * q * 2.03 + vec2<f32>(17.1, 9.3);
        back = back * transpose(r);
        f *= 2.03;
        amp *= 0.5;
    }
    return sum;
}

// Tangent-space normal (+z up, x along local x, y along local z) of a height gradient.
fn snow_normal_from_gradient(g: vec2<f32>) -> vec3<f32> {
    return normalize(vec3<f32>(-g.x, -g.y, 1.0));
}

// ---------------------------------------------------------------------------------------------
// Reoriented Normal Mapping [Barré-Brisebois & Hill 2012], the talk's formula on unpacked normals:
// the detail normal rotated by the rotation that takes +z to the base normal.
// Must match `rnm` in cpu.rs.
fn snow_rnm(base: vec3<f32>, detail: vec3<f32>) -> vec3<f32> {
    let t = base + vec3<f32>(0.0, 0.0, 1.0);
    let u = detail * vec3<f32>(-1.0, -1.0, 1.0);
    return normalize(t * dot(t, u) / t.z - u);
}

// Tangent space (x, y along local x, z; z up) to the surface's local frame (y up), and back.
fn snow_ts_to_local(n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(n.x, n.z, n.y);
}

fn snow_local_to_ts(n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(n.x, n.z, n.y);
}

// ---------------------------------------------------------------------------------------------
// The heightfield and the ray through the snow slab.

fn snow_uv(s: SnowSurface, xz: vec2<f32>) -> vec2<f32> {
    return (xz + s.half_size) / (2.0 * s.half_size);
}

// Top of the slab the view ray is traced through: the highest snow top (the snow depth on flat
// ground), raised by the room for rims (`translucency.w`, metres) where the material throws them
// (their banks are in `snow_depression`).
fn snow_top(s: SnowSurface) -> f32 {
    return s.terrain_top + s.translucency.w;
}

// The untouched snow top over a local (x, z), raised by the room for rims: `snow_top` of the
// column there.
fn snow_local_top(s: SnowSurface, xz: vec2<f32>) -> f32 {
    return snow_ground_base(s, snow_uv(s, xz)) + s.snow_depth + s.translucency.w;
}

// Snow height at a local (x, z), metres: above the ground on flat ground, the column's base plus
// what is left of the depth on ground that is not flat. (On flat ground the base is not read, so
// the search is exactly the flat one.)
fn snow_height(s: SnowSurface, xz: vec2<f32>) -> f32 {
    let uv = snow_uv(s, xz);
    let h = s.snow_depth * (1.0 - snow_depression(s, uv));
    if s.terrain == SNOW_NO_GROUND {
        return h;
    }
    return snow_ground_base(s, uv) + h;
}

fn snow_inside(s: SnowSurface, o: vec3<f32>, d: vec3<f32>, t: f32) -> bool {
    let p = o + d * t;
    return p.y <= snow_height(s, p.xz) + SNOW_EPSILON;
}

// Where the ray leaves the slab |x| <= half.x, |z| <= half.y, terrain_low <= y <= snow_top(s):
// (t, 1 when it reaches the ground first). Must match `slab_exit` in cpu.rs.
fn snow_slab_exit(s: SnowSurface, o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    var t = 3.0e38;
    var ground = 0.0;
    if d.y < 0.0 {
        t = (o.y - s.terrain_low) / -d.y;
        ground = 1.0;
    } else if d.y > 0.0 {
        t = (snow_top(s) - o.y) / d.y;
    }
    if d.x != 0.0 {
        let tx = (select(-s.half_size.x, s.half_size.x, d.x > 0.0) - o.x) / d.x;
        if tx < t {
            t = tx;
            ground = 0.0;
        }
    }
    if d.z != 0.0 {
        let tz = (select(-s.half_size.y, s.half_size.y, d.z > 0.0) - o.z) / d.z;
        if tz < t {
            t = tz;
            ground = 0.0;
        }
    }
    return vec2<f32>(max(t, 0.0), ground);
}

// Linear taps for `t_max` metres of ray: s.search.x per texel crossed, within [min, max], the
// max raised on ground that is not flat (`snow_max_taps`). Must match `linear_taps` in cpu.rs.
fn snow_linear_taps(s: SnowSurface, d: vec3<f32>, t_max: f32) -> u32 {
    let travel = length(d.xz) * t_max / s.texel;
    return u32(clamp(ceil(travel * s.search.x), s.search.y, snow_max_taps(s)));
}

// Most linear taps: the tier's, times the times the box is taller than the snow on ground that is
// not flat (a valley's box holds metres of rise that a ray crosses between taps; with the tier's
// taps alone the search steps over the slopes and their hits band into contours), at most
// SNOW_TERRAIN_TAPS. Must match `max_taps` in cpu.rs.
fn snow_max_taps(s: SnowSurface) -> f32 {
    if s.terrain == SNOW_NO_GROUND {
        return s.search.z;
    }
    let tall = max((s.terrain_top - s.terrain_low) / s.snow_depth, 1.0);
    return min(ceil(s.search.z * tall), max(SNOW_TERRAIN_TAPS, s.search.z));
}

// The most linear taps a ray over ground that is not flat takes.
const SNOW_TERRAIN_TAPS: f32 = 192.0;

// Relief mapping: linear taps, then binary refinement. Returns (t, found).
// Must match `relief_search` in cpu.rs.
fn snow_relief_search(s: SnowSurface, o: vec3<f32>, d: vec3<f32>, t_max: f32, taps: u32, refine: u32) -> vec2<f32> {
    if snow_inside(s, o, d, 0.0) {
        return vec2<f32>(0.0, 1.0);
    }
    let dt = t_max / f32(taps);
    var lo = 0.0;
    var hi = -1.0;
    for (var i = 1u; i <= taps; i++) {
        let t = dt * f32(i);
        if snow_inside(s, o, d, t) {
            hi = t;
            break;
        }
        lo = t;
    }
    if hi < 0.0 {
        return vec2<f32>(t_max, 0.0);
    }
    for (var k = 0u; k < refine; k++) {
        let mid = 0.5 * (lo + hi);
        if snow_inside(s, o, d, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    return vec2<f32>(0.5 * (lo + hi), 1.0);
}

// Parallax occlusion mapping: linear taps, then the secant through the last two, refined `refine`
// times by false position. Returns (t, found). Must match `pom_search` in cpu.rs.
fn snow_pom_search(s: SnowSurface, o: vec3<f32>, d: vec3<f32>, t_max: f32, taps: u32, refine: u32) -> vec2<f32> {
    let f0 = o.y - snow_height(s, o.xz) - SNOW_EPSILON;
    if f0 <= 0.0 {
        return vec2<f32>(0.0, 1.0);
    }
    let dt = t_max / f32(taps);
    var lo = 0.0;
    var f_lo = f0;
    for (var i = 1u; i <= taps; i++) {
        let t = dt * f32(i);
        let p = o + d * t;
        let f = p.y - snow_height(s, p.xz) - SNOW_EPSILON;
        if f <= 0.0 {
            var hi = t;
            var f_hi = f;
            var x = lo + (hi - lo) * f_lo / (f_lo - f_hi);
            for (var k = 0u; k < refine; k++) {
                let q = o + d * x;
                let fx = q.y - snow_height(s, q.xz) - SNOW_EPSILON;
                if fx <= 0.0 {
                    hi = x;
                    f_hi = fx;
                } else {
                    lo = x;
                    f_lo = fx;
                }
                x = lo + (hi - lo) * f_lo / (f_lo - f_hi);
            }
            return vec2<f32>(x, 1.0);
        }
        lo = t;
        f_lo = f;
    }
    return vec2<f32>(t_max, 0.0);
}

// Per-pixel soft self-shadow of the heightfield towards a local light direction `l` (POM tier,
// refining the per-texel visibility): march from the hit up to the snow top, with the penumbra of
// `light_visibility` (heightfield.wgsl). The march starts a texel's height above the hit, so that
// the wall the hit lies on does not shadow itself (N.L does that).
fn snow_self_shadow(s: SnowSurface, p: vec3<f32>, l: vec3<f32>, taps: u32) -> f32 {
    if l.y <= 0.02 || taps == 0u {
        return 1.0;
    }
    let start = p + vec3<f32>(0.0, 0.5 * s.texel, 0.0);
    let t_top = (snow_local_top(s, p.xz) - start.y) / l.y;
    if t_top <= 0.0 {
        return 1.0;
    }
    var lit = 1.0;
    for (var i = 1u; i <= taps; i++) {
        let t = t_top * f32(i) / f32(taps);
        let q = start + l * t;
        let width = 0.01 + 0.12 * t;
        lit = min(lit, clamp(0.5 + (q.y - snow_height(s, q.xz)) / (2.0 * width), 0.0, 1.0));
    }
    return lit;
}

// Height above the ground of the water table (`grain.w` below the top), or -1 without water.
fn snow_water_level(s: SnowSurface) -> f32 {
    if s.grain.w <= 0.0 {
        return -1.0;
    }
    return s.snow_depth - s.grain.w;
}

// Trace the view ray entering the surface's box at local `o` with unit local direction `d`.
fn snow_trace(s: SnowSurface, o_in: vec3<f32>, d: vec3<f32>, tier: u32, light_local: vec3<f32>) -> SnowHit {
    // The rasterized point can lie a hair outside the box: pull it in.
    let o = clamp(o_in, vec3<f32>(-s.half_size.x, s.terrain_low, -s.half_size.y), vec3<f32>(s.half_size.x, snow_top(s), s.half_size.y));
    var hit: SnowHit;
    hit.shadow = 1.0;
    hit.side = 0u;
    let exit = snow_slab_exit(s, o, d);
    let taps = snow_linear_taps(s, d, exit.x);
    var r: vec2<f32>;
    let refine = u32(s.search.w);
    if tier == SNOW_TIER_POM {
        r = snow_pom_search(s, o, d, exit.x, taps, refine);
    } else {
        r = snow_relief_search(s, o, d, exit.x, taps, refine);
    }
    hit.taps = taps + refine + 1u;
    hit.t = r.x;
    hit.found = u32(r.y);
    hit.position = o + d * r.x;
    hit.water = 0u;
    // The base under the entry and under the hit (0 on flat ground, where it is not read).
    var base_o = 0.0;
    var base_hit = 0.0;
    if s.terrain != SNOW_NO_GROUND {
        base_o = snow_ground_base(s, snow_uv(s, o.xz));
        base_hit = snow_ground_base(s, snow_uv(s, hit.position.xz));
    }
    if r.x == 0.0 && o.y < base_o + s.snow_depth - 1e-3 {
        hit.side = 1u;
        // A side face below the column's base cuts through the ground, not the snow: nothing of
        // the snow's to draw there.
        if o.y < base_o {
            hit.found = 0u;
        }
    }
    // Water: a hit below the water table lies in a print deeper than it; the view ray met the
    // flat water surface first, where it crossed the level (in the air over the print, since the
    // search found no material before the hit). On ground that is not flat the table lies over
    // the column under the hit.
    var level = snow_water_level(s);
    if level >= 0.0 {
        level += base_hit;
    }
    if hit.found == 1u && hit.side == 0u && hit.position.y < level && d.y < 0.0 {
        hit.t = max((level - o.y) / d.y, 0.0);
        hit.position = o + d * hit.t;
        hit.water = 1u;
    }
    if hit.water == 1u {
        // The moon over the water surface: the floor's visibility, scaled by the walls above it.
        let uv = snow_uv(s, hit.position.xz);
        let floor_lit = snow_light_visibility(s, uv);
        hit.shadow = mix(1.0, floor_lit, snow_water_enclosed(s, snow_depression(s, uv)));
        hit.taps += 1u;
    } else if hit.found == 1u && hit.side == 0u {
        hit.shadow = snow_light_visibility(s, snow_uv(s, hit.position.xz));
        hit.taps += 1u;
        if tier == SNOW_TIER_POM {
            let shadow_taps = u32(s.look.w);
            hit.shadow = min(hit.shadow, snow_self_shadow(s, hit.position, light_local, shadow_taps));
            hit.taps += shadow_taps;
        }
    }
    return hit;
}

// ---------------------------------------------------------------------------------------------
// Procedural layers: snow (macro "wave" and detail normals), roof tiles, concrete.

// The macro "wave" of wind-blown snow: drifts about 1.7 m apart and broad undulations, a few cm
// high. Height in metres.
fn snow_macro_height(p: vec2<f32>) -> f32 {
    let warp = snow_noise(p * 0.45).x;
    let ripple = sin(dot(p, vec2<f32>(0.93, 0.37)) * (2.0 * SNOW_PI / 1.7) + 3.0 * warp);
    let broad = snow_noise(p * 0.22 + vec2<f32>(3.1, 7.7)).x;
    return 0.012 * ripple * (0.5 + 0.5 * broad) + 0.05 * broad;
}

fn snow_macro_normal(p: vec2<f32>) -> vec3<f32> {
    let e = 0.02;
    let h = snow_macro_height(p);
    let g = vec2<f32>(snow_macro_height(p + vec2<f32>(e, 0.0)) - h, snow_macro_height(p + vec2<f32>(0.0, e)) - h) / e;
    return snow_normal_from_gradient(g);
}

// Grain of the snow: a few millimetres over a few centimetres.
fn snow_detail_normal(p: vec2<f32>, strength: f32, pixel: f32) -> vec3<f32> {
    let n = snow_fbm(p, 14.0, pixel);
    return snow_normal_from_gradient(n.yz * 0.004 * strength);
}

struct SnowLayer {
    albedo: vec3<f32>,
    roughness: f32,
    normal: vec3<f32>,      // tangent space
    f0: f32,
}

// Clay roof tiles in staggered rows along local z: each tile rises towards the row above (where it
// hides under the next one) and is curved across; dark gaps between tiles.
fn snow_roof_tiles(p: vec2<f32>, pixel: f32) -> SnowLayer {
    let row_pitch = 0.30;
    let tile_w = 0.22;
    let row = floor(p.y / row_pitch);
    let fz = p.y / row_pitch - row;
    let xo = p.x / tile_w + 0.5 * (row - 2.0 * floor(row * 0.5));
    let col = floor(xo);
    let fx = xo - col;
    let id = vec2<i32>(i32(col), i32(row));
    let v = snow_hash2(id);
    // Height profile and its gradient (per metre).
    let dhdz = 0.014 / row_pitch;
    let dhdx = 0.007 * SNOW_PI * cos(SNOW_PI * fx) / tile_w;
    let grain = snow_fbm(p, 40.0, pixel);
    // Gaps fade to their average once they are thinner than a pixel.
    let blur = smoothstep(0.004, 0.02, pixel);
    let shape = 1.0 - smoothstep(0.01, 0.05, pixel);
    var n = snow_normal_from_gradient(vec2<f32>(dhdx, dhdz) * shape + grain.yz * 0.0008);
    // Gaps: the lower edge of each row (a shadowed step) and the joints between tiles.
    let edge_z = mix(smoothstep(0.0, 0.06, fz), 0.8, blur);
    let edge_x = mix(smoothstep(0.0, 0.05, fx) * smoothstep(0.0, 0.05, 1.0 - fx), 0.85, blur);
    let gap = edge_z * edge_x;
    let clay = mix(vec3<f32>(0.36, 0.11, 0.06), vec3<f32>(0.50, 0.20, 0.10), v);
    let weathered = mix(clay, vec3<f32>(0.16, 0.12, 0.10), 0.35 * snow_noise(p * 1.3).x);
    var layer: SnowLayer;
    layer.albedo = weathered * (0.25 + 0.75 * gap) * (0.85 + 0.3 * grain.x);
    layer.roughness = mix(0.75, 0.45, gap);
    layer.normal = normalize(mix(vec3<f32>(0.0, -0.6, 0.8), n, mix(0.3 + 0.7 * edge_z, 1.0, blur)));
    layer.f0 = 0.04;
    return layer;
}

// Concrete: blotchy grey with a fine grain and expansion joints every 2 m.
fn snow_concrete(p: vec2<f32>, pixel: f32) -> SnowLayer {
    let blotch = snow_fbm(p, 0.8, pixel);
    let grain = snow_fbm(p, 35.0, pixel);
    let cell = p / 2.0;
    let f = abs(cell - round(cell)) * 2.0;            // 0 on a joint
    let joint = mix(smoothstep(0.0, 0.012, min(f.x, f.y)), 0.97, smoothstep(0.005, 0.02, pixel));
    var layer: SnowLayer;
    let base = vec3<f32>(0.38, 0.38, 0.37) * (0.75 + 0.5 * blotch.x) * (0.9 + 0.2 * grain.x);
    layer.albedo = base * (0.35 + 0.65 * joint);
    layer.roughness = 0.85 - 0.2 * blotch.x;
    // The joint grooves tilt the normal towards their middle.
    let s = sign(cell - round(cell));
    let groove = vec2<f32>(
        select(0.0, s.x * 0.35, f.x < 0.012),
        select(0.0, s.y * 0.35, f.y < 0.012),
    ) * (1.0 - smoothstep(0.005, 0.02, pixel));
    layer.normal = snow_normal_from_gradient(grain.yz * 0.0012 + groove);
    layer.f0 = 0.04;
    return layer;
}

// Bare rock (a terrain's cliffs and outcrops): weathered grey stone, blotched over metres, mottled
// over centimetres, and cut by a few irregular cracks where a noise crosses its middle. Nothing in
// it is straight or periodic, so the planar mapping's stretch down a steep face reads as streaks
// of weathering, not as the lines that concrete's joints drew there.
fn snow_rock(p: vec2<f32>, pixel: f32) -> SnowLayer {
    let blotch = snow_fbm(p, 0.45, pixel);
    let mottle = snow_fbm(p + vec2<f32>(5.3, 1.7), 6.0, pixel);
    let grain = snow_fbm(p, 30.0, pixel);
    let vein = snow_fbm(p + vec2<f32>(11.0, 3.0), 1.3, pixel);
    // A crack: a line about a centimetre wide where the vein noise is 0.5, broken up by the
    // blotches (so it runs for a while and stops) and faded once it is narrower than a pixel.
    let width = 0.012 * length(vein.yz) + 1e-4;
    let runs = smoothstep(0.45, 0.6, blotch.x);
    let crack = (1.0 - smoothstep(0.0, width, abs(vein.x - 0.5))) * runs * (1.0 - smoothstep(0.01, 0.04, pixel));
    var layer: SnowLayer;
    let tone = (0.65 + 0.7 * blotch.x) * (0.8 + 0.4 * mottle.x) * (0.92 + 0.16 * grain.x);
    layer.albedo = vec3<f32>(0.33, 0.31, 0.28) * tone * (1.0 - 0.4 * crack);
    layer.roughness = 0.9 - 0.1 * mottle.x;
    layer.normal = snow_normal_from_gradient(mottle.yz * 0.004 + grain.yz * 0.0015 + vein.yz * 0.02 * crack);
    layer.f0 = 0.04;
    return layer;
}

fn snow_ground_layer(s: SnowSurface, p: vec2<f32>, pixel: f32) -> SnowLayer {
    if s.ground == SNOW_GROUND_CONCRETE {
        return snow_concrete(p, pixel);
    }
    if s.ground == SNOW_GROUND_ROCK {
        return snow_rock(p, pixel);
    }
    return snow_roof_tiles(p, pixel);
}

// The talk's fresh snow (`MaterialLook::snow`'s albedo), for the snow cover of meshes.
const SNOW_FRESH: vec3<f32> = vec3<f32>(0.86, 0.89, 0.93);

// ---------------------------------------------------------------------------------------------
// The material's look (`MaterialLook`): grain, wetness, glints and water.

// Fine grain (sand, mud): a per-grain speckle of the albedo, cells of 2.5 mm fixed in the world,
// faded to its mean once a cell is smaller than about half a pixel. Multiplies the albedo.
fn snow_grain_speckle(s: SnowSurface, q: vec2<f32>, pixel: f32) -> f32 {
    let fine = snow_hash2(vec2<i32>(floor(q * 400.0))) - 0.5;
    let coarse = snow_noise(q * 60.0).x - 0.5;
    let keep = 1.0 - smoothstep(0.003, 0.012, pixel);
    let keep_coarse = 1.0 - smoothstep(0.01, 0.04, pixel);
    return 1.0 + s.grain.x * (0.35 * keep * fine + 0.3 * keep_coarse * coarse);
}

// Glints of single grains: each cell of a lattice fixed in the world (`q`, 2.5 cm) holds at most
// one grain, at a random spot with a random facet tilted from the surface normal `n`; it flashes
// when that facet mirrors the light `l` into the eye `v` (all local, unit). So the glints are view
// dependent but fixed per grain: a still camera sees the same grains flash every frame, a moving
// one sees them come and go as a real snowfield does. Cells smaller than a pixel fade out (no
// screen-space noise). Returns the glint's intensity, to be multiplied by the light.
fn snow_sparkle(q: vec2<f32>, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, pixel: f32) -> f32 {
    let cell_size = 0.025;
    let p = q / cell_size;
    let cell = vec2<i32>(floor(p));
    let a = snow_hash2(cell);
    if a > 0.4 {
        return 0.0;
    }
    let spot = vec2<f32>(snow_hash2(cell + vec2<i32>(7919, 0)), snow_hash2(cell + vec2<i32>(0, 7919)));
    let r = length(fract(p) - (0.2 + 0.6 * spot));
    let dot_size = 1.0 - smoothstep(0.12, 0.3, r);
    let tilt = vec3<f32>(
        snow_hash2(cell + vec2<i32>(31, 17)) - 0.5,
        snow_hash2(cell + vec2<i32>(53, 91)) - 0.5,
        snow_hash2(cell + vec2<i32>(97, 13)) - 0.5,
    );
    let facet = normalize(n + 0.9 * tilt);
    let h = normalize(l + v);
    let mirror = smoothstep(0.95, 0.99, dot(facet, h));
    let fade = 1.0 - smoothstep(cell_size, 3.0 * cell_size, pixel);
    return 40.0 * mirror * dot_size * fade * max(dot(n, l), 0.0);
}

// Share of a print's walls (its floor `dep` deep, a fraction of the depth) that stand above the
// water table: the water surface is that much less enclosed than the floor under it, so its
// occlusion and the moon's shadow over it are the floor's scaled by it.
fn snow_water_enclosed(s: SnowSurface, dep: f32) -> f32 {
    return clamp(s.grain.w / max(dep * s.snow_depth, 1e-4), 0.0, 1.0);
}

// The flat water filling a deep print: smooth, a mirror of the sky (added in lighting from
// `mirror`), over the soaked floor of the print seen through it, darker where the water is deeper
// (`hf.x`: the floor's depression). Lit as the water surface, not as the floor: its occlusion is
// the floor's, scaled by the walls that stand above the water.
fn snow_water(s: SnowSurface, hf: vec4<f32>) -> SnowSample {
    var m: SnowSample;
    let column = max(hf.x * s.snow_depth - s.grain.w, 0.0);
    let floor_albedo = s.disturbed.xyz * (1.0 - 0.35 * s.grain.z);
    m.albedo = floor_albedo * mix(0.45, 1.0, exp(-column / 0.1));
    m.roughness = 0.06;
    // The meniscus: near its edge (up to 2 cm of water over the floor) the water curves up the print's wall
    // (`hf.yz`, the heightmap's slope there), so its rim mirrors the brighter sky low over the
    // horizon: the line that tells a surface of water from a hole.
    let hn = vec3<f32>(hf.y, hf.z, sqrt(max(1.0 - hf.y * hf.y - hf.z * hf.z, 0.0)));
    let rim = 1.0 - smoothstep(0.0, 0.02, column);
    m.normal = snow_ts_to_local(normalize(mix(vec3<f32>(0.0, 0.0, 1.0), hn, 0.6 * rim)));
    m.f0 = 0.02;
    m.ao = mix(1.0, clamp(hf.w, 0.0, 1.0), s.look.z * snow_water_enclosed(s, hf.x));
    m.ground = 0.0;
    m.transition = 0.0;
    m.wrap = 0.0;
    m.sparkle = 0.0;
    m.mirror = 1.0;
    return m;
}

// The sky mirrored by water: Schlick's Fresnel of water (f0 0.02) times the sky in the reflected
// direction `sky` (the caller's sky radiance there), for `cos_v` the cosine of the view angle.
fn snow_water_reflection(sky: vec3<f32>, cos_v: f32) -> vec3<f32> {
    let f = 0.02 + 0.98 * pow(1.0 - clamp(cos_v, 0.0, 1.0), 5.0);
    return sky * f;
}

// Albedo in the transition zone tinted with the sky, to fake light scattered under the snow (the
// talk's fake SSS). `sky` is the sky colour scaled to a luminance near 1.
fn snow_sss_tint(albedo: vec3<f32>, transition: f32, sky: vec3<f32>) -> vec3<f32> {
    return mix(albedo, albedo * sky, clamp(transition, 0.0, 1.0));
}

// Switches that turn one term of the material off (`s.pattern.z`, a sum of these bits), so that a
// test can show the images see the term. Must match `SnowLook::switch_bits` in mod.rs.
const SNOW_NO_SKY_TINT: u32 = 1u;
const SNOW_NO_RNM: u32 = 2u;
// Above the switches, one bit a side (local -x, +x, -z, +z): where the surface's snow meets
// another surface's (a finer terrain window level inside a coarser one, a surface linked beside
// it), so a cut met there is no cut: the renderer shades it as the top.
const SNOW_SEAM_SIDES: u32 = 4u;

// Whether side k (local -x, +x, -z, +z) of the surface meets another surface's snow.
fn snow_seam_side(s: SnowSurface, k: u32) -> bool {
    return (u32(s.pattern.z) & (SNOW_SEAM_SIDES << k)) != 0u;
}

fn snow_switched_off(s: SnowSurface, bit: u32) -> bool {
    return (u32(s.pattern.z) & bit) != 0u;
}

// The sky tint of walls and rims, unless switched off.
fn snow_tint(s: SnowSurface, albedo: vec3<f32>, transition: f32, sky: vec3<f32>) -> vec3<f32> {
    if snow_switched_off(s, SNOW_NO_SKY_TINT) {
        return albedo;
    }
    return snow_sss_tint(albedo, transition, sky);
}

// Detail on a base normal: RNM, or (switched off) the linear blend RNM replaces, which flattens
// the detail.
fn snow_combine(s: SnowSurface, base: vec3<f32>, detail: vec3<f32>) -> vec3<f32> {
    if snow_switched_off(s, SNOW_NO_RNM) {
        return normalize(vec3<f32>(base.xy + detail.xy, base.z * detail.z));
    }
    return snow_rnm(base, detail);
}

// The basic snow material: fresh, untouched snow, no heightmap at all (the talk's cheaper material
// for surfaces nothing has pressed). `face` is the box face's local normal, `pixel` the pixel's
// footprint on the surface in metres (detail finer than a few pixels fades out).
fn snow_basic(s: SnowSurface, p: vec3<f32>, face: vec3<f32>, sky: vec3<f32>, pixel: f32) -> SnowSample {
    var m: SnowSample;
    let q = p.xz + s.pattern.xy;
    m.ao = 1.0;
    m.ground = 0.0;
    m.f0 = 0.02;
    m.wrap = 0.35 * s.translucency.x;
    m.mirror = 0.0;
    m.sparkle = 0.0;
    if face.y > 0.5 {
        let n = snow_combine(s, snow_macro_normal(q), snow_detail_normal(q, 1.0, pixel));
        m.normal = snow_ts_to_local(n);
        m.albedo = s.albedo.xyz;
        if s.grain.x > 0.0 {
            m.albedo *= snow_grain_speckle(s, q, pixel);
        }
        m.roughness = s.albedo.w;
        m.transition = 0.0;
        m.sparkle = s.grain.y;
    } else {
        // The cut through the snow at an open edge: faint layers of successive snowfalls, laid
        // out where the patterns are (`q`), so that the open edges of two surfaces side by side
        // run on without a jump.
        let along = dot(q, vec2<f32>(-face.z, face.x));
        let layers = snow_noise(vec2<f32>(along * 2.0, p.y * 40.0)).x;
        m.normal = face;
        m.albedo = s.albedo.xyz * (0.85 + 0.1 * layers);
        m.roughness = 0.8;
        m.transition = 0.45 * s.translucency.x;
        m.ao = mix(0.6, 1.0, clamp(p.y / max(s.snow_depth, 1e-3), 0.0, 1.0));
    }
    m.albedo = snow_tint(s, m.albedo, m.transition, sky);
    return m;
}

// The deformable snow material: the two stages of the talk (untouched snow, flattened ground)
// blended by the heightmap at the relief hit. `hf` is `snow_heightfield` at the hit, `face` the
// entry face's local normal, `pixel` the pixel's footprint in metres.
fn snow_deformable(s: SnowSurface, hit: SnowHit, hf: vec4<f32>, face: vec3<f32>, sky: vec3<f32>, pixel: f32) -> SnowSample {
    if hit.water == 1u {
        return snow_water(s, hf);
    }
    if hit.side == 1u {
        var cut = snow_basic(s, hit.position, face, sky, pixel);
        cut.ao = min(cut.ao, mix(1.0, hf.w, s.look.z));
        return cut;
    }
    let p = hit.position;
    let q = p.xz + s.pattern.xy;
    // The depression where the ray met the snow is the hit's own depth: it drives the stages (the
    // filtered `hf.x` is smoother but rounds off the bottoms of narrow prints).
    let dep = clamp(max(hf.x, 1.0 - p.y / s.snow_depth), 0.0, 1.0);
    // Stage weights: how much ground shows, and the transition (walls and rims of prints).
    // Where the ground shows: the renderer's look, or the material's own (sand and mud show
    // themselves at the bottom of prints until pressed almost through).
    var ground_from = s.look.x;
    var ground_full = s.look.y;
    if s.translucency.y > 0.0 {
        ground_from = s.translucency.y;
        ground_full = s.translucency.z;
    }
    let ground = smoothstep(ground_from, ground_full, dep);
    let rim = smoothstep(0.01, 0.12, dep);
    let transition = rim * (1.0 - ground) * (0.55 + 0.45 * (1.0 - smoothstep(0.3, 0.9, dep))) * s.translucency.x;

    // Normals. The heightmap's normal is the base; on it, RNM puts the snow's macro wave (pressed
    // flat where the snow is packed) and its detail, or the ground's own normal where it shows.
    let hn = vec3<f32>(hf.y, hf.z, sqrt(max(1.0 - hf.y * hf.y - hf.z * hf.z, 0.0)));
    let flatten = 1.0 - smoothstep(0.0, 0.5, dep);
    let wave = normalize(mix(vec3<f32>(0.0, 0.0, 1.0), snow_macro_normal(q), flatten));
    let snow_n = snow_combine(s, wave, snow_detail_normal(q, mix(1.0, 0.45, dep), pixel));
    var ground_layer: SnowLayer;
    if ground > 0.0 {
        ground_layer = snow_ground_layer(s, q, pixel);
    } else {
        ground_layer.albedo = vec3<f32>(0.0);
        ground_layer.roughness = 1.0;
        ground_layer.normal = vec3<f32>(0.0, 0.0, 1.0);
        ground_layer.f0 = 0.04;
    }
    // Detail normals of the two stages are mixed as perturbations of the same surface, then
    // reoriented onto the heightmap's normal.
    let detail = normalize(mix(snow_n, ground_layer.normal, ground));
    let n = snow_combine(s, hn, detail);

    // Diffuse and specular: a simple lerp between the stages, as in the talk. The ground is wet
    // where the snow was pressed onto it.
    // The material's own albedo: untouched on top, disturbed at the bottom of prints; a wet
    // material (mud) darkens and turns glossy quickly as it is pressed.
    var snow_albedo = mix(s.albedo.xyz, s.disturbed.xyz, smoothstep(0.05, 0.8, dep));
    var wet = dep;
    var f0 = 0.02;
    if s.grain.x > 0.0 {
        snow_albedo *= snow_grain_speckle(s, q, pixel);
    }
    if s.grain.z > 0.0 {
        let soaked = smoothstep(0.02, 0.3, dep) * s.grain.z;
        wet = max(dep, soaked);
        snow_albedo *= 1.0 - 0.35 * soaked;
        f0 = mix(0.02, 0.03, soaked);
    }
    let wet_ground = ground_layer.albedo * 0.8;
    var m: SnowSample;
    m.albedo = snow_tint(s, mix(snow_albedo, wet_ground, ground), transition, sky);
    m.roughness = mix(mix(s.albedo.w, s.disturbed.w, wet), ground_layer.roughness * 0.55, ground);
    m.f0 = mix(f0, 0.05, ground);
    m.sparkle = s.grain.y * (1.0 - smoothstep(0.05, 0.5, dep)) * (1.0 - ground);
    m.mirror = 0.0;
    m.normal = snow_ts_to_local(n);
    m.ao = mix(1.0, clamp(hf.w, 0.0, 1.0), s.look.z);
    m.ground = ground;
    m.transition = transition;
    m.wrap = 0.35 * (1.0 - ground) * s.translucency.x;
    return m;
}
