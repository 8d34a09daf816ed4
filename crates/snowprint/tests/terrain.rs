//! Snow on ground that is not flat: the capture follows the ground (a sphere pressed into snow on a
//! 30-degree plane, on a sine-hill terrain and on a slope steep enough to be partly bare leaves the
//! depression computed by hand from the local snow top, never below the ground), the GPU capture
//! against its CPU reference on a ground field, and a mesh terrain against the same terrain as a
//! 16-bit PNG heightmap.

mod common;

use glam::{Vec2, Vec3};
use snowprint::low_level::capture::{self, CaptureVolume};
use snowprint::reference::capture as cap_cpu;
use snowprint::reference::ground as ground_cpu;
use snowprint::{
    Deformer, Ground, GroundMesh, HeightGrid, Pose, Shape, SlopeRule, SnowError, SnowWorld,
    SurfaceDesc, WorldConfig,
};

const ANKLE: f32 = 0.25;
const DEPTH: f32 = 0.3;

fn world() -> SnowWorld {
    SnowWorld::new(common::gpu(), WorldConfig::default()).expect("world")
}

/// A grid with one sample per texel of `desc` (so that sampling it at texel centres is exact) of
/// the heights `f(x, z)` in local metres.
fn grid_of(desc: &SurfaceDesc, f: impl Fn(f32, f32) -> f32) -> HeightGrid {
    let l = desc.layout();
    let half = desc.size * 0.5;
    let mut heights = Vec::new();
    for r in 0..l.height {
        for c in 0..l.width {
            let p = cap_cpu::texel_center(c, r, l.width, l.height, half);
            heights.push(f(p.x, p.y));
        }
    }
    HeightGrid {
        columns: l.width,
        rows: l.height,
        heights,
    }
}

/// Depression (fraction of the snow depth) a sphere of radius `r` centred at local `c` leaves over
/// local `(x, z)` on ground `g` holding `k` of the snow depth: measured from the local snow top
/// `g + k D`, at most down to the ground.
fn analytic(c: Vec3, r: f32, p: Vec2, g: f32, k: f32) -> f32 {
    let d = (p - Vec2::new(c.x, c.z)).length();
    if d >= r {
        return 0.0;
    }
    let bottom = (c.y - (r * r - d * d).sqrt()).max(g);
    let top = g + k * DEPTH;
    // A fraction of the whole depth, measured from the local top: at most `k`, the ground.
    ((top - bottom) / DEPTH).clamp(0.0, k)
}

/// Each texel lies within the analytic values of its 3x3 neighbourhood (the blur mixes the 3x3
/// centres around a texel), give or take a unit and a half of quantization; the texel never reads
/// deeper than the ground (`k` of the depth). Returns how many texels the sphere pressed.
fn assert_print(
    map: &snowprint::Heightmap,
    half: Vec2,
    value: impl Fn(Vec2) -> f32,
    deepest: impl Fn(Vec2) -> f32,
) -> usize {
    let (w, h) = (map.width, map.height);
    let mut pressed = 0;
    let probes = [Vec2::ZERO, Vec2::X, -Vec2::X, Vec2::Y, -Vec2::Y].map(|v| v * 5e-4);
    let unit = 1.5 / 65535.0;
    for row in 0..h {
        for col in 0..w {
            let (mut lo, mut hi) = (f32::MAX, f32::MIN);
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (x, y) = (
                        (col as i32 + dx).clamp(0, w as i32 - 1) as u32,
                        (row as i32 + dy).clamp(0, h as i32 - 1) as u32,
                    );
                    let n = cap_cpu::texel_center(x, y, w, h, half);
                    for p in probes {
                        let v = value(n + p);
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
            }
            let got = map.fraction(col, row);
            assert!(
                got >= lo - unit && got <= hi + unit,
                "texel ({col},{row}): {got} not in [{lo}, {hi}]"
            );
            let centre = cap_cpu::texel_center(col, row, w, h, half);
            assert!(
                got <= deepest(centre) + unit,
                "texel ({col},{row}): {got} is below the ground ({})",
                deepest(centre)
            );
            if got > 0.0 {
                pressed += 1;
            }
        }
    }
    pressed
}

/// Lay `desc` on `ground`, press a sphere of radius `r` at local `c` for one frame, and return the
/// world, the surface and its heightmap.
fn press(
    desc: &SurfaceDesc,
    ground: &Ground,
    slope: SlopeRule,
    c: Vec3,
    r: f32,
) -> (SnowWorld, snowprint::SurfaceId, snowprint::Heightmap) {
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(id, ground, slope).unwrap();
    let at = desc.local_to_world().transform_point3(c);
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: r },
            Pose::at(at.to_array()),
        )],
    )
    .unwrap();
    let map = w.read_heightmap(id).unwrap();
    (w, id, map)
}

