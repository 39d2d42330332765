//! Extrinsics by PnP: SQPnP on bearings for a globally optimal start, then Levenberg-Marquardt on
//! the pixel reprojection error of the true camera model, optionally inside RANSAC.
//!
//! Source: R-Tac0 paper, Sec. IV-A, Eq. (1): the pin-dome points (x, y, z) and their pixels (u, v)
//! give `[R | T]` by solving the Perspective-n-Point problem. Here `[R | T]` is `T_cam_sensor`.

use nalgebra::{
    Isometry3, Matrix3, Matrix6, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3, Vector6,
};

use crate::camera::{CameraError, CameraModel};
use crate::p3p::p3p;
use crate::refraction::Imaging;
use crate::sqpnp::sqpnp;

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
    #[error("no pose puts the points in front of the camera (and, through an optical path, where its rays reach them)")]
    NoSolution,
    #[error("point {index} is behind the camera or outside the lens's field at the solved pose")]
    BehindCamera { index: usize },
    #[error("RANSAC found {inliers} inliers within {threshold_px:.2} px: at least {needed} are needed (are the ids right?)")]
    TooFewInliers {
        inliers: usize,
        needed: usize,
        threshold_px: f64,
    },
}

/// RANSAC settings. The first hypothesis is the all-points solution; minimal samples of 3 points
/// (P3P, each refined on its consensus set when it is the best so far) follow until the adaptive
/// count for `confidence` is reached. The samples are a fixed schedule ([`Triples`]) over the
/// pairs in a canonical order: the same pairs in any order give the same pose, bit for bit, and
/// no seed enters it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RansacOptions {
    /// A point is an inlier when its reprojection error is below this, px; `None`: from the
    /// data ([`robust_threshold_px`]), so that a lens the camera file describes only roughly
    /// (errors of several px towards the edge of its field) still gives a consensus.
    pub threshold_px: Option<f64>,
    /// Probability of drawing at least one outlier-free sample, in (0, 1).
    pub confidence: f64,
    /// Largest number of sampled hypotheses.
    pub max_hypotheses: usize,
    /// Smallest fraction of the points that must be inliers, in (0, 1]; below it the consensus
    /// is a coincidence (e.g. observations labelled at random) and solving fails.
    pub min_inlier_fraction: f64,
}

