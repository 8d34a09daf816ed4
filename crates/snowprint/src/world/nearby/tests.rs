//! The grid against the all-pairs tests it stands in for: every deformer the capture's ball test
//! or the footstep test keeps is offered, in the list's order, once.

use glam::{Quat, Vec3};
use proptest::prelude::*;

use super::*;
use crate::capture::{CaptureVolume, GpuPrimitive, MeshDraw};
use crate::deformer::{Pose, Shape};
use crate::mesh::MeshId;
use crate::surface::{SurfaceId, SurfaceLayout};
use crate::world::WorldConfig;
use crate::world::footstep::{Footstep, landing_on};
use crate::world::plan::{FramePlan, PlanMeshes, PlanSettings, PlanSurface};

/// A deformer: shape kind (sphere, capsule, box, mesh), sizes, position, step, rotations, and
/// whether it moved.
type DeformerSeed = (u8, [f32; 3], [f32; 3], [f32; 3], [[f32; 4]; 2], bool);

fn deformer_seed() -> impl Strategy<Value = DeformerSeed> {
    (
        0u8..4,
        prop::array::uniform3(0.02f32..1.5),
        // Over and around the surfaces, some far above or below them.
        (-40.0f32..40.0, -3.0f32..3.0, -40.0f32..40.0).prop_map(|(x, y, z)| [x, y, z]),
        prop::array::uniform3(-4.0f32..4.0),
        [
            prop::array::uniform4(-1.0f32..1.0),
            prop::array::uniform4(-1.0f32..1.0),
        ],
        any::<bool>(),
    )
}

fn rotation(q: [f32; 4]) -> Quat {
    let q = Quat::from_array(q);
    if q.length() < 1e-3 {
        Quat::IDENTITY
    } else {
        q.normalize()
    }
}

fn deformer((kind, [a, b, c], at, step, [q0, q1], moved): DeformerSeed) -> Deformer {
    let shape = match kind {
        0 => Shape::Sphere { radius: a },
        1 => Shape::Capsule {
            radius: a,
            half_height: b,
        },
        2 => Shape::Box {
            half_extents: Vec3::new(a, b, c),
        },
        _ => Shape::Mesh(MeshId(0)),
    };
    let to = Pose {
        position: Vec3::from(at),
        rotation: rotation(q1),
    };
    if !moved {
        return Deformer::new(shape, to);
    }
    let from = Pose {
        position: Vec3::from(at) - Vec3::from(step),
        rotation: rotation(q0),
    };
    Deformer::moving(shape, from, to)
}

/// A surface: centre `(x, z)`, size, yaw in degrees, snow depth.
type SurfaceSeed = ([f32; 2], [f32; 2], f32, f32);

fn surface_seed() -> impl Strategy<Value = SurfaceSeed> {
    (
        prop::array::uniform2(-40.0f32..40.0),
        prop::array::uniform2(0.3f32..12.0),
        0.0f32..360.0,
        0.05f32..0.6,
    )
}

fn surface(i: usize, (c, size, yaw, depth): SurfaceSeed) -> SurfaceDesc {
    let mut d = SurfaceDesc::new(&format!("s{i}"), [c[0], 0.0, c[1]], size, depth);
    d.yaw_degrees = yaw;
    d.replenish_rate = 0.0;
    d
}

/// The capture volume the plan culls a surface's deformers against.
fn volume(desc: &SurfaceDesc) -> CaptureVolume {
    CaptureVolume {
        world_to_local: desc.world_to_local(),
        half_size: CaptureVolume::of_region(
            desc.size * 0.5,
            desc.layout().width,
            desc.layout().height,
        ),
        frustum_height: desc.snow_depth + WorldConfig::default().capture.ankle_height,
        ground: (0.0, 0.0),
    }
}

