//! The bytes each per-frame buffer of a plan must hold.

/// Bytes each per-frame buffer must hold for the plan (0: not used this frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BufferSizes {
    /// Surface records.
    pub records: u64,
    /// Capture views, one uniform block each.
    pub views: u64,
    /// Analytic primitives.
    pub prims: u64,
    /// Mesh draws, one uniform block each.
    pub draws: u64,
    /// Blurred captures (separate passes only).
    pub scratch: u64,
    /// The capture.
    pub capture: u64,
    /// Mesh winding (only when meshes are drawn).
    pub winding: u64,
    /// Tile flags.
    pub tiles: u64,
    /// The tile list with its header.
    pub tile_list: u64,
    /// Relaxation records.
    pub relax_records: u64,
    /// Relaxation scratch (a u32 a texel of every relaxing surface).
    pub relax_scratch: u64,
    /// Relaxation tile flags (a u32 a tile of every relaxing surface's rectangle).
    pub relax_tiles: u64,
}

impl BufferSizes {
    /// The first buffer (its name and bytes) larger than `max` bytes, the device's largest
    /// storage binding, in the order the fields are declared.
    pub fn first_over(&self, max: u64) -> Option<(&'static str, u64)> {
        [
            ("surface records", self.records),
            ("capture views", self.views),
            ("analytic primitives", self.prims),
            ("mesh draws", self.draws),
            ("blurred captures", self.scratch),
            ("capture", self.capture),
            ("mesh winding", self.winding),
            ("tile flags", self.tiles),
            ("tile list", self.tile_list),
            ("relaxation records", self.relax_records),
            ("relaxation scratch", self.relax_scratch),
            ("relaxation tiles", self.relax_tiles),
        ]
        .into_iter()
        .find(|&(_, bytes)| bytes > max)
    }
}
