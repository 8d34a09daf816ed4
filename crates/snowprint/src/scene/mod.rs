//! Scene files: snow surfaces, capture settings and keyframed deformers in one TOML file.
//!
//! A scene is what `snowprint simulate --scene FILE` runs. The format (version 1, metres, `+Y` up)
//! is documented in `docs/SCENES.md`; in short:
//!
//! ```toml
//! version = 1
//!
//! [[surface]]
//! name = "roof"
//! center = [0.0, 10.0, 0.0]
//! size = [8.0, 6.0]
//! snow_depth = 0.3
//!
//! [[deformer]]
//! name = "ball"
//! shape = "sphere"
//! radius = 0.2
//! keys = [ { t = 0.0, position = [-3.0, 10.1, 0.0] }, { t = 4.0, position = [3.0, 10.1, 0.0] } ]
//! ```
//!
//! Every problem in a file is reported as one [`SnowError::Scene`] sentence of the form
//! `<file>:<line>: <what is wrong, quoting the value>; <what to do>`.
//!
//! [`SnowError::Scene`]: crate::error::SnowError::Scene

mod convert;
mod diagnose;
mod raw;

use std::path::{Path, PathBuf};

use glam::{EulerRot, Quat, Vec3};

use crate::deformer::Pose;
use crate::error::{Result, SnowError};
use crate::mesh::Mesh;
use crate::surface::SurfaceDesc;
use crate::world::CaptureConfig;

/// The only scene file version this library reads (the file's `version` key).
pub const SCENE_VERSION: u32 = 1;

/// The largest scene file read, bytes (4 MiB, about 90,000 deformer keys). Parsing keeps every
/// value with its position for messages, some 2 KiB a key, so the limit keeps a hostile or
/// runaway file from taking gigabytes; it is checked before parsing.
pub const MAX_SCENE_BYTES: u64 = 4 << 20;

/// A loaded scene: everything a simulation needs, checked and with meshes loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The file the scene was read from (as given to [`Scene::load`] or [`Scene::parse`]).
    pub path: PathBuf,
    /// Capture settings (`[capture]`; defaults when the table is absent).
    pub capture: CaptureConfig,
    /// The snow surfaces, in file order (`[[surface]]`).
    pub surfaces: Vec<SurfaceDesc>,
    /// The deformers, in file order (`[[deformer]]`).
    pub deformers: Vec<SceneDeformer>,
    /// The streaming zone of each surface (`zone`, default 0), in the order of `surfaces`.
    pub zones: Vec<u32>,
    /// The surface manager's limits (`[budget]`); `None` runs every surface every frame.
    pub budget: Option<SceneBudget>,
    /// The camera (`[camera]`), which decides what the manager counts as visible.
    pub camera: Option<SceneCamera>,
    /// The ground of each surface (`ground` and the slope keys), in the order of `surfaces`; `None`
    /// on flat ground.
    pub grounds: Vec<Option<SceneGround>>,
    /// The terrains whose window follows a focus (`[[terrain]]`), in file order.
    pub terrains: Vec<SceneTerrain>,
}

/// A `[[terrain]]` of a scene: see `docs/SCENES.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneTerrain {
    /// The terrain and its levels.
    pub desc: crate::window::TerrainDesc,
    /// What its window follows.
    pub follow: TerrainFollow,
    /// Line of its table in the scene file (for messages).
    pub line: usize,
}

impl SceneTerrain {
    /// Where its window is centred at time `t` of `scene`: the player deformer's position (else
    /// the first deformer's, else the camera's target) or the camera's eye, else the origin.
    pub fn focus(&self, scene: &Scene, t: f32) -> Vec3 {
        let camera = scene.camera.as_ref();
        match self.follow {
            TerrainFollow::Player => scene
                .deformers
                .iter()
                .find(|d| d.player)
                .or(scene.deformers.first())
                .map(|d| d.pose_at(t).position)
                .or(camera.map(|c| c.target))
                .unwrap_or(Vec3::ZERO),
            TerrainFollow::Camera => camera.map_or(Vec3::ZERO, |c| c.at(t).eye),
        }
    }
}

/// What a scene's terrain window is centred on each frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TerrainFollow {
    /// The deformer with `player = true` (else the first deformer; else the camera's target).
    Player,
    /// The camera's eye (else the origin).
    Camera,
}

/// The ground a scene lays a surface on: see `docs/SCENES.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneGround {
    /// The ground (a mesh's triangles already in world metres).
    pub ground: crate::ground::Ground,
    /// How much snow its slopes hold.
    pub slope: crate::ground::SlopeRule,
    /// Line of the surface's `ground` key (for messages).
    pub line: usize,
}

