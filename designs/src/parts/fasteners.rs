//! Fasteners the parts are held together with: the ISO metric sizes and standard lengths the
//! bought-items list and the procedure name, the screw a clearance or pilot hole is for, and
//! the bolt that clamps a mold with a nut. Shared by every family that drills for a screw.

/// ISO 4032 hexagon nut height, as a fraction of the nominal diameter.
pub const NUT_HEIGHT_PER_D: f64 = 0.8;

/// Thread left beyond the nut, mm.
pub const BOLT_PROTRUSION_MM: f64 = 1.0;

/// ISO metric screw sizes (nominal diameter, mm) the bought-items list names.
pub const METRIC_SIZES_MM: [f64; 9] = [1.6, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0];

/// Standard screw lengths, mm (ISO 4762 / ISO 7045 preferred lengths up to 100 mm).
pub const SCREW_LENGTHS_MM: [f64; 23] = [
    3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0,
    55.0, 60.0, 65.0, 70.0, 80.0, 90.0, 100.0,
];

/// The metric screw a through hole of `clearance_mm` is for: the largest size below it with at
/// most 0.7 mm of clearance (ISO 273 fine to coarse: M2 2.2-2.6, M3 3.2-3.6 mm).
pub fn metric_from_clearance(clearance_mm: f64) -> Option<f64> {
    METRIC_SIZES_MM
        .iter()
        .copied()
        .rev()
        .find(|d| *d < clearance_mm && clearance_mm - d <= 0.7 + 1e-9)
}

/// The self-tapping screw a pilot hole of `pilot_mm` is for: the size whose 0.75-0.85 x
/// diameter the pilot is (a 1.6 mm pilot takes an M2 / 2.0 mm screw).
pub fn metric_from_pilot(pilot_mm: f64) -> Option<f64> {
    METRIC_SIZES_MM
        .iter()
        .copied()
        .find(|d| (0.75 * d - 1e-9..=0.85 * d + 1e-9).contains(&pilot_mm))
}

/// `M2`, `M2.5`.
pub fn metric_name(d: f64) -> String {
    format!("M{d}")
}

/// `M2 x 6`: the screw for a `clearance_mm` hole, in the longest standard length that is at
/// most `max_length_mm`; `None` when no standard size or length fits.
pub fn screw_name(clearance_mm: f64, max_length_mm: f64) -> Option<String> {
    let d = metric_from_clearance(clearance_mm)?;
    let l = SCREW_LENGTHS_MM
        .iter()
        .copied()
        .rev()
        .find(|l| *l <= max_length_mm + 1e-9)?;
    Some(format!("{} x {l}", metric_name(d)))
}

/// The bolt for a through hole of `clearance_mm` clamping `grip_mm` with a nut: the shortest
/// standard length ([`SCREW_LENGTHS_MM`]) that passes the grip and the nut
/// (0.8 d, ISO 4032) by [`BOLT_PROTRUSION_MM`]; `None` when no standard size or length fits.
pub fn bolt_name(clearance_mm: f64, grip_mm: f64) -> Option<String> {
    let d = metric_from_clearance(clearance_mm)?;
    let need = grip_mm + NUT_HEIGHT_PER_D * d + BOLT_PROTRUSION_MM;
    let l = SCREW_LENGTHS_MM
        .iter()
        .copied()
        .find(|l| *l >= need - 1e-9)?;
    Some(format!("M{d} x {l}"))
}
