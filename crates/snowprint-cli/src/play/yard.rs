//! The yard `snowprint play` walks in: one field of fresh snow in a low concrete wall, a few
//! snowy posts and a street lamp, under the demo's moonlit night, and the follow camera.

use glam::{Mat4, Quat, Vec2, Vec3};
use snowprint::render::{Instance, MeshMaterial, PointLight, RenderMeshId, Renderer};
use snowprint::{Camera, GroundMaterial, Mesh, MeshId, SnowWorld, SurfaceDesc, SurfaceId};

use super::player::{BALL_RADIUS, Player};

/// Side of the square field of snow, metres.
pub const SIDE: f32 = 18.0;
/// Depth of its fresh snow, metres.
pub const SNOW_DEPTH: f32 = 0.25;

/// The yard's surface, meshes and lights, registered with the world and the renderer.
pub struct Yard {
    /// The snow surface and the ground under it.
    pub surfaces: Vec<(SurfaceId, GroundMaterial)>,
    /// The lamp.
    pub lights: Vec<PointLight>,
    /// The body parts' meshes in the world (deformers), in `Part::ALL` order.
    pub part_world: Vec<MeshId>,
    part_render: Vec<RenderMeshId>,
    albedo: Vec<[f32; 3]>,
    ball: RenderMeshId,
    statics: Vec<Instance>,
}

fn rerr(e: snowprint::render::RenderError) -> String {
    e.to_string()
}

impl Yard {
    /// Build the yard into `world` and `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let werr = |e: snowprint::SnowError| e.to_string();
        let field = world
            .add_surface(SurfaceDesc::new(
                "yard",
                [0.0, 0.0, 0.0],
                [SIDE, SIDE],
                SNOW_DEPTH,
            ))
            .map_err(werr)?;
        // The demo's people wear the walker's clothes.
        let cast = snowprint_demo::people::cast();
        let outfit = cast.first().map(|p| p.outfit);
        let mut part_world = Vec::new();
        let mut part_render = Vec::new();
        let mut albedo = Vec::new();
        for (part, mesh) in snowprint_demo::skeleton::Part::ALL
            .iter()
            .zip(snowprint_demo::skeleton::part_meshes())
        {
            part_world.push(world.add_mesh(part.name(), &mesh).map_err(werr)?);
            part_render.push(renderer.add_mesh(&mesh).map_err(rerr)?);
            albedo.push(outfit.as_ref().map_or([0.5; 3], |o| o.albedo(*part)));
        }
        let ball = renderer
            .add_mesh(&Mesh::uv_sphere(BALL_RADIUS, 8, 12))
            .map_err(rerr)?;
        let (statics, lights) = Self::scenery(renderer)?;
        Ok(Self {
            surfaces: vec![(field, GroundMaterial::Concrete)],
            lights,
            part_world,
            part_render,
            albedo,
            ball,
            // The scenery stays where it is: its shadows are kept while the cascades hold still.
            statics: statics.into_iter().map(|i| i.with_still(true)).collect(),
        })
    }

    /// The wall, the posts, the lamp and the ground beyond the wall.
    fn scenery(renderer: &mut Renderer) -> Result<(Vec<Instance>, Vec<PointLight>), String> {
        let unit = renderer
            .add_mesh(&Mesh::cuboid(Vec3::splat(0.5)))
            .map_err(rerr)?;
        let block = |size: Vec3, at: Vec3, albedo: [f32; 3], material| {
            let mut i = Instance::new(
                unit,
                Mat4::from_scale_rotation_translation(size, Quat::IDENTITY, at),
                albedo,
            )
            .with_material(material);
            i.snow_cover = 1.0;
            i
        };
        let mut statics = Vec::new();
        let mut ground = block(
            Vec3::new(300.0, 1.0, 300.0),
            Vec3::new(0.0, -0.5, 0.0),
            [0.35, 0.35, 0.36],
            MeshMaterial::Concrete,
        )
        .with_shadow(false);
        ground.snow_cover = 0.8;
        statics.push(ground);
        let h = SIDE * 0.5 + 0.2;
        for (size, at) in [
            (Vec3::new(SIDE + 0.8, 0.7, 0.4), Vec3::new(0.0, 0.35, -h)),
            (Vec3::new(SIDE + 0.8, 0.7, 0.4), Vec3::new(0.0, 0.35, h)),
            (Vec3::new(0.4, 0.7, SIDE), Vec3::new(-h, 0.35, 0.0)),
            (Vec3::new(0.4, 0.7, SIDE), Vec3::new(h, 0.35, 0.0)),
        ] {
            statics.push(block(size, at, [0.5, 0.48, 0.45], MeshMaterial::Concrete));
        }
        // A few wooden posts standing in the snow.
        for (k, at) in [(-5.0, -4.0), (4.5, -6.0), (6.0, 5.0), (-6.5, 5.5)]
            .iter()
            .enumerate()
        {
            statics.push(
                block(
                    Vec3::new(0.25, 1.4, 0.25),
                    Vec3::new(at.0, 0.7, at.1),
                    [0.32, 0.2, 0.12],
                    MeshMaterial::Plain,
                )
                .with_seed(k as f32 * 0.31),
            );
        }
        // A sodium street lamp at a corner.
        let pole = renderer
            .add_mesh(&Mesh::capsule(0.07, 2.4, 4, 10))
            .map_err(rerr)?;
        let bulb = renderer
            .add_mesh(&Mesh::uv_sphere(0.18, 8, 16))
            .map_err(rerr)?;
        let base = Vec3::new(-h - 0.6, 0.0, -h - 0.6);
        let head = base + Vec3::new(0.5, 5.0, 0.5);
        statics.push(
            Instance::new(
                pole,
                Mat4::from_translation(base + Vec3::Y * 2.5),
                [0.08; 3],
            )
            .with_material(MeshMaterial::Metal),
        );
        statics.push(
            Instance::new(bulb, Mat4::from_translation(head), [1.0, 0.62, 0.28])
                .with_material(MeshMaterial::Emissive)
                .with_emission(6.0)
                .with_shadow(false),
        );
        let lights = vec![PointLight {
            position: head - Vec3::Y * 0.25,
            color: Vec3::new(1.0, 0.55, 0.22) * 9.0,
            radius: 18.0,
        }];
        Ok((statics, lights))
    }

    /// What to draw this frame: the scenery, the person and the snowballs.
    pub fn instances(&self, player: &Player) -> Vec<Instance> {
        let mut v = self.statics.clone();
        for ((pose, &mesh), &albedo) in player
            .parts()
            .iter()
            .zip(&self.part_render)
            .zip(&self.albedo)
        {
            let mut inst = Instance::new(
                mesh,
                Mat4::from_rotation_translation(pose.rotation, pose.position),
                albedo,
            );
            inst.roughness = 0.8;
            v.push(inst);
        }
        for b in player.balls() {
            v.push(Instance::new(
                self.ball,
                Mat4::from_translation(b.position),
                [0.9, 0.92, 0.95],
            ));
        }
        v
    }
}