/// `[budget]` of a scene: see `docs/SCENES.md` and `docs/MANAGER.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBudget {
    /// Surface updates per frame (the talk's 2).
    pub updates_per_frame: Option<u32>,
    /// Bytes of the heightmap pool (the talk's 2 MiB).
    pub pool_bytes: Option<u64>,
    /// Distance from the player (or camera) within which a visible surface is active, metres.
    pub active_distance: Option<f32>,
    /// Bits a channel of the heightmaps in the pool (8, 16 or 32).
    pub precision: Option<crate::pool::Precision>,
}

/// `[camera]` of a scene: eye positions keyed in time, looking at one target.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneCamera {
    /// `(t, eye)` keys, times strictly increasing.
    pub keys: Vec<(f32, Vec3)>,
    /// The point looked at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
    /// Line of the `[camera]` table in the scene file (for messages; 0 when built by hand).
    pub line: usize,
}

impl SceneCamera {
    /// The camera at time `t` (eye interpolated linearly, held before the first key and after the
    /// last).
    pub fn at(&self, t: f32) -> crate::view::Camera {
        let eye = match (self.keys.first(), self.keys.iter().position(|k| k.0 > t)) {
            (None, _) => Vec3::ZERO,
            (Some(first), Some(0)) => first.1,
            (Some(_), None) => self.keys[self.keys.len() - 1].1,
            (Some(_), Some(i)) => {
                let (a, b) = (self.keys[i - 1], self.keys[i]);
                a.1.lerp(b.1, (t - a.0) / (b.0 - a.0))
            }
        };
        crate::view::Camera {
            eye,
            target: self.target,
            fov_y_degrees: self.fov_y_degrees,
        }
    }
}

/// One keyframed deformer of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDeformer {
    /// Its name, unique among the scene's deformers.
    pub name: String,
    /// Its geometry.
    pub shape: SceneShape,
    /// Its keys: at least one, times strictly increasing.
    pub keys: Vec<Key>,
    /// Whether it is the player (`player = true`): the manager updates the player's surface first.
    pub player: bool,
    /// For a mesh with `animation = "NAME"`: the skinned mesh and how its animation plays.
    pub animation: Option<SceneAnimation>,
    /// Line of its `[[deformer]]` table in the scene file (for messages; 0 when built by hand).
    pub line: usize,
}

/// A mesh deformer's animation (`animation`, `animation_speed`, `loop`): the file read as a
/// skinned mesh, posed each frame at the scene's time times the speed.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneAnimation {
    /// The file read with its skeleton and animations.
    pub skinned: crate::skin::SkinnedMesh,
    /// The animation's index in [`crate::SkinnedMesh::animations`].
    pub index: usize,
    /// The name as written in the scene.
    pub name: String,
    /// Animation seconds per scene second (`animation_speed`, default 1).
    pub speed: f32,
    /// Whether it starts again at its end (`loop`, default true) or holds its last pose.
    pub playback: crate::skin::Playback,
}

impl SceneAnimation {
    /// The pose of the deformer's mesh at scene time `t`, for [`crate::SnowWorld::animate_meshes`].
    pub fn at(&self, mesh: crate::MeshId, t: f32) -> crate::MeshAnimation {
        crate::MeshAnimation {
            mesh,
            animation: Some(self.index),
            time: t * self.speed,
            playback: self.playback,
        }
    }
}

/// The geometry of a scene deformer, in its own frame.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneShape {
    /// A ball.
    Sphere {
        /// Radius, metres (above 0).
        radius: f32,
    },
    /// A capsule along its local `Y` axis (see [`crate::Shape::Capsule`]).
    Capsule {
        /// Radius, metres (above 0).
        radius: f32,
        /// Half the length of the inner segment, metres (0 or more).
        half_height: f32,
    },
    /// A box.
    Box {
        /// Half of each side, metres (each above 0).
        half_extents: Vec3,
    },
    /// A triangle mesh loaded from a glTF or GLB file.
    Mesh {
        /// The file, resolved against the scene file's folder.
        path: PathBuf,
        /// The loaded mesh, in the file's frame.
        mesh: Mesh,
    },
}

/// One key of a deformer's motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Time, seconds from the start of the scene.
    pub t: f32,
    /// World position of the deformer's origin, metres.
    pub position: Vec3,
    /// Rotation as `[x, y, z]` Euler angles in degrees (see [`Key::rotation`]).
    pub rotation_degrees: Vec3,
}

