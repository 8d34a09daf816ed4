//! # bevy_snowprint
//!
//! snowprint's deformable snow in a Bevy 0.20 game: put [`SnowSurface`] on the ground entities
//! and [`SnowDeformer`] (a sphere, capsule, box, or a closed Bevy mesh, skinned or not) on what
//! walks, rolls or falls through it, and add [`SnowprintPlugin`].
//!
//! - The snow world lives in Bevy's render world, on Bevy's own `RenderDevice` and `RenderQueue`
//!   (checked against snowprint's required limits; what falls short is [`SnowStatus::Unavailable`]
//!   with one sentence, and the game runs on without snow).
//! - Each frame its update (capture and accumulation) is recorded into the render graph's command
//!   encoder ahead of the cameras, from the deformers' `GlobalTransform`s.
//! - Every surface is drawn with [`SnowMaterial`], Bevy's `StandardMaterial` extended with
//!   snowprint's relief tier (the library's WGSL material module), lit by Bevy's lights.
//! - Gameplay asks what is under a point through [`SnowProbes`]; answers come a frame or two
//!   later, without waiting for the GPU. Deformers landing on the snow are [`SnowFootstep`]
//!   messages.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_snowprint::{SnowDeformer, SnowSurface, SnowprintPlugin};
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, SnowprintPlugin::default()))
//!     .add_systems(Startup, |mut commands: Commands| {
//!         commands.spawn((SnowSurface::new(Vec2::new(8.0, 8.0), 0.3), Transform::default()));
//!         commands.spawn((SnowDeformer::sphere(0.3), Transform::from_xyz(0.0, 0.4, 0.0)));
//!     })
//!     .run();
//! ```

mod components;
pub mod material;
mod update;

pub use bevy;
pub use snowprint;

pub use components::{DeformerShape, SnowDeformer, SnowSurface};
pub use material::{SnowExtension, SnowMaterial};
pub use update::exchange::{SnowFootstep, SnowProbes, SnowStatus, SnowUnder};

use bevy::prelude::*;
use update::exchange::SharedExchange;

/// Deformable snow: the snow world on Bevy's render device, its update in the render graph, the
/// snow material, and [`SnowProbes`].
#[derive(Clone, Debug, Default)]
pub struct SnowprintPlugin {
    /// The snow world's settings (pool size, capture, spray...): the library's defaults unless
    /// set.
    pub world: snowprint::WorldConfig,
}

impl Plugin for SnowprintPlugin {
    fn build(&self, app: &mut App) {
        let shared = SharedExchange::default();
        app.insert_resource(SnowProbes {
            shared: shared.clone(),
        })
        .insert_resource(shared.clone())
        .add_message::<SnowFootstep>()
        .add_systems(PreUpdate, update::exchange::write_footsteps);
        material::build(app);
        update::build(app, shared, self.world.clone());
    }
}
