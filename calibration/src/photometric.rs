//! A photometric model fitted from calibration captures: how the real camera's intensities
//! respond to the skin's surface normal, so that images of any protrusion set can be rendered
//! in a sensor's own appearance.
//!
//! Each capture pairs known geometry (the pins' imprints through the solved pose: every
//! pixel's surface point and normal, [`crate::groundtruth::SurfaceHits`]) with the
//! intensities the camera recorded. The model, per colour channel, is
//!
//! `I(x, n) = gain x R(x) x (1 + sum_k sum_m c_km P_m(x) f_k(n, x) + sum_l w_l G_l(x, n)
//!            - sum_j b_j S_j(x))`
//!
//! - `R(x)`: the unindented appearance, per pixel: the reference image, averaged with the
//!   unpressed pixels of every capture (each divided by its gain) to lower its noise;
//! - `f_k`: the change of the surface normal from the reference normal in the reference
//!   surface's local frame about the camera's optical axis (`a` along the tangent away from
//!   the axis, `r` round it, `c` along the reference normal: one minus the tilt's cosine), the
//!   monomials of `a` and `r` up to degree 3 (`a^2, ar, r^2, a^3, a^2 r, a r^2, r^3`), and the
//!   indentation depth along the ray (mm);
//! - `P_m(x)`: powers of the pixel's normalised distance from the image centre up to
//!   [`SPATIAL_DEGREE`]: the lights' directions and fall-off change slowly over the skin;
//! - `G_l(x, n)`: candidate point lights ([`LIGHT_TERMS`]: twelve azimuths at three heights
//!   about the optical axis): the change of light `l`'s Lambertian irradiance (incidence
//!   cosine over squared distance, zero where the protrusions block it) from the reference
//!   surface to the pressed one, over all candidates' irradiance of the reference; they follow
//!   lights at a few azimuths, which the spatial term (round the axis) cannot;
//! - `S_j(x)`: the shadows ([`shadow_map`]): the share of candidate ring `j`'s light (rings of
//!   effective lights about the optical axis, [`ShadowRings`]) that the protrusions block at
//!   the pixel, beside an imprint or inside it; `b_j` the share of the pixel's light the ring
//!   stands for;
//! - `gain`: each capture's global gain against the reference (exposure and LED drift), the
//!   median ratio over its unpressed skin.
//!
//! Why this form: under Lambertian lights the radiance is a sum of clamped cosines
//! `max(0, n . l_k)`, a smooth function of the normal. With `n = (1 - c) n0 - a e_a - r e_r`
//! each cosine is linear in `a`, `r` and `c` until it clamps, and low-order polynomials in the
//! tilt take the clamping and the lights' spread (order 2 already holds most of a clamped
//! cosine's energy, Ramamoorthi and Hanrahan 2001; `c` keeps the walls of a deep imprint,
//! tilted near 90 deg, from bending the polynomial). Divided by the reference, the response is
//! `1` at no tilt, and what remains varies slowly over the skin; moving the surface by the
//! indentation changes the distances to the lights to first order in the depth. Fitting the
//! ratio, not the intensity, leaves every pixel's own appearance (rim LEDs, vignetting, the
//! skin's albedo) to the reference and only the response to tilt to the captures. A look-up
//! table over binned normals (Taxim) needs a flat sensor and many more imprints per bin than a
//! pin dome gives; a low-order spatial term is what a curved skin's few dozen imprints can
//! fix. A pin pressed deeper than its tip's radius shadows the skin beside its imprint from
//! lights at grazing incidence; the lights are not known, so the shadow term spans candidate
//! rings of them and the fit weighs each (with R-Tac0's LED ring the weight goes to the ring
//! nearest it, about 0.9 of the light).
//!
//! Limits: the spatial term and the candidate rings are round the optical axis, so the model
//! is closest for lights in a ring about it (R-Tac0's, the TacTip's, UVDtact's). For lights at
//! a few azimuths (ShadowTac's three single-colour LEDs) the candidate point lights halve the
//! error but leave about 5 grey levels (balls) to 6.5 (R-Tac0's pins) in the leave-one-out
//! test: their weights are divided by all candidates' irradiance, not the unknown lights'.
//! Penumbrae are those of the sampled rings (24 lights each).

use crate::groundtruth::exact::ExactPrimitives;
use crate::groundtruth::rays::PixelRays;
use crate::groundtruth::SurfaceHits;
use fabkit_designs::primitives::{cross, dot};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

pub use crate::groundtruth::pins::{pin_primitives, read_pins, Pins};

/// Degree of the spatial polynomial in the normalised distance from the image centre.
pub const SPATIAL_DEGREE: usize = 3;

/// Highest angular harmonic of the spatial term: 0, the coefficients of lights in a ring
/// about the axis. Higher orders follow lights at a few azimuths on the captures they are
/// fitted to but do not carry to new pin positions from a pin dome's few dozen imprints
/// (order 2 fitted ShadowTac-like R, G, B side LEDs within 3 grey levels and re-rendered new
/// pin positions 4 to 6 off); the candidate point lights ([`LIGHT_TERMS`]) take that part.
pub const ANGULAR_ORDER: usize = 0;

/// Number of spatial terms ([`spatial`]).
pub const SPATIAL_TERMS: usize = SPATIAL_DEGREE + 1 + 2 * ANGULAR_ORDER * SPATIAL_DEGREE;

/// Number of features of the surface: the normal's change along and round the axis and along
/// the reference normal, the indentation depth, and the quadratic (3) and cubic (4) terms of
/// the first two.
pub const FEATURES: usize = 11;

/// Number of candidate rings of effective lights the shadow term is fitted over:
/// [`SHADOW_HEIGHTS`] x [`SHADOW_RADII`].
pub const SHADOW_TERMS: usize = 9;

/// Lights sampled on each candidate ring, evenly in azimuth.
pub const SHADOW_AZIMUTHS: usize = 24;

/// Heights of the candidate rings' centres along the optical axis from the camera centre, as
/// fractions of the skin's median range (negative: behind the camera).
pub const SHADOW_HEIGHTS: [f64; 3] = [-0.5, -0.2, 0.1];

/// Radii of the candidate rings about the optical axis, as fractions of the skin's median
/// range.
pub const SHADOW_RADII: [f64; 3] = [0.2, 0.45, 0.7];

/// How far from a protrusion's bounding sphere a surface point may lie and still be tested
/// for its shadow, as a fraction of the skin's median range.
pub const SHADOW_REACH: f64 = 0.25;

/// Candidate point lights of the light term: azimuths per height.
pub const LIGHT_AZIMUTHS: usize = 12;
/// Heights of the candidate lights along the optical axis from the camera centre, fractions of
/// the skin's median range.
pub const LIGHT_HEIGHTS: [f64; 3] = [-0.5, 0.0, 0.5];
/// Radius of the candidate lights about the optical axis, fraction of the skin's median range.
pub const LIGHT_RADIUS: f64 = 0.5;
/// Number of candidate point lights.
pub const LIGHT_TERMS: usize = LIGHT_AZIMUTHS * 3;

/// Number of coefficients per channel: the response to the surface features times the
/// spatial terms (feature major), then the candidate point lights' weights.
pub const COEFFICIENTS: usize = FEATURES * SPATIAL_TERMS + LIGHT_TERMS;

