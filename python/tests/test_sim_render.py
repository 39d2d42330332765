"""MuJoCo renders the sensor's camera of `fabkit export --format mjcf` off screen (EGL on the
CPU: Mesa's llvmpipe; MUJOCO_GL is set to egl in conftest.py), and the skin it sees is fabkit's
own ground truth's: the pixels whose ray meets the skin's outer surface (`DepthRenderer.
reference()`, the NaN-free pixels of `range_mm`, as `fabkit groundtruth` writes them) for the
same pinhole camera at the same pose, through straight rays (MuJoCo's cameras do not refract;
R-Tac0's glass tube and gel do: docs/src/guide/export.md, Simulators).

Every library design: where the design seats a camera, where `fabkit calibrate nominal` puts it
(ShadowTac with --view-angle-deg 120: its skin fills the picture); elsewhere (DIGIT-pinki,
Soter, 9DTact) on the sensor's axis under the skin, far enough for the skin's edge to be in the
picture. The camera is a 640 x 480 pinhole of 200 px focal length (`--camera pin.yaml
--extrinsics`). MuJoCo draws the skin's layers alone (segmentation rendering): IoU >= 0.98 with
the ground truth's mask (measured 0.9994 to 1.0; 9DTact's wrapped black gel is in both).
"""

import json
import os
from pathlib import Path

import numpy as np
import pytest

LIBRARY = Path(__file__).resolve().parents[2] / "designs" / "library"
W, H, F = 640, 480, 200.0
PINHOLE = f"""image_width: {W}
image_height: {H}
camera_matrix:
  rows: 3
  cols: 3
  data: [{F}, 0.0, {(W - 1) / 2}, 0.0, {F}, {(H - 1) / 2}, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.0, 0.0, 0.0, 0.0, 0.0]
"""
NOMINAL = {"rtac0": [], "tactip_dualmodal": [], "uvdtact": [],
           "shadowtac": ["--view-angle-deg", "120"]}


def skin_box(out, design):
    """(min, max) mm of the skin's outer member's mesh, the MJCF's contact-surface collision
    geom's (sim/meshes/NAME.stl, binary STL in mm)."""
    xml = (out / "sim" / f"{design}.xml").read_text()
    mesh = xml.split('name="contact_surface_collision" type="mesh" mesh="', 1)[1].split('"', 1)[0]
    raw = (out / "sim" / "meshes" / f"{mesh}.stl").read_bytes()
    n = int(np.frombuffer(raw, "<u4", 1, 80)[0])
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    v = np.frombuffer(raw, rec, n, 84)["v"].reshape(-1, 3).astype(float)
    return v.min(0), v.max(0)


def mujoco_skin(xml, skin):
    """(H, W) bool: the pixels where MuJoCo's camera `camera` sees one of the geoms `skin`
    (names), drawn alone."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(xml))
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name) for name in skin]
    assert min(ids) >= 0, skin
    # the skin alone: every other geom to a group the scene leaves out
    model.geom_group[:] = 5
    model.geom_group[ids] = 3
    option = mujoco.MjvOption()
    option.geomgroup[:] = 0
    option.geomgroup[3] = 1
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
    w, h = (int(v) for v in model.cam_resolution[cam])
    renderer = mujoco.Renderer(model, h, w)
    try:
        renderer.enable_segmentation_rendering()
        renderer.update_scene(data, camera="camera", scene_option=option)
        seg = renderer.render()
    finally:
        renderer.close()
    return np.isin(seg[..., 0], ids) & (seg[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM))


def skin_layers(out):
    """The skin's layers as the manifest's assembly lists them: the cast members (the filling gel
    aside) and a printed skin (the rule of the MJCF's contact-surface geom, export/src/sim.rs
    skin_member)."""
    members = json.loads((out / "manifest.json").read_text())["assembly_3mf"]["members"]
    return [m["name"] for m in members
            if (m["kind"] == "cast" and m["name"] != "filling_gel")
            or (m["kind"] == "printed" and m["name"] == "skin")]


@pytest.mark.parametrize("design", sorted(p.stem for p in LIBRARY.glob("*.yaml")))
def test_mujocos_camera_sees_the_skin_fabkits_ground_truth_sees(design, tmp_path, run_cli):
    pytest.importorskip("mujoco")
    import fabkit

    (tmp_path / "pin.yaml").write_text(PINHOLE)
    if design in NOMINAL:
        run_cli(tmp_path, "calibrate", "nominal", design, "--out", "nom", *NOMINAL[design])
        extrinsics = tmp_path / "nom" / "extrinsics.json"
    else:
        # on the axis, looking +z, under the skin's outer member where its larger half extent
        # at its lowest fills 80 % of the picture's half height
        run_cli(tmp_path, "export", design, "--format", "mjcf", "--out", "plain")
        lo, hi = skin_box(tmp_path / "plain", design)
        half = max(hi[0] - lo[0], hi[1] - lo[1]) / 2
        below = F * half / (0.8 * H / 2)
        T = np.eye(4)
        T[2, 3] = below - lo[2]
        extrinsics = tmp_path / "ext.json"
        extrinsics.write_text(json.dumps({
            "T_cam_sensor": T.tolist(), "optical_path_from": f"design '{design}'",
            "provenance": {"camera_file": str(tmp_path / "pin.yaml")}}))
    run_cli(tmp_path, "export", design, "--format", "3mf,mjcf", "--camera", "pin.yaml",
            "--extrinsics", extrinsics, "--out", "out")
    seen = mujoco_skin(tmp_path / "out" / "sim" / f"{design}.xml", skin_layers(tmp_path / "out"))

    T = np.asarray(json.loads(extrinsics.read_text())["T_cam_sensor"], float)
    camera = fabkit.Camera.from_file(str(tmp_path / "pin.yaml"))
    # T as an array: straight rays (the file would bend them at the design's optical path)
    reference = fabkit.DepthRenderer(fabkit.Design.load(design), camera, T).reference()
    truth = ~np.isnan(reference["range_mm"])
    assert truth.sum() > 0.05 * W * H, f"{design}: the skin is {truth.sum()} px of the picture"
    if design not in NOMINAL:
        assert not truth.all(), f"{design}: the skin's edge is out of the picture"
    iou = (seen & truth).sum() / (seen | truth).sum()
    print(f"{design}: MuJoCo {seen.sum()} px, ground truth {truth.sum()} px, IoU {iou:.4f}")
    assert iou >= 0.98, f"{design}: IoU {iou:.4f}"
