// resolve.wgsl: the tonemap's maths, shared by its compute pass (`tonemap_compute.wgsl`, the
// default) and its raster fallback (`tonemap.wgsl`, for a caller's view that cannot be a storage
// texture). Averages the supersampled scene colour down to an output pixel, adds the night haze by
// distance, applies exposure and a filmic curve, a vignette and a dither, and gives the pixel
// encoded in sRGB.
// Reads: frame uniforms, scene colour (HDR), scene depth.

// import frame

@group(1) @binding(0) var scene_color: texture_2d<f32>;
@group(1) @binding(1) var scene_depth: texture_depth_2d;

// Output pixels per side of a supersampled block.
override SUPERSAMPLE: u32 = 1u;

// ACES filmic fit (Narkowicz 2015).
fn aces(x: vec3<f32>) -> vec3<f32> {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn to_srgb(c: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055, c * 12.92, c <= vec3<f32>(0.0031308));
}

fn from_srgb(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

fn hazed(texel: vec2<i32>) -> vec3<f32> {
    let c = textureLoad(scene_color, texel, 0).rgb;
    let depth = textureLoad(scene_depth, texel, 0);
    if depth >= 1.0 || frame.options.x != DEBUG_SHADED {
        return c;
    }
    let uv = (vec2<f32>(texel) + 0.5) * frame.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = frame.inv_view_proj * ndc;
    let p = w.xyz / w.w;
    let dir = p - frame.eye.xyz;
    let dist = length(dir);
    let haze = 1.0 - exp(-frame.sky_horizon.w * max(dist - 4.0, 0.0));
    return mix(c, sky_radiance(normalize(vec3<f32>(dir.x, max(dir.y, 0.0) + 0.02 * dist, dir.z))) * 0.8, haze);
}

// The output pixel whose centre is `pos` (a fragment's position: the pixel's corner plus a half),
// sRGB encoded and dithered (not clamped).
fn tonemap_srgb(pos: vec2<f32>) -> vec3<f32> {
    let base = vec2<i32>(floor(pos)) * i32(SUPERSAMPLE);
    var sum = vec3<f32>(0.0);
    for (var y = 0u; y < SUPERSAMPLE; y++) {
        for (var x = 0u; x < SUPERSAMPLE; x++) {
            // Average after the curve: edges against the bright moon or lamps stay smooth.
            let c = hazed(base + vec2<i32>(i32(x), i32(y)));
            if frame.options.x == DEBUG_SHADED {
                sum += aces(c * frame.sky_zenith.w);
            } else {
                sum += clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
            }
        }
    }
    var c = sum / f32(SUPERSAMPLE * SUPERSAMPLE);
    // A faint vignette.
    let uv = pos * frame.viewport.zw * f32(SUPERSAMPLE);
    c *= 1.0 - 0.25 * pow(length(uv - 0.5) * 1.2, 3.0);
    // Dither in sRGB space against banding in the dark sky; a fixed pattern per pixel, so it does
    // not crawl from frame to frame.
    let h = fract(52.9829189 * fract(dot(floor(pos), vec2<f32>(0.06711056, 0.00583715))));
    return to_srgb(c) + (h - 0.5) / 255.0;
}