/// Margin about a dent's contact points (the pixels sample its rim), as a fraction of the
/// skin's median range.
const DENT_MARGIN: f64 = 0.02;

/// Least reference intensity (counts) of a pixel used to fit or to measure a gain: darker
/// pixels carry mostly noise in a ratio.
pub const MIN_REFERENCE_COUNTS: f64 = 8.0;

/// A fitted photometric model of one camera at one pose.
#[derive(Debug, Clone)]
pub struct PhotometricModel {
    pub width: usize,
    pub height: usize,
    /// The unindented appearance per pixel and channel, counts (NaN off the skin).
    pub reference: Vec<[f64; 3]>,
    /// Per channel, the coefficients `c_km` at `k * SPATIAL_TERMS + m`, then the weights of the
    /// candidate point lights ([`COEFFICIENTS`] in all).
    pub coefficients: [Vec<f64>; 3],
    /// The camera's optical axis in the sensor frame (the local frame of the features).
    pub axis: [f64; 3],
    /// The candidate light rings of the shadow term.
    pub rings: ShadowRings,
    /// Per channel, the weight of each candidate ring's shadow ([`ShadowMap`]): the fraction
    /// of a pixel's light its ring stands for.
    pub shadow_coefficients: [[f64; SHADOW_TERMS]; 3],
    /// The gain of each fitted capture against the reference.
    pub gains: Vec<f64>,
    /// The images' full scale, counts: rendered values are clipped to it.
    pub full_scale: f64,
    /// Root-mean-square residual of each fitted capture over its skin, counts (all channels).
    pub residual_rms: Vec<f64>,
}

/// One capture to fit: its image (row-major, per channel, counts), its surface and the
/// shadows its protrusions cast ([`shadow_map`]).
#[derive(Debug, Clone, Copy)]
pub struct Capture<'a> {
    pub image: &'a [[f64; 3]],
    pub hits: &'a SurfaceHits,
    pub shadows: &'a ShadowMap,
}

/// The candidate lights of the shadow term: rings about the camera's optical axis, where a
/// sensor's LEDs are not known (a ring of LEDs, or a few, round the camera or the skin's
/// base), at [`SHADOW_HEIGHTS`] and [`SHADOW_RADII`] times the skin's median range `scale_mm`
/// from the camera centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowRings {
    /// The camera centre, sensor frame, mm.
    pub centre_mm: [f64; 3],
    /// The optical axis, sensor frame (unit).
    pub axis: [f64; 3],
    /// The median distance from the camera centre to the reference skin, mm.
    pub scale_mm: f64,
}

impl ShadowRings {
    /// The rings of the camera whose rays are `rays`, seeing the reference skin `reference`.
    pub fn of(rays: &PixelRays, reference: &SurfaceHits) -> ShadowRings {
        let ranges: Vec<f64> = reference
            .t_mm
            .iter()
            .copied()
            .filter(|t| t.is_finite())
            .collect();
        ShadowRings {
            centre_mm: rays.origin_mm,
            axis: optical_axis(rays),
            scale_mm: median(ranges).unwrap_or(1.0),
        }
    }

    /// The candidate point lights of the light term, sensor frame, mm.
    fn point_lights(&self) -> [[f64; 3]; LIGHT_TERMS] {
        let (e1, e2) = self.frame();
        std::array::from_fn(|k| {
            let h = LIGHT_HEIGHTS[k / LIGHT_AZIMUTHS] * self.scale_mm;
            let r = LIGHT_RADIUS * self.scale_mm;
            let (sn, cs) = (std::f64::consts::TAU * (k % LIGHT_AZIMUTHS) as f64
                / LIGHT_AZIMUTHS as f64)
                .sin_cos();
            std::array::from_fn(|q| {
                self.centre_mm[q] + h * self.axis[q] + r * (cs * e1[q] + sn * e2[q])
            })
        })
    }

    /// Two unit vectors square to the axis and to each other: the rings' azimuth 0 and 90 deg.
    fn frame(&self) -> ([f64; 3], [f64; 3]) {
        let a = self.axis;
        let helper = if a[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = cross(a, helper);
        let l1 = dot(e1, e1).sqrt();
        let e1 = e1.map(|x| x / l1);
        (e1, cross(a, e1))
    }

    /// The sampled lights of ring `m` (height major, radius minor), sensor frame, mm: a ring
    /// at [`SHADOW_HEIGHTS`]`[m / 3]` and [`SHADOW_RADII`]`[m % 3]` times `scale_mm`.
    pub fn lights(&self, m: usize) -> [[f64; 3]; SHADOW_AZIMUTHS] {
        let a = self.axis;
        let (e1, e2) = self.frame();
        let h = SHADOW_HEIGHTS[m / SHADOW_RADII.len()] * self.scale_mm;
        let r = SHADOW_RADII[m % SHADOW_RADII.len()] * self.scale_mm;
        std::array::from_fn(|j| {
            let (sn, cs) = (std::f64::consts::TAU * j as f64 / SHADOW_AZIMUTHS as f64).sin_cos();
            std::array::from_fn(|q| self.centre_mm[q] + h * a[q] + r * (cs * e1[q] + sn * e2[q]))
        })
    }
}

/// The shadows the protrusions of a frame cast on its surface from the candidate rings: for
/// each pixel near a protrusion, per ring the share of the ring's light (each sampled light
/// weighted by its incidence cosine over the squared distance) that the protrusions block.
/// Pixels with no shadow are left out (sorted by pixel index).
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowMap {
    pub rings: ShadowRings,
    pub pixels: Vec<ShadowPixel>,
}

/// One shadowed pixel of a [`ShadowMap`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowPixel {
    /// Row-major pixel index.
    pub pixel: u32,
    /// Per candidate ring, the share of its light the protrusions block.
    pub rings: [f64; SHADOW_TERMS],
    /// Bit `k`: candidate point light `k` of the light term is blocked.
    pub blocked: u64,
}

impl ShadowMap {
    /// No shadow (the reference, or a frame without protrusions).
    pub fn none(rings: ShadowRings) -> ShadowMap {
        ShadowMap {
            rings,
            pixels: Vec::new(),
        }
    }

    /// The shadow features of pixel `i`, if it is shadowed.
    pub fn at(&self, i: usize) -> Option<&ShadowPixel> {
        self.pixels
            .binary_search_by_key(&(i as u32), |p| p.pixel)
            .ok()
            .map(|k| &self.pixels[k])
    }
}

