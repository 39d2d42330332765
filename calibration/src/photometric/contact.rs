//! The skin near a capture's imprints and far from them ([`ImprintMap`]): each capture's gain
//! measured on the skin far from every imprint ([`PhotometricModel::gain_of`]), and the fit
//! judged where the pins press ([`PhotometricModel::contact_region`]): the RMS within a
//! stated distance of each imprint and the offset between the centroids of the real and the
//! rendered darkening.

use super::model::{Capture, PhotometricModel};
use super::terms::{median, MIN_REFERENCE_COUNTS};
use crate::groundtruth::hits::SurfaceHits;

/// How far from every imprint (px, to the nearest pressed pixel) a pixel must lie to serve a
/// capture's gain, besides being unshadowed: twice [`CONTACT_REACH_PX`], past the rim a real
/// skin's bulge and the pins' penumbrae reach on R-Tac0's 640 x 480 captures (an imprint is
/// about 10 px across there).
pub const GAIN_CLEARANCE_PX: f64 = 30.0;

/// Default distance from an imprint (px, to its nearest pressed pixel) within which the fit is
/// judged where the pins press ([`PhotometricModel::contact_region`]).
pub const CONTACT_REACH_PX: f64 = 15.0;

/// Outliers of the gain's least squares: pixel values further than this many robust standard
/// deviations from the first estimate (LED highlights that move between images, specks) are
/// left out of the second.
pub const GAIN_OUTLIER_SIGMAS: f64 = 4.0;

/// Darkening below this many standard deviations of a capture's noise (measured on its skin far
/// from the imprints) does not weigh in an imprint's centroid, in the capture or its rendering.
pub const DARKENING_NOISE_SIGMAS: f64 = 3.0;

/// Least pixel channels far from the imprints for the gain to be measured there; with fewer,
/// every unpressed, unshadowed pixel serves.
const MIN_GAIN_SAMPLES: usize = 300;

/// The imprints of one capture (8-connected components of its pressed pixels, numbered in
/// raster order of their first pixel) and, for every pixel within reach of one, which imprint
/// is nearest and how far, px (Euclidean distance between pixel centres, to the nearest
/// pressed pixel; 0 on the imprint).
#[derive(Debug, Clone)]
pub struct ImprintMap {
    pub width: usize,
    pub height: usize,
    /// How far from the imprints the distances are measured, px.
    pub reach_px: f64,
    /// Per imprint, the centroid of its pressed pixels, px.
    pub centres_px: Vec<[f64; 2]>,
    /// Per imprint, its pressed pixels.
    pub pressed: Vec<usize>,
    nearest: Vec<u32>,
    dist2: Vec<f64>,
}

