//! The nominal camera a design places (`fabkit calibrate nominal`): the lens's view angle
//! spans the image's short side through the ideal equidistant fisheye, the pose puts the centre
//! of projection at the lens's front on the sensor's axis, and the files read back as the
//! camera file and extrinsics the other commands take, with the design's optical path.

use fabkit_calibration::camera_file::read_camera_file;
use fabkit_calibration::groundtruth::inputs::{read_extrinsics, read_optical_path};
use fabkit_calibration::nalgebra::{Point3, Vector3};
use fabkit_calibration::nominal::{nominal_camera, nominal_files, NominalError};
use fabkit_designs::library;

#[test]
fn rtac0s_lens_sees_its_view_across_the_short_side_from_its_front() {
    let design = library::load("rtac0").unwrap();
    let n = nominal_camera(&design, 640, 480, None).unwrap();
    // R-Tac0: a 160 deg lens (Sec. III-B3), its front 8.4 mm under the gel's surface (z = -17.4)
    assert_eq!(n.view_angle_deg, 160.0);
    assert!(
        (n.lens.front_z_mm + 17.4).abs() < 1e-9,
        "{}",
        n.lens.front_z_mm
    );
    let camera = fabkit_calibration::CameraModel::new(n.intrinsics.clone()).unwrap();
    // a ray 80 deg off the axis, in the camera frame, lands on the short side's edge: 240 px
    // from the principal point (319.5, 239.5); 40 deg lands halfway (equidistant)
    for (deg, r_px) in [(80.0f64, 240.0), (40.0, 120.0)] {
        let t = deg.to_radians();
        let uv = camera
            .project(&Vector3::new(t.sin(), 0.0, t.cos()))
            .unwrap();
        assert!((uv[0] - 319.5 - r_px).abs() < 1e-9, "{deg}: {uv}");
        assert!((uv[1] - 239.5).abs() < 1e-9, "{deg}: {uv}");
    }
    // the sensor's point on the axis ahead of the lens is ahead of the camera, on its axis
    let p = n.t_cam_sensor * Point3::new(0.0, 0.0, 0.0);
    assert!((p - Point3::new(0.0, 0.0, 17.4)).norm() < 1e-9, "{p}");
    // the optical path is the design's: the gel's free surface at the tube's mouth first
    let path = fabkit_designs::optics::optical_path_of_design(&design, Default::default()).unwrap();
    assert_eq!(n.optical_path, path);
    assert!((path.planes[0].z_mm + 9.0).abs() < 1e-9);
}

#[test]
fn the_files_read_back_as_a_camera_file_and_extrinsics_with_the_optical_path() {
    let design = library::load("rtac0").unwrap();
    let n = nominal_camera(&design, 800, 600, Some(150.0)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in nominal_files(&n, "fabkit calibrate nominal rtac0").unwrap() {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let cam = read_camera_file(&dir.path().join("camera.yaml")).unwrap();
    assert_eq!(cam.intrinsics(), &n.intrinsics);
    // 150 deg across 600 px: f = 300 / 75 deg in rad
    assert!((n.intrinsics.fx_px - 300.0 / 75f64.to_radians()).abs() < 1e-9);
    let (pose, _) = read_extrinsics(&dir.path().join("extrinsics.json")).unwrap();
    assert!((pose.translation.vector - Vector3::new(0.0, 0.0, 17.4)).norm() < 1e-12);
    assert!(pose.rotation.angle() < 1e-12);
    let (layers, used) = read_optical_path(&dir.path().join("extrinsics.json"))
        .unwrap()
        .expect("the design's optical path is in the file");
    assert_eq!(
        used["planes"].as_array().unwrap().len(),
        n.optical_path.planes.len()
    );
    drop(layers);
    let text = std::fs::read_to_string(dir.path().join("extrinsics.json")).unwrap();
    assert!(text.contains("not a calibration"), "{text}");
}

#[test]
fn bad_sizes_angles_and_a_design_without_a_view_angle_are_refused_by_option() {
    let rtac0 = library::load("rtac0").unwrap();
    let e = nominal_camera(&rtac0, 1, 480, None).unwrap_err();
    assert_eq!(e.to_string(), "--width-px = 1: must be 2 to 16384 px");
    let e = nominal_camera(&rtac0, 640, 20000, None).unwrap_err();
    assert_eq!(e.to_string(), "--height-px = 20000: must be 2 to 16384 px");
    for bad in [0.0, -10.0, 360.0, f64::NAN] {
        let e = nominal_camera(&rtac0, 640, 480, Some(bad)).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("--view-angle-deg = {bad}: must be above 0")),
            "{e}"
        );
    }
    // ShadowTac's casing gives the lens's height but no view angle
    let shadowtac = library::load("shadowtac").unwrap();
    let e = nominal_camera(&shadowtac, 640, 480, None).unwrap_err();
    assert!(matches!(e, NominalError::NoViewAngle { .. }), "{e}");
    assert!(e.to_string().ends_with("give --view-angle-deg"), "{e}");
    assert!(nominal_camera(&shadowtac, 640, 480, Some(90.0)).is_ok());
    // 9DTact's flat housing places no lens (its camera is calibrated by `calibrate board`)
    let ninedtact = library::load("ninedtact").unwrap();
    let e = nominal_camera(&ninedtact, 640, 480, Some(90.0)).unwrap_err();
    assert!(matches!(e, NominalError::NoLens(_)), "{e}");
}