/// The [`ShadowMap`] of the surface `hits` (seen along `rays`) under `protrusions`. Pixels
/// are computed in parallel; the map does not depend on the thread count.
pub fn shadow_map(
    rays: &PixelRays,
    hits: &SurfaceHits,
    protrusions: &ExactPrimitives,
    rings: &ShadowRings,
) -> ShadowMap {
    let lights: Vec<[[f64; 3]; SHADOW_AZIMUTHS]> =
        (0..SHADOW_TERMS).map(|m| rings.lights(m)).collect();
    let points = rings.point_lights();
    let reach = SHADOW_REACH * rings.scale_mm;
    let o = rays.origin_mm;
    let point = |i: usize| -> [f64; 3] {
        let (t, d) = (hits.t_mm[i], rays.dirs[i]);
        std::array::from_fn(|q| o[q] + t * d[q])
    };
    // Only what a protrusion pushes into the skin can shadow it from lights inside: each
    // primitive's dent is bounded by the contact points in its bounding sphere; a primitive
    // with none does not press the skin.
    let contact: Vec<[f64; 3]> = (0..hits.t_mm.len())
        .filter(|&i| hits.contact[i] && hits.t_mm[i].is_finite())
        .map(point)
        .collect();
    let dents: Vec<(usize, [f64; 3], f64)> = (0..protrusions.len())
        .filter_map(|k| {
            let (c, r) = protrusions.bounding_sphere_of(k);
            let inside: Vec<&[f64; 3]> = contact
                .iter()
                .filter(|q| {
                    let v = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
                    dot(v, v) <= r * r
                })
                .collect();
            if inside.is_empty() {
                return None;
            }
            let n = inside.len() as f64;
            let m: [f64; 3] = std::array::from_fn(|q| inside.iter().map(|p| p[q]).sum::<f64>() / n);
            let rad = inside
                .iter()
                .map(|p| {
                    let v = [p[0] - m[0], p[1] - m[1], p[2] - m[2]];
                    dot(v, v)
                })
                .fold(0.0, f64::max)
                .sqrt();
            Some((k, m, rad + DENT_MARGIN * rings.scale_mm))
        })
        .collect();
    let pixels = (0..hits.t_mm.len())
        .into_par_iter()
        .filter_map(|i| {
            if !hits.t_mm[i].is_finite() {
                return None;
            }
            let p = point(i);
            // the protrusions whose dents are near enough to shadow the point
            let near: Vec<&(usize, [f64; 3], f64)> = dents
                .iter()
                .filter(|(_, c, r)| {
                    let v = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                    dot(v, v).sqrt() <= r + reach
                })
                .collect();
            if near.is_empty() {
                return None;
            }
            // the camera's side of the surface: the elastomer's outward normal reversed
            let n = hits.normal[i].map(|v| -v);
            let start = [p[0] + 1e-6 * n[0], p[1] + 1e-6 * n[1], p[2] + 1e-6 * n[2]];
            // whether the segment to the light at `l` is blocked, and its weight
            let to = |l: &[f64; 3]| -> (bool, f64) {
                let v = [l[0] - p[0], l[1] - p[1], l[2] - p[2]];
                let dist = dot(v, v).sqrt();
                let u = v.map(|x| x / dist);
                let w = dot(n, u).max(0.0) / (dist * dist);
                if w <= 0.0 {
                    return (false, 0.0);
                }
                // only a dent the segment passes through can block it
                let crossed = near.iter().filter_map(|(k, c, r)| {
                    let v = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
                    let along = dot(v, u).clamp(0.0, dist);
                    let w = [
                        v[0] - along * u[0],
                        v[1] - along * u[1],
                        v[2] - along * u[2],
                    ];
                    (dot(w, w) <= r * r).then_some(*k)
                });
                let hit = protrusions
                    .first_crossing_among(start, u, dist, crossed)
                    .is_some();
                (hit, w)
            };
            let mut f = [0.0; SHADOW_TERMS];
            for (m, ring) in lights.iter().enumerate() {
                let (mut blocked, mut all) = (0.0, 0.0);
                for l in ring {
                    let (hit, w) = to(l);
                    all += w;
                    if hit {
                        blocked += w;
                    }
                }
                if all > 0.0 {
                    f[m] = blocked / all;
                }
            }
            let mut mask = 0u64;
            for (k, l) in points.iter().enumerate() {
                if to(l).0 {
                    mask |= 1 << k;
                }
            }
            (f.iter().any(|x| *x > 0.0) || mask != 0).then_some(ShadowPixel {
                pixel: i as u32,
                rings: f,
                blocked: mask,
            })
        })
        .collect();
    ShadowMap {
        rings: *rings,
        pixels,
    }
}

/// The spatial basis at pixel `i`: with `rho` its distance from the image centre over the
/// half-diagonal and `phi` its azimuth about it, the powers `rho^d` (d = 0 to
/// [`SPATIAL_DEGREE`]) and `rho^d cos(j phi)`, `rho^d sin(j phi)` (d = 1 to
/// [`SPATIAL_DEGREE`], j = 1 to [`ANGULAR_ORDER`]): smooth over the image, and able to follow
/// lights at a few azimuths.
fn spatial(i: usize, width: usize, height: usize) -> [f64; SPATIAL_TERMS] {
    let (hw, hh) = (0.5 * width as f64, 0.5 * height as f64);
    let s = hw.hypot(hh).max(1.0);
    let u = ((i % width) as f64 + 0.5 - hw) / s;
    let v = ((i / width) as f64 + 0.5 - hh) / s;
    let (rho, phi) = (u.hypot(v), v.atan2(u));
    let mut out = [0.0; SPATIAL_TERMS];
    let mut k = 0;
    for d in 0..=SPATIAL_DEGREE {
        let r = rho.powi(d as i32);
        out[k] = r;
        k += 1;
        if d == 0 {
            continue;
        }
        for j in (1..).take(ANGULAR_ORDER) {
            let (sn, cs) = (j as f64 * phi).sin_cos();
            out[k] = r * cs;
            out[k + 1] = r * sn;
            k += 2;
        }
    }
    out
}

/// The surface features of pixel `i` of a frame against the reference: the change of the
/// camera-side normal in the reference surface's local frame about the optical axis `axis`
/// (along the tangent away from the axis, along the tangent round it, along the normal) and
/// the indentation depth along the ray (mm); `None` off the skin. In that frame a ring of
/// lights about the axis gives coefficients that depend on the distance from the axis only.
fn features(
    i: usize,
    hits: &SurfaceHits,
    reference: &SurfaceHits,
    axis: [f64; 3],
) -> Option<[f64; FEATURES]> {
    let (t, t0) = (hits.t_mm[i], reference.t_mm[i]);
    if !t.is_finite() || !t0.is_finite() {
        return None;
    }
    // normals out of the elastomer: the camera's side is their negative
    let (n, n0) = (hits.normal[i], reference.normal[i]);
    let dn = [n0[0] - n[0], n0[1] - n[1], n0[2] - n[2]];
    let mut round = cross(axis, n0);
    let len = dot(round, round).sqrt();
    if len < 1e-9 {
        round = cross([1.0, 0.0, 0.0], n0);
        let l = dot(round, round).sqrt();
        round = round.map(|x| x / l);
    } else {
        round = round.map(|x| x / len);
    }
    let away = cross(n0, round);
    let (a, r) = (dot(dn, away), dot(dn, round));
    Some([
        a,
        r,
        dot(dn, n0),
        t0 - t,
        a * a,
        r * r,
        a * r,
        a * a * a,
        a * a * r,
        a * r * r,
        r * r * r,
    ])
}

