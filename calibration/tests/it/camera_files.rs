//! Camera files: every form round-trips exactly; OpenCV FileStorage text as OpenCV writes it is
//! read; errors name file:line and the field.

use fabkit_calibration::{
    parse_camera, parse_camera_as, write_camera, CameraFileError, CameraFileFormat, Distortion,
    DistortionModelHint as Hint, Intrinsics,
};

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

/// Calibration scripts' spellings of the matrices (`fs.write("K", K)`, `cameraMatrix` and
/// `distCoeffs` as OpenCV's functions name them) read as the OpenCV keys, in YAML and XML; an
/// error in one names its line; a file with neither spelling names them all.
#[test]
fn common_spellings_of_the_matrices_read_as_the_opencv_keys() {
    let want = parse_camera(OPENCV_CALIBRATE_OUTPUT, "cal.yaml").unwrap();
    for (k, d) in [
        ("K", "D"),
        ("cameraMatrix", "distCoeffs"),
        ("K", "dist_coeffs"),
    ] {
        let yaml = OPENCV_CALIBRATE_OUTPUT
            .replace("camera_matrix:", &format!("{k}:"))
            .replace("distortion_coefficients:", &format!("{d}:"));
        assert_eq!(
            parse_camera(&yaml, "k.yaml").unwrap().intrinsics(),
            want.intrinsics(),
            "{k} {d}"
        );
        let xml = OPENCV_XML
            .replace("camera_matrix", k)
            .replace("distortion_coefficients", d);
        assert_eq!(
            parse_camera(&xml, "k.xml").unwrap().intrinsics(),
            want.intrinsics(),
            "{k} {d}"
        );
    }
    // an error under another spelling names its line
    let bad = OPENCV_CALIBRATE_OUTPUT
        .replace("camera_matrix:", "K:")
        .replace("rows: 3", "rows: 2");
    let e = parse_camera(&bad, "k.yaml").unwrap_err().to_string();
    let line = bad.lines().position(|l| l.starts_with("K:")).unwrap() + 1;
    assert!(
        e.starts_with(&format!("k.yaml:{line}: camera_matrix")),
        "{e}"
    );
    let none = OPENCV_CALIBRATE_OUTPUT.replace("camera_matrix:", "intrinsics:");
    let e = parse_camera(&none, "n.yaml").unwrap_err().to_string();
    assert!(
        e.contains("camera_matrix: missing")
            && e.contains("read as camera_matrix, K, k or cameraMatrix"),
        "{e}"
    );
}

/// The camera of `text` projects a grid of camera-frame points where the canonical file's does.
fn same_projections(a: &fabkit_calibration::CameraModel, b: &fabkit_calibration::CameraModel) {
    for x in [-0.4, 0.0, 0.3] {
        for y in [-0.3, 0.0, 0.25] {
            let p = fabkit_calibration::nalgebra::Vector3::new(x, y, 1.0);
            assert_eq!(a.project(&p), b.project(&p), "{p:?}");
        }
    }
}

