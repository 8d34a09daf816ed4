//! The `tonemap` pass: resolves the supersampled HDR scene into the output (an offscreen texture or
//! the caller's view), exposing and tonemapping it, with `resolve.wgsl`'s maths.
//!
//! A compute pass (`tonemap_compute.wgsl`, one thread an output pixel) writes the output as a
//! storage texture wherever it can be one: the offscreen output ([`OUTPUT_FORMAT`], `Rgba8Unorm`)
//! and a caller's view of that format made with `STORAGE_BINDING`. Any other view (a window's
//! `Bgra8UnormSrgb` surface, a texture without `STORAGE_BINDING`) gets the raster fallback
//! (`tonemap.wgsl`, one fullscreen triangle), the same maths through a fragment stage. Pipelines
//! are made the first time a format and supersampling are asked for.

use std::collections::HashMap;

use super::graph::PASSES;
use super::pipeline;
use super::readback::{Timestamps, compute_pass, render_writes};
use super::targets::{OUTPUT_FORMAT, Targets};
use crate::gpu::resources::KeptGroups;

/// Output pixels a workgroup of `tonemap_compute.wgsl` covers along each axis.
const WORKGROUP: u32 = 8;

/// How this frame's output is written.
enum Current {
    /// The compute pass: its pipeline, inputs with the output, and the output's size.
    Compute(wgpu::ComputePipeline, wgpu::BindGroup, (u32, u32)),
    /// The raster fallback: its pipeline and inputs.
    Raster(wgpu::RenderPipeline, wgpu::BindGroup),
}

pub(super) struct TonemapPass {
    layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: HashMap<(wgpu::TextureFormat, u32), wgpu::RenderPipeline>,
    compute_layout: wgpu::BindGroupLayout,
    compute_module: wgpu::ShaderModule,
    compute_pipeline_layout: wgpu::PipelineLayout,
    compute_pipelines: HashMap<u32, wgpu::ComputePipeline>,
    current: Option<Current>,
    /// The inputs' groups, kept while the targets stay: compute at slot 0, raster at 1.
    kept: KeptGroups,
}

/// Whether the tonemap can write `target` (in `format`) as a storage texture: an `Rgba8Unorm`
/// texture made with `STORAGE_BINDING`, viewed in its own format.
pub(super) fn can_compute(target: &wgpu::TextureView, format: wgpu::TextureFormat) -> bool {
    let t = target.texture();
    format == OUTPUT_FORMAT
        && t.format() == format
        && t.usage().contains(wgpu::TextureUsages::STORAGE_BINDING)
}

impl TonemapPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let layout = crate::wgsl::TONEMAP.bind_group_layout(device, "tonemap inputs", 1);
        let module = pipeline::shader(device, "tonemap.wgsl", crate::wgsl::TONEMAP.wgsl());
        let pipeline_layout = pipeline::layout(device, "tonemap", &[frame_layout, &layout]);
        let compute = &crate::wgsl::TONEMAP_COMPUTE;
        let compute_layout = compute.bind_group_layout(device, "tonemap compute inputs", 1);
        let compute_module = pipeline::shader(device, "tonemap_compute.wgsl", compute.wgsl());
        let compute_pipeline_layout =
            pipeline::layout(device, "tonemap compute", &[frame_layout, &compute_layout]);
        Self {
            layout,
            module,
            pipeline_layout,
            pipelines: HashMap::new(),
            compute_layout,
            compute_module,
            compute_pipeline_layout,
            compute_pipelines: HashMap::new(),
            current: None,
            kept: KeptGroups::default(),
        }
    }

    fn raster_pipeline(
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

    fn compute_pipeline(
        &mut self,
        device: &wgpu::Device,
        supersample: u32,
    ) -> wgpu::ComputePipeline {
        if let Some(p) = self.compute_pipelines.get(&supersample) {
            return p.clone();
        }
        let constants = [("SUPERSAMPLE", supersample as f64)];
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("tonemap compute"),
            layout: Some(&self.compute_pipeline_layout),
            module: &self.compute_module,
            entry_point: Some("tonemap"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        });
        self.compute_pipelines.insert(supersample, pipeline.clone());
        pipeline
    }

    /// Bind the scene's colour and depth (and the output, in compute), and pick the pipeline of
    /// the output's format.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        targets: &Targets,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        supersample: u32,
    ) {
        let color = wgpu::BindingResource::TextureView(&targets.color_view);
        let depth = wgpu::BindingResource::TextureView(&targets.depth_view);
        self.current = Some(if can_compute(target, format) {
            let output = wgpu::BindingResource::TextureView(target);
            let inputs = self.kept.get(
                device,
                "tonemap compute inputs",
                &self.compute_layout,
                0,
                &[color, depth, output],
            );
            let t = target.texture();
            let pipeline = self.compute_pipeline(device, supersample);
            Current::Compute(pipeline, inputs, (t.width(), t.height()))
        } else {
            let inputs = self
                .kept
                .get(device, "tonemap inputs", &self.layout, 1, &[color, depth]);
            Current::Raster(self.raster_pipeline(device, format, supersample), inputs)
        });
    }

    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        target: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
    ) {
        match &self.current {
            Some(Current::Compute(pipeline, inputs, (w, h))) => {
                let mut p = compute_pass(encoder, ts, slot);
                p.set_pipeline(pipeline);
                p.set_bind_group(0, frame, &[]);
                p.set_bind_group(1, inputs, &[]);
                p.dispatch_workgroups(w.div_ceil(WORKGROUP), h.div_ceil(WORKGROUP), 1);
            }
            Some(Current::Raster(pipeline, inputs)) => {
                let mut p = raster_pass(encoder, ts, slot, target);
                p.set_pipeline(pipeline);
                p.set_bind_group(0, frame, &[]);
                p.set_bind_group(1, inputs, &[]);
                p.draw(0..3, 0..1);
            }
            None => drop(raster_pass(encoder, ts, slot, target)),
        }
    }
}

/// The raster fallback's pass: the target cleared, then drawn over.
fn raster_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    ts: Option<&'e Timestamps>,
    slot: usize,
    target: &'e wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
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
    })
}
