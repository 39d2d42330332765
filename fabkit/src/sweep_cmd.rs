//! `fabkit sweep` and `fabkit sweep merge`: argument parsing, progress and dispatch over
//! `fabkit_sweep` (which writes variant files with the export crate's writer).

use fabkit_sweep::{self as sweep, Event, ExportWriter, RunOptions, Shard, Status, SweepSpec};
use std::error::Error;
use std::io::IsTerminal as _;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

#[derive(clap::Args, Debug)]
#[command(
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    after_help = "Sweep file (YAML):\n  base: shadowtac                 # library design, or a YAML path relative to the sweep file\n  preset: paper_text              # optional\n  chord_tolerance_mm: 0.01        # optional\n  vary:\n    layers[0].markers[0].pattern.spacing_mm: {range: [1.2, 2.0, 0.2]}\n    layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.5, 0.6]\n  mode: grid                      # grid | zip | random (with count: N, seed: S)\n  outputs: [metrics]              # or [metrics, files] (also stl or 3mf alone)"
)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    /// The sweep file.
    #[arg(value_name = "SWEEP.yaml", required = true)]
    sweep: Option<PathBuf>,
    /// The sweep folder: results.csv, results.jsonl, sweep.json, variants/. Re-running into it
    /// skips the variants whose results are complete.
    #[arg(long, value_name = "DIR", required = true)]
    out: Option<PathBuf>,
    /// Variants built at once (default: one per core).
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
    /// Run every N-th variant starting at I (0 <= I < N), e.g. --shard $SLURM_ARRAY_TASK_ID/8.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Leave build_time_s empty in results.csv / results.jsonl, so that the tables are the
    /// same bytes on any machine, thread count or sharding (variants/<id>.json keeps it).
    #[arg(long)]
    no_build_time: bool,
    /// Record a variant estimated (before building) at more triangles than this as an error
    /// (about 1 KB of memory each, per variant built at once; 1 to 100000000).
    #[arg(long, value_name = "N", default_value_t = fabkit_designs::estimate::DEFAULT_MAX_TRIANGLES,
          value_parser = fabkit_designs::estimate::parse_max_triangles, allow_negative_numbers = true)]
    max_triangles: u64,
    /// Replace an --out folder that holds another sweep's output (another sweep file, plan or
    /// shard) whole; without it such a folder is refused. A folder of your own is never
    /// replaced.
    #[arg(long)]
    force: bool,
    #[command(flatten)]
    data_files: crate::args::DataFileArgs,
}

#[derive(clap::Subcommand, Debug)]
enum SweepCommand {
    /// Join the results of the shards of one sweep (checks that none overlap or is missing).
    Merge {
        /// The shard folders (each the --out of one `fabkit sweep --shard I/N`).
        #[arg(value_name = "DIR", required = true, num_args = 1..)]
        dirs: Vec<PathBuf>,
        /// Folder for the merged results.csv, results.jsonl and sweep.json.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// As for `fabkit sweep`: leave build_time_s empty.
        #[arg(long)]
        no_build_time: bool,
        /// Replace an --out folder that holds another sweep's output whole; without it such a
        /// folder is refused.
        #[arg(long)]
        force: bool,
    },
}

pub fn run(args: SweepArgs) -> Result<(), Box<dyn Error>> {
    if let Some(SweepCommand::Merge {
        dirs,
        out,
        no_build_time,
        force,
    }) = args.command
    {
        let m = sweep::merge(
            &dirs,
            &out,
            !no_build_time,
            std::env::args().collect(),
            force,
        )?;
        out!(
            "merged {} shards, {} variants -> {}",
            m.shards,
            m.variants,
            m.results_csv.display()
        );
        return Ok(());
    }
    let (Some(file), Some(out)) = (args.sweep, args.out) else {
        return Err("give a sweep file and --out DIR".into());
    };
    let terminal = std::io::stderr().is_terminal();
    let spec = {
        // reading checks every value and builds a few probes (fabkit_sweep::
        // SweepSpec::refuse_ignored_parameters): a spinner on a terminal
        let _reading = Spinner::new(terminal, format!("reading {}", file.display()));
        SweepSpec::from_file_with(&file, &args.data_files.rules())?
    };
    let plan = {
        let planning = Planning::new(terminal);
        let plan = spec.plan_with_progress(&|done, total| planning.report(done, total))?;
        planning.finish(plan.variants.len());
        plan
    };
    let opts = RunOptions {
        out_dir: out.clone(),
        jobs: args.jobs,
        shard: args.shard,
        build_time: !args.no_build_time,
        command_line: std::env::args().collect(),
        fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
        max_triangles: args.max_triangles,
        force: args.force,
    };
    let writer = ExportWriter {
        command_line: opts.command_line.clone(),
    };
    let progress = Progress::new(std::io::stderr().is_terminal());
    let t0 = Instant::now();
    let summary = sweep::run(&spec, &plan, &opts, Some(&writer), &|e| progress.event(e))?;
    progress.finish();
    let shard = args
        .shard
        .map(|s| format!(" (shard {s}: {} of them)", summary.selected))
        .unwrap_or_default();
    out!(
        "sweep {}: {} variants{shard}: {} built, {} skipped (complete); {} ok, {} infeasible, {} errors -> {} ({:.1} s)",
        file.display(),
        summary.total,
        summary.ran.len(),
        summary.reused,
        summary.ok,
        summary.infeasible,
        summary.errors,
        summary.results_csv.display(),
        t0.elapsed().as_secs_f64()
    );
    if summary.errors > 0 {
        return Err(format!(
            "{} variant(s) failed to build or write (status error in {}); re-running retries them",
            summary.errors,
            summary.results_csv.display()
        )
        .into());
    }
    Ok(())
}

