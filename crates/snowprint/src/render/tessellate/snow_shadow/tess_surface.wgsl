// tess_surface.wgsl: the tessellated tier's snow, drawn from the vertices `dice.wgsl` wrote.
// The vertex stage displaces each vertex of the top to the snow there: the base height, plus the
// snow depth minus the depression (the heightfield pass's smoothed depression), plus the banks
// (banks.wgsl), plus the macro "waves" of snow.wgsl's `snow_macro_height` (the same function whose
// normal the relief tier shades with), pressed flat where the snow is packed. Where the material
// has water (mud) and a print is deeper than its water depth, the top is the flat water surface at
// the water table instead, so the water is real geometry (in the shadow map too) and the fragment
// stage shades it as the relief tier's water: a mirror of the sky. Skirt vertices at the base stay
// there. On ground that is not flat every vertex, skirts included, is lifted by the base of the
// snow column under it (the ground field, `ground_at_uv`): the snow, its prints and banks follow
// the slope, and the skirts close the cut down to the ground. The fragment stage shades the real surface with the deformable material
// (snow.wgsl) without any search: the heightmap's normal tilted by the banks' slope, RNM detail,
// the heightmap's AO, and the moon's shadow from the shadow map, which holds this same displaced
// geometry (vs_tess_shadow), so trails shadow themselves and characters' shadows bend into them.
// Imports surface.wgsl (and with it frame.wgsl and snow.wgsl): its bindings 0-4 of group 1 (the
// bank texture and `bank_height`, the ground fields and `ground_at_uv` included) and its heightfield contract are reused.
// Reads: frame uniforms, shadow map, the surface's heightfield, light and bank textures, the
// surface state, diced vertices and indices. Writes: scene colour and depth, or a shadow cascade;
// on the visibility path (`fs_tess_visible`) the visibility buffer and the hits, which `shade_tess`
// shades into the scene colour.

// import surface

@group(1) @binding(5) var<storage, read> surface_state: array<u32>;

// Mean of snow_macro_height over a large area, taken out so the waves move the snow both ways.
const MACRO_MEAN: f32 = 0.025;

struct TessVertex {
    @location(0) position: vec4<f32>,   // xyz local (y: the base), w: 0 top, 1 skirt top, 2 skirt base
    @location(1) outward: vec4<f32>,    // skirts: outward normal; top and seams' skirts: the base's slope (xz); w: 1 on seams' skirts
}

struct TessVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) @interpolate(flat) outward: vec4<f32>,   // w: 1 on skirts; top: base slope in xz
}

fn tess_touched() -> bool {
    return surface_state[surface.index * STATE_WORDS + STATE_TOUCHED] != 0u;
}

// Snow top above the base at local xz, metres: depth minus depression, plus banks, plus the
// macro waves (scaled by pattern.w, flattened where the snow is pressed).
fn tess_material_height(xz: vec2<f32>) -> f32 {
    var dep = 0.0;
    var bank = 0.0;
    if tess_touched() {
        let uv = snow_uv(surface, xz);
        dep = manual_bilinear(uv).x;
        bank = bank_height(uv);
    }
    let flatten = 1.0 - smoothstep(0.0, 0.5, dep);
    let waves = surface.pattern.w * (snow_macro_height(xz + surface.pattern.xy) - MACRO_MEAN) * flatten;
    return surface.snow_depth * (1.0 - dep) + bank + waves;
}

// Whether the material at local xz lies under the water table (snow.wgsl's `snow_water_level`):
// a print deeper than the material's water depth, filled with water up to it.
fn tess_under_water(xz: vec2<f32>) -> bool {
    let level = snow_water_level(surface);
    return level >= 0.0 && tess_touched() && tess_material_height(xz) < level;
}

// The top above the base at local xz: the material's, or the water's flat surface over it.
fn tess_snow_height(xz: vec2<f32>) -> f32 {
    let h = tess_material_height(xz);
    if tess_under_water(xz) {
        return snow_water_level(surface);
    }
    return h;
}

fn tess_local(v: TessVertex) -> vec3<f32> {
    var p = v.position.xyz;
    if v.position.w < 1.5 {
        p.y += tess_snow_height(p.xz);
    }
    if surface.terrain != SNOW_NO_GROUND {
        p.y += ground_at_uv(snow_uv(surface, p.xz)).x;
    }
    return p;
}

// Whether local xz lies in the surface's hole, less a millimetre: the renderer's rectangle is
// diced with the hole cut out (render/tessellate/seams.rs), and the skirts on its sides, which
// lie on the hole's lines, are kept; a mesh the user gave is cut here.
fn tess_in_hole(xz: vec2<f32>) -> bool {
    return all(xz > surface.hole.xy + 1e-3) && all(xz < surface.hole.zw - 1e-3);
}

@vertex
fn vs_tess(v: TessVertex) -> TessVarying {
    let p = tess_local(v);
    var out: TessVarying;
    out.clip = frame.view_proj * (surface.local_to_world * vec4<f32>(p, 1.0));
    out.local = p;
    // A seam's skirt (outward.w 1) is shaded as the top: it closes the step between two
    // surfaces' tops (dice.wgsl), and its `outward` holds the base's slope.
    out.outward = vec4<f32>(v.outward.xyz, select(0.0, 1.0, v.position.w > 0.5 && v.outward.w < 0.5));
    return out;
}

