//! Two surfaces side by side on one texel grid update as one surface over both: each captures an
//! apron of one texel beyond its sides (`capture::region`), so the blur of the two columns along
//! the line reads the same field on either side. A ball straddles the line and a small one
//! presses only the right surface's edge column (nothing of the left surface's own texels): on
//! both capture paths the GPU gives the CPU reference's heights, and both give, texel for texel,
//! what the one wider surface holds, the line's columns included, whether the update runs over its
//! grid, over the capture's tile list or as separate passes; on flat ground and on a 45
//! degree plane (whose apron's ground is extrapolated from the field, exact on a plane). Under
//! the manager, a print pressing only the right surface's edge is queued on the left one too.

mod common;

use snowprint::low_level::capture::{self, CaptureVolume};
use snowprint::reference::accumulate::{self as acc_cpu, BlurInput};
use snowprint::reference::capture as cap_cpu;
use snowprint::{
    CaptureMode, CapturePath, Deformer, Ground, HeightGrid, PassMode, PoolFormat, Pose, Precision,
    Shape, SlopeRule, SnowWorld, SurfaceDesc, SurfaceId, WorldConfig,
};

const DEPTH: f32 = 0.3;
const ANKLE: f32 = 0.25;
const TEXEL: f32 = 0.04;
/// Texels of the left and right surfaces along x (the one surface has both), and along z.
const LEFT: u32 = 32;
const RIGHT: u32 = 24;
const ROWS: u32 = 24;
/// World x of the line where the two meet.
const LINE: f32 = LEFT as f32 * TEXEL;

/// How the update runs: the fused pass over its grid (tiles the capture did not flag skipped),
/// over the capture's tile list, or blur and merge as separate passes.
#[derive(Clone, Copy, Debug)]
enum Update {
    Grid,
    Listed,
    Separate,
}

fn world(path: CapturePath, update: Update) -> SnowWorld {
    let config = WorldConfig {
        capture_path: path,
        format: PoolFormat::new(Precision::Bits16),
        passes: match update {
            Update::Separate => PassMode::Separate,
            _ => PassMode::Fused,
        },
        list_tiles_from: match update {
            Update::Listed => 0,
            _ => u32::MAX,
        },
        ..WorldConfig::default()
    };
    SnowWorld::new(common::gpu(), config).expect("world")
}

/// A surface of `columns` texels from world x `from`, on the grid of every other.
fn surface(name: &str, from: f32, columns: u32) -> SurfaceDesc {
    let size = [columns as f32 * TEXEL, ROWS as f32 * TEXEL];
    let mut d = SurfaceDesc::new(name, [from + size[0] * 0.5, 1.0, 0.0], size, DEPTH);
    d.replenish_rate = 0.0;
    d
}

/// Height of the ground (above the surfaces' centre height) at world x: flat, or a plane rising
/// `slope` metres a metre along x.
fn ground_at(x: f32, slope: f32) -> f32 {
    slope * (x - 1.0)
}

/// The plane as a grid over a surface's texel centres.
fn plane(d: &SurfaceDesc, columns: u32, slope: f32) -> Ground {
    let left = d.center.x - d.size.x * 0.5;
    let heights = (0..ROWS)
        .flat_map(|_| (0..columns).map(move |c| ground_at(left + (c as f32 + 0.5) * TEXEL, slope)))
        .collect();
    Ground::Grid(HeightGrid {
        columns,
        rows: ROWS,
        heights,
    })
}

/// Snow held on the plane: the whole depth up to 35 degrees, none from 60 (the default rule).
fn held(slope: f32) -> f32 {
    SlopeRule::default().holds(slope.atan().to_degrees()) * DEPTH
}

/// A ball of `radius` at world (x, z), its bottom `press` below the snow top there.
fn ball(x: f32, z: f32, radius: f32, press: f32, slope: f32) -> Pose {
    Pose::at([
        x,
        1.0 + ground_at(x, slope) + held(slope) - press + radius,
        z,
    ])
}

