//! The tessellated tier's GPU side: bind group layouts, pipelines and buffers of the `banks`,
//! `dice`, `snow_shadow` and tessellated `snow` passes. The renderer encodes them from
//! `render::Renderer::encode`.

use crate::gpu::resources::{Growable, compute_storage, uniform};

use super::{ARGS_BASE, ARGS_STRIDE, VERTEX_BYTES};
use crate::render::shaders;

/// Texture binding for a layout (`textureLoad` only, or filtered sampling in the fragment stage).
fn texture(
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

/// Pipelines and buffers of the tessellated tier.
pub(crate) struct TessGpu {
    pub bank_layout: wgpu::BindGroupLayout,
    pub dice_layout: wgpu::BindGroupLayout,
    pub surface_layout: wgpu::BindGroupLayout,
    pub bank_norm: wgpu::ComputePipeline,
    pub bank_gather: wgpu::ComputePipeline,
    pub dice: wgpu::ComputePipeline,
    pub seal: wgpu::ComputePipeline,
    pub draw: wgpu::RenderPipeline,
    pub shadow: [wgpu::RenderPipeline; 2],
    /// Per surface: `BankParams`, then `DiceParams`, in uniform blocks.
    pub bank_params: Growable,
    pub dice_params: Growable,
    /// Diced vertices (two vec4 each), indices, counters and draw arguments.
    pub vertices: Growable,
    pub indices: Growable,
    pub counters: Growable,
}

/// Bytes of the counters buffer for `n` surfaces.
pub(crate) fn counters_bytes(n: usize) -> u64 {
    (ARGS_BASE + ARGS_STRIDE * n.max(1) as u64) * 4
}

impl TessGpu {
    pub fn new(
        device: &wgpu::Device,
        frame_layout: &wgpu::BindGroupLayout,
        shadow_layout: &wgpu::BindGroupLayout,
        filterable: bool,
        hdr: wgpu::TextureFormat,
    ) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let storage_texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: c,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba16Float,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        let bank_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("banks"),
            entries: &[
                uniform(0, c),
                texture(1, c, false),
                texture(2, c, false),
                texture(3, c, false),
                storage_texture(4),
            ],
        });
        let dice_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dice"),
            entries: &[
                uniform(0, c),
                compute_storage(1, true),
                texture(2, c, false),
                texture(3, c, false),
                compute_storage(4, true),
                compute_storage(5, false),
                compute_storage(6, false),
                compute_storage(7, false),
            ],
        });
        let surface_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tessellated snow surface"),
            entries: &[
                uniform(0, vf),
                texture(1, vf, filterable),
                texture(2, vf, filterable),
                texture(3, vf, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: vf,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let module = |label: &str, source: String| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        };
        let banks_module = module("banks.wgsl", shaders::BANKS.to_owned());
        let dice_module = module("dice.wgsl", shaders::DICE.to_owned());
        let surface_module = module("tess_surface.wgsl", shaders::tess_surface());
        let layout = |label: &str, groups: &[&wgpu::BindGroupLayout]| {
            let groups: Vec<Option<&wgpu::BindGroupLayout>> =
                groups.iter().map(|g| Some(*g)).collect();
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &groups,
                immediate_size: 0,
            })
        };
        let compute = |label: &str, module: &wgpu::ShaderModule, entry: &str, group| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(&layout(label, &[group])),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let bank_norm = compute("bank norm", &banks_module, "bank_norm", &bank_layout);
        let bank_gather = compute("bank gather", &banks_module, "bank_gather", &bank_layout);
        let dice = compute("dice", &dice_module, "dice_surface", &dice_layout);
        let seal = compute("dice seal", &dice_module, "seal", &dice_layout);

        const VERTEX: [wgpu::VertexAttribute; 2] =
            wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX,
        })];
        let manual: &[(&str, f64)] = if filterable {
            &[]
        } else {
            &[("MANUAL_FILTER", 1.0)]
        };
        let draw = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("snow tessellated"),
            layout: Some(&layout(
                "snow tessellated",
                &[frame_layout, &surface_layout],
            )),
            vertex: wgpu::VertexState {
                module: &surface_module,
                entry_point: Some("vs_tess"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            // Skirts face outwards whichever way a mesh is wound: no culling.
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: crate::render::depth_state(wgpu::CompareFunction::LessEqual, true),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &surface_module,
                entry_point: Some("fs_tess"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: manual,
                    ..Default::default()
                },
                targets: &[Some(wgpu::ColorTargetState {
                    format: hdr,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let shadow = [0.0, 1.0].map(|cascade| {
            let constants = [("TESS_SHADOW_CASCADE", cascade)];
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("snow shadow"),
                layout: Some(&layout("snow shadow", &[shadow_layout, &surface_layout])),
                vertex: wgpu::VertexState {
                    module: &surface_module,
                    entry_point: Some("vs_tess_shadow"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: crate::render::shadow_depth_state(),
                multisample: wgpu::MultisampleState::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        });
        use wgpu::BufferUsages as U;
        Self {
            bank_params: Growable::new(device, "bank params", U::UNIFORM | U::COPY_DST, 256 * 8),
            dice_params: Growable::new(device, "dice params", U::UNIFORM | U::COPY_DST, 256 * 8),
            vertices: Growable::new(
                device,
                "diced vertices",
                U::STORAGE | U::VERTEX | U::COPY_SRC,
                16,
            ),
            indices: Growable::new(
                device,
                "diced indices",
                U::STORAGE | U::INDEX | U::COPY_SRC,
                16,
            ),
            counters: Growable::new(
                device,
                "dice counters",
                U::STORAGE | U::INDIRECT | U::COPY_SRC | U::COPY_DST,
                counters_bytes(8),
            ),
            bank_layout,
            dice_layout,
            surface_layout,
            bank_norm,
            bank_gather,
            dice,
            seal,
            draw,
            shadow,
        }
    }
}
