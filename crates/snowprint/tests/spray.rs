//! Kicked-up snow (issue 17, part 3) on the GPU against the CPU reference: particles spawn exactly
//! where an update deepened the snow by more than the threshold (read off the heights before and
//! after), none on a still scene (a deformer resting in place after its first frame, with or
//! without snow refilling), on the new snow top; they move as the reference step says; a frame's
//! spawns past the ring's capacity are dropped and counted; and the update's heights are
//! bit-identical with spray on or off; each material thins, scales and colours its own grains as
//! the reference's `place` says; the renderer's `spray` pass draws them, sand's warmer and mud's
//! darker than snow's (stills are written to `target/tmp/spray/`).

mod common;

use snowprint::glam::Vec3;
use snowprint::reference::spray::{integrate, kept, ring_fold, spawning_texels};
use snowprint::{
    Deformer, Material, Particle, PoolFormat, Pose, Precision, Shape, SnowWorld, SprayConfig,
    SurfaceDesc, SurfaceId, WorldConfig,
};

const DT: f32 = 1.0 / 60.0;
const DEPTH: f32 = 0.2;
/// The yard: 1 m square of 4 cm texels, turned 30 degrees, off the origin.
const TEXEL: f32 = 0.04;
const SIDE: u32 = 25;

fn world(spray: Option<SprayConfig>) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            format: PoolFormat::new(Precision::Bits16),
            pool_bytes: 4 << 20,
            spray,
            ..Default::default()
        },
    )
    .unwrap()
}

fn spray(capacity: u32) -> SprayConfig {
    SprayConfig {
        capacity,
        threshold: 0.02,
        ..SprayConfig::default()
    }
}

fn yard_desc(replenish_rate: f32) -> SurfaceDesc {
    let mut desc = SurfaceDesc::new("yard", [2.0, 1.0, -3.0], [1.0, 1.0], DEPTH);
    desc.yaw_degrees = 30.0;
    desc.replenish_rate = replenish_rate;
    desc
}

/// A ball pressed `depth` metres into the yard at local (x, z).
fn ball(desc: &SurfaceDesc, x: f32, z: f32, depth: f32) -> Deformer {
    let radius = 0.15;
    let local = Vec3::new(x, DEPTH - depth + radius, z);
    let p = desc.local_to_world().transform_point3(local);
    Deformer::new(Shape::Sphere { radius }, Pose::at(p.into()))
}

fn depressions(w: &SnowWorld, id: SurfaceId) -> Vec<u32> {
    w.read_channels(id).unwrap().0
}

/// The texel (row-major index) under a particle's position, and its local height.
fn texel_of(desc: &SurfaceDesc, p: &Particle) -> (usize, f32) {
    let local = desc
        .world_to_local()
        .transform_point3(Vec3::from(p.position));
    let col = (local.x / TEXEL + SIDE as f32 / 2.0).floor() as i64;
    let row = (local.z / TEXEL + SIDE as f32 / 2.0).floor() as i64;
    assert!(
        (0..SIDE as i64).contains(&col) && (0..SIDE as i64).contains(&row),
        "particle off the yard: {local}"
    );
    (row as usize * SIDE as usize + col as usize, local.y)
}

/// The texels this frame's particles (age 0) were spawned on, sorted, checking each sits on the
/// new snow top.
fn spawned_texels(desc: &SurfaceDesc, particles: &[Particle], after: &[u32]) -> Vec<usize> {
    let mut texels: Vec<usize> = particles
        .iter()
        .filter(|p| p.life > 0.0 && p.age == 0.0)
        .map(|p| {
            let (t, y) = texel_of(desc, p);
            let top = DEPTH * (1.0 - after[t] as f32 / 65535.0);
            assert!((y - top).abs() < 1e-4, "spawned at {y}, top {top}");
            assert!(p.velocity[1] > 0.0, "thrown down: {:?}", p.velocity);
            t
        })
        .collect();
    texels.sort_unstable();
    texels
}

