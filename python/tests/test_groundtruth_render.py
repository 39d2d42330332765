"""Tests of fabkit.DepthRenderer and fabkit.read_protrusions against `fabkit groundtruth`.

A 160 x 120 fisheye camera (ROS camera_info YAML), R-Tac0 with 2 protrusion patterns
(`fabkit fixtures --semidomes 2`), a pose inside the dome given to the CLI as the 4 x 4
T_cam_sensor of an extrinsics.json; the CLI writes --format npy, and the arrays rendered in
Python from the same camera file, the same matrix and the same fixtures folder must equal its
files exactly.
"""

import json
import warnings

import numpy as np
import pytest

import fabkit
from conftest import CAMERA_YAML, H, KB, W, cli_message, ran_during
from fabkit.groundtruth import _read_png

FRAME_ARRAYS = ("range_mm", "zdepth_mm", "delta_range_mm", "delta_zdepth_mm", "normals")


def rodrigues(r):
    r = np.asarray(r, float)
    th = np.linalg.norm(r)
    k = r / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def pose(rvec=(0.02, -0.015, 0.4), tvec=(0.3, -0.2, 10.4)):
    """The camera inside the dome, about 10.4 mm under the pole, slightly rotated."""
    t = np.eye(4)
    t[:3, :3] = rodrigues(rvec)
    t[:3, 3] = tvec
    return t


def write_extrinsics(path, t):
    # json writes floats with repr: the CLI reads back the same doubles
    path.write_text(json.dumps({"T_cam_sensor": np.asarray(t).tolist()}))


@pytest.fixture(scope="module")
def scene(tmp_path_factory, run_cli):
    d = tmp_path_factory.mktemp("render")
    (d / "cam.yaml").write_text(CAMERA_YAML)
    write_extrinsics(d / "extrinsics.json", pose())
    run_cli(d, "fixtures", "rtac0", "--semidomes", "2", "--seed", "3", "--format", "stl",
            "--out", "fx")
    run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--out", "gt", "--format", "npy")
    t = np.array(json.loads((d / "extrinsics.json").read_text())["T_cam_sensor"])
    design = fabkit.Design.load("rtac0")
    return {
        "dir": d,
        "gt": d / "gt",
        "design": design,
        "T": t,
        "sets": fabkit.read_protrusions(d / "fx", design),
        "renderer": fabkit.DepthRenderer(design, str(d / "cam.yaml"), t),
    }


def _mask(path):
    m = _read_png(str(path))
    assert m.dtype == np.uint8 and m.shape == (H, W)
    return m > 0


def test_read_protrusions_lists_the_configurations_the_cli_renders(scene):
    sets = scene["sets"]
    manifest = json.loads((scene["gt"] / "manifest.json").read_text())
    patterns = manifest["fixtures"]["patterns"]
    assert len(patterns) == 2
    assert [(s.pattern, s.orientation_deg) for s in sets] == [
        (p, o) for p in patterns for o in (0, 180)
    ]
    assert [s.name for s in sets] == [c["dir"] for c in manifest["configurations"]]
    assert all(s.name == f"{s.pattern}_{s.orientation_deg}" for s in sets)
    assert all(len(s) >= 1 for s in sets)
    assert all((scene["gt"] / s.name).is_dir() for s in sets)


def test_reference_equals_the_cli_files(scene):
    r = scene["renderer"]
    assert r.shape == (H, W)
    ref = r.reference()
    assert sorted(ref) == ["normals", "range_mm", "zdepth_mm"]
    for name, a in ref.items():
        f = np.load(scene["gt"] / "reference" / f"{name}.npy")
        assert a.dtype == np.float32 and a.shape == f.shape, name
        np.testing.assert_array_equal(a, f, err_msg=name)
    ok = np.isfinite(ref["range_mm"])
    manifest = json.loads((scene["gt"] / "manifest.json").read_text())
    assert ok.sum() == sum(m["pixels"] for m in manifest["masks_and_pairs"][:2]) > 5000
    assert not ok.all()  # the fisheye's corners see past the skin
    n = ref["normals"][ok]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    # the camera centre is the inverse of the pose's translation
    t = scene["T"]
    np.testing.assert_allclose(r.camera_centre_mm, -t[:3, :3].T @ t[:3, 3], atol=1e-9)


