// surface.wgsl: the snow pass. Each surface is drawn as the box of its snow slab (top face at
// y = snow_depth, raised by the room for rims where the material throws them, four sides down to
// the ground; on ground that is not flat, from the lowest base of its columns to the highest snow
// top, and always with the deformable material) in its local frame; every fragment of the
// deformable material traces its view ray through the heightfield (snow.wgsl) and writes the depth
// of the point it hits, so characters standing in prints and bodies lying in trenches are hidden
// and shown correctly. On the visibility path (`fs_deformable_visible`, `fs_basic_visible`) the
// fragments write the hit into the visibility buffer and the hits target instead, and the compute
// entry `shade_deformable` (the `snow_shade` pass) shades it.
// Reads: frame uniforms, shadow map, the surface's heightfield texture (heightfield.wgsl), the
// world's ground fields; `shade_deformable`: the visibility buffer, the hits, the scene's depth.
// Writes: scene colour (HDR) and depth; the visibility buffer and the hits.

// import frame, snow, ground_texel

@group(1) @binding(0) var<uniform> surface: SnowSurface;
@group(1) @binding(1) var heightfield: texture_2d<f32>;
@group(1) @binding(2) var heightfield_light: texture_2d<f32>;
// Bank heights (metres, .x; banks.wgsl): the tessellated tier's banks, and the rims of materials
// that throw them (`translucency.w` > 0) in the relief and POM tiers.
@group(1) @binding(3) var bank_texture: texture_2d<f32>;
// The world's ground fields, `[base, bare]` per texel (read through `ground_texel`); the surface's
// field starts at `surface.terrain`, unread on flat ground.
@group(1) @binding(4) var<storage, read> ground: array<vec2<f32>>;

// Set when the device cannot filter Rgba16Float: bilinear filtering is then done by hand.
override MANUAL_FILTER: bool = false;

// Corners of the six faces of the box: face k uses vertices 6k..6k+5. The deformable material's
// box rises `rim_room` above the snow top, the room for rims. The bottom is seen only from inside
// the box (a camera standing in a valley's box, looking down at the snow through it).
fn box_vertex(i: u32, rim_room: f32) -> array<vec3<f32>, 2> {
    let face = i / 6u;
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    )[i % 6u];
    let a = corner * 2.0 - 1.0;
    let hx = surface.half_size.x;
    let hz = surface.half_size.y;
    let top = surface.terrain_top + rim_room;
    let y = surface.terrain_low + corner.y * (top - surface.terrain_low);
    var p: vec3<f32>;
    var n: vec3<f32>;
    switch face {
        // Top: counter-clockwise seen from above.
        case 0u: {
            p = vec3<f32>(a.x * hx, top, -a.y * hz);
            n = vec3<f32>(0.0, 1.0, 0.0);
        }
        case 1u: {
            p = vec3<f32>(hx, y, -a.x * hz);
            n = vec3<f32>(1.0, 0.0, 0.0);
        }
        case 2u: {
            p = vec3<f32>(-hx, y, a.x * hz);
            n = vec3<f32>(-1.0, 0.0, 0.0);
        }
        case 3u: {
            p = vec3<f32>(a.x * hx, y, hz);
            n = vec3<f32>(0.0, 0.0, 1.0);
        }
        case 4u: {
            p = vec3<f32>(-a.x * hx, y, -hz);
            n = vec3<f32>(0.0, 0.0, -1.0);
        }
        // Bottom: counter-clockwise seen from below.
        default: {
            p = vec3<f32>(a.x * hx, surface.terrain_low, a.y * hz);
            n = vec3<f32>(0.0, -1.0, 0.0);
        }
    }
    return array<vec3<f32>, 2>(p, n);
}

struct SurfaceVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) @interpolate(flat) face: vec3<f32>,
}

@vertex
fn vs_surface(@builtin(vertex_index) i: u32) -> SurfaceVarying {
    return surface_box(i, 0.0);
}

// The deformable material's box: raised by the room for rims (snow.wgsl's `snow_top`).
@vertex
fn vs_surface_deformable(@builtin(vertex_index) i: u32) -> SurfaceVarying {
    return surface_box(i, surface.translucency.w);
}

