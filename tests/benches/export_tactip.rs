//! Benchmarks of the complete dual-modal TacTip kit (`designs/library/tactip_dualmodal.yaml`:
//! the printed skin with its pins and tips, the tip's bayonet fitting, the body, the robot
//! mount, the lens window, the filling gel and the assembled sensor with its fit check) at
//! 0.01 mm chord tolerance.
//!
//! Groups (ids `<group>/tactip_dualmodal`):
//! - `build_kit`: `build_kit` only: validation, every boolean of every part, the gel's
//!   solid and the fit check. The YAML is parsed once, outside the timed loop.
//! - `export`: `build_kit` + `write_kit` (STL per part, the kit's 3MF, `assembly.3mf`,
//!   `section.png`, the window's DXF/SVG, `manifest.json`, `FABRICATION.md`, each file synced,
//!   the directory renamed into place), replaced by every iteration: what `fabkit export` does
//!   minus process start, YAML parsing and printing.
//!
//! Run: `cargo bench -p fabkit-benches --bench export_tactip` (about 30 s on 2 cores); flat
//! sampling, 10 samples, numbers per iteration.

use criterion::{criterion_group, criterion_main, Criterion};

#[path = "common_kit.rs"]
mod common_kit;

fn bench(c: &mut Criterion) {
    common_kit::bench_kit(c, "tactip_dualmodal", "export_tactip", 0.01);
}

criterion_group!(benches, bench);
criterion_main!(benches);
