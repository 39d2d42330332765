//! `fabkit groundtruth` end to end on the output of `fabkit fixtures` (R-Tac0, 2 patterns):
//! layout, byte-identical output with 1 and 2 threads, the manifest's hashes, the relations
//! between the maps (delta = indented - reference, contact mask = pushed-in pixels, z-depth =
//! range x bearing z, half masks partition the surface pixels, N x N pairs), the files read by
//! numpy, OpenCV and Open3D, and input errors.

use std::path::Path;

use crate::common::*;
use fabkit_calibration::nalgebra::Vector2;
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::{write_camera, CameraFileFormat, CameraModel};

/// The output of `fabkit fixtures rtac0 --pins-preset rtac0 --semidomes 2 --seed 3 --format stl
/// --out fx`, made once per test run (in `<target>/tmp/shared-pin-fixtures`, emptied first) for
/// the tests that [`setup`] a folder with it (22 runs of the suite made it, 0.45 s each).
fn shared_pin_fixtures() -> &'static Path {
    static FX: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    FX.get_or_init(|| {
        let dir = shared_dir("shared-pin-fixtures");
        let o = run(
            &dir,
            &[
                "fixtures",
                "rtac0",
                "--pins-preset",
                "rtac0",
                "--semidomes",
                "2",
                "--seed",
                "3",
                "--format",
                "stl",
                "--out",
                "fx",
            ],
            &[],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        dir.join("fx")
    })
}

/// Prepares `dir` for a ground-truth run of R-Tac0: the fixtures folder `fx` (a copy of
/// [`shared_pin_fixtures`]: two semi-dome patterns and the pin dome), the benchmark camera
/// `cam.yaml` and `extrinsics.json`.
pub(crate) fn setup(dir: &Path) {
    copy_tree(shared_pin_fixtures(), &dir.join("fx"));
    std::fs::write(
        dir.join("cam.yaml"),
        write_camera(&benchmark_intrinsics(), CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    // The form `fabkit calibrate extrinsics` writes: rvec, tvec_mm and the matrix.
    let (rx, ry, rz) = (0.02f64, -0.015f64, 0.4f64);
    let r = fabkit_calibration::nalgebra::Rotation3::from_scaled_axis(
        fabkit_calibration::nalgebra::Vector3::new(rx, ry, rz),
    );
    let t = [0.3, -0.2, 10.4];
    let m: Vec<Vec<f64>> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| {
                    if i == 3 {
                        [0.0, 0.0, 0.0, 1.0][j]
                    } else if j == 3 {
                        t[i]
                    } else {
                        r[(i, j)]
                    }
                })
                .collect()
        })
        .collect();
    let ext = serde_json::json!({"rvec": [rx, ry, rz], "tvec_mm": t, "T_cam_sensor": m});
    std::fs::write(
        dir.join("extrinsics.json"),
        serde_json::to_vec_pretty(&ext).unwrap(),
    )
    .unwrap();
}

pub(crate) fn groundtruth(dir: &Path, out: &str, threads: &str) -> std::process::Output {
    run(
        dir,
        &[
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "extrinsics.json",
            "--fixtures",
            "fx",
            "--out",
            out,
        ],
        &[("RAYON_NUM_THREADS", threads)],
    )
}

/// `groundtruth rtac0 --camera CAMERA --extrinsics extrinsics.json --fixtures fx --out gt`, then
/// `extra`: the run of the folder [`setup`] prepares.
fn gt_args<'a>(camera: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    design_gt_args("rtac0", camera, extra)
}

/// [`gt_args`] of `design`.
pub(crate) fn design_gt_args<'a>(
    design: &'a str,
    camera: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut a = vec![
        "groundtruth",
        design,
        "--camera",
        camera,
        "--extrinsics",
        "extrinsics.json",
        "--fixtures",
        "fx",
        "--out",
        "gt",
    ];
    a.extend(extra);
    a
}

