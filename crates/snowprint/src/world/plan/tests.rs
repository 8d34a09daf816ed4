//! The frame plan without a GPU: culling, sweeping, replenishment, atlas packing, dispatch shape.

use glam::{Quat, Vec2};
use proptest::prelude::*;

use super::*;
use crate::deformer::{Pose, Shape};
use crate::pool::{MODE_MESHES, Precision};

fn settings() -> PlanSettings {
    PlanSettings::of(&WorldConfig::default())
}

/// Surfaces `descs` at consecutive pool offsets, each touched by `deformers[i]`.
fn inputs<'a>(
    descs: &'a [SurfaceDesc],
    deformers: &'a [Vec<Deformer>],
    elapsed: f32,
) -> Vec<PlanSurface<'a>> {
    let mut word = 0;
    descs
        .iter()
        .zip(deformers)
        .enumerate()
        .map(|(index, (desc, deformers))| {
            let layout = SurfaceLayout::for_size_capped(desc.size, 512);
            let s = PlanSurface {
                index,
                id: SurfaceId(index as u32, 0),
                desc,
                layout,
                heights_word: word,
                normals_word: None,
                wrap: 0,
                carry: 0.0,
                elapsed,
                deformers,
                settle: Default::default(),
                ground: None,
                ground_field: None,
            };
            word += layout.width * layout.height;
            s
        })
        .collect()
}

fn no_meshes(_: MeshId) -> Option<f32> {
    None
}

fn sphere_at(p: [f32; 3]) -> Deformer {
    Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at(p))
}

/// A surface 4 x 4 m, 0.3 m of snow, at `x` along the street, that does not refill.
fn still(name: &str, x: f32) -> SurfaceDesc {
    let mut d = SurfaceDesc::new(name, [x, 0.0, 0.0], [4.0, 4.0], 0.3);
    d.replenish_rate = 0.0;
    d
}

#[test]
fn deformers_are_culled_against_each_capture_volume() {
    let descs = [still("a", 0.0), still("b", 10.0), still("c", 20.0)];
    let deformers = vec![
        // Over a: captured.
        vec![sphere_at([0.5, 0.1, 0.5])],
        // Beside b (outside its 4 m square) and above its frustum (0.3 + 0.25 m): nothing.
        vec![sphere_at([13.0, 0.1, 0.0]), sphere_at([10.0, 0.8, 0.0])],
        // Nothing over c.
        vec![],
    ];
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.1), no_meshes);
    assert_eq!(
        plan.surfaces,
        vec![PlannedSurface {
            index: 0,
            captured: true
        }]
    );
    assert_eq!(plan.capture.prims.len(), 1);
    assert_eq!(plan.capture.surfaces.len(), 1);
    assert_eq!(plan.capture.surfaces[0].prims, 0..1);
    // Every surface planned keeps its carry, updated or not.
    assert_eq!(plan.carries, vec![(0, 0.0), (1, 0.0), (2, 0.0)]);
    let stats = plan.stats();
    assert_eq!((stats.updated, stats.captured, stats.primitives), (1, 1, 1));
}

#[test]
fn nothing_to_do_plans_nothing() {
    let descs = [still("a", 0.0)];
    let deformers = vec![vec![sphere_at([30.0, 0.1, 0.0])]];
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.1), no_meshes);
    assert!(plan.is_empty());
    assert_eq!(plan.sizes, BufferSizes::default());
    assert_eq!(plan.capture.batches, 0);
}

#[test]
fn a_moving_capsule_is_drawn_at_its_sub_steps() {
    let descs = [still("a", 0.0)];
    let (radius, half_height) = (0.05, 0.1);
    let from = Pose::at([-1.0, 0.1, 0.0]);
    let to = Pose::at([1.0, 0.1, 0.0]);
    let capsule = Shape::Capsule {
        radius,
        half_height,
    };
    let deformers = vec![vec![Deformer::moving(capsule, from, to)]];
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.0), no_meshes);
    // 2 m in steps of half the radius, at most MAX_SUBSTEPS, both ends drawn.
    let n = capture::substeps(2.0, radius);
    assert_eq!(n, capture::MAX_SUBSTEPS);
    assert_eq!(plan.capture.prims.len() as u32, n + 1);
    // A sphere is swept exactly: one capsule whatever the distance.
    let sphere = Shape::Sphere { radius: 0.2 };
    let deformers = vec![vec![Deformer::moving(sphere, from, to)]];
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.0), no_meshes);
    assert_eq!(plan.capture.prims.len(), 1);
    // At rest, one capsule.
    let deformers = vec![vec![Deformer::new(capsule, to)]];
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.0), no_meshes);
    assert_eq!(plan.capture.prims.len(), 1);
}

