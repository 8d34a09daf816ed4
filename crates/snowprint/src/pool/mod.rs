//! The pooled heightmap storage: one GPU buffer holding the heightmaps of every resident surface,
//! so that all surfaces updated in a frame are processed by one dispatch per stage.
//!
//! Each surface owns a *slot*: its heightmap, two channels per texel (the depression and the
//! displaced snow, both in units of `1 / channel_max` of the snow depth) at the pool's
//! [`Precision`], and, only when [`PoolFormat::normals`] is on, a region of packed normals. No
//! history is kept per surface: the update replenishes and deepens each texel in place (it reads
//! only that texel's old value), and the per-frame capture buffers are shared by every surface
//! updated in the frame. Slots are placed first-fit at 256-byte alignment and accounted in exact
//! bytes (alignment padding included). Running out of room is a normal state:
//! [`SlotAllocator::alloc`] returns `None` and the caller decides whom to evict.
//!
//! Storage of the heights region, in 32-bit words (`texel.wgsl` reads and writes it the same way):
//!
//! | precision | bytes a texel | layout |
//! |---|---|---|
//! | 8 bits | 2 | rows padded to an even width; a word holds two neighbours along x, each as 16 bits: depression in the low byte, displaced in the high byte |
//! | 16 bits | 4 | a word per texel: depression in the low 16 bits, displaced in the high 16 |
//! | 32 bits | 8 | two planes: every texel's depression, then every texel's displaced snow |

use bytemuck::{Pod, Zeroable};

/// Side of the update's tiles, texels: the fused pass's workgroup, and the unit in which the
/// capture flags what it wrote (`TILE` of `wgsl/constants.wgsl`).
pub const TILE_SIDE: u32 = crate::wgsl::consts::TILE;
/// Words before the entries of the capture's tile list: the dispatch arguments and the count
/// (`TILE_LIST_HEADER` of `wgsl/constants.wgsl`).
pub const TILE_LIST_HEADER: u64 = crate::wgsl::consts::TILE_LIST_HEADER as u64;

/// Alignment of slots in the pool, bytes.
pub const SLOT_ALIGN: u64 = 256;

/// Bits per channel of the heightmaps in a pool.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum Precision {
    /// 8 bits a channel (1/255 of the snow depth: 1.2 mm of 30 cm snow), 2 bytes a texel.
    Bits8,
    /// 16 bits a channel, 4 bytes a texel (the default).
    #[default]
    Bits16,
    /// 32 bits a channel, 8 bytes a texel: no quantization coarser than the f32 capture.
    Bits32,
}

impl Precision {
    /// All precisions, coarsest first.
    pub const ALL: [Precision; 3] = [Precision::Bits8, Precision::Bits16, Precision::Bits32];

    /// Bits a channel.
    pub fn bits(self) -> u32 {
        match self {
            Precision::Bits8 => 8,
            Precision::Bits16 => 16,
            Precision::Bits32 => 32,
        }
    }

    /// The precision of `bits` bits a channel (8, 16 or 32).
    pub fn from_bits(bits: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.bits() == bits)
    }

    /// The value of a channel pressed to the ground (a whole snow depth).
    pub fn channel_max(self) -> u32 {
        match self {
            Precision::Bits8 => 0xff,
            Precision::Bits16 => 0xffff,
            Precision::Bits32 => u32::MAX,
        }
    }

    /// Bytes a texel (both channels).
    pub fn texel_bytes(self) -> u64 {
        2 * self.bits() as u64 / 8
    }

    /// Texels one invocation of the update writes together without racing its neighbours: the
    /// two texels of a word at 8 bits, one otherwise. Must match `unit_texels` in
    /// `texel_write.wgsl`.
    pub fn unit_texels(self) -> u32 {
        match self {
            Precision::Bits8 => 2,
            Precision::Bits16 | Precision::Bits32 => 1,
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}-bit", self.bits())
    }
}

/// How heightmaps are stored in a pool.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct PoolFormat {
    /// Bits a channel.
    pub precision: Precision,
    /// Keep a region of packed normals per surface (4 bytes a texel), written by the update for
    /// renderers that want them precomputed. Off by default: the renderer derives normals from
    /// the heights as it shades.
    pub normals: bool,
}