impl Default for RansacOptions {
    fn default() -> Self {
        RansacOptions {
            threshold_px: None,
            confidence: 0.999,
            max_hypotheses: 1000,
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
    /// The RANSAC inlier threshold used, px: the option's, or the one from the data (`None`
    /// without RANSAC).
    pub ransac_threshold_px: Option<f64>,
}

/// The least inlier threshold taken from the data, px: on well-described lenses the consensus
/// is that of a fixed 3 px (a good pin is never dropped for the noise of its centroid); the
/// data only widen it.
pub const MIN_ROBUST_THRESHOLD_PX: f64 = 3.0;

/// The chance, per solve, that the noise alone puts any good pair outside the threshold from
/// the data.
pub const ROBUST_THRESHOLD_RISK: f64 = 0.002;

/// How many robust standard deviations (per axis) of the reprojection error the threshold from
/// the data is for `n` pairs: a 2D Gaussian error's length exceeds `k sigma` with probability
/// `exp(-k^2 / 2)` (Rayleigh), so that none of `n` good pairs does but with probability
/// [`ROBUST_THRESHOLD_RISK`] (Bonferroni), `k = sqrt(2 ln(n / risk))`: 3.5 for one pair, 4.4
/// for 30, 4.7 for 150. A fixed 3.5 sigma rejected some good pair of 30 in 6 % of solves.
pub fn threshold_sigmas(n: usize) -> f64 {
    (2.0 * (n.max(1) as f64 / ROBUST_THRESHOLD_RISK).ln()).sqrt()
}

/// ... and at most this fraction of the observed pixels' spread (the RMS distance from their
/// mean): errors beyond it are no consensus (pins labelled at random), not a rough lens model.
pub const MAX_ROBUST_THRESHOLD_OF_SPREAD: f64 = 0.1;

/// The point-pixel pairs a solve draws its samples from: the camera, the points (sensor
/// frame, mm), their pixels (px) and the pixels' unit bearing vectors.
#[derive(Clone, Copy)]
struct Pairs<'a> {
    camera: Imaging<'a>,
    pts: &'a [Vector3<f64>],
    /// The points where the straight-ray solvers (P3P, SQPnP) take them: as they are, or
    /// where they appear through the layers ([`Imaging::apparent_points`]).
    apparent: &'a [Vector3<f64>],
    px: &'a [Vector2<f64>],
    bearings: &'a [Vector3<f64>],
}

/// The inlier threshold from the data, px: least median of squares (Rousseeuw 1984; Rousseeuw
/// and Leroy 1987, Sec. 5.1) over the all-points pose `start` and minimal P3P samples (as many
/// as give `confidence` of an outlier-free sample when half the points are outliers), the best
/// refined on its better half; the median squared reprojection error at that pose gives the
/// robust standard deviation per axis, sigma = sqrt(med / (2 ln 2)) (1 + 5 / (n - 6)) (2D
/// Gaussian errors; the finite-sample factor of Rousseeuw and Leroy), and the threshold is
/// [`threshold_sigmas`] sigma, at least [`MIN_ROBUST_THRESHOLD_PX`] and at most
/// [`MAX_ROBUST_THRESHOLD_OF_SPREAD`] of the pixels' spread.
fn robust_threshold_px(
    pairs: &Pairs<'_>,
    start: (&Matrix3<f64>, &Vector3<f64>),
    ro: &RansacOptions,
    opts: &PnpOptions,
) -> f64 {
    let (camera, pts, px, bearings) = (&pairs.camera, pairs.pts, pairs.px, pairs.bearings);
    let n = pts.len();
    let half = n / 2;
    let mut e2 = vec![0.0; n];
    let median2 = |r: &Matrix3<f64>, t: &Vector3<f64>, e2: &mut Vec<f64>| {
        for (k, (m, uv)) in pts.iter().zip(px).enumerate() {
            e2[k] = camera
                .project(r, t, m)
                .map_or(f64::INFINITY, |p| (p - uv).norm_squared());
        }
        let mut sorted = e2.clone();
        *sorted.select_nth_unstable_by(half, f64::total_cmp).1
    };
    let mut best = (median2(start.0, start.1, &mut e2), *start.0, *start.1);
    let samples = ((1.0 - ro.confidence).ln() / (1.0 - 0.5f64.powi(3)).ln())
        .ceil()
        .clamp(1.0, ro.max_hypotheses.max(1) as f64) as usize;
    let mut triples = Triples::new(n);
    let mut poses = Vec::with_capacity(4);
    for _ in 0..samples {
        let sample = triples.next_triple();
        p3p(
            &sample.map(|i| pairs.apparent[i]),
            &sample.map(|i| bearings[i]),
            &mut poses,
        );
        for (r, t) in &poses {
            let t = camera.admissible_start(r, t);
            let m = median2(r, &t, &mut e2);
            if m < best.0 {
                best = (m, *r, t);
            }
        }
    }
    // the best pose refined on the half of the points it explains best
    median2(&best.1, &best.2, &mut e2);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| e2[a].total_cmp(&e2[b]));
    order.truncate((half + 1).max(MIN_POINTS).min(n));
    order.sort_unstable();
    if let Some(mut f) = Fit::at(camera, pts, px, &order, best.1, best.2) {
        f.refine(camera, pts, px, opts.max_iterations);
        let m = median2(&f.r, &f.t, &mut e2);
        if m < best.0 {
            best.0 = m;
        }
    }
    let finite = (1.0 + 5.0 / n.saturating_sub(6).max(1) as f64).min(2.0);
    let sigma = (best.0 / (2.0 * std::f64::consts::LN_2)).sqrt() * finite;
    let most = most_threshold_px(px);
    if sigma.is_finite() {
        (threshold_sigmas(n) * sigma).clamp(MIN_ROBUST_THRESHOLD_PX, most)
    } else {
        MIN_ROBUST_THRESHOLD_PX
    }
}