#[test]
fn a_moving_mesh_is_drawn_at_its_sub_steps_and_culled() {
    let descs = [still("a", 0.0)];
    let id = MeshId(0);
    let from = Pose::at([-0.1, 0.1, 0.0]);
    let to = Pose {
        rotation: Quat::from_rotation_y(0.5),
        ..Pose::at([0.1, 0.1, 0.0])
    };
    let deformers = vec![vec![Deformer::moving(Shape::Mesh(id), from, to)]];
    let radius = 0.2;
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.0), |m| {
        (m == id).then_some(radius)
    });
    let n = capture::mesh_substeps(&from, &to, radius);
    assert!(n > 1);
    assert_eq!(plan.capture.draws.len() as u32, n);
    assert_eq!(plan.capture.draw_meshes, vec![id; n as usize]);
    assert_eq!(plan.accumulate.records[0].mode & MODE_MESHES, MODE_MESHES);
    assert_eq!(plan.capture.winding_texels(), plan.capture.texels);
    // An unregistered mesh draws nothing.
    let plan = FramePlan::build(&settings(), inputs(&descs, &deformers, 0.0), no_meshes);
    assert!(plan.is_empty());
}

/// Units refilled over `frames` updates of `dt`, the carry fed back as the world does.
fn refilled(rate: f32, dt: f32, frames: u32, precision: Precision) -> u64 {
    let mut desc = still("a", 0.0);
    desc.replenish_rate = rate;
    let mut s = settings();
    s.format.precision = precision;
    let mut carry = 0.0;
    let mut total = 0u64;
    let mut plan = FramePlan::default();
    let nothing = [vec![]];
    for _ in 0..frames {
        let mut input = inputs(std::slice::from_ref(&desc), &nothing, dt);
        input[0].carry = carry;
        plan.rebuild(&s, input, no_meshes);
        carry = plan.carries[0].1;
        assert!((0.0..1.0).contains(&carry));
        total += plan
            .accumulate
            .records
            .first()
            .map_or(0, |r| r.replenish_units) as u64;
    }
    total
}

