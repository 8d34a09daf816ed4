//! What a frame shows: camera, surfaces, mesh instances, lights and the night's environment.

use glam::{Mat4, Vec3};

use super::error::{RenderError, RenderResult};
use crate::surface::SurfaceId;
use crate::view::{Camera, GroundMaterial};

/// The light of the night: the moon, the sky and the haze.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Unit direction towards the moon.
    pub moon_direction: Vec3,
    /// Moonlight: the radiance a white Lambertian surface facing the moon reflects (linear RGB).
    pub moon_color: Vec3,
    /// The moon's angular radius on the sky, degrees (drawn larger than life).
    pub moon_radius_degrees: f32,
    /// Sky overhead (linear RGB radiance).
    pub sky_zenith: Vec3,
    /// Sky at the horizon.
    pub sky_horizon: Vec3,
    /// Light bounced up from the ground and the city.
    pub ground_bounce: Vec3,
    /// Strength of the city's orange glow on the horizon.
    pub city_glow: f32,
    /// Light from the whole sky on a surface facing up (what lights the snow in shadow).
    pub sky_ambient: Vec3,
    /// Tint of the snow's transition zone (the fake subsurface scattering), luminance about 1.
    pub sss_tint: Vec3,
    /// Strength of that tint (0 to 1).
    pub sss_strength: f32,
    /// Exposure before the filmic curve.
    pub exposure: f32,
    /// Haze density per metre.
    pub fog_density: f32,
}

impl Environment {
    /// A clear, cold night with a low moon.
    pub fn moonlit_night() -> Self {
        Self {
            moon_direction: Vec3::new(0.8, 0.42, 0.42).normalize(),
            moon_color: Vec3::new(0.55, 0.68, 1.0),
            moon_radius_degrees: 1.6,
            sky_zenith: Vec3::new(0.010, 0.018, 0.045),
            sky_horizon: Vec3::new(0.040, 0.055, 0.090),
            ground_bounce: Vec3::new(0.030, 0.032, 0.040),
            city_glow: 0.05,
            sky_ambient: Vec3::new(0.07, 0.10, 0.19),
            sss_tint: Vec3::new(0.72, 0.9, 1.25),
            sss_strength: 0.6,
            exposure: 0.75,
            fog_density: 0.012,
        }
    }
}

impl Default for Environment {
    fn default() -> Self {
        Self::moonlit_night()
    }
}

/// A point light (a street lamp, a lit window).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// World position.
    pub position: Vec3,
    /// Linear colour times intensity: the radiance a white surface facing it at 1 m reflects.
    pub color: Vec3,
    /// Distance where its light ends, metres.
    pub radius: f32,
}

/// The procedural material of a mesh instance. Every material but `Plain` and `Emissive` gathers
/// snow on faces that look up (see [`Instance::snow_cover`]).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum MeshMaterial {
    /// The albedo as given (people, clothes, props).
    #[default]
    Plain,
    /// Brick courses tinted by the albedo.
    Brick,
    /// Brick with a grid of windows, some of them lit.
    Facade,
    /// Concrete tinted by the albedo.
    Concrete,
    /// Painted metal with rust streaks (water towers, vents).
    Metal,
    /// Glowing (lamp bulbs): albedo times the instance's emission.
    Emissive,
}

impl MeshMaterial {
    /// Must match the `MATERIAL_*` constants of `mesh.wgsl`.
    pub(crate) fn code(self) -> f32 {
        match self {
            MeshMaterial::Plain => 0.0,
            MeshMaterial::Brick => 1.0,
            MeshMaterial::Facade => 2.0,
            MeshMaterial::Concrete => 3.0,
            MeshMaterial::Metal => 4.0,
            MeshMaterial::Emissive => 5.0,
        }
    }
}

/// Handle of a mesh registered with [`Renderer::add_mesh`](super::Renderer::add_mesh).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderMeshId(pub(crate) u32);

/// One placed mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh.
    pub mesh: RenderMeshId,
    /// Mesh frame to world.
    pub transform: Mat4,
    /// Base colour (linear RGB, 0 to 1).
    pub albedo: [f32; 3],
    /// Procedural material.
    pub material: MeshMaterial,
    /// Perceptual roughness (0 to 1).
    pub roughness: f32,
    /// Light emitted, as a multiple of the albedo.
    pub emission: f32,
    /// How much snow lies on its upward faces (0 to 1).
    pub snow_cover: f32,
    /// Whether it casts the moon's shadow.
    pub casts_shadow: bool,
    /// Whether it stays where it is from frame to frame (buildings, props): its shadow may be
    /// kept in a cascade's cache and copied in instead of drawn again
    /// ([`RenderConfig::shadow_cache`](super::RenderConfig::shadow_cache)). A still instance that
    /// does move, or changes its mesh, is still shadowed right: the cache is redrawn.
    pub still: bool,
    /// Varies the procedural patterns between instances of the same material.
    pub seed: f32,
}

