//! The window's GPU side: an adapter that can present to the window, the library's device on it
//! (`GpuContext::from_adapter`, the engine path of `docs/EMBEDDING.md`), the configured surface,
//! and reading a presented frame back for `--screenshot` and `--gif`.

use std::sync::Arc;

use snowprint::GpuContext;
use winit::window::Window;

/// The surface a window presents, on the library's device.
pub struct Gfx {
    /// The device and queue the world and the renderer share.
    pub ctx: GpuContext,
    surface: wgpu::Surface<'static>,
    /// The surface's configuration (its size is the renderer's).
    pub config: wgpu::SurfaceConfiguration,
    /// Whether the surface's textures can be copied from (then screenshots are the presented
    /// frame itself).
    pub copyable: bool,
}

/// A frame read back: RGBA8 rows.
pub type Rgba = image::RgbaImage;

impl Gfx {
    /// An adapter that presents to `window` (by name with `adapter`, like `--adapter` elsewhere),
    /// its device, and the surface configured at the window's size.
    pub fn new(window: Arc<Window>, adapter: Option<&str>) -> Result<Self, String> {
        let instance = wgpu::Instance::new(
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(window.clone())),
        );
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| format!("cannot draw into the window: {e}"))?;
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let names = || {
            adapters
                .iter()
                .map(|a| a.get_info().name)
                .collect::<Vec<_>>()
                .join(", ")
        };
        let presenting: Vec<&wgpu::Adapter> = adapters
            .iter()
            .filter(|a| a.is_surface_supported(&surface))
            .collect();
        let wanted = adapter
            .map(str::to_owned)
            .or_else(|| std::env::var("SNOWPRINT_ADAPTER").ok())
            .filter(|s| !s.trim().is_empty());
        let chosen = match &wanted {
            Some(name) => {
                let needle = name.to_lowercase();
                presenting
                    .iter()
                    .find(|a| a.get_info().name.to_lowercase().contains(&needle))
                    .ok_or_else(|| {
                        format!(
                            "no adapter named like {name:?} can draw into the window; adapters: {}",
                            names()
                        )
                    })?
            }
            // A real GPU before a software one.
            None => presenting
                .iter()
                .min_by_key(|a| match a.get_info().device_type {
                    wgpu::DeviceType::DiscreteGpu => 0,
                    wgpu::DeviceType::IntegratedGpu => 1,
                    wgpu::DeviceType::VirtualGpu => 2,
                    wgpu::DeviceType::Other => 3,
                    wgpu::DeviceType::Cpu => 4,
                })
                .ok_or_else(|| {
                    format!(
                        "no adapter can draw into this window (adapters: {}); install a Vulkan driver (Mesa's lavapipe works without a GPU)",
                        if adapters.is_empty() {
                            "none".into()
                        } else {
                            names()
                        }
                    )
                })?,
        };
        let caps = surface.get_capabilities(chosen);
        let ctx = pollster::block_on(GpuContext::from_adapter((*chosen).clone()))
            .map_err(|e| e.to_string())?;
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                matches!(
                    f,
                    wgpu::TextureFormat::Bgra8UnormSrgb | wgpu::TextureFormat::Rgba8UnormSrgb
                )
            })
            .or_else(|| caps.formats.first().copied())
            .ok_or("the window's surface offers no texture format")?;
        let copyable = caps.usages.contains(wgpu::TextureUsages::COPY_SRC)
            && matches!(
                format.remove_srgb_suffix(),
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
            );
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | if copyable {
                    wgpu::TextureUsages::COPY_SRC
                } else {
                    wgpu::TextureUsages::empty()
                },
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(16),
            height: size.height.max(16),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        surface.configure(&ctx.device, &config);
        Ok(Self {
            ctx,
            surface,
            config,
            copyable,
        })
    }

    /// Follow the window's new size (at least 16 pixels a side).
    pub fn resize(&mut self, width: u32, height: u32) {
        self.config.width = width.max(16);
        self.config.height = height.max(16);
        self.surface.configure(&self.ctx.device, &self.config);
    }

    /// The next texture to draw into, or `None` when this frame is to be skipped (the surface
    /// was reconfigured or timed out).
    pub fn acquire(&mut self) -> Result<Option<wgpu::SurfaceTexture>, String> {
        match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Ok(Some(t)),
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                Ok(None)
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                Ok(None)
            }
            other => Err(format!("the window's surface failed: {other:?}")),
        }
    }
}

/// A copy of a presented texture on its way to the CPU.
pub struct Readback {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
    bgra: bool,
}

impl Readback {
    /// Record the copy of `texture` (a surface texture with `COPY_SRC`) into `encoder`.
    pub fn record(
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Self {
        let (width, height) = (texture.width(), texture.height());
        let padded_row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("snowprint play screenshot"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
        Self {
            buffer,
            width,
            height,
            padded_row,
            bgra: texture.format().remove_srgb_suffix() == wgpu::TextureFormat::Bgra8Unorm,
        }
    }

    /// Wait for the copy (after its submit) and return the pixels as RGBA.
    pub fn read(self, device: &wgpu::Device) -> Result<Rgba, String> {
        let slice = self.buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| format!("reading the frame back failed: {e}"))?;
        rx.recv()
            .map_err(|e| format!("reading the frame back failed: {e}"))?
            .map_err(|e| format!("reading the frame back failed: {e}"))?;
        let mut rgba = Vec::with_capacity((self.width * self.height * 4) as usize);
        {
            let data = slice
                .get_mapped_range()
                .map_err(|e| format!("reading the frame back failed: {e}"))?;
            for row in 0..self.height as usize {
                let o = row * self.padded_row as usize;
                rgba.extend_from_slice(&data[o..o + self.width as usize * 4]);
            }
        }
        self.buffer.unmap();
        if self.bgra {
            for px in rgba.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
        }
        // The window shows no alpha: keep the PNG opaque.
        for px in rgba.chunks_exact_mut(4) {
            px[3] = 255;
        }
        Rgba::from_raw(self.width, self.height, rgba)
            .ok_or_else(|| "the frame read back has the wrong size".into())
    }
}
