//! The frame graph: the renderer's passes in order, each naming the resources it reads and writes.
//! The renderer's `encode` walks this table and records entry `i` `i`-th, dispatching it to its
//! pass's module (labels and timestamp slots come from the table), and a test checks that every
//! resource a pass reads was written by an earlier pass or comes from outside the frame.

/// A resource passes read or write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Resource {
    /// The world's heightmap pool (from [`crate::SnowWorld`]; outside the frame).
    HeightmapPool,
    /// Meshes and their instances this frame (uploaded by the CPU; outside the frame).
    Instances,
    /// Camera, moon, sky, lights, options (uploaded by the CPU; outside the frame).
    FrameUniforms,
    /// Surfaces this frame with their transforms (uploaded by the CPU; outside the frame).
    SurfaceTable,
    /// The world's kicked-up snow: its spray ring (from [`crate::SnowWorld`]; outside the frame).
    SprayParticles,
    /// Per surface: material flag, indirect draw and dispatch arguments.
    SurfaceState,
    /// Per deformed surface: the filtered texture of (depression, normal, occlusion).
    Heightfields,
    /// Per deformed surface: bank heights (tessellated tier).
    Banks,
    /// Diced vertices, indices and indirect draws of the snow surfaces (tessellated tier).
    DicedMesh,
    /// The moon's shadow map.
    ShadowMap,
    /// Per shadow cascade, its still casters' depth (`RenderConfig::shadow_cache`): written by
    /// the shadow pass, which reads it and the shadow map again in later frames while they hold.
    ShadowCache,
    /// The visibility buffer: per pixel of the scene, the opaque instance and triangle seen and
    /// the depth they wrote, or the relief-mapped snow's hit (`OpaquePath::Visibility`).
    Visibility,
    /// The scene's HDR colour (supersampled).
    SceneColor,
    /// The scene's depth (supersampled).
    SceneDepth,
    /// The output image (an offscreen texture or the caller's view).
    Output,
}

impl Resource {
    /// Whether the resource comes from outside the frame (nothing in the graph writes it).
    pub fn is_external(self) -> bool {
        matches!(
            self,
            Resource::HeightmapPool
                | Resource::Instances
                | Resource::FrameUniforms
                | Resource::SurfaceTable
                | Resource::SprayParticles
        )
    }
}

/// Compute or render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PassKind {
    /// A compute pass.
    Compute,
    /// A render pass.
    Render,
}

/// One pass of the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PassInfo {
    /// Name (label, timestamp and report key).
    pub name: &'static str,
    /// Compute or render.
    pub kind: PassKind,
    /// What it reads.
    pub reads: &'static [Resource],
    /// What it writes.
    pub writes: &'static [Resource],
}

use Resource as R;

/// Index of each pass in [`PASSES`].
pub mod pass {
    /// Choose each surface's material.
    pub const CLASSIFY: usize = 0;
    /// Heightmaps to filtered shading textures.
    pub const HEIGHTFIELD: usize = 1;
    /// Snow banks from the displaced channel (tessellated tier; empty otherwise).
    pub const BANKS: usize = 2;
    /// Dicing of the snow surfaces' meshes (tessellated tier; empty otherwise).
    pub const DICE: usize = 3;
    /// The moon's shadow map: meshes.
    pub const SHADOW: usize = 4;
    /// The moon's shadow map: the displaced snow (tessellated tier; empty otherwise).
    pub const SNOW_SHADOW: usize = 5;
    /// Opaque meshes: shaded (forward), or into the visibility buffer.
    pub const OPAQUE: usize = 6;
    /// Snow surfaces.
    pub const SNOW: usize = 7;
    /// The relief-mapped snow's hits in the visibility buffer shaded (empty on the forward path).
    pub const SNOW_SHADE: usize = 8;
    /// The visibility buffer shaded where the snow left it visible (empty on the forward path).
    pub const OPAQUE_SHADE: usize = 9;
    /// Sky.
    pub const SKY: usize = 10;
    /// Falling snow.
    pub const SNOWFALL: usize = 11;
    /// Kicked-up snow (the world's spray; empty without it).
    pub const SPRAY: usize = 12;
    /// Resolve and tonemap.
    pub const TONEMAP: usize = 13;
}

