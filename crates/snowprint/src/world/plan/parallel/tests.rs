//! A plan split over threads is the serial plan: every vector, in the same order, bit for bit.

use glam::{Quat, Vec3};

use super::super::*;
use super::{
    AUTO_THREADS_MAX, NoPrims, Opened, PrimsPiece, PrimsTarget, RUN_MIN, RUNS_A_THREAD, SPLIT_FROM,
};
use crate::deformer::{Pose, Shape};
use crate::ground::{GroundField, SlopeRule};
use crate::material::Material;
use wgpu::WriteOnly;

/// A small deterministic generator (xorshift), so that a failure is reproduced by its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// True one time in `n`.
    fn one_in(&mut self, n: u64) -> bool {
        self.next().is_multiple_of(n)
    }
}

/// Mesh 0 is registered (a box's corners), every other mesh is not (its deformers are refused).
struct Meshes;

const CORNERS: [Vec3; 4] = [
    Vec3::new(-0.2, -0.1, -0.2),
    Vec3::new(0.2, -0.1, 0.2),
    Vec3::new(-0.2, 0.1, 0.2),
    Vec3::new(0.2, 0.1, -0.2),
];

impl PlanMeshes for Meshes {
    fn radius(&self, id: MeshId) -> Option<f32> {
        (id.0 == 0).then_some(0.3)
    }

    fn vertices(&self, id: MeshId) -> Option<&[Vec3]> {
        (id.0 == 0).then_some(&CORNERS[..])
    }
}

/// A deformer near `c` (world), of any shape, moving or not; one in `refuse` is refused (a
/// negative radius, or a mesh not registered).
fn deformer(rng: &mut Rng, c: Vec3, refuse: u64) -> Deformer {
    let at = |rng: &mut Rng| {
        let p = c + Vec3::new(
            rng.range(-3.0, 3.0),
            rng.range(0.0, 0.6),
            rng.range(-3.0, 3.0),
        );
        Pose {
            position: p,
            rotation: Quat::from_rotation_y(rng.range(0.0, 6.0)),
        }
    };
    let shape = match rng.next() % 5 {
        0 | 1 => Shape::Sphere {
            radius: rng.range(0.05, 0.4),
        },
        2 => Shape::Capsule {
            radius: rng.range(0.05, 0.2),
            half_height: rng.range(0.05, 0.5),
        },
        3 => Shape::Box {
            half_extents: Vec3::new(rng.range(0.05, 0.3), 0.1, rng.range(0.05, 0.3)),
        },
        _ => Shape::Mesh(MeshId(0)),
    };
    let shape = match (refuse > 0 && rng.one_in(refuse), rng.one_in(2)) {
        (false, _) => shape,
        (true, true) => Shape::Sphere { radius: -0.1 },
        (true, false) => Shape::Mesh(MeshId(3)),
    };
    let pose = at(rng);
    if rng.one_in(3) {
        Deformer::new(shape, pose)
    } else {
        Deformer::moving(shape, at(rng), pose)
    }
}

/// A frame of `n` surfaces on a grid: yawed or not, refilling or not, slumping or not, on hills
/// or flat ground, each with a list of its own (some empty) or the shared `long` list.
struct Frame {
    descs: Vec<SurfaceDesc>,
    fields: Vec<Option<GroundField>>,
    lists: Vec<Vec<Deformer>>,
    long: Vec<Deformer>,
    shared: Vec<bool>,
}

fn frame(seed: u64, n: usize, refuse: u64) -> Frame {
    let mut rng = Rng(seed | 1);
    let mut f = Frame {
        descs: Vec::new(),
        fields: Vec::new(),
        lists: Vec::new(),
        long: Vec::new(),
        shared: Vec::new(),
    };
    for i in 0..n {
        let c = Vec3::new(
            (i % 32) as f32 * 7.0,
            rng.range(-0.5, 0.5),
            (i / 32) as f32 * 7.0,
        );
        let size = [rng.range(2.0, 5.0), rng.range(2.0, 5.0)];
        let mut desc = SurfaceDesc::new(&format!("s{i}"), c.to_array(), size, 0.3);
        desc.yaw_degrees = if rng.one_in(2) {
            rng.range(0.0, 90.0)
        } else {
            0.0
        };
        desc.replenish_rate = if rng.one_in(3) {
            rng.range(0.0, 0.5)
        } else {
            0.0
        };
        if rng.one_in(4) {
            desc.material = Material::sand();
        }
        let field = rng.one_in(3).then(|| {
            let layout = SurfaceLayout::for_size_capped(desc.size, 128);
            let (w, h) = (layout.width, layout.height);
            let (a, k) = (rng.range(0.0, 0.3), rng.range(0.5, 3.0));
            let ground = (0..w * h)
                .map(|t| a * ((t % w) as f32 * k / w as f32).sin() * ((t / w) as f32 / h as f32))
                .collect();
            GroundField::build(layout, desc.size, ground, 0.3, SlopeRule::default())
        });
        let count = rng.next() % 12;
        f.lists
            .push((0..count).map(|_| deformer(&mut rng, c, refuse)).collect());
        f.shared.push(rng.one_in(5));
        f.descs.push(desc);
        f.fields.push(field);
    }
    // The shared list: deformers over every fourth surface (long enough to be indexed).
    for i in (0..n).step_by(4) {
        let c = f.descs[i].center;
        f.long.extend((0..3).map(|_| deformer(&mut rng, c, 0)));
    }
    assert!(f.long.len() >= crate::world::nearby::INDEX_FROM);
    f
}