#[test]
fn groundtruth_of_two_patterns_is_complete_consistent_and_deterministic() {
    let (d1, d2) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    setup(d1.path());
    setup(d2.path());
    let o = groundtruth(d1.path(), "gt", "1");
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout)
            .contains("4 configurations (2 patterns x 2 orientations), 4 stitched pairs"),
        "{}",
        text(&o.stdout)
    );
    let o = groundtruth(d2.path(), "gt", "2");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (a, b) = (d1.path().join("gt"), d2.path().join("gt"));

    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("manifest.json")).unwrap()).unwrap();
    let files = manifest["files"].as_array().unwrap();
    // reference: range and zdepth (npy, 16-bit PNG, preview), normals (npy, preview), PLY;
    // each configuration also the two deltas and the contact mask; 2 masks and pairs.csv.
    assert_eq!(files.len(), 9 + 4 * 16 + 3);
    for f in files {
        let rel = f["file"].as_str().unwrap();
        let bytes = std::fs::read(a.join(rel)).unwrap();
        assert_eq!(
            fabkit_calibration::groundtruth::inputs::sha256_hex(&bytes),
            f["sha256"].as_str().unwrap(),
            "{rel}"
        );
        assert!(
            bytes == std::fs::read(b.join(rel)).unwrap(),
            "{rel} differs between 1 and 2 threads"
        );
    }
    assert!(
        std::fs::read(a.join("manifest.json")).unwrap()
            == std::fs::read(b.join("manifest.json")).unwrap()
    );
    let names: Vec<&str> = manifest["configurations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["p001_0", "p001_180", "p002_0", "p002_180"]);
    let pairs = std::fs::read_to_string(a.join("pairs.csv")).unwrap();
    let rows: Vec<&str> = pairs
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("pair,"))
        .collect();
    assert_eq!(
        rows,
        [
            "0,p001,p001_0,p001,p001_180",
            "1,p001,p001_0,p002,p002_180",
            "2,p002,p002_0,p001,p001_180",
            "3,p002,p002_0,p002,p002_180"
        ]
    );

    // Relations between the maps.
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let (w, h) = (640usize, 480usize);
    let rref = read_npy_f32(&a.join("reference/range_mm.npy"));
    let zref = read_npy_f32(&a.join("reference/zdepth_mm.npy"));
    assert_eq!(rref.len(), w * h);
    let mut surface = 0;
    for p in (0..w * h).step_by(97) {
        if rref[p].is_finite() {
            surface += 1;
            let bz = cam
                .unproject(&Vector2::new((p % w) as f64, (p / w) as f64))
                .unwrap()
                .z;
            // float32 arrays: ulp 9.5e-7 mm at 8 to 16 mm, 1e-5 is 10 ulp
            assert!(
                (zref[p] as f64 - rref[p] as f64 * bz).abs() < 1e-5,
                "zdepth = range * bearing z at {p}"
            );
        } else {
            assert!(zref[p].is_nan());
        }
    }
    // measured 2,247
    assert!(surface > 1000);
    for c in &names {
        let r = read_npy_f32(&a.join(c).join("range_mm.npy"));
        let dr = read_npy_f32(&a.join(c).join("delta_range_mm.npy"));
        let (mut contact, mut pushed) = (0, 0);
        for p in 0..w * h {
            if rref[p].is_finite() {
                assert!((dr[p] - (r[p] - rref[p])).abs() < 1e-5, "{c}: delta at {p}");
                assert!(
                    dr[p] <= 0.0,
                    "{c}: protrusions only push the skin towards the camera"
                );
                if dr[p] < 0.0 {
                    pushed += 1;
                }
            } else {
                assert!(dr[p].is_nan());
            }
        }
        let cm = &manifest["configurations"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == *c)
            .unwrap()["contact_pixels"];
        contact += cm.as_u64().unwrap();
        assert!(
            pushed > 0 && (pushed as u64) <= contact,
            "{c}: {pushed} pushed pixels, {contact} contact pixels"
        );
    }
    let masks = &manifest["masks_and_pairs"];
    let (l, r) = (
        masks[0]["pixels"].as_u64().unwrap(),
        masks[1]["pixels"].as_u64().unwrap(),
    );
    assert_eq!(
        l + r,
        manifest["image"]["pixels_on_surface"].as_u64().unwrap()
    );
    // measured 109,657 and 107,862
    assert!(l > 1000 && r > 1000);

    // numpy, OpenCV and Open3D read the files.
    let Some(py) = oracle_python() else {
        return missing("the oracle python (numpy, opencv, open3d)");
    };
    let script = r#"
