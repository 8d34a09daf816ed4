// skin.wgsl: linear blend skinning of one mesh deformer into the vertex buffer the capture draws
// (capture/capture.wgsl's vs_mesh reads it as Float32x3, 12 bytes a vertex, so it is written here as
// three f32 a vertex). One invocation a vertex: the weighted sum of its four joints' matrices
// (global * inverse bind, posed on the CPU in skin/cpu.rs) applied to its bind-pose position.
// CPU side: skin/encode.rs (`GpuBindVertex` and `SkinParams` must match the structs here); the
// reference is skin/cpu.rs `skin_vertices`.

// import constants

struct SkinParams {
    // Vertices of the mesh.
    vertex_count: u32,
    // Joint matrices bound.
    joint_count: u32,
    _pad0: u32,
    _pad1: u32,
}

struct BindVertex {
    // Bind-pose position (w unused).
    position: vec4<f32>,
    // The four weights, summing to 1.
    weights: vec4<f32>,
    // The four joints, indices into `joints`.
    joints: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: SkinParams;
@group(0) @binding(1) var<storage, read> bind_vertices: array<BindVertex>;
@group(0) @binding(2) var<storage, read> joints: array<mat4x4<f32>>;
@group(0) @binding(3) var<storage, read_write> skinned: array<f32>;

@compute @workgroup_size(SKIN_WORKGROUP)
fn skin(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = id.x;
    if v >= params.vertex_count {
        return;
    }
    let b = bind_vertices[v];
    let last = max(params.joint_count, 1u) - 1u;
    let m = b.weights.x * joints[min(b.joints.x, last)]
        + b.weights.y * joints[min(b.joints.y, last)]
        + b.weights.z * joints[min(b.joints.z, last)]
        + b.weights.w * joints[min(b.joints.w, last)];
    let p = m * vec4<f32>(b.position.xyz, 1.0);
    skinned[3u * v] = p.x;
    skinned[3u * v + 1u] = p.y;
    skinned[3u * v + 2u] = p.z;
}
