//! The page store: heightmaps of surfaces that gave their slot up (evicted for memory, or in an
//! unloaded zone), compressed on the CPU until their surface is admitted again.
//!
//! A page is a [`SurfaceSnapshot`] whose words are compressed with LZ4 (a heightmap is mostly
//! untouched snow, zeros, and compresses to a few percent); it comes back bit for bit. The store
//! counts its bytes exactly; the planner bounds them by `ManagerConfig::page_bytes` before it
//! evicts anything.

use std::collections::HashMap;

use crate::error::{Result, SnowError};
use crate::world::SurfaceSnapshot;

/// One paged heightmap.
#[derive(Clone, Debug, PartialEq)]
pub struct Page {
    /// The snapshot with its words taken out.
    pub meta: SurfaceSnapshot,
    /// Words of the slot, little-endian bytes, LZ4 block-compressed.
    pub compressed: Vec<u8>,
    /// Bytes of the words before compression.
    pub raw_bytes: usize,
}

impl Page {
    /// Compress a snapshot.
    pub fn compress(mut snapshot: SurfaceSnapshot) -> Self {
        let words = std::mem::take(&mut snapshot.words);
        let bytes: &[u8] = bytemuck::cast_slice(&words);
        Self {
            compressed: lz4_flex::block::compress(bytes),
            raw_bytes: bytes.len(),
            meta: snapshot,
        }
    }

    /// The snapshot back, bit for bit.
    pub fn decompress(&self) -> Result<SurfaceSnapshot> {
        let bytes = lz4_flex::block::decompress(&self.compressed, self.raw_bytes).map_err(|e| {
            SnowError::Snapshot {
                name: self.meta.desc.name.clone(),
                reason: format!("its page does not decompress: {e}"),
            }
        })?;
        if bytes.len() != self.raw_bytes || !bytes.len().is_multiple_of(4) {
            return Err(SnowError::Snapshot {
                name: self.meta.desc.name.clone(),
                reason: format!(
                    "its page holds {} bytes, {} were stored",
                    bytes.len(),
                    self.raw_bytes
                ),
            });
        }
        let words = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Ok(SurfaceSnapshot {
            words,
            ..self.meta.clone()
        })
    }

    /// Bytes the page takes in the store.
    pub fn bytes(&self) -> u64 {
        self.compressed.len() as u64
    }
}

/// Pages by managed surface index, with exact byte accounting.
#[derive(Clone, Debug, Default)]
pub struct PageStore {
    pages: HashMap<u32, Page>,
    bytes: u64,
}

impl PageStore {
    /// Keep a surface's page (replacing any older one). Returns the page's bytes.
    pub fn put(&mut self, surface: u32, page: Page) -> u64 {
        let b = page.bytes();
        if let Some(old) = self.pages.insert(surface, page) {
            self.bytes -= old.bytes();
        }
        self.bytes += b;
        b
    }

    /// Take a surface's page out of the store.
    pub fn take(&mut self, surface: u32) -> Option<Page> {
        let page = self.pages.remove(&surface)?;
        self.bytes -= page.bytes();
        Some(page)
    }

    /// A surface's page, if it has one.
    pub fn get(&self, surface: u32) -> Option<&Page> {
        self.pages.get(&surface)
    }

    /// Every page, by surface index (in no particular order).
    pub fn iter(&self) -> impl Iterator<Item = (u32, &Page)> {
        self.pages.iter().map(|(&k, v)| (k, v))
    }

    /// Bytes of every page.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Pages held.
    pub fn len(&self) -> usize {
        self.pages.len()
    }

    /// Whether the store holds no page.
    pub fn is_empty(&self) -> bool {
        self.pages.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pool::PoolFormat;
    use crate::surface::SurfaceDesc;

    fn snapshot(words: Vec<u32>) -> SurfaceSnapshot {
        SurfaceSnapshot {
            desc: SurfaceDesc::new("s", [0.0; 3], [1.0, 1.0], 0.2),
            width: 25,
            height: 25,
            format: PoolFormat::default(),
            carry: 0.25,
            words,
        }
    }

    #[test]
    fn a_page_comes_back_bit_for_bit_and_is_counted() {
        let mut words = vec![0u32; 625];
        for (i, w) in words.iter_mut().enumerate().skip(100).take(40) {
            *w = (i as u32).wrapping_mul(2_654_435_761);
        }
        let snap = snapshot(words);
        let page = Page::compress(snap.clone());
        assert!(page.bytes() < 625 * 4 / 2, "{} bytes", page.bytes());
        assert_eq!(page.decompress().unwrap(), snap);
        let mut store = PageStore::default();
        let b = store.put(3, page.clone());
        assert_eq!(store.bytes(), b);
        store.put(3, page);
        assert_eq!((store.bytes(), store.len()), (b, 1));
        assert!(store.take(3).is_some());
        assert_eq!((store.bytes(), store.len()), (0, 0));
    }

    #[test]
    fn a_damaged_page_is_an_error() {
        let mut page = Page::compress(snapshot(vec![7; 625]));
        page.raw_bytes += 4;
        assert!(page.decompress().is_err());
    }
}
