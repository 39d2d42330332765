//! How a flat sensor's image answers its skin's deformation: the capture is the reference
//! times the capture's gain (its exposure) plus a response to how far the face the camera sees
//! sinks into the skin (positive) or rises out of it (negative) at the pixel, blurred by the
//! out-of-focus lens:
//!
//! `I(p) = g I_ref(p) + (G_sigma * f(u))(p)`
//!
//! with `u` the seen face's displacement ([`crate::groundtruth::press_skin::PressedSkin`], the
//! elastic skin under the indenters) at the point of the contact face the pixel sees, `f` a
//! piecewise-linear function through 0 at `u = 0` (its values at knots), `G_sigma` a Gaussian
//! of `sigma` px. 9DTact's principle (Lin et al., RA-L 2023, Sec. III): the camera sees light
//! scattered in the translucent gel under an opaque black layer, which darkens where the gel is
//! thinned (the black face pushed towards the camera) and brightens where it thickens (the
//! skin's bulge round a press); `f` is that answer, measured, not assumed: its knots' values,
//! the gain and `sigma` are fitted by linear least squares (for each `sigma` of a list; the
//! best kept) from captures whose skin is known.
//!
//! What it leaves out: the answer's dependence on the place in the image (the LEDs' falloff:
//! only through the reference's gain), on the surface's slope (shading), and the coat's
//! own bending.

use crate::camera::CameraModel;
use crate::groundtruth::press_skin::{Face, PressedSkin};
use crate::imprints::{gaussian_blur, GrayImage};
use nalgebra::{DMatrix, DVector, Isometry3};
use serde::Serialize;

/// A fitted response.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlatResponse {
    /// The knots, mm of the seen face's sink (increasing, one of them 0).
    pub knots_mm: Vec<f64>,
    /// `f` at each knot, grey levels (0 at the knot 0).
    pub grey: Vec<f64>,
    /// The blur, px.
    pub blur_px: f64,
}

impl FlatResponse {
    /// `f(u)`: linear between knots, held at the end values past them.
    pub fn at(&self, u: f64) -> f64 {
        hats(&self.knots_mm, u)
            .into_iter()
            .map(|(k, w)| w * self.grey[k])
            .sum()
    }
}

/// The hat functions of `knots` nonzero at `u` (at most two), with their weights; `u` past
/// the ends is held at the end knot.
fn hats(knots: &[f64], u: f64) -> Vec<(usize, f64)> {
    let n = knots.len();
    if !u.is_finite() {
        return Vec::new();
    }
    if u <= knots[0] {
        return vec![(0, 1.0)];
    }
    if u >= knots[n - 1] {
        return vec![(n - 1, 1.0)];
    }
    let k = knots.partition_point(|&x| x <= u) - 1;
    let w = (u - knots[k]) / (knots[k + 1] - knots[k]);
    vec![(k, 1.0 - w), (k + 1, w)]
}

/// The seen face's (or the surface's) displacement into the skin at the point of the contact
/// face `plane_z_mm` each pixel of `camera` sees (row-major, `W x H`); 0 off the skin's grid,
/// NaN where the pixel's ray does not meet the plane.
pub fn sink_per_pixel(
    skin: &PressedSkin,
    face: Face,
    camera: &CameraModel,
    t_cam_sensor: &Isometry3<f64>,
    plane_z_mm: f64,
) -> Vec<f64> {
    crate::seating::sink_at(
        skin,
        face,
        &crate::seating::plane_points(camera, t_cam_sensor, plane_z_mm),
    )
}

/// `G_sigma * f(u)`: the response's change of the image, grey levels, for the sink per pixel
/// (row-major, `width` a row; 0 where the sink is NaN).
pub fn response_image(response: &FlatResponse, width: usize, sink_mm: &[f64]) -> GrayImage {
    let f = GrayImage {
        width,
        height: sink_mm.len() / width.max(1),
        data: sink_mm
            .iter()
            .map(|&u| {
                if u.is_finite() {
                    response.at(u) as f32
                } else {
                    0.0
                }
            })
            .collect(),
    };
    gaussian_blur(&f, response.blur_px)
}

/// `g I_ref + G_sigma * f(u)`: the capture `response` predicts for a reference, a gain and the
/// seen face's displacement per pixel (NaN: no response there).
pub fn render(
    response: &FlatResponse,
    gain: f64,
    reference: &GrayImage,
    sink_mm: &[f64],
) -> GrayImage {
    let b = response_image(response, reference.width, sink_mm);
    GrayImage {
        width: reference.width,
        height: reference.height,
        data: reference
            .data
            .iter()
            .zip(&b.data)
            .map(|(&r, &d)| (gain * r as f64 + d as f64) as f32)
            .collect(),
    }
}

/// A capture to fit from: its reference, the capture, the seen face's displacement per pixel,
/// and the pixels that count (the lit skin).
pub struct FitCapture<'a> {
    pub reference: &'a GrayImage,
    pub capture: &'a GrayImage,
    pub sink_mm: &'a [f64],
    pub mask: &'a [bool],
}

/// A fit: the response, each capture's gain, and each capture's RMS residual over its mask,
/// grey levels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResponseFit {
    pub response: FlatResponse,
    pub gains: Vec<f64>,
    pub rms_grey: Vec<f64>,
}