impl ImprintMap {
    /// The imprints of `contact` (row-major, `width` x `height`), distances measured up to
    /// `reach_px`. Ties between imprints go to the one whose rim pixel comes first in raster
    /// order: the map depends on the pixels only.
    pub fn of(contact: &[bool], width: usize, height: usize, reach_px: f64) -> ImprintMap {
        let n = width * height;
        let pressed_at = |i: usize| contact.get(i).copied().unwrap_or(false);
        let mut nearest = vec![u32::MAX; n];
        let mut dist2 = vec![f64::INFINITY; n];
        let mut sums: Vec<[f64; 3]> = Vec::new();
        // the imprints: 8-connected components, by flood fill in raster order
        let mut stack = Vec::new();
        for start in 0..n {
            if !pressed_at(start) || nearest[start] != u32::MAX {
                continue;
            }
            let label = sums.len() as u32;
            let mut s = [0.0; 3];
            nearest[start] = label;
            stack.push(start);
            while let Some(i) = stack.pop() {
                dist2[i] = 0.0;
                let (u, v) = (i % width, i / width);
                s[0] += u as f64;
                s[1] += v as f64;
                s[2] += 1.0;
                for dv in -1i64..=1 {
                    for du in -1i64..=1 {
                        let (uu, vv) = (u as i64 + du, v as i64 + dv);
                        if uu < 0 || vv < 0 || uu >= width as i64 || vv >= height as i64 {
                            continue;
                        }
                        let j = vv as usize * width + uu as usize;
                        if pressed_at(j) && nearest[j] == u32::MAX {
                            nearest[j] = label;
                            stack.push(j);
                        }
                    }
                }
            }
            sums.push(s);
        }
        // the distances: the nearest pressed pixel of an unpressed one is on an imprint's rim
        // (a pressed pixel with an unpressed 4-neighbour), so only the rims spread
        let r = reach_px.max(0.0).floor() as i64;
        let r2 = reach_px.max(0.0).powi(2);
        for b in 0..n {
            if !pressed_at(b) {
                continue;
            }
            let (u, v) = ((b % width) as i64, (b / width) as i64);
            let rim = [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
                .iter()
                .any(|&(du, dv)| {
                    let (uu, vv) = (u + du, v + dv);
                    uu >= 0
                        && vv >= 0
                        && uu < width as i64
                        && vv < height as i64
                        && !pressed_at(vv as usize * width + uu as usize)
                });
            if !rim {
                continue;
            }
            let label = nearest[b];
            for dv in -r..=r {
                let vv = v + dv;
                if vv < 0 || vv >= height as i64 {
                    continue;
                }
                for du in -r..=r {
                    let uu = u + du;
                    let d2 = (du * du + dv * dv) as f64;
                    if uu < 0 || uu >= width as i64 || d2 > r2 {
                        continue;
                    }
                    let j = vv as usize * width + uu as usize;
                    if d2 < dist2[j] {
                        dist2[j] = d2;
                        nearest[j] = label;
                    }
                }
            }
        }
        let mut pressed = vec![0; sums.len()];
        for i in (0..n).filter(|&i| pressed_at(i)) {
            pressed[nearest[i] as usize] += 1;
        }
        ImprintMap {
            width,
            height,
            reach_px,
            centres_px: sums.iter().map(|s| [s[0] / s[2], s[1] / s[2]]).collect(),
            pressed,
            nearest,
            dist2,
        }
    }

    /// The imprint nearest pixel `i` within `within_px` (at most the map's reach), if any.
    pub fn imprint_near(&self, i: usize, within_px: f64) -> Option<usize> {
        let d2 = *self.dist2.get(i)?;
        (d2 <= within_px * within_px).then(|| self.nearest[i] as usize)
    }

    /// Whether pixel `i` lies further than the map's reach from every imprint.
    pub fn beyond_reach(&self, i: usize) -> bool {
        self.dist2
            .get(i)
            .is_some_and(|&d2| d2 > self.reach_px * self.reach_px)
    }
}

/// The gain of `image` against `appearance` (both row-major per channel, counts of at most
/// `full_scale`): the least-squares ratio `sum a r / sum r^2` over every channel of the pixels
/// `serve` keeps that are lit (appearance at least [`MIN_REFERENCE_COUNTS`]) and below full
/// scale in both, computed twice: the second time without the values further than
/// [`GAIN_OUTLIER_SIGMAS`] robust standard deviations (1.4826 times the median absolute
/// residual) from the first. `None` when no pixel serves.
pub(super) fn least_squares_gain(
    image: &[[f64; 3]],
    appearance: &[[f64; 3]],
    serve: impl Fn(usize) -> bool,
    full_scale: f64,
) -> Option<f64> {
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for (i, (a, r)) in image.iter().zip(appearance).enumerate() {
        if !serve(i) {
            continue;
        }
        for (&a, &r) in a.iter().zip(r) {
            if a.is_finite() && r >= MIN_REFERENCE_COUNTS && a < full_scale && r < full_scale {
                pairs.push((a, r));
            }
        }
    }
    let ratio = |keep: &dyn Fn(f64, f64) -> bool| {
        let (mut ar, mut rr) = (0.0, 0.0);
        for &(a, r) in pairs.iter().filter(|(a, r)| keep(*a, *r)) {
            ar += a * r;
            rr += r * r;
        }
        (rr > 0.0).then(|| ar / rr).filter(|g| *g > 0.0)
    };
    let first = ratio(&|_, _| true)?;
    let sigma = 1.4826 * median(pairs.iter().map(|(a, r)| (a - first * r).abs()).collect())?;
    let cut = GAIN_OUTLIER_SIGMAS * sigma;
    Some(ratio(&|a, r| (a - first * r).abs() <= cut).unwrap_or(first))
}

/// Whether each pixel is shadowed in `capture`.
fn shadowed(capture: &Capture<'_>, n: usize) -> Vec<bool> {
    let mut s = vec![false; n];
    for p in &capture.shadows.pixels {
        if let Some(x) = s.get_mut(p.pixel as usize) {
            *x = true;
        }
    }
    s
}

/// The gain of `capture` against `appearance` ([`least_squares_gain`]) over its skin
/// (`reference.t_mm` finite), unshadowed and further than [`GAIN_CLEARANCE_PX`] from every
/// imprint; where fewer than a few hundred values lie so far, over its unpressed,
/// unshadowed skin.
pub(super) fn capture_gain(
    capture: &Capture<'_>,
    appearance: &[[f64; 3]],
    reference: &SurfaceHits,
    width: usize,
    height: usize,
    full_scale: f64,
) -> f64 {
    let n = width * height;
    let map = ImprintMap::of(&capture.hits.contact, width, height, GAIN_CLEARANCE_PX);
    let shade = shadowed(capture, n);
    let skin = |i: usize| reference.t_mm.get(i).is_some_and(|t| t.is_finite()) && !shade[i];
    let far: Vec<bool> = (0..n).map(|i| skin(i) && map.beyond_reach(i)).collect();
    let far_count = far.iter().filter(|&&f| f).count();
    let g = if 3 * far_count >= MIN_GAIN_SAMPLES {
        least_squares_gain(capture.image, appearance, |i| far[i], full_scale)
    } else {
        least_squares_gain(
            capture.image,
            appearance,
            |i| skin(i) && !capture.hits.contact[i],
            full_scale,
        )
    };
    g.unwrap_or(1.0)
}

/// How a rendering of one capture fits it where the pins press
/// ([`PhotometricModel::contact_region`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRegion {
    /// The distance from an imprint (to its nearest pressed pixel) within which the figures
    /// are taken, px.
    pub reach_px: f64,
    /// RMS difference of the rendering from the capture over the skin within `reach_px` of
    /// every imprint, all channels, counts (NaN when no pixel is there).
    pub rms_counts: f64,
    /// The skin pixels within `reach_px` of the imprints.
    pub pixels: usize,
    /// The darkening below which a pixel does not weigh in a centroid, counts per channel:
    /// [`DARKENING_NOISE_SIGMAS`] times the capture's noise far from the imprints.
    pub darkening_floor_counts: f64,
    /// Per imprint, in the order of [`ImprintMap`].
    pub imprints: Vec<ImprintFit>,
    /// The median of the imprints' centroid offsets, px (the upper of the middle two); `None`
    /// when no imprint has one.
    pub median_offset_px: Option<f64>,
}