#[test]
fn spawns_only_where_the_snow_was_pressed_deeper() {
    let config = spray(4096);
    let threshold = config.threshold_units(Precision::Bits16);
    let mut w = world(Some(config));
    let desc = yard_desc(0.0);
    let id = w.add_surface(desc.clone()).unwrap();
    let mut before = depressions(&w, id);
    let mut last_particles: Option<Vec<Particle>> = None;
    // Pressed, resting (three frames), moved, resting again.
    let poses = [
        (0.0, 0.12),
        (0.0, 0.12),
        (0.0, 0.12),
        (0.0, 0.12),
        (0.08, 0.14),
        (0.08, 0.14),
    ];
    for (frame, &(x, depth)) in poses.iter().enumerate() {
        w.step(DT, &[ball(&desc, x, 0.05, depth)]).unwrap();
        let after = depressions(&w, id);
        let expect = spawning_texels(&before, &after, 0, threshold);
        let (counters, particles) = w.read_spray().unwrap().unwrap();
        let resting = frame > 0 && poses[frame - 1] == poses[frame];
        if resting {
            assert!(
                expect.is_empty(),
                "frame {frame}: the reference spawns at rest"
            );
        } else {
            assert!(
                !expect.is_empty(),
                "frame {frame}: the press spawns nothing"
            );
        }
        assert_eq!(
            counters.last_requested,
            expect.len() as u32,
            "frame {frame}"
        );
        assert_eq!(counters.last_dropped, 0);
        assert_eq!(
            spawned_texels(&desc, &particles, &after),
            expect,
            "frame {frame}"
        );
        for &t in &expect {
            assert!(after[t] > before[t], "texel {t} spawned without growing");
        }
        // Every earlier particle took the reference's step.
        if let Some(old) = &last_particles {
            for (i, (o, n)) in old.iter().zip(&particles).enumerate() {
                if o.life > 0.0 && (n.age > 0.0 || o.life <= DT) {
                    let r = integrate(o, DT, config.gravity);
                    for k in 0..3 {
                        assert!(
                            (r.position[k] - n.position[k]).abs() < 1e-5
                                && (r.velocity[k] - n.velocity[k]).abs() < 1e-4,
                            "particle {i}: {n:?} vs reference {r:?}"
                        );
                    }
                    assert!((r.life - n.life).abs() < 1e-6 && (r.age - n.age).abs() < 1e-6);
                }
            }
        }
        let alive = particles.iter().filter(|p| p.life > 0.0).count() as u32;
        assert!(alive <= config.capacity && alive <= counters.spawned_total);
        last_particles = Some(particles);
        before = after;
    }
}

/// Snow, sand and mud yards pressed one a frame by the same ball: each frame's spawns are thinned
/// by the material's amount exactly as the reference's hash of (slot, frame) says, and every grain
/// kept carries its material's albedo, radius and drag, a life and a speed within its material's
/// factors of the world's, over its own yard.
#[test]
fn each_material_throws_its_own_grains() {
    let config = spray(4096);
    let mut w = world(Some(config));
    let materials = [
        ("snow", Material::snow()),
        ("sand", Material::sand()),
        ("mud", Material::mud()),
    ];
    let mut yards = Vec::new();
    for (k, (name, material)) in materials.iter().enumerate() {
        let mut desc = yard_desc(0.0);
        desc.name = (*name).to_owned();
        desc.center = Vec3::new(2.0 + 3.0 * k as f32, 1.0, -3.0);
        desc.material = *material;
        w.add_surface(desc.clone()).unwrap();
        yards.push(desc);
    }
    let mut head = 0;
    let mut kept_by_material = Vec::new();
    for (k, (desc, (name, material))) in yards.iter().zip(&materials).enumerate() {
        w.step(DT, &[ball(desc, 0.0, 0.05, 0.12)]).unwrap();
        let (counters, particles) = w.read_spray().unwrap().unwrap();
        let spawned = counters.last_requested - counters.last_dropped;
        assert!(spawned > 20, "{name}: {spawned} spawns");
        let look = material.spray;
        let expect = (0..spawned)
            .filter(|i| kept((head + i) % config.capacity, k as u32 + 1, look.amount))
            .count();
        let fresh: Vec<&Particle> = particles
            .iter()
            .filter(|p| p.life > 0.0 && p.age == 0.0)
            .collect();
        assert_eq!(fresh.len(), expect, "{name}: grains kept of {spawned}");
        let unorm = |c: f32| (c * 255.0).round() as u32;
        let [r, g, b] = look.albedo;
        let albedo = unorm(r) | unorm(g) << 8 | unorm(b) << 16 | 255 << 24;
        for p in &fresh {
            texel_of(desc, p);
            assert_eq!(p.albedo, albedo, "{name}");
            assert_eq!(p.radius, look.radius, "{name}");
            assert_eq!(p.drag, config.drag * look.drag, "{name}");
            let life = config.lifetime * look.lifetime;
            assert!(
                p.life <= life * 1.0001 && p.life >= 0.7 * life * 0.9999,
                "{name}: life {} of {life}",
                p.life
            );
            let speed = Vec3::from(p.velocity).length();
            assert!(
                speed <= 1.5 * config.speed * look.speed * 1.0001 && p.velocity[1] > 0.0,
                "{name}: speed {speed}"
            );
        }
        kept_by_material.push(fresh.len() as f32 / spawned as f32);
        head = counters.head;
    }
    // Snow keeps every spawn; sand about 0.6 of them and mud about 0.3 (a hash, not a count).
    assert_eq!(kept_by_material[0], 1.0);
    assert!(
        (kept_by_material[1] - 0.6).abs() < 0.2,
        "{kept_by_material:?}"
    );
    assert!(
        (kept_by_material[2] - 0.3).abs() < 0.2,
        "{kept_by_material:?}"
    );
}

