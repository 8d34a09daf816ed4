//! What a surface is made of, as data: how it moves after it is pressed.
//!
//! The talk's snow keeps every print as pressed: that is [`Material::snow`], the default, and a
//! surface of it updates bit for bit as before materials existed. A material with an angle of
//! repose slumps: after each update that presses it (and for [`Material::settle_updates`] updates
//! after the last), the relaxation pass (`relax/`) lets material flow from each texel to its lower
//! neighbours until no step between neighbours is steeper than the repose angle, keeping the
//! volume pressed out exactly. Dry sand slumps strongly, fresh powder a little; packed snow and
//! mud keep their walls.

use crate::error::{Result, SnowError};

/// How a surface's material moves after it is pressed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Steepest slope the material stands at, degrees above the horizontal (0 to 90); `None`:
    /// walls stand whatever their slope (the talk's snow, packed snow, mud).
    pub repose_degrees: Option<f32>,
    /// Relaxation steps a slumping material takes in each update (rounded up to even). Each moves
    /// an eighth of a step's excess over the repose slope, so more steps slump faster.
    pub relax_steps: u32,
    /// Updates it keeps slumping after the last one that pressed it (a world's `step` lists every
    /// surface, so this is frames; under a manager, the surface's own updates).
    pub settle_updates: u32,
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
            repose_degrees: None,
            relax_steps: 0,
            settle_updates: 0,
        }
    }

    /// Packed snow: crisp edges, no slumping.
    pub const fn packed_snow() -> Self {
        Self::snow()
    }

    /// Fresh powder: walls steeper than 60 degrees crumble, slowly.
    pub const fn powder() -> Self {
        Self {
            repose_degrees: Some(60.0),
            relax_steps: 2,
            settle_updates: 30,
        }
    }

    /// Dry sand: slumps back into a print until its walls stand at 34 degrees.
    pub const fn sand() -> Self {
        Self {
            repose_degrees: Some(34.0),
            relax_steps: 8,
            settle_updates: 120,
        }
    }

    /// Wet mud: keeps a sharp print.
    pub const fn mud() -> Self {
        Self::snow()
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