/// The largest inlier threshold the data may give, px: [`MAX_ROBUST_THRESHOLD_OF_SPREAD`] of the
/// pixels' spread (the RMS distance from their mean), at least [`MIN_ROBUST_THRESHOLD_PX`].
fn most_threshold_px(px: &[Vector2<f64>]) -> f64 {
    let n = px.len().max(1) as f64;
    let mean = px.iter().sum::<Vector2<f64>>() / n;
    let spread = (px.iter().map(|p| (p - mean).norm_squared()).sum::<f64>() / n).sqrt();
    (MAX_ROBUST_THRESHOLD_OF_SPREAD * spread).max(MIN_ROBUST_THRESHOLD_PX)
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
    solve_pnp_through(&Imaging::straight(camera), points_mm, pixels_px, opts)
}

/// [`solve_pnp`] through an optical path: the residuals, the consensus and every refinement
/// project through `imaging`'s layers ([`crate::refraction`]); the minimal samples and the
/// closed-form starts take the pixels' straight bearings, which the refinement then corrects.
///
/// # Errors
/// As [`solve_pnp`].
pub fn solve_pnp_through(
    camera: &Imaging<'_>,
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
                .camera
                .unproject(uv)
                .map_err(|source| PnpError::Unprojectable { index, source })?,
        );
    }
    // The pairs in a canonical order (by point, then pixel): every sum and every sample below
    // follows it, so the same pairs in any input order give the same pose, bit for bit.
    let mut order: Vec<usize> = (0..n).collect();
    let key = |i: usize| {
        let (m, uv) = (points_mm[i], pixels_px[i]);
        [m.x, m.y, m.z, uv.x, uv.y]
    };
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key(a), key(b));
        ka.iter()
            .zip(&kb)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let points: Vec<Vector3<f64>> = order.iter().map(|&i| points_mm[i]).collect();
    let pixels: Vec<Vector2<f64>> = order.iter().map(|&i| pixels_px[i]).collect();
    let bearings: Vec<Vector3<f64>> = order.iter().map(|&i| bearings[i]).collect();
    let s = solve_in_order(camera, &points, &pixels, &bearings, opts).map_err(|e| match e {
        PnpError::BehindCamera { index } => PnpError::BehindCamera {
            index: order[index],
        },
        e => e,
    })?;
    let mut inliers = vec![false; n];
    let mut residuals_px = vec![None; n];
    for (k, &i) in order.iter().enumerate() {
        inliers[i] = s.inliers[k];
        residuals_px[i] = s.residuals_px[k];
    }
    Ok(PnpSolution {
        inliers,
        residuals_px,
        ..s
    })
}