impl PoolFormat {
    /// The format with `precision` and no normals.
    pub fn new(precision: Precision) -> Self {
        Self {
            precision,
            normals: false,
        }
    }

    /// 32-bit words of one row of the heights region (a plane's, at 32 bits).
    pub fn row_words(&self, width: u32) -> u32 {
        width.div_ceil(self.precision.unit_texels())
    }

    /// Bytes of the heights region of a `width x height` heightmap.
    pub fn heights_bytes(&self, width: u32, height: u32) -> u64 {
        let words = self.row_words(width) as u64 * height as u64;
        match self.precision {
            Precision::Bits32 => 8 * words,
            _ => 4 * words,
        }
    }

    /// Bytes a `width x height` surface takes in the pool, alignment included.
    pub fn slot_bytes(&self, width: u32, height: u32) -> u64 {
        let normals = if self.normals {
            4 * width as u64 * height as u64
        } else {
            0
        };
        (self.heights_bytes(width, height) + normals).div_ceil(SLOT_ALIGN) * SLOT_ALIGN
    }

    /// Encode channels (row-major, `width x height` texels each, values up to
    /// [`Precision::channel_max`]; higher bits are dropped) into the words of a heights region.
    pub fn encode(
        &self,
        width: u32,
        height: u32,
        depression: &[u32],
        displaced: &[u32],
    ) -> crate::Result<Vec<u32>> {
        let (w, h) = (width as usize, height as usize);
        for channel in [depression, displaced] {
            self.check(width, height, "texels a channel", w * h, channel.len())?;
        }
        Ok(match self.precision {
            Precision::Bits8 => {
                let rw = self.row_words(width) as usize;
                let mut out = vec![0u32; rw * h];
                for y in 0..h {
                    for x in 0..w {
                        let i = y * w + x;
                        let v = (depression[i] & 0xff) | ((displaced[i] & 0xff) << 8);
                        out[y * rw + x / 2] |= v << (16 * (x % 2));
                    }
                }
                out
            }
            Precision::Bits16 => depression
                .iter()
                .zip(displaced)
                .map(|(&d, &p)| (d & 0xffff) | (p << 16))
                .collect(),
            Precision::Bits32 => depression.iter().chain(displaced).copied().collect(),
        })
    }

    fn check(
        &self,
        width: u32,
        height: u32,
        what: &'static str,
        expected: usize,
        got: usize,
    ) -> crate::Result<()> {
        if expected == got {
            return Ok(());
        }
        Err(crate::SnowError::HeightsLength {
            width,
            height,
            bits: self.precision.bits(),
            what,
            expected,
            got,
        })
    }

    /// Decode the words of a heights region into `(depression, displaced)` channels, row-major.
    pub fn decode(
        &self,
        width: u32,
        height: u32,
        words: &[u32],
    ) -> crate::Result<(Vec<u32>, Vec<u32>)> {
        let (w, h) = (width as usize, height as usize);
        let expected = (self.heights_bytes(width, height) / 4) as usize;
        self.check(width, height, "words", expected, words.len())?;
        Ok(match self.precision {
            Precision::Bits8 => {
                let rw = self.row_words(width) as usize;
                let half = |x: usize, y: usize| (words[y * rw + x / 2] >> (16 * (x % 2))) & 0xffff;
                let all = |shift: u32| {
                    (0..h)
                        .flat_map(|y| (0..w).map(move |x| (x, y)))
                        .map(|(x, y)| (half(x, y) >> shift) & 0xff)
                        .collect()
                };
                (all(0), all(8))
            }
            Precision::Bits16 => (
                words.iter().map(|&v| v & 0xffff).collect(),
                words.iter().map(|&v| v >> 16).collect(),
            ),
            Precision::Bits32 => (words[..w * h].to_vec(), words[w * h..2 * w * h].to_vec()),
        })
    }
}

