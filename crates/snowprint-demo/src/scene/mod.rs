//! What the rendered demo draws: a [`DemoScene`] is a world the command `snowprint demo` can
//! simulate and render, and [`build_scene`] picks one by name. Three worlds implement it:
//! [`rooftops`] (the demo world of this crate, [`crate::DemoWorld`], with materials and street
//! lamps), [`standin`] (a small, self-contained second world) and [`shore`] (sand, mud and snow
//! side by side, walked across by the stand-in's people).

pub mod mountain;
pub mod rooftops;
pub mod shore;
pub mod skinned;
pub mod standin;

use snowprint::render::{Environment, Instance, PointLight, Renderer};
use snowprint::{Camera, GroundMaterial, SnowWorld, SurfaceId};

/// The scenery's instances marked as staying where they are ([`Instance::still`]): their shadows
/// are kept from frame to frame while the moon's cascades hold still.
pub(crate) fn held_still(statics: Vec<Instance>) -> Vec<Instance> {
    statics.into_iter().map(|i| i.with_still(true)).collect()
}

/// A world the demo can simulate and draw. Built once (surfaces into the world, meshes into the
/// renderer), then asked what happens at each moment.
pub trait DemoScene {
    /// A short description for the report.
    fn name(&self) -> &str;
    /// Snow surfaces with the ground under each.
    fn surfaces(&self) -> &[(SurfaceId, GroundMaterial)];
    /// Street lamps and other point lights.
    fn lights(&self) -> &[PointLight];
    /// Moon, sky and haze (both demos: the moonlit night).
    fn environment(&self) -> Environment {
        Environment::moonlit_night()
    }
    /// Advance the snow of `world` from `t0` to `t1`: whatever presses the snow meanwhile, with
    /// its poses at both ends (by `SnowWorld::step`, or per surface by `SnowWorld::update`).
    fn advance(&mut self, world: &mut SnowWorld, t0: f32, t1: f32) -> Result<(), String>;
    /// Meshes to draw at time `t`.
    fn instances(&self, t: f32) -> Vec<Instance>;
    /// Names of the cameras.
    fn cameras(&self) -> &[&'static str];
    /// Seconds of the action a camera's clip covers.
    fn span(&self, camera: &str) -> (f32, f32);
    /// A camera at time `t`; `None` for an unknown name.
    fn camera(&self, name: &str, t: f32) -> Option<Camera>;
}

/// The demo world by name: `rooftops`, this crate's demo world ([`crate::DemoWorld`]),
/// `standin`, the small world the command carried before that one existed, or `shore`, the
/// materials' beach. This is the one place where a world plugs into the renderer's demo.
pub fn build_scene(
    name: &str,
    world: &mut SnowWorld,
    renderer: &mut Renderer,
) -> Result<Box<dyn DemoScene>, String> {
    match name {
        "rooftops" => Ok(Box::new(rooftops::LibraryDemo::new(world, renderer)?)),
        "standin" => Ok(Box::new(standin::StandIn::new(world, renderer)?)),
        "skinned" => Ok(Box::new(skinned::SkinnedDemo::new(world, renderer)?)),
        "shore" => Ok(Box::new(shore::Shore::new(world, renderer)?)),
        "mountain" => Ok(Box::new(mountain::Mountain::new(world, renderer)?)),
        _ => Err(format!(
            "unknown scene {name:?}; use rooftops, skinned, standin, shore, mountain or city"
        )),
    }
}
