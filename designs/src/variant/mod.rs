//! What one variant of a design needs: its parameter paths (every settable number, flag and
//! name, by path; a short path expanded to the one it names), a value set at a path, and the
//! variant's metrics (parts, casts, markers, printability). Sweeps of many variants are the
//! `fabkit-sweep` crate's.

mod metrics;
mod paths;

pub use metrics::{
    evaluate, evaluate_bounded, evaluate_scoped, min_wall, printability, CastMetrics,
    MarkerMetrics, Metrics, Outcome, PartMetrics, Verdict, PROFILES,
};
pub use paths::{
    canonical_json, expand_short_path, parameter_paths, path_exists, path_keys, span_of, with_value,
};
