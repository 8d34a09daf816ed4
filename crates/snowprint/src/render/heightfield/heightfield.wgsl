// heightfield.wgsl: turns one surface's heightmap in the pool into the texture the snow material
// samples with filtering: (depression, normal.x, normal.z, ambient occlusion) per texel. Normals
// by a 3x3 Sobel filter, occlusion from the horizon of the snow around each texel (the talk's
// "derive parametric AO from the heightmap"; the depression itself is stored smoothed by a 3x3
// binomial filter), and a second texture with the moon's visibility
// over the snow of each texel (a soft shadow of the prints' walls on their floors, computed once
// per texel instead of per pixel) in .r and the displaced snow (the pool's high 16 bits, raw) in
// .g, which the tessellated tier's banks read. Dispatched over every surface the frame can show;
// a surface on the basic material (classify.wgsl's STATE_SHADED, 0) leaves at once.
// The textures hold HEIGHTFIELD_BORDER texels more on each side than the heightmap: there, and in
// every tap that reaches past the surface's edge, the heights are those of the surface linked
// beside that side (render/heightfield/sides.rs) where there is one, so that two surfaces side by
// side shade as one; elsewhere the taps clamp to the edge and the border repeats it.
// Reads: the heightmap pool (this surface's and its neighbours'), the surface state table.
// Writes: the surface's heightfield and light textures.
// CPU reference: render::cpu::{smoothed_depression, sobel_normal, horizon_ao, light_visibility,
// displaced_fraction}.

// import heightfield_texels, constants, ground_texel

// `pool` and `params` are what heightfield_texels.wgsl reads.
@group(0) @binding(0) var<storage, read> pool: array<u32>;
@group(0) @binding(1) var<uniform> params: HeightfieldParams;
@group(0) @binding(2) var out_texture: texture_storage_2d<rgba16float, write>;
@group(0) @binding(3) var out_light: texture_storage_2d<rgba16float, write>;
// The world's ground fields; this surface's starts at `params.ground`.
@group(0) @binding(4) var<storage, read> ground: array<vec2<f32>>;
// The surface state table (classify.wgsl); this surface's words start at `params.slot`'s.
@group(0) @binding(5) var<storage, read> state: array<u32>;

// Must match AO_RADII in cpu.rs (PENUMBRA_*, LIGHT_TAPS and AO_DIRECTIONS: constants.wgsl).
const AO_RADII: array<f32, 4> = array<f32, 4>(0.04, 0.09, 0.16, 0.28);

// Snow height (metres above the ground) at the texel nearest to a metric offset.
fn height_at(c: i32, r: i32, dx: f32, dz: f32) -> f32 {
    let oc = i32(round(dx / params.texel_x));
    let orow = i32(round(dz / params.texel_z));
    return params.snow_depth * (1.0 - depression(c + oc, r + orow));
}

// Snow height at a local offset (metres) from texel (c, r), bilinear between texel centres.
fn height_bilinear(c: i32, r: i32, dx: f32, dz: f32) -> f32 {
    let fx = dx / params.texel_x;
    let fz = dz / params.texel_z;
    let ix = floor(fx);
    let iz = floor(fz);
    let wx = fx - ix;
    let wz = fz - iz;
    let x0 = c + i32(ix);
    let z0 = r + i32(iz);
    let a = mix(depression(x0, z0), depression(x0 + 1, z0), wx);
    let b = mix(depression(x0, z0 + 1), depression(x0 + 1, z0 + 1), wx);
    return params.snow_depth * (1.0 - mix(a, b, wz));
}

// Base of the snow column at a texel, clamped to the grid (on ground that is not flat).
fn ground_base(c: i32, r: i32) -> f32 {
    let x = u32(clamp(c, 0, i32(params.width) - 1));
    let y = u32(clamp(r, 0, i32(params.height) - 1));
    return ground_texel(params.ground, params.width, x, y).x;
}

// The moon as the prints at a texel see it: on flat ground the surface's own direction; on ground
// that is not flat the direction turned by the rotation that takes the ground's normal there
// (central differences of the base) to local up, so that the walls of a print on a slope shadow
// its floor as they would on flat ground lit from the same angle to the slope.
fn light_at(c: i32, r: i32) -> vec3<f32> {
    let l = params.light.xyz;
    if params.ground == NO_GROUND {
        return l;
    }
    let gx = (ground_base(c + 1, r) - ground_base(c - 1, r)) / (2.0 * params.texel_x);
    let gz = (ground_base(c, r + 1) - ground_base(c, r - 1)) / (2.0 * params.texel_z);
    let n = normalize(vec3<f32>(-gx, 1.0, -gz));
    // Rotation taking n to +y: R v = v + k x v + k x (k x v) / (1 + n.y), k = n x y.
    let k = cross(n, vec3<f32>(0.0, 1.0, 0.0));
    let kv = cross(k, l);
    return normalize(l + kv + cross(k, kv) / (1.0 + n.y));
}

