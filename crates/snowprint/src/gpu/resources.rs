//! Small GPU resource helpers shared by the world's passes and the renderer's.

/// A GPU buffer that grows (to the next power of two) when asked for more; the old contents are
/// not kept, so it suits per-frame tables rewritten before each use.
pub(crate) struct Growable {
    /// The current buffer.
    pub buffer: wgpu::Buffer,
    usage: wgpu::BufferUsages,
    label: &'static str,
}

impl Growable {
    /// A buffer of at least `size` bytes (16 at least, so that it can always be bound).
    pub(crate) fn new(
        device: &wgpu::Device,
        label: &'static str,
        usage: wgpu::BufferUsages,
        size: u64,
    ) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            usage,
            label,
        }
    }

    /// Make sure the buffer holds at least `size` bytes: the next power of two, but no more than
    /// the device can bind whole (the world refuses a frame that needs more, before this).
    pub(crate) fn ensure(&mut self, device: &wgpu::Device, size: u64) {
        if self.buffer.size() < size {
            let limits = device.limits();
            let most = limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size);
            let grown = size.next_power_of_two().min(most).max(size);
            *self = Self::new(device, self.label, self.usage, grown);
        }
    }
}

/// Spacing of the per-draw uniform blocks in one buffer, bytes: WebGPU's largest minimum
/// dynamic-offset alignment, so a block can be chosen by dynamic offset on every device.
pub(crate) const UNIFORM_STRIDE: u64 = 256;

/// Block `index` (its first `size` bytes) of a buffer of uniform blocks spaced
/// [`UNIFORM_STRIDE`] apart.
pub(crate) fn uniform_block(
    buffer: &wgpu::Buffer,
    index: usize,
    size: usize,
) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: index as u64 * UNIFORM_STRIDE,
        size: std::num::NonZeroU64::new(size as u64),
    })
}

/// A bind group of `resources` at bindings 0, 1, 2, ... in order.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Record a write of `bytes` into `target` at `offset` in `enc`, through a staging buffer made for
/// it: unlike `queue.write_buffer`, which lands before every command buffer of the next
/// submission, this lands in the encoder's order (after what `enc` recorded before it).
pub(crate) fn write_in_order(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    target: &wgpu::Buffer,
    offset: u64,
    bytes: &[u8],
) {
    use wgpu::util::DeviceExt;
    if bytes.is_empty() {
        return;
    }
    let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("in-order write"),
        contents: bytes,
        usage: wgpu::BufferUsages::COPY_SRC,
    });
    enc.copy_buffer_to_buffer(&staging, 0, target, offset, bytes.len() as u64);
}
