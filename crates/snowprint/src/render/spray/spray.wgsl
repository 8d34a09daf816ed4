// spray.wgsl: kicked-up snow, sand or mud (the world's spray ring, src/spray/) drawn as the
// snowfall's flakes are: a small camera-facing quad per live particle, of its material's albedo and
// radius, lit by the sky, the moon and the street
// lights with the snowfall's model (snowfall.wgsl `vs_flake`; keep the two alike), blended over
// the scene and hidden by its depth. The particles come in as an instance vertex buffer (the
// ring past its counters); dead ones (life 0) are dropped by a degenerate position. A particle
// fades in its last 0.3 s of life.
// Reads: frame uniforms, the ring's particles, depth (test only). Writes: scene colour (blended).

// import frame

struct SprayVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) corner: vec2<f32>,
    @location(1) color: vec4<f32>,
}

@vertex
fn vs_spray(
    @builtin(vertex_index) vi: u32,
    @location(0) position_life: vec4<f32>,
    @location(1) velocity_age: vec4<f32>,
    @location(2) albedo: vec4<f32>,
    @location(3) radius_drag: vec2<f32>,
) -> SprayVarying {
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    )[vi];
    var out: SprayVarying;
    out.corner = corner;
    let p = position_life.xyz;
    let life = position_life.w;
    if life <= 0.0 || velocity_age.w < 0.0 {
        out.clip = vec4<f32>(0.0, 0.0, -1.0, 1.0);
        out.color = vec4<f32>(0.0);
        return out;
    }
    let clip = frame.view_proj * vec4<f32>(p, 1.0);
    // Radius in pixels; grains smaller than a pixel are drawn one pixel wide and fainter.
    let pixels = radius_drag.x * frame.viewport.y / max(clip.w, 1e-3) * 1.2;
    let shown = max(pixels, 0.75);
    let fade = clamp(pixels / shown, 0.0, 1.0);
    out.clip = clip + vec4<f32>(corner * shown * 2.0 * frame.viewport.zw * clip.w, 0.0, 0.0);
    var light = ambient_light(vec3<f32>(0.0, 1.0, 0.0)) + frame.moon_color.rgb * 0.6;
    let count = min(frame.options.y, MAX_POINT_LIGHTS);
    for (var i = 0u; i < count; i++) {
        let l = frame.lights[i];
        let d = distance(l.position_radius.xyz, p);
        light += l.color.rgb * pow(clamp(1.0 - pow(d / l.position_radius.w, 4.0), 0.0, 1.0), 2.0) / max(d * d, 0.05);
    }
    let alpha = 0.9 * fade * fade * smoothstep(0.0, 0.3, life);
    out.color = vec4<f32>(light * albedo.rgb * alpha, alpha);
    return out;
}

@fragment
fn fs_spray(in: SprayVarying) -> @location(0) vec4<f32> {
    let r = length(in.corner);
    let a = 1.0 - smoothstep(0.3, 1.0, r);
    return in.color * a;
}
