// The `shadow` pass's restore: a cascade's still casters' depth, copied back from its cache over
// the rectangles that the frame before's moving casters and displaced snow drew into, so that
// a cascade which held still is not cleared and redrawn whole (`render/shadow/cache.rs`).

// The cascade's cache: the still casters' depth alone.
@group(0) @binding(0) var cache: texture_depth_2d;
// The rectangles, in the cascade's clip space: (x0, y0, x1, y1).
@group(0) @binding(1) var<storage, read> rects: array<vec4<f32>>;

@vertex
fn vs_restore(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> @builtin(position) vec4<f32> {
    let r = rects[i];
    let x = select(r.x, r.z, (v & 1u) == 1u);
    let y = select(r.y, r.w, (v & 2u) == 2u);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_restore(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(cache, vec2<i32>(p.xy), 0);
}
