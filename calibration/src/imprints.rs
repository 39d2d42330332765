//! Pin-imprint detection (R-Tac0 Sec. IV-A): a calibration pin pressing the skin shows in the
//! capture as a spot that differs from the reference image of the unloaded skin (darker for
//! R-Tac0). The detector works on the difference image (reference minus capture, so that a
//! darkening is positive), smoothed by a small Gaussian, inside a mask of the pixels that can
//! be skin; it thresholds at a multiple of the noise (estimated robustly from the difference
//! itself), grows each spot by hysteresis down to a lower threshold, and reports each spot's
//! sub-pixel centre as the centroid of the smoothed difference over the spot (weights above
//! the lower threshold), with a score (peak over noise). Spots brighter than the reference (LED
//! reflections) are never candidates.
//!
//! Real captures differ from their reference everywhere by a small global gain (LED flicker,
//! auto exposure) and along every strong edge by a pixel or two (the saturated LED highlights
//! at the chamber rim move): the reference is scaled by the capture's gain (the median ratio
//! of capture to reference over the skin) and, before differencing, each reference pixel is
//! replaced by the darkest reference pixel within [`DetectParams::edge_tolerance_px`] (a grey
//! erosion), so that an edge that moved by up to that much does not read as a darkening. On
//! smooth skin, where a pin's imprint is, the erosion lowers the difference by the
//! reference's slope over that distance only.
//!
//! Images are grey levels as `f32`, row-major, (0, 0) the centre of the top-left pixel
//! (docs/conventions.md).

mod assign;

/// A grey image: `data[v * width + u]`, grey levels (any scale; 8-bit images 0..255).
#[derive(Debug, Clone, PartialEq)]
pub struct GrayImage {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl GrayImage {
    /// A `width` x `height` image of `value`.
    pub fn filled(width: usize, height: usize, value: f32) -> Self {
        Self {
            width,
            height,
            data: vec![value; width * height],
        }
    }
}

/// The detector's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectParams {
    /// Sigma of the Gaussian that smooths the difference, px.
    pub smooth_sigma_px: f64,
    /// A spot starts where the smoothed difference exceeds this many noise sigmas.
    pub threshold_sigma: f64,
    /// ... and grows over its neighbours above this many.
    pub grow_sigma: f64,
    /// Spots of fewer pixels (after growing) are noise.
    pub min_area_px: usize,
    /// An edge of the reference that moved by up to this many px in the capture is not a
    /// darkening (the reference is eroded by a square of this half-width); 0: none.
    pub edge_tolerance_px: usize,
    /// Scale the reference by the capture's global gain (the median ratio of capture to
    /// reference over the mask) before differencing.
    pub compensate_gain: bool,
}

impl Default for DetectParams {
    fn default() -> Self {
        Self {
            smooth_sigma_px: 1.0,
            threshold_sigma: 8.0,
            grow_sigma: 2.0,
            min_area_px: 12,
            edge_tolerance_px: 2,
            compensate_gain: true,
        }
    }
}

/// One detected imprint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spot {
    /// Sub-pixel centre, px.
    pub u_px: f64,
    pub v_px: f64,
    /// Peak of the smoothed difference over the noise sigma.
    pub score: f64,
    /// Pixels in the spot.
    pub area_px: usize,
}

/// Errors of [`detect`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DetectError {
    #[error("the capture is {0} x {1} px and the reference {2} x {3} px: they must match")]
    SizeMismatch(usize, usize, usize, usize),
    #[error("the mask holds {0} values for {1} pixels")]
    MaskSize(usize, usize),
}

/// A 1D Gaussian kernel of `sigma`, radius 3 sigma, normalised.
fn kernel(sigma: f64) -> Vec<f32> {
    let r = (3.0 * sigma).ceil().max(1.0) as i64;
    let k: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let s: f64 = k.iter().sum();
    k.iter().map(|x| (x / s) as f32).collect()
}

