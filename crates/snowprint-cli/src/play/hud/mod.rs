//! The play window's heads-up line: frame time, tier and debug view, drawn by a small render pass
//! (`hud.wgsl`) over the finished frame in the window's texture, in the frame's own encoder. The
//! renderer draws no text (an engine has its own UI); this is the window's.

mod font;

use wgpu::util::DeviceExt;

/// Characters the line holds; longer text is cut.
pub const MAX_CHARS: usize = 32;

/// The pass: one pipeline for the window's format, one uniform.
pub struct Hud {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// Where and how large the line is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// Top left of the first character, pixels.
    pub x: u32,
    pub y: u32,
    /// Pixels a font pixel.
    pub scale: u32,
}

impl Placement {
    /// The top left corner, scaled for a window `height` pixels tall (one font pixel per 270).
    pub fn corner(height: u32) -> Self {
        let scale = (height / 270).max(1);
        Self {
            x: 3 * scale,
            y: 3 * scale,
            scale,
        }
    }
}

/// The uniform's bytes (`Hud` in hud.wgsl): rect, target, then two glyph words a character.
fn uniform_bytes(text: &str, at: Placement, target: (u32, u32)) -> Vec<u8> {
    let glyphs: Vec<[u32; 2]> = text
        .chars()
        .take(MAX_CHARS)
        .map(|c| font::glyph(c).unwrap_or([0, 0]))
        .collect();
    let mut words = vec![at.x, at.y, at.scale, glyphs.len() as u32];
    words.extend([target.0 as f32, target.1 as f32, 0.0, 0.0].map(f32::to_bits));
    let mut packed = glyphs.concat();
    packed.resize(MAX_CHARS * 2, 0);
    words.extend(packed);
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

impl Hud {
    /// The pass for targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("hud.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("hud.wgsl").into()),
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("hud"),
            contents: &uniform_bytes("", Placement::corner(270), (1, 1)),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("hud"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("hud"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("hud"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("hud"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_hud"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_hud"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self {
            pipeline,
            uniform,
            bind_group,
        }
    }

    /// Draw `text` at `at` over `view` (`target` pixels), recorded into `encoder`; the text lands
    /// with the encoder's submit (written with `queue.write_buffer`).
    pub fn encode(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        target: (u32, u32),
        at: Placement,
        text: &str,
    ) {
        queue.write_buffer(&self.uniform, 0, &uniform_bytes(text, at, target));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("hud"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.draw(0..6, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::font::{CELL_H, CELL_W, mask};
    use super::{Hud, Placement};

    /// The pass over a grey target draws exactly the CPU reference's glyph pixels white, darkens
    /// the rest of its box by the shade, and leaves everything else as it was.
    #[test]
    fn the_hud_draws_what_the_font_says() {
        let gpu = snowprint::GpuContext::new(&snowprint::GpuOptions::default()).expect("GPU");
        let (device, queue) = (&gpu.device, &gpu.queue);
        let (w, h) = (160u32, 40u32);
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hud test"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 0.5,
                        g: 0.5,
                        b: 0.5,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let text = "16.7 ms 60 fps pom";
        let at = Placement {
            x: 6,
            y: 5,
            scale: 1,
        };
        Hud::new(device, format).encode(queue, &mut encoder, &view, (w, h), at, text);
        let copy = crate::play::window::Readback::record(device, &mut encoder, &texture);
        queue.submit([encoder.finish()]);
        let image = copy.read(device).expect("read back");
        let reference = mask(text, at.scale);
        let (tw, th) = (text.len() as u32 * CELL_W, CELL_H);
        let margin = 2 * at.scale;
        let (mut glyph, mut shade) = (0, 0);
        for y in 0..h {
            for x in 0..w {
                let px = image.get_pixel(x, y).0[0];
                let inside_box = x + margin >= at.x
                    && x < at.x + tw + margin
                    && y + margin >= at.y
                    && y < at.y + th + margin;
                let expect = if x >= at.x && y >= at.y && x < at.x + tw && y < at.y + th {
                    let i = ((y - at.y) * tw + (x - at.x)) as usize;
                    if reference[i] { 255 } else { 57 }
                } else if inside_box {
                    57
                } else {
                    128
                };
                glyph += usize::from(expect == 255);
                shade += usize::from(expect == 57);
                assert!(
                    px.abs_diff(expect) <= 1,
                    "pixel ({x}, {y}) is {px}, the reference says {expect}"
                );
            }
        }
        assert!(
            glyph > 100 && shade > 500,
            "{glyph} glyph and {shade} shade pixels"
        );
    }
}
