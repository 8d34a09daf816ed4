//! Small GPU resource helpers shared by the world's passes and the renderer's.

/// A GPU buffer that grows (to the next power of two) when asked for more; the old contents are
/// not kept, so it suits per-frame tables rewritten before each use.
pub(crate) struct Growable {
    /// The current buffer.
    pub buffer: wgpu::Buffer,
    usage: wgpu::BufferUsages,
    label: &'static str,
    /// What [`Growable::write_whole`] last wrote at the start of this buffer, while it holds it.
    written: Option<Vec<u8>>,
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
            written: None,
        }
    }

    /// Grow the buffer to hold `bytes` ([`Growable::ensure`]) and write them at its start, unless
    /// it holds them already: the last `write_whole` wrote the same bytes to this buffer (not
    /// replaced since). Each write costs wgpu a staging buffer of its own and a copy at the next
    /// submission, and a frame's tables are often the last frame's. Only for a buffer that nothing
    /// else writes (no other `queue.write_buffer`, no pass).
    pub(crate) fn write_whole(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) {
        self.ensure(device, bytes.len() as u64);
        if self.written.as_deref() == Some(bytes) {
            return;
        }
        queue.write_buffer(&self.buffer, 0, bytes);
        let written = self.written.get_or_insert_with(Vec::new);
        written.clear();
        written.extend_from_slice(bytes);
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

/// One binding of a kept bind group, as [`KeptGroups`] compares it: wgpu's handles compare by the
/// resource they name, so a buffer re-created (grown) or another texture's view differs.
#[derive(Clone, PartialEq)]
enum Bound {
    Buffer(wgpu::Buffer, u64, Option<std::num::NonZeroU64>),
    View(wgpu::TextureView),
    Sampler(wgpu::Sampler),
}

impl Bound {
    /// The binding of `resource`; `None` for the kinds never kept (arrays, acceleration
    /// structures): a group with one is made every time.
    fn of(resource: &wgpu::BindingResource<'_>) -> Option<Self> {
        match resource {
            wgpu::BindingResource::Buffer(b) => {
                Some(Self::Buffer(b.buffer.clone(), b.offset, b.size))
            }
            wgpu::BindingResource::TextureView(v) => Some(Self::View((*v).clone())),
            wgpu::BindingResource::Sampler(s) => Some(Self::Sampler((*s).clone())),
            _ => None,
        }
    }

    /// Whether this is the binding of `resource`.
    fn binds(&self, resource: &wgpu::BindingResource<'_>) -> bool {
        match (self, resource) {
            (Self::Buffer(buffer, offset, size), wgpu::BindingResource::Buffer(b)) => {
                buffer == b.buffer && *offset == b.offset && *size == b.size
            }
            (Self::View(view), wgpu::BindingResource::TextureView(v)) => view == *v,
            (Self::Sampler(sampler), wgpu::BindingResource::Sampler(s)) => sampler == *s,
            _ => false,
        }
    }
}

/// A kept bind group: its layout, what it binds and the group.
type Kept = (wgpu::BindGroupLayout, Vec<Bound>, wgpu::BindGroup);

/// Bind groups kept from frame to frame, one per slot (a surface's place in the frame's list,
/// say). Making a bind group each frame costs the CPU twice, once to make it and again in
/// `CommandEncoder::finish`; most frames bind what the last bound. A slot's group is made again
/// when its layout or anything it binds differs from the last time (a buffer re-created as it
/// grew, another surface's textures, another block of a uniform buffer), never reused stale.
#[derive(Default)]
pub(crate) struct KeptGroups {
    slots: Vec<Option<Kept>>,
}

impl KeptGroups {
    /// Slot `slot`'s group of `resources` at bindings 0, 1, 2, ... in order (as [`bind_group`]):
    /// the kept one where it binds the same, else a new one, kept.
    pub(crate) fn get(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        slot: usize,
        resources: &[wgpu::BindingResource<'_>],
    ) -> wgpu::BindGroup {
        if self.slots.len() <= slot {
            self.slots.resize_with(slot + 1, || None);
        }
        if let Some((kept_layout, bound, group)) = &self.slots[slot] {
            let same = kept_layout == layout
                && bound.len() == resources.len()
                && bound.iter().zip(resources).all(|(b, r)| b.binds(r));
            if same {
                return group.clone();
            }
        }
        let group = bind_group(device, label, layout, resources);
        let bound: Option<Vec<Bound>> = resources.iter().map(Bound::of).collect();
        self.slots[slot] = bound.map(|bound| (layout.clone(), bound, group.clone()));
        group
    }

    /// Let go of the groups of slots `slots` and after (the frame has fewer), and what they bind.
    pub(crate) fn truncate(&mut self, slots: usize) {
        self.slots.truncate(slots);
    }
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

/// Write `runs`, one after the other, into `target` from its start, as one write: with
/// `queue.write_buffer_with` when `enc` is `None`, else through one staging buffer copied in
/// `enc`'s order ([`write_in_order`]). Each write costs wgpu a staging buffer of its own; a split
/// frame plan's primitives come as one run a part, tens of them (`world/plan/parallel.rs`).
/// `total` is the runs' length together, a multiple of 4 bytes (`wgpu::COPY_BUFFER_ALIGNMENT`).
pub(crate) fn write_runs<'a>(
    (device, queue): (&wgpu::Device, &wgpu::Queue),
    enc: Option<&mut wgpu::CommandEncoder>,
    target: &wgpu::Buffer,
    total: u64,
    runs: impl Iterator<Item = &'a [u8]>,
) {
    let Some(size) = wgpu::BufferSize::new(total) else {
        return;
    };
    let fill = |to| fill_runs(to, runs);
    match enc {
        None => {
            // `None` only where wgpu reports a validation error of its own (an error scope sees it).
            if let Some(mut view) = queue.write_buffer_with(target, 0, size) {
                fill(view.slice(..));
            }
        }
        Some(enc) => {
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("in-order write"),
                size: total,
                usage: wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: true,
            });
            if let Ok(mut view) = staging.get_mapped_range_mut(..) {
                fill(view.slice(..));
            }
            staging.unmap();
            enc.copy_buffer_to_buffer(&staging, 0, target, 0, total);
        }
    }
}

