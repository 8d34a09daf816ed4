//! Rasterising a ground mesh into a surface's texels on the GPU (`raster.wgsl`): the highest face
//! over each texel centre, read back once when the ground is set (the ground is static, and the
//! world keeps its field on the CPU for culling and its reference).
//!
//! CPU reference: [`super::cpu::rasterise`].

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};
use wgpu::util::DeviceExt;

use crate::error::Result;
use crate::gpu::resources::bind_group;
use crate::surface::SurfaceLayout;

/// Uniform of the rasterisation. Must match `RasterView` in `raster.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RasterView {
    /// World to surface-local transform.
    pub to_local: [[f32; 4]; 4],
    /// Half the surface's sides, metres.
    pub half_size: [f32; 2],
    /// Heightmap texels along `x`.
    pub width: u32,
    /// Padding to 16 bytes.
    pub pad: u32,
}

/// The rasterisation's pipeline.
#[derive(Debug)]
pub struct GroundRaster {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

/// Decode a height code of `raster.wgsl` (`None`: no face).
pub fn decode_height(code: u32) -> Option<f32> {
    if code == 0 {
        return None;
    }
    let bits = if code & 0x8000_0000 != 0 {
        code & 0x7fff_ffff
    } else {
        !code
    };
    Some(f32::from_bits(bits))
}

impl GroundRaster {
    /// Build the pipeline.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("ground raster.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::wgsl::GROUND_RASTER.source.into()),
        });
        let layout = crate::wgsl::GROUND_RASTER.bind_group_layout(device, "ground raster", 0);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ground raster"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ground raster"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_ground"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                })],
            },
            // Any winding: the highest face is the ground whichever way it faces.
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: crate::capture::ATLAS_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_ground"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { pipeline, layout }
    }

    /// Rasterise world-space `triangles` into the texels of a surface (`world_to_local`, sides
    /// `size`, `layout`) and read the heights back: the highest face over each texel centre, or
    /// `None` where no face lies.
    pub fn rasterise(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        triangles: &[[Vec3; 3]],
        world_to_local: Mat4,
        size: Vec2,
        layout: SurfaceLayout,
    ) -> Result<Vec<Option<f32>>> {
        let (w, h) = (layout.width, layout.height);
        let view = RasterView {
            to_local: world_to_local.to_cols_array_2d(),
            half_size: (size * 0.5).to_array(),
            width: w,
            pad: 0,
        };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ground raster view"),
            contents: bytemuck::bytes_of(&view),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let positions: Vec<[f32; 3]> = triangles.iter().flatten().map(|v| v.to_array()).collect();
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ground raster vertices"),
            contents: bytemuck::cast_slice(&positions),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let bytes = w as u64 * h as u64 * 4;
        let heights = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ground raster heights"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // Places the viewport only, as the capture's atlas does: never read or written.
        let target = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("ground raster target"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: crate::capture::ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let target_view = target.create_view(&Default::default());
        let bg = bind_group(
            device,
            "ground raster",
            &self.layout,
            &[uniform.as_entire_binding(), heights.as_entire_binding()],
        );
        let mut enc = device.create_command_encoder(&Default::default());
        enc.clear_buffer(&heights, 0, None);
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ground raster"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..positions.len() as u32, 0..1);
        }
        queue.submit([enc.finish()]);
        let data = crate::gpu::readback::download(device, queue, &heights, 0, bytes)?;
        Ok(bytemuck::cast_slice::<u8, u32>(&data)
            .iter()
            .map(|&c| decode_height(c))
            .collect())
    }
}
