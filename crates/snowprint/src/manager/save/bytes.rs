//! The byte layer of a save: a bounded little-endian reader, and the writers that match it.

use super::{CODEC_LZ4, CODEC_RAW};
use crate::mesh::Mesh;
use crate::relax::{Rect, Settle};

/// A little-endian reader over a byte slice that never reads past its end.
pub(super) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    pub(super) fn take(&mut self, n: usize, what: &str) -> std::result::Result<&'a [u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "it ends inside {what} (byte {} of {})",
                    self.at,
                    self.bytes.len()
                )
            })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    pub(super) fn u32(&mut self, what: &str) -> std::result::Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4, what)?.try_into().unwrap_or_default(),
        ))
    }

    pub(super) fn u64(&mut self, what: &str) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8, what)?.try_into().unwrap_or_default(),
        ))
    }

    pub(super) fn i64(&mut self, what: &str) -> std::result::Result<i64, String> {
        Ok(self.u64(what)? as i64)
    }

    pub(super) fn f32(&mut self, what: &str) -> std::result::Result<f32, String> {
        Ok(f32::from_bits(self.u32(what)?))
    }

    pub(super) fn f64(&mut self, what: &str) -> std::result::Result<f64, String> {
        Ok(f64::from_bits(self.u64(what)?))
    }

    /// A count of items of at least `item_bytes` each, checked against the bytes left.
    pub(super) fn count(
        &mut self,
        item_bytes: usize,
        what: &str,
    ) -> std::result::Result<usize, String> {
        let n = self.u64(what)?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(item_bytes.max(1) as u64) > left {
            return Err(format!("{what} claims {n} items, more than its bytes hold"));
        }
        Ok(n as usize)
    }

    /// A counted run of 4-byte little-endian words (the count a u64, checked against the bytes
    /// left), as the writers lay a count and then the words.
    pub(super) fn words(&mut self, what: &str) -> std::result::Result<Vec<u32>, String> {
        let n = self.count(4, what)?;
        Ok(self
            .take(n * 4, what)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }

    /// [`Reader::words`] read as `f32`s.
    pub(super) fn floats(&mut self, what: &str) -> std::result::Result<Vec<f32>, String> {
        Ok(self.words(what)?.into_iter().map(f32::from_bits).collect())
    }

    pub(super) fn done(&self, what: &str) -> std::result::Result<(), String> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err(format!(
                "{what} has {} bytes past its end",
                self.bytes.len() - self.at
            ))
        }
    }
}

pub(super) fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

pub(super) fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

pub(super) fn put_mesh(out: &mut Vec<u8>, mesh: &Mesh) {
    put_u64(out, mesh.positions.len() as u64);
    for p in &mesh.positions {
        for c in p.to_array() {
            put_u32(out, c.to_bits());
        }
    }
    put_u64(out, mesh.indices.len() as u64);
    for &i in &mesh.indices {
        put_u32(out, i);
    }
}

pub(super) fn read_mesh(r: &mut Reader<'_>) -> std::result::Result<Mesh, String> {
    let n = r.count(12, "a mesh's vertices")?;
    let mut positions = Vec::with_capacity(n);
    for _ in 0..n {
        positions.push(glam::Vec3::new(
            r.f32("a vertex")?,
            r.f32("a vertex")?,
            r.f32("a vertex")?,
        ));
    }
    let n = r.count(4, "a mesh's indices")?;
    let mut indices = Vec::with_capacity(n);
    for _ in 0..n {
        indices.push(r.u32("an index")?);
    }
    Ok(Mesh { positions, indices })
}

/// A settle state after a heightmap's words (from version 4): updates, then the rectangle's first
/// column, first row, and one past its last column and row ([`read_settle`] reads it).
pub(super) fn put_settle(out: &mut Vec<u8>, s: &Settle) {
    let r = s.rect;
    for v in [s.updates, r.x0, r.y0, r.x1, r.y1] {
        put_u32(out, v);
    }
}

/// A settle state as [`put_settle`] writes it.
pub(super) fn read_settle(r: &mut Reader<'_>) -> std::result::Result<Settle, String> {
    let updates = r.u32("its settle updates")?;
    let mut v = [0; 4];
    for x in &mut v {
        *x = r.u32("its settle rectangle")?;
    }
    let [x0, y0, x1, y1] = v;
    Ok(Settle {
        updates,
        rect: Rect { x0, y0, x1, y1 },
    })
}

pub(super) fn put_string(out: &mut Vec<u8>, s: &str) {
    put_u64(out, s.len() as u64);
    out.extend_from_slice(s.as_bytes());
}

pub(super) fn read_string(r: &mut Reader<'_>) -> std::result::Result<String, String> {
    let n = r.count(1, "a name")?;
    String::from_utf8(r.take(n, "a name")?.to_vec()).map_err(|_| "a name is not UTF-8".into())
}

pub(super) fn section(out: &mut Vec<u8>, tag: &[u8; 4], data: &[u8]) {
    let packed = lz4_flex::block::compress(data);
    let (codec, stored) = if packed.len() < data.len() {
        (CODEC_LZ4, &packed[..])
    } else {
        (CODEC_RAW, data)
    };
    out.extend_from_slice(tag);
    put_u32(out, codec);
    put_u64(out, data.len() as u64);
    put_u64(out, stored.len() as u64);
    put_u32(out, crc32fast::hash(stored));
    out.extend_from_slice(stored);
}
