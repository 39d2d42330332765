//! Progress of long work on stderr: a bar on a terminal, plain lines elsewhere (a log, a CI
//! job, a pipe), so that no long step is silent.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal as _;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Least time between two plain progress lines.
const LINE_INTERVAL: Duration = Duration::from_secs(1);

/// Reports `done / total` of one task, prefixed by `label` (`fixtures`, `groundtruth`).
pub(crate) struct Progress {
    label: String,
    bar: Option<ProgressBar>,
    /// When the last plain line was printed (None: none yet).
    last_line: Mutex<Option<Instant>>,
    /// When the current stage started (for the estimate of the time left).
    stage_start: Mutex<Instant>,
}

/// `done / total` steps in `elapsed`: the elapsed time and, from the mean step so far, about
/// how long the rest takes (`3.2 s, about 12 s left`).
fn timing(done: u64, total: u64, elapsed: Duration) -> String {
    let secs = elapsed.as_secs_f64();
    if done == 0 || done >= total {
        return format!("{secs:.1} s");
    }
    let left = secs / done as f64 * (total - done) as f64;
    format!("{secs:.1} s, about {} left", rounded(left))
}

/// A time left in words a reader takes at a glance: `5 s`, `40 s`, `3 min`.
fn rounded(secs: f64) -> String {
    if secs < 10.0 {
        format!("{} s", secs.ceil().max(1.0))
    } else if secs < 90.0 {
        format!("{} s", (secs / 5.0).ceil() * 5.0)
    } else {
        format!("{} min", (secs / 60.0).ceil())
    }
}

impl Progress {
    /// Starts the report of `what` (e.g. `building 105 parts`), `total` steps long.
    pub(crate) fn new(label: &str, what: &str, total: u64) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::new(total);
            if let Ok(style) = ProgressStyle::with_template(
                "{msg} [{bar:30}] {pos}/{len} ({elapsed}, about {eta} left)",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            b.set_message(format!("{label}: {what}"));
            b.enable_steady_tick(Duration::from_millis(200));
            b
        });
        if bar.is_none() {
            eprintln!("{label}: {what}");
        }
        Progress {
            label: label.to_string(),
            bar,
            last_line: Mutex::new(None),
            stage_start: Mutex::new(Instant::now()),
        }
    }

    /// `done` of `total` steps are finished (safe from several threads).
    pub(crate) fn set(&self, done: u64, total: u64) {
        if let Some(b) = &self.bar {
            b.set_length(total);
            b.set_position(done);
            return;
        }
        let mut last = self.last_line.lock().unwrap_or_else(|e| e.into_inner());
        let due = last.is_none_or(|t| t.elapsed() >= LINE_INTERVAL);
        if due || done == total {
            let start = *self.stage_start.lock().unwrap_or_else(|e| e.into_inner());
            eprintln!(
                "{}: {done}/{total} ({})",
                self.label,
                timing(done, total, start.elapsed())
            );
            *last = Some(Instant::now());
        }
    }

    /// A new stage of the same task (e.g. `writing 105 parts`).
    pub(crate) fn stage(&self, what: &str) {
        *self.stage_start.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
        match &self.bar {
            Some(b) => {
                b.reset_eta();
                b.set_message(format!("{}: {what}", self.label))
            }
            None => eprintln!("{}: {what}", self.label),
        }
    }

    /// Ends the report (the bar is cleared; plain lines stay).
    pub(crate) fn finish(self) {
        if let Some(b) = self.bar {
            b.finish_and_clear();
        }
    }
}
