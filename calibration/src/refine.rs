//! Intrinsics refinement from the pin captures (R-Tac0 Sec. IV-A: the authors can refine the
//! camera matrix and distortion from the same pin captures, their `calibrateCamera` path):
//! fx, fy, cx, cy and the distortion coefficients of the camera file's model, jointly with the
//! pose, by Levenberg-Marquardt on the reprojection error; each parameter's standard deviation
//! from the covariance at the solution (sigma^2 (J^T J)^-1, sigma^2 the residual variance;
//! Hartley & Zisserman, Multiple View Geometry, 2nd ed., Ch. 5).
//!
//! Not every parameter is fixed by one camera's view of pins on a dome: seen from near the
//! sphere's axis, the focal length trades against the camera's distance along the axis (with
//! every parameter free the Jacobian's condition number is about 1e16). Before the fit, the
//! Jacobian's columns are scaled to unit length and its condition number taken; while it is
//! above [`MAX_CONDITION`], the parameter that weighs most in the least-determined direction
//! (the right singular vector of the smallest singular value) is held at the camera file's
//! value, and the report says which and with what it trades. After the fit, the distortion
//! coefficients beyond k1 and k2 (the lens's main distortion, always refined when the
//! condition number allows) are taken from the highest order down: one whose move from the camera file's
//! value lowers the squared reprojection error by less than ln N sigma^2 (N the observations;
//! dropping one parameter raises it by t^2 sigma^2, t its move over its standard deviation) is
//! not worth its place by the Bayesian information criterion (Schwarz 1978) and is held, and
//! the fit repeated; the first that is worth it ends the pruning. A coefficient independent of
//! the others (within [`MAX_CONDITION`]) may still be so weakly seen that its value is the
//! fit's guess (issue 97: k3 = -1.02 +- 3.9 from 29 pins of a 160 deg lens). Parameters named
//! by the user are never held: a list that the captures do not constrain is refused.

use nalgebra::{
    DMatrix, DVector, Isometry3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3,
};

use crate::camera::{CameraModel, Distortion, Intrinsics};
use crate::pnp::PnpSolution;
use crate::refraction::{Imaging, OpticalLayers};

/// Largest condition number of the column-scaled Jacobian (pose and free intrinsics) that is
/// refined; a parameter beyond it is not constrained by the captures.
pub const MAX_CONDITION: f64 = 300.0;

/// The names of a model's intrinsic parameters, in order: fx, fy, cx, cy, then the distortion
/// coefficients in OpenCV's order.
pub fn parameter_names(d: &Distortion) -> &'static [&'static str] {
    match d {
        Distortion::Fisheye(_) => &["fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"],
        Distortion::PlumbBob(_) => &["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"],
        Distortion::RationalPolynomial(_) => &[
            "fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6",
        ],
    }
}

const POSE_NAMES: [&str; 6] = [
    "the camera's rotation about x",
    "the camera's rotation about y",
    "the camera's rotation about z",
    "the camera's offset along x",
    "the camera's offset along y",
    "the camera's distance along its axis (tz)",
];

/// Which parameters to refine.
#[derive(Debug, Clone, PartialEq)]
pub enum RefineParameters {
    /// Every parameter the captures constrain; the others are held and reported.
    Constrained,
    /// Exactly these (names of [`parameter_names`]); refused if the captures do not constrain
    /// them.
    Only(Vec<String>),
}

/// Why the intrinsics cannot be refined.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefineError {
    #[error("--refine-intrinsics {value}: '{name}' is not a parameter of the {model} model (its parameters: {known})")]
    UnknownParameter {
        value: String,
        name: String,
        model: &'static str,
        known: String,
    },
    #[error("--refine-intrinsics {value}: '{name}' is named twice")]
    Twice { value: String, name: String },
    #[error("--refine-intrinsics {value}: the captures do not constrain {name} (it trades against {with}): the condition number is {condition:.1e}, above {limit:.0e}; leave it out (it is then held at the camera file's value), or observe pins over more of the field")]
    Unconstrained {
        value: String,
        name: String,
        with: String,
        condition: f64,
        limit: f64,
    },
    #[error("--refine-intrinsics: {observations} observations for {parameters} parameters (the pose's 6 and {intrinsics} intrinsics): too few to refine and estimate the noise; observe more pins")]
    TooFewObservations {
        observations: usize,
        parameters: usize,
        intrinsics: usize,
    },
    #[error("--refine-intrinsics: the captures constrain none of the intrinsics (every one trades against the pose: condition number {condition:.1e} with only {first} free); the camera file's values are kept")]
    NothingConstrained { first: String, condition: f64 },
    #[error("--refine-intrinsics: a point does not project at the camera file's intrinsics and the solved pose")]
    Unprojectable,
}