/// Per-surface record read by every compute pass of the update.
/// Must match `SurfaceRecord` in `shared.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SurfaceRecord {
    /// Word offset of the heights region in the pool (updated in place).
    pub heights: u32,
    /// Word offset of the normals region, or [`NO_NORMALS`].
    pub normals: u32,
    /// Word offset into the per-frame capture buffers: the first texel of the surface's capture
    /// region ([`crate::capture::region`], the apron included); the separate blur's output starts
    /// there too, `width * height` of it.
    pub scratch: u32,
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Capture atlas x of the surface's capture region.
    pub atlas_x: u32,
    /// Capture atlas y of the surface's capture region.
    pub atlas_y: u32,
    /// Bit 0: mask capture (else depth); bit 1: [`MODE_MESHES`]; bit 2: [`MODE_GROUND`]; bit 3:
    /// [`MODE_REFILLED`]; bit 4: [`MODE_CAST`].
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
    /// First of the surface's tile flags written by the capture (see `capture.wgsl`).
    pub tiles: u32,
    /// Toroidal storage offsets, `ox | oy << 16` (`pool::wrapped`); 0 for an ordinary surface.
    pub wrap: u32,
    /// With [`MODE_CAST`]: half the surface's side along x, metres (what the update's ray cast
    /// reads instead of a capture view).
    pub half_x: f32,
    /// With [`MODE_CAST`]: half the surface's side along z, metres.
    pub half_z: f32,
    /// With [`MODE_CAST`]: its first primitive in the frame's list.
    pub prims: u32,
    /// With [`MODE_CAST`]: its primitives (at most [`crate::capture::CAST_PRIMS_MAX`]).
    pub prim_count: u32,
    /// With [`MODE_CAST`]: the first texel of its ground field, or [`crate::capture::NO_GROUND`].
    pub ground: u32,
}

impl SurfaceRecord {
    /// The update's 16x16 tiles (the fused pass's workgroups) over the surface.
    pub fn tile_count(&self) -> u32 {
        self.width.div_ceil(TILE_SIDE) * self.height.div_ceil(TILE_SIDE)
    }
}

/// Toroidal storage offsets `(ox, oy)` packed as the records carry them: `ox | oy << 16`.
pub fn pack_wrap(ox: u32, oy: u32) -> u32 {
    (ox & 0xffff) | (oy << 16)
}

/// Where logical texel `(x, y)` of a `width x height` heightmap stored with the packed offsets
/// `wrap` ([`pack_wrap`]) lives in its slot: `((x + ox) mod width, (y + oy) mod height)`. The CPU
/// side of `pool_wrapped` in `pool/texel.wgsl`, written independently of it (an ordinary surface
/// has `wrap` 0: the identity).
pub fn wrapped(wrap: u32, width: u32, height: u32, x: u32, y: u32) -> (u32, u32) {
    let (ox, oy) = (wrap & 0xffff, wrap >> 16);
    ((x + ox) % width, (y + oy) % height)
}

/// Channels stored wrapped (physical, row-major) put back in logical order (see [`wrapped`]).
pub fn unwrap_channel(wrap: u32, width: u32, height: u32, stored: &[u32]) -> Vec<u32> {
    if wrap == 0 {
        return stored.to_vec();
    }
    let mut out = Vec::with_capacity(stored.len());
    for y in 0..height {
        for x in 0..width {
            let (px, py) = wrapped(wrap, width, height, x, y);
            out.push(stored[(py * width + px) as usize]);
        }
    }
    out
}

/// Channels in logical order put where a slot stored with the offsets `wrap` keeps them: the
/// inverse of [`unwrap_channel`] (a saved window level written back into its slot).
pub fn wrap_channel(wrap: u32, width: u32, height: u32, logical: &[u32]) -> Vec<u32> {
    if wrap == 0 {
        return logical.to_vec();
    }
    let mut out = vec![0; logical.len()];
    for y in 0..height {
        for x in 0..width {
            let (px, py) = wrapped(wrap, width, height, x, y);
            out[(py * width + px) as usize] = logical[(y * width + x) as usize];
        }
    }
    out
}

