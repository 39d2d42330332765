//! fabkit-designs: the geometry core, sensor body profiles, layer stacks, molds, housings and
//! the YAML design schema of fabkit.
//!
//! Frames and units are defined in `docs/conventions.md`: millimetres, degrees at public
//! boundaries, the sensor frame with z along the sensor axis through the pole.

// `!(x > 0.0)` is how the checks here reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

/// `impl Default` for a parameter struct from its fields' default values.
macro_rules! defaults {
    ($t:ident { $($f:ident : $v:expr),* $(,)? }) => {
        impl Default for $t {
            fn default() -> Self { Self { $($f: $v),* } }
        }
    };
}

pub mod assembly;
pub mod build;
pub mod cast_check;
pub mod cut;
pub mod error;
pub mod estimate;
pub mod geometry;
pub mod glyphs;
pub mod input_files;
pub mod insertion;
pub mod kit;
pub mod library;
pub mod markers;
pub mod materials;
pub mod optics;
pub mod parts;
pub mod plausible;
pub mod primitives;
pub mod procedure;
pub mod profile;
pub mod schema;
pub mod stack;
pub mod timings;
pub mod values;
pub mod variant;
pub mod yaml;

/// The layer stack's part families, at their older paths.
pub use parts::{flat, lasercut, layers, molds};

pub use build::{build_kit, build_kit_bounded, validate_design};
pub use error::{error_report, DesignError, ParamError, ParamErrors};
pub use geometry::{ChordTolerance, Mesh, Solid};
pub use kit::{Kit, Part, PrintTechnology};
pub use schema::Design;
