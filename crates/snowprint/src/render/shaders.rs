//! The renderer's WGSL, one file per pass, and how each pass's module is put together. A pass's
//! module is its own file after the modules it imports (`frame.wgsl` for the shared uniforms and
//! lighting, `snow.wgsl` for the material); WGSL lets declarations come in any order, so plain
//! concatenation is the import.

/// Shared frame uniforms, shadow map and lighting.
pub const FRAME: &str = include_str!("frame/frame.wgsl");
/// The snow material (basic and deformable), importable by other renderers: see its header.
pub const SNOW: &str = include_str!("snow/snow.wgsl");
/// The snow pass: surface boxes, relief mapping, frag depth.
pub const SURFACE: &str = include_str!("snow/surface.wgsl");
/// Opaque meshes and the shadow map.
pub const MESH: &str = include_str!("opaque/mesh.wgsl");
/// The night sky.
pub const SKY: &str = include_str!("sky/sky.wgsl");
/// Falling snow.
pub const SNOWFALL: &str = include_str!("snowfall/snowfall.wgsl");
/// Resolve and tonemap.
pub const TONEMAP: &str = include_str!("tonemap/tonemap.wgsl");
/// Per-surface material choice and indirect arguments.
pub const CLASSIFY: &str = include_str!("classify/classify.wgsl");
/// Heightmap to filtered shading texture (depression, normal, occlusion).
pub const HEIGHTFIELD: &str = include_str!("heightfield/heightfield.wgsl");

/// Module of the classify pass (reads the pool through `pool/texel.wgsl`).
pub fn classify() -> String {
    join(&[crate::pool::TEXEL_WGSL, CLASSIFY])
}

/// Module of the heightfield pass (reads the pool through `pool/texel.wgsl`).
pub fn heightfield() -> String {
    join(&[crate::pool::TEXEL_WGSL, HEIGHTFIELD])
}

/// Snow banks from the displaced channel (tessellated tier).
pub const BANKS: &str = include_str!("tessellate/banks/banks.wgsl");
/// Dicing of the snow surfaces' meshes (tessellated tier).
pub const DICE: &str = include_str!("tessellate/dice/dice.wgsl");
/// The tessellated tier's snow: displacement, shading, shadow.
pub const TESS_SURFACE: &str = include_str!("tessellate/snow_shadow/tess_surface.wgsl");

fn join(parts: &[&str]) -> String {
    parts.join("\n")
}

/// Module of the snow pass.
pub fn surface() -> String {
    join(&[FRAME, SNOW, SURFACE])
}

/// Module of the tessellated tier's snow and snow shadow passes (it reuses the snow pass's
/// bindings and heightfield contract).
pub fn tess_surface() -> String {
    join(&[FRAME, SNOW, SURFACE, TESS_SURFACE])
}

/// Module of the shadow and opaque passes.
pub fn mesh() -> String {
    join(&[FRAME, SNOW, MESH])
}

/// Module of the sky pass.
pub fn sky() -> String {
    join(&[FRAME, SKY])
}

/// Module of the snowfall pass.
pub fn snowfall() -> String {
    join(&[FRAME, SNOWFALL])
}

/// Module of the tonemap pass.
pub fn tonemap() -> String {
    join(&[FRAME, TONEMAP])
}

/// Every pass's module, by name (for validation tests).
pub fn all() -> Vec<(&'static str, String)> {
    vec![
        ("surface", surface()),
        ("mesh", mesh()),
        ("sky", sky()),
        ("snowfall", snowfall()),
        ("tonemap", tonemap()),
        ("classify", classify()),
        ("heightfield", heightfield()),
        ("tess_surface", tess_surface()),
        ("banks", BANKS.to_owned()),
        ("dice", DICE.to_owned()),
    ]
}
