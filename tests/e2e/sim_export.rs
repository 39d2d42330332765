//! `fabkit export DESIGN --format mjcf,urdf,usd` (issue 103): the assembled sensor as MuJoCo,
//! PyBullet and USD (usd-core, [`check_usd`]) read it. For every library design MuJoCo (`mujoco` from PyPI,
//! tests/oracles/mujoco_check.py) loads `sim/<design>.xml` with its meshes and steps it, and
//! PyBullet (DIRECT, tests/oracles/pybullet_check.py) loads `sim/<design>.urdf` and steps it,
//! and yourdfpy validates the URDF and reads it back ([`check_yourdfpy`]; its forward
//! kinematics put the camera link within 1e-9 m); in all three the body's mass, centre of mass and full inertia tensor are the manifest's
//! (`assembly_3mf.mass`, checked against trimesh in tests/e2e/mass.rs) within 1e-6 relative,
//! and there is one mesh per assembly member; the URDF's frame links weigh nothing; each
//! collides with the skin's mesh and a cylinder or box round each printed housing member's box. Where the
//! design places a camera, MuJoCo's camera and the URDF's `camera_optical_frame` sit where
//! `fabkit calibrate nominal` puts it (in MuJoCo within 1e-9 m, its axes within 1e-9: x right,
//! y up, looking along -z, the OpenCV frame turned about x; in the URDF's text within 1e-12 m;
//! in PyBullet, which keeps a link's frame in single precision, within 1e-8 m and 1e-6), MuJoCo's fovy is
//! the pinhole's 2 atan(h / 2 / fy) of the nominal camera file, `sim/camera.yaml` is that file,
//! and the contact surface (site, link) is on the skin's top.

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

/// The printed housing members (not a printed skin): each collides as a simple shape.
fn housing(members: &[Value]) -> Vec<&Value> {
    members
        .iter()
        .filter(|m| m["kind"] == "printed" && m["name"] != "skin")
        .collect()
}

/// The USD layer as usd-core reads it: a stage in metres and kilograms, z up, the design its
/// default prim with no schema error; its MassAPI the manifest's (mass 1e-6 relative, centre
/// 1e-8 m, the tensor rebuilt from the principal moments and axes 1e-6 of its largest: the
/// attributes are single precision); one triangle mesh per member, the skin alone with
/// CollisionAPI, each authored extent the box of its points and the member's box in the
/// manifest (1e-8 m).
fn check_usd(design: &str, usd: &Value, members: &[Value], mass: &Value) {
    assert_eq!(usd["default_prim"], design, "{usd}");
    assert_eq!(f(&usd["meters_per_unit"]), 1.0);
    assert_eq!(f(&usd["kilograms_per_unit"]), 1.0);
    assert_eq!(usd["up_axis"], "Z");
    assert_eq!(usd["errors"], serde_json::json!([]), "{design}");
    let m = f(&mass["mass_g"]) * 1e-3;
    assert!(
        (f(&usd["mass"]["mass"]) - m).abs() < 1e-6 * m,
        "{design}: {usd}"
    );
    let scale = (0..3)
        .map(|k| f(&mass["inertia_g_mm2"][k][k]))
        .fold(0.0, f64::max);
    for i in 0..3 {
        let want = f(&mass["centre_of_mass_mm"][i]) * 1e-3;
        assert!(
            (f(&usd["mass"]["center_of_mass"][i]) - want).abs() < 1e-8,
            "{design}"
        );
        for j in 0..3 {
            let want = f(&mass["inertia_g_mm2"][i][j]);
            let got = f(&usd["mass"]["inertia"][i][j]) * 1e9;
            assert!(
                (got - want).abs() < 1e-6 * scale,
                "{design} I{i}{j}: {got} vs {want}"
            );
        }
    }
    let meshes = usd["meshes"].as_object().unwrap();
    assert_eq!(meshes.len(), members.len(), "{design}");
    let collisions: Vec<&String> = meshes
        .iter()
        .filter(|(_, v)| v["collision"] == true)
        .map(|(k, _)| k)
        .collect();
    assert_eq!(collisions.len(), 1, "{design}: {collisions:?}");
    // the skin's mesh and one shape per housing member
    assert_eq!(
        usd["collisions"].as_array().unwrap().len(),
        1 + housing(members).len(),
        "{design}: {usd}"
    );
    for m in members {
        let mesh = &meshes[m["name"].as_str().unwrap()];
        for (c, side) in ["min", "max"].iter().enumerate() {
            for k in 0..3 {
                let extent = f(&mesh["extent"][c][k]);
                assert!(
                    (extent - f(&mesh["points_box"][c][k])).abs() < 1e-9,
                    "{design}"
                );
                let want = f(&m["bbox_mm"][side][k]) * 1e-3;
                assert!((extent - want).abs() < 1e-8, "{design}: {mesh}");
            }
        }
    }
}

