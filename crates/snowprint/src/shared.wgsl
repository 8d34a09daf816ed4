// Shared layout of the per-surface record read by every compute pass of the update.
// Must match `SurfaceRecord` in src/pool/mod.rs (checked by a test that parses this file with naga).

// import constants

struct SurfaceRecord {
    // Word (u32) offsets into the pool buffer.
    heights: u32,         // the heights region (see pool/texel.wgsl), updated in place
    normals: u32,         // normals region (pack2x16snorm of local x and z), or NO_NORMALS
    scratch: u32,         // word offset into the per-frame capture buffers and the scratch
    width: u32,
    height: u32,
    atlas_x: u32,         // where the surface's capture lies in the capture atlas
    atlas_y: u32,
    mode: u32,            // bit 0: mask capture (else depth); bit 1: MODE_MESHES; bit 2: MODE_GROUND; bit 3: MODE_REFILLED; bit 4: MODE_CAST
    replenish_units: u32, // channel units (1/channel_max(PRECISION) of the snow depth) refilled
    batch: u32,           // capture batch; NO_CAPTURE when nothing touched the surface (0xfffffffe: the compute path; 0xfffffffd: cast by the update)
    mask_fraction: f32,   // mask capture: fraction of the snow depth a covered texel is pressed
    snow_depth: f32,      // metres
    frustum_height: f32,  // metres: snow depth + ankle height
    texel_x: f32,         // metres
    texel_z: f32,         // metres
    tiles: u32,           // first of the surface's 16x16 tile flags (set where the capture wrote)
    wrap: u32,            // toroidal storage offsets, ox | oy << 16 (pool/texel.wgsl); 0: none
    // MODE_CAST: what the update's own ray cast reads (accumulate/cast.wgsl); else unused.
    half_x: f32,          // half the surface's sides, metres
    half_z: f32,
    prims: u32,           // its primitives in the capture's list: first
    prim_count: u32,      // and how many
    ground: u32,          // first texel of its ground field, or NO_GROUND
}

// Bits a channel of the pool's heightmaps (8, 16 or 32): set when the world compiles its passes.
override PRECISION: u32 = 16u;
