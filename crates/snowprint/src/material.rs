//! What a surface is made of, as data: how it moves after it is pressed.
//!
//! The talk's snow keeps every print as pressed: that is [`Material::snow`], the default, and a
//! surface of it updates bit for bit as before materials existed. A material with an angle of
//! repose slumps: after each update that presses it (and for [`Material::settle_updates`] updates
//! after the last), the relaxation pass (`relax/`) lets material flow from each texel to its lower
//! neighbours until no step between neighbours is steeper than the repose angle, keeping the
//! volume pressed out exactly. Dry sand slumps strongly, fresh powder a little; packed snow and
//! mud keep their walls.
//!
//! What is pressed out either compacts under the foot or is pushed aside: [`Material::compressibility`]
//! says how much of it compacts. The rest rises in rims beside the print, drawn from the
//! heightmap's displaced channel by the renderer's banks (`render/tessellate/banks/`), so the rims
//! hold `1 - compressibility` of the volume pressed out. Sand barely compacts and throws most of it
//! aside; powder about half.

use crate::error::{Result, SnowError};
pub use crate::spray::SprayLook;

/// How a surface's material moves after it is pressed, and how it looks.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// How it looks: albedos, roughness, grain, sparkle, wetness and water (the renderer's
    /// `snow.wgsl` reads them per surface). Absent from older saves: the talk's snow.
    #[serde(default)]
    pub look: MaterialLook,
    /// Steepest slope the material stands at, degrees above the horizontal (0 to 90); `None`:
    /// walls stand whatever their slope (the talk's snow, packed snow, mud).
    pub repose_degrees: Option<f32>,
    /// Relaxation steps a slumping material takes in each update (rounded up to even). Each moves
    /// an eighth of a step's excess over the repose slope, so more steps slump faster.
    pub relax_steps: u32,
    /// Updates it keeps slumping after the last one that pressed it (a world's `step` lists every
    /// surface, so this is frames; under a manager, the surface's own updates).
    pub settle_updates: u32,
    /// Its kicked-up grains, when the world has spray ([`crate::WorldConfig::spray`]). Absent from
    /// older saves: the talk's snow.
    #[serde(default)]
    pub spray: SprayLook,
    /// Share of a print's volume that compacts (0 to 1); the rest, `1 - compressibility` of the
    /// volume pressed out, is pushed aside into rims beside the print. `None`: the renderer's
    /// `BankSettings::fraction` decides (the talk's snow: a quarter into banks by default). Absent
    /// from older saves: `None`.
    #[serde(default)]
    pub compressibility: Option<f32>,
}

impl Default for Material {
    fn default() -> Self {
        Self::snow()
    }
}

impl Material {
    /// The talk's snow: prints keep their walls (no relaxation).
    pub const fn snow() -> Self {
        Self {
            look: MaterialLook::snow(),
            repose_degrees: None,
            relax_steps: 0,
            settle_updates: 0,
            spray: SprayLook::snow(),
            compressibility: None,
        }
    }

    /// Packed snow: crisp edges, no slumping; the look of the talk's snow; its spray is a few
    /// chunks.
    pub const fn packed_snow() -> Self {
        Self {
            spray: SprayLook::packed_snow(),
            ..Self::snow()
        }
    }

    /// Fresh powder: walls steeper than 60 degrees crumble, slowly; it sparkles; half of what a
    /// print presses out compacts, half is pushed aside into loose rims.
    pub const fn powder() -> Self {
        Self {
            look: MaterialLook::powder(),
            repose_degrees: Some(60.0),
            relax_steps: 2,
            settle_updates: 30,
            spray: SprayLook::powder(),
            compressibility: Some(0.5),
        }
    }

    /// Dry sand: slumps back into a print until its walls stand at 34 degrees; it hardly
    /// compacts, so four fifths of what a print presses out rise in rims beside it.
    pub const fn sand() -> Self {
        Self {
            look: MaterialLook::sand(),
            repose_degrees: Some(34.0),
            relax_steps: 8,
            settle_updates: 120,
            spray: SprayLook::sand(),
            compressibility: Some(0.2),
        }
    }

