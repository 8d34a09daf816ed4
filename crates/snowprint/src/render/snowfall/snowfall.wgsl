// snowfall.wgsl: falling snow. Each flake is a small camera-facing quad whose position is a pure
// function of its index and the time: flakes are anchored in the world (wrapped in a box that
// follows the camera), so they do not swim when the camera moves.
// Reads: frame uniforms, depth (test only, not written). Writes: scene colour (blended).

// import frame

// The box of flakes around the camera, metres.
const FLAKE_BOX: vec3<f32> = vec3<f32>(28.0, 16.0, 28.0);

struct FlakeVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) corner: vec2<f32>,
    @location(1) color: vec4<f32>,
}

fn flake_hash(i: u32, k: u32) -> f32 {
    var v = i * 747796405u + k * 2891336453u + 12345u;
    v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
    v = (v >> 22u) ^ v;
    return f32(v >> 8u) * (1.0 / 16777215.0);
}

@vertex
fn vs_flake(@builtin(vertex_index) vi: u32, @builtin(instance_index) flake: u32) -> FlakeVarying {
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    )[vi];
    let t = frame.eye.w;
    let seed = vec3<f32>(flake_hash(flake, 1u), flake_hash(flake, 2u), flake_hash(flake, 3u));
    let speed = 0.7 + 0.6 * flake_hash(flake, 4u);
    let phase = 6.2831 * flake_hash(flake, 5u);
    let sway = vec3<f32>(0.25 * sin(0.9 * t + phase), 0.0, 0.25 * cos(0.7 * t + phase * 1.3));
    let wind = vec3<f32>(0.35, 0.0, 0.12) * t;
    let moving = seed * FLAKE_BOX + sway + wind - vec3<f32>(0.0, speed * t, 0.0);
    let origin = frame.eye.xyz - 0.5 * FLAKE_BOX;
    let p = origin + moving - FLAKE_BOX * floor((moving - origin) / FLAKE_BOX);

    let clip = frame.view_proj * vec4<f32>(p, 1.0);
    let radius = 0.008 + 0.008 * flake_hash(flake, 6u);
    // Radius in pixels; flakes smaller than a pixel are drawn one pixel wide and fainter, so that
    // distant ones do not flicker in and out.
    let pixels = radius * frame.viewport.y / max(clip.w, 1e-3) * 1.2;
    let shown = max(pixels, 0.75);
    let fade = clamp(pixels / shown, 0.0, 1.0);
    let dist = length(p - frame.eye.xyz);
    let near_fade = smoothstep(0.3, 1.2, dist) * (1.0 - smoothstep(9.0, 14.0, dist));
    var out: FlakeVarying;
    out.clip = clip + vec4<f32>(corner * shown * 2.0 * frame.viewport.zw * clip.w, 0.0, 0.0);
    out.corner = corner;
    // Lit by the sky, the moon and the street lights.
    var light = ambient_light(vec3<f32>(0.0, 1.0, 0.0)) + frame.moon_color.rgb * 0.6;
    let count = min(frame.options.y, MAX_POINT_LIGHTS);
    for (var i = 0u; i < count; i++) {
        let l = frame.lights[i];
        let d = distance(l.position_radius.xyz, p);
        light += l.color.rgb * pow(clamp(1.0 - pow(d / l.position_radius.w, 4.0), 0.0, 1.0), 2.0) / max(d * d, 0.05);
    }
    let alpha = 0.85 * fade * fade * near_fade;
    out.color = vec4<f32>(light * 0.9 * alpha, alpha);
    if frame.options.w == 0u {
        out.clip = vec4<f32>(0.0, 0.0, -1.0, 1.0);
    }
    return out;
}

@fragment
fn fs_flake(in: FlakeVarying) -> @location(0) vec4<f32> {
    let r = length(in.corner);
    let a = 1.0 - smoothstep(0.3, 1.0, r);
    return in.color * a;
}
