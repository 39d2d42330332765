//! The designs crate's integration tests, one binary (one link) with a module per area.

mod markers;
mod patterns;
mod properties;
mod shadowtac;
mod validation;
