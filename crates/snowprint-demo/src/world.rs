//! The city block: a street between two rows of buildings whose flat roofs hold the snow, with
//! parapets, a roof door, chimneys and two water towers.

use glam::{Mat4, Vec2, Vec3};

use super::{DemoSurface, Prop};
use snowprint::GroundMaterial;
use snowprint::Mesh;
use snowprint::SurfaceDesc;

/// Height of a parapet above its roof's ground, metres.
pub const PARAPET_HEIGHT: f32 = 0.6;
/// Thickness of a parapet, metres.
pub const PARAPET_THICKNESS: f32 = 0.3;

/// Index of each surface in [`super::DemoWorld::surfaces`].
pub mod surface {
    /// The street: nobody walks on it.
    pub const STREET: usize = 0;
    /// The walker's roof (10 m).
    pub const WALK_ROOF: usize = 1;
    /// The highest roof (14 m), with a water tower; the faller stands on its parapet.
    pub const HIGH_ROOF: usize = 2;
    /// The roof below the high one (10.5 m): the faller lands on it, the snow angel lies on it.
    pub const LOW_ROOF: usize = 3;
    /// The runner's roof (12 m).
    pub const RUN_ROOF: usize = 4;
    /// The slide and the fight (9 m).
    pub const YARD_ROOF: usize = 5;
    /// A roof with the second water tower (11 m): nobody goes there.
    pub const TOWER_ROOF: usize = 6;
}

/// One roof or street: its snow surface, and which sides get a parapet (`-x, +x, -z, +z`).
struct Block {
    name: &'static str,
    center: Vec3,
    size: Vec2,
    snow: f32,
    ground: GroundMaterial,
    parapets: [bool; 4],
    wall: [f32; 3],
}

const BLOCKS: [Block; 7] = [
    Block {
        name: "street",
        center: Vec3::new(-2.0, 0.0, 0.0),
        size: Vec2::new(44.0, 9.0),
        snow: 0.25,
        ground: GroundMaterial::Concrete,
        parapets: [false; 4],
        wall: [0.0; 3],
    },
    Block {
        name: "walk_roof",
        center: Vec3::new(-13.0, 10.0, -11.0),
        size: Vec2::new(10.0, 4.0),
        snow: 0.25,
        ground: GroundMaterial::RoofTiles,
        parapets: [true; 4],
        wall: [0.42, 0.22, 0.16],
    },
    Block {
        name: "high_roof",
        center: Vec3::new(-3.0, 14.0, -11.0),
        size: Vec2::new(6.0, 6.0),
        snow: 0.3,
        ground: GroundMaterial::Concrete,
        parapets: [true; 4],
        wall: [0.30, 0.30, 0.33],
    },
    Block {
        name: "low_roof",
        center: Vec3::new(6.3, 10.5, -11.0),
        size: Vec2::new(12.0, 6.0),
        snow: 0.3,
        ground: GroundMaterial::RoofTiles,
        // The high building's wall stands along -x.
        parapets: [false, true, true, true],
        wall: [0.36, 0.25, 0.20],
    },
    Block {
        name: "run_roof",
        center: Vec3::new(-12.0, 12.0, 10.0),
        size: Vec2::new(12.0, 4.0),
        snow: 0.25,
        ground: GroundMaterial::Concrete,
        parapets: [true; 4],
        wall: [0.45, 0.40, 0.33],
    },
    Block {
        name: "yard_roof",
        center: Vec3::new(5.0, 9.0, 11.0),
        size: Vec2::new(12.0, 7.0),
        snow: 0.3,
        ground: GroundMaterial::RoofTiles,
        parapets: [true; 4],
        wall: [0.40, 0.20, 0.15],
    },
    Block {
        name: "tower_roof",
        center: Vec3::new(16.5, 11.0, 11.0),
        size: Vec2::new(6.0, 7.0),
        snow: 0.3,
        ground: GroundMaterial::Concrete,
        parapets: [true; 4],
        wall: [0.33, 0.31, 0.29],
    },
];