/// Issue 102: every spelling of the matrices that calibration scripts and ROS write (`K`/`D`,
/// ROS 2's `k`/`d`, `cameraMatrix`/`distCoeffs`; `width`/`height` of the CameraInfo message),
/// as an opencv-matrix, a plain list of 9 numbers or 3 rows, in YAML and JSON, reads as the
/// same camera as the canonical OpenCV file (same intrinsics, same projections), and says
/// which keys were read.
#[test]
fn every_spelling_and_list_form_reads_as_the_canonical_camera() {
    use fabkit_calibration::camera_file::parse_camera_keys;
    let want = parse_camera_keys(OPENCV_CALIBRATE_OUTPUT, "cal.yaml", None).unwrap();
    assert_eq!(
        want.keys_read.to_string(),
        "camera_matrix (intrinsics), distortion_coefficients (distortion)"
    );
    let k = "300.12, 0, 320.1, 0, 299.88, 240.3, 0, 0, 1";
    let k_rows = "[300.12, 0, 320.1], [0, 299.88, 240.3], [0, 0, 1]";
    let d = "-0.26, 0.07, 0.001, -0.0005, -0.008";
    for (kk, dk, size) in [
        (
            "camera_matrix",
            "distortion_coefficients",
            ("image_width", "image_height"),
        ),
        ("K", "D", ("width", "height")),
        ("k", "d", ("width", "height")),
        (
            "cameraMatrix",
            "distCoeffs",
            ("image_width", "image_height"),
        ),
        ("K", "dist_coeffs", ("image_width", "image_height")),
    ] {
        let (w, h) = size;
        let texts = [
            // opencv-matrix under the spelling
            OPENCV_CALIBRATE_OUTPUT
                .replace("camera_matrix:", &format!("{kk}:"))
                .replace("distortion_coefficients:", &format!("{dk}:"))
                .replace("image_width:", &format!("{w}:"))
                .replace("image_height:", &format!("{h}:")),
            // plain lists, as ROS 1 `rostopic echo` and ROS 2 `ros2 topic echo` print CameraInfo
            format!("header:\n  frame_id: cam\n{h}: 480\n{w}: 640\ndistortion_model: plumb_bob\n{dk}: [{d}]\n{kk}: [{k}]\nr: [1, 0, 0, 0, 1, 0, 0, 0, 1]\nroi:\n  height: 0\n  width: 0\n"),
            // 3 rows, as numpy's tolist() writes K
            format!("{w}: 640\n{h}: 480\n{kk}:\n  - [{k_rows_0}]\n  - [{k_rows_1}]\n  - [{k_rows_2}]\n{dk}: [[{d}]]\n", k_rows_0 = "300.12, 0, 320.1", k_rows_1 = "0, 299.88, 240.3", k_rows_2 = "0, 0, 1"),
            // JSON with the same keys (json.dump of numpy's tolist())
            format!("{{\"{w}\": 640, \"{h}\": 480,\n \"{kk}\": [{k_rows}],\n \"{dk}\": [{d}]}}\n"),
        ];
        for text in &texts {
            let got = parse_camera_keys(text, "k.yaml", None)
                .unwrap_or_else(|e| panic!("{kk} {dk}: {e}\n{text}"));
            assert_eq!(got.camera.intrinsics(), want.camera.intrinsics(), "{text}");
            same_projections(&got.camera, &want.camera);
            assert_eq!(
                got.keys_read.to_string(),
                format!("{kk} (intrinsics), {dk} (distortion)")
            );
        }
    }
}

