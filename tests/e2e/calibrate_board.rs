//! `fabkit calibrate board` on the real 9DTact board press (tests/data/9dtact_sensor1): the
//! board's point table from `fabkit fixtures ninedtact`, the camera solved with default options,
//! its files read back by OpenCV and numpy (tests/oracles/board_check.py); bad input refused
//! by option with nothing written.

use crate::common::{missing, oracle_python, repo_root, run, text};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn press(name: &str) -> PathBuf {
    repo_root()
        .join("tests/data/9dtact_sensor1/camera_calibration")
        .join(name)
}

/// `fabkit fixtures ninedtact` in `dir`: the board's point table (with the sidecar that names
/// the design).
fn board_table(dir: &Path) -> PathBuf {
    let o = run(dir, &["fixtures", "ninedtact", "--out", "fx"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    dir.join("fx/points/board_table.csv")
}

/// Default options on the real press: 63 of 63 bumps; the RMS reprojection error at most
/// 1.3 px (1.16 measured; the centres scatter about 0.85 px about any smooth lens model, see
/// calibration/tests/it/board.rs); the authors' scale (the pitch over the centre bump's mean
/// distance to its four neighbours) within 1.5 % of their 0.05102 mm per px; the plane's
/// distance from the design's housing (11.548 mm: 2.8 mm of air, the 10.4 mm window over
/// n = 1.491, the 2.5 mm translucent gel over 1.41, up to the opaque black gel). OpenCV's
/// projectPoints with the written camera.yaml and the pose puts every bump where fabkit's
/// report does (1e-6 px), and the pixel-to-plane map numpy reads is 480 x 640 x 2 float32,
/// finite, and takes the bumps' pixels to their points within their scatter (0.1 mm RMS).
#[test]
fn the_real_board_press_calibrates_the_9dtact_camera() {
    let tmp = tempfile::tempdir().unwrap();
    let table = board_table(tmp.path());
    let o = run(
        tmp.path(),
        &[
            "calibrate",
            "board",
            "--points",
            table.to_str().unwrap(),
            "--reference",
            press("ref.png").to_str().unwrap(),
            "--image",
            press("sample.png").to_str().unwrap(),
            "--out",
            "cal",
        ],
        &[],
    );
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("63 of 63 bumps found"), "{out}");
    let dir = tmp.path().join("cal");
    let r: Value =
        serde_json::from_slice(&std::fs::read(dir.join("extrinsics.json")).unwrap()).unwrap();
    assert_eq!(r["found"], 63);
    assert_eq!(r["missing_ids"].as_array().unwrap().len(), 0);
    let rms = r["rms_reprojection_error_px"].as_f64().unwrap();
    assert!(rms < 1.3, "RMS {rms} px");
    let scale = r["mm_per_px_neighbours"].as_f64().unwrap();
    assert!(
        (scale / 0.0510150969 - 1.0).abs() < 0.015,
        "{scale} mm per px"
    );
    let d = r["plane_distance_mm"].as_f64().unwrap();
    let want = 2.8 + 10.4 / 1.491 + 2.5 / 1.41;
    assert!((d - want).abs() < 1e-9, "{d} against {want}");
    assert!(r["plane_distance_from"]
        .as_str()
        .unwrap()
        .contains("black_gel"));
    for f in [
        "camera.yaml",
        "camera_info.yaml",
        "camera.json",
        "extrinsics.yaml",
        "transform.yaml",
        "observations.csv",
        "overlay.png",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    let Some(py) = oracle_python() else {
        return missing("the oracle python (opencv-python-headless, numpy)");
    };
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/board_check.py"))
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let c: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(c["projection_max_diff_px"].as_f64().unwrap() < 1e-6, "{c}");
    assert_eq!(c["map_shape"], serde_json::json!([480, 640, 2]), "{c}");
    assert_eq!(c["map_dtype"], "float32");
    assert_eq!(c["map_finite"], true);
    assert!(c["map_at_bumps_rms_mm"].as_f64().unwrap() < 0.1, "{c}");
}

/// Bad input is refused naming the option and the file, and nothing is written under --out: a
/// press of another size than its reference, a table whose points are not a grid, a press
/// with no imprint (the reference itself), a plane distance that is not positive, and no
/// plane distance with no design to take it from.
#[test]
fn bad_board_presses_are_refused_by_option_with_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let table = board_table(tmp.path());
    let small = tmp.path().join("small.png");
    image::open(press("sample.png"))
        .unwrap()
        .crop_imm(0, 0, 320, 240)
        .save(&small)
        .unwrap();
    let not_grid = tmp.path().join("not_grid.csv");
    std::fs::write(
        &not_grid,
        "id,x_mm,y_mm,z_mm\n1,0,0,2.8\n2,2.5,0,2.8\n3,0,2.5,2.8\n4,3,2.5,2.8\n",
    )
    .unwrap();
    let plain = tmp.path().join("plain.csv");
    let t = std::fs::read_to_string(&table).unwrap();
    let mut rows = String::from("id,x_mm,y_mm,z_mm\n");
    for l in t.lines().skip(1) {
        let c: Vec<&str> = l.split(',').collect();
        rows += &format!("{},{},{},{}\n", c[0], c[5], c[6], c[7]);
    }
    std::fs::write(&plain, rows).unwrap();
    let (tab, pl, sm, ng) = (
        table.to_str().unwrap(),
        plain.to_str().unwrap(),
        small.to_str().unwrap(),
        not_grid.to_str().unwrap(),
    );
    let (r, s) = (press("ref.png"), press("sample.png"));
    let (r, s) = (r.to_str().unwrap(), s.to_str().unwrap());
    let cases: [(&[&str], &str); 5] = [
        (
            &["--points", tab, "--reference", r, "--image", sm],
            "--image",
        ),
        (
            &[
                "--points",
                ng,
                "--reference",
                r,
                "--image",
                s,
                "--plane-distance-mm",
                "12",
            ],
            "--points",
        ),
        (
            &["--points", tab, "--reference", r, "--image", r],
            "--image",
        ),
        (
            &[
                "--points",
                tab,
                "--reference",
                r,
                "--image",
                s,
                "--plane-distance-mm=-1",
            ],
            "--plane-distance-mm",
        ),
        (
            &["--points", pl, "--reference", r, "--image", s],
            "--plane-distance-mm",
        ),
    ];
    for (k, (args, option)) in cases.iter().enumerate() {
        let out = format!("out{k}");
        let mut a = vec!["calibrate", "board", "--out", &out];
        a.extend_from_slice(args);
        let o = run(tmp.path(), &a, &[]);
        let err = text(&o.stderr);
        assert!(!o.status.success(), "case {k} ran");
        assert!(err.contains(option), "case {k}: {err}");
        assert!(!tmp.path().join(&out).exists(), "case {k} wrote {out}");
        let leftovers: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(&out))
            .collect();
        assert!(leftovers.is_empty(), "case {k}: {leftovers:?}");
    }
}

