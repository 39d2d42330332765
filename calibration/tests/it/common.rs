//! Helpers shared by the calibration tests.

/// The seed set of the seeded tests (`FABKIT_TEST_SEED_SET`, 0 unless set; `.ci/run` cycles
/// 0, 1 and 2): their seeds start at `1000 x set`, so a bound must hold on every set.
pub fn seed_set() -> u64 {
    let set = std::env::var("FABKIT_TEST_SEED_SET").ok();
    set.and_then(|s| s.parse().ok()).unwrap_or(0)
}

/// A grid's point table as `fabkit fixtures` writes a board's or a grid plate's (`file`): ids
/// 1.. row by row from -y, each row from -x (id = row x columns + column + 1), centred on the
/// axis at `pitch_mm`, every point at `z_mm`; each row's origin its CSV line.
pub fn grid_table(
    file: &str,
    rows: u32,
    columns: u32,
    pitch_mm: f64,
    z_mm: f64,
) -> fabkit_calibration::tables::PointTable {
    let mut table = Vec::new();
    for r in 0..rows {
        for c in 0..columns {
            let x = (f64::from(c) - f64::from(columns - 1) / 2.0) * pitch_mm;
            let y = (f64::from(r) - f64::from(rows - 1) / 2.0) * pitch_mm;
            let n = r * columns + c;
            table.push((
                (n + 1).to_string(),
                nalgebra::Vector3::new(x, y, z_mm),
                format!("{file}:{}", n + 2),
            ));
        }
    }
    fabkit_calibration::tables::PointTable {
        file: file.into(),
        rows: table,
    }
}