/// The snow surfaces, in [`surface`] order.
pub fn surfaces() -> Vec<DemoSurface> {
    BLOCKS
        .iter()
        .map(|b| DemoSurface {
            desc: SurfaceDesc::new(b.name, b.center.to_array(), b.size.to_array(), b.snow),
            ground: b.ground,
        })
        .collect()
}

/// World height of the top of a surface's parapets.
pub fn parapet_top(surface: usize) -> f32 {
    BLOCKS[surface].center.y + PARAPET_HEIGHT
}

fn cuboid_prop(min: Vec3, max: Vec3, albedo: [f32; 3]) -> Prop {
    Prop {
        mesh: Mesh::cuboid(0.5 * (max - min)),
        transform: Mat4::from_translation(0.5 * (min + max)),
        albedo,
    }
}

/// A closed cylinder along `Y` from `y = 0` to `height`, `segments` sides.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    cone_frustum(radius, radius, height, segments)
}

/// A closed truncated cone along `Y` from radius `r0` at `y = 0` to `r1` at `height` (`r1` may be
/// 0: a cone).
pub fn cone_frustum(r0: f32, r1: f32, height: f32, segments: u32) -> Mesh {
    let n = segments.max(3);
    let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, height, 0.0)];
    for (y, r) in [(0.0, r0), (height, r1)] {
        for s in 0..n {
            let a = std::f32::consts::TAU * s as f32 / n as f32;
            positions.push(Vec3::new(r * a.cos(), y, r * a.sin()));
        }
    }
    let bottom = |s: u32| 2 + s % n;
    let top = |s: u32| 2 + n + s % n;
    let mut indices = Vec::new();
    for s in 0..n {
        // Seen from outside, counter-clockwise: +Y x +X points to -Z, so increasing angle (towards
        // +Z from +X) turns clockwise seen from above.
        indices.extend_from_slice(&[1, top(s + 1), top(s)]);
        indices.extend_from_slice(&[0, bottom(s), bottom(s + 1)]);
        indices.extend_from_slice(&[bottom(s), top(s), top(s + 1)]);
        indices.extend_from_slice(&[bottom(s), top(s + 1), bottom(s + 1)]);
    }
    Mesh { positions, indices }
}

/// A water tower standing on the ground at `base`: a wooden tank with a conical roof on four
/// steel legs.
pub fn water_tower(base: Vec3) -> Vec<Prop> {
    let steel = [0.12, 0.12, 0.13];
    let wood = [0.38, 0.25, 0.14];
    let roof = [0.22, 0.22, 0.24];
    let legs = 2.6;
    let radius = 1.2;
    let tank = 2.4;
    let mut out = Vec::new();
    for (dx, dz) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        let c = base + Vec3::new(dx * 0.8, 0.0, dz * 0.8);
        out.push(cuboid_prop(
            c + Vec3::new(-0.07, 0.0, -0.07),
            c + Vec3::new(0.07, legs, 0.07),
            steel,
        ));
    }
    // Cross beams under the tank.
    for b in [Vec2::new(0.9, 0.06), Vec2::new(0.06, 0.9)] {
        out.push(cuboid_prop(
            base + Vec3::new(-b.x, legs - 0.15, -b.y),
            base + Vec3::new(b.x, legs, b.y),
            steel,
        ));
    }
    out.push(Prop {
        mesh: cylinder(radius, tank, 24),
        transform: Mat4::from_translation(base + Vec3::Y * legs),
        albedo: wood,
    });
    out.push(Prop {
        mesh: cone_frustum(radius + 0.1, 0.0, 0.9, 24),
        transform: Mat4::from_translation(base + Vec3::Y * (legs + tank)),
        albedo: roof,
    });
    out
}

