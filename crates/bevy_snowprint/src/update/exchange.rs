//! What the main world and the render world tell each other: probe questions and answers, and
//! whether the snow runs. One `Arc<Mutex<_>>` held by a resource in each world; each side locks
//! it once a frame.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};

use bevy::prelude::*;

/// Whether the snow world runs on Bevy's render device.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum SnowStatus {
    /// The render world has not started yet.
    #[default]
    Starting,
    /// The snow world runs on Bevy's device.
    Running,
    /// The snow cannot run: one sentence saying why and what to do.
    Unavailable(String),
}

/// The snow under a point, as a probe answered it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SnowUnder {
    /// The point asked about, world metres.
    pub point: Vec3,
    /// Whether a surface lies under the point (every other field is 0 and the normal +Y if not).
    pub on_snow: bool,
    /// Snow left above the ground there, metres.
    pub snow_depth_m: f32,
    /// How far the snow top is pressed below fresh snow, metres.
    pub depression_m: f32,
    /// World normal of the pressed top.
    pub normal: Vec3,
    /// How many snow updates ago the GPU read this (0: during the last one).
    pub age: u64,
}

impl SnowUnder {
    pub(crate) fn from_sample(s: &snowprint::ProbeSample, age: u64) -> Self {
        Self {
            point: Vec3::from_array(s.point.to_array()),
            on_snow: s.surface.is_some(),
            snow_depth_m: s.snow_depth_m,
            depression_m: s.depression_m,
            normal: Vec3::from_array(s.normal.to_array()),
            age,
        }
    }
}

/// A deformer landed on the snow during an update: its lowest point crossed the fresh snow's
/// top going down (snowprint's `Footstep`). Written as a Bevy message a frame or two after the
/// update, for sounds and effects.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct SnowFootstep {
    /// The entity of the [`crate::SnowDeformer`] that landed.
    pub deformer: Entity,
    /// Its lowest point at the end of the update, world metres.
    pub point: Vec3,
    /// How far below the fresh snow's top that point reaches, metres (at most the snow depth).
    pub depth_m: f32,
    /// Speed of the lowest point over the update, metres per second.
    pub speed: f32,
}

#[derive(Default)]
pub(crate) struct Exchange {
    /// Footsteps of the updates since the main world last looked.
    pub footsteps: Vec<SnowFootstep>,
    /// Keyed points asked since the render world last looked.
    pub asked: Vec<(u64, Vec3)>,
    /// The newest answer of every key.
    pub answers: HashMap<u64, SnowUnder>,
    pub status: SnowStatus,
    /// Snow updates submitted so far.
    pub updates: u64,
}

/// The shared half both worlds hold.
#[derive(Resource, Clone, Default)]
pub(crate) struct SharedExchange(pub Arc<Mutex<Exchange>>);

impl SharedExchange {
    pub fn lock(&self) -> MutexGuard<'_, Exchange> {
        // A panic while holding the lock leaves plain data behind: keep using it.
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// Gameplay's questions to the snow: ask what is under a point under a key (a foot, a wheel)
/// every frame, read the newest answer, a frame or two later (the GPU reads the heightmap after
/// the update and the answer comes back without waiting).
///
/// `examples/walk.rs` asks under each planted boot every frame and shows the answers in the
/// window's title; `docs/EMBEDDING.md` ("Bevy") has a short example.
#[derive(Resource, Clone)]
pub struct SnowProbes {
    pub(crate) shared: SharedExchange,
}

impl SnowProbes {
    /// Ask what is under `point` (world metres) for `key`; the answer replaces the key's last.
    pub fn ask(&mut self, key: u64, point: Vec3) {
        self.shared.lock().asked.push((key, point));
    }

    /// The newest answer for `key`, if one has come back.
    pub fn under(&self, key: u64) -> Option<SnowUnder> {
        self.shared.lock().answers.get(&key).copied()
    }

    /// Whether the snow runs, or why not.
    pub fn status(&self) -> SnowStatus {
        self.shared.lock().status.clone()
    }

    /// Snow updates submitted so far.
    pub fn updates(&self) -> u64 {
        self.shared.lock().updates
    }
}

/// Hand the footsteps the render world heard to the main world as messages.
pub(crate) fn write_footsteps(shared: Res<SharedExchange>, mut out: MessageWriter<SnowFootstep>) {
    let heard = std::mem::take(&mut shared.lock().footsteps);
    out.write_batch(heard);
}