/// Frame `f`'s deformers: a ball straddling the line, moving along z, and a small ball over the
/// right surface's first column only (at a texel centre, 3.5 cm across: the centres beside it
/// are 4 cm away).
fn deformers(f: u32, slope: f32) -> Vec<Deformer> {
    let edge = LINE + 0.5 * TEXEL;
    let row = |r: u32| -(ROWS as f32) * TEXEL * 0.5 + (r as f32 + 0.5) * TEXEL;
    let straddle = |f: u32| ball(LINE + 0.03, -0.2 + 0.06 * f as f32, 0.12, 0.1, slope);
    vec![
        Deformer::moving(
            Shape::Sphere { radius: 0.12 },
            straddle(f.saturating_sub(1)),
            straddle(f),
        ),
        Deformer::new(
            Shape::Sphere { radius: 0.035 },
            ball(edge, row(16 + f), 0.035, 0.15, slope),
        ),
    ]
}

/// One surface of a world and the CPU reference's channels for it.
struct Tracked {
    id: SurfaceId,
    desc: SurfaceDesc,
    cpu: (Vec<u32>, Vec<u32>),
}

impl Tracked {
    fn new(w: &mut SnowWorld, desc: SurfaceDesc, columns: u32, slope: f32) -> Self {
        let id = w.add_surface(desc.clone()).unwrap();
        if slope != 0.0 {
            w.set_ground(id, &plane(&desc, columns, slope), SlopeRule::default())
                .unwrap();
        }
        let n = (columns * ROWS) as usize;
        Self {
            id,
            desc,
            cpu: (vec![0; n], vec![0; n]),
        }
    }

    /// The CPU reference's update by `ds`: the capture of the surface's region (the culling
    /// volume grown by the apron, as the plan's), blurred, merged.
    fn step_cpu(&mut self, w: &SnowWorld, ds: &[Deformer]) {
        let l = w.layout(self.id).unwrap();
        let field = w.ground(self.id).unwrap();
        let half = self.desc.size * 0.5;
        let volume = CaptureVolume {
            world_to_local: self.desc.world_to_local(),
            half_size: CaptureVolume::of_region(half, l.width, l.height),
            frustum_height: DEPTH + ANKLE,
            ground: field.map_or((0.0, 0.0), |f| f.region_range()),
        };
        let mut prims = Vec::new();
        for d in ds {
            capture::push_primitives(d, &volume, &mut prims);
        }
        if prims.is_empty() {
            return;
        }
        let columns = field.map(|f| f.columns.as_slice());
        let region = cap_cpu::capture_on_ground_region(
            l.width,
            l.height,
            half,
            DEPTH + ANKLE,
            &prims,
            &[],
            columns,
        );
        let input = BlurInput {
            width: l.width,
            height: l.height,
            mode: CaptureMode::Depth,
            mask_fraction: 1.0,
            snow_depth: DEPTH,
            frustum_height: DEPTH + ANKLE,
        };
        let blurred = acc_cpu::blur(&input, &region);
        self.cpu = acc_cpu::merge(
            &self.cpu.0,
            &self.cpu.1,
            Some(&blurred),
            0,
            Precision::Bits16,
        );
    }
}

/// The two surfaces' depressions laid side by side as the one surface's texels.
fn joined(left: &[u32], right: &[u32]) -> Vec<u32> {
    (0..ROWS as usize)
        .flat_map(|r| {
            let l = &left[r * LEFT as usize..(r + 1) * LEFT as usize];
            let rr = &right[r * RIGHT as usize..(r + 1) * RIGHT as usize];
            l.iter().chain(rr).copied()
        })
        .collect()
}

