//! The assembled sensor's mass properties in `manifest.json` (`assembly_3mf.mass` and each
//! member's `mass`) against trimesh's on the meshes of assembly.3mf at materials.yaml's
//! densities (tests/oracles/mass_check.py), for a round, a flat and a cased library design.

use crate::common::{missing, oracle_python, repo_root, run, text};

#[test]
fn the_sensors_mass_and_inertia_are_trimeshs() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (trimesh)");
    };
    let tmp = tempfile::tempdir().unwrap();
    for design in ["rtac0", "ninedtact", "shadowtac"] {
        let o = run(
            tmp.path(),
            &["export", design, "--format", "3mf", "--out", design],
            &[],
        );
        assert!(o.status.success(), "{design}: {}", text(&o.stderr));
        let o = std::process::Command::new(&py)
            .arg(repo_root().join("tests/oracles/mass_check.py"))
            .arg(tmp.path().join(design))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{design}: {}\n{}",
            text(&o.stdout),
            text(&o.stderr)
        );
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let members = r["members"].as_array().unwrap();
        // every design has printed or cast members with materials; the sensor weighs grams
        assert!(members.len() >= 3, "{design}: {r}");
        let mass = r["sensor"]["mass_g"][0].as_f64().unwrap();
        assert!(mass > 1.0 && mass < 1000.0, "{design}: {r}");
    }
}
