//! Benchmarks of the ShadowTac one-piece open mold (`designs/library/shadowtac.yaml` with the
//! preset `open_mold`, layer 0) at 0.005 mm chord tolerance: the marker features (cylinder +
//! hemisphere; pins standing into the cavity for the skin's dimples) join the mold with one
//! `Solid::compose` of the features and one boolean.
//!
//! Every iteration is `stack::validate` + `fabkit_designs::build::build_layer(.., 0, ..)`: the mold alone, every
//! boolean evaluated (the kernel evaluates each boolean when the solid is made), nothing written.
//! The YAML is parsed, and the design mutated, once outside the timed loop.
//!
//! Groups (ids `<group>/<id>`):
//! - `markers/shadowtac_469_mold`: the authors' layout: 469 features of 0.45 mm diameter,
//!   0.5 mm high, concentric_6k, 12 rings 3.9474 deg apart on the R22.5 cap.
//! - `markers_scaling/<N>` for N = 1000, 5000, 10000: N features on an equal-area golden spiral
//!   ([`scaled_design`]); throughput in features (elements) per second. The feature diameter
//!   shrinks with N so that features keep a wall between them: 0.45 mm at 1000, 0.24 mm at 5000,
//!   0.17 mm at 10000. The two dense cases are below the default SLA minimum hole (0.4 mm), so
//!   their SLA profile is lowered (0.15 mm minimum hole, 0.1 mm minimum wall): they validate but
//!   are not printable on the default profile. Smaller features have fewer facets at the same
//!   chord tolerance, so the mold's triangle count grows slower than N (173k, 356k, 842k and
//!   1.66M triangles for 469, 1000, 5000 and 10000 features).
//!
//! Run: `cargo bench -p fabkit-benches --bench markers`: about 4 minutes on 2 idle cores after the build
//! (measured 3 min 50 s at load average 0.4-1.1). An iteration takes 0.8 to 11 s, so sampling is
//! flat with criterion's minimum: 10 samples of one iteration each after one warm-up iteration,
//! 11 iterations per case; the 11 at 10000 features alone take about 2 minutes, so the whole bench
//! cannot fit in 2. `cargo bench -p fabkit-benches --bench markers -- shadowtac_469` runs the published
//! mold alone in about 10 s. The numbers are per iteration.
//! Feature counts actually placed are printed to stderr before each group.
//! `scripts/bench-markers` times the same molds as a table against manifold3d replaying their
//! booleans.

use criterion::{
    criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput,
};
use fabkit::designs::markers::{Layout, Surface};
use fabkit::designs::materials::MaterialsTable;
use fabkit::designs::{layers, library, stack, ChordTolerance, Design};
use std::hint::black_box;
use std::time::Duration;

const CHORD_TOLERANCE_MM: f64 = 0.005;
/// SLA profile for the scaling cases whose features are below the default 0.4 mm minimum hole.
const DENSE_SLA_MIN_HOLE_DIAMETER_MM: f64 = 0.15;
const DENSE_SLA_MIN_WALL_MM: f64 = 0.1;
const SCALING_COUNTS: [u32; 3] = [1000, 5000, 10000];

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
/// `designs/examples/bench_markers.rs` (used by `scripts/bench-markers`).
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

/// What one iteration does: validation of the stack, then the mold of layer 0.
fn build_mold(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
) -> layers::LayerOutput {
    let st = stack::validate(design, materials, tol).expect("the benchmark design validates");
    fabkit_designs::build::build_layer(design, &st, 0, tol).expect("the benchmark mold builds")
}

/// Features placed on layer 0 (validated first; panics with every violation otherwise).
fn features_placed(design: &Design, materials: &MaterialsTable, tol: ChordTolerance) -> usize {
    let st = match stack::validate(design, materials, tol) {
        Ok(st) => st,
        Err(e) => panic!("the benchmark design does not validate: {e}"),
    };
    layers::place_layer_markers(&design.stack_input(), &st.layers[0], tol)
        .iter()
        .map(|p| p.markers.len())
        .sum()
}

/// Flat sampling, criterion's minimum of 10 samples, one warm-up iteration, and a measurement
/// time far below 10 iterations so that every sample is exactly one iteration on any machine:
/// criterion then always prints "Unable to complete 10 samples in 1.0s" (expected, harmless).
fn configure(group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(1));
}

fn setup() -> (Design, MaterialsTable, ChordTolerance) {
    let base = library::load("shadowtac")
        .and_then(|d| d.with_preset("open_mold"))
        .expect("the library design parses and its open_mold preset applies");
    let materials = MaterialsTable::embedded().expect("the embedded materials table parses");
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM).expect("0.005 mm is a valid tolerance");
    (base, materials, tol)
}

fn bench_published(c: &mut Criterion) {
    let (base, materials, tol) = setup();
    let design = base
        .with_preset("published_469")
        .expect("the published_469 preset applies");
    eprintln!(
        "markers/shadowtac_469_mold: {} features placed",
        features_placed(&design, &materials, tol)
    );
    let mut group = c.benchmark_group("markers");
    configure(&mut group);
    group.bench_function("shadowtac_469_mold", |b| {
        b.iter(|| build_mold(black_box(&design), &materials, tol))
    });
    group.finish();
}

fn bench_scaling(c: &mut Criterion) {
    let (base, materials, tol) = setup();
    let mut group = c.benchmark_group("markers_scaling");
    for n in SCALING_COUNTS {
        let design = scaled_design(&base, n);
        let placed = features_placed(&design, &materials, tol);
        let f = &design.layers[0].markers[0].feature;
        eprintln!(
            "markers_scaling/{n}: {placed} features placed, diameter {} mm, SLA min hole {} mm, min wall {} mm",
            f.diameter_mm, design.printers.sla.min_hole_diameter_mm, design.printers.sla.min_wall_mm
        );
        configure(&mut group);
        group.throughput(Throughput::Elements(placed as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &design, |b, d| {
            b.iter(|| build_mold(black_box(d), &materials, tol))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_published, bench_scaling);
criterion_main!(benches);