/// [`solve_pnp`] on validated pairs in the canonical order, with their bearings.
fn solve_in_order(
    camera: &Imaging<'_>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    bearings: &[Vector3<f64>],
    opts: &PnpOptions,
) -> Result<PnpSolution, PnpError> {
    let n = points_mm.len();
    check_layout(points_mm, bearings)?;
    let all: Vec<usize> = (0..n).collect();
    let apparent = camera.apparent_points(points_mm);
    let start = sqpnp(&apparent, bearings).ok_or(PnpError::NoSolution)?;
    // A start from which a point is seen through no ray (a core's open end hides it from a
    // camera too far below) is moved towards the lowest plane, where the view widens.
    let start_t = camera.admissible_start(&start.rotation, &start.translation_mm);
    let mut fit = Fit::at(camera, points_mm, pixels_px, &all, start.rotation, start_t);
    for frac in [0.25, 0.5, 0.75, 1.0] {
        if fit.is_some() {
            break;
        }
        let t = camera.start_nearer_plane(&start.rotation, &start_t, frac);
        fit = Fit::at(camera, points_mm, pixels_px, &all, start.rotation, t);
    }
    let mut fit = fit.ok_or(PnpError::NoSolution)?;
    // Through an optical path the apparent points are exact on the axis only: far off it (a
    // glass core's faces) the closed-form start misses the outer pins by pixels. The start
    // refined through the path on every pair replaces it when that lowers the median
    // reprojection error, so that the threshold and the first consensus are taken where the
    // path's model holds.
    if camera.layers.is_some() {
        let median = |f: &Fit| {
            let mut e: Vec<f64> = f.residuals.iter().map(|r| r.norm()).collect();
            e.sort_by(f64::total_cmp);
            e[e.len() / 2]
        };
        let mut refined = fit.clone();
        refined.refine(camera, points_mm, pixels_px, opts.max_iterations);
        if median(&refined) < median(&fit) {
            fit = refined;
        }
    }
    let mut hypotheses = 0;
    let mut inliers = vec![true; n];
    let mut threshold_used = None;
    let pairs = Pairs {
        camera: *camera,
        pts: points_mm,
        apparent: &apparent,
        px: pixels_px,
        bearings,
    };
    match &opts.ransac {
        None => fit.refine(camera, points_mm, pixels_px, opts.max_iterations),
        Some(ro) => {
            let threshold_px = match ro.threshold_px {
                Some(t) => t,
                None => robust_threshold_px(&pairs, (&fit.r, &fit.t), ro, opts),
            };
            let ro = &RansacOptions {
                threshold_px: Some(threshold_px),
                ..*ro
            };
            let thr2 = threshold_px * threshold_px;
            // The all-points SQPnP pose is the first hypothesis. When it explains every pair,
            // the refinement on all of them is the answer unless it pushes a pair out.
            let rescore = |c: &mut Consensus, fit: &Fit| {
                c.score(
                    camera,
                    points_mm,
                    pixels_px,
                    &fit.r,
                    &fit.t,
                    thr2,
                    f64::INFINITY,
                );
            };
            let mut consensus = Consensus::new(n);
            rescore(&mut consensus, &fit);
            if consensus.count() == n {
                fit.refine(camera, points_mm, pixels_px, opts.max_iterations);
                consensus.set_from_fit(&fit, thr2);
            }
            if consensus.count() < n {
                hypotheses = ransac(&pairs, ro, opts, &mut fit, &mut consensus);
            }
            // The final fit on the consensus ([`fit_on`]), scored again and fitted again until
            // the set stops changing.
            for _ in 0..6 {
                let idx = consensus.indices();
                if idx.len() < MIN_POINTS {
                    break;
                }
                if let Some(f) = fit_on(&pairs, &idx, &fit, opts) {
                    fit = f;
                }
                rescore(&mut consensus, &fit);
                if consensus.indices() == idx {
                    break;
                }
            }
            threshold_used = Some(threshold_px);
            inliers = consensus.inliers;
            let count = inliers.iter().filter(|&&b| b).count();
            let needed = MIN_POINTS.max((ro.min_inlier_fraction * n as f64).ceil() as usize);
            if count < needed {
                return Err(PnpError::TooFewInliers {
                    inliers: count,
                    needed,
                    threshold_px,
                });
            }
        }
    }
    // Residuals: the fit's own for the pairs it was refined on, a projection for the others.
    let mut residuals_px: Vec<Option<Vector2<f64>>> = vec![None; n];
    for (k, &i) in fit.idx.iter().enumerate() {
        residuals_px[i] = Some(fit.residuals[k]);
    }
    let (mut sum2, mut m) = (0.0, 0usize);
    for i in 0..n {
        if residuals_px[i].is_none() {
            residuals_px[i] = camera
                .project(&fit.r, &fit.t, &points_mm[i])
                .map(|uv| uv - pixels_px[i]);
        }
        if inliers[i] {
            match residuals_px[i] {
                Some(e) => {
                    sum2 += e.norm_squared();
                    m += 1;
                }
                None => return Err(PnpError::BehindCamera { index: i }),
            }
        }
    }
    // LM updates R by exact rotations, so R is orthonormal to rounding: the quaternion of R,
    // renormalised, is the nearest rotation.
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(fit.r));
    let rot = UnitQuaternion::new_normalize(q.into_inner());
    Ok(PnpSolution {
        t_cam_sensor: Isometry3::from_parts(Translation3::from(fit.t), rot),
        inliers,
        residuals_px,
        rms_reprojection_error_px: (sum2 / m as f64).sqrt(),
        hypotheses,
        ransac_threshold_px: threshold_used,
    })
}

