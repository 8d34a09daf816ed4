//! Ground that is not flat: the terrain under a surface's snow, one height per heightmap texel, and
//! how much snow each texel's slope holds.
//!
//! A surface's ground is [`Ground::Flat`] (its rectangle at the height of its centre, as every
//! surface was before), a [`HeightGrid`] of heights over the rectangle (read from a 16-bit PNG with
//! its height range, or a raw grid of little-endian `f32`), or a [`GroundMesh`] of triangles (a
//! terrain or a pitched roof) rasterised into the surface's texels on the GPU ([`raster`]). Heights
//! are metres along the surface's local `y`, 0 at its centre.
//!
//! [`GroundField::build`] turns a ground into what the capture reads per texel: the *base* of the
//! snow column and its *bare* depth. On ground no steeper than [`SlopeRule::full_degrees`] the base
//! is the ground and nothing is bare: the snow top is the ground plus the snow depth. Steeper, the
//! texel holds a fraction `k` of the snow depth `D`, falling linearly with the slope angle to none at
//! [`SlopeRule::bare_degrees`] (the slope measured over the snow's depth either side of the texel,
//! at least a texel: snow bridges what is smaller, and fields of any texel size read it alike);
//! its column is lowered to the base `ground - (1 - k) D`, of which the
//! lowest `(1 - k) D` is rock. So the snow top is `ground + k D`, a depression is still a fraction of
//! `D` measured from that top, and the capture's depth clamp holds at the ground itself (the bare
//! depth above the base): a foot never digs below the terrain. Capture: `capture/write.wgsl`.

pub(crate) mod cpu;
pub(crate) mod raster;

use glam::Vec3;

use crate::error::{Result, SnowError};
use crate::surface::SurfaceLayout;

/// What lies under a surface's snow.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Ground {
    /// The surface's rectangle, flat at its centre's height (every surface's ground before this).
    #[default]
    Flat,
    /// Heights sampled over the surface's rectangle (bilinearly between the grid's samples).
    Grid(HeightGrid),
    /// Triangles in world metres, rasterised into the surface's texels on the GPU: each texel takes
    /// the highest face over its centre; texels no face covers keep the flat ground (0).
    Mesh(GroundMesh),
}

/// A grid of ground heights covering a surface's rectangle: sample `(c, r)` lies at the centre of
/// cell `(c, r)` of a `columns x rows` division of the rectangle (column 0 the smallest local `x`,
/// row 0 the smallest `z`), as a PNG's pixels lie over its image. Heights are metres along local `y`.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightGrid {
    /// Samples along local `x`.
    pub columns: u32,
    /// Samples along local `z`.
    pub rows: u32,
    /// `columns * rows` heights, row after row, metres.
    pub heights: Vec<f32>,
}

/// A ground mesh: triangles in world metres, any winding (the highest face over a texel is the
/// ground there).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroundMesh {
    /// The triangles.
    pub triangles: Vec<[Vec3; 3]>,
}

/// How much snow a slope holds: all of it up to `full_degrees`, none from `bare_degrees`, linearly
/// less in the angle between. The default (35 and 60 degrees) lets a 30-degree roof keep its snow
/// and leaves cliffs bare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeRule {
    /// Steepest slope that holds the whole snow depth, degrees.
    pub full_degrees: f32,
    /// Gentlest slope that holds none, degrees (above `full_degrees`).
    pub bare_degrees: f32,
}

impl Default for SlopeRule {
    fn default() -> Self {
        Self {
            full_degrees: 35.0,
            bare_degrees: 60.0,
        }
    }
}

impl SlopeRule {
    /// A rule that never bares a slope (every texel holds the whole depth).
    pub const NEVER_BARE: Self = Self {
        full_degrees: 90.0,
        bare_degrees: 91.0,
    };

    /// Fraction of the snow depth a slope of `degrees` holds.
    pub fn holds(&self, degrees: f32) -> f32 {
        if degrees <= self.full_degrees {
            return 1.0;
        }
        ((self.bare_degrees - degrees) / (self.bare_degrees - self.full_degrees)).clamp(0.0, 1.0)
    }

    /// Check the angles, naming the surface.
    pub fn validate(&self, surface: &str) -> Result<()> {
        let ok = |a: f32| a.is_finite() && a >= 0.0;
        if !(ok(self.full_degrees)
            && ok(self.bare_degrees)
            && self.bare_degrees > self.full_degrees)
        {
            return Err(SnowError::InvalidGround {
                name: surface.to_owned(),
                reason: format!(
                    "the slope rule holds full snow to {} degrees and none from {} degrees; both must be 0 or more and the second larger",
                    self.full_degrees, self.bare_degrees
                ),
            });
        }
        Ok(())
    }
}

