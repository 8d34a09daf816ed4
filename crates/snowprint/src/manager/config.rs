//! A manager's settings, checked before anything is made.

use crate::error::{Result, SnowError};
use crate::world::CaptureConfig;

/// Updates per frame that means "no budget".
pub const UNLIMITED: usize = usize::MAX;

/// Settings of a manager.
#[derive(Clone, Debug, PartialEq)]
pub struct ManagerConfig {
    /// Most surface updates per frame, `K` (the talk's 2). [`UNLIMITED`] updates every due surface.
    pub updates_per_frame: usize,
    /// Bytes of the heightmap pool (the talk's 2 MB: default 2 MiB).
    pub pool_bytes: u64,
    /// A visible surface is active only within this distance of the camera's eye, metres
    /// (default 60).
    pub active_distance: f32,
    /// The largest head start, in frames, that a near surface has over a far one (`S`, default 8):
    /// a surface's deadline is the frame it became due plus `S * min(distance / active_distance, 1)`.
    pub distance_slack_frames: u32,
    /// Updates a frame reserved for the player's surfaces, at most `K - 1` (default 1).
    pub player_slots: usize,
    /// Most imprints kept queued on a surface that waits for its update (default 1024, about
    /// 96 bytes each); past it, neighbouring entries merge into covering sweeps (see
    /// [`crate::low_level::queue`]). A surface updated in a frame takes its whole queue, however long.
    pub queue_cap: usize,
    /// Bytes the page store may hold (evicted heightmaps, compressed); default unlimited
    /// (`u64::MAX`). A surface is evicted only when the store has room for its whole slot, so a
    /// heightmap is never lost for want of it: when the store is full, candidates for a slot wait.
    /// A zone unload pages its surfaces whatever the store holds (the game asked for it).
    pub page_bytes: u64,
    /// Seconds between the updates of a surface that only needs its snowfall refilled (default
    /// 0.25).
    pub replenish_interval: f32,
    /// Capture settings of the world.
    pub capture: CaptureConfig,
    /// Largest side of the world's capture atlas, texels.
    pub atlas_side: u32,
    /// How the world's pool stores heightmaps (bits a channel, normals or not).
    pub format: crate::pool::PoolFormat,
    /// How a surface that waited catches up with its queued imprints (default
    /// [`CatchUp::FrameByFrame`], exact).
    pub catch_up: CatchUp,
}

/// How a surface that waited for its update captures the imprints queued meanwhile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CatchUp {
    /// One capture and update per queued frame, in order: the heightmap ends exactly as if the
    /// surface had been updated every frame, and a waiting surface costs, when its turn comes, one
    /// update per frame it waited (the budget bounds the surfaces updated a frame, not the work).
    #[default]
    FrameByFrame,
    /// One capture of everything queued, as the talk's budget intends: a surface costs one update
    /// whatever it waited. Never shallower than frame by frame; where the sweeps of successive
    /// frames meet within the blur's reach (a dragged shape), the blur of their union is a little
    /// deeper along the trench (measured: +1 % pressed volume, at most 1.4 % of the snow depth at a
    /// texel; `tests/manager.rs`).
    Union,
}

impl Default for ManagerConfig {
    fn default() -> Self {
        Self {
            updates_per_frame: 2,
            pool_bytes: 2 << 20,
            active_distance: 60.0,
            distance_slack_frames: 8,
            player_slots: 1,
            queue_cap: 1024,
            page_bytes: u64::MAX,
            replenish_interval: 0.25,
            capture: CaptureConfig::default(),
            atlas_side: 2048,
            format: crate::pool::PoolFormat::default(),
            catch_up: CatchUp::FrameByFrame,
        }
    }
}

impl ManagerConfig {
    /// Check every field, naming the first one that is wrong.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::Config {
                config: "manager setting",
                what,
                value,
                expected,
            })
        };
        if self.updates_per_frame == 0 {
            return bad("updates_per_frame", "0".into(), "1 or more");
        }
        if !(self.active_distance.is_finite() && self.active_distance >= 0.0) {
            return bad(
                "active_distance",
                self.active_distance.to_string(),
                "a finite number of metres, 0 or more",
            );
        }
        if self.queue_cap == 0 {
            return bad("queue_cap", "0".into(), "1 or more");
        }
        if !(self.replenish_interval.is_finite() && self.replenish_interval >= 0.0) {
            return bad(
                "replenish_interval",
                self.replenish_interval.to_string(),
                "a finite number of seconds, 0 or more",
            );
        }
        let ankle = self.capture.ankle_height;
        if !(ankle.is_finite() && ankle > 0.0) {
            return bad(
                "ankle_height",
                ankle.to_string(),
                "a finite number of metres above 0",
            );
        }
        Ok(())
    }
}
