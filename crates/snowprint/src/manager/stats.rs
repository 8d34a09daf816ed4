//! What one tick did, for reports and tests.

/// What one tick did. Serialized as one JSON object per frame by `snowprint simulate --report`.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TickStats {
    /// Frame number, from 0.
    pub frame: u64,
    /// Names of the surfaces updated this frame, in update order (player's first).
    pub updated: Vec<String>,
    /// Active surfaces: visible and near, touched, or with imprints waiting.
    pub active: usize,
    /// Surfaces holding a heightmap.
    pub resident: usize,
    /// Names of the surfaces that gave their heightmap up since the last frame.
    pub evicted: Vec<String>,
    /// Pool bytes in heightmap slots (exact, alignment included).
    pub pool_bytes_used: u64,
    /// The pool's budget, bytes.
    pub pool_bytes_budget: u64,
    /// The longest wait, in frames, of a resident surface due for an update (updated this frame or
    /// still waiting).
    pub max_wait_frames: u64,
    /// Surfaces something touched this frame.
    pub touched: usize,
    /// Resident surfaces due for an update this frame (before the budget was applied).
    pub due: usize,
    /// Active surfaces with imprints waiting for a slot of the pool.
    pub waiting_for_memory: usize,
    /// Imprints queued, over all surfaces, after this frame's updates.
    pub queued_imprints: usize,
    /// Queued imprints merged into covering sweeps this frame because a waiting surface's queue
    /// passed `queue_cap` (conservative: the kept sweep presses at least what the merged ones
    /// did). Nothing is ever dropped.
    pub imprints_merged: u64,
    /// Bytes of heightmaps read back from the GPU and paged out since the last frame (evictions
    /// and zone unloads), before compression.
    pub paged_out_bytes: u64,
    /// Bytes of heightmaps paged back in and written to the GPU this frame.
    pub paged_in_bytes: u64,
    /// Bytes the page store holds after this frame (compressed).
    pub page_store_bytes: u64,
    /// Surfaces whose heightmap is paged out after this frame.
    pub paged_surfaces: usize,
    /// Of those, surfaces whose page is still on its way from the GPU (copied out by a tick
    /// recorded with [`super::SnowManager::encode_tick`] and not read back yet; they are not
    /// admitted again until it has arrived).
    pub pages_arriving: usize,
}
