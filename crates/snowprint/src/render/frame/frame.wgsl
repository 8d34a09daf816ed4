// frame.wgsl: what every pass of the renderer shares: the frame's uniforms (camera, moon, sky,
// point lights, options), the shadow map, and the lighting model. Imported by each pass's WGSL.

// import constants

struct PointLight {
    position_radius: vec4<f32>,   // world position, radius of influence (metres)
    color: vec4<f32>,             // linear colour times intensity at 1 m; w unused
}

// Must match `FrameUniform` in src/render/gpu.rs (a test checks the layout with naga).
struct Frame {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    shadow_near: mat4x4<f32>,   // world to the moon's near shadow cascade
    shadow_far: mat4x4<f32>,    // world to the far cascade (everything drawn)
    eye: vec4<f32>,             // xyz: camera position; w: time, seconds
    moon_dir: vec4<f32>,        // xyz: unit direction towards the moon; w: cosine of the moon's radius on the sky
    moon_color: vec4<f32>,      // rgb: moonlight (what a white Lambertian surface facing it reflects); w unused
    sky_zenith: vec4<f32>,      // rgb: sky overhead; w: exposure
    sky_horizon: vec4<f32>,     // rgb: sky at the horizon; w: fog density per metre
    ground_bounce: vec4<f32>,   // rgb: light bounced from below; w: city glow on the horizon
    sss_tint: vec4<f32>,        // rgb: the sky tint of the snow's transition zone (luminance about 1); w: its strength
    sky_ambient: vec4<f32>,     // rgb: light from the whole sky on a surface facing up; w unused
    viewport: vec4<f32>,        // internal (supersampled) width, height, and their reciprocals
    options: vec4<u32>,         // x: debug view, y: point lights in use, z: tier, w: snowflakes
    shadow_texels: vec4<f32>,   // x: near cascade texel, y: far cascade texel (metres)
    lights: array<PointLight, 8>,
}

const DEBUG_SHADED: u32 = 0u;
const DEBUG_MATERIALS: u32 = 1u;
const DEBUG_DEPRESSION: u32 = 2u;
const DEBUG_OCCLUSION: u32 = 3u;
const DEBUG_NORMALS: u32 = 4u;
const DEBUG_TAPS: u32 = 5u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var shadow_map: texture_depth_2d_array;   // layer 0 near, 1 far
@group(0) @binding(2) var shadow_sampler: sampler_comparison;
@group(0) @binding(3) var linear_sampler: sampler;

const PI: f32 = 3.14159265;

// The night sky in a world direction: a dark blue gradient, the orange glow of the city low on the
// horizon, and the moon with its halo.
fn sky_radiance(dir: vec3<f32>) -> vec3<f32> {
    let up = clamp(dir.y, -1.0, 1.0);
    let h = max(up, 0.0);
    var c = mix(frame.sky_horizon.rgb, frame.sky_zenith.rgb, pow(h, 0.45));
    // Light pollution: warm, hugging the horizon.
    let glow = exp(-max(up + 0.02, 0.0) * 9.0) * frame.ground_bounce.w;
    c += vec3<f32>(0.55, 0.30, 0.14) * glow;
    if up < 0.0 {
        c = mix(c, frame.ground_bounce.rgb, clamp(-up * 4.0, 0.0, 1.0));
    }
    let m = dot(dir, frame.moon_dir.xyz);
    c += frame.moon_color.rgb * (0.015 * pow(max(m, 0.0), 24.0) + 0.06 * pow(max(m, 0.0), 400.0));
    if m > frame.moon_dir.w {
        c += frame.moon_color.rgb * 6.0;
    }
    return c;
}

// Light from the sky and the ground reaching a surface facing `n` (hemisphere lighting).
fn ambient_light(n: vec3<f32>) -> vec3<f32> {
    return mix(frame.ground_bounce.rgb, frame.sky_ambient.rgb, clamp(n.y * 0.5 + 0.5, 0.0, 1.0));
}

// Percentage-closer filtering: a 4 x 4 grid of bilinear comparisons one texel apart, a filter
// about 4 texels wide that varies smoothly with the position (no staircase of texels along grazing
// edges) and is locked to the shadow map's texel grid, so it does not crawl when the camera moves.
// (A version built from four textureGatherCompare calls, a quarter of the taps, showed serrated
// edges on lavapipe; this one is the plain, portable form.)
fn shadow_pcf(layer: i32, uv: vec2<f32>, depth: f32) -> f32 {
    let size = vec2<f32>(textureDimensions(shadow_map));
    var sum = 0.0;
    for (var y = 0; y < 4; y++) {
        for (var x = 0; x < 4; x++) {
            let o = (vec2<f32>(f32(x), f32(y)) - 1.5) / size;
            sum += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + o, layer, depth);
        }
    }
    return sum / 16.0;
}