/// One intrinsic parameter after refinement.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RefinedParameter {
    pub name: String,
    /// The camera file's value.
    pub initial: f64,
    /// The refined value (the initial one when held).
    pub value: f64,
    /// Standard deviation from the covariance, same unit as the value (`null` when held).
    pub std: Option<f64>,
    /// Why it was held at the camera file's value (`null` when refined).
    pub held: Option<String>,
}

/// The result of [`refine_intrinsics`].
#[derive(Debug, Clone, PartialEq)]
pub struct Refinement {
    pub camera: CameraModel,
    pub t_cam_sensor: Isometry3<f64>,
    pub parameters: Vec<RefinedParameter>,
    /// Condition number of the column-scaled Jacobian over the pose and the refined
    /// parameters, at the solution.
    pub condition_number: f64,
    /// RMS reprojection error before (camera file's intrinsics, solved pose) and after, px.
    pub rms_before_px: f64,
    pub rms_after_px: f64,
    pub iterations: usize,
    /// Standard deviations of the refined pose from the same covariance (the intrinsics'
    /// uncertainty included): the rotation about the camera's x, y and z axes (the left
    /// increment of T_cam_sensor), degrees, and the translation along them, mm; `None` when the
    /// covariance is singular.
    pub pose_std: Option<([f64; 3], [f64; 3])>,
}

/// The intrinsic parameter vector of a camera: fx, fy, cx, cy, distortion coefficients.
fn intrinsic_vector(i: &Intrinsics) -> Vec<f64> {
    let mut v = vec![i.fx_px, i.fy_px, i.cx_px, i.cy_px];
    v.extend_from_slice(i.distortion.coefficients());
    v
}

fn with_vector(i: &Intrinsics, v: &[f64]) -> Intrinsics {
    let d = match i.distortion {
        Distortion::Fisheye(_) => Distortion::Fisheye(std::array::from_fn(|k| v[4 + k])),
        Distortion::PlumbBob(_) => Distortion::PlumbBob(std::array::from_fn(|k| v[4 + k])),
        Distortion::RationalPolynomial(_) => {
            Distortion::RationalPolynomial(std::array::from_fn(|k| v[4 + k]))
        }
    };
    Intrinsics {
        fx_px: v[0],
        fy_px: v[1],
        cx_px: v[2],
        cy_px: v[3],
        distortion: d,
        ..*i
    }
}

/// The problem: which intrinsics are free, the fixed data.
struct Problem<'a> {
    base: Intrinsics,
    free: Vec<usize>,
    points: &'a [Vector3<f64>],
    pixels: &'a [Vector2<f64>],
    /// The optical path in front of the lens ([`crate::refraction`]); `None`: straight rays.
    layers: Option<&'a OpticalLayers>,
    /// Points that must keep projecting (the pins the fit leaves out but that project at the
    /// start: a refined model must not fold the image back before them).
    keep: &'a [Vector3<f64>],
}

/// A state: the full intrinsic vector and the pose (R, t).
#[derive(Clone)]
struct State {
    intr: Vec<f64>,
    r: Rotation3<f64>,
    t: Vector3<f64>,
}

