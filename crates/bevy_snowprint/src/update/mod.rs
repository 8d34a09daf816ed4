//! The snow world in Bevy's render world: created on Bevy's own device and queue, its update
//! recorded each frame into the render graph's command encoder ahead of the cameras, and each
//! surface's heights copied where its material reads them.
//!
//! Per frame:
//! 1. `ExtractSchedule`: [`extract_surfaces`] and [`extract_deformers`] copy the surfaces, the
//!    deformers (their `GlobalTransform`s, skinned meshes' joint matrices) and the frame's time
//!    step out of the main world, registering meshes with the snow world the first time.
//! 2. `RenderGraph`, before Bevy's `camera_driver`: [`record`] adds and removes surfaces, sends
//!    the probes asked, records the skinning of skinned deformers and `SnowWorld::encode_step`
//!    into the render context's encoder, hands the update's footsteps to the main world, then
//!    (`copy.rs`) each surface's `SurfaceUniform` and heights into its material's buffers.
//! 3. `RenderGraph`, after Bevy submitted: [`finish`] tells the world the frame was submitted and
//!    hands the probes' newest answers to the main world.

mod copy;
pub(crate) mod exchange;

use std::collections::HashMap;

use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::renderer::{
    RenderAdapter, RenderContext, RenderDevice, RenderGraph, RenderGraphSystems, RenderQueue,
};
use bevy::render::storage::GpuShaderBuffer;
use bevy::render::{Extract, ExtractSchedule, RenderApp, RenderStartup};
use snowprint::{Deformer, GpuContext, PendingFrame, Pose, SnowWorld, SurfaceId, WorldConfig};

use crate::components::pose_of;
use crate::material::SnowSurfaceBuffers;
use crate::{SnowDeformer, SnowSurface};
use exchange::{SharedExchange, SnowStatus, SnowUnder};

/// Register the render world's resources and systems.
pub(crate) fn build(app: &mut App, shared: SharedExchange, config: WorldConfig) {
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        shared.lock().status = SnowStatus::Unavailable(
            "the snow needs Bevy's RenderPlugin (DefaultPlugins with the bevy_render feature)"
                .into(),
        );
        return;
    };
    render_app
        .insert_resource(shared)
        .insert_resource(SnowSettings(config))
        .init_resource::<ExtractedSnow>()
        .add_systems(RenderStartup, start)
        .add_systems(ExtractSchedule, (extract_surfaces, extract_deformers))
        .add_systems(
            RenderGraph,
            (
                record
                    .in_set(RenderGraphSystems::Render)
                    .before(bevy::core_pipeline::schedule::camera_driver),
                finish.in_set(RenderGraphSystems::Finish),
            ),
        );
}

/// The world's settings, kept until the render device exists.
#[derive(Resource)]
struct SnowSettings(WorldConfig);

/// One surface as extracted from the main world.
struct ExtractedSurface {
    entity: Entity,
    desc: snowprint::SurfaceDesc,
    buffers: Option<SnowSurfaceBuffers>,
}

/// The main world's snow this frame.
#[derive(Resource, Default)]
struct ExtractedSnow {
    surfaces: Vec<ExtractedSurface>,
    deformers: Vec<(Entity, snowprint::Shape, Pose)>,
    /// Skinned mesh deformers' joint matrices this frame (`joint global * inverse bind`).
    skins: Vec<(snowprint::MeshId, Vec<snowprint::glam::Mat4>)>,
    dt: f32,
}

/// The snow world and what it remembers between frames.
#[derive(Resource)]
pub(crate) struct RenderSnow {
    world: SnowWorld,
    surfaces: HashMap<Entity, SurfaceId>,
    /// Surfaces refused (bad settings): said once, not asked again.
    refused: HashMap<Entity, String>,
    previous: HashMap<Entity, Pose>,
    pending: Option<PendingFrame>,
    keys: Vec<u64>,
    /// Bevy meshes registered as deformers, or why they could not be (said once).
    meshes: HashMap<AssetId<Mesh>, Result<snowprint::MeshId, String>>,
    /// Skinned mesh deformers, one registration an entity (each is skinned into its own
    /// vertices).
    skinned: HashMap<Entity, Result<snowprint::MeshId, String>>,
}