#[test]
fn replenishment_over_many_frames_is_the_whole_units_of_rate_times_time() {
    // Exact in binary: 0.25 of the depth a second, 1/64 s frames, 16 bits.
    let total = refilled(0.25, 1.0 / 64.0, 1000, Precision::Bits16);
    assert_eq!(total, (0.25 * 1000.0 / 64.0 * 65535.0f64).floor() as u64);
    // A slow snowfall at 60 Hz that refills less than a unit a frame at 8 bits.
    let (rate, dt) = (0.01f32, 1.0f32 / 60.0);
    let total = refilled(rate, dt, 6000, Precision::Bits8);
    let exact = rate as f64 * dt as f64 * 255.0 * 6000.0;
    assert_eq!(total, exact.floor() as u64);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Units refilled over many frames equal floor(rate * t * max) (but where the exact total
    /// lies within rounding of a whole unit).
    #[test]
    fn replenishment_carries_the_fraction(
        rate in 0.0f32..0.05,
        dt in 0.001f32..0.1,
        frames in 1u32..400,
        bits in prop::sample::select(vec![8u32, 16, 32]),
    ) {
        let precision = Precision::from_bits(bits).unwrap();
        let total = refilled(rate, dt, frames, precision);
        let exact = rate as f64 * dt as f64 * precision.channel_max() as f64 * frames as f64;
        let near_whole = (exact - exact.round()).abs() < 1e-6 * exact.max(1.0);
        prop_assume!(!near_whole);
        prop_assert_eq!(total, exact.floor() as u64);
    }

    /// Captured surfaces are placed inside the atlas, in its batches, never overlapping, each
    /// exactly once, with the capture buffer and tile flags laid out one after the other. On the
    /// compute path (spheres alone) none takes a place in the atlas, and each view's rectangle of
    /// tiles lies inside its surface.
    #[test]
    fn atlas_batches_never_overlap_and_cover_every_captured_surface(
        sizes in prop::collection::vec((1.0f32..20.0, 1.0f32..20.0, any::<bool>()), 1..24),
        atlas_side in prop::sample::select(vec![64u32, 256, 512, 1024]),
        raster in any::<bool>(),
    ) {
        let descs: Vec<SurfaceDesc> = sizes
            .iter()
            .enumerate()
            .map(|(i, &(w, h, _))| {
                let mut d = still(&format!("s{i}"), i as f32 * 50.0);
                d.size = Vec2::new(w, h);
                d
            })
            .collect();
        let deformers: Vec<Vec<Deformer>> = sizes
            .iter()
            .enumerate()
            .map(|(i, &(_, _, touched))| {
                if touched { vec![sphere_at([i as f32 * 50.0, 0.1, 0.0])] } else { vec![] }
            })
            .collect();
        let mut s = settings();
        s.atlas_side = atlas_side;
        if raster {
            s.capture_path = capture::CapturePath::Raster;
        }
        // The world caps heightmaps at the atlas side less the capture's apron.
        let mut input = inputs(&descs, &deformers, 0.1);
        for p in &mut input {
            p.layout = SurfaceLayout::for_size_capped(p.desc.size, atlas_side - 2 * capture::APRON);
        }
        let plan = FramePlan::build(&s, input, no_meshes);
        let c = &plan.capture;
        let touched: Vec<usize> = (0..sizes.len()).filter(|&i| sizes[i].2).collect();
        let mut seen: Vec<usize> = c.surfaces.iter().map(|s| plan.surfaces[s.record as usize].index).collect();
        seen.sort();
        prop_assert_eq!(seen, touched);
        prop_assert!(c.atlas_side <= atlas_side.max(64));
        let (mut texels, mut flags) = (0, 0);
        prop_assert_eq!(c.batches == 0, !raster || c.surfaces.is_empty());
        for (k, a) in c.surfaces.iter().enumerate() {
            let r = &plan.accumulate.records[a.record as usize];
            prop_assert_eq!(a.compute, !raster);
            if a.compute {
                let v = &c.views[k];
                prop_assert_eq!(r.batch, capture::COMPUTED);
                prop_assert!(v.prims[1] > 0);
                // Its work: at least the tile under the sphere's centre, each tile inside it
                // and listed once.
                let mine: Vec<u32> =
                    c.work.iter().filter(|e| e[0] == k as u32).map(|e| e[1]).collect();
                prop_assert!(!mine.is_empty());
                let mut unique = mine.clone();
                unique.sort();
                unique.dedup();
                prop_assert_eq!(unique.len(), mine.len());
                // Tiles of the capture region, the surface and its apron.
                let (rw, rh) = capture::region(a.width, a.height);
                for t in mine {
                    prop_assert!((t & 0xffff) < rw.div_ceil(TILE_SIDE));
                    prop_assert!((t >> 16) * TILE_SIDE < rh);
                }
                prop_assert_eq!((r.scratch, r.tiles), (texels, flags));
                texels += rw * rh;
                flags += r.tile_count();
                continue;
            }
            prop_assert!(a.batch < c.batches);
            let (aw, ah) = capture::region(a.width, a.height);
            prop_assert!(a.x + aw <= c.atlas_side && a.y + ah <= c.atlas_side);
            let r = &plan.accumulate.records[a.record as usize];
            prop_assert_eq!((r.atlas_x, r.atlas_y, r.batch), (a.x, a.y, a.batch));
            prop_assert_eq!((r.width, r.height), (a.width, a.height));
            prop_assert_eq!((r.scratch, r.tiles), (texels, flags));
            prop_assert_eq!(c.views[k].offset, r.scratch);
            texels += aw * ah;
            flags += r.tile_count();
            for b in &c.surfaces[k + 1..] {
                let (bw, bh) = capture::region(b.width, b.height);
                let apart = a.batch != b.batch
                    || a.x + aw <= b.x
                    || b.x + bw <= a.x
                    || a.y + ah <= b.y
                    || b.y + bh <= a.y;
                prop_assert!(apart, "{:?} and {:?} overlap", a, b);
            }
        }
        prop_assert_eq!((c.texels, c.tile_flags), (texels, flags));
        // An empty plan needs no buffer at all.
        let capture_bytes = if plan.is_empty() { 0 } else { texels.max(1) as u64 * 4 };
        prop_assert_eq!(plan.sizes.capture, capture_bytes);
    }
}

#[test]
fn surfaces_that_refill_come_first_and_the_rest_are_listed() {
    let mut refill = still("refill", 0.0);
    refill.replenish_rate = 0.1;
    let descs = [still("a", 10.0), refill, still("b", 20.0)];
    let deformers = vec![
        vec![sphere_at([10.0, 0.1, 0.0])],
        vec![],
        vec![sphere_at([20.0, 0.1, 0.0])],
    ];
    let mut s = settings();
    s.list_tiles_from = 0;
    let plan = FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes);
    let order: Vec<usize> = plan.surfaces.iter().map(|p| p.index).collect();
    assert_eq!(order, vec![1, 0, 2]);
    let a = &plan.accumulate;
    assert!(a.fused && a.listed);
    // A few words of snowfall: the fused pass's grid refills the refilling surface's every tile.
    assert_eq!((a.grid, a.refill), (1, 0));
    assert_eq!(a.records[0].mode & MODE_REFILLED, 0);
    assert_eq!(plan.capture.views[0].record, 1);
    // Streamed from 0 words: the refill pass takes that surface's whole region, marked so, and
    // the list every surface's tiles, so the fused pass needs no grid.
    s.refill_stream_from = 0;
    let plan = FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes);
    let a = &plan.accumulate;
    assert!(a.listed);
    assert_eq!((a.grid, a.refill), (0, 1));
    let r = &a.records[0];
    assert_eq!(r.mode & MODE_REFILLED, MODE_REFILLED);
    assert!(a.records[1..].iter().all(|r| r.mode & MODE_REFILLED == 0));
    assert_eq!(
        a.refill_words as u64,
        s.format.heights_bytes(r.width, r.height) / 4
    );
    // Just above the surface's words, the fused pass refills it again.
    s.refill_stream_from = a.refill_words + 1;
    let plan = FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes);
    assert_eq!((plan.accumulate.grid, plan.accumulate.refill), (1, 0));
    s.refill_stream_from = 0;
    // Never listing: the grid covers every record and the views say so.
    s.list_tiles_from = u32::MAX;
    let plan = FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes);
    assert!(!plan.accumulate.listed);
    assert_eq!(plan.accumulate.grid, 3);
    assert!(
        plan.capture
            .views
            .iter()
            .all(|v| v.record == capture::NO_LIST)
    );
    // Separate passes never list, and need the scratch buffer.
    s.passes = PassMode::Separate;
    s.list_tiles_from = 0;
    let plan = FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes);
    assert!(!plan.accumulate.fused && !plan.accumulate.listed);
    assert_eq!(plan.accumulate.refill, 0, "the separate merge refills");
    // Their blur reads every texel of every captured region: the whole capture is cleared.
    assert_eq!(plan.capture.clears, vec![(0, plan.capture.texels)]);
    assert_eq!(plan.sizes.scratch, plan.sizes.capture);
}

