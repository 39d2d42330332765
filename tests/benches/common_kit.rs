//! What the kit benchmarks share: the export options of a library design and the benchmark of
//! one complete kit (`build_kit`, and `build_kit` + `write_kit`).

#![allow(dead_code)] // each bench binary uses the parts it needs

use criterion::{Criterion, SamplingMode};
use fabkit::designs::{build_kit, library, ChordTolerance};
use fabkit::export::{write_kit, ExportOptions, Formats};
use sha2::{Digest, Sha256};
use std::hint::black_box;
use std::time::Duration;

/// The options `fabkit export <design>` would use, the embedded YAML's hash included;
/// `bench` names the bench binary on the command line recorded in the manifest.
pub fn export_options(design: &str, bench: &str, tol: ChordTolerance) -> ExportOptions {
    let text = library::yaml(design).expect("the library design exists");
    let design_sha256 = Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    ExportOptions {
        formats: Formats::default(),
        command_line: vec![format!("cargo bench -p fabkit-benches --bench {bench}")],
        design_source: format!("embedded:{design}"),
        design_sha256,
        chord_tolerance_mm: tol.mm(),
        fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
        printers: Default::default(),
        command: fabkit::export::OutputCommand::Export,
        force: false,
        sim: Default::default(),
    }
}

/// Groups `build_kit/<design>` and `export/<design>` of one library design at
/// `chord_tolerance_mm`: flat sampling, 10 samples, the export replaced by every iteration.
pub fn bench_kit(c: &mut Criterion, design_name: &str, bench: &str, chord_tolerance_mm: f64) {
    bench_kit_preset(c, design_name, None, bench, chord_tolerance_mm);
}

/// [`bench_kit`] of the design with `preset` applied; ids `<group>/<design>_<preset>`.
pub fn bench_kit_preset(
    c: &mut Criterion,
    design_name: &str,
    preset: Option<&str>,
    bench: &str,
    chord_tolerance_mm: f64,
) {
    let tol = ChordTolerance::new(chord_tolerance_mm).expect("a valid tolerance");
    let mut design = library::load(design_name).expect("the library design parses");
    let id = match preset {
        Some(p) => {
            design = design.with_preset(p).expect("the preset applies");
            format!("{design_name}_{p}")
        }
        None => design_name.to_string(),
    };
    let opts = export_options(design_name, bench, tol);
    let design_name = id.as_str();
    let parent = tempfile::tempdir().expect("a temporary directory");
    let out_dir = parent.path().join(design_name);
    for (group_name, seconds) in [("build_kit", 4), ("export", 7)] {
        let mut group = c.benchmark_group(group_name);
        group
            .sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(seconds));
        group.bench_function(design_name, |b| {
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
