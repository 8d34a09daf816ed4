//! The demo world on the GPU: the whole scene runs through a `SnowWorld` at 30 Hz and the
//! heightmaps are measured: one print per footfall with a heel and a toe, a long slide trench, a
//! body-sized fall imprint, a snow angel with fans, and untouched snow where nobody went.
//!
//! Set `SNOWPRINT_DEMO_OUT` to a folder to get every heightmap as a 16-bit PNG.

mod common;

use std::collections::VecDeque;
use std::sync::OnceLock;

use glam::{Vec2, Vec3};
use snowprint::{
    CaptureConfig, Heightmap, MeshId, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    SurfaceUpdate, WorldConfig,
};
use snowprint_demo::anim::Action;
use snowprint_demo::skeleton::dims;
use snowprint_demo::world::surface;
use snowprint_demo::{DemoWorld, Part, Person};

const DT: f32 = 1.0 / 30.0;
/// A texel counts as pressed from this fraction of the snow depth.
const PRESSED: f32 = 0.25;

fn new_world() -> SnowWorld {
    SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world")
}

fn add_parts(world: &mut SnowWorld, demo: &DemoWorld) -> Vec<MeshId> {
    demo.part_meshes
        .iter()
        .zip(Part::ALL)
        .map(|(m, p)| world.add_mesh(p.name(), m).expect("part mesh"))
        .collect()
}

/// Run `demo` from `t0` to `t1` over the given surfaces (indices into `demo.surfaces`, or
/// replacement descriptions) and return their heightmaps.
fn simulate(demo: &DemoWorld, surfaces: &[SurfaceDesc], t0: f32, t1: f32) -> Vec<Heightmap> {
    let mut world = new_world();
    let ids: Vec<SurfaceId> = surfaces
        .iter()
        .map(|d| world.add_surface(d.clone()).expect("surface"))
        .collect();
    let parts = add_parts(&mut world, demo);
    // The demo's deformers are sorted against its own surfaces; map them onto ours.
    let probe = DemoWorld {
        surfaces: surfaces
            .iter()
            .map(|d| snowprint_demo::DemoSurface {
                desc: d.clone(),
                ground: Default::default(),
            })
            .collect(),
        ..demo.clone()
    };
    let ankle = CaptureConfig::default().ankle_height;
    let frames = ((t1 - t0) / DT).round() as u32;
    for f in 1..=frames {
        let t = t0 + f as f32 * DT;
        let sorted = probe.surface_deformers(t, DT, &parts, ankle);
        let updates: Vec<SurfaceUpdate<'_>> = sorted
            .iter()
            .map(|(i, d)| SurfaceUpdate {
                surface: ids[*i],
                elapsed: DT,
                deformers: d,
            })
            .collect();
        world.update(&updates).expect("update");
    }
    ids.iter()
        .map(|&id| world.read_heightmap(id).expect("readback"))
        .collect()
}

struct Run {
    demo: DemoWorld,
    maps: Vec<Heightmap>,
}

/// The whole demo, once for all tests.
fn run() -> &'static Run {
    static RUN: OnceLock<Run> = OnceLock::new();
    RUN.get_or_init(|| {
        let demo = DemoWorld::build();
        let descs: Vec<SurfaceDesc> = demo.surfaces.iter().map(|s| s.desc.clone()).collect();
        let maps = simulate(&demo, &descs, 0.0, demo.duration);
        if let Some(dir) = std::env::var_os("SNOWPRINT_DEMO_OUT") {
            let dir = std::path::PathBuf::from(dir);
            std::fs::create_dir_all(&dir).expect("output folder");
            for (s, m) in demo.surfaces.iter().zip(&maps) {
                m.save_png(&dir.join(format!("{}.png", s.desc.name)))
                    .expect("png");
            }
        }
        Run { demo, maps }
    })
}

/// World position of a texel centre (on the ground under the snow).
fn texel_world(desc: &SurfaceDesc, map: &Heightmap, col: u32, row: u32) -> Vec3 {
    let texel = desc.size / Vec2::new(map.width as f32, map.height as f32);
    let local = Vec3::new(
        -0.5 * desc.size.x + (col as f32 + 0.5) * texel.x,
        0.0,
        -0.5 * desc.size.y + (row as f32 + 0.5) * texel.y,
    );
    desc.local_to_world().transform_point3(local)
}