#[test]
fn every_library_design_loads_in_mujoco_and_pybullet_with_its_mass_and_camera() {
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
            &[
                "export",
                design,
                "--format",
                "3mf,mjcf,urdf,usd",
                "--out",
                design,
            ],
            &[],
        );
        assert!(o.status.success(), "{design}: {}", text(&o.stderr));
        let manifest = json(&dir.join(design).join("manifest.json"));
        let mj = oracle(
            &py,
            "mujoco_check.py",
            &[
                &dir.join(design).join(format!("sim/{design}.xml")),
                Path::new(design),
                Path::new("10"),
            ],
        );
        let pb = oracle(
            &py,
            "pybullet_check.py",
            &[&dir.join(design).join(format!("sim/{design}.urdf"))],
        );
        let usd = oracle(
            &py,
            "usd_check.py",
            &[&dir.join(design).join(format!("sim/{design}.usda"))],
        );
        let yu = oracle(
            &py,
            "yourdfpy_check.py",
            &[&dir.join(design).join(format!("sim/{design}.urdf"))],
        );
        let mass = &manifest["assembly_3mf"]["mass"];
        let members = manifest["assembly_3mf"]["members"].as_array().unwrap();
        check_yourdfpy(design, &yu, members, mass);
        check_usd(design, &usd, members, mass);
        assert_eq!(
            mj["nmesh"].as_u64().unwrap() as usize,
            members.len(),
            "{design}"
        );
        assert_eq!(mj["steps"], 10);
        assert_eq!(
            pb["visual_shapes"].as_u64().unwrap() as usize,
            members.len(),
            "{design}"
        );
        assert!(
            pb["link_masses_kg"]
                .as_array()
                .unwrap()
                .iter()
                .all(|m| f(m) == 0.0),
            "{design}: {pb}"
        );
        let shapes = housing(members);
        assert_eq!(
            pb["collision_shapes"].as_u64().unwrap() as usize,
            1 + shapes.len(),
            "{design}: {pb}"
        );
        // MuJoCo's collision geoms: the skin's mesh, and a cylinder or box round each housing
        // member's box (sizes are half extents; a cylinder's radius half its width)
        let geoms = mj["collision_geoms"].as_object().unwrap();
        assert_eq!(geoms.len(), 1 + shapes.len(), "{design}: {geoms:?}");
        for h in &shapes {
            let g = &geoms[&format!("{}_collision", h["name"].as_str().unwrap())];
            let (lo, hi) = (&h["bbox_mm"]["min"], &h["bbox_mm"]["max"]);
            let half = |k: usize| (f(&hi[k]) - f(&lo[k])) / 2.0 * 1e-3;
            let size = |k: usize| f(&g["size"][k]);
            match g["type"].as_str().unwrap() {
                "cylinder" => assert!(
                    (size(0) - half(0)).abs() < 1e-9 && (size(1) - half(2)).abs() < 1e-9,
                    "{design}: {g}"
                ),
                "box" => {
                    for k in 0..3 {
                        assert!((size(k) - half(k)).abs() < 1e-9, "{design}: {g}");
                    }
                }
                other => panic!("{design}: {other}"),
            }
            for k in 0..3 {
                let centre = (f(&hi[k]) + f(&lo[k])) / 2.0 * 1e-3;
                assert!((f(&g["pos_m"][k]) - centre).abs() < 1e-9, "{design}: {g}");
            }
        }
        let m = f(&mass["mass_g"]) * 1e-3;
        for (what, got) in [
            ("MuJoCo", f(&mj["body"]["mass_kg"])),
            ("PyBullet", f(&pb["base"]["mass_kg"])),
        ] {
            assert!((got - m).abs() < 1e-6 * m, "{design} {what}: {got} vs {m}");
        }
        for k in 0..3 {
            let want = f(&mass["centre_of_mass_mm"][k]) * 1e-3;
            for (what, got) in [
                ("MuJoCo", f(&mj["body"]["com_m"][k])),
                ("PyBullet", f(&pb["base"]["com_m"][k])),
            ] {
                assert!(
                    (got - want).abs() < 1e-9,
                    "{design} {what}: {got} vs {want}"
                );
            }
        }
        let scale = (0..3)
            .map(|k| f(&mass["inertia_g_mm2"][k][k]))
            .fold(0.0, f64::max)
            * 1e-9;
        for i in 0..3 {
            for j in 0..3 {
                let want = f(&mass["inertia_g_mm2"][i][j]) * 1e-9;
                for (what, got) in [
                    ("MuJoCo", f(&mj["body"]["inertia_kg_m2"][i][j])),
                    ("PyBullet", f(&pb["base"]["inertia_kg_m2"][i][j])),
                ] {
                    assert!(
                        (got - want).abs() < 1e-6 * scale,
                        "{design} {what} I{i}{j}: {got} vs {want}"
                    );
                }
            }
        }
        // the contact surface on the skin's top (above the centre of mass): MuJoCo's site,
        // the URDF's link (single precision in PyBullet), USD's Xform
        let top = f(&mj["site"]["pos_m"][2]);
        assert!(top > f(&mj["body"]["com_m"][2]), "{design}: {mj}");
        let link = &pb["links"]["contact_surface"]["pos_m"];
        assert!((f(&link[2]) - top).abs() < 1e-8, "{design}: {pb}");
        assert!(
            (f(&usd["contact_surface"][2]) - top).abs() < 1e-12,
            "{design}: {usd}"
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
                pb["links"]["camera_optical_frame"].is_null(),
                "{design}: {pb}"
            );
            assert!(usd["camera"].is_null(), "{design}: {usd}");
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
        let frame = &pb["links"]["camera_optical_frame"];
        let yu_frame = &yu["frames"]["camera_optical_frame"];
        // the camera joint's origin as the URDF writes it
        let urdf =
            std::fs::read_to_string(dir.join(format!("{design}/sim/{design}.urdf"))).unwrap();
        let joint = &urdf[urdf
            .find("<joint name=\"camera_optical_frame_joint\"")
            .unwrap()..];
        let xyz = &joint[joint.find("xyz=\"").unwrap() + 5..];
        let urdf_camera: Vec<f64> = xyz[..xyz.find('"').unwrap()]
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect();
        for k in 0..3 {
            // the camera's centre in the sensor frame: -R^T t
            let want = -(0..3).map(|i| r(i, k) * f(&t[i][3])).sum::<f64>() * 1e-3;
            assert!((f(&cam["pos_m"][k]) - want).abs() < 1e-9, "{design}: {cam}");
            // PyBullet keeps link frames in single precision (6e-8 relative); the file's
            // numbers are checked exactly below
            assert!(
                (f(&frame["pos_m"][k]) - want).abs() < 1e-8,
                "{design}: {frame}"
            );
            assert!(
                (urdf_camera[k] - want).abs() < 1e-12,
                "{design}: {urdf_camera:?}"
            );
            // yourdfpy's forward kinematics
            assert!(
                (f(&yu_frame[k][3]) - want).abs() < 1e-9,
                "{design}: {yu_frame}"
            );
            for c in 0..3 {
                assert!(
                    (f(&yu_frame[k][c]) - r(c, k)).abs() < 1e-9,
                    "{design}: {yu_frame}"
                );
            }
            // the optical frame's axes (columns) are OpenCV's: the rows of R
            for c in 0..3 {
                let got = f(&frame["R"][k][c]);
                assert!((got - r(c, k)).abs() < 1e-6, "{design}: {frame}");
            }
            // USD's camera: rows of its transform are its axes (OpenCV's x, -y, -z), then its
            // position (double precision)
            let xf = &usd["camera"]["transform"];
            assert!((f(&xf[3][k]) - want).abs() < 1e-12, "{design}: {xf}");
            for (c, sign) in [(0, 1.0), (1, -1.0), (2, -1.0)] {
                assert!(
                    (f(&xf[c][k]) - sign * r(c, k)).abs() < 1e-12,
                    "{design}: {xf}"
                );
            }
            // MuJoCo's axes: OpenCV's x, -y, -z (the rows of R are OpenCV's axes in the sensor frame)
            for (c, sign) in [(0, 1.0), (1, -1.0), (2, -1.0)] {
                let want = sign * r(c, k);
                let got = f(&cam["R_body_cam"][k][c]);
                assert!((got - want).abs() < 1e-9, "{design}: {cam}");
            }
        }
        let camera_yaml =
            std::fs::read_to_string(dir.join(format!("nom_{design}/camera.yaml"))).unwrap();
        let fy = fy_px(&camera_yaml);
        let fovy = 2.0 * (240.0 / fy).atan().to_degrees();
        // USD: focal length over aperture is the focal length over the image width
        let u = &usd["camera"];
        let fx_usd = f(&u["focal_length"]) / f(&u["horizontal_aperture"]) * 640.0;
        assert!((fx_usd - fy).abs() < 1e-6 * fy, "{design}: {u}");
        let ratio = f(&u["vertical_aperture"]) / f(&u["horizontal_aperture"]);
        assert!((ratio - 0.75).abs() < 1e-6, "{design}: {u}");
        assert!((f(&cam["fovy_deg"]) - fovy).abs() < 1e-9, "{design}: {cam}");
        assert_eq!(cam["resolution"], serde_json::json!([640, 480]), "{design}");
        assert_eq!(
            std::fs::read(dir.join(format!("{design}/sim/camera.yaml"))).unwrap(),
            camera_yaml.as_bytes(),
            "{design}: sim/camera.yaml is the nominal camera's file"
        );
    }
    // R-Tac0, UVDtact, the TacTip (and any design that places its lens)
    assert!(cameras >= 2, "{cameras} designs with a camera");
}