def test_every_configuration_equals_the_cli_files(scene):
    r = scene["renderer"]
    ref = r.reference()
    for s in scene["sets"]:
        frame = r.indented(s)
        assert sorted(frame) == sorted(FRAME_ARRAYS + ("contact",))
        folder = scene["gt"] / s.name
        for name in FRAME_ARRAYS:
            f = np.load(folder / f"{name}.npy")
            a = frame[name]
            assert a.dtype == np.float32 and a.shape == f.shape, (s.name, name)
            np.testing.assert_array_equal(a, f, err_msg=f"{s.name}/{name}")
        c = frame["contact"]
        assert c.dtype == bool and c.shape == (H, W)
        np.testing.assert_array_equal(c, _mask(folder / "contact_mask.png"), err_msg=s.name)
        # the protrusions are seen, and the skin is pushed towards the camera where they are
        assert c.any(), s.name
        d = frame["delta_range_mm"]
        assert np.nanmin(d) < 0 and (d[np.isfinite(d)] <= 0).all(), s.name
        assert not ((np.nan_to_num(d) < 0) & ~c).any(), s.name
        np.testing.assert_array_equal(np.isnan(d), np.isnan(ref["range_mm"]))
        # a 0-deg pattern is on the +x half, its 180-deg twin on the -x half
        left, right = r.masks()
        half = right if s.orientation_deg == 0 else left
        assert c[half].sum() == c.sum(), s.name


def test_indented_all_is_indented_in_order_with_progress(scene):
    r, sets = scene["renderer"], scene["sets"]
    calls = []
    frames = r.indented_all(sets, progress=lambda *a: calls.append(a))
    assert calls == [(k + 1, len(sets), s.name) for k, s in enumerate(sets)]
    assert len(frames) == len(sets)
    for s, f in zip(sets, frames):
        one = r.indented(s)
        for name in FRAME_ARRAYS + ("contact",):
            np.testing.assert_array_equal(f[name], one[name], err_msg=f"{s.name}/{name}")
    assert r.indented_all([]) == []


def test_images_equal_the_cli_pngs(scene, run_cli):
    """DepthRenderer.image gives the pixels `fabkit groundtruth --images` writes: the
    reference as frame 0, configuration i as frame i + 1, 8-bit RGB."""
    d, r = scene["dir"], scene["renderer"]
    run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--out", "gt_img", "--format", "png",
            "--images")
    ref = r.image()
    assert ref.dtype == np.uint8 and ref.shape == (H, W, 3)
    np.testing.assert_array_equal(ref, _read_png(str(d / "gt_img/reference/image.png")))
    for k, s in enumerate(scene["sets"]):
        img = r.image(s, frame=k + 1)
        np.testing.assert_array_equal(img, _read_png(str(d / "gt_img" / s.name / "image.png")),
                                      err_msg=s.name)
        # the imprint is where the contact mask is: the image changes most there
        c = r.indented(s)["contact"]
        diff = np.abs(img.astype(int) - ref.astype(int)).sum(axis=2)
        # measured 14 to 43 x
        assert diff[c].mean() > 4 * diff[~c & np.isfinite(r.reference()["range_mm"])].mean()
    # another frame index draws other noise, the same one the same
    assert not np.array_equal(r.image(frame=1), ref)
    np.testing.assert_array_equal(r.image(frame=0), ref)