#[test]
fn rebuilding_reuses_the_plan() {
    let descs = [still("a", 0.0)];
    let deformers = vec![vec![sphere_at([0.0, 0.1, 0.0])]];
    let mut plan = FramePlan::default();
    plan.rebuild(&settings(), inputs(&descs, &deformers, 0.1), no_meshes);
    let first = plan.clone();
    plan.rebuild(&settings(), inputs(&descs, &deformers, 0.1), no_meshes);
    assert_eq!(plan.capture, first.capture);
    assert_eq!(plan.accumulate, first.accumulate);
    assert_eq!(plan.surfaces, first.surfaces);
}

/// A sand surface relaxes in the update that presses it and for `settle_updates` after, by its
/// own threshold, over what the press reached grown by the update's steps; snow and a settled
/// surface plan no relaxation (and no update).
#[test]
fn slumping_materials_relax_while_they_settle() {
    use crate::relax::{Rect, Settle};
    let mut sand = still("sand", 0.0);
    sand.material = crate::Material::sand();
    let descs = [sand, still("snow", 10.0)];
    let pressed = vec![
        vec![sphere_at([0.5, 0.1, 0.5])],
        vec![sphere_at([10.5, 0.1, 0.5])],
    ];
    let plan = FramePlan::build(&settings(), inputs(&descs, &pressed, 0.1), no_meshes);
    let m = crate::Material::sand();
    // The ball (radius 0.2 m) at local (0.5, 0.5) of a 4 m square of 4 cm texels: texel 62.5,
    // 5 texels of radius, 3 of blur margin: columns and rows 54..71, grown by the 8 steps: 46..79.
    let rect = Rect {
        x0: 46,
        y0: 46,
        x1: 79,
        y1: 79,
    };
    assert_eq!(m.steps(), 8);
    assert_eq!(
        plan.settles,
        vec![
            (
                0,
                Settle {
                    updates: m.settle_updates,
                    rect
                }
            ),
            (1, Settle::default())
        ]
    );
    assert_eq!(plan.relax.records.len(), 1, "only the sand relaxes");
    assert_eq!(plan.relax.steps, m.steps());
    let r = plan.relax.records[0];
    // 34 degrees over a 4 cm texel in 0.3 m of snow at 16 bits, less 7 units.
    let rise = (34f64.to_radians().tan() * 0.04 / 0.3 * 65_535.0).floor() as u32;
    assert_eq!((r.threshold_x, r.threshold_z), (rise - 7, rise - 7));
    assert_eq!((r.width, r.height, r.scratch), (100, 100, 0));
    assert_eq!(r.rect, [46, 46, 33, 33]);
    assert_eq!(plan.sizes.relax_scratch, 33 * 33 * 4);

    // Nothing touches them now: the sand settles (one update fewer to go) over its rectangle
    // grown by the steps, the snow is left.
    let idle = vec![vec![], vec![]];
    let mut surfaces = inputs(&descs, &idle, 0.1);
    surfaces[0].settle = Settle { updates: 3, rect };
    let plan = FramePlan::build(&settings(), surfaces.clone(), no_meshes);
    let grown = Rect {
        x0: 38,
        y0: 38,
        x1: 87,
        y1: 87,
    };
    assert_eq!(
        plan.settles,
        vec![
            (
                0,
                Settle {
                    updates: 2,
                    rect: grown
                }
            ),
            (1, Settle::default())
        ]
    );
    assert_eq!(
        plan.surfaces,
        vec![PlannedSurface {
            index: 0,
            captured: false
        }]
    );
    assert_eq!(plan.relax.records[0].rect, [38, 38, 49, 49]);
    surfaces[0].settle = Settle::default();
    let plan = FramePlan::build(&settings(), surfaces, no_meshes);
    assert!(plan.is_empty() && plan.relax.is_empty());
}

/// The update's own cast takes workgroups of 128 invocations from `cast_many_from` of its tiles
/// in a frame, and of 256 below.
#[test]
fn the_cast_is_narrowed_from_its_many_tiles() {
    let descs = [still("a", 0.0), still("b", 10.0)];
    let deformers = vec![
        vec![sphere_at([0.5, 0.1, 0.5]), sphere_at([-1.0, 0.1, -1.0])],
        vec![sphere_at([10.0, 0.1, 1.0])],
    ];
    let plan_from = |from: u32| {
        let mut s = settings();
        s.capture_path = capture::CapturePath::Update;
        s.cast_many_from = from;
        FramePlan::build(&s, inputs(&descs, &deformers, 0.1), no_meshes).accumulate
    };
    let tiles = plan_from(u32::MAX).cast_tiles;
    assert!(tiles >= 3, "three spheres reach {tiles} tiles");
    for (from, many) in [
        (0, true),
        (tiles, true),
        (tiles + 1, false),
        (u32::MAX, false),
    ] {
        let a = plan_from(from);
        assert_eq!((a.cast_tiles, a.cast_many), (tiles, many), "from {from}");
    }
}
