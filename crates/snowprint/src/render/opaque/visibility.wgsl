// visibility.wgsl: the opaque meshes into a visibility buffer: depth, and per pixel the instance
// and triangle seen (an `Rg32Uint` target), nothing shaded. Vertices are pulled from storage
// (`geometry.wgsl`), so the triangle is the vertex's index over three; the clip position is the
// forward pass's (`vs_mesh`), so both cover the same pixels at the same depths.
// Reads: frame uniforms, meshes, instances. Writes: visibility, scene depth.

// import frame, mesh_geometry

struct VisibilityVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) ids: vec2<u32>,
}

@vertex
fn vs_visibility(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VisibilityVarying {
    let m = instance_meshes[instance];
    let v = m.y + mesh_indices[m.x + vertex];
    let world = instances[instance].model * vec4<f32>(vertex_position(v), 1.0);
    var out: VisibilityVarying;
    out.clip = frame.view_proj * world;
    out.ids = vec2<u32>(instance, vertex / 3u);
    return out;
}

@fragment
fn fs_visibility(in: VisibilityVarying) -> @location(0) vec2<u32> {
    // Whatever draws over this pixel later (the snow) writes the buffer too.
    return in.ids;
}
