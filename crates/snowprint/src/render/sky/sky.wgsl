// sky.wgsl: the night sky behind everything, drawn as a fullscreen triangle on the far plane where
// nothing else was drawn (depth test "less or equal" against the cleared depth of 1).
// Reads: frame uniforms, depth (test only). Writes: scene colour.

// import frame

struct SkyVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

@vertex
fn vs_sky(@builtin(vertex_index) i: u32) -> SkyVarying {
    let p = fullscreen_position(i);
    var out: SkyVarying;
    out.clip = vec4<f32>(p, 1.0, 1.0);
    out.ndc = p;
    return out;
}

@fragment
fn fs_sky(in: SkyVarying) -> @location(0) vec4<f32> {
    let far = frame.inv_view_proj * vec4<f32>(in.ndc, 1.0, 1.0);
    let near = frame.inv_view_proj * vec4<f32>(in.ndc, 0.0, 1.0);
    let dir = normalize(far.xyz / far.w - near.xyz / near.w);
    var c = sky_radiance(dir);
    // A few faint stars, fixed to the sky (no twinkle: it would shimmer from frame to frame).
    let cell = floor(vec2<f32>(atan2(dir.z, dir.x) * 180.0, dir.y * 240.0));
    let h = snow_star_hash(vec2<i32>(cell));
    if h > 0.996 && dir.y > 0.12 {
        c += vec3<f32>(0.25, 0.27, 0.32) * (h - 0.996) * 250.0 * smoothstep(0.12, 0.4, dir.y);
    }
    if frame.options.x != DEBUG_SHADED {
        c = vec3<f32>(0.02, 0.02, 0.03);
    }
    return vec4<f32>(c, 1.0);
}

fn snow_star_hash(c: vec2<i32>) -> f32 {
    var v = bitcast<u32>(c.x) * 1664525u + bitcast<u32>(c.y) * 22695477u + 1013904223u;
    v = (v ^ (v >> 16u)) * 2246822519u;
    v = (v ^ (v >> 13u)) * 3266489917u;
    v = v ^ (v >> 16u);
    return f32(v >> 8u) * (1.0 / 16777215.0);
}
