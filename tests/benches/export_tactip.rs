//! Benchmarks of the complete dual-modal TacTip kit (`designs/library/tactip_dualmodal.yaml`:
//! the printed skin with its pins and tips, the tip's bayonet fitting, the body, the robot
//! mount, the lens window, the filling gel and the assembled sensor with its fit check) at
//! 0.01 mm chord tolerance.
//!
//! Groups (ids `<group>/tactip_dualmodal`):
//! - `build_kit`: [`build_kit`] only: validation, every boolean of every part, the gel's
//!   solid and the fit check. The YAML is parsed once, outside the timed loop.
//! - `export`: [`build_kit`] + [`write_kit`] (STL per part, the kit's 3MF, `assembly.3mf`,
//!   `section.png`, the window's DXF/SVG, `manifest.json`, `FABRICATION.md`, each file synced,
//!   the directory renamed into place), replaced by every iteration: what `fabkit export` does
//!   minus process start, YAML parsing and printing.
//!
//! Run: `cargo bench -p fabkit-benches --bench export_tactip` (about 30 s on 2 cores); flat
//! sampling, 10 samples, numbers per iteration.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use fabkit::designs::{build_kit, library, ChordTolerance};
use fabkit::export::{write_kit, ExportOptions, Formats};
use sha2::{Digest, Sha256};
use std::hint::black_box;
use std::time::Duration;

const DESIGN: &str = "tactip_dualmodal";
const CHORD_TOLERANCE_MM: f64 = 0.01;

fn export_options(tol: ChordTolerance) -> ExportOptions {
    let text = library::yaml(DESIGN).expect("the library design exists");
    let design_sha256 = Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    ExportOptions {
        formats: Formats::default(),
        command_line: vec!["cargo bench -p fabkit-benches --bench export_tactip".to_string()],
        design_source: format!("embedded:{DESIGN}"),
        design_sha256,
        chord_tolerance_mm: tol.mm(),
        fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
    }
}

fn bench(c: &mut Criterion) {
    let tol = ChordTolerance::new(CHORD_TOLERANCE_MM).expect("0.01 mm is a valid tolerance");
    let design = library::load(DESIGN).expect("the library design parses");
    let opts = export_options(tol);
    let parent = tempfile::tempdir().expect("a temporary directory");
    let out_dir = parent.path().join(DESIGN);
    for (group_name, seconds) in [("build_kit", 4), ("export", 7)] {
        let mut group = c.benchmark_group(group_name);
        group
            .sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(seconds));
        group.bench_function(DESIGN, |b| {
            b.iter(|| {
                let kit = build_kit(black_box(&design), tol).expect("the library design builds");
                if group_name == "export" {
                    write_kit(&kit, &out_dir, &opts).expect("the kit exports");
                }
                kit
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
