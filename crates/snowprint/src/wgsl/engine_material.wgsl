// engine_material.wgsl: the snow material (render/snow/snow.wgsl) with its heightfield contract
// filled from the pool by engine.wgsl, for an engine that wants the material without deriving
// heightfield textures (`wgsl::material_module`). Defines the four functions snow.wgsl calls:
// `snow_depression` (one bilinear read of the pool), `snow_heightfield` (depression and the
// normal by central differences; no ambient occlusion, so 1) and `snow_light_visibility` (no
// shadow of the prints' walls, so 1). The snowprint renderer draws smoother normals and those two
// terms from its heightfield textures (heightfield.wgsl); these defaults cost more pool reads per
// pixel and show the texel grid at close range.

// import engine, snow

// The engine module's view of a material surface (the two structs have one layout).
fn snowprint_surface_of(s: SnowSurface) -> snowprint_Surface {
    return snowprint_Surface(
        s.local_to_world, s.world_to_local, s.half_size, s.snow_depth, s.texel, s.grid,
        s.ground, s.index, s.search, s.look, s.pattern,
        s.heights, s.row_words, s.bits, s.channel_max, s.width, s.height, s.texel_x, s.texel_z,
        s.albedo, s.disturbed, s.grain, s.translucency,
        s.terrain, s.terrain_low, s.terrain_top, s.wrap, s.hole,
    );
}

// The engine module binds no ground field: the snow is drawn on flat ground.
fn snow_ground_base(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 0.0;
}

fn snow_depression(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return snowprint_depression_uv(snowprint_surface_of(s), uv);
}

fn snow_heightfield(s: SnowSurface, uv: vec2<f32>) -> vec4<f32> {
    let e = snowprint_surface_of(s);
    let n = snowprint_normal(e, uv);
    return vec4<f32>(snowprint_depression_uv(e, uv), n.x, n.z, 1.0);
}

fn snow_light_visibility(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 1.0;
}
