//! A sphere pressed into a flat skin, found in one capture against its reference through the
//! camera a board press calibrated ([`crate::board`]): where the sphere's centre is over the
//! skin's plane and how deep it presses, with their standard deviations.
//!
//! The method, and why not the edge. Where the sphere touches the skin, the skin takes the
//! sphere's shape: the indentation depth at distance `r` from the axis is
//! `d0 - (R - sqrt(R^2 - r^2))`, `d0 - r^2 / (2R)` to within `r^4 / (8 R^3)` (0.4 % of the
//! drop at r = R / 4). A flat sensor such as 9DTact darkens with depth (the authors' grey-to-
//! depth table, `Pixel_to_Depth.npy`, is monotonic), so that near the axis the darkening is a
//! paraboloid in the plane's coordinates: `D(x) = A - B |x - c|^2`. Its apex `c` is the
//! sphere's centre over the plane; its curvature is the response's gain `g` (grey levels per
//! mm of depth) times `1 / (2R)`, so that `g = 2 R B` and the depth at the centre
//! `d0 = A / g = A / (2 R B)`: the sphere's known radius calibrates the gain from the same
//! capture. A Gaussian blur (the out-of-focus lens) adds a constant to a paraboloid
//! (`2 B sigma^2`) and keeps its curvature, so the blur moves `d0` by `sigma^2 / R` only (0.006
//! mm for sigma = 0.15 mm). Only pixels well inside the contact are fitted (where the fitted
//! dome is above [`PressOptions::core_fraction`] of its apex: for a response linear in depth,
//! `r^2 <= 2 R d0 (1 - f)`, inside the contact radius of a half-space, `sqrt(R d0)` (Hertz),
//! for `f >= 0.5`),
//! so that where the contact ends does not enter: the edge of the dark disc is not the contact
//! boundary (an elastic skin meets a sphere over a smaller radius than the geometric
//! intersection, by about sqrt(2) for a half-space, Johnson, Contact Mechanics, 1985, Sec.
//! 4.2), and its image is blurred besides.
//!
//! What it assumes: the response is linear in depth over the fitted core (the gain there is
//! the local one; a response that grows less steeply at small depths, as 9DTact's table does,
//! makes `A / g` short of the depth), and the darkening has no other cause there (no shading
//! by the surface's slope: the core's slopes are under `r / R`).

use crate::board::pixel_on_plane as on_plane;
use crate::camera::CameraModel;
use crate::imprints::{gaussian_blur, GrayImage};
use nalgebra::{Isometry3, Matrix4, Vector2, Vector4};
use serde::Serialize;

/// Why a press cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PressError {
    #[error("the capture is {0} x {1} px but the reference {2} x {3} px; they must match")]
    Size(usize, usize, usize, usize),
    #[error("no contact: the capture darkens the reference by at most {peak:.2} grey levels, under {need:.2} ({sigmas} noise sigmas)")]
    NoContact { peak: f64, need: f64, sigmas: f64 },
    #[error("{0} pixels of the contact's core map onto the plane: at least 12 are needed")]
    TooFewPixels(usize),
    #[error("the darkening is not a dome about its peak (curvature {0:.4} grey levels per mm^2): not a sphere's press")]
    NotADome(f64),
}

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressOptions {
    /// The sphere's radius, mm.
    pub radius_mm: f64,
    /// The difference is smoothed over this, px, before the peak is sought and the core taken.
    pub smooth_sigma_px: f64,
    /// The core fitted: the pixels where the fitted dome is above this fraction of its apex
    /// (first: where the smoothed darkening is above it of its peak). The fit takes the
    /// unsmoothed difference, whose pixels' noise is independent, so that the reported
    /// standard deviations hold.
    pub core_fraction: f64,
    /// A press darkens its peak by at least this many noise sigmas.
    pub min_sigmas: f64,
}

impl PressOptions {
    /// For a sphere of `radius_mm`: smoothing 1.5 px, the core above 0.6 of the peak (for a
    /// half-space, 0.89 of the contact radius), at least 8 noise sigmas.
    pub fn sphere(radius_mm: f64) -> Self {
        PressOptions {
            radius_mm,
            smooth_sigma_px: 1.5,
            core_fraction: 0.6,
            min_sigmas: 8.0,
        }
    }
}