/// The light features of pixel `i`: per candidate point light the change of its Lambertian
/// irradiance (incidence cosine over squared distance) from the reference surface to `hits`,
/// over the sum of all candidates' irradiance of the reference.
fn light_features(
    i: usize,
    rays: &PixelRays,
    hits: &SurfaceHits,
    reference: &SurfaceHits,
    lights: &[[f64; 3]; LIGHT_TERMS],
    blocked: u64,
) -> Option<[f64; LIGHT_TERMS]> {
    let (t, t0) = (hits.t_mm[i], reference.t_mm[i]);
    if !t.is_finite() || !t0.is_finite() {
        return None;
    }
    let (o, d) = (rays.origin_mm, rays.dirs[i]);
    let p: [f64; 3] = std::array::from_fn(|q| o[q] + t * d[q]);
    let p0: [f64; 3] = std::array::from_fn(|q| o[q] + t0 * d[q]);
    let (n, n0) = (hits.normal[i].map(|v| -v), reference.normal[i].map(|v| -v));
    let irr = |p: [f64; 3], n: [f64; 3], l: [f64; 3]| {
        let v = [l[0] - p[0], l[1] - p[1], l[2] - p[2]];
        let dd = dot(v, v);
        dot(n, v).max(0.0) / (dd * dd.sqrt())
    };
    let e0: [f64; LIGHT_TERMS] = std::array::from_fn(|k| irr(p0, n0, lights[k]));
    let sum: f64 = e0.iter().sum();
    if !(sum > 0.0) {
        return None;
    }
    Some(std::array::from_fn(|k| {
        let lit = if blocked & (1 << k) != 0 {
            0.0
        } else {
            irr(p, n, lights[k])
        };
        (lit - e0[k]) / sum
    }))
}

/// The camera's optical axis in the sensor frame: the direction of the ray nearest the image
/// centre.
fn optical_axis(rays: &PixelRays) -> [f64; 3] {
    let i = (rays.height / 2) * rays.width + rays.width / 2;
    let d = rays.dirs.get(i).copied().unwrap_or([0.0, 0.0, 1.0]);
    if d.iter().all(|x| x.is_finite()) {
        d
    } else {
        [0.0, 0.0, 1.0]
    }
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    Some(*m)
}

/// The gain of `image` against `reference` over the unpressed skin: the median ratio of the
/// green channel (or the first channel with light) where the reference is bright enough.
fn gain_of(image: &[[f64; 3]], reference: &[[f64; 3]], pressed: impl Fn(usize) -> bool) -> f64 {
    let ratios: Vec<f64> = (0..image.len())
        .filter(|&i| !pressed(i))
        .filter_map(|i| {
            let (a, r) = (image[i], reference[i]);
            let c = (0..3).max_by(|&x, &y| r[x].total_cmp(&r[y]))?;
            (r[c] >= MIN_REFERENCE_COUNTS && a[c].is_finite()).then(|| a[c] / r[c])
        })
        .collect();
    median(ratios).filter(|g| *g > 0.0).unwrap_or(1.0)
}

/// Why an image cannot serve the fit ([`image_fault`], [`capture_fault`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ImageFault {
    /// Fewer than half of the skin's pixels reach [`MIN_REFERENCE_COUNTS`] in any channel
    /// (`lit_share`: the share that do): a dark frame, a capture with the lights off.
    Dark { lit_share: f64 },
    /// More than half of the skin's pixels are at full scale in some channel
    /// (`saturated_share`): an overexposed or white frame.
    Saturated { saturated_share: f64 },
    /// The pressed pixels differ from the reference (at the capture's gain) by `imprint_counts`
    /// RMS over all channels, no more than [`IMPRINT_NOISE_FACTOR`] times the skin's noise
    /// elsewhere (`noise_counts`, robust standard deviation) or [`MIN_IMPRINT_COUNTS`]: the
    /// camera saw no imprint at the pins (a copy of the reference, an unpressed frame).
    NoImprint {
        imprint_counts: f64,
        noise_counts: f64,
    },
}

/// How far above the skin's noise a capture's pressed pixels must lie, RMS over the noise's
/// standard deviation: at 3 an unpressed frame of Gaussian noise passes about once in a few
/// hundred thousand pixels' worth, and a pin's imprint (tens of counts) is far above it.
pub const IMPRINT_NOISE_FACTOR: f64 = 3.0;

/// Least RMS difference from the reference over the pressed pixels, in 8-bit counts (scaled
/// to the image's full scale), for a capture to show an imprint.
pub const MIN_IMPRINT_COUNTS: f64 = 1.0;

impl std::fmt::Display for ImageFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            ImageFault::Dark { lit_share } => write!(
                f,
                "dark: {:.0}% of the skin's pixels reach {MIN_REFERENCE_COUNTS} counts, fewer than half (lights off or no exposure?)",
                100.0 * lit_share
            ),
            ImageFault::Saturated { saturated_share } => write!(
                f,
                "saturated: {:.0}% of the skin's pixels are at full scale, more than half (overexposed?)",
                100.0 * saturated_share
            ),
            ImageFault::NoImprint {
                imprint_counts,
                noise_counts,
            } => write!(
                f,
                "no imprint at its pins: the pressed pixels differ from the reference by {imprint_counts:.2} counts RMS, within {IMPRINT_NOISE_FACTOR} times the skin's noise elsewhere ({noise_counts:.2} counts) or {MIN_IMPRINT_COUNTS} count; a capture must show its pins pressed into the skin (a copy of the reference or an unpressed frame fits nothing)"
            ),
        }
    }
}

/// Whether `image` (row-major, per channel, counts of at most `full_scale`) is lit and not
/// overexposed over the skin (the pixels where `reference.t_mm` is finite).
///
/// # Errors
/// [`ImageFault::Dark`] or [`ImageFault::Saturated`]; none when no pixel sees the skin.
pub fn image_fault(
    reference: &SurfaceHits,
    image: &[[f64; 3]],
    full_scale: f64,
) -> Option<ImageFault> {
    let (mut skin, mut lit, mut saturated) = (0usize, 0usize, 0usize);
    for (t, px) in reference.t_mm.iter().zip(image) {
        if !t.is_finite() {
            continue;
        }
        skin += 1;
        lit += usize::from(px.iter().any(|&x| x >= MIN_REFERENCE_COUNTS));
        saturated += usize::from(px.iter().any(|&x| x >= full_scale));
    }
    if skin == 0 {
        return None;
    }
    let (lit_share, saturated_share) = (lit as f64 / skin as f64, saturated as f64 / skin as f64);
    if lit_share < 0.5 {
        Some(ImageFault::Dark { lit_share })
    } else if saturated_share > 0.5 {
        Some(ImageFault::Saturated { saturated_share })
    } else {
        None
    }
}