impl Key {
    /// The rotation of the key: `Quat::from_euler(EulerRot::YXZ, y, x, z)` with the angles of
    /// [`Key::rotation_degrees`] in radians, i.e. the rotation about `Y` applied last (outermost),
    /// then `X`, then `Z` applied first to the shape.
    pub fn rotation(&self) -> Quat {
        let r = self.rotation_degrees;
        Quat::from_euler(
            EulerRot::YXZ,
            r.y.to_radians(),
            r.x.to_radians(),
            r.z.to_radians(),
        )
    }

    /// The key as a pose.
    pub fn pose(&self) -> Pose {
        Pose {
            position: self.position,
            rotation: self.rotation(),
        }
    }
}

impl SceneDeformer {
    /// The pose at time `t` (seconds): position and the degree triples interpolated linearly
    /// between the keys around `t`; the first key before it, the last key after it. A deformer
    /// without keys (only possible when built by hand) sits at the origin.
    pub fn pose_at(&self, t: f32) -> Pose {
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else {
            return Pose::at([0.0; 3]);
        };
        if t.is_nan() || t <= first.t {
            return first.pose();
        }
        if t >= last.t {
            return last.pose();
        }
        // keys[i - 1].t <= t < keys[i].t, with 1 <= i < len.
        let i = self.keys.partition_point(|k| k.t <= t);
        let (a, b) = (&self.keys[i - 1], &self.keys[i]);
        let f = (t - a.t) / (b.t - a.t);
        Key {
            t,
            position: a.position.lerp(b.position, f),
            rotation_degrees: a.rotation_degrees.lerp(b.rotation_degrees, f),
        }
        .pose()
    }

    /// True when the deformer never moves: a single key, or every key at the first key's position
    /// and rotation.
    pub fn is_static(&self) -> bool {
        match self.keys.split_first() {
            None => true,
            Some((first, rest)) => rest.iter().all(|k| {
                k.position == first.position && k.rotation_degrees == first.rotation_degrees
            }),
        }
    }

    /// Time of the last key, seconds.
    pub fn end_time(&self) -> f32 {
        self.keys.last().map_or(0.0, |k| k.t)
    }
}

