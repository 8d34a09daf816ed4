//! The window's page store for a world without a manager: what left a level's window, kept on
//! the CPU in LZ4-compressed chunks of [`CHUNK`] x [`CHUNK`] world texels (the manager's page
//! store keeps whole surfaces the same way, `manager/pages.rs`), and given back when the window
//! returns. A texel never paged out is fresh snow: both channels 0.

use std::collections::HashMap;

/// Side of a chunk, texels.
pub const CHUNK: i64 = 64;

/// Texels of a chunk.
const CHUNK_TEXELS: usize = (CHUNK * CHUNK) as usize;

/// One chunk's texels, `(depression, displaced)` word pairs row-major, LZ4-compressed.
#[derive(Clone, Debug)]
struct ChunkPage {
    compressed: Vec<u8>,
}

impl ChunkPage {
    fn compress(pairs: &[u32]) -> Self {
        Self {
            compressed: lz4_flex::block::compress(bytemuck::cast_slice(pairs)),
        }
    }

    fn decompress(&self) -> Vec<u32> {
        // The store wrote every page itself: a page that does not decompress is a bug, and the
        // texels are fresh snow rather than a panic.
        let bytes = lz4_flex::block::decompress(&self.compressed, CHUNK_TEXELS * 8)
            .unwrap_or_else(|_| vec![0; CHUNK_TEXELS * 8]);
        bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }
}

/// Where a page lies: (level, chunk column, chunk row).
pub(crate) type PageKey = (usize, i64, i64);

/// Pages of every level of a terrain, by (level, chunk column, chunk row).
#[derive(Clone, Debug, Default)]
pub struct StripStore {
    pages: HashMap<PageKey, ChunkPage>,
    bytes: u64,
}

impl StripStore {
    /// Keep the texels of a `columns x rows` rectangle of `level` whose first texel is world
    /// texel `world`: `pairs` holds `(depression, displaced)` row-major.
    pub fn put(&mut self, level: usize, world: [i64; 2], columns: u32, rows: u32, pairs: &[u32]) {
        let mut groups = Vec::new();
        chunks_of(world, columns, rows, &mut |c, t| groups.push((c, t)));
        for (chunk, texels) in groups {
            let key = (level, chunk[0], chunk[1]);
            let mut page = self
                .pages
                .get(&key)
                .map_or_else(|| vec![0; CHUNK_TEXELS * 2], ChunkPage::decompress);
            for (c, r) in texels {
                let i = 2 * ((r - world[1]) * columns as i64 + (c - world[0])) as usize;
                let j = 2 * ((r - chunk[1] * CHUNK) * CHUNK + (c - chunk[0] * CHUNK)) as usize;
                page[j..j + 2].copy_from_slice(&pairs[i..i + 2]);
            }
            let page = ChunkPage::compress(&page);
            self.bytes += page.compressed.len() as u64;
            if let Some(old) = self.pages.insert(key, page) {
                self.bytes -= old.compressed.len() as u64;
            }
        }
    }

    /// The texels of a rectangle (see [`StripStore::put`]): those paged out before, fresh snow
    /// (zeros) elsewhere.
    pub fn get(&mut self, level: usize, world: [i64; 2], columns: u32, rows: u32) -> Vec<u32> {
        let mut out = vec![0u32; 2 * columns as usize * rows as usize];
        let pages = &self.pages;
        let mut visit = |chunk: [i64; 2], texels: Vec<(i64, i64)>| {
            let Some(page) = pages.get(&(level, chunk[0], chunk[1])) else {
                return;
            };
            let page = page.decompress();
            for (c, r) in texels {
                let i = 2 * ((r - world[1]) * columns as i64 + (c - world[0])) as usize;
                let j = 2 * ((r - chunk[1] * CHUNK) * CHUNK + (c - chunk[0] * CHUNK)) as usize;
                out[i..i + 2].copy_from_slice(&page[j..j + 2]);
            }
        };
        chunks_of(world, columns, rows, &mut visit);
        out
    }

    /// Compressed bytes held.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Chunks held.
    pub fn chunks(&self) -> usize {
        self.pages.len()
    }