/// Whether `capture` can serve the fit against `reference_image` of the unpressed skin
/// `reference`: lit, not overexposed ([`image_fault`]), and showing its imprints: over the
/// pressed pixels (`capture.hits.contact`, lit and below full scale in both images) its
/// values divided by its gain differ from the reference's by more than
/// [`IMPRINT_NOISE_FACTOR`] times the noise of the unpressed, unshadowed skin (1.4826 times
/// the median absolute difference there) and more than [`MIN_IMPRINT_COUNTS`].
///
/// # Errors
/// The [`ImageFault`] found; none when the capture shows its imprints.
pub fn capture_fault(
    reference: &SurfaceHits,
    reference_image: &[[f64; 3]],
    capture: &Capture<'_>,
    full_scale: f64,
) -> Option<ImageFault> {
    if let Some(f) = image_fault(reference, capture.image, full_scale) {
        return Some(f);
    }
    let on_skin = |i: usize| reference.t_mm[i].is_finite();
    let gain = gain_of(capture.image, reference_image, |i| capture.hits.contact[i]);
    let shadowed: std::collections::HashSet<u32> =
        capture.shadows.pixels.iter().map(|p| p.pixel).collect();
    let usable = |i: usize| {
        (0..3).all(|c| {
            let (y, r) = (capture.image[i][c], reference_image[i][c]);
            y.is_finite() && r.is_finite() && y < full_scale && r < full_scale
        }) && reference_image[i]
            .iter()
            .any(|&r| r >= MIN_REFERENCE_COUNTS)
    };
    let (mut pressed_sq, mut pressed_n) = (0.0, 0usize);
    let mut quiet: Vec<f64> = Vec::new();
    for i in (0..capture.image.len()).filter(|&i| on_skin(i) && usable(i)) {
        let d: [f64; 3] =
            std::array::from_fn(|c| capture.image[i][c] / gain - reference_image[i][c]);
        if capture.hits.contact[i] {
            pressed_sq += d.iter().map(|x| x * x).sum::<f64>();
            pressed_n += 3;
        } else if !shadowed.contains(&(i as u32)) {
            quiet.extend(d);
        }
    }
    let imprint_counts = if pressed_n == 0 {
        0.0
    } else {
        (pressed_sq / pressed_n as f64).sqrt()
    };
    let noise_counts = median(quiet.iter().map(|x| x.abs()).collect()).unwrap_or(0.0) * 1.4826;
    let floor = MIN_IMPRINT_COUNTS * full_scale / 255.0;
    (imprint_counts <= (IMPRINT_NOISE_FACTOR * noise_counts).max(floor)).then_some(
        ImageFault::NoImprint {
            imprint_counts,
            noise_counts,
        },
    )
}