#[test]
fn a_full_ring_drops_the_rest_of_the_frame_and_counts_them() {
    let capacity = 8;
    let config = spray(capacity);
    let threshold = config.threshold_units(Precision::Bits16);
    let mut w = world(Some(config));
    let desc = yard_desc(0.0);
    let id = w.add_surface(desc.clone()).unwrap();
    let (mut kept_total, mut dropped_total) = (0, 0);
    let mut before = depressions(&w, id);
    for (frame, x) in [-0.2f32, 0.1].into_iter().enumerate() {
        w.step(DT, &[ball(&desc, x, 0.0, 0.15)]).unwrap();
        let after = depressions(&w, id);
        let n = spawning_texels(&before, &after, 0, threshold).len() as u32;
        assert!(n > capacity, "frame {frame}: only {n} spawns");
        let (kept, dropped) = ring_fold(n, capacity);
        kept_total += kept;
        dropped_total += dropped;
        let (c, particles) = w.read_spray().unwrap().unwrap();
        assert_eq!(c.last_requested, n);
        assert_eq!(c.last_dropped, dropped);
        assert_eq!(
            (c.spawned_total, c.dropped_total),
            (kept_total, dropped_total)
        );
        assert_eq!(c.head, kept_total % capacity);
        assert_eq!(particles.len(), capacity as usize);
        let fresh = particles
            .iter()
            .filter(|p| p.age == 0.0 && p.life > 0.0)
            .count();
        assert_eq!(fresh as u32, kept, "frame {frame}");
        before = after;
    }
}

#[test]
fn the_update_is_the_same_with_spray_on_or_off_and_refilling_snow_at_rest_spawns_nothing() {
    let mut on = world(Some(spray(1024)));
    let mut off = world(None);
    assert!(off.spray_particles().is_none() && off.read_spray().unwrap().is_none());
    assert!(on.spray_particles().is_some());
    // Snow refilling 0.05 m/s: 0.4 % of the depth a frame, under the 2 % threshold.
    let desc = yard_desc(0.05);
    let a = on.add_surface(desc.clone()).unwrap();
    let b = off.add_surface(desc.clone()).unwrap();
    let mut requested = Vec::new();
    for frame in 0..8 {
        let x = if frame < 3 { -0.1 } else { 0.1 };
        let d = [ball(&desc, x, 0.0, 0.1)];
        on.step(DT, &d).unwrap();
        off.step(DT, &d).unwrap();
        assert_eq!(
            on.read_packed(a).unwrap(),
            off.read_packed(b).unwrap(),
            "frame {frame}"
        );
        requested.push(on.read_spray().unwrap().unwrap().0.last_requested);
    }
    // Pressed at frames 0 and 3; at rest (refilling, pressed back) otherwise.
    for (frame, &n) in requested.iter().enumerate() {
        assert_eq!(
            n > 0,
            frame == 0 || frame == 3,
            "frame {frame}: {requested:?}"
        );
    }
}

#[test]
fn bad_settings_are_refused_with_their_name() {
    let bad = SprayConfig {
        capacity: 0,
        ..SprayConfig::default()
    };
    let e = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            spray: Some(bad),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("capacity"), "{e}");
}

