"""Tests of fabkit.PressGroundTruth (the reader of a `fabkit groundtruth --press-image` folder)
on the real 9DTact ball press (tests/data/9dtact_sensor1/depth_calibration, a 4 mm ball) through
the camera its board press calibrates (`fabkit calibrate board`), as tests/e2e/groundtruth_press.rs
runs the CLI; written with --format npy and png."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import fabkit

DATA = Path(__file__).resolve().parents[2] / "tests" / "data" / "9dtact_sensor1"


@pytest.fixture(scope="module")
def folders(tmp_path_factory, run_cli):
    """{"npy": Path, "png": Path}: the press's ground truth made by the CLI."""
    d = tmp_path_factory.mktemp("press")
    run_cli(d, "fixtures", "ninedtact", "--out", "fx")
    run_cli(d, "calibrate", "board", "--points", "fx/points/board_table.csv",
            "--reference", DATA / "camera_calibration" / "ref.png",
            "--image", DATA / "camera_calibration" / "sample.png", "--out", "board")
    out = {}
    for fmt in ("npy", "png"):
        run_cli(d, "groundtruth", "ninedtact", "--camera", "board/camera.yaml",
                "--extrinsics", "board/extrinsics.json",
                "--press-image", DATA / "depth_calibration" / "sample.png",
                "--press-reference", DATA / "depth_calibration" / "ref.png",
                "--sphere-radius-mm", "4", "--format", fmt, "--out", f"gt_{fmt}")
        out[fmt] = d / f"gt_{fmt}"
    return out


def test_the_fit_is_press_json(folders):
    """The fit as press.json gives it: a 4 mm sphere 1.5 to 1.8 mm deep (1.715 measured, sd
    0.0016 mm) centred within 0.05 mm of (0.79, 0.79) mm (measured (0.778, 0.784)), with its
    standard deviations; the sphere's centre R above its lowest point; the pose and camera of
    the board calibration."""
    g = fabkit.PressGroundTruth(folders["npy"])
    fit = json.loads((folders["npy"] / "press.json").read_text())
    assert g.fit == fit
    assert g.radius_mm == 4.0
    assert 1.5 < g.depth_mm < 1.8 and g.depth_mm == fit["depth_mm"]
    assert g.centre_mm.shape == (2,) and np.abs(g.centre_mm - 0.79).max() < 0.05
    np.testing.assert_array_equal(g.centre_std_mm, fit["centre_std_mm"])
    assert 0 < g.centre_std_mm.max() < 0.01 and 0 < g.depth_std_mm < 0.1
    assert 0 < g.depth_spread_mm < 0.1
    assert g.sphere_centre_mm[2] == pytest.approx(2.8 - g.depth_mm + 4.0, abs=1e-12)
    assert g.lowest_point_px.shape == (2,)
    board = json.loads((folders["npy"].parent / "board" / "extrinsics.json").read_text())
    np.testing.assert_array_equal(g.T_cam_sensor, np.array(board["T_cam_sensor"]))
    assert g.shape == (480, 640) and g.format == "npy"
    assert "4 mm sphere" in repr(g)


def test_the_frames_hold_the_sphere_where_the_fit_puts_it(folders):
    """The pressed frame's z-depth difference is deepest by the fitted depth (0.01 mm; 0.0003
    measured) within 1 px of the pixel the sphere's lowest point projects to; the contact mask
    has the manifest's pixel count and is where the skin is pushed in; normals are unit
    vectors; the half masks cover the pixels that see the reference surface; every array is
    read-only."""
    g = fabkit.PressGroundTruth(folders["npy"])
    p, ref = g.press, g.reference
    assert set(p) == {"range_mm", "zdepth_mm", "delta_range_mm", "delta_zdepth_mm", "normals",
                      "contact"}
    assert set(ref) == {"range_mm", "zdepth_mm", "normals"}
    for name, a in list(p.items()) + list(ref.items()):
        want = (480, 640, 3) if name == "normals" else (480, 640)
        assert a.shape == want and not a.flags.writeable, name
    dz = p["delta_zdepth_mm"]
    k = np.unravel_index(np.nanargmin(dz), dz.shape)
    assert abs(-dz[k] - g.depth_mm) < 0.01
    assert np.hypot(k[1] - g.lowest_point_px[0], k[0] - g.lowest_point_px[1]) < 1.0
    np.testing.assert_allclose(p["zdepth_mm"], ref["zdepth_mm"] + dz, atol=1e-5)
    contact = p["contact"]
    assert contact.dtype == bool
    assert contact.sum() == g.manifest["configurations"][0]["contact_pixels"] > 0
    assert (dz[contact] < 0).all() and (dz[~contact] == 0).all()
    n = p["normals"]
    assert np.nanmax(np.abs(np.linalg.norm(n, axis=2) - 1)) < 1e-6
    left, right = g.masks
    assert not (left & right).any()
    np.testing.assert_array_equal(left | right, np.isfinite(ref["zdepth_mm"]))


