"""Tests of fabkit.groundtruth (the reader of a `fabkit groundtruth` folder) against folders made
by the CLI: a 160 x 120 fisheye camera, R-Tac0 with 2 protrusion patterns, written with
--format npy, npz and png.

The CLI binary comes from the environment variable FABKIT_BIN (the tests are skipped without
it). The reader takes the dataset's file names from the native extension
(fabkit.GROUNDTRUTH_FILES), as the writer does.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import CAMERA_YAML, H, W

from fabkit import groundtruth as gtr

GroundTruth, StitchedPair = gtr.GroundTruth, gtr.StitchedPair

# The camera inside the dome, 10.4 mm under the pole, slightly rotated (as tests/e2e).
EXTRINSICS = {"rvec": [0.02, -0.015, 0.4], "tvec_mm": [0.3, -0.2, 10.4]}
SCALARS = ("range_mm", "zdepth_mm", "delta_range_mm", "delta_zdepth_mm")
EPS32 = float(np.finfo(np.float32).eps)


def _run(binary, cwd, *args):
    p = subprocess.run(
        [binary, *args], cwd=cwd, capture_output=True, text=True, timeout=300
    )
    assert p.returncode == 0, f"fabkit {' '.join(args)} failed:\n{p.stderr}"
    return p


@pytest.fixture(scope="module")
def folders(tmp_path_factory, fabkit_bin):
    """{"npy": Path, "npz": Path, "png": Path, "fixtures": Path} made by the CLI."""
    binary = fabkit_bin
    d = tmp_path_factory.mktemp("groundtruth")
    (d / "cam.yaml").write_text(CAMERA_YAML)
    (d / "extrinsics.json").write_text(json.dumps(EXTRINSICS))
    _run(binary, d, "fixtures", "rtac0", "--semidomes", "2", "--seed", "3",
         "--format", "stl", "--out", "fx")
    out = {"fixtures": d / "fx"}
    for fmt in ("npy", "npz", "png"):
        _run(binary, d, "groundtruth", "rtac0", "--camera", "cam.yaml",
             "--extrinsics", "extrinsics.json", "--fixtures", "fx",
             "--out", f"gt_{fmt}", "--format", fmt)
        out[fmt] = d / f"gt_{fmt}"
    return out


@pytest.fixture(scope="module")
def gt(folders):
    return GroundTruth(folders["npy"])


def _manifest(folder):
    return json.loads((Path(folder) / "manifest.json").read_text())


def _npy(folder, frame, name):
    a = np.load(Path(folder) / frame / f"{name}.npy")
    assert a.dtype == np.float32
    return a


def test_length_is_n_squared_in_pairs_csv_order(gt, folders):
    m = _manifest(folders["npy"])
    patterns = m["fixtures"]["patterns"]
    assert len(patterns) == 2
    assert len(gt) == len(patterns) ** 2 == m["masks_and_pairs"][2]["pairs"]
    assert gt.format == "npy" and gt.shape == (H, W)
    expected = [(r, l) for r in patterns for l in patterns]  # right pattern major
    got = [(p.right_pattern, p.left_pattern) for p in gt]
    assert got == expected
    for k, p in enumerate(gt):
        assert isinstance(p, StitchedPair) and p.index == k
        assert (p.right_dir, p.left_dir) == (f"{p.right_pattern}_0", f"{p.left_pattern}_180")


def test_sequence_protocol(gt):
    n = len(gt)
    assert gt[-1].index == n - 1 and gt[-n].index == 0
    with pytest.raises(IndexError):
        gt[n]
    with pytest.raises(IndexError):
        gt[-n - 1]
    with pytest.raises(TypeError):
        gt["p001"]
    assert [p.index for p in gt[1:3]] == [1, 2]
    assert [p.index for p in gt[::-1]] == list(range(n))[::-1]
    assert sum(1 for _ in gt) == n
    assert gt[np.int64(1)].index == 1


def test_masks_partition_the_surface_pixels(gt, folders):
    m = _manifest(folders["npy"])
    left, right = gt.masks
    assert left.dtype == bool and left.shape == (H, W) and right.shape == (H, W)
    assert not (left & right).any()
    assert int(left.sum()) == m["masks_and_pairs"][0]["pixels"]
    assert int(right.sum()) == m["masks_and_pairs"][1]["pixels"]
    ref = _npy(folders["npy"], "reference", "range_mm")
    assert np.array_equal(left | right, np.isfinite(ref))
    # measured 6,852 and 6,740
    assert left.sum() > 1000 and right.sum() > 1000


def test_pairs_are_the_right_and_left_frames_on_their_masks(gt, folders):
    left, right = gt.masks
    neither = ~(left | right)
    for p in gt:
        for name in SCALARS + ("normals",):
            a = getattr(p, name)
            r = _npy(folders["npy"], p.right_dir, name)
            l_ = _npy(folders["npy"], p.left_dir, name)
            assert a.dtype == np.float32 and a.shape == r.shape, name
            assert np.array_equal(a[right], r[right]), (p.index, name)
            assert np.array_equal(a[left], l_[left]), (p.index, name)
            assert np.isnan(a[neither]).all(), (p.index, name)
            # complete on the surface: NaN exactly where neither mask
            finite = np.isfinite(a) if a.ndim == 2 else np.isfinite(a).all(axis=2)
            assert np.array_equal(finite, ~neither), (p.index, name)
        assert p.contact.dtype == bool and p.contact.shape == (H, W)
        assert not p.contact[neither].any()
        # where the skin is pushed in, the surface seen is a protrusion
        pushed = np.nan_to_num(p.delta_range_mm, nan=0.0) < 0
        assert pushed.any() and not (pushed & ~p.contact).any(), p.index
        # each half's contact pixels are the frame's contact pixels on that half; the manifest
        # counts a frame's contact pixels over the whole image
        assert p.contact.sum() <= sum(
            c["contact_pixels"] for c in _manifest(folders["npy"])["configurations"]
            if c["dir"] in (p.right_dir, p.left_dir)
        )
        n = p.normals[~neither]
        assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)


def test_pairs_are_fresh_arrays(gt):
    a = gt[0]
    a.range_mm[:] = 0.0
    a.contact[:] = True
    b = gt[0]
    assert np.isnan(b.range_mm).any() and not b.contact.all()


def test_delta_is_indented_minus_reference(gt):
    ref = gt.reference
    assert sorted(ref) == ["normals", "range_mm", "zdepth_mm"]
    assert ref["range_mm"].shape == (H, W) and ref["normals"].shape == (H, W, 3)
    for p in gt:
        for full, delta, rname in (("range_mm", "delta_range_mm", "range_mm"),
                                   ("zdepth_mm", "delta_zdepth_mm", "zdepth_mm")):
            ind, d, r = getattr(p, full), getattr(p, delta), ref[rname]
            ok = np.isfinite(r)
            tol = 4 * EPS32 * np.maximum(np.abs(ind[ok]), np.abs(r[ok]))
            assert (np.abs(d[ok] - (ind[ok] - r[ok])) <= tol).all(), (p.index, delta)
            assert np.isnan(d[~ok]).all()
            assert (d[ok] <= 0).all() or delta == "delta_zdepth_mm"
        assert (p.delta_range_mm[np.isfinite(p.delta_range_mm)] <= 0).all()


def test_npz_folder_reads_to_the_same_arrays(gt, folders):
    gz = GroundTruth(folders["npz"])
    assert gz.format == "npz" and len(gz) == len(gt)
    for a, b in zip(gt, gz):
        for name in StitchedPair._fields:
            x, y = getattr(a, name), getattr(b, name)
            if isinstance(x, np.ndarray):
                assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
            else:
                assert x == y, name
    for name, x in gt.reference.items():
        assert np.array_equal(x, gz.reference[name], equal_nan=True), name
    assert all(np.array_equal(x, y) for x, y in zip(gt.masks, gz.masks))


def test_png_folder_reads_to_a_micrometre(gt, folders):
    gp = GroundTruth(folders["png"])
    assert gp.format == "png" and len(gp) == len(gt)
    assert "normals" not in gp.reference
    for a, b in zip(gt, gp):
        assert b.normals is None
        assert np.array_equal(a.contact, b.contact)
        for name in SCALARS:
            x, y = getattr(a, name), getattr(b, name)
            assert y.dtype == np.float32
            assert np.array_equal(np.isnan(x), np.isnan(y)), name
            ok = np.isfinite(x)
            # rounded to 1 um counts; float32 of the decoded value adds its own rounding
            assert np.abs(x[ok] - y[ok]).max() <= 0.0005 + 1e-5, name


def test_camera_and_extrinsics_from_the_manifest(gt, folders):
    m = _manifest(folders["npy"])
    assert gt.manifest == m
    assert gt.camera["image_width_px"] == W and gt.camera["image_height_px"] == H
    assert gt.camera["distortion_model"] == "fisheye"
    t = gt.T_cam_sensor
    assert t.shape == (4, 4) and t.dtype == np.float64
    assert np.array_equal(t, np.array(m["extrinsics"]["T_cam_sensor"]))
    assert np.allclose(t[:3, :3] @ t[:3, :3].T, np.eye(3), atol=1e-12)
    assert np.array_equal(t[3], [0, 0, 0, 1])
    assert np.allclose(t[:3, 3], EXTRINSICS["tvec_mm"])


def test_bad_folders_name_the_file(folders, tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        GroundTruth(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="manifest.json"):
        GroundTruth(tmp_path / "empty")
    # the fixtures folder has a manifest.json of another kind
    with pytest.raises(ValueError, match=r"manifest\.json.*'reference'.*not the manifest of `fabkit groundtruth`"):
        GroundTruth(folders["fixtures"])

    broken = tmp_path / "broken"
    shutil.copytree(folders["npy"], broken)
    (broken / "p002_180" / "zdepth_mm.npy").unlink()
    with pytest.raises(FileNotFoundError, match=r"p002_180[/\\]zdepth_mm\.npy: missing"):
        GroundTruth(broken)

    nomask = tmp_path / "nomask"
    shutil.copytree(folders["npz"], nomask)
    (nomask / "left_mask.png").unlink()
    with pytest.raises(FileNotFoundError, match="left_mask.png"):
        GroundTruth(nomask)

    badjson = tmp_path / "badjson"
    shutil.copytree(folders["npz"], badjson)
    (badjson / "manifest.json").write_text('{"reference": ')
    with pytest.raises(ValueError, match=r"manifest\.json:1:\d+: not JSON"):
        GroundTruth(badjson)

    badpairs = tmp_path / "badpairs"
    shutil.copytree(folders["npz"], badpairs)
    text = (badpairs / "pairs.csv").read_text().replace("p002_180", "p009_180")
    (badpairs / "pairs.csv").write_text(text)
    with pytest.raises(ValueError, match=r"pairs\.csv:3: left_dir = p009_180"):
        GroundTruth(badpairs)

    shortpairs = tmp_path / "shortpairs"
    shutil.copytree(folders["npz"], shortpairs)
    lines = (shortpairs / "pairs.csv").read_text().splitlines()[:-1]
    (shortpairs / "pairs.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"pairs\.csv: 3 pairs: must be N x N = 4"):
        GroundTruth(shortpairs)

    # a frame file that goes bad after the folder was opened is reported when read
    late = tmp_path / "late"
    shutil.copytree(folders["npy"], late)
    g = GroundTruth(late, cache_frames=0)
    np.save(late / "p001_0" / "range_mm.npy", np.zeros((3, 3), np.float32))
    with pytest.raises(ValueError, match=r"p001_0[/\\]range_mm\.npy: float32 \(3, 3\): must be float32 of shape \(120, 160\)"):
        g[0]


def test_reader_does_not_import_torch(tmp_path):
    code = "import sys, fabkit.groundtruth\nprint('torch' in sys.modules)\n"
    # from another folder than python/, whose fabkit/ has no native extension
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=tmp_path)
    assert out.stdout.strip() == "False"
