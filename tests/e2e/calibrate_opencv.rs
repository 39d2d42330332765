//! OpenCV (opencv-python-headless, tests/oracles/opencv_project.py) as the oracle for the camera
//! models and the OpenCV FileStorage camera file: projection agrees to 1e-6 px over the field of
//! view (fisheye up to 89 deg off axis, where cv2.fisheye's z = 1 plane still holds), and
//! cv2.FileStorage reads back exactly what fabkit writes.

use crate::common::{missing, oracle_python, repo_root, text};
use fabkit_calibration::nalgebra::Vector3;
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::{write_camera, CameraFileFormat, CameraModel, Distortion, Intrinsics};

fn cameras() -> Vec<Intrinsics> {
    let base = |d| Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 300.5,
        fy_px: 299.25,
        cx_px: 318.75,
        cy_px: 241.5,
        distortion: d,
    };
    vec![
        benchmark_intrinsics(),
        base(Distortion::Fisheye([0.05, -0.02, 0.006, -0.0008])),
        // R-Tac0's published form: pinhole, k1 about -0.26.
        base(Distortion::PlumbBob([-0.26, 0.07, 0.0012, -0.0007, -0.009])),
        base(Distortion::RationalPolynomial([
            0.5, -0.1, 0.001, 0.002, 0.01, 0.8, -0.05, 0.02,
        ])),
    ]
}

#[test]
fn projection_agrees_with_opencv_to_1e_6_px_over_the_field_and_filestorage_reads_our_files() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (opencv-python-headless)");
    };
    let d = tempfile::tempdir().unwrap();
    let mut cases = Vec::new();
    let mut ours = Vec::new();
    for (k, intr) in cameras().iter().enumerate() {
        let cam = CameraModel::new(*intr).unwrap();
        let fisheye = matches!(intr.distortion, Distortion::Fisheye(_));
        let max = if fisheye {
            89.0f64.min(cam.max_field_angle_deg())
        } else {
            0.97 * cam.max_field_angle_deg()
        };
        let mut pts = Vec::new();
        let mut px = Vec::new();
        for i in 0..60 {
            let t = (max * i as f64 / 59.0).to_radians();
            let a = (i as f64 * 137.5).to_radians();
            let p = (5.0 + i as f64) * Vector3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos());
            let uv = cam.project(&p).unwrap();
            pts.push([p.x, p.y, p.z]);
            px.push([uv.x, uv.y]);
        }
        let file = d.path().join(format!("cam{k}.yaml"));
        std::fs::write(&file, write_camera(intr, CameraFileFormat::OpenCvYaml)).unwrap();
        cases.push(serde_json::json!({
            "model": intr.distortion.name(),
            "K": [[intr.fx_px, 0.0, intr.cx_px], [0.0, intr.fy_px, intr.cy_px], [0.0, 0.0, 1.0]],
            "D": intr.distortion.coefficients(),
            "points": pts,
            "camera_file": file,
        }));
        ours.push(px);
    }
    let input = d.path().join("cases.json");
    std::fs::write(
        &input,
        serde_json::to_vec(&serde_json::json!({ "cases": cases })).unwrap(),
    )
    .unwrap();
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/opencv_project.py"))
        .arg(&input)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let res: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut worst = 0.0f64;
    for (k, (case, px)) in res["cases"]
        .as_array()
        .unwrap()
        .iter()
        .zip(&ours)
        .enumerate()
    {
        for (i, uv) in case["pixels"].as_array().unwrap().iter().enumerate() {
            let (u, v) = (uv[0].as_f64().unwrap(), uv[1].as_f64().unwrap());
            let e = (u - px[i][0]).hypot(v - px[i][1]);
            worst = worst.max(e);
            assert!(
                e < 1e-6,
                "camera {k} point {i}: opencv ({u}, {v}) vs fabkit {:?}",
                px[i]
            );
        }
        let intr = &cameras()[k];
        let f = &case["file"];
        assert_eq!(f["width"], intr.image_width_px);
        assert_eq!(f["height"], intr.image_height_px);
        assert_eq!(f["model"], intr.distortion.name());
        assert_eq!(f["K"][0][0].as_f64().unwrap(), intr.fx_px);
        assert_eq!(f["K"][1][2].as_f64().unwrap(), intr.cy_px);
        let dd: Vec<f64> = f["D"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(dd, intr.distortion.coefficients(), "camera {k}");
    }
    eprintln!(
        "worst |fabkit - OpenCV| = {worst:.2e} px (OpenCV {})",
        res["opencv_version"]
    );
}