impl Problem<'_> {
    fn n_params(&self) -> usize {
        self.free.len() + 6
    }

    /// Residuals (reprojected minus observed, u then v per point), or `None` when a point
    /// does not project or the intrinsics are not a camera.
    fn residuals(&self, s: &State) -> Option<DVector<f64>> {
        let each = self.point_residuals(s)?;
        let mut e = DVector::zeros(2 * self.points.len());
        for (k, r) in each.iter().enumerate() {
            let r = (*r)?;
            e[2 * k] = r.x;
            e[2 * k + 1] = r.y;
        }
        Some(e)
    }

    /// Each point's residual, `None` for a point that does not project; `None` in all when
    /// the intrinsics are not a camera.
    fn point_residuals(&self, s: &State) -> Option<Vec<Option<Vector2<f64>>>> {
        let cam = CameraModel::new(with_vector(&self.base, &s.intr)).ok()?;
        let imaging = Imaging {
            camera: &cam,
            layers: self.layers,
        };
        let r = *s.r.matrix();
        Some(
            self.points
                .iter()
                .zip(self.pixels)
                .map(|(p, px)| imaging.project(&r, &s.t, p).map(|uv| uv - px))
                .collect(),
        )
    }

    /// Whether every point of `keep` projects at `s`.
    fn keeps(&self, s: &State) -> bool {
        if self.keep.is_empty() {
            return true;
        }
        let Ok(cam) = CameraModel::new(with_vector(&self.base, &s.intr)) else {
            return false;
        };
        let imaging = Imaging {
            camera: &cam,
            layers: self.layers,
        };
        let r = *s.r.matrix();
        self.keep
            .iter()
            .all(|p| imaging.project(&r, &s.t, p).is_some())
    }

    /// `s` moved by `d` (free intrinsics, then the rotation increment on the left, then t).
    fn step(&self, s: &State, d: &[f64]) -> State {
        let mut n = s.clone();
        for (k, &i) in self.free.iter().enumerate() {
            n.intr[i] += d[k];
        }
        let m = self.free.len();
        n.r = Rotation3::new(Vector3::new(d[m], d[m + 1], d[m + 2])) * s.r;
        n.t += Vector3::new(d[m + 3], d[m + 4], d[m + 5]);
        n
    }

    /// Central-difference Jacobian of the residuals; for a point that a parameter's step one
    /// way puts outside the model's field (a pin at the edge of a pinhole model's monotonic
    /// radius, where a little more distortion folds the image back), the one-sided difference
    /// of the other way. `None` when a point does not project at both steps (or, where one
    /// side is needed, at `s`).
    fn jacobian(&self, s: &State) -> Option<DMatrix<f64>> {
        let p = self.n_params();
        let mut j = DMatrix::zeros(2 * self.points.len(), p);
        let m = self.free.len();
        // the residuals at `s`, needed only for a one-sided difference
        let mut at: Option<Vec<Vector2<f64>>> = None;
        let mut at_s = |k: usize| -> Option<Vector2<f64>> {
            if at.is_none() {
                at = Some(
                    self.point_residuals(s)?
                        .into_iter()
                        .collect::<Option<_>>()?,
                );
            }
            at.as_ref().map(|v| v[k])
        };
        for c in 0..p {
            let h = if c < m {
                1e-6 * (s.intr[self.free[c]].abs() + 1e-2)
            } else if c < m + 3 {
                1e-7
            } else {
                1e-6
            };
            let mut d = vec![0.0; p];
            d[c] = h;
            let plus = self.point_residuals(&self.step(s, &d))?;
            d[c] = -h;
            let minus = self.point_residuals(&self.step(s, &d))?;
            for (k, (a, b)) in plus.iter().zip(&minus).enumerate() {
                let dk = match (a, b) {
                    (Some(a), Some(b)) => (a - b) / (2.0 * h),
                    (Some(a), None) => (a - at_s(k)?) / h,
                    (None, Some(b)) => (at_s(k)? - b) / h,
                    (None, None) => return None,
                };
                j[(2 * k, c)] = dk.x;
                j[(2 * k + 1, c)] = dk.y;
            }
        }
        Some(j)
    }
}

