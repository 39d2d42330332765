"""Tests of fabkit.calibrate_board against `fabkit calibrate board` on the real 9DTact board
press (tests/data/9dtact_sensor1/camera_calibration: the 7 x 9 board at 2.5 mm pressed into the
gel, and its reference), with the board's point table from `fabkit fixtures ninedtact`."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import fabkit
from conftest import cli_message

DATA = Path(__file__).resolve().parents[2] / "tests" / "data" / "9dtact_sensor1" / "camera_calibration"
REF, SAMPLE = str(DATA / "ref.png"), str(DATA / "sample.png")
FILES = sorted(["extrinsics.json", "extrinsics.yaml", "transform.yaml", "camera.yaml", "camera_info.yaml",
                "camera.json", "observations.csv", "pixel_to_plane_mm.npy", "overlay.png"])
# the plane's distance the design's housing gives: 2.8 mm of air, the 10.4 mm window over
# n = 1.491, the 2.5 mm translucent gel over 1.41, up to the opaque black gel
PLANE_DISTANCE_MM = 2.8 + 10.4 / 1.491 + 2.5 / 1.41


@pytest.fixture(scope="module")
def board(tmp_path_factory, run_cli):
    """(folder, its point table, the CLI's calibration, the Python one's result)."""
    d = tmp_path_factory.mktemp("board")
    run_cli(d, "fixtures", "ninedtact", "--out", "fx")
    table = d / "fx" / "points" / "board_table.csv"
    run_cli(d, "calibrate", "board", "--points", table, "--reference", REF, "--image", SAMPLE,
            "--out", "cli")
    r = fabkit.calibrate_board(table, REF, SAMPLE, d / "py")
    return d, table, d / "cli", r


def test_calibrate_board_calibrates_the_real_press(board):
    """63 of 63 bumps with their ids (1..63, grid order), the RMS reprojection error under 1.3 px
    (1.16 measured, as the CLI), the plane's distance from the design the point table names, the
    files written; the arrays agree with the report (pose, pixels, residuals) and the camera is
    the written camera.json's."""
    d, _, _, r = board
    rep = r["report"]
    assert rep["found"] == 63 and rep["missing_ids"] == []
    assert r["ids"] == [str(k) for k in range(1, 64)]
    assert r["rms_reprojection_error_px"] < 1.3
    assert r["rms_reprojection_error_px"] == rep["rms_reprojection_error_px"]
    assert abs(rep["plane_distance_mm"] - PLANE_DISTANCE_MM) < 1e-9
    assert "black_gel" in rep["plane_distance_from"]
    assert rep["board_turn_deg"] == 0
    assert r["files"] == FILES and r["warnings"] == []
    assert sorted(p.name for p in (d / "py").iterdir() if not p.name.startswith(".")) == FILES
    assert r["T_cam_sensor"].shape == (4, 4)
    np.testing.assert_array_equal(r["T_cam_sensor"], np.array(rep["T_cam_sensor"]))
    observed = np.array([b["observed_px"] for b in rep["bumps"]])
    reprojected = np.array([b["reprojected_px"] for b in rep["bumps"]])
    np.testing.assert_array_equal(r["observed_px"], observed)
    np.testing.assert_allclose(r["residuals_px"], reprojected - observed, atol=1e-12)
    assert isinstance(r["camera"], fabkit.Camera) and r["camera"].shape == (480, 640)
    fx = next(p for p in rep["parameters"] if p["name"] == "fx")
    assert r["camera"].intrinsics["fx_px"] == fx["value"]
    # the camera projects the bumps where the report puts them
    t = r["T_cam_sensor"]
    points = np.array([b["point_mm"] for b in rep["bumps"]])
    px = r["camera"].project(points @ t[:3, :3].T + t[:3, 3])
    np.testing.assert_allclose(px, reprojected, atol=1e-6)


def test_calibrate_board_writes_what_the_cli_writes(board):
    """Every file byte for byte as the CLI's, but extrinsics.json and .yaml, which differ in the
    command line only."""
    _, _, cli, r = board
    py = cli.parent / "py"
    for name in FILES:
        if name.startswith("extrinsics."):
            continue
        assert (py / name).read_bytes() == (cli / name).read_bytes(), name
    a = json.loads((py / "extrinsics.json").read_text())
    b = json.loads((cli / "extrinsics.json").read_text())
    assert a.pop("command_line") != b.pop("command_line")
    assert a == b


