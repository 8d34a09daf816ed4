//! Cameras of the demo: a scripted flythrough, a high overview, and one close camera per event.

use glam::Vec3;

use super::DemoWorld;
use snowprint::Camera;

/// Names accepted by [`DemoWorld::camera`].
pub const NAMES: [&str; 8] = [
    "flythrough",
    "overview",
    "closeup",
    "run",
    "fall",
    "angel",
    "slide",
    "fight",
];

/// A flythrough keyframe: `(time, eye, target)`.
type Key = (f32, [f32; 3], [f32; 3]);

/// Flythrough keyframes, visiting each event as it happens.
const FLYTHROUGH: [Key; 7] = [
    (0.0, [-26.0, 18.0, 0.0], [-12.0, 10.5, -3.0]),
    (1.6, [-6.0, 18.0, 1.0], [1.5, 12.5, -10.0]),
    (3.2, [2.0, 16.0, 2.0], [5.5, 9.3, 12.0]),
    (4.8, [5.0, 15.0, 3.0], [8.0, 9.3, 10.5]),
    (6.2, [5.0, 17.0, -3.0], [9.2, 10.5, -11.0]),
    (8.0, [-6.0, 18.0, -2.0], [-12.0, 10.0, -11.0]),
    (10.0, [-2.0, 30.0, 26.0], [-2.0, 8.0, -1.0]),
];

/// Catmull-Rom through the keyframes (clamped at the ends).
fn flythrough(t: f32) -> Camera {
    let keys = &FLYTHROUGH;
    let n = keys.len();
    let t = t.clamp(keys[0].0, keys[n - 1].0);
    let i = keys.windows(2).position(|w| t <= w[1].0).unwrap_or(n - 2);
    let u = (t - keys[i].0) / (keys[i + 1].0 - keys[i].0).max(1e-6);
    let at = |k: isize, f: fn(&Key) -> [f32; 3]| {
        Vec3::from(f(&keys[k.clamp(0, n as isize - 1) as usize]))
    };
    let spline = |f: fn(&Key) -> [f32; 3]| {
        let i = i as isize;
        let (p0, p1, p2, p3) = (at(i - 1, f), at(i, f), at(i + 1, f), at(i + 2, f));
        let (u2, u3) = (u * u, u * u * u);
        0.5 * (2.0 * p1
            + (p2 - p0) * u
            + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2
            + (3.0 * p1 - p0 - 3.0 * p2 + p3) * u3)
    };
    Camera {
        eye: spline(|k| k.1),
        target: spline(|k| k.2),
        fov_y_degrees: 55.0,
    }
}

/// A camera by name at time `t`.
pub fn camera(world: &DemoWorld, name: &str, t: f32) -> Option<Camera> {
    let t = t.clamp(0.0, world.duration);
    camera_following(world, name, t, &|who: &str| {
        Some(world.person(who)?.pose_at(t).root)
    })
}

/// A camera by name at time `t`, the cameras that follow someone (`closeup` the walker, `run` the
/// runner) following the pelvis that `root(name)` gives: the scripted one for [`camera`], a
/// trudging person's own ([`crate::trudge::Crowd`]) for the rendered demo.
pub fn camera_following(
    world: &DemoWorld,
    name: &str,
    t: f32,
    root: &dyn Fn(&str) -> Option<Vec3>,
) -> Option<Camera> {
    let t = t.clamp(0.0, world.duration);
    let ground = |who: &str| -> Option<f32> {
        let p = world.person(who)?;
        Some(world.surfaces.get(p.surface)?.desc.center.y)
    };
    let cam = |eye: Vec3, target: Vec3, fov: f32| Camera {
        eye,
        target,
        fov_y_degrees: fov,
    };
    Some(match name {
        "flythrough" => flythrough(t),
        "overview" => cam(
            Vec3::new(-2.0, 34.0, 31.0),
            Vec3::new(-2.0, 7.0, -1.0),
            55.0,
        ),
        "closeup" => {
            // Just behind the walker, looking down at the prints it has just left.
            let r = root("walker")?;
            let g = ground("walker")?;
            cam(
                Vec3::new(r.x - 3.0, g + 2.2, r.z + 2.0),
                Vec3::new(r.x - 0.6, g + 0.2, r.z),
                50.0,
            )
        }
        "run" => {
            let r = root("runner")?;
            let g = ground("runner")?;
            cam(
                Vec3::new(r.x - 2.5, g + 3.5, r.z - 6.5),
                Vec3::new(r.x + 0.5, g + 0.4, r.z),
                50.0,
            )
        }
        "fall" => cam(
            Vec3::new(7.0, 14.5, -4.5),
            Vec3::new(1.2, 11.8, -11.0),
            55.0,
        ),
        "angel" => cam(
            Vec3::new(9.2, 15.0, -7.0),
            Vec3::new(9.2, 10.5, -11.0),
            45.0,
        ),
        "slide" => cam(Vec3::new(3.0, 13.0, 5.5), Vec3::new(5.0, 9.2, 13.3), 50.0),
        "fight" => cam(Vec3::new(8.0, 12.8, 4.5), Vec3::new(8.0, 9.5, 10.0), 50.0),
        _ => return None,
    })
}