/// The GPU's capture of the last step against the CPU reference on the surface's ground field.
fn assert_capture_matches_reference(
    w: &SnowWorld,
    id: snowprint::SurfaceId,
    prims_of: &[Deformer],
) {
    let desc = w.surface(id).unwrap().clone();
    let field = w.ground(id).unwrap().expect("a ground field");
    let l = desc.layout();
    let (low, high) = field.range();
    let vol = CaptureVolume {
        world_to_local: desc.world_to_local(),
        half_size: desc.size * 0.5,
        frustum_height: DEPTH + ANKLE,
        ground: (low, high),
    };
    let cpu_of = |ds: &[Deformer]| {
        let mut prims = vec![];
        for d in ds {
            capture::push_primitives(d, &vol, &mut prims);
        }
        cap_cpu::capture_on_ground(
            l.width,
            l.height,
            vol.half_size,
            vol.frustum_height,
            &prims,
            &[],
            Some(&field.columns),
        )
    };
    let gpu = w.read_last_capture(id).unwrap().expect("captured");
    let cpu = cpu_of(prims_of);
    // Judged against the heights the CPU gives with the deformers nudged by a GPU's last bits of
    // position (`common::capture_envelope`): an H100 put a grazing texel 165 um from the height
    // at its centre, within that range.
    let envelope = common::capture_envelope(&cpu, prims_of, cpu_of);
    let mut mismatched = 0;
    for ((g, c), range) in gpu.iter().zip(&cpu).zip(&envelope) {
        if (*g < 1.0) != (*c < 1.0) {
            mismatched += 1;
        } else {
            let dh = common::outside(*g, *range) * vol.frustum_height;
            assert!(
                dh <= 5e-5,
                "capture {g} vs reference {c} (nudged {range:?}): {dh} m apart"
            );
        }
    }
    // Rim texels whose centre grazes the sphere may fall either side.
    assert!(mismatched <= 4, "{mismatched} texels differ in coverage");
}

#[test]
fn sphere_on_a_30_degree_plane_presses_from_the_local_snow_top() {
    let desc = SurfaceDesc::new("slope", [1.0, 3.0, -2.0], [2.0, 2.0], DEPTH);
    let t = 30f32.to_radians().tan();
    let g = move |x: f32, _z: f32| x * t;
    let ground = Ground::Grid(grid_of(&desc, g));
    // Centre over local (0.1, -0.2), 0.12 below the local snow top plus the radius: the print is
    // 12 cm deep at its centre, deeper on the uphill side, and where the sphere reaches below the
    // ground (uphill), pressed to the ground and no further.
    let (r, cx, cz) = (0.3f32, 0.1f32, -0.2f32);
    for depth_at_centre in [0.12f32, 0.45] {
        let c = Vec3::new(cx, g(cx, cz) + DEPTH - depth_at_centre + r, cz);
        let (w, id, map) = press(&desc, &ground, SlopeRule::default(), c, r);
        let pressed = assert_print(
            &map,
            desc.size * 0.5,
            |p| analytic(c, r, p, g(p.x, p.y), 1.0),
            |_| 1.0,
        );
        assert!(pressed > 100, "{pressed}");
        // At the centre texel nearest the sphere's axis: the hand-computed 12 cm (blur aside,
        // the print is flat to within a texel's slope of the sphere there).
        if depth_at_centre < 0.2 {
            let l = desc.layout();
            let (col, row) = (
                ((cx + 1.0) / 2.0 * l.width as f32) as u32,
                ((cz + 1.0) / 2.0 * l.height as f32) as u32,
            );
            let got = map.fraction(col, row) * DEPTH;
            assert!((got - 0.12).abs() < 0.01, "centre pressed {got} m");
        } else {
            // Pressed to the ground over a disc: the capture clamps at the ground.
            assert!(map.depression.contains(&65535));
        }
        let at = desc.local_to_world().transform_point3(c);
        assert_capture_matches_reference(
            &w,
            id,
            &[Deformer::new(
                Shape::Sphere { radius: r },
                Pose::at(at.to_array()),
            )],
        );
    }
}

