//! The features and limits a device must have for the world's update and the renderer's passes,
//! and the check of a caller's device against them.
//!
//! The limits start from `wgpu::Limits::downlevel_defaults()` (what every Vulkan, Metal and DX12
//! device offers) and raise only what a pass needs beyond it. The counts below are the largest of
//! any pipeline of the shader registry ([`crate::wgsl`]); `tests/embedding.rs` creates a device
//! with exactly these limits and runs the update and both render tiers on it.

use crate::error::{Result, SnowError};

/// The `wgpu::Features` the world and the renderer need: none. GPU timestamps
/// (`TIMESTAMP_QUERY`) are optional; [`crate::GpuContext::new`] asks for them where the adapter
/// has them and profiling falls back to CPU times where it does not.
pub fn required_features() -> wgpu::Features {
    wgpu::Features::empty()
}

/// The `wgpu::Limits` the world and the renderer need at their default settings (a 32 MiB pool,
/// a 2048-texel capture atlas and shadow map). Larger settings are clamped to, or checked against,
/// the device's own limits, so an engine that wants a bigger pool or atlas raises those limits
/// (`max_storage_buffer_binding_size`, `max_buffer_size`, `max_texture_dimension_2d`).
pub fn required_limits() -> wgpu::Limits {
    let base = wgpu::Limits::downlevel_defaults();
    wgpu::Limits {
        // The fused blur + merge dispatch (accumulate/fused.wgsl) binds eight storage buffers in
        // the compute stage: records, capture, pool, winding, tiles, tile list, and the primitives
        // and ground fields of the surfaces it ray-casts itself (`CapturePath::Update`). The
        // capture's fragment stage (capture/capture.wgsl) binds five: primitives, and the capture,
        // winding, tile flags and tile list it writes with atomics. Downlevel devices promise
        // four; WebGPU promises eight.
        max_storage_buffers_per_shader_stage: 8,
        // Two at most (capture, tonemap, the snow passes: frame or view globals, then the pass's
        // own group).
        max_bind_groups: base.max_bind_groups.max(2),
        // Capture views and mesh draws are chosen by dynamic offset (capture/capture.wgsl).
        max_dynamic_uniform_buffers_per_pipeline_layout: base
            .max_dynamic_uniform_buffers_per_pipeline_layout
            .max(2),
        // The heightfield pass writes two storage textures (render/heightfield).
        max_storage_textures_per_shader_stage: base.max_storage_textures_per_shader_stage.max(2),
        // 256 invocations a workgroup: the fused update's 16 x 16 tiles (accumulate/fused.wgsl),
        // the classify pass's 256 x 1 (render/classify).
        max_compute_invocations_per_workgroup: base.max_compute_invocations_per_workgroup.max(256),
        max_compute_workgroup_size_x: base.max_compute_workgroup_size_x.max(256),
        max_compute_workgroup_size_y: base.max_compute_workgroup_size_y.max(16),
        // The default capture atlas and shadow map are 2048 texels a side.
        max_texture_dimension_2d: base.max_texture_dimension_2d.max(2048),
        // The default heightmap pool is one 32 MiB storage binding.
        max_storage_buffer_binding_size: base.max_storage_buffer_binding_size.max(32 << 20),
        ..base
    }
}

/// Check a device's features and limits against [`required_features`] and
/// [`required_limits`]: the first limit below what is needed is
/// [`SnowError::DeviceLimit`], missing features are [`SnowError::DeviceFeature`].
pub fn check_device(device: &wgpu::Device) -> Result<()> {
    check(device.features(), &device.limits())
}

/// [`check_device`] on a set of features and limits (an adapter's, before requesting a device).
pub fn check(features: wgpu::Features, limits: &wgpu::Limits) -> Result<()> {
    let missing = required_features().difference(features);
    if !missing.is_empty() {
        return Err(SnowError::DeviceFeature {
            missing: format!("{missing:?}"),
        });
    }
    let mut failed = None;
    required_limits().check_limits_with_fail_fn(limits, true, |limit, required, available| {
        failed = Some(SnowError::DeviceLimit {
            limit,
            required,
            available,
        });
    });
    failed.map_or(Ok(()), Err)
}