// Which shadow cascade a shadow pipeline renders (0 near, 1 far).
override TESS_SHADOW_CASCADE: u32 = 0u;

@vertex
fn vs_tess_shadow(v: TessVertex) -> @builtin(position) vec4<f32> {
    var m = frame.shadow_far;
    if TESS_SHADOW_CASCADE == 0u {
        m = frame.shadow_near;
    }
    return m * (surface.local_to_world * vec4<f32>(tess_local(v), 1.0));
}

@fragment
fn fs_tess(in: TessVarying) -> @location(0) vec4<f32> {
    let pixel = length(fwidth(in.local));
    if tess_in_hole(in.local.xz) {
        discard;
    }
    return vec4<f32>(tess_shade(in.local, in.outward, pixel), 1.0);
}

// The colour of the diced snow at `local` (`outward`: the varying of that name, `pixel`: the
// pixel's footprint, metres).
fn tess_shade(local: vec3<f32>, outward: vec4<f32>, pixel: f32) -> vec3<f32> {
    var m: SnowSample;
    var hf = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if outward.w > 0.5 {
        // A skirt: the cut through the snow at an open edge, as the relief tier's box sides.
        let face = normalize(vec3<f32>(outward.x, 0.0, outward.z));
        var cut = local;
        cut.y -= ground_at_uv(snow_uv(surface, local.xz)).x;
        m = snow_basic(surface, cut, face, sky_tint(), pixel);
    } else {
        let uv = snow_uv(surface, local.xz);
        // The snow top's slope: the base mesh's (a pitched roof), plus the heightmap's and the
        // banks' where something pressed the snow.
        var g = outward.xz;
        if tess_touched() {
            hf = snow_heightfield(surface, uv);
            let ny = max(sqrt(max(1.0 - hf.y * hf.y - hf.z * hf.z, 0.0)), 1e-3);
            g += vec2<f32>(-hf.y, -hf.z) / ny + bank_gradient(uv);
        }
        if surface.terrain != SNOW_NO_GROUND {
            // The ground's slope under the snow; the stages see the depression as a fraction of
            // the snow the column holds (as the relief tier's `on_ground`).
            g += ground_gradient(uv);
            let d = surface.snow_depth;
            hf.x /= max(d - ground_at_uv(uv).y, 1e-3 * d) / d;
        }
        let n = normalize(vec3<f32>(-g.x, 1.0, -g.y));
        hf = vec4<f32>(hf.x, n.x, n.z, hf.w);
        var hit: SnowHit;
        // The depression drives the stages; the height of the hit is the filtered one.
        hit.position = vec3<f32>(local.x, surface.snow_depth, local.z);
        hit.found = 1u;
        hit.side = 0u;
        hit.shadow = 1.0;
        hit.taps = 0u;
        hit.t = 0.0;
        // Water: the diced top is the flat water surface where the material lies under it.
        hit.water = select(0u, 1u, tess_under_water(local.xz));
        m = snow_deformable(surface, hit, hf, vec3<f32>(0.0, 1.0, 0.0), sky_tint(), pixel);
    }
    // No search in this tier: no taps.
    return deformable_view(shade(m, local, 1.0, pixel), m, hf.x, 0.0);
}

// The diced snow on the visibility path (`OpaquePath::Visibility`): the fragment writes what
// `tess_shade` reads into the visibility buffer (as surface.wgsl's `SnowVisible`: the tag and
// slot, bit 3 set on skirts; the footprint) and the hits target (`local`, and `outward.xz` as two
// halves: a slope or an axis), and `shade_tess` shades it in compute.
struct TessVisible {
    @location(0) visibility: vec2<u32>,
    @location(1) hit: vec4<u32>,
}

@fragment
fn fs_tess_visible(in: TessVarying) -> TessVisible {
    let pixel = length(fwidth(in.local));
    if tess_in_hole(in.local.xz) {
        discard;
    }
    // The depth is the rasterised one (written by the fixed function, as the forward path's).
    var out: TessVisible;
    let skirt = select(0u, 8u, in.outward.w > 0.5);
    out.visibility = vec2<u32>(snow_visible_id(surface.index) | skirt, bitcast<u32>(pixel));
    out.hit = vec4<u32>(bitcast<vec3<u32>>(in.local), pack2x16float(in.outward.xz));
    return out;
}

// The visibility buffer's diced snow of this surface, shaded (as surface.wgsl's
// `shade_deformable`, over the same rectangles and targets).
@compute @workgroup_size(8, 8, 1)
fn shade_tess(@builtin(global_invocation_id) id: vec3<u32>) {
    let s = visible_snow(id.xy);
    if !s.mine {
        return;
    }
    let xz = unpack2x16float(s.hit.w);
    let outward = vec4<f32>(xz.x, 0.0, xz.y, select(0.0, 1.0, (s.words.x & 8u) != 0u));
    let c = tess_shade(bitcast<vec3<f32>>(s.hit.xyz), outward, bitcast<f32>(s.words.y));
    textureStore(scene_color, s.pixel, vec4<f32>(c, 1.0));
}