    /// Every page with its compressed bytes, by (level, chunk column, chunk row) in order (what a
    /// save keeps: the same store gives the same bytes).
    pub(crate) fn pages(&self) -> Vec<(PageKey, &[u8])> {
        let mut pages: Vec<_> = self
            .pages
            .iter()
            .map(|(&k, p)| (k, p.compressed.as_slice()))
            .collect();
        pages.sort_by_key(|p| p.0);
        pages
    }

    /// A store of saved pages (each checked by [`check_page`], no key twice).
    pub(crate) fn from_pages(pages: impl IntoIterator<Item = (PageKey, Vec<u8>)>) -> Self {
        let mut store = Self::default();
        for (key, compressed) in pages {
            store.bytes += compressed.len() as u64;
            if let Some(old) = store.pages.insert(key, ChunkPage { compressed }) {
                store.bytes -= old.compressed.len() as u64;
            }
        }
        store
    }
}

/// Whether `compressed` is a page the store could have written: LZ4 of exactly a chunk's
/// `(depression, displaced)` pairs, no channel above `max`. One clause for what is wrong.
pub(crate) fn check_page(compressed: &[u8], max: u32) -> std::result::Result<(), String> {
    let bytes = lz4_flex::block::decompress(compressed, CHUNK_TEXELS * 8)
        .map_err(|e| format!("does not decompress ({e})"))?;
    if bytes.len() != CHUNK_TEXELS * 8 {
        return Err(format!(
            "holds {} bytes, a chunk {}",
            bytes.len(),
            CHUNK_TEXELS * 8
        ));
    }
    let over = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .find(|&v| v > max);
    match over {
        Some(v) => Err(format!("holds a channel of {v}, above the pool's {max}")),
        None => Ok(()),
    }
}

/// The world texels of a rectangle grouped by chunk: `f(chunk, texels)` once a chunk.
fn chunks_of(
    world: [i64; 2],
    columns: u32,
    rows: u32,
    f: &mut dyn FnMut([i64; 2], Vec<(i64, i64)>),
) {
    if columns == 0 || rows == 0 {
        return;
    }
    let (x1, y1) = (world[0] + columns as i64, world[1] + rows as i64);
    for cy in world[1].div_euclid(CHUNK)..=(y1 - 1).div_euclid(CHUNK) {
        for cx in world[0].div_euclid(CHUNK)..=(x1 - 1).div_euclid(CHUNK) {
            let (c0, r0) = ((cx * CHUNK).max(world[0]), (cy * CHUNK).max(world[1]));
            let (c1, r1) = (((cx + 1) * CHUNK).min(x1), ((cy + 1) * CHUNK).min(y1));
            let texels = (r0..r1)
                .flat_map(|r| (c0..c1).map(move |c| (c, r)))
                .collect();
            f([cx, cy], texels);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_put_comes_back_and_the_rest_is_fresh_snow() {
        let mut s = StripStore::default();
        let (cols, rows) = (70u32, 3u32);
        let pairs: Vec<u32> = (0..2 * cols * rows).map(|i| i * 7 + 1).collect();
        s.put(1, [-10, 60], cols, rows, &pairs);
        assert_eq!(s.get(1, [-10, 60], cols, rows), pairs);
        // Another level, or next to it: fresh snow.
        assert!(s.get(0, [-10, 60], cols, rows).iter().all(|&v| v == 0));
        let beside = s.get(1, [-12, 59], 3, 2);
        assert_eq!(&beside[..6], &[0; 6]);
        assert_eq!(&beside[6..10], &[0; 4]);
        assert_eq!(&beside[10..12], &pairs[0..2]);
        assert!(s.bytes() > 0 && s.chunks() == 2);
        // Its pages, saved and read back, are the same store.
        let pages: Vec<_> = s
            .pages()
            .into_iter()
            .map(|(k, b)| (k, b.to_vec()))
            .collect();
        for (_, b) in &pages {
            assert_eq!(check_page(b, u32::MAX), Ok(()));
        }
        assert!(check_page(&pages[0].1, 5).unwrap_err().contains("above"));
        assert!(check_page(&pages[0].1[..3], u32::MAX).is_err());
        let mut back = StripStore::from_pages(pages);
        assert_eq!((back.bytes(), back.chunks()), (s.bytes(), s.chunks()));
        assert_eq!(back.get(1, [-10, 60], cols, rows), pairs);
    }
}