/// Condition number of `j` with its columns scaled to unit length, and the right singular
/// vector of its smallest singular value.
fn scaled_condition(j: &DMatrix<f64>) -> (f64, DVector<f64>) {
    let mut js = j.clone();
    for mut c in js.column_iter_mut() {
        let n = c.norm();
        if n > 0.0 {
            c /= n;
        }
    }
    let svd = js.svd(false, true);
    let sv = &svd.singular_values;
    let (mut imax, mut imin) = (0, 0);
    for k in 0..sv.len() {
        if sv[k] > sv[imax] {
            imax = k;
        }
        if sv[k] < sv[imin] {
            imin = k;
        }
    }
    let cond = if sv[imin] > 0.0 {
        sv[imax] / sv[imin]
    } else {
        f64::INFINITY
    };
    let v_t = svd.v_t.expect("asked for V^T");
    (cond, v_t.row(imin).transpose())
}

/// A distortion coefficient's rank: radial terms by their power, tangential ones below k3.
fn distortion_order(name: &str) -> u32 {
    match name {
        "k1" => 1,
        "k2" => 2,
        "p1" | "p2" => 3,
        "k3" => 4,
        "k4" => 5,
        "k5" => 6,
        "k6" => 7,
        _ => 0,
    }
}

/// The lowest [`distortion_order`] the information criterion may hold (p1, p2, k3 and beyond;
/// k1 and k2 carry a lens's main distortion and are refined whenever the condition number
/// allows).
const MIN_PRUNED_ORDER: u32 = 3;

/// The names of the columns that weigh in `v` (|component| at least a third of the largest),
/// but `except`, largest first.
fn trading(v: &DVector<f64>, names: &[String], except: &[usize]) -> String {
    let big = v.amax();
    let mut w: Vec<(usize, f64)> = (0..v.len())
        .filter(|&k| !except.contains(&k) && v[k].abs() >= big / 3.0)
        .map(|k| (k, v[k].abs()))
        .collect();
    w.sort_by(|a, b| b.1.total_cmp(&a.1));
    let list: Vec<&str> = w.iter().map(|(k, _)| names[*k].as_str()).collect();
    if list.is_empty() {
        "nothing else: no capture moves it".into()
    } else {
        list.join(", ")
    }
}

/// Refines the intrinsics of `camera` jointly with the pose `t_cam_sensor` over the pairs
/// (`points_mm` sensor frame, mm; `pixels_px` observed, px; the inliers of the pose solve).
///
/// # Errors
/// [`RefineError`]: a name that is not a parameter of the model, a named parameter the
/// captures do not constrain, too few observations, none of the intrinsics constrained.
pub fn refine_intrinsics(
    camera: &CameraModel,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    t_cam_sensor: &Isometry3<f64>,
    which: &RefineParameters,
) -> Result<Refinement, RefineError> {
    refine_intrinsics_through(camera, None, points_mm, pixels_px, t_cam_sensor, which)
}

/// [`refine_intrinsics`] with the rays bent by `layers` between the lens and the points
/// ([`crate::refraction`]): the lens model is refined, the optical path held.
///
/// # Errors
/// As [`refine_intrinsics`].
pub fn refine_intrinsics_through(
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    t_cam_sensor: &Isometry3<f64>,
    which: &RefineParameters,
) -> Result<Refinement, RefineError> {
    refine_intrinsics_keeping(
        camera,
        layers,
        points_mm,
        pixels_px,
        t_cam_sensor,
        which,
        &[],
    )
}