/// `img` smoothed by a separable Gaussian of `sigma` px (edges clamped).
pub fn gaussian_blur(img: &GrayImage, sigma: f64) -> GrayImage {
    if !(sigma > 0.0) {
        return img.clone();
    }
    let k = kernel(sigma);
    let r = k.len() / 2;
    let (w, h) = (img.width, img.height);
    // horizontally: one row at a time over a copy padded with its edge values, the taps
    // without bounds checks
    let pass = |line: &[f32], out: &mut [f32], pad: &mut Vec<f32>| {
        let n = line.len();
        pad.clear();
        pad.extend(std::iter::repeat_n(line[0], r));
        pad.extend_from_slice(line);
        pad.extend(std::iter::repeat_n(line[n - 1], r));
        out.fill(0.0);
        for (j, kj) in k.iter().enumerate() {
            for (o, p) in out.iter_mut().zip(&pad[j..j + n]) {
                *o += kj * p;
            }
        }
    };
    let mut pad = Vec::with_capacity(w.max(h) + 2 * r);
    let mut tmp = vec![0f32; w * h];
    for v in 0..h {
        pass(
            &img.data[v * w..(v + 1) * w],
            &mut tmp[v * w..(v + 1) * w],
            &mut pad,
        );
    }
    // vertically: each output row a weighted sum of whole rows (edge rows repeated)
    let mut out = vec![0f32; w * h];
    for (v, row) in out.chunks_exact_mut(w).enumerate() {
        for (j, kj) in k.iter().enumerate() {
            let src = (v + j).saturating_sub(r).min(h - 1);
            for (o, t) in row.iter_mut().zip(&tmp[src * w..(src + 1) * w]) {
                *o += kj * t;
            }
        }
    }
    GrayImage {
        width: w,
        height: h,
        data: out,
    }
}

/// The noise is estimated on every this many pixels.
const NOISE_STRIDE: usize = 7;

/// Median of `v` (reordered).
fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f32::total_cmp).1
}

/// The capture's gain and the erosion's offset are medians over every this many pixels (a
/// prime, so that the samples do not line up in columns; about 14000 of 640 x 480).
const LEVEL_STRIDE: usize = 23;

/// Grey levels of the reference counted in the gain: above this (not the dark outside) ...
const GAIN_MIN_GREY: f32 = 20.0;
/// ... and below this (not saturated), on 8-bit images.
const GAIN_MAX_GREY: f32 = 250.0;

/// The capture's global gain against the reference: the median of capture / reference over
/// the pixels `inside` (every [`LEVEL_STRIDE`]-th) whose reference grey is neither dark nor
/// saturated; 1 when there are none. The imprints are a small part of the skin and do not
/// move the median.
fn capture_gain(reference: &GrayImage, capture: &GrayImage, inside: &dyn Fn(usize) -> bool) -> f32 {
    let mut ratios: Vec<f32> = (0..reference.data.len())
        .step_by(LEVEL_STRIDE)
        .filter(|&i| inside(i))
        .filter_map(|i| {
            let r = reference.data[i];
            (GAIN_MIN_GREY..GAIN_MAX_GREY)
                .contains(&r)
                .then(|| capture.data[i] / r)
        })
        .collect();
    if ratios.is_empty() {
        1.0
    } else {
        median(&mut ratios)
    }
}

/// The median of `gain x (reference - eroded)` over the pixels `inside` (every
/// [`LEVEL_STRIDE`]-th): how much the erosion lowers the difference on the skin.
fn erosion_offset(
    reference: &GrayImage,
    eroded: &GrayImage,
    gain: f32,
    inside: &dyn Fn(usize) -> bool,
) -> f64 {
    let mut v: Vec<f32> = (0..reference.data.len())
        .step_by(LEVEL_STRIDE)
        .filter(|&i| inside(i))
        .map(|i| gain * (reference.data[i] - eroded.data[i]))
        .collect();
    f64::from(median(&mut v))
}