impl HeightGrid {
    /// Check the grid's size against its heights, naming the surface.
    pub fn validate(&self, surface: &str) -> Result<()> {
        let bad = |reason: String| {
            Err(SnowError::InvalidGround {
                name: surface.to_owned(),
                reason,
            })
        };
        if self.columns < 2 || self.rows < 2 {
            return bad(format!(
                "the height grid is {} x {} samples; it needs at least 2 x 2",
                self.columns, self.rows
            ));
        }
        let n = self.columns as u64 * self.rows as u64;
        if self.heights.len() as u64 != n {
            return bad(format!(
                "the height grid says {} x {} samples ({n}) but holds {} heights",
                self.columns,
                self.rows,
                self.heights.len()
            ));
        }
        if let Some(h) = self.heights.iter().find(|h| !h.is_finite()) {
            return bad(format!("the height grid holds {h}; heights must be finite"));
        }
        Ok(())
    }

    /// A grid from a 16-bit greyscale PNG: 0 is `low` metres, 65535 is `high`, linearly between.
    pub fn from_png16(bytes: &[u8], low: f32, high: f32) -> std::result::Result<Self, String> {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder
            .read_info()
            .map_err(|e| format!("is not a readable PNG ({e})"))?;
        let info = reader.info();
        let (columns, rows) = (info.width, info.height);
        if info.bit_depth != png::BitDepth::Sixteen || info.color_type != png::ColorType::Grayscale
        {
            return Err(format!(
                "is a {:?} {:?} PNG; a heightmap must be 16-bit greyscale",
                info.bit_depth, info.color_type
            ));
        }
        let mut buf = vec![0u8; reader.output_buffer_size().unwrap_or(0)];
        reader
            .next_frame(&mut buf)
            .map_err(|e| format!("is not a readable PNG ({e})"))?;
        let scale = (high - low) / 65535.0;
        let heights = buf
            .chunks_exact(2)
            .take(columns as usize * rows as usize)
            .map(|p| low + u16::from_be_bytes([p[0], p[1]]) as f32 * scale)
            .collect();
        Ok(Self {
            columns,
            rows,
            heights,
        })
    }

    /// A grid from raw little-endian `f32` heights, `columns * rows` of them row after row.
    pub fn from_raw_f32(
        bytes: &[u8],
        columns: u32,
        rows: u32,
    ) -> std::result::Result<Self, String> {
        let want = columns as u64 * rows as u64 * 4;
        if bytes.len() as u64 != want {
            return Err(format!(
                "holds {} bytes, but a {columns} x {rows} grid of f32 heights is {want} bytes",
                bytes.len()
            ));
        }
        let heights = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok(Self {
            columns,
            rows,
            heights,
        })
    }

    /// The height at a point of the rectangle given as fractions `(u, v)` of its sides in `[0, 1]`:
    /// bilinear between the four nearest samples, clamped at the edges.
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        let x = (u * self.columns as f32 - 0.5).clamp(0.0, (self.columns - 1) as f32);
        let y = (v * self.rows as f32 - 0.5).clamp(0.0, (self.rows - 1) as f32);
        let (x0, y0) = (
            (x.floor() as u32).min(self.columns - 2),
            (y.floor() as u32).min(self.rows - 2),
        );
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |c: u32, r: u32| self.heights[(r * self.columns + c) as usize];
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
        let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// What the capture reads of a surface's ground, per heightmap texel (row-major).
#[derive(Clone, Debug, PartialEq)]
pub struct GroundField {
    /// Texels along local `x`.
    pub width: u32,
    /// Texels along local `z`.
    pub height: u32,
    /// Ground height at each texel centre, metres along local `y`.
    pub ground: Vec<f32>,
    /// `[base, bare]` at each texel: the bottom of the snow column (`ground - bare`) and its bare
    /// depth, metres (see the module's documentation). Must match `ground` in `capture.wgsl`.
    pub columns: Vec<[f32; 2]>,
}

impl GroundField {
    /// The field of `ground` heights (one per texel of `layout`) under snow `snow_depth` deep on a
    /// surface of `size` metres, bared by `slope`.
    pub fn build(
        layout: SurfaceLayout,
        size: glam::Vec2,
        ground: Vec<f32>,
        snow_depth: f32,
        slope: SlopeRule,
    ) -> Self {
        let (w, h) = (layout.width, layout.height);
        let texel = size / glam::Vec2::new(w as f32, h as f32);
        let columns = (0..h)
            .flat_map(|r| (0..w).map(move |c| (c, r)))
            .map(|(c, r)| column_at(&ground, w, h, texel, c, r, snow_depth, slope))
            .collect();
        Self {
            width: w,
            height: h,
            ground,
            columns,
        }
    }