/// RANSAC with local optimisation: minimal samples of 3 (P3P), MSAC scores with early exit, a
/// Levenberg-Marquardt refinement of every new best hypothesis on its consensus set, then a final
/// refinement repeated while the consensus set changes. `fit` and `consensus` hold the best so
/// far on entry and the result on return. Returns the number of hypotheses drawn.
fn ransac(
    pairs: &Pairs<'_>,
    ro: &RansacOptions,
    opts: &PnpOptions,
    fit: &mut Fit,
    best: &mut Consensus,
) -> usize {
    let (camera, pts, px, bearings) = (&pairs.camera, pairs.pts, pairs.px, pairs.bearings);
    let n = pts.len();
    let thr = ro.threshold_px.unwrap_or(MIN_ROBUST_THRESHOLD_PX);
    let thr2 = thr * thr;
    // Local optimisation of the starting hypothesis.
    let local_opt = |fit: &mut Fit, c: &mut Consensus| {
        let idx = c.indices();
        if idx.len() < MIN_POINTS {
            return;
        }
        if let Some(mut f) = Fit::at(camera, pts, px, &idx, fit.r, fit.t) {
            f.refine(camera, pts, px, opts.max_iterations);
            let mut c1 = Consensus::new(n);
            c1.score(camera, pts, px, &f.r, &f.t, thr2, c.score);
            if c1.score <= c.score {
                *fit = f;
                *c = c1;
            }
        }
    };
    local_opt(fit, best);
    let adaptive = |c: &Consensus| {
        let w = c.count() as f64 / n as f64;
        let denom = (1.0 - w.powi(3)).ln();
        if denom < 0.0 {
            ((1.0 - ro.confidence).ln() / denom).ceil().max(1.0) as usize
        } else {
            // No inlier yet: sample up to the limit.
            usize::MAX
        }
    };
    let mut needed = adaptive(best).min(ro.max_hypotheses);
    let mut triples = Triples::new(n);
    let mut poses = Vec::with_capacity(4);
    let mut trial = Consensus::new(n);
    let mut hypotheses = 0;
    while hypotheses < needed {
        hypotheses += 1;
        let sample = triples.next_triple();
        let sp = sample.map(|i| pairs.apparent[i]);
        let sb = sample.map(|i| bearings[i]);
        p3p(&sp, &sb, &mut poses);
        for (hr, ht) in &poses {
            let ht = &camera.admissible_start(hr, ht);
            if !trial.score(camera, pts, px, hr, ht, thr2, best.score) {
                continue;
            }
            let mut hfit = Fit {
                r: *hr,
                t: *ht,
                ..Fit::default()
            };
            let mut hc = trial.clone();
            local_opt(&mut hfit, &mut hc);
            *fit = hfit;
            *best = hc;
            needed = adaptive(best).min(ro.max_hypotheses);
        }
    }
    // Final fit on the consensus set ([`fit_on`]), repeated while the set changes.
    for _ in 0..4 {
        let idx = best.indices();
        if idx.len() < MIN_POINTS || fit.idx == idx {
            break;
        }
        if let Some(f) = fit_on(pairs, &idx, fit, opts) {
            *fit = f;
        }
        best.score(camera, pts, px, &fit.r, &fit.t, thr2, f64::INFINITY);
    }
    hypotheses
}

/// The fit on the pairs `idx`: refined from `from` and from SQPnP's globally optimal start on
/// them, the lower cost kept, so that the pose is the optimum of the set, not of where a
/// hypothesis left the refinement (a flat valley of the reprojection error can hold one start
/// short of it). `None` when neither start projects every pair.
fn fit_on(pairs: &Pairs<'_>, idx: &[usize], from: &Fit, opts: &PnpOptions) -> Option<Fit> {
    let (camera, pts, px, bearings) = (&pairs.camera, pairs.pts, pairs.px, pairs.bearings);
    let mut best: Option<Fit> = None;
    let mut consider = |r: Matrix3<f64>, t: Vector3<f64>| {
        if let Some(mut f) = Fit::at(camera, pts, px, idx, r, t) {
            f.refine(camera, pts, px, opts.max_iterations);
            if best.as_ref().is_none_or(|b| f.cost < b.cost) {
                best = Some(f);
            }
        }
    };
    consider(from.r, from.t);
    let (sp, sb): (Vec<_>, Vec<_>) = idx
        .iter()
        .map(|&i| (pairs.apparent[i], bearings[i]))
        .unzip();
    if let Some(g) = sqpnp(&sp, &sb) {
        consider(
            g.rotation,
            camera.admissible_start(&g.rotation, &g.translation_mm),
        );
    }
    best
}

