"""Tests of fabkit.Camera and fabkit.solve_extrinsics against `fabkit calibrate extrinsics`.

The capture is synthetic: the 29 pin tips of an R-Tac0-like dome (pole + rings of 4, 6, 8, 10 on
a 16.65 mm sphere, as tests/e2e/calibrate_cli.rs) seen by a 160 x 120 fisheye camera (the
benchmark lens scaled down, ROS camera_info YAML) at a known pose, projected with
fabkit.Camera.project. The same numbers go to the CLI as files (floats written with repr, so
they parse back to the same doubles): the Python result must equal the CLI's extrinsics.json.
"""

import json
import re

import numpy as np
import pytest

import fabkit
from conftest import CAMERA_YAML, CX, CY, FX, FY, H, KB, W, cli_message

RVEC = [0.02, -0.015, 0.4]
TVEC = [0.3, -0.2, 10.4]


def rodrigues(r):
    r = np.asarray(r, float)
    th = np.linalg.norm(r)
    k = r / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def pose(rvec=RVEC, tvec=TVEC):
    t = np.eye(4)
    t[:3, :3] = rodrigues(rvec)
    t[:3, 3] = tvec
    return t


def pins():
    out = []
    for polar, n in [(0.0, 1), (17.87, 4), (35.74, 6), (53.6, 8), (71.5, 10)]:
        for k in range(n):
            p, a = np.radians(polar), 2 * np.pi * k / n
            out.append(16.65 * np.array([np.sin(p) * np.cos(a), np.sin(p) * np.sin(a), np.cos(p)]))
    return np.array(out)


def transform(t, p):
    return p @ t[:3, :3].T + t[:3, 3]


@pytest.fixture(scope="module")
def camera():
    return fabkit.Camera(FX, FY, CX, CY, W, H, "fisheye", KB)


def observe(camera, t=None, points=None):
    t = pose() if t is None else t
    points = pins() if points is None else points
    px = camera.project(transform(t, points))
    assert np.isfinite(px).all()
    return px


def write_inputs(d, points, pixels, obs_name="obs.csv"):
    (d / "cam.yaml").write_text(CAMERA_YAML)
    with open(d / "pts.csv", "w") as f:
        f.write("id,x_mm,y_mm,z_mm\n")
        for i, p in enumerate(points):
            f.write(f"{i},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r}\n")
    with open(d / obs_name, "w") as f:
        f.write("id,u_px,v_px\n")
        for i, p in enumerate(pixels):
            f.write(f"{i},{float(p[0])!r},{float(p[1])!r}\n")


def max_pose_error_mm(t_est, t_true, points):
    """Largest distance between the points mapped by the two poses (and the camera centres)."""
    a = transform(t_est, points)
    b = transform(t_true, points)
    ca = -t_est[:3, :3].T @ t_est[:3, 3]
    cb = -t_true[:3, :3].T @ t_true[:3, 3]
    return max(np.linalg.norm(a - b, axis=1).max(), np.linalg.norm(ca - cb))


def test_camera_from_file_reads_the_numbers_of_the_file(tmp_path, camera):
    (tmp_path / "cam.yaml").write_text(CAMERA_YAML)
    cam = fabkit.Camera.from_file(tmp_path / "cam.yaml")
    assert cam.intrinsics == {
        "image_width_px": W,
        "image_height_px": H,
        "fx_px": FX,
        "fy_px": FY,
        "cx_px": CX,
        "cy_px": CY,
        "distortion_model": "fisheye",  # ROS `equidistant` is Kannala-Brandt
        "distortion_coefficients": KB,
    }
    assert cam.shape == (H, W)
    assert cam.intrinsics == camera.intrinsics
    # the same model: the same pixels, bit for bit
    p = transform(pose(), pins())
    np.testing.assert_array_equal(cam.project(p), camera.project(p))
    # the principal point images the optical axis; a point behind the camera is not imaged
    uv = cam.project(np.array([[0.0, 0.0, 10.0], [0.0, 0.0, -10.0]]))
    np.testing.assert_array_equal(uv[0], [CX, CY])
    assert np.isnan(uv[1]).all()
    with pytest.raises(ValueError, match=r"model: 'bogus' is not a distortion model"):
        fabkit.Camera.from_file(tmp_path / "cam.yaml", model="bogus")
    with pytest.raises(fabkit.CalibrationError, match=r"^distortion_model fisheye: "):
        fabkit.Camera(FX, FY, CX, CY, W, H, "fisheye", KB[:3])


