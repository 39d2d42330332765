"""OpenCV oracle for fabkit's camera models and camera files.

Usage: python opencv_project.py CASES.json
CASES.json: {"cases": [{"model": "fisheye"|"plumb_bob"|"rational_polynomial",
                        "K": [[...]x3], "D": [...], "points": [[x, y, z], ...],
                        "camera_file": optional path of an OpenCV FileStorage YAML to read}]}
Prints JSON: {"opencv_version": ..., "cases": [{"pixels": [[u, v], ...],
              "file": {"K": ..., "D": ..., "width": ..., "height": ..., "model": ...} or null}]}
Projection: cv2.fisheye.projectPoints for fisheye, cv2.projectPoints otherwise (rvec = tvec = 0).
"""
import json
import sys

import cv2
import numpy as np


def main():
    cases = json.load(open(sys.argv[1]))["cases"]
    out = []
    for c in cases:
        K = np.array(c["K"], dtype=np.float64)
        D = np.array(c["D"], dtype=np.float64)
        P = np.array(c["points"], dtype=np.float64).reshape(-1, 1, 3)
        z = np.zeros((3, 1))
        if c["model"] == "fisheye":
            px, _ = cv2.fisheye.projectPoints(P, z, z, K, D.reshape(-1, 1))
        else:
            px, _ = cv2.projectPoints(P, z, z, K, D)
        res = {"pixels": px.reshape(-1, 2).tolist(), "file": None}
        if c.get("camera_file"):
            fs = cv2.FileStorage(c["camera_file"], cv2.FILE_STORAGE_READ)
            res["file"] = {
                "K": fs.getNode("camera_matrix").mat().tolist(),
                "D": fs.getNode("distortion_coefficients").mat().reshape(-1).tolist(),
                "width": int(fs.getNode("image_width").real()),
                "height": int(fs.getNode("image_height").real()),
                "model": fs.getNode("distortion_model").string(),
            }
            fs.release()
        out.append(res)
    json.dump({"opencv_version": cv2.__version__, "cases": out}, sys.stdout)


if __name__ == "__main__":
    main()