    /// Move the field's window by `by` texels (logical texel `(c, r)` becomes what was
    /// `(c + by[0], r + by[1])`), in place: the heights that stay are moved, `sample(c, r)` gives
    /// those of the texels that enter, and the columns are computed again only where they can
    /// differ from [`GroundField::build`] on the moved heights: the entering strips, the texels
    /// that were on an edge (their differences now reach into the strips) and those that now are
    /// (one-sided there). The result is bit for bit `build`'s. `false`, and nothing changed, for
    /// a move as large as the field (a jump): build it whole then.
    pub(crate) fn scroll(
        &mut self,
        by: [i64; 2],
        size: glam::Vec2,
        snow_depth: f32,
        slope: SlopeRule,
        mut sample: impl FnMut(u32, u32) -> f32,
    ) -> bool {
        let (w, h) = (self.width, self.height);
        let [dx, dz] = by;
        if dx.unsigned_abs() >= w as u64 || dz.unsigned_abs() >= h as u64 {
            return false;
        }
        shift(&mut self.ground, w, h, dx, dz);
        shift(&mut self.columns, w, h, dx, dz);
        let xs = entering(w, dx);
        let zs = entering(h, dz);
        for r in 0..h {
            let cs = if zs.contains(&r) { 0..w } else { xs.clone() };
            for c in cs {
                self.ground[(r * w + c) as usize] = sample(c, r);
            }
        }
        let texel = size / glam::Vec2::new(w as f32, h as f32);
        let mut redo = |c: u32, r: u32| {
            self.columns[(r * w + c) as usize] =
                column_at(&self.ground, w, h, texel, c, r, snow_depth, slope);
        };
        for c in changed(w, dx, slope_reach(texel.x, snow_depth)) {
            (0..h).for_each(|r| redo(c, r));
        }
        for r in changed(h, dz, slope_reach(texel.y, snow_depth)) {
            (0..w).for_each(|c| redo(c, r));
        }
        true
    }

    /// The columns of the surface's capture region, the apron's extrapolated
    /// (`region_columns`).
    pub fn region_columns(&self) -> Vec<[f32; 2]> {
        region_columns(&self.columns, self.width, self.height)
    }

    /// [`GroundField::range`] over the capture region ([`GroundField::region_columns`]): the
    /// capture volume the plan culls against reaches from the first to the second plus the snow
    /// depth and the ankle height.
    pub fn region_range(&self) -> (f32, f32) {
        let columns = self.region_columns();
        let low = columns.iter().map(|c| c[0]).fold(f32::INFINITY, f32::min);
        let high = columns
            .iter()
            .map(|c| c[0] + c[1])
            .fold(f32::NEG_INFINITY, f32::max);
        let (l, h) = self.range();
        (low.min(l), high.max(h))
    }

