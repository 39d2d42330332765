//! Extrinsics by PnP: SQPnP on bearings for a globally optimal start, then Levenberg-Marquardt on
//! the pixel reprojection error of the true camera model, optionally inside RANSAC.
//!
//! Source: R-Tac0 paper, Sec. IV-A, Eq. (1): the pin-dome points (x, y, z) and their pixels (u, v)
//! give `[R | T]` by solving the Perspective-n-Point problem. Here `[R | T]` is `T_cam_sensor`.

use nalgebra::{
    Isometry3, Matrix3, Matrix6, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3, Vector6,
};
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::camera::{CameraError, CameraModel};
use crate::p3p::p3p;
use crate::sqpnp::{nearest_rotation, sqpnp};

/// Smallest number of point-pixel pairs the solver accepts.
pub const MIN_POINTS: usize = 4;

/// Why the pose could not be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PnpError {
    #[error("{given} usable point-pixel pairs: PnP needs at least {needed}")]
    TooFewPoints { given: usize, needed: usize },
    #[error("{points} points but {pixels} pixels: the two lists must pair up")]
    LengthMismatch { points: usize, pixels: usize },
    #[error("point {index}: {what} is not finite")]
    NonFinite { index: usize, what: &'static str },
    #[error("point {index}: {source}")]
    Unprojectable {
        index: usize,
        #[source]
        source: CameraError,
    },
    #[error("degenerate layout: {reason}")]
    Degenerate { reason: String },
    #[error("no pose puts the points in front of the camera")]
    NoSolution,
    #[error("point {index} is behind the camera or outside the lens's field at the solved pose")]
    BehindCamera { index: usize },
    #[error("RANSAC found {inliers} inliers within {threshold_px} px: at least {needed} are needed (are the ids right?)")]
    TooFewInliers {
        inliers: usize,
        needed: usize,
        threshold_px: f64,
    },
}

/// RANSAC settings. The first hypothesis is the all-points solution; minimal samples of 3 points
/// (P3P, each refined on its consensus set when it is the best so far) follow until the adaptive count for `confidence` is reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RansacOptions {
    /// A point is an inlier when its reprojection error is below this, px.
    pub threshold_px: f64,
    /// Probability of drawing at least one outlier-free sample, in (0, 1).
    pub confidence: f64,
    /// Largest number of sampled hypotheses.
    pub max_hypotheses: usize,
    /// Seed of the sampler (same seed and input, same result).
    pub seed: u64,
    /// Smallest fraction of the points that must be inliers, in (0, 1]; below it the consensus
    /// is a coincidence (e.g. observations labelled at random) and solving fails.
    pub min_inlier_fraction: f64,
}

impl Default for RansacOptions {
    fn default() -> Self {
        RansacOptions {
            threshold_px: 3.0,
            confidence: 0.999,
            max_hypotheses: 1000,
            seed: 0,
            min_inlier_fraction: 0.5,
        }
    }
}

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PnpOptions {
    /// `None`: every pair is used (no outlier rejection).
    pub ransac: Option<RansacOptions>,
    /// Largest number of Levenberg-Marquardt iterations.
    pub max_iterations: usize,
}

impl Default for PnpOptions {
    fn default() -> Self {
        PnpOptions {
            ransac: Some(RansacOptions::default()),
            max_iterations: 50,
        }
    }
}

/// A solved pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PnpSolution {
    /// T_cam_sensor: maps sensor-frame points (mm) into the camera frame (mm).
    pub t_cam_sensor: Isometry3<f64>,
    /// Per input pair: used in the final fit.
    pub inliers: Vec<bool>,
    /// Per input pair: reprojected minus observed pixel, px (`None` if it does not project).
    pub residuals_px: Vec<Option<Vector2<f64>>>,
    /// RMS of the inliers' reprojection errors, px.
    pub rms_reprojection_error_px: f64,
    /// RANSAC hypotheses drawn (0 without RANSAC or when the all-points fit had no outlier).
    pub hypotheses: usize,
}

