// mesh.wgsl: opaque meshes (rooftops, walls, props, people), forward: each fragment shaded by
// `shading.wgsl`; and the moon's shadow map.
// Shadow pass reads: frame uniforms (shadow_near, shadow_far), meshes, instances; writes: the
// shadow cascades.
// Opaque pass reads: frame uniforms, shadow map, meshes, instances; writes: scene colour, depth.

// import mesh_shading

struct MeshVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

// Must match `InstanceRaw` in src/render/gpu.rs.
struct MeshInstance {
    @location(2) model_0: vec4<f32>,
    @location(3) model_1: vec4<f32>,
    @location(4) model_2: vec4<f32>,
    @location(5) model_3: vec4<f32>,
    @location(6) normal_0: vec4<f32>,
    @location(7) normal_1: vec4<f32>,
    @location(8) normal_2: vec4<f32>,
    @location(9) albedo_material: vec4<f32>,   // rgb albedo, w: material
    @location(10) params: vec4<f32>,           // x: roughness, y: emission, z: snow cover, w: seed
}

struct MeshVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) albedo_material: vec4<f32>,
    @location(3) @interpolate(flat) params: vec4<f32>,
}

fn model_matrix(inst: MeshInstance) -> mat4x4<f32> {
    return mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
}

@vertex
fn vs_mesh(v: MeshVertex, inst: MeshInstance) -> MeshVarying {
    let world = model_matrix(inst) * vec4<f32>(v.position, 1.0);
    let nm = mat3x3<f32>(inst.normal_0.xyz, inst.normal_1.xyz, inst.normal_2.xyz);
    var out: MeshVarying;
    out.clip = frame.view_proj * world;
    out.world = world.xyz;
    out.normal = nm * v.normal;
    out.albedo_material = inst.albedo_material;
    out.params = inst.params;
    return out;
}

// Which shadow cascade a shadow pipeline renders (0 near, 1 far).
override SHADOW_CASCADE: u32 = 0u;

@vertex
fn vs_shadow(v: MeshVertex, inst: MeshInstance) -> @builtin(position) vec4<f32> {
    var m = frame.shadow_far;
    if SHADOW_CASCADE == 0u {
        m = frame.shadow_near;
    }
    return m * (model_matrix(inst) * vec4<f32>(v.position, 1.0));
}

@fragment
fn fs_mesh(in: MeshVarying) -> @location(0) vec4<f32> {
    let point = MeshPoint(in.world, in.albedo_material, in.params);
    return vec4<f32>(shade_mesh(point, in.normal, length(fwidth(in.world))), 1.0);
}
