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
}

impl Progress {
    /// Starts the report of `what` (e.g. `building 105 parts`), `total` steps long.
    pub(crate) fn new(label: &str, what: &str, total: u64) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::new(total);
            if let Ok(style) =
                ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed})")
            {
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
            eprintln!("{}: {done}/{total}", self.label);
            *last = Some(Instant::now());
        }
    }

    /// A new stage of the same task (e.g. `writing 105 parts`).
    pub(crate) fn stage(&self, what: &str) {
        match &self.bar {
            Some(b) => b.set_message(format!("{}: {what}", self.label)),
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
