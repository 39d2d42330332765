//! End-to-end: `fabkit export` of the R-Tac0 kit in both mold strategies, checked by the
//! Python oracles (manifold3d + trimesh), by PrusaSlicer through printcheck, for determinism,
//! and for the pour numbers.

mod common;
use common::*;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn export(dir: &Path, strategy: &str, threads: &str) -> serde_json::Value {
    let out = dir.join("rtac0");
    let o = run(
        dir,
        &[
            "export",
            "rtac0",
            "--out",
            out.to_str().unwrap(),
            "--mold-strategy",
            strategy,
        ],
        &[("RAYON_NUM_THREADS", threads)],
    );
    assert!(
        o.status.success(),
        "fabkit export failed:\n{}",
        text(&o.stderr)
    );
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    m
}

fn roles(m: &serde_json::Value) -> BTreeMap<String, usize> {
    let mut r = BTreeMap::new();
    for p in m["parts"].as_array().unwrap() {
        *r.entry(p["role"].as_str().unwrap().to_string())
            .or_default() += 1;
    }
    r
}

fn files_of(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir.join("parts"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v.push(dir.join("rtac0.3mf"));
    v
}

#[test]
fn master_strategy_kit_passes_oracles_and_printcheck() {
    let tmp = tempfile::tempdir().unwrap();
    let m = export(tmp.path(), "master", "2");
    let r = roles(&m);
    assert_eq!(r.get("master_pattern"), Some(&2), "{r:?}");
    assert_eq!(r.get("mold_box"), Some(&2));
    assert_eq!(r.get("casting_jig"), Some(&2));
    assert_eq!(r.get("shell_half"), Some(&2));
    // Two Mold Star pours, then the two gel layers inside out.
    let casts: Vec<&str> = m["casts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["cast"].as_str().unwrap())
        .collect();
    assert_eq!(
        casts,
        [
            "silicone_mold:transparent_gel",
            "silicone_mold:translucent_gel",
            "transparent_gel",
            "translucent_gel"
        ]
    );
    oracle_check(&tmp.path().join("rtac0"));
    printcheck_all(&files_of(&tmp.path().join("rtac0")));
}

#[test]
fn direct_strategy_kit_passes_oracles_and_printcheck() {
    let tmp = tempfile::tempdir().unwrap();
    let m = export(tmp.path(), "direct", "2");
    let r = roles(&m);
    assert_eq!(r.get("mold_half"), Some(&4), "{r:?}");
    assert_eq!(r.get("core_holder"), Some(&2));
    assert_eq!(r.get("shell_half"), Some(&2));
    for p in m["parts"].as_array().unwrap() {
        match p["role"].as_str().unwrap() {
            // 4 clamp bolt holes through each half; sprue + 2 vents through each holder
            "mold_half" => assert_eq!(p["genus"], 4, "{}", p["name"]),
            "core_holder" => assert_eq!(p["genus"], 3, "{}", p["name"]),
            _ => {}
        }
    }
    oracle_check(&tmp.path().join("rtac0"));
    printcheck_all(&files_of(&tmp.path().join("rtac0")));
}

#[test]
fn same_input_same_bytes_whatever_the_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    export(tmp.path(), "direct", "1");
    let first = tmp.path().join("first");
    std::fs::rename(tmp.path().join("rtac0"), &first).unwrap();
    export(tmp.path(), "direct", "2");
    let second = tmp.path().join("rtac0");
    let mut names = vec![
        PathBuf::from("manifest.json"),
        PathBuf::from("FABRICATION.md"),
    ];
    names.extend(
        files_of(&second)
            .iter()
            .map(|f| f.strip_prefix(&second).unwrap().to_path_buf()),
    );
    for n in names {
        let a = std::fs::read(first.join(&n)).unwrap();
        let b = std::fs::read(second.join(&n)).unwrap();
        assert!(a == b, "{} differs between 1 and 2 threads", n.display());
    }
}

#[test]
fn readme_first_command_writes_out_rtac0_with_provenance() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(tmp.path(), &["export"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dir = tmp.path().join("out/rtac0");
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["design"]["name"], "rtac0");
    assert_eq!(m["design"]["source"], "embedded:rtac0");
    assert_eq!(m["design"]["sha256"].as_str().unwrap().len(), 64);
    assert_eq!(m["chord_tolerance_mm"], 0.01);
    assert_eq!(m["fabkit_version"], env!("CARGO_PKG_VERSION"));
    // Envelope of the paper (Sec. III-B): 30 x 30 x 43 mm (the skin is 30.2 mm across).
    let env = m["summary"]["envelope_mm"].as_array().unwrap();
    assert!((env[2].as_f64().unwrap() - 43.0).abs() < 1e-9, "{env:?}");
    assert!((env[0].as_f64().unwrap() - 30.2).abs() < 1e-9);
    // STL headers carry provenance and never start with "solid".
    for p in m["parts"].as_array().unwrap() {
        let bytes = std::fs::read(dir.join(p["file"].as_str().unwrap())).unwrap();
        let header = String::from_utf8_lossy(&bytes[..80]).to_string();
        assert!(
            header.starts_with("fabkit") && header.contains("rtac0"),
            "{header}"
        );
    }
    let sheet = std::fs::read_to_string(dir.join("FABRICATION.md")).unwrap();
    assert!(
        sheet.contains("Sylgard") || sheet.contains("sylgard"),
        "{sheet}"
    );
}

#[test]
fn pour_numbers_follow_from_the_cavity_and_the_materials_table() {
    let tmp = tempfile::tempdir().unwrap();
    let m = export(tmp.path(), "direct", "2");
    let casts = m["casts"].as_array().unwrap();
    let pdms = casts
        .iter()
        .find(|c| c["cast"] == "transparent_gel")
        .unwrap();
    // Analytic PDMS layer: hemisphere shell 10 -> 13.5 mm plus 6 mm of cylinder shell.
    let layer =
        2.0 / 3.0 * PI * (13.5f64.powi(3) - 10f64.powi(3)) + PI * (13.5f64.powi(2) - 100.0) * 6.0;
    // The pour also fills the reservoir ring between the core and the plinth (radius 18.5 mm,
    // 1.5 mm deep under the holder's spigot) and the thin clearance gaps around the holder.
    let reservoir = PI * (18.5f64.powi(2) - 10.0f64.powi(2)) * 1.5;
    let v = pdms["cavity_volume_ml"].as_f64().unwrap() * 1000.0;
    assert!(
        v > layer + 0.95 * reservoir && v < layer + 1.15 * reservoir,
        "pour {v} mm3, layer {layer}, reservoir {reservoir}"
    );
    // Sylgard 184: 1.03 g/cm3, 10:1 by weight, 20 % waste.
    let total = v / 1000.0 * 1.03 * 1.2;
    assert!((pdms["total_mass_g"].as_f64().unwrap() - total).abs() < 1e-9);
    let a = pdms["components"][0]["mass_g"].as_f64().unwrap();
    let b = pdms["components"][1]["mass_g"].as_f64().unwrap();
    assert!((a / b - 10.0).abs() < 1e-9 && (a + b - total).abs() < 1e-9);
    // The translucent pour excludes the sprayed black coating.
    let eco = casts
        .iter()
        .find(|c| c["cast"] == "translucent_gel")
        .unwrap();
    let layer2 = 2.0 / 3.0 * PI * (15f64.powi(3) - 13.5f64.powi(3))
        + PI * (15f64.powi(2) - 13.5f64.powi(2)) * 6.0;
    let reservoir2 = PI * (20.1f64.powi(2) - 10.0f64.powi(2)) * 1.5;
    let v2 = eco["cavity_volume_ml"].as_f64().unwrap() * 1000.0;
    assert!(
        v2 > layer2 + 0.95 * reservoir2 && v2 < layer2 + 1.15 * reservoir2,
        "pour {v2}, layer {layer2}"
    );
    assert!(eco["notes"].as_str().unwrap().contains("black_coating"));
}
