//! Times the ShadowTac one-piece open mold (`designs/library/shadowtac.yaml`, preset
//! `open_mold`, layer 0) at
//! 0.005 mm chord tolerance for one feature count, and writes the mold's CSG tree.
//!
//! Usage: `cargo run --release -p fabkit-designs --example bench_markers -- CASE [RUNS] [CSG]`
//! - CASE: `published_469` (the authors' layout: concentric_6k, 12 rings 3.9474 deg apart) or a feature
//!   count N (the scaling variant of [`scaled_design`]: N features on a golden spiral).
//! - RUNS (default 3): timed runs; each is `stack::validate` + `build::build_layer`, the mold
//!   only (nothing written). The YAML is parsed once, before the clock starts.
//! - CSG: writes the mold part's CSG tree (fabkit-csg/1) from the last run to this file, for
//!   `tests/oracles/replay_csg.py`.
//!
//! Prints one JSON object on stdout: the case, features placed, feature diameter, the SLA
//! profile used, per-run seconds of validate and build_layer, their bests, and the mold's
//! triangle count and volume. `scripts/bench-markers` runs it for 469, 1000, 5000, 10000.
//! The criterion bench `tests/benches/markers.rs` builds the same designs (same rule).
use fabkit_designs::markers::{Layout, Surface};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{geometry, library, stack, ChordTolerance, Design};
use serde_json::json;
use std::time::Instant;

const CHORD_TOLERANCE_MM: f64 = 0.005;
/// SLA profile for the scaling cases whose features are below the default 0.4 mm minimum hole.
const DENSE_SLA_MIN_HOLE_DIAMETER_MM: f64 = 0.15;
const DENSE_SLA_MIN_WALL_MM: f64 = 0.1;

/// The ShadowTac design with `n` features on an equal-area golden spiral over the skin's outer
/// surface, for scaling runs. With s = sqrt(A / (n sqrt(3) / 2)) the hexagonal pitch of n
/// features on the patterned area A (pole to the rim less the 0.85 mm rim margin of the 0.45 mm
/// feature, about 1100 mm^2) and 0.78 s a safe lower bound on the spiral's nearest-neighbour
/// distance (0.80-0.82 s measured), the feature diameter is min(0.45, 0.78 s - 0.4) so that the
/// default SLA minimum wall (0.4 mm) is left between features. When that is below the SLA
/// minimum hole (0.4 mm; from about 1200 features), the SLA profile is lowered to a 0.15 mm
/// minimum hole and a 0.1 mm minimum wall and the diameter is min(0.45, 0.5 s) (up to 13000
/// features): those molds validate but are not printable on the default profile. Diameters are
/// rounded down to 0.01 mm; the height stays 0.5 mm. Same rule as
/// `tests/benches/markers.rs`.
fn scaled_design(base: &Design, n: u32) -> Design {
    let mut d = base.clone();
    let surface = Surface::new(&d.body, 0.0);
    let area_mm2 = surface.area_to(surface.total_arc_mm() - (0.45 + 0.4));
    let pitch_mm = (area_mm2 / (n as f64 * 3f64.sqrt() / 2.0)).sqrt();
    let mut diameter_mm = (0.78 * pitch_mm - d.printers.sla.min_wall_mm).min(0.45);
    if diameter_mm < d.printers.sla.min_hole_diameter_mm {
        d.printers.sla.min_hole_diameter_mm = DENSE_SLA_MIN_HOLE_DIAMETER_MM;
        d.printers.sla.min_wall_mm = DENSE_SLA_MIN_WALL_MM;
        diameter_mm = (0.5 * pitch_mm).min(0.45);
    }
    let diameter_mm = (diameter_mm * 100.0).floor() / 100.0;
    let spec = &mut d.layers[0].markers[0];
    spec.feature.diameter_mm = diameter_mm;
    let p = &mut spec.pattern;
    p.layout = Layout::GoldenSpiral;
    p.count = Some(n);
    p.spacing_mm = None;
    p.rings = None;
    p.pitch_arc_mm = None;
    p.polar_step_deg = None;
    p.ring_azimuth_offset = None;
    d
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let case = args.first().ok_or(
        "usage: bench_markers CASE [RUNS] [CSG]  (CASE: published_469 or a feature count)",
    )?;
    let runs: usize = match args.get(1) {
        Some(r) => r.parse().map_err(|e| format!("RUNS = {r:?}: {e}"))?,
        None => 3,
    };
    let csg_path = args.get(2);
    let base = library::load("shadowtac")?.with_preset("open_mold")?;
    let design = if case == "published_469" {
        base.with_preset("published_469")?
    } else {
        let n: u32 = case
            .parse()
            .map_err(|e| format!("CASE = {case:?}: not published_469 nor a count: {e}"))?;
        scaled_design(&base, n)
    };
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM)?;
    let materials = MaterialsTable::embedded()?;
    let mut validate_s = Vec::new();
    let mut build_s = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let st = stack::validate(&design, &materials, tol)?;
        let t1 = Instant::now();
        let out = fabkit_designs::build::build_layer(&design, &st, 0, tol)?;
        let t2 = Instant::now();
        validate_s.push((t1 - t0).as_secs_f64());
        build_s.push((t2 - t1).as_secs_f64());
        last = Some(out);
    }
    let out = last.ok_or("no run")?;
    let part = out
        .parts
        .iter()
        .find(|p| p.role == "open_mold")
        .ok_or("build_layer made no open_mold part")?;
    if let Some(path) = csg_path {
        let doc = geometry::csg_json(&[(part.name.as_str(), &part.solid)]);
        std::fs::write(path, serde_json::to_vec(&doc)?)
            .map_err(|e| format!("writing {path}: {e}"))?;
    }
    let m = out.markers.first().ok_or("no marker pattern")?;
    let best = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    let total: Vec<f64> = validate_s
        .iter()
        .zip(&build_s)
        .map(|(a, b)| a + b)
        .collect();
    let spec = &design.layers[0].markers[0];
    println!(
        "{}",
        json!({
            "case": case,
            "chord_tolerance_mm": CHORD_TOLERANCE_MM,
            "layout": spec.pattern.layout,
            "features": m["count"],
            "feature_diameter_mm": spec.feature.diameter_mm,
            "feature_height_mm": spec.feature.height_mm,
            "min_spacing_mm": m["min_spacing_mm"],
            "sla_min_hole_diameter_mm": design.printers.sla.min_hole_diameter_mm,
            "sla_min_wall_mm": design.printers.sla.min_wall_mm,
            "part": part.name,
            "triangles": part.solid.triangle_count(),
            "volume_mm3": part.solid.volume(),
            "validate_s": validate_s,
            "build_layer_s": build_s,
            "validate_s_best": best(&validate_s),
            "build_layer_s_best": best(&build_s),
            "total_s_best": best(&total),
        })
    );
    Ok(())
}