impl Instance {
    /// A plain, shadow-casting instance with roughness 0.6.
    pub fn new(mesh: RenderMeshId, transform: Mat4, albedo: [f32; 3]) -> Self {
        Self {
            mesh,
            transform,
            albedo,
            material: MeshMaterial::Plain,
            roughness: 0.6,
            emission: 0.0,
            snow_cover: 0.0,
            casts_shadow: true,
            still: false,
            seed: 0.0,
        }
    }

    /// The same instance with another material; building materials gather snow on top.
    pub fn with_material(mut self, material: MeshMaterial) -> Self {
        self.material = material;
        self.snow_cover = match material {
            MeshMaterial::Plain | MeshMaterial::Emissive => 0.0,
            _ => 1.0,
        };
        self
    }

    /// The same instance glowing.
    pub fn with_emission(mut self, emission: f32) -> Self {
        self.emission = emission;
        self
    }

    /// The same instance with a shadow or without.
    pub fn with_shadow(mut self, casts_shadow: bool) -> Self {
        self.casts_shadow = casts_shadow;
        self
    }

    /// The same instance marked as staying where it is, or as moving ([`Instance::still`]).
    pub fn with_still(mut self, still: bool) -> Self {
        self.still = still;
        self
    }

    /// The same instance with a pattern seed.
    pub fn with_seed(mut self, seed: f32) -> Self {
        self.seed = seed;
        self
    }
}

/// Everything one frame shows.
#[derive(Clone, Copy, Debug)]
pub struct RenderFrame<'a> {
    /// The camera.
    pub camera: Camera,
    /// Seconds (animates falling snow).
    pub time: f32,
    /// Snow surfaces of the world to draw, with the ground under each.
    pub surfaces: &'a [(SurfaceId, GroundMaterial)],
    /// Meshes to draw.
    pub instances: &'a [Instance],
    /// Point lights; beyond 8, the 8 nearest the camera are used.
    pub lights: &'a [PointLight],
    /// Moon, sky and haze.
    pub environment: Environment,
    /// Whether snow is falling.
    pub snowfall: bool,
}

impl RenderFrame<'_> {
    /// Check the frame's values (the renderer holds `meshes` meshes).
    pub(crate) fn check(&self, meshes: usize) -> RenderResult<()> {
        let frame = self;
        let bad = |what: String, value: String, expected| {
            Err(RenderError::InvalidFrame {
                what,
                value,
                expected,
            })
        };
        let c = &frame.camera;
        if !(c.eye.is_finite() && c.target.is_finite()) || c.eye.distance(c.target) < 1e-4 {
            return bad(
                "camera".into(),
                format!(
                    "eye {:?}, target {:?}",
                    c.eye.to_array(),
                    c.target.to_array()
                ),
                "two finite, distinct points",
            );
        }
        if !(c.fov_y_degrees.is_finite() && c.fov_y_degrees > 1.0 && c.fov_y_degrees < 179.0) {
            return bad(
                "camera fov_y_degrees".into(),
                c.fov_y_degrees.to_string(),
                "between 1 and 179 degrees",
            );
        }
        if !frame.time.is_finite() {
            return bad("time".into(), frame.time.to_string(), "finite");
        }
        for (i, inst) in frame.instances.iter().enumerate() {
            if inst.mesh.0 as usize >= meshes {
                return Err(RenderError::StaleMesh { index: inst.mesh.0 });
            }
            if !finite_mat(&inst.transform) || inst.transform.determinant().abs() < 1e-12 {
                return bad(
                    format!("instance {i} transform"),
                    format!("{:?}", inst.transform),
                    "finite and invertible (no zero scale)",
                );
            }
        }
        for (i, l) in frame.lights.iter().enumerate() {
            if !(l.position.is_finite()
                && l.color.is_finite()
                && l.radius.is_finite()
                && l.radius > 0.0)
            {
                return bad(
                    format!("light {i}"),
                    format!("{l:?}"),
                    "a finite position and colour and a radius above 0",
                );
            }
        }
        let e = &frame.environment;
        if !(e.moon_direction.is_finite()
            && e.moon_direction.length() > 1e-3
            && e.exposure.is_finite()
            && e.exposure > 0.0)
        {
            return bad(
                "environment".into(),
                format!("{e:?}"),
                "a moon direction of non-zero length and an exposure above 0",
            );
        }
        if frame.surfaces.len() > super::snow::SURFACES_MAX {
            return bad(
                "surfaces".into(),
                frame.surfaces.len().to_string(),
                "at most 131072 a frame (the visibility buffer's slots)",
            );
        }
        for (i, (id, _)) in frame.surfaces.iter().enumerate() {
            if frame.surfaces[..i].iter().any(|(other, _)| other == id) {
                return bad(
                    format!("surface {}", id.index()),
                    "listed twice".into(),
                    "listed once per frame",
                );
            }
        }
        Ok(())
    }
}

fn finite_mat(m: &Mat4) -> bool {
    m.to_cols_array().iter().all(|v| v.is_finite())
}