/// The frame's surfaces as the plan takes them; every 97th is `None` (a surface the world no
/// longer has).
fn surfaces(f: &Frame) -> Vec<Option<PlanSurface<'_>>> {
    let (mut word, mut ground) = (0, 0);
    (0..f.descs.len())
        .map(|i| {
            let desc = &f.descs[i];
            let layout = SurfaceLayout::for_size_capped(desc.size, 128);
            let field = f.fields[i].as_ref();
            let plan_ground = field.map(|g| {
                let region = capture::region_texels(layout.width, layout.height);
                let p = PlanGround {
                    offset: ground,
                    codes: ground,
                    range: g.range(),
                };
                ground += region;
                p
            });
            let s = PlanSurface {
                index: i,
                id: SurfaceId(i as u32, 0),
                desc,
                layout,
                heights_word: word,
                normals_word: None,
                wrap: 0,
                carry: (i % 7) as f64 / 7.0,
                elapsed: 1.0 / 30.0,
                deformers: if f.shared[i] { &f.long } else { &f.lists[i] },
                settle: Settle {
                    updates: (i % 3) as u32,
                    rect: crate::relax::Rect {
                        x0: 1,
                        y0: 2,
                        x1: 9,
                        y1: 7,
                    },
                },
                ground: plan_ground,
                ground_field: field,
            };
            word += layout.width * layout.height;
            (i % 97 != 50).then_some(s)
        })
        .collect()
}

/// Every public vector and table of the plan, the primitives (in their runs, as the GPU gets
/// them) as bytes.
fn assert_same(serial: &FramePlan, split: &FramePlan, case: &str) {
    assert_eq!(serial.surfaces, split.surfaces, "{case}: surfaces");
    let bytes = |p: &FramePlan| -> Vec<u8> {
        p.prims()
            .flat_map(|run| bytemuck::cast_slice::<_, u8>(run).to_vec())
            .collect()
    };
    assert_eq!(bytes(serial), bytes(split), "{case}: primitive bytes");
    assert_eq!(serial.prims_len(), split.prims_len(), "{case}: primitives");
    let rest = |p: &FramePlan| {
        let mut c = p.capture.clone();
        c.prims.clear();
        c
    };
    assert_eq!(rest(serial), rest(split), "{case}: capture");
    assert_eq!(serial.accumulate, split.accumulate, "{case}: accumulate");
    assert_eq!(serial.carries, split.carries, "{case}: carries");
    assert_eq!(serial.relax, split.relax, "{case}: relax");
    assert_eq!(serial.settles, split.settles, "{case}: settles");
    assert_eq!(serial.sizes, split.sizes, "{case}: sizes");
    assert_eq!(serial.footsteps, split.footsteps, "{case}: footsteps");
    assert_eq!(serial.refused, split.refused, "{case}: refused");
    let mut tables = (Vec::new(), Vec::new());
    for (plan, bytes) in [(serial, &mut tables.0), (split, &mut tables.1)] {
        bytes.extend_from_slice(bytemuck::cast_slice(&plan.accumulate.records));
        bytes.extend_from_slice(bytemuck::cast_slice(&plan.capture.views));
        if !plan.capture.work.is_empty() {
            capture::append_work_table(&plan.capture, bytes);
        }
    }
    assert!(tables.0 == tables.1, "{case}: written tables");
}

/// A piece of a test's memory.
impl PrimsPiece for &mut [u8] {
    fn fill(self, bytes: &[u8]) {
        self.copy_from_slice(bytes);
    }
}

/// Memory for the primitives, cut into a piece a run as the world's ring is, or whole as the
/// queue's staging (`.2`), filled with a byte no plan writes whole, so that a primitive left out
/// shows; the runs' lengths as asked.
struct Staging<'m>(Option<&'m mut [u8]>, Vec<usize>, bool);

impl<'m> PrimsTarget for Staging<'m> {
    type Piece = &'m mut [u8];

