//! Prints that read as prints: one demo person's walking (and running) steps pressed into a flat
//! surface on the GPU, each print's depression profile read back with `read_heightmap` along the
//! foot's axis and measured against the boot's geometry computed by hand (`skeleton::foot_mesh`).

mod common;

use glam::Vec2;
use snowprint::{
    CaptureConfig, Heightmap, MeshId, SnowWorld, SurfaceDesc, SurfaceUpdate, WorldConfig,
};
use snowprint_demo::anim::{Action, Footfall, Gait, GaitStyle, Motion, Segment, StepPlan};
use snowprint_demo::{DemoSurface, DemoWorld, Part, Side};

const DT: f32 = 1.0 / 30.0;

/// A flat surface 8 m x 2 m centred on the origin, 4 cm texels (200 x 50), whose ground lies
/// `below` under the ground the gait walks on, with `snow` metres of snow.
fn surface(below: f32, snow: f32) -> SurfaceDesc {
    SurfaceDesc::new("print", [0.0, -below, 0.0], [8.0, 2.0], snow)
}

/// One person walking (or running) 6 m along `+x` at `speed` from x = -3.2, feet either side of
/// z = 0 at 0.14 m (prints centred on texel rows 28 and 21).
fn walker(style: GaitStyle, speed: f32, step_time: f32, duty: f32) -> DemoWorld {
    let mut demo = DemoWorld::build();
    let (t0, t1) = (0.3, 0.3 + 6.0 / speed);
    let path = move |t: f32| {
        let x = -3.2 + speed * (t.clamp(t0, t1) - t0);
        (Vec2::new(x, 0.0), 0.0)
    };
    let plan = StepPlan {
        start: t0,
        end: t1,
        step_time,
        duty,
        lateral: 0.14,
        stagger: 0.0,
        min_stride: 0.5,
        first: Side::Right,
        ground: 0.0,
    };
    let gait = Gait::plan(plan, style, &path);
    let mut person = demo.people[0].clone();
    person.motion = Motion {
        segments: vec![Segment {
            start: 0.0,
            blend: 0.0,
            action: Action::Gait(gait),
        }],
    };
    demo.people = vec![person];
    demo
}

/// Run the whole walk over `desc` and read the snow back.
fn press(demo: &DemoWorld, desc: &SurfaceDesc) -> Heightmap {
    let mut world = SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world");
    let id = world.add_surface(desc.clone()).expect("surface");
    let parts: Vec<MeshId> = demo
        .part_meshes
        .iter()
        .zip(Part::ALL)
        .map(|(m, p)| world.add_mesh(p.name(), m).expect("part"))
        .collect();
    let demo = DemoWorld {
        surfaces: vec![DemoSurface {
            desc: desc.clone(),
            ground: Default::default(),
        }],
        ..demo.clone()
    };
    let ankle = CaptureConfig::default().ankle_height;
    let frames = (7.5 / DT) as u32;
    for f in 1..=frames {
        let sorted = demo.surface_deformers(f as f32 * DT, DT, &parts, ankle);
        let updates: Vec<SurfaceUpdate<'_>> = sorted
            .iter()
            .map(|(_, d)| SurfaceUpdate {
                surface: id,
                elapsed: DT,
                deformers: d,
            })
            .collect();
        world.update(&updates).expect("update");
    }
    world.read_heightmap(id).expect("readback")
}

/// The depression (fraction of the snow) along a print's axis: the texel row of its ankle, from
/// 30 cm behind the ankle to 36 cm ahead, as (x relative to the ankle, fraction).
fn profile(desc: &SurfaceDesc, map: &Heightmap, f: &Footfall) -> Vec<(f32, f32)> {
    let texel = desc.size.x / map.width as f32;
    let local = desc.world_to_local().transform_point3(f.ankle);
    let row = ((local.z + 0.5 * desc.size.y) / texel).floor() as u32;
    (0..map.width)
        .filter_map(|col| {
            let x = -0.5 * desc.size.x + (col as f32 + 0.5) * texel - local.x;
            (-0.3..=0.36)
                .contains(&x)
                .then(|| (x, map.fraction(col, row)))
        })
        .collect()
}

/// The prints of the steps in the middle of a walk (struck and lifted), with their profiles.
fn prints(
    demo: &DemoWorld,
    desc: &SurfaceDesc,
    map: &Heightmap,
) -> Vec<(Footfall, Vec<(f32, f32)>)> {
    demo.people[0]
        .footfalls()
        .into_iter()
        .filter(|f| f.strike.is_finite() && f.lift.is_finite())
        .map(|f| (f, profile(desc, map, &f)))
        .collect()
}

/// The deepest sample of a profile within `[lo, hi]` metres of the ankle: (x, fraction).
fn deepest(p: &[(f32, f32)], lo: f32, hi: f32) -> (f32, f32) {
    p.iter()
        .filter(|(x, _)| (lo..=hi).contains(x))
        .fold((f32::NAN, -1.0), |a, &b| if b.1 > a.1 { b } else { a })
}

/// Where a profile crosses `level` behind and ahead of the ankle (linear between samples): the
/// print's back and front, metres from the ankle.
fn ends(p: &[(f32, f32)], level: f32) -> (f32, f32) {
    let cross = |a: (f32, f32), b: (f32, f32)| a.0 + (b.0 - a.0) * (level - a.1) / (b.1 - a.1);
    let back = p
        .windows(2)
        .find(|w| w[0].1 < level && w[1].1 >= level)
        .map_or(f32::NAN, |w| cross(w[0], w[1]));
    let front = p
        .windows(2)
        .rev()
        .find(|w| w[0].1 >= level && w[1].1 < level)
        .map_or(f32::NAN, |w| cross(w[0], w[1]));
    (back, front)
}

