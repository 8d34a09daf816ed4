// tonemap_compute.wgsl: the tonemap as a compute pass (the default): one thread an output pixel,
// `resolve.wgsl`'s maths, the sRGB-encoded pixel stored into an `Rgba8Unorm` storage texture (the
// offscreen output, or a caller's view made with `STORAGE_BINDING`).
// Reads: frame uniforms, scene colour (HDR), scene depth. Writes: the output.

// import tonemap_resolve

@group(1) @binding(2) var output: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn tonemap(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(output);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    // A colour target clamps what a fragment writes to [0, 1]; a storage write is clamped here.
    let s = tonemap_srgb(vec2<f32>(id.xy) + 0.5);
    textureStore(output, id.xy, vec4<f32>(clamp(s, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0));
}
