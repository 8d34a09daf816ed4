//! Each surface's part of the pool, copied where its material reads it: the `SurfaceUniform`
//! (with the heights moved to word 0) written with the queue, the heights region copied in the
//! same encoder right after the update, so the material draws this frame's snow.

use std::collections::HashMap;

use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::renderer::RenderQueue;
use bevy::render::storage::GpuShaderBuffer;
use snowprint::{SnowWorld, SurfaceId, SurfaceUniform};

use super::ExtractedSurface;

/// Words of a surface's heights region: a plane of rows, two planes at 32 bits (depressions, then
/// displaced; `snowprint_texel_raw` in snowprint's engine.wgsl).
pub(crate) fn heights_words(uniform: &SurfaceUniform) -> u64 {
    let plane = u64::from(uniform.row_words) * u64::from(uniform.height);
    if uniform.bits == 32 { 2 * plane } else { plane }
}

/// The uniform the material reads: the library's, its heights at the start of its own buffer.
pub(crate) fn rebased(mut uniform: SurfaceUniform) -> SurfaceUniform {
    uniform.heights = 0;
    uniform
}

pub(super) fn surfaces_to_materials(
    world: &SnowWorld,
    ids: &HashMap<Entity, SurfaceId>,
    surfaces: &[ExtractedSurface],
    shader_buffers: &RenderAssets<GpuShaderBuffer>,
    queue: &RenderQueue,
    encoder: &mut bevy::render::render_resource::CommandEncoder,
) {
    let view = world.frame_view();
    for s in surfaces {
        let (Some(id), Some(buffers)) = (ids.get(&s.entity), &s.buffers) else {
            continue;
        };
        let (Some(surface), Some(heights)) = (
            shader_buffers.get(&buffers.surface),
            shader_buffers.get(&buffers.heights),
        ) else {
            // Bevy uploads the buffers a frame after the material is made.
            continue;
        };
        let Ok(uniform) = SurfaceUniform::for_surface(&view, *id) else {
            continue;
        };
        let bytes = heights_words(&uniform) * 4;
        if bytes > heights.buffer.size() {
            warn!(
                "snow surface of entity {} holds {bytes} bytes of heights, its material's buffer {}",
                s.entity,
                heights.buffer.size()
            );
            continue;
        }
        queue.write_buffer(&surface.buffer, 0, bytemuck::bytes_of(&rebased(uniform)));
        encoder.copy_buffer_to_buffer(
            view.pool_buffer,
            u64::from(uniform.heights) * 4,
            &heights.buffer,
            0,
            bytes,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(bits: u32, row_words: u32, height: u32) -> SurfaceUniform {
        SurfaceUniform {
            bits,
            row_words,
            height,
            heights: 4096,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    /// The region copied holds every word `snowprint_texel_raw` reads: rows of `row_words`, and
    /// at 32 bits the displaced plane after the depressions.
    #[test]
    fn the_heights_region_covers_every_plane() {
        // 8 bits: 201 texels a row, two a word: 101 words.
        assert_eq!(heights_words(&uniform(8, 101, 150)), 101 * 150);
        assert_eq!(heights_words(&uniform(16, 200, 150)), 200 * 150);
        assert_eq!(heights_words(&uniform(32, 200, 150)), 2 * 200 * 150);
    }

    /// The material's uniform is the library's with the heights at word 0 of its own buffer.
    #[test]
    fn the_uniform_is_rebased_and_otherwise_the_same() {
        let u = uniform(16, 200, 150);
        let r = rebased(u);
        assert_eq!(r.heights, 0);
        assert_eq!(
            bytemuck::bytes_of(&SurfaceUniform { heights: 0, ..u }),
            bytemuck::bytes_of(&r)
        );
    }
}
