//! Design sweeps: many variants of one design, built and measured, with a results table.
//!
//! Researchers pick layer thicknesses, marker spacing and feature sizes by comparing variants
//! (Pestell et al. compare four pin layouts, Sec. III-D; ShadowTac iterated dimple size and
//! spacing, Sec. IV-A; R-Tac0 tuned its 1.5 mm translucent layer, Sec. III-B). A sweep file
//! names a base design and the values of some of its parameters:
//!
//! ```yaml
//! base: shadowtac                  # a library design, or a YAML path relative to this file
//! vary:
//!   layers[0].markers[0].pattern.spacing_mm: {range: [1.2, 2.0, 0.2]}
//!   layers[0].markers[0].feature.height_mm: [0.3, 0.4, 0.5, 0.6]
//! mode: grid                       # grid, zip, or random (with count and seed)
//! outputs: [metrics]               # or [metrics, files]: also the files of `fabkit export`
//! ```
//!
//! - [`SweepSpec`] parses and checks it: unknown paths (with the nearest valid ones) and
//!   values of the wrong type are errors at their `file:line:column` before anything runs.
//! - [`SweepSpec::plan`] expands it into [`Variant`]s with stable ids (a hash of the resolved
//!   design).
//! - [`run`] builds them in parallel into a sweep folder, one atomically written result per
//!   variant, resumable and shardable; [`merge`] joins the shards.
//!
//! A variant's files are written through a [`KitWriter`]: [`ExportWriter`] writes what
//! `fabkit export` writes. What one variant needs (parameter paths, values, metrics) is
//! `fabkit_designs::variant`, re-exported here.

mod effect;
mod file;
mod merge;
mod nearest;
mod plan;
mod results;
mod run;
mod variants;

pub use effect::{MAX_CONTEXT_VALUES, MAX_PROBED_VALUES, PROBE_CHORD_TOLERANCE_MM};
pub use fabkit_designs::variant::{
    canonical_json, expand_short_path, parameter_paths, path_exists,
};
pub use fabkit_designs::variant::{
    evaluate, evaluate_bounded, evaluate_scoped, min_wall, printability, CastMetrics,
    MarkerMetrics, Metrics, Outcome, PartMetrics, Verdict, PROFILES,
};
pub use file::{values_of, FileOutputs, Mode, Output, Parameter, SweepSpec};
pub use merge::{merge, MergeSummary};
pub use nearest::nearest_paths;
#[doc(hidden)]
pub use plan::{splice_pieces, takes_any_number};
pub use plan::{
    variant_count, variant_id, Plan, PlanProgress, Shard, Variant, ID_HEX_DIGITS, MAX_VARIANTS,
};
pub use results::{render_csv, render_jsonl, Status, VariantResult};
pub use run::{
    record, run, write_atomic, Event, ExportWriter, FilesJob, KitWriter, RunOptions, RunSummary,
    SweepRecord, FORMAT,
};
pub use variants::{
    checked_path, checked_value, evaluate_variant, plan_variants, resolve_variant, VariantList,
    WriteFiles,
};

use fabkit_designs::DesignError;

/// Why a sweep could not be read, run or merged. Problems of single variants are not errors:
/// they are results ([`Status`]).
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The sweep file breaks a rule; `at` is `file:line:column` (empty when the message
    /// carries it).
    #[error("{}{message}", prefix(at))]
    File { at: String, message: String },
    /// A `vary` key is not a parameter path of the base design.
    #[error(
        "{at}: vary: '{path}' is not a parameter path of design '{design}'{}",
        hint(nearest)
    )]
    UnknownPath {
        at: String,
        path: String,
        design: String,
        /// The nearest valid paths, best first.
        nearest: Vec<String>,
    },
    /// A value does not fit the parameter's type.
    #[error("{at}: vary.{path} = {value}: {message}")]
    WrongValue {
        at: String,
        path: String,
        value: String,
        message: String,
    },
    /// The base design (or its preset) does not load.
    #[error("{at}: base design: {error}")]
    Design { at: String, error: DesignError },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// The output folder holds something that is not a fabkit sweep.
    #[error(
        "sweep folder {path} is not a folder a fabkit sweep wrote: {}{why}; refusing to write \
         into it (hint: choose a new or empty folder)",
        if entry.is_empty() { String::new() } else { format!("`{entry}` ") }
    )]
    ForeignDirectory {
        path: String,
        entry: String,
        why: String,
    },
    /// The output folder holds another sweep's output.
    #[error(
        "sweep folder {path} holds the output of another sweep, {theirs}; this is {ours}: \
         refusing to mix them (hint: choose a new folder, or give --force to replace that \
         folder whole)"
    )]
    OtherSweep {
        path: String,
        theirs: String,
        ours: String,
    },
    /// More worker threads than the machine can use (or none).
    #[error(
        "jobs = {jobs}: must be from 1 to {max} (4 x the {cpus} CPUs of this machine; each job \
         builds one variant at a time)"
    )]
    Jobs {
        jobs: usize,
        max: usize,
        cpus: usize,
    },
    /// Shards that cannot be merged.
    #[error("merge: {0}")]
    Merge(String),
}

fn prefix(at: &str) -> String {
    if at.is_empty() {
        String::new()
    } else {
        format!("{at}: ")
    }
}

fn hint(nearest: &[String]) -> String {
    if nearest.is_empty() {
        String::new()
    } else {
        format!("; nearest: {}", nearest.join(", "))
    }
}