import sys, json, numpy as np, cv2, open3d as o3d
d = sys.argv[1]
m = json.load(open(f"{d}/manifest.json"))
out = {}
r = np.load(f"{d}/p001_0/range_mm.npy")
png = cv2.imread(f"{d}/p001_0/range_um.png", cv2.IMREAD_UNCHANGED)
ok = np.isfinite(r)
out["shape"] = list(r.shape)
out["dtype"] = str(png.dtype)
out["png_err_um"] = float(np.abs(png[ok].astype(np.float64) - np.round(r[ok].astype(np.float64) * 1000)).max())
out["png_zero_on_missing"] = bool((png[~ok] == 0).all())
dr = np.load(f"{d}/p001_0/delta_range_mm.npy")
dp = cv2.imread(f"{d}/p001_0/delta_range_um.png", cv2.IMREAD_UNCHANGED).astype(np.float64)
ok = np.isfinite(dr)
out["delta_png_err_um"] = float(np.abs((dp[ok] - 32768) - np.round(dr[ok].astype(np.float64) * 1000)).max())
mask = cv2.imread(f"{d}/p001_0/contact_mask.png", cv2.IMREAD_UNCHANGED)
out["mask_pixels"] = int((mask == 255).sum())
pc = o3d.io.read_point_cloud(f"{d}/p001_0/points.ply")
out["ply_points"] = len(pc.points)
out["ply_vs_npy"] = int(np.isfinite(r).sum())
n = np.load(f"{d}/reference/normals.npy")
out["normals_shape"] = list(n.shape)
print(json.dumps(out))
"#;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(&a)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["shape"], serde_json::json!([480, 640]));
    assert_eq!(v["dtype"], "uint16");
    assert!(v["png_err_um"].as_f64().unwrap() <= 1.0, "{v}");
    assert!(v["delta_png_err_um"].as_f64().unwrap() <= 1.0, "{v}");
    assert_eq!(v["png_zero_on_missing"], true);
    assert_eq!(
        v["mask_pixels"],
        manifest["configurations"][0]["contact_pixels"]
    );
    assert_eq!(v["ply_points"], v["ply_vs_npy"]);
    assert_eq!(v["normals_shape"], serde_json::json!([480, 640, 3]));
}

