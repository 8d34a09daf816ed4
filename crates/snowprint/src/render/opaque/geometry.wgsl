// geometry.wgsl: the frame's meshes and instances as storage buffers, for the visibility buffer's
// passes (`visibility.wgsl` rasterises them by pulling vertices; `shade.wgsl` finds each pixel's
// triangle again). Every registered mesh's vertices and indices lie in one buffer each, and each
// instance of the frame has its mesh's first index and first vertex.
// Reads: instances, instance meshes, mesh vertices, mesh indices (group 1).

// Must match `InstanceRaw` in src/render/gpu.rs (as `MeshInstance` in mesh.wgsl).
struct InstanceData {
    model: mat4x4<f32>,
    normal_0: vec4<f32>,
    normal_1: vec4<f32>,
    normal_2: vec4<f32>,
    albedo_material: vec4<f32>,   // rgb albedo, w: material
    params: vec4<f32>,            // x: roughness, y: emission, z: snow cover, w: seed
}

@group(1) @binding(0) var<storage, read> instances: array<InstanceData>;
// Per instance: its mesh's first index in `mesh_indices`, first vertex in `mesh_vertices`.
@group(1) @binding(1) var<storage, read> instance_meshes: array<vec2<u32>>;
// Per vertex six floats: position, normal (`MeshVertexRaw`).
@group(1) @binding(2) var<storage, read> mesh_vertices: array<f32>;
@group(1) @binding(3) var<storage, read> mesh_indices: array<u32>;

// No triangle: what the visibility target is cleared to.
const NO_TRIANGLE: u32 = 0xffffffffu;

// Vertex `corner` (0 to 2) of triangle `triangle` of instance `instance`: its index in
// `mesh_vertices`.
fn triangle_vertex(instance: u32, triangle: u32, corner: u32) -> u32 {
    let m = instance_meshes[instance];
    return m.y + mesh_indices[m.x + 3u * triangle + corner];
}

fn vertex_position(v: u32) -> vec3<f32> {
    return vec3<f32>(mesh_vertices[6u * v], mesh_vertices[6u * v + 1u], mesh_vertices[6u * v + 2u]);
}

fn vertex_normal(v: u32) -> vec3<f32> {
    return vec3<f32>(mesh_vertices[6u * v + 3u], mesh_vertices[6u * v + 4u], mesh_vertices[6u * v + 5u]);
}
