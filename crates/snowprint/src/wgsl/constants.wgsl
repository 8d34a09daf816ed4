// constants.wgsl: the constants that the Rust code and the WGSL both use, defined here once.
// build.rs reflects every `const` of this file into `snowprint::wgsl::consts` (the comment lines
// right above a declaration become its doc); WGSL modules bring them in with `// import constants`.
// Only scalar literals (u32, i32, f32, bool) belong here.

// Code of depth 1.0, the top of the capture frustum: a stored capture value v is the depth
// bitcast(ONE_BITS - v), 0 (the cleared value) meaning nothing was captured.
const ONE_BITS: u32 = 0x3f800000u;
// Side of the update's tiles, the fused pass's workgroup side.
const TILE: u32 = 16u;
// Texels of apron a surface's capture covers beyond each of its sides: the blur reads one texel
// around each texel, so two surfaces on one grid blur the same field where they meet.
const APRON: u32 = 1u;
// Workgroup side of the separate accumulation passes.
const WORKGROUP: u32 = 8u;
// Invocations of a workgroup of the refill (accumulate/refill.wgsl).
const REFILL_GROUP: u32 = 256u;
// 16-byte vectors of a heights region each invocation of the refill takes, all loaded before any
// is stored.
const REFILL_VECTORS: u32 = 2u;
// The most workgroups a dispatch takes along one axis (wgpu's default limit, WebGPU's): a dispatch
// over a list takes as few rows of them as this allows (gpu::resources::dispatch_rows, seal.wgsl).
const DISPATCH_ROW_MAX: u32 = 65535u;
// Words before the entries of the capture's tile list: the dispatch arguments (0-2), the count
// (3), the first record of the fused pass's grid (TILE_LIST_GRID_FIRST), and three unused.
const TILE_LIST_HEADER: u32 = 8u;
// Word of the tile list's header holding the first record of the fused pass's grid (0 unless the
// plan uploads the header: the records before it are cast by the update and refill snow).
const TILE_LIST_GRID_FIRST: u32 = 4u;
// What a primitive leaves at a texel it does not press (capture/write.wgsl's `prim_code`): above
// every code of a depth in [0, 1].
const NO_HIT: u32 = 0xffffffffu;
// `record` of a capture view whose flagged tiles are not listed (the update runs its grid).
const NO_LIST: u32 = 0xffffffffu;
// `ground` of a capture view whose surface lies on flat ground (no ground field is read).
const NO_GROUND: u32 = 0xffffffffu;
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
// Mode bit of a surface record: meshes press a surface on ground that is not flat (pool/mod.rs).
const MODE_GROUND: u32 = 4u;
// Mode bit of a surface record: its snowfall is refilled by the streaming refill pass this update,
// so the fused pass replenishes nothing and updates only the tiles the capture reached.
const MODE_REFILLED: u32 = 8u;
// Mode bit of a surface record: its analytic primitives are ray-cast by the fused update itself
// where its blur reads them (accumulate/cast.wgsl); nothing of it is in the capture's buffers.
const MODE_CAST: u32 = 16u;
// Most primitives a surface the update ray-casts may have (a bit each of a tile's mask).
const CAST_PRIMS_MAX: u32 = 32u;
// Primitive kind of a capture primitive (`kind.x`): a capsule (a sphere is a capsule of zero length).
const PRIM_CAPSULE: u32 = 0u;
// Primitive kind of a capture primitive: an oriented box.
const PRIM_BOX: u32 = 1u;
// Texels the renderer's heightfield and bank textures hold beyond each side of a heightmap: the
// surface's cubic B-spline reads two texels past its edge, so two surfaces side by side draw the
// same heights on the line where they meet (render/heightfield/heightfield.wgsl).
const HEIGHTFIELD_BORDER: i32 = 2;
// Words per surface in the renderer's surface state table (written by classify.wgsl).
const STATE_WORDS: u32 = 16u;
// Word of a surface's state holding the "deformed" flag.
const STATE_TOUCHED: u32 = 11u;
// Word of a surface's state that is 1 when its heightfield and bank passes are to run this frame
// (classify.wgsl: it takes the deformable material and the frame can show it), else 0.
const STATE_SHADED: u32 = 8u;
// Words of the dicing counters before the per-surface draw arguments.
const ARGS_BASE: u32 = 8u;
// Words per surface of the dicing's draw arguments.
const ARGS_STRIDE: u32 = 8u;
// Bit of a base triangle's first edge's seam mark (`ids.w`, four bits an edge): where the diced
// snow meets another surface's (render/tessellate/seams.rs), the edge's skirt is shaded as the top.
const SEAM_SHIFT: u32 = 8u;
// Seam mark of an edge on the rectangle's side k (local -x, +x, -z, +z): SEAM_SIDE + k, a seam
// when the dicing parameters' side mask has bit k.
const SEAM_SIDE: u32 = 1u;
// Seam mark of an edge of the hole a finer terrain window level draws: always a seam.
const SEAM_HOLE: u32 = 5u;
// Dicing counter of vertices appended.
const COUNTER_VERTICES: u32 = 0u;
// Dicing counter of indices appended.
const COUNTER_INDICES: u32 = 1u;
// Dicing counter of indices already sealed into draw arguments.
const COUNTER_SEALED: u32 = 2u;
// Dicing counter of base triangles dropped because the buffers were full.
const COUNTER_OVERFLOW: u32 = 3u;
// Point lights the frame uniform holds.
const MAX_POINT_LIGHTS: u32 = 8u;
// Softness of the moon's shadow over the snow: penumbra width per metre from the occluder (the
// heightfield pass and its CPU reference, render::cpu::light_visibility).
const PENUMBRA_SLOPE: f32 = 0.12;
// Penumbra width at the occluder, metres.
const PENUMBRA_BASE: f32 = 0.01;
// Most taps of the light visibility along the moon's direction.
const LIGHT_TAPS: u32 = 16u;
// Directions of the horizon search of the snow's ambient occlusion.
const AO_DIRECTIONS: u32 = 8u;
// Least receptivity of a texel to banks (at the bottom of trails), so that no pushed snow is lost.
const RECEPTIVITY_FLOOR: f32 = 0.001;
// Side of the square of texels a workgroup of the relaxation (relax/relax.wgsl) writes.
const RELAX_TILE: u32 = 32u;
// Most relaxation steps one dispatch takes: the halo of texels a workgroup reads around its tile.
const RELAX_HALO: u32 = 4u;
// Vertices a workgroup of the skinning pass (skin/skin.wgsl) skins.
const SKIN_WORKGROUP: u32 = 64u;
// Tag of a snow hit in the first word of the visibility buffer (`OpaquePath::Visibility`): the
// deformable material's fragments write it, with the surface's slot above SNOW_SLOT_SHIFT; an
// opaque triangle's instance never reaches it, and the cleared value (every bit set) is neither.
const SNOW_VISIBLE: u32 = 0x80000000u;
// First bit of a snow hit's surface slot in the visibility buffer's first word (below it: the box
// face, the hit's side and water flags, and its taps).
const SNOW_SLOT_SHIFT: u32 = 13u;