#[test]
fn sphere_on_sine_hills_presses_from_the_local_snow_top_never_below_the_ground() {
    let mut desc = SurfaceDesc::new("hills", [-3.0, 1.0, 4.0], [3.0, 2.0], DEPTH);
    desc.yaw_degrees = 25.0;
    // Hills 0.25 m high, 2.4 m apart: slopes up to about 33 degrees, under the rule's 35.
    let (a, k) = (0.25f32, std::f32::consts::TAU / 2.4);
    let g = move |x: f32, z: f32| a * (k * x).sin() * (k * z).cos();
    let ground = Ground::Grid(grid_of(&desc, g));
    let r = 0.35f32;
    for (cx, cz) in [(0.3f32, 0.0f32), (-0.6, 0.4)] {
        // Sunk 0.2 m into the snow at its centre: on the hill's flank one side reaches the ground.
        let c = Vec3::new(cx, g(cx, cz) + DEPTH - 0.2 + r, cz);
        let (w, id, map) = press(&desc, &ground, SlopeRule::default(), c, r);
        let pressed = assert_print(
            &map,
            desc.size * 0.5,
            |p| analytic(c, r, p, g(p.x, p.y), 1.0),
            |_| 1.0,
        );
        assert!(pressed > 100, "{pressed}");
        let at = desc.local_to_world().transform_point3(c);
        assert_capture_matches_reference(
            &w,
            id,
            &[Deformer::new(
                Shape::Sphere { radius: r },
                Pose::at(at.to_array()),
            )],
        );
    }
}

#[test]
fn a_slope_steeper_than_the_rule_holds_less_snow_and_is_pressed_to_its_ground() {
    // A 50-degree plane under the default rule (full to 35, bare from 60): it holds 0.4 of the
    // depth, so its snow top is 0.12 m above the ground and a foot presses at most that.
    let desc = SurfaceDesc::new("steep", [0.0, 2.0, 0.0], [2.0, 2.0], DEPTH);
    let t = 50f32.to_radians().tan();
    let g = move |_x: f32, z: f32| z * t;
    let ground = Ground::Grid(grid_of(&desc, g));
    let rule = SlopeRule::default();
    let k = rule.holds(50.0);
    assert!((k - 0.4).abs() < 1e-6);
    let r = 0.3f32;
    // Sunk 0.1 m below the local snow top at its centre; uphill it reaches the ground.
    let c = Vec3::new(0.0, g(0.0, 0.0) + k * DEPTH - 0.1 + r, 0.0);
    let (w, id, map) = press(&desc, &ground, rule, c, r);
    // The stored depression is a fraction of the whole depth measured from the local top; it
    // never exceeds what the slope holds (pressed to the ground).
    let pressed = assert_print(
        &map,
        desc.size * 0.5,
        |p| analytic(c, r, p, g(p.x, p.y), k),
        |_| k,
    );
    assert!(pressed > 100, "{pressed}");
    let deepest = map.depression.iter().copied().max().unwrap() as f32 / 65535.0;
    assert!((deepest - k).abs() < 2.0 / 65535.0, "deepest {deepest}");
    let field = w.ground(id).unwrap().unwrap();
    assert!(
        field
            .columns
            .iter()
            .all(|c| (c[1] - 0.6 * DEPTH).abs() < 1e-4)
    );
    let at = desc.local_to_world().transform_point3(c);
    assert_capture_matches_reference(
        &w,
        id,
        &[Deformer::new(
            Shape::Sphere { radius: r },
            Pose::at(at.to_array()),
        )],
    );
}

/// A sine-hill terrain as triangles in world metres over `desc`'s rectangle (a vertex every 5 cm,
/// a little beyond the edges), and the same terrain as a 16-bit PNG of `columns x rows` samples.
fn hill_mesh(desc: &SurfaceDesc, g: &impl Fn(f32, f32) -> f32) -> GroundMesh {
    let to_world = desc.local_to_world();
    let (nx, nz) = (
        (desc.size.x / 0.05).ceil() as i32 + 2,
        (desc.size.y / 0.05).ceil() as i32 + 2,
    );
    let v = |i: i32, j: i32| {
        let (x, z) = (
            -0.5 * desc.size.x + (i - 1) as f32 * 0.05,
            -0.5 * desc.size.y + (j - 1) as f32 * 0.05,
        );
        to_world.transform_point3(Vec3::new(x, g(x, z), z))
    };
    let mut triangles = vec![];
    for j in 0..nz {
        for i in 0..nx {
            triangles.push([v(i, j), v(i, j + 1), v(i + 1, j)]);
            triangles.push([v(i + 1, j), v(i, j + 1), v(i + 1, j + 1)]);
        }
    }
    GroundMesh { triangles }
}