/// [`refine_intrinsics_through`] that never leaves a point of `keep` (sensor frame, mm)
/// unprojected: the pins the fit does not use (RANSAC's outliers) that project at the camera
/// file's intrinsics and the starting pose still project at the refined ones (a step that would
/// fold the image back before one of them is refused), so that their residuals can be
/// reported and the pose solved again may take them in (issue 97: refined over the inner
/// rings, the outer ring no longer projected at all).
///
/// # Errors
/// As [`refine_intrinsics`].
pub fn refine_intrinsics_keeping(
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    t_cam_sensor: &Isometry3<f64>,
    which: &RefineParameters,
    keep: &[Vector3<f64>],
) -> Result<Refinement, RefineError> {
    let imaging = Imaging { camera, layers };
    let (r0, t0) = (
        *t_cam_sensor.rotation.to_rotation_matrix().matrix(),
        t_cam_sensor.translation.vector,
    );
    let keep: Vec<Vector3<f64>> = keep
        .iter()
        .filter(|p| imaging.project(&r0, &t0, p).is_some())
        .copied()
        .collect();
    let keep = keep.as_slice();
    let base = *camera.intrinsics();
    let (free, mut held) = chosen_parameters(&base.distortion, which)?;
    let n_obs = 2 * points_mm.len();
    if n_obs <= free.len() + 6 {
        return Err(RefineError::TooFewObservations {
            observations: points_mm.len(),
            parameters: free.len() + 6,
            intrinsics: free.len(),
        });
    }
    let start = State {
        intr: intrinsic_vector(&base),
        r: t_cam_sensor.rotation.to_rotation_matrix(),
        t: t_cam_sensor.translation.vector,
    };
    let mut pb = Problem {
        base,
        free,
        points: points_mm,
        pixels: pixels_px,
        layers,
        keep,
    };
    pb.hold_unconstrained(&start, which, &mut held)?;
    let initial = intrinsic_vector(&base);
    let e0 = pb.residuals(&start).ok_or(RefineError::Unprojectable)?;
    let rms_before_px = pb.rms(&e0);
    let fit = pb.fit_pruning(&start, e0, which, &initial, &mut held)?;
    pb.refinement(fit, &initial, &held, rms_before_px)
}

/// The parameters held at the camera file's value: (index into [`parameter_names`], why).
type Held = Vec<(usize, String)>;

/// The parameters to refine (indices into [`parameter_names`] of `distortion`'s model,
/// ascending) and those held from the start with why: every parameter for
/// [`RefineParameters::Constrained`], else exactly the listed ones.
///
/// # Errors
/// [`RefineError::UnknownParameter`], [`RefineError::Twice`].
fn chosen_parameters(
    distortion: &Distortion,
    which: &RefineParameters,
) -> Result<(Vec<usize>, Held), RefineError> {
    let names = parameter_names(distortion);
    let model = distortion.name();
    let mut held: Held = Vec::new();
    let free: Vec<usize> = match which {
        RefineParameters::Constrained => (0..names.len()).collect(),
        RefineParameters::Only(list) => {
            let value = list.join(",");
            let mut v = Vec::new();
            for n in list {
                let k = names.iter().position(|x| x == n).ok_or_else(|| {
                    RefineError::UnknownParameter {
                        value: value.clone(),
                        name: n.clone(),
                        model,
                        known: names.join(", "),
                    }
                })?;
                if v.contains(&k) {
                    return Err(RefineError::Twice {
                        value: value.clone(),
                        name: n.clone(),
                    });
                }
                v.push(k);
            }
            v.sort_unstable();
            for k in 0..names.len() {
                if !v.contains(&k) {
                    held.push((k, "not in the --refine-intrinsics list".into()));
                }
            }
            v
        }
    };
    Ok((free, held))
}

/// A fit's outcome: the state, its residuals, the iterations taken, the Jacobian there and the
/// covariance of the free parameters and the pose (`None` when singular).
struct Fit {
    s: State,
    e: DVector<f64>,
    iterations: usize,
    j: DMatrix<f64>,
    cov: Option<DMatrix<f64>>,
}

