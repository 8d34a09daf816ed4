//! Pictures of runs as self-contained SVG, drawn with `plotters` (its SVG backend only): the
//! surface manager's run (pool bytes used against the budget, surface updates and evictions per
//! frame, [`svg`]) and the command's benchmark sweeps (log-log lines, [`log_log_svg`]).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use snowprint::TickStats;
use snowprint::{Result, SnowError};

const WIDTH: u32 = 960;
const HEIGHT: u32 = 530;
/// Height of the pool panel (the title above it, the updates panel below).
const POOL_PANEL: u32 = 270;

const POOL_FILL: RGBColor = RGBColor(0x9e, 0xca, 0xe1);
const POOL_LINE: RGBColor = RGBColor(0x31, 0x82, 0xbd);
const BUDGET: RGBColor = RGBColor(0xd6, 0x27, 0x28);
/// The colour of an update bar: one bar a frame that updated something.
pub const UPDATE_BAR: RGBColor = RGBColor(0x74, 0xc4, 0x76);
const UPDATE_BUDGET: RGBColor = RGBColor(0x31, 0xa3, 0x54);

/// A drawing error as a sentence (drawing into a string fails only on a bug of the plot).
fn drawing<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    format!("cannot draw the plot: {e}")
}

fn bytes_label(b: f64) -> String {
    if b >= (1u64 << 20) as f64 {
        format!("{:.2} MiB", b / (1u64 << 20) as f64)
    } else {
        format!("{:.0} KiB", b / 1024.0)
    }
}

/// The SVG of a run, one [`TickStats`] per frame, under a title.
///
/// Top: pool bytes in slots (filled) and the budget (dashed). Bottom: surfaces updated per frame
/// (bars, with the budget's level when it is finite) and surfaces evicted (red ticks below the
/// axis).
pub fn svg(
    frames: &[TickStats],
    title: &str,
    updates_per_frame: Option<usize>,
) -> std::result::Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let body = root
            .titled(title, ("sans-serif", 16).into_font().style(FontStyle::Bold))
            .map_err(drawing)?;
        let (pool, updates) = body.split_vertically(POOL_PANEL - 30);
        pool_panel(&pool, frames)?;
        updates_panel(&updates, frames, updates_per_frame)?;
        root.present().map_err(drawing)?;
    }
    Ok(out)
}

/// The frame number at the left edge of bucket `i` of `frames` (one past the last at the end).
fn frame_at(frames: &[TickStats], i: usize) -> u64 {
    frames
        .get(i)
        .map_or(frames.last().map_or(0, |f| f.frame + 1), |f| f.frame)
}

fn pool_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    frames: &[TickStats],
) -> std::result::Result<(), String> {
    let n = frames.len().max(1) as f64;
    let budget = frames
        .iter()
        .map(|f| f.pool_bytes_budget)
        .max()
        .unwrap_or(0);
    let peak = frames.iter().map(|f| f.pool_bytes_used).max().unwrap_or(0);
    let y_max = budget.max(peak).max(1) as f64 * 1.1;
    let caption = format!(
        "heightmap pool: bytes in slots (blue) and budget (dashed); peak {} of {}",
        bytes_label(peak as f64),
        bytes_label(budget as f64)
    );
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 12))
        .margin_right(20)
        .y_label_area_size(80)
        .x_label_area_size(10)
        .build_cartesian_2d(0.0..n, 0.0..y_max)
        .map_err(drawing)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(5)
        .y_label_formatter(&|b| bytes_label(*b))
        .draw()
        .map_err(drawing)?;
    // The bytes in slots as steps, one a frame (a bucket of frames in a long run).
    let mut area_points = vec![(0.0, 0.0)];
    for (i, f) in frames.iter().enumerate() {
        let y = f.pool_bytes_used as f64;
        area_points.push((i as f64, y));
        area_points.push((i as f64 + 1.0, y));
    }
    area_points.push((frames.len() as f64, 0.0));
    chart
        .draw_series(std::iter::once(Polygon::new(
            area_points.clone(),
            POOL_FILL.filled(),
        )))
        .map_err(drawing)?;
    chart
        .draw_series(std::iter::once(PathElement::new(area_points, POOL_LINE)))
        .map_err(drawing)?;
    let b = budget as f64;
    chart
        .draw_series(DashedLineSeries::new(
            [(0.0, b), (n, b)],
            6,
            4,
            BUDGET.stroke_width(2),
        ))
        .map_err(drawing)?;
    Ok(())
}

