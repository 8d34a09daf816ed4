//! Progress of long runs: a bar when stderr is a terminal; otherwise (a CI log, a pipe, a file) a
//! plain line every few seconds with what is done, the rate and the time left.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Seconds between two progress lines when stderr is not a terminal.
const LINE_EVERY: Duration = Duration::from_secs(5);

/// Progress over a known number of steps (frames, configurations).
pub struct Progress {
    bar: Option<ProgressBar>,
    what: String,
    unit: &'static str,
    total: u64,
    done: u64,
    start: Instant,
    last_line: Instant,
    every: Duration,
}

impl Progress {
    /// Progress of `what` over `total` steps called `unit` (plural, such as "frames").
    pub fn new(total: u64, what: &str, unit: &'static str) -> Result<Self, String> {
        let terminal = std::io::stderr().is_terminal();
        let bar = if terminal {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} {what} {{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, about {{eta}} left"
                ))
                .map_err(|e| e.to_string())?
                .progress_chars("=> "),
            );
            Some(bar)
        } else {
            None
        };
        // SNOWPRINT_PROGRESS_SECONDS sets the interval of the lines (tests use 0: every step).
        let every = std::env::var("SNOWPRINT_PROGRESS_SECONDS")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .map_or(LINE_EVERY, Duration::from_secs_f64);
        let now = Instant::now();
        Ok(Self {
            bar,
            what: what.to_owned(),
            unit,
            total,
            done: 0,
            start: now,
            last_line: now,
            every,
        })
    }

    /// A word on what is happening now (shown by the bar only).
    pub fn set_message(&self, msg: &str) {
        if let Some(bar) = &self.bar {
            bar.set_message(msg.to_owned());
        }
    }

    /// `n` more steps done.
    pub fn inc(&mut self, n: u64) {
        self.done += n;
        if let Some(bar) = &self.bar {
            bar.inc(n);
            return;
        }
        let now = Instant::now();
        if now.duration_since(self.last_line) >= self.every && self.done < self.total {
            self.last_line = now;
            eprintln!("snowprint: {}", self.line());
        }
    }

    /// The line printed when stderr is not a terminal.
    fn line(&self) -> String {
        let secs = self.start.elapsed().as_secs_f64();
        let rate = if secs > 0.0 {
            self.done as f64 / secs
        } else {
            0.0
        };
        let left = if rate > 0.0 {
            format!(
                "about {:.0} s left",
                (self.total - self.done.min(self.total)) as f64 / rate
            )
        } else {
            "time left unknown".to_owned()
        };
        let unit = self.unit;
        format!(
            "{}: {}/{} {unit} ({:.0} %), {rate:.1} {unit}/s, {left}",
            self.what,
            self.done,
            self.total,
            100.0 * self.done as f64 / self.total.max(1) as f64,
        )
    }

    /// Remove the bar (lines need nothing).
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
