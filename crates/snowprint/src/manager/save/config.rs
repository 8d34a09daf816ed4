//! The settings as saved: a stable mirror of the manager's, checked when read.

use crate::manager::{CatchUp, ManagerConfig, UNLIMITED};
use crate::pool::{PoolFormat, Precision};
use crate::world::{CaptureConfig, CaptureMode};

/// The settings as saved (a stable mirror of [`ManagerConfig`]).
#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct SavedConfig {
    /// `null` for no budget.
    updates_per_frame: Option<u64>,
    pool_bytes: u64,
    active_distance: f32,
    distance_slack_frames: u32,
    player_slots: u64,
    queue_cap: u64,
    page_bytes: u64,
    replenish_interval: f32,
    capture_mask: bool,
    ankle_height: f32,
    mask_depth: f32,
    atlas_side: u32,
    precision_bits: u32,
    normals: bool,
    /// `false`: frame by frame (the default); `true`: one capture of the union.
    #[serde(default)]
    catch_up_union: bool,
}

impl SavedConfig {
    pub(super) fn of(c: &ManagerConfig) -> Self {
        Self {
            updates_per_frame: (c.updates_per_frame != UNLIMITED)
                .then_some(c.updates_per_frame as u64),
            pool_bytes: c.pool_bytes,
            active_distance: c.active_distance,
            distance_slack_frames: c.distance_slack_frames,
            player_slots: c.player_slots as u64,
            queue_cap: c.queue_cap as u64,
            page_bytes: c.page_bytes,
            replenish_interval: c.replenish_interval,
            capture_mask: c.capture.mode == CaptureMode::Mask,
            ankle_height: c.capture.ankle_height,
            mask_depth: c.capture.mask_depth,
            atlas_side: c.atlas_side,
            precision_bits: c.format.precision.bits(),
            normals: c.format.normals,
            catch_up_union: c.catch_up == CatchUp::Union,
        }
    }

    pub(super) fn config(&self) -> std::result::Result<ManagerConfig, String> {
        let precision = Precision::from_bits(self.precision_bits).ok_or_else(|| {
            format!(
                "precision of {} bits is not 8, 16 or 32",
                self.precision_bits
            )
        })?;
        let usize_of = |v: u64, what: &str| {
            usize::try_from(v).map_err(|_| format!("{what} {v} does not fit this machine"))
        };
        let config = ManagerConfig {
            updates_per_frame: match self.updates_per_frame {
                Some(k) => usize_of(k, "updates_per_frame")?,
                None => UNLIMITED,
            },
            pool_bytes: self.pool_bytes,
            active_distance: self.active_distance,
            distance_slack_frames: self.distance_slack_frames,
            player_slots: usize_of(self.player_slots, "player_slots")?,
            queue_cap: usize_of(self.queue_cap, "queue_cap")?,
            page_bytes: self.page_bytes,
            replenish_interval: self.replenish_interval,
            capture: CaptureConfig {
                mode: if self.capture_mask {
                    CaptureMode::Mask
                } else {
                    CaptureMode::Depth
                },
                ankle_height: self.ankle_height,
                mask_depth: self.mask_depth,
            },
            atlas_side: self.atlas_side,
            format: PoolFormat {
                precision,
                normals: self.normals,
            },
            catch_up: if self.catch_up_union {
                CatchUp::Union
            } else {
                CatchUp::FrameByFrame
            },
        };
        config.validate().map_err(|e| e.to_string())?;
        Ok(config)
    }
}
