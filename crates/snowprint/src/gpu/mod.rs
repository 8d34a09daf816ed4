//! GPU context: adapter choice, device creation and the capability checks every pass relies on.
//!
//! The best adapter is picked by type (discrete, integrated, virtual, other, software last) and by
//! backend (Vulkan, Metal and DX12 before GL), unless one is named by [`GpuOptions::adapter`] or the
//! `SNOWPRINT_ADAPTER` environment variable. Optional features (timestamp queries) are requested only
//! where the adapter has them; where one is missing the library falls back and says so with a warning.
//! An engine that owns its device creates it with [`required_features`] and [`required_limits`]
//! and hands it over with [`GpuContext::from_device`], which checks them.

mod limits;
pub(crate) mod readback;
pub(crate) mod resources;
pub(crate) mod ring;
pub(crate) mod timestamps;

pub use limits::{check_device, required_features, required_limits};

use crate::error::{Result, SnowError};

/// How to choose the GPU.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Case-insensitive part of an adapter name (for example `"llvmpipe"` or `"H100"`). When `None`,
    /// `SNOWPRINT_ADAPTER` is read; when that is unset too, the best adapter is chosen.
    pub adapter: Option<String>,
}

/// What the chosen device can do, checked once at start.
#[derive(Clone, Debug)]
pub struct Capabilities {
    /// GPU timestamp queries can be written at pass boundaries.
    pub timestamps: bool,
    /// Largest storage buffer binding, bytes. Pools larger than this are clamped with a warning.
    pub max_storage_binding: u64,
    /// Largest 2D texture side, texels: bounds the capture atlas.
    pub max_texture_side: u32,
    /// `Rgba16Float` can be filtered (used by shading); when false, shading falls back to nearest.
    pub filterable_rgba16f: bool,
    /// Warnings issued while checking, kept so that reports can show them.
    pub warnings: Vec<String>,
}

/// A device and queue on the chosen adapter.
pub struct GpuContext {
    /// The wgpu device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Description of the adapter (name, backend, type, driver).
    pub info: wgpu::AdapterInfo,
    /// Checked capabilities.
    pub caps: Capabilities,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.info.name)
            .field("backend", &self.info.backend)
            .field("caps", &self.caps)
            .finish()
    }
}

/// What the passes need beyond WebGPU's baseline: compute shaders, and fragment shaders that write
/// storage buffers (the capture keeps the lowest point per texel with an atomic in a buffer).
pub const REQUIRED_DOWNLEVEL: wgpu::DownlevelFlags =
    wgpu::DownlevelFlags::COMPUTE_SHADERS.union(wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE);

/// The required capabilities an adapter lacks (empty when it has them all).
pub fn missing_capabilities(adapter: &wgpu::Adapter) -> wgpu::DownlevelFlags {
    REQUIRED_DOWNLEVEL.difference(adapter.get_downlevel_capabilities().flags)
}

/// [`SnowError::AdapterUnsupported`] when the adapter lacks [`REQUIRED_DOWNLEVEL`].
fn check_downlevel(adapter: &wgpu::Adapter) -> Result<()> {
    let missing = missing_capabilities(adapter);
    if missing.is_empty() {
        return Ok(());
    }
    Err(SnowError::AdapterUnsupported {
        adapter: describe(&adapter.get_info()),
        missing: format!("{missing:?}"),
    })
}

/// Rank of an adapter: lower is better.
fn adapter_rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    let backend = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    (kind, backend)
}

/// A one-line description of an adapter, as reports show it.
pub fn describe(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?}, {:?}, driver {} {})",
        info.name, info.backend, info.device_type, info.driver, info.driver_info
    )
}

impl GpuContext {
    /// Choose an adapter and create a device on it.
    pub fn new(options: &GpuOptions) -> Result<Self> {
        pollster::block_on(Self::new_async(options))
    }

