//! The surface manager's per-frame statistics written as they come: a JSON array streamed to disk
//! frame by frame, and a plot drawn at the end from a summary of bounded size. A run of any length
//! keeps at most [`MAX_BUCKETS`] summaries in memory.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use snowprint::TickStats;
use snowprint_demo::plot;

/// Most summaries kept for the plot: up to this many frames each frame is drawn as it was; past
/// it, neighbours are merged two by two (peaks kept), so the plot never holds more points.
pub const MAX_BUCKETS: usize = 2048;

/// Most evictions kept per summary (the plot draws at most six ticks).
const MAX_EVICTED: usize = 6;

/// A bounded summary of a run for the plot: consecutive frames merged into buckets of equal width.
#[derive(Default)]
pub struct Summary {
    buckets: Vec<TickStats>,
    /// Frames in the last bucket.
    last_count: u64,
    /// Frames a full bucket holds.
    width: u64,
}

impl Summary {
    /// Add one frame.
    pub fn push(&mut self, s: &TickStats) {
        if self.width == 0 {
            self.width = 1;
            self.buckets.reserve_exact(MAX_BUCKETS + 1);
        }
        match self.buckets.last_mut() {
            Some(last) if self.last_count < self.width => {
                merge(last, s);
                self.last_count += 1;
            }
            _ => {
                let mut b = s.clone();
                b.evicted.truncate(MAX_EVICTED);
                self.buckets.push(b);
                self.last_count = 1;
            }
        }
        if self.buckets.len() > MAX_BUCKETS {
            // Merge neighbours in place: the vector keeps its capacity, so memory stays put.
            let n = self.buckets.len();
            let half = n.div_ceil(2);
            for i in 0..half {
                let mut b = std::mem::take(&mut self.buckets[2 * i]);
                if let Some(second) = self.buckets.get(2 * i + 1) {
                    merge(&mut b, second);
                }
                self.buckets[i] = b;
            }
            self.buckets.truncate(half);
            // The last bucket was possibly partial; after merging it holds its frames plus a full
            // bucket's, or only its own when it had no partner.
            self.last_count = if n.is_multiple_of(2) {
                self.width + self.last_count
            } else {
                self.last_count
            };
            self.width *= 2;
        }
    }

    /// The buckets, first frame first.
    pub fn buckets(&self) -> &[TickStats] {
        &self.buckets
    }
}

/// Fold frame `s` into bucket `b`: peaks of the levels, the longest update list, evictions added
/// up to [`MAX_EVICTED`].
fn merge(b: &mut TickStats, s: &TickStats) {
    if s.updated.len() > b.updated.len() {
        b.updated.clone_from(&s.updated);
    }
    for name in &s.evicted {
        if b.evicted.len() < MAX_EVICTED {
            b.evicted.push(name.clone());
        }
    }
    b.active = b.active.max(s.active);
    b.resident = b.resident.max(s.resident);
    b.pool_bytes_used = b.pool_bytes_used.max(s.pool_bytes_used);
    b.pool_bytes_budget = b.pool_bytes_budget.max(s.pool_bytes_budget);
    b.max_wait_frames = b.max_wait_frames.max(s.max_wait_frames);
    b.touched = b.touched.max(s.touched);
    b.due = b.due.max(s.due);
    b.waiting_for_memory = b.waiting_for_memory.max(s.waiting_for_memory);
    b.queued_imprints = b.queued_imprints.max(s.queued_imprints);
    b.imprints_merged = b.imprints_merged.max(s.imprints_merged);
    b.paged_out_bytes = b.paged_out_bytes.max(s.paged_out_bytes);
    b.paged_in_bytes = b.paged_in_bytes.max(s.paged_in_bytes);
    b.page_store_bytes = b.page_store_bytes.max(s.page_store_bytes);
    b.paged_surfaces = b.paged_surfaces.max(s.paged_surfaces);
}

/// A JSON array of [`TickStats`] written frame by frame, with its plot written on
/// [`StatsStream::finish`].
pub struct StatsStream {
    out: std::io::BufWriter<std::fs::File>,
    json: PathBuf,
    svg: PathBuf,
    frames: u64,
    summary: Summary,
}

