//! The renderer's WGSL, one file per pass. A pass's module is its own file after the modules it
//! imports (`frame.wgsl` for the shared uniforms and lighting, `snow.wgsl` for the material), as
//! composed and validated by the shader registry ([`crate::wgsl`]).

/// Shared frame uniforms, shadow map and lighting.
pub const FRAME: &str = crate::wgsl::files::FRAME;
/// The snow material (basic and deformable), importable by other renderers: see its header.
pub const SNOW: &str = crate::wgsl::files::SNOW;
/// The snow pass: surface boxes, relief mapping, frag depth.
pub const SURFACE: &str = crate::wgsl::files::SURFACE;
/// Opaque meshes and the shadow map.
pub const MESH: &str = crate::wgsl::files::MESH;
/// The night sky.
pub const SKY: &str = crate::wgsl::files::SKY;
/// Falling snow.
pub const SNOWFALL: &str = crate::wgsl::files::SNOWFALL;
/// Resolve and tonemap.
pub const TONEMAP: &str = crate::wgsl::files::TONEMAP;
/// Per-surface material choice and indirect arguments.
pub const CLASSIFY: &str = crate::wgsl::files::CLASSIFY;
/// Heightmap to filtered shading texture (depression, normal, occlusion).
pub const HEIGHTFIELD: &str = crate::wgsl::files::HEIGHTFIELD;

/// Module of the classify pass (reads the pool through `pool/texel.wgsl`).
pub fn classify() -> String {
    crate::wgsl::CLASSIFY.wgsl()
}

/// Module of the heightfield pass (reads the pool through `pool/texel.wgsl`).
pub fn heightfield() -> String {
    crate::wgsl::HEIGHTFIELD.wgsl()
}

/// Snow banks from the displaced channel (tessellated tier).
pub const BANKS: &str = crate::wgsl::BANKS.source;
/// Dicing of the snow surfaces' meshes (tessellated tier).
pub const DICE: &str = crate::wgsl::DICE.source;
/// The tessellated tier's snow: displacement, shading, shadow.
pub const TESS_SURFACE: &str = crate::wgsl::files::TESS_SURFACE;

/// Module of the snow pass.
pub fn surface() -> String {
    crate::wgsl::SURFACE.wgsl()
}

/// Module of the tessellated tier's snow and snow shadow passes (it reuses the snow pass's
/// bindings and heightfield contract).
pub fn tess_surface() -> String {
    crate::wgsl::TESS_SURFACE.wgsl()
}

/// Module of the shadow and opaque passes.
pub fn mesh() -> String {
    crate::wgsl::MESH.wgsl()
}

/// Module of the sky pass.
pub fn sky() -> String {
    crate::wgsl::SKY.wgsl()
}

/// Module of the snowfall pass.
pub fn snowfall() -> String {
    crate::wgsl::SNOWFALL.wgsl()
}

/// Module of the tonemap pass.
pub fn tonemap() -> String {
    crate::wgsl::TONEMAP.wgsl()
}

/// Every pass's module, by name (for validation tests).
pub fn all() -> Vec<(&'static str, String)> {
    [
        "surface",
        "mesh",
        "sky",
        "snowfall",
        "tonemap",
        "classify",
        "heightfield",
        "tess_surface",
        "banks",
        "dice",
    ]
    .into_iter()
    .filter_map(|name| Some((name, crate::wgsl::get(name)?.wgsl())))
    .collect()
}
