//! Benchmarks of the R-Tac0 kit (`designs/library/rtac0.yaml`) at 0.01 mm chord tolerance, with
//! both mold strategies (`master`, the library design's choice, and `direct`).
//!
//! Groups (ids `<group>/<strategy>`):
//! - `build_kit`: [`build_kit`] only: stack validation, every boolean of every mold and the shell
//!   (the kernel evaluates each boolean when the solid is made). The YAML is parsed once, outside
//!   the timed loop.
//! - `export`: [`build_kit`] + [`write_kit`] (STL per part, one 3MF, `manifest.json`,
//!   `FABRICATION.md`, each file synced, the directory renamed into place) into one output
//!   directory under a temporary parent, replaced by every iteration. This is what `fabkit export`
//!   does minus process start, YAML parsing, the CSG dump and printing.
//!
//! - `pictures`: the part previews and a plate picture alone (see [`bench_pictures`]).
//!
//! Run: `cargo bench -p fabkit-benches --bench export_rtac0` (about a minute on 2 cores). Every iteration
//! takes a sizeable fraction of a second, so sampling is flat: 10 samples of one or a few
//! iterations each; the numbers are per iteration. `scripts/bench-compare` times the whole command against
//! the same booleans replayed in manifold3d.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use fabkit::designs::schema::MoldStrategy;
use fabkit::designs::{build_kit, library, ChordTolerance, Design};
use fabkit::export::{write_kit, ExportOptions};

#[path = "common_kit.rs"]
mod common_kit;
use std::hint::black_box;
use std::time::Duration;

const DESIGN: &str = "rtac0";
const CHORD_TOLERANCE_MM: f64 = 0.01;

/// The library design with every cast layer on `strategy` (as `fabkit export --mold-strategy`).
fn design_with(strategy: MoldStrategy) -> Design {
    let mut design = library::load(DESIGN).expect("the library design parses");
    design.mold.strategy = strategy;
    for layer in &mut design.layers {
        layer.mold_strategy = None;
    }
    design
}

/// The options `fabkit export` would pass, with this benchmark as the recorded command line.
fn export_options(tol: ChordTolerance) -> ExportOptions {
    common_kit::export_options(DESIGN, "export_rtac0", tol)
}

const STRATEGIES: [(&str, MoldStrategy); 2] = [
    ("master", MoldStrategy::Master),
    ("direct", MoldStrategy::Direct),
];

/// Flat sampling, 10 samples; `measurement_s` is sized so that a sample is one or a few
/// iterations (criterion warns, and takes longer, when 10 iterations do not fit).
fn configure(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    measurement_s: u64,
) {
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(measurement_s));
}

fn bench_build_kit(c: &mut Criterion) {
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM).expect("0.01 mm is a valid tolerance");
    let mut group = c.benchmark_group("build_kit");
    configure(&mut group, 4);
    for (name, strategy) in STRATEGIES {
        let design = design_with(strategy);
        group.bench_function(name, |b| {
            b.iter(|| build_kit(black_box(&design), tol).expect("the library design builds"))
        });
    }
    group.finish();
}

fn bench_export(c: &mut Criterion) {
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM).expect("0.01 mm is a valid tolerance");
    let opts = export_options(tol);
    let parent = tempfile::tempdir().expect("a temporary directory");
    let mut group = c.benchmark_group("export");
    configure(&mut group, 7);
    for (name, strategy) in STRATEGIES {
        let design = design_with(strategy);
        // One directory per strategy; write_kit replaces the previous iteration's export.
        let out_dir = parent.path().join(name);
        group.bench_function(name, |b| {
            b.iter(|| {
                let kit = build_kit(black_box(&design), tol).expect("the library design builds");
                write_kit(&kit, &out_dir, &opts).expect("the kit exports")
            })
        });
    }
    group.finish();
}

/// `pictures/<strategy>`: the pictures alone, as the export makes them: every part's preview
/// ([`part_pngs`]) and, for the plates, one picture of every part on a bed plus a thumbnail
/// copy (rtac0 has three plates of fewer parts: an upper bound). `export - pictures` is the
/// export without them.
fn bench_pictures(c: &mut Criterion) {
    use fabkit::export::preview::{part_pngs, render_plate, BedOutline, PlacedObject};
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM).expect("0.01 mm is a valid tolerance");
    let mut group = c.benchmark_group("pictures");
    configure(&mut group, 4);
    for (name, strategy) in STRATEGIES {
        let kit = build_kit(&design_with(strategy), tol).expect("the library design builds");
        let meshes: Vec<_> = kit.parts.iter().map(|p| p.written_mesh()).collect();
        let named: Vec<(&str, &fabkit::designs::Mesh)> = kit
            .parts
            .iter()
            .zip(&meshes)
            .map(|(p, m)| (p.name.as_str(), m))
            .collect();
        group.bench_function(name, |b| {
            b.iter(|| {
                let parts = part_pngs(black_box(&named)).expect("previews encode");
                let placed: Vec<PlacedObject<'_>> = meshes
                    .iter()
                    .enumerate()
                    .map(|(k, m)| PlacedObject {
                        name: "part",
                        meshes: vec![m],
                        turned: false,
                        translation_mm: [60.0 * (k % 4) as f64, 60.0 * (k / 4) as f64, 0.0],
                    })
                    .collect();
                let plate = render_plate(
                    &placed,
                    Some(BedOutline {
                        size_xy_mm: [250.0, 210.0],
                        margin_mm: 10.0,
                    }),
                );
                (parts, plate.png("plate").expect("plate encodes"))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_build_kit, bench_export, bench_pictures);
criterion_main!(benches);
