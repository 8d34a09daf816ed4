// shade.wgsl: the visibility buffer's shading, one thread a pixel of the scene, after the snow
// pass: a pixel is shaded only where the buffer still holds an opaque triangle (every fragment
// that writes depth before this pass writes the buffer too: the snow replaced the triangles it
// drew over; where nothing was drawn, depth 1, the buffer is an earlier frame's and is not read,
// and the sky fills it). The pixel's triangle is
// fetched again (`geometry.wgsl`), cut by the pixel's view ray (and its neighbours'
// rays, for the footprint the forward pass takes from `fwidth`), its normal interpolated by the
// hit's barycentrics (perspective-correct, as a rasteriser's), and the point shaded by
// `shading.wgsl`, the forward pass's own function.
// Reads: frame uniforms, shadow map, meshes, instances, visibility, scene depth. Writes: scene
// colour.

// import mesh_shading, mesh_geometry

@group(2) @binding(0) var visibility: texture_2d<u32>;
@group(2) @binding(1) var scene_color: texture_storage_2d<rgba16float, write>;
@group(2) @binding(2) var scene_depth: texture_depth_2d;

// The view ray through a point of the scene's pixel grid (`pixel`: pixels from the top left
// corner): origin and direction (not unit).
fn pixel_ray(pixel: vec2<f32>) -> array<vec3<f32>, 2> {
    let uv = pixel * frame.viewport.zw;
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let near = frame.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let a = near.xyz / near.w;
    return array<vec3<f32>, 2>(a, far.xyz / far.w - a);
}

// Barycentrics (of corners 1 and 2) where a ray meets the plane of triangle `p` (Moller-Trumbore,
// without its bounds: a neighbour's ray may pass beside the triangle).
fn ray_barycentrics(ray: array<vec3<f32>, 2>, p: array<vec3<f32>, 3>) -> vec2<f32> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let q = cross(ray[1], e2);
    let inv = 1.0 / dot(e1, q);
    let s = ray[0] - p[0];
    let r = cross(s, e1);
    return vec2<f32>(dot(s, q), dot(ray[1], r)) * inv;
}

fn at(b: vec2<f32>, p: array<vec3<f32>, 3>) -> vec3<f32> {
    return p[0] + b.x * (p[1] - p[0]) + b.y * (p[2] - p[0]);
}

@compute @workgroup_size(8, 8, 1)
fn shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(scene_color);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let ids = textureLoad(visibility, id.xy, 0).xy;
    // Nothing to shade here (NO_TRIANGLE), or the snow's hit (shaded by the snow pass); where
    // nothing was drawn (depth 1) the buffer holds an earlier frame's words.
    if (ids.x & SNOW_VISIBLE) != 0u || textureLoad(scene_depth, id.xy, 0) >= 1.0 {
        return;
    }
    let inst = instances[ids.x];
    var world: array<vec3<f32>, 3>;
    var normal: array<vec3<f32>, 3>;
    let nm = mat3x3<f32>(inst.normal_0.xyz, inst.normal_1.xyz, inst.normal_2.xyz);
    for (var k = 0u; k < 3u; k++) {
        let v = triangle_vertex(ids.x, ids.y, k);
        world[k] = (inst.model * vec4<f32>(vertex_position(v), 1.0)).xyz;
        normal[k] = nm * vertex_normal(v);
    }
    let centre = vec2<f32>(id.xy) + 0.5;
    let b = ray_barycentrics(pixel_ray(centre), world);
    let p = at(b, world);
    // A pixel's footprint, as a rasteriser's coarse `fwidth` gives it: the differences across the
    // pixel's 2 x 2 quad, taken at the quad's first pixel, of the hits of its pixels' rays on the
    // triangle's plane.
    let quad = vec2<f32>(id.xy & vec2<u32>(~1u)) + 0.5;
    let q = at(ray_barycentrics(pixel_ray(quad), world), world);
    let dx = at(ray_barycentrics(pixel_ray(quad + vec2<f32>(1.0, 0.0)), world), world) - q;
    let dy = at(ray_barycentrics(pixel_ray(quad + vec2<f32>(0.0, 1.0)), world), world) - q;
    let footprint = length(abs(dx) + abs(dy));
    let n = normal[0] + b.x * (normal[1] - normal[0]) + b.y * (normal[2] - normal[0]);
    let point = MeshPoint(p, inst.albedo_material, inst.params);
    textureStore(scene_color, id.xy, vec4<f32>(shade_mesh(point, n, footprint), 1.0));
}