/// Solves T_cam_sensor from sensor-frame points `points_mm` (N, mm) and their observed pixels
/// `pixels_px` (N, px) through `camera`.
///
/// # Errors
/// [`PnpError`]: fewer than 4 pairs, non-finite input, pixels that do not unproject, degenerate
/// layouts (collinear points, parallel rays), no pose in front of the camera, too few inliers.
pub fn solve_pnp(
    camera: &CameraModel,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    opts: &PnpOptions,
) -> Result<PnpSolution, PnpError> {
    let n = points_mm.len();
    if pixels_px.len() != n {
        return Err(PnpError::LengthMismatch {
            points: n,
            pixels: pixels_px.len(),
        });
    }
    if n < MIN_POINTS {
        return Err(PnpError::TooFewPoints {
            given: n,
            needed: MIN_POINTS,
        });
    }
    let mut bearings = Vec::with_capacity(n);
    for (index, (m, uv)) in points_mm.iter().zip(pixels_px).enumerate() {
        if !m.iter().all(|v| v.is_finite()) {
            return Err(PnpError::NonFinite {
                index,
                what: "point",
            });
        }
        if !uv.iter().all(|v| v.is_finite()) {
            return Err(PnpError::NonFinite {
                index,
                what: "pixel",
            });
        }
        bearings.push(
            camera
                .unproject(uv)
                .map_err(|source| PnpError::Unprojectable { index, source })?,
        );
    }
    check_layout(points_mm, &bearings)?;
    let all: Vec<usize> = (0..n).collect();
    let start = sqpnp(points_mm, &bearings).ok_or(PnpError::NoSolution)?;
    let (mut r, mut t) = (start.rotation, start.translation_mm);
    if let Some((r1, t1, _)) = refine(
        camera,
        points_mm,
        pixels_px,
        &all,
        r,
        t,
        opts.max_iterations,
    ) {
        (r, t) = (r1, t1);
    }
    // The inlier set the current pose was refined on (skip refitting the same set).
    let mut fitted_on: Option<Vec<bool>> = Some(vec![true; n]);
    let mut hypotheses = 0;
    let mut inliers = vec![true; n];
    if let Some(ro) = &opts.ransac {
        let thr2 = ro.threshold_px * ro.threshold_px;
        let (mut best_in, mut best_score) = score(camera, points_mm, pixels_px, &r, &t, thr2);
        if best_in.iter().filter(|&&b| b).count() < n {
            let mut rng = ChaCha8Rng::seed_from_u64(ro.seed);
            let mut needed = ro.max_hypotheses;
            let mut sample = [0usize; 3];
            let mut poses = Vec::with_capacity(4);
            while hypotheses < needed.min(ro.max_hypotheses) {
                hypotheses += 1;
                draw(&mut rng, n, &mut sample);
                let sp = sample.map(|i| points_mm[i]);
                let sb = sample.map(|i| bearings[i]);
                p3p(&sp, &sb, &mut poses);
                for (hr, ht) in &poses {
                    let (inl, sc) = score(camera, points_mm, pixels_px, hr, ht, thr2);
                    if sc >= best_score {
                        continue;
                    }
                    // Local optimisation on the consensus set.
                    let (mut hr, mut ht, mut hin, mut hsc) = (*hr, *ht, inl, sc);
                    let idx: Vec<usize> = (0..n).filter(|&i| hin[i]).collect();
                    if idx.len() >= MIN_POINTS {
                        if let Some((r1, t1, _)) = refine(
                            camera,
                            points_mm,
                            pixels_px,
                            &idx,
                            hr,
                            ht,
                            opts.max_iterations,
                        ) {
                            let (i1, s1) = score(camera, points_mm, pixels_px, &r1, &t1, thr2);
                            if s1 <= hsc {
                                (hr, ht, hin, hsc) = (r1, t1, i1, s1);
                            }
                        }
                    }
                    (r, t, best_in, best_score) = (hr, ht, hin, hsc);
                    fitted_on = None;
                    let w = best_in.iter().filter(|&&b| b).count() as f64 / n as f64;
                    let denom = (1.0 - w.powi(3)).ln();
                    needed = if denom < 0.0 {
                        ((1.0 - ro.confidence).ln() / denom).ceil().max(1.0) as usize
                    } else {
                        0
                    };
                }
            }
        }
        // Final fit on the consensus set, repeated while the set changes.
        for _ in 0..3 {
            let idx: Vec<usize> = (0..n).filter(|&i| best_in[i]).collect();
            if idx.len() < MIN_POINTS {
                return Err(PnpError::TooFewInliers {
                    inliers: idx.len(),
                    needed: MIN_POINTS,
                    threshold_px: ro.threshold_px,
                });
            }
            if fitted_on.as_ref() == Some(&best_in) {
                break;
            }
            if let Some((r1, t1, _)) = refine(
                camera,
                points_mm,
                pixels_px,
                &idx,
                r,
                t,
                opts.max_iterations,
            ) {
                (r, t) = (r1, t1);
            }
            fitted_on = Some(best_in.clone());
            let (inl, _) = score(camera, points_mm, pixels_px, &r, &t, thr2);
            let same = inl == best_in;
            best_in = inl;
            if same {
                break;
            }
        }
        inliers = best_in;
        let count = inliers.iter().filter(|&&b| b).count();
        let needed = MIN_POINTS.max((ro.min_inlier_fraction * n as f64).ceil() as usize);
        if count < needed {
            return Err(PnpError::TooFewInliers {
                inliers: count,
                needed,
                threshold_px: ro.threshold_px,
            });
        }
    }
    let mut residuals_px = Vec::with_capacity(n);
    let (mut sum2, mut m) = (0.0, 0usize);
    for i in 0..n {
        let res = camera
            .project(&(r * points_mm[i] + t))
            .map(|uv| uv - pixels_px[i]);
        if inliers[i] {
            match res {
                Some(e) => {
                    sum2 += e.norm_squared();
                    m += 1;
                }
                None => return Err(PnpError::BehindCamera { index: i }),
            }
        }
        residuals_px.push(res);
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
        nearest_rotation(&r),
    ));
    Ok(PnpSolution {
        t_cam_sensor: Isometry3::from_parts(Translation3::from(t), rot),
        inliers,
        residuals_px,
        rms_reprojection_error_px: (sum2 / m as f64).sqrt(),
        hypotheses,
    })
}