    fn open(&mut self, lens: &[usize]) -> Option<Opened<'_, Self::Piece>> {
        let mut rest = self.0.take()?;
        rest.fill(0xa5);
        self.1 = lens.to_vec();
        if self.2 {
            return Some(Opened::Whole(WriteOnly::from(rest)));
        }
        let pieces = lens.iter().map(|&len| {
            let (piece, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            (len > 0).then_some(piece)
        });
        Some(Opened::Pieces(pieces.collect()))
    }
}

#[test]
fn split_plan_is_the_serial_plan() {
    let paths = [
        capture::CapturePath::Update,
        capture::CapturePath::Compute,
        capture::CapturePath::Raster,
    ];
    for (seed, path) in [11, 12, 13, 14, 15, 16]
        .into_iter()
        .zip(paths.iter().cycle())
    {
        // Some frames refuse a deformer of a short list (checked in the plan's walk).
        let refuse = if seed % 2 == 0 { 40 } else { 0 };
        let f = frame(seed, 700, refuse);
        let items = surfaces(&f);
        let mut settings = PlanSettings::of(&WorldConfig::default());
        settings.capture_path = *path;
        // Low thresholds, so that the frame lists its tiles and streams its refill.
        settings.list_tiles_from = if seed < 14 { 0 } else { u32::MAX };
        settings.refill_stream_from = if seed % 3 == 0 { 0 } else { u32::MAX };
        settings.atlas_side = 4096;
        let mut serial = FramePlan {
            check_short_lists: true,
            ..Default::default()
        };
        serial.rebuild(&settings, items.iter().flatten().copied(), Meshes);
        assert!(serial.capture.prims.len() > 1000 && !serial.footsteps.is_empty());
        assert!(
            serial.jobs.iter().any(|j| j.way == Way::Cast)
                == (*path == capture::CapturePath::Update)
        );
        assert_eq!(serial.refused, refuse > 0, "seed {seed}");
        let mut split = FramePlan {
            check_short_lists: true,
            ..Default::default()
        };
        for threads in [2, 3, 5] {
            // The later passes reuse the parts' memory, and copy the primitives into memory
            // opened for them as the world's staging: a piece a run, or whole.
            for pass in 0..3 {
                let serial_bytes: &[u8] = bytemuck::cast_slice(&serial.capture.prims);
                let mut memory = vec![0u8; serial_bytes.len()];
                let mut staging = Staging(Some(&mut memory[..]), Vec::new(), pass == 2);
                let target = (pass > 0).then_some(&mut staging);
                split.rebuild_split(&settings, &items, |s| *s, Meshes, (threads, target));
                let case = format!("seed {seed}, {threads} threads, pass {pass}");
                assert_same(&serial, &split, &case);
                assert_eq!(split.prims_written, pass > 0, "{case}");
                if pass > 0 {
                    // A piece a run, the plan's own first.
                    assert_eq!(staging.1.len(), split.parts.len() + 1, "{case}");
                    assert!(memory == serial_bytes, "{case}: primitives copied");
                }
            }
        }
        // 5 threads: 8 runs a thread, of 18 surfaces (unless that is shorter than RUN_MIN / 4),
        // so 39 runs; the first is planned into the plan itself.
        let run = 700usize.div_ceil(5 * RUNS_A_THREAD).max(RUN_MIN / 4);
        assert_eq!(split.parts.len(), 700usize.div_ceil(run) - 1);
        // Memory not opened: the primitives are left to be written from the parts.
        split.rebuild_split(&settings, &items, |s| *s, Meshes, (3, Some(&mut NoPrims)));
        assert!(!split.prims_written);
        assert_same(&serial, &split, &format!("seed {seed}, not opened"));
        // Planned serially again, the plan leaves the parts' primitives behind.
        split.rebuild_split(&settings, &items, |s| *s, Meshes, (1, None::<&mut NoPrims>));
        assert_same(&serial, &split, &format!("seed {seed}, serial after split"));
    }
}

#[test]
fn few_surfaces_are_planned_serially() {
    let f = frame(3, SPLIT_FROM - 1, 0);
    let items = surfaces(&f);
    let settings = PlanSettings::of(&WorldConfig::default());
    let mut plan = FramePlan::default();
    plan.rebuild_split(&settings, &items, |s| *s, Meshes, (4, None::<&mut NoPrims>));
    assert!(plan.parts.is_empty());
    let serial = FramePlan::build(&settings, items.iter().flatten().copied(), Meshes);
    assert_same(&serial, &plan, "serial");
}

#[test]
fn zero_threads_means_the_machine_s() {
    assert!((1..=AUTO_THREADS_MAX).contains(&plan_threads(0)));
    assert_eq!(plan_threads(3), 3);
}