/// `gain x reference - capture` at pixel `i`, smoothed by the separable kernel `k` (the
/// Gaussian of [`gaussian_blur`], edges clamped), computed at that pixel alone.
fn smoothed_at(reference: &GrayImage, capture: &GrayImage, gain: f32, k: &[f32], i: usize) -> f64 {
    let (w, h) = (reference.width, reference.height);
    let (u, v) = (i % w, i / w);
    let r = k.len() / 2;
    let mut sum = 0f32;
    if u >= r && v >= r && u + r < w && v + r < h {
        for (a, ka) in k.iter().enumerate() {
            let start = (v + a - r) * w + u - r;
            let rr = &reference.data[start..start + k.len()];
            let cc = &capture.data[start..start + k.len()];
            let row: f32 = k
                .iter()
                .zip(rr)
                .zip(cc)
                .map(|((kb, x), y)| kb * (gain * x - y))
                .sum();
            sum += ka * row;
        }
    } else {
        for (a, ka) in k.iter().enumerate() {
            let vv = (v + a).saturating_sub(r).min(h - 1);
            for (b, kb) in k.iter().enumerate() {
                let uu = (u + b).saturating_sub(r).min(w - 1);
                let j = vv * w + uu;
                sum += ka * kb * (gain * reference.data[j] - capture.data[j]);
            }
        }
    }
    f64::from(sum)
}

/// `out[j] = min(a[j], b[j], c[j])` for every `j`.
fn min3_into(out: &mut [f32], a: &[f32], b: &[f32], c: &[f32]) {
    for (((o, x), y), z) in out.iter_mut().zip(a).zip(b).zip(c) {
        *o = x.min(*y).min(*z);
    }
}

/// `img` with each pixel replaced by the smallest within `r` px along each axis (a grey
/// erosion by a (2r + 1) x (2r + 1) square, as `r` erosions by a 3 x 3 one; separable; the
/// window cut at the edges).
pub fn erode(img: &GrayImage, r: usize) -> GrayImage {
    let (w, h) = (img.width, img.height);
    if w < 2 || h < 2 || r == 0 {
        return img.clone();
    }
    let mut cur = img.data.clone();
    let mut other = vec![0f32; w * h];
    for _ in 0..r {
        // along rows, cur -> other: each pixel and its left and right neighbours
        for (out, src) in other.chunks_exact_mut(w).zip(cur.chunks_exact(w)) {
            out[0] = src[0].min(src[1]);
            min3_into(&mut out[1..w - 1], &src[..w - 2], &src[1..w - 1], &src[2..]);
            out[w - 1] = src[w - 2].min(src[w - 1]);
        }
        // along columns, other -> cur: each row and the rows above and below
        for v in 0..h {
            let (up, down) = (v.saturating_sub(1), (v + 1).min(h - 1));
            min3_into(
                &mut cur[v * w..(v + 1) * w],
                &other[up * w..(up + 1) * w],
                &other[v * w..(v + 1) * w],
                &other[down * w..(down + 1) * w],
            );
        }
    }
    GrayImage {
        width: w,
        height: h,
        data: cur,
    }
}