def test_pin_captures_and_photometric_images_equal_the_cli(scene, run_cli):
    """read_pin_captures gives the frames `fabkit groundtruth --pin-captures` writes (named by
    their pins, the same images); a photometric model fitted on those captures by `fabkit
    calibrate photometric` and read with read_photometric renders, through
    DepthRenderer.image(..., photometric=model), the pixels `--images --photometric` writes."""
    d, r, design = scene["dir"], scene["renderer"], scene["design"]
    run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--pin-captures", "--out", "gt_pins",
            "--format", "png", "--images")
    # the stitched-pair reader says what such a folder is instead
    with pytest.raises(ValueError, match="pin dome's captures"):
        fabkit.GroundTruth(d / "gt_pins")
    pins = fabkit.read_pin_captures(d / "fx", design)
    plan = (d / "fx/points/capture_plan.csv").read_text().splitlines()[1:]
    assert len(pins) == len({row.split(",")[0] for row in plan})
    (d / "caps").mkdir()
    names = []
    for k, s in enumerate(pins):
        assert s.pins and s.name == "_".join("%02d" % int(i) for i in s.pins)
        img = r.image(s, frame=k + 1)
        cli = _read_png(str(d / "gt_pins" / s.name / "image.png"))
        np.testing.assert_array_equal(img, cli, err_msg=s.name)
        (d / "caps" / (s.name + ".png")).write_bytes((d / "gt_pins" / s.name / "image.png").read_bytes())
        names.append("caps/%s.png" % s.name)
    (d / "caps/ref.png").write_bytes((d / "gt_pins/reference/image.png").read_bytes())
    run_cli(d, "calibrate", "photometric", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--reference", "caps/ref.png", "--out", "ph",
            "--images", *names)
    model = fabkit.read_photometric(d / "ph")
    assert (model.width, model.height, model.bit_depth) == (W, H, 8)
    run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--out", "gt_ph", "--format", "png",
            "--images", "--photometric", "ph")
    ref = r.image(photometric=model)
    np.testing.assert_array_equal(ref, _read_png(str(d / "gt_ph/reference/image.png")))
    for s in scene["sets"]:
        img = r.image(s, photometric=model)
        np.testing.assert_array_equal(img, _read_png(str(d / "gt_ph" / s.name / "image.png")),
                                      err_msg=s.name)
        assert not np.array_equal(img, ref)
    # Issue 95: the model's design, camera and pose are checked as `groundtruth --photometric`
    # checks them (by their files' sha256); a pose given as values cannot be, and says so
    with pytest.warns(UserWarning, match="extrinsics was given as values"):
        r.image(photometric=model)
    by_file = fabkit.DepthRenderer(design, str(d / "cam.yaml"), str(d / "extrinsics.json"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(by_file.image(photometric=model), ref)
    moved = json.loads((d / "extrinsics.json").read_text())
    moved["T_cam_sensor"][0][3] += 0.5
    (d / "moved.json").write_text(json.dumps(moved))
    elsewhere = fabkit.DepthRenderer(design, str(d / "cam.yaml"), str(d / "moved.json"))
    with pytest.raises(fabkit.GroundTruthError, match="fitted with another extrinsics"):
        elsewhere.image(photometric=model)
    import pathlib
    text = (pathlib.Path(__file__).parents[2] / "designs/library/rtac0.yaml").read_text()
    (d / "edited.yaml").write_text(text + "\n# edited\n")
    edited = fabkit.DepthRenderer(fabkit.Design.load(str(d / "edited.yaml")),
                                  str(d / "cam.yaml"), str(d / "extrinsics.json"))
    with pytest.raises(fabkit.GroundTruthError, match="fitted with another design"):
        edited.image(photometric=model)
    # a model of another camera size is refused
    other = fabkit.DepthRenderer(design, str(d / "cam.yaml"), scene["T"], max_pixels=W * H)
    (d / "ph2").mkdir()
    (d / "ph2/photometric.json").write_bytes((d / "ph/photometric.json").read_bytes())
    np.save(d / "ph2/appearance.npy", np.zeros((4, 4, 3), np.float32))
    small = fabkit.read_photometric(d / "ph2")
    with pytest.raises(fabkit.GroundTruthError, match="4 x 4 px camera"):
        other.image(photometric=small)


def test_bad_optics_name_their_path(scene):
    import pathlib
    text = (pathlib.Path(__file__).parents[2] / "designs/library/rtac0.yaml").read_text()
    path = scene["dir"] / "rough.yaml"
    # R-Tac0's own optics section (its skin's darkness mapping) given a bad roughness
    path.write_text(text.replace("\noptics:\n  surface:\n", "\noptics:\n  surface:\n    roughness: 0\n", 1))
    design = fabkit.Design.load(str(path))
    r = fabkit.DepthRenderer(design, str(scene["dir"] / "cam.yaml"), scene["T"])
    with pytest.raises(fabkit.GroundTruthError, match=r"optics\.surface\.roughness"):
        r.image()


def test_masks_equal_the_cli_pngs(scene):
    left, right = scene["renderer"].masks()
    for m, name in ((left, "left_mask.png"), (right, "right_mask.png")):
        assert m.dtype == bool and m.shape == (H, W)
        np.testing.assert_array_equal(m, _mask(scene["gt"] / name), err_msg=name)
    assert not (left & right).any()
    np.testing.assert_array_equal(left | right,
                                  np.isfinite(scene["renderer"].reference()["range_mm"]))
    # measured 6,852 and 6,740
    assert left.sum() > 1000 and right.sum() > 1000


def test_camera_object_and_array_likes_render_the_same(scene):
    cam = fabkit.Camera.from_file(scene["dir"] / "cam.yaml")
    r2 = fabkit.DepthRenderer(scene["design"], cam, scene["T"].tolist())
    ref1, ref2 = scene["renderer"].reference(), r2.reference()
    for name in ref1:
        np.testing.assert_array_equal(ref1[name], ref2[name], err_msg=name)
    # another pose renders another image (the comparison above can fail)
    r3 = fabkit.DepthRenderer(scene["design"], cam, pose(tvec=(0.3, -0.2, 9.0)))
    assert not np.array_equal(r3.reference()["range_mm"], ref1["range_mm"], equal_nan=True)


def test_camera_outside_the_body_is_the_cli_message(scene, run_cli):
    d = scene["dir"]
    far = np.eye(4)
    far[2, 3] = -40.0  # the camera centre 40 mm above the pole
    write_extrinsics(d / "far.json", far)
    out = run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
                  "far.json", "--fixtures", "fx", "--out", "gt_far", ok=False)
    cli = cli_message(out.stderr)
    with pytest.raises(fabkit.GroundTruthError) as e:
        fabkit.DepthRenderer(scene["design"], str(d / "cam.yaml"), far)
    py = str(e.value)
    assert isinstance(e.value, fabkit.FabkitError)
    # the CLI names the extrinsics file, Python the argument; the rest is the same
    assert cli.startswith("far.json: the camera centre [0.000, 0.000, 40.000] mm"), cli
    assert py.startswith("T_cam_sensor: ")
    assert cli[len("far.json"):] == py[len("T_cam_sensor"):]
    assert not (d / "gt_far").exists()


def test_a_non_rigid_pose_names_the_rule_as_the_cli(scene, run_cli, monkeypatch):
    d = scene["dir"]
    monkeypatch.chdir(d)
    skew = np.eye(4)
    skew[0, 1] = 0.1
    skew[2, 3] = 10.0
    write_extrinsics(d / "skew.json", skew)
    out = run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
                  "skew.json", "--fixtures", "fx", "--out", "gt_skew", ok=False)
    with pytest.raises(fabkit.GroundTruthError) as e:
        fabkit.DepthRenderer(scene["design"], "cam.yaml", skew)
    py = str(e.value)
    assert py.startswith("T_cam_sensor = ")
    assert py.endswith(": the 3 x 3 block must be a rotation (orthonormal, determinant +1, to 1e-6)")
    assert cli_message(out.stderr) == "skew.json: " + py
    # a last row other than [0, 0, 0, 1]
    bad = pose()
    bad[3, 0] = 0.5
    with pytest.raises(fabkit.GroundTruthError, match=r"^T_cam_sensor\[3\] = .*: must be \[0, 0, 0, 1\]$"):
        fabkit.DepthRenderer(scene["design"], str(d / "cam.yaml"), bad)