/// How a rendering fits one imprint of a capture ([`ContactRegion`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImprintFit {
    /// The centroid of the imprint's pressed pixels, px.
    pub centre_px: [f64; 2],
    /// Its pressed pixels.
    pub pressed_pixels: usize,
    /// RMS difference of the rendering from the capture over the skin nearer this imprint
    /// than any other and within the reach, all channels, counts.
    pub rms_counts: f64,
    /// The centroid of the capture's darkening there (the appearance at the capture's gain
    /// minus the capture, summed over the channels, each less the floor and clipped at 0), px;
    /// `None` where nothing darkens past the floor.
    pub real_centroid_px: Option<[f64; 2]>,
    /// The same of the rendering, px.
    pub rendered_centroid_px: Option<[f64; 2]>,
    /// The distance between the two centroids, px.
    pub offset_px: Option<f64>,
}

impl PhotometricModel {
    /// The gain of `capture` against the model's appearance, as the fit measures it: the
    /// least-squares ratio over the skin further than [`GAIN_CLEARANCE_PX`] from every imprint
    /// and unshadowed, without outliers ([`GAIN_OUTLIER_SIGMAS`]); `reference` is the
    /// unindented surface.
    pub fn gain_of(&self, capture: &Capture<'_>, reference: &SurfaceHits) -> f64 {
        capture_gain(
            capture,
            &self.reference,
            reference,
            self.width,
            self.height,
            self.full_scale,
        )
    }