impl Problem<'_> {
    /// RMS reprojection error of the residuals `e` over the points, px.
    fn rms(&self, e: &DVector<f64>) -> f64 {
        (e.norm_squared() / self.points.len() as f64).sqrt()
    }

    /// Holds what the captures do not constrain: while the column-scaled Jacobian at `start`
    /// has a condition number above [`MAX_CONDITION`], the intrinsics weighing most in the
    /// least-determined direction leave `free` for `held`, with why.
    ///
    /// # Errors
    /// [`RefineError::Unprojectable`] at `start`; [`RefineError::Unconstrained`] for a listed
    /// parameter ([`RefineParameters::Only`]); [`RefineError::NothingConstrained`] when
    /// nothing would be left free.
    fn hold_unconstrained(
        &mut self,
        start: &State,
        which: &RefineParameters,
        held: &mut Held,
    ) -> Result<(), RefineError> {
        let names = parameter_names(&self.base.distortion);
        loop {
            let j = self.jacobian(start).ok_or(RefineError::Unprojectable)?;
            let (cond, v) = scaled_condition(&j);
            if cond <= MAX_CONDITION {
                return Ok(());
            }
            let free = &self.free;
            let col_names: Vec<String> = free
                .iter()
                .map(|&k| names[k].to_string())
                .chain(POSE_NAMES.iter().map(|s| s.to_string()))
                .collect();
            // the intrinsic that weighs most in the least-determined direction
            let Some(c) = (0..free.len()).max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs())) else {
                return Err(RefineError::NothingConstrained {
                    first: String::new(),
                    condition: cond,
                });
            };
            if let RefineParameters::Only(list) = which {
                let with = trading(&v, &col_names, &[c]);
                return Err(RefineError::Unconstrained {
                    value: list.join(","),
                    name: names[free[c]].into(),
                    with,
                    condition: cond,
                    limit: MAX_CONDITION,
                });
            }
            // what to hold, of the intrinsics weighing in that direction (at least a third of
            // the largest): the focal length as a whole (fx and fy trade together against the
            // camera's distance), else the highest-order distortion coefficient, else the
            // principal point's coordinate that weighs most
            let weighing: Vec<usize> = (0..free.len())
                .filter(|&k| v[k].abs() >= v[c].abs() / 3.0)
                .collect();
            let is_focal = |k: &usize| matches!(names[free[*k]], "fx" | "fy");
            let hold: Vec<usize> = if weighing.iter().any(is_focal) {
                (0..free.len()).filter(is_focal).collect()
            } else if let Some(k) = weighing
                .iter()
                .filter(|&&k| free[k] >= 4)
                .max_by_key(|&&k| distortion_order(names[free[k]]))
            {
                vec![*k]
            } else {
                vec![c]
            };
            if hold.len() >= free.len() {
                return Err(RefineError::NothingConstrained {
                    first: names[free[c]].into(),
                    condition: cond,
                });
            }
            let what = if hold.len() == 2 {
                "the focal length (fx and fy together)".to_string()
            } else {
                names[free[hold[0]]].to_string()
            };
            let with = trading(&v, &col_names, &hold);
            for &k in &hold {
                held.push((
                    free[k],
                    format!(
                        "the captures do not constrain {what}; it trades against {with} (condition number {cond:.1e} with it free, above {MAX_CONDITION:.0e})"
                    ),
                ));
            }
            self.free = (0..free.len())
                .filter(|k| !hold.contains(k))
                .map(|k| free[k])
                .collect();
        }
    }

    /// Fits from `start` (residuals `e0`); then, from the highest order down, holds the
    /// distortion coefficient the fit does not need (the Bayesian information criterion:
    /// its move from `initial` lowers the squared error by less than ln N sigma^2), notes it
    /// in `held` and fits again, until the last free one is worth its place.
    ///
    /// # Errors
    /// [`RefineError::Unprojectable`] at a fitted state.
    fn fit_pruning(
        &mut self,
        start: &State,
        e0: DVector<f64>,
        which: &RefineParameters,
        initial: &[f64],
        held: &mut Held,
    ) -> Result<Fit, RefineError> {
        let names = parameter_names(&self.base.distortion);
        let n_obs = 2 * self.points.len();
        loop {
            let (s, e, iterations) = levenberg_marquardt(self, start, e0.clone());
            let j = self.jacobian(&s).ok_or(RefineError::Unprojectable)?;
            let dof = (n_obs - self.n_params()) as f64;
            let sigma2 = e.norm_squared() / dof;
            let cov = (j.transpose() * &j).try_inverse().map(|c| c * sigma2);
            // the highest-order free distortion coefficient, and whether the fit needs it
            let last = self
                .free
                .iter()
                .enumerate()
                .filter(|(_, &k)| k >= 4 && distortion_order(names[k]) >= MIN_PRUNED_ORDER)
                .max_by_key(|(_, &k)| (distortion_order(names[k]), k))
                .map(|(col, &k)| (col, k));
            let undetermined = match (which, &cov, last) {
                (RefineParameters::Constrained, Some(c), Some((col, k))) => {
                    let var = c[(col, col)].max(0.0);
                    // dropping it raises the squared error by about t^2 sigma^2
                    let t2 = (s.intr[k] - initial[k]).powi(2) / var.max(1e-300);
                    (t2 < (n_obs as f64).ln()).then_some((col, k, var.sqrt(), t2))
                }
                _ => None,
            };
            let Some((col, k, sd, t2)) = undetermined else {
                return Ok(Fit {
                    s,
                    e,
                    iterations,
                    j,
                    cov,
                });
            };
            held.push((
                k,
                format!(
                    "the captures do not determine {}: refined, it moves {:.4} +- {sd:.4} from the camera file's value, which lowers the squared reprojection error by {t2:.2} sigma^2, less than ln {n_obs} = {:.2} for a parameter (the Bayesian information criterion)",
                    names[k],
                    s.intr[k] - initial[k],
                    (n_obs as f64).ln()
                ),
            ));
            self.free.remove(col);
        }
    }

    /// The [`Refinement`] of `fit`: each parameter's value, standard deviation or why it was
    /// `held`, the pose and its standard deviations, the condition number at the solution and
    /// the RMS before (`rms_before_px`) and after.
    ///
    /// # Errors
    /// [`RefineError::Unprojectable`] when the refined intrinsics are not a camera.
    fn refinement(
        &self,
        fit: Fit,
        initial: &[f64],
        held: &[(usize, String)],
        rms_before_px: f64,
    ) -> Result<Refinement, RefineError> {
        let Fit {
            s,
            e,
            iterations,
            j,
            cov,
        } = fit;
        let (base, free) = (&self.base, &self.free);
        let names = parameter_names(&base.distortion);
        let condition_number = scaled_condition(&j).0;
        let parameters = names
            .iter()
            .enumerate()
            .map(|(k, n)| {
                let col = free.iter().position(|&f| f == k);
                RefinedParameter {
                    name: (*n).into(),
                    initial: initial[k],
                    value: s.intr[k],
                    std: col.and_then(|c| cov.as_ref().map(|m| m[(c, c)].max(0.0).sqrt())),
                    held: held.iter().find(|(h, _)| *h == k).map(|(_, r)| r.clone()),
                }
            })
            .collect();
        let m = free.len();
        let pose_std = cov.as_ref().map(|c| {
            let sd = |k: usize| c[(k, k)].max(0.0).sqrt();
            (
                std::array::from_fn(|i| sd(m + i).to_degrees()),
                std::array::from_fn(|i| sd(m + 3 + i)),
            )
        });
        let camera =
            CameraModel::new(with_vector(base, &s.intr)).map_err(|_| RefineError::Unprojectable)?;
        Ok(Refinement {
            camera,
            t_cam_sensor: Isometry3::from_parts(
                Translation3::from(s.t),
                UnitQuaternion::from_rotation_matrix(&s.r),
            ),
            parameters,
            condition_number,
            rms_before_px,
            rms_after_px: self.rms(&e),
            iterations,
            pose_std,
        })
    }
}

