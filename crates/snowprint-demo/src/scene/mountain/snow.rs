//! The mountain's snow: the valley as a grid of surfaces, each laid on the ground under it, and the
//! cabin's roof laid on its two planes.

use glam::Vec2;
use snowprint::{Ground, GroundMaterial, SlopeRule, SnowWorld, SurfaceDesc, SurfaceId};

use super::SNOW_DEPTH;
use super::terrain::{self, CABIN};

/// Half the side of the snowy square around the valley's centre, metres.
pub const HALF: f32 = 48.0;
/// Surfaces along each side of it: 12 m each, 300 texels of 4 cm.
const TILES: u32 = 8;
/// The roof's snow, metres.
const ROOF_DEPTH: f32 = 0.25;

/// The snow's top at `(x, z)` where people walk: the ground plus the whole depth (the paths keep
/// to slopes gentle enough to hold all of it).
pub fn top(p: Vec2) -> f32 {
    terrain::height(p) + SNOW_DEPTH
}

/// Every surface of the valley into `world`, on its ground; the roof on its mesh.
pub fn lay(world: &mut SnowWorld) -> Result<Vec<(SurfaceId, GroundMaterial)>, String> {
    let side = 2.0 * HALF / TILES as f32;
    let mut out = Vec::new();
    for r in 0..TILES {
        for c in 0..TILES {
            let centre = Vec2::new(
                -HALF + (c as f32 + 0.5) * side,
                -HALF + (r as f32 + 0.5) * side,
            );
            let mut desc = SurfaceDesc::new(
                &format!("valley_{c}_{r}"),
                [centre.x, terrain::height(centre), centre.y],
                [side, side],
                SNOW_DEPTH,
            );
            desc.replenish_rate = 0.0;
            let ground = Ground::Grid(terrain::grid_under(&desc));
            let id = world.add_surface(desc).map_err(|e| e.to_string())?;
            world
                .set_ground(id, &ground, SlopeRule::default())
                .map_err(|e| e.to_string())?;
            out.push((id, GroundMaterial::Concrete));
        }
    }
    let (roof, ridge) = terrain::roof_triangles();
    let (c, half, _, _) = CABIN;
    let mut desc = SurfaceDesc::new(
        "cabin_roof",
        [c.x, ridge - 1.0, c.y],
        [2.0 * (half.x + 0.4), 2.0 * (half.y + 0.4)],
        ROOF_DEPTH,
    );
    desc.replenish_rate = 0.0;
    let id = world.add_surface(desc).map_err(|e| e.to_string())?;
    world
        .set_ground(id, &Ground::Mesh(roof), SlopeRule::default())
        .map_err(|e| e.to_string())?;
    out.push((id, GroundMaterial::RoofTiles));
    Ok(out)
}
