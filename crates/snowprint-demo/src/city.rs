//! A generated city of snow surfaces for the manager's demo and benchmark: rooftops at varied
//! heights (some stacked over others), streets cut into short segments, streaming zones of 4 x 4
//! blocks, and walkers whose two feet leave rows of footprints. Everything is a pure function of
//! the seed.
//!
//! Layout: blocks on a square grid with a pitch of [`BLOCK_PITCH`] metres. A block owns the street
//! band along its west side and the one along its north side (each cut into four 6 m x 6 m
//! segments) and the intersection at its north-west corner, then up to four rooftops on its lots,
//! one of which may carry a smaller roof above it. Blocks are generated row by row until the number
//! of surfaces asked for is reached.

use glam::{Vec2, Vec3};

use snowprint::SurfaceDesc;
use snowprint::manager::{ManagedDeformer, ZoneId};
use snowprint::{Camera, GroundMaterial};
use snowprint::{Deformer, Pose, Shape};

/// Metres from one block to the next.
pub const BLOCK_PITCH: f32 = 30.0;
/// Width of a street band, metres.
pub const STREET_WIDTH: f32 = 6.0;
/// Blocks per side of a streaming zone.
pub const ZONE_BLOCKS: u32 = 4;

/// A tiny deterministic generator (xorshift64*), so the city needs no dependency.
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from a seed (any value, 0 included).
    pub fn new(seed: u64) -> Self {
        Self(seed ^ 0x9E37_79B9_7F4A_7C15 | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A number in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A number in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// An index below `n` (`n` > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
}

/// What a surface of the city is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceKind {
    /// A rooftop.
    Roof,
    /// A street segment or an intersection.
    Street,
}

/// One surface of the city.
#[derive(Clone, Debug, PartialEq)]
pub struct CitySurface {
    /// The surface.
    pub desc: SurfaceDesc,
    /// Its streaming zone.
    pub zone: ZoneId,
    /// Roof or street.
    pub kind: SurfaceKind,
    /// What shows where the snow is pressed to the ground.
    pub material: GroundMaterial,
}

/// A walker: two spherical feet stepping along a path on the snow. See [`WalkerPath::feet`].
#[derive(Clone, Debug, PartialEq)]
pub struct WalkerPath {
    /// Name (for reports).
    pub name: String,
    /// Path on the snow top, world metres; the walker loops when `closed`, else walks back and forth.
    pub points: Vec<Vec3>,
    /// Whether the path is a loop.
    pub closed: bool,
    /// Walking speed, metres per second.
    pub speed: f32,
    /// Distance between two successive prints of the same foot, metres.
    pub step: f32,
    /// Distance between the left and the right foot's prints, metres.
    pub stance_width: f32,
    /// Radius of a foot, metres.
    pub foot_radius: f32,
    /// How far below the snow top a planted foot's lowest point goes, metres.
    pub press_depth: f32,
    /// Height of a swinging foot's lowest point above the snow top, metres (above the capture
    /// frustum, so a swing leaves nothing).
    pub lift: f32,
    /// Metres along the path at time 0.
    pub start: f32,
    /// Whether this walker is the player.
    pub player: bool,
}

impl WalkerPath {
    /// A walker with the gait of the demo (1.3 m/s, prints 0.8 m apart per foot, 11 cm feet
    /// pressing 6 cm into the snow).
    pub fn new(name: &str, points: Vec<Vec3>, closed: bool) -> Self {
        Self {
            name: name.to_owned(),
            points,
            closed,
            speed: 1.3,
            step: 0.8,
            stance_width: 0.26,
            foot_radius: 0.11,
            press_depth: 0.06,
            lift: 0.5,
            start: 0.0,
            player: false,
        }
    }

    /// Length of the path, metres (a loop includes its closing segment).
    pub fn length(&self) -> f32 {
        self.segments().map(|(a, b)| a.distance(b)).sum()
    }