/// Largest difference between two channels and where (column, row) on the one surface's grid.
fn worst(a: &[u32], b: &[u32], columns: u32) -> (u32, (u32, u32)) {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(i, (x, y))| (x.abs_diff(*y), (i as u32 % columns, i as u32 / columns)))
        .max_by_key(|t| t.0)
        .unwrap_or((0, (0, 0)))
}

fn run(path: CapturePath, update: Update, slope: f32) {
    let (mut two, mut one) = (world(path, update), world(path, update));
    let mut left = Tracked::new(&mut two, surface("left", 0.0, LEFT), LEFT, slope);
    let mut right = Tracked::new(&mut two, surface("right", LINE, RIGHT), RIGHT, slope);
    let mut wide = Tracked::new(
        &mut one,
        surface("one", 0.0, LEFT + RIGHT),
        LEFT + RIGHT,
        slope,
    );
    let size = |w: &SnowWorld, t: &Tracked| {
        let l = w.layout(t.id).unwrap();
        (l.width, l.height)
    };
    assert_eq!(
        [size(&two, &left), size(&two, &right), size(&one, &wide)],
        [(LEFT, ROWS), (RIGHT, ROWS), (LEFT + RIGHT, ROWS)],
        "the surfaces lie on one grid of {TEXEL} m texels"
    );
    let at = |what: &str, f: u32| format!("{path:?}, {update:?}, slope {slope}, frame {f}: {what}");
    for f in 0..3 {
        let ds = deformers(f, slope);
        two.step(1.0 / 30.0, &ds).unwrap();
        one.step(1.0 / 30.0, &ds).unwrap();
        left.step_cpu(&two, &ds);
        right.step_cpu(&two, &ds);
        wide.step_cpu(&one, &ds);
        let gpu = |w: &SnowWorld, t: &Tracked| w.read_channels(t.id).unwrap();
        let (gl, gr, gw) = (gpu(&two, &left), gpu(&two, &right), gpu(&one, &wide));
        // Each surface against its CPU reference, both channels.
        for (name, g, t, columns) in [
            ("left", &gl, &left, LEFT),
            ("right", &gr, &right, RIGHT),
            ("one", &gw, &wide, LEFT + RIGHT),
        ] {
            for (channel, a, b) in [
                ("depression", &g.0, &t.cpu.0),
                ("displaced", &g.1, &t.cpu.1),
            ] {
                let (d, texel) = worst(a, b, columns);
                assert!(
                    d <= 1,
                    "{}",
                    at(
                        &format!("{name}'s {channel} is {d} from the CPU's at {texel:?}"),
                        f
                    )
                );
            }
        }
        // The two against the one, on the GPU and on the CPU.
        let columns = LEFT + RIGHT;
        let (d, texel) = worst(&joined(&gl.0, &gr.0), &gw.0, columns);
        assert!(
            d <= 1,
            "{}",
            at(
                &format!("the GPU's two differ from the one by {d} at {texel:?}"),
                f
            )
        );
        let (d, texel) = worst(&joined(&left.cpu.0, &right.cpu.0), &wide.cpu.0, columns);
        assert!(
            d <= 1,
            "{}",
            at(
                &format!("the CPU's two differ from the one by {d} at {texel:?}"),
                f
            )
        );
        // The small ball pressed the right surface's first column only, yet the left surface's
        // last column took its share through the blur (10/64 of it beside it), as on the one.
        let row = (16 + f) as usize;
        let pressed = gr.0[row * RIGHT as usize];
        let beside = gl.0[row * LEFT as usize + LEFT as usize - 1];
        // By hand: the ball presses its texel to half the snow depth (15 cm of 30) and the
        // blur's kernel gives a texel 12/64 of itself and 10/64 of its neighbour beside it.
        let units = |weight: f64| (0.5 * weight / 64.0 * 65535.0).round() as u32;
        assert!(
            pressed.abs_diff(units(12.0)) <= 1 && beside.abs_diff(units(10.0)) <= 1,
            "{}",
            at(
                &format!(
                    "the edge ball left {pressed} and {beside} beside it, by hand {} and {}",
                    units(12.0),
                    units(10.0)
                ),
                f
            )
        );
        println!(
            "{path:?}, {update:?}, slope {slope}, frame {f}: edge column {pressed}, the left surface's column beside it {beside} (the one surface: {})",
            gw.0[row * columns as usize + LEFT as usize - 1]
        );
    }
}