/// Copy `runs`, one after the other, into `to` from its start; what does not fit is cut short (the
/// callers size `to` to the runs together).
pub(crate) fn fill_runs<'a>(
    mut to: wgpu::WriteOnly<'_, [u8]>,
    runs: impl IntoIterator<Item = &'a [u8]>,
) {
    for run in runs {
        let Ok((mut head, rest)) = to.split_at_checked(run.len()) else {
            return;
        };
        head.copy_from_slice(run);
        to = rest;
    }
}

/// The most workgroups a dispatch takes along one axis (wgpu's default limit, WebGPU's).
pub(crate) const DISPATCH_ROW_MAX: u32 = crate::wgsl::consts::DISPATCH_ROW_MAX;

/// A dispatch of `n` workgroups, one an item, as `(x, y)`: `y` rows of `x` each, as few rows as
/// the axis's limit allows and the rows as even as can be, so that at most `y - 1` workgroups
/// past the items are launched (a shader takes item `id.x + id.y * num_workgroups.x` and leaves
/// past `n`).
pub(crate) fn dispatch_rows(n: u32) -> (u32, u32) {
    let rows = n.div_ceil(DISPATCH_ROW_MAX).max(1);
    (n.div_ceil(rows), rows)
}

#[cfg(test)]
mod tests {
    use super::{DISPATCH_ROW_MAX, dispatch_rows};

    /// Every item has a workgroup, no row passes the limit, and at most `rows - 1` workgroups are
    /// launched past the items.
    #[test]
    fn dispatch_rows_cover_the_items_with_few_to_spare() {
        assert_eq!(dispatch_rows(0), (0, 1));
        assert_eq!(dispatch_rows(1), (1, 1));
        assert_eq!(dispatch_rows(65535), (65535, 1));
        assert_eq!(dispatch_rows(65536), (32768, 2));
        assert_eq!(dispatch_rows(81_000), (40_500, 2));
        for n in [2, 1000, 65534, 65537, 131_070, 131_071, 200_003, 5_000_000] {
            let (x, y) = dispatch_rows(n);
            assert!(x <= DISPATCH_ROW_MAX && x * y >= n, "{n}: {x} x {y}");
            assert!(x * y - n < y, "{n}: {x} x {y} launches {} past", x * y - n);
        }
    }
}
