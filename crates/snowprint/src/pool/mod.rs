//! The pooled heightmap storage: one GPU buffer holding the heightmaps of every resident surface,
//! so that all surfaces updated in a frame are processed by one dispatch per stage.
//!
//! Each surface owns a *slot* of three regions of `width * height` 32-bit texels:
//! the two halves of its ping-pong pair (depression in the low 16 bits, displaced snow in the high
//! 16) and its normals. Slots are placed first-fit at 256-byte alignment and accounted in exact
//! bytes (alignment padding included). Running out of room is a normal state: [`SlotAllocator::alloc`]
//! returns `None` and the caller decides whom to evict.

use bytemuck::{Pod, Zeroable};

/// Alignment of slots in the pool, bytes.
pub const SLOT_ALIGN: u64 = 256;
/// Bytes per texel per region (one `u32`).
pub const TEXEL_BYTES: u64 = 4;
/// Regions per slot: ping-pong pair of heights, and normals.
pub const REGIONS: u64 = 3;

/// Per-surface record read by every compute pass of the update.
/// Must match `SurfaceRecord` in `shared.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SurfaceRecord {
    /// Element offset of the half holding the previous heightmap.
    pub heights_read: u32,
    /// Element offset of the half receiving the new heightmap.
    pub heights_write: u32,
    /// Element offset of the normals region.
    pub normals: u32,
    /// Element offset into the scratch buffer.
    pub scratch: u32,
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Capture atlas x of the surface's rectangle.
    pub atlas_x: u32,
    /// Capture atlas y of the surface's rectangle.
    pub atlas_y: u32,
    /// 0 = depth capture, 1 = mask capture.
    pub mode: u32,
    /// Depression units refilled this update.
    pub replenish_units: u32,
    /// Capture batch, or [`NO_CAPTURE`].
    pub batch: u32,
    /// Mask capture imprint, fraction of the snow depth.
    pub mask_fraction: f32,
    /// Snow depth, metres.
    pub snow_depth: f32,
    /// Snow depth plus ankle height, metres.
    pub frustum_height: f32,
    /// Texel side along x, metres.
    pub texel_x: f32,
    /// Texel side along z, metres.
    pub texel_z: f32,
}

/// `batch` of a record whose surface had nothing to capture this update.
pub const NO_CAPTURE: u32 = u32::MAX;

/// A slot in the pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slot {
    /// Byte offset in the pool.
    pub offset: u64,
    /// Bytes reserved, alignment included.
    pub bytes: u64,
    /// Texels per region.
    pub texels: u64,
}

impl Slot {
    /// Element (u32) offset of region `r` (0, 1: ping-pong halves; 2: normals).
    pub fn region(&self, r: u64) -> u32 {
        ((self.offset + r * self.texels * TEXEL_BYTES) / TEXEL_BYTES) as u32
    }

    /// Byte offset of region `r`.
    pub fn region_bytes(&self, r: u64) -> u64 {
        self.offset + r * self.texels * TEXEL_BYTES
    }
}

/// Bytes a surface of `texels` texels takes in the pool.
pub fn slot_bytes(texels: u64) -> u64 {
    (texels * TEXEL_BYTES * REGIONS).div_ceil(SLOT_ALIGN) * SLOT_ALIGN
}

/// First-fit allocator over a fixed byte budget, with exact accounting.
#[derive(Clone, Debug)]
pub struct SlotAllocator {
    budget: u64,
    /// Free ranges `(offset, bytes)`, sorted by offset, never adjacent.
    free: Vec<(u64, u64)>,
    used: u64,
    high_water: u64,
}

impl SlotAllocator {
    /// An empty pool of `budget` bytes (rounded down to the slot alignment).
    pub fn new(budget: u64) -> Self {
        let budget = budget / SLOT_ALIGN * SLOT_ALIGN;
        Self {
            budget,
            free: if budget > 0 {
                vec![(0, budget)]
            } else {
                vec![]
            },
            used: 0,
            high_water: 0,
        }
    }

    /// The budget, bytes.
    pub fn budget(&self) -> u64 {
        self.budget
    }

    /// Bytes in use.
    pub fn used(&self) -> u64 {
        self.used
    }

    /// Most bytes ever in use at once.
    pub fn high_water(&self) -> u64 {
        self.high_water
    }

    /// Largest free block, bytes.
    pub fn largest_free(&self) -> u64 {
        self.free.iter().map(|f| f.1).max().unwrap_or(0)
    }

    /// Reserve a slot for `texels` texels, or `None` when no free block is large enough.
    pub fn alloc(&mut self, texels: u64) -> Option<Slot> {
        let bytes = slot_bytes(texels);
        let i = self.free.iter().position(|&(_, len)| len >= bytes)?;
        let (offset, len) = self.free[i];
        if len == bytes {
            self.free.remove(i);
        } else {
            self.free[i] = (offset + bytes, len - bytes);
        }
        self.used += bytes;
        self.high_water = self.high_water.max(self.used);
        Some(Slot {
            offset,
            bytes,
            texels,
        })
    }

    /// Return a slot to the pool, merging it with free neighbours.
    pub fn free(&mut self, slot: Slot) {
        let i = self.free.partition_point(|&(o, _)| o < slot.offset);
        self.free.insert(i, (slot.offset, slot.bytes));
        self.used -= slot.bytes;
        // Merge with the next, then with the previous.
        if i + 1 < self.free.len() && self.free[i].0 + self.free[i].1 == self.free[i + 1].0 {
            self.free[i].1 += self.free[i + 1].1;
            self.free.remove(i + 1);
        }
        if i > 0 && self.free[i - 1].0 + self.free[i - 1].1 == self.free[i].0 {
            self.free[i - 1].1 += self.free[i].1;
            self.free.remove(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn record_is_64_bytes() {
        assert_eq!(std::mem::size_of::<SurfaceRecord>(), 64);
    }

    #[test]
    fn exact_accounting() {
        let mut a = SlotAllocator::new(1 << 20);
        let s1 = a.alloc(200 * 150).unwrap();
        assert_eq!(s1.bytes, slot_bytes(30_000));
        assert_eq!(s1.bytes, 360_192); // 360000 rounded up to 256
        let s2 = a.alloc(100).unwrap();
        assert_eq!(a.used(), s1.bytes + s2.bytes);
        assert!(a.alloc(1 << 20).is_none());
        a.free(s1);
        a.free(s2);
        assert_eq!(a.used(), 0);
        assert_eq!(a.largest_free(), 1 << 20);
    }

    proptest! {
        #[test]
        fn never_over_budget_and_never_overlapping(ops in proptest::collection::vec((0u64..40_000, any::<bool>()), 1..200)) {
            let mut a = SlotAllocator::new(2 << 20);
            let mut live: Vec<Slot> = Vec::new();
            for (texels, free) in ops {
                if free && !live.is_empty() {
                    let s = live.swap_remove(texels as usize % live.len());
                    a.free(s);
                } else if let Some(s) = a.alloc(texels.max(1)) {
                    live.push(s);
                }
                let sum: u64 = live.iter().map(|s| s.bytes).sum();
                prop_assert_eq!(sum, a.used());
                prop_assert!(a.used() <= a.budget());
                let mut sorted = live.clone();
                sorted.sort_by_key(|s| s.offset);
                for w in sorted.windows(2) {
                    prop_assert!(w[0].offset + w[0].bytes <= w[1].offset);
                }
                if let Some(last) = sorted.last() {
                    prop_assert!(last.offset + last.bytes <= a.budget());
                }
            }
        }
    }
}
