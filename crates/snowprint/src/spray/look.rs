//! How a material's kicked-up grains behave and look ([`crate::Material::spray`]): snow's spray,
//! powder's fine cloud, packed snow's few chunks, sand's low puff that hangs, mud's heavy spatter.
//! Applied by `place` (simulate.wgsl) to each spawn of a surface of the material, from the
//! surface's [`super::SprayRecord`]; the world's [`super::SprayConfig`] sets the base values that
//! the factors scale.

use crate::error::{Result, SnowError};

/// A material's spray (all factors scale the world's [`super::SprayConfig`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SprayLook {
    /// Fraction of the spawning texels that throw a grain, 0 to 1 (0: this material throws
    /// nothing). A spawn thinned out still takes its slot of the ring for the frame.
    pub amount: f32,
    /// Launch speed factor.
    pub speed: f32,
    /// Lifetime factor.
    pub lifetime: f32,
    /// Drag factor: above 1 a grain hangs in the air (a puff), below 1 it flies on (a clump).
    pub drag: f32,
    /// Radius of a grain as drawn, metres.
    pub radius: f32,
    /// Linear albedo of a grain.
    pub albedo: [f32; 3],
}

impl Default for SprayLook {
    fn default() -> Self {
        Self::snow()
    }
}

impl SprayLook {
    /// The talk's snow: the spray as it was before materials had their own.
    pub const fn snow() -> Self {
        Self {
            amount: 1.0,
            speed: 1.0,
            lifetime: 1.0,
            drag: 1.0,
            radius: 0.012,
            albedo: [0.9, 0.9, 0.9],
        }
    }

    /// Packed snow: few, larger chunks, thrown low.
    pub const fn packed_snow() -> Self {
        Self {
            amount: 0.35,
            speed: 0.8,
            lifetime: 0.9,
            drag: 0.8,
            radius: 0.016,
            albedo: [0.85, 0.86, 0.88],
        }
    }

    /// Fresh powder: a fine, bright cloud thrown higher that hangs longer.
    pub const fn powder() -> Self {
        Self {
            amount: 1.0,
            speed: 1.25,
            lifetime: 1.4,
            drag: 2.0,
            radius: 0.009,
            albedo: [0.95, 0.95, 0.97],
        }
    }

    /// Dry sand: a low puff of fine grains that hangs, then settles.
    pub const fn sand() -> Self {
        Self {
            amount: 0.6,
            speed: 0.6,
            lifetime: 1.6,
            drag: 3.0,
            radius: 0.007,
            albedo: [0.62, 0.52, 0.36],
        }
    }

    /// Wet mud: a few heavy clumps that arc and drop.
    pub const fn mud() -> Self {
        Self {
            amount: 0.3,
            speed: 0.8,
            lifetime: 0.7,
            drag: 0.3,
            radius: 0.016,
            albedo: [0.1, 0.07, 0.045],
        }
    }

    /// Check every field, naming the first that is wrong (for surface `name`).
    pub fn validate(&self, name: &str) -> Result<()> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::InvalidSurface {
                name: name.to_owned(),
                what,
                value,
                expected,
            })
        };
        if !(self.amount.is_finite() && (0.0..=1.0).contains(&self.amount)) {
            return bad(
                "material spray amount",
                self.amount.to_string(),
                "a fraction from 0 to 1",
            );
        }
        for (what, v) in [
            ("material spray speed", self.speed),
            ("material spray lifetime", self.lifetime),
            ("material spray drag", self.drag),
        ] {
            if !(v.is_finite() && (0.0..=100.0).contains(&v)) {
                return bad(what, v.to_string(), "a factor from 0 to 100");
            }
        }
        if !(self.radius.is_finite() && self.radius > 0.0 && self.radius <= 0.5) {
            return bad(
                "material spray radius",
                self.radius.to_string(),
                "metres above 0, at most 0.5",
            );
        }
        if !self
            .albedo
            .iter()
            .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
        {
            return bad(
                "material spray albedo",
                format!("{:?}", self.albedo),
                "three values from 0 to 1",
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::SprayLook;

    #[test]
    fn presets_pass_and_bad_values_are_named() {
        for look in [
            SprayLook::snow(),
            SprayLook::packed_snow(),
            SprayLook::powder(),
            SprayLook::sand(),
            SprayLook::mud(),
        ] {
            assert!(look.validate("yard").is_ok(), "{look:?}");
        }
        let ok = SprayLook::snow();
        for (bad, what) in [
            (SprayLook { amount: 1.5, ..ok }, "amount"),
            (
                SprayLook {
                    drag: f32::NAN,
                    ..ok
                },
                "drag",
            ),
            (SprayLook { radius: 0.0, ..ok }, "radius"),
            (
                SprayLook {
                    albedo: [0.5, 2.0, 0.5],
                    ..ok
                },
                "albedo",
            ),
        ] {
            let e = bad.validate("yard").expect_err(what).to_string();
            assert!(e.contains(what) && e.contains("yard"), "{e}");
        }
    }
}
