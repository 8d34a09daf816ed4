//! What the tessellated tier's passes share on the GPU: the size of the dicing's counters. Each
//! pass (`banks`, `dice`, `snow_shadow` with the tessellated snow draw) owns its layouts (from
//! the shader registry), pipelines and buffers in its own module.

use super::{ARGS_BASE, ARGS_STRIDE};

/// Bytes of the counters buffer for `n` surfaces.
pub(crate) fn counters_bytes(n: usize) -> u64 {
    (ARGS_BASE + ARGS_STRIDE * n.max(1) as u64) * 4
}
