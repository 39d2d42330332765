"""OpenCV and numpy read what `fabkit calibrate board` wrote (tests/e2e/calibrate_board.rs).

Usage: board_check.py OUT_DIR

Reads OUT_DIR/camera.yaml with cv2.FileStorage, OUT_DIR/extrinsics.json (rvec, tvec_mm and each
bump's sensor-frame point and reprojected pixel) and OUT_DIR/pixel_to_plane_mm.npy with numpy,
and prints one JSON object: how far cv2.projectPoints puts each bump from fabkit's
reprojection (px), the map's shape and dtype, and the map's value at each bump's observed
pixel (rounded) against the bump's point (mm).
"""

import json
import sys

import cv2
import numpy as np


def main() -> None:
    out = sys.argv[1]
    fs = cv2.FileStorage(f"{out}/camera.yaml", cv2.FILE_STORAGE_READ)
    k = fs.getNode("camera_matrix").mat()
    d = fs.getNode("distortion_coefficients").mat()
    fs.release()
    ext = json.load(open(f"{out}/extrinsics.json"))
    pts = np.array([b["point_mm"] for b in ext["bumps"]], dtype=np.float64)
    ours = np.array([b["reprojected_px"] for b in ext["bumps"]], dtype=np.float64)
    obs = np.array([b["observed_px"] for b in ext["bumps"]], dtype=np.float64)
    rvec = np.array(ext["rvec"], dtype=np.float64)
    tvec = np.array(ext["tvec_mm"], dtype=np.float64)
    cv, _ = cv2.projectPoints(pts, rvec, tvec, k, d)
    cv = cv.reshape(-1, 2)
    m = np.load(f"{out}/pixel_to_plane_mm.npy")
    at = np.array([m[int(round(v)), int(round(u))] for u, v in obs], dtype=np.float64)
    print(
        json.dumps(
            {
                "opencv_version": cv2.__version__,
                "projection_max_diff_px": float(np.abs(cv - ours).max()),
                "map_shape": list(m.shape),
                "map_dtype": str(m.dtype),
                "map_finite": bool(np.isfinite(m).all()),
                "map_at_bumps_rms_mm": float(np.sqrt(((at - pts[:, :2]) ** 2).sum(1).mean())),
            }
        )
    )


if __name__ == "__main__":
    main()