    /// Lowest base and highest ground: the renderer's bounds of the surface's snow.
    pub fn range(&self) -> (f32, f32) {
        let low = self
            .columns
            .iter()
            .map(|c| c[0])
            .fold(f32::INFINITY, f32::min);
        let high = self
            .ground
            .iter()
            .copied()
            .fold(f32::NEG_INFINITY, f32::max);
        (low, high)
    }
}

/// The `[base, bare]` columns of a surface's capture region ([`crate::capture::region`]: its
/// texels and the apron around them, row-major) from its `width x height` `columns`. Past the
/// field's sides the capture reads the ground one texel beyond the surface: a field knows no
/// ground there, so it is extrapolated linearly from the two texels at the side, along `x` and
/// then along `z`, the bare depth kept at 0 or more (exact on a plane, which holds its slope and
/// so its bare depth; on curved ground off by the curvature over a texel). The same maths as
/// `ground_of` in `capture/write.wgsl`, operation for operation (`2 a - b` rounds once, fused or
/// not); a field one texel wide or high repeats its edge.
fn region_columns(columns: &[[f32; 2]], width: u32, height: u32) -> Vec<[f32; 2]> {
    let a = crate::wgsl::consts::APRON as i32;
    let (w, h) = (width as i32, height as i32);
    let at = |x: i32, y: i32| columns[(y * w + x) as usize];
    let ext = |p: [f32; 2], q: [f32; 2]| [2.0 * p[0] - q[0], 2.0 * p[1] - q[1]];
    let row = |x: i32, y: i32| {
        if x < 0 && w > 1 {
            ext(at(0, y), at(1, y))
        } else if x >= w && w > 1 {
            ext(at(w - 1, y), at(w - 2, y))
        } else {
            at(x.clamp(0, w - 1), y)
        }
    };
    let mut out = Vec::with_capacity(((w + 2 * a) * (h + 2 * a)) as usize);
    for y in -a..h + a {
        for x in -a..w + a {
            let [base, bare] = if y < 0 && h > 1 {
                ext(row(x, 0), row(x, 1))
            } else if y >= h && h > 1 {
                ext(row(x, h - 1), row(x, h - 2))
            } else {
                row(x, y.clamp(0, h - 1))
            };
            out.push([base, bare.max(0.0)]);
        }
    }
    out
}

/// Heights at the centres of a surface's texels from a grid.
pub fn sample_grid(grid: &HeightGrid, layout: SurfaceLayout) -> Vec<f32> {
    let (w, h) = (layout.width, layout.height);
    (0..h)
        .flat_map(|r| (0..w).map(move |c| (c, r)))
        .map(|(c, r)| grid.sample((c as f32 + 0.5) / w as f32, (r as f32 + 0.5) / h as f32))
        .collect()
}

/// The `[base, bare]` column of texel `(c, r)` of ground heights `g` (`w x h` texels of
/// `texel` metres) under snow `snow_depth` deep, bared by `slope`.
#[allow(clippy::too_many_arguments)]
fn column_at(
    g: &[f32],
    w: u32,
    h: u32,
    texel: glam::Vec2,
    c: u32,
    r: u32,
    snow_depth: f32,
    slope: SlopeRule,
) -> [f32; 2] {
    let degrees = slope_degrees(g, w, h, texel, snow_depth, c, r);
    let bare = (1.0 - slope.holds(degrees)) * snow_depth;
    [g[(r * w + c) as usize] - bare, bare]
}

/// Move a `w x h` row-major field by `(dx, dz)` in place: texel `(c, r)` takes what was at
/// `(c + dx, r + dz)`; the texels that enter keep stale values, to be written.
fn shift<T: Copy>(v: &mut [T], w: u32, h: u32, dx: i64, dz: i64) {
    let (w, h) = (w as i64, h as i64);
    let keep = (w - dx.abs()) as usize;
    let (to, from) = (dx.min(0).unsigned_abs() as usize, dx.max(0) as usize);
    let row = |r: i64| {
        let from_row = r + dz;
        (0..h).contains(&from_row).then_some((r * w) as usize)
    };
    // Rows in the order that reads each source row before it is written over.
    let order: Box<dyn Iterator<Item = i64>> = if dz > 0 {
        Box::new(0..h)
    } else {
        Box::new((0..h).rev())
    };
    for r in order {
        if let Some(at) = row(r) {
            let src = ((r + dz) * w) as usize + from;
            v.copy_within(src..src + keep, at + to);
        }
    }
}

/// The logical texels along a side of `n` that enter when the window moves by `d` texels.
fn entering(n: u32, d: i64) -> std::ops::Range<u32> {
    let k = d.unsigned_abs() as u32;
    if d >= 0 { n - k..n } else { 0..k }
}

/// The logical texels along a side of `n` whose column may change when the window moves by `d`,
/// for slopes measured `k` texels either side: those whose reach takes in an entering texel, and
/// those whose reach is cut by an edge now or was before the move (one-sided there).
fn changed(n: u32, d: i64, k: u32) -> Vec<u32> {
    if d == 0 {
        return Vec::new();
    }
    let (n, k) = (n as i64, k as i64);
    let enter = entering(n as u32, d);
    let (lo, hi) = (enter.start as i64, enter.end as i64 - 1);
    let cut = |c: i64| c < k || c >= n - k;
    (0..n)
        .filter(|&c| (c + k >= lo && c - k <= hi) || cut(c) || cut(c + d))
        .map(|c| c as u32)
        .collect()
}

/// Texels either side over which a field of `texel` metres measures the slope that decides the
/// snow a texel holds: the snow's depth, at least one texel ([`slope_degrees`]).
fn slope_reach(texel: f32, snow_depth: f32) -> u32 {
    ((snow_depth / texel).round() as u32).max(1)
}

/// Slope angle at texel `(c, r)`, degrees, from the differences of the heights the snow's depth
/// either side (at least a texel; [`slope_reach`]), one-sided at the edges. Snow bridges what is
/// smaller than its depth, and so a field of any texel size reads the slope alike: measured
/// between neighbouring texels, a field finer than its ground's samples (a window level of 5 cm
/// on a grid of 50 cm) reads a slope that jumps at every line of the grid, where the bilinear
/// ground kinks, and on a flank steeper than the rule's full angle the snow it held stepped there
/// by centimetres: lines down the mountain's outcrop.
fn slope_degrees(
    g: &[f32],
    w: u32,
    h: u32,
    texel: glam::Vec2,
    snow_depth: f32,
    c: u32,
    r: u32,
) -> f32 {
    let at = |c: u32, r: u32| g[(r * w + c) as usize];
    let (kx, kz) = (
        slope_reach(texel.x, snow_depth),
        slope_reach(texel.y, snow_depth),
    );
    let (cl, cr) = (c.saturating_sub(kx), (c + kx).min(w - 1));
    let (rb, rf) = (r.saturating_sub(kz), (r + kz).min(h - 1));
    let dx = if cr > cl {
        (at(cr, r) - at(cl, r)) / ((cr - cl) as f32 * texel.x)
    } else {
        0.0
    };
    let dz = if rf > rb {
        (at(c, rf) - at(c, rb)) / ((rf - rb) as f32 * texel.y)
    } else {
        0.0
    };
    (dx * dx + dz * dz).sqrt().atan().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_rule_is_linear_between_its_angles() {
        let r = SlopeRule::default();
        assert_eq!(r.holds(30.0), 1.0);
        assert_eq!(r.holds(35.0), 1.0);
        assert!((r.holds(47.5) - 0.5).abs() < 1e-6);
        assert_eq!(r.holds(60.0), 0.0);
        assert_eq!(r.holds(80.0), 0.0);
        assert!(SlopeRule::NEVER_BARE.holds(89.0) == 1.0);
        assert!(
            SlopeRule {
                full_degrees: 50.0,
                bare_degrees: 40.0
            }
            .validate("s")
            .is_err()
        );
    }

    #[test]
    fn grid_sampling_is_bilinear_between_sample_centres() {
        let g = HeightGrid {
            columns: 2,
            rows: 2,
            heights: vec![0.0, 1.0, 2.0, 3.0],
        };
        // Sample centres at u = 0.25 and 0.75: the middle is the mean, the edges clamp.
        assert_eq!(g.sample(0.5, 0.5), 1.5);
        assert_eq!(g.sample(0.25, 0.25), 0.0);
        assert_eq!(g.sample(0.0, 1.0), 2.0);
        assert_eq!(g.sample(0.5, 0.25), 0.5);
    }

    #[test]
    fn a_steep_plane_lowers_its_base_by_the_bare_depth() {
        // A 1 m x 1 m surface of 25 x 25 texels on a 50-degree plane holds 0.4 of the depth: 0.6 of
        // 0.5 m is bare.
        let layout = SurfaceLayout::for_size(glam::Vec2::ONE);
        let t = 50f32.to_radians().tan();
        let g: Vec<f32> = (0..25 * 25).map(|i| (i % 25) as f32 * 0.04 * t).collect();
        let f = GroundField::build(
            layout,
            glam::Vec2::ONE,
            g.clone(),
            0.5,
            SlopeRule::default(),
        );
        for (i, c) in f.columns.iter().enumerate() {
            assert!((c[1] - 0.3).abs() < 1e-4, "{i}: {c:?}");
            assert!((c[0] - (g[i] - c[1])).abs() < 1e-6);
        }
    }

    /// A field of 5 cm texels on a ground grid of 50 cm samples (bilinear between them, so its
    /// slope jumps at every line of samples) over a bowl whose flank steepens past the rule's 35
    /// and 60 degrees: the snow each texel holds changes by under 1.5 cm from a texel to the next
    /// (measured between neighbouring texels, it stepped by 2.6 cm at the grid's lines), and a field
    /// of 10 cm texels over the same ground holds within 1 cm of it where they overlap.
    #[test]
    fn the_snow_held_on_a_flank_does_not_step_at_the_grounds_sample_lines() {
        // Sample i at x = 0.25 + 0.5 i: the bowl y = x^2 / 8, its slope x / 4 (67 degrees at the end).
        let grid = HeightGrid {
            columns: 20,
            rows: 2,
            heights: (0..40)
                .map(|i| (0.25 + 0.5 * (i % 20) as f32).powi(2) / 8.0)
                .collect(),
        };
        let field = |texels: u32| {
            let layout = SurfaceLayout {
                width: texels,
                height: 4,
            };
            let g = (0..4 * texels)
                .map(|i| grid.sample(((i % texels) as f32 + 0.5) / texels as f32, 0.5))
                .collect();
            GroundField::build(
                layout,
                glam::Vec2::new(10.0, 0.2),
                g,
                0.3,
                SlopeRule::default(),
            )
        };
        let (fine, coarse) = (field(200), field(100));
        let bare = |f: &GroundField, c: usize| f.columns[f.width as usize + c][1];
        let step = (20..180)
            .map(|c| (bare(&fine, c + 1) - bare(&fine, c)).abs())
            .fold(0.0, f32::max);
        assert!(
            step < 0.015,
            "the held snow steps by {step} m between texels"
        );
        assert!(
            bare(&fine, 40) == 0.0 && bare(&fine, 100) > 0.0 && bare(&fine, 190) > 0.29,
            "the bowl holds all, part and none of the snow along its flank"
        );
        for c in 10..90 {
            // Coarse texel c spans fine texels 2c and 2c + 1.
            let (a, b) = (
                bare(&coarse, c),
                0.5 * (bare(&fine, 2 * c) + bare(&fine, 2 * c + 1)),
            );
            assert!((a - b).abs() < 0.01, "texel {c}: {a} against {b}");
        }
    }

    /// Every move of a 9 x 7 field on rough, steep ground (partly bared, partly bare) by up to
    /// its size in each direction: the field scrolled in place is bit for bit the field built
    /// whole at the new origin, and a move as large as the field is refused.
    #[test]
    fn a_scrolled_field_is_the_field_built_at_its_new_origin() {
        let (w, h) = (9u32, 7u32);
        let layout = SurfaceLayout {
            width: w,
            height: h,
        };
        let size = glam::Vec2::new(0.9, 0.7);
        // Heights as a function of the world texel: hills, a hash-like roughness and a bowl that
        // steepens along x (so that slopes measured over the snow's 0.3 m either side hold all,
        // part or none of it), 0.1 m texels.
        let height = |x: i64, z: i64| {
            let (x, z) = (x as f32, z as f32);
            0.1 * (x * 0.7).sin()
                + 0.05 * (z * 1.3).cos()
                + 0.2 * ((x * 12.9898 + z * 78.233).sin() * 43758.5).fract()
                + 0.015 * x * x
        };
        let at = |o: [i64; 2]| {
            let g = (0..h as i64)
                .flat_map(|r| (0..w as i64).map(move |c| height(o[0] + c, o[1] + r)))
                .collect();
            GroundField::build(layout, size, g, 0.3, SlopeRule::default())
        };
        let whole = at([0, 0]);
        assert!(whole.columns.iter().any(|c| c[1] == 0.3), "nothing bare");
        assert!(
            whole.columns.iter().any(|c| c[1] > 0.0 && c[1] < 0.3),
            "nothing bared in part"
        );
        assert!(
            whole.columns.iter().any(|c| c[1] == 0.0),
            "nothing holds all its snow"
        );
        let (o0, o1) = (3i64, -5i64);
        let start = at([o0, o1]);
        for dz in -(h as i64)..=h as i64 {
            for dx in -(w as i64)..=w as i64 {
                let mut f = start.clone();
                let to = [o0 + dx, o1 + dz];
                let moved = f.scroll([dx, dz], size, 0.3, SlopeRule::default(), |c, r| {
                    height(to[0] + c as i64, to[1] + r as i64)
                });
                if dx.abs() >= w as i64 || dz.abs() >= h as i64 {
                    assert!(!moved, "({dx}, {dz}) is a jump");
                    assert_eq!(f, start, "a refused jump changed the field");
                    continue;
                }
                assert!(moved);
                let want = at(to);
                let bits = |f: &GroundField| {
                    let g: Vec<u32> = f.ground.iter().map(|v| v.to_bits()).collect();
                    let c: Vec<[u32; 2]> = f.columns.iter().map(|c| c.map(f32::to_bits)).collect();
                    (g, c)
                };
                assert_eq!(bits(&f), bits(&want), "moved by ({dx}, {dz})");
            }
        }
    }
}