fn hill_png(desc: &SurfaceDesc, g: &impl Fn(f32, f32) -> f32, columns: u32, rows: u32) -> Vec<u8> {
    let (low, high) = (-0.3f32, 0.3f32);
    let mut data = Vec::new();
    for r in 0..rows {
        for c in 0..columns {
            let x = -0.5 * desc.size.x + (c as f32 + 0.5) / columns as f32 * desc.size.x;
            let z = -0.5 * desc.size.y + (r as f32 + 0.5) / rows as f32 * desc.size.y;
            let v = ((g(x, z) - low) / (high - low) * 65535.0).round() as u16;
            data.extend_from_slice(&v.to_be_bytes());
        }
    }
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, columns, rows);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Sixteen);
    enc.write_header().unwrap().write_image_data(&data).unwrap();
    out
}

#[test]
fn a_mesh_terrain_and_the_same_terrain_as_a_png_agree_within_a_texel() {
    let mut desc = SurfaceDesc::new("valley", [2.0, 0.5, 1.0], [3.0, 2.0], DEPTH);
    desc.yaw_degrees = -40.0;
    let (a, k) = (0.2f32, std::f32::consts::TAU / 1.6);
    let g = move |x: f32, z: f32| a * (k * x).sin() * (k * z).cos();
    let l = desc.layout();
    let texel = desc.size.x / l.width as f32;
    // Steepest rise over one texel: |grad g| <= a k sqrt(2).
    let per_texel = a * k * 2f32.sqrt() * texel;
    let mesh = hill_mesh(&desc, &g);
    // The GPU's rasterisation against its CPU reference, texel for texel.
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(id, &Ground::Mesh(mesh.clone()), SlopeRule::NEVER_BARE)
        .unwrap();
    let from_mesh = w.ground(id).unwrap().unwrap().ground.clone();
    let reference = ground_cpu::rasterise(&mesh.triangles, desc.world_to_local(), desc.size, l);
    for (i, (gpu, cpu)) in from_mesh.iter().zip(&reference).enumerate() {
        let cpu = cpu.expect("the mesh covers every texel centre");
        assert!((gpu - cpu).abs() < 1e-4, "texel {i}: GPU {gpu}, CPU {cpu}");
    }
    // The PNG at a coarser grid than the texels (every 3 cm... 96 x 64 samples).
    let png = hill_png(&desc, &g, 96, 64);
    let grid = HeightGrid::from_png16(&png, -0.3, 0.3).unwrap();
    let mut w2 = world();
    let id2 = w2.add_surface(desc.clone()).unwrap();
    w2.set_ground(id2, &Ground::Grid(grid), SlopeRule::NEVER_BARE)
        .unwrap();
    let from_png = w2.ground(id2).unwrap().unwrap().ground.clone();
    let worst = from_mesh
        .iter()
        .zip(&from_png)
        .map(|(m, p)| (m - p).abs())
        .fold(0.0f32, f32::max);
    assert!(
        worst <= per_texel,
        "mesh and PNG grounds differ by {worst} m, more than a texel's rise {per_texel}"
    );
    // And both against the function itself at the texel centres.
    for (i, m) in from_mesh.iter().enumerate() {
        let p = cap_cpu::texel_center(
            i as u32 % l.width,
            i as u32 / l.width,
            l.width,
            l.height,
            desc.size * 0.5,
        );
        assert!((m - g(p.x, p.y)).abs() <= per_texel, "texel {i}");
    }
    // The same sphere on both leaves prints that differ by no more than the grounds do.
    let c = Vec3::new(0.2, g(0.2, 0.1) + DEPTH - 0.15 + 0.3, 0.1);
    let at = desc.local_to_world().transform_point3(c);
    let foot = [Deformer::new(
        Shape::Sphere { radius: 0.3 },
        Pose::at(at.to_array()),
    )];
    w.step(1.0 / 60.0, &foot).unwrap();
    w2.step(1.0 / 60.0, &foot).unwrap();
    let (m1, m2) = (
        w.read_heightmap(id).unwrap(),
        w2.read_heightmap(id2).unwrap(),
    );
    let mut pressed = 0;
    for (a, b) in m1.depression.iter().zip(&m2.depression) {
        let d = (*a as f32 - *b as f32).abs() / 65535.0 * DEPTH;
        assert!(d <= worst + 1e-4, "prints differ by {d} m");
        pressed += (*a > 0) as usize;
    }
    assert!(pressed > 100, "{pressed}");
}

