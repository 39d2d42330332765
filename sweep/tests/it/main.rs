//! fabkit-sweep's tests, one binary: plan, run (resume, shards, merge, files) and the
//! nearest-path hints.

mod nearest;
mod plan;
mod run;