fn texel_area(desc: &SurfaceDesc, map: &Heightmap) -> f32 {
    desc.size.x * desc.size.y / (map.width * map.height) as f32
}

/// A connected region of pressed texels.
struct Blob {
    texels: Vec<(u32, u32)>,
}

impl Blob {
    fn world(&self, desc: &SurfaceDesc, map: &Heightmap) -> Vec<Vec3> {
        self.texels
            .iter()
            .map(|&(c, r)| texel_world(desc, map, c, r))
            .collect()
    }

    /// Extent along a horizontal direction, metres (texel centres, plus one texel).
    fn extent(&self, desc: &SurfaceDesc, map: &Heightmap, dir: Vec3) -> f32 {
        let proj: Vec<f32> = self.world(desc, map).iter().map(|p| p.dot(dir)).collect();
        let (lo, hi) = proj
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        hi - lo + desc.size.x / map.width as f32
    }

    fn area(&self, desc: &SurfaceDesc, map: &Heightmap) -> f32 {
        self.texels.len() as f32 * texel_area(desc, map)
    }

    /// Whether a texel lies within `r` metres of a world point.
    fn near(&self, desc: &SurfaceDesc, map: &Heightmap, p: Vec3, r: f32) -> bool {
        self.world(desc, map)
            .iter()
            .any(|q| Vec2::new(q.x - p.x, q.z - p.z).length() <= r)
    }
}

/// 8-connected regions of texels pressed at least `PRESSED` of the snow depth.
fn blobs(map: &Heightmap) -> Vec<Blob> {
    let (w, h) = (map.width as i32, map.height as i32);
    let pressed = |c: i32, r: i32| map.fraction(c as u32, r as u32) >= PRESSED;
    let mut seen = vec![false; (w * h) as usize];
    let mut out = Vec::new();
    for r0 in 0..h {
        for c0 in 0..w {
            if seen[(r0 * w + c0) as usize] || !pressed(c0, r0) {
                continue;
            }
            let mut texels = Vec::new();
            let mut queue = VecDeque::from([(c0, r0)]);
            seen[(r0 * w + c0) as usize] = true;
            while let Some((c, r)) = queue.pop_front() {
                texels.push((c as u32, r as u32));
                for dr in -1..=1 {
                    for dc in -1..=1 {
                        let (nc, nr) = (c + dc, r + dr);
                        if nc < 0 || nr < 0 || nc >= w || nr >= h {
                            continue;
                        }
                        let i = (nr * w + nc) as usize;
                        if !seen[i] && pressed(nc, nr) {
                            seen[i] = true;
                            queue.push_back((nc, nr));
                        }
                    }
                }
            }
            out.push(Blob { texels });
        }
    }
    out
}

fn person<'a>(demo: &'a DemoWorld, name: &str) -> &'a Person {
    demo.person(name)
        .unwrap_or_else(|| panic!("no {name} in the demo"))
}

/// Where the prints of a person's footfalls are: one centre per distinct spot (a foot planted
/// twice on the same spot, as when the feet come together at the end, leaves one print).
fn print_spots(p: &Person) -> Vec<Vec3> {
    let mut spots: Vec<Vec3> = Vec::new();
    for f in p.footfalls() {
        let c = f.print_center();
        if !spots.iter().any(|s| s.distance(c) < 0.1) {
            spots.push(c);
        }
    }
    spots
}

/// Each print spot matches exactly one blob and each blob exactly one spot.
fn assert_one_blob_per_print(
    name: &str,
    desc: &SurfaceDesc,
    map: &Heightmap,
    spots: &[Vec3],
) -> Vec<usize> {
    let found = blobs(map);
    assert_eq!(
        found.len(),
        spots.len(),
        "{name}: {} separate prints in the snow for {} planted feet",
        found.len(),
        spots.len()
    );
    let mut owner = Vec::new();
    for s in spots {
        let hits: Vec<usize> = (0..found.len())
            .filter(|&i| found[i].near(desc, map, *s, 0.08))
            .collect();
        assert_eq!(
            hits.len(),
            1,
            "{name}: the print at {s} lies in {} blobs",
            hits.len()
        );
        owner.push(hits[0]);
    }
    let mut sorted = owner.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(
        sorted.len(),
        spots.len(),
        "{name}: two footfalls share a print"
    );
    owner
}

