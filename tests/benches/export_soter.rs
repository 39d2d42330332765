//! Benchmarks of the flat skin of Soter et al. (`designs/library/soter_channels.yaml`: the
//! channel layer's tray with its 16 ribs, the marker layer's tray with its 100 holes, each the
//! union of its laser-cut sheets, whose DXF, SVG and STL are written too; the two layers as
//! the assembly, the pours and the procedure) at 0.01 mm chord tolerance.
//!
//! Groups (ids `<group>/soter_channels`):
//! - `build_kit`: `build_kit` only: validation and every boolean of both trays and layers.
//! - `export`: `build_kit` + `write_kit` (STL per part, the kit's 3MF, `assembly.3mf`,
//!   `section.png`, `manifest.json`, `FABRICATION.md`, each file synced, the directory renamed
//!   into place), replaced by every iteration.
//!
//! Run: `cargo bench -p fabkit-benches --bench export_soter` (about 20 s on 2 cores); flat
//! sampling, 10 samples, numbers per iteration.

use criterion::{criterion_group, criterion_main, Criterion};

#[path = "common_kit.rs"]
mod common_kit;

fn bench(c: &mut Criterion) {
    common_kit::bench_kit(c, "soter_channels", "export_soter", 0.01);
}

criterion_group!(benches, bench);
criterion_main!(benches);