/// yourdfpy's reading of a design's URDF: valid (no error logged), the design's one root link
/// with the frame links, a visual mesh per member, and the inertial of the manifest's mass
/// (mass within 1e-6 relative, centre of mass within 1e-9 m, axes the sensor's, the tensor within
/// 1e-6 of its largest moment).
fn check_yourdfpy(design: &str, yu: &Value, members: &[Value], mass: &Value) {
    assert_eq!(yu["valid"], true, "{design}: {yu}");
    assert_eq!(yu["errors"], serde_json::json!([]), "{design}: {yu}");
    assert_eq!(yu["base"], design, "{design}: {yu}");
    assert_eq!(
        yu["meshes"].as_u64().unwrap() as usize,
        members.len(),
        "{design}: {yu}"
    );
    let inertial = &yu["inertial"];
    let m = f(&mass["mass_g"]) * 1e-3;
    assert!(
        (f(&inertial["mass_kg"]) - m).abs() < 1e-6 * m,
        "{design}: {inertial}"
    );
    let scale = (0..3)
        .map(|k| f(&mass["inertia_g_mm2"][k][k]))
        .fold(0.0, f64::max)
        * 1e-9;
    for i in 0..3 {
        let com = f(&mass["centre_of_mass_mm"][i]) * 1e-3;
        assert!(
            (f(&inertial["origin"][i][3]) - com).abs() < 1e-9,
            "{design}: {inertial}"
        );
        for j in 0..3 {
            let axis = if i == j { 1.0 } else { 0.0 };
            assert!(
                (f(&inertial["origin"][i][j]) - axis).abs() < 1e-12,
                "{design}: {inertial}"
            );
            let want = f(&mass["inertia_g_mm2"][i][j]) * 1e-9;
            assert!(
                (f(&inertial["inertia_kg_m2"][i][j]) - want).abs() < 1e-6 * scale,
                "{design} I{i}{j}: {inertial}"
            );
        }
    }
}

