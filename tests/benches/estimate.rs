//! The up-front work estimate (`fabkit_designs::estimate::estimate`: the layer surfaces'
//! profiles and one placement of every marker pattern) against the build it bounds
//! (`build_kit`, every boolean evaluated, nothing written), for each library design at the
//! default 0.01 mm chord tolerance.
//!
//! The same for the fixtures (`fabkit_fixtures::estimate` against `build_fixtures`, the
//! default fixtures with three generated semi-domes).
//!
//! Ids `estimate/<design>`, `build_kit/<design>`, `estimate_fixtures/<design>` and
//! `build_fixtures/<design>`. Each estimate must cost under 1 % of its build. Run:
//! `cargo bench -p fabkit-benches --bench estimate` (about three minutes after the build).

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use fabkit::designs::estimate::estimate;
use fabkit::designs::materials::MaterialsTable;
use fabkit::designs::{build_kit, library, stack, ChordTolerance};
use fabkit::fixtures::params::FixtureParams;
use fabkit::fixtures::{build_fixtures, semidome};
use std::hint::black_box;
use std::time::Duration;

/// The library's curved designs (the estimate and the fixtures are for curved skins).
fn curved() -> Vec<(&'static str, fabkit::designs::Design)> {
    library::LIBRARY
        .iter()
        .map(|(n, _)| (*n, library::load(n).unwrap()))
        .filter(|(_, d)| d.body.flat_outline().is_none())
        .collect()
}

fn bench(c: &mut Criterion) {
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::default();
    let mut g = c.benchmark_group("estimate");
    for (name, d) in curved() {
        let st = stack::validate(&d, &materials, tol).unwrap();
        g.bench_function(name, |b| b.iter(|| black_box(estimate(&d, &st, tol))));
    }
    g.finish();
    let mut g = c.benchmark_group("build_kit");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1));
    for (name, _) in library::LIBRARY {
        let d = library::load(name).unwrap();
        g.bench_function(*name, |b| b.iter(|| black_box(build_kit(&d, tol).unwrap())));
    }
    g.finish();

    let mut params = FixtureParams::default();
    params.semidomes.generate = 3;
    let mut g = c.benchmark_group("estimate_fixtures");
    for (name, d) in curved() {
        let st = stack::validate(&d, &materials, tol).unwrap();
        // the patterns, which build_fixtures generates before it estimates
        let specs = semidome::generate(&d, &st, &params.semidomes);
        g.bench_function(name, |b| {
            b.iter(|| black_box(fabkit::fixtures::estimate(&d, &params, &specs, tol)))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("build_fixtures");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1));
    for (name, d) in curved() {
        g.bench_function(name, |b| {
            b.iter(|| black_box(build_fixtures(&d, &params, tol, u64::MAX, "bench").unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
