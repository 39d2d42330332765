//! `fabkit export --format step` writes `assembly.step`, the assembled sensor as exact B-reps
//! in the sensor frame, read back here by OpenCASCADE's XDE reader
//! (tests/oracles/read_assembly_step.py) in the CadQuery Python. Needs FABKIT_CADQUERY_PYTHON
//! (skips without it; FABKIT_REQUIRE_CADQUERY=1 makes it required).

use crate::common::{cadquery_python, repo_root, run, text};
use sha2::{Digest, Sha256};
use std::path::Path;

/// `fabkit export rtac0 --format step --out <out>` with the CadQuery Python; the manifest.
fn export_step(cwd: &Path, out: &str, python: &Path) -> serde_json::Value {
    let py = python.to_str().unwrap();
    let o = run(
        cwd,
        &["export", "rtac0", "--format", "step", "--out", out],
        &[("FABKIT_CADQUERY_PYTHON", py)],
    );
    assert!(
        o.status.success(),
        "export rtac0 --format step:\n{}{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    serde_json::from_slice(&std::fs::read(cwd.join(out).join("manifest.json")).unwrap()).unwrap()
}

/// rtac0's `assembly.step`: one STEP assembly `rtac0` with one named solid per assembly member
/// (the manifest's `assembly_step.members`, in order), each valid and closed, its volume equal
/// to the member's mesh volume within the chord-tolerance bound (surface area x tolerance), in
/// the sensor frame: the collar's top face on the body's base plane z = -6 mm, the diffuser
/// between the collar (z = -9) and the tube (z = -11), the base below the tube. The manifest
/// records the file's sha256, and a second export writes the same bytes. The first export is
/// the twins' shared one of R-Tac0 ([`crate::cad_twins::shared_step_export`]: `--format
/// stl,3mf,step`, whose STEP files are those of `--format step`). The reader also sews
/// an octahedron through fabkit's mesh-sewing path (members without an exact shape).
#[test]
fn assembly_step_of_rtac0_has_one_valid_solid_per_member_in_the_sensor_frame() {
    let Some(python) = cadquery_python() else {
        eprintln!("SKIPPED: assembly.step of rtac0 (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let shared = crate::cad_twins::shared_step_export("rtac0").expect("CadQuery is set");
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(shared.join("manifest.json")).unwrap()).unwrap();
    let bytes = std::fs::read(shared.join("assembly.step")).unwrap();
    assert!(bytes.starts_with(b"ISO-10303-21;"));
    let a = &m["assembly_step"];
    assert_eq!(a["file"], "assembly.step");
    let sha: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(a["sha256"], sha.as_str());
    // same input, same bytes
    export_step(t.path(), "b", &python);
    assert!(
        bytes == std::fs::read(t.path().join("b/assembly.step")).unwrap(),
        "two exports of rtac0 wrote different assembly.step files"
    );

    let o = std::process::Command::new(&python)
        .arg(repo_root().join("tests/oracles/read_assembly_step.py"))
        .arg(shared.join("assembly.step"))
        .output()
        .expect("the CadQuery python runs");
    assert!(
        o.status.success(),
        "read_assembly_step.py:\n{}",
        text(&o.stderr)
    );
    let read: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(read["roots"], serde_json::json!(["rtac0"]));
    let tol = m["chord_tolerance_mm"].as_f64().unwrap();
    let want = a["members"].as_array().unwrap();
    let got = read["members"].as_array().unwrap();
    let names = |v: &[serde_json::Value], k: &str| -> Vec<String> {
        v.iter()
            .map(|x| x[k].as_str().unwrap().to_owned())
            .collect()
    };
    assert_eq!(names(got, "component"), names(want, "name"));
    assert_eq!(names(got, "product"), names(want, "name"));
    // every assembly member of the 3MF path is here (printed, cast and bought)
    for (name, kind) in [
        ("shell_collar", "printed"),
        ("transparent_gel", "cast"),
        ("filling_gel", "cast"),
        ("diffuser_envelope", "bought"),
    ] {
        assert!(
            want.iter().any(|w| w["name"] == name && w["kind"] == kind),
            "{name} ({kind}) missing: {want:?}"
        );
    }
    for (w, g) in want.iter().zip(got) {
        let name = w["name"].as_str().unwrap();
        assert_eq!(g["solids"], 1, "{name}: {g}");
        assert_eq!(w["shells"], 1, "{name}: {w}");
        assert_eq!(g["valid"], true, "{name}: not valid (BRepCheck)");
        assert_eq!(g["closed"], true, "{name}: an open shell");
        let (v, v_mesh) = (
            g["volume_mm3"].as_f64().unwrap(),
            w["volume_mm3"].as_f64().unwrap(),
        );
        let bound = w["surface_area_mm2"].as_f64().unwrap() * tol + 1e-6 * v.abs();
        assert!(
            (v - v_mesh).abs() <= bound,
            "{name}: STEP volume {v} mm3, mesh {v_mesh} mm3, bound {bound} mm3"
        );
        let bb: Vec<f64> = serde_json::from_value(g["bbox_mm"].clone()).unwrap();
        let (lo, hi): (Vec<f64>, Vec<f64>) = (
            serde_json::from_value(w["bbox_mm"]["min"].clone()).unwrap(),
            serde_json::from_value(w["bbox_mm"]["max"].clone()).unwrap(),
        );
        let dev = (0..3)
            .map(|k| (bb[k] - lo[k]).abs().max((bb[k + 3] - hi[k]).abs()))
            .fold(0.0, f64::max);
        assert!(
            dev <= tol + 1e-3,
            "{name}: box {bb:?} vs mesh {lo:?} {hi:?}"
        );
    }
    // the sensor frame, from the STEP file alone
    let member = |name: &str| got.iter().find(|g| g["component"] == name).unwrap();
    let zs = |name: &str| -> (f64, f64, Vec<f64>) {
        let g = member(name);
        let up: Vec<f64> = serde_json::from_value(g["up_faces_z_mm"].clone()).unwrap();
        (
            g["bbox_mm"][2].as_f64().unwrap(),
            g["bbox_mm"][5].as_f64().unwrap(),
            up,
        )
    };
    let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
    let (collar_lo, collar_hi, collar_up) = zs("shell_collar");
    assert!(near(collar_hi, -6.0), "collar top at z = {collar_hi}");
    assert!(
        collar_up.last().is_some_and(|&z| near(z, -6.0)),
        "the collar has no upward face at z = -6: {collar_up:?}"
    );
    let (diffuser_lo, diffuser_hi, _) = zs("diffuser_envelope");
    let (tube_lo, tube_hi, _) = zs("shell_tube");
    let (base_lo, base_hi, _) = zs("shell_base");
    assert!(near(collar_lo, diffuser_hi) && near(collar_lo, -9.0));
    assert!(near(tube_hi, diffuser_lo) && near(tube_hi, -11.0));
    assert!(base_lo < tube_lo && base_hi < tube_hi && base_hi > tube_lo);
    // members without an exact shape are sewn from their mesh: that path on a known solid
    let octa = &read["sewn_octahedron"];
    assert_eq!(octa["solids"], 1);
    assert_eq!(octa["valid"], true);
    assert_eq!(octa["closed"], true);
    assert!((octa["volume_mm3"].as_f64().unwrap() - 4.0 / 3.0).abs() < 1e-9);
}