def test_a_non_finite_pose_and_wrong_shapes(scene):
    cam = str(scene["dir"] / "cam.yaml")
    t = pose()
    t[1, 3] = np.nan
    with pytest.raises(fabkit.GroundTruthError, match=r"^T_cam_sensor = .*: must be finite$"):
        fabkit.DepthRenderer(scene["design"], cam, t)
    with pytest.raises(ValueError, match=r"T_cam_sensor: shape \(3, 4\) where \(4, 4\) is needed"):
        fabkit.DepthRenderer(scene["design"], cam, pose()[:3])
    with pytest.raises(ValueError, match=r"T_cam_sensor: shape \(16,\)"):
        fabkit.DepthRenderer(scene["design"], cam, pose().ravel())


def test_max_pixels_is_the_cli_limit(scene, run_cli, monkeypatch):
    d = scene["dir"]
    monkeypatch.chdir(d)  # the camera file named as the CLI names it
    out = run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
                  "extrinsics.json", "--fixtures", "fx", "--out", "gt_small",
                  "--max-pixels", str(W * H - 1), ok=False)
    with pytest.raises(fabkit.GroundTruthError) as e:
        fabkit.DepthRenderer(scene["design"], "cam.yaml", scene["T"], max_pixels=W * H - 1)
    # the same message but for the hint (a keyword argument, not a command-line option)
    cli, py = cli_message(out.stderr), str(e.value)
    stem = f"cam.yaml: the camera image is {W} x {H} = {W * H} pixels, over the ground-truth limit of {W * H - 1} pixels"
    assert cli.startswith(stem) and py.startswith(stem), (cli, py)
    assert py.endswith("raise max_pixels)")
    assert fabkit.DepthRenderer(scene["design"], "cam.yaml", scene["T"], max_pixels=W * H).shape == (H, W)
    # bounded by the render's memory budget, as --max-pixels
    with pytest.raises(ValueError, match=r"max_pixels = 4194305: must be from 1 to 4194304"):
        fabkit.DepthRenderer(scene["design"], "cam.yaml", scene["T"], max_pixels=2048 * 2048 + 1)