/// The mesh's radius and its vertices (a box's corners), for both tests.
const MESH_RADIUS: f32 = 0.5;
fn mesh_vertices(_: MeshId) -> Option<&'static [Vec3]> {
    const H: f32 = 0.28;
    const CORNERS: [Vec3; 8] = [
        Vec3::new(-H, -H, -H),
        Vec3::new(H, -H, -H),
        Vec3::new(-H, H, -H),
        Vec3::new(H, H, -H),
        Vec3::new(-H, -H, H),
        Vec3::new(H, -H, H),
        Vec3::new(-H, H, H),
        Vec3::new(H, H, H),
    ];
    Some(&CORNERS)
}

/// Every mesh is registered with [`MESH_RADIUS`] and [`mesh_vertices`].
struct TestMeshes;

impl PlanMeshes for TestMeshes {
    fn radius(&self, _: MeshId) -> Option<f32> {
        Some(MESH_RADIUS)
    }

    fn vertices(&self, id: MeshId) -> Option<&[Vec3]> {
        mesh_vertices(id)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every surface is offered, ascending and once each, a superset of the deformers that the
    /// capture's swept-ball test keeps (meshes always) and of those that land on it; so the exact
    /// tests run on the offered deformers keep exactly what they kept on the whole list.
    #[test]
    fn the_grid_offers_every_deformer_the_all_pairs_tests_keep(
        seeds in prop::collection::vec(deformer_seed(), INDEX_FROM..300),
        surfaces in prop::collection::vec(surface_seed(), 1..24),
    ) {
        let deformers: Vec<Deformer> = seeds.into_iter().map(deformer).collect();
        let mut grid = NearbyDeformers::default();
        grid.index(&deformers);
        prop_assert!(grid.is_for(&deformers));
        let mut near = Vec::new();
        for (k, seed) in surfaces.into_iter().enumerate() {
            let desc = surface(k, seed);
            let vol = volume(&desc);
            grid.near(surface_rect(&desc, vol.half_size), &mut near);
            prop_assert!(near.windows(2).all(|w| w[0] < w[1]), "not ascending once: {near:?}");
            prop_assert!(near.last().is_none_or(|&i| (i as usize) < deformers.len()));
            let m = desc.world_to_local();
            let kept = |i: usize| {
                let d = &deformers[i];
                let ball = capture::swept_ball(d).is_none_or(|(c, r)| vol.overlaps_ball(c, r));
                let lands = d.previous.as_ref().is_some_and(|prev| {
                    landing_on((&desc, &m), None, &d.shape, prev, &d.pose, 0.1, mesh_vertices)
                        .is_some()
                });
                ball || lands
            };
            let all: Vec<u32> = (0..deformers.len()).filter(|&i| kept(i)).map(|i| i as u32).collect();
            // What the grid rests on, without its cells (which would hide a square too small):
            // the square of every deformer kept overlaps the surface's rectangle.
            let [x0, z0, x1, z1] = surface_rect(&desc, vol.half_size);
            for &i in &all {
                if let Some([a0, b0, a1, b1]) = deformer_square(&deformers[i as usize]) {
                    prop_assert!(a1 >= x0 && a0 <= x1 && b1 >= z0 && b0 <= z1, "deformer {}", i);
                }
            }
            let offered: Vec<u32> = near.iter().copied().filter(|&i| kept(i as usize)).collect();
            prop_assert_eq!(&offered, &all, "surface {} offered {:?}", k, &near);
        }
    }

    /// A plan over surfaces that share one long list draws, surface by surface, exactly what the
    /// capture's culling draws from the whole list: the same primitives and mesh draws in the
    /// same order; and it finds the footsteps the test of every pair finds, in the same order.
    #[test]
    fn a_shared_list_plans_what_every_pair_plans(
        seeds in prop::collection::vec(deformer_seed(), INDEX_FROM..200),
        surfaces in prop::collection::vec(surface_seed(), 1..16),
    ) {
        let deformers: Vec<Deformer> = seeds.into_iter().map(deformer).collect();
        let descs: Vec<SurfaceDesc> =
            surfaces.into_iter().enumerate().map(|(k, s)| surface(k, s)).collect();
        let mut word = 0;
        let inputs: Vec<PlanSurface<'_>> = descs
            .iter()
            .enumerate()
            .map(|(index, desc)| {
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
                    elapsed: 0.1,
                    deformers: &deformers,
                    settle: Default::default(),
                    ground: None,
                    ground_field: None,
                };
                word += layout.width * layout.height;
                s
            })
            .collect();
        let settings = PlanSettings::of(&WorldConfig::default());
        let plan = FramePlan::build(&settings, inputs, TestMeshes);
        let mut drawn = vec![(Vec::new(), Vec::new()); descs.len()];
        for s in &plan.capture.surfaces {
            let index = plan.surfaces[s.record as usize].index;
            let c = &plan.capture;
            drawn[index] = (
                c.prims[s.prims.start as usize..s.prims.end as usize].to_vec(),
                c.draws[s.draws.start as usize..s.draws.end as usize].to_vec(),
            );
        }
        for (index, desc) in descs.iter().enumerate() {
            let vol = volume(desc);
            let (mut prims, mut draws): (Vec<GpuPrimitive>, Vec<MeshDraw>) = (vec![], vec![]);
            let mut meshes = Vec::new();
            for d in &deformers {
                match d.shape {
                    Shape::Mesh(id) => {
                        capture::push_mesh_draws(d, id, MESH_RADIUS, &vol, &mut draws, &mut meshes)
                    }
                    _ => capture::push_primitives(d, &vol, &mut prims),
                }
            }
            prop_assert_eq!(&drawn[index].0, &prims, "primitives of surface {}", index);
            prop_assert_eq!(&drawn[index].1, &draws, "mesh draws of surface {}", index);
        }
        // The footsteps, surface by surface and deformer by deformer.
        let mut steps = Vec::new();
        for (index, desc) in descs.iter().enumerate() {
            let m = desc.world_to_local();
            for (i, d) in deformers.iter().enumerate() {
                let Some(prev) = d.previous.as_ref() else { continue };
                if let Some((point, depth_m, speed)) =
                    landing_on((desc, &m), None, &d.shape, prev, &d.pose, 0.1, mesh_vertices)
                {
                    let surface = SurfaceId(index as u32, 0);
                    steps.push(Footstep { deformer: i, surface, point, depth_m, speed });
                }
            }
        }
        prop_assert_eq!(&plan.footsteps, &steps);
    }
}