/// Issue 102: two spellings of one quantity in a file (YAML, XML, JSON) are refused naming
/// both keys, at the second one's line; a file with neither spelling lists them all.
#[test]
fn two_spellings_of_one_matrix_are_refused_naming_both() {
    let both = OPENCV_CALIBRATE_OUTPUT.replace(
        "avg_reprojection_error",
        "K: [300, 0, 320, 0, 300, 240, 0, 0, 1]\navg_reprojection_error",
    );
    let line = both.lines().position(|l| l.starts_with("K:")).unwrap() + 1;
    let e = parse_camera(&both, "two.yaml").unwrap_err().to_string();
    assert_eq!(
        e,
        format!("two.yaml:{line}: camera_matrix = camera_matrix and K: the file gives camera_matrix twice, spelled camera_matrix and K: keep one")
    );
    let both = OPENCV_CALIBRATE_OUTPUT.replace(
        "avg_reprojection_error",
        "distCoeffs: [0, 0, 0, 0, 0]\navg_reprojection_error",
    );
    let e = parse_camera(&both, "two.yaml").unwrap_err().to_string();
    assert!(
        e.contains("distortion_coefficients = distortion_coefficients and distCoeffs"),
        "{e}"
    );
    let xml = OPENCV_XML.replace(
        "<avg_reprojection_error>",
        "<D type_id=\"opencv-matrix\"><rows>1</rows><cols>5</cols><dt>d</dt><data>0 0 0 0 0</data></D>\n<avg_reprojection_error>",
    );
    let e = parse_camera(&xml, "two.xml").unwrap_err().to_string();
    assert!(
        e.starts_with("two.xml:")
            && e.contains("distortion_coefficients = distortion_coefficients and D"),
        "{e}"
    );
    let json = "{\"width\": 640, \"image_width\": 640, \"height\": 480, \"K\": [1, 0, 1, 0, 1, 1, 0, 0, 1], \"D\": [0, 0, 0, 0, 0]}";
    let e = parse_camera(json, "two.json").unwrap_err().to_string();
    assert!(
        e.starts_with("two.json:1: image_width = image_width and width"),
        "{e}"
    );
    // none of the spellings: the error lists them
    let none = OPENCV_CALIBRATE_OUTPUT.replace("distortion_coefficients:", "distortion:");
    let e = parse_camera(&none, "n.yaml").unwrap_err().to_string();
    assert!(
        e.contains("distortion_coefficients: missing")
            && e.contains("read as distortion_coefficients, D, d, distCoeffs or dist_coeffs"),
        "{e}"
    );
    // a plain list of the wrong length names the spelling's line
    let short = "width: 640\nheight: 480\nK: [1, 2, 3]\nD: [0, 0, 0, 0, 0]\n";
    let e = parse_camera(short, "s.yaml").unwrap_err().to_string();
    assert_eq!(e, "s.yaml:3: camera_matrix = a list of 3 numbers: must be 9 numbers (row-major) or 3 rows of 3");
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
    assert_eq!(
        e,
        "cam.yaml: image_width: missing (image width in px; also read as width)"
    );
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
        e.starts_with("cal.yaml:12: distortion_coefficients = 4 values")
            && e.contains("`fisheye_model: 1`")
            && e.contains("`--camera-model fisheye`"),
        "{e}"
    );
}

/// What OpenCV's camera_calibration sample writes for `cv::fisheye` (Settings `Calibrate_UseFisheyeModel`):
/// no distortion_model, `fisheye_model: 1`, D as 4 x 1.
const OPENCV_FISHEYE_SAMPLE_OUTPUT: &str = "%YAML:1.0
---
calibration_time: \"Thu 01 Feb 2024\"
nr_of_frames: 25
image_width: 640
image_height: 480
board_width: 9
board_height: 6
square_size: 50.
flags: 0
fisheye_model: 1
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 2.1500000000000000e+02, 0., 3.2200000000000000e+02, 0.,
       2.1450000000000000e+02, 2.3800000000000000e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 4
   cols: 1
   dt: d
   data: [ -2.0000000000000000e-02, 4.0000000000000001e-03,
       -1.5000000000000000e-03, 2.0000000000000001e-04 ]
avg_reprojection_error: 2.1000000000000001e-01
";

const FISHEYE_K: [f64; 4] = [-0.02, 0.004, -0.0015, 0.0002];

#[test]
fn fisheye_model_key_of_the_opencv_sample_reads_four_coefficients_as_fisheye() {
    let c = parse_camera(OPENCV_FISHEYE_SAMPLE_OUTPUT, "sample.yaml").unwrap();
    assert_eq!(c.intrinsics().distortion, Distortion::Fisheye(FISHEYE_K));
    assert_eq!(c.intrinsics().fx_px, 215.0);
    // fisheye_model: 0 (the sample's pinhole case): 4 coefficients are k1, k2, p1, p2.
    let pinhole = OPENCV_FISHEYE_SAMPLE_OUTPUT.replace("fisheye_model: 1", "fisheye_model: 0");
    assert_eq!(
        parse_camera(&pinhole, "sample.yaml")
            .unwrap()
            .intrinsics()
            .distortion,
        Distortion::PlumbBob([-0.02, 0.004, -0.0015, 0.0002, 0.0])
    );
    // The key with a model name that agrees is fine; one that disagrees is an error.
    let named = OPENCV_FISHEYE_SAMPLE_OUTPUT.replace(
        "fisheye_model: 1\n",
        "fisheye_model: 1\ndistortion_model: equidistant\n",
    );
    assert_eq!(
        parse_camera(&named, "s.yaml")
            .unwrap()
            .intrinsics()
            .distortion,
        Distortion::Fisheye(FISHEYE_K)
    );
    let e = parse_camera(&named.replace("equidistant", "plumb_bob"), "s.yaml")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "s.yaml:11: fisheye_model = 1: contradicts the file's distortion_model: plumb_bob"
    );
    // Only 0 or 1.
    let e = parse_camera(
        &OPENCV_FISHEYE_SAMPLE_OUTPUT.replace("fisheye_model: 1", "fisheye_model: 2"),
        "s.yaml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("s.yaml:11: fisheye_model = 2: must be 0 or 1"),
        "{e}"
    );
    // fisheye_model: 1 with 5 coefficients: the count error says where the model came from.
    let five = OPENCV_CALIBRATE_OUTPUT.replace("image_width", "fisheye_model: 1\nimage_width");
    let e = parse_camera(&five, "s.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with("s.yaml:13: distortion_coefficients = [-0.26,")
            && e.contains("model 'fisheye' takes 4")
            && e.contains("the model is from fisheye_model: 1"),
        "{e}"
    );
}