def test_renders_release_the_gil(scene):
    # a larger camera (1280 x 960, the same lens) so that each render takes a while
    s = 8
    cam = fabkit.Camera(53.75 * s, 53.75 * s, (W * s - 1) / 2, (H * s - 1) / 2, W * s, H * s,
                        "fisheye", KB)
    design, t, sets = scene["design"], scene["T"], scene["sets"]
    holder = {}

    def construct():
        holder["r"] = fabkit.DepthRenderer(design, cam, t)

    for what, call in (("DepthRenderer()", construct),
                       ("indented()", lambda: holder["r"].indented(sets[0])),
                       ("indented_all()", lambda: holder["r"].indented_all(sets[:2]))):
        # another thread ran while the call did: with the GIL held by the render it could not
        # (conftest.ran_during: no clock)
        _, during = ran_during(call)
        assert during, what
    assert holder["r"].shape == (H * s, W * s)


def test_a_camera_that_sees_no_skin_is_refused(scene):
    # the camera turned about its own centre to look at the base: no pixel sees the skin
    away = np.diag([1.0, -1.0, -1.0, 1.0]) @ scene["T"]
    with pytest.raises(fabkit.GroundTruthError,
                       match=r"the camera sees the skin in \d+ of its \d+ pixels, fewer than"):
        fabkit.DepthRenderer(scene["design"], str(scene["dir"] / "cam.yaml"), away)