def test_the_skin_is_the_deformed_one(folders):
    """The deformed skin (press/skin/): as deep as the fit at its deepest (0.01 mm); where the
    sphere touches it, the sphere's surface (the indenter frame's depth within 0.01 mm but for
    the contact's edge pixels); its contact mask inside the sphere's intersection with the face
    (elastic.contact_radius_mm 3.16 mm against 3.28, measured); round the contact the skin
    rises (an incompressible layer's bulge: delta z-depth > 0 somewhere, at most 0.4 mm) and
    settles within 0.05 mm far from it; elastic names its model and assumptions."""
    g = fabkit.PressGroundTruth(folders["npy"])
    s, p = g.skin, g.press
    assert set(s) == set(p)
    dz, di = s["delta_zdepth_mm"], p["delta_zdepth_mm"]
    assert abs(-np.nanmin(dz) - g.depth_mm) < 0.01
    contact = s["contact"]
    assert contact.sum() == g.manifest["configurations"][0]["skin"]["contact_pixels"] > 0
    assert (contact & ~p["contact"]).sum() <= 0.005 * contact.sum()
    off = np.abs(dz - di)[contact]
    assert np.median(off) < 1e-4 and (off > 0.01).sum() <= 0.005 * contact.sum()
    e = g.elastic
    assert 0.85 * e["geometric_contact_radius_mm"] < e["contact_radius_mm"]
    assert e["contact_radius_mm"] < e["geometric_contact_radius_mm"]
    assert e["thickness_mm"] == 2.8 and e["seen_depth_mm"] == 0.3 and e["assumptions"]
    assert 0.0 < np.nanmax(dz) < 0.4
    v, u = np.mgrid[:480, :640]
    r = np.hypot(u - g.lowest_point_px[0], v - g.lowest_point_px[1])
    assert np.nanmax(np.abs(dz[r > 220])) < 0.05


def test_the_captures_are_the_real_ones(folders):
    """The copies are the captures byte for byte, and decode to their pixels (OpenCV's, BGR)."""
    g = fabkit.PressGroundTruth(folders["npy"])
    src = DATA / "depth_calibration"
    assert Path(g.capture_file).read_bytes() == (src / "sample.png").read_bytes()
    assert Path(g.reference_capture_file).read_bytes() == (src / "ref.png").read_bytes()
    cap, ref = g.capture(), g.reference_capture()
    assert cap.shape == ref.shape == (480, 640, 3) and cap.dtype == np.uint8
    cv2 = pytest.importorskip("cv2")
    np.testing.assert_array_equal(cap[..., ::-1], cv2.imread(str(src / "sample.png")))
    np.testing.assert_array_equal(ref[..., ::-1], cv2.imread(str(src / "ref.png")))


def test_a_png_folder_reads_to_a_micrometre_without_normals(folders):
    """--format png: the same maps quantised to 1 um (half a count off the npy ones, and float32's
    rounding at 19 mm, 2 nm), the same contact, no normals."""
    a, b = fabkit.PressGroundTruth(folders["npy"]), fabkit.PressGroundTruth(folders["png"])
    assert b.format == "png" and "normals" not in b.press and "normals" not in b.reference
    for name in ("range_mm", "zdepth_mm", "delta_range_mm", "delta_zdepth_mm"):
        assert np.nanmax(np.abs(a.press[name] - b.press[name])) <= 0.0005 + 4e-6, name
    np.testing.assert_array_equal(a.press["contact"], b.press["contact"])
    assert b.depth_mm == a.depth_mm


def test_each_reader_refuses_the_others_folder(folders, tmp_path):
    """GroundTruth on a press's folder says to open it with PressGroundTruth; PressGroundTruth
    on a folder with no press (its manifest's press removed) says to open it with GroundTruth; a
    missing press.json or capture copy is named."""
    with pytest.raises(ValueError, match=r"--press-image.*fabkit\.PressGroundTruth"):
        fabkit.GroundTruth(folders["npy"])
    d = tmp_path / "gt"
    shutil.copytree(folders["npy"], d)
    m = json.loads((d / "manifest.json").read_text())
    del m["press"]
    (d / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match=r"no 'press'.*fabkit\.GroundTruth"):
        fabkit.PressGroundTruth(d)
    d = tmp_path / "gt2"
    shutil.copytree(folders["npy"], d)
    (d / "press" / "capture.png").unlink()
    with pytest.raises(FileNotFoundError, match=r"capture\.png: missing: press\.json's capture\.copy"):
        fabkit.PressGroundTruth(d)
    (d / "press.json").unlink()
    with pytest.raises(FileNotFoundError, match=r"press\.json: missing"):
        fabkit.PressGroundTruth(d)
