//! `snowprint demo --scene skinned`: the rooftops with no crowd, and on the walker's roof one person
//! trudging across as the talk's deformer, the character's own skinned mesh: `scenes/Trudger.glb`
//! as the exporter writes it (`crate::export`), loaded by the library's glTF loader, posed on the
//! GPU each update at its animation's time (`SnowWorld::animate_meshes`) and pressed as one mesh
//! deformer. The body is drawn by its fifteen part meshes at the same motion's pose, which is the
//! skinned mesh's geometry (each vertex is bound to one joint with weight 1; a test holds the two
//! to 2e-5 m).

use glam::{Mat4, Quat, Vec3};
use snowprint::render::{Instance, PointLight, RenderMeshId, Renderer};
use snowprint::{
    Camera, Deformer, GroundMaterial, MeshAnimation, MeshId, Playback, Pose, Shape, SkinnedMesh,
    SnowWorld, SurfaceId,
};

use super::DemoScene;
use super::rooftops::Scenery;
use crate::anim::Motion;
use crate::export::{TRUDGER_SECONDS, trudger_glb, trudger_motion};
use crate::skeleton::Outfit;
use crate::world::surface;
use crate::{DemoWorld, Part};

/// The cameras: following the figure from behind and above (as the rooftops' `closeup`), and low
/// beside the trail, looking back along it.
const CAMERAS: [&str; 2] = ["closeup", "trail"];

/// The skinned figure on the walker's roof.
pub struct SkinnedDemo {
    scenery: Scenery,
    figure: MeshId,
    walk: Option<usize>,
    motion: Motion,
    /// Where the figure file's origin stands: on the walker's roof, its ground.
    place: Pose,
    part_render: Vec<RenderMeshId>,
    outfit: Outfit,
    ground: f32,
}

impl SkinnedDemo {
    /// Build the scenery, register the skinned figure with `world` and its parts with `renderer`.
    pub fn new(world: &mut SnowWorld, renderer: &mut Renderer) -> Result<Self, String> {
        let demo = DemoWorld::build();
        let scenery = Scenery::build(&demo, world, renderer)?;
        let skinned =
            SkinnedMesh::from_gltf_slice(&trudger_glb(), std::path::Path::new("Trudger.glb"), None)
                .map_err(|e| e.to_string())?;
        let figure = world
            .add_skinned_mesh("trudger", &skinned)
            .map_err(|e| e.to_string())?;
        let part_render = demo
            .part_meshes
            .iter()
            .map(|m| renderer.add_mesh(m).map_err(|e| e.to_string()))
            .collect::<Result<_, _>>()?;
        // The walker's path, 3 m either side of its middle: the file walks x = -3 to 3.
        let ground = demo.surfaces[surface::WALK_ROOF].desc.center.y;
        let walker = demo
            .person("walker")
            .ok_or("the demo world has no walker")?;
        Ok(Self {
            scenery,
            figure,
            walk: skinned.animation_index("walk"),
            motion: trudger_motion(),
            place: Pose {
                position: Vec3::new(-13.3, ground, -11.0),
                rotation: Quat::IDENTITY,
            },
            part_render,
            outfit: walker.outfit,
            ground,
        })
    }

    /// The pelvis in the world at `t`.
    fn root(&self, t: f32) -> Vec3 {
        self.place.position + self.place.rotation * self.motion.pose(t).root
    }
}

impl DemoScene for SkinnedDemo {
    fn name(&self) -> &str {
        "snowprint::demo skinned (scenes/Trudger.glb on the rooftops)"
    }

    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)] {
        &self.scenery.surfaces
    }

    fn lights(&self) -> &[PointLight] {
        &self.scenery.lights
    }

    /// Pose the skinned mesh at `t1` on the GPU and press the snow with it.
    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String> {
        world
            .animate_meshes(&[MeshAnimation {
                mesh: self.figure,
                animation: self.walk,
                time: t1,
                playback: Playback::Clamp,
            }])
            .map_err(|e| e.to_string())?;
        world
            .step(
                t1 - t0,
                &[Deformer::new(Shape::Mesh(self.figure), self.place)],
            )
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    fn instances(&self, t: f32) -> Vec<Instance> {
        let mut v = self.scenery.statics.clone();
        let place = Mat4::from_rotation_translation(self.place.rotation, self.place.position);
        for (part, pose) in Part::ALL.iter().zip(self.motion.pose(t).world()) {
            let m = place * Mat4::from_rotation_translation(pose.rotation, pose.position);
            let mut inst =
                Instance::new(self.part_render[part.index()], m, self.outfit.albedo(*part));
            inst.roughness = 0.8;
            v.push(inst);
        }
        v
    }

    fn cameras(&self) -> &[&'static str] {
        &CAMERAS
    }

    fn span(&self, _camera: &str) -> (f32, f32) {
        (0.0, TRUDGER_SECONDS)
    }

    fn camera(&self, name: &str, t: f32) -> Option<Camera> {
        let r = self.root(t.clamp(0.0, TRUDGER_SECONDS));
        let g = self.ground;
        let (eye, target) = match name {
            "closeup" => (
                Vec3::new(r.x - 3.0, g + 2.2, r.z + 2.0),
                Vec3::new(r.x - 0.6, g + 0.2, r.z),
            ),
            "trail" => (
                Vec3::new(r.x + 2.2, g + 1.5, r.z + 2.6),
                Vec3::new(r.x - 1.4, g + 0.2, r.z),
            ),
            _ => return None,
        };
        Some(Camera {
            eye,
            target,
            fov_y_degrees: 50.0,
        })
    }
}