/// cv2.fisheye.calibrate's D written with cv2.FileStorage: 4 x 1, no model name.
fn fisheye_without_name() -> String {
    OPENCV_FISHEYE_SAMPLE_OUTPUT.replace("fisheye_model: 1\n", "")
}

#[test]
fn model_hint_reads_a_file_that_names_no_model() {
    let text = fisheye_without_name();
    assert!(parse_camera(&text, "cam.yaml").is_err());
    let c = parse_camera_as(&text, "cam.yaml", Some(Hint::Fisheye)).unwrap();
    assert_eq!(c.intrinsics().distortion, Distortion::Fisheye(FISHEYE_K));
    let c = parse_camera_as(&text, "cam.yaml", Some(Hint::PlumbBob)).unwrap();
    assert_eq!(
        c.intrinsics().distortion,
        Distortion::PlumbBob([-0.02, 0.004, -0.0015, 0.0002, 0.0])
    );
    // A hint that agrees with the file's own name (ROS `equidistant`) changes nothing.
    let ros = write_camera(&all()[0], CameraFileFormat::RosYaml);
    assert!(ros.contains("distortion_model: equidistant"));
    assert_eq!(
        parse_camera_as(&ros, "ros.yaml", Some(Hint::Fisheye))
            .unwrap()
            .intrinsics(),
        &all()[0]
    );
    // The hint does not override a coefficient count: 5 values are not fisheye.
    let e = parse_camera_as(OPENCV_CALIBRATE_OUTPUT, "cal.yaml", Some(Hint::Fisheye))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("cal.yaml:12: distortion_coefficients = [-0.26,")
            && e.contains("5 coefficients: model 'fisheye' takes 4")
            && e.contains("the model is from --camera-model fisheye"),
        "{e}"
    );
    let e = parse_camera_as(
        OPENCV_CALIBRATE_OUTPUT,
        "cal.yaml",
        Some(Hint::RationalPolynomial),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("model 'rational_polynomial' takes 8"), "{e}");
}

#[test]
fn model_hint_that_contradicts_the_file_names_both() {
    let plumb = write_camera(&all()[1], CameraFileFormat::OpenCvYaml);
    let e = parse_camera_as(&plumb, "cam.yaml", Some(Hint::Fisheye)).unwrap_err();
    match &e {
        CameraFileError::Field {
            file,
            line,
            field,
            value,
            ..
        } => assert_eq!(
            (file.as_str(), *line, field.as_str(), value.as_str()),
            ("cam.yaml", 10, "distortion_model", "plumb_bob")
        ),
        other => panic!("{other:?}"),
    }
    let e = e.to_string();
    assert!(
        e.contains("--camera-model fisheye") && e.contains("give --camera-model plumb_bob"),
        "{e}"
    );
    // fisheye_model: 1 against a pinhole hint.
    let e = parse_camera_as(OPENCV_FISHEYE_SAMPLE_OUTPUT, "s.yaml", Some(Hint::PlumbBob))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("s.yaml:11: fisheye_model = 1: the file's fisheye_model: 1 contradicts --camera-model plumb_bob"),
        "{e}"
    );
    // The JSON form always names its model.
    let j = write_camera(&all()[2], CameraFileFormat::Json);
    let e = parse_camera_as(&j, "cam.json", Some(Hint::PlumbBob))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("cam.json:3: distortion_model = rational_polynomial: ")
            && e.contains("--camera-model plumb_bob"),
        "{e}"
    );
}

