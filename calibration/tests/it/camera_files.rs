//! Camera files: every form round-trips exactly; OpenCV FileStorage text as OpenCV writes it is
//! read; errors name file:line and the field.

use fabkit_calibration::{parse_camera, write_camera, CameraFileFormat, Distortion, Intrinsics};

fn intr(d: Distortion) -> Intrinsics {
    Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 301.123456789012,
        fy_px: 300.0,
        cx_px: 319.5,
        cy_px: 241.25,
        distortion: d,
    }
}

fn all() -> Vec<Intrinsics> {
    vec![
        intr(Distortion::Fisheye([
            0.0312345678901234,
            -0.0123,
            1e-5,
            -3.3e-7,
        ])),
        intr(Distortion::PlumbBob([
            -0.26, 0.071, 0.0011, -0.00052, -0.0083,
        ])),
        intr(Distortion::RationalPolynomial([
            0.5, -0.1, 0.001, 0.002, 0.01, 0.8, -0.05, 0.02,
        ])),
    ]
}

#[test]
fn every_form_round_trips_exactly() {
    for i in all() {
        for f in [
            CameraFileFormat::OpenCvYaml,
            CameraFileFormat::RosYaml,
            CameraFileFormat::Json,
        ] {
            let text = write_camera(&i, f);
            let back = parse_camera(&text, "cam").unwrap_or_else(|e| panic!("{f:?}: {e}\n{text}"));
            assert_eq!(back.intrinsics(), &i, "{f:?}\n{text}");
            // Deterministic text.
            assert_eq!(write_camera(&i, f), text);
        }
    }
}

#[test]
fn opencv_form_is_written_as_opencv_writes_it() {
    let text = write_camera(&all()[0], CameraFileFormat::OpenCvYaml);
    assert!(text.starts_with("%YAML:1.0\n---\n"), "{text}");
    assert!(text.contains("camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 3.0112345678901198e+02, 0., 3.1950000000000000e+02, 0., 300.,"), "{text}");
    assert!(text.contains("distortion_model: fisheye\n"));
    assert!(text.contains("distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n"));
}

/// What cv2.calibrateCamera + cv2.FileStorage leave: no distortion_model, 1 x 5, extra keys.
const OPENCV_CALIBRATE_OUTPUT: &str = "%YAML:1.0
---
calibration_time: \"Thu 01 Feb 2024\"
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 3.0012000000000000e+02, 0., 3.2010000000000000e+02, 0.,
       2.9988000000000000e+02, 2.4030000000000000e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -2.6000000000000001e-01, 7.0000000000000007e-02,
       1.0000000000000000e-03, -5.0000000000000001e-04,
       -8.0000000000000002e-03 ]
avg_reprojection_error: 2.1000000000000001e-01
";

#[test]
fn opencv_calibrate_output_without_model_name_reads_as_plumb_bob() {
    let c = parse_camera(OPENCV_CALIBRATE_OUTPUT, "cal.yaml").unwrap();
    let i = c.intrinsics();
    assert_eq!(i.fx_px, 300.12);
    assert_eq!(i.cy_px, 240.3);
    assert_eq!(
        i.distortion,
        Distortion::PlumbBob([-0.26, 0.07, 0.001, -0.0005, -0.008])
    );
}

#[test]
fn ros_equidistant_reads_as_fisheye() {
    let text = "image_width: 640\nimage_height: 480\ncamera_name: cam\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [215, 0, 320, 0, 215, 240, 0, 0, 1]\ndistortion_model: equidistant\ndistortion_coefficients:\n  rows: 1\n  cols: 4\n  data: [0.1, 0.01, 0.001, 0.0001]\n";
    let c = parse_camera(text, "ros.yaml").unwrap();
    assert_eq!(
        c.intrinsics().distortion,
        Distortion::Fisheye([0.1, 0.01, 0.001, 0.0001])
    );
}

#[test]
fn errors_name_file_line_and_field() {
    let ok = write_camera(&all()[1], CameraFileFormat::OpenCvYaml);
    // Wrong coefficient count for the model.
    let bad = ok.replace("distortion_model: plumb_bob", "distortion_model: fisheye");
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with("cam.yaml:11: distortion_coefficients = [-0.26,"),
        "{e}"
    );
    assert!(e.contains("model 'fisheye' takes 4"), "{e}");
    // Unknown model.
    let bad = ok.replace("distortion_model: plumb_bob", "distortion_model: kb8");
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with("cam.yaml:10: distortion_model = kb8: unknown distortion model"),
        "{e}"
    );
    // rows x cols disagree with data.
    let bad = ok.replacen("   cols: 3", "   cols: 4", 1);
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with("cam.yaml:5: camera_matrix = rows 3 x cols 4 with 9 data values"),
        "{e}"
    );
    // Negative focal length.
    let bad = ok.replacen(
        "data: [ 3.0112345678901198e+02",
        "data: [ -3.0112345678901198e+02",
        1,
    );
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with("cam.yaml:5: fx_px = -301.123456789012: must be finite and > 0"),
        "{e}"
    );
    // YAML syntax: file:line:column.
    let bad = ok.replace("image_height: 480", "image_height: [480");
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert!(e.starts_with("cam.yaml:4:"), "{e}");
    // Missing key.
    let bad = ok.replace("image_width: 640\n", "");
    let e = parse_camera(&bad, "cam.yaml").unwrap_err().to_string();
    assert_eq!(e, "cam.yaml: image_width: missing (image width in px)");
    // JSON: unknown field with line and column.
    let j = write_camera(&all()[0], CameraFileFormat::Json).replace("\"fx_px\"", "\"fx\"");
    let e = parse_camera(&j, "cam.json").unwrap_err().to_string();
    assert!(
        e.starts_with("cam.json:6:6: ") && e.contains("unknown field `fx`"),
        "{e}"
    );
    // Four coefficients without a model are ambiguous.
    let bad = OPENCV_CALIBRATE_OUTPUT
        .replace("cols: 5", "cols: 4")
        .replace(",\n       -8.0000000000000002e-03", "");
    let e = parse_camera(&bad, "cal.yaml").unwrap_err().to_string();
    assert!(
        e.contains("distortion_coefficients = 4 values") && e.contains("add distortion_model"),
        "{e}"
    );
}
