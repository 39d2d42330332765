//! Camera models: Kannala-Brandt fisheye (OpenCV `cv::fisheye`), OpenCV pinhole with
//! radial-tangential distortion (`plumb_bob`, 5 coefficients) and its rational 8-coefficient form
//! (`rational_polynomial`).
//!
//! Conventions (`docs/conventions.md`, "Camera and image conventions"): pixel (0, 0) is the centre
//! of the top-left pixel; camera frame x right, y down, z forward; points in mm, pixels in px.
//! Projection agrees with `cv2.fisheye.projectPoints` / `cv2.projectPoints` to 1e-6 px over the
//! field of view (checked against opencv-python-headless in `tests/e2e/calibrate_opencv.rs`).
//!
//! Source: R-Tac0 paper (`shared/papers/rtac0-rounded-monochrome-vbts.txt`), Sec. IV-A, Eq. (1):
//! `(u, v) = M D [R | T] (x, y, z)`; `M` is the camera matrix (fx, fy, cx, cy), `D` the distortion.

use nalgebra::{Matrix2, Matrix2x3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// The lens distortion model and its coefficients, in OpenCV's order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", content = "coefficients", rename_all = "snake_case")]
pub enum Distortion {
    /// Kannala-Brandt / OpenCV fisheye: `theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6
    /// + k4 theta^8)`, `theta` the angle off the optical axis. `[k1, k2, k3, k4]`.
    /// ROS name `equidistant`; OpenCV FileStorage name `fisheye`.
    Fisheye([f64; 4]),
    /// Pinhole with radial-tangential distortion, `[k1, k2, p1, p2, k3]` (ROS `plumb_bob`).
    PlumbBob([f64; 5]),
    /// Pinhole with the rational radial model, `[k1, k2, p1, p2, k3, k4, k5, k6]`
    /// (ROS `rational_polynomial`).
    RationalPolynomial([f64; 8]),
}

impl Distortion {
    /// The model's name as written in camera files (`fisheye`, `plumb_bob`, `rational_polynomial`).
    pub fn name(&self) -> &'static str {
        match self {
            Distortion::Fisheye(_) => "fisheye",
            Distortion::PlumbBob(_) => "plumb_bob",
            Distortion::RationalPolynomial(_) => "rational_polynomial",
        }
    }

    /// The coefficients in OpenCV's order.
    pub fn coefficients(&self) -> &[f64] {
        match self {
            Distortion::Fisheye(k) => k,
            Distortion::PlumbBob(k) => k,
            Distortion::RationalPolynomial(k) => k,
        }
    }

    /// Builds a model from its name (OpenCV or ROS spelling) and coefficients.
    ///
    /// # Errors
    /// An unknown name, or a coefficient count that the model does not take (`plumb_bob` takes 4
    /// or 5, `fisheye` 4, `rational_polynomial` 8), as a message naming the rule.
    pub fn from_name(name: &str, k: &[f64]) -> Result<Distortion, String> {
        match name {
            "fisheye" | "equidistant" | "kannala_brandt" => match k.len() {
                4 => Ok(Distortion::Fisheye([k[0], k[1], k[2], k[3]])),
                n => Err(format!("{n} coefficients: model '{name}' takes 4 (k1, k2, k3, k4)")),
            },
            "plumb_bob" | "radtan" => match k.len() {
                4 => Ok(Distortion::PlumbBob([k[0], k[1], k[2], k[3], 0.0])),
                5 => Ok(Distortion::PlumbBob([k[0], k[1], k[2], k[3], k[4]])),
                n => Err(format!(
                    "{n} coefficients: model '{name}' takes 5 (k1, k2, p1, p2, k3) or 4 (k3 = 0)"
                )),
            },
            "rational_polynomial" => match k.len() {
                8 => {
                    let mut a = [0.0; 8];
                    a.copy_from_slice(k);
                    Ok(Distortion::RationalPolynomial(a))
                }
                n => Err(format!(
                    "{n} coefficients: model '{name}' takes 8 (k1, k2, p1, p2, k3, k4, k5, k6)"
                )),
            },
            other => Err(format!(
                "unknown distortion model '{other}': must be fisheye (or equidistant), plumb_bob or rational_polynomial"
            )),
        }
    }
}