/// MSAC consensus of a pose: which pairs reproject within the threshold and the truncated score.
#[derive(Debug, Clone)]
struct Consensus {
    inliers: Vec<bool>,
    /// Sum over the pairs of min(squared reprojection error, threshold^2), px^2.
    score: f64,
}

impl Consensus {
    fn new(n: usize) -> Self {
        Consensus {
            inliers: vec![false; n],
            score: f64::INFINITY,
        }
    }

    fn count(&self) -> usize {
        self.inliers.iter().filter(|&&b| b).count()
    }

    fn indices(&self) -> Vec<usize> {
        (0..self.inliers.len())
            .filter(|&i| self.inliers[i])
            .collect()
    }

    /// Scores the pose; stops early (returning false, `self` then unspecified) as soon as the
    /// partial score reaches `bound`. True when the whole score is below `bound`.
    #[allow(clippy::too_many_arguments)]
    fn score(
        &mut self,
        camera: &Imaging<'_>,
        pts: &[Vector3<f64>],
        px: &[Vector2<f64>],
        r: &Matrix3<f64>,
        t: &Vector3<f64>,
        thr2: f64,
        bound: f64,
    ) -> bool {
        let mut s = 0.0;
        for (k, (m, uv)) in pts.iter().zip(px).enumerate() {
            let e2 = camera
                .project(r, t, m)
                .map_or(f64::INFINITY, |p| (p - uv).norm_squared());
            self.inliers[k] = e2 < thr2;
            s += e2.min(thr2);
            if s >= bound {
                self.score = f64::INFINITY;
                return false;
            }
        }
        self.score = s;
        true
    }

    /// The consensus of a fit made on every pair, from its own residuals.
    fn set_from_fit(&mut self, fit: &Fit, thr2: f64) {
        let mut s = 0.0;
        for (k, &i) in fit.idx.iter().enumerate() {
            let e2 = fit.residuals[k].norm_squared();
            self.inliers[i] = e2 < thr2;
            s += e2.min(thr2);
        }
        self.score = s;
    }
}

/// A pose with the normal equations and residuals of the reprojection error over `idx`.
#[derive(Debug, Clone, Default)]
struct Fit {
    r: Matrix3<f64>,
    t: Vector3<f64>,
    idx: Vec<usize>,
    jtj: Matrix6<f64>,
    jte: Vector6<f64>,
    /// Sum of squared reprojection errors over `idx`, px^2.
    cost: f64,
    /// Reprojected minus observed pixel per entry of `idx`, px.
    residuals: Vec<Vector2<f64>>,
}

impl Fit {
    /// `None` if a point of `idx` does not project at (r, t).
    fn at(
        camera: &Imaging<'_>,
        pts: &[Vector3<f64>],
        px: &[Vector2<f64>],
        idx: &[usize],
        r: Matrix3<f64>,
        t: Vector3<f64>,
    ) -> Option<Fit> {
        let mut residuals = Vec::with_capacity(idx.len());
        let (jtj, jte, cost) = normal_equations(camera, pts, px, idx, &r, &t, &mut residuals)?;
        Some(Fit {
            r,
            t,
            idx: idx.to_vec(),
            jtj,
            jte,
            cost,
            residuals,
        })
    }