/// Runs the oracle `script` with `args`; its JSON.
fn oracle(py: &Path, script: &str, args: &[&Path]) -> Value {
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles").join(script))
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{script}: {}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

/// With `--camera` and `--extrinsics` (a calibration's files) the simulators' camera is the
/// calibrated one: a pinhole camera file (fx = fy = 500 px, 640 x 480, centred) and a pose
/// turned 10 deg about x and 20 deg about z, 0.5 / -0.3 / 17 mm off: MuJoCo's camera, the
/// URDF's optical frame (PyBullet) and USD's Camera prim sit there (1e-9 m, 1e-8 m in
/// PyBullet's single precision, 1e-12 m), MuJoCo's fovy is 2 atan(240 / 500), USD's focal
/// ratio 500 / 640, and sim/camera.yaml is the given file. Refused by option with nothing
/// written: an extrinsics file solved for another design, a camera file of another size than
/// the one the extrinsics were solved with, and the options without a simulator format.
#[test]
fn a_calibrated_camera_is_placed_where_its_extrinsics_say() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (mujoco, pybullet, usd-core)");
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let camera = "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [500.0, 0.0, 319.5, 0.0, 500.0, 239.5, 0.0, 0.0, 1.0]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0.0, 0.0, 0.0, 0.0, 0.0]\n";
    std::fs::write(dir.join("pin.yaml"), camera).unwrap();
    std::fs::write(
        dir.join("big.yaml"),
        camera.replace("image_width: 640", "image_width: 1280"),
    )
    .unwrap();
    // R = Rz(20 deg) Rx(10 deg), t = (0.5, -0.3, 17) mm
    let (a, b) = (10f64.to_radians(), 20f64.to_radians());
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, a.cos(), -a.sin()],
        [0.0, a.sin(), a.cos()],
    ];
    let rz = [
        [b.cos(), -b.sin(), 0.0],
        [b.sin(), b.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let r: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| rz[i][k] * rx[k][j]).sum()));
    let t = [0.5, -0.3, 17.0];
    let m: Vec<Vec<f64>> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| match (i, j) {
                    (3, 3) => 1.0,
                    (3, _) => 0.0,
                    (_, 3) => t[i],
                    _ => r[i][j],
                })
                .collect()
        })
        .collect();
    let extrinsics = |design: &str, camera_file: &Path| {
        serde_json::json!({
            "T_cam_sensor": m,
            "optical_path_from": format!("design {design}, the point table's (fx/points/point_table.json)"),
            "provenance": {"camera_file": camera_file.display().to_string()},
        })
        .to_string()
    };
    std::fs::write(
        dir.join("ext.json"),
        extrinsics("rtac0", &dir.join("pin.yaml")),
    )
    .unwrap();
    let o = run(
        dir,
        &[
            "export",
            "rtac0",
            "--format",
            "3mf,mjcf,urdf,usd",
            "--camera",
            "pin.yaml",
            "--extrinsics",
            "ext.json",
            "--out",
            "k",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sim = dir.join("k/sim");
    let mj = oracle(
        &py,
        "mujoco_check.py",
        &[&sim.join("rtac0.xml"), Path::new("rtac0"), Path::new("1")],
    );
    let pb = oracle(&py, "pybullet_check.py", &[&sim.join("rtac0.urdf")]);
    let usd = oracle(&py, "usd_check.py", &[&sim.join("rtac0.usda")]);
    let yu = oracle(&py, "yourdfpy_check.py", &[&sim.join("rtac0.urdf")]);
    assert_eq!(yu["valid"], true, "{yu}");
    // the camera's centre in the sensor frame: -R^T t
    let centre: [f64; 3] =
        std::array::from_fn(|k| -(0..3).map(|i| r[i][k] * t[i]).sum::<f64>() * 1e-3);
    for k in 0..3 {
        assert!(
            (f(&mj["camera"]["pos_m"][k]) - centre[k]).abs() < 1e-9,
            "{mj}"
        );
        let frame = &pb["links"]["camera_optical_frame"];
        assert!((f(&frame["pos_m"][k]) - centre[k]).abs() < 1e-8, "{frame}");
        let yu_frame = &yu["frames"]["camera_optical_frame"];
        assert!((f(&yu_frame[k][3]) - centre[k]).abs() < 1e-9, "{yu_frame}");
        let xf = &usd["camera"]["transform"];
        assert!((f(&xf[3][k]) - centre[k]).abs() < 1e-12, "{xf}");
        for (c, sign) in [(0, 1.0), (1, -1.0), (2, -1.0)] {
            // the camera's axes in the sensor frame: the rows of R (OpenCV's), y and z flipped
            // for MuJoCo and USD
            let want = sign * r[c][k];
            assert!(
                (f(&mj["camera"]["R_body_cam"][k][c]) - want).abs() < 1e-9,
                "{mj}"
            );
            assert!((f(&xf[c][k]) - want).abs() < 1e-12, "{xf}");
            assert!((f(&frame["R"][k][c]) - r[c][k]).abs() < 1e-6, "{frame}");
            assert!((f(&yu_frame[k][c]) - r[c][k]).abs() < 1e-9, "{yu_frame}");
        }
    }
    let fovy = 2.0 * (240.0f64 / 500.0).atan().to_degrees();
    assert!((f(&mj["camera"]["fovy_deg"]) - fovy).abs() < 1e-9, "{mj}");
    let u = &usd["camera"];
    let ratio = f(&u["focal_length"]) / f(&u["horizontal_aperture"]);
    assert!((ratio - 500.0 / 640.0).abs() < 1e-6, "{u}");
    assert_eq!(
        std::fs::read(sim.join("camera.yaml")).unwrap(),
        camera.as_bytes()
    );
    // refused by option, nothing written
    std::fs::write(
        dir.join("other.json"),
        extrinsics("shadowtac", &dir.join("pin.yaml")),
    )
    .unwrap();
    for (args, words) in [
        (
            vec![
                "--format",
                "mjcf",
                "--camera",
                "pin.yaml",
                "--extrinsics",
                "other.json",
            ],
            vec![
                "--extrinsics other.json",
                "design 'shadowtac'",
                "not 'rtac0'",
            ],
        ),
        (
            vec![
                "--format",
                "mjcf",
                "--camera",
                "big.yaml",
                "--extrinsics",
                "ext.json",
            ],
            vec!["--camera big.yaml: 1280 x 480 px", "640 x 480 px"],
        ),
        (
            vec!["--camera", "pin.yaml", "--extrinsics", "ext.json"],
            vec!["--format mjcf, urdf or usd"],
        ),
    ] {
        let mut all = vec!["export", "rtac0", "--out", "never"];
        all.extend(&args);
        let o = run(dir, &all, &[]);
        assert!(!o.status.success(), "{args:?}");
        for w in &words {
            assert!(text(&o.stderr).contains(w), "{w}: {}", text(&o.stderr));
        }
        assert!(!dir.join("never").exists(), "{args:?}");
    }
}
