//! OpenCV (opencv-python-headless, tests/oracles/opencv_project.py) as the oracle for the camera
//! models and the OpenCV FileStorage camera file: projection agrees to 1e-6 px over the field of
//! view (fisheye up to 89 deg off axis, where cv2.fisheye's z = 1 plane still holds), and
//! cv2.FileStorage reads back exactly what fabkit writes. OpenCV (tests/oracles/
//! opencv_camera_files.py) also writes the camera files users already have, in every layout
//! (YAML and XML; calibrateCamera's 5, 12 and 14 coefficients, cv2.fisheye.calibrate's 4 with and
//! without `fisheye_model: 1`), which fabkit reads to exactly OpenCV's numbers, and reads the
//! `extrinsics.yaml` fabkit writes.

use std::path::Path;

use crate::calibrate_cli::{extrinsics_args, intrinsics, json, observe, write_table};
use crate::common::{missing, oracle_python, repo_root, run, text};
use fabkit_calibration::nalgebra::Vector3;
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::{
    read_camera_file_as, write_camera, CameraFileError, CameraFileFormat, CameraModel, Distortion,
    DistortionModelHint, Intrinsics,
};

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
        // every other camera as XML
        let (file, format) = if k % 2 == 0 {
            (
                d.path().join(format!("cam{k}.xml")),
                CameraFileFormat::OpenCvXml,
            )
        } else {
            (
                d.path().join(format!("cam{k}.yaml")),
                CameraFileFormat::OpenCvYaml,
            )
        };
        std::fs::write(&file, write_camera(intr, format)).unwrap();
        // and fabkit reads its own file back to the same camera
        assert_eq!(
            fabkit_calibration::read_camera_file(&file)
                .unwrap()
                .intrinsics(),
            intr
        );
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

/// tests/oracles/opencv_camera_files.py with `args`: its JSON output.
fn camera_files_oracle(py: &Path, args: &[&std::ffi::OsStr]) -> serde_json::Value {
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/opencv_camera_files.py"))
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// 1-based line of the YAML key or XML element `key` in `text`.
fn line_of(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(&format!("{key}:")) || l.starts_with(&format!("<{key} ")))
        .unwrap()
        + 1
}

#[test]
fn camera_files_opencv_writes_in_every_layout_read_to_opencvs_numbers() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (opencv-python-headless)");
    };
    let d = tempfile::tempdir().unwrap();
    let res = camera_files_oracle(&py, &["write".as_ref(), d.path().as_os_str()]);
    let files = res["files"].as_array().unwrap();
    assert_eq!(files.len(), 12, "{res}");
    let prism_rule =
        "thin-prism and tilt coefficients s1..s4, tauX, tauY are not modelled, must be 0";
    let mut seen = Vec::new();
    for f in files {
        let name = f["name"].as_str().unwrap();
        let layout = f["layout"].as_str().unwrap();
        let path = d.path().join(name);
        let file_text = std::fs::read_to_string(&path).unwrap();
        let k: Vec<Vec<f64>> = f["K"].as_array().unwrap().iter().map(floats).collect();
        let dd = floats(&f["D"]);
        let opencv = |distortion| Intrinsics {
            image_width_px: f["width"].as_u64().unwrap() as u32,
            image_height_px: f["height"].as_u64().unwrap() as u32,
            fx_px: k[0][0],
            fy_px: k[1][1],
            cx_px: k[0][2],
            cy_px: k[1][2],
            distortion,
        };
        let read = |hint| read_camera_file_as(&path, hint).map(|c| *c.intrinsics());
        let at = |e: &CameraFileError| e.to_string();
        match layout {
            "plumb_bob_5" => {
                assert_eq!(dd.len(), 5);
                let want = opencv(Distortion::PlumbBob(dd[..5].try_into().unwrap()));
                assert_eq!(read(None).unwrap(), want, "{name}");
                assert_eq!(
                    read(Some(DistortionModelHint::PlumbBob)).unwrap(),
                    want,
                    "{name}"
                );
            }
            "rational_14" => {
                assert_eq!((dd.len(), &dd[8..]), (14, &[0.0; 6][..]), "{name}");
                let want = opencv(Distortion::RationalPolynomial(dd[..8].try_into().unwrap()));
                assert_eq!(read(None).unwrap(), want, "{name}");
                assert_eq!(
                    read(Some(DistortionModelHint::RationalPolynomial)).unwrap(),
                    want,
                    "{name}"
                );
            }
            "fisheye_4" => {
                assert_eq!(f["D_shape"], serde_json::json!([4, 1]));
                let want = opencv(Distortion::Fisheye(dd[..].try_into().unwrap()));
                assert_eq!(read(None).unwrap(), want, "{name}");
            }
            "fisheye_4_bare" => {
                let e = at(&read(None).unwrap_err());
                assert!(
                    e.starts_with(&format!(
                        "{}:{}: distortion_coefficients = 4 values",
                        path.display(),
                        line_of(&file_text, "distortion_coefficients")
                    )) && e.contains("`fisheye_model: 1`")
                        && e.contains("`--camera-model fisheye`"),
                    "{e}"
                );
                let want = opencv(Distortion::Fisheye(dd[..].try_into().unwrap()));
                assert_eq!(
                    read(Some(DistortionModelHint::Fisheye)).unwrap(),
                    want,
                    "{name}"
                );
            }
            "thin_prism_12" | "tilted_14" => {
                let nonzero: Vec<String> = dd[8..]
                    .iter()
                    .zip(["s1", "s2", "s3", "s4", "tauX", "tauY"])
                    .filter(|(v, _)| **v != 0.0)
                    .map(|(v, n)| format!("{n} = {v:?}"))
                    .collect();
                assert!(!nonzero.is_empty(), "{name}: {dd:?}");
                match read(None).unwrap_err() {
                    CameraFileError::Field {
                        file,
                        line,
                        field,
                        value,
                        rule,
                    } => {
                        assert_eq!(file, path.display().to_string());
                        assert_eq!(line, line_of(&file_text, "distortion_coefficients"));
                        assert_eq!(field, "distortion_coefficients");
                        assert_eq!(
                            value,
                            format!("{} values with {}", dd.len(), nonzero.join(", "))
                        );
                        assert!(rule.starts_with(prism_rule), "{rule}");
                    }
                    other => panic!("{name}: {other:?}"),
                }
            }
            other => panic!("unexpected layout {other}"),
        }
        seen.push(name.to_string());
    }
    seen.sort();
    let mut want: Vec<String> = [
        "fisheye_4",
        "fisheye_4_bare",
        "plumb_bob_5",
        "rational_14",
        "thin_prism_12",
        "tilted_14",
    ]
    .iter()
    .flat_map(|l| [format!("{l}.xml"), format!("{l}.yaml")])
    .collect();
    want.sort();
    assert_eq!(seen, want);
    eprintln!("camera files of OpenCV {} read", res["opencv_version"]);
}