def test_solve_extrinsics_equals_the_cli_on_the_same_data(tmp_path, run_cli, camera):
    points = pins()
    pixels = observe(camera)
    # a +-0.3 px pattern, and one gross outlier (id 5) for RANSAC to reject
    noise = np.where(np.arange(len(points)) % 2 == 0, 0.3, -0.3)
    pixels = pixels + np.c_[noise, -0.5 * noise]
    pixels[5] += [20.0, -15.0]
    write_inputs(tmp_path, points, pixels)
    run_cli(tmp_path, "calibrate", "extrinsics", "--camera", "cam.yaml", "--points", "pts.csv",
            "--observations", "obs.csv", "--out", "out")
    j = json.loads((tmp_path / "out" / "extrinsics.json").read_text())

    ids = [str(i) for i in range(len(points))]
    r = fabkit.solve_extrinsics(points, pixels, fabkit.Camera.from_file(tmp_path / "cam.yaml"),
                                ids=ids)
    assert set(r) == {"T_cam_sensor", "residuals_px", "inliers", "outliers",
                      "rms_reprojection_error_px", "report"}
    t = r["T_cam_sensor"]
    assert t.shape == (4, 4) and t.dtype == np.float64
    # same code path: the same doubles
    np.testing.assert_array_equal(t, np.array(j["T_cam_sensor"]))
    np.testing.assert_array_equal(t[3], [0, 0, 0, 1])
    # rvec / tvec of the JSON are the matrix's
    np.testing.assert_allclose(t[:3, :3], rodrigues(j["rvec"]), atol=1e-12)
    np.testing.assert_array_equal(t[:3, 3], j["tvec_mm"])
    assert r["rms_reprojection_error_px"] == j["rms_reprojection_error_px"]
    # per-point residuals: reprojected minus observed, as the JSON's points
    jp = j["residuals"]["points"]
    assert [p["id"] for p in jp] == ids
    np.testing.assert_array_equal(np.array([p["observed_px"] for p in jp]), pixels)
    expected = np.array([p["reprojected_px"] for p in jp]) - np.array([p["observed_px"] for p in jp])
    np.testing.assert_array_equal(r["residuals_px"], expected)
    np.testing.assert_array_equal(np.linalg.norm(r["residuals_px"], axis=1),
                                  [p["reprojection_error_px"] for p in jp])
    # outliers: exactly the injected one, in both
    assert r["outliers"].dtype == bool and r["outliers"].shape == (len(points),)
    np.testing.assert_array_equal(r["outliers"], [not p["inlier"] for p in jp])
    np.testing.assert_array_equal(r["inliers"], ~r["outliers"])
    assert np.flatnonzero(r["outliers"]).tolist() == [5]
    assert j["residuals"]["outlier_ids"] == ["5"]
    # the report dict is the JSON's, number for number, but for where the inputs came from
    rep = r["report"]
    assert set(rep) == set(j)
    for key in j:
        if key != "provenance":
            assert rep[key] == j[key], key
    assert rep["provenance"]["points_file"] == "<arrays>"
    assert rep["provenance"]["camera_file"] == str(tmp_path / "cam.yaml")
    # the camera given as a path: the same solve
    r2 = fabkit.solve_extrinsics(points, pixels, str(tmp_path / "cam.yaml"), ids=ids)
    np.testing.assert_array_equal(r2["T_cam_sensor"], t)
    np.testing.assert_array_equal(r2["residuals_px"], r["residuals_px"])
    # and without RANSAC the outlier drags the pose (the rejection is what kept it)
    r3 = fabkit.solve_extrinsics(points, pixels, camera, ransac=False)
    assert not r3["outliers"].any()
    # measured 13 x
    assert r3["rms_reprojection_error_px"] > 2 * r["rms_reprojection_error_px"]


def test_noise_free_pixels_give_back_the_pose(camera):
    points = pins()
    for rvec, tvec in [(RVEC, TVEC), ([-0.05, 0.03, -1.2], [-0.4, 0.6, 9.8])]:
        truth = pose(rvec, tvec)
        r = fabkit.solve_extrinsics(points, observe(camera, truth), camera)
        err = max_pose_error_mm(r["T_cam_sensor"], truth, points)
        assert err < 1e-6, (rvec, tvec, err)
        assert np.abs(r["residuals_px"]).max() < 1e-6
        assert r["rms_reprojection_error_px"] < 1e-6
        assert not r["outliers"].any()
        assert r["report"]["residuals"]["outlier_ids"] == []


