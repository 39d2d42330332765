//! The export crate's integration tests, one binary (one link) with a module per area.

mod export_kit;
mod library_sheets;
mod mass;
mod raster;
