//! fabkit's end-to-end tests: the CLI binary run on real designs, its outputs read back by
//! independent consumers (tests/oracles/, printcheck). One test binary (one link), a module per
//! command or area; `common` holds the shared helpers.
//!
//! libtest starts the tests in the order of their names, two at a time here: the longest test
//! (the CAD twins' full tier, about four minutes) is in `cad_twins` so that it starts among the
//! first and the short tests fill the other thread, rather than starting last and running alone.

mod common;

mod assembly_step;
mod authors_cad;
mod byte_identical;
mod cad_twins;
mod calibrate_board;
mod calibrate_cli;
mod calibrate_images;
mod calibrate_opencv;
mod calibrate_photometric;
mod cli_errors;
mod default_readers;
mod docs;
mod export_flat;
mod export_markers;
mod export_rtac0;
mod extreme_values;
mod fixtures_cli;
mod groundtruth_cli;
mod groundtruth_flat;
mod groundtruth_images;
mod groundtruth_open3d;
mod groundtruth_press;
mod maker_path;
mod mass;
mod output_ownership;
mod plates;
mod report_html;
mod schema;
mod sim_export;
mod step_install;
mod sweep_cli;
mod tutorial;