def test_gross_outliers_are_flagged_exactly_and_the_pose_kept(camera):
    points = pins()
    truth = pose()
    pixels = observe(camera, truth)
    bad = [3, 11, 20, 26]
    offsets = np.array([[12.0, -9.0], [-8.0, 15.0], [25.0, 4.0], [-6.0, -7.0]])
    pixels[bad] += offsets
    ids = [f"pin{i}" for i in range(len(points))]
    r = fabkit.solve_extrinsics(points, pixels, camera, ids=ids, threshold_px=2.0)
    # the pairs in another order: the same pose, bit for bit, the flags following their pairs;
    # a seed changes nothing (and says so)
    perm = np.random.default_rng(0).permutation(len(points))
    with pytest.warns(DeprecationWarning, match="seed has no effect"):
        rp = fabkit.solve_extrinsics(points[perm], pixels[perm], camera,
                                     ids=[ids[i] for i in perm], threshold_px=2.0, seed=7)
    np.testing.assert_array_equal(rp["T_cam_sensor"], r["T_cam_sensor"])
    np.testing.assert_array_equal(rp["outliers"], r["outliers"][perm])
    expected = np.zeros(len(points), bool)
    expected[bad] = True
    np.testing.assert_array_equal(r["outliers"], expected)
    assert r["report"]["residuals"]["outlier_ids"] == [ids[i] for i in bad]
    assert max_pose_error_mm(r["T_cam_sensor"], truth, points) < 1e-6
    # the outliers' residuals are minus the injected offsets (the pose is the true one)
    np.testing.assert_allclose(r["residuals_px"][bad], -offsets, atol=1e-6)
    assert np.abs(r["residuals_px"][~expected]).max() < 1e-6
    # without rejection the same data give a pose off by far more
    r2 = fabkit.solve_extrinsics(points, pixels, camera, ransac=False)
    # measured 1.56 mm
    assert max_pose_error_mm(r2["T_cam_sensor"], truth, points) > 1e-2


def test_a_non_finite_value_names_the_entry_and_the_rule_as_the_cli(tmp_path, run_cli, camera):
    points = pins()
    pixels = observe(camera)
    p = points.copy()
    p[2, 1] = np.nan
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.solve_extrinsics(p, pixels, camera)
    assert str(e.value) == "points_mm[2, 1] = NaN: must be finite"
    q = pixels.copy()
    q[3, 0] = np.inf
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.solve_extrinsics(points, q, camera)
    assert str(e.value) == "pixels_px[3, 0] = inf: must be finite"
    q[3, 0] = np.nan
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.solve_extrinsics(points, q, camera)
    py_msg = str(e.value)
    assert py_msg == "pixels_px[3, 0] = NaN: must be finite"
    assert isinstance(e.value, fabkit.FabkitError)
    # the CLI: the same value in the observation CSV (row of id 3 is line 5)
    write_inputs(tmp_path, points, q)
    out = run_cli(tmp_path, "calibrate", "extrinsics", "--camera", "cam.yaml", "--points",
                  "pts.csv", "--observations", "obs.csv", "--out", "out", ok=False)
    cli_msg = cli_message(out.stderr)
    # the CLI names file:line and column and echoes the cell's text (`nan` as written here)
    assert re.fullmatch(r"obs\.csv:5: u_px = nan: must be finite", cli_msg), cli_msg
    assert cli_msg.endswith(": must be finite") and py_msg.endswith(": must be finite")
    assert not (tmp_path / "out").exists()