impl PhotometricModel {
    /// Fits the model of the camera whose rays are `rays`, from its `reference_image` of the
    /// unindented skin (whose surface is `reference`) and `captures`, whose values are
    /// counts of at most `full_scale` (255 for 8-bit images): saturated pixels are left out of
    /// the fit.
    ///
    /// # Errors
    /// A message when the sizes disagree, when the reference is dark or saturated or a
    /// capture shows no imprint ([`capture_fault`]), or when the captures hold fewer pressed
    /// pixels than twice the unknowns (too few imprints to fit the response to tilt).
    pub fn fit(
        rays: &PixelRays,
        reference: &SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &[Capture<'_>],
        full_scale: f64,
    ) -> Result<PhotometricModel, String> {
        let (w, h) = (rays.width, rays.height);
        let n = w * h;
        if reference_image.len() != n || reference.t_mm.len() != n {
            return Err(format!(
                "the reference image has {} pixels, the camera {w} x {h} = {n}",
                reference_image.len()
            ));
        }
        for (k, c) in captures.iter().enumerate() {
            if c.image.len() != n || c.hits.t_mm.len() != n {
                return Err(format!(
                    "capture {k}: {} pixels, the camera {w} x {h} = {n}",
                    c.image.len()
                ));
            }
        }
        if let Some(f) = image_fault(reference, reference_image, full_scale) {
            return Err(format!("the reference image is {f}"));
        }
        for (k, c) in captures.iter().enumerate() {
            if let Some(f) = capture_fault(reference, reference_image, c, full_scale) {
                return Err(format!("capture {k}: {f}"));
            }
        }
        let on_skin = |i: usize| reference.t_mm[i].is_finite();
        let axis = optical_axis(rays);
        let rings = ShadowRings::of(rays, reference);
        if let Some(k) = captures.iter().position(|c| c.shadows.rings != rings) {
            return Err(format!(
                "capture {k}: its shadows are of other light rings than this camera's"
            ));
        }
        let gains: Vec<f64> = captures
            .iter()
            .map(|c| gain_of(c.image, reference_image, |i| c.hits.contact[i]))
            .collect();
        // The unindented appearance: per pixel and channel, the median of the reference and
        // every capture's unpressed value divided by its gain (a highlight or a speck that only
        // one image shows does not move it; with no capture unpressed there, the reference).
        let appearance: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                if !on_skin(i) {
                    return [f64::NAN; 3];
                }
                std::array::from_fn(|ch| {
                    let mut v: Vec<f64> = std::iter::once(reference_image[i][ch])
                        .chain(
                            captures
                                .iter()
                                .zip(&gains)
                                .filter(|(c, _)| !c.hits.contact[i])
                                .map(|(c, g)| c.image[i][ch] / g),
                        )
                        .collect();
                    crate::median_sorting(&mut v)
                })
            })
            .collect();
        // The response to tilt and the shadows, by least squares on the pressed and the
        // shadowed pixels of every capture.
        let tilt_unknowns = COEFFICIENTS;
        let unknowns = tilt_unknowns + SHADOW_TERMS;
        let lights = rings.point_lights();
        let mut rows: Vec<(usize, usize, Option<&ShadowPixel>)> = Vec::new();
        let mut pressed = 0;
        for (k, c) in captures.iter().enumerate() {
            let mut shadowed = c.shadows.pixels.iter().peekable();
            for i in 0..n {
                let mut sh = None;
                while let Some(sp) = shadowed.peek() {
                    let j = sp.pixel as usize;
                    if j < i {
                        shadowed.next();
                    } else {
                        if j == i {
                            sh = Some(*sp);
                        }
                        break;
                    }
                }
                if on_skin(i) && (c.hits.contact[i] || sh.is_some()) {
                    pressed += usize::from(c.hits.contact[i]);
                    rows.push((k, i, sh));
                }
            }
        }
        if pressed < 2 * unknowns {
            return Err(format!(
                "the captures press {} pixels of the skin, fewer than the {} the fit needs (twice its {unknowns} unknowns): give captures with more imprints",
                pressed,
                2 * unknowns
            ));
        }
        let mut coefficients: [Vec<f64>; 3] = Default::default();
        let mut shadow_coefficients = [[0.0; SHADOW_TERMS]; 3];
        for (ch, coef) in coefficients.iter_mut().enumerate() {
            let mut ata = DMatrix::<f64>::zeros(unknowns, unknowns);
            let mut atb = DVector::<f64>::zeros(unknowns);
            let mut row = vec![0.0; unknowns];
            let mut nonzero: Vec<usize> = Vec::with_capacity(unknowns);
            for &(k, i, sh) in &rows {
                let r = appearance[i][ch];
                let y_counts = captures[k].image[i][ch];
                if !(r >= MIN_REFERENCE_COUNTS)
                    || y_counts >= full_scale
                    || r * gains[k] >= full_scale
                {
                    continue;
                }
                let Some(f) = features(i, captures[k].hits, reference, axis) else {
                    continue;
                };
                let p = spatial(i, w, h);
                for (a, fa) in f.iter().enumerate() {
                    for (m, pm) in p.iter().enumerate() {
                        row[a * SPATIAL_TERMS + m] = fa * pm;
                    }
                }
                let lf = light_features(
                    i,
                    rays,
                    captures[k].hits,
                    reference,
                    &lights,
                    sh.map_or(0, |f| f.blocked),
                )
                .unwrap_or([0.0; LIGHT_TERMS]);
                row[FEATURES * SPATIAL_TERMS..tilt_unknowns].copy_from_slice(&lf);
                for (m, x) in row[tilt_unknowns..].iter_mut().enumerate() {
                    *x = -sh.map_or(0.0, |f| f.rings[m]);
                }
                // the ratio's change, weighted by the reference so that each row counts in
                // grey levels
                let y = y_counts / (gains[k] * r) - 1.0;
                let wgt = r * r;
                // an unpressed pixel's row has only its shadow terms
                nonzero.clear();
                nonzero.extend((0..unknowns).filter(|&a| row[a] != 0.0));
                for (j, &a) in nonzero.iter().enumerate() {
                    atb[a] += wgt * row[a] * y;
                    for &b in &nonzero[j..] {
                        ata[(a, b)] += wgt * row[a] * row[b];
                    }
                }
            }
            for a in 0..unknowns {
                for b in 0..a {
                    ata[(a, b)] = ata[(b, a)];
                }
            }
            // a channel without light (all pixels below the floor) keeps zero coefficients
            let x = ata
                .clone()
                .cholesky()
                .map(|c| c.solve(&atb))
                .or_else(|| ata.svd(true, true).solve(&atb, 1e-12).ok())
                .unwrap_or_else(|| DVector::zeros(unknowns));
            *coef = x.iter().take(tilt_unknowns).copied().collect();
            shadow_coefficients[ch] = std::array::from_fn(|m| x[tilt_unknowns + m]);
        }
        let mut model = PhotometricModel {
            width: w,
            height: h,
            reference: appearance,
            coefficients,
            axis,
            rings,
            shadow_coefficients,
            gains: gains.clone(),
            full_scale,
            residual_rms: Vec::new(),
        };
        model.residual_rms = captures
            .iter()
            .zip(&gains)
            .map(|(c, g)| {
                rms_over_skin(
                    &model.render(rays, reference, c.hits, c.shadows, *g),
                    c.image,
                )
            })
            .collect();
        Ok(model)
    }

    /// The model's section of photometric.json (`fabkit calibrate photometric`): the basis
    /// (feature names and counts, the candidate lights and rings), the optical axis, the full
    /// scale and the coefficients per channel. The appearance goes to its own file
    /// (appearance.npy, (H, W, 3) float32).
    pub fn model_json(&self) -> serde_json::Value {
        serde_json::json!({
            "features": ["a", "r", "c", "depth_mm", "a^2", "r^2", "a r", "a^3", "a^2 r", "a r^2", "r^3"],
            "feature_count": FEATURES, "spatial_degree": SPATIAL_DEGREE, "angular_order": ANGULAR_ORDER,
            "spatial_terms": SPATIAL_TERMS, "optical_axis": self.axis, "full_scale_counts": self.full_scale,
            "coefficients_rgb": self.coefficients, "appearance": "appearance.npy",
            "light_terms": LIGHT_TERMS, "shadow_terms": SHADOW_TERMS, "shadow_azimuths": SHADOW_AZIMUTHS,
            "lights": {"heights": LIGHT_HEIGHTS, "radius": LIGHT_RADIUS, "azimuths": LIGHT_AZIMUTHS,
                       "notes": "candidate point lights l = h x azimuths + j at height heights[h] x scale_mm along the axis from the camera centre and radius radius x scale_mm, azimuth j x 360 / azimuths deg from the axis x e1 with e1 = axis x (x or y); scale_mm and centre_mm as in shadow.rings"},
            "shadow": {
                "rings": {"centre_mm": self.rings.centre_mm, "axis": self.rings.axis, "scale_mm": self.rings.scale_mm,
                          "heights": SHADOW_HEIGHTS, "radii": SHADOW_RADII,
                          "notes": "candidate rings of effective lights about the optical axis, ring m at height heights[m / 3] x scale_mm along the axis from the camera centre (centre_mm) and radius radii[m % 3] x scale_mm, each sampled by shadow_azimuths lights; scale_mm is the skin's median range"},
                "coefficients_rgb": self.shadow_coefficients,
            },
        })
    }

    /// The model `fabkit calibrate photometric` wrote to `dir` (photometric.json and the
    /// (H, W, 3) float32 appearance.npy), the sha256 of its photometric.json, and the inputs
    /// it records it was fitted with ([`FittedWith`]).
    ///
    /// # Errors
    /// A message naming the file and what does not fit: unreadable, not JSON, an appearance
    /// that is not (H, W, 3) float32, or what [`Self::from_json`] refuses.
    pub fn read(dir: &std::path::Path) -> Result<(PhotometricModel, String, FittedWith), String> {
        use crate::groundtruth::inputs::read_with_hash;
        let jpath = dir.join("photometric.json");
        let (bytes, sha) = read_with_hash(&jpath).map_err(|e| e.to_string())?;
        let text = quote_non_finite(&String::from_utf8_lossy(&bytes));
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not JSON: {e}", jpath.display()))?;
        let apath = dir.join("appearance.npy");
        let (abytes, _) = read_with_hash(&apath).map_err(|e| e.to_string())?;
        let (shape, data) = fabkit_export::raster::read_npy_f32(&abytes)
            .map_err(|e| format!("{}: {e}", apath.display()))?;
        let [h, w, 3] = shape[..] else {
            return Err(format!(
                "{}: shape {shape:?}, not (H, W, 3)",
                apath.display()
            ));
        };
        let appearance = data
            .chunks_exact(3)
            .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])])
            .collect();
        let model = PhotometricModel::from_json(&v["model"], appearance, w, h)
            .map_err(|e| format!("{}: {e}", jpath.display()))?;
        let fitted = FittedWith::of_record(&v, jpath.display().to_string());
        Ok((model, sha, fitted))
    }

    /// The model from its section of photometric.json ([`Self::model_json`]) and its
    /// appearance (row-major, `width` x `height`, counts; NaN off the skin).
    ///
    /// # Errors
    /// A message naming the key (`model.<key>`), the value and the rule: another basis than
    /// this fabkit's (fit the model again), coefficients of another length, an axis, ring or
    /// full scale that is not one, an appearance of another size.
    pub fn from_json(
        model: &serde_json::Value,
        appearance: Vec<[f64; 3]>,
        width: usize,
        height: usize,
    ) -> Result<PhotometricModel, String> {
        use serde_json::from_value;
        let m = model;
        let basis = [
            ("feature_count", FEATURES),
            ("spatial_degree", SPATIAL_DEGREE),
            ("angular_order", ANGULAR_ORDER),
            ("spatial_terms", SPATIAL_TERMS),
            ("shadow_terms", SHADOW_TERMS),
            ("light_terms", LIGHT_TERMS),
            ("shadow_azimuths", SHADOW_AZIMUTHS),
        ];
        for (key, want) in basis {
            if m[key].as_u64() != Some(want as u64) {
                return Err(format!(
                    "model.{key} = {}: this fabkit's model has {want} (fit it again with this version)",
                    m[key]
                ));
            }
        }
        // the candidate lights and rings the basis is made of
        let lights_basis = [
            (
                "lights.heights",
                &m["lights"]["heights"],
                serde_json::json!(LIGHT_HEIGHTS),
            ),
            (
                "lights.radius",
                &m["lights"]["radius"],
                serde_json::json!(LIGHT_RADIUS),
            ),
            (
                "lights.azimuths",
                &m["lights"]["azimuths"],
                serde_json::json!(LIGHT_AZIMUTHS),
            ),
            (
                "shadow.rings.heights",
                &m["shadow"]["rings"]["heights"],
                serde_json::json!(SHADOW_HEIGHTS),
            ),
            (
                "shadow.rings.radii",
                &m["shadow"]["rings"]["radii"],
                serde_json::json!(SHADOW_RADII),
            ),
        ];
        for (key, have, want) in lights_basis {
            if *have != want {
                return Err(format!(
                    "model.{key} = {have}: this fabkit's model has {want} (fit it again with this version)"
                ));
            }
        }
        let coefficients: [Vec<f64>; 3] = from_value(m["coefficients_rgb"].clone())
            .ok()
            .filter(|c: &[Vec<f64>; 3]| c.iter().all(|x| x.len() == COEFFICIENTS))
            .ok_or_else(|| {
                format!("model.coefficients_rgb must be 3 lists of {COEFFICIENTS} numbers")
            })?;
        let axis: [f64; 3] = from_value(m["optical_axis"].clone())
            .map_err(|_| "model.optical_axis must be 3 numbers".to_string())?;
        let shadow_coefficients: [[f64; SHADOW_TERMS]; 3] =
            from_value(m["shadow"]["coefficients_rgb"].clone()).map_err(|_| {
                format!("model.shadow.coefficients_rgb must be 3 lists of {SHADOW_TERMS} numbers")
            })?;
        let ring = &m["shadow"]["rings"];
        let rings = match (
            from_value::<[f64; 3]>(ring["centre_mm"].clone()),
            from_value::<[f64; 3]>(ring["axis"].clone()),
            ring["scale_mm"].as_f64().filter(|x| *x > 0.0),
        ) {
            (Ok(centre_mm), Ok(axis), Some(scale_mm)) => ShadowRings {
                centre_mm,
                axis,
                scale_mm,
            },
            _ => {
                return Err("model.shadow.rings must hold centre_mm and axis (3 numbers each) and scale_mm (above 0)".into())
            }
        };
        let full_scale = m["full_scale_counts"]
            .as_f64()
            .filter(|f| *f == 255.0 || *f == 65535.0)
            .ok_or_else(|| "model.full_scale_counts must be 255 or 65535".to_string())?;
        check_model_values(&coefficients, axis, &shadow_coefficients, &rings)?;
        if appearance.len() != width * height {
            return Err(format!(
                "the appearance has {} pixels, the camera {width} x {height}",
                appearance.len()
            ));
        }
        if let Some((k, c, v)) = appearance.iter().enumerate().find_map(|(k, p)| {
            (0..3)
                .find(|&c| {
                    !(p[c].is_nan() || (0.0..=APPEARANCE_HEADROOM * full_scale).contains(&p[c]))
                })
                .map(|c| (k, c, p[c]))
        }) {
            return Err(format!(
                "appearance.npy: pixel ({}, {}) channel {c} = {v}: must be NaN (off the skin) or a count from 0 to {} ({APPEARANCE_HEADROOM} x the full scale {full_scale}: the captures over their gains)",
                k % width.max(1),
                k / width.max(1),
                APPEARANCE_HEADROOM * full_scale
            ));
        }
        Ok(PhotometricModel {
            width,
            height,
            reference: appearance,
            coefficients,
            axis,
            rings,
            shadow_coefficients,
            gains: Vec::new(),
            full_scale,
            residual_rms: Vec::new(),
        })
    }

    /// The model's image of the surface `hits` (seen along `rays`; `reference` the
    /// unindented one) pressed by `protrusions` (their shadows computed here): [`Self::render`]
    /// at gain 1, rounded to counts, 0 off the skin. The model's mean image: no noise.
    pub fn image(
        &self,
        rays: &PixelRays,
        reference: &SurfaceHits,
        hits: &SurfaceHits,
        protrusions: Option<&ExactPrimitives>,
    ) -> Vec<[u16; 3]> {
        let shadows = match protrusions {
            Some(p) => shadow_map(rays, hits, p, &self.rings),
            None => ShadowMap::none(self.rings),
        };
        let full = self.full_scale;
        self.render(rays, reference, hits, &shadows, 1.0)
            .into_iter()
            .map(|p| {
                p.map(|x| {
                    if x.is_finite() {
                        x.round().clamp(0.0, full) as u16
                    } else {
                        0
                    }
                })
            })
            .collect()
    }

    /// The gain of `image` (a capture whose surface is `hits`) against the model's appearance:
    /// the median ratio over its unpressed skin, for re-rendering it.
    pub fn gain_of(&self, image: &[[f64; 3]], hits: &SurfaceHits) -> f64 {
        gain_of(image, &self.reference, |i| hits.contact[i])
    }

    /// The image (row-major, per channel, counts clipped to the full scale; NaN off the skin)
    /// of the surface `hits` (the reference's, or indented: its contact pixels follow the
    /// model) with the protrusions' `shadows` ([`shadow_map`] of the model's rings; those of
    /// other rings are ignored) at `gain`.
    pub fn render(
        &self,
        rays: &PixelRays,
        reference: &SurfaceHits,
        hits: &SurfaceHits,
        shadows: &ShadowMap,
        gain: f64,
    ) -> Vec<[f64; 3]> {
        let same_rings = shadows.rings == self.rings;
        let lights = self.rings.point_lights();
        (0..self.width * self.height)
            .map(|i| {
                let r = self.reference[i];
                let plain = || r.map(|x| (gain * x).clamp(0.0, self.full_scale));
                let sh = if same_rings { shadows.at(i) } else { None };
                if !hits.contact[i] && sh.is_none() {
                    return plain();
                }
                let Some(f) = features(i, hits, reference, self.axis) else {
                    return plain();
                };
                let p = spatial(i, self.width, self.height);
                let lf = light_features(
                    i,
                    rays,
                    hits,
                    reference,
                    &lights,
                    sh.map_or(0, |f| f.blocked),
                )
                .unwrap_or([0.0; LIGHT_TERMS]);
                std::array::from_fn(|ch| {
                    let c = &self.coefficients[ch];
                    let mut s = 0.0;
                    for (a, fa) in f.iter().enumerate() {
                        for (m, pm) in p.iter().enumerate() {
                            s += c[a * SPATIAL_TERMS + m] * fa * pm;
                        }
                    }
                    for (k, x) in lf.iter().enumerate() {
                        s += c[FEATURES * SPATIAL_TERMS + k] * x;
                    }
                    if let Some(sh) = sh {
                        s -= sh
                            .rings
                            .iter()
                            .zip(&self.shadow_coefficients[ch])
                            .map(|(x, b)| x * b)
                            .sum::<f64>();
                    }
                    (gain * r[ch] * (1.0 + s)).clamp(0.0, self.full_scale)
                })
            })
            .collect()
    }
}

