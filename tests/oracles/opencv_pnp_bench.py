"""OpenCV side of the extrinsics benchmark (calibration/examples/extrinsics_benchmark.rs).

Usage: python opencv_pnp_bench.py TRIALS.json
TRIALS.json: {"intrinsics": fabkit Intrinsics (fisheye), "trials": [{"rotation", "translation_mm",
              "points_mm", "pixels_px"}, ...]}
Solves every trial with cv2.fisheye.solvePnP(..., flags=cv2.SOLVEPNP_SQPNP) and prints JSON:
rotation / translation RMS against the truth, and the time per solve of cv2 alone (best of 60
passes over all trials, Python call overhead included).
"""
import json
import sys
import time

import cv2
import numpy as np


def main():
    doc = json.load(open(sys.argv[1]))
    intr = doc["intrinsics"]
    K = np.array([[intr["fx_px"], 0, intr["cx_px"]], [0, intr["fy_px"], intr["cy_px"]], [0, 0, 1]], dtype=np.float64)
    D = np.array(intr["distortion"]["coefficients"], dtype=np.float64).reshape(4, 1)
    data = []
    for t in doc["trials"]:
        P = np.array(t["points_mm"], dtype=np.float64).reshape(-1, 1, 3)
        U = np.array(t["pixels_px"], dtype=np.float64).reshape(-1, 1, 2)
        data.append((P, U, np.array(t["rotation"]), np.array(t["translation_mm"])))
    er, et = [], []
    for P, U, R, tt in data:
        ok, rvec, tvec = cv2.fisheye.solvePnP(P, U, K, D, flags=cv2.SOLVEPNP_SQPNP)
        Re, _ = cv2.Rodrigues(rvec)
        c = np.clip((np.trace(Re @ R.T) - 1) / 2, -1, 1)
        er.append(np.degrees(np.arccos(c)))
        et.append(np.linalg.norm(tvec.reshape(3) - tt))
    best = float("inf")
    for _ in range(60):
        t0 = time.perf_counter()
        for P, U, _, _ in data:
            cv2.fisheye.solvePnP(P, U, K, D, flags=cv2.SOLVEPNP_SQPNP)
        best = min(best, (time.perf_counter() - t0) / len(data))
    json.dump(
        {
            "opencv_version": cv2.__version__,
            "rotation_rms_deg": float(np.sqrt(np.mean(np.square(er)))),
            "translation_rms_mm": float(np.sqrt(np.mean(np.square(et)))),
            "us_per_solve": best * 1e6,
        },
        sys.stdout,
    )


if __name__ == "__main__":
    main()
