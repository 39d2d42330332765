//! Where a command's time goes (`fabkit export --timings`): the wall time of each stage and
//! the process's CPU time over it (all threads, so CPU / wall is the number of cores the
//! stage kept busy). Off unless [`enable`]d: a [`stage`] guard then costs two clock reads.
//! Stages are recorded in the order they end; nested stages end before their parent.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

static ENABLED: AtomicBool = AtomicBool::new(false);
static RECORDS: Mutex<Vec<Record>> = Mutex::new(Vec::new());

/// One stage's times.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub stage: &'static str,
    /// Wall time, s.
    pub wall_s: f64,
    /// The process's CPU time (user + system, all threads) over the stage, s; NaN where the
    /// platform does not tell.
    pub cpu_s: f64,
}

/// Records every stage from now on.
pub fn enable() {
    ENABLED.store(true, Ordering::Relaxed);
}

/// A stage being timed: recorded when dropped.
#[must_use = "the stage is timed until the guard is dropped"]
pub struct Stage {
    name: &'static str,
    wall: Instant,
    cpu_s: f64,
}

/// Starts timing stage `name` if timings are enabled.
pub fn stage(name: &'static str) -> Option<Stage> {
    ENABLED.load(Ordering::Relaxed).then(|| Stage {
        name,
        wall: Instant::now(),
        cpu_s: cpu_seconds(),
    })
}

impl Drop for Stage {
    fn drop(&mut self) {
        let r = Record {
            stage: self.name,
            wall_s: self.wall.elapsed().as_secs_f64(),
            cpu_s: cpu_seconds() - self.cpu_s,
        };
        if let Ok(mut v) = RECORDS.lock() {
            v.push(r);
        }
    }
}

/// The stages recorded so far, in the order they ended; clears the list.
pub fn take() -> Vec<Record> {
    RECORDS
        .lock()
        .map(|mut v| std::mem::take(&mut *v))
        .unwrap_or_default()
}

/// The process's CPU time so far (user + system, all threads), s; NaN where unknown.
pub fn cpu_seconds() -> f64 {
    #[cfg(unix)]
    {
        let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
        // SAFETY: getrusage writes the struct it is given; RUSAGE_SELF is always valid.
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr()) } == 0 {
            // SAFETY: initialised by the successful call above.
            let u = unsafe { u.assume_init() };
            let t = |tv: libc::timeval| tv.tv_sec as f64 + tv.tv_usec as f64 * 1e-6;
            return t(u.ru_utime) + t(u.ru_stime);
        }
        f64::NAN
    }
    #[cfg(not(unix))]
    {
        f64::NAN
    }
}

/// The records as a table: stage, wall s, CPU s, cores (CPU / wall), and the total of the
/// whole command (`total_wall_s`, `total_cpu_s`).
pub fn table(records: &[Record], total_wall_s: f64, total_cpu_s: f64) -> String {
    let width = records
        .iter()
        .map(|r| r.stage.len())
        .chain([5])
        .max()
        .unwrap_or(5);
    let mut s = format!(
        "{:<width$}  {:>8}  {:>8}  {:>5}\n",
        "stage", "wall s", "CPU s", "cores"
    );
    let row = |name: &str, wall: f64, cpu: f64| {
        let cores = if wall > 0.0 { cpu / wall } else { f64::NAN };
        format!("{name:<width$}  {wall:>8.3}  {cpu:>8.3}  {cores:>5.2}\n")
    };
    for r in records {
        s.push_str(&row(r.stage, r.wall_s, r.cpu_s));
    }
    s.push_str(&row("whole command", total_wall_s, total_cpu_s));
    s
}
