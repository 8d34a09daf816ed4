//! The mountain's snow: the valley as a terrain-wide layer whose windows follow the hiker (a near
//! level of 1024^2 texels of 5 cm and a far one of 512^2 of 40 cm, [`snowprint::Terrain`]) on the
//! valley's ground, and the cabin's roof laid on its two planes.

use glam::{Vec2, Vec3};
use snowprint::{
    Ground, GroundMaterial, HeightGrid, LevelDesc, Material, SlopeRule, SnowWorld, SurfaceDesc,
    SurfaceId, Terrain, TerrainDesc, TerrainGround,
};

use super::SNOW_DEPTH;
use super::terrain::{self, CABIN};

/// Half the side of the ground grid the terrain is laid on, metres (past the far level's reach).
const GROUND_HALF: f32 = 140.0;
/// Metres between the ground grid's samples.
const GROUND_STEP: f32 = 0.5;
/// The roof's snow, metres.
const ROOF_DEPTH: f32 = 0.25;

/// The snow's top at `(x, z)` where people walk: the ground plus the whole depth (the paths keep
/// to slopes gentle enough to hold all of it).
pub fn top(p: Vec2) -> f32 {
    terrain::height(p) + SNOW_DEPTH
}

/// The valley's snow: its levels, near then far.
pub fn valley() -> TerrainDesc {
    let n = (2.0 * GROUND_HALF / GROUND_STEP) as u32;
    let heights = (0..n)
        .flat_map(|r| (0..n).map(move |c| (c, r)))
        .map(|(c, r)| {
            let p = Vec2::new(c as f32 + 0.5, r as f32 + 0.5) * GROUND_STEP - GROUND_HALF;
            terrain::height(p)
        })
        .collect();
    TerrainDesc {
        name: "valley".into(),
        ground_height: 0.0,
        ground: Some(TerrainGround {
            grid: HeightGrid {
                columns: n,
                rows: n,
                heights,
            },
            origin: [-GROUND_HALF, -GROUND_HALF],
            size: [2.0 * GROUND_HALF, 2.0 * GROUND_HALF],
            slope: SlopeRule::default(),
        }),
        snow_depth: SNOW_DEPTH,
        replenish_rate: 0.0,
        material: Material::snow(),
        levels: vec![
            LevelDesc {
                texels: [1024, 1024],
                texel_size: 0.05,
            },
            LevelDesc {
                texels: [512, 512],
                texel_size: 0.4,
            },
        ],
    }
}

/// The valley's terrain into `world` around `focus`, and the roof; the surfaces to draw.
pub fn lay(
    world: &mut SnowWorld,
    focus: Vec3,
) -> Result<(Terrain, Vec<(SurfaceId, GroundMaterial)>), String> {
    let valley = Terrain::new(world, valley(), focus).map_err(|e| e.to_string())?;
    let mut out: Vec<(SurfaceId, GroundMaterial)> = valley
        .surfaces()
        .into_iter()
        .map(|id| (id, GroundMaterial::Rock))
        .collect();
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
    Ok((valley, out))
}