/// `fabkit calibrate extrinsics` on cv2.fisheye.calibrate's files as OpenCV wrote them (XML with
/// `fisheye_model: 1`; YAML without a model name and `--camera-model fisheye`) solves the same
/// pose as with fabkit's own camera file; a contradicting `--camera-model` is refused.
#[test]
fn calibrate_extrinsics_reads_opencvs_fisheye_files() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (opencv-python-headless)");
    };
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    camera_files_oracle(&py, &["write".as_ref(), dir.as_os_str()]);
    std::fs::write(
        dir.join("cam.json"),
        write_camera(&intrinsics(), CameraFileFormat::Json),
    )
    .unwrap();
    write_table(&dir.join("pins.csv"));
    std::fs::write(dir.join("obs.csv"), observe(false, 0..29)).unwrap();
    let calibrate = |camera: &str, model: &[&str], out: &str| {
        run(dir, &extrinsics_args(camera, out, model), &[])
    };
    let o = calibrate("cam.json", &[], "ours");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let ours = json(&dir.join("ours/extrinsics.json"));
    for (camera, model, out) in [
        ("fisheye_4.xml", &[][..], "xml"),
        ("fisheye_4.yaml", &["--camera-model", "fisheye"][..], "yaml"),
        (
            "fisheye_4_bare.yaml",
            &["--camera-model", "fisheye"][..],
            "bare",
        ),
    ] {
        let o = calibrate(camera, model, out);
        assert!(o.status.success(), "{camera}: {}", text(&o.stderr));
        let j = json(&dir.join(out).join("extrinsics.json"));
        assert_eq!(j["distortion_model"], "fisheye");
        // OpenCV's intrinsics are the truth to 1e-12: the same pose.
        for key in ["rvec", "tvec_mm"] {
            for (a, b) in floats(&j[key]).iter().zip(floats(&ours[key])) {
                assert!((a - b).abs() < 1e-9, "{camera} {key}: {a} vs {b}");
            }
        }
    }
    let o = calibrate("fisheye_4.xml", &["--camera-model", "plumb_bob"], "out");
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("fisheye_4.xml:7: fisheye_model = 1: the file's fisheye_model: 1 contradicts --camera-model plumb_bob"),
        "{e}"
    );
    assert!(!dir.join("out").exists());
}

