//! fabkit: parametric fabrication kits for vision-based tactile sensors.
//!
//! This crate is the `fabkit` command line and a facade over the library crates:
//! [`designs`] (geometry core, profiles, layer stacks, molds, housings, the YAML schema) and
//! [`export`] (STL, 3MF, manifest, fabrication sheet), [`fixtures`] (pin dome, semi-domes,
//! indenters) and [`calibration`] (camera models, PnP extrinsics).

/// Prints a line on stdout; a closed pipe (`fabkit ... | head`) is not an error.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

pub use fabkit_calibration as calibration;
pub use fabkit_designs as designs;
pub use fabkit_export as export;
pub use fabkit_fixtures as fixtures;
pub use fabkit_sweep as sweep;

pub mod args;
pub mod calibrate_cmd;
pub mod cli;
pub mod fixtures_cmd;
pub mod groundtruth_cmd;
pub mod photometric_cmd;
pub mod printers;
mod progress;
pub mod sweep_cmd;