/// Levenberg-Marquardt from `start` (residuals `e0`), Marquardt's scaling by the diagonal: the
/// state, its residuals and the iterations taken (at most 100; until a step gains less than
/// 1e-14 of the cost).
fn levenberg_marquardt(
    pb: &Problem<'_>,
    start: &State,
    e0: DVector<f64>,
) -> (State, DVector<f64>, usize) {
    let (mut s, mut e, mut lambda) = (start.clone(), e0, 1e-3);
    let mut iterations = 0;
    for _ in 0..100 {
        iterations += 1;
        let Some(j) = pb.jacobian(&s) else { break };
        let a = j.transpose() * &j;
        let g = j.transpose() * &e;
        let cost = e.norm_squared();
        let mut improved = false;
        while lambda < 1e12 {
            let mut m = a.clone();
            for k in 0..m.nrows() {
                m[(k, k)] += lambda * a[(k, k)].max(1e-12);
            }
            let Some(d) = m.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let cand = pb.step(&s, d.as_slice());
            match pb.residuals(&cand) {
                Some(ec) if ec.norm_squared() < cost && pb.keeps(&cand) => {
                    let gain = cost - ec.norm_squared();
                    s = cand;
                    e = ec;
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = gain > 1e-14 * cost.max(1e-300);
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved {
            break;
        }
    }
    (s, e, iterations)
}

/// The refinement as `extrinsics.json` reports it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RefinementReport {
    /// What the numbers mean.
    pub description: String,
    /// The refined camera file in the output folder, in the form the camera file was read.
    pub camera_file: String,
    /// fx, fy, cx, cy (px) and the distortion coefficients, each with the camera file's value,
    /// the refined one and its standard deviation, or why it was held.
    pub parameters: Vec<RefinedParameter>,
    /// Condition number of the column-scaled Jacobian over the pose and the refined parameters.
    pub condition_number: f64,
    /// RMS reprojection error over the inliers with the camera file's intrinsics (at the pose
    /// solved with them) and after the refinement, px.
    pub rms_before_px: f64,
    pub rms_after_px: f64,
}

impl RefinementReport {
    pub fn new(r: &Refinement, camera_file: &str) -> RefinementReport {
        RefinementReport {
            description: format!("Intrinsics refined jointly with the pose by Levenberg-Marquardt on the reprojection error; standard deviations from the covariance sigma^2 (J^T J)^-1 at the solution, sigma^2 the residual variance. A parameter the captures do not constrain (the column-scaled Jacobian's condition number above {MAX_CONDITION:.0e} with it free), or a distortion coefficient beyond k1 and k2 they do not determine (from the highest order down, one whose move lowers the squared reprojection error by less than ln N sigma^2, N the observations: the Bayesian information criterion), is held at the camera file's value, and says why."),
            camera_file: camera_file.into(),
            parameters: r.parameters.clone(),
            condition_number: r.condition_number,
            rms_before_px: r.rms_before_px,
            rms_after_px: r.rms_after_px,
        }
    }
}

/// The name and form of the refined camera file, from the camera file's text: fabkit JSON
/// (`camera_refined.json`), OpenCV FileStorage XML (`camera_refined.xml`), OpenCV FileStorage
/// YAML or ROS `camera_info` YAML (`camera_refined.yaml`).
pub fn refined_camera_file(text: &str) -> (&'static str, crate::CameraFileFormat) {
    use crate::CameraFileFormat as F;
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with('{') {
        ("camera_refined.json", F::Json)
    } else if t.starts_with('<') {
        ("camera_refined.xml", F::OpenCvXml)
    } else if t.starts_with("%YAML") || t.contains("opencv-matrix") {
        ("camera_refined.yaml", F::OpenCvYaml)
    } else {
        ("camera_refined.yaml", F::RosYaml)
    }
}

/// The pose solution `sol` re-evaluated at `camera` and `t_cam_sensor` (same inliers): the
/// residuals of every pair and the inliers' RMS.
pub fn solution_at(
    camera: &Imaging<'_>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    sol: &PnpSolution,
    t_cam_sensor: Isometry3<f64>,
) -> PnpSolution {
    let r = *t_cam_sensor.rotation.to_rotation_matrix().matrix();
    let t = t_cam_sensor.translation.vector;
    let residuals_px: Vec<Option<Vector2<f64>>> = points_mm
        .iter()
        .zip(pixels_px)
        .map(|(p, px)| camera.project(&r, &t, p).map(|uv| uv - px))
        .collect();
    let (mut sq, mut n) = (0.0, 0usize);
    for (r, &inl) in residuals_px.iter().zip(&sol.inliers) {
        if let (Some(r), true) = (r, inl) {
            sq += r.norm_squared();
            n += 1;
        }
    }
    PnpSolution {
        t_cam_sensor,
        inliers: sol.inliers.clone(),
        residuals_px,
        rms_reprojection_error_px: (sq / n.max(1) as f64).sqrt(),
        hypotheses: sol.hypotheses,
        ransac_threshold_px: sol.ransac_threshold_px,
    }
}