#[test]
fn two_surfaces_on_one_grid_update_as_the_one_surface_over_both_on_both_capture_paths() {
    for path in [CapturePath::Raster, CapturePath::Compute] {
        for update in [Update::Grid, Update::Listed, Update::Separate] {
            run(path, update, 0.0);
        }
    }
}

#[test]
fn two_surfaces_on_one_plane_update_as_the_one_surface_over_both() {
    for path in [CapturePath::Raster, CapturePath::Compute] {
        run(path, Update::Listed, 1.0);
    }
}

/// Under the surface manager a ball over the right surface's first column, its bounds clear of
/// the left surface's rectangle (1.5 cm across, 2.5 cm past the line), is queued on the left
/// surface too (its touch volume is its capture region): flushed, both heightmaps are what a plain
/// world leaves, the left surface's last column holding its share through the blur.
#[test]
fn the_manager_queues_an_edge_print_on_the_neighbour_too() {
    use snowprint::manager::{ManagedDeformer, ManagerConfig, SnowManager, ZoneId};
    let mut m = SnowManager::new(common::gpu(), ManagerConfig::default()).unwrap();
    let mut plain = world(CapturePath::Auto, Update::Grid);
    let mut ids = Vec::new();
    for (name, from, columns) in [("left", 0.0, LEFT), ("right", LINE, RIGHT)] {
        let d = surface(name, from, columns);
        ids.push((
            m.add_surface(d.clone(), ZoneId(0)).unwrap(),
            plain.add_surface(d).unwrap(),
        ));
    }
    let row = -(ROWS as f32) * TEXEL * 0.5 + 16.5 * TEXEL;
    let edge_ball = Deformer::new(
        Shape::Sphere { radius: 0.015 },
        ball(LINE + 0.025, row, 0.015, 0.15, 0.0),
    );
    m.tick(1.0 / 30.0, None, &[ManagedDeformer::new(edge_ball)])
        .unwrap();
    m.flush().unwrap();
    plain.step(1.0 / 30.0, &[edge_ball]).unwrap();
    for (&(managed, world_id), name) in ids.iter().zip(["left", "right"]) {
        let (a, b) = (
            m.read_heightmap(managed).unwrap(),
            plain.read_heightmap(world_id).unwrap(),
        );
        let differ = (a.depression.iter().zip(&b.depression))
            .chain(a.displaced.iter().zip(&b.displaced))
            .filter(|(x, y)| x != y)
            .count();
        assert_eq!(
            differ, 0,
            "the managed {name} surface differs from the plain world's"
        );
    }
    let left = m.read_heightmap(ids[0].0).unwrap();
    let beside = left.depression[16 * LEFT as usize + LEFT as usize - 1];
    // About 10/64 of half the depth (5,120 units) less the ball's curve 5 mm off the centre.
    assert!(
        (5000..=5120).contains(&beside),
        "the left surface's last column holds {beside}"
    );
}

/// The largest heightmap a world allows is the atlas side less the apron, so that its capture
/// region fits the atlas.
#[test]
fn the_largest_heightmap_leaves_room_for_the_apron() {
    let config = WorldConfig {
        atlas_side: 256,
        max_resolution: 4096,
        ..WorldConfig::default()
    };
    let w = SnowWorld::new(common::gpu(), config).expect("world");
    assert_eq!(
        w.config().max_resolution,
        256 - 2 * capture::APRON,
        "the region of the largest heightmap fits the atlas"
    );
}