/// JSON `text` with the numbers JSON cannot hold quoted as strings: the `NaN`, `Infinity` and
/// `-Infinity` that Python's `json` module writes, and numbers past the f64 range (`1e999`).
/// The model's reader then names the field that holds one (a number is expected there)
/// instead of failing on the syntax.
pub fn quote_non_finite(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let (mut i, mut start) = (0, 0);
    let mut in_string = false;
    while i < b.len() {
        let c = b[i];
        if in_string {
            match c {
                b'\\' => i += 1,
                b'"' => in_string = false,
                _ => {}
            }
            i += 1;
            continue;
        }
        let word = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|w| b[i..].starts_with(w.as_bytes()));
        let token = if let Some(w) = word {
            Some(w.len())
        } else if c == b'-' || c.is_ascii_digit() {
            let n = b[i..]
                .iter()
                .take_while(|x| x.is_ascii_digit() || matches!(x, b'-' | b'+' | b'.' | b'e' | b'E'))
                .count();
            // the token's bytes are ASCII: a char boundary on both sides
            let finite = text[i..i + n].parse::<f64>().is_ok_and(f64::is_finite);
            if finite {
                i += n;
                continue;
            }
            Some(n)
        } else {
            None
        };
        match token {
            Some(n) => {
                out.push_str(&text[start..i]);
                out.push('"');
                out.push_str(&text[i..i + n]);
                out.push('"');
                i += n;
                start = i;
            }
            None => {
                in_string = c == b'"';
                i += 1;
            }
        }
    }
    out.push_str(&text[start..]);
    out
}

