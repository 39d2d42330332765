//! Benchmarks of the complete ShadowTac kit (`designs/library/shadowtac.yaml`: the authors'
//! two-piece SLA mold with its 469 dimple pins, the casing, the gripper base, the backing
//! plate's DXF/SVG and the assembled sensor with its fit check) at 0.01 mm chord tolerance.
//!
//! Groups (ids `<group>/shadowtac`):
//! - `build_kit`: `build_kit` only: validation, every boolean of every
//!   part and the fit check. The YAML is parsed once, outside the timed loop.
//! - `export`: `build_kit` + `write_kit` (STL per part, the kit's 3MF, `assembly.3mf`,
//!   `section.png`, the plate's DXF/SVG, `manifest.json`, `FABRICATION.md`, each file synced,
//!   the directory renamed into place), replaced by every iteration: what `fabkit export` does
//!   minus process start, YAML parsing and printing.
//!
//! Run: `cargo bench -p fabkit-benches --bench export_shadowtac` (about 40 s on 2 cores); flat
//! sampling, 10 samples, numbers per iteration.

use criterion::{criterion_group, criterion_main, Criterion};

#[path = "common_kit.rs"]
mod common_kit;

fn bench(c: &mut Criterion) {
    common_kit::bench_kit(c, "shadowtac", "export_shadowtac", 0.01);
}

criterion_group!(benches, bench);
criterion_main!(benches);