/// Rejects collinear points (the pose has a free rotation) and parallel rays.
fn check_layout(points: &[Vector3<f64>], bearings: &[Vector3<f64>]) -> Result<(), PnpError> {
    let n = points.len() as f64;
    let c = points.iter().sum::<Vector3<f64>>() / n;
    let cov = points
        .iter()
        .fold(Matrix3::zeros(), |a, p| a + (p - c) * (p - c).transpose());
    let mut ev = [0.0; 3];
    ev.copy_from_slice(cov.symmetric_eigenvalues().as_slice());
    ev.sort_by(f64::total_cmp);
    let (lo, hi) = (ev[1], ev[2]);
    if !(hi > 0.0) || lo < 1e-10 * hi {
        return Err(PnpError::Degenerate {
            reason: if hi > 0.0 {
                "the points are collinear".into()
            } else {
                "the points coincide".into()
            },
        });
    }
    let b0 = bearings[0];
    if bearings.iter().all(|b| b.cross(&b0).norm() < 1e-9) {
        return Err(PnpError::Degenerate {
            reason: "every pixel is on the same ray".into(),
        });
    }
    Ok(())
}

/// Draws distinct indices in 0..n.
fn draw(rng: &mut ChaCha8Rng, n: usize, out: &mut [usize]) {
    for k in 0..out.len() {
        loop {
            let i = (rng.next_u64() % n as u64) as usize;
            if !out[..k].contains(&i) {
                out[k] = i;
                break;
            }
        }
    }
}

/// Inliers and the MSAC score (sum of squared errors truncated at the threshold).
fn score(
    camera: &CameraModel,
    pts: &[Vector3<f64>],
    px: &[Vector2<f64>],
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
    thr2: f64,
) -> (Vec<bool>, f64) {
    let mut inl = Vec::with_capacity(pts.len());
    let mut s = 0.0;
    for (m, uv) in pts.iter().zip(px) {
        let e2 = camera
            .project(&(r * m + t))
            .map_or(f64::INFINITY, |p| (p - uv).norm_squared());
        inl.push(e2 < thr2);
        s += e2.min(thr2);
    }
    (inl, s)
}

/// Sum of squared reprojection errors over `idx`, or `None` if a point does not project.
fn cost(
    camera: &CameraModel,
    pts: &[Vector3<f64>],
    px: &[Vector2<f64>],
    idx: &[usize],
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
) -> Option<f64> {
    let mut s = 0.0;
    for &i in idx {
        s += (camera.project(&(r * pts[i] + t))? - px[i]).norm_squared();
    }
    Some(s)
}