impl RenderSnow {
    /// Remove the skinned meshes of deformers not seen this frame.
    fn forget_skinned_except(&mut self, seen: &[Entity]) {
        let gone: Vec<Entity> = self
            .skinned
            .keys()
            .filter(|e| !seen.contains(e))
            .copied()
            .collect();
        for entity in gone {
            if let Some(Ok(id)) = self.skinned.remove(&entity)
                && let Err(e) = self.world.remove_mesh(id)
            {
                warn!("the skinned snow deformer {entity} could not be removed: {e}");
            }
        }
    }

    /// The library's skinned mesh of a skinned deformer entity, registered the first time.
    fn skinned_mesh(
        &mut self,
        entity: Entity,
        id: AssetId<Mesh>,
        meshes: &Assets<Mesh>,
        inverse_bindposes: &[Mat4],
    ) -> Option<snowprint::MeshId> {
        if let Some(known) = self.skinned.get(&entity) {
            return known.as_ref().ok().copied();
        }
        let mesh = meshes.get(id)?;
        let registered =
            crate::components::library_skinned_mesh(mesh, inverse_bindposes).and_then(|m| {
                self.world
                    .add_skinned_mesh(&format!("{entity}"), &m)
                    .map_err(|e| e.to_string())
            });
        if let Err(e) = &registered {
            warn!("the skinned snow deformer {entity} {e}");
        }
        let answer = registered.as_ref().ok().copied();
        self.skinned.insert(entity, registered);
        answer
    }

    /// The library's mesh of a Bevy mesh, registered the first time it is asked for; `None` (and
    /// one warning) for a mesh that is not a closed triangle list, `None` without a word while
    /// the asset is still loading.
    fn mesh(&mut self, id: AssetId<Mesh>, meshes: &Assets<Mesh>) -> Option<snowprint::MeshId> {
        if let Some(known) = self.meshes.get(&id) {
            return known.as_ref().ok().copied();
        }
        let mesh = meshes.get(id)?;
        let registered = crate::components::library_mesh(mesh).and_then(|m| {
            self.world
                .add_mesh(&format!("{id:?}"), &m)
                .map_err(|e| e.to_string())
        });
        if let Err(e) = &registered {
            warn!("the snow deformer's mesh {id:?} {e}");
        }
        let answer = registered.as_ref().ok().copied();
        self.meshes.insert(id, registered);
        answer
    }
}

/// Create the snow world on Bevy's device, checked against snowprint's required features and
/// limits; what falls short is said in one sentence and the snow stays off.
fn start(
    mut commands: Commands,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    adapter: Res<RenderAdapter>,
    settings: Res<SnowSettings>,
    shared: Res<SharedExchange>,
) {
    let created =
        GpuContext::from_device(&adapter, device.wgpu_device().clone(), (**queue).clone())
            .and_then(|gpu| SnowWorld::new(&gpu, settings.0.clone()));
    match created {
        Ok(world) => {
            commands.insert_resource(RenderSnow {
                world,
                surfaces: HashMap::new(),
                refused: HashMap::new(),
                previous: HashMap::new(),
                pending: None,
                keys: Vec::new(),
                meshes: HashMap::new(),
                skinned: HashMap::new(),
            });
            shared.lock().status = SnowStatus::Running;
        }
        Err(e) => {
            let sentence = unavailable(&e);
            error!("{sentence}");
            shared.lock().status = SnowStatus::Unavailable(sentence);
        }
    }
}

/// Why the snow cannot run on Bevy's device, and what to do.
pub(crate) fn unavailable(e: &snowprint::SnowError) -> String {
    match e {
        snowprint::SnowError::DeviceLimit {
            limit,
            required,
            available,
        } => format!(
            "the snow needs the render device's {limit} to be at least {required} but Bevy's device has {available}: allow it in RenderPlugin's WgpuSettings (limits and constrained_limits; WgpuSettingsPriority::Functionality takes the adapter's) or run on an adapter that has it"
        ),
        other => format!("the snow cannot run on Bevy's render device: {other}"),
    }
}