/// Camera intrinsics: camera matrix, image size and distortion. Plain data; build a
/// [`CameraModel`] from it to project and unproject.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    /// Image width, px.
    pub image_width_px: u32,
    /// Image height, px.
    pub image_height_px: u32,
    /// Focal lengths, px.
    pub fx_px: f64,
    pub fy_px: f64,
    /// Principal point, px (pixel (0, 0) is the centre of the top-left pixel).
    pub cx_px: f64,
    pub cy_px: f64,
    pub distortion: Distortion,
}

/// Why intrinsics are not a usable camera.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error("{field} = {value}: {rule}")]
    Invalid {
        field: &'static str,
        value: String,
        rule: &'static str,
    },
    #[error("pixel ({u_px}, {v_px}): {reason}")]
    Unprojectable {
        u_px: f64,
        v_px: f64,
        reason: &'static str,
    },
}

/// A validated camera model: projection of camera-frame points (mm) to pixels and unprojection
/// of pixels to unit bearing vectors, with the projection Jacobian.
///
/// The fisheye model projects with `theta = atan2(|xy|, z)`, so rays at and beyond 90 deg off
/// axis project (up to the angle where `theta_d(theta)` stops increasing); it never goes through
/// the z = 1 plane. The pinhole models need `z > 0` and stay within the radius where the radial
/// distortion is monotonic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraModel {
    intr: Intrinsics,
    /// Fisheye: largest valid theta, rad. Pinhole: largest valid normalised radius squared.
    limit: f64,
}

/// Largest fisheye angle considered, rad (a little beyond 180 deg full field).
const FISHEYE_MAX_THETA: f64 = std::f64::consts::PI * 0.999;
/// Largest normalised pinhole radius considered (about 84 deg off axis).
const PINHOLE_MAX_RADIUS: f64 = 10.0;

/// Largest image width or height a camera model accepts, px (16384: beyond any camera a
/// tactile sensor carries; every per-pixel array is sized by it).
pub const MAX_IMAGE_SIDE_PX: u32 = 16384;
/// Smallest focal length a camera model accepts, px: below it the whole field of view falls
/// on a few pixels.
pub const MIN_FOCAL_PX: f64 = 1.0;
/// Largest focal length a camera model accepts, px: a 16384 px image then spans under 1 deg.
pub const MAX_FOCAL_PX: f64 = 1e6;

