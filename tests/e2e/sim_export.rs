//! `fabkit export DESIGN --format mjcf` (issue 103): the assembled sensor as MuJoCo loads it.
//! For every library design MuJoCo (`mujoco` from PyPI, tests/oracles/mujoco_check.py) loads
//! `sim/<design>.xml` with its meshes and steps it; the body's mass, centre of mass and full
//! inertia tensor are the manifest's (`assembly_3mf.mass`, checked against trimesh in
//! tests/e2e/mass.rs) within 1e-6 relative; there is one mesh per assembly member; where the
//! design places a camera, MuJoCo's camera sits where `fabkit calibrate nominal` puts it
//! (position within 1e-9 m, axes within 1e-9: MuJoCo's x right, y up, looking along -z, the
//! OpenCV frame turned about x), its fovy the pinhole's 2 atan(h / 2 / fy) of the nominal
//! camera file, and the contact-surface site on the skin's top.

use crate::common::{missing, oracle_python, repo_root, run, text};
use serde_json::Value;
use std::path::Path;

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

/// fy of an OpenCV camera file's `camera_matrix` (its fifth number).
fn fy_px(camera_yaml: &str) -> f64 {
    let after = &camera_yaml[camera_yaml.find("camera_matrix").unwrap()..];
    let data = &after[after.find("data: [").unwrap() + 7..];
    let numbers: Vec<f64> = data[..data.find(']').unwrap()]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    numbers[4]
}

#[test]
fn every_library_design_loads_in_mujoco_with_its_mass_and_camera() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (mujoco)");
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mut cameras = 0;
    for design in [
        "rtac0",
        "shadowtac",
        "uvdtact",
        "tactip_dualmodal",
        "soter_channels",
        "digit_pinki",
        "ninedtact",
    ] {
        let o = run(
            dir,
            &["export", design, "--format", "3mf,mjcf", "--out", design],
            &[],
        );
        assert!(o.status.success(), "{design}: {}", text(&o.stderr));
        let manifest = json(&dir.join(design).join("manifest.json"));
        let o = std::process::Command::new(&py)
            .arg(repo_root().join("tests/oracles/mujoco_check.py"))
            .arg(dir.join(design).join(format!("sim/{design}.xml")))
            .arg(design)
            .arg("10")
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{design}: {}\n{}",
            text(&o.stdout),
            text(&o.stderr)
        );
        let mj: Value = serde_json::from_slice(&o.stdout).unwrap();
        let mass = &manifest["assembly_3mf"]["mass"];
        let members = manifest["assembly_3mf"]["members"].as_array().unwrap();
        assert_eq!(
            mj["nmesh"].as_u64().unwrap() as usize,
            members.len(),
            "{design}"
        );
        assert_eq!(mj["steps"], 10);
        let m = f(&mass["mass_g"]) * 1e-3;
        assert!(
            (f(&mj["body"]["mass_kg"]) - m).abs() < 1e-6 * m,
            "{design}: {mj}"
        );
        for k in 0..3 {
            let want = f(&mass["centre_of_mass_mm"][k]) * 1e-3;
            assert!(
                (f(&mj["body"]["com_m"][k]) - want).abs() < 1e-9,
                "{design}: {mj}"
            );
        }
        let scale = (0..3)
            .map(|k| f(&mass["inertia_g_mm2"][k][k]))
            .fold(0.0, f64::max)
            * 1e-9;
        for i in 0..3 {
            for j in 0..3 {
                let want = f(&mass["inertia_g_mm2"][i][j]) * 1e-9;
                let got = f(&mj["body"]["inertia_kg_m2"][i][j]);
                assert!(
                    (got - want).abs() < 1e-6 * scale,
                    "{design} I{i}{j}: {got} vs {want}"
                );
            }
        }
        // the contact-surface site on the skin's top (above the centre of mass)
        assert!(
            f(&mj["site"]["pos_m"][2]) > f(&mj["body"]["com_m"][2]),
            "{design}: {mj}"
        );
        // the camera, where `calibrate nominal` puts it
        let nominal = run(
            dir,
            &[
                "calibrate",
                "nominal",
                design,
                "--out",
                &format!("nom_{design}"),
            ],
            &[],
        );
        if !nominal.status.success() {
            assert!(mj["camera"].is_null(), "{design}: {mj}");
            assert!(
                text(&std::fs::read(dir.join(format!("{design}/sim/{design}.xml"))).unwrap())
                    .contains("<!-- no camera: "),
                "{design}"
            );
            continue;
        }
        cameras += 1;
        let ext = json(&dir.join(format!("nom_{design}/extrinsics.json")));
        let t = &ext["T_cam_sensor"];
        let r = |i: usize, j: usize| f(&t[i][j]);
        let cam = &mj["camera"];
        for k in 0..3 {
            // the camera's centre in the sensor frame: -R^T t
            let want = -(0..3).map(|i| r(i, k) * f(&t[i][3])).sum::<f64>() * 1e-3;
            assert!((f(&cam["pos_m"][k]) - want).abs() < 1e-9, "{design}: {cam}");
            // MuJoCo's axes: OpenCV's x, -y, -z (the rows of R are OpenCV's axes in the sensor frame)
            for (c, sign) in [(0, 1.0), (1, -1.0), (2, -1.0)] {
                let want = sign * r(c, k);
                let got = f(&cam["R_body_cam"][k][c]);
                assert!((got - want).abs() < 1e-9, "{design}: {cam}");
            }
        }
        let camera_yaml =
            std::fs::read_to_string(dir.join(format!("nom_{design}/camera.yaml"))).unwrap();
        let fovy = 2.0 * (240.0 / fy_px(&camera_yaml)).atan().to_degrees();
        assert!((f(&cam["fovy_deg"]) - fovy).abs() < 1e-9, "{design}: {cam}");
        assert_eq!(cam["resolution"], serde_json::json!([640, 480]), "{design}");
    }
    // R-Tac0, UVDtact, the TacTip (and any design that places its lens)
    assert!(cameras >= 2, "{cameras} designs with a camera");
}