    /// Levenberg-Marquardt on the reprojection error over `idx`, from the current pose.
    fn refine(
        &mut self,
        camera: &Imaging<'_>,
        pts: &[Vector3<f64>],
        px: &[Vector2<f64>],
        max_iterations: usize,
    ) {
        let mut lambda = 1e-6;
        let mut res1 = Vec::with_capacity(self.idx.len());
        for _ in 0..max_iterations {
            let mut a = self.jtj;
            for k in 0..6 {
                a[(k, k)] += lambda * self.jtj[(k, k)].max(1e-12);
            }
            let Some(ch) = a.cholesky() else {
                lambda *= 10.0;
                if lambda > 1e8 {
                    break;
                }
                continue;
            };
            let d = ch.solve(&(-self.jte));
            // Gauss-Newton's predicted decrease: below 1e-9 of the cost the pose is converged far
            // below the noise; skip evaluating a step that cannot matter.
            let predicted = -(d.dot(&self.jte)) - 0.5 * (d.transpose() * self.jtj * d)[0];
            if predicted.abs() <= 1e-9 * self.cost.max(1e-30) {
                break;
            }
            let w = Vector3::new(d[0], d[1], d[2]);
            let r1 = *Rotation3::new(w).matrix() * self.r;
            let t1 = self.t + Vector3::new(d[3], d[4], d[5]);
            match normal_equations(camera, pts, px, &self.idx, &r1, &t1, &mut res1) {
                Some((j1, e1, c1)) => {
                    // Converged when the cost stops changing (relative 1e-8: a pose change far
                    // below the noise) or the step is negligible.
                    let done =
                        (self.cost - c1).abs() <= 1e-8 * self.cost.max(1e-30) || d.norm() < 1e-10;
                    if c1 <= self.cost {
                        (self.r, self.t, self.jtj, self.jte, self.cost) = (r1, t1, j1, e1, c1);
                        std::mem::swap(&mut self.residuals, &mut res1);
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
    }
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

/// The minimal samples of a solve: triples of distinct indices in `0..n` from the R3
/// low-discrepancy sequence (Roberts 2018, "The unreasonable effectiveness of quasirandom
/// sequences"): point `k` is `frac(0.5 + k (1/g, 1/g^2, 1/g^3))` in the unit cube, `g` the
/// positive root of `x^4 = x + 1`, scaled to indices; points with a repeated index are
/// skipped. A fixed schedule, not a random one: the triples depend on `n` only, and they
/// spread over all triples as evenly as the sequence spreads over the cube, from the first.
pub struct Triples {
    n: usize,
    k: u64,
}

impl Triples {
    const G: f64 = 1.220_744_084_605_759_5;

    /// The schedule for `n >= 3` indices.
    pub fn new(n: usize) -> Triples {
        Triples { n, k: 0 }
    }

    /// The next triple of distinct indices.
    pub fn next_triple(&mut self) -> [usize; 3] {
        let a = [
            1.0 / Self::G,
            1.0 / (Self::G * Self::G),
            1.0 / Self::G.powi(3),
        ];
        let n = self.n.max(3);
        loop {
            self.k += 1;
            let s = a.map(|a| {
                let x = (0.5 + self.k as f64 * a).fract();
                ((x * n as f64) as usize).min(n - 1)
            });
            if s[0] != s[1] && s[0] != s[2] && s[1] != s[2] {
                return s;
            }
        }
    }
}

/// Normal equations of the reprojection error at (r, t): J^T J and J^T e over `idx`, with the
/// rotation perturbed on the left (R <- exp(w) R) and parameters (w, t); `residuals` gets the
/// reprojected minus observed pixel per entry of `idx`.
pub(crate) fn normal_equations(
    camera: &Imaging<'_>,
    pts: &[Vector3<f64>],
    px: &[Vector2<f64>],
    idx: &[usize],
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
    residuals: &mut Vec<Vector2<f64>>,
) -> Option<(Matrix6<f64>, Vector6<f64>, f64)> {
    residuals.clear();
    let mut jtj = Matrix6::zeros();
    let mut jte = Vector6::zeros();
    let mut s = 0.0;
    for &i in idx {
        let (uv, j) = camera.project_with_jacobian(r, t, &pts[i])?;
        let e = uv - px[i];
        residuals.push(e);
        s += e.norm_squared();
        jtj += j.transpose() * j;
        jte += j.transpose() * e;
    }
    Some((jtj, jte, s))
}

/// The rotation matrix and translation of a pose, as [`normal_equations`] takes them.
fn rotation_translation(pose: &Isometry3<f64>) -> (Matrix3<f64>, Vector3<f64>) {
    (
        *pose.rotation.to_rotation_matrix().matrix(),
        pose.translation.vector,
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
    let (r, t) = rotation_translation(t_cam_sensor);
    normal_equations(
        &Imaging::straight(camera),
        points_mm,
        pixels_px,
        &idx,
        &r,
        &t,
        &mut Vec::new(),
    )
}

/// How well the pins' geometry fixes a pose: the first-order covariance of the pose from the
/// reprojection error's Jacobian at the solution (Hartley & Zisserman, Multiple View Geometry,
/// 2nd ed., Ch. 5, the covariance of an estimated transformation: Sigma = sigma^2 (J^T J)^-1), for a pixel noise of 1 px in each
/// coordinate. It scales with the noise: multiply the standard deviations by the noise in px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseUncertainty {
    /// Covariance of (w, t) for 1 px of pixel noise, 6 x 6 rows: w the rotation perturbation
    /// of T_cam_sensor on the left (camera frame, rad), t its translation (mm).
    pub covariance_per_px2: [[f64; 6]; 6],
    /// Standard deviation of the rotation about the camera's x, y and z axes per px of noise,
    /// degrees.
    pub rotation_std_deg_per_px: [f64; 3],
    /// Standard deviation of the translation along x, y and z per px of noise, mm.
    pub translation_std_mm_per_px: [f64; 3],
}

impl PoseUncertainty {
    /// The root-mean-square rotation (deg) and translation (mm) errors of the pose for a pixel
    /// noise of `sigma_px` per coordinate: the roots of the traces of the covariance's rotation
    /// and translation blocks, times `sigma_px` (the Cramer-Rao bound's RMS).
    pub fn rms_errors(&self, sigma_px: f64) -> (f64, f64) {
        let c = &self.covariance_per_px2;
        let block = |k: usize| (0..3).map(|i| c[k + i][k + i]).sum::<f64>().max(0.0).sqrt();
        (sigma_px * block(0).to_degrees(), sigma_px * block(3))
    }
}

/// Largest rotation standard deviation per px of pixel noise (about any camera axis) of a pose
/// whose geometry is not weak, degrees. The benchmark scene's 30 pins over 75 deg give about
/// 0.2 deg/px; 4 pins within 18 deg of the pole about 16 deg/px (tests/it/extrinsics_synthetic).
pub const WEAK_POSE_DEG_PER_PX: f64 = 1.0;
/// Largest translation standard deviation per px of pixel noise (along any camera axis) of a
/// pose whose geometry is not weak, mm (the benchmark scene: about 0.05 mm/px).
pub const WEAK_POSE_MM_PER_PX: f64 = 1.0;

/// The [`PoseUncertainty`] of `t_cam_sensor` over the pairs marked in `inliers`; `None` when
/// the pose is not determined (J^T J singular) or a point does not project.
pub fn pose_uncertainty(
    camera: &CameraModel,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    inliers: &[bool],
    t_cam_sensor: &Isometry3<f64>,
) -> Option<PoseUncertainty> {
    pose_uncertainty_through(
        &Imaging::straight(camera),
        points_mm,
        pixels_px,
        inliers,
        t_cam_sensor,
    )
}

/// [`pose_uncertainty`] through an optical path.
pub fn pose_uncertainty_through(
    camera: &Imaging<'_>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    inliers: &[bool],
    t_cam_sensor: &Isometry3<f64>,
) -> Option<PoseUncertainty> {
    let idx: Vec<usize> = (0..points_mm.len())
        .filter(|&i| inliers.get(i).copied().unwrap_or(false))
        .collect();
    let (r, t) = rotation_translation(t_cam_sensor);
    let mut residuals = Vec::with_capacity(idx.len());
    let (jtj, _, _) = normal_equations(camera, points_mm, pixels_px, &idx, &r, &t, &mut residuals)?;
    let cov = jtj.try_inverse()?;
    if !cov.iter().all(|x| x.is_finite()) || (0..6).any(|k| !(cov[(k, k)] >= 0.0)) {
        return None;
    }
    Some(PoseUncertainty {
        covariance_per_px2: std::array::from_fn(|i| std::array::from_fn(|j| cov[(i, j)])),
        rotation_std_deg_per_px: std::array::from_fn(|k| cov[(k, k)].sqrt().to_degrees()),
        translation_std_mm_per_px: std::array::from_fn(|k| cov[(k + 3, k + 3)].sqrt()),
    })
}
