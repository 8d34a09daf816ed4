// shading.wgsl: how an opaque mesh's point is shaded (its material: brick, facades with lit
// windows, concrete, painted metal, lamps, snow lying on what faces up; lit by the moon through its
// shadow map and by the point lights), shared by the forward pass's fragment stage (`mesh.wgsl`)
// and the visibility buffer's compute pass (`shade.wgsl`), which reconstructs the same inputs.
// Imports snow.wgsl for its noise and the snow colours; the heightfield contract is stubbed below
// because meshes never trace snow.

// import frame, snow

fn snow_depression(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 0.0;
}

fn snow_heightfield(s: SnowSurface, uv: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(0.0, 0.0, 0.0, 1.0);
}

fn snow_light_visibility(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 1.0;
}

fn snow_ground_base(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 0.0;
}

// Must match `MeshMaterial` in src/render/mod.rs.
const MATERIAL_PLAIN: u32 = 0u;
const MATERIAL_BRICK: u32 = 1u;
const MATERIAL_FACADE: u32 = 2u;
const MATERIAL_CONCRETE: u32 = 3u;
const MATERIAL_METAL: u32 = 4u;
const MATERIAL_EMISSIVE: u32 = 5u;

// What the shading of a mesh's point needs of it besides its normal.
struct MeshPoint {
    world: vec3<f32>,
    albedo_material: vec4<f32>,   // rgb albedo, w: material
    params: vec4<f32>,            // x: roughness, y: emission, z: snow cover, w: seed
}

// Coordinates on a wall: horizontal along the wall, vertical up.
fn wall_coords(p: vec3<f32>, n: vec3<f32>) -> vec2<f32> {
    if abs(n.x) > abs(n.z) {
        return vec2<f32>(p.z, p.y);
    }
    return vec2<f32>(p.x, p.y);
}

struct MeshSurface {
    albedo: vec3<f32>,
    roughness: f32,
    emission: vec3<f32>,
    normal: vec3<f32>,
    f0: f32,
}

// Brick courses of 7.5 cm, bricks 22 cm long, mortar lines 1 cm; mortar and brick-to-brick variation
// fade to their average once they are smaller than a pixel (`pixel`, metres), so walls do not
// shimmer or show moire in the distance.
fn brick(p: vec2<f32>, base: vec3<f32>, seed: f32, pixel: f32) -> vec3<f32> {
    let course = floor(p.y / 0.075);
    let x = p.x / 0.225 + 0.5 * (course - 2.0 * floor(course * 0.5));
    let id = vec2<i32>(i32(floor(x)), i32(course) + i32(seed * 97.0));
    let fx = fract(x);
    let fy = fract(p.y / 0.075);
    let mortar = smoothstep(0.0, 0.05, fx) * smoothstep(0.0, 0.05, 1.0 - fx) * smoothstep(0.0, 0.13, fy) * smoothstep(0.0, 0.13, 1.0 - fy);
    let v = mix(snow_hash2(id), 0.5, smoothstep(0.02, 0.06, pixel));
    let b = base * (0.7 + 0.6 * v) * (0.85 + 0.3 * snow_noise(p * 3.0).x);
    let m = mix(mortar, 0.78, smoothstep(0.003, 0.012, pixel));
    return mix(vec3<f32>(0.22, 0.21, 0.2), b, m);
}

fn material(in: MeshPoint, n: vec3<f32>, pixel: f32) -> MeshSurface {
    let kind = u32(in.albedo_material.w + 0.5);
    let base = in.albedo_material.rgb;
    var s: MeshSurface;
    s.albedo = base;
    s.roughness = in.params.x;
    s.emission = vec3<f32>(0.0);
    s.normal = n;
    s.f0 = 0.04;
    let w = wall_coords(in.world, n);
    switch kind {
        case MATERIAL_BRICK: {
            s.albedo = brick(w, base, in.params.w, pixel);
        }
        case MATERIAL_FACADE: {
            // Brick with a grid of windows: 1.1 m x 1.5 m, every 3 m, floors 3.2 m high. A third
            // of them are lit, warm.
            s.albedo = brick(w, base, in.params.w, pixel);
            let cell = vec2<f32>(w.x / 3.0, (w.y - 0.9) / 3.2);
            let id = vec2<i32>(floor(cell)) + vec2<i32>(i32(in.params.w * 131.0), 0);
            let f = fract(cell) * vec2<f32>(3.0, 3.2);
            let inside = step(0.95, f.x) * step(f.x, 2.05) * step(0.0, f.y) * step(f.y, 1.5);
            if inside > 0.5 && abs(n.y) < 0.5 {
                let v = snow_hash2(id);
                let lit = step(0.62, v);
                let warm = mix(vec3<f32>(1.0, 0.62, 0.28), vec3<f32>(0.9, 0.8, 0.6), snow_hash2(id + vec2<i32>(7, 3)));
                s.albedo = vec3<f32>(0.02, 0.025, 0.03);
                s.roughness = 0.08;
                s.f0 = 0.06;
                s.emission = warm * lit * (0.5 + 0.6 * snow_hash2(id + vec2<i32>(1, 9)));
            }
        }
        case MATERIAL_CONCRETE: {
            s.albedo = base * (0.75 + 0.5 * snow_fbm(w, 0.9, pixel).x);
        }
        case MATERIAL_METAL: {
            // Painted metal with rust streaks running down.
            let rust = smoothstep(0.55, 0.8, snow_noise(vec2<f32>(w.x * 6.0, w.y * 0.6)).x);
            s.albedo = mix(base, vec3<f32>(0.2, 0.08, 0.03), rust);
            s.roughness = mix(0.45, 0.8, rust);
            s.f0 = 0.05;
        }
        case MATERIAL_EMISSIVE: {
            s.emission = base * in.params.y;
            s.albedo = base * 0.2;
        }
        default: {}
    }
    if kind != MATERIAL_EMISSIVE && in.params.y > 0.0 {
        s.emission += base * in.params.y;
    }
    // Snow lying on everything that faces up (ledges, parapets, the water tower's roof).
    let cover = in.params.z * smoothstep(0.55, 0.85, n.y + 0.15 * (snow_noise(in.world.xz * 4.0).x - 0.5));
    if cover > 0.0 {
        let q = in.world.xz;
        let sn = snow_ts_to_local(snow_rnm(snow_macro_normal(q), snow_detail_normal(q, 1.0, pixel)));
        s.albedo = mix(s.albedo, SNOW_FRESH, cover);
        s.roughness = mix(s.roughness, 0.62, cover);
        s.normal = normalize(mix(s.normal, normalize(vec3<f32>(sn.x * 0.5, 1.0, sn.z * 0.5)), cover));
        s.emission *= 1.0 - cover;
    }
    return s;
}

// The HDR colour of a mesh's point: `normal` as interpolated (not unit), `pixel` the world
// footprint of a pixel there (metres: the length of `fwidth` of the world position).
fn shade_mesh(in: MeshPoint, normal: vec3<f32>, pixel: f32) -> vec3<f32> {
    let n = normalize(normal);
    let s = material(in, n, pixel);
    let shadow = moon_shadow(in.world, n);
    var c = light_surface(s.albedo, s.roughness, s.f0, s.normal, in.world, 1.0, 0.0, shadow) + s.emission;
    if frame.options.x == DEBUG_NORMALS {
        c = s.normal * 0.5 + 0.5;
    } else if frame.options.x != DEBUG_SHADED {
        c = vec3<f32>(0.12) * (0.5 + 0.5 * n.y);
    }
    return c;
}