#[test]
fn flat_ground_set_explicitly_is_the_flat_surface_bit_for_bit() {
    let desc = SurfaceDesc::new("flat", [0.0, 1.0, 0.0], [2.0, 1.5], DEPTH);
    let foot = [Deformer::new(
        Shape::Sphere { radius: 0.2 },
        Pose::at([0.1, 1.25, 0.0]),
    )];
    let mut w = world();
    let a = w.add_surface(desc.clone()).unwrap();
    w.step(1.0 / 60.0, &foot).unwrap();
    // A grid of zeros is a ground field of zeros: the same maths as flat ground.
    let mut w2 = world();
    let b = w2.add_surface(desc.clone()).unwrap();
    let zeros = grid_of(&desc, |_, _| 0.0);
    w2.set_ground(b, &Ground::Grid(zeros), SlopeRule::default())
        .unwrap();
    assert!(w2.ground(b).unwrap().is_some());
    w2.step(1.0 / 60.0, &foot).unwrap();
    assert_eq!(w.read_heightmap(a).unwrap(), w2.read_heightmap(b).unwrap());
    w2.set_ground(b, &Ground::Flat, SlopeRule::default())
        .unwrap();
    assert!(w2.ground(b).unwrap().is_none());
}

#[test]
fn bad_ground_is_refused_with_one_sentence() {
    let desc = SurfaceDesc::new("roof", [0.0, 1.0, 0.0], [2.0, 1.5], DEPTH);
    let mut w = world();
    let id = w.add_surface(desc).unwrap();
    let e = w
        .set_ground(
            id,
            &Ground::Mesh(GroundMesh::default()),
            SlopeRule::default(),
        )
        .unwrap_err();
    assert!(matches!(e, SnowError::InvalidGround { .. }), "{e}");
    assert!(e.to_string().contains("no triangles"), "{e}");
    let short = HeightGrid {
        columns: 4,
        rows: 4,
        heights: vec![0.0; 15],
    };
    let e = w
        .set_ground(id, &Ground::Grid(short), SlopeRule::default())
        .unwrap_err();
    assert!(
        e.to_string().contains("4 x 4") && e.to_string().contains("15"),
        "{e}"
    );
    let rule = SlopeRule {
        full_degrees: 40.0,
        bare_degrees: 30.0,
    };
    assert!(w.set_ground(id, &Ground::Flat, rule).is_err());
    assert!(
        HeightGrid::from_raw_f32(&[0u8; 10], 2, 2)
            .unwrap_err()
            .contains("10 bytes")
    );
}