// Bevy's extract queries are tuples of what they read; naming them adds nothing.
#[allow(clippy::type_complexity)]
fn extract_surfaces(
    mut extracted: ResMut<ExtractedSnow>,
    surfaces: Extract<
        Query<(
            Entity,
            &SnowSurface,
            &GlobalTransform,
            Option<&SnowSurfaceBuffers>,
        )>,
    >,
    time: Extract<Res<Time>>,
) {
    extracted.surfaces.clear();
    for (entity, surface, transform, buffers) in &surfaces {
        extracted.surfaces.push(ExtractedSurface {
            entity,
            desc: surface.desc(&format!("{entity}"), transform),
            buffers: buffers.cloned(),
        });
    }
    extracted.dt = time.delta_secs();
}

/// The deformers' shapes and poses; meshes registered with the snow world the first time, and
/// skinned meshes' joint matrices.
#[allow(clippy::type_complexity)]
fn extract_deformers(
    mut extracted: ResMut<ExtractedSnow>,
    deformers: Extract<
        Query<(
            Entity,
            &SnowDeformer,
            &GlobalTransform,
            Option<&SkinnedMesh>,
        )>,
    >,
    joints: Extract<Query<&GlobalTransform>>,
    bindposes: Extract<Res<Assets<SkinnedMeshInverseBindposes>>>,
    meshes: Extract<Res<Assets<Mesh>>>,
    snow: Option<ResMut<RenderSnow>>,
) {
    extracted.deformers.clear();
    extracted.skins.clear();
    let mut snow = snow;
    let mut skinned_seen = Vec::new();
    for (entity, deformer, transform, skinned) in &deformers {
        if let (crate::DeformerShape::Mesh(handle), Some(skinned)) = (&deformer.shape, skinned) {
            skinned_seen.push(entity);
            let Some(snow) = snow.as_deref_mut() else {
                continue;
            };
            let Some(inverse) = bindposes.get(&skinned.inverse_bindposes) else {
                continue;
            };
            let matrices: Option<Vec<snowprint::glam::Mat4>> = skinned
                .joints
                .iter()
                .zip(inverse.iter())
                .map(|(&joint, inverse)| {
                    let global = joints.get(joint).ok()?.to_matrix() * *inverse;
                    Some(snowprint::glam::Mat4::from_cols_array(
                        &global.to_cols_array(),
                    ))
                })
                .collect();
            let (Some(matrices), Some(id)) = (
                matrices,
                snow.skinned_mesh(entity, handle.id(), &meshes, inverse),
            ) else {
                continue;
            };
            extracted.skins.push((id, matrices));
            // The joints' matrices carry the mesh into the world: the deformer stands at the origin.
            extracted
                .deformers
                .push((entity, snowprint::Shape::Mesh(id), Pose::at([0.0; 3])));
            continue;
        }
        let shape = match (&deformer.shape, deformer.shape.analytic()) {
            (_, Some(shape)) => shape,
            (crate::DeformerShape::Mesh(handle), None) => {
                let Some(snow) = snow.as_deref_mut() else {
                    continue;
                };
                match snow.mesh(handle.id(), &meshes) {
                    Some(id) => snowprint::Shape::Mesh(id),
                    None => continue,
                }
            }
            (_, None) => continue,
        };
        extracted
            .deformers
            .push((entity, shape, pose_of(transform)));
    }
    // Skinned deformers gone (their entity or component): their meshes leave the snow world.
    if let Some(snow) = snow.as_deref_mut() {
        snow.forget_skinned_except(&skinned_seen);
    }
}

