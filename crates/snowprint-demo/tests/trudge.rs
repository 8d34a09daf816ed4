//! The rendered demo's people trudge (`trudge::Crowd`, driven by `scene::rooftops`): with the demo
//! world's own roofs and walker on the GPU, a walker in the walk roof's 0.25 m of snow falls behind
//! the same walk over 10 cm of snow and over bare ground, and sinks; its prints in the snow are
//! those of its own clock; two runs give the same clocks and the same snow bit for bit.

mod common;

use glam::Vec3;
use snowprint::{Heightmap, MeshId, SnowWorld, SurfaceDesc, SurfaceId, WorldConfig};
use snowprint_demo::anim::Action;
use snowprint_demo::trudge::{Crowd, Trudge, pace, sink, sunk_pose};
use snowprint_demo::world::surface;
use snowprint_demo::{DemoSurface, DemoWorld, PART_COUNT, Part, Person};

const DT: f32 = 1.0 / 30.0;
/// Frames run: 4.5 s, the walker's walk well under way.
const FRAMES: u32 = 135;
/// Where the shallow and the bare walks are, from the walker's.
const SHALLOW: Vec3 = Vec3::new(0.0, 0.0, -30.0);
const BARE: Vec3 = Vec3::new(0.0, 0.0, -60.0);

/// `p`'s walk moved by `offset`.
fn moved(p: &Person, name: &'static str, surface: usize, offset: Vec3) -> Person {
    let mut p = p.clone();
    p.name = name;
    p.surface = surface;
    for seg in &mut p.motion.segments {
        let Action::Gait(g) = &mut seg.action else {
            panic!("the walker only walks");
        };
        g.footfalls.iter_mut().for_each(|f| f.ankle += offset);
        g.path.iter_mut().for_each(|k| k.position += offset);
    }
    p
}

/// The demo world with its walker alone, and two copies of the walk: over a copy of the walk roof
/// with 10 cm of snow, and over nothing.
fn three_walks() -> DemoWorld {
    let mut demo = DemoWorld::build();
    let walker = demo.person("walker").expect("walker").clone();
    let mut shallow = demo.surfaces[surface::WALK_ROOF].clone();
    shallow.desc.name = "shallow".into();
    shallow.desc.center += SHALLOW;
    shallow.desc.snow_depth = 0.1;
    demo.surfaces.push(DemoSurface { ..shallow });
    let shallow_index = demo.surfaces.len() - 1;
    demo.people = vec![
        moved(&walker, "walker", surface::WALK_ROOF, Vec3::ZERO),
        moved(&walker, "shallow", shallow_index, SHALLOW),
        moved(&walker, "bare", shallow_index, BARE),
    ];
    demo
}

struct Run {
    clocks: Vec<Trudge>,
    crowd: Crowd,
    walk_roof: Heightmap,
    desc: SurfaceDesc,
}

fn run(demo: &DemoWorld) -> Run {
    let mut world = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
    let ids: Vec<SurfaceId> = demo
        .surfaces
        .iter()
        .map(|s| world.add_surface(s.desc.clone()).expect("surface"))
        .collect();
    let parts: Vec<MeshId> = demo
        .part_meshes
        .iter()
        .zip(Part::ALL)
        .map(|(m, p)| world.add_mesh(p.name(), m).expect("part"))
        .collect();
    let mut crowd = Crowd::new(demo, 0);
    for _ in 0..FRAMES {
        crowd
            .step(demo, &mut world, DT, &ids, &parts)
            .expect("a trudging step");
    }
    Run {
        clocks: (0..3)
            .map(|i| crowd.trudge(i).expect("a trudge").clone())
            .collect(),
        crowd,
        walk_roof: world
            .read_heightmap(ids[surface::WALK_ROOF])
            .expect("readback"),
        desc: demo.surfaces[surface::WALK_ROOF].desc.clone(),
    }
}

/// Deepest pressed fraction of the walk roof within `r` metres of a world point.
fn pressed_near(run: &Run, p: Vec3, r: f32) -> f32 {
    let map = &run.walk_roof;
    let local = run.desc.world_to_local().transform_point3(p);
    let texel = run.desc.size.x / map.width as f32;
    let mut deepest = 0.0f32;
    for row in 0..map.height {
        for col in 0..map.width {
            let x = -0.5 * run.desc.size.x + (col as f32 + 0.5) * texel;
            let z = -0.5 * run.desc.size.y + (row as f32 + 0.5) * texel;
            if (x - local.x).hypot(z - local.z) <= r {
                deepest = deepest.max(map.fraction(col, row));
            }
        }
    }
    deepest
}