    fn segments(&self) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
        let n = self.points.len();
        let count = if self.closed { n } else { n.saturating_sub(1) };
        (0..count).map(move |i| (self.points[i], self.points[(i + 1) % n]))
    }

    /// Position and horizontal heading at `s` metres along the path (looping, or back and forth).
    pub fn point_at(&self, s: f32) -> (Vec3, Vec3) {
        let len = self.length();
        let Some(&first) = self.points.first() else {
            return (Vec3::ZERO, Vec3::X);
        };
        if !(len > 0.0 && s.is_finite()) {
            return (first, Vec3::X);
        }
        let (mut s, mut back) = (
            s.rem_euclid(if self.closed { len } else { 2.0 * len }),
            false,
        );
        if s > len {
            s = 2.0 * len - s;
            back = true;
        }
        let mut along = 0.0;
        let mut last = (first, Vec3::X);
        for (a, b) in self.segments() {
            let l = a.distance(b);
            let dir = ((b - a) * Vec3::new(1.0, 0.0, 1.0)).normalize_or(Vec3::X);
            last = (b, dir);
            if l > 0.0 && s <= along + l {
                let p = a.lerp(b, (s - along) / l);
                return (p, if back { -dir } else { dir });
            }
            along += l;
        }
        (last.0, if back { -last.1 } else { last.1 })
    }

    /// The print of `foot` (0 or 1) number `k`: centre of the planted sphere.
    fn print(&self, foot: usize, k: i64) -> Vec3 {
        let a = (k as f32 + 0.5 * foot as f32) * self.step;
        let (p, dir) = self.point_at(a);
        let side = Vec3::new(-dir.z, 0.0, dir.x)
            * (if foot == 0 { 0.5 } else { -0.5 } * self.stance_width);
        p + side + Vec3::Y * (self.foot_radius - self.press_depth)
    }

    /// Where `foot` is at `time` seconds. A foot is planted while the body is within a quarter step
    /// of its print; otherwise it swings: straight up from its print, across above the snow, and
    /// straight down onto its next print, so that each print is one clean dent.
    pub fn foot_pose(&self, foot: usize, time: f32) -> Pose {
        let s = self.start + self.speed * time;
        let offset = 0.5 * foot as f32 * self.step;
        // Print k of this foot is planted for s in [a_k - step/4, a_k + step/4).
        let x = (s - offset) / self.step + 0.25;
        let k = x.floor();
        let phase = x - k;
        let k = k as i64;
        if phase < 0.5 {
            return Pose::at(self.print(foot, k).into());
        }
        // Swing from print k to print k + 1; hold above each end for a quarter of the swing.
        let u = ((phase - 0.5) * 2.0 - 0.25) / 0.5;
        let t = u.clamp(0.0, 1.0);
        let t = t * t * (3.0 - 2.0 * t);
        let raise = Vec3::Y * (self.lift + self.press_depth);
        let p = self.print(foot, k).lerp(self.print(foot, k + 1), t) + raise;
        Pose::at(p.into())
    }

    /// Both feet at frame `frame` of a run with steps of `dt` seconds, each with its pose at the
    /// previous frame (none at frame 0).
    pub fn feet(&self, frame: u64, dt: f32) -> [ManagedDeformer; 2] {
        let shape = Shape::Sphere {
            radius: self.foot_radius,
        };
        let t = frame as f32 * dt;
        let foot = |j: usize| {
            let pose = self.foot_pose(j, t);
            let deformer = if frame == 0 {
                Deformer::new(shape, pose)
            } else {
                Deformer::moving(shape, self.foot_pose(j, (frame - 1) as f32 * dt), pose)
            };
            ManagedDeformer {
                deformer,
                player: self.player,
            }
        };
        [foot(0), foot(1)]
    }

    /// Where the walker's body is (on the snow top) at `time`, and its heading.
    pub fn body(&self, time: f32) -> (Vec3, Vec3) {
        self.point_at(self.start + self.speed * time)
    }
}

/// A generated city.
#[derive(Clone, Debug, PartialEq)]
pub struct City {
    /// Every surface, streets of a block before its roofs.
    pub surfaces: Vec<CitySurface>,
    /// Every walker; the first is the player when there is any.
    pub walkers: Vec<WalkerPath>,
    /// Blocks per row of the grid.
    pub blocks_per_row: u32,
}