#[test]
fn walker_leaves_one_print_per_footfall_each_with_heel_and_toe() {
    let run = run();
    let walker = person(&run.demo, "walker");
    let desc = &run.demo.surfaces[surface::WALK_ROOF].desc;
    let map = &run.maps[surface::WALK_ROOF];
    let spots = print_spots(walker);
    assert!(spots.len() >= 12, "a walk of {} steps", spots.len());
    assert_one_blob_per_print("walker", desc, map, &spots);

    let texel = desc.size.x / map.width as f32;
    let found = blobs(map);
    let fwd = Vec3::X;
    for b in &found {
        // A footprint, not a dent: as long as the boot, about a third as wide.
        let length = b.extent(desc, map, fwd);
        let width = b.extent(desc, map, Vec3::Z);
        assert!(
            (0.8 * dims::FOOT_LENGTH..=dims::FOOT_LENGTH + 3.0 * texel).contains(&length),
            "print {length} m long for a {} m boot",
            dims::FOOT_LENGTH
        );
        assert!(
            length >= 1.8 * width,
            "print {length} x {width} m is no footprint"
        );
        // Heel and toe: along the print, the deepest texel of each cross-section peaks at the heel
        // and again at the ball, with the shallower arch between.
        let cols: Vec<u32> = b.texels.iter().map(|t| t.0).collect();
        let (c0, c1) = (
            *cols.iter().min().unwrap_or(&0),
            *cols.iter().max().unwrap_or(&0),
        );
        let profile: Vec<f32> = (c0..=c1)
            .map(|c| {
                b.texels
                    .iter()
                    .filter(|t| t.0 == c)
                    .map(|t| map.fraction(t.0, t.1))
                    .fold(0.0, f32::max)
            })
            .collect();
        let n = profile.len();
        let third = n / 3;
        let heel = profile[..third].iter().copied().fold(0.0, f32::max);
        let ball = profile[n - third..].iter().copied().fold(0.0, f32::max);
        let arch = profile[third..n - third]
            .iter()
            .copied()
            .fold(f32::MAX, f32::min);
        assert!(
            arch < heel - 0.03 && arch < ball - 0.03,
            "no heel and toe along the print: {profile:?}"
        );
    }
}

#[test]
fn runner_leaves_separate_prints_a_stride_apart() {
    let run = run();
    let runner = person(&run.demo, "runner");
    let desc = &run.demo.surfaces[surface::RUN_ROOF].desc;
    let map = &run.maps[surface::RUN_ROOF];
    let spots = print_spots(runner);
    assert_one_blob_per_print("runner", desc, map, &spots);
    // At full speed consecutive prints (alternate feet) lie more than a metre apart.
    let longest = spots
        .windows(2)
        .map(|w| (w[1].x - w[0].x).abs())
        .fold(0.0, f32::max);
    assert!(longest > 1.0, "longest step {longest} m");
}

#[test]
fn slide_leaves_one_long_trench() {
    let run = run();
    let slider = person(&run.demo, "slider");
    let slide = slider.slide().expect("the slider slides");
    let desc = &run.demo.surfaces[surface::YARD_ROOF].desc;
    let map = &run.maps[surface::YARD_ROOF];
    let dir = snowprint_demo::anim::forward_of(slide.yaw);
    let start = Vec3::new(slide.start.x, desc.center.y, slide.start.y);
    let middle = start + dir * (0.5 * slide.length());
    let found = blobs(map);
    let trench = found
        .iter()
        .find(|b| b.near(desc, map, middle, 0.1))
        .expect("a trench halfway along the slide");
    let length = trench.extent(desc, map, dir);
    let width = trench.extent(desc, map, Vec3::Y.cross(dir).normalize());
    // The pelvis slides `slide.length()`, the first `drop` of it in the air while the body drops
    // onto its back; the body lying on the snow adds its own length (feet to shoulders).
    let d = slide.drop_time;
    let drop = slide.speed * d - 0.5 * slide.decel * d * d;
    let expected = slide.length() - drop + 0.6 * dims::HEIGHT;
    assert!(
        length >= expected.max(2.5),
        "trench {length} m for a {} m slide (at least {expected} m)",
        slide.length()
    );
    assert!(width <= 2.0 * dims::SHOULDER_WIDTH, "trench {width} m wide");
}