/// A ball sliding fast across the yard, drawn by two renderers: one world with spray and one
/// without, the same frames. The spray shows as grains over the print and nowhere else changes much;
/// the still is written for a look.
/// A ball slid across a yard of `material` in a world with spray and one without, both rendered
/// (320x180, relief); the two images, written to `target/tmp/spray/NAME_{with,without}.png`.
fn slid_yard(material: snowprint::Material, name: &str) -> [Vec<u8>; 2] {
    use snowprint::render::{Environment, PointLight, RenderConfig, RenderFrame, Renderer, Tier};
    use snowprint::{Camera, GroundMaterial};
    let mut desc = SurfaceDesc::new("yard", [0.0, 0.0, 0.0], [2.0, 2.0], DEPTH);
    desc.material = material;
    let mut worlds = [
        world(Some(SprayConfig {
            threshold: 0.02,
            speed: 2.0,
            ..SprayConfig::default()
        })),
        world(None),
    ];
    let ids: Vec<SurfaceId> = worlds
        .iter_mut()
        .map(|w| w.add_surface(desc.clone()).unwrap())
        .collect();
    for k in 0..10 {
        let x = -0.7 + 0.1 * k as f32;
        let d = [ball(&desc, x, 0.0, 0.12)];
        for w in &mut worlds {
            w.step(DT, &d).unwrap();
        }
    }
    let (c, particles) = worlds[0].read_spray().unwrap().unwrap();
    let alive = particles.iter().filter(|p| p.life > 0.0).count();
    assert!(alive > 15, "{name}: {c:?}: {alive} alive");
    let lights = [PointLight {
        position: Vec3::new(0.5, 1.5, 1.0),
        color: Vec3::new(3.0, 2.6, 2.0),
        radius: 6.0,
    }];
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("spray");
    std::fs::create_dir_all(&dir).unwrap();
    let mut images = Vec::new();
    for ((w, &id), which) in worlds.iter().zip(&ids).zip(["with", "without"]) {
        let mut config = RenderConfig::new(320, 180, Tier::Relief);
        config.shadow_map_size = 512;
        let mut r = Renderer::new(common::gpu(), config).unwrap();
        let surfaces = [(id, GroundMaterial::Concrete)];
        let frame = RenderFrame {
            camera: Camera {
                eye: Vec3::new(0.0, 0.9, 1.6),
                target: Vec3::new(-0.1, 0.2, 0.0),
                fov_y_degrees: 50.0,
            },
            time: 0.0,
            surfaces: &surfaces,
            instances: &[],
            lights: &lights,
            environment: Environment::moonlit_night(),
            snowfall: false,
        };
        let img = r.render(w, &frame).unwrap().rgba8;
        let file = dir.join(format!("{name}_{which}.png"));
        image::save_buffer(file, &img, 320, 180, image::ColorType::Rgba8).unwrap();
        images.push(img);
    }
    [images.remove(0), images.remove(0)]
}

/// Pixels the spray changed (by more than 8 of 255 in a channel): their indices.
fn changed(images: &[Vec<u8>; 2]) -> Vec<usize> {
    images[0]
        .chunks(4)
        .zip(images[1].chunks(4))
        .enumerate()
        .filter(|(_, (a, b))| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .map(|(i, _)| i)
        .collect()
}

#[test]
fn the_renderer_draws_the_spray_where_the_ball_slid() {
    let images = slid_yard(Material::snow(), "snow");
    let changed = changed(&images).len();
    assert!(changed > 20, "the spray changed {changed} pixels");
    assert!(
        changed < 320 * 180 / 5,
        "the spray changed {changed} pixels"
    );
}

/// Sand's grains are drawn warmer than snow's, mud's darker: the mean red less blue, and the mean
/// brightness, of the pixels each spray changed.
#[test]
fn each_material_draws_its_own_grains() {
    let look = |m: Material, name: &str| {
        let images = slid_yard(m, name);
        let px = changed(&images);
        assert!(
            px.len() > 10,
            "{name}: the spray changed {} pixels",
            px.len()
        );
        let (mut warm, mut bright) = (0.0, 0.0);
        for &i in &px {
            let p = &images[0][i * 4..i * 4 + 3];
            warm += p[0] as f64 - p[2] as f64;
            bright += (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
        }
        let n = px.len() as f64;
        println!(
            "{name}: {} pixels, red - blue {:.1}, brightness {:.1}",
            px.len(),
            warm / n,
            bright / n
        );
        (warm / n, bright / n)
    };
    let snow = look(Material::snow(), "snow");
    let sand = look(Material::sand(), "sand");
    let mud = look(Material::mud(), "mud");
    assert!(sand.0 > snow.0 + 10.0, "sand {sand:?}, snow {snow:?}");
    assert!(mud.1 < snow.1 - 20.0, "mud {mud:?}, snow {snow:?}");
}