impl StatsStream {
    /// Start the array in `json` (a staging path); the plot will go to `svg`.
    pub fn create(json: PathBuf, svg: PathBuf) -> Result<Self, String> {
        let file = std::fs::File::create(&json)
            .map_err(|e| format!("cannot write {}: {e}", json.display()))?;
        let mut out = std::io::BufWriter::new(file);
        out.write_all(b"[")
            .map_err(|e| format!("cannot write {}: {e}", json.display()))?;
        Ok(Self {
            out,
            json,
            svg,
            frames: 0,
            summary: Summary::default(),
        })
    }

    /// Append one frame.
    pub fn push(&mut self, s: &TickStats) -> Result<(), String> {
        let sep: &[u8] = if self.frames == 0 { b"\n" } else { b",\n" };
        let text = serde_json::to_string_pretty(s).map_err(|e| e.to_string())?;
        self.out
            .write_all(sep)
            .and_then(|()| self.out.write_all(text.as_bytes()))
            .map_err(|e| format!("cannot write {}: {e}", self.json.display()))?;
        self.frames += 1;
        self.summary.push(s);
        Ok(())
    }

    /// Close the array and write the plot under `title`.
    pub fn finish(mut self, title: &str, updates_per_frame: Option<usize>) -> Result<(), String> {
        self.out
            .write_all(b"\n]\n")
            .and_then(|()| self.out.flush())
            .map_err(|e| format!("cannot write {}: {e}", self.json.display()))?;
        plot::write_svg(&self.svg, self.summary.buckets(), title, updates_per_frame)
            .map_err(|e| e.to_string())
    }
}

/// The report's JSON file name and the plot's beside it (`report.json` and `report.svg`).
pub fn file_names(report: &Path) -> Result<(String, String), String> {
    let json = report
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| {
            format!(
                "--report {}: give a file path such as out/report.json",
                report.display()
            )
        })?;
    let svg = Path::new(&json)
        .with_extension("svg")
        .to_string_lossy()
        .into_owned();
    if svg == json {
        return Err(format!(
            "--report {}: the plot goes beside the report as .svg, so give the report another extension, such as .json",
            report.display()
        ));
    }
    Ok((json, svg))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(i: u64, updates: usize, pool: u64) -> TickStats {
        TickStats {
            frame: i,
            updated: (0..updates).map(|k| format!("s{k}")).collect(),
            pool_bytes_used: pool,
            pool_bytes_budget: 1000,
            ..Default::default()
        }
    }

    #[test]
    fn short_runs_keep_every_frame() {
        let mut s = Summary::default();
        for i in 0..100 {
            s.push(&frame(i, (i % 3) as usize, i));
        }
        assert_eq!(s.buckets().len(), 100);
        assert_eq!(s.buckets()[42].pool_bytes_used, 42);
        assert_eq!(s.buckets()[42].frame, 42);
    }

    #[test]
    fn long_runs_stay_bounded_and_keep_peaks_and_frame_numbers() {
        let mut s = Summary::default();
        let n = 100_000u64;
        for i in 0..n {
            // One spike of pool use and one frame with 5 updates.
            let pool = if i == 77_777 { 999 } else { 10 };
            let updates = if i == 12_345 { 5 } else { 1 };
            s.push(&frame(i, updates, pool));
        }
        let b = s.buckets();
        assert!(
            b.len() <= MAX_BUCKETS && b.len() > MAX_BUCKETS / 2,
            "{}",
            b.len()
        );
        assert_eq!(b.iter().map(|f| f.pool_bytes_used).max(), Some(999));
        assert_eq!(b.iter().map(|f| f.updated.len()).max(), Some(5));
        // Buckets are of equal width, in order, starting at frame 0.
        assert_eq!(b[0].frame, 0);
        let width = b[1].frame - b[0].frame;
        assert!(b.windows(2).all(|w| w[1].frame - w[0].frame == width));
        // Every frame is in exactly one bucket: the last bucket starts within a width of the end.
        let last = b[b.len() - 1].frame;
        assert!(last < n && n - last <= width, "last {last}, width {width}");
    }
}