impl Scene {
    /// Read, check and load a scene file, with its mesh files (relative to the file's folder).
    ///
    /// # Errors
    ///
    /// [`SnowError::Scene`] with one sentence `<file>:<line>: <what is wrong>; <what to do>` when
    /// the file cannot be read, is not valid TOML, breaks a rule of the format, or names a mesh
    /// file that is missing or unusable.
    pub fn load(path: &Path) -> Result<Scene> {
        use std::io::Read as _;
        let unreadable = |e: std::io::Error| {
            SnowError::Scene(format!(
                "{}: the scene file cannot be read ({e}); check the path and that it is a UTF-8 text file",
                path.display()
            ))
        };
        let file = std::fs::File::open(path).map_err(unreadable)?;
        if let Ok(meta) = file.metadata() {
            if meta.is_dir() {
                return Err(SnowError::Scene(format!(
                    "{}: this is a folder, not a scene file; give the path of a .toml scene file",
                    path.display()
                )));
            }
            check_size(meta.len(), path)?;
        }
        // Read at most one byte past the limit, whatever the metadata said (a pipe, a growing file).
        let mut bytes = Vec::new();
        file.take(MAX_SCENE_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(unreadable)?;
        check_size(bytes.len() as u64, path)?;
        let text = String::from_utf8(bytes)
            .map_err(|e| unreadable(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))?;
        Self::parse(&text, path)
    }

    /// Check a scene given as text. `path` names the file in messages, and mesh paths are
    /// resolved against its folder (mesh files are loaded here).
    ///
    /// # Errors
    ///
    /// As [`Scene::load`], except for reading the scene file itself.
    pub fn parse(text: &str, path: &Path) -> Result<Scene> {
        check_size(text.len() as u64, path)?;
        let src = diagnose::Source::new(text, path);
        let raw: raw::RawScene =
            toml::from_str(text).map_err(|e| diagnose::toml_error(&src, &e))?;
        let dir = path.parent().unwrap_or(Path::new(""));
        convert::convert(raw, &src, dir, path)
    }

    /// Length of the scene's motion, seconds: the latest last-key time over the deformers that
    /// move (0 when all are static, and never below 0).
    pub fn duration(&self) -> f32 {
        self.deformers
            .iter()
            .filter(|d| !d.is_static())
            .map(SceneDeformer::end_time)
            .fold(0.0, f32::max)
    }
}

/// Refuse a scene file over [`MAX_SCENE_BYTES`].
fn check_size(bytes: u64, path: &Path) -> Result<()> {
    if bytes > MAX_SCENE_BYTES {
        return Err(SnowError::Scene(format!(
            "{}: the scene file is {} bytes or more, but a scene may have at most {MAX_SCENE_BYTES} bytes (4 MiB, about 90,000 deformer keys); use fewer keys (a key every few frames is enough, poses are interpolated)",
            path.display(),
            bytes
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(t: f32, p: [f32; 3], r: [f32; 3]) -> Key {
        Key {
            t,
            position: Vec3::from(p),
            rotation_degrees: Vec3::from(r),
        }
    }

    fn deformer(keys: Vec<Key>) -> SceneDeformer {
        SceneDeformer {
            name: "d".into(),
            shape: SceneShape::Sphere { radius: 0.1 },
            keys,
            player: false,
            animation: None,
            line: 0,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn pose_between_before_and_after() {
        let d = deformer(vec![
            key(1.0, [0.0, 10.0, 0.0], [0.0; 3]),
            key(3.0, [2.0, 10.0, -4.0], [0.0; 3]),
            key(4.0, [2.0, 11.0, -4.0], [0.0; 3]),
        ]);
        assert!(close(d.pose_at(2.0).position, Vec3::new(1.0, 10.0, -2.0)));
        assert!(close(d.pose_at(2.5).position, Vec3::new(1.5, 10.0, -3.0)));
        assert!(close(d.pose_at(3.0).position, Vec3::new(2.0, 10.0, -4.0)));
        assert!(close(d.pose_at(3.25).position, Vec3::new(2.0, 10.25, -4.0)));
        assert!(close(d.pose_at(0.0).position, Vec3::new(0.0, 10.0, 0.0)));
        assert!(close(d.pose_at(-5.0).position, Vec3::new(0.0, 10.0, 0.0)));
        assert!(close(d.pose_at(9.0).position, Vec3::new(2.0, 11.0, -4.0)));
        assert!(close(
            d.pose_at(f32::NAN).position,
            Vec3::new(0.0, 10.0, 0.0)
        ));
        assert!(!d.is_static());
        assert_eq!(d.end_time(), 4.0);
    }

    #[test]
    fn rotation_convention_and_interpolated_degrees() {
        // [90, 0, 0]: a quarter turn about +X takes local +Y to +Z.
        let k = key(0.0, [0.0; 3], [90.0, 0.0, 0.0]);
        assert!(close(k.rotation() * Vec3::Y, Vec3::Z));
        // [0, 0, 90]: about +Z takes +Y to -X.
        let k = key(0.0, [0.0; 3], [0.0, 0.0, 90.0]);
        assert!(close(k.rotation() * Vec3::Y, -Vec3::X));
        // Halfway between [0, 0, 0] and [0, 90, 0] is 45 degrees about Y:
        // (cos 22.5, 0, sin 22.5 about y) = (x 0, y 0.382683, z 0, w 0.923880).
        let d = deformer(vec![
            key(0.0, [0.0; 3], [0.0; 3]),
            key(2.0, [0.0; 3], [0.0, 90.0, 0.0]),
        ]);
        let q = d.pose_at(1.0).rotation;
        let want = Quat::from_xyzw(0.0, 0.382_683_43, 0.0, 0.923_879_5);
        assert!((q.x - want.x).abs() < 1e-5, "{q:?}");
        assert!((q.y - want.y).abs() < 1e-5, "{q:?}");
        assert!((q.z - want.z).abs() < 1e-5, "{q:?}");
        assert!((q.w - want.w).abs() < 1e-5, "{q:?}");
    }

    #[test]
    fn static_deformers_and_empty_keys() {
        let d = deformer(vec![key(2.0, [1.0, 2.0, 3.0], [0.0; 3])]);
        assert!(d.is_static());
        assert_eq!(d.pose_at(0.0).position, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(d.pose_at(5.0).position, Vec3::new(1.0, 2.0, 3.0));
        let d = deformer(vec![
            key(0.0, [1.0, 2.0, 3.0], [0.0; 3]),
            key(5.0, [1.0, 2.0, 3.0], [0.0; 3]),
        ]);
        assert!(d.is_static());
        let scene = Scene {
            path: PathBuf::from("x.toml"),
            capture: CaptureConfig::default(),
            surfaces: vec![],
            deformers: vec![d],
            zones: vec![],
            budget: None,
            camera: None,
            grounds: vec![],
            terrains: vec![],
        };
        assert_eq!(scene.duration(), 0.0);
        let empty = deformer(vec![]);
        assert!(empty.is_static());
        assert_eq!(empty.pose_at(1.0), Pose::at([0.0; 3]));
    }
}