fn surface_box(i: u32, rim_room: f32) -> SurfaceVarying {
    let v = box_vertex(i, rim_room);
    var out: SurfaceVarying;
    let world = surface.local_to_world * vec4<f32>(v[0], 1.0);
    out.clip = frame.view_proj * world;
    out.local = v[0];
    out.face = v[1];
    return out;
}

// The bank texture has the heightfield's border (banks.wgsl).
fn bank_texel(c: vec2<i32>) -> f32 {
    return textureLoad(bank_texture, border_texel(c), 0).x;
}

// Bank height (metres) at uv, bilinear by hand (also usable in the vertex stage).
fn bank_height(uv: vec2<f32>) -> f32 {
    let p = uv * surface.grid - 0.5;
    let i = floor(p);
    let f = p - i;
    let c = vec2<i32>(i);
    let a = mix(bank_texel(c), bank_texel(c + vec2<i32>(1, 0)), f.x);
    let b = mix(bank_texel(c + vec2<i32>(0, 1)), bank_texel(c + vec2<i32>(1, 1)), f.x);
    return mix(a, b, f.y);
}

// Slope of the banks at uv (metres per metre along local x and z), central differences.
fn bank_gradient(uv: vec2<f32>) -> vec2<f32> {
    let du = vec2<f32>(1.0 / surface.grid.x, 0.0);
    let dv = vec2<f32>(0.0, 1.0 / surface.grid.y);
    let step = 2.0 * surface.half_size / surface.grid;
    return vec2<f32>(
        (bank_height(uv + du) - bank_height(uv - du)) / (2.0 * step.x),
        (bank_height(uv + dv) - bank_height(uv - dv)) / (2.0 * step.y),
    );
}

// The heightfield, light and bank textures hold a border of HEIGHTFIELD_BORDER texels around the
// heightmap's (heightfield.wgsl): the texels of the surface beside that side where one is linked,
// else the edge repeated. Texel `c` of the heightmap is the textures' `c + HEIGHTFIELD_BORDER`;
// `border_uv` maps the heightmap's uv to the textures'.
fn border_texel(c: vec2<i32>) -> vec2<i32> {
    let b = HEIGHTFIELD_BORDER;
    return clamp(c, vec2<i32>(-b), vec2<i32>(surface.grid) + b - 1) + b;
}

fn border_uv(uv: vec2<f32>) -> vec2<f32> {
    let b = f32(HEIGHTFIELD_BORDER);
    return (uv * surface.grid + b) / (surface.grid + 2.0 * b);
}

fn load_texel(c: vec2<i32>) -> vec4<f32> {
    return textureLoad(heightfield, border_texel(c), 0);
}

// Bilinear filtering by hand (the fallback when the format cannot be filtered).
fn manual_bilinear(uv: vec2<f32>) -> vec4<f32> {
    let p = uv * surface.grid - 0.5;
    let i = floor(p);
    let f = p - i;
    let c = vec2<i32>(i);
    let a = mix(load_texel(c), load_texel(c + vec2<i32>(1, 0)), f.x);
    let b = mix(load_texel(c + vec2<i32>(0, 1)), load_texel(c + vec2<i32>(1, 1)), f.x);
    return mix(a, b, f.y);
}

fn sample_bilinear(uv: vec2<f32>) -> vec4<f32> {
    if MANUAL_FILTER {
        return manual_bilinear(uv);
    }
    return textureSampleLevel(heightfield, linear_sampler, border_uv(uv), 0.0);
}

fn ground_column(c: vec2<i32>) -> vec2<f32> {
    let t = clamp(c, vec2<i32>(0), vec2<i32>(surface.grid) - 1);
    return ground_texel(surface.terrain, surface.width, u32(t.x), u32(t.y));
}

// (base, bare) of the ground field at uv, bilinear between texel centres (as the heightmap);
// (0, 0) on flat ground.
fn ground_at_uv(uv: vec2<f32>) -> vec2<f32> {
    if surface.terrain == SNOW_NO_GROUND {
        return vec2<f32>(0.0);
    }
    let p = uv * surface.grid - 0.5;
    let i = floor(p);
    let f = p - i;
    let c = vec2<i32>(i);
    let a = mix(ground_column(c), ground_column(c + vec2<i32>(1, 0)), f.x);
    let b = mix(ground_column(c + vec2<i32>(0, 1)), ground_column(c + vec2<i32>(1, 1)), f.x);
    return mix(a, b, f.y);
}