/// A grid plate pressed a few pins at a time (Soter et al.'s, `fabkit fixtures
/// soter_channels`: 49 pins at 10 mm, its capture plan of 13 captures), rendered as a camera
/// 55 mm away would see it (calibration/src/board/synthetic.rs; f = 290 px with a plumb_bob
/// distortion, as calibration/tests/it/board_synthetic.rs's plate), one PNG per capture:
/// `calibrate board --image` with the 13 captures and `--capture-plan` finds all 49 pins, each
/// in its capture, and writes observations.csv (one row per pin, `id,u_px,v_px`) with the
/// report naming every capture; the scale at the centre pin within 1 % of the truth. A plan
/// of another length than the images is refused by `--capture-plan` with nothing written.
#[test]
fn a_grid_plate_pressed_over_several_captures_calibrates_with_its_plan() {
    use fabkit_calibration::board::synthetic::{render_board, BoardPress, BoardShading};
    use fabkit_calibration::board::{board_grid, mm_per_px_at, BoardCamera};
    use fabkit_calibration::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2};
    use fabkit_calibration::tables::{read_capture_plan, read_point_table, PointsFrom};
    use fabkit_calibration::{CameraModel, Distortion, Intrinsics};

    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &["fixtures", "soter_channels", "--out", "fx"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let points = tmp.path().join("fx/points/point_table.csv");
    let plan_file = tmp.path().join("fx/points/capture_plan.csv");
    let table = read_point_table(&points, PointsFrom::Contact).unwrap();
    let grid = board_grid(&table).unwrap();
    let plan = read_capture_plan(&plan_file).unwrap();
    assert_eq!((grid.points.len(), plan.captures.len()), (49, 13));
    let camera = CameraModel::new(Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 290.0,
        fy_px: 290.0,
        cx_px: 319.5,
        cy_px: 239.5,
        distortion: Distortion::PlumbBob([0.9, -1.0, 0.0, 0.0, 0.5]),
    })
    .unwrap();
    let distance_mm = 55.0;
    let rot = UnitQuaternion::from_euler_angles(-0.01, 0.02, 0.01);
    let pose = Isometry3::from_parts(
        Translation3::new(0.5, -0.4, grid.plane_z_mm - distance_mm),
        rot,
    )
    .inverse();
    let all: Vec<String> = grid.points.iter().map(|g| g.id.clone()).collect();
    let renders: Vec<_> = std::thread::scope(|s| {
        let jobs: Vec<_> = plan
            .captures
            .iter()
            .enumerate()
            .map(|(k, ids)| {
                let (camera, grid, all) = (&camera, &grid, &all);
                s.spawn(move || {
                    let press = BoardPress {
                        bump_radius_mm: 3.0,
                        depth_mm: 1.0,
                        unpressed: all.iter().filter(|i| !ids.contains(i)).cloned().collect(),
                        specks: Vec::new(),
                    };
                    let shading = BoardShading {
                        darkening_per_mm: 0.15,
                        seed: 200 + k as u64,
                        ..BoardShading::default()
                    };
                    render_board(camera, &pose, grid, &press, &shading)
                })
            })
            .collect();
        jobs.into_iter().map(|j| j.join().unwrap()).collect()
    });
    let save = |name: &str, rgb: &[u8]| {
        let p = tmp.path().join(name);
        image::RgbImage::from_raw(640, 480, rgb.to_vec())
            .unwrap()
            .save(&p)
            .unwrap();
        p.to_str().unwrap().to_string()
    };
    let reference = save("ref.png", &renders[0].reference_rgb);
    let images: Vec<String> = renders
        .iter()
        .enumerate()
        .map(|(k, r)| save(&format!("capture_{:02}.png", k + 1), &r.capture_rgb))
        .collect();
    let distance = distance_mm.to_string();
    let args = |out: &'static str, plan: &str, images: &[String]| -> Vec<String> {
        let mut a: Vec<String> = [
            "calibrate",
            "board",
            "--points",
            points.to_str().unwrap(),
            "--reference",
            &reference,
            "--capture-plan",
            plan,
            "--plane-distance-mm",
            &distance,
            "--out",
            out,
            "--image",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend_from_slice(images);
        a
    };
    let a = args("cal", plan_file.to_str().unwrap(), &images);
    let o = run(
        tmp.path(),
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        &[],
    );
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("49 of 49 bumps found"), "{out}");
    let dir = tmp.path().join("cal");
    let r: Value =
        serde_json::from_slice(&std::fs::read(dir.join("extrinsics.json")).unwrap()).unwrap();
    assert_eq!(r["found"], 49);
    assert_eq!(r["capture_images"].as_array().unwrap().len(), 13);
    let captures = r["captures"].as_array().unwrap();
    for (k, c) in captures.iter().enumerate() {
        let ids: Vec<&str> = c["found"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["id"].as_str().unwrap())
            .collect();
        let mut planned: Vec<&str> = plan.captures[k].iter().map(String::as_str).collect();
        planned.sort_by_key(|i| i.parse::<u32>().unwrap());
        assert_eq!(ids, planned, "capture {}", k + 1);
        assert_eq!(c["missing_planned_ids"].as_array().unwrap().len(), 0);
    }
    let csv = std::fs::read_to_string(dir.join("observations.csv")).unwrap();
    assert!(
        csv.starts_with("id,u_px,v_px\n") && csv.lines().count() == 50,
        "{csv}"
    );
    assert!(dir.join("overlay.png").is_file());
    let rms = r["rms_reprojection_error_px"].as_f64().unwrap();
    assert!(rms < 0.25, "RMS {rms} px");
    let centre = &r["centre_bump_px"];
    let at = Vector2::new(centre[0].as_f64().unwrap(), centre[1].as_f64().unwrap());
    let truth = BoardCamera {
        camera,
        t_cam_sensor: pose,
        parameters: Vec::new(),
        condition_number: 0.0,
        residuals_px: Vec::new(),
        rms_px: 0.0,
        pose_std: None,
    };
    let true_scale = mm_per_px_at(&truth, grid.plane_z_mm, at).unwrap();
    let scale = r["mm_per_px_at_centre"].as_f64().unwrap();
    assert!(
        (scale / true_scale - 1.0).abs() < 0.01,
        "{scale} mm per px, true {true_scale}"
    );

    // a plan of 13 captures with 12 images
    let a = args("short", plan_file.to_str().unwrap(), &images[..12]);
    let o = run(
        tmp.path(),
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        &[],
    );
    let err = text(&o.stderr);
    assert!(!o.status.success(), "ran with 12 images");
    assert!(
        err.contains("--capture-plan") && err.contains("13 captures but 12"),
        "{err}"
    );
    assert!(!tmp.path().join("short").exists());
}