/// `batch` of a record whose surface had nothing to capture this update.
pub const NO_CAPTURE: u32 = crate::wgsl::consts::NO_CAPTURE;
/// Bit of [`SurfaceRecord::mode`] set when mesh solids were drawn over the surface this update:
/// only then does the update read the capture's winding buffer.
pub const MODE_MESHES: u32 = crate::wgsl::consts::MODE_MESHES;
/// Bit of [`SurfaceRecord::mode`] set when mesh solids press a surface on ground that is not flat:
/// its capture and winding regions are then twice its texels, the winding's second half holding
/// the capture code of the ground at each texel (what a texel inside a solid is pressed to).
pub const MODE_GROUND: u32 = crate::wgsl::consts::MODE_GROUND;
/// Bit of [`SurfaceRecord::mode`] set when the update's refill pass replenishes the surface over
/// its whole heights region (accumulate/refill.wgsl): the fused pass then replenishes nothing.
pub const MODE_REFILLED: u32 = crate::wgsl::consts::MODE_REFILLED;
/// Bit of [`SurfaceRecord::mode`] set when the fused update ray-casts the surface's analytic
/// primitives itself, where its blur reads them ([`crate::CapturePath::Update`]): nothing of the
/// surface is in the capture's buffers, and its `half_x`, `half_z`, `prims`, `prim_count` and
/// `ground` say what to cast.
pub const MODE_CAST: u32 = crate::wgsl::consts::MODE_CAST;
/// `normals` of a record in a pool that keeps no normals.
pub const NO_NORMALS: u32 = crate::wgsl::consts::NO_NORMALS;

/// A slot in the pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slot {
    /// Byte offset in the pool.
    pub offset: u64,
    /// Bytes reserved, alignment included.
    pub bytes: u64,
}

impl Slot {
    /// Word (u32) offset of the heights region.
    pub fn heights_word(&self) -> u32 {
        (self.offset / 4) as u32
    }

    /// Word offset of the normals region of a `width x height` surface in `format`, when kept.
    pub fn normals_word(&self, format: &PoolFormat, width: u32, height: u32) -> Option<u32> {
        format
            .normals
            .then(|| ((self.offset + format.heights_bytes(width, height)) / 4) as u32)
    }
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

    /// Reserve a slot of `bytes` bytes (rounded up to [`SLOT_ALIGN`]), or `None` when no free
    /// block is large enough.
    pub fn alloc(&mut self, bytes: u64) -> Option<Slot> {
        let bytes = bytes.max(1).div_ceil(SLOT_ALIGN) * SLOT_ALIGN;
        let i = self.free.iter().position(|&(_, len)| len >= bytes)?;
        let (offset, len) = self.free[i];
        if len == bytes {
            self.free.remove(i);
        } else {
            self.free[i] = (offset + bytes, len - bytes);
        }
        self.used += bytes;
        self.high_water = self.high_water.max(self.used);
        Some(Slot { offset, bytes })
    }

