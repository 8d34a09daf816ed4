//! Folding a finer level's leaving strips into the next coarser level: each coarse texel takes,
//! channel by channel, the larger of what it holds and the deepest fine texel whose centre lies
//! in it (`strip_max` in `strip.wgsl`), so the far level keeps the broad shape of what the near
//! level pages out. `summary` is the CPU side; `tests/window.rs` checks the result against the
//! near level's texels taken before the scroll.

use super::strip::{Direction, StripParams};
use super::{Level, Terrain, plan};
use crate::error::Result;
use crate::world::SnowWorld;

impl Terrain {
    /// Fold finer levels' leaving strips into the next coarser level (where that level's window
    /// holds them): each coarse texel takes, channel by channel, the larger of what it holds and
    /// the deepest fine texel whose centre lies in it.
    pub(super) fn fold(
        &mut self,
        world: &mut SnowWorld,
        folds: &[(usize, plan::Strip, Vec<u32>)],
    ) -> Result<()> {
        let unit = world.pool_format().precision.unit_texels();
        let mut dispatches = Vec::new();
        let mut incoming = Vec::new();
        let mut first = 0u32;
        for (i, strip, pairs) in folds {
            let (fine, coarse) = (&self.levels[*i], &self.levels[*i + 1]);
            let Some((rect, data)) = summary(fine.desc.texel_size, coarse, strip, pairs, unit)
            else {
                continue;
            };
            let (heights, layout, wrap) = world.level_slot(coarse.surface)?;
            dispatches.push((
                Direction::Max,
                StripParams {
                    heights,
                    width: layout.width,
                    height: layout.height,
                    wrap,
                    x0: rect.x0,
                    y0: rect.y0,
                    columns: rect.columns,
                    rows: rect.rows,
                    first,
                    unit_bytes: self.strips.unit_bytes(),
                    _pad: [0; 2],
                },
            ));
            first += rect.texels() as u32;
            incoming.extend(data);
        }
        if dispatches.is_empty() {
            return Ok(());
        }
        self.submit_strips(world, &dispatches, &incoming, Vec::new(), true);
        Ok(())
    }
}

/// A fine level's leaving `strip` (`pairs`, texel side `fine`) summed up at the texels of the
/// `coarse` level: the logical rectangle of the coarse window it covers (columns widened to whole
/// units of `unit` texels) and, there, the largest of each channel over the fine texels whose
/// centres lie in each coarse texel (0 elsewhere). `None` when the coarse window holds none of it.
fn summary(
    fine: f32,
    coarse: &Level,
    strip: &plan::Strip,
    pairs: &[u32],
    unit: u32,
) -> Option<(plan::Strip, Vec<u32>)> {
    let ratio = fine as f64 / coarse.desc.texel_size as f64;
    let to_coarse = |i: i64| ((i as f64 + 0.5) * ratio).floor() as i64;
    let [w, h] = coarse.desc.texels.map(|v| v as i64);
    let (ox, oz) = (coarse.origin[0], coarse.origin[1]);
    let clamp = |v: i64, n: i64| v.clamp(0, n);
    let x0 = clamp(to_coarse(strip.world[0]) - ox, w);
    let x1 = clamp(
        to_coarse(strip.world[0] + strip.columns as i64 - 1) - ox + 1,
        w,
    );
    let y0 = clamp(to_coarse(strip.world[1]) - oz, h);
    let y1 = clamp(
        to_coarse(strip.world[1] + strip.rows as i64 - 1) - oz + 1,
        h,
    );
    let u = unit as i64;
    let (x0, x1) = (x0 / u * u, (x1 + u - 1) / u * u);
    if x1 <= x0 || y1 <= y0 {
        return None;
    }
    let columns = (x1 - x0) as usize;
    let mut data = vec![0u32; 2 * columns * (y1 - y0) as usize];
    for r in 0..strip.rows as i64 {
        let y = to_coarse(strip.world[1] + r) - oz;
        for c in 0..strip.columns as i64 {
            let x = to_coarse(strip.world[0] + c) - ox;
            if x < x0 || x >= x1 || y < y0 || y >= y1 {
                continue;
            }
            let src = 2 * (r * strip.columns as i64 + c) as usize;
            let dst = 2 * ((y - y0) as usize * columns + (x - x0) as usize);
            data[dst] = data[dst].max(pairs[src]);
            data[dst + 1] = data[dst + 1].max(pairs[src + 1]);
        }
    }
    let rect = plan::Strip {
        x0: x0 as u32,
        y0: y0 as u32,
        columns: columns as u32,
        rows: (y1 - y0) as u32,
        world: [ox + x0, oz + y0],
    };
    Some((rect, data))
}