/// The fitted press.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PressFit {
    /// The sphere's centre over the plane (sensor frame x, y), mm, and its standard deviation.
    pub centre_mm: [f64; 2],
    pub centre_std_mm: [f64; 2],
    /// The indentation depth at the centre, mm, and its standard deviation (from the fit's
    /// residuals; the assumptions' error is not in it).
    pub depth_mm: f64,
    pub depth_std_mm: f64,
    /// The largest change of the depth when the core is taken above 0.5 or 0.75 of the apex
    /// instead, mm: a response not linear in depth gives a gain, and so a depth, that depends
    /// on the core (the fit's own standard deviation does not show it).
    pub depth_spread_mm: f64,
    /// The response's gain the sphere's curvature gives, grey levels per mm of depth.
    pub gain_grey_per_mm: f64,
    /// The darkening at the centre, grey levels.
    pub peak_grey: f64,
    /// The pixels fitted and the RMS of their residuals, grey levels.
    pub core_pixels: usize,
    pub residual_rms_grey: f64,
    /// The core's radius on the plane (the farthest fitted pixel from the centre), mm.
    pub core_radius_mm: f64,
    /// The apex's pixel, px.
    pub centre_px: [f64; 2],
}

/// Fits the press of a sphere (`opts.radius_mm`) in `capture` against `reference` (grey
/// levels, same size), seen by `camera` at `t_cam_sensor` with the skin's plane at
/// `plane_z_mm` (sensor frame): see the module's documentation.
///
/// # Errors
/// [`PressError`]: the sizes differ, no darkening above the noise, too few core pixels on the
/// plane, a darkening that is not a dome.
pub fn fit_sphere_press(
    reference: &GrayImage,
    capture: &GrayImage,
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    plane_z_mm: f64,
    opts: &PressOptions,
) -> Result<PressFit, PressError> {
    let mut fit = fit_core(reference, capture, camera, t_cam_sensor, plane_z_mm, opts)?;
    // the depth over other cores: how far the response departs from linear in depth
    let mut spread: f64 = 0.0;
    for f in [0.5, 0.75] {
        let o = PressOptions {
            core_fraction: f,
            ..*opts
        };
        if let Ok(other) = fit_core(reference, capture, camera, t_cam_sensor, plane_z_mm, &o) {
            spread = spread.max((other.depth_mm - fit.depth_mm).abs());
        }
    }
    fit.depth_spread_mm = spread;
    Ok(fit)
}

