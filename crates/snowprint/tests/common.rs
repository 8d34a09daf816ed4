//! Shared set-up of the GPU tests: one device for the whole test binary.

#![allow(dead_code)]

use std::sync::OnceLock;

use snowprint::{GpuContext, GpuOptions};

/// The test device (software Vulkan in CI). A missing adapter fails the tests with the library's
/// own sentence about what to install.
pub fn gpu() -> &'static GpuContext {
    static GPU: OnceLock<GpuContext> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new(&GpuOptions::default()) {
        Ok(g) => g,
        Err(e) => panic!("GPU tests need an adapter: {e}"),
    })
}

/// Bytes of a save with these sections, every length and checksum right (stored raw).
pub fn assemble_save(version: u32, sections: &[([u8; 4], Vec<u8>)]) -> Vec<u8> {
    let mut out = b"SNOWSAVE".to_vec();
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(sections.len() as u32).to_le_bytes());
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    for (tag, data) in sections {
        out.extend_from_slice(tag);
        out.extend_from_slice(&0u32.to_le_bytes());
        out.extend_from_slice(&(data.len() as u64).to_le_bytes());
        out.extend_from_slice(&(data.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
        out.extend_from_slice(data);
    }
    out
}