/// `cv2.calibrateCamera(..., flags=cv2.CALIB_RATIONAL_MODEL)` in OpenCV 5 returns D as 1 x 14
/// (k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tauX tauY); written by cv2.FileStorage.
const OPENCV_RATIONAL_14: &str = "%YAML 1.2
---
calibration_time: Thu 01 Feb 2024
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 299.99996577805354, 0., 319.99996233788482, 0.,
       299.99996050416121, 239.99998916883675, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 14
   dt: d
   data: [ -0.077330799632288852, -0.1011988593255983,
       0.00099999357915455506, -0.0005000148599361594,
       0.023831349686126158, 0.22266879018921973, -0.10437941172205673,
       -0.027302944192948462, 0., 0., 0., 0., 0., 0. ]
avg_reprojection_error: 9.9964626221629396e-06
";

const RATIONAL_8: [f64; 8] = [
    -0.07733079963228885,
    -0.1011988593255983,
    0.000999993579154555,
    -0.0005000148599361594,
    0.023831349686126158,
    0.22266879018921973,
    -0.10437941172205673,
    -0.027302944192948462,
];

#[test]
fn rational_model_14_or_12_coefficients_with_zero_extras_read_as_the_8_coefficient_file() {
    let eight = OPENCV_RATIONAL_14
        .replace("cols: 14", "cols: 8")
        .replace(", 0., 0., 0., 0., 0., 0. ]", " ]");
    let want = parse_camera(&eight, "r8.yaml").unwrap();
    assert_eq!(
        want.intrinsics().distortion,
        Distortion::RationalPolynomial(RATIONAL_8)
    );
    let twelve = OPENCV_RATIONAL_14
        .replace("cols: 14", "cols: 12")
        .replace(", 0., 0., 0., 0., 0., 0. ]", ", 0., 0., 0., 0. ]");
    for (text, hint) in [
        (OPENCV_RATIONAL_14.to_string(), None),
        (
            OPENCV_RATIONAL_14.to_string(),
            Some(Hint::RationalPolynomial),
        ),
        (
            OPENCV_RATIONAL_14.replace(
                "image_width",
                "distortion_model: rational_polynomial\nimage_width",
            ),
            None,
        ),
        (twelve, None),
    ] {
        let c = parse_camera_as(&text, "r.yaml", hint).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(c.intrinsics(), want.intrinsics(), "{text}");
    }
    // 14 values are not a plumb_bob's.
    let e = parse_camera_as(OPENCV_RATIONAL_14, "r.yaml", Some(Hint::PlumbBob))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("14 coefficients: model 'plumb_bob' takes 5"),
        "{e}"
    );
}

#[test]
fn nonzero_thin_prism_or_tilt_coefficients_are_a_named_error() {
    let rule = "thin-prism and tilt coefficients s1..s4, tauX, tauY are not modelled, must be 0";
    let tilted = OPENCV_RATIONAL_14.replace(", 0., 0. ]", ", 1.5e-3, 0. ]");
    let prism12 = OPENCV_RATIONAL_14
        .replace("cols: 14", "cols: 12")
        .replace(", 0., 0., 0., 0., 0., 0. ]", ", -2.2e-8, 0., 7.9e-7, 0. ]");
    for (text, want_value) in [
        (tilted, "14 values with tauX = 0.0015"),
        (prism12, "12 values with s1 = -2.2e-8, s3 = 7.9e-7"),
    ] {
        match parse_camera(&text, "r.yaml").unwrap_err() {
            CameraFileError::Field {
                file,
                line,
                field,
                value,
                rule: r,
            } => {
                assert_eq!(
                    (file.as_str(), line, field.as_str(), value.as_str()),
                    ("r.yaml", 12, "distortion_coefficients", want_value)
                );
                assert!(r.starts_with(rule), "{r}");
            }
            other => panic!("{other:?}"),
        }
    }
}

