//! fabkit-calibration: camera models, camera files, PnP extrinsics and residual reports, and
//! ground-truth depth rendering ([`groundtruth`], R-Tac0 Sec. IV-B).
//! Conventions (pixels, camera frame, transform names): `docs/conventions.md`.
//!
//! Source: R-Tac0 paper (`shared/papers/rtac0-rounded-monochrome-vbts.txt`), Sec. IV-A, Eq. (1):
//! intrinsics and distortion from a checkerboard (OpenCV), then the extrinsics `[R | T]`
//! (here `T_cam_sensor`) from pin-dome points and their pixels by PnP.

// Negated comparisons (`!(x > 0.0)`) are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod camera;
pub mod camera_file;
pub mod extrinsics;
pub mod groundtruth;
pub mod overlay;
pub mod p3p;
pub mod pnp;
pub mod report;
pub mod sqpnp;
pub mod synthetic;
pub mod tables;

pub use camera::{CameraError, CameraModel, Distortion, Intrinsics};
pub use camera_file::{
    parse_camera, read_camera_file, write_camera, CameraFileError, CameraFileFormat,
};
pub use extrinsics::{calibrate_extrinsics, ExtrinsicsError, ExtrinsicsJob, ExtrinsicsOutput};
pub use nalgebra;
pub use pnp::{solve_pnp, PnpError, PnpOptions, PnpSolution, RansacOptions};
pub use report::ExtrinsicsReport;
pub use tables::{PointsFrom, TableError};
