"""OpenCV as the writer of the camera files users already have, and as a reader of extrinsics.yaml.

Usage:
  python opencv_camera_files.py write DIR
      Calibrates synthetic checkerboard views with cv2.calibrateCamera (default flags: 1 x 5;
      CALIB_RATIONAL_MODEL: 1 x 14 in OpenCV 5; CALIB_RATIONAL_MODEL | CALIB_THIN_PRISM_MODEL:
      1 x 12) and cv2.fisheye.calibrate (4 x 1), and writes each result with cv2.FileStorage as
      YAML and XML into DIR, as OpenCV's camera_calibration sample does (image_width,
      image_height, camera_matrix, distortion_coefficients, no distortion_model; the fisheye
      files with and without `fisheye_model: 1`). A 14-coefficient file with tauX != 0 is the
      rational result with that one value changed. Prints JSON: {"opencv_version": ...,
      "files": [{"name", "layout", "K": 3 x 3, "D": [...], "width", "height"}]} with the
      numbers OpenCV returned.
  python opencv_camera_files.py read-extrinsics FILE
      Reads extrinsics.yaml with cv2.FileStorage (the pose's matrices by FileNode.mat(), as
      OpenCV matrices) and with PyYAML (the `%YAML:1.0` line dropped, a constructor for the
      `!!opencv-matrix` tag); prints JSON: {"rvec", "tvec_mm", "T_cam_sensor" (each as .mat()
      gave it, nested by rows), "shapes" (rows, cols of each), "rms_reprojection_error_px",
      "command_line", "pyyaml_command_line", "pyyaml_T_cam_sensor"}.
"""
import json
import os
import sys

import cv2
import numpy as np

W, H = 640, 480


def views(project):
    """Image points of a 9 x 6 board (20 mm squares) seen from 14 poses, by `project`."""
    board = np.zeros((6 * 9, 3), np.float64)
    board[:, :2] = np.mgrid[0:9, 0:6].T.reshape(-1, 2) * 20.0
    board -= board.mean(axis=0)
    rng = np.random.default_rng(7)
    objs, imgs = [], []
    for _ in range(14):
        rvec = rng.normal(0.0, 0.35, 3)
        tvec = np.array([rng.normal(0, 15), rng.normal(0, 10), 260 + rng.normal(0, 40)])
        px = project(board.reshape(-1, 1, 3), rvec, tvec)
        objs.append(board.reshape(-1, 1, 3))
        imgs.append(px.reshape(-1, 1, 2))
    return objs, imgs


def write(path, K, D, fisheye_model=None):
    fs = cv2.FileStorage(path, cv2.FILE_STORAGE_WRITE)
    fs.write("calibration_time", "Thu 01 Feb 2024 10:00:00")
    fs.write("image_width", W)
    fs.write("image_height", H)
    fs.write("flags", 0)
    if fisheye_model is not None:
        fs.write("fisheye_model", fisheye_model)
    fs.write("camera_matrix", K)
    fs.write("distortion_coefficients", D)
    fs.write("avg_reprojection_error", 0.1)
    fs.release()


def write_all(out):
    K0 = np.array([[300.0, 0, 320.5], [0, 299.0, 240.25], [0, 0, 1]])
    D0 = np.array([-0.2, 0.05, 0.001, -0.0005, 0.01, 0.1, 0.01, 0.002])
    objs, imgs = views(lambda P, r, t: cv2.projectPoints(P, r, t, K0, D0)[0])
    results = {}
    for layout, flags in [
        ("plumb_bob_5", 0),
        ("rational_14", cv2.CALIB_RATIONAL_MODEL),
        ("thin_prism_12", cv2.CALIB_RATIONAL_MODEL | cv2.CALIB_THIN_PRISM_MODEL),
    ]:
        _, K, D, _, _ = cv2.calibrateCamera(
            [o.astype(np.float32) for o in objs],
            [i.astype(np.float32) for i in imgs],
            (W, H), None, None, flags=flags,
        )
        results[layout] = (K, D, None)
    K, D, _ = results["rational_14"]
    tilted = D.copy()
    tilted.reshape(-1)[12] = 1.5e-3
    results["tilted_14"] = (K, tilted, None)

    Kf0 = np.array([[215.0, 0, 322.0], [0, 214.5, 238.0], [0, 0, 1]])
    Df0 = np.array([-0.02, 0.004, -0.0015, 0.0002]).reshape(4, 1)
    objs, imgs = views(lambda P, r, t: cv2.fisheye.projectPoints(P, r, t, Kf0, Df0)[0])
    # cv2.fisheye wants each view as 1 x N; from a rough guess (the synthetic views are noise
    # free, so it converges to the truth).
    _, Kf, Df, _, _ = cv2.fisheye.calibrate(
        [o.reshape(1, -1, 3) for o in objs],
        [i.reshape(1, -1, 2) for i in imgs],
        (W, H),
        np.array([[200.0, 0, 320.0], [0, 200.0, 240.0], [0, 0, 1]]),
        np.zeros((4, 1)),
        flags=cv2.CALIB_RECOMPUTE_EXTRINSIC | cv2.CALIB_FIX_SKEW | cv2.CALIB_USE_INTRINSIC_GUESS,
        criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-12),
    )
    results["fisheye_4"] = (Kf, Df, 1)
    results["fisheye_4_bare"] = (Kf, Df, None)

    files = []
    for layout, (K, D, fisheye_model) in results.items():
        for ext in ("yaml", "xml"):
            name = f"{layout}.{ext}"
            write(os.path.join(out, name), K, D, fisheye_model)
            files.append({
                "name": name,
                "layout": layout,
                "K": K.tolist(),
                "D": D.reshape(-1).tolist(),
                "D_shape": list(D.shape),
                "width": W,
                "height": H,
            })
    json.dump({"opencv_version": cv2.__version__, "files": files}, sys.stdout)


def read_extrinsics(path):
    import yaml

    fs = cv2.FileStorage(path, cv2.FILE_STORAGE_READ)
    mats = {k: fs.getNode(k).mat() for k in ("rvec", "tvec_mm", "T_cam_sensor")}
    out = {k: m.tolist() for k, m in mats.items()}
    out["shapes"] = {k: list(m.shape) for k, m in mats.items()}
    out["dtypes"] = {k: str(m.dtype) for k, m in mats.items()}
    out["rms_reprojection_error_px"] = fs.getNode("rms_reprojection_error_px").real()
    out["command_line"] = fs.getNode("provenance").getNode("command_line").string()
    fs.release()

    class Loader(yaml.SafeLoader):
        pass

    def opencv_matrix(loader, node):
        m = loader.construct_mapping(node, deep=True)
        return np.array(m["data"], np.float64).reshape(m["rows"], m["cols"])

    Loader.add_constructor("tag:yaml.org,2002:opencv-matrix", opencv_matrix)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if text.startswith("%YAML:"):  # OpenCV's directive, not YAML's: drop it
        text = text.split("\n", 1)[1]
    doc = yaml.load(text, Loader=Loader)
    out["pyyaml_command_line"] = doc["provenance"]["command_line"]
    out["pyyaml_T_cam_sensor"] = doc["T_cam_sensor"].tolist()
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write_all(sys.argv[2])
    elif sys.argv[1] == "read-extrinsics":
        read_extrinsics(sys.argv[2])
    else:
        sys.exit(f"unknown mode {sys.argv[1]}")
