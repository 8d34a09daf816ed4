//! The `tonemap` pass (`tonemap.wgsl`): resolves the supersampled HDR scene into the output (an
//! offscreen texture or the caller's view), exposing and tonemapping it. One pipeline per output
//! format and supersampling, made the first time they are asked for.

use std::collections::HashMap;

use super::graph::PASSES;
use super::pipeline;
use super::readback::{Timestamps, render_writes};
use super::targets::Targets;
use crate::gpu::resources::bind_group;

pub(super) struct TonemapPass {
    layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    /// This frame's pipeline and inputs.
    current: Option<(wgpu::RenderPipeline, wgpu::BindGroup)>,
}

impl TonemapPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let layout = crate::wgsl::TONEMAP.bind_group_layout(device, "tonemap inputs", 1);
        let module = pipeline::shader(device, "tonemap.wgsl", crate::wgsl::TONEMAP.wgsl());
        let pipeline_layout = pipeline::layout(device, "tonemap", &[frame_layout, &layout]);
        Self {
            layout,
            module,
            pipeline_layout,
            pipelines: HashMap::new(),
            current: None,
        }
    }

    fn pipeline(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        supersample: u32,
    ) -> wgpu::RenderPipeline {
        if let Some(p) = self.pipelines.get(&(format, supersample)) {
            return p.clone();
        }
        let constants = [
            ("SUPERSAMPLE", supersample as f64),
            ("ENCODE_SRGB", if format.is_srgb() { 0.0 } else { 1.0 }),
        ];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tonemap"),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_tonemap"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_tonemap"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        self.pipelines
            .insert((format, supersample), pipeline.clone());
        pipeline
    }

    /// Bind the scene's colour and depth, and pick the pipeline of the output's format.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        targets: &Targets,
        format: wgpu::TextureFormat,
        supersample: u32,
    ) {
        let inputs = bind_group(
            device,
            "tonemap inputs",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(&targets.color_view),
                wgpu::BindingResource::TextureView(&targets.depth_view),
            ],
        );
        let pipeline = self.pipeline(device, format, supersample);
        self.current = Some((pipeline, inputs));
    }

    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        target: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
    ) {
        let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(PASSES[slot].name),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: render_writes(ts, slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some((pipeline, inputs)) = &self.current {
            p.set_pipeline(pipeline);
            p.set_bind_group(0, frame, &[]);
            p.set_bind_group(1, inputs, &[]);
            p.draw(0..3, 0..1);
        }
    }
}