fn fit_core(
    reference: &GrayImage,
    capture: &GrayImage,
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    plane_z_mm: f64,
    opts: &PressOptions,
) -> Result<PressFit, PressError> {
    let (w, h) = (capture.width, capture.height);
    if (reference.width, reference.height) != (w, h) {
        return Err(PressError::Size(w, h, reference.width, reference.height));
    }
    let raw = GrayImage {
        width: w,
        height: h,
        data: reference
            .data
            .iter()
            .zip(&capture.data)
            .map(|(r, c)| r - c)
            .collect(),
    };
    let diff = gaussian_blur(&raw, opts.smooth_sigma_px);
    // the noise: the median absolute deviation of the raw difference from the smoothed one
    let mut dev: Vec<f64> = raw
        .data
        .iter()
        .zip(&diff.data)
        .map(|(a, b)| f64::from((a - b).abs()))
        .collect();
    let noise = 1.4826 * crate::median_sorting(&mut dev);
    // the skin away from the press is the reference's: no offset is taken off (a press
    // reaches far, 1 / r outside the contact of a half-space, and a bonded skin bulges round
    // it, so the image's median is not the unpressed level)
    let base = 0.0;
    let (k, &peak) = diff
        .data
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
        .unwrap_or((0, &0.0));
    let peak = f64::from(peak) - base;
    let need = opts.min_sigmas * noise;
    if !(peak > need) {
        return Err(PressError::NoContact {
            peak,
            need,
            sigmas: opts.min_sigmas,
        });
    }
    // the core: the connected region above the fraction of the peak round the peak's pixel
    let level = (base + opts.core_fraction * peak) as f32;
    let mut inside = vec![false; w * h];
    let mut stack = vec![k];
    inside[k] = true;
    while let Some(i) = stack.pop() {
        let (u, v) = (i % w, i / w);
        let mut push = |j: usize| {
            if !inside[j] && diff.data[j] >= level {
                inside[j] = true;
                stack.push(j);
            }
        };
        if u > 0 {
            push(i - 1);
        }
        if u + 1 < w {
            push(i + 1);
        }
        if v > 0 {
            push(i - w);
        }
        if v + 1 < h {
            push(i + w);
        }
    }
    let inv = t_cam_sensor.inverse();
    let sample = |i: usize| {
        let px = Vector2::new((i % w) as f64, (i / w) as f64);
        on_plane(camera, &inv, plane_z_mm, px).map(|x| (x, f64::from(raw.data[i]) - base, px))
    };
    let mut samples: Vec<(Vector2<f64>, f64, Vector2<f64>)> = inside
        .iter()
        .enumerate()
        .filter(|(_, &b)| b)
        .filter_map(|(i, _)| sample(i))
        .collect();
    let mut fit = paraboloid(&samples)?;
    // The core again as the fitted dome's level set, twice: a core cut from the noisy image
    // takes in the pixels whose noise lifts them above the level and leaves out those it
    // lowers, which flattens the fitted dome (2 % of the gain at 1.5 grey levels of noise)
    let (mut u0, mut u1, mut v0, mut v1) = (w, 0, h, 0);
    for s in &samples {
        let (u, v) = (s.2.x as usize, s.2.y as usize);
        (u0, u1, v0, v1) = (u0.min(u), u1.max(u), v0.min(v), v1.max(v));
    }
    let (du, dv) = ((u1 - u0) / 2 + 2, (v1 - v0) / 2 + 2);
    let (u0, u1, v0, v1) = (
        u0.saturating_sub(du),
        (u1 + du).min(w - 1),
        v0.saturating_sub(dv),
        (v1 + dv).min(h - 1),
    );
    let window: Vec<(Vector2<f64>, f64, Vector2<f64>)> = (v0..=v1)
        .flat_map(|v| (u0..=u1).map(move |u| v * w + u))
        .filter_map(sample)
        .collect();
    for _ in 0..2 {
        let (c, bq, apex) = fit.dome();
        let r_core2 = (1.0 - opts.core_fraction) * apex / bq;
        samples = window
            .iter()
            .filter(|s| (s.0 - c).norm_squared() <= r_core2)
            .copied()
            .collect();
        fit = paraboloid(&samples)?;
    }
    let Paraboloid { a, cov, mean, rms } = fit;
    let r2 = 2.0 * opts.radius_mm;
    let derived = |a: &Vector4<f64>| -> [f64; 4] {
        let bq = -a[3];
        let c = Vector2::new(a[1], a[2]) / (2.0 * bq);
        let apex = a[0] + bq * c.norm_squared();
        [mean.x + c.x, mean.y + c.y, apex / (r2 * bq), apex]
    };
    let val = derived(&a);
    // standard deviations by the Jacobian of `derived` (central differences) and `cov`
    let mut jac = nalgebra::Matrix4::<f64>::zeros();
    for j in 0..4 {
        let e = 1e-6 * a[j].abs().max(1e-9);
        let (mut ap, mut am) = (a, a);
        ap[j] += e;
        am[j] -= e;
        let (p, q) = (derived(&ap), derived(&am));
        for i in 0..4 {
            jac[(i, j)] = (p[i] - q[i]) / (2.0 * e);
        }
    }
    let vc = jac * cov * jac.transpose();
    let centre = Vector2::new(val[0], val[1]);
    let core_radius = samples
        .iter()
        .map(|s| (s.0 - centre).norm())
        .fold(0.0, f64::max);
    let centre_px = {
        let s = samples
            .iter()
            .min_by(|p, q| (p.0 - centre).norm().total_cmp(&(q.0 - centre).norm()))
            .map_or(Vector2::zeros(), |s| s.2);
        [s.x, s.y]
    };
    Ok(PressFit {
        centre_mm: [val[0], val[1]],
        centre_std_mm: [vc[(0, 0)].sqrt(), vc[(1, 1)].sqrt()],
        depth_mm: val[2],
        depth_std_mm: vc[(2, 2)].sqrt(),
        depth_spread_mm: 0.0,
        gain_grey_per_mm: r2 * (-a[3]),
        peak_grey: val[3],
        core_pixels: samples.len(),
        residual_rms_grey: rms,
        core_radius_mm: core_radius,
        centre_px,
    })
}

/// The indentation depth of a sphere pressed `depth_mm` into an elastic half-space at distance
/// `r_mm` from its axis (Hertz; Johnson, Contact Mechanics, 1985, Eq. 3.41): the contact radius
/// `a = sqrt(R d)`, inside it `d - r^2 / (2R)`, outside
/// `(d / (pi a^2)) ((2a^2 - r^2) asin(a / r) + r a sqrt(1 - a^2 / r^2))`, which meets the inside
/// at `r = a` and falls to 0 far away. For the synthetic presses.
pub fn hertz_depth_mm(radius_mm: f64, depth_mm: f64, r_mm: f64) -> f64 {
    let a2 = radius_mm * depth_mm;
    let a = a2.sqrt();
    if r_mm <= a {
        depth_mm - r_mm * r_mm / (2.0 * radius_mm)
    } else {
        let r2 = r_mm * r_mm;
        depth_mm / (std::f64::consts::PI * a2)
            * ((2.0 * a2 - r2) * (a / r_mm).asin() + r_mm * a * (1.0 - a2 / r2).sqrt())
    }
}

/// A synthetic press of a sphere: what the camera sees of the skin before and after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticPress {
    pub radius_mm: f64,
    pub depth_mm: f64,
    /// The sphere's centre over the plane, sensor frame x and y, mm.
    pub centre_mm: [f64; 2],
    /// The darkening per mm of depth, grey levels (linear).
    pub gain_grey_per_mm: f64,
    /// The skin's grey at the image's centre and at its corners.
    pub centre_grey: f64,
    pub corner_grey: f64,
    /// Sigma of the lens's blur, px, and of the noise, grey levels.
    pub psf_sigma_px: f64,
    pub noise_sigma: f64,
    pub seed: u64,
}

