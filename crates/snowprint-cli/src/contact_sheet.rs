//! The demo's secondary outputs: the contact sheet of chosen frames (labelled with a tiny built-in
//! font, no font files), the GIF animation, and the MP4 when `ffmpeg` is present.

use std::path::Path;

use image::{Rgba, RgbaImage, imageops};

/// `count` frame indices spread evenly over `frames`, first and last included.
pub fn pick(frames: usize, count: usize) -> Vec<usize> {
    if frames <= count {
        return (0..frames).collect();
    }
    let mut v: Vec<usize> = (0..count)
        .map(|i| ((i as f64 * (frames - 1) as f64 / (count - 1) as f64).round()) as usize)
        .collect();
    v.dedup();
    v
}

/// 3x5 glyphs of the characters labels use, one row per 3-bit line (top first).
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        's' => [0, 3, 6, 3, 6],
        '#' => [5, 7, 5, 7, 5],
        't' => [2, 7, 2, 2, 3],
        '=' => [0, 7, 0, 7, 0],
        'r' => [0, 5, 6, 4, 4],
        'e' => [7, 5, 7, 4, 7],
        'l' => [6, 2, 2, 2, 7],
        'i' => [2, 0, 2, 2, 2],
        'f' => [3, 4, 7, 4, 4],
        'a' => [0, 6, 1, 7, 7],
        'd' => [1, 1, 7, 5, 7],
        _ => [0; 5],
    }
}

/// Draw `text` at (x, y) with pixels of `scale`.
fn draw_text(img: &mut RgbaImage, text: &str, x: u32, y: u32, scale: u32, color: Rgba<u8>) {
    for (i, c) in text.chars().enumerate() {
        let g = glyph(c);
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = x + (i as u32 * 4 + col) * scale + dx;
                        let py = y + row as u32 * scale + dy;
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, color);
                        }
                    }
                }
            }
        }
    }
}

/// Thumbnails of the chosen frames in a grid of three columns, each labelled `#frame t=seconds`.
/// Two images of the same size side by side, 8 pixels apart, each labelled in its top-left corner.
pub fn side_by_side(left: &RgbaImage, right: &RgbaImage, a: &str, b: &str) -> RgbaImage {
    let (w, h) = left.dimensions();
    let mut out = RgbaImage::from_pixel(2 * w + 8, h, Rgba([0, 0, 0, 255]));
    image::imageops::overlay(&mut out, left, 0, 0);
    image::imageops::overlay(&mut out, right, (w + 8) as i64, 0);
    let scale = (h / 180).max(1);
    draw_text(&mut out, a, 8, 8, scale, Rgba([255, 255, 255, 255]));
    draw_text(&mut out, b, w + 16, 8, scale, Rgba([255, 255, 255, 255]));
    out
}

pub fn compose(frames: &[(usize, f32, RgbaImage)]) -> RgbaImage {
    let Some((_, _, first)) = frames.first() else {
        return RgbaImage::new(1, 1);
    };
    let tw = first.width().min(480);
    let th = (first.height() as u64 * tw as u64 / first.width() as u64) as u32;
    let cols = frames.len().clamp(1, 3) as u32;
    let rows = (frames.len() as u32).div_ceil(cols);
    let pad = 8;
    let mut sheet = RgbaImage::from_pixel(
        cols * (tw + pad) + pad,
        rows * (th + pad) + pad,
        Rgba([12, 13, 18, 255]),
    );
    for (i, (k, t, img)) in frames.iter().enumerate() {
        let thumb = imageops::resize(img, tw, th, imageops::FilterType::Triangle);
        let (c, r) = (i as u32 % cols, i as u32 / cols);
        let (x, y) = (pad + c * (tw + pad), pad + r * (th + pad));
        imageops::overlay(&mut sheet, &thumb, x as i64, y as i64);
        let label = format!("#{k} t={t:.2}s");
        draw_text(&mut sheet, &label, x + 7, y + 7, 2, Rgba([0, 0, 0, 255]));
        draw_text(
            &mut sheet,
            &label,
            x + 6,
            y + 6,
            2,
            Rgba([255, 255, 255, 255]),
        );
    }
    sheet
}

/// A GIF written frame by frame (frames wider than 480 pixels are scaled down).
pub struct GifWriter {
    encoder: image::codecs::gif::GifEncoder<std::io::BufWriter<std::fs::File>>,
    size: (u32, u32),
    delay_ms: u32,
}

impl GifWriter {
    /// Start a looping GIF at `path`.
    pub fn create(path: &Path, width: u32, height: u32, delay_ms: u32) -> Result<Self, String> {
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut encoder =
            image::codecs::gif::GifEncoder::new_with_speed(std::io::BufWriter::new(file), 10);
        encoder
            .set_repeat(image::codecs::gif::Repeat::Infinite)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        let w = width.min(480);
        let h = (height as u64 * w as u64 / width as u64).max(1) as u32;
        Ok(Self {
            encoder,
            size: (w, h),
            delay_ms,
        })
    }

    /// Append a frame.
    pub fn add(&mut self, img: &RgbaImage) -> Result<(), String> {
        let img = if img.dimensions() == self.size {
            img.clone()
        } else {
            imageops::resize(
                img,
                self.size.0,
                self.size.1,
                imageops::FilterType::Triangle,
            )
        };
        let frame = image::Frame::from_parts(
            img,
            0,
            0,
            image::Delay::from_numer_denom_ms(self.delay_ms, 1),
        );
        self.encoder
            .encode_frame(frame)
            .map_err(|e| format!("GIF encoding failed: {e}"))
    }

    /// Finish the file.
    pub fn finish(self) -> Result<(), String> {
        drop(self.encoder);
        Ok(())
    }
}

/// Encode `dir/frame_%04d.png` into an H.264 MP4 with ffmpeg, when it is installed. Returns whether
/// the file was made.
pub fn encode_mp4(dir: &Path, out: &Path, fps: f32) -> bool {
    let status = std::process::Command::new("ffmpeg")
        .arg("-y")
        .args(["-loglevel", "error"])
        .args(["-framerate", &format!("{fps}")])
        .arg("-i")
        .arg(dir.join("frame_%04d.png"))
        .args([
            "-c:v",
            "libx264",
            "-pix_fmt",
            "yuv420p",
            "-vf",
            "scale=trunc(iw/2)*2:trunc(ih/2)*2",
        ])
        .arg(out)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status();
    matches!(status, Ok(s) if s.success()) && out.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_spread_frames() {
        assert_eq!(pick(3, 6), vec![0, 1, 2]);
        assert_eq!(pick(11, 6), vec![0, 2, 4, 6, 8, 10]);
        assert_eq!(pick(36, 6), vec![0, 7, 14, 21, 28, 35]);
    }

    #[test]
    fn sheet_has_a_cell_per_frame() {
        let img = RgbaImage::from_pixel(64, 36, Rgba([200, 0, 0, 255]));
        let s = compose(&[
            (0, 0.0, img.clone()),
            (5, 1.5, img.clone()),
            (9, 3.0, img.clone()),
            (12, 4.0, img),
        ]);
        assert_eq!(s.dimensions(), (3 * 72 + 8, 2 * 44 + 8));
    }
}