/// The real press as a camera turned about its optical axis sees it: the reference and the
/// capture turned by the image crate's rotate90 (clockwise as shown: 480 x 640 px, the 7 x 9
/// board 9 bumps tall and 7 wide) and rotate180, written as PNGs, calibrated with
/// `--board-turn 90` and `--board-turn 180`: 63 of 63 bumps, each id at the turned pixel of
/// that id in the unturned calibration (0.01 px), `board_turn_deg` in extrinsics.json, the
/// RMS reprojection error within 0.05 px of the unturned one's (1e-4 px measured), and the
/// pose turned by the turn about the optical axis: T_cam_sensor's rotation is the unturned
/// one followed by 90 (180) deg about the camera's z, within 0.1 deg (1e-4 measured). The
/// quarter-turned press calibrated unturned is refused by `--image`, naming the turns that
/// fit; `--board-turn 45` and `--board-turn -90` are refused naming the option, the value and
/// the rule; neither writes anything.
#[test]
fn the_real_board_press_turned_in_the_image_calibrates_with_board_turn() {
    let tmp = tempfile::tempdir().unwrap();
    let table = board_table(tmp.path());
    let tab = table.to_str().unwrap();
    let calibrate = |reference: &Path, image: &Path, out: &str, extra: &[&str]| {
        let mut a = vec![
            "calibrate",
            "board",
            "--points",
            tab,
            "--reference",
            reference.to_str().unwrap(),
            "--image",
            image.to_str().unwrap(),
            "--out",
            out,
        ];
        a.extend_from_slice(extra);
        run(tmp.path(), &a, &[])
    };
    let report = |out: &str| -> Value {
        serde_json::from_slice(
            &std::fs::read(tmp.path().join(out).join("extrinsics.json")).unwrap(),
        )
        .unwrap()
    };
    let observed = |r: &Value| -> std::collections::BTreeMap<String, (f64, f64)> {
        r["bumps"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let p = &b["observed_px"];
                (
                    b["id"].as_str().unwrap().to_string(),
                    (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()),
                )
            })
            .collect()
    };
    let rotation = |r: &Value| -> [[f64; 3]; 3] {
        let m = &r["T_cam_sensor"];
        std::array::from_fn(|i| std::array::from_fn(|j| m[i][j].as_f64().unwrap()))
    };
    let o = calibrate(&press("ref.png"), &press("sample.png"), "cal0", &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r0 = report("cal0");
    assert_eq!(r0["board_turn_deg"], 0);
    let (px0, rot0) = (observed(&r0), rotation(&r0));
    let rms0 = r0["rms_reprojection_error_px"].as_f64().unwrap();

    for (deg, turned) in [(90u32, 0usize), (180, 1)] {
        let turn = |img: image::DynamicImage| match deg {
            90 => img.rotate90(),
            _ => img.rotate180(),
        };
        let (reference, image) = (
            tmp.path().join(format!("ref_{deg}.png")),
            tmp.path().join(format!("sample_{deg}.png")),
        );
        turn(image::open(press("ref.png")).unwrap())
            .save(&reference)
            .unwrap();
        turn(image::open(press("sample.png")).unwrap())
            .save(&image)
            .unwrap();
        let out = format!("cal{deg}");
        let d = deg.to_string();
        let o = calibrate(&reference, &image, &out, &["--board-turn", &d]);
        let stdout = text(&o.stdout);
        assert!(o.status.success(), "{deg}: {stdout}\n{}", text(&o.stderr));
        assert!(stdout.contains("63 of 63 bumps found"), "{deg}: {stdout}");
        let r = report(&out);
        assert_eq!(r["board_turn_deg"], deg);
        assert_eq!(r["found"], 63);
        let want_size = [[480, 640], [640, 480]][turned];
        assert_eq!(r["image_size_px"], serde_json::json!(want_size));
        for (id, (u, v)) in observed(&r) {
            let (u0, v0) = px0[&id];
            let (tu, tv) = match deg {
                90 => (479.0 - v0, u0),
                _ => (639.0 - u0, 479.0 - v0),
            };
            assert!(
                (u - tu).hypot(v - tv) < 0.01,
                "{deg}: id {id} at ({u}, {v}), unturned ({u0}, {v0}) turned to ({tu}, {tv})"
            );
        }
        let rms = r["rms_reprojection_error_px"].as_f64().unwrap();
        assert!((rms - rms0).abs() < 0.05, "{deg}: RMS {rms} against {rms0}");
        // R_turned R_0^T: a turn about the camera's z
        let rot = rotation(&r);
        let m: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| rot[i][k] * rot0[j][k]).sum())
        });
        let about_z = m[1][0].atan2(m[0][0]).to_degrees().rem_euclid(360.0);
        let tilt = m[2][2].clamp(-1.0, 1.0).acos().to_degrees();
        assert!(
            (about_z - f64::from(deg)).abs() < 0.1 && tilt < 0.1,
            "{deg}: turned {about_z} deg about z, {tilt} deg off it"
        );
        eprintln!(
            "--board-turn {deg}: RMS {rms:.4} px (unturned {rms0:.4}), about z {about_z:.5} deg, tilt {tilt:.5} deg"
        );
    }

    // refused, nothing written
    let (r90, s90) = (
        tmp.path().join("ref_90.png"),
        tmp.path().join("sample_90.png"),
    );
    let cases: [(&[&str], &[&str]); 3] = [
        (
            &[],
            &["--image", "7 wide", "9 tall", "--board-turn 90 or 270 fits"],
        ),
        (
            &["--board-turn", "45"],
            &["--board-turn = 45: must be 0, 90, 180 or 270"],
        ),
        (
            &["--board-turn", "-90"],
            &[
                "--board-turn = -90: must be 0, 90, 180 or 270",
                "(-90 is 270)",
            ],
        ),
    ];
    for (k, (extra, told)) in cases.iter().enumerate() {
        let out = format!("refused{k}");
        let o = calibrate(&r90, &s90, &out, extra);
        let err = text(&o.stderr);
        assert!(!o.status.success(), "case {k} ran");
        for t in told.iter() {
            assert!(err.contains(t), "case {k}: {err}");
        }
        assert!(!tmp.path().join(&out).exists(), "case {k} wrote {out}");
    }
}
