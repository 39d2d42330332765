//! The model's terms: their counts and the candidate lights' and rings' placement; their
//! values at a pixel (the spatial basis, the surface features and the candidate point lights'
//! features); and the optical axis, the medians and the gains they are measured with.

use crate::groundtruth::hits::SurfaceHits;
use crate::groundtruth::rays::PixelRays;
use fabkit_designs::primitives::{cross, dot};

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
pub(super) const DENT_MARGIN: f64 = 0.02;

/// Least reference intensity (counts) of a pixel used to fit or to measure a gain: darker
/// pixels carry mostly noise in a ratio.
pub const MIN_REFERENCE_COUNTS: f64 = 8.0;

/// The spatial basis at pixel `i`: with `rho` its distance from the image centre over the
/// half-diagonal and `phi` its azimuth about it, the powers `rho^d` (d = 0 to
/// [`SPATIAL_DEGREE`]) and `rho^d cos(j phi)`, `rho^d sin(j phi)` (d = 1 to
/// [`SPATIAL_DEGREE`], j = 1 to [`ANGULAR_ORDER`]): smooth over the image, and able to follow
/// lights at a few azimuths.
pub(super) fn spatial(i: usize, width: usize, height: usize) -> [f64; SPATIAL_TERMS] {
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
pub(super) fn features(
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
pub(super) fn light_features(
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
pub(super) fn optical_axis(rays: &PixelRays) -> [f64; 3] {
    let i = (rays.height / 2) * rays.width + rays.width / 2;
    let d = rays.dirs.get(i).copied().unwrap_or([0.0, 0.0, 1.0]);
    if d.iter().all(|x| x.is_finite()) {
        d
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// The median of `v` (of an even count, the upper of the middle two); `None` when empty.
pub(super) fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    Some(*m)
}

/// A quick gain of `image` against `reference` over the unpressed skin, for the check that a
/// capture shows its imprints ([`super::faults::capture_fault`], which knows no image size):
/// the median ratio of the brightest channel where the reference is bright enough. The fit
/// and the renderings use the least-squares gain far from the imprints
/// ([`super::contact::capture_gain`]).
pub(super) fn median_gain(
    image: &[[f64; 3]],
    reference: &[[f64; 3]],
    pressed: impl Fn(usize) -> bool,
) -> f64 {
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