/// A folder of its own under the system's temporary folder, for scene files and their grounds.
fn scratch_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("snowprint-terrain-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const SURFACE: &str = "version = 1\n\n[[surface]]\nname = \"hill\"\ncenter = [0, 0, 0]\nsize = [3, 2]\nsnow_depth = 0.3\n";

fn parse_in(dir: &std::path::Path, extra: &str) -> snowprint::Result<snowprint::scene::Scene> {
    let path = dir.join("s.toml");
    let text = format!("{SURFACE}{extra}");
    std::fs::write(&path, &text).unwrap();
    snowprint::scene::Scene::load(&path)
}

#[test]
fn scene_keys_lay_a_surface_on_a_heightmap_and_refuse_bad_ground_with_its_line() {
    let dir = scratch_dir("scene");
    let desc = SurfaceDesc::new("hill", [0.0; 3], [3.0, 2.0], DEPTH);
    let g = |x: f32, z: f32| 0.1 * x + 0.05 * z;
    std::fs::write(dir.join("hill.png"), hill_png(&desc, &g, 30, 20)).unwrap();
    // A PNG with its height range and a slope rule.
    let scene = parse_in(
        &dir,
        "ground = \"hill.png\"\nground_heights = [-0.3, 0.3]\nfull_slope_degrees = 20\nbare_slope_degrees = 45\n",
    )
    .unwrap();
    let sg = scene.grounds[0].as_ref().expect("a ground");
    assert_eq!(sg.line, 8);
    assert_eq!(
        sg.slope,
        SlopeRule {
            full_degrees: 20.0,
            bare_degrees: 45.0
        }
    );
    let Ground::Grid(grid) = &sg.ground else {
        panic!("a grid")
    };
    assert_eq!((grid.columns, grid.rows), (30, 20));
    // The first sample's centre is at (-1.45, -0.95): within a 16-bit step of the plane.
    assert!((grid.heights[0] - g(-1.45, -0.95)).abs() < 1e-4);
    let err = |extra: &str| parse_in(&dir, extra).unwrap_err().to_string();
    // No height range for a PNG.
    let e = err("ground = \"hill.png\"\n");
    assert!(
        e.contains("s.toml:8:") && e.contains("ground_heights"),
        "{e}"
    );
    // A heightmap of the wrong size.
    let e = err("ground = \"hill.png\"\nground_heights = [0, 1]\nground_grid = [32, 20]\n");
    assert!(
        e.contains("s.toml:10:") && e.contains("30 x 20 pixels"),
        "{e}"
    );
    // A raw grid of the wrong size.
    std::fs::write(dir.join("hill.f32"), vec![0u8; 4 * 30 * 20 - 4]).unwrap();
    let e = err("ground = \"hill.f32\"\nground_grid = [30, 20]\n");
    assert!(
        e.contains("s.toml:8:") && e.contains("2396 bytes") && e.contains("2400"),
        "{e}"
    );
    // The same file at the right size reads.
    std::fs::write(dir.join("hill.f32"), vec![0u8; 4 * 30 * 20]).unwrap();
    assert!(parse_in(&dir, "ground = \"hill.f32\"\nground_grid = [30, 20]\n").is_ok());
    // A mesh with no triangles.
    std::fs::write(
        dir.join("empty.gltf"),
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": []}]}",
    )
    .unwrap();
    let e = err("ground = \"empty.gltf\"\n");
    assert!(e.contains("s.toml:8:") && e.contains("no triangles"), "{e}");
    // A slope rule that bares before it is full.
    let e = err("ground = \"hill.f32\"\nground_grid = [30, 20]\nfull_slope_degrees = 70\n");
    assert!(
        e.contains("s.toml:10:") && e.contains("bare_slope_degrees"),
        "{e}"
    );
    // Grid keys without a ground.
    let e = err("ground_grid = [30, 20]\n");
    assert!(e.contains("s.toml:8:") && e.contains("no ground"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_pitched_roof_scene_leaves_trenches_that_follow_the_roof() {
    // scenes/pitched_roof.toml: two 30-degree planes from a glTF, a ball dragged up one side and
    // down the other 0.1 m deep, and one dragged across a side along its contour 0.2 m deep.
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/pitched_roof.toml");
    let scene = snowprint::scene::Scene::load(&path).unwrap();
    let mut w = world();
    let desc = scene.surfaces[0].clone();
    let id = w.add_surface(desc.clone()).unwrap();
    let g = scene.grounds[0].as_ref().expect("the roof mesh");
    w.set_ground(id, &g.ground, g.slope).unwrap();
    let field = w.ground(id).unwrap().unwrap().clone();
    let l = desc.layout();
    let t30 = 30f32.to_radians().tan();
    // The rasterised roof is (3 - |z|) tan 30 at every texel centre, and holds all its snow.
    for (i, h) in field.ground.iter().enumerate() {
        let p = cap_cpu::texel_center(
            i as u32 % l.width,
            i as u32 / l.width,
            l.width,
            l.height,
            desc.size * 0.5,
        );
        assert!((h - (3.0 - p.y.abs()) * t30).abs() < 1e-4, "texel {i}: {h}");
    }
    // The ridge row's slope is a mean of the two sides (0): it holds all its snow too.
    assert!(field.columns.iter().all(|c| c[1] == 0.0));
    let dt = 1.0 / 60.0;
    let mut prev: Vec<Option<Pose>> = vec![None; scene.deformers.len()];
    for f in 1..=240 {
        let t = f as f32 * dt;
        let ds: Vec<Deformer> = scene
            .deformers
            .iter()
            .zip(&mut prev)
            .map(|(d, p)| {
                let snowprint::scene::SceneShape::Sphere { radius } = d.shape else {
                    panic!("spheres")
                };
                let pose = d.pose_at(t);
                match p.replace(pose) {
                    Some(before) => Deformer::moving(Shape::Sphere { radius }, before, pose),
                    None => Deformer::new(Shape::Sphere { radius }, pose),
                }
            })
            .collect();
        w.step(dt, &ds).unwrap();
    }
    let map = w.read_heightmap(id).unwrap();
    let at = |x: f32, z: f32| {
        let c = ((x + 4.0) / 8.0 * l.width as f32) as u32;
        let r = ((z + 3.0) / 6.0 * l.height as f32) as u32;
        map.fraction(c, r) * DEPTH
    };
    // Up the side, the ball's centre runs 0.2 m below the local top plus its radius, parallel to
    // the roof: swept, it is a cylinder whose bottom lies sqrt(r^2 - dx^2) / cos 30 below its axis
    // over a line dx off it, so the trench is 0.3 - 0.4 + sqrt(r^2 - dx^2) / cos 30 deep there
    // (0.131 m on the axis, not the ball's 0.1 at rest). The texel at x = -2 has its centre 2 cm off
    // the axis and the blur mixes its neighbours at 2 and 6 cm.
    let r = 0.2f32;
    let trench = |dx: f32| 0.3 - 0.4 + (r * r - dx * dx).sqrt() / 30f32.to_radians().cos();
    let (shallow, deep) = (trench(0.06), trench(0.02));
    for z in [-2.2f32, -1.0, 1.0, 2.2] {
        let d = at(-2.0, z);
        assert!(
            d >= shallow - 1e-3 && d <= deep + 1e-3,
            "up-and-over trench at z = {z}: {d} m, not in [{shallow}, {deep}]"
        );
    }
    // Across the slope the axis is level: over the axis row (its centres at z = -1.5 exactly) the
    // ball is 0.2 m deep; the rows 4 cm up and down the slope are 0.2 + 0.023 - 0.004 and
    // 0.2 - 0.023 - 0.004 m deep (the top moves by 0.04 tan 30, the ball's bottom by
    // r - sqrt(r^2 - 0.04^2)), and the blur weighs them 1/4 each against the axis row's 1/2.
    let up = 0.04 * t30;
    let rise = r - (r * r - 0.04f32 * 0.04).sqrt();
    let across = 0.5 * 0.2 + 0.25 * (0.2 + up - rise) + 0.25 * (0.2 - up - rise);
    for x in [-3.0f32, -1.0, 0.5, 3.0] {
        let d = at(x, -1.5);
        assert!(
            (d - across).abs() < 2e-3,
            "trail across at x = {x}: {d} m, not {across}"
        );
        assert_eq!(at(x, -0.9), 0.0, "beside the trail at x = {x}");
    }
    assert_eq!(at(0.0, 1.5), 0.0);
    // Never below the roof.
    assert!(map.depression.iter().all(|&v| v < 65535));
}

#[test]
fn footsteps_land_on_the_local_snow_top() {
    // A 30-degree plane rising along x: at local x = 0.5 the ground is 0.289 m above the centre and
    // the snow top 0.589. A ball coming down to 0.1 m below that top lands 0.1 deep; on the flat
    // surface's top (0.3) it would not have landed at all.
    let desc = SurfaceDesc::new("slope", [1.0, 3.0, -2.0], [2.0, 2.0], DEPTH);
    let t = 30f32.to_radians().tan();
    let g = move |x: f32, _z: f32| x * t;
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(id, &Ground::Grid(grid_of(&desc, g)), SlopeRule::default())
        .unwrap();
    let r = 0.1f32;
    // x = 0.5 is the centre of texel 37 (4 cm texels from x = -1), where the field is exact.
    let x = 0.5f32;
    let top = 3.0 + g(x, 0.0) + DEPTH;
    let above = Pose::at([1.0 + x, top + 0.3, -2.0]);
    let down = Pose::at([1.0 + x, top - 0.1 + r, -2.0]);
    let ball = Shape::Sphere { radius: r };
    w.step(1.0 / 60.0, &[Deformer::moving(ball, above, down)])
        .unwrap();
    let steps = w.footsteps();
    assert_eq!(steps.len(), 1, "{steps:?}");
    assert!((steps[0].depth_m - 0.1).abs() < 1e-4, "{:?}", steps[0]);
    // On a 50-degree plane holding 0.4 of the depth, a ball driven 0.3 m below the local top
    // lands as deep as the snow there, 0.12 m.
    let t50 = 50f32.to_radians().tan();
    let steep = move |x: f32, _z: f32| x * t50;
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(
        id,
        &Ground::Grid(grid_of(&desc, steep)),
        SlopeRule::default(),
    )
    .unwrap();
    let top = 3.0 + steep(x, 0.0) + 0.4 * DEPTH;
    let above = Pose::at([1.0 + x, top + 0.3, -2.0]);
    let down = Pose::at([1.0 + x, top - 0.3 + r, -2.0]);
    w.step(1.0 / 60.0, &[Deformer::moving(ball, above, down)])
        .unwrap();
    let steps = w.footsteps();
    assert_eq!(steps.len(), 1, "{steps:?}");
    assert!(
        (steps[0].depth_m - 0.4 * DEPTH).abs() < 1e-3,
        "{:?}",
        steps[0]
    );
}

#[test]
fn probes_read_the_snow_over_the_ground() {
    // A 50-degree plane rising along z holds 0.4 of the 0.3 m: 0.12 m of snow, the base tilted 50
    // degrees. Untouched, a probe there reads 0.12 m of snow and a normal leaning 50 degrees back
    // along -z; a point below the local ground (but above the flat rectangle) is under no surface.
    let desc = SurfaceDesc::new("steep", [0.0, 2.0, 0.0], [2.0, 2.0], DEPTH);
    let t = 50f32.to_radians().tan();
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(
        id,
        &Ground::Grid(grid_of(&desc, move |_, z| z * t)),
        SlopeRule::default(),
    )
    .unwrap();
    w.step(1.0 / 60.0, &[]).unwrap();
    // z = 0.5 is the centre of row 37: ground 0.5 tan 50 = 0.596 above the centre.
    let on = Vec3::new(0.1, 2.0 + 0.5 * t + 0.05, 0.5);
    let below = Vec3::new(0.1, 2.0 + 0.5 * t - 0.2, 0.5);
    let ticket = w.probe(&[on, below]).unwrap();
    let samples = loop {
        if let snowprint::ProbeStatus::Ready(s) = w.probe_result(ticket).unwrap() {
            break s;
        }
        w.step(1.0 / 60.0, &[]).unwrap();
    };
    assert_eq!(samples[0].surface, Some(id));
    assert!(
        (samples[0].snow_depth_m - 0.4 * DEPTH).abs() < 1e-5,
        "{:?}",
        samples[0]
    );
    assert_eq!(samples[0].depression_m, 0.0);
    let lean = samples[0].normal.angle_between(Vec3::Y).to_degrees();
    assert!((lean - 50.0).abs() < 0.1, "normal leans {lean} degrees");
    assert!(samples[0].normal.z < 0.0);
    assert_eq!(samples[1].surface, None);
}

#[test]
fn a_mesh_pressed_into_the_rock_of_a_bare_slope_stops_at_the_ground() {
    // A 50-degree plane holding 0.4 of the depth, and a cube mesh of half side 0.2 sunk so far into
    // it that its bottom is below the rock over most of its footprint: where the ground point lies
    // inside the cube the snow is pressed to the ground (a depression of 0.4, what the slope holds),
    // never below it; the GPU capture is the CPU reference's.
    let desc = SurfaceDesc::new("steep", [0.0, 2.0, 0.0], [2.0, 2.0], DEPTH);
    let t = 50f32.to_radians().tan();
    let g = move |_x: f32, z: f32| z * t;
    let mut w = world();
    let id = w.add_surface(desc.clone()).unwrap();
    w.set_ground(id, &Ground::Grid(grid_of(&desc, g)), SlopeRule::default())
        .unwrap();
    let cube = snowprint::Mesh::cuboid(Vec3::splat(0.2));
    let m = w.add_mesh("cube", &cube).unwrap();
    // At x = 0.11 no column of texel centres lies on a side of the cube.
    let pose = Pose::at([0.11, 2.0 + g(0.0, 0.0) + 0.05, 0.0]);
    w.step(1.0 / 60.0, &[Deformer::new(Shape::Mesh(m), pose)])
        .unwrap();
    let map = w.read_heightmap(id).unwrap();
    let k = 0.4f32;
    let deepest = map.depression.iter().copied().max().unwrap() as f32 / 65535.0;
    assert!(
        (deepest - k).abs() < 2.0 / 65535.0,
        "deepest {deepest}, not the ground's {k}"
    );
    let pressed_to_ground = map
        .depression
        .iter()
        .filter(|&&v| (v as f32 / 65535.0 - k).abs() < 2.0 / 65535.0)
        .count();
    // The ground point is inside the cube where -0.15 < z tan 50 < 0.25 over |z| < 0.2: about 8 rows
    // of 10 texels, of which the blur leaves the inner 6 x 8 wholly at the ground.
    assert!(pressed_to_ground >= 40, "{pressed_to_ground}");
    // The capture against the reference's winding on the field.
    let l = desc.layout();
    let field = w.ground(id).unwrap().unwrap();
    let to_local = desc.world_to_local() * glam::Mat4::from_translation(pose.position);
    let t = cube.transformed(to_local);
    let tris: Vec<[Vec3; 3]> = t
        .indices
        .chunks(3)
        .map(|i| [0, 1, 2].map(|k| t.positions[i[k] as usize]))
        .collect();
    let gpu = w.read_last_capture(id).unwrap().unwrap();
    let cpu = cap_cpu::capture_on_ground(
        l.width,
        l.height,
        desc.size * 0.5,
        DEPTH + ANKLE,
        &[],
        &tris,
        Some(&field.columns),
    );
    let mut differ = 0;
    for (a, b) in gpu.iter().zip(&cpu) {
        if (*a < 1.0) != (*b < 1.0) || (a - b).abs() > 1e-4 {
            differ += 1;
        }
    }
    // Only texel centres on the cube's edges may fall either way.
    assert!(
        differ <= 2 * l.width as usize / 10,
        "{differ} texels differ"
    );
}
