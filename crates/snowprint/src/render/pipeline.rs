//! Small builders shared by the passes: shader modules, pipeline layouts, compute and render
//! pipelines, depth states and layout entries.

use super::targets::DEPTH_FORMAT;

/// A WGSL shader module.
pub(super) fn shader(device: &wgpu::Device, label: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// A pipeline layout of bind groups 0, 1, ... in order.
pub(super) fn layout(
    device: &wgpu::Device,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    })
}

/// A compute pipeline of one entry point.
pub(super) fn compute(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    compute_with(device, label, (module, entry), groups, &[])
}

/// [`compute`] with override constants.
pub(super) fn compute_with(
    device: &wgpu::Device,
    label: &str,
    (module, entry): (&wgpu::ShaderModule, &str),
    groups: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout(device, label, groups)),
        module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

/// A render pipeline with a vertex and a fragment stage (override constants on the fragment
/// stage only).
pub(super) struct Raster<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    pub vs: &'a str,
    pub fs: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub groups: &'a [&'a wgpu::BindGroupLayout],
    pub primitive: wgpu::PrimitiveState,
    pub depth: Option<wgpu::DepthStencilState>,
    pub targets: &'a [Option<wgpu::ColorTargetState>],
    pub constants: &'a [(&'a str, f64)],
}

impl Raster<'_> {
    pub(super) fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(&layout(device, self.label, self.groups)),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vs),
                compilation_options: Default::default(),
                buffers: self.buffers,
            },
            primitive: self.primitive,
            depth_stencil: self.depth.clone(),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fs),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: self.constants,
                    ..Default::default()
                },
                targets: self.targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// The depth-only pipelines drawing into the moon's shadow cascades, one a cascade: the cascade
/// is the override constant `constant` of the vertex stage, the map's depth `format`.
pub(super) struct ShadowCaster<'a> {
    pub label: &'a str,
    pub layout: &'a wgpu::PipelineLayout,
    pub module: &'a wgpu::ShaderModule,
    pub entry: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub constant: &'a str,
    pub format: wgpu::TextureFormat,
    /// Which faces are drawn.
    pub primitive: wgpu::PrimitiveState,
}

impl ShadowCaster<'_> {
    pub(super) fn build(&self, device: &wgpu::Device) -> [wgpu::RenderPipeline; 2] {
        [0.0, 1.0].map(|cascade| {
            let constants = [(self.constant, cascade)];
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(self.label),
                layout: Some(self.layout),
                vertex: wgpu::VertexState {
                    module: self.module,
                    entry_point: Some(self.entry),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    buffers: self.buffers,
                },
                primitive: self.primitive,
                depth_stencil: shadow_depth_state(self.format),
                multisample: wgpu::MultisampleState::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

/// Render target of the scene's HDR colour, unblended.
pub(super) fn hdr_target() -> [Option<wgpu::ColorTargetState>; 1] {
    [Some(wgpu::ColorTargetState {
        format: super::targets::HDR_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })]
}

/// The targets of the snow's draws on the visibility path: the visibility buffer and the hits
/// (without the scene's colour: the three would pass the bytes a sample may have in every
/// device's limits).
pub(super) fn visibility_targets() -> [Option<wgpu::ColorTargetState>; 2] {
    let target = |format| {
        Some(wgpu::ColorTargetState {
            format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        })
    };
    [
        target(super::targets::VISIBILITY_FORMAT),
        target(super::targets::SNOW_HITS_FORMAT),
    ]
}

/// Back faces culled.
pub(super) fn back_culled() -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        cull_mode: Some(wgpu::Face::Back),
        ..Default::default()
    }
}

/// `MANUAL_FILTER` where the adapter cannot filter `Rgba16Float` (the material filters by hand).
pub(super) fn manual_filter(filterable: bool) -> &'static [(&'static str, f64)] {
    if filterable {
        &[]
    } else {
        &[("MANUAL_FILTER", 1.0)]
    }
}

pub(super) fn depth_state(
    compare: wgpu::CompareFunction,
    write: bool,
) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    })
}

/// Depth state of everything drawn into the moon's shadow cascades (meshes, and the tessellated
/// tier's snow): nearest wins, biased against acne by slope.
pub(super) fn shadow_depth_state(format: wgpu::TextureFormat) -> Option<wgpu::DepthStencilState> {
    depth_state(wgpu::CompareFunction::Less, true).map(|d| wgpu::DepthStencilState {
        format,
        bias: wgpu::DepthBiasState {
            constant: 2,
            slope_scale: 2.0,
            clamp: 0.0,
        },
        ..d
    })
}