// Slope of the columns' base at uv (metres per metre along local x and z): the untouched snow
// top's, central differences a texel apart.
fn ground_gradient(uv: vec2<f32>) -> vec2<f32> {
    let du = vec2<f32>(1.0 / surface.grid.x, 0.0);
    let dv = vec2<f32>(0.0, 1.0 / surface.grid.y);
    let step = 2.0 * surface.half_size / surface.grid;
    return vec2<f32>(
        (ground_at_uv(uv + du).x - ground_at_uv(uv - du).x) / (2.0 * step.x),
        (ground_at_uv(uv + dv).x - ground_at_uv(uv - dv).x) / (2.0 * step.y),
    );
}

// The heightfield contract of snow.wgsl: the base of the snow column.
fn snow_ground_base(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return ground_at_uv(uv).x;
}

// The heightfield contract of snow.wgsl, for the search: one bilinear tap of the smoothed
// depression. (A smoothstep remap of the weights would remove the creases at texel boundaries,
// but its flat spots at texel centres pull the rims of deep pits onto the texel grid.) Where the
// material throws rims, the banks raise the top: less depression, below zero on a rim.
fn snow_depression(s: SnowSurface, uv: vec2<f32>) -> f32 {
    let dep = sample_bilinear(uv).x;
    if s.translucency.w > 0.0 {
        return dep - bank_height(uv) / s.snow_depth;
    }
    return dep;
}

// ... and for shading: a cubic B-spline from four bilinear taps (smooth normals and occlusion,
// no texel grid).
fn snow_heightfield(s: SnowSurface, uv: vec2<f32>) -> vec4<f32> {
    let p = uv * s.grid - 0.5;
    let i = floor(p);
    let f = p - i;
    let f2 = f * f;
    let f3 = f2 * f;
    let w0 = (1.0 / 6.0) * (-f3 + 3.0 * f2 - 3.0 * f + 1.0);
    let w1 = (1.0 / 6.0) * (3.0 * f3 - 6.0 * f2 + 4.0);
    let w2 = (1.0 / 6.0) * (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0);
    let w3 = (1.0 / 6.0) * f3;
    let g0 = w0 + w1;
    let g1 = w2 + w3;
    let h0 = (i - 0.5 + w1 / g0) / s.grid;
    let h1 = (i + 1.5 + w3 / g1) / s.grid;
    let a = mix(sample_bilinear(vec2<f32>(h1.x, h0.y)), sample_bilinear(vec2<f32>(h0.x, h0.y)), g0.x);
    let b = mix(sample_bilinear(vec2<f32>(h1.x, h1.y)), sample_bilinear(vec2<f32>(h0.x, h1.y)), g0.x);
    return mix(b, a, g0.y);
}

// ... and the moon's visibility over the prints (heightfield.wgsl), one bilinear tap.
fn snow_light_visibility(s: SnowSurface, uv: vec2<f32>) -> f32 {
    if MANUAL_FILTER {
        let size = vec2<i32>(s.grid);
        let c = clamp(vec2<i32>(floor(uv * s.grid)), vec2<i32>(0), size - 1);
        return textureLoad(heightfield_light, c + HEIGHTFIELD_BORDER, 0).x;
    }
    return textureSampleLevel(heightfield_light, linear_sampler, border_uv(uv), 0.0).x;
}

fn sky_tint() -> vec3<f32> {
    return mix(vec3<f32>(1.0), frame.sss_tint.rgb, frame.sss_tint.w);
}

