//! Part families that any sensor design can use, one module per family (../shared/STYLE.md):
//! each with its parameters, its rules and its solids.

pub mod bayonet;
pub mod casing;
pub mod core_shell;
pub mod fingertip_base;
pub mod robot_mount;
pub mod shaft_body;

use crate::error::ParamError;
use crate::geometry::{cylinder, ChordTolerance, GeometryError, Solid};

/// "must be above 0" for each `(path, value)` that is not a positive finite number, the path
/// under `prefix` (`casing.` ...).
pub(crate) fn check_positive(prefix: &str, values: &[(&str, f64)], errs: &mut Vec<ParamError>) {
    for &(p, v) in values {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(
                format!("{prefix}{p}"),
                v,
                "must be above 0",
            ));
        }
    }
}

/// A cylinder of radius `r` about the vertical through `(x, y)`, from `z0` up to `z1`, mm.
pub(crate) fn z_cylinder(
    r: f64,
    z0: f64,
    z1: f64,
    [x, y]: [f64; 2],
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    cylinder(z1 - z0, r, tol).map(|s| s.translate([x, y, z0]))
}