/// The reference and the capture of `p` through `camera` at `t_cam_sensor`, the skin's plane
/// at `plane_z_mm`: the skin lit brighter at the centre than at the corners, the capture
/// darkened by `gain x depth` (the half-space's depth, [`hertz_depth_mm`]) where each pixel's
/// ray meets the plane, both blurred by a Gaussian, with Gaussian noise drawn from a
/// fixed-seed stream (same input, same images). What it lacks against a real capture: a
/// response that is not linear in depth, the bright halo where the skin bulges round the
/// contact (a bonded layer's, not a half-space's), shading by the surface's slope, the
/// colours of the three channels.
pub fn synthetic_sphere_press(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    plane_z_mm: f64,
    p: &SyntheticPress,
) -> (GrayImage, GrayImage) {
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let i = camera.intrinsics();
    let (w, h) = (i.image_width_px as usize, i.image_height_px as usize);
    let inv = t_cam_sensor.inverse();
    let (cu, cv) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    let corner = cu.hypot(cv);
    let mut base = Vec::with_capacity(w * h);
    let mut pressed = Vec::with_capacity(w * h);
    for v in 0..h {
        for u in 0..w {
            let rho = ((u as f64 - cu).hypot(v as f64 - cv) / corner).powi(2);
            let g = p.centre_grey + (p.corner_grey - p.centre_grey) * rho;
            let d = on_plane(camera, &inv, plane_z_mm, Vector2::new(u as f64, v as f64)).map_or(
                0.0,
                |x| {
                    let r = (x - Vector2::new(p.centre_mm[0], p.centre_mm[1])).norm();
                    hertz_depth_mm(p.radius_mm, p.depth_mm, r)
                },
            );
            base.push(g as f32);
            pressed.push((g - p.gain_grey_per_mm * d) as f32);
        }
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(p.seed);
    let mut finish = |img: Vec<f32>| {
        let mut b = gaussian_blur(
            &GrayImage {
                width: w,
                height: h,
                data: img,
            },
            p.psf_sigma_px,
        );
        for x in &mut b.data {
            let n: f64 = StandardNormal.sample(&mut rng);
            *x += (p.noise_sigma * n) as f32;
        }
        b
    };
    let reference = finish(base);
    let capture = finish(pressed);
    (reference, capture)
}

/// `D = a0 + a1 x + a2 y + a3 |x|^2` (x about `mean`) fitted to the samples, with the
/// coefficients' covariance and the residuals' RMS.
struct Paraboloid {
    a: Vector4<f64>,
    cov: Matrix4<f64>,
    mean: Vector2<f64>,
    rms: f64,
}

impl Paraboloid {
    /// The apex's point, the curvature `B` (> 0 for a dome) and the apex's value.
    fn dome(&self) -> (Vector2<f64>, f64, f64) {
        let bq = -self.a[3];
        let c = Vector2::new(self.a[1], self.a[2]) / (2.0 * bq);
        (self.mean + c, bq, self.a[0] + bq * c.norm_squared())
    }
}

/// Least squares of [`Paraboloid`] over `samples` (plane point mm, darkening, pixel).
///
/// # Errors
/// [`PressError::TooFewPixels`] under 12 samples or a singular system,
/// [`PressError::NotADome`] for a curvature that does not fall away from the apex.
fn paraboloid(samples: &[(Vector2<f64>, f64, Vector2<f64>)]) -> Result<Paraboloid, PressError> {
    if samples.len() < 12 {
        return Err(PressError::TooFewPixels(samples.len()));
    }
    let mean = samples.iter().map(|s| s.0).sum::<Vector2<f64>>() / samples.len() as f64;
    let row = |x: &Vector2<f64>| {
        let q = x - mean;
        Vector4::new(1.0, q.x, q.y, q.norm_squared())
    };
    let mut m = Matrix4::zeros();
    let mut b = Vector4::zeros();
    for (x, d, _) in samples {
        let r = row(x);
        m += r * r.transpose();
        b += r * *d;
    }
    let inv_m = m
        .try_inverse()
        .ok_or(PressError::TooFewPixels(samples.len()))?;
    let a = inv_m * b;
    let ss: f64 = samples
        .iter()
        .map(|(x, d, _)| (row(x).dot(&a) - d).powi(2))
        .sum();
    if !(a[3] < 0.0) {
        return Err(PressError::NotADome(a[3]));
    }
    Ok(Paraboloid {
        a,
        cov: inv_m * (ss / (samples.len() - 4) as f64),
        mean,
        rms: (ss / samples.len() as f64).sqrt(),
    })
}