/// Issue 102: cv2.FileStorage reads the pose of `extrinsics.yaml` as OpenCV matrices
/// (`getNode("T_cam_sensor").mat()` is the 4 x 4 of extrinsics.json to 1e-12, `rvec` and
/// `tvec_mm` 3 x 1 float64), and its command line holding a newline (an `--out` folder named
/// with one); PyYAML reads it too with a constructor for the `opencv-matrix` tag. (A block
/// scalar, which serde-saphyr writes for multi-line strings, and an unindented sequence are
/// parse errors for OpenCV.) `transform.yaml` is a geometry_msgs/msg/TransformStamped that a
/// ROS message parser (rosbags' ROS 2 type store) builds and round-trips through CDR: camera
/// frame to sensor frame, the translation in metres and the rotation of T_cam_sensor.
#[test]
fn opencv_filestorage_reads_extrinsics_yaml_with_a_multi_line_command_line() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (opencv-python-headless)");
    };
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(
        dir.join("cam.yaml"),
        write_camera(&intrinsics(), CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    write_table(&dir.join("pins.csv"));
    std::fs::write(dir.join("obs.csv"), observe(false, 0..29)).unwrap();
    let out = "out\n  \"two\" \\ lines: # not a comment";
    let o = run(dir, &extrinsics_args("cam.yaml", out, &[]), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // (cv::FileStorage refuses such a path itself: read a copy.)
    let yaml = dir.join("extrinsics.yaml");
    std::fs::copy(dir.join(out).join("extrinsics.yaml"), &yaml).unwrap();
    let written = std::fs::read_to_string(&yaml).unwrap();
    assert!(written.starts_with("%YAML:1.0\n---\n"), "{written}");
    assert!(
        written.contains("\nT_cam_sensor: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n"),
        "{written}"
    );
    let j = json(&dir.join(out).join("extrinsics.json"));
    let cv = camera_files_oracle(&py, &["read-extrinsics".as_ref(), yaml.as_os_str()]);
    let close = |a: &[f64], b: &[f64], what: &str| {
        assert_eq!(a.len(), b.len(), "{what}");
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-12, "{what}: {a:?} against {b:?}");
        }
    };
    for key in ["rvec", "tvec_mm"] {
        assert_eq!(cv["shapes"][key], serde_json::json!([3, 1]), "{key}");
        assert_eq!(cv["dtypes"][key], "float64", "{key}");
        let column: Vec<f64> = cv[key]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(floats)
            .collect();
        close(&column, &floats(&j[key]), key);
    }
    assert_eq!(cv["shapes"]["T_cam_sensor"], serde_json::json!([4, 4]));
    for i in 0..4 {
        close(
            &floats(&cv["T_cam_sensor"][i]),
            &floats(&j["T_cam_sensor"][i]),
            "T_cam_sensor",
        );
        close(
            &floats(&cv["pyyaml_T_cam_sensor"][i]),
            &floats(&j["T_cam_sensor"][i]),
            "T_cam_sensor (PyYAML)",
        );
    }
    assert_eq!(
        cv["rms_reprojection_error_px"].as_f64(),
        j["rms_reprojection_error_px"].as_f64()
    );
    let command_line = j["provenance"]["command_line"].as_str().unwrap();
    assert!(
        command_line.ends_with(&format!("--out {out}")),
        "{command_line}"
    );
    assert_eq!(cv["command_line"], command_line);
    assert_eq!(cv["pyyaml_command_line"], command_line);

    // transform.yaml: a TransformStamped by a ROS message parser, the pose of T_cam_sensor
    let o = std::process::Command::new(&py)
        .arg(repo_root().join("tests/oracles/ros_messages.py"))
        .arg("geometry_msgs/msg/TransformStamped")
        .arg(dir.join(out).join("transform.yaml"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let msg: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(msg["header"]["frame_id"], "camera_optical_frame", "{msg}");
    assert_eq!(msg["child_frame_id"], "sensor", "{msg}");
    let t = &msg["transform"]["translation"];
    let r = &msg["transform"]["rotation"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let q = fabkit_calibration::nalgebra::UnitQuaternion::from_quaternion(
        fabkit_calibration::nalgebra::Quaternion::new(
            f(&r["w"]),
            f(&r["x"]),
            f(&r["y"]),
            f(&r["z"]),
        ),
    );
    let m = q.to_rotation_matrix();
    for i in 0..3 {
        for k in 0..3 {
            let want = j["T_cam_sensor"][i][k].as_f64().unwrap();
            assert!(
                (m[(i, k)] - want).abs() < 1e-12,
                "R[{i}][{k}] {} against {want}",
                m[(i, k)]
            );
        }
    }
    for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
        let want_m = j["T_cam_sensor"][i][3].as_f64().unwrap() / 1000.0;
        assert!((f(&t[axis]) - want_m).abs() < 1e-15, "translation {axis}");
    }
    // the quaternion is a unit one, as ROS wants it
    let n: f64 = ["x", "y", "z", "w"].iter().map(|a| f(&r[*a]).powi(2)).sum();
    assert!((n - 1.0).abs() < 1e-12, "|q|^2 = {n}");
}
