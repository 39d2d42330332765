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
    /// Minor over major axis of the spot's pixels (the square root of the ratio of the
    /// eigenvalues of their second central moments): 1 for a disc, near 0 for a line (a
    /// scratch, the edge of a highlight).
    pub roundness: f64,
}

/// [`Spot::roundness`] from the spot's pixel count and the sums of u, v, u^2, v^2 and u v.
fn roundness(n: f64, su: f64, sv: f64, suu: f64, svv: f64, suv: f64) -> f64 {
    let (mu, mv) = (su / n, sv / n);
    // second central moments, each pixel a unit square (+1/12 per axis)
    let cuu = suu / n - mu * mu + 1.0 / 12.0;
    let cvv = svv / n - mv * mv + 1.0 / 12.0;
    let cuv = suv / n - mu * mv;
    let half_tr = 0.5 * (cuu + cvv);
    let d = (0.25 * (cuu - cvv).powi(2) + cuv * cuv).sqrt();
    let (major, minor) = (half_tr + d, (half_tr - d).max(0.0));
    if major > 0.0 {
        (minor / major).sqrt()
    } else {
        1.0
    }
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
        // the spot's pixels' moments, unweighted (its shape)
        let mut m = [0f64; 5];
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
            let (fu, fv) = (u as f64, v as f64);
            m[0] += fu;
            m[1] += fv;
            m[2] += fu * fu;
            m[3] += fv * fv;
            m[4] += fu * fv;
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
            roundness: roundness(area as f64, m[0], m[1], m[2], m[3], m[4]),
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

pub mod synthetic;