/// The OpenCV FileStorage XML twin of [`OPENCV_CALIBRATE_OUTPUT`] as cv2.FileStorage writes it
/// (plus a comment and an entity in a string).
const OPENCV_XML: &str = "<?xml version=\"1.0\"?>
<opencv_storage>
<calibration_time>\"Thu 01 Feb 2024 &amp; later\"</calibration_time>
<image_width>640</image_width>
<image_height>480</image_height>
<!-- flags: +fix_k3 -->
<camera_matrix type_id=\"opencv-matrix\">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    3.0012000000000000e+02 0. 3.2010000000000000e+02 0.
    2.9988000000000000e+02 2.4030000000000000e+02 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id=\"opencv-matrix\">
  <rows>1</rows>
  <cols>5</cols>
  <dt>d</dt>
  <data>
    -2.6000000000000001e-01 7.0000000000000007e-02 1.0000000000000000e-03
    -5.0000000000000001e-04 -8.0000000000000002e-03</data></distortion_coefficients>
<avg_reprojection_error>2.1000000000000001e-01</avg_reprojection_error>
</opencv_storage>
";

#[test]
fn opencv_xml_reads_as_the_yaml_form() {
    let yaml = parse_camera(OPENCV_CALIBRATE_OUTPUT, "cal.yaml").unwrap();
    let xml = parse_camera(OPENCV_XML, "cal.xml").unwrap();
    assert_eq!(xml.intrinsics(), yaml.intrinsics());
    // Fisheye: fisheye_model 1 or distortion_model, and the hint, as in YAML.
    let fisheye = OPENCV_XML
        .replace("<cols>5</cols>", "<cols>4</cols>")
        .replace(" -8.0000000000000002e-03", "");
    let e = parse_camera(&fisheye, "f.xml").unwrap_err().to_string();
    assert!(
        e.starts_with("f.xml:14: distortion_coefficients = 4 values"),
        "{e}"
    );
    let want = Distortion::Fisheye([-0.26, 0.07, 0.001, -0.0005]);
    for (text, hint) in [
        (
            fisheye.replace(
                "<image_width>",
                "<fisheye_model>1</fisheye_model>\n<image_width>",
            ),
            None,
        ),
        (
            fisheye.replace(
                "<image_width>",
                "<distortion_model>fisheye</distortion_model><image_width>",
            ),
            None,
        ),
        (fisheye.clone(), Some(Hint::Fisheye)),
    ] {
        let c = parse_camera_as(&text, "f.xml", hint).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(c.intrinsics().distortion, want);
    }
    // A model name in double quotes (OpenCV quotes strings with spaces or punctuation).
    let quoted = OPENCV_XML.replace(
        "<image_width>",
        "<distortion_model>\"plumb_bob\"</distortion_model>\n<image_width>",
    );
    assert_eq!(
        parse_camera(&quoted, "q.xml").unwrap().intrinsics(),
        yaml.intrinsics()
    );
}