// Light a material sample at `local` (`pixel`: the pixel's footprint, metres): the frame's lights,
// then the grains' glints towards the moon and the sky mirrored by water, where the material has
// them (snow.wgsl's `snow_sparkle`, `snow_water_reflection`).
fn shade(m: SnowSample, local: vec3<f32>, shadow_in: f32, pixel: f32) -> vec3<f32> {
    let world = (surface.local_to_world * vec4<f32>(local, 1.0)).xyz;
    let n = normalize((surface.local_to_world * vec4<f32>(m.normal, 0.0)).xyz);
    let shadow = moon_shadow(world, n) * shadow_in;
    var c = light_surface(m.albedo, m.roughness, m.f0, n, world, m.ao, m.wrap, shadow);
    let v = normalize(frame.eye.xyz - world);
    if m.sparkle > 0.0 {
        let q = local.xz + surface.pattern.xy;
        let glint = snow_sparkle(q, n, v, frame.moon_dir.xyz, pixel);
        c += frame.moon_color.rgb * shadow * m.sparkle * glint;
    }
    if m.mirror > 0.0 {
        let sky = sky_radiance(reflect(-v, n));
        c += m.mirror * m.ao * snow_water_reflection(sky, dot(n, v));
    }
    return c;
}

struct SnowOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The deformable snow material (the talk's second material): relief mapping (or POM), the two
// stages blended by the heightmap, RNM normals, fake SSS, occlusion from the heightmap.
//
// Both sides of the box are rasterised: from outside it, its front faces, the ray entering where
// the face is; from inside it (a camera standing in a valley's box, metres tall), its back faces,
// the ray starting at the eye. The other side's fragments are discarded.
@fragment
fn fs_deformable(in: SurfaceVarying, @builtin(front_facing) front: bool) -> SnowOut {
    // Footprint of the pixel on the surface, before any non-uniform control flow.
    let pixel = length(fwidth(in.local));
    let hit = trace_pixel(in, front);
    var out: SnowOut;
    out.color = vec4<f32>(shade_hit(hit, in.face, pixel), 1.0);
    out.depth = hit_depth(hit);
    return out;
}

// The view ray of a fragment of the box traced through the heightfield; the fragment is
// discarded where it meets no snow, or where a finer terrain window level draws instead
// (`SnowSurface::hole`; `through_hole`).
fn trace_pixel(in: SurfaceVarying, front: bool) -> SnowHit {
    let eye = (surface.world_to_local * vec4<f32>(frame.eye.xyz, 1.0)).xyz;
    let top = snow_top(surface);
    let inside = all(abs(eye.xz) <= surface.half_size) && eye.y >= surface.terrain_low && eye.y <= top;
    if front == inside {
        discard;
    }
    let o = select(in.local, eye, inside);
    let d = normalize(in.local - eye);
    let moon = normalize((surface.world_to_local * vec4<f32>(frame.moon_dir.xyz, 0.0)).xyz);
    var hit = through_hole(o, d, moon);
    if hit.found == 0u {
        discard;
    }
    if hit.side == 1u && !inside && snow_seam_side(surface, face_side(in.face)) {
        // Entered through a side where another surface's snow goes on: the step between the two
        // tops, shaded as the top.
        hit.side = 0u;
        hit.shadow = snow_light_visibility(surface, snow_uv(surface, hit.position.xz));
    }
    return hit;
}

// The ray from `o` along `d` traced through the heightfield, leaving the surface's hole to the
// finer terrain window level that draws it. Where the first snow met lies in the hole, the ray
// goes on from where it leaves the hole: under this level's snow there it meets the step
// between the two levels' tops (the finer level lower at its edge, as in a print that this
// coarser level holds shallower), drawn as this level's top there (the tessellated tier's seam
// skirts, tessellate/seams.rs); above it, it is traced again beyond the hole. Not found (0)
// where the ray meets no snow outside the hole.
fn through_hole(o: vec3<f32>, d: vec3<f32>, moon: vec3<f32>) -> SnowHit {
    var origin = o;
    var gone = 0.0;
    var hit: SnowHit;
    for (var attempt = 0u; attempt < 2u; attempt++) {
        hit = snow_trace(surface, origin, d, frame.options.z, moon);
        hit.t += gone;
        if hit.found == 0u || !snow_in_hole(surface, hit.position.xz) {
            return hit;
        }
        let t = hole_exit(origin, d);
        let p = origin + d * t;
        if attempt == 1u || t <= 0.0 || any(abs(p.xz) > surface.half_size) {
            break;
        }
        if snow_inside(surface, origin, d, t) {
            // The step; under the ground it is the ground's, not the snow's.
            if p.y < snow_ground_base(surface, snow_uv(surface, p.xz)) {
                break;
            }
            hit.position = p;
            hit.t = gone + t;
            hit.side = 0u;
            hit.water = 0u;
            hit.taps += 1u;
            hit.shadow = snow_light_visibility(surface, snow_uv(surface, p.xz));
            return hit;
        }
        // A hair past the hole's line, so that the next trace starts outside it.
        origin = p + d * 1e-4;
        gone += t + 1e-4;
    }
    hit.found = 0u;
    return hit;
}

// Where a ray from `o` along `d` leaves the surface's hole (its far side along the ray), as a
// distance along it (3e38 when it runs along both axes' lines).
fn hole_exit(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let lo = surface.hole.xy;
    let hi = surface.hole.zw;
    var t = 3.0e38;
    if d.x != 0.0 {
        t = min(t, (select(lo.x, hi.x, d.x > 0.0) - o.x) / d.x);
    }
    if d.z != 0.0 {
        t = min(t, (select(lo.y, hi.y, d.z > 0.0) - o.z) / d.z);
    }
    return t;
}

// Side k (local -x, +x, -z, +z) of a box face's normal (a side face's).
fn face_side(face: vec3<f32>) -> u32 {
    if abs(face.x) > 0.5 {
        return select(0u, 1u, face.x > 0.0);
    }
    return select(2u, 3u, face.z > 0.0);
}

// The depth of a hit, as the scene's depth target stores it.
fn hit_depth(hit: SnowHit) -> f32 {
    let world = surface.local_to_world * vec4<f32>(hit.position, 1.0);
    let clip = frame.view_proj * world;
    return clamp(clip.z / clip.w, 0.0, 1.0);
}

// The colour of a hit (`face`: the normal of the box face rasterised, `pixel`: the pixel's
// footprint, metres): the deformable material sampled there and lit, or the frame's debug view.
fn shade_hit(hit: SnowHit, face: vec3<f32>, pixel: f32) -> vec3<f32> {
    let uv = snow_uv(surface, hit.position.xz);
    var hf = snow_heightfield(surface, uv);
    if surface.translucency.w > 0.0 {
        // Rims: the heightmap's slope tilted by the banks', as the tessellated tier shades them.
        let ny = max(sqrt(max(1.0 - hf.y * hf.y - hf.z * hf.z, 0.0)), 1e-3);
        let g = vec2<f32>(-hf.y, -hf.z) / ny + bank_gradient(uv);
        let n = normalize(vec3<f32>(-g.x, 1.0, -g.y));
        hf = vec4<f32>(hf.x, n.x, n.z, hf.w);
    }
    var at = hit;
    if surface.terrain != SNOW_NO_GROUND {
        let on = on_ground(hit, hf, uv);
        at = on.hit;
        hf = on.hf;
    }
    let m = snow_deformable(surface, at, hf, face, sky_tint(), pixel);
    return deformable_view(shade(m, hit.position, hit.shadow, pixel), m, hf.x, f32(hit.taps) / 48.0);
}

// The deformable material on the visibility path (`OpaquePath::Visibility`): the fragment only
// traces, and writes its hit into the visibility buffer; `shade_deformable` shades it in compute
// (on GPUs with few graphics units, the shading costs far more in a fragment than in compute).
struct SnowVisible {
    // (SNOW_VISIBLE | slot << SNOW_SLOT_SHIFT | taps << 5 | water << 4 | side << 3 | face,
    // pixel footprint bits)
    @location(0) visibility: vec2<u32>,
    // The hit, surface-local, and its self-shadow, as bits.
    @location(1) hit: vec4<u32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_deformable_visible(in: SurfaceVarying, @builtin(front_facing) front: bool) -> SnowVisible {
    let pixel = length(fwidth(in.local));
    let hit = trace_pixel(in, front);
    var out: SnowVisible;
    out.depth = hit_depth(hit);
    let flags = min(hit.taps, 255u) << 5u | (hit.water & 1u) << 4u | (hit.side & 1u) << 3u | face_code(in.face);
    out.visibility = vec2<u32>(snow_visible_id(surface.index) | flags, bitcast<u32>(pixel));
    out.hit = vec4<u32>(bitcast<vec3<u32>>(hit.position), bitcast<u32>(hit.shadow));
    return out;
}

// The high bits of a snow pixel's first visibility word: the tag and the surface's slot.
fn snow_visible_id(slot: u32) -> u32 {
    return SNOW_VISIBLE | slot << SNOW_SLOT_SHIFT;
}

// A box face's normal as three bits (its axis, and its sign in the third bit), and back.
fn face_code(n: vec3<f32>) -> u32 {
    let axis = select(select(2u, 1u, n.y != 0.0), 0u, n.x != 0.0);
    return axis | select(0u, 4u, n.x + n.y + n.z < 0.0);
}

fn face_normal(code: u32) -> vec3<f32> {
    var n = vec3<f32>(0.0);
    n[code & 3u] = select(1.0, -1.0, (code & 4u) != 0u);
    return n;
}

@group(2) @binding(0) var visibility: texture_2d<u32>;
@group(2) @binding(1) var snow_hits: texture_2d<u32>;
@group(2) @binding(2) var scene_color: texture_storage_2d<rgba16float, write>;
@group(2) @binding(3) var scene_depth: texture_depth_2d;
// Per surface slot: the rectangle of pixels [x0, x1) x [y0, y1) its box covers on screen.
@group(2) @binding(4) var<storage, read> shade_rects: array<vec4<u32>>;

// A pixel of this surface's dispatch (invocation `at` of its rectangle) and what the visibility
// buffer and the hits hold there; `mine` where that is this surface's hit. Where nothing was drawn
// (depth 1) the buffer holds an earlier frame's words and is not read.
struct VisibleSnow {
    mine: bool,
    pixel: vec2<u32>,
    words: vec2<u32>,
    hit: vec4<u32>,
}

fn visible_snow(at: vec2<u32>) -> VisibleSnow {
    var s: VisibleSnow;
    let rect = shade_rects[surface.index];
    s.pixel = rect.xy + at;
    if s.pixel.x >= rect.z || s.pixel.y >= rect.w {
        return s;
    }
    s.words = textureLoad(visibility, s.pixel, 0).xy;
    let id_bits = ~((1u << SNOW_SLOT_SHIFT) - 1u);
    s.mine = (s.words.x & id_bits) == snow_visible_id(surface.index)
        && textureLoad(scene_depth, s.pixel, 0) < 1.0;
    if s.mine {
        s.hit = textureLoad(snow_hits, s.pixel, 0);
    }
    return s;
}

// The visibility buffer's snow, shaded: one dispatch per relief-mapped surface over the
// rectangle its box covers, each pixel shaded only where the visibility buffer holds this
// surface's hit (every fragment that writes the scene's depth before this pass writes the
// buffer too, so it holds what the scene shows wherever something was drawn).
@compute @workgroup_size(8, 8, 1)
fn shade_deformable(@builtin(global_invocation_id) id: vec3<u32>) {
    let s = visible_snow(id.xy);
    if !s.mine {
        return;
    }
    let p = s.pixel;
    let v = s.words;
    let h = s.hit;
    var hit: SnowHit;
    hit.position = bitcast<vec3<f32>>(h.xyz);
    hit.t = 0.0;
    hit.found = 1u;
    hit.taps = (v.x >> 5u) & 255u;
    hit.water = (v.x >> 4u) & 1u;
    hit.side = (v.x >> 3u) & 1u;
    hit.shadow = bitcast<f32>(h.w);
    textureStore(scene_color, p, vec4<f32>(shade_hit(hit, face_normal(v.x & 7u), bitcast<f32>(v.y)), 1.0));
}

struct OnGround {
    hit: SnowHit,
    hf: vec4<f32>,
}

// The material is written for snow on flat ground; on ground that is not flat, give it the hit and
// the heightfield as they are measured from the ground under the hit: the hit's height above the
// ground scaled to a whole depth (a slope that holds a fraction k of the depth is pressed through
// at a depression of k, so the ground shows there), the depression as a fraction of the snow the
// column holds, and the heightfield's normal reoriented onto the ground's (RNM), so prints follow
// the slope. The hit's true position stays the caller's for lighting and depth.
fn on_ground(hit: SnowHit, hf_in: vec4<f32>, uv: vec2<f32>) -> OnGround {
    let g = ground_at_uv(uv);
    let d = surface.snow_depth;
    let held = max(d - g.y, 1e-3 * d) / d;
    var out: OnGround;
    out.hit = hit;
    out.hit.position.y = (hit.position.y - g.x - g.y) / held;
    let base_n = snow_normal_from_gradient(ground_gradient(uv));
    let hn = vec3<f32>(hf_in.y, hf_in.z, sqrt(max(1.0 - hf_in.y * hf_in.y - hf_in.z * hf_in.z, 0.0)));
    let n = snow_rnm(base_n, hn);
    out.hf = vec4<f32>(hf_in.x / held, n.x, n.y, hf_in.w);
    // Where a slope holds almost none of the depth (under a tenth) the division above magnifies
    // the search's last bits into speckle: the rock shows there, as where a print reaches the
    // ground, fading in as the snow thins.
    let snow = smoothstep(0.0, 0.1, held);
    out.hit.position.y = mix(0.0, out.hit.position.y, snow);
    out.hf.x = mix(1.0, out.hf.x, snow);
    return out;
}

// What a pixel of the deformable material shows in the frame's debug view (`shaded` otherwise):
// the material's stages, the depression, the occlusion, the normal, or the search's taps (as a
// fraction of 48). Shared by the relief and tessellated tiers.
fn deformable_view(shaded: vec3<f32>, m: SnowSample, depression: f32, taps: f32) -> vec3<f32> {
    switch frame.options.x {
        case DEBUG_MATERIALS: {
            if m.mirror > 0.5 {
                return vec3<f32>(0.0, 0.9, 1.0);   // water
            }
            return mix(vec3<f32>(1.0, 0.45, 0.1), vec3<f32>(0.35, 0.2, 0.1), m.ground) * (0.3 + 0.7 * m.ao) + vec3<f32>(0.0, 0.2, 0.9) * m.transition;
        }
        case DEBUG_DEPRESSION: {
            return debug_ramp(depression);
        }
        case DEBUG_OCCLUSION: {
            return vec3<f32>(m.ao);
        }
        case DEBUG_NORMALS: {
            return m.normal * 0.5 + 0.5;
        }
        case DEBUG_TAPS: {
            return debug_ramp(taps);
        }
        default: {
            return shaded;
        }
    }
}

// The basic snow material (the talk's first material): untouched snow, no heightmap, no search.
@fragment
fn fs_basic(in: SurfaceVarying) -> @location(0) vec4<f32> {
    let pixel = length(fwidth(in.local));
    if snow_in_hole(surface, in.local.xz) {
        discard;
    }
    return basic_color(in, pixel);
}

struct BasicVisible {
    @location(0) color: vec4<f32>,
    // Nothing for the compute passes to shade here (the visibility buffer is not cleared: every
    // fragment that writes the scene's depth before them writes it).
    @location(1) visibility: vec2<u32>,
}

// The basic material on the visibility path: its colour, and the visibility buffer told that the
// pixel is shaded.
@fragment
fn fs_basic_visible(in: SurfaceVarying) -> BasicVisible {
    let pixel = length(fwidth(in.local));
    if snow_in_hole(surface, in.local.xz) {
        discard;
    }
    var out: BasicVisible;
    out.color = basic_color(in, pixel);
    out.visibility = vec2<u32>(0xffffffffu);
    return out;
}

fn basic_color(in: SurfaceVarying, pixel: f32) -> vec4<f32> {
    let m = snow_basic(surface, in.local, in.face, sky_tint(), pixel);
    var c = shade(m, in.local, 1.0, pixel);
    switch frame.options.x {
        case DEBUG_MATERIALS: {
            c = vec3<f32>(0.15, 0.8, 0.3) * (0.5 + 0.5 * m.normal.y);
        }
        case DEBUG_DEPRESSION: {
            c = debug_ramp(0.0);
        }
        case DEBUG_OCCLUSION: {
            c = vec3<f32>(m.ao);
        }
        case DEBUG_NORMALS: {
            c = m.normal * 0.5 + 0.5;
        }
        case DEBUG_TAPS: {
            c = debug_ramp(0.0);
        }
        default: {}
    }
    return vec4<f32>(c, 1.0);
}