    /// Reserve the slot of `bytes` bytes (rounded up to [`SLOT_ALIGN`]) that starts at `offset`,
    /// or `None` when that range is not free (restoring a saved pool's exact placement).
    pub fn alloc_at(&mut self, offset: u64, bytes: u64) -> Option<Slot> {
        let bytes = bytes.max(1).div_ceil(SLOT_ALIGN) * SLOT_ALIGN;
        if !offset.is_multiple_of(SLOT_ALIGN) {
            return None;
        }
        let i = self.free.iter().position(|&(o, len)| {
            o <= offset && offset.checked_add(bytes).is_some_and(|end| end <= o + len)
        })?;
        let (o, len) = self.free[i];
        let mut pieces = Vec::with_capacity(2);
        if offset > o {
            pieces.push((o, offset - o));
        }
        if offset + bytes < o + len {
            pieces.push((offset + bytes, o + len - offset - bytes));
        }
        self.free.splice(i..=i, pieces);
        self.used += bytes;
        self.high_water = self.high_water.max(self.used);
        Some(Slot { offset, bytes })
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
    fn wrapping_a_channel_undoes_unwrapping_it() {
        let (w, h) = (6u32, 4u32);
        let stored: Vec<u32> = (0..w * h).collect();
        for wrap in [0, pack_wrap(1, 0), pack_wrap(5, 3), pack_wrap(0, 2)] {
            let logical = unwrap_channel(wrap, w, h, &stored);
            assert_eq!(wrap_channel(wrap, w, h, &logical), stored, "{wrap:#x}");
            if wrap != 0 {
                assert_ne!(logical, stored);
            }
        }
    }

    #[test]
    fn record_is_88_bytes() {
        assert_eq!(std::mem::size_of::<SurfaceRecord>(), 88);
    }

    #[test]
    fn a_slot_can_be_reserved_where_it_was() {
        let mut a = SlotAllocator::new(10 * SLOT_ALIGN);
        let s = a.alloc_at(3 * SLOT_ALIGN, 2 * SLOT_ALIGN).unwrap();
        assert_eq!((s.offset, s.bytes), (3 * SLOT_ALIGN, 2 * SLOT_ALIGN));
        assert_eq!(a.used(), 2 * SLOT_ALIGN);
        // Overlapping, misaligned or past the end: refused, nothing changes.
        assert!(a.alloc_at(4 * SLOT_ALIGN, SLOT_ALIGN).is_none());
        assert!(a.alloc_at(SLOT_ALIGN + 1, SLOT_ALIGN).is_none());
        assert!(a.alloc_at(9 * SLOT_ALIGN, 2 * SLOT_ALIGN).is_none());
        assert!(a.alloc_at(u64::MAX - 255, SLOT_ALIGN).is_none());
        // First fit now takes the hole before it, then after it.
        assert_eq!(a.alloc(3 * SLOT_ALIGN).unwrap().offset, 0);
        assert_eq!(a.alloc(SLOT_ALIGN).unwrap().offset, 5 * SLOT_ALIGN);
        a.free(s);
        assert_eq!(a.largest_free(), 4 * SLOT_ALIGN);
    }

    #[test]
    fn exact_accounting() {
        let mut a = SlotAllocator::new(1 << 20);
        let f = PoolFormat {
            precision: Precision::Bits16,
            normals: true,
        };
        let s1 = a.alloc(f.slot_bytes(201, 150)).unwrap();
        assert_eq!(s1.bytes, 241_408); // 201 x 150 x 8 = 241200, rounded up to 256
        let s2 = a.alloc(100).unwrap();
        assert_eq!(a.used(), s1.bytes + s2.bytes);
        assert!(a.alloc(1 << 20).is_none());
        a.free(s1);
        a.free(s2);
        assert_eq!(a.used(), 0);
        assert_eq!(a.largest_free(), 1 << 20);
    }

    /// The talk's memory figure: four 512^2 heightmaps with both channels in its 2 MiB pool at
    /// 8 bits, two at 16, one at 32.
    #[test]
    fn talk_pool_holds_four_512_surfaces_at_8_bits() {
        for (p, fit) in [
            (Precision::Bits8, 4),
            (Precision::Bits16, 2),
            (Precision::Bits32, 1),
        ] {
            let f = PoolFormat::new(p);
            let mut a = SlotAllocator::new(2 << 20);
            let n = std::iter::from_fn(|| a.alloc(f.slot_bytes(512, 512))).count();
            assert_eq!(n, fit, "{p}");
        }
    }

    /// Encoding and decoding are inverse at every precision, odd widths included (8-bit rows are
    /// padded to whole words).
    #[test]
    fn encode_decode_round_trip() {
        for p in Precision::ALL {
            let f = PoolFormat::new(p);
            let (w, h) = (7, 3);
            let max = p.channel_max();
            let dep: Vec<u32> = (0..21u32).map(|i| max - i * 3).collect();
            let disp: Vec<u32> = (0..21u32).map(|i| i * 5).collect();
            let words = f.encode(w, h, &dep, &disp).unwrap();
            assert_eq!(words.len() as u64 * 4, f.heights_bytes(w, h));
            assert_eq!(f.decode(w, h, &words).unwrap(), (dep, disp.clone()), "{p}");
            // A wrong length is one sentence, not a panic.
            let e = f.decode(w, h, &words[1..]).unwrap_err().to_string();
            assert!(
                e.contains("7 x 3 heightmap") && e.contains("were given"),
                "{e}"
            );
            assert!(f.encode(w, h, &[1, 2], &disp).is_err());
        }
        // 8 bits: texel (1, 0) sits in the high half of word 0, depression in its low byte.
        let f = PoolFormat::new(Precision::Bits8);
        let words = f.encode(3, 1, &[1, 2, 3], &[4, 5, 6]).unwrap();
        assert_eq!(words, vec![0x0502_0401, 0x0000_0603]);
    }

    proptest! {
        #[test]
        fn never_over_budget_and_never_overlapping(ops in proptest::collection::vec((0u64..40_000, any::<bool>()), 1..200)) {
            let mut a = SlotAllocator::new(2 << 20);
            let mut live: Vec<Slot> = Vec::new();
            for (bytes, free) in ops {
                if free && !live.is_empty() {
                    let s = live.swap_remove(bytes as usize % live.len());
                    a.free(s);
                } else if let Some(s) = a.alloc(bytes * 4) {
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