/// The passes of a frame, in the order they run. The tessellated tier's passes (`dice`,
/// `snow_shadow`) are encoded empty in the other tiers, `banks` too but for surfaces whose
/// material throws rims, `spray` for a world without spray, and `opaque_shade` on the forward
/// path, so every tier and path reports the same list.
pub const PASSES: [PassInfo; 14] = [
    PassInfo {
        name: "classify",
        kind: PassKind::Compute,
        reads: &[R::HeightmapPool, R::SurfaceTable],
        writes: &[R::SurfaceState],
    },
    PassInfo {
        name: "heightfield",
        kind: PassKind::Compute,
        reads: &[R::HeightmapPool, R::SurfaceTable, R::SurfaceState],
        writes: &[R::Heightfields],
    },
    PassInfo {
        name: "banks",
        kind: PassKind::Compute,
        reads: &[R::SurfaceTable, R::SurfaceState, R::Heightfields],
        writes: &[R::Banks],
    },
    PassInfo {
        name: "dice",
        kind: PassKind::Compute,
        reads: &[
            R::SurfaceTable,
            R::SurfaceState,
            R::Heightfields,
            R::Banks,
            R::FrameUniforms,
        ],
        writes: &[R::DicedMesh],
    },
    PassInfo {
        name: "shadow",
        kind: PassKind::Render,
        reads: &[R::Instances, R::FrameUniforms],
        writes: &[R::ShadowMap, R::ShadowCache],
    },
    PassInfo {
        name: "snow_shadow",
        kind: PassKind::Render,
        reads: &[
            R::SurfaceTable,
            R::SurfaceState,
            R::Heightfields,
            R::Banks,
            R::DicedMesh,
            R::FrameUniforms,
            R::ShadowMap,
        ],
        writes: &[R::ShadowMap],
    },
    PassInfo {
        name: "opaque",
        kind: PassKind::Render,
        reads: &[R::Instances, R::FrameUniforms, R::ShadowMap],
        // The forward path writes colour and depth; the visibility path depth and visibility.
        writes: &[R::SceneColor, R::SceneDepth, R::Visibility],
    },
    PassInfo {
        name: "snow",
        kind: PassKind::Render,
        reads: &[
            R::SurfaceTable,
            R::SurfaceState,
            R::Heightfields,
            R::Banks,
            R::DicedMesh,
            R::FrameUniforms,
            R::ShadowMap,
            R::SceneDepth,
        ],
        writes: &[R::SceneColor, R::SceneDepth, R::Visibility],
    },
    PassInfo {
        name: "snow_shade",
        kind: PassKind::Compute,
        reads: &[
            R::SurfaceTable,
            R::Heightfields,
            R::Banks,
            R::FrameUniforms,
            R::ShadowMap,
            R::Visibility,
            R::SceneDepth,
        ],
        writes: &[R::SceneColor],
    },
    PassInfo {
        name: "opaque_shade",
        kind: PassKind::Compute,
        reads: &[R::Instances, R::FrameUniforms, R::ShadowMap, R::Visibility],
        writes: &[R::SceneColor],
    },
    PassInfo {
        name: "sky",
        kind: PassKind::Render,
        reads: &[R::FrameUniforms, R::SceneDepth],
        writes: &[R::SceneColor],
    },
    PassInfo {
        name: "snowfall",
        kind: PassKind::Render,
        reads: &[R::FrameUniforms, R::SceneDepth],
        writes: &[R::SceneColor],
    },
    PassInfo {
        name: "spray",
        kind: PassKind::Render,
        reads: &[R::SprayParticles, R::FrameUniforms, R::SceneDepth],
        writes: &[R::SceneColor],
    },
    PassInfo {
        name: "tonemap",
        // A raster pass only for a caller's view that cannot be a storage texture.
        kind: PassKind::Compute,
        reads: &[R::FrameUniforms, R::SceneColor, R::SceneDepth],
        writes: &[R::Output],
    },
];

/// Check that every read is produced earlier or external, and that the output is written.
pub fn validate(passes: &[PassInfo]) -> Result<(), String> {
    let mut written: Vec<Resource> = Vec::new();
    for p in passes {
        for r in p.reads {
            if !r.is_external() && !written.contains(r) {
                return Err(format!(
                    "pass {} reads {r:?} before any pass writes it",
                    p.name
                ));
            }
        }
        for w in p.writes {
            if w.is_external() {
                return Err(format!(
                    "pass {} writes {w:?}, which comes from outside the frame",
                    p.name
                ));
            }
            written.push(*w);
        }
    }
    if !written.contains(&Resource::Output) {
        return Err("no pass writes the output".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_graph_is_ordered() {
        validate(&PASSES).unwrap();
        assert_eq!(PASSES[pass::CLASSIFY].name, "classify");
        assert_eq!(PASSES[pass::HEIGHTFIELD].name, "heightfield");
        assert_eq!(PASSES[pass::BANKS].name, "banks");
        assert_eq!(PASSES[pass::DICE].name, "dice");
        assert_eq!(PASSES[pass::SHADOW].name, "shadow");
        assert_eq!(PASSES[pass::SNOW_SHADOW].name, "snow_shadow");
        assert_eq!(PASSES[pass::OPAQUE].name, "opaque");
        assert_eq!(PASSES[pass::SNOW].name, "snow");
        assert_eq!(PASSES[pass::SNOW_SHADE].name, "snow_shade");
        assert_eq!(PASSES[pass::OPAQUE_SHADE].name, "opaque_shade");
        assert_eq!(PASSES[pass::SKY].name, "sky");
        assert_eq!(PASSES[pass::SNOWFALL].name, "snowfall");
        assert_eq!(PASSES[pass::SPRAY].name, "spray");
        assert_eq!(PASSES[pass::TONEMAP].name, "tonemap");
    }

    #[test]
    fn a_misordered_graph_is_refused() {
        let mut p = PASSES;
        p.swap(pass::SHADOW, pass::OPAQUE);
        assert!(validate(&p).unwrap_err().contains("opaque reads ShadowMap"));
        let mut p = PASSES;
        p.swap(pass::BANKS, pass::DICE);
        assert!(validate(&p).unwrap_err().contains("dice reads Banks"));
    }
}