    /// Async form of [`GpuContext::new`].
    pub async fn new_async(options: &GpuOptions) -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let requested = options
            .adapter
            .clone()
            .or_else(|| std::env::var("SNOWPRINT_ADAPTER").ok())
            .filter(|s| !s.trim().is_empty());
        let mut adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        if adapters.is_empty() {
            return Err(SnowError::NoAdapter);
        }
        // Adapters that lack what the passes need go last, then by type and backend.
        adapters.sort_by_key(|a| {
            (
                !missing_capabilities(a).is_empty(),
                adapter_rank(&a.get_info()),
            )
        });
        let adapter = match &requested {
            Some(name) => {
                let needle = name.to_lowercase();
                let found = adapters
                    .iter()
                    .position(|a| a.get_info().name.to_lowercase().contains(&needle));
                match found {
                    Some(i) => adapters.swap_remove(i),
                    None => {
                        let available = adapters
                            .iter()
                            .map(|a| a.get_info().name)
                            .collect::<Vec<_>>()
                            .join(", ");
                        return Err(SnowError::AdapterNotFound {
                            requested: name.clone(),
                            available,
                        });
                    }
                }
            }
            None => adapters.swap_remove(0),
        };
        Self::from_adapter(adapter).await
    }

    /// Create a device on a given adapter, checking capabilities: it requests
    /// [`required_features`] and [`required_limits`], with timestamp queries where the adapter has
    /// them, and the size limits the pool and the atlas grow into (largest storage binding and
    /// buffer, texture side, workgroups a dispatch) raised to the adapter's.
    pub async fn from_adapter(adapter: wgpu::Adapter) -> Result<Self> {
        let info = adapter.get_info();
        check_downlevel(&adapter)?;
        let features = adapter.features();
        let limits = adapter.limits();
        // An adapter that cannot give what the passes need is refused before asking for a device.
        limits::check(features, &limits)?;
        let mut required = required_features();
        // Conservative depth lets the snow pass reject hidden fragments before tracing them
        // (render/snow): used where the adapter has it.
        required |= features & wgpu::Features::SHADER_EARLY_DEPTH_TEST;
        if features.contains(wgpu::Features::TIMESTAMP_QUERY) {
            required |= wgpu::Features::TIMESTAMP_QUERY;
            if features.contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS) {
                required |= wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
            }
        }
        let required_limits = wgpu::Limits {
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
            max_buffer_size: limits.max_buffer_size,
            max_texture_dimension_2d: limits.max_texture_dimension_2d,
            max_compute_workgroups_per_dimension: limits.max_compute_workgroups_per_dimension,
            ..required_limits()
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("snowprint"),
                required_features: required,
                required_limits,
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|source| SnowError::RequestDevice {
                adapter: info.name.clone(),
                source,
            })?;
        Self::from_device(&adapter, device, queue)
    }

    /// Use a device the caller created (an engine's own) on `adapter`. Its features and limits are
    /// checked against [`required_features`] and [`required_limits`]: what falls short is
    /// [`SnowError::DeviceLimit`] or [`SnowError::DeviceFeature`], naming what to request.
    /// Timestamp queries are used where the device was created with
    /// `wgpu::Features::TIMESTAMP_QUERY`; without them profiling falls back to CPU times.
    pub fn from_device(
        adapter: &wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Result<Self> {
        let info = adapter.get_info();
        check_downlevel(adapter)?;
        check_device(&device)?;
        let limits = device.limits();
        let mut warnings = Vec::new();
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        if !timestamps {
            warnings.push(format!(
                "{} has no GPU timestamp queries: per-pass GPU times are unavailable, whole frames are timed on the CPU instead",
                info.name
            ));
        }
        let rgba16f = adapter.get_texture_format_features(wgpu::TextureFormat::Rgba16Float);
        let filterable_rgba16f = rgba16f
            .flags
            .contains(wgpu::TextureFormatFeatureFlags::FILTERABLE);
        if !filterable_rgba16f {
            warnings.push(format!(
                "{} cannot filter Rgba16Float: shading samples it with nearest filtering",
                info.name
            ));
        }
        let depth = adapter.get_texture_format_features(wgpu::TextureFormat::Depth32Float);
        if !depth
            .allowed_usages
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING)
        {
            // Depth32Float as attachment and sampled texture is required by WebGPU, so this is a
            // broken driver; say it plainly rather than failing in the first capture.
            warnings.push(format!(
                "{} reports Depth32Float without attachment+binding usage; captures may fail",
                info.name
            ));
        }
        for w in &warnings {
            tracing::warn!("{w}");
        }
        let caps = Capabilities {
            timestamps,
            max_storage_binding: limits.max_storage_buffer_binding_size,
            max_texture_side: limits.max_texture_dimension_2d,
            filterable_rgba16f,
            warnings,
        };
        Ok(Self {
            device,
            queue,
            info,
            caps,
        })
    }

    /// Block until all submitted GPU work is done.
    pub fn wait_idle(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(SnowError::from)
    }
}
