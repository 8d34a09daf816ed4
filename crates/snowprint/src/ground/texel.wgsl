// texel.wgsl (module `ground_texel`): the one place a shader reads a surface's ground field. The
// including shader declares `ground: array<vec2<f32>>` (the world's packed fields,
// `SnowWorld::ground_buffer`); a surface's field starts at its first texel (`NO_GROUND` on flat
// ground, which the callers test first) and runs row after row, `width` texels a row. Texel
// (x, y) is logical: column x along local +x, row y along local +z, as the pool's heightmaps.
// Every reader goes through this function (the capture, the renderer's snow, tessellated snow and
// heightfield passes), so a field stored another way changes here only.
// CPU reference: ground::GroundField::columns.

// (base, bare) of texel (x, y) of the field starting at `first`: the bottom of the snow column
// (local y, metres) and its bare depth (the rock between the base and the ground).
fn ground_texel(first: u32, width: u32, x: u32, y: u32) -> vec2<f32> {
    return ground[first + y * width + x];
}