    /// Wet mud: keeps a sharp print; water gathers in the deep ones.
    pub const fn mud() -> Self {
        Self {
            look: MaterialLook::mud(),
            spray: SprayLook::mud(),
            ..Self::snow()
        }
    }

    /// The preset named `name` (`snow`, `packed_snow`, `powder`, `sand`, `mud`).
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "snow" => Self::snow(),
            "packed_snow" => Self::packed_snow(),
            "powder" => Self::powder(),
            "sand" => Self::sand(),
            "mud" => Self::mud(),
            _ => return None,
        })
    }

    /// Whether the material slumps (runs the relaxation pass).
    pub fn slumps(&self) -> bool {
        self.repose_degrees.is_some() && self.relax_steps > 0
    }

    /// Share of the volume pressed out that rises in rims, when the material says
    /// (`1 - compressibility`); `None`: the renderer's bank settings decide.
    pub fn rim_fraction(&self) -> Option<f32> {
        self.compressibility.map(|c| 1.0 - c)
    }

    /// Relaxation steps an update takes: even, so that the last writes the pool.
    pub fn steps(&self) -> u32 {
        if self.slumps() {
            self.relax_steps.div_ceil(2) * 2
        } else {
            0
        }
    }

    /// Check every field, naming the first that is wrong (for surface `name`).
    pub fn validate(&self, name: &str) -> Result<()> {
        if let Some(a) = self.repose_degrees
            && !(a.is_finite() && (0.0..=90.0).contains(&a))
        {
            return Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what: "material repose_degrees",
                value: a.to_string(),
                expected: "degrees from 0 to 90",
            });
        }
        if let Some(c) = self.compressibility
            && !(c.is_finite() && (0.0..=1.0).contains(&c))
        {
            return Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what: "material compressibility",
                value: c.to_string(),
                expected: "a share of the pressed volume from 0 to 1",
            });
        }
        self.look.validate(name)?;
        self.spray.validate(name)?;
        if self.relax_steps > 64 {
            return Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what: "material relax_steps",
                value: self.relax_steps.to_string(),
                expected: "at most 64 steps an update",
            });
        }
        Ok(())
    }
}

/// How a surface's material looks: what `snow.wgsl` blends by the depression at each point.
/// "Undisturbed" is the untouched top; "disturbed" the material at the bottom of a print (blended
/// in from 5 % to 80 % of the depth pressed). The defaults are the talk's snow, drawn bit for bit as
/// before materials existed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MaterialLook {
    /// Diffuse albedo of the untouched material (linear RGB, 0 to 1).
    pub albedo: [f32; 3],
    /// Diffuse albedo of the disturbed material at the bottom of prints.
    pub disturbed_albedo: [f32; 3],
    /// Perceptual roughness of the untouched (dry) material.
    pub roughness: f32,
    /// Perceptual roughness where pressed (wet, or compacted): blended in by the depression.
    pub wet_roughness: f32,
    /// Fine grain, 0 to 1: a per-grain speckle of the albedo and a fine normal, fixed in the world
    /// (0 for snow, whose grain is the talk's detail normal).
    pub grain: f32,
    /// Glints of single crystals towards the moon, 0 to 1: view dependent, fixed per grain in the
    /// world so that they do not shimmer from frame to frame.
    pub sparkle: f32,
    /// How wet the pressed material gets, 0 to 1: darker and more specular at the bottom of prints.
    pub wetness: f32,
    /// How much light passes through it, 0 to 1: the talk's fake subsurface scattering (the sky
    /// tint of prints' walls) and the diffuse wrap. 1 for snow, 0 for sand and mud.
    pub translucency: f32,
    /// Depth below the untouched top, metres, of the water table: prints deeper than this fill
    /// with a flat water surface up to it (mud); `None`: no water.
    pub water_depth: Option<f32>,
    /// Depression (fraction of the depth pressed, 0 to 1) from which the ground under the
    /// material shows, fully once pressed through; `None`: the renderer's `SnowLook` decides
    /// (snow, which packs into a thin layer: from two thirds). Sand and mud show the material
    /// itself at the bottom of a print until it is pressed almost to the ground.
    pub ground_from: Option<f32>,
}