// Must match `light_visibility` in cpu.rs (which takes the light `light_at` gives).
fn light_visibility(c: i32, r: i32) -> f32 {
    let l = light_at(c, r);
    if l.y <= 0.02 {
        // Below the horizon of flat ground: no moon. Where a slope turns away from it, the
        // lighting's N.L (and its wrap) darkens the snow; the prints' walls add nothing.
        if params.ground != NO_GROUND {
            return 1.0;
        }
        return 0.0;
    }
    let h0 = height_bilinear(c, r, 0.0, 0.0);
    let t_top = (params.snow_depth - h0) / l.y;
    if t_top <= 0.0 {
        return 1.0;
    }
    let across = length(l.xz) * t_top / max(params.texel_x, params.texel_z);
    let taps = u32(clamp(ceil(across), 1.0, f32(LIGHT_TAPS)));
    var visible = 1.0;
    for (var i = 1u; i <= taps; i++) {
        let t = t_top * f32(i) / f32(taps);
        let p = vec3<f32>(0.0, h0, 0.0) + l * t;
        let width = PENUMBRA_BASE + PENUMBRA_SLOPE * t;
        let v = clamp(0.5 + (p.y - height_bilinear(c, r, p.x, p.z)) / (2.0 * width), 0.0, 1.0);
        visible = min(visible, v);
    }
    return visible;
}

// Must match `sobel_normal` in cpu.rs.
fn sobel_normal(c: i32, r: i32) -> vec3<f32> {
    let d = params.snow_depth;
    let h00 = -depression(c - 1, r - 1) * d;
    let h10 = -depression(c, r - 1) * d;
    let h20 = -depression(c + 1, r - 1) * d;
    let h01 = -depression(c - 1, r) * d;
    let h21 = -depression(c + 1, r) * d;
    let h02 = -depression(c - 1, r + 1) * d;
    let h12 = -depression(c, r + 1) * d;
    let h22 = -depression(c + 1, r + 1) * d;
    let gx = (h20 + 2.0 * h21 + h22) - (h00 + 2.0 * h01 + h02);
    let gz = (h02 + 2.0 * h12 + h22) - (h00 + 2.0 * h10 + h20);
    return normalize(vec3<f32>(-gx / (8.0 * params.texel_x), 1.0, -gz / (8.0 * params.texel_z)));
}

// Must match `horizon_ao` in cpu.rs.
fn horizon_ao(c: i32, r: i32) -> f32 {
    let h0 = height_at(c, r, 0.0, 0.0);
    var sum = 0.0;
    for (var k = 0u; k < AO_DIRECTIONS; k++) {
        let a = 6.28318530718 * f32(k) / f32(AO_DIRECTIONS);
        let sx = cos(a);
        let sz = sin(a);
        var best = 0.0;
        for (var j = 0u; j < 4u; j++) {
            let rad = AO_RADII[j];
            let dh = height_at(c, r, sx * rad, sz * rad) - h0;
            best = max(best, dh / sqrt(dh * dh + rad * rad));
        }
        sum += best;
    }
    return 1.0 - sum / f32(AO_DIRECTIONS);
}

// The texels of the textures that hold texel `t` along one axis: itself and, at an edge with no
// surface linked beyond it, the border there (which repeats the edge), as offsets from `t`.
fn held_span(t: i32, size: i32, low: bool, high: bool) -> vec2<i32> {
    let b = HEIGHTFIELD_BORDER;
    return vec2<i32>(select(0, -b, t == 0 && low), select(0, b, t == size - 1 && high));
}

// One texel of the textures, which hold the surface and a border around it: texture texel (x, y)
// is the surface's (x - HEIGHTFIELD_BORDER, y - HEIGHTFIELD_BORDER). A border texel past a side
// with no surface linked repeats the edge: the edge texel's invocation writes it.
// The pass runs over the surface and the border past its linked sides (`FrameSurface::
// heightfield_domain`): a surface with nothing beside it keeps its grid of workgroups.
@compute @workgroup_size(8, 8, 1)
fn heightfield(@builtin(global_invocation_id) gid: vec3<u32>) {
    if state[params.slot * STATE_WORDS + STATE_SHADED] == 0u {
        return;
    }
    let b = HEIGHTFIELD_BORDER;
    let w = i32(params.width);
    let h = i32(params.height);
    let c = i32(gid.x) - select(b, 0, open_side(0u));
    let r = i32(gid.y) - select(b, 0, open_side(2u));
    let outside = c < -b || r < -b || c >= w + b || r >= h + b;
    let repeated = (c < 0 && open_side(0u)) || (c >= w && open_side(1u))
        || (r < 0 && open_side(2u)) || (r >= h && open_side(3u));
    if outside || repeated {
        return;
    }
    let n = sobel_normal(c, r);
    let shape = vec4<f32>(smoothed_depression(c, r), n.x, n.z, horizon_ao(c, r));
    let light = vec4<f32>(light_visibility(c, r), displaced(c, r), 0.0, 1.0);
    let xs = held_span(c, w, open_side(0u), open_side(1u));
    let ys = held_span(r, h, open_side(2u), open_side(3u));
    for (var y = ys.x; y <= ys.y; y++) {
        for (var x = xs.x; x <= xs.y; x++) {
            let at = vec2<i32>(c + x + b, r + y + b);
            textureStore(out_texture, at, shape);
            textureStore(out_light, at, light);
        }
    }
}