// One cascade's shadow at a world point with normal `n`, offset along the normal by a texel and a
// half against acne. x: lit fraction, y: how far inside the cascade the point is (0 at its border,
// 1 well inside; negative outside).
fn cascade_shadow(layer: i32, m: mat4x4<f32>, texel: f32, p: vec3<f32>, n: vec3<f32>) -> vec2<f32> {
    let q = m * vec4<f32>(p + n * (1.5 * texel), 1.0);
    let ndc = q.xyz / q.w;
    let uv = ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5);
    let inside = min(min(uv.x, 1.0 - uv.x), min(uv.y, 1.0 - uv.y)) * 10.0;
    if inside <= 0.0 || ndc.z > 1.0 {
        return vec2<f32>(1.0, inside);
    }
    return vec2<f32>(shadow_pcf(layer, uv, ndc.z - 0.0005), inside);
}

// Moon shadow at a world point: the near cascade where it reaches (blended into the far one over
// its outer tenth), the far cascade elsewhere.
fn moon_shadow(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let near = cascade_shadow(0, frame.shadow_near, frame.shadow_texels.x, p, n);
    if near.y >= 1.0 {
        return near.x;
    }
    let far = cascade_shadow(1, frame.shadow_far, frame.shadow_texels.y, p, n);
    return mix(far.x, near.x, clamp(near.y, 0.0, 1.0));
}

// GGX specular (normalized so that it multiplies the same light as the diffuse term).
fn specular_ggx(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, roughness: f32, f0: f32) -> f32 {
    let h = normalize(v + l);
    let a = max(roughness * roughness, 0.02);
    let a2 = a * a;
    let nh = max(dot(n, h), 0.0);
    let nv = max(dot(n, v), 1e-3);
    let nl = max(dot(n, l), 0.0);
    let d = a2 / (PI * pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
    let k = a * 0.5;
    let vis = 0.25 / ((nv * (1.0 - k) + k) * (nl * (1.0 - k) + k));
    let f = f0 + (1.0 - f0) * pow(1.0 - max(dot(v, h), 0.0), 5.0);
    return d * vis * f * PI;
}

// A lit opaque surface: moon (with shadow), sky ambient (with occlusion) and point lights.
// `wrap` lets light wrap around the terminator, as it does through snow.
fn light_surface(albedo: vec3<f32>, roughness: f32, f0: f32, n: vec3<f32>, p: vec3<f32>, ao: f32, wrap: f32, shadow: f32) -> vec3<f32> {
    let v = normalize(frame.eye.xyz - p);
    let l = frame.moon_dir.xyz;
    let ndl = dot(n, l);
    let diffuse = clamp((ndl + wrap) / (1.0 + wrap), 0.0, 1.0);
    var c = frame.moon_color.rgb * shadow * (albedo * diffuse + specular_ggx(n, v, l, roughness, f0) * max(ndl, 0.0));
    c += albedo * ambient_light(n) * ao;
    let count = min(frame.options.y, MAX_POINT_LIGHTS);
    for (var i = 0u; i < count; i++) {
        let light = frame.lights[i];
        let to = light.position_radius.xyz - p;
        let d2 = max(dot(to, to), 1e-4);
        let d = sqrt(d2);
        let lp = to / d;
        let fall = pow(clamp(1.0 - pow(d / light.position_radius.w, 4.0), 0.0, 1.0), 2.0) / d2;
        let nl = dot(n, lp);
        let dl = clamp((nl + wrap) / (1.0 + wrap), 0.0, 1.0);
        c += light.color.rgb * fall * (albedo * dl + specular_ggx(n, v, lp, roughness, f0) * max(nl, 0.0));
    }
    return c;
}

// A colour ramp for debug views.
fn debug_ramp(x: f32) -> vec3<f32> {
    let t = clamp(x, 0.0, 1.0);
    return clamp(vec3<f32>(1.5 * t - 0.2, sin(PI * t), 1.2 - 1.5 * t), vec3<f32>(0.0), vec3<f32>(1.0));
}

// A fullscreen triangle: vertex `i` of 3.
fn fullscreen_position(i: u32) -> vec2<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec2<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0);
}