impl CameraModel {
    /// Validates the intrinsics (focal lengths from [`MIN_FOCAL_PX`] to [`MAX_FOCAL_PX`], image
    /// sides from 1 to [`MAX_IMAGE_SIDE_PX`], the principal point within the image or at most
    /// one image width or height outside it, no NaN coefficients) and finds the monotonic range
    /// of the distortion.
    ///
    /// # Errors
    /// [`CameraError::Invalid`] naming the field, its value and the rule.
    pub fn new(intr: Intrinsics) -> Result<CameraModel, CameraError> {
        let bad = |field, value: f64, rule| CameraError::Invalid {
            field,
            value: crate::shown_f64(value),
            rule,
        };
        for (field, v) in [("fx_px", intr.fx_px), ("fy_px", intr.fy_px)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, v, "must be finite and > 0"));
            }
            if !(MIN_FOCAL_PX..=MAX_FOCAL_PX).contains(&v) {
                return Err(bad(
                    field,
                    v,
                    "must be from 1 to 1e6 px (a lens maps about one radian onto that many pixels)",
                ));
            }
        }
        for (field, v) in [("cx_px", intr.cx_px), ("cy_px", intr.cy_px)] {
            if !v.is_finite() {
                return Err(bad(field, v, "must be finite"));
            }
        }
        for (field, v) in [
            ("image_width", intr.image_width_px),
            ("image_height", intr.image_height_px),
        ] {
            if !(1..=MAX_IMAGE_SIDE_PX).contains(&v) {
                return Err(bad(field, f64::from(v), "must be from 1 to 16384 px"));
            }
        }
        for (field, v, side) in [
            ("cx_px", intr.cx_px, intr.image_width_px),
            ("cy_px", intr.cy_px, intr.image_height_px),
        ] {
            let side = f64::from(side);
            if !(-side..=2.0 * side).contains(&v) {
                return Err(bad(
                    field,
                    v,
                    "the principal point must lie within the image or at most one image width (cx) or height (cy) outside it",
                ));
            }
        }
        if let Some(v) = intr
            .distortion
            .coefficients()
            .iter()
            .find(|v| !v.is_finite())
        {
            return Err(bad("distortion_coefficients", *v, "must be finite"));
        }
        let limit = match intr.distortion {
            Distortion::Fisheye(k) => {
                // First theta where d theta_d / d theta <= 0 (scan, then bisect).
                let d = |t: f64| kb_theta_d(&k, t).1;
                first_non_positive(d, FISHEYE_MAX_THETA)
            }
            _ => {
                // Radial-only monotonicity of r * radial(r) along the x axis, then squared.
                let d = |r: f64| {
                    let h = 1e-6;
                    let f = |r: f64| r * radial(&intr.distortion, r * r);
                    (f(r + h) - f(r - h)) / (2.0 * h)
                };
                let r = first_non_positive(d, PINHOLE_MAX_RADIUS);
                r * r
            }
        };
        if limit <= 1e-3 {
            return Err(CameraError::Invalid {
                field: "distortion_coefficients",
                value: format!("{:?}", intr.distortion.coefficients()),
                rule: "the distortion must be monotonic near the optical axis",
            });
        }
        Ok(CameraModel { intr, limit })
    }

    pub fn intrinsics(&self) -> &Intrinsics {
        &self.intr
    }

    /// Largest angle off the optical axis that projects, degrees.
    pub fn max_field_angle_deg(&self) -> f64 {
        match self.intr.distortion {
            Distortion::Fisheye(_) => self.limit.to_degrees(),
            _ => self.limit.sqrt().atan().to_degrees(),
        }
    }

    /// Projects a camera-frame point `p` (mm, any scale) to pixels. `None` if the point is on the
    /// optical centre, outside the model's valid field (fisheye: theta beyond the monotonic range;
    /// pinhole: z <= 0 or beyond the monotonic radius).
    #[inline]
    pub fn project(&self, p: &Vector3<f64>) -> Option<Vector2<f64>> {
        self.project_impl(p, false).map(|(uv, _)| uv)
    }

    /// [`project`](Self::project) and its 2 x 3 Jacobian d(u, v)/d(x, y, z), px per mm.
    #[inline]
    pub fn project_with_jacobian(
        &self,
        p: &Vector3<f64>,
    ) -> Option<(Vector2<f64>, Matrix2x3<f64>)> {
        self.project_impl(p, true)
    }

    #[inline]
    fn project_impl(&self, p: &Vector3<f64>, jac: bool) -> Option<(Vector2<f64>, Matrix2x3<f64>)> {
        let (x, y, z) = (p.x, p.y, p.z);
        let i = &self.intr;
        let (xd, yd, jd) = match &i.distortion {
            Distortion::Fisheye(k) => {
                let rho2 = x * x + y * y;
                let rho = rho2.sqrt();
                let n2 = rho2 + z * z;
                if !(n2 > 0.0) || !n2.is_finite() {
                    return None;
                }
                let theta = atan2_nonneg(rho, z);
                if theta > self.limit {
                    return None;
                }
                let (td, dtd) = kb_theta_d(k, theta);
                if rho < 1e-9 * n2.sqrt() {
                    // On the axis: theta_d / rho -> 1 / z, distortion vanishes to second order.
                    if z <= 0.0 {
                        return None;
                    }
                    let jd = Matrix2x3::new(1.0 / z, 0.0, -x / (z * z), 0.0, 1.0 / z, -y / (z * z));
                    (x / z, y / z, jd)
                } else {
                    let s = td / rho;
                    let mut jd = Matrix2x3::zeros();
                    if jac {
                        // s = theta_d(theta) / rho; ds/dx = x g, ds/dz = -theta_d' / n2.
                        let g = (dtd * z / n2 - s) / rho2;
                        let dsdz = -dtd / n2;
                        jd = Matrix2x3::new(
                            s + x * x * g,
                            x * y * g,
                            x * dsdz,
                            x * y * g,
                            s + y * y * g,
                            y * dsdz,
                        );
                    }
                    (s * x, s * y, jd)
                }
            }
            dist => {
                if !(z > 0.0) {
                    return None;
                }
                let (a, b) = (x / z, y / z);
                let r2 = a * a + b * b;
                if r2 > self.limit {
                    return None;
                }
                let (xd, yd, j2) = pinhole_distort(dist, a, b, jac);
                let mut jd = Matrix2x3::zeros();
                if jac {
                    let dn = Matrix2x3::new(1.0 / z, 0.0, -a / z, 0.0, 1.0 / z, -b / z);
                    jd = j2 * dn;
                }
                (xd, yd, jd)
            }
        };
        let uv = Vector2::new(i.fx_px * xd + i.cx_px, i.fy_px * yd + i.cy_px);
        if !(uv.x.is_finite() && uv.y.is_finite()) {
            return None;
        }
        let mut j = jd;
        if jac {
            j.row_mut(0).scale_mut(i.fx_px);
            j.row_mut(1).scale_mut(i.fy_px);
        }
        Some((uv, j))
    }

    /// Unprojects a pixel to the unit bearing vector of its ray in the camera frame.
    ///
    /// Fisheye: Newton iteration on theta (rays at and beyond 90 deg off axis are returned with
    /// z <= 0). Pinhole: Newton iteration on the normalised coordinates.
    ///
    /// # Errors
    /// [`CameraError::Unprojectable`] for a non-finite pixel, one beyond the model's valid field,
    /// or when the iteration does not converge.
    pub fn unproject(&self, uv: &Vector2<f64>) -> Result<Vector3<f64>, CameraError> {
        let err = |reason| CameraError::Unprojectable {
            u_px: uv.x,
            v_px: uv.y,
            reason,
        };
        if !(uv.x.is_finite() && uv.y.is_finite()) {
            return Err(err("not finite"));
        }
        let i = &self.intr;
        let xd = (uv.x - i.cx_px) / i.fx_px;
        let yd = (uv.y - i.cy_px) / i.fy_px;
        match &i.distortion {
            Distortion::Fisheye(k) => {
                let td = (xd * xd + yd * yd).sqrt();
                if td < 1e-15 {
                    return Ok(Vector3::new(0.0, 0.0, 1.0));
                }
                let td_max = kb_theta_d(k, self.limit).0;
                if td > td_max {
                    return Err(err(
                        "outside the lens's field (beyond the monotonic range of theta_d)",
                    ));
                }
                let mut theta = td.min(self.limit);
                let mut ok = false;
                for _ in 0..30 {
                    let (f, df) = kb_theta_d(k, theta);
                    let step = (f - td) / df;
                    theta = (theta - step).clamp(0.0, self.limit);
                    if step.abs() < 1e-15 {
                        ok = true;
                        break;
                    }
                }
                if !ok && (kb_theta_d(k, theta).0 - td).abs() > 1e-12 {
                    return Err(err("fisheye unprojection did not converge"));
                }
                let s = theta.sin() / td;
                Ok(Vector3::new(xd * s, yd * s, theta.cos()))
            }
            dist => {
                let mut a = Vector2::new(xd, yd);
                // Start from the radial-only inverse guess.
                let mut ok = false;
                for _ in 0..40 {
                    let (fx, fy, j) = pinhole_distort(dist, a.x, a.y, true);
                    let r = Vector2::new(fx - xd, fy - yd);
                    if r.norm() < 1e-15 {
                        ok = true;
                        break;
                    }
                    let Some(ji) = j.try_inverse() else { break };
                    let mut step = ji * r;
                    // Damp steps that would leave the monotonic region.
                    while (a - step).norm_squared() > self.limit && step.norm() > 1e-12 {
                        step *= 0.5;
                    }
                    a -= step;
                    if step.norm() < 1e-15 {
                        ok = true;
                        break;
                    }
                }
                let (fx, fy, _) = pinhole_distort(dist, a.x, a.y, false);
                if !ok && ((fx - xd).hypot(fy - yd) > 1e-10) {
                    return Err(err("pinhole undistortion did not converge"));
                }
                if a.norm_squared() > self.limit {
                    return Err(err("outside the monotonic range of the distortion"));
                }
                Ok(Vector3::new(a.x, a.y, 1.0).normalize())
            }
        }
    }
}