/// Fits the response's knot values and each capture's gain by linear least squares, for each
/// blur of `blurs_px`, keeping the blur of the least residual; `knots_mm` increasing, one of
/// them 0 (whose value is held at 0).
///
/// # Panics
/// Never for finite images of one size; a `knots_mm` without 0 or not increasing is a
/// programming error (asserted).
pub fn fit_response(
    captures: &[FitCapture<'_>],
    knots_mm: &[f64],
    blurs_px: &[f64],
) -> ResponseFit {
    assert!(knots_mm.windows(2).all(|w| w[0] < w[1]) && knots_mm.contains(&0.0));
    let zero = knots_mm.iter().position(|&k| k == 0.0).unwrap_or(0);
    let free: Vec<usize> = (0..knots_mm.len()).filter(|&k| k != zero).collect();
    let (nk, nc) = (free.len(), captures.len());
    let mut best: Option<(f64, ResponseFit)> = None;
    for &sigma in blurs_px {
        // per capture: the blurred hat images of the free knots
        let basis: Vec<Vec<GrayImage>> = captures
            .iter()
            .map(|c| {
                free.iter()
                    .map(|&k| {
                        let img = GrayImage {
                            width: c.reference.width,
                            height: c.reference.height,
                            data: c
                                .sink_mm
                                .iter()
                                .map(|&u| {
                                    hats(knots_mm, u)
                                        .into_iter()
                                        .filter(|&(j, _)| j == k)
                                        .map(|(_, w)| w as f32)
                                        .sum()
                                })
                                .collect(),
                        };
                        gaussian_blur(&img, sigma)
                    })
                    .collect()
            })
            .collect();
        let m = nk + nc;
        let mut ata = DMatrix::<f64>::zeros(m, m);
        let mut atb = DVector::<f64>::zeros(m);
        let mut row = vec![0.0; m];
        for (ci, c) in captures.iter().enumerate() {
            for p in 0..c.capture.data.len() {
                if !c.mask[p] {
                    continue;
                }
                row.iter_mut().for_each(|x| *x = 0.0);
                for (j, b) in basis[ci].iter().enumerate() {
                    row[j] = b.data[p] as f64;
                }
                row[nk + ci] = c.reference.data[p] as f64;
                let y = c.capture.data[p] as f64;
                for a in 0..m {
                    if row[a] == 0.0 {
                        continue;
                    }
                    atb[a] += row[a] * y;
                    for b in 0..m {
                        ata[(a, b)] += row[a] * row[b];
                    }
                }
            }
        }
        // a knot no pixel reaches is held by a small penalty on the response's curvature
        // (straight through it), which a reached knot's data outweigh
        let weight = 1e-3 * (0..nk).map(|j| ata[(j, j)]).fold(0.0, f64::max).max(1.0);
        let index = |k: usize| free.iter().position(|&f| f == k);
        for k in 1..knots_mm.len() - 1 {
            let (hl, hr) = (knots_mm[k] - knots_mm[k - 1], knots_mm[k + 1] - knots_mm[k]);
            // second difference on uneven knots: f'' ~ c_l f_{k-1} + c_m f_k + c_r f_{k+1}
            let c = [
                (k - 1, 2.0 / (hl * (hl + hr))),
                (k, -2.0 / (hl * hr)),
                (k + 1, 2.0 / (hr * (hl + hr))),
            ];
            let scale = weight * (hl * hr).powi(2) * 1e-2;
            for &(a, ca) in &c {
                for &(b, cb) in &c {
                    if let (Some(ia), Some(ib)) = (index(a), index(b)) {
                        ata[(ia, ib)] += scale * ca * cb;
                    }
                }
            }
        }
        let Some(x) = ata.clone().cholesky().map(|ch| ch.solve(&atb)) else {
            continue;
        };
        let mut grey = vec![0.0; knots_mm.len()];
        for (j, &k) in free.iter().enumerate() {
            grey[k] = x[j];
        }
        let response = FlatResponse {
            knots_mm: knots_mm.to_vec(),
            grey,
            blur_px: sigma,
        };
        let gains: Vec<f64> = (0..nc).map(|c| x[nk + c]).collect();
        let rms_grey: Vec<f64> = captures
            .iter()
            .zip(&gains)
            .map(|(c, &g)| {
                rms_over(
                    &render(&response, g, c.reference, c.sink_mm),
                    c.capture,
                    c.mask,
                )
            })
            .collect();
        let total: f64 = rms_grey.iter().map(|r| r * r).sum();
        if best.as_ref().is_none_or(|(t, _)| total < *t) {
            best = Some((
                total,
                ResponseFit {
                    response,
                    gains,
                    rms_grey,
                },
            ));
        }
    }
    best.map(|(_, f)| f).unwrap_or(ResponseFit {
        response: FlatResponse {
            knots_mm: knots_mm.to_vec(),
            grey: vec![0.0; knots_mm.len()],
            blur_px: 0.0,
        },
        gains: vec![1.0; nc],
        rms_grey: vec![f64::NAN; nc],
    })
}

/// The RMS difference of two images over `mask`, grey levels.
pub fn rms_over(a: &GrayImage, b: &GrayImage, mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for ((x, y), &m) in a.data.iter().zip(&b.data).zip(mask) {
        if m {
            let d = *x as f64 - *y as f64;
            s += d * d;
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        (s / n as f64).sqrt()
    }
}
