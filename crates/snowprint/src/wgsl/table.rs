// The shader registry's one table: every WGSL file of the crate, by module name, as a path under
// `crates/snowprint/src/`. `build.rs` includes this file: it composes every *entry* module (one
// that a pipeline compiles) from its file and the modules it imports, validates it with naga and
// writes it to `OUT_DIR`; `src/wgsl/mod.rs` exposes the results. A WGSL file imports another module
// by name with a line `// import name` (after its header comment); an import brings in the whole
// module (and what that imports) once, before the importer's own text. Moving a file means editing
// its row here, nothing else.

/// (module name, path under `src/`, entry module: compiled by a pipeline).
const WGSL_FILES: &[(&str, &str, bool)] = &[
    // Constants shared by Rust and WGSL (reflected into `wgsl::consts`).
    ("constants", "wgsl/constants.wgsl", false),
    // The update: capture, then the accumulation chain.
    ("shared", "shared.wgsl", false),
    ("channels", "pool/channels.wgsl", false),
    ("texel", "pool/texel.wgsl", false),
    ("texel_write", "pool/texel_write.wgsl", false),
    ("maths", "accumulate/maths.wgsl", false),
    ("capture_read", "accumulate/capture_read.wgsl", false),
    ("update_cast", "accumulate/cast.wgsl", false),
    ("capture_cast", "capture/cast.wgsl", false),
    ("capture_write", "capture/write.wgsl", false),
    ("capture", "capture/capture.wgsl", true),
    ("capture_prims", "capture/prims.wgsl", true),
    ("blur", "accumulate/blur.wgsl", true),
    ("merge", "accumulate/merge.wgsl", true),
    ("normals", "accumulate/normals.wgsl", true),
    ("refill", "accumulate/refill.wgsl", true),
    ("fused", "accumulate/fused.wgsl", true),
    ("seal", "accumulate/seal.wgsl", true),
    // Kicked-up snow: spawned from the update's data, simulated in a ring (`spray/`).
    ("particle", "spray/particle.wgsl", false),
    ("spray_spawn", "spray/spawn.wgsl", true),
    ("spray_simulate", "spray/simulate.wgsl", true),
    // Materials that slump to their angle of repose.
    ("relax", "relax/relax.wgsl", true),
    // Skinned mesh deformers: the bind pose blended by the joints into the capture's vertices.
    ("skin", "skin/skin.wgsl", true),
    // Ground meshes rasterised into surfaces' texels (`ground/`).
    ("ground_raster", "ground/raster.wgsl", true),
    // Reading a surface's ground field (the capture and the renderer).
    ("ground_texel", "ground/texel.wgsl", false),
    // A terrain's sliding window: strips paged between the pool and the CPU (`window/`).
    ("window_strip", "window/strip.wgsl", true),
    // Gameplay probes: the pool under chosen points.
    ("probe", "world/probe/probe.wgsl", true),
    // The renderer.
    ("frame", "render/frame/frame.wgsl", false),
    ("snow", "render/snow/snow.wgsl", false),
    ("surface", "render/snow/surface.wgsl", true),
    ("tess_surface", "render/tessellate/snow_shadow/tess_surface.wgsl", true),
    ("mesh_shading", "render/opaque/shading.wgsl", false),
    ("mesh", "render/opaque/mesh.wgsl", true),
    ("mesh_geometry", "render/opaque/geometry.wgsl", false),
    ("mesh_visibility", "render/opaque/visibility.wgsl", true),
    ("mesh_shade", "render/opaque/shade.wgsl", true),
    ("sky", "render/sky/sky.wgsl", true),
    ("shadow_restore", "render/shadow/restore.wgsl", true),
    ("snowfall", "render/snowfall/snowfall.wgsl", true),
    ("spray", "render/spray/spray.wgsl", true),
    ("tonemap_resolve", "render/tonemap/resolve.wgsl", false),
    ("tonemap", "render/tonemap/tonemap.wgsl", true),
    ("tonemap_compute", "render/tonemap/tonemap_compute.wgsl", true),
    ("classify", "render/classify/classify.wgsl", true),
    ("heightfield_texels", "render/heightfield/texels.wgsl", false),
    ("heightfield", "render/heightfield/heightfield.wgsl", true),
    ("banks", "render/tessellate/banks/banks.wgsl", true),
    ("dice", "render/tessellate/dice/dice.wgsl", true),
    // For engines' own shaders: the pool read by prefixed functions, and the material on it.
    ("engine", "wgsl/engine.wgsl", false),
    ("engine_material", "wgsl/engine_material.wgsl", false),
];
