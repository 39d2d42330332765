//! The designs crate's integration tests, one binary (one link) with a module per area.

mod assembly;
mod cast_markers;
mod common;
mod error_paths;
mod estimate;
mod flat_housing;
mod flat_skin;
mod geometry;
mod glyphs;
mod hostile_values;
mod insertion;
mod json_schema;
mod lasercut;
mod marker_layout;
mod markers;
mod materials;
mod mesh;
mod optics;
mod patterns;
mod primitives;
mod profile;
mod properties;
mod recess;
mod shadowtac;
mod shadowtac_casing;
mod spacer_family;

mod variant_metrics;
mod variant_paths;

mod tactip_body;
mod uvdtact_base;
mod uvdtact_shell;
mod validation;