/// The inputs a model was fitted with, as `fabkit calibrate photometric` records them in
/// photometric.json: per input (`design`, `camera`, `extrinsics`), its name or file and its
/// sha256. A model belongs to one sensor, camera and pose.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FittedWith {
    /// (input, name or file, sha256), in the record's order.
    pub inputs: Vec<(String, String, String)>,
    /// The record, for messages.
    pub file: String,
}

impl FittedWith {
    /// The inputs recorded in photometric.json's record `v` (none for a record without
    /// them), `file` naming it in messages.
    pub fn of_record(v: &serde_json::Value, file: String) -> FittedWith {
        let inputs = ["design", "camera", "extrinsics"]
            .iter()
            .filter_map(|&key| {
                let sha = v[key]["sha256"].as_str()?;
                let name = v[key]["name"]
                    .as_str()
                    .or(v[key]["file"].as_str())
                    .unwrap_or("?");
                Some((key.to_string(), name.to_string(), sha.to_string()))
            })
            .collect();
        FittedWith { inputs, file }
    }

    /// Refuses `input` (`design`, `camera` or `extrinsics`) with sha256 `sha`, named `ours`
    /// (a file or a design), when the model was fitted with another.
    ///
    /// # Errors
    /// Naming the record, the input, both names and both hashes (first 12 digits).
    pub fn check(&self, input: &str, sha: &str, ours: &str) -> Result<(), String> {
        let Some((_, name, theirs)) = self.inputs.iter().find(|(k, _, _)| k == input) else {
            return Ok(());
        };
        if theirs == sha {
            return Ok(());
        }
        let short = |s: &str| s.chars().take(12).collect::<String>();
        Err(format!(
            "{}: the model was fitted with another {input} ({name}, sha256 {}...), not {ours} (sha256 {}...): a photometric model belongs to one sensor, camera and pose; fit one for these with fabkit calibrate photometric",
            self.file,
            short(theirs),
            short(sha)
        ))
    }
}

/// Root-mean-square difference of `a` and `b` over the pixels where `a` is finite, all
/// channels, counts.
pub fn rms_over_skin(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for (x, y) in a.iter().zip(b) {
        for c in 0..3 {
            if x[c].is_finite() && y[c].is_finite() {
                s += (x[c] - y[c]).powi(2);
                n += 1;
            }
        }
    }
    if n == 0 {
        0.0
    } else {
        (s / n as f64).sqrt()
    }
}

/// How far above the full scale an appearance value may lie: the appearance is the captures'
/// counts over their gains, and a gain below 1 lifts a saturated pixel past the full scale.
pub const APPEARANCE_HEADROOM: f64 = 16.0;

/// Largest coefficient a model may hold: a coefficient is the relative change of a pixel's
/// intensity per unit of its feature (or the share of its light a ring or a light stands
/// for), so past it every pressed pixel saturates; fits give values of order 1.
pub const MAX_COEFFICIENT: f64 = 1000.0;

/// Shortest and longest median range from the camera to the skin a model may hold, mm.
pub const SCALE_RANGE_MM: (f64, f64) = (0.1, 1000.0);

/// The numbers of a model read back ([`PhotometricModel::from_json`]): coefficients finite and
/// within [`MAX_COEFFICIENT`], the axes unit vectors, the rings' centre finite and within
/// 1000 mm, their scale within [`SCALE_RANGE_MM`]. Names the first value that is not.
fn check_model_values(
    coefficients: &[Vec<f64>; 3],
    axis: [f64; 3],
    shadow_coefficients: &[[f64; SHADOW_TERMS]; 3],
    rings: &ShadowRings,
) -> Result<(), String> {
    let lists = coefficients
        .iter()
        .enumerate()
        .flat_map(|(c, l)| {
            l.iter()
                .enumerate()
                .map(move |(k, x)| (format!("coefficients_rgb[{c}][{k}]"), *x))
        })
        .chain(shadow_coefficients.iter().enumerate().flat_map(|(c, l)| {
            l.iter()
                .enumerate()
                .map(move |(k, x)| (format!("shadow.coefficients_rgb[{c}][{k}]"), *x))
        }));
    for (key, x) in lists {
        if !(x.is_finite() && x.abs() <= MAX_COEFFICIENT) {
            return Err(format!(
                "model.{key} = {x}: must be a finite number within +-{MAX_COEFFICIENT} (a relative change of the intensity; past it every pressed pixel saturates): not a model fabkit fits"
            ));
        }
    }
    for (key, a) in [("optical_axis", axis), ("shadow.rings.axis", rings.axis)] {
        let n = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(a.iter().all(|x| x.is_finite()) && (n - 1.0).abs() <= 1e-6) {
            return Err(format!(
                "model.{key} = {a:?}: must be a unit vector (length {n})"
            ));
        }
    }
    let max = fabkit_designs::values::MAX_LENGTH_MM;
    if let Some(x) = rings
        .centre_mm
        .iter()
        .find(|x| !(x.is_finite() && x.abs() <= max))
    {
        return Err(format!(
            "model.shadow.rings.centre_mm = {:?}: each coordinate must be finite and within +-{max} mm ({x})",
            rings.centre_mm
        ));
    }
    let (lo, hi) = SCALE_RANGE_MM;
    if !(lo..=hi).contains(&rings.scale_mm) {
        return Err(format!(
            "model.shadow.rings.scale_mm = {}: must be from {lo} to {hi} mm (the skin's median range from the camera)",
            rings.scale_mm
        ));
    }
    Ok(())
}
