//! A picture of a run: pool bytes used against the budget, and surface updates and evictions per
//! frame, as a self-contained SVG (hand-written: no plotting dependency).

use std::fmt::Write as _;
use std::path::Path;

use snowprint::TickStats;
use snowprint::error::{Result, SnowError};

const WIDTH: f32 = 960.0;
const LEFT: f32 = 80.0;
const RIGHT: f32 = 20.0;
const POOL_TOP: f32 = 50.0;
const POOL_HEIGHT: f32 = 220.0;
const UPDATES_TOP: f32 = 330.0;
const UPDATES_HEIGHT: f32 = 150.0;
const HEIGHT: f32 = 530.0;

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
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
pub fn svg(frames: &[TickStats], title: &str, updates_per_frame: Option<usize>) -> String {
    let mut s = String::new();
    let plot_w = WIDTH - LEFT - RIGHT;
    let n = frames.len().max(1) as f32;
    let x_of = |i: usize| LEFT + plot_w * i as f32 / n;
    let budget = frames
        .iter()
        .map(|f| f.pool_bytes_budget)
        .max()
        .unwrap_or(0);
    let peak = frames.iter().map(|f| f.pool_bytes_used).max().unwrap_or(0);
    let y_max = (budget.max(peak).max(1) as f64 * 1.1) as f32;
    let pool_y = |b: u64| POOL_TOP + POOL_HEIGHT * (1.0 - b as f32 / y_max);
    let most_updates = frames.iter().map(|f| f.updated.len()).max().unwrap_or(0);
    let u_max = most_updates.max(updates_per_frame.unwrap_or(0)).max(1) as f32 * 1.15;
    let upd_y = |u: f32| UPDATES_TOP + UPDATES_HEIGHT * (1.0 - u / u_max);

    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="24" font-size="16" font-weight="bold">{}</text>"#,
        escape(title)
    );

    // Pool panel.
    let _ = writeln!(
        s,
        r##"<text x="{LEFT}" y="{}" fill="#333">heightmap pool: bytes in slots (blue) and budget (dashed); peak {} of {}</text>"##,
        POOL_TOP - 8.0,
        bytes_label(peak as f64),
        bytes_label(budget as f64)
    );
    let bottom = POOL_TOP + POOL_HEIGHT;
    let mut area = format!("M{LEFT:.1},{bottom:.1}");
    for (i, f) in frames.iter().enumerate() {
        let y = pool_y(f.pool_bytes_used);
        let _ = write!(area, " L{:.1},{y:.1} L{:.1},{y:.1}", x_of(i), x_of(i + 1));
    }
    let _ = write!(area, " L{:.1},{bottom:.1} Z", x_of(frames.len()));
    let _ = writeln!(
        s,
        r##"<path d="{area}" fill="#9ecae1" stroke="#3182bd" stroke-width="1"/>"##
    );
    let by = pool_y(budget);
    let _ = writeln!(
        s,
        r##"<line x1="{LEFT}" y1="{by:.1}" x2="{:.1}" y2="{by:.1}" stroke="#d62728" stroke-width="1.5" stroke-dasharray="6 4"/>"##,
        WIDTH - RIGHT
    );
    for k in 0..=4 {
        let b = y_max as f64 * k as f64 / 4.0;
        let y = pool_y(b as u64);
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{LEFT}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT - 4.0,
            LEFT - 6.0,
            y + 4.0,
            bytes_label(b)
        );
    }
    let _ = writeln!(
        s,
        r##"<rect x="{LEFT}" y="{POOL_TOP}" width="{plot_w}" height="{POOL_HEIGHT}" fill="none" stroke="#333"/>"##
    );

    // Updates panel.
    let label = match updates_per_frame {
        Some(k) => {
            format!("surfaces updated per frame (bars, budget {k} dashed); evictions (red, below)")
        }
        None => "surfaces updated per frame (bars); evictions (red, below)".to_owned(),
    };
    let _ = writeln!(
        s,
        r##"<text x="{LEFT}" y="{}" fill="#333">{label}</text>"##,
        UPDATES_TOP - 8.0
    );
    let base = UPDATES_TOP + UPDATES_HEIGHT;
    let mut bars = String::new();
    let mut evictions = String::new();
    for (i, f) in frames.iter().enumerate() {
        let (x0, x1) = (x_of(i), x_of(i + 1));
        if !f.updated.is_empty() {
            let y = upd_y(f.updated.len() as f32);
            let _ = write!(bars, "M{x0:.1},{base:.1} V{y:.1} H{x1:.1} V{base:.1} Z ");
        }
        if !f.evicted.is_empty() {
            let len = 4.0 + 3.0 * f.evicted.len().min(6) as f32;
            let _ = write!(
                evictions,
                "M{:.1},{:.1} v{len:.1} ",
                (x0 + x1) * 0.5,
                base + 2.0
            );
        }
    }
    let _ = writeln!(s, r##"<path d="{bars}" fill="#74c476" stroke="none"/>"##);
    let _ = writeln!(
        s,
        r##"<path d="{evictions}" stroke="#d62728" stroke-width="1.5"/>"##
    );
    if let Some(k) = updates_per_frame {
        let y = upd_y(k as f32);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#31a354" stroke-dasharray="6 4"/>"##,
            WIDTH - RIGHT
        );
    }
    for k in 0..=most_updates.max(updates_per_frame.unwrap_or(0)).min(1000) {
        let step = (most_updates.max(1) / 4).max(1);
        if k % step != 0 {
            continue;
        }
        let y = upd_y(k as f32);
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{LEFT}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}" text-anchor="end">{k}</text>"##,
            LEFT - 4.0,
            LEFT - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r##"<rect x="{LEFT}" y="{UPDATES_TOP}" width="{plot_w}" height="{UPDATES_HEIGHT}" fill="none" stroke="#333"/>"##
    );
    // Frame axis.
    let ticks = 8.min(frames.len().max(1));
    for k in 0..=ticks {
        let i = frames.len() * k / ticks;
        let x = x_of(i);
        let frame = frames
            .get(i)
            .map_or(frames.last().map_or(0, |f| f.frame + 1), |f| f.frame);
        let _ = writeln!(
            s,
            r##"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{frame}</text>"##,
            base + 34.0
        );
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" text-anchor="middle" fill="#333">frame</text>"##,
        LEFT + plot_w * 0.5,
        HEIGHT - 4.0
    );
    s.push_str("</svg>\n");
    s
}

/// Write [`svg`] to a file.
pub fn write_svg(
    path: &Path,
    frames: &[TickStats],
    title: &str,
    updates_per_frame: Option<usize>,
) -> Result<()> {
    std::fs::write(path, svg(frames, title, updates_per_frame)).map_err(|e| SnowError::Output {
        path: path.to_owned(),
        reason: e.to_string(),
    })
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
        let svg = svg(&frames, "a <city> & more", Some(2));
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("a &lt;city&gt; &amp; more"));
        // Frames 1, 2, 4, 5, 7, 8 updated something.
        assert_eq!(svg.matches(" Z ").count(), 6);
        assert!(svg.contains("2.00 MiB"));
        // Every element that opens closes.
        assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count());
    }

    #[test]
    fn empty_run_still_draws() {
        let s = svg(&[], "nothing", None);
        assert!(s.contains("</svg>"));
    }

    #[test]
    fn unwritable_path_is_an_error() {
        let e = write_svg(Path::new("/nonexistent-dir/x/plot.svg"), &[], "t", None).unwrap_err();
        assert!(matches!(e, SnowError::Output { .. }));
    }
}