fn updates_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    frames: &[TickStats],
    updates_per_frame: Option<usize>,
) -> std::result::Result<(), String> {
    let n = frames.len().max(1) as f64;
    let most = frames.iter().map(|f| f.updated.len()).max().unwrap_or(0);
    let u_max = most.max(updates_per_frame.unwrap_or(0)).max(1) as f64 * 1.15;
    // Evictions are drawn below the axis, in the bottom 15 % of the panel.
    let below = u_max * 0.2;
    let caption = match updates_per_frame {
        Some(k) => {
            format!("surfaces updated per frame (bars, budget {k} dashed); evictions (red, below)")
        }
        None => "surfaces updated per frame (bars); evictions (red, below)".to_owned(),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 12))
        .margin_right(20)
        .y_label_area_size(80)
        .x_label_area_size(40)
        .build_cartesian_2d(0.0..n, -below..u_max)
        .map_err(drawing)?;
    let step = (most.max(1) / 4).max(1);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(9)
        .x_label_formatter(&|x| frame_at(frames, x.round().max(0.0) as usize).to_string())
        .x_desc("frame")
        .y_labels(5)
        .y_label_formatter(&|u| {
            let k = u.round();
            if k >= 0.0 && (k - u).abs() < 1e-6 && (k as usize).is_multiple_of(step) {
                format!("{k}")
            } else {
                String::new()
            }
        })
        .draw()
        .map_err(drawing)?;
    chart
        .draw_series(
            frames
                .iter()
                .enumerate()
                .filter(|(_, f)| !f.updated.is_empty())
                .map(|(i, f)| {
                    Rectangle::new(
                        [(i as f64, 0.0), (i as f64 + 1.0, f.updated.len() as f64)],
                        UPDATE_BAR.filled(),
                    )
                }),
        )
        .map_err(drawing)?;
    chart
        .draw_series(
            frames
                .iter()
                .enumerate()
                .filter(|(_, f)| !f.evicted.is_empty())
                .map(|(i, f)| {
                    let x = i as f64 + 0.5;
                    let len = below * (0.3 + 0.1 * f.evicted.len().min(6) as f64);
                    PathElement::new(vec![(x, 0.0), (x, -len)], BUDGET.stroke_width(2))
                }),
        )
        .map_err(drawing)?;
    if let Some(k) = updates_per_frame {
        let y = k as f64;
        chart
            .draw_series(DashedLineSeries::new(
                [(0.0, y), (n, y)],
                6,
                4,
                UPDATE_BUDGET.stroke_width(1),
            ))
            .map_err(drawing)?;
    }
    Ok(())
}

/// Write [`svg`] to a file.
pub fn write_svg(
    path: &Path,
    frames: &[TickStats],
    title: &str,
    updates_per_frame: Option<usize>,
) -> Result<()> {
    let output = |reason: String| SnowError::Output {
        path: path.to_owned(),
        reason,
    };
    let svg = svg(frames, title, updates_per_frame).map_err(output)?;
    std::fs::write(path, svg).map_err(|e| output(e.to_string()))
}

/// A log-log line plot as SVG: each series a line with its points marked, named in a legend;
/// points at or below zero on either axis are left out.
pub fn log_log_svg(
    title: &str,
    x_label: &str,
    series: &[(&str, Vec<(f64, f64)>)],
) -> std::result::Result<String, String> {
    let positive = |p: &&(f64, f64)| p.0 > 0.0 && p.1 > 0.0;
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.1.iter().filter(positive).copied())
        .collect();
    // Whole decades around the points (one decade when there are none).
    let decades = |v: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = v.fold((f64::MAX, f64::MIN), |(lo, hi), x| {
            (lo.min(x.log10()), hi.max(x.log10()))
        });
        let lo = if lo.is_finite() && lo < f64::MAX {
            lo.floor()
        } else {
            0.0
        };
        let hi = hi.ceil().max(lo + 1.0);
        10f64.powf(lo)..10f64.powf(hi)
    };
    let xs = decades(&mut all.iter().map(|p| p.0));
    let ys = decades(&mut all.iter().map(|p| p.1));
    let colors = [
        RGBColor(0x1f, 0x77, 0xb4),
        RGBColor(0xd6, 0x27, 0x28),
        RGBColor(0x2c, 0xa0, 0x2c),
    ];
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (640, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 14))
            .margin(10)
            .margin_right(30)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.log_scale(), ys.log_scale())
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .x_label_formatter(&|v| format!("{v}"))
            .y_label_formatter(&|v| format!("{v} us"))
            .draw()
            .map_err(drawing)?;
        for (i, (name, pts)) in series.iter().enumerate() {
            let c = colors[i % colors.len()];
            let pts: Vec<(f64, f64)> = pts.iter().filter(positive).copied().collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                .map_err(drawing)?
                .label(*name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(drawing)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(drawing)?;
        root.present().map_err(drawing)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_has_one_bar_per_frame_with_updates_and_is_well_formed() {
        let frames: Vec<TickStats> = (0..10)
            .map(|i| TickStats {
                frame: i,
                updated: (0..(i % 3)).map(|k| format!("s{k}")).collect(),
                evicted: if i == 4 { vec!["old".into()] } else { vec![] },
                pool_bytes_used: i * 1000,
                pool_bytes_budget: 2 << 20,
                ..Default::default()
            })
            .collect();
        let svg = svg(&frames, "a <city> & more", Some(2)).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("a &lt;city&gt; &amp; more"));
        // Frames 1, 2, 4, 5, 7, 8 updated something: one bar each, in the bars' colour.
        let bar = format!(
            "fill=\"#{:02X}{:02X}{:02X}\"",
            UPDATE_BAR.0, UPDATE_BAR.1, UPDATE_BAR.2
        );
        assert_eq!(svg.matches(&bar).count(), 6, "{svg}");
        assert!(svg.contains("2.00 MiB"));
        // Every element that opens closes.
        assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count());
    }

    #[test]
    fn empty_run_still_draws() {
        let s = svg(&[], "nothing", None).unwrap();
        assert!(s.contains("</svg>"));
    }

    #[test]
    fn unwritable_path_is_an_error() {
        let e = write_svg(Path::new("/nonexistent-dir/x/plot.svg"), &[], "t", None).unwrap_err();
        assert!(matches!(e, SnowError::Output { .. }));
    }
}