def test_the_plane_distance_from_a_design_or_a_number(board):
    """design as a Design or a library name gives the design's distance; plane_distance_mm is
    taken as given; with neither, a point table without its sidecar is refused naming
    plane_distance_mm, with nothing written."""
    d, table, _, _ = board
    for k, design in enumerate([fabkit.Design.load("ninedtact"), "ninedtact"]):
        r = fabkit.calibrate_board(table, REF, [SAMPLE], d / f"design{k}", design=design)
        assert abs(r["report"]["plane_distance_mm"] - PLANE_DISTANCE_MM) < 1e-9
    r = fabkit.calibrate_board(table, REF, SAMPLE, d / "given", plane_distance_mm=12.0)
    assert r["report"]["plane_distance_mm"] == 12.0
    assert r["report"]["plane_distance_from"] == "plane_distance_mm"
    bare = d / "bare.csv"
    shutil.copy(table, bare)
    with pytest.raises(fabkit.CalibrationError, match=r"plane_distance_mm: not given.*bare\.csv names none"):
        fabkit.calibrate_board(bare, REF, SAMPLE, d / "bare")
    assert not (d / "bare").exists()


def test_bad_input_is_the_cli_message_with_nothing_written(board, run_cli):
    """A turn other than 0, 90, 180 or 270 and a press of the reference itself (no imprint):
    CalibrationError with the message the CLI prints; a bad points_from or images: ValueError,
    TypeError. Nothing is written."""
    d, table, _, _ = board
    for extra, kwargs, image in [
        (["--board-turn", "45"], {"board_turn_deg": 45}, SAMPLE),
        (["--board-turn=-90"], {"board_turn_deg": -90}, SAMPLE),
        ([], {}, REF),
    ]:
        p = run_cli(d, "calibrate", "board", "--points", table, "--reference", REF, "--image",
                    image, "--out", "refused_cli", *extra, ok=False)
        with pytest.raises(fabkit.CalibrationError) as e:
            fabkit.calibrate_board(table, REF, image, d / "refused", **kwargs)
        assert str(e.value) == cli_message(p.stderr)
        assert not (d / "refused").exists() and not (d / "refused_cli").exists()
    with pytest.raises(ValueError, match="points_from = 'side': must be 'contact' or 'tip'"):
        fabkit.calibrate_board(table, REF, SAMPLE, d / "refused", points_from="side")
    with pytest.raises(TypeError, match="images"):
        fabkit.calibrate_board(table, REF, 3, d / "refused")
    assert not (d / "refused").exists()


def test_a_quarter_turned_camera_calibrates_with_board_turn_deg(board):
    """The real press turned a quarter clockwise as shown (numpy.rot90(img, -1), the image
    crate's rotate90: 480 x 640 px, the board 9 bumps tall and 7 wide), calibrated with
    board_turn_deg=90: 63 bumps, each id at the turned pixel of that id unturned (0.01 px), the
    RMS within 0.05 px of the unturned one's, and T_cam_sensor's rotation the unturned one
    followed by 90 deg about the camera's z (0.1 deg)."""
    cv2 = pytest.importorskip("cv2")
    d, table, _, r0 = board
    for name, src in (("ref_90.png", REF), ("sample_90.png", SAMPLE)):
        assert cv2.imwrite(str(d / name), np.ascontiguousarray(np.rot90(cv2.imread(src), -1)))
    r = fabkit.calibrate_board(table, d / "ref_90.png", d / "sample_90.png", d / "turned",
                               board_turn_deg=90)
    assert r["report"]["found"] == 63 and r["report"]["board_turn_deg"] == 90
    assert r["report"]["image_size_px"] == [480, 640]
    assert r["ids"] == r0["ids"]
    u0, v0 = r0["observed_px"].T
    np.testing.assert_allclose(r["observed_px"], np.stack([479.0 - v0, u0], axis=1), atol=0.01)
    assert abs(r["rms_reprojection_error_px"] - r0["rms_reprojection_error_px"]) < 0.05
    m = r["T_cam_sensor"][:3, :3] @ r0["T_cam_sensor"][:3, :3].T
    assert np.degrees(np.arctan2(m[1, 0], m[0, 0])) == pytest.approx(90.0, abs=0.1)
    assert np.degrees(np.arccos(np.clip(m[2, 2], -1, 1))) < 0.1