/// The follow camera: it orbits the person at a distance, turned by mouse drags or the arrows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Angle about the person, radians (0: the camera is south, +z, looking north).
    pub yaw: f32,
    /// Angle above the horizon, radians.
    pub pitch: f32,
    /// Distance to the person, metres.
    pub distance: f32,
    /// The point followed (smoothed).
    target: Vec3,
}

impl Orbit {
    /// Behind and above a person at `target`.
    pub fn new(target: Vec3) -> Self {
        Self {
            yaw: 0.0,
            pitch: 0.45,
            distance: 5.5,
            target,
        }
    }

    /// Turn by `yaw` and `pitch` radians (pitch kept between 5 and 80 degrees).
    pub fn turn(&mut self, yaw: f32, pitch: f32) {
        self.yaw = (self.yaw + yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + pitch).clamp(0.09, 1.4);
    }

    /// Follow `target` over `dt` seconds.
    pub fn follow(&mut self, target: Vec3, dt: f32) {
        self.target += (target - self.target) * (1.0 - (-5.0 * dt).exp());
    }

    /// The camera.
    pub fn camera(&self) -> Camera {
        let back = Vec3::new(
            self.yaw.sin() * self.pitch.cos(),
            self.pitch.sin(),
            self.yaw.cos() * self.pitch.cos(),
        );
        Camera {
            eye: self.target + back * self.distance,
            target: self.target,
            fov_y_degrees: 55.0,
        }
    }

    /// The ground direction (x, z) that walking "forward" goes: away from the camera.
    pub fn forward(&self) -> Vec2 {
        Vec2::new(-self.yaw.sin(), -self.yaw.cos())
    }

    /// The ground direction to the camera's right.
    pub fn right(&self) -> Vec2 {
        Vec2::new(self.yaw.cos(), -self.yaw.sin())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forward_is_away_from_the_camera_and_right_is_its_right() {
        let mut o = Orbit::new(Vec3::ZERO);
        for yaw in [0.0, 1.0, 2.5, 4.0] {
            o.yaw = yaw;
            let cam = o.camera();
            let away = (cam.target - cam.eye) * Vec3::new(1.0, 0.0, 1.0);
            let f = o.forward();
            assert!(away.normalize().dot(Vec3::new(f.x, 0.0, f.y)) > 0.999);
            // Right-handed, +Y up: right = forward x up.
            let r = Vec3::new(f.x, 0.0, f.y).cross(Vec3::Y);
            assert!((Vec2::new(r.x, r.z) - o.right()).length() < 1e-5);
        }
        o.turn(0.0, 5.0);
        assert_eq!(o.pitch, 1.4);
    }
}