#[test]
fn a_surface_far_from_every_deformer_is_offered_only_the_meshes() {
    let mut deformers: Vec<Deformer> = (0..INDEX_FROM)
        .map(|i| {
            Deformer::new(
                Shape::Sphere { radius: 0.2 },
                Pose::at([i as f32, 0.0, 0.0]),
            )
        })
        .collect();
    deformers.push(Deformer::new(Shape::Mesh(MeshId(0)), Pose::at([0.0; 3])));
    let mut grid = NearbyDeformers::default();
    grid.index(&deformers);
    let mut near = Vec::new();
    let far = SurfaceDesc::new("far", [0.0, 0.0, 500.0], [4.0, 4.0], 0.3);
    grid.near(surface_rect(&far, far.size * 0.5), &mut near);
    assert_eq!(near, vec![INDEX_FROM as u32]);
    // Over the spheres 10 to 12 (a 4 m square at x = 11, their balls 0.2 m and a margin).
    let over = SurfaceDesc::new("over", [11.0, 0.0, 0.0], [2.0, 2.0], 0.3);
    grid.near(surface_rect(&over, over.size * 0.5), &mut near);
    assert!([10, 11, 12].iter().all(|i| near.contains(i)), "{near:?}");
    assert!(near.len() <= 8, "{near:?}");
    assert_eq!(near.last(), Some(&(INDEX_FROM as u32)));
}
