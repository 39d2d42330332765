//! A press's seating refined from its own capture: how deep the indenters sit in the skin and
//! how far they lie beside where they were put, found by rendering the capture through the
//! elastic skin ([`crate::groundtruth::press_skin`]) and a flat sensor's response
//! ([`crate::flat_response`]) and matching it to the real one.
//!
//! A fixture is re-seated for every capture: a calibration board pressed by hand sits 0.4 to
//! 1.0 mm deep (its cup's floor is the stop at 1.5 mm only when it is pressed home), and its
//! bumps lie a little beside their nominal places. The seating is three numbers here, the
//! depth and the offset in the contact face's plane (x, y, sensor frame, mm); the tilt and the
//! turn about the face's normal are not fitted (ASSUMPTION: a board pressed flat, the turn
//! taken by the camera's pose).
//!
//! The fit: the residual over the capture's lit pixels of `g I_ref + G_sigma * f(u(s)) - I`,
//! `u(s)` the seen face's sink under the indenters seated `s`, `f` and `sigma` the response
//! (fixed), the gain `g` solved in closed form at every `s` (variable projection); minimised
//! by Levenberg and Marquardt's damped Gauss-Newton steps on `s` (Jacobian by forward
//! differences of 5 um), within the stated bounds, with a Gaussian prior of the stated
//! `prior_sigma_mm` on the offset (zero mean: where the fixture was put). Deterministic: no
//! random start, the same steps for the same inputs.

use serde::Serialize;

use crate::camera::CameraModel;
use crate::elastic::{bump_heights, ContactError};
use crate::flat_response::{response_image, FlatResponse};
use crate::groundtruth::press_skin::{Face, PressedSkin, SkinSolver};
use crate::imprints::GrayImage;
use nalgebra::{Isometry3, Matrix3, Vector2, Vector3};

/// How a press sits: its indenters' lowest point under the contact face, mm, and their offset
/// from their nominal places in the face's plane, x and y, mm (sensor frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Seating {
    pub depth_mm: f64,
    pub offset_mm: [f64; 2],
}

/// What a seating may be: its depth within `depth_mm` (least, most), each offset within
/// `offset_mm` of 0, and the prior's standard deviation on the offsets, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeatingBounds {
    pub depth_mm: [f64; 2],
    pub offset_mm: f64,
    pub prior_sigma_mm: f64,
}

/// A refined seating.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeatingFit {
    pub start: Seating,
    pub seating: Seating,
    /// The capture's gain (exposure) at the seating.
    pub gain: f64,
    /// The RMS residual over the fit's pixels, grey levels.
    pub rms_grey: f64,
    /// The standard deviations of the depth and the offsets, mm, from the Gauss-Newton
    /// normal matrix and the residual's variance (pixels taken as independent, which the blur
    /// makes them not: a lower bound).
    pub std_mm: [f64; 3],
    /// The presses solved.
    pub evaluations: usize,
    /// The steps taken.
    pub iterations: usize,
}

/// The point of the contact face `plane_z_mm` (sensor frame x, y, mm) each pixel of `camera`
/// at `t_cam_sensor` sees (row-major, `W x H`); NaN where the pixel's ray does not meet it.
pub fn plane_points(
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    plane_z_mm: f64,
) -> Vec<[f64; 2]> {
    let i = camera.intrinsics();
    let (w, h) = (i.image_width_px as usize, i.image_height_px as usize);
    let inv = t_cam_sensor.inverse();
    (0..w * h)
        .map(|p| {
            let px = Vector2::new((p % w) as f64, (p / w) as f64);
            match crate::board::pixel_on_plane(camera, &inv, plane_z_mm, px) {
                Some(q) => [q.x, q.y],
                None => [f64::NAN, f64::NAN],
            }
        })
        .collect()
}

