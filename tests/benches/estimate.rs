//! The up-front work estimate (`fabkit_designs::estimate::estimate`: the layer surfaces'
//! profiles and one placement of every marker pattern) against the build it bounds
//! (`build_kit`, every boolean evaluated, nothing written), for each library design at the
//! default 0.01 mm chord tolerance.
//!
//! Ids `estimate/<design>` and `build_kit/<design>`. The estimate must cost under 1 % of the
//! build. Run: `cargo bench -p fabkit-benches --bench estimate` (about a minute after the build).

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use fabkit::designs::estimate::estimate;
use fabkit::designs::materials::MaterialsTable;
use fabkit::designs::{build_kit, library, stack, ChordTolerance};
use std::hint::black_box;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::default();
    let mut g = c.benchmark_group("estimate");
    for (name, _) in library::LIBRARY {
        let d = library::load(name).unwrap();
        let st = stack::validate(&d, &materials, tol).unwrap();
        g.bench_function(*name, |b| b.iter(|| black_box(estimate(&d, &st, tol))));
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
}

criterion_group!(benches, bench);
criterion_main!(benches);