/// Buildings, parapets, and rooftop clutter.
pub fn props() -> Vec<Prop> {
    let mut out = Vec::new();
    let t = PARAPET_THICKNESS;
    for b in BLOCKS.iter().skip(1) {
        let half = b.size * 0.5;
        let lo = Vec3::new(b.center.x - half.x, 0.0, b.center.z - half.y);
        let hi = Vec3::new(b.center.x + half.x, b.center.y, b.center.z + half.y);
        // The building stops just under the snow's ground so that the snow slab covers its top.
        out.push(cuboid_prop(
            lo - Vec3::new(t, 0.0, t),
            hi + Vec3::new(t, -0.05, t),
            b.wall,
        ));
        let stone = [0.52, 0.50, 0.47];
        let y0 = b.center.y - 0.05;
        let y1 = b.center.y + PARAPET_HEIGHT;
        let [nx, px, nz, pz] = b.parapets;
        if nx {
            out.push(cuboid_prop(
                Vec3::new(lo.x - t, y0, lo.z - t),
                Vec3::new(lo.x, y1, hi.z + t),
                stone,
            ));
        }
        if px {
            out.push(cuboid_prop(
                Vec3::new(hi.x, y0, lo.z - t),
                Vec3::new(hi.x + t, y1, hi.z + t),
                stone,
            ));
        }
        if nz {
            out.push(cuboid_prop(
                Vec3::new(lo.x, y0, lo.z - t),
                Vec3::new(hi.x, y1, lo.z),
                stone,
            ));
        }
        if pz {
            out.push(cuboid_prop(
                Vec3::new(lo.x, y0, hi.z),
                Vec3::new(hi.x, y1, hi.z + t),
                stone,
            ));
        }
    }
    let walk = &BLOCKS[surface::WALK_ROOF];
    // The door the walker comes out of.
    out.push(cuboid_prop(
        Vec3::new(-18.0, walk.center.y, -12.2),
        Vec3::new(-17.0, walk.center.y + 2.3, -9.8),
        [0.30, 0.28, 0.27],
    ));
    out.push(cuboid_prop(
        Vec3::new(-17.02, walk.center.y, -11.45),
        Vec3::new(-16.98, walk.center.y + 2.0, -10.55),
        [0.25, 0.12, 0.08],
    ));
    // Chimneys on the low roof, away from the angel.
    for (x, z) in [(11.6, -8.7), (11.6, -13.3)] {
        out.push(cuboid_prop(
            Vec3::new(x - 0.35, 10.5, z - 0.35),
            Vec3::new(x + 0.35, 11.9, z + 0.35),
            [0.45, 0.2, 0.14],
        ));
    }
    out.extend(water_tower(
        BLOCKS[surface::HIGH_ROOF].center + Vec3::new(-0.8, 0.0, 0.0),
    ));
    out.extend(water_tower(BLOCKS[surface::TOWER_ROOF].center));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3Swizzles;

    #[test]
    fn cylinder_and_cone_are_closed_and_outward() {
        let c = cylinder(1.0, 2.0, 64);
        let exact = std::f32::consts::PI * 2.0;
        let v = c.signed_volume();
        assert!(v > 0.98 * exact && v <= exact, "{v}");
        let k = cone_frustum(1.0, 0.0, 3.0, 64);
        let v = k.signed_volume();
        assert!(
            v > 0.98 * std::f32::consts::PI && v <= std::f32::consts::PI,
            "{v}"
        );
    }

    #[test]
    fn roofs_do_not_overlap() {
        let s = surfaces();
        for (i, a) in s.iter().enumerate() {
            for b in &s[i + 1..] {
                let (a0, a1) = (
                    a.desc.center.xz() - a.desc.size / 2.0,
                    a.desc.center.xz() + a.desc.size / 2.0,
                );
                let (b0, b1) = (
                    b.desc.center.xz() - b.desc.size / 2.0,
                    b.desc.center.xz() + b.desc.size / 2.0,
                );
                let apart = a1.x <= b0.x || b1.x <= a0.x || a1.y <= b0.y || b1.y <= a0.y;
                assert!(apart, "{} and {}", a.desc.name, b.desc.name);
            }
        }
    }
}
