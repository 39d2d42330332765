//! `fabkit groundtruth` on a flat skin (the liquid-channel skin of Soter et al.) from the
//! semi-plates of `fabkit fixtures`: a camera under the skin looking up its axis sees the
//! contact face at a known z-depth, each protrusion pushes the face in by at most its
//! indentation depth (reached to the pixel pitch), on the half its orientation puts it on.

use std::path::Path;

use crate::common::*;
use fabkit_calibration::nalgebra::Vector2;
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::{write_camera, CameraFileFormat, CameraModel};

/// The camera's distance below the base plane, mm; the skin's contact face is 5 mm above it.
const BELOW_MM: f64 = 30.0;
const FACE_Z_MM: f64 = 5.0;

fn setup(dir: &Path) {
    let o = run(
        dir,
        &[
            "fixtures",
            "soter_channels",
            "--semidomes",
            "2",
            "--seed",
            "5",
            "--format",
            "stl",
            "--out",
            "fx",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("semi-plates: 2 patterns + the empty half -> 4 stitched pairs"),
        "{}",
        text(&o.stdout)
    );
    std::fs::write(
        dir.join("cam.yaml"),
        write_camera(&benchmark_intrinsics(), CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    // The camera on the skin's axis, BELOW_MM under the base plane, looking up (+z): its x axis
    // is the sensor's x, so sensor x > 0 is the image's right half.
    let ext = serde_json::json!({"rvec": [0.0, 0.0, 0.0], "tvec_mm": [0.0, 0.0, BELOW_MM]});
    std::fs::write(
        dir.join("extrinsics.json"),
        serde_json::to_vec_pretty(&ext).unwrap(),
    )
    .unwrap();
}

#[test]
fn groundtruth_of_a_flat_skin_sees_the_face_and_each_protrusion_at_its_depth() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let o = run(
        d,
        &crate::groundtruth_cli::design_gt_args("soter_channels", "cam.yaml", &[]),
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout)
            .contains("4 configurations (2 patterns x 2 orientations), 4 stitched pairs"),
        "{}",
        text(&o.stdout)
    );
    let gt = d.join("gt");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(gt.join("manifest.json")).unwrap()).unwrap();
    assert!(manifest["description"]
        .as_str()
        .unwrap()
        .contains("semi-plate"));

    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let (w, h) = (640usize, 480usize);
    let bearing_z: Vec<f64> = (0..w * h)
        .map(|p| {
            cam.unproject(&Vector2::new((p % w) as f64, (p / w) as f64))
                .map(|b| b.z / b.norm())
                .unwrap_or(f64::NAN)
        })
        .collect();
    // Reference: the face at z-depth BELOW_MM + FACE_Z_MM, the walls nearer (below the face).
    let face = BELOW_MM + FACE_Z_MM;
    let zref = read_npy_f32(&gt.join("reference/zdepth_mm.npy"));
    let rref = read_npy_f32(&gt.join("reference/range_mm.npy"));
    let (mut valid, mut on_face) = (0, 0);
    for p in 0..w * h {
        if zref[p].is_finite() {
            valid += 1;
            let z = zref[p] as f64;
            // float32 arrays: 1e-4 mm is about 100 ulp at these depths
            assert!(z <= face + 1e-4, "pixel {p}: z-depth {z} beyond the face");
            assert!(
                (z - rref[p] as f64 * bearing_z[p]).abs() < 1e-4,
                "pixel {p}: z-depth = range x bearing z"
            );
            if (z - face).abs() < 1e-4 {
                on_face += 1;
            }
        }
    }
    assert!((zref[240 * w + 320] as f64 - face).abs() < 1e-4);
    // measured 134,476 valid, 115,788 on the face
    assert!(
        valid > 100_000 && on_face * 2 > valid,
        "{on_face} of {valid} pixels on the face"
    );

    for (k, cfg) in manifest["configurations"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let name = cfg["name"].as_str().unwrap();
        let pattern = cfg["pattern"].as_str().unwrap();
        let desc: serde_json::Value = serde_json::from_slice(
            &std::fs::read(d.join("fx/protrusions").join(format!("{pattern}.json"))).unwrap(),
        )
        .unwrap();
        let deepest = desc["protrusions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|q| q["indentation_depth_mm"].as_f64().unwrap())
            .fold(0.0, f64::max);
        let dz = read_npy_f32(&gt.join(name).join("delta_zdepth_mm.npy"));
        let z = read_npy_f32(&gt.join(name).join("zdepth_mm.npy"));
        let mut most: f64 = 0.0;
        let mut pushed = 0;
        for p in 0..w * h {
            if !zref[p].is_finite() {
                continue;
            }
            let dzp = dz[p] as f64;
            assert!(dzp <= 0.0, "{name}: pixel {p} pushed away from the camera");
            if dzp < 0.0 {
                pushed += 1;
                most = most.max(-dzp);
                // the pushed point's sensor-frame x: on +x at orientation 0, -x at 180
                let b = cam
                    .unproject(&Vector2::new((p % w) as f64, (p / w) as f64))
                    .unwrap();
                let x = b.x / b.z * z[p] as f64;
                if k % 2 == 0 {
                    assert!(x > 0.0, "{name}: pushed at x = {x} mm");
                } else {
                    assert!(x < 0.0, "{name}: pushed at x = {x} mm");
                }
            }
        }
        // measured 251 to 578
        assert!(pushed > 20, "{name}: {pushed} pixels pushed");
        assert!(
            most <= deepest + 1e-4 && most > deepest - 0.2,
            "{name}: deepest push {most} mm, the pattern's indentation depth {deepest} mm"
        );
        assert_eq!(cfg["contact_pixels"].as_u64().unwrap(), pushed as u64);
    }
}

/// A camera above the skin's contact face is outside the sensor body: the error names the
/// extrinsics file, the camera centre and the face, and nothing is written.
#[test]
fn a_camera_above_a_flat_skin_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let ext = serde_json::json!({"rvec": [0.0, 0.0, 0.0], "tvec_mm": [0.0, 0.0, -BELOW_MM]});
    std::fs::write(d.join("above.json"), serde_json::to_vec(&ext).unwrap()).unwrap();
    let o = run(
        d,
        &[
            "groundtruth",
            "soter_channels",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "above.json",
            "--fixtures",
            "fx",
            "--out",
            "gt",
        ],
        &[],
    );
    assert!(!o.status.success());
    let e = text(&o.stderr);
    assert!(
        e.contains("above.json: the camera centre [0.000, 0.000, 30.000] mm (sensor frame) is outside the sensor body of soter_channels (the 80 x 80 mm skin's contact face z = 5 mm"),
        "{e}"
    );
    assert!(!d.join("gt").exists());
}