/// `face`'s displacement into the skin at each of `points` (NaN where a point is NaN; 0 off
/// the skin's grid).
pub fn sink_at(skin: &PressedSkin, face: Face, points: &[[f64; 2]]) -> Vec<f64> {
    points
        .iter()
        .map(|q| {
            if q[0].is_finite() && q[1].is_finite() {
                skin.sample(face, q[0], q[1]).0
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// The gain `g` of least squares of `g reference + change - capture` over `mask`.
pub fn best_gain(
    reference: &GrayImage,
    capture: &GrayImage,
    change: &GrayImage,
    mask: &[bool],
) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for p in 0..capture.data.len() {
        if mask[p] {
            let r = reference.data[p] as f64;
            num += r * (capture.data[p] as f64 - change.data[p] as f64);
            den += r * r;
        }
    }
    if den > 0.0 {
        num / den
    } else {
        1.0
    }
}

/// The capture a seating is refined on: its reference, the capture, the pixels that count,
/// and the contact face's point each pixel sees ([`plane_points`]).
pub struct SeatedCapture<'a> {
    pub reference: &'a GrayImage,
    pub capture: &'a GrayImage,
    pub mask: &'a [bool],
    pub points: &'a [[f64; 2]],
}

/// The residuals (masked pixels, in order) and the gain of `skin` rendered by `response`.
fn residuals(
    skin: &PressedSkin,
    response: &FlatResponse,
    c: &SeatedCapture<'_>,
) -> (Vec<f64>, f64) {
    let sink = sink_at(skin, Face::Seen, c.points);
    let change = response_image(response, c.reference.width, &sink);
    let g = best_gain(c.reference, c.capture, &change, c.mask);
    let r = (0..c.capture.data.len())
        .filter(|&p| c.mask[p])
        .map(|p| g * c.reference.data[p] as f64 + change.data[p] as f64 - c.capture.data[p] as f64)
        .collect();
    (r, g)
}

/// Refines the seating of the press whose skin `skin_of` solves for a seating, from `start`,
/// by the capture `capture` rendered through `response` (module docs).
///
/// # Errors
/// [`ContactError`] of the solver; a start outside `bounds`
/// ([`ContactError::Value`], `seating.depth_mm`).
pub fn refine_seating(
    skin_of: &dyn Fn(&Seating) -> Result<PressedSkin, ContactError>,
    start: Seating,
    bounds: SeatingBounds,
    response: &FlatResponse,
    capture: &SeatedCapture<'_>,
) -> Result<SeatingFit, ContactError> {
    if !(bounds.depth_mm[0] <= start.depth_mm && start.depth_mm <= bounds.depth_mm[1]) {
        return Err(ContactError::Value {
            name: "seating.depth_mm",
            value: start.depth_mm,
            rule: "the start must lie within the depth's bounds",
        });
    }
    let clamp = |v: Vector3<f64>| {
        Vector3::new(
            v.x.clamp(bounds.depth_mm[0], bounds.depth_mm[1]),
            v.y.clamp(-bounds.offset_mm, bounds.offset_mm),
            v.z.clamp(-bounds.offset_mm, bounds.offset_mm),
        )
    };
    let seat = |v: &Vector3<f64>| Seating {
        depth_mm: v.x,
        offset_mm: [v.y, v.z],
    };
    let mut evaluations = 0;
    let mut eval = |v: &Vector3<f64>| -> Result<(Vec<f64>, f64), ContactError> {
        evaluations += 1;
        Ok(residuals(&skin_of(&seat(v))?, response, capture))
    };
    let prior =
        |v: &Vector3<f64>, var: f64| var * (v.y * v.y + v.z * v.z) / bounds.prior_sigma_mm.powi(2);
    let mut x = clamp(Vector3::new(
        start.depth_mm,
        start.offset_mm[0],
        start.offset_mm[1],
    ));
    let (mut r, mut gain) = eval(&x)?;
    let pixels = r.len().max(1) as f64;
    let sq = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    // the residual's variance, for the prior's weight (held from the start)
    let var = sq(&r) / pixels;
    let mut cost = sq(&r) + prior(&x, var);
    let mut lambda: f64 = 1e-3;
    let mut iterations = 0;
    let step_mm = 0.005;
    let mut jtj = Matrix3::zeros();
    for _ in 0..15 {
        iterations += 1;
        // the Jacobian by forward differences (backward at an upper bound)
        let mut cols: Vec<Vec<f64>> = Vec::with_capacity(3);
        for k in 0..3 {
            let mut xs = x;
            let upper = if k == 0 {
                bounds.depth_mm[1]
            } else {
                bounds.offset_mm
            };
            let h = if x[k] + step_mm > upper {
                -step_mm
            } else {
                step_mm
            };
            xs[k] += h;
            let (rs, _) = eval(&xs)?;
            cols.push(rs.iter().zip(&r).map(|(a, b)| (a - b) / h).collect());
        }
        let w = var / bounds.prior_sigma_mm.powi(2);
        jtj = Matrix3::from_fn(|a, b| {
            cols[a]
                .iter()
                .zip(&cols[b])
                .map(|(p, q)| p * q)
                .sum::<f64>()
        });
        let mut jtr =
            Vector3::from_fn(|a, _| cols[a].iter().zip(&r).map(|(p, q)| p * q).sum::<f64>());
        jtr.y += w * x.y;
        jtr.z += w * x.z;
        let mut improved = false;
        for _ in 0..8 {
            let mut a = jtj;
            a[(1, 1)] += w;
            a[(2, 2)] += w;
            for d in 0..3 {
                a[(d, d)] += lambda * a[(d, d)].max(1e-12);
            }
            let Some(delta) = a.lu().solve(&(-jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let next = clamp(x + delta);
            let (rn, gn) = eval(&next)?;
            let cn = sq(&rn) + prior(&next, var);
            if cn < cost {
                let moved = (next - x).norm();
                x = next;
                r = rn;
                gain = gn;
                cost = cn;
                lambda = (lambda / 10.0).max(1e-9);
                improved = moved >= 1e-4;
                break;
            }
            lambda *= 10.0;
        }
        // no step lowered the cost, or the last moved under 0.1 um: converged
        if !improved {
            break;
        }
    }
    Ok(finish(
        start,
        seat(&x),
        gain,
        &r,
        jtj,
        evaluations,
        iterations,
    ))
}

fn finish(
    start: Seating,
    seating: Seating,
    gain: f64,
    r: &[f64],
    jtj: Matrix3<f64>,
    evaluations: usize,
    iterations: usize,
) -> SeatingFit {
    let var = r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64;
    let std_mm = jtj
        .try_inverse()
        .map(|c| [0, 1, 2].map(|k| (c[(k, k)] * var).max(0.0).sqrt()))
        .unwrap_or([f64::NAN; 3]);
    SeatingFit {
        start,
        seating,
        gain,
        rms_grey: var.sqrt(),
        std_mm,
        evaluations,
        iterations,
    }
}

/// A calibration board's press on a skin: its bumps (each a cylinder of `bump_radius_mm`
/// capped by a hemisphere, `bump_height_mm` from the cup's floor to its tip) at `bumps_mm`
/// (sensor frame x, y, mm), on the grid of `solver` centred on the sensor's axis.
pub struct BoardPressSkin<'a> {
    pub solver: &'a SkinSolver,
    pub bumps_mm: &'a [[f64; 2]],
    pub bump_radius_mm: f64,
    pub bump_height_mm: f64,
}

impl BoardPressSkin<'_> {
    /// The skin with the board seated `seating`: the bumps moved by its offset, their tips
    /// its depth under the contact face (the floor meets the skin's bulges where they reach
    /// it).
    ///
    /// # Errors
    /// [`ContactError`] of the solver.
    pub fn skin(&self, seating: &Seating) -> Result<PressedSkin, ContactError> {
        let grid = self.solver.grid();
        let [dx, dy] = seating.offset_mm;
        let heights = bump_heights(
            grid,
            [-dx, -dy],
            self.bumps_mm,
            self.bump_radius_mm,
            self.bump_height_mm,
        );
        self.solver.press([0.0, 0.0], &heights, seating.depth_mm)
    }
}

/// A press whose seating is fitted with the response ([`fit_response_and_seatings`]): its
/// capture, its skin for a seating, where it starts, and its bounds (`None`: held at the
/// start, a press whose seating is known, such as a ball's from its dark disc).
pub struct SeatedPress<'a> {
    pub capture: SeatedCapture<'a>,
    pub skin_of: &'a dyn Fn(&Seating) -> Result<PressedSkin, ContactError>,
    pub start: Seating,
    pub bounds: Option<SeatingBounds>,
}

/// The response and every press's seating, fitted in turns: the response and the gains by
/// [`crate::flat_response::fit_response`] on every press at its seating, then each free
/// seating by [`refine_seating`] with that response, until no seating moves by 1 um or
/// `rounds` turns. The presses whose seating is held fix the response's scale (a free
/// seating alone trades its depth against the response's slope); a free one is found by the
/// shape of its imprints under the response they share.
///
/// # Errors
/// [`ContactError`] of the solver.
pub fn fit_response_and_seatings(
    presses: &[SeatedPress<'_>],
    knots_mm: &[f64],
    blurs_px: &[f64],
    rounds: usize,
) -> Result<(crate::flat_response::ResponseFit, Vec<SeatingFit>), ContactError> {
    use crate::flat_response::{fit_response, FitCapture};
    let mut seatings: Vec<Seating> = presses.iter().map(|p| p.start).collect();
    let mut fits: Vec<SeatingFit> = Vec::new();
    let mut response_fit = None;
    let any_held = presses.iter().any(|p| p.bounds.is_none());
    for round in 0..rounds.max(2) {
        // the first response from the held presses alone (a free one at its start would
        // bend the response to fit a wrong seating), then from all
        let counted: Vec<usize> = (0..presses.len())
            .filter(|&k| round > 0 || !any_held || presses[k].bounds.is_none())
            .collect();
        let sinks: Vec<Vec<f64>> = counted
            .iter()
            .map(|&k| {
                let p = &presses[k];
                Ok(sink_at(
                    &(p.skin_of)(&seatings[k])?,
                    Face::Seen,
                    p.capture.points,
                ))
            })
            .collect::<Result<_, ContactError>>()?;
        let captures: Vec<FitCapture<'_>> = counted
            .iter()
            .zip(&sinks)
            .map(|(&k, sink)| FitCapture {
                reference: presses[k].capture.reference,
                capture: presses[k].capture.capture,
                sink_mm: sink,
                mask: presses[k].capture.mask,
            })
            .collect();
        let rf = fit_response(&captures, knots_mm, blurs_px);
        fits = Vec::with_capacity(presses.len());
        let mut moved: f64 = 0.0;
        for (k, p) in presses.iter().enumerate() {
            let fit = match p.bounds {
                Some(bounds) => {
                    refine_seating(p.skin_of, seatings[k], bounds, &rf.response, &p.capture)?
                }
                None => {
                    let (r, gain) =
                        residuals(&(p.skin_of)(&seatings[k])?, &rf.response, &p.capture);
                    finish(p.start, seatings[k], gain, &r, Matrix3::zeros(), 1, 0)
                }
            };
            let (a, b) = (fit.seating, seatings[k]);
            moved = moved
                .max((a.depth_mm - b.depth_mm).abs())
                .max((a.offset_mm[0] - b.offset_mm[0]).abs())
                .max((a.offset_mm[1] - b.offset_mm[1]).abs());
            seatings[k] = fit.seating;
            fits.push(SeatingFit {
                start: p.start,
                ..fit
            });
        }
        // the gains of every press, in order (those the response fit did not count from
        // their seating's fit)
        let gains = fits.iter().map(|f| f.gain).collect();
        response_fit = Some(crate::flat_response::ResponseFit { gains, ..rf });
        if round > 0 && moved < 1e-3 {
            break;
        }
    }
    Ok((response_fit.expect("at least one round"), fits))
}