/// The walker's steps (its gait, `GaitStyle::trudge`, whose flat sole stops 7 cm above the gait's
/// ground) onto 35 cm of snow whose ground is 10 cm under the gait's, so that no part of the print
/// is cut flat by the ground. By hand, from `skeleton::foot_mesh` (ankle frame, sole 8 cm under
/// the ankle):
///
/// * the heel block (-11 to 0 cm) is flat from about -9 to -2 cm: the flat sole, 17 cm above the
///   ground, leaves 35 - 17 = 18 cm of the 35 pressed (0.514), the heel strike 2 cm more (0.571),
///   centred at -5.5 cm;
/// * the ball and toes (+7 to +21 cm) are flat from about +9 to +19 cm, pressed as deep (2 cm
///   deeper at the push-off);
/// * between the heel's front (0) and the ball's back (+7 cm) only the upper reaches down, to
///   9 cm above the sole: 18 - 9 = 9 cm of 35 (0.257).
///
/// The capture's blur spreads each over about a texel (4 cm), which lowers the narrow heel and
/// lifts the arch a little; positions are checked to within a texel.
#[test]
fn a_walking_print_has_a_heel_and_a_ball_with_the_arch_between() {
    let demo = walker(GaitStyle::trudge(), 1.0, 0.6, 0.6);
    let desc = surface(0.1, 0.35);
    let map = press(&demo, &desc);
    let prints = prints(&demo, &desc, &map);
    for side in [Side::Left, Side::Right] {
        let n = prints.iter().filter(|(f, _)| f.side == side).count();
        assert!(n >= 3, "{n} {side:?} prints");
    }
    for (f, p) in &prints {
        let show = || format!("{:?} print at x = {:.2}: {p:.2?}", f.side, f.ankle.x);
        let heel = deepest(p, -0.14, 0.0);
        let ball = deepest(p, 0.06, 0.26);
        let arch = p
            .iter()
            .filter(|(x, _)| *x > heel.0 && *x < ball.0)
            .fold((f32::NAN, 2.0), |a, &b| if b.1 < a.1 { b } else { a });
        // Two maxima with a shallower minimum between them, each at least 5 cm of snow apart.
        assert!(
            heel.1 - arch.1 > 0.15 && ball.1 - arch.1 > 0.15,
            "{}",
            show()
        );
        // Where the geometry puts them.
        assert!(
            (heel.0 - -0.055).abs() <= 0.04,
            "heel at {}: {}",
            heel.0,
            show()
        );
        assert!(
            (0.09 - 0.02..=0.19 + 0.02).contains(&ball.0),
            "ball at {}: {}",
            ball.0,
            show()
        );
        assert!(
            (-0.02..=0.07 + 0.02).contains(&arch.0),
            "arch at {}: {}",
            arch.0,
            show()
        );
        // As deep as the geometry presses, less what the blur takes off a narrow heel.
        assert!(
            (0.45..=0.58).contains(&heel.1),
            "heel {}: {}",
            heel.1,
            show()
        );
        assert!(
            (0.47..=0.58).contains(&ball.1),
            "ball {}: {}",
            ball.1,
            show()
        );
        assert!(
            (0.23..=0.34).contains(&arch.1),
            "arch {}: {}",
            arch.1,
            show()
        );
        // Nothing presses behind the heel's back (-11 cm, rolled 1 cm further back at the strike)
        // or ahead of the toe cap (+22.5 cm) by more than the blur's one and a half texels.
        let (back, front) = ends(p, 0.1);
        assert!(
            (-0.12 - 0.06..=-0.11).contains(&back),
            "back {back}: {}",
            show()
        );
        assert!(
            (0.225..=0.225 + 0.06).contains(&front),
            "front {front}: {}",
            show()
        );
    }
}

/// The runner's steps (`GaitStyle::run`) on the same snow: the foot skids 12 cm from its heel
/// strike and digs the ball 6 cm deeper at the push-off, its flat sole 6 cm above the gait's
/// ground. By hand: flat 35 - 16 = 19 cm of 35 pressed (0.543) at the heel, the ball at 25 cm
/// (0.714); the print longer at the back.
#[test]
fn a_running_print_is_longer_and_deeper_at_the_toe() {
    let walk = walker(GaitStyle::trudge(), 1.0, 0.6, 0.6);
    let run = walker(GaitStyle::run(), 3.8, 0.34, 0.26);
    let desc = surface(0.1, 0.35);
    let walked = prints(&walk, &desc, &press(&walk, &desc));
    let ran = prints(&run, &desc, &press(&run, &desc));
    assert!(ran.len() >= 2, "{} running prints", ran.len());
    let (w_back, w_front) = ends(&walked[0].1, 0.1);
    for (f, p) in &ran {
        let show = || format!("{:?} print at x = {:.2}: {p:.2?}", f.side, f.ankle.x);
        let heel = deepest(p, -0.2, 0.0);
        let toe = deepest(p, 0.06, 0.26);
        assert!(toe.1 > heel.1 + 0.1, "{}", show());
        assert!((0.62..=0.76).contains(&toe.1), "toe {}: {}", toe.1, show());
        assert!(
            (0.45..=0.6).contains(&heel.1),
            "heel {}: {}",
            heel.1,
            show()
        );
        let (back, front) = ends(p, 0.1);
        assert!(
            (front - back) > (w_front - w_back) + 0.03,
            "run {back}..{front}, walk {w_back}..{w_front}: {}",
            show()
        );
        assert!(back < w_back - 0.03, "{}", show());
    }
}
