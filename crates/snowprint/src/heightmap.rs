//! Heightmaps read back from the GPU, and their 16-bit PNG form.

use std::path::Path;

use crate::error::{Result, SnowError};

/// A surface's heightmap on the CPU. Texel `(column, row)` is at `row * width + column`; column 0 is
/// the smallest local `x`, row 0 the smallest local `z` (before yaw).
#[derive(Clone, Debug, PartialEq)]
pub struct Heightmap {
    /// Texels along local x.
    pub width: u32,
    /// Texels along local z.
    pub height: u32,
    /// Depression per texel: 0 = untouched snow, 65535 = pressed to the ground.
    pub depression: Vec<u16>,
    /// Snow pushed out of each texel by deformers (same units), kept for snow banks.
    pub displaced: Vec<u16>,
}

impl Heightmap {
    /// Unpack texels as stored in the pool (depression low 16 bits, displaced high 16).
    pub fn from_packed(width: u32, height: u32, packed: &[u32]) -> Self {
        Self {
            width,
            height,
            depression: packed.iter().map(|&v| (v & 0xffff) as u16).collect(),
            displaced: packed.iter().map(|&v| (v >> 16) as u16).collect(),
        }
    }

    /// Convert channels at `precision` (see [`crate::Precision`]) to 16-bit units, rounding to nearest.
    pub fn from_channels(
        width: u32,
        height: u32,
        precision: crate::pool::Precision,
        depression: &[u32],
        displaced: &[u32],
    ) -> Self {
        let max = precision.channel_max() as u64;
        let to16 = |v: &u32| ((*v as u64 * 65535 + max / 2) / max) as u16;
        Self {
            width,
            height,
            depression: depression.iter().map(to16).collect(),
            displaced: displaced.iter().map(to16).collect(),
        }
    }

    /// Depression at a texel as a fraction of the snow depth.
    pub fn fraction(&self, column: u32, row: u32) -> f32 {
        self.depression[(row * self.width + column) as usize] as f32 / 65535.0
    }

    /// Sum of the depression over all texels, in texels x snow depth (multiply by the texel area and
    /// the snow depth for cubic metres).
    pub fn pressed_volume(&self) -> f64 {
        self.depression.iter().map(|&v| v as f64 / 65535.0).sum()
    }

    /// PNG bytes: 16-bit greyscale of the depression.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, self.width, self.height);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Sixteen);
            let mut w = enc.write_header()?;
            let data: Vec<u8> = self
                .depression
                .iter()
                .flat_map(|v| v.to_be_bytes())
                .collect();
            w.write_image_data(&data)?;
        }
        Ok(bytes)
    }

    /// Write the depression as a 16-bit greyscale PNG.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        let bytes = self.to_png()?;
        std::fs::write(path, bytes).map_err(|source| SnowError::WriteFile {
            path: path.to_owned(),
            source,
        })
    }

    /// Read a 16-bit greyscale PNG written by [`Heightmap::save_png`] (displaced is zero).
    pub fn load_png(path: &Path) -> Result<Self> {
        let decode = |source| SnowError::PngDecode {
            path: path.to_owned(),
            source,
        };
        let file = std::fs::File::open(path).map_err(|source| SnowError::ReadFile {
            path: path.to_owned(),
            source,
        })?;
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .map_err(decode)?;
        let info = reader.info().clone();
        if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen
        {
            return Err(SnowError::PngFormat {
                path: path.to_owned(),
                reason: "it is not a 16-bit greyscale PNG",
            });
        }
        let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
        reader.next_frame(&mut buf).map_err(decode)?;
        let depression: Vec<u16> = buf
            .chunks_exact(2)
            .map(|c| u16::from_be_bytes([c[0], c[1]]))
            .take((info.width * info.height) as usize)
            .collect();
        Ok(Self {
            width: info.width,
            height: info.height,
            displaced: vec![0; depression.len()],
            depression,
        })
    }
}