impl City {
    /// The feet of every walker at a frame (see [`WalkerPath::feet`]).
    pub fn deformers(&self, frame: u64, dt: f32) -> Vec<ManagedDeformer> {
        self.walkers
            .iter()
            .flat_map(|w| w.feet(frame, dt))
            .collect()
    }

    /// A camera behind and above the player (or over the first block when there is no walker),
    /// looking at it.
    pub fn player_camera(&self, time: f32) -> Camera {
        let (target, dir) = match self.walkers.first() {
            Some(w) => w.body(time),
            None => (
                Vec3::new(BLOCK_PITCH * 0.5, 0.0, BLOCK_PITCH * 0.5),
                Vec3::X,
            ),
        };
        Camera {
            eye: target - dir * 9.0 + Vec3::Y * 7.0,
            target,
            fov_y_degrees: 60.0,
        }
    }
}

/// Generate a city of exactly `surfaces` surfaces (several hundred makes a good demo) and
/// `walkers` walkers, half on streets and half on roofs, the first (on a street) the player.
pub fn generate(seed: u64, surfaces: usize, walkers: usize) -> City {
    let mut rng = XorShift::new(seed);
    // About 13 surfaces per block.
    let blocks = surfaces.div_ceil(13).max(1);
    let per_row = (blocks as f32).sqrt().ceil() as u32;
    // One snow depth for all streets, so a walker's feet sink the same on every segment.
    let street_depth = rng.range(0.12, 0.2);
    let (out, roofs, blocks_made) = city_blocks(&mut rng, surfaces, per_row, street_depth);
    let paths = walker_paths(
        &mut rng,
        walkers,
        &out,
        &roofs,
        (per_row, blocks_made),
        street_depth,
    );
    City {
        surfaces: out,
        walkers: paths,
        blocks_per_row: per_row,
    }
}

/// `surfaces` surfaces, block by block (`per_row` blocks a row): each block's streets, then its
/// four lots' roofs and penthouses. Returns the surfaces, the indices of the roofs and how many
/// blocks were started.
fn city_blocks(
    rng: &mut XorShift,
    surfaces: usize,
    per_row: u32,
    street_depth: f32,
) -> (Vec<CitySurface>, Vec<usize>, u32) {
    let zones_per_row = per_row.div_ceil(ZONE_BLOCKS);
    let mut out: Vec<CitySurface> = Vec::with_capacity(surfaces);
    let mut roofs: Vec<usize> = Vec::new();
    let mut block = 0u32;
    while out.len() < surfaces {
        let (bx, bz) = (block % per_row, block / per_row);
        block += 1;
        let zone = ZoneId((bx / ZONE_BLOCKS) + (bz / ZONE_BLOCKS) * zones_per_row);
        let origin = Vec2::new(bx as f32, bz as f32) * BLOCK_PITCH;
        let push = |out: &mut Vec<CitySurface>, s: CitySurface| {
            if out.len() < surfaces {
                out.push(s);
            }
        };
        let street = |name: String, c: Vec2, depth: f32| CitySurface {
            desc: SurfaceDesc {
                replenish_rate: 0.01,
                ..SurfaceDesc::new(&name, [c.x, 0.0, c.y], [STREET_WIDTH, STREET_WIDTH], depth)
            },
            zone,
            kind: SurfaceKind::Street,
            material: GroundMaterial::Concrete,
        };
        let half = STREET_WIDTH * 0.5;
        push(
            &mut out,
            street(
                format!("x{bx}_{bz}"),
                origin + Vec2::splat(half),
                street_depth,
            ),
        );
        for k in 0..4 {
            let along = STREET_WIDTH + half + k as f32 * STREET_WIDTH;
            push(
                &mut out,
                street(
                    format!("n{bx}_{bz}_{k}"),
                    origin + Vec2::new(along, half),
                    street_depth,
                ),
            );
            push(
                &mut out,
                street(
                    format!("w{bx}_{bz}_{k}"),
                    origin + Vec2::new(half, along),
                    street_depth,
                ),
            );
        }
        // Four lots of 12 m x 12 m in the 24 m x 24 m interior.
        for lot in 0..4 {
            let lot_min = origin
                + Vec2::splat(STREET_WIDTH)
                + Vec2::new((lot % 2) as f32, (lot / 2) as f32) * 12.0;
            let size = Vec2::new(rng.range(5.0, 10.0), rng.range(5.0, 10.0));
            let c = lot_min + Vec2::splat(6.0);
            let height = rng.range(6.0, 30.0);
            let yaw = if rng.unit() < 0.3 {
                rng.range(-20.0, 20.0)
            } else {
                0.0
            };
            let material = if rng.unit() < 0.7 {
                GroundMaterial::RoofTiles
            } else {
                GroundMaterial::Concrete
            };
            let roof =
                |name: String, c: Vec2, y: f32, size: Vec2, yaw: f32, depth: f32| CitySurface {
                    desc: SurfaceDesc {
                        yaw_degrees: yaw,
                        replenish_rate: 0.01,
                        ..SurfaceDesc::new(&name, [c.x, y, c.y], size.to_array(), depth)
                    },
                    zone,
                    kind: SurfaceKind::Roof,
                    material,
                };
            let depth = rng.range(0.15, 0.3);
            if out.len() < surfaces {
                roofs.push(out.len());
            }
            push(
                &mut out,
                roof(format!("r{bx}_{bz}_{lot}"), c, height, size, yaw, depth),
            );
            // A penthouse: a smaller roof stacked above this one.
            if rng.unit() < 0.25 {
                if out.len() < surfaces {
                    roofs.push(out.len());
                }
                let top = height + rng.range(3.0, 6.0);
                push(
                    &mut out,
                    roof(format!("p{bx}_{bz}_{lot}"), c, top, size * 0.5, yaw, depth),
                );
            }
        }
    }
    (out, roofs, block)
}

