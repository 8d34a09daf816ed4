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

/// A 2D texture a frame is drawn into, as an engine's target would be.
pub fn target(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Bytes of the settle state that follows a heightmap's words from version 4 (a `SURF` section's
/// last, and each level's of a `TERR`): updates and a rectangle.
pub const SETTLE_BYTES: usize = 20;

/// Bytes of a save with these sections, every length and checksum right (stored raw). The
/// sections are this build's (version 4): for an older `version`, each `SURF` loses its settle
/// state, as older builds wrote it (a `TERR` is left as it is: files older than version 3 have
/// none).
pub fn assemble_save(version: u32, sections: &[([u8; 4], Vec<u8>)]) -> Vec<u8> {
    let older: Vec<([u8; 4], Vec<u8>)>;
    let sections = if version < 4 {
        older = sections
            .iter()
            .map(|(tag, data)| {
                let keep = if tag == b"SURF" {
                    data.len().saturating_sub(SETTLE_BYTES)
                } else {
                    data.len()
                };
                (*tag, data[..keep].to_vec())
            })
            .collect();
        &older
    } else {
        sections
    };
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

/// How far a GPU may place a texel's ray from where the CPU does, metres: a few last bits of a
/// coordinate some metres from the origin (one bit of 6.0 is 4.8e-7), after the compiler fuses
/// and reorders the transforms' products.
pub const POSITION_SLACK: f32 = 2e-6;

/// The deformers moved by `by` (world metres), both poses of a moving one.
pub fn nudged(deformers: &[snowprint::Deformer], by: glam::Vec3) -> Vec<snowprint::Deformer> {
    deformers
        .iter()
        .map(|d| {
            let mut d = *d;
            d.pose.position += by;
            if let Some(p) = d.previous.as_mut() {
                p.position += by;
            }
            d
        })
        .collect()
}

/// Per texel, the range of a CPU capture over the deformers at their place (`at_place`, given)
/// and nudged by [`POSITION_SLACK`] along world x and z each way: where a ray grazes a silhouette, the height
/// it meets changes without bound as the ray moves, so a GPU's last-bit difference in where the
/// ray is can only be judged against how much the height moves there.
pub fn capture_envelope(
    at_place: &[f32],
    deformers: &[snowprint::Deformer],
    capture: impl Fn(&[snowprint::Deformer]) -> Vec<f32>,
) -> Vec<(f32, f32)> {
    let s = POSITION_SLACK;
    let mut env: Vec<(f32, f32)> = at_place.iter().map(|&c| (c, c)).collect();
    for by in [
        glam::Vec3::new(s, 0.0, 0.0),
        glam::Vec3::new(-s, 0.0, 0.0),
        glam::Vec3::new(0.0, 0.0, s),
        glam::Vec3::new(0.0, 0.0, -s),
    ] {
        for (e, c) in env.iter_mut().zip(capture(&nudged(deformers, by))) {
            *e = (e.0.min(c), e.1.max(c));
        }
    }
    env
}

/// How far `g` lies outside `range`.
pub fn outside(g: f32, range: (f32, f32)) -> f32 {
    (range.0 - g).max(g - range.1).max(0.0)
}
