//! fabkit-calibration: camera models, camera files, PnP extrinsics and residual reports.
//! Conventions (pixels, camera frame, transform names): `docs/conventions.md`.