/// `atan2(y, x)` for `y >= 0` (so the result is in [0, pi]), to about 2 ulp: Cephes' rational
/// approximation of atan with its three-interval reduction (S. L. Moshier, Cephes Math Library,
/// atan.c). About twice as fast as the C library's correctly rounded atan2, which dominated
/// projection time in the PnP solver.
#[inline]
pub(crate) fn atan2_nonneg(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    if x > 0.0 {
        atan_nonneg(y / x)
    } else if y > 0.0 {
        FRAC_PI_2 + atan_nonneg(-x / y)
    } else if x < 0.0 {
        PI
    } else {
        0.0
    }
}

/// `atan(x)` for `x >= 0` (Cephes atan.c).
#[inline]
fn atan_nonneg(x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
    // tan(3 pi / 8) and the low bits of pi / 2.
    const T3P8: f64 = 2.414_213_562_373_095;
    const MOREBITS: f64 = 6.123_233_995_736_766e-17;
    let (y0, xr, extra) = if x > T3P8 {
        (FRAC_PI_2, -1.0 / x, MOREBITS)
    } else if x > 0.66 {
        (FRAC_PI_4, (x - 1.0) / (x + 1.0), 0.5 * MOREBITS)
    } else {
        (0.0, x, 0.0)
    };
    let z = xr * xr;
    let p = (((-8.750_608_600_031_904e-1 * z - 1.615_753_718_733_365e1) * z
        - 7.500_855_792_314_705e1)
        * z
        - 1.228_866_684_490_136e2)
        * z
        - 6.485_021_904_942_025e1;
    let q = ((((z + 2.485_846_490_142_306e1) * z + 1.650_270_098_316_988e2) * z
        + 4.328_810_604_912_902e2)
        * z
        + 4.853_903_996_359_137e2)
        * z
        + 1.945_506_571_482_614e2;
    y0 + (xr * z * p / q + xr) + extra
}

