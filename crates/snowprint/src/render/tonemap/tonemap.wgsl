// tonemap.wgsl: the tonemap's raster fallback, one fullscreen triangle into a caller's view that
// cannot be a storage texture (a window's sRGB surface). The maths are `resolve.wgsl`'s; the output
// is sRGB encoded by the target format, or here when the target is not an sRGB format.
// Reads: frame uniforms, scene colour (HDR), scene depth. Writes: the output target.

// import tonemap_resolve

// Set when the target format does not encode sRGB itself.
override ENCODE_SRGB: bool = false;

@vertex
fn vs_tonemap(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(fullscreen_position(i), 0.0, 1.0);
}

@fragment
fn fs_tonemap(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let s = tonemap_srgb(pos.xy);
    if ENCODE_SRGB {
        return vec4<f32>(s, 1.0);
    }
    return vec4<f32>(from_srgb(max(s, vec3<f32>(0.0))), 1.0);
}