impl Default for MaterialLook {
    fn default() -> Self {
        Self::snow()
    }
}

impl MaterialLook {
    /// The talk's snow: bright, faintly blue, greyer and smoother where packed; no sparkle.
    pub const fn snow() -> Self {
        Self {
            albedo: [0.86, 0.89, 0.93],
            disturbed_albedo: [0.66, 0.71, 0.78],
            roughness: 0.62,
            wet_roughness: 0.5,
            grain: 0.0,
            sparkle: 0.0,
            wetness: 0.0,
            translucency: 1.0,
            water_depth: None,
            ground_from: None,
        }
    }

    /// Fresh powder: the snow's look, brighter where untouched, with glints.
    pub const fn powder() -> Self {
        Self {
            albedo: [0.88, 0.91, 0.95],
            sparkle: 0.8,
            ..Self::snow()
        }
    }

    /// Dry sand: warm (saturated enough to stay sand under the bluish moon), fine grained, with a
    /// slightly lighter, drier (rougher) layer kicked up in prints; the ground shows only where a
    /// print is pressed almost through.
    pub const fn sand() -> Self {
        Self {
            albedo: [0.52, 0.36, 0.17],
            disturbed_albedo: [0.56, 0.39, 0.19],
            roughness: 0.88,
            wet_roughness: 0.95,
            grain: 0.8,
            sparkle: 0.0,
            wetness: 0.0,
            translucency: 0.0,
            water_depth: None,
            ground_from: Some(0.92),
        }
    }

    /// Wet mud: dark brown, darker and glossy where pressed, water in prints deeper than 6 cm;
    /// the ground shows only where a print is pressed almost through.
    pub const fn mud() -> Self {
        Self {
            albedo: [0.11, 0.08, 0.055],
            disturbed_albedo: [0.075, 0.05, 0.035],
            roughness: 0.7,
            wet_roughness: 0.22,
            grain: 0.3,
            sparkle: 0.0,
            wetness: 0.9,
            translucency: 0.0,
            water_depth: Some(0.06),
            ground_from: Some(0.92),
        }
    }

    /// Check every field, naming the first that is wrong (for surface `name`).
    pub fn validate(&self, name: &str) -> Result<()> {
        let unit = |what: &'static str, v: f32| {
            if v.is_finite() && (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(SnowError::InvalidSurface {
                    name: name.to_owned(),
                    what,
                    value: v.to_string(),
                    expected: "a number from 0 to 1",
                })
            }
        };
        for (what, c) in [
            ("material albedo", self.albedo),
            ("material disturbed_albedo", self.disturbed_albedo),
        ] {
            for v in c {
                unit(what, v)?;
            }
        }
        unit("material roughness", self.roughness)?;
        unit("material wet_roughness", self.wet_roughness)?;
        unit("material grain", self.grain)?;
        unit("material sparkle", self.sparkle)?;
        unit("material wetness", self.wetness)?;
        unit("material translucency", self.translucency)?;
        if let Some(g) = self.ground_from
            && !(g.is_finite() && g > 0.0 && g < 1.0)
        {
            return Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what: "material ground_from",
                value: g.to_string(),
                expected: "a fraction of the depth above 0 and below 1",
            });
        }
        if let Some(d) = self.water_depth
            && !(d.is_finite() && d > 0.0)
        {
            return Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what: "material water_depth",
                value: d.to_string(),
                expected: "metres above 0",
            });
        }
        Ok(())
    }
}