/// Kannala-Brandt `theta_d(theta)` and its derivative.
#[inline]
fn kb_theta_d(k: &[f64; 4], t: f64) -> (f64, f64) {
    let t2 = t * t;
    let poly = 1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
    let dpoly = 1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
    (t * poly, dpoly)
}

/// Radial factor of the pinhole models at squared normalised radius `r2`.
#[inline]
fn radial(d: &Distortion, r2: f64) -> f64 {
    match d {
        Distortion::PlumbBob(k) => 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4])),
        Distortion::RationalPolynomial(k) => {
            (1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4])))
                / (1.0 + r2 * (k[5] + r2 * (k[6] + r2 * k[7])))
        }
        Distortion::Fisheye(_) => 1.0,
    }
}

/// OpenCV pinhole distortion of normalised coordinates `(a, b)` and its 2 x 2 Jacobian.
#[inline]
fn pinhole_distort(d: &Distortion, a: f64, b: f64, jac: bool) -> (f64, f64, Matrix2<f64>) {
    let (k1, k2, p1, p2, k3, k4, k5, k6) = match *d {
        Distortion::PlumbBob(k) => (k[0], k[1], k[2], k[3], k[4], 0.0, 0.0, 0.0),
        Distortion::RationalPolynomial(k) => (k[0], k[1], k[2], k[3], k[4], k[5], k[6], k[7]),
        Distortion::Fisheye(_) => (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };
    let r2 = a * a + b * b;
    let num = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    let den = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
    let rad = num / den;
    let xd = a * rad + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a);
    let yd = b * rad + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b;
    let mut j = Matrix2::zeros();
    if jac {
        let dnum = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3);
        let dden = k4 + r2 * (2.0 * k5 + r2 * 3.0 * k6);
        let drad = (dnum * den - num * dden) / (den * den); // d rad / d r2
        j[(0, 0)] = rad + a * drad * 2.0 * a + 2.0 * p1 * b + 6.0 * p2 * a;
        j[(0, 1)] = a * drad * 2.0 * b + 2.0 * p1 * a + 2.0 * p2 * b;
        j[(1, 0)] = b * drad * 2.0 * a + 2.0 * p1 * a + 2.0 * p2 * b;
        j[(1, 1)] = rad + b * drad * 2.0 * b + 6.0 * p1 * b + 2.0 * p2 * a;
    }
    (xd, yd, j)
}