/// Normal equations of the reprojection error at (r, t): J^T J and J^T e over `idx`, with the
/// rotation perturbed on the left (R <- exp(w) R) and parameters (w, t).
pub(crate) fn normal_equations(
    camera: &CameraModel,
    pts: &[Vector3<f64>],
    px: &[Vector2<f64>],
    idx: &[usize],
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
) -> Option<(Matrix6<f64>, Vector6<f64>, f64)> {
    let mut jtj = Matrix6::zeros();
    let mut jte = Vector6::zeros();
    let mut s = 0.0;
    for &i in idx {
        let q = r * pts[i];
        let (uv, j) = camera.project_with_jacobian(&(q + t))?;
        let e = uv - px[i];
        s += e.norm_squared();
        // d(pc)/dw = -[q]x, d(pc)/dt = I.
        let jw = j * (-q.cross_matrix());
        let row = |k: usize| {
            Vector6::new(
                jw[(k, 0)],
                jw[(k, 1)],
                jw[(k, 2)],
                j[(k, 0)],
                j[(k, 1)],
                j[(k, 2)],
            )
        };
        let (a, b) = (row(0), row(1));
        jtj += a * a.transpose() + b * b.transpose();
        jte += a * e.x + b * e.y;
    }
    Some((jtj, jte, s))
}

/// Levenberg-Marquardt on the reprojection error over `idx`; returns the refined pose and cost.
fn refine(
    camera: &CameraModel,
    pts: &[Vector3<f64>],
    px: &[Vector2<f64>],
    idx: &[usize],
    mut r: Matrix3<f64>,
    mut t: Vector3<f64>,
    max_iterations: usize,
) -> Option<(Matrix3<f64>, Vector3<f64>, f64)> {
    let (mut jtj, mut jte, mut c) = normal_equations(camera, pts, px, idx, &r, &t)?;
    let mut lambda = 1e-6;
    for _ in 0..max_iterations {
        let mut a = jtj;
        for k in 0..6 {
            a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
        }
        let Some(ch) = a.cholesky() else {
            lambda *= 10.0;
            continue;
        };
        let d = ch.solve(&(-jte));
        // Gauss-Newton's predicted decrease: below 1e-9 of the cost the pose is converged far
        // below the noise; skip evaluating a step that cannot matter.
        let predicted = -(d.dot(&jte)) - 0.5 * (d.transpose() * jtj * d)[0];
        if predicted.abs() <= 1e-9 * c.max(1e-30) {
            break;
        }
        let w = Vector3::new(d[0], d[1], d[2]);
        let r1 = *Rotation3::new(w).matrix() * r;
        let t1 = t + Vector3::new(d[3], d[4], d[5]);
        match normal_equations(camera, pts, px, idx, &r1, &t1) {
            Some((j1, e1, c1)) => {
                // Converged when the cost stops changing (relative 1e-8: a pose change far below the
                // noise) or the step is negligible.
                let done = (c - c1).abs() <= 1e-8 * c.max(1e-30) || d.norm() < 1e-10;
                if c1 <= c {
                    (r, t, jtj, jte, c) = (r1, t1, j1, e1, c1);
                    lambda = (lambda * 0.1).max(1e-12);
                } else {
                    lambda *= 10.0;
                }
                if done || lambda > 1e8 {
                    break;
                }
            }
            None => {
                lambda *= 10.0;
                if lambda > 1e8 {
                    break;
                }
            }
        }
    }
    Some((r, t, c))
}

/// Reprojection cost of a pose over all pairs, px^2 (for tests and reports).
pub fn reprojection_cost(
    camera: &CameraModel,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    t_cam_sensor: &Isometry3<f64>,
) -> Option<f64> {
    let idx: Vec<usize> = (0..points_mm.len()).collect();
    let r = *t_cam_sensor.rotation.to_rotation_matrix().matrix();
    cost(
        camera,
        points_mm,
        pixels_px,
        &idx,
        &r,
        &t_cam_sensor.translation.vector,
    )
}

/// Normal equations at a pose (J^T J, J^T e, cost); used by the Jacobian test and the
/// Cramer-Rao bound of the benchmark. Parameters: left rotation increment w (rad), then t (mm).
pub fn reprojection_normal_equations(
    camera: &CameraModel,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    t_cam_sensor: &Isometry3<f64>,
) -> Option<(Matrix6<f64>, Vector6<f64>, f64)> {
    let idx: Vec<usize> = (0..points_mm.len()).collect();
    let r = *t_cam_sensor.rotation.to_rotation_matrix().matrix();
    normal_equations(
        camera,
        points_mm,
        pixels_px,
        &idx,
        &r,
        &t_cam_sensor.translation.vector,
    )
}
