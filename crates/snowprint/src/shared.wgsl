// Shared layout of the per-surface record read by every compute pass of the update.
// Must match `SurfaceRecord` in src/pool/mod.rs (checked by a test that parses this file with naga).

struct SurfaceRecord {
    // Element (u32) offsets into the pool buffer.
    heights_read: u32,    // half of the ping-pong pair holding the previous heightmap
    heights_write: u32,   // half that receives the new heightmap
    normals: u32,         // normals region (pack2x16snorm of local x and z)
    scratch: u32,         // element offset into the scratch buffer (blurred capture, f32)
    width: u32,
    height: u32,
    atlas_x: u32,         // where the surface's capture lies in the capture atlas
    atlas_y: u32,
    mode: u32,            // 0 = depth capture, 1 = mask capture
    replenish_units: u32, // depression units (1/65535 of the snow depth) refilled this update
    batch: u32,           // capture batch; NO_CAPTURE when nothing touched the surface
    mask_fraction: f32,   // mask capture: fraction of the snow depth a covered texel is pressed
    snow_depth: f32,      // metres
    frustum_height: f32,  // metres: snow depth + ankle height
    texel_x: f32,         // metres
    texel_z: f32,         // metres
}

const NO_CAPTURE: u32 = 0xffffffffu;
const MODE_DEPTH: u32 = 0u;
const MODE_MASK: u32 = 1u;
const UNITS: f32 = 65535.0;
