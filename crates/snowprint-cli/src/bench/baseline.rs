//! The update's baselines: the same bytes moved by a plain `copy_buffer_to_buffer` and by a compute
//! pass that streams them in and out with 16-byte loads and stores (what a pass that reads and
//! writes every byte once can at best do), each timed with GPU timestamps when the device has them,
//! else whole submissions timed on the CPU.

use std::time::Instant;

use snowprint::GpuContext;

/// The compute copy: every invocation moves `vec4<u32>`s, a grid stride apart, so that any size
/// fits in the dispatch limits.
const COMPUTE_COPY: &str = "
@group(0) @binding(0) var<storage, read> src: array<vec4<u32>>;
@group(0) @binding(1) var<storage, read_write> dst: array<vec4<u32>>;

@compute @workgroup_size(256)
fn copy(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let stride = n.x * 256u;
    for (var i = id.x; i < arrayLength(&src); i += stride) {
        dst[i] = src[i];
    }
}
";

/// Workgroups of the compute copy: enough to fill a large GPU, each looping over the rest.
const COPY_WORKGROUPS: u32 = 8192;

/// Two timestamps around the measured work, resolved and read back.
struct Stopwatch {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period: f32,
}

impl Stopwatch {
    fn new(gpu: &GpuContext, feature: wgpu::Features) -> Option<Self> {
        use wgpu::BufferUsages as U;
        if !gpu.device.features().contains(feature) {
            return None;
        }
        let buffer = |label, usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("baseline timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: buffer("baseline resolve", U::QUERY_RESOLVE | U::COPY_SRC),
            readback: buffer("baseline readback", U::MAP_READ | U::COPY_DST),
            period: gpu.queue.get_timestamp_period(),
        })
    }

    fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        enc.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 16);
    }

    /// Microseconds between the two timestamps (after the submission finished).
    fn read(&self, gpu: &GpuContext) -> Result<f64, String> {
        let slice = self.readback.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        gpu.wait_idle().map_err(|e| e.to_string())?;
        rx.recv()
            .map_err(|e| e.to_string())?
            .map_err(|e| e.to_string())?;
        let ticks = u64s(&slice.get_mapped_range().map_err(|e| format!("{e:?}"))?);
        self.readback.unmap();
        Ok(ticks[1].saturating_sub(ticks[0]) as f64 * self.period as f64 * 1e-3)
    }
}

fn u64s(bytes: &[u8]) -> Vec<u64> {
    bytes
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect()
}

/// Source and destination of `bytes` (rounded up to 16).
fn buffers(gpu: &GpuContext, bytes: u64) -> (wgpu::Buffer, wgpu::Buffer) {
    use wgpu::BufferUsages as U;
    let make = |label, usage| {
        gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16).div_ceil(16) * 16,
            usage,
            mapped_at_creation: false,
        })
    };
    (
        make("copy source", U::COPY_SRC | U::STORAGE),
        make("copy destination", U::COPY_DST | U::STORAGE),
    )
}

/// Submit `enc`, wait, and give the stopwatch's time or the submission's wall time, microseconds.
fn finish(
    gpu: &GpuContext,
    enc: wgpu::CommandEncoder,
    watch: Option<&Stopwatch>,
) -> Result<f64, String> {
    let start = Instant::now();
    gpu.queue.submit([enc.finish()]);
    gpu.wait_idle().map_err(|e| e.to_string())?;
    let wall = start.elapsed().as_secs_f64() * 1e6;
    match watch {
        Some(w) => w.read(gpu),
        None => Ok(wall),
    }
}

/// Timing of a plain `copy_buffer_to_buffer`, with encoder timestamps when the device has them.
pub(super) struct CopyTimer {
    src: wgpu::Buffer,
    dst: wgpu::Buffer,
    watch: Option<Stopwatch>,
}

impl CopyTimer {
    pub(super) fn new(gpu: &GpuContext, bytes: u64) -> Self {
        let (src, dst) = buffers(gpu, bytes);
        Self {
            src,
            dst,
            watch: Stopwatch::new(gpu, wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
        }
    }

    /// One copy, microseconds.
    pub(super) fn time(&self, gpu: &GpuContext) -> Result<f64, String> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        if let Some(w) = &self.watch {
            enc.write_timestamp(&w.set, 0);
        }
        enc.copy_buffer_to_buffer(&self.src, 0, &self.dst, 0, self.src.size());
        if let Some(w) = &self.watch {
            enc.write_timestamp(&w.set, 1);
            w.resolve(&mut enc);
        }
        finish(gpu, enc, self.watch.as_ref())
    }
}

/// Timing of a `clear_buffer` of `bytes`, as the update clears its capture buffer before its first
/// pass (outside the passes' timestamps), with encoder timestamps when the device has them.
pub(super) struct ClearTimer {
    buffer: wgpu::Buffer,
    bytes: u64,
    watch: Option<Stopwatch>,
}

impl ClearTimer {
    pub(super) fn new(gpu: &GpuContext, bytes: u64) -> Self {
        Self {
            buffer: buffers(gpu, bytes).1,
            bytes,
            watch: Stopwatch::new(gpu, wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
        }
    }

    /// One clear, microseconds (0 for a clear of nothing).
    pub(super) fn time(&self, gpu: &GpuContext) -> Result<f64, String> {
        if self.bytes == 0 {
            return Ok(0.0);
        }
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        if let Some(w) = &self.watch {
            enc.write_timestamp(&w.set, 0);
        }
        enc.clear_buffer(&self.buffer, 0, None);
        if let Some(w) = &self.watch {
            enc.write_timestamp(&w.set, 1);
            w.resolve(&mut enc);
        }
        finish(gpu, enc, self.watch.as_ref())
    }
}

/// Timing of the compute copy, with pass timestamps when the device has them.
pub(super) struct ComputeCopyTimer {
    pipeline: wgpu::ComputePipeline,
    bind: wgpu::BindGroup,
    watch: Option<Stopwatch>,
}

impl ComputeCopyTimer {
    pub(super) fn new(gpu: &GpuContext, bytes: u64) -> Self {
        let (src, dst) = buffers(gpu, bytes);
        let module = gpu
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("compute copy"),
                source: wgpu::ShaderSource::Wgsl(COMPUTE_COPY.into()),
            });
        let pipeline = gpu
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("compute copy"),
                layout: None,
                module: &module,
                entry_point: Some("copy"),
                compilation_options: Default::default(),
                cache: None,
            });
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compute copy"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: src.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: dst.as_entire_binding(),
                },
            ],
        });
        Self {
            pipeline,
            bind,
            watch: Stopwatch::new(gpu, wgpu::Features::TIMESTAMP_QUERY),
        }
    }

    /// One compute copy, microseconds.
    pub(super) fn time(&self, gpu: &GpuContext) -> Result<f64, String> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("compute copy"),
                timestamp_writes: self
                    .watch
                    .as_ref()
                    .map(|w| wgpu::ComputePassTimestampWrites {
                        query_set: &w.set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind, &[]);
            pass.dispatch_workgroups(COPY_WORKGROUPS, 1, 1);
        }
        if let Some(w) = &self.watch {
            w.resolve(&mut enc);
        }
        finish(gpu, enc, self.watch.as_ref())
    }
}