/// One path a walker: odd walkers around a roof's edge, the others (the player first, round the
/// middle block) around a block's streets, or back and forth along a street in a city too small
/// for a loop.
fn walker_paths(
    rng: &mut XorShift,
    walkers: usize,
    out: &[CitySurface],
    roofs: &[usize],
    (per_row, blocks_made): (u32, u32),
    street_depth: f32,
) -> Vec<WalkerPath> {
    let mut paths = Vec::with_capacity(walkers);
    // A block can be walked around when its east and south neighbours exist (their bands close
    // the loop). Streets of a block come first, so an existing block has all its bands.
    // The last block may lack some of its surfaces, so it does not count.
    let exists = |bx: u32, bz: u32| bx < per_row && bz * per_row + bx + 1 < blocks_made;
    let full =
        |bx: u32, bz: u32| exists(bx + 1, bz) && exists(bx, bz + 1) && exists(bx + 1, bz + 1);
    let loops: Vec<(u32, u32)> = (0..blocks_made)
        .map(|b| (b % per_row, b / per_row))
        .filter(|&(bx, bz)| full(bx, bz))
        .collect();
    for w in 0..walkers {
        let name = format!("walker{w}");
        let on_roof = w % 2 == 1 && !roofs.is_empty();
        let mut path = if on_roof {
            let s = &out[roofs[rng.below(roofs.len())]].desc;
            let m = s.local_to_world();
            let inset = (s.size * 0.5 - Vec2::splat(0.8)).max(Vec2::splat(0.2));
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            let points = corners
                .iter()
                .map(|&(x, z)| {
                    m.transform_point3(Vec3::new(x * inset.x, s.snow_depth, z * inset.y))
                })
                .collect();
            WalkerPath::new(&name, points, true)
        } else if let Some(&(bx, bz)) = (!loops.is_empty()).then(|| {
            // The player walks around the middle block.
            if w == 0 {
                &loops[loops.len() / 2]
            } else {
                &loops[rng.below(loops.len())]
            }
        }) {
            let o = Vec2::new(bx as f32, bz as f32) * BLOCK_PITCH + Vec2::splat(STREET_WIDTH * 0.5);
            let lane = rng.range(-1.5, 1.5);
            let (a, b) = (lane, BLOCK_PITCH + lane);
            let y = street_depth;
            let points = [(a, a), (b, a), (b, b), (a, b)]
                .iter()
                .map(|&(x, z)| Vec3::new(o.x + x, y, o.y + z))
                .collect();
            WalkerPath::new(&name, points, true)
        } else {
            // Too small a city for a loop: back and forth along the first block's north street.
            let y = street_depth;
            let z = STREET_WIDTH * 0.5 + rng.range(-1.5, 1.5);
            let points = vec![Vec3::new(1.0, y, z), Vec3::new(BLOCK_PITCH - 1.0, y, z)];
            WalkerPath::new(&name, points, false)
        };
        path.speed = rng.range(1.1, 1.6);
        path.start = rng.range(0.0, path.length().max(1.0));
        path.player = w == 0;
        paths.push(path);
    }
    paths
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_city_and_exact_count() {
        let a = generate(7, 300, 20);
        let b = generate(7, 300, 20);
        assert_eq!(a, b);
        assert_eq!(a.surfaces.len(), 300);
        assert_eq!(a.walkers.len(), 20);
        assert_ne!(a, generate(8, 300, 20));
        let roofs = a
            .surfaces
            .iter()
            .filter(|s| s.kind == SurfaceKind::Roof)
            .count();
        assert!((80..300).contains(&roofs), "{roofs}");
        let names: std::collections::HashSet<_> = a.surfaces.iter().map(|s| &s.desc.name).collect();
        assert_eq!(names.len(), 300, "names are unique");
        assert!(a.surfaces.iter().all(|s| s.desc.validate().is_ok()));
        assert!(a.walkers[0].player && !a.walkers[1].player);
    }

    #[test]
    fn feet_alternate_and_leave_separate_prints() {
        let w = WalkerPath::new(
            "w",
            vec![Vec3::new(0.0, 0.2, 0.0), Vec3::new(20.0, 0.2, 0.0)],
            false,
        );
        let dt = 1.0 / 30.0;
        let top = 0.2;
        let mut prints: Vec<Vec3> = Vec::new();
        for f in 0..120 {
            let feet = w.feet(f, dt);
            let planted: Vec<_> = feet
                .iter()
                .filter(|d| d.deformer.pose.position.y - w.foot_radius < top)
                .collect();
            // Always at least one foot on the ground, never a foot dragging through the snow.
            assert!(!planted.is_empty(), "frame {f}");
            for d in &feet {
                let y = d.deformer.pose.position.y - w.foot_radius;
                assert!(
                    (y - (top - w.press_depth)).abs() < 1e-5 || y > top + 0.4,
                    "frame {f}: {y}"
                );
                if let Some(prev) = d.deformer.previous {
                    let (a, b) = (prev.position, d.deformer.pose.position);
                    // Into or out of the snow only vertically.
                    if a.y.min(b.y) - w.foot_radius < top {
                        assert!(
                            (a.x - b.x).abs() < 1e-6 && (a.z - b.z).abs() < 1e-6,
                            "frame {f}: {a} -> {b}"
                        );
                    }
                }
                let p = d.deformer.pose.position;
                if p.y - w.foot_radius < top && !prints.iter().any(|q| q.distance(p) < 1e-4) {
                    prints.push(p);
                }
            }
        }
        // 4 s at 1.3 m/s with a print every 0.4 m.
        assert!(prints.len() >= 12, "{}", prints.len());
        for (i, a) in prints.iter().enumerate() {
            for b in &prints[i + 1..] {
                assert!(a.distance(*b) > 2.0 * w.foot_radius + 0.1, "{a} {b}");
            }
        }
    }

    #[test]
    fn walkers_walk_on_snow_of_their_city() {
        let city = generate(3, 400, 30);
        for w in &city.walkers {
            let (p, _) = w.body(1.0);
            let on = city.surfaces.iter().any(|s| {
                let l = s.desc.world_to_local().transform_point3(p);
                l.x.abs() <= s.desc.size.x * 0.5 + 2.0
                    && l.z.abs() <= s.desc.size.y * 0.5 + 2.0
                    && (l.y - s.desc.snow_depth).abs() < 1e-3
            });
            assert!(on, "{} at {p}", w.name);
        }
    }
}
