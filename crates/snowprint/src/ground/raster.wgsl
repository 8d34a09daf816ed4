// Rasterise a ground mesh into a surface's texels, looking straight down its local y: each
// fragment lands on one texel (the viewport is the surface's heightmap, fragment (c + 0.5, r + 0.5)
// is texel (c, r)'s centre, as in capture.wgsl) and keeps the highest face over the texel's centre
// with an atomic max on an order-preserving code of its height. Nothing is clipped by depth.
// Reads: `view`, the mesh's vertices (world metres). Writes: `heights` (cleared to 0 = no face).
// CPU reference: ground::cpu::rasterise.

struct RasterView {
    to_local: mat4x4<f32>,  // world to surface-local
    half_size: vec2<f32>,   // half the surface's sides, metres
    width: u32,             // heightmap texels along x
    pad: u32,
}
// Must match `RasterView` in ground/raster.rs.

@group(0) @binding(0) var<uniform> view: RasterView;
@group(0) @binding(1) var<storage, read_write> heights: array<atomic<u32>>;

struct RasterOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) height: f32,
}

@vertex
fn vs_ground(@location(0) position: vec3<f32>) -> RasterOut {
    let local = view.to_local * vec4<f32>(position, 1.0);
    var out: RasterOut;
    // Column 0 is the smallest x and row 0 the smallest z: NDC y is +1 at row 0.
    out.clip = vec4<f32>(local.x / view.half_size.x, -local.z / view.half_size.y, 0.5, 1.0);
    out.height = local.y;
    return out;
}

// Larger heights give larger codes; no height gives 0 (the cleared "no face").
fn height_code(h: f32) -> u32 {
    let b = bitcast<u32>(h);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

@fragment
fn fs_ground(in: RasterOut) {
    let cell = vec2<u32>(in.clip.xy);
    atomicMax(&heights[cell.y * view.width + cell.x], height_code(in.height));
}
