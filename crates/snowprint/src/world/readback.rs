//! Reading a world's heightmaps, normals and last captures back to the CPU (waits for the GPU).

use super::{PassMode, SnowWorld};
use crate::accumulate;
use crate::capture;
use crate::error::{Result, SnowError};
use crate::gpu::readback;
use crate::heightmap::Heightmap;
use crate::surface::SurfaceId;

#[cfg(doc)]
use crate::pool::PoolFormat;

impl SnowWorld {
    /// Copy `size` bytes of a GPU buffer to the CPU.
    fn download(&self, source: &wgpu::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
        readback::download(&self.device, &self.queue, source, offset, size)
    }

    /// The words of a surface's heights region as stored (layout per precision: see
    /// [`crate::PoolFormat`]; at 16 bits, depression in the low 16 bits and displaced in the high 16).
    pub fn read_packed(&self, id: SurfaceId) -> Result<Vec<u32>> {
        let s = self.state(id)?;
        let bytes = self.download(
            &self.pool,
            s.slot.offset,
            self.config
                .format
                .heights_bytes(s.layout.width, s.layout.height),
        )?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// A surface's `(depression, displaced)` channels in units of `1 / channel_max` of the snow
    /// depth at the pool's precision, row-major.
    pub fn read_channels(&self, id: SurfaceId) -> Result<(Vec<u32>, Vec<u32>)> {
        let s = self.state(id)?;
        let words = self.read_packed(id)?;
        let (w, h) = (s.layout.width, s.layout.height);
        let (depression, displaced) = self.config.format.decode(w, h, &words)?;
        // Logical order, whatever the storage's toroidal offsets.
        Ok((
            crate::pool::unwrap_channel(s.wrap, w, h, &depression),
            crate::pool::unwrap_channel(s.wrap, w, h, &displaced),
        ))
    }

    /// Read a surface's current heightmap back to the CPU (waits for the GPU), in 16-bit units
    /// whatever the pool's precision (exact at 8 and 16 bits, rounded to nearest at 32).
    pub fn read_heightmap(&self, id: SurfaceId) -> Result<Heightmap> {
        let s = self.state(id)?;
        let (depression, displaced) = self.read_channels(id)?;
        Ok(Heightmap::from_channels(
            s.layout.width,
            s.layout.height,
            self.config.format.precision,
            &depression,
            &displaced,
        ))
    }

    /// Read a surface's packed normals (see [`crate::accumulate::cpu::unpack_normal`]). Fails
    /// when the pool keeps no normals ([`PoolFormat::normals`]).
    pub fn read_normals_packed(&self, id: SurfaceId) -> Result<Vec<u32>> {
        let s = self.state(id)?;
        let Some(word) = s
            .slot
            .normals_word(&self.config.format, s.layout.width, s.layout.height)
        else {
            return Err(SnowError::Readback(
                "this world keeps no normals; set WorldConfig.format.normals to keep them".into(),
            ));
        };
        let bytes = self.download(&self.pool, word as u64 * 4, s.layout.texels() * 4)?;
        let (w, h) = (s.layout.width, s.layout.height);
        Ok(crate::pool::unwrap_channel(
            s.wrap,
            w,
            h,
            bytemuck::cast_slice(&bytes),
        ))
    }

    /// Read a surface's normals in its local frame.
    pub fn read_normals(&self, id: SurfaceId) -> Result<Vec<glam::Vec3>> {
        Ok(self
            .read_normals_packed(id)?
            .into_iter()
            .map(accumulate::cpu::unpack_normal)
            .collect())
    }

    /// Debug readback of the last step: the capture of a surface (depth per texel, 1 = nothing,
    /// `width x height` of them), when it was captured in that step; `None` otherwise, and for a
    /// surface whose deformers the update ray-cast itself ([`crate::CapturePath::Update`]: no
    /// capture holds it). The apron the capture also covers is left out
    /// ([`SnowWorld::read_last_capture_region`] keeps it).
    pub fn read_last_capture(&self, id: SurfaceId) -> Result<Option<Vec<f32>>> {
        let layout = self.state(id)?.layout;
        Ok(self
            .read_last_capture_region(id)?
            .map(|r| capture::strip_apron(layout.width, layout.height, &r)))
    }

    /// [`SnowWorld::read_last_capture`] over the surface's whole capture region: its texels and
    /// the apron of one texel around them that the update's blur reads
    /// ([`crate::capture::region`]: `(width + 2) x (height + 2)`, row-major, region texel
    /// `(c, r)` the surface's `(c - 1, r - 1)`).
    pub fn read_last_capture_region(&self, id: SurfaceId) -> Result<Option<Vec<f32>>> {
        self.state(id)?;
        let Some(view) = self.last.captured.iter().position(|c| c.0 == id.0 as usize) else {
            return Ok(None);
        };
        let r = self.last.captured[view].1;
        let texels = capture::region_texels(r.width, r.height);
        let mut bytes = self.download(
            &self.capture.buffer,
            r.scratch as u64 * 4,
            texels as u64 * 4,
        )?;
        // The winding buffer holds this surface's texels only when meshes were drawn over it.
        let winding = if r.mode & crate::pool::MODE_MESHES != 0 {
            self.download(
                &self.winding.buffer,
                r.scratch as u64 * 4,
                texels as u64 * 4,
            )?
        } else {
            vec![0; texels as usize * 4]
        };
        if r.batch == capture::COMPUTED {
            self.unwritten_to_zero(view as u32, (r.width, r.height), &mut bytes);
        }
        let codes: &[u32] = bytemuck::cast_slice(&bytes);
        let winding: &[i32] = bytemuck::cast_slice(&winding);
        // As capture_read.wgsl reads it: inside a mesh solid at the ground, depth 0, or on ground
        // that is not flat the ground's own code.
        let on_ground = r.mode & crate::pool::MODE_GROUND != 0;
        let ground = if on_ground {
            self.download(
                &self.winding.buffer,
                (r.scratch + texels) as u64 * 4,
                texels as u64 * 4,
            )?
        } else {
            vec![0; texels as usize * 4]
        };
        let ground: &[u32] = bytemuck::cast_slice(&ground);
        Ok(Some(
            codes
                .iter()
                .zip(winding)
                .zip(ground)
                .map(|((&v, &n), &g)| match (n > 0, on_ground) {
                    (true, false) => 0.0,
                    (true, true) => capture::decode_depth(g),
                    _ => capture::decode_depth(v),
                })
                .collect(),
        ))
    }

    /// The codes of a compute-path region (`bytes`, little-endian words) outside the tiles its
    /// workgroups wrote, which the buffer holds from an earlier frame, read as 0 ("nothing"), as the
    /// update, which never reads them, would find them.
    fn unwritten_to_zero(&self, view: u32, (width, height): (u32, u32), bytes: &mut [u8]) {
        let tile = crate::pool::TILE_SIDE;
        let (rw, rh) = capture::region(width, height);
        let tiles_x = rw.div_ceil(tile);
        let mut written = vec![false; (tiles_x * rh.div_ceil(tile)) as usize];
        for &[_, packed] in self.last.written.iter().filter(|w| w[0] == view) {
            if let Some(w) =
                written.get_mut(((packed >> 16) * tiles_x + (packed & 0xffff)) as usize)
            {
                *w = true;
            }
        }
        for (i, word) in bytes.chunks_exact_mut(4).enumerate() {
            let (x, y) = (i as u32 % rw, i as u32 / rw);
            if written.get(((y / tile) * tiles_x + x / tile) as usize) != Some(&true) {
                word.fill(0);
            }
        }
    }

    /// Debug readback of the last step: the blurred capture (stage 1 output) of a surface, when it
    /// was captured in that step by separate stages ([`PassMode::Separate`]; the fused pass keeps
    /// stage 1's output in registers).
    pub fn read_last_blurred(&self, id: SurfaceId) -> Result<Option<Vec<f32>>> {
        self.state(id)?;
        if self.config.passes == PassMode::Fused {
            return Ok(None);
        }
        let Some(&(_, r)) = self.last.captured.iter().find(|c| c.0 == id.0 as usize) else {
            return Ok(None);
        };
        let bytes = self.download(
            &self.scratch.buffer,
            r.scratch as u64 * 4,
            (r.width * r.height) as u64 * 4,
        )?;
        Ok(Some(bytemuck::cast_slice(&bytes).to_vec()))
    }
}