/// The imprints in `capture` against `reference` (same size; grey levels), within `mask` (true:
/// a pixel that can be skin; `None`: every pixel), strongest first.
///
/// # Errors
/// [`DetectError`] when the sizes differ.
pub fn detect(
    reference: &GrayImage,
    capture: &GrayImage,
    mask: Option<&[bool]>,
    p: &DetectParams,
) -> Result<Vec<Spot>, DetectError> {
    let (w, h) = (capture.width, capture.height);
    if (reference.width, reference.height) != (w, h) {
        return Err(DetectError::SizeMismatch(
            w,
            h,
            reference.width,
            reference.height,
        ));
    }
    if let Some(m) = mask {
        if m.len() != w * h {
            return Err(DetectError::MaskSize(m.len(), w * h));
        }
    }
    let inside = |i: usize| mask.is_none_or(|m| m[i]);
    let gain = if p.compensate_gain {
        capture_gain(reference, capture, &inside)
    } else {
        1.0
    };
    let eroded = erode(reference, p.edge_tolerance_px);
    let lo_offset = erosion_offset(reference, &eroded, gain, &inside);
    // the difference in the eroded reference's buffer
    let mut diff = eroded;
    for (r, c) in diff.data.iter_mut().zip(&capture.data) {
        *r = gain * *r - c;
    }
    let d = gaussian_blur(&diff, p.smooth_sigma_px);
    let k = if p.smooth_sigma_px > 0.0 {
        kernel(p.smooth_sigma_px)
    } else {
        vec![1.0]
    };
    // noise: the median absolute deviation of the smoothed difference over the mask, on every
    // NOISE_STRIDE-th pixel (plenty for a median, in a fraction of the time)
    let mut vals: Vec<f32> = (0..w * h)
        .step_by(NOISE_STRIDE)
        .filter(|&i| inside(i))
        .map(|i| d.data[i])
        .collect();
    let med = median(&mut vals);
    let mut dev: Vec<f32> = vals.iter().map(|x| (x - med).abs()).collect();
    let sigma = (1.4826 * median(&mut dev)).max(1e-6) as f64;
    let hi = med as f64 + p.threshold_sigma * sigma;
    let lo = med as f64 + p.grow_sigma * sigma;
    // the same lower threshold on the difference with the reference itself: the erosion
    // lowers the difference by about the same everywhere on smooth skin (the darkest of the
    // reference's noise within the window), which would otherwise weigh every pixel of a spot
    // alike and pull its centre to the middle of its area
    let lo_plain = lo + lo_offset;
    let mut label = vec![0u32; w * h];
    let mut spots = Vec::new();
    let mut stack = Vec::new();
    // the seeds first, in one tight pass over the image; then each grows its spot
    let hi32 = hi as f32;
    let seeds: Vec<usize> = match mask {
        Some(m) => d
            .data
            .iter()
            .zip(m)
            .enumerate()
            .filter(|(_, (x, &m))| m && **x > hi32)
            .map(|(i, _)| i)
            .collect(),
        None => d
            .data
            .iter()
            .enumerate()
            .filter(|(_, x)| **x > hi32)
            .map(|(i, _)| i)
            .collect(),
    };
    for start in seeds {
        if label[start] != 0 || (d.data[start] as f64) <= hi {
            continue;
        }
        // grow by hysteresis over 8-neighbours above `lo`
        let id = spots.len() as u32 + 1;
        label[start] = id;
        stack.push(start);
        let (mut sw, mut su, mut sv, mut peak, mut area) = (0f64, 0f64, 0f64, 0f64, 0usize);
        while let Some(i) = stack.pop() {
            let (u, v) = (i % w, i / w);
            // weighted by the difference with the reference itself (not eroded), smoothed
            // the same way: the erosion decides which pixels a spot has, not its centre
            let x = smoothed_at(reference, capture, gain, &k, i) - lo_plain;
            sw += x;
            su += x * u as f64;
            sv += x * v as f64;
            peak = peak.max(d.data[i] as f64 - med as f64);
            area += 1;
            for dv in -1i64..=1 {
                for du in -1i64..=1 {
                    let (uu, vv) = (u as i64 + du, v as i64 + dv);
                    if uu < 0 || vv < 0 || uu >= w as i64 || vv >= h as i64 {
                        continue;
                    }
                    let j = vv as usize * w + uu as usize;
                    if label[j] == 0 && inside(j) && d.data[j] as f64 > lo {
                        label[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        spots.push(Spot {
            u_px: su / sw,
            v_px: sv / sw,
            score: peak / sigma,
            area_px: area,
        });
    }
    let mut spots: Vec<Spot> = spots
        .into_iter()
        .filter(|s| s.area_px >= p.min_area_px)
        .collect();
    spots.sort_by(|a, b| b.score.total_cmp(&a.score));
    Ok(spots)
}

pub use assign::{
    assign_ids, Assignment, CaptureOutcome, CaptureSpots, Observation, MAX_PINS_PER_CAPTURE,
};

/// The ids a capture's file name lists in ring order (the R-Tac0 authors' convention:
/// `01_02_06_14_22.png` holds pins 1, 2, 6, 14 and 22): the stem's `_`-separated numbers;
/// `None` when the stem is not such a list.
pub fn ids_from_file_name(path: &std::path::Path) -> Option<Vec<u32>> {
    let stem = path.file_stem()?.to_str()?;
    stem.split('_')
        .map(|t| {
            (!t.is_empty() && t.chars().all(|c| c.is_ascii_digit()))
                .then(|| t.parse::<u32>().ok())
                .flatten()
        })
        .collect()
}

/// The pixels that can hold an imprint, from the reference image: skin (brighter than a
/// quarter of the median grey) and not an LED reflection (at most halfway from the median to
/// `white`), the reflections grown by `margin_px`.
pub fn reference_mask(reference: &GrayImage, white: f32, margin_px: usize) -> Vec<bool> {
    let (w, h) = (reference.width, reference.height);
    let mut all = reference.data.clone();
    let med = median(&mut all);
    let bright = 0.5 * (med + white);
    let mut mask: Vec<bool> = reference.data.iter().map(|&g| g > 0.25 * med).collect();
    let m = margin_px as i64;
    for v in 0..h as i64 {
        for u in 0..w as i64 {
            if reference.data[v as usize * w + u as usize] <= bright {
                continue;
            }
            for dv in -m..=m {
                for du in -m..=m {
                    let (uu, vv) = (u + du, v + dv);
                    if uu >= 0 && vv >= 0 && uu < w as i64 && vv < h as i64 {
                        mask[vv as usize * w + uu as usize] = false;
                    }
                }
            }
        }
    }
    mask
}

/// Synthetic captures for the tests and benchmarks: the skin rendered through a camera with the
/// ground-truth caster ([`crate::groundtruth`]), each pin's imprint shaded as a darkening
/// proportional to its indentation depth along the pixel's ray, blurred by a Gaussian
/// point-spread function, with vignetting, bright LED reflections near the rim (a little
/// brighter or dimmer in each image) and Gaussian noise.
pub mod synthetic {
    use super::{gaussian_blur, GrayImage};
    use crate::groundtruth::exact::ExactPrimitives;
    use crate::groundtruth::rays::PixelRays;
    use crate::groundtruth::surface::ReferenceSurface;
    use crate::groundtruth::{indented_hits, reference_hits};
    use crate::CameraModel;
    use fabkit_designs::primitives::Primitive;
    use nalgebra::Isometry3;
    use rand_chacha::rand_core::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// How the images are shaded.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Shading {
        /// Grey of the skin at the image centre.
        pub skin_grey: f32,
        /// Grey outside the skin.
        pub background_grey: f32,
        /// Darkening per mm of indentation depth along the ray.
        pub grey_per_mm: f32,
        /// Sigma of the point-spread function, px.
        pub psf_sigma_px: f64,
        /// Sigma of the noise, grey levels.
        pub noise_sigma: f64,
        /// Fraction of the grey lost at the image's corners (quadratic in the radius).
        pub vignetting: f32,
        /// LED reflections: count, peak grey above the skin, sigma px, and how much each image's
        /// peak varies (fraction).
        pub leds: usize,
        pub led_grey: f32,
        pub led_sigma_px: f64,
        pub led_flicker: f32,
        /// How far each LED highlight moves between the reference and the capture, px (in a
        /// random direction per highlight).
        pub led_shift_px: f64,
        /// The capture's global gain differs from the reference's by a random factor in
        /// [1 - drift, 1 + drift] (auto exposure, LED supply).
        pub gain_drift: f32,
    }

    impl Default for Shading {
        fn default() -> Self {
            Self {
                skin_grey: 160.0,
                background_grey: 12.0,
                grey_per_mm: 120.0,
                psf_sigma_px: 1.2,
                noise_sigma: 2.0,
                vignetting: 0.35,
                leds: 6,
                led_grey: 90.0,
                led_sigma_px: 3.0,
                led_flicker: 0.3,
                led_shift_px: 0.0,
                gain_drift: 0.0,
            }
        }
    }

    impl Shading {
        /// What a real R-Tac0 capture adds to [`Shading::default`]: a ring of 12 LED
        /// highlights saturated at 255 (steep edges around flat tops, dark skin between them)
        /// that each move by 1.5 px between the reference and the capture, and a global gain
        /// that drifts by up to 5 %. It still lacks side-lit crescent imprints, specks off the
        /// pins and JPEG compression.
        pub fn real_rim() -> Self {
            Self {
                leds: 12,
                led_grey: 300.0,
                led_sigma_px: 8.0,
                led_flicker: 0.1,
                led_shift_px: 1.5,
                gain_drift: 0.05,
                ..Self::default()
            }
        }
    }

    /// A pin of a capture: a sphere of `radius_mm` about `centre_mm` (sensor frame), pressing
    /// the skin.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Pin {
        pub centre_mm: [f64; 3],
        pub radius_mm: f64,
    }

    /// One pin per ring of an R-Tac0-like dome (polar 0, 18, 34, 50 and 64 deg, azimuths 0, 30,
    /// 150, 250 and 330 deg turned by `turn_deg`), each a ball of 1.5 mm radius pressed
    /// `depth_mm` into the R = 15 mm skin along its normal: the test and benchmark captures.
    pub fn ring_pins(turn_deg: f64, depth_mm: f64) -> Vec<Pin> {
        [
            (0.0, 0.0),
            (18.0, 30.0),
            (34.0, 150.0),
            (50.0, 250.0),
            (64.0, 330.0),
        ]
        .iter()
        .map(|&(polar, az): &(f64, f64)| {
            let (p, a) = (polar.to_radians(), (az + turn_deg).to_radians());
            let c = 15.0 + 1.5 - depth_mm;
            Pin {
                centre_mm: [c * p.sin() * a.cos(), c * p.sin() * a.sin(), c * p.cos()],
                radius_mm: 1.5,
            }
        })
        .collect()
    }

    /// A rendered capture and its reference.
    #[derive(Debug, Clone)]
    pub struct Rendered {
        pub reference: GrayImage,
        pub capture: GrayImage,
        /// Each pin's true centre, px: the centroid of its noise-free imprint (the darkening
        /// before blur), in the order given; `None` for a pin the camera does not see press.
        pub centres_px: Vec<Option<[f64; 2]>>,
    }

    /// Uniform in [0, 1).
    fn unit(rng: &mut ChaCha8Rng) -> f64 {
        (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn led_image(
        w: usize,
        h: usize,
        base: &[f32],
        leds: &[[f64; 2]],
        s: &Shading,
        rng: &mut ChaCha8Rng,
    ) -> Vec<f32> {
        let mut img = base.to_vec();
        for c in leds {
            let k = 1.0 + s.led_flicker * (2.0 * unit(rng) as f32 - 1.0);
            let r = (4.0 * s.led_sigma_px).ceil() as i64;
            for dv in -r..=r {
                for du in -r..=r {
                    let (u, v) = (c[0].round() as i64 + du, c[1].round() as i64 + dv);
                    if u < 0 || v < 0 || u >= w as i64 || v >= h as i64 {
                        continue;
                    }
                    let d2 = (u as f64 - c[0]).powi(2) + (v as f64 - c[1]).powi(2);
                    img[v as usize * w + u as usize] += k
                        * s.led_grey
                        * (-d2 / (2.0 * s.led_sigma_px * s.led_sigma_px)).exp() as f32;
                }
            }
        }
        img
    }

    fn noisy(img: Vec<f32>, sigma: f64, rng: &mut ChaCha8Rng) -> Vec<f32> {
        img.into_iter()
            .map(|g| {
                // Box-Muller
                let (a, b): (f64, f64) = (unit(rng).max(1e-300), unit(rng));
                let n = (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
                (g as f64 + sigma * n).clamp(0.0, 255.0) as f32
            })
            .collect()
    }

    /// Renders the reference and the capture of `pins` seen by `camera` at `t_cam_sensor`
    /// (seeded noise and flicker).
    pub fn render(
        camera: &CameraModel,
        t_cam_sensor: &Isometry3<f64>,
        surface: &ReferenceSurface,
        pins: &[Pin],
        s: &Shading,
        seed: u64,
    ) -> Rendered {
        let rays = PixelRays::new(camera, t_cam_sensor);
        let (w, h) = (rays.width, rays.height);
        let refh = reference_hits(&rays, surface);
        let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
        let rmax = cx.hypot(cy);
        let mut base = vec![s.background_grey; w * h];
        let mut skin_r: f64 = 0.0;
        for p in 0..w * h {
            if refh.t_mm[p].is_finite() {
                let r = ((p % w) as f64 - cx).hypot((p / w) as f64 - cy) / rmax;
                base[p] = s.skin_grey * (1.0 - s.vignetting * (r * r) as f32);
                skin_r = skin_r.max(r * rmax);
            }
        }
        // LED reflections on a circle at 90 % of the skin's extent in the image
        let leds: Vec<[f64; 2]> = (0..s.leds)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + 0.5) / s.leds as f64;
                let r = 0.9 * skin_r.min(cy);
                [cx + r * a.cos(), cy + r * a.sin()]
            })
            .collect();
        // each pin's imprint: the depth it pushes the skin in along each ray
        let mut dent = vec![0f32; w * h];
        let mut centres = Vec::with_capacity(pins.len());
        for pin in pins {
            let prim = ExactPrimitives::new(&[Primitive::Sphere {
                centre_mm: pin.centre_mm,
                radius_mm: pin.radius_mm,
            }])
            .expect("a sphere of positive radius");
            let hits = indented_hits(&rays, &refh, &prim, surface.base_z_mm());
            let (mut sw, mut su, mut sv) = (0f64, 0f64, 0f64);
            for p in 0..w * h {
                if hits.contact[p] && refh.t_mm[p].is_finite() {
                    let depth = refh.t_mm[p] - hits.t_mm[p];
                    dent[p] += depth as f32;
                    sw += depth;
                    su += depth * (p % w) as f64;
                    sv += depth * (p / w) as f64;
                }
            }
            centres.push((sw > 0.0).then(|| [su / sw, sv / sw]));
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let blur = |img: Vec<f32>| {
            gaussian_blur(
                &GrayImage {
                    width: w,
                    height: h,
                    data: img,
                },
                s.psf_sigma_px,
            )
            .data
        };
        let reference = led_image(w, h, &blur(base.clone()), &leds, s, &mut rng);
        let pressed: Vec<f32> = base
            .iter()
            .zip(&dent)
            .map(|(b, d)| b - s.grey_per_mm * d)
            .collect();
        // the highlights move, the gain drifts (no draws when neither does: the same images)
        let moved: Vec<[f64; 2]> = if s.led_shift_px > 0.0 {
            leds.iter()
                .map(|c| {
                    let a = std::f64::consts::TAU * unit(&mut rng);
                    [
                        c[0] + s.led_shift_px * a.cos(),
                        c[1] + s.led_shift_px * a.sin(),
                    ]
                })
                .collect()
        } else {
            leds.clone()
        };
        let gain = if s.gain_drift > 0.0 {
            1.0 + s.gain_drift * (2.0 * unit(&mut rng) as f32 - 1.0)
        } else {
            1.0
        };
        let capture: Vec<f32> = led_image(w, h, &blur(pressed), &moved, s, &mut rng)
            .into_iter()
            .map(|g| gain * g)
            .collect();
        let reference = noisy(reference, s.noise_sigma, &mut rng);
        let capture = noisy(capture, s.noise_sigma, &mut rng);
        Rendered {
            reference: GrayImage {
                width: w,
                height: h,
                data: reference,
            },
            capture: GrayImage {
                width: w,
                height: h,
                data: capture,
            },
            centres_px: centres,
        }
    }
}