#[test]
fn xml_errors_name_file_and_line() {
    let err = |text: &str| parse_camera(text, "cal.xml").unwrap_err().to_string();
    // Not well-formed: file:line:column.
    let e = err(&OPENCV_XML.replace("</image_height>", "</image_width>"));
    assert!(
        e.starts_with("cal.xml:5:18: ") && e.contains("expected `</image_height>`"),
        "{e}"
    );
    let e = err(&OPENCV_XML.replace("</opencv_storage>\n", ""));
    assert_eq!(e, "cal.xml:22:1: <opencv_storage> is not closed");
    // rows x cols disagree with data.
    let e = err(&OPENCV_XML.replacen("<cols>3</cols>", "<cols>4</cols>", 1));
    assert_eq!(
        e,
        "cal.xml:7: camera_matrix = rows 3 x cols 4 with 9 data values: rows x cols must equal the number of data values"
    );
    // A value that is not a number: the line of <data>.
    let e = err(&OPENCV_XML.replace("3.2010000000000000e+02", "3.2010000000000000e+O2"));
    assert_eq!(
        e,
        "cal.xml:11: camera_matrix.data = 3.2010000000000000e+O2: must be numbers separated by white space"
    );
    let e = err(&OPENCV_XML.replace("<image_width>640<", "<image_width>640 px<"));
    assert_eq!(e, "cal.xml:4: image_width = 640 px: must be a whole number");
    // Negative focal length (checked by the camera model): the line of <camera_matrix>.
    let e = err(&OPENCV_XML.replace("3.0012000000000000e+02 0.", "-3.0012000000000000e+02 0."));
    assert!(
        e.starts_with("cal.xml:7: fx_px = -300.12: must be finite and > 0"),
        "{e}"
    );
    // An unknown model, a missing key, a key given twice, another root.
    let e = err(&OPENCV_XML.replace(
        "<image_width>",
        "<distortion_model>kb8</distortion_model>\n<image_width>",
    ));
    assert!(
        e.starts_with("cal.xml:4: distortion_model = kb8: unknown distortion model"),
        "{e}"
    );
    let e = err(&OPENCV_XML.replace("<image_height>480</image_height>\n", ""));
    assert_eq!(
        e,
        "cal.xml: image_height: missing (image height in px; also read as height)"
    );
    let e = err(&OPENCV_XML.replace(
        "<image_height>480</image_height>\n",
        "<image_width>640</image_width>\n",
    ));
    assert!(
        e.starts_with("cal.xml:5: image_width = given twice: must be given once (first on line 4)"),
        "{e}"
    );
    let e = err(&OPENCV_XML.replace("opencv_storage>", "storage>"));

    assert!(
        e.starts_with("cal.xml:2: root element = <storage>: must be <opencv_storage>"),
        "{e}"
    );
}

/// Every JSON file a user may have written (an editor's "UTF-8 with BOM"): extrinsics.json, a
/// JSON camera file and the fixtures' protrusion index read as the same file without the byte
/// order mark (extrinsics.json was refused with "expected value at line 1 column 1").
#[test]
fn json_inputs_with_a_byte_order_mark_read_as_without() {
    use fabkit_calibration::groundtruth::inputs::{read_extrinsics, read_fixtures};
    let d = tempfile::tempdir().unwrap();
    let ext = r#"{"rvec": [0.02, -0.015, 0.4], "tvec_mm": [0.3, -0.2, 10.4]}"#;
    std::fs::write(d.path().join("plain.json"), ext).unwrap();
    std::fs::write(d.path().join("bom.json"), format!("\u{feff}{ext}")).unwrap();
    let (plain, _) = read_extrinsics(&d.path().join("plain.json")).unwrap();
    let (bom, _) = read_extrinsics(&d.path().join("bom.json")).unwrap();
    assert_eq!(plain, bom);
    for i in all() {
        let j = write_camera(&i, CameraFileFormat::Json);
        let cam = parse_camera(&format!("\u{feff}{j}"), "cam.json").unwrap();
        assert_eq!(*cam.intrinsics(), i);
        std::fs::write(d.path().join("cam.json"), format!("\u{feff}{j}")).unwrap();
        let cam = fabkit_calibration::read_camera_file(&d.path().join("cam.json")).unwrap();
        assert_eq!(*cam.intrinsics(), i);
    }
    // an empty protrusion index with a BOM reads (an error past the BOM would name line 1)
    std::fs::create_dir_all(d.path().join("fx/protrusions")).unwrap();
    std::fs::write(
        d.path().join("fx/protrusions/index.json"),
        "\u{feff}{\"patterns\": []}",
    )
    .unwrap();
    let f = read_fixtures(&d.path().join("fx"), "rtac0").unwrap();
    assert!(f.configurations.is_empty());
}
