// constants.wgsl: the constants that the Rust code and the WGSL both use, defined here once.
// build.rs reflects every `const` of this file into `snowprint::wgsl::consts` (the comment lines
// right above a declaration become its doc); WGSL modules bring them in with `// import constants`.
// Only scalar literals (u32, i32, f32, bool) belong here.

// Code of depth 1.0, the top of the capture frustum: a stored capture value v is the depth
// bitcast(ONE_BITS - v), 0 (the cleared value) meaning nothing was captured.
const ONE_BITS: u32 = 0x3f800000u;
// Side of the update's tiles, the fused pass's workgroup side.
const TILE: u32 = 16u;
// Workgroup side of the separate accumulation passes.
const WORKGROUP: u32 = 8u;
// Words before the entries of the capture's tile list: the dispatch arguments and the count.
const TILE_LIST_HEADER: u32 = 4u;
// `record` of a capture view whose flagged tiles are not listed (the update runs its grid).
const NO_LIST: u32 = 0xffffffffu;
// `batch` of a surface record that nothing touched this update.
const NO_CAPTURE: u32 = 0xffffffffu;
// `normals` of a surface record whose pool keeps no normals.
const NO_NORMALS: u32 = 0xffffffffu;
// `mode` of a surface record: depth capture.
const MODE_DEPTH: u32 = 0u;
// Bit of `mode`: mask capture (else depth).
const MODE_MASK: u32 = 1u;
// Bit of `mode` set when mesh solids were drawn over the surface: only then is `winding` read.
const MODE_MESHES: u32 = 2u;