#[test]
fn bad_inputs_name_the_file_and_the_rule_and_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    // Fixtures of another design.
    let o = run(d.path(), &design_gt_args("uvdtact", "cam.yaml", &[]), &[]);
    assert_eq!(o.status.code(), Some(2));
    let e = text(&o.stderr);
    assert!(
        e.contains("p001.json: design = rtac0") && e.contains("another design"),
        "{e}"
    );
    // A camera outside the sensor body (extrinsics with the translation's sign flipped).
    std::fs::write(
        d.path().join("far.json"),
        r#"{"T_cam_sensor": [[1,0,0,0],[0,1,0,0],[0,0,1,-40],[0,0,0,1]]}"#,
    )
    .unwrap();
    let o = run(
        d.path(),
        &[
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "far.json",
            "--fixtures",
            "fx",
            "--out",
            "gt",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("far.json: the camera centre [0.000, 0.000, 40.000] mm"),
        "{}",
        text(&o.stderr)
    );
    // Not a rotation.
    std::fs::write(
        d.path().join("skew.json"),
        r#"{"T_cam_sensor": [[1,0.1,0,0],[0,1,0,0],[0,0,1,10],[0,0,0,1]]}"#,
    )
    .unwrap();
    let o = run(
        d.path(),
        &[
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "skew.json",
            "--fixtures",
            "fx",
            "--out",
            "gt",
        ],
        &[],
    );
    assert!(
        text(&o.stderr).contains("skew.json: T_cam_sensor")
            && text(&o.stderr).contains("must be a rotation"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("gt").exists());

    // Bounded work: the camera image against --max-pixels (checked before any per-pixel array),
    // bad --max-pixels values, a camera image side past 16384 px, a FIFO as the camera file.
    let groundtruth = |camera: &str, extra: &[&str]| run(d.path(), &gt_args(camera, extra), &[]);
    let i = benchmark_intrinsics();
    let (w, h) = (i.image_width_px, i.image_height_px);
    let o = groundtruth("cam.yaml", &["--max-pixels", "1000"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains(&format!(
            "cam.yaml: the camera image is {w} x {h} = {} pixels, over the ground-truth limit of 1000 pixels",
            w * h
        )) && text(&o.stderr).contains("--max-pixels"),
        "{}",
        text(&o.stderr)
    );
    for bad in ["0", "-1", "4194305", "268435456", "lots"] {
        let o = groundtruth("cam.yaml", &["--max-pixels", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(
            text(&o.stderr).contains(&format!("invalid value '{bad}' for '--max-pixels"))
                && text(&o.stderr)
                    .contains("must be a whole number of pixels from 1 to 4194304 (2048 x 2048"),
            "{bad}: {}",
            text(&o.stderr)
        );
    }
    for bad in ["0", "-1", "1000000000000001", "1GB"] {
        let o = groundtruth("cam.yaml", &["--max-output-bytes", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(
            text(&o.stderr).contains(&format!("invalid value '{bad}' for '--max-output-bytes"))
                && text(&o.stderr)
                    .contains("must be a whole number of bytes from 1 to 1000000000000000 (10^15)"),
            "{bad}: {}",
            text(&o.stderr)
        );
    }
    let o = groundtruth("cam.yaml", &["--format", "tiff"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("invalid value 'tiff' for '--format <FORMAT>'")
            && text(&o.stderr).contains("[possible values: npy, npz, png]"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("gt").exists());
    let mut huge = benchmark_intrinsics();
    huge.image_width_px = 200_000;
    std::fs::write(
        d.path().join("huge.yaml"),
        write_camera(&huge, CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    let o = groundtruth("huge.yaml", &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("image_width = 200000: must be from 1 to 16384 px"),
        "{}",
        text(&o.stderr)
    );
    let fifo = std::process::Command::new("mkfifo")
        .arg(d.path().join("pipe.yaml"))
        .status()
        .unwrap();
    assert!(fifo.success());
    let o = groundtruth("pipe.yaml", &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains(
            "pipe.yaml: cannot read: is a FIFO (named pipe); only regular files are read"
        ),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("gt").exists());
}

/// The size of the output is printed first and bounded before anything is rendered: above
/// `--max-output-bytes` the run is refused (naming the bound, the limit and the smaller
/// formats) unless `--yes`; the printed file count is exact and the byte bound holds for every
/// `--format`; `npz` holds the same arrays as the `.npy` files (numpy), `png` writes no arrays.
#[test]
fn groundtruth_bounds_its_output_first_and_writes_npz_or_png_on_request() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let gt = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "extrinsics.json",
            "--fixtures",
            "fx",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        run(d.path(), &args, &[])
    };
    let o = gt("refused", &["--max-output-bytes", "1000"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.starts_with("groundtruth: reference + 4 configurations of "),
        "{err}"
    );
    assert!(
        err.contains("over --max-output-bytes 1000 (1 kB): refusing before rendering (hint: give --yes to write it, use --format npz (at most ")
            && err.contains(" or --format png (at most "),
        "{err}"
    );
    assert!(!d.path().join("refused").exists());
    for (out, format) in [("gt", "npy"), ("gtz", "npz"), ("gtp", "png")] {
        let o = gt(
            out,
            &["--format", format, "--max-output-bytes", "1000", "--yes"],
        );
        assert!(o.status.success(), "{format}: {}", text(&o.stderr));
        let m: serde_json::Value = serde_json::from_slice(
            &std::fs::read(d.path().join(out).join("manifest.json")).unwrap(),
        )
        .unwrap();
        let files = m["files"].as_array().unwrap();
        let bytes: u64 = files
            .iter()
            .map(|f| f["bytes"].as_u64().unwrap())
            .sum::<u64>()
            + std::fs::metadata(d.path().join(out).join("manifest.json"))
                .unwrap()
                .len();
        let (w, h) = (
            m["image"]["width_px"].as_u64().unwrap(),
            m["image"]["height_px"].as_u64().unwrap(),
        );
        let f = match format {
            "npy" => fabkit::calibration::groundtruth::dataset::DataFormat::Npy,
            "npz" => fabkit::calibration::groundtruth::dataset::DataFormat::Npz,
            _ => fabkit::calibration::groundtruth::dataset::DataFormat::Png,
        };
        let (n_files, bound) =
            fabkit::calibration::groundtruth::dataset::output_bound(w, h, 4, 2, f, None);
        assert_eq!(files.len() as u64 + 1, n_files, "{format}");
        // measured 0.08 to 0.63 of the bound
        assert!(
            bytes <= bound,
            "{format}: {bytes} bytes over the bound {bound}"
        );
        // the float arrays are written at their size; PNG (all of `png`) at deflate's worst case
        if format != "png" {
            assert!(
                bound <= 4 * bytes,
                "{format}: the bound {bound} is loose for {bytes} bytes"
            );
        }
        let line = format!(
            "groundtruth: reference + 4 configurations of {w} x {h} pixels -> {n_files} files, at most "
        );
        assert!(
            text(&o.stderr).lines().next().unwrap().starts_with(&line),
            "{}",
            text(&o.stderr)
        );
        let names: Vec<&str> = files.iter().map(|f| f["file"].as_str().unwrap()).collect();
        let arrays = names
            .iter()
            .filter(|n| n.ends_with(".npy") || n.ends_with(".npz") || n.ends_with(".ply"))
            .count();
        match format {
            // reference: range, z-depth, normals, PLY; each configuration also the two deltas
            "npy" => assert_eq!(arrays, 4 + 4 * 6, "{names:?}"),
            "npz" => assert_eq!(arrays, 5, "{names:?}"),
            _ => assert_eq!(arrays, 0, "{names:?}"),
        }
    }
    let Some(py) = oracle_python() else {
        return missing("the oracle python (numpy)");
    };
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("gt/manifest.json")).unwrap()).unwrap();
    let cfg = m["configurations"][0]["dir"].as_str().unwrap().to_string();
    let script = r#"
import sys, numpy as np
d, cfg = sys.argv[1], sys.argv[2]
for frame, names in [("reference", ["normals", "range_mm", "zdepth_mm"]),
                     (cfg, ["delta_range_mm", "delta_zdepth_mm", "normals", "range_mm", "zdepth_mm"])]:
    z = np.load(d + "/gtz/" + frame + "/arrays.npz")
    assert sorted(z.files) == names, (frame, z.files)
    for n in names:
        a = np.load(d + "/gt/" + frame + "/" + n + ".npy")
        assert a.dtype == np.float32 and np.array_equal(a, z[n], equal_nan=True), (frame, n)
print("ok")
"#;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(d.path())
        .arg(&cfg)
        .output()
        .unwrap();
    assert!(
        o.status.success() && text(&o.stdout).contains("ok"),
        "{}",
        text(&o.stderr)
    );
}

/// The raster memory is bounded before anything is allocated: an 8192 x 8192 or a
/// 16384 x 16384 camera with `--max-pixels` at its largest value, run under a 2 GB
/// address-space limit, exits 2 naming `--max-pixels` and the camera file's image size (the
/// 8192 x 8192 camera aborted on allocation: the limit let 16384 x 16384 through), and leaves
/// no output folder or temporary sibling behind. The largest `--max-pixels` is what the stated
/// memory budget holds; the old largest value is refused.
#[test]
fn a_camera_past_the_memory_budget_is_refused_before_allocating_under_a_2_gb_limit() {
    use fabkit_calibration::groundtruth::budget::{
        render_memory, MAX_PIXELS_LIMIT, MEMORY_BUDGET_BYTES,
    };
    assert!(render_memory(MAX_PIXELS_LIMIT, 1) <= MEMORY_BUDGET_BYTES);
    assert!(render_memory(MAX_PIXELS_LIMIT + 1, 1) > MEMORY_BUDGET_BYTES);
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("extrinsics.json"),
        r#"{"rvec": [0, 0, 0], "tvec_mm": [0, 0, 10]}"#,
    )
    .unwrap();
    let max = MAX_PIXELS_LIMIT.to_string();
    for side in [8192u32, 16384] {
        let mut i = benchmark_intrinsics();
        (i.image_width_px, i.image_height_px) = (side, side);
        (i.cx_px, i.cy_px) = (side as f64 / 2.0 - 0.5, side as f64 / 2.0 - 0.5);
        let cam = format!("cam{side}.yaml");
        std::fs::write(
            d.path().join(&cam),
            write_camera(&i, CameraFileFormat::OpenCvYaml),
        )
        .unwrap();
        let o = run_limited(
            d.path(),
            &gt_args(&cam, &["--max-pixels", &max]),
            &[],
            2_000_000,
        );
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{side}: {e}");
        let px = u64::from(side) * u64::from(side);
        assert!(
            e.contains(&format!(
                "{cam}: the camera image is {side} x {side} = {px} pixels, over the ground-truth limit of {max} pixels (image_width x image_height against --max-pixels"
            )) && e.contains("--max-pixels is at its largest value, what the render's memory budget of 2 GiB holds"),
            "{side}: {e}"
        );
        assert!(
            !e.contains("panicked") && !e.contains("memory allocation"),
            "{e}"
        );
        let left: Vec<_> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("gt"))
            .collect();
        assert!(left.is_empty(), "{side}: {left:?}");
    }
    // the old largest value, 16384 x 16384, is past the budget
    let o = run(
        d.path(),
        &gt_args("cam8192.yaml", &["--max-pixels", "268435456"]),
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("invalid value '268435456' for '--max-pixels")
            && text(&o.stderr).contains(&format!(
                "must be a whole number of pixels from 1 to {MAX_PIXELS_LIMIT} (2048 x 2048, what the render's memory budget of 2 GiB holds)"
            )),
        "{}",
        text(&o.stderr)
    );
}

/// A camera that sees (almost) none of the skin is refused before anything is written, naming
/// the camera file's fields as the file names them; focal lengths and principal points far
/// outside any camera are refused when the file is read (fx = 5e-324 px, fx = 1e300 px and
/// cx = 1e300 px exited 0 with a dataset of 0 or 1 skin pixels).
#[test]
fn a_camera_that_sees_too_little_of_the_skin_is_refused_naming_its_fields() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let gt = |camera: &str| run(d.path(), &gt_args(camera, &[]), &[]);
    type Set = fn(&mut fabkit_calibration::Intrinsics);
    let cases: [(Set, CameraFileFormat, &str); 4] = [
        (
            |i| i.fx_px = 5e-324,
            CameraFileFormat::OpenCvYaml,
            "fx_px = 5e-324: must be from 1 to 1e6 px",
        ),
        (
            |i| i.fx_px = 1e300,
            CameraFileFormat::Json,
            "fx_px = 1e300: must be from 1 to 1e6 px",
        ),
        (
            |i| i.cx_px = 1e300,
            CameraFileFormat::RosYaml,
            "cx_px = 1e300: the principal point must lie within the image",
        ),
        (
            |i| i.cy_px = -1e300,
            CameraFileFormat::OpenCvXml,
            "cy_px = -1e300: the principal point must lie within the image",
        ),
    ];
    for (k, (set, form, want)) in cases.into_iter().enumerate() {
        let mut i = benchmark_intrinsics();
        set(&mut i);
        let name = format!("bad{k}.cam");
        std::fs::write(d.path().join(&name), write_camera(&i, form)).unwrap();
        let o = gt(&name);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{want}: {e}");
        assert!(e.contains(&name) && e.contains(want), "{want}: {e}");
        assert!(e.len() < 1000, "{e}");
    }
    // Within the bounds but seeing (almost) none of the skin: a 1 px focal length puts all but
    // a few central pixels beyond the lens's field; the fields are named as each form names
    // them.
    let mut i = benchmark_intrinsics();
    (i.fx_px, i.fy_px) = (1.0, 1.0);
    for (name, form, fields) in [
        (
            "blind.yaml",
            CameraFileFormat::OpenCvYaml,
            "camera_matrix: fx = 1, fy = 1, cx = 319.5, cy = 239.5 px",
        ),
        (
            "blind.json",
            CameraFileFormat::Json,
            "fx_px = 1, fy_px = 1, cx_px = 319.5, cy_px = 239.5 px",
        ),
    ] {
        std::fs::write(d.path().join(name), write_camera(&i, form)).unwrap();
        let o = gt(name);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(
            e.contains(&format!(
                "{name}: {fields}, image 640 x 480 px: the camera sees the skin in "
            )) && e.contains(
                " of its 307200 pixels, fewer than the 3072 (1% of the image) ground truth needs"
            ) && !e.contains("rendering"),
            "{e}"
        );
    }
    assert!(!d.path().join("gt").exists());
    // the legitimate camera sees far more than the bound (the manifest counts its pixels)
    let o = gt("cam.yaml");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("gt/manifest.json")).unwrap()).unwrap();
    let seen = m["image"]["pixels_on_surface"].as_u64().unwrap();
    assert!(seen * 100 >= 640 * 480, "{seen}");
}

/// The output folder is checked before anything is read or rendered: `--out /` and a folder
/// of the user's own files are refused at once (they were refused only after rendering, for
/// seconds), before the camera's size is even checked.
#[test]
fn groundtruth_refuses_an_unusable_out_folder_before_any_work() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("mine")).unwrap();
    std::fs::write(d.path().join("mine/notes.txt"), "mine").unwrap();
    for (out, want) in [
        ("/", "output directory /: has no final directory name"),
        (
            "mine",
            "output directory mine is not a folder fabkit wrote: `notes.txt`",
        ),
    ] {
        // no camera file, extrinsics or fixtures at all: the folder is refused first
        let o = run(
            d.path(),
            &[
                "groundtruth",
                "--camera",
                "missing.yaml",
                "--extrinsics",
                "missing.json",
                "--fixtures",
                "missing",
                "--out",
                out,
            ],
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{out}");
        assert!(text(&o.stderr).contains(want), "{out}: {}", text(&o.stderr));
    }
    assert_eq!(
        std::fs::read_to_string(d.path().join("mine/notes.txt")).unwrap(),
        "mine"
    );
}

/// The memory estimate bounds the render: a 1024 x 1024 camera (4 configurations, 2 frames at
/// a time, with their images) renders under an address-space limit of the estimate
/// (`ulimit -v`).
#[test]
fn a_render_fits_in_its_memory_estimate_under_an_address_space_limit() {
    use fabkit_calibration::groundtruth::budget::{frames_at_once, render_memory};
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let mut i = benchmark_intrinsics();
    (i.image_width_px, i.image_height_px) = (1024, 1024);
    (i.fx_px, i.fy_px, i.cx_px, i.cy_px) = (344.0, 344.0, 511.5, 511.5);
    std::fs::write(
        d.path().join("big.json"),
        write_camera(&i, CameraFileFormat::Json),
    )
    .unwrap();
    let px = 1024 * 1024;
    let frames = frames_at_once(px, 2) as u64;
    assert_eq!(frames, 2);
    let limit_kb = render_memory(px, frames) / 1024;
    let o = run_limited(
        d.path(),
        &gt_args("big.json", &["--format", "npy", "--yes", "--images"]),
        &[("RAYON_NUM_THREADS", "2")],
        limit_kb,
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(d.path().join("gt/manifest.json").exists());
    assert!(d.path().join("gt/p001_0/image.png").exists());
}

/// DIGIT Pinki's ground truth through a camera file of the user's (OpenCV YAML, plumb_bob, a
/// camera looking up the axis from the seat's mouth on the base plane, as the fiber bundle's
/// end sits): its semi-domes render, and the reference range along the optical axis is the
/// distance to the gel's pole (the R7.5 tip 15.6 mm above the base plane).
#[test]
fn digit_pinki_ground_truth_through_the_users_camera_file() {
    use fabkit_calibration::{Distortion, Intrinsics};
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let o = run(
        dir,
        &[
            "fixtures",
            "digit_pinki",
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
    let k = Intrinsics {
        image_width_px: 400,
        image_height_px: 400,
        fx_px: 300.0,
        fy_px: 300.0,
        cx_px: 200.0,
        cy_px: 200.0,
        distortion: Distortion::PlumbBob([-0.05, 0.01, 0.0, 0.0, 0.0]),
    };
    std::fs::write(
        dir.join("cam.yaml"),
        write_camera(&k, CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    // the camera on the axis at the base plane (z = -8.1 mm), looking along +z
    let m = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 8.1],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let ext =
        serde_json::json!({"rvec": [0.0, 0.0, 0.0], "tvec_mm": [0.0, 0.0, 8.1], "T_cam_sensor": m});
    std::fs::write(
        dir.join("extrinsics.json"),
        serde_json::to_vec_pretty(&ext).unwrap(),
    )
    .unwrap();
    let o = run(dir, &design_gt_args("digit_pinki", "cam.yaml", &[]), &[]);
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(
        text(&o.stdout).contains("4 configurations (2 patterns x 2 orientations)"),
        "{}",
        text(&o.stdout)
    );
    let range = read_npy_f32(&dir.join("gt/reference/range_mm.npy"));
    assert_eq!(range.len(), 400 * 400);
    // the pixel whose centre is the principal point (200, 200) looks along the axis
    let centre = f64::from(range[200 * 400 + 200]);
    // measured 15.600 (the pole's range, exact but for float32 rounding)
    assert!(
        (centre - 15.6).abs() < 0.01,
        "range on the axis {centre} mm, the pole at 15.6 mm"
    );
    // every pixel sees the gel's outer surface: no range beyond the farthest point of it
    let far = 7.5 + 8.1;
    assert!(range
        .iter()
        .filter(|r| r.is_finite())
        .all(|&r| f64::from(r) <= far + 0.01));
}

/// A pose solved through the design's optical path (an extrinsics file with `optical_path`, as
/// `calibrate extrinsics --design rtac0` writes it): the depth maps are rendered with the rays
/// bent at the gel's surface (z = -9 mm, n = 1.41) and the glass tube's faces, as the library
/// renders them
/// (`Scene::through`, whose maps project back onto their pixels: calibration's refraction
/// tests), the manifest says so, and they differ from the straight rays' towards the rim; the
/// tactile images follow the same rays (the lights' own rays stay straight, as the manifest
/// says).
#[test]
fn a_pose_solved_through_the_gel_gives_depth_maps_through_it() {
    use fabkit_calibration::groundtruth::{reference_hits, DepthFrame, Scene};
    use fabkit_calibration::refraction::OpticalLayers;
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    setup(dir);
    let mut ext: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("extrinsics.json")).unwrap()).unwrap();
    let design = fabkit_designs::library::load("rtac0").unwrap();
    let path = fabkit_designs::optics::optical_path_of_design(
        &design,
        fabkit_designs::ChordTolerance::new(fabkit_designs::ChordTolerance::DEFAULT_MM).unwrap(),
    )
    .unwrap();
    ext["optical_path"] = serde_json::to_value(&path).unwrap();
    std::fs::write(
        dir.join("bent.json"),
        serde_json::to_vec_pretty(&ext).unwrap(),
    )
    .unwrap();
    let args = |ext: &'static str, out: &'static str, extra: &[&'static str]| {
        let mut a = vec![
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            ext,
            "--fixtures",
            "fx",
            "--out",
            out,
        ];
        a.extend(extra);
        a
    };
    let o = run(dir, &args("bent.json", "bent", &[]), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = run(dir, &args("extrinsics.json", "straight", &[]), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("bent/manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["optical_path"]["planes"][0]["z_mm"], -9.0);
    // the tube's faces as the file gives them, the equal-index one too
    let radii: Vec<f64> = manifest["optical_path"]["shells"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["radius_mm"].as_f64().unwrap())
        .collect();
    assert_eq!(radii, [9.0, 10.0, 13.5]);
    assert!(manifest["conventions"]["not_modelled"]
        .as_str()
        .unwrap()
        .starts_with("refraction at faces that are not planes or spheres"));
    // the library's render of the same scene, to float32
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let (pose, _) =
        fabkit_calibration::groundtruth::inputs::read_extrinsics(&dir.join("extrinsics.json"))
            .unwrap();
    let gel = OpticalLayers::from_optical_path(&path).unwrap();
    assert_eq!(gel.shells().len(), 2);
    let scene = Scene::through(&design, &cam, &pose, "pose", Some(&gel)).unwrap();
    let frame = DepthFrame::new(&scene.rays, &reference_hits(&scene.rays, &scene.surface));
    let bent = read_npy_f32(&dir.join("bent/reference/zdepth_mm.npy"));
    let straight = read_npy_f32(&dir.join("straight/reference/zdepth_mm.npy"));
    let (mut n, mut most) = (0, 0.0f32);
    for p in 0..bent.len() {
        let z = frame.zdepth_mm[p];
        if z.is_finite() {
            assert_eq!(bent[p], z as f32, "pixel {p}");
            n += 1;
            if straight[p].is_finite() {
                most = most.max((bent[p] - straight[p]).abs());
            }
        } else {
            assert!(bent[p].is_nan());
        }
    }
    eprintln!("{n} pixels; bent and straight depth differ by up to {most:.2} mm");
    // measured: 237,682 pixels (the rays the tube's mouth and seat let through); up to 8.19 mm
    // apart (the rim, seen through the gel's surface and the tube)
    assert!(n > 1000 && most > 0.5, "{n} {most}");
    // the tactile images through the same bent rays; the manifest says what they leave out
    let o = run(dir, &args("bent.json", "img", &["--images"]), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("img/manifest.json")).unwrap()).unwrap();
    let gaps = manifest["images"]["not_modelled"].as_str().unwrap();
    assert!(gaps.starts_with("refraction of the light"), "{gaps}");
    assert!(dir.join("img/reference/image.png").exists());
}