    /// How `rendered` (this model's image of `capture` at `gain`, [`Self::render`]) fits the
    /// capture within `reach_px` of its imprints ([`ContactRegion`]); `reference` is the
    /// unindented surface. The capture's noise is 1.4826 times the median absolute difference
    /// of the capture from the appearance at `gain` over its unshadowed skin beyond the reach.
    pub fn contact_region(
        &self,
        capture: &Capture<'_>,
        reference: &SurfaceHits,
        rendered: &[[f64; 3]],
        gain: f64,
        reach_px: f64,
    ) -> ContactRegion {
        let (w, h) = (self.width, self.height);
        let n = w * h;
        let map = ImprintMap::of(&capture.hits.contact, w, h, reach_px);
        let shade = shadowed(capture, n);
        let image = capture.image;
        let skin = |i: usize| {
            reference.t_mm.get(i).is_some_and(|t| t.is_finite())
                && image.get(i).is_some()
                && rendered.get(i).is_some()
        };
        let base = |i: usize, c: usize| gain * self.reference[i][c];
        let mut noise: Vec<f64> = Vec::new();
        for i in (0..n).filter(|&i| skin(i) && !shade[i] && map.beyond_reach(i)) {
            for c in 0..3 {
                let x = (image[i][c] - base(i, c)).abs();
                if x.is_finite() {
                    noise.push(x);
                }
            }
        }
        let floor = DARKENING_NOISE_SIGMAS * 1.4826 * median(noise).unwrap_or(0.0);
        let k = map.centres_px.len();
        // per imprint: squared differences and their count, then the weighted sums of the
        // real and the rendered darkening (u, v, weight)
        let mut sq = vec![(0.0, 0usize); k];
        let mut pixels = 0usize;
        let mut real = vec![[0.0; 3]; k];
        let mut again = vec![[0.0; 3]; k];
        for i in (0..n).filter(|&i| skin(i)) {
            let Some(j) = map.imprint_near(i, reach_px) else {
                continue;
            };
            pixels += 1;
            let (u, v) = ((i % w) as f64, (i / w) as f64);
            let dark = |img: &[[f64; 3]], acc: &mut [f64; 3]| {
                let wgt: f64 = (0..3)
                    .map(|c| (base(i, c) - img[i][c] - floor).max(0.0))
                    .filter(|x| x.is_finite())
                    .sum();
                acc[0] += wgt * u;
                acc[1] += wgt * v;
                acc[2] += wgt;
            };
            dark(image, &mut real[j]);
            dark(rendered, &mut again[j]);
            for c in 0..3 {
                let d = rendered[i][c] - image[i][c];
                if d.is_finite() {
                    sq[j].0 += d * d;
                    sq[j].1 += 1;
                }
            }
        }
        let centroid = |a: [f64; 3]| (a[2] > 0.0).then(|| [a[0] / a[2], a[1] / a[2]]);
        let rms = |s: f64, m: usize| {
            if m == 0 {
                f64::NAN
            } else {
                (s / m as f64).sqrt()
            }
        };
        let imprints: Vec<ImprintFit> = (0..k)
            .map(|j| {
                let (a, b) = (centroid(real[j]), centroid(again[j]));
                ImprintFit {
                    centre_px: map.centres_px[j],
                    pressed_pixels: map.pressed[j],
                    rms_counts: rms(sq[j].0, sq[j].1),
                    real_centroid_px: a,
                    rendered_centroid_px: b,
                    offset_px: a.zip(b).map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1])),
                }
            })
            .collect();
        let (s, m) = sq
            .iter()
            .fold((0.0, 0), |acc, x| (acc.0 + x.0, acc.1 + x.1));
        ContactRegion {
            reach_px,
            rms_counts: rms(s, m),
            pixels,
            darkening_floor_counts: floor,
            median_offset_px: median(imprints.iter().filter_map(|f| f.offset_px).collect()),
            imprints,
        }
    }
}
