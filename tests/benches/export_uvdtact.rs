//! Benchmarks of the complete UVDtact kit (`designs/library/uvdtact.yaml`: the three layers'
//! boundary molds with their 85 slots and protrusions, the shell holder, the sensor base, the
//! camera holder, the diffusion ring, the lighting PCB's outline, the acrylic shell made to
//! order (its drawing and mesh) and the assembled sensor with its fit check) at 0.01 mm chord
//! tolerance.
//!
//! Groups (ids `<group>/uvdtact`, and `<group>/uvdtact_no_markers` for the preset without
//! marker molds: its boundary molds are plain revolved shells):
//! - `build_kit`: `build_kit` only: validation, every boolean of every part and the fit check.
//!   The YAML is parsed once, outside the timed loop.
//! - `export`: `build_kit` + `write_kit` (STL per part, the kit's 3MF, `assembly.3mf`,
//!   `section.png`, the PCB's DXF, `manifest.json`, `FABRICATION.md`, each file synced, the
//!   directory renamed into place), replaced by every iteration: what `fabkit export` does
//!   minus process start, YAML parsing and printing.
//!
//! Run: `cargo bench -p fabkit-benches --bench export_uvdtact` (about 80 s on 2 cores); flat
//! sampling, 10 samples, numbers per iteration.

use criterion::{criterion_group, criterion_main, Criterion};

#[path = "common_kit.rs"]
mod common_kit;

fn bench(c: &mut Criterion) {
    common_kit::bench_kit(c, "uvdtact", "export_uvdtact", 0.01);
    // without marker molds: the 1 s goal
    common_kit::bench_kit_preset(c, "uvdtact", Some("no_markers"), "export_uvdtact", 0.01);
}

criterion_group!(benches, bench);
criterion_main!(benches);