#[test]
fn a_walker_in_deep_snow_falls_behind_and_sinks() {
    let demo = three_walks();
    let run = run(&demo);
    let [deep, shallow, bare] = [0, 1, 2].map(|i| &run.clocks[i]);
    let elapsed = FRAMES as f32 * DT;
    eprintln!(
        "after {elapsed} s: clocks {} / {} / {}, depths {} / {} / {}, sinks {} / {} / {}, late reads {} / {} / {}",
        deep.clock,
        shallow.clock,
        bare.clock,
        deep.depth,
        shallow.depth,
        bare.depth,
        deep.sink,
        shallow.sink,
        bare.sink,
        deep.late,
        shallow.late,
        bare.late
    );
    // Over nothing, the walk keeps the world's time and its height: exactly the scripted walk.
    assert!((bare.clock - elapsed).abs() < 1e-4, "{}", bare.clock);
    assert_eq!((bare.depth, bare.sink), (0.0, 0.0));
    let scripted = demo.people[2].pose_at(bare.clock).world();
    let parts = run.crowd.parts();
    for part in Part::ALL {
        let got = parts[2 * PART_COUNT + part.index()].pose;
        assert!(got.position.distance(scripted[part.index()].position) < 1e-5);
    }
    // The snow is never deeper than the surface's, so the pace never drops below its pace; the
    // walk in 0.25 m loses more than a second in 4.5 s (an average depth above 0.1 m), the one in
    // 10 cm some (at most what its pace bound allows).
    assert!(deep.clock >= elapsed * pace(0.25), "{}", deep.clock);
    assert!(deep.clock < elapsed - 1.0, "{}", deep.clock);
    assert!(shallow.clock >= elapsed * pace(0.1), "{}", shallow.clock);
    assert!(shallow.clock < elapsed - 0.2, "{}", shallow.clock);
    assert!(deep.clock < shallow.clock - 0.5);
    // Sunk: the pelvis lower than the scripted walk's at the same clock, by the sink, and more in
    // deep snow than in shallow.
    assert!(deep.sink > 0.05 && deep.sink <= sink(0.25), "{}", deep.sink);
    assert!(shallow.sink <= sink(0.1) && shallow.sink < deep.sink);
    let pelvis = parts[Part::Pelvis.index()].pose.position;
    let upright = demo.people[0].pose_at(deep.clock).root;
    assert!((upright.y - pelvis.y - deep.sink).abs() < 1e-5);
    assert_eq!(
        pelvis,
        sunk_pose(&demo.people[0], deep.clock, deep.sink).root
    );
    // The snow shows the trudging walk: every print struck by the walker's own clock (a frame
    // for its weight to arrive) is in the snow (the flat boot stops 7 cm above the roof: 0.72 of
    // the 0.25 m, less the blur's share at the edges), and none of those the script would have
    // struck by now.
    let walker = &demo.people[0];
    let footfalls = walker.footfalls();
    let made: Vec<_> = footfalls
        .iter()
        .filter(|f| f.strike < deep.clock - 0.1)
        .collect();
    let not_yet: Vec<_> = footfalls
        .iter()
        .filter(|f| f.strike > deep.clock && f.strike < elapsed)
        .collect();
    assert!(
        made.len() >= 4 && not_yet.len() >= 2,
        "{} {}",
        made.len(),
        not_yet.len()
    );
    for f in made {
        let d = pressed_near(&run, f.print_center(), 0.06);
        assert!(d > 0.45, "print at {} only {d} deep", f.strike);
    }
    for f in not_yet {
        let d = pressed_near(&run, f.print_center(), 0.06);
        assert!(
            d < 0.05,
            "a print at {} the walker has not reached: {d}",
            f.strike
        );
    }
}

/// Probe answers are read exactly `LAG` updates after their probe, waiting for late ones: two
/// runs give the same clocks, poses and snow, bit for bit.
#[test]
fn trudging_is_deterministic() {
    let demo = three_walks();
    let (a, b) = (run(&demo), run(&demo));
    for (x, y) in a.clocks.iter().zip(&b.clocks) {
        assert_eq!(
            (x.clock.to_bits(), x.sink.to_bits()),
            (y.clock.to_bits(), y.sink.to_bits())
        );
    }
    assert_eq!(a.crowd.parts(), b.crowd.parts());
    assert!(a.walk_roof == b.walk_roof, "the snow differs");
}