/// A spinner with a message on a terminal while something without counts runs; nothing
/// otherwise. Cleared when dropped.
struct Spinner(Option<indicatif::ProgressBar>);

impl Spinner {
    fn new(terminal: bool, message: String) -> Self {
        Self(terminal.then(|| {
            let b = indicatif::ProgressBar::new_spinner();
            b.set_style(
                indicatif::ProgressStyle::with_template("{spinner} sweep: {msg} ({elapsed})")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            );
            b.set_message(message);
            b.enable_steady_tick(std::time::Duration::from_millis(200));
            b
        }))
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

/// Progress of planning (ids of millions of variants take seconds): on a terminal a bar that
/// appears after half a second; otherwise a line every 5 s once planning has taken a second,
/// and a last line with the time taken if any was printed. Quick plans print nothing.
struct Planning {
    terminal: bool,
    t0: Instant,
    /// The bar (terminal), and when the last plain line was printed.
    state: Mutex<(Option<indicatif::ProgressBar>, Option<Instant>)>,
}

impl Planning {
    /// Seconds between two plain lines.
    const LINE_EVERY_S: f64 = 5.0;

    fn new(terminal: bool) -> Self {
        Self {
            terminal,
            t0: Instant::now(),
            state: Mutex::new((None, None)),
        }
    }

    /// `done` of `total` variants planned; called with counts that never decrease.
    fn report(&self, done: usize, total: usize) {
        let Ok(mut st) = self.state.lock() else {
            return;
        };
        let s = self.t0.elapsed().as_secs_f64();
        if self.terminal {
            if st.0.is_none() && s >= 0.5 && done < total {
                let b = indicatif::ProgressBar::new(total as u64);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{spinner} sweep: planning [{bar:30}] {pos}/{len} variants, ETA {eta}",
                    )
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                    .progress_chars("=> "),
                );
                b.enable_steady_tick(std::time::Duration::from_millis(200));
                st.0 = Some(b);
            }
            if let Some(b) = &st.0 {
                b.set_position(done as u64);
            }
        } else if s >= 1.0
            && done < total
            && st
                .1
                .is_none_or(|t| t.elapsed().as_secs_f64() >= Self::LINE_EVERY_S)
        {
            eprintln!("sweep: planning: {done} of {total} variants ({s:.0} s)");
            st.1 = Some(Instant::now());
        }
    }

    /// Planning is over: clears the bar, or closes the plain lines with the time taken.
    fn finish(&self, total: usize) {
        let Ok(st) = self.state.lock() else {
            return;
        };
        if let Some(b) = &st.0 {
            b.finish_and_clear();
        }
        if st.1.is_some() {
            eprintln!(
                "sweep: planned {total} variants in {:.1} s",
                self.t0.elapsed().as_secs_f64()
            );
        }
    }
}

/// A progress bar with rate and ETA on a terminal; one plain line per variant otherwise.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    state: Mutex<(usize, usize, Instant)>,
}

impl Progress {
    fn new(terminal: bool) -> Self {
        let bar = terminal.then(|| {
            let b = indicatif::ProgressBar::new(0);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} sweep [{bar:30}] {pos}/{len} variants, {rate}, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .with_key(
                    "rate",
                    |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{:.2} variants/s", s.per_sec());
                    },
                )
                .progress_chars("=> "),
            );
            b.enable_steady_tick(std::time::Duration::from_millis(200));
            b
        });
        Self {
            bar,
            state: Mutex::new((0, 0, Instant::now())),
        }
    }

    fn event(&self, e: Event<'_>) {
        let Ok(mut st) = self.state.lock() else {
            return;
        };
        match e {
            Event::Start {
                total,
                selected,
                complete,
            } => {
                *st = (0, selected - complete, Instant::now());
                let msg =
                    format!("{selected} of {total} variants selected, {complete} already complete");
                match &self.bar {
                    Some(b) => {
                        b.set_length((selected - complete) as u64);
                        if complete > 0 {
                            b.set_message(format!("({complete} already complete, skipped)"));
                        }
                    }
                    None => eprintln!("sweep: {msg}"),
                }
            }
            Event::Done(r) => {
                st.0 += 1;
                let (done, todo, t0) = *st;
                let status = match r.status {
                    Status::Ok => "ok".to_string(),
                    Status::Infeasible => format!(
                        "infeasible: {}",
                        r.errors.first().map(String::as_str).unwrap_or("")
                    ),
                    Status::Error => {
                        format!(
                            "error: {}",
                            r.errors.first().map(String::as_str).unwrap_or("")
                        )
                    }
                };
                match &self.bar {
                    Some(b) => {
                        if r.status != Status::Ok {
                            b.println(format!("variant {} ({}): {status}", r.index, r.id));
                        }
                        b.inc(1);
                    }
                    None => {
                        let s = t0.elapsed().as_secs_f64();
                        let rate = done as f64 / s.max(1e-9);
                        eprintln!(
                            "sweep: [{done}/{todo}] variant {} ({}) {status} in {:.2} s; {rate:.2} variants/s, ETA {:.0} s",
                            r.index,
                            r.id,
                            r.build_time_s.unwrap_or(0.0),
                            (todo - done) as f64 / rate.max(1e-9)
                        );
                    }
                }
            }
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
