//! fabkit-calibration: camera models, camera files, PnP extrinsics and residual reports.
//! Conventions (pixels, camera frame, transform names): `docs/conventions.md`.
//!
//! Source: R-Tac0 paper (`shared/papers/rtac0-rounded-monochrome-vbts.txt`), Sec. IV-A, Eq. (1).

pub mod camera;
pub mod pnp;
pub mod sqpnp;
pub mod synthetic;

pub use camera::{CameraError, CameraModel, Distortion, Intrinsics};
pub use pnp::{solve_pnp, PnpError, PnpOptions, PnpSolution, RansacOptions};