def _tree(folder):
    """{relative path: bytes} of every file under folder."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.parametrize(
    "out,extra,kwargs",
    [
        ("gt", ("--format", "npy"), {"format": "npy"}),
        ("gt_npz_img", ("--format", "npz", "--images"), {"format": "npz", "images": True}),
    ],
)
def test_write_is_the_cli_dataset_byte_for_byte(scene, run_cli, fabkit_bin, monkeypatch,
                                                out, extra, kwargs):
    """DepthRenderer.write, given the CLI's inputs (the same relative paths from the same
    folder) and its command line, writes the dataset `fabkit groundtruth` writes: every file,
    the manifest and the output marker, byte for byte; GroundTruth reads both alike."""
    d = scene["dir"]
    args = ["groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "extrinsics.json", "--fixtures", "fx", "--out", out, *extra]
    if out != "gt":
        run_cli(d, *args)
    monkeypatch.chdir(d)
    r = fabkit.DepthRenderer(fabkit.Design.load("rtac0"), "cam.yaml", "extrinsics.json")
    seen = []
    written = r.write(out + "_py", "fx", command_line=[fabkit_bin, *args],
                      progress=lambda done, total, msg: seen.append((done, total)), **kwargs)
    cli, py = _tree(d / out), _tree(d / (out + "_py"))
    assert sorted(py) == sorted(cli)
    assert len(py) > 10 and written[-1] == fabkit.GROUNDTRUTH_FILES["manifest"]
    assert set(written) <= set(py) and len(written) == len(py) - 1  # and the marker
    for rel in cli:
        assert py[rel] == cli[rel], rel
    assert sorted(seen)[-1] == (len(scene["sets"]) + 1,) * 2
    a, b = fabkit.GroundTruth(d / out), fabkit.GroundTruth(d / (out + "_py"))
    assert len(a) == len(b) == 4
    for pa, pb in zip(a, b):
        np.testing.assert_array_equal(pa.delta_zdepth_mm, pb.delta_zdepth_mm)
        np.testing.assert_array_equal(pa.contact, pb.contact)
    # the same inputs again replace the earlier output; another's folder is refused
    r.write(out + "_py", "fx", command_line=[fabkit_bin, *args], **kwargs)
    assert _tree(d / (out + "_py")) == py
    with pytest.raises(fabkit.FabkitError, match="fx"):
        r.write("fx", "fx", **kwargs)


def test_write_bounds_its_output_before_rendering(scene, monkeypatch):
    monkeypatch.chdir(scene["dir"])
    r = scene["renderer"]
    with pytest.raises(fabkit.GroundTruthError, match="max_output_bytes = 1000: refused before rendering"):
        r.write("gt_small", "fx", max_output_bytes=1000)
    assert not (scene["dir"] / "gt_small").exists()
    with pytest.raises(ValueError, match="format = 'tiff'"):
        r.write("gt_small", "fx", format="tiff")


def test_an_extrinsics_file_with_an_optical_path_bends_the_rays_as_the_cli(scene, run_cli):
    """An extrinsics.json solved through R-Tac0's gel and glass tube (its ``optical_path``, as
    ``calibrate extrinsics --design`` writes it): ``fabkit groundtruth`` bends the rays at the
    gel's surface and the tube's faces, and so does DepthRenderer given that file: the same
    arrays, the manifest lists the same planes and faces; the same matrix given as an array
    renders straight rays."""
    d = scene["dir"]
    t = pose(tvec=(0.3, -0.2, 17.4))  # 17.4 mm under the dome's centre, under the gel (-9 mm)
    tube = [{"radius_mm": r, "centre_z_mm": 0.0, "join_z_mm": 0.0, "bottom_z_mm": -9.0,
             "outside_bottom_z_mm": b, "index_outside": n, "what": w}
            for r, b, n, w in [(9.0, -9.0, 1.473, "core: the core's inner face"),
                               (10.0, -6.0, 1.41, "core: the core's outer face")]]
    e = {"T_cam_sensor": t.tolist(),
         "optical_path": {"planes": [{"z_mm": -9.0, "index_above": 1.41,
                                      "what": "housing.filling_gel: the gel's free surface"}],
                          "shells": tube}}
    (d / "through.json").write_text(json.dumps(e))
    run_cli(d, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics", "through.json",
            "--fixtures", "fx", "--out", "gt_through", "--format", "npy")
    design = scene["design"]
    bent = fabkit.DepthRenderer(design, str(d / "cam.yaml"), str(d / "through.json"))
    for name, a in bent.reference().items():
        f = np.load(d / "gt_through" / "reference" / f"{name}.npy")
        np.testing.assert_array_equal(a, f, err_msg=name)
    bent.write(d / "py_through", d / "fx", format="npy")
    path = lambda p: json.loads((p / "manifest.json").read_text())["optical_path"]
    assert path(d / "py_through")["planes"] == path(d / "gt_through")["planes"]
    assert path(d / "py_through")["shells"] == path(d / "gt_through")["shells"]
    assert [s["radius_mm"] for s in path(d / "gt_through")["shells"]] == [9.0, 10.0]
    straight = fabkit.DepthRenderer(design, str(d / "cam.yaml"), t)
    r_bent, r_straight = bent.reference()["range_mm"], straight.reference()["range_mm"]
    both = np.isfinite(r_bent) & np.isfinite(r_straight)
    # measured: up to 3.38 mm apart (the bent rays meet the skin elsewhere towards the rim)
    assert np.abs(r_bent[both] - r_straight[both]).max() > 0.5