/// Area a body lying on its back covers from above, arms out: torso and pelvis, head, legs and
/// arms as rectangles of their widths.
fn lying_body_area() -> (f32, f32) {
    let trunk = dims::SHOULDER_WIDTH * (dims::SPINE + dims::NECK + 0.1);
    let head = 0.16 * 0.24;
    let legs = 2.0 * 0.13 * (dims::THIGH + dims::SHIN);
    let arms = 2.0 * 0.09 * (dims::UPPER_ARM + dims::FOREARM + 0.17);
    let body = trunk + head + legs + arms;
    (0.6 * body, 1.6 * body)
}

#[test]
fn fall_leaves_a_body_sized_imprint() {
    let run = run();
    let faller = person(&run.demo, "faller");
    let (_, topple) = faller.topple().expect("the faller falls");
    let desc = &run.demo.surfaces[surface::LOW_ROOF].desc;
    let map = &run.maps[surface::LOW_ROOF];
    let (root, _) = topple.lying_root();
    let found = blobs(map);
    let body = found
        .iter()
        .find(|b| b.near(desc, map, root, 0.1))
        .expect("an imprint under the landed body");
    let area = body.area(desc, map);
    let (lo, hi) = lying_body_area();
    assert!(
        area >= lo && area <= hi,
        "imprint {area} m², a body covers {lo}..{hi}"
    );
    let fall_dir = -snowprint_demo::anim::forward_of(topple.yaw);
    let length = body.extent(desc, map, fall_dir);
    assert!(
        (0.85 * dims::HEIGHT..=1.3 * dims::HEIGHT).contains(&length),
        "imprint {length} m long for a {} m body",
        dims::HEIGHT
    );
    // Nothing else of the faller's reaches the low roof: it fell from the parapet.
    let others = found
        .iter()
        .filter(|b| b.near(desc, map, root, 2.5))
        .count();
    assert_eq!(others, 1, "one imprint where the faller landed");
}

#[test]
fn thrown_fighter_leaves_a_body_sized_imprint() {
    let run = run();
    let thug = person(&run.demo, "thug");
    let (_, topple) = thug.topple().expect("the thug is thrown");
    let desc = &run.demo.surfaces[surface::YARD_ROOF].desc;
    let map = &run.maps[surface::YARD_ROOF];
    let (root, _) = topple.lying_root();
    let found = blobs(map);
    let body = found
        .iter()
        .find(|b| b.near(desc, map, root, 0.1))
        .expect("an imprint under the thrown fighter");
    let (lo, _) = lying_body_area();
    assert!(
        body.area(desc, map) >= lo,
        "imprint {} m²",
        body.area(desc, map)
    );
}

/// A copy of the demo with only the angel, sweeping or lying still.
fn angel_only(sweeping: bool) -> DemoWorld {
    let mut demo = DemoWorld::build();
    demo.people.retain(|p| p.name == "angel");
    for p in &mut demo.people {
        for s in &mut p.motion.segments {
            if let Action::Angel(a) = &mut s.action {
                a.sweeping = sweeping;
            }
        }
    }
    demo
}

