//! What the tessellated tier's passes share on the GPU: the size of the dicing's counters and
//! the texture binding of their layouts. Each pass (`banks`, `dice`, `snow_shadow` with the
//! tessellated snow draw) owns its layouts, pipelines and buffers in its own module.

use super::{ARGS_BASE, ARGS_STRIDE};

/// Texture binding for a layout (`textureLoad` only, or filtered sampling in the fragment stage).
pub(crate) fn texture(
    binding: u32,
    visibility: wgpu::ShaderStages,
    filterable: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// Bytes of the counters buffer for `n` surfaces.
pub(crate) fn counters_bytes(n: usize) -> u64 {
    (ARGS_BASE + ARGS_STRIDE * n.max(1) as u64) * 4
}
