//! Part families that any sensor design can use, one module per family (../shared/STYLE.md):
//! each with its parameters, its rules and its solids.

pub mod bayonet;
pub mod casing;
pub mod channels;
pub mod context;
pub mod core_shell;
pub mod cut_part;
pub mod family;
pub mod fasteners;
pub mod fingertip_base;
pub mod flat;
pub mod housing;
pub mod lasercut;
pub mod layers;
mod member;
pub mod molds;
mod part;
pub mod placement;
pub mod recess;
pub mod registry;
pub mod robot_mount;
pub mod shaft_body;
pub mod spacer;

pub use context::{Context, ResolvedCore, ResolvedLayer, Stack};
pub use member::{
    axial_cylinder, axial_ring, ExactShape, FeatureKey, Member, MemberFeatures, MemberKind,
};
pub use part::{Part, PrintTechnology, ProcedureAction, ProcedureStep};

use crate::error::ParamError;
use crate::geometry::{cylinder, ChordTolerance, GeometryError, Solid};

/// The rule on lengths and sizes: "must be above 0" for each `(path, value)` that is not a
/// positive finite number, the path under `prefix` (`casing.`, `pin_dome.` ...); whether any
/// broke it.
pub fn check_positive(prefix: &str, values: &[(&str, f64)], errs: &mut Vec<ParamError>) -> bool {
    let before = errs.len();
    for &(p, v) in values {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(
                format!("{prefix}{p}"),
                v,
                "must be above 0",
            ));
        }
    }
    errs.len() > before
}

/// Smallest LED package fabkit counts around a ring, mm along the ring: the 0402 package
/// (1.0 x 0.5 mm), the smallest in common use.
pub const MIN_LED_PITCH_MM: f64 = 1.0;

/// The LED count of a ring PCB of `outer_diameter_mm` and `inner_diameter_mm` (positive,
/// checked): at least 1 and at most as many [`MIN_LED_PITCH_MM`] packages as fit around the
/// ring's mid-line.
pub(crate) fn check_led_count(
    path: &str,
    led_count: u32,
    outer_diameter_mm: f64,
    inner_diameter_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let mid_circumference_mm = std::f64::consts::PI * (outer_diameter_mm + inner_diameter_mm) / 2.0;
    let fit = (mid_circumference_mm / MIN_LED_PITCH_MM).floor().max(1.0);
    if led_count == 0 {
        errs.push(ParamError::new(path, 0, "must be 1 or more"));
    } else if f64::from(led_count) > fit {
        errs.push(ParamError::new(
            path,
            led_count,
            format!(
                "at most {fit:.0} LEDs fit around the ring ({mid_circumference_mm:.1} mm at mid-width, {MIN_LED_PITCH_MM} mm per LED, the 0402 package)"
            ),
        ));
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