/// Record the snow's update into the render graph's encoder, ahead of the cameras.
fn record(
    mut ctx: RenderContext,
    snow: Option<ResMut<RenderSnow>>,
    extracted: Res<ExtractedSnow>,
    shader_buffers: Res<RenderAssets<GpuShaderBuffer>>,
    queue: Res<RenderQueue>,
    shared: Res<SharedExchange>,
) {
    let Some(mut snow) = snow else { return };
    let snow = &mut *snow;
    if snow.pending.take().is_some() {
        // The last frame's `finish` did not run (no submit): its encoder is gone.
        snow.world.abandon_pending();
    }
    sync_surfaces(snow, &extracted.surfaces);
    let deformers = deformers(snow, &extracted.deformers);
    for (key, point) in std::mem::take(&mut shared.lock().asked) {
        let point = snowprint::glam::Vec3::from_array(point.to_array());
        match snow.world.probe_keyed(key, point) {
            Ok(()) if !snow.keys.contains(&key) => snow.keys.push(key),
            Ok(()) => {}
            Err(e) => warn!("a snow probe was not sent: {e}"),
        }
    }
    let encoder = ctx.command_encoder();
    if !extracted.skins.is_empty() {
        let poses: Vec<(snowprint::MeshId, &[snowprint::glam::Mat4])> = extracted
            .skins
            .iter()
            .map(|(id, m)| (*id, m.as_slice()))
            .collect();
        // Skinned before the update that captures them, in the same encoder.
        if let Err(e) = snow.world.encode_skin_meshes(encoder, &poses) {
            error!("the snow's skinned deformers were not skinned: {e}");
        }
    }
    match snow.world.encode_step(encoder, extracted.dt, &deformers) {
        Ok(pending) => snow.pending = Some(pending),
        Err(e) => {
            error!("the snow's update was not recorded: {e}");
            return;
        }
    }
    // A footstep names its deformer by its index in the update's list: this frame's entities.
    let heard: Vec<_> = snow
        .world
        .footsteps()
        .iter()
        .filter_map(|f| {
            let &(entity, _, _) = extracted.deformers.get(f.deformer)?;
            Some(exchange::SnowFootstep {
                deformer: entity,
                point: Vec3::from_array(f.point.to_array()),
                depth_m: f.depth_m,
                speed: f.speed,
            })
        })
        .collect();
    shared.lock().footsteps.extend(heard);
    copy::surfaces_to_materials(
        &snow.world,
        &snow.surfaces,
        &extracted.surfaces,
        &shader_buffers,
        &queue,
        encoder,
    );
}

/// Add the surfaces seen for the first time, remove those gone from the main world.
fn sync_surfaces(snow: &mut RenderSnow, surfaces: &[ExtractedSurface]) {
    for s in surfaces {
        if snow.surfaces.contains_key(&s.entity) || snow.refused.contains_key(&s.entity) {
            continue;
        }
        match snow.world.add_surface(s.desc.clone()) {
            Ok(id) => {
                snow.surfaces.insert(s.entity, id);
            }
            Err(e) => {
                let sentence = format!("snow surface on entity {} was refused: {e}", s.entity);
                error!("{sentence}");
                snow.refused.insert(s.entity, sentence);
            }
        }
    }
    let gone: Vec<Entity> = snow
        .surfaces
        .keys()
        .filter(|e| !surfaces.iter().any(|s| s.entity == **e))
        .copied()
        .collect();
    for entity in gone {
        if let Some(id) = snow.surfaces.remove(&entity)
            && let Err(e) = snow.world.remove_surface(id)
        {
            warn!("snow surface of entity {entity} could not be removed: {e}");
        }
    }
    snow.refused
        .retain(|e, _| surfaces.iter().any(|s| s.entity == *e));
}

/// The frame's deformers, each swept from where it was last frame.
fn deformers(
    snow: &mut RenderSnow,
    extracted: &[(Entity, snowprint::Shape, Pose)],
) -> Vec<Deformer> {
    let list = extracted
        .iter()
        .map(|&(entity, shape, pose)| match snow.previous.get(&entity) {
            // Meshes are captured at their pose only (the library sweeps analytic shapes).
            Some(&previous) if !matches!(shape, snowprint::Shape::Mesh(_)) => {
                Deformer::moving(shape, previous, pose)
            }
            _ => Deformer::new(shape, pose),
        })
        .collect();
    snow.previous = extracted.iter().map(|&(e, _, pose)| (e, pose)).collect();
    list
}

/// After Bevy's submit: the frame is on the GPU; hand the probes' answers to the main world.
fn finish(snow: Option<ResMut<RenderSnow>>, shared: Res<SharedExchange>) {
    let Some(mut snow) = snow else { return };
    let Some(pending) = snow.pending.take() else {
        return;
    };
    if let Err(e) = snow.world.submitted(pending) {
        error!("the snow's frame could not be completed: {e}");
    }
    let mut exchange = shared.lock();
    exchange.updates += 1;
    for &key in &snow.keys {
        if let Some((sample, age)) = snow.world.under(key) {
            exchange
                .answers
                .insert(key, SnowUnder::from_sample(&sample, age));
        }
    }
}