def test_wrong_shapes_raise_value_error(camera):
    points = pins()
    pixels = observe(camera)
    cases = [
        (points[:, :2], pixels, r"points_mm: shape \(29, 2\) where \(n, 3\) is needed"),
        (points, points, r"pixels_px: shape \(29, 3\) where \(n, 2\) is needed"),
        (points.ravel(), pixels, r"points_mm: shape \(87,\) where \(n, 3\) is needed"),
        (points[None], pixels, r"points_mm: shape \(1, 29, 3\)"),
        (points, pixels[:-1], r"pixels_px: 28 rows for 29 points"),
        ("not numbers", pixels, r"points_mm: "),
    ]
    for p, q, match in cases:
        with pytest.raises(ValueError, match=match):
            fabkit.solve_extrinsics(p, q, camera)
    with pytest.raises(ValueError, match=r"ids: 2 ids for 29 points"):
        fabkit.solve_extrinsics(points, pixels, camera, ids=["a", "b"])
    with pytest.raises(ValueError, match=r"points_mm: shape \(4, 2\)"):
        camera.project(np.zeros((4, 2)))
    # array-likes of other dtypes are converted (lists, float32), not refused
    r = fabkit.solve_extrinsics(points.tolist(), pixels.astype(np.float32), camera)
    assert max_pose_error_mm(r["T_cam_sensor"], pose(), points) < 1e-2


def test_too_few_points_is_the_cli_message(tmp_path, run_cli, camera):
    points = pins()[:3]
    pixels = observe(camera, points=points)
    write_inputs(tmp_path, points, pixels)
    out = run_cli(tmp_path, "calibrate", "extrinsics", "--camera", "cam.yaml", "--points",
                  "pts.csv", "--observations", "obs.csv", "--out", "out", ok=False)
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.solve_extrinsics(points, pixels, camera)
    # the CLI names the files the pairs came from; the rest is the same message
    assert cli_message(out.stderr) == "pts.csv with obs.csv: " + str(e.value)
    assert str(e.value) == "3 usable point-pixel pairs: PnP needs at least 4"


def test_a_missing_camera_file_is_the_cli_message(tmp_path, run_cli, camera):
    points = pins()
    pixels = observe(camera)
    write_inputs(tmp_path, points, pixels)
    out = run_cli(tmp_path, "calibrate", "extrinsics", "--camera", "/nonexistent.yaml",
                  "--points", "pts.csv", "--observations", "obs.csv", "--out", "out", ok=False)
    expected = cli_message(out.stderr)
    assert "/nonexistent.yaml" in expected
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.Camera.from_file("/nonexistent.yaml")
    assert str(e.value) == expected
    with pytest.raises(fabkit.CalibrationError) as e:
        fabkit.solve_extrinsics(points, pixels, "/nonexistent.yaml")
    assert str(e.value) == expected


def test_solve_extrinsics_through_a_designs_gel_equals_the_cli(tmp_path, run_cli, camera):
    """With ``design``, the rays bend at the design's filling gel surface and glass tube as
    ``calibrate extrinsics --design`` bends them: the same pose, to the bit, and the report lists the
    optical path; without it, the same pixels put the camera elsewhere (straight rays)."""
    design = fabkit.Design.load("rtac0")
    # the CLI's pose through R-Tac0's gel from pixels made by straight projection at a pose
    # 17.4 mm under the dome's centre, under the gel's surface (z = -9 mm)
    t = pose(tvec=[-0.4, 0.3, 17.4])
    points = pins()
    pixels = observe(camera, t=t)
    write_inputs(tmp_path, points, pixels)
    run_cli(tmp_path, "calibrate", "extrinsics", "--camera", "cam.yaml", "--points", "pts.csv",
            "--observations", "obs.csv", "--design", "rtac0", "--out", "out")
    j = json.loads((tmp_path / "out" / "extrinsics.json").read_text())
    ids = [str(i) for i in range(len(points))]
    r = fabkit.solve_extrinsics(points, pixels, fabkit.Camera.from_file(tmp_path / "cam.yaml"),
                                ids=ids, design=design)
    np.testing.assert_array_equal(r["T_cam_sensor"], np.array(j["T_cam_sensor"]))
    assert r["report"]["optical_path"] == j["optical_path"]
    assert [p["z_mm"] for p in j["optical_path"]["planes"]] == [-9.0]
    assert r["report"]["optical_path_from"] == "design rtac0 (embedded:rtac0)"
    straight = fabkit.solve_extrinsics(points, pixels, camera, ids=ids)
    assert "optical_path" not in straight["report"]
    # straight pixels read through the gel and the tube: the camera comes out at another
    # distance (measured 5.95 mm; 19 of 29 pins are inliers at 0.28 px RMS, the outer ring out:
    # the tube's mouth hides it from where the straight pixels put the camera)
    assert max_pose_error_mm(r["T_cam_sensor"], straight["T_cam_sensor"], points) > 0.5
