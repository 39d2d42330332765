//! fabkit-calibration: camera models, camera files, PnP extrinsics and residual reports, and
//! ground-truth depth rendering ([`groundtruth`], R-Tac0 Sec. IV-B).
//! Conventions (pixels, camera frame, transform names): `docs/conventions.md`.
//!
//! Source: R-Tac0 paper (`shared/papers/rtac0-rounded-monochrome-vbts.txt`), Sec. IV-A, Eq. (1):
//! intrinsics and distortion from a checkerboard (OpenCV), then the extrinsics `[R | T]`
//! (here `T_cam_sensor`) from pin-dome points and their pixels by PnP.

// Negated comparisons (`!(x > 0.0)`) are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod board;
pub mod camera;
pub mod camera_file;
pub mod capture_images;
pub mod elastic;
pub mod extrinsics;
pub mod flat_response;
pub mod groundtruth;
pub mod imprints;
pub mod models;
pub mod nominal;
pub mod overlay;
pub mod p3p;
pub mod photometric;
pub mod pnp;
pub mod press;
pub mod refine;
pub mod refraction;
pub mod report;
pub mod seating;
pub mod sqpnp;
pub mod synthetic;
pub mod tables;

pub use camera::{CameraError, CameraModel, Distortion, Intrinsics};
pub use camera_file::{
    parse_camera, parse_camera_as, read_camera_file, read_camera_file_as, write_camera,
    CameraFileError, CameraFileFormat, DistortionModelHint,
};
pub use extrinsics::{
    calibrate_extrinsics, ExtrinsicsError, ExtrinsicsJob, ExtrinsicsOutput, FoundInImages, Observed,
};
pub use nalgebra;
pub use pnp::{
    pose_uncertainty, solve_pnp, PnpError, PnpOptions, PnpSolution, PoseUncertainty, RansacOptions,
};
pub use report::ExtrinsicsReport;
pub use tables::{PointsFrom, TableError};

/// Largest text input (camera file, point table, observations, capture plan, fixture index),
/// bytes: 64 MiB. Only regular files are read (a FIFO or a device is refused at once).
pub const MAX_TEXT_INPUT_BYTES: u64 = 64 << 20;
/// Largest binary input (capture PNG, fixture meshes), bytes: 1 GiB.
pub const MAX_BINARY_INPUT_BYTES: u64 = 1 << 30;

/// `x` as a reader would write it: `{}` where that is short, scientific notation (`1e300`,
/// `5e-324`) where `{}` would print hundreds of digits.
pub fn shown_f64(x: f64) -> String {
    fabkit_designs::error::compact_numbers(&x.to_string())
}

/// The median of `v` (sorted in place): the middle value, or the mean of the middle two; NaN
/// when `v` is empty.
pub(crate) fn median_sorting(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_unstable_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// [`median_sorting`]'s value (the same bits) by selection: `v` is reordered, not sorted.
pub(crate) fn median_selecting(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let (len, m) = (v.len(), v.len() / 2);
    let (lower, upper, _) = v.select_nth_unstable_by(m, f64::total_cmp);
    let upper = *upper;
    if len % 2 == 1 {
        upper
    } else {
        // the lower middle: the greatest of the values before position m
        let below = lower
            .iter()
            .copied()
            .max_by(f64::total_cmp)
            .unwrap_or(upper);
        0.5 * (below + upper)
    }
}

/// A regular file of at most [`MAX_TEXT_INPUT_BYTES`] as UTF-8 text.
pub(crate) fn read_text(path: &std::path::Path) -> std::io::Result<String> {
    fabkit_designs::input_files::read_text_file(path, MAX_TEXT_INPUT_BYTES)
}

/// A regular file of at most [`MAX_BINARY_INPUT_BYTES`].
pub(crate) fn read_binary(path: &std::path::Path) -> std::io::Result<Vec<u8>> {
    fabkit_designs::input_files::read_regular_file(path, MAX_BINARY_INPUT_BYTES)
}

#[cfg(test)]
mod tests {
    /// The selecting median is the sorting one to the bit: odd and even counts, ties, signed
    /// zeros, a lone value and the empty slice.
    #[test]
    fn the_selecting_median_is_the_sorting_one() {
        let cases: Vec<Vec<f64>> = vec![
            vec![],
            vec![3.5],
            vec![2.0, 1.0],
            vec![0.1, 0.7, 0.3],
            vec![5.0, 5.0, 1.0, 5.0],
            vec![-0.0, 0.0, -0.0, 0.0],
            (0..31)
                .map(|k| ((k * 37 % 31) as f64 * 0.1).sin())
                .collect(),
            (0..32)
                .map(|k| ((k * 37 % 32) as f64 * 0.1).cos())
                .collect(),
        ];
        for v in cases {
            let (mut a, mut b) = (v.clone(), v.clone());
            let (s, q) = (
                super::median_sorting(&mut a),
                super::median_selecting(&mut b),
            );
            assert_eq!(
                s.to_bits(),
                q.to_bits(),
                "{v:?}: sorting {s}, selecting {q}"
            );
        }
    }
}