/// The first x in (0, max] where `d(x) <= 0`, or `max`.
fn first_non_positive(d: impl Fn(f64) -> f64, max: f64) -> f64 {
    let n = 2000;
    let mut prev = 0.0;
    for s in 1..=n {
        let x = max * s as f64 / n as f64;
        if !(d(x) > 0.0) {
            let (mut lo, mut hi) = (prev, x);
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if d(m) > 0.0 {
                    lo = m
                } else {
                    hi = m
                }
            }
            return lo;
        }
        prev = x;
    }
    max
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kb() -> CameraModel {
        CameraModel::new(Intrinsics {
            image_width_px: 640,
            image_height_px: 480,
            fx_px: 215.0,
            fy_px: 214.0,
            cx_px: 320.5,
            cy_px: 239.5,
            distortion: Distortion::Fisheye([0.02, -0.01, 0.003, -0.0005]),
        })
        .unwrap()
    }

    #[test]
    fn fisheye_round_trips_rays_beyond_90_deg() {
        let c = kb();
        for deg in [0.0, 10.0, 45.0, 89.0, 90.0, 95.0, 100.0] {
            let t = f64::to_radians(deg);
            let p = Vector3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos());
            let uv = c.project(&p).unwrap();
            let b = c.unproject(&uv).unwrap();
            assert!((b - p.normalize()).norm() < 1e-12, "{deg}: {b:?} vs {p:?}");
        }
    }
}

#[cfg(test)]
mod atan_tests {
    use super::atan2_nonneg;

    /// Against the C library over the whole half plane y >= 0, including the reduction
    /// boundaries and the axes.
    #[test]
    fn atan2_nonneg_matches_libm() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let a = std::f64::consts::PI * i as f64 / 200_000.0;
            for r in [1e-9, 0.37, 1.0, 15.0, 3e7] {
                let (y, x) = (r * a.sin().max(0.0), r * a.cos());
                let want = y.atan2(x);
                let got = atan2_nonneg(y, x);
                worst = worst.max((got - want).abs() / want.abs().max(1e-300));
            }
        }
        for (y, x) in [
            (0.0, 1.0),
            (0.0, -1.0),
            (1.0, 0.0),
            (0.0, 0.0),
            (2.414_213_562_373_095, 1.0),
            (0.66, 1.0),
        ] {
            let want = f64::atan2(y, x);
            assert!(
                (atan2_nonneg(y, x) - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
                "{y} {x}"
            );
        }
        assert!(worst < 5e-16, "worst relative error {worst:e}");
    }
}