#[test]
fn snow_angel_has_fans() {
    let demo = angel_only(true);
    let angel = person(&demo, "angel");
    let (start, sweeps) = angel.angel().expect("the angel sweeps");
    let (topple_start, _) = angel.topple().expect("the angel lies down first");
    let low = &demo.surfaces[surface::LOW_ROOF].desc;
    // A small surface around the angel, same ground and snow, so that both runs are cheap and
    // measured on the same texels.
    let mut local = SurfaceDesc::new(
        "angel",
        [sweeps.root.x, low.center.y, sweeps.root.z],
        [5.0, 5.0],
        low.snow_depth,
    );
    local.replenish_rate = 0.0;
    let end = start + sweeps.duration() + 0.2;
    let with = simulate(&demo, std::slice::from_ref(&local), topple_start - 0.1, end);
    let still = simulate(
        &angel_only(false),
        std::slice::from_ref(&local),
        topple_start - 0.1,
        end,
    );
    if let Some(dir) = std::env::var_os("SNOWPRINT_DEMO_OUT") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).expect("output folder");
        with[0]
            .save_png(&dir.join("angel_sweeping.png"))
            .expect("png");
        still[0]
            .save_png(&dir.join("angel_still.png"))
            .expect("png");
    }
    let area = |m: &Heightmap| blobs(m).iter().map(|b| b.area(&local, m)).sum::<f32>();
    let (a_with, a_still) = (area(&with[0]), area(&still[0]));
    let (lo, hi) = lying_body_area();
    assert!(
        a_still >= lo && a_still <= hi,
        "the body alone pressed {a_still} m²"
    );
    assert!(
        a_with >= 1.8 * a_still,
        "sweeping pressed {a_with} m², lying still {a_still} m²"
    );
    // The fans: the sweeping hands pass over the snow above the head and out to the sides,
    // where the still body never reaches.
    let pose = angel.pose_at(start + 0.5 * sweeps.period).world();
    for side in [Part::HandRight, Part::HandLeft] {
        let hand = pose[side.index()].position;
        let map = &with[0];
        let desc = &local;
        let texel = desc.size.x / map.width as f32;
        let local_hand = desc.world_to_local().transform_point3(hand);
        let col = ((local_hand.x + 0.5 * desc.size.x) / texel) as u32;
        let row = ((local_hand.z + 0.5 * desc.size.y) / texel) as u32;
        assert!(
            map.fraction(col, row) >= PRESSED,
            "{side:?} fully open not pressed"
        );
        assert!(
            still[0].fraction(col, row) < PRESSED,
            "{side:?} pressed lying still"
        );
    }
}

#[test]
fn nobody_touches_the_street_or_the_tower_roofs() {
    let run = run();
    for s in [surface::STREET, surface::HIGH_ROOF, surface::TOWER_ROOF] {
        let m = &run.maps[s];
        assert!(
            m.depression.iter().all(|&v| v == 0),
            "{} has pressed snow",
            run.demo.surfaces[s].desc.name
        );
    }
    for s in [
        surface::WALK_ROOF,
        surface::LOW_ROOF,
        surface::RUN_ROOF,
        surface::YARD_ROOF,
    ] {
        assert!(
            !blobs(&run.maps[s]).is_empty(),
            "{} has no prints",
            run.demo.surfaces[s].desc.name
        );
    }
}

/// The contract the prints rely on: a boot held above the snow top, inside the ankle-high zone,
/// presses nothing (the capture keeps the lowest point of what is in the zone).
#[test]
fn boot_above_the_snow_presses_nothing() {
    let demo = DemoWorld::build();
    let mut world = new_world();
    let desc = SurfaceDesc::new("boot", [0.0, 0.0, 0.0], [1.0, 1.0], 0.25);
    let id = world.add_surface(desc).expect("surface");
    let boot = world
        .add_mesh("boot", &demo.part_meshes[Part::FootRight.index()])
        .expect("mesh");
    // Sole 5 cm above the snow top, top of the boot inside the zone.
    let pose = Pose::at([0.0, 0.25 + 0.05 + dims::ANKLE_HEIGHT, 0.0]);
    world
        .step(DT, &[snowprint::Deformer::new(Shape::Mesh(boot), pose)])
        .expect("step");
    let map = world.read_heightmap(id).expect("readback");
    let max = map.depression.iter().copied().max().unwrap_or(0);
    assert_eq!(max, 0, "a boot above the snow pressed it ({max} of 65535)");
}
