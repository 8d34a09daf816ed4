//! The scene file exactly as written: every field optional and spanned, so that the checks in
//! `convert` can say which line is wrong and quote what is there. Unknown keys are refused by serde
//! (`deny_unknown_fields`) and reported through `diagnose::toml_error`.

use serde::Deserialize;
use toml::Spanned;

/// A spanned number (TOML integers are accepted where floats are expected).
pub(super) type Num = Spanned<f64>;
/// A spanned array of numbers (its length is checked later).
pub(super) type Nums = Spanned<Vec<f64>>;
/// A spanned string.
pub(super) type Str = Spanned<String>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    pub version: Option<Spanned<i64>>,
    pub capture: Option<Spanned<RawCapture>>,
    #[serde(default)]
    pub surface: Vec<Spanned<RawSurface>>,
    #[serde(default)]
    pub deformer: Vec<Spanned<RawDeformer>>,
    pub budget: Option<Spanned<RawBudget>>,
    pub camera: Option<Spanned<RawCamera>>,
    #[serde(default)]
    pub material: Vec<Spanned<RawMaterial>>,
    #[serde(default)]
    pub terrain: Vec<Spanned<RawTerrain>>,
}

/// One `[[terrain]]`: a snow layer whose window follows a focus (`crate::Terrain`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTerrain {
    pub name: Option<Str>,
    pub ground_height: Option<Num>,
    pub snow_depth: Option<Num>,
    pub replenish_rate: Option<Num>,
    pub material: Option<Str>,
    pub follow: Option<Str>,
    pub levels: Option<Spanned<Vec<Spanned<RawLevel>>>>,
    pub ground: Option<Str>,
    pub ground_heights: Option<Nums>,
    pub ground_grid: Option<Nums>,
    pub ground_rect: Option<Nums>,
    pub full_slope_degrees: Option<Num>,
    pub bare_slope_degrees: Option<Num>,
}

/// One level of a `[[terrain]]`, inline (`levels = [{ ... }]`) or as `[[terrain.levels]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLevel {
    pub texels: Option<Nums>,
    pub texel_size: Option<Num>,
}

/// One `[[material]]`: a preset with some keys changed.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaterial {
    pub name: Option<Str>,
    pub like: Option<Str>,
    pub repose_degrees: Option<Num>,
    pub relax_steps: Option<Spanned<i64>>,
    pub settle_updates: Option<Spanned<i64>>,
    pub compressibility: Option<Num>,
    pub albedo: Option<Nums>,
    pub disturbed_albedo: Option<Nums>,
    pub roughness: Option<Num>,
    pub wet_roughness: Option<Num>,
    pub grain: Option<Num>,
    pub sparkle: Option<Num>,
    pub wetness: Option<Num>,
    pub translucency: Option<Num>,
    pub water_depth: Option<Num>,
    pub ground_from: Option<Num>,
}

/// `[budget]`: the surface manager's limits.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBudget {
    pub updates_per_frame: Option<Spanned<i64>>,
    pub pool_bytes: Option<Spanned<i64>>,
    pub active_distance: Option<Num>,
    pub precision_bits: Option<Spanned<i64>>,
}

/// `[camera]`: keyed eye positions looking at one target.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCamera {
    pub target: Option<Nums>,
    pub fov_y_degrees: Option<Num>,
    pub keys: Option<Spanned<Vec<Spanned<RawCameraKey>>>>,
}

/// One key of the camera.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCameraKey {
    pub t: Option<Num>,
    pub eye: Option<Nums>,
}

/// `[capture]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCapture {
    pub mode: Option<Str>,
    pub ankle_height: Option<Num>,
    pub mask_depth: Option<Num>,
}

/// One `[[surface]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSurface {
    pub name: Option<Str>,
    pub center: Option<Nums>,
    pub size: Option<Nums>,
    pub yaw_degrees: Option<Num>,
    pub snow_depth: Option<Num>,
    pub replenish_rate: Option<Num>,
    pub material: Option<Str>,
    pub zone: Option<Spanned<i64>>,
    pub ground: Option<Str>,
    pub ground_heights: Option<Nums>,
    pub ground_grid: Option<Nums>,
    pub full_slope_degrees: Option<Num>,
    pub bare_slope_degrees: Option<Num>,
}

/// One `[[deformer]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDeformer {
    pub name: Option<Str>,
    pub shape: Option<Str>,
    pub radius: Option<Num>,
    pub half_height: Option<Num>,
    pub half_extents: Option<Nums>,
    pub path: Option<Str>,
    pub player: Option<Spanned<bool>>,
    pub keys: Option<Spanned<Vec<Spanned<RawKey>>>>,
    pub animation: Option<Str>,
    pub animation_speed: Option<Num>,
    #[serde(rename = "loop")]
    pub looping: Option<Spanned<bool>>,
}

/// One key of a deformer, inline (`keys = [{ ... }]`) or as `[[deformer.keys]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawKey {
    pub t: Option<Num>,
    pub position: Option<Nums>,
    pub rotation_degrees: Option<Nums>,
}

/// The keys each table accepts, for messages about unknown keys. The first entry says where the
/// table is, as a user would look for it.
pub(super) const TABLES: &[(&str, &[&str])] = &[
    (
        "at the top level",
        &[
            "version", "capture", "surface", "deformer", "budget", "camera", "material", "terrain",
        ],
    ),
    (
        "in a [[terrain]] table",
        &[
            "name",
            "ground_height",
            "snow_depth",
            "replenish_rate",
            "material",
            "follow",
            "levels",
            "ground",
            "ground_heights",
            "ground_grid",
            "ground_rect",
            "full_slope_degrees",
            "bare_slope_degrees",
        ],
    ),
    ("in a terrain level", &["texels", "texel_size"]),
    ("in [capture]", &["mode", "ankle_height", "mask_depth"]),
    (
        "in a [[material]] table",
        &[
            "name",
            "like",
            "repose_degrees",
            "relax_steps",
            "settle_updates",
            "compressibility",
            "albedo",
            "disturbed_albedo",
            "roughness",
            "wet_roughness",
            "grain",
            "sparkle",
            "wetness",
            "translucency",
            "water_depth",
            "ground_from",
        ],
    ),
    (
        "in a [[surface]] table",
        &[
            "name",
            "center",
            "size",
            "yaw_degrees",
            "snow_depth",
            "replenish_rate",
            "material",
            "zone",
            "ground",
            "ground_heights",
            "ground_grid",
            "full_slope_degrees",
            "bare_slope_degrees",
        ],
    ),
    (
        "in a [[deformer]] table",
        &[
            "name",
            "shape",
            "radius",
            "half_height",
            "half_extents",
            "path",
            "player",
            "keys",
            "animation",
            "animation_speed",
            "loop",
        ],
    ),
    ("in a deformer key", &["t", "position", "rotation_degrees"]),
    (
        "in [budget]",
        &[
            "updates_per_frame",
            "pool_bytes",
            "active_distance",
            "precision_bits",
        ],
    ),
    ("in [camera]", &["target", "fov_y_degrees", "keys"]),
    ("in a camera key", &["t", "eye"]),
];
