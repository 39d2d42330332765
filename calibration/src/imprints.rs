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
mod mask;

pub use mask::reference_mask;

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
    /// The centre is the centroid of the imprint's core: each pixel weighted by how far its
    /// darkening exceeds this fraction of the way from the growing threshold to the spot's
    /// peak (0: every pixel of the spot above the threshold; 0.5: the core above half the
    /// peak, so that a faint halo the spot grows into, lopsided where a neighbour or the
    /// mask's edge cuts it, does not pull the centre; issue 97 measured 1.65 to 2.45 px on
    /// real captures with the halo in). In [0, 1).
    pub core_fraction: f64,
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
            core_fraction: 0.5,
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
    /// Pixels in the spot (grown over its neighbours above the growing threshold).
    pub area_px: usize,
    /// Minor over major axis of the spot's core (its pixels above
    /// [`DetectParams::core_fraction`]; the square root of the ratio of the eigenvalues of
    /// their second central moments): 1 for a disc, near 0 for a line (a scratch, the edge of
    /// a highlight).
    pub roundness: f64,
    /// The standard deviation of the core's pixels along their major axis, px (a disc of
    /// radius r: r / 2).
    pub major_sd_px: f64,
    /// Pixels in the core.
    pub core_px: usize,
    /// The spot touches the mask's edge or the image's: part of it may be cut off.
    pub clipped: bool,
    /// The spot cut in two along its major axis (two means of its core's pixels, weighted as
    /// its centre): each part's centre (u, v) px and core pixel count; `None` for a core of
    /// fewer than twice [`DetectParams::min_area_px`] pixels. Two imprints that touch make one spot; the
    /// ids' assignment splits it when the capture plans two pins there
    /// ([`assign_ids_through`]).
    pub halves: Option<[Half; 2]>,
}

/// One part of a spot cut in two ([`Spot::halves`]): its centre, px, its core's pixel count,
/// and itself cut in two (`None` for a part of fewer than twice
/// [`DetectParams::min_area_px`] pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Half {
    pub u_px: f64,
    pub v_px: f64,
    pub area_px: usize,
    pub parts: Option<[Part; 2]>,
}

/// A half of a [`Half`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Part {
    pub u_px: f64,
    pub v_px: f64,
    pub area_px: usize,
}

/// `pixels` (weights `wts`) cut in two along their major axis ([`two_means`]), and each
/// pixel's side; `None` for fewer than `min_px` pixels.
fn split_core(
    pixels: &[(usize, usize)],
    wts: &[f64],
    min_px: usize,
) -> Option<([Half; 2], Vec<u8>)> {
    if pixels.len() < min_px.max(2) {
        return None;
    }
    let mut m = [0f64; 5];
    for &(u, v) in pixels {
        let (fu, fv) = (u as f64, v as f64);
        m[0] += fu;
        m[1] += fv;
        m[2] += fu * fu;
        m[3] += fv * fv;
        m[4] += fu * fv;
    }
    let n = pixels.len() as f64;
    let (_, major, minor, axis) = shape(n, m[0], m[1], m[2], m[3], m[4]);
    two_means(
        pixels,
        wts,
        [m[0] / n, m[1] / n],
        axis,
        (major * major - minor * minor).max(0.25).sqrt(),
    )
}

/// How far the centre of a disc of `radius_px` lies from the centroid of `core`, the part of
/// it that shows inside the mask and the image (a core cut by the mask's edge: an imprint
/// beside a dark LED notch). The disc's centre `c` is moved until the centroid of its pixels
/// that show equals the core's (`c += core centroid - shown centroid`, at most 20 times, to
/// 0.01 px); the disc's radius is the core's own, twice its major axis's standard deviation (a
/// disc cut by a straight edge keeps its extent along the edge while at least half of it
/// shows). `(0, 0)` when the disc shows whole.
fn clipped_disc_shift(
    core: &[(usize, usize)],
    radius_px: f64,
    w: usize,
    h: usize,
    mask: Option<&[bool]>,
) -> (f64, f64) {
    let n = core.len() as f64;
    let o = core.iter().fold([0.0, 0.0], |a, &(u, v)| {
        [a[0] + u as f64 / n, a[1] + v as f64 / n]
    });
    let shows = |u: i64, v: i64| {
        u >= 0
            && v >= 0
            && (u as usize) < w
            && (v as usize) < h
            && mask.is_none_or(|m| m[v as usize * w + u as usize])
    };
    let r = radius_px.max(0.5);
    let mut c = o;
    for _ in 0..20 {
        let (mut su, mut sv, mut k) = (0.0, 0.0, 0.0);
        let rr = r.ceil() as i64;
        for v in c[1].round() as i64 - rr..=c[1].round() as i64 + rr {
            for u in c[0].round() as i64 - rr..=c[0].round() as i64 + rr {
                if (u as f64 - c[0]).hypot(v as f64 - c[1]) <= r && shows(u, v) {
                    su += u as f64;
                    sv += v as f64;
                    k += 1.0;
                }
            }
        }
        if k == 0.0 {
            break;
        }
        let (eu, ev) = (o[0] - su / k, o[1] - sv / k);
        c = [c[0] + eu, c[1] + ev];
        if eu.hypot(ev) < 0.01 {
            break;
        }
    }
    (c[0] - o[0], c[1] - o[1])
}

/// The two weighted means of `pixels` (weights `wts`), started at the centroid plus and minus
/// the spread along `axis` beyond the minor one, iterated until no pixel changes side (at
/// most 32 times); `None` when a part is empty or weightless.
fn two_means(
    pixels: &[(usize, usize)],
    wts: &[f64],
    centre: [f64; 2],
    axis: [f64; 2],
    offset: f64,
) -> Option<([Half; 2], Vec<u8>)> {
    let mut c = [
        [centre[0] - offset * axis[0], centre[1] - offset * axis[1]],
        [centre[0] + offset * axis[0], centre[1] + offset * axis[1]],
    ];
    let mut side = vec![0u8; pixels.len()];
    for iteration in 0..32 {
        let mut changed = false;
        for (k, &(u, v)) in pixels.iter().enumerate() {
            let (fu, fv) = (u as f64, v as f64);
            let d0 = (fu - c[0][0]).powi(2) + (fv - c[0][1]).powi(2);
            let d1 = (fu - c[1][0]).powi(2) + (fv - c[1][1]).powi(2);
            let s = u8::from(d1 < d0);
            changed |= s != side[k];
            side[k] = s;
        }
        if iteration > 0 && !changed {
            break;
        }
        let mut acc = [[0f64; 3]; 2];
        for (k, &(u, v)) in pixels.iter().enumerate() {
            let a = &mut acc[side[k] as usize];
            a[0] += wts[k];
            a[1] += wts[k] * u as f64;
            a[2] += wts[k] * v as f64;
        }
        for (ck, a) in c.iter_mut().zip(&acc) {
            if !(a[0] > 0.0) {
                return None;
            }
            *ck = [a[1] / a[0], a[2] / a[0]];
        }
    }
    let n1 = side.iter().filter(|&&s| s == 1).count();
    let n0 = pixels.len() - n1;
    if n0 == 0 || n1 == 0 {
        return None;
    }
    Some((
        [
            Half {
                u_px: c[0][0],
                v_px: c[0][1],
                area_px: n0,
                parts: None,
            },
            Half {
                u_px: c[1][0],
                v_px: c[1][1],
                area_px: n1,
                parts: None,
            },
        ],
        side,
    ))
}

/// The shape of a spot's pixels from their count and the sums of u, v, u^2, v^2 and u v:
/// [`Spot::roundness`], [`Spot::major_sd_px`], the minor axis's standard deviation (px) and
/// the unit major axis.
fn shape(n: f64, su: f64, sv: f64, suu: f64, svv: f64, suv: f64) -> (f64, f64, f64, [f64; 2]) {
    let (mu, mv) = (su / n, sv / n);
    // second central moments, each pixel a unit square (+1/12 per axis)
    let cuu = suu / n - mu * mu + 1.0 / 12.0;
    let cvv = svv / n - mv * mv + 1.0 / 12.0;
    let cuv = suv / n - mu * mv;
    let half_tr = 0.5 * (cuu + cvv);
    let d = (0.25 * (cuu - cvv).powi(2) + cuv * cuv).sqrt();
    let (major, minor) = ((half_tr + d).max(0.0), (half_tr - d).max(0.0));
    // the eigenvector of the larger eigenvalue
    let axis = if cuv.abs() > 1e-12 {
        let (x, y) = (major - cvv, cuv);
        let l = x.hypot(y);
        [x / l, y / l]
    } else if cuu >= cvv {
        [1.0, 0.0]
    } else {
        [0.0, 1.0]
    };
    let roundness = if major > 0.0 {
        (minor / major).sqrt()
    } else {
        1.0
    };
    (roundness, major.sqrt(), minor.sqrt(), axis)
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

/// `pad` (a row with `r` spare values at each end) padded with its edge values.
#[inline(always)]
fn pad_edges(pad: &mut [f32], r: usize) {
    let n = pad.len();
    let (first, last) = (pad[r], pad[n - r - 1]);
    pad[..r].fill(first);
    pad[n - r..].fill(last);
}

/// Pixels computed together by [`fold_rows`], in registers.
const LANES: usize = 32;

/// For every `u`, `out[u]` the fold by `f` of `src[start(0) + u]`, `src[start(1) + u]`, ..
/// `src[start(n - 1) + u]` (`f(acc, j, x)`, from `init`, in that order): [`LANES`] outputs at
/// a time, held in registers over all the `n` terms, then 8 at a time, then one by one.
#[inline(always)]
fn fold_rows(
    out: &mut [f32],
    src: &[f32],
    n: usize,
    start: impl Fn(usize) -> usize,
    init: f32,
    f: impl Fn(f32, usize, f32) -> f32,
) {
    let done = fold_lanes::<LANES>(out, 0, src, n, &start, init, &f);
    let done = fold_lanes::<8>(out, done, src, n, &start, init, &f);
    fold_lanes::<1>(out, done, src, n, &start, init, &f);
}

/// [`fold_rows`] from `out[from]` on, `L` outputs at a time: as far as whole chunks go (the
/// end returned).
#[inline(always)]
fn fold_lanes<const L: usize>(
    out: &mut [f32],
    from: usize,
    src: &[f32],
    n: usize,
    start: &impl Fn(usize) -> usize,
    init: f32,
    f: &impl Fn(f32, usize, f32) -> f32,
) -> usize {
    let end = from + (out.len() - from) / L * L;
    for (c, o) in out[from..end].chunks_exact_mut(L).enumerate() {
        let at = from + c * L;
        let mut acc = [init; L];
        for j in 0..n {
            let s = start(j) + at;
            for (a, x) in acc.iter_mut().zip(&src[s..s + L]) {
                *a = f(*a, j, *x);
            }
        }
        o.copy_from_slice(&acc);
    }
    end
}

/// `out[u] = 0 + k[0] x src[starts[0] + u] + k[1] x src[starts[1] + u] + ...` (in that order)
/// for every `u`; `starts` as long as `k`.
#[inline(always)]
fn weighted_sum(out: &mut [f32], k: &[f32], src: &[f32], starts: &[usize]) {
    fold_rows(
        out,
        src,
        k.len(),
        |j| starts[j],
        0.0,
        |a, j, x| a + k[j] * x,
    );
}

/// The steps before and after the smoothing of [`blur_rows`].
trait RowSteps {
    /// Writes the input's row `t` into `line`.
    fn fill(&mut self, t: usize, line: &mut [f32]);
    /// Takes the output's row `v` (to change at will).
    fn emit(&mut self, v: usize, row: &mut [f32]);
}

/// A `w` x `h` image smoothed by the separable kernel `k` (edges clamped), one row at a time:
/// `steps.fill(t, line)` writes the input's row `t` into `line`, and `steps.emit(v, row)`
/// takes the output's row `v`, in order. Only the last `k.len()` horizontally smoothed rows
/// are kept (a ring), so that the steps before and after the smoothing run on rows in the
/// cache rather than through full-size intermediate images. The taps are summed in the same
/// order as a horizontal pass over the whole image followed by a vertical one. `w` and `h`
/// are not 0.
///
/// On a CPU with AVX2 the same code (the steps too: their methods are inlined) runs compiled
/// for it: twice the pixels per instruction, the same operations in the same order (no fused
/// multiply-adds), so the same results.
fn blur_rows(w: usize, h: usize, k: &[f32], steps: &mut impl RowSteps) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports the features the function is compiled for.
        unsafe { blur_rows_avx2(w, h, k, steps) };
        return;
    }
    blur_rows_any(w, h, k, steps);
}

/// [`blur_rows_any`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn blur_rows_avx2(w: usize, h: usize, k: &[f32], steps: &mut impl RowSteps) {
    blur_rows_any(w, h, k, steps);
}

/// [`blur_rows`] for any CPU.
#[inline(always)]
fn blur_rows_any(w: usize, h: usize, k: &[f32], steps: &mut impl RowSteps) {
    let n = k.len();
    let r = n / 2;
    // the input row padded with its edge values: the taps without bounds checks
    let mut pad = vec![0f32; w + 2 * r];
    let mut ring = vec![0f32; n * w];
    let mut out = vec![0f32; w];
    let shifts: Vec<usize> = (0..n).collect();
    let mut rows = vec![0usize; n];
    for t in 0..h + r {
        if t < h {
            steps.fill(t, &mut pad[r..r + w]);
            pad_edges(&mut pad, r);
            weighted_sum(&mut ring[(t % n) * w..(t % n + 1) * w], k, &pad, &shifts);
        }
        // the output row r rows up: a weighted sum of the rows within r of it (edge rows
        // repeated), all still in the ring
        if let Some(v) = t.checked_sub(r) {
            for (j, s) in rows.iter_mut().enumerate() {
                *s = (v + j).saturating_sub(r).min(h - 1) % n * w;
            }
            weighted_sum(&mut out, k, &ring, &rows);
            steps.emit(v, &mut out);
        }
    }
}

/// `img` smoothed by a separable Gaussian of `sigma` px (edges clamped).
pub fn gaussian_blur(img: &GrayImage, sigma: f64) -> GrayImage {
    if !(sigma > 0.0) || img.data.is_empty() {
        return img.clone();
    }
    let (w, h) = (img.width, img.height);
    let mut steps = Copied {
        img,
        out: Vec::with_capacity(w * h),
    };
    blur_rows(w, h, &kernel(sigma), &mut steps);
    GrayImage {
        width: w,
        height: h,
        data: steps.out,
    }
}

/// [`gaussian_blur`]'s steps: the image's rows in, the smoothed rows kept.
struct Copied<'a> {
    img: &'a GrayImage,
    out: Vec<f32>,
}

impl RowSteps for Copied<'_> {
    #[inline(always)]
    fn fill(&mut self, t: usize, line: &mut [f32]) {
        let w = self.img.width;
        line.copy_from_slice(&self.img.data[t * w..(t + 1) * w]);
    }

    #[inline(always)]
    fn emit(&mut self, _: usize, row: &mut [f32]) {
        self.out.extend_from_slice(row);
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
/// the pixels inside `mask` (every [`LEVEL_STRIDE`]-th) whose reference grey is neither dark
/// nor saturated; 1 when there are none. The imprints are a small part of the skin and do not
/// move the median.
fn capture_gain(reference: &GrayImage, capture: &GrayImage, mask: Option<&[bool]>) -> f32 {
    let mut ratios: Vec<f32> = samples(0, reference.data.len(), LEVEL_STRIDE, mask)
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

/// The pixels on the grid of every `stride`-th pixel (of the whole image) among the `n` from
/// pixel `base` on, inside `mask`: their offsets from `base`.
fn samples(
    base: usize,
    n: usize,
    stride: usize,
    mask: Option<&[bool]>,
) -> impl Iterator<Item = usize> + '_ {
    (base.next_multiple_of(stride) - base..n)
        .step_by(stride)
        .filter(move |&u| mask.is_none_or(|m| m[base + u]))
}

/// `gain x reference - capture` smoothed by the separable kernel `k` (the Gaussian of
/// [`gaussian_blur`], edges clamped, the taps summed in the same order) at each of `pixels`,
/// computed over those pixels alone: along each of their rows from the first of them to the
/// last, from the rows within the kernel's reach, smoothed horizontally over the columns that
/// those runs need.
fn smoothed_over(
    reference: &GrayImage,
    capture: &GrayImage,
    gain: f32,
    k: &[f32],
    pixels: &[(usize, usize)],
) -> Vec<f32> {
    let (w, h) = (reference.width, reference.height);
    let n = k.len();
    let r = n / 2;
    let (v0, v1) = pixels
        .iter()
        .fold((usize::MAX, 0), |(a, b), &(_, v)| (a.min(v), b.max(v)));
    if v0 > v1 {
        return Vec::new();
    }
    // each row's run: the columns of its first and last pixel
    let rows = v1 + 1 - v0;
    let hull = |runs: &[(usize, usize)]| {
        runs.iter()
            .fold((usize::MAX, 0), |(a, b), e| (a.min(e.0), b.max(e.1)))
    };
    let mut run = vec![(usize::MAX, 0); rows];
    for &(u, v) in pixels {
        let e = &mut run[v - v0];
        *e = (e.0.min(u), e.1.max(u));
    }
    let (u0, u1) = hull(&run);
    let cols = u1 + 1 - u0;
    // row q: the image's row v0 - r + q (clamped), smoothed along the row over the runs of
    // the rows q - 2r ..= q, the ones whose vertical taps reach it
    let mut hs = vec![0f32; (rows + 2 * r) * cols];
    let mut line = Vec::with_capacity(cols + 2 * r);
    let shifts: Vec<usize> = (0..n).collect();
    for q in 0..rows + 2 * r {
        let (a, b) = hull(&run[q.saturating_sub(2 * r)..(q + 1).min(rows)]);
        if a > b {
            continue;
        }
        let s = (v0 + q).saturating_sub(r).min(h - 1) * w;
        line.clear();
        line.extend((a..=b + 2 * r).map(|c| {
            let j = s + c.saturating_sub(r).min(w - 1);
            gain * reference.data[j] - capture.data[j]
        }));
        let out = &mut hs[q * cols + a - u0..q * cols + b + 1 - u0];
        weighted_sum(out, k, &line, &shifts);
    }
    // then across the rows, along each run
    let mut xs = vec![0f32; rows * cols];
    let mut starts = vec![0; n];
    for (j, &(a, b)) in run.iter().enumerate().filter(|(_, (a, b))| a <= b) {
        for (t, st) in starts.iter_mut().enumerate() {
            *st = (j + t) * cols + a - u0;
        }
        weighted_sum(
            &mut xs[j * cols + a - u0..j * cols + b + 1 - u0],
            k,
            &hs,
            &starts,
        );
    }
    pixels
        .iter()
        .map(|&(u, v)| xs[(v - v0) * cols + u - u0])
        .collect()
}

/// `out[u]` the smallest of `src[u]`, `src[u + stride]`, .. `src[u + (n - 1) stride]` for
/// every `u` (`f32::min` without its care for NaN, which does not vectorise as well).
#[inline(always)]
fn min_of_rows(out: &mut [f32], src: &[f32], n: usize, stride: usize) {
    fold_rows(
        out,
        src,
        n,
        |j| j * stride,
        f32::INFINITY,
        |a, _, x| {
            if a < x {
                a
            } else {
                x
            }
        },
    );
}

/// Row `t` of `img` eroded by a (2r + 1) x (2r + 1) square (the window cut at the edges) into
/// `out`: the smallest of the rows within `r` of `t`, then the smallest of that within `r`
/// along the row. `pad` is scratch of `width + 2 r` values.
#[inline(always)]
fn erode_row(img: &GrayImage, r: usize, t: usize, pad: &mut [f32], out: &mut [f32]) {
    let (w, h) = (img.width, img.height);
    let first = t.saturating_sub(r);
    let rows = (t + r).min(h - 1) + 1 - first;
    min_of_rows(&mut pad[r..r + w], &img.data[first * w..], rows, w);
    // padded with its edge values, which are in every cut window anyway
    pad_edges(pad, r);
    min_of_rows(out, pad, 2 * r + 1, 1);
}

/// `img` with each pixel replaced by the smallest within `r` px along each axis (a grey
/// erosion by a (2r + 1) x (2r + 1) square; separable; the window cut at the edges).
pub fn erode(img: &GrayImage, r: usize) -> GrayImage {
    let (w, h) = (img.width, img.height);
    if w < 2 || h < 2 || r == 0 {
        return img.clone();
    }
    let mut out = vec![0f32; w * h];
    let mut pad = vec![0f32; w + 2 * r];
    for (t, line) in out.chunks_exact_mut(w).enumerate() {
        erode_row(img, r, t, &mut pad, line);
    }
    GrayImage {
        width: w,
        height: h,
        data: out,
    }
}

/// Seeds are looked for only in the runs of this many pixels of a row whose largest smoothed
/// difference exceeds the upper threshold.
const SEED_BLOCK: usize = 64;

/// The largest of `x` (`-inf` when empty), in lanes that vectorise.
#[inline(always)]
fn max_of(x: &[f32]) -> f32 {
    let mut lanes = [f32::NEG_INFINITY; 8];
    let chunks = x.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, y) in lanes.iter_mut().zip(c) {
            *l = if *y > *l { *y } else { *l };
        }
    }
    lanes
        .iter()
        .chain(rest)
        .fold(f32::NEG_INFINITY, |a, &y| if y > a { y } else { a })
}

/// [`detect`]'s pass over the rows: each row of the reference eroded, the difference `gain x
/// eroded - capture` smoothed (the Gaussian of [`gaussian_blur`]); from each smoothed row the
/// samples of the noise, the pixels outside the mask set to -inf (never above a threshold),
/// the largest value of each [`SEED_BLOCK`]; on the way, the samples of how much the erosion
/// lowers the difference on the skin.
struct Difference<'a> {
    reference: &'a GrayImage,
    capture: &'a GrayImage,
    mask: Option<&'a [bool]>,
    gain: f32,
    /// The erosion's half-width, px.
    erode_px: usize,
    /// Scratch for [`erode_row`].
    pad: Vec<f32>,
    /// `gain x (reference - eroded)` on every [`LEVEL_STRIDE`]-th pixel inside the mask.
    lowered: Vec<f32>,
    /// The smoothed difference on every [`NOISE_STRIDE`]-th pixel inside the mask (plenty for
    /// a median, in a fraction of the time).
    noise: Vec<f32>,
    /// The smoothed difference, -inf outside the mask.
    d: Vec<f32>,
    /// The largest of `d` over each [`SEED_BLOCK`] of each row.
    block_max: Vec<f32>,
}

impl RowSteps for Difference<'_> {
    #[inline(always)]
    fn fill(&mut self, t: usize, line: &mut [f32]) {
        let w = self.reference.width;
        erode_row(self.reference, self.erode_px, t, &mut self.pad, line);
        let base = t * w;
        let plain = &self.reference.data[base..base + w];
        let gain = self.gain;
        let lowered =
            samples(base, w, LEVEL_STRIDE, self.mask).map(|u| gain * (plain[u] - line[u]));
        self.lowered.extend(lowered);
        for (x, c) in line.iter_mut().zip(&self.capture.data[base..base + w]) {
            *x = gain * *x - c;
        }
    }

    #[inline(always)]
    fn emit(&mut self, v: usize, row: &mut [f32]) {
        let w = row.len();
        let base = v * w;
        let noise = samples(base, w, NOISE_STRIDE, self.mask).map(|u| row[u]);
        self.noise.extend(noise);
        if let Some(m) = self.mask {
            for (x, &m) in row.iter_mut().zip(&m[base..base + w]) {
                *x = if m { *x } else { f32::NEG_INFINITY };
            }
        }
        self.block_max.extend(row.chunks(SEED_BLOCK).map(max_of));
        self.d.extend_from_slice(row);
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
    if w * h == 0 {
        return Ok(Vec::new());
    }
    let gain = if p.compensate_gain {
        capture_gain(reference, capture, mask)
    } else {
        1.0
    };
    let k = if p.smooth_sigma_px > 0.0 {
        kernel(p.smooth_sigma_px)
    } else {
        vec![1.0]
    };
    // as `erode` does, an image of one row or column is not eroded
    let er = if w < 2 || h < 2 {
        0
    } else {
        p.edge_tolerance_px
    };
    let mut pass = Difference {
        reference,
        capture,
        mask,
        gain,
        erode_px: er,
        pad: vec![0f32; w + 2 * er],
        lowered: Vec::with_capacity(w * h / LEVEL_STRIDE + 1),
        noise: Vec::with_capacity(w * h / NOISE_STRIDE + 1),
        d: Vec::with_capacity(w * h),
        block_max: Vec::with_capacity(h * w.div_ceil(SEED_BLOCK)),
    };
    blur_rows(w, h, &k, &mut pass);
    let Difference {
        mut lowered,
        mut noise,
        d,
        block_max,
        ..
    } = pass;
    let levels = Levels::of(&mut lowered, &mut noise, p);
    let measure = Measure {
        reference,
        capture,
        mask,
        gain,
        kernel: &k,
        levels: &levels,
        p,
    };
    let mut grow = Growth {
        d,
        w,
        h,
        stack: Vec::new(),
        pixels: Vec::new(),
    };
    let mut spots = Vec::new();
    // the seeds in the order of the pixels, in the blocks whose largest value exceeds the upper
    // threshold; each grows its spot. A pixel taken into a spot is set to -inf in `d`: no
    // other spot takes it, and no later seed starts there.
    let (hi, hi32) = (levels.hi, levels.hi as f32);
    let blocks = w.div_ceil(SEED_BLOCK);
    for (b, _) in block_max.iter().enumerate().filter(|(_, &x)| x > hi32) {
        let first = (b / blocks) * w + (b % blocks) * SEED_BLOCK;
        let end = first + SEED_BLOCK.min(w - (b % blocks) * SEED_BLOCK);
        for start in first..end {
            let d = &grow.d;
            if !(d[start] > hi32) || (d[start] as f64) <= hi {
                continue;
            }
            let peak = grow.spot_from(start, levels.lo, levels.med);
            spots.push(measure.spot(&grow.pixels, peak));
        }
    }
    let mut spots: Vec<Spot> = spots
        .into_iter()
        .filter(|s| s.area_px >= p.min_area_px)
        .collect();
    spots.sort_by(|a, b| b.score.total_cmp(&a.score));
    Ok(spots)
}

/// [`detect`]'s levels of the smoothed difference: its median and noise sigma over the mask,
/// the thresholds a spot starts above and grows above, and the growing threshold on the
/// difference with the reference itself (not eroded).
struct Levels {
    /// Median of the smoothed difference over the mask.
    med: f32,
    /// Noise: 1.4826 times the median absolute deviation of the smoothed difference.
    sigma: f64,
    /// A spot starts above this.
    hi: f64,
    /// ... and grows over its neighbours above this.
    lo: f64,
    /// `lo` on the difference with the reference itself (the erosion's median lowering added).
    lo_plain: f64,
}

impl Levels {
    /// The levels from [`Difference`]'s samples of the erosion's lowering (`lowered`) and of
    /// the smoothed difference (`noise`), both sorted in place, and the thresholds of `p`.
    fn of(lowered: &mut [f32], noise: &mut [f32], p: &DetectParams) -> Levels {
        let lo_offset = f64::from(median(lowered));
        // noise: the median absolute deviation of the smoothed difference over the mask
        let med = median(noise);
        let mut dev: Vec<f32> = noise.iter().map(|x| (x - med).abs()).collect();
        let sigma = (1.4826 * median(&mut dev)).max(1e-6) as f64;
        let hi = med as f64 + p.threshold_sigma * sigma;
        let lo = med as f64 + p.grow_sigma * sigma;
        // the same lower threshold on the difference with the reference itself: the erosion
        // lowers the difference by about the same everywhere on smooth skin (the darkest of
        // the reference's noise within the window), which would otherwise weigh every pixel of
        // a spot alike and pull its centre to the middle of its area
        let lo_plain = lo + lo_offset;
        Levels {
            med,
            sigma,
            hi,
            lo,
            lo_plain,
        }
    }
}

/// The growing of spots over the smoothed difference `d` (`w` x `h`, -inf outside the mask and
/// where a spot took a pixel), with its scratch.
struct Growth {
    d: Vec<f32>,
    w: usize,
    h: usize,
    stack: Vec<(usize, usize)>,
    /// The pixels (u, v) of the spot grown last.
    pixels: Vec<(usize, usize)>,
}

impl Growth {
    /// Grows the spot seeded at pixel `start` by hysteresis over 8-neighbours above `lo` into
    /// `pixels`, taking each pixel out of `d`; returns the peak over the pixels taken (above
    /// the median `med`, at least 0).
    fn spot_from(&mut self, start: usize, lo: f64, med: f32) -> f64 {
        let (w, h) = (self.w, self.h);
        let (d, stack, pixels) = (&mut self.d, &mut self.stack, &mut self.pixels);
        // grow by hysteresis over 8-neighbours above `lo`; the peak over the pixels taken
        let mut peak = (d[start] as f64 - med as f64).max(0.0);
        d[start] = f32::NEG_INFINITY;
        stack.push((start % w, start / w));
        pixels.clear();
        while let Some((u, v)) = stack.pop() {
            pixels.push((u, v));
            let (u0, u1) = (u.saturating_sub(1), (u + 1).min(w - 1));
            for vv in v.saturating_sub(1)..=(v + 1).min(h - 1) {
                for uu in u0..=u1 {
                    let j = vv * w + uu;
                    if d[j] as f64 > lo {
                        peak = peak.max(d[j] as f64 - med as f64);
                        d[j] = f32::NEG_INFINITY;
                        stack.push((uu, vv));
                    }
                }
            }
        }
        peak
    }
}

/// [`detect`]'s measure of a grown spot: its centre, shape and halves from the difference with
/// the reference itself.
struct Measure<'a> {
    reference: &'a GrayImage,
    capture: &'a GrayImage,
    mask: Option<&'a [bool]>,
    gain: f32,
    /// The smoothing Gaussian's kernel.
    kernel: &'a [f32],
    levels: &'a Levels,
    p: &'a DetectParams,
}

/// A spot's sums over its pixels: the weighted centroid's, the core's (the pixels of positive
/// weight) unweighted moments, and whether the spot and its core touch an edge.
struct Moments {
    /// Sum of the weights, and of the weights times u and v.
    sw: f64,
    su: f64,
    sv: f64,
    /// The core's sums of u, v, u^2, v^2 and u v.
    m: [f64; 5],
    /// The core's pixels (u, v).
    core: Vec<(usize, usize)>,
    clipped: bool,
    core_clipped: bool,
}

impl Measure<'_> {
    /// The [`Spot`] of `pixels` (grown from a seed, `peak` its largest smoothed difference
    /// above the median).
    fn spot(&self, pixels: &[(usize, usize)], peak: f64) -> Spot {
        let (w, h) = (self.reference.width, self.reference.height);
        let (p, lo_plain) = (self.p, self.levels.lo_plain);
        // weighted by the difference with the reference itself (not eroded), smoothed the
        // same way: the erosion decides which pixels a spot has, not its centre; the
        // weights are the darkening above the core's level (`core_fraction` of the way
        // from the growing threshold to the spot's peak)
        let plain = smoothed_over(self.reference, self.capture, self.gain, self.kernel, pixels);
        let top = plain
            .iter()
            .fold(f64::NEG_INFINITY, |a, &x| a.max(f64::from(x)));
        let level = lo_plain + p.core_fraction * (top - lo_plain).max(0.0);
        let wts: Vec<f64> = plain
            .iter()
            .map(|&x| (f64::from(x) - level).max(0.0))
            .collect();
        let Moments {
            sw,
            su,
            sv,
            m,
            core,
            clipped,
            core_clipped,
        } = self.moments(pixels, &wts);
        let area = pixels.len();
        let n = core.len() as f64;
        let (roundness, major_sd) = if core.is_empty() {
            (1.0, 0.0)
        } else {
            let (r, major, _, _) = shape(n, m[0], m[1], m[2], m[3], m[4]);
            (r, major)
        };
        let core_wts: Vec<f64> = wts.iter().copied().filter(|&x| x > 0.0).collect();
        let halves = halves_of(&core, &core_wts, 2 * p.min_area_px.max(1));
        // a spot whose core has no weight (its peak at the growing threshold): its pixels'
        // centroid
        let (su, sv, sw) = if sw > 0.0 {
            (su, sv, sw)
        } else {
            let (a, b) = pixels
                .iter()
                .fold((0.0, 0.0), |(a, b), &(u, v)| (a + u as f64, b + v as f64));
            (a, b, area as f64)
        };
        // a core cut by the mask's edge: the centre of the disc whose visible part it is
        let (du, dv) = if core_clipped && !core.is_empty() {
            clipped_disc_shift(&core, 2.0 * major_sd, w, h, self.mask)
        } else {
            (0.0, 0.0)
        };
        Spot {
            u_px: su / sw + du,
            v_px: sv / sw + dv,
            score: peak / self.levels.sigma,
            area_px: area,
            roundness,
            major_sd_px: major_sd,
            core_px: core.len(),
            clipped,
            halves,
        }
    }

    /// The [`Moments`] of `pixels` weighted by `wts`; a pixel on the image's border or beside
    /// one outside the mask is on an edge.
    fn moments(&self, pixels: &[(usize, usize)], wts: &[f64]) -> Moments {
        let (w, h, mask) = (self.reference.width, self.reference.height, self.mask);
        let (mut sw, mut su, mut sv) = (0f64, 0f64, 0f64);
        // the core's pixels' moments, unweighted (its shape: a halo the spot grew into
        // is not the imprint's)
        let mut m = [0f64; 5];
        let mut core = Vec::with_capacity(pixels.len());
        let (mut clipped, mut core_clipped) = (false, false);
        for (&(u, v), &x) in pixels.iter().zip(wts) {
            let (fu, fv) = (u as f64, v as f64);
            sw += x;
            su += x * fu;
            sv += x * fv;
            if x > 0.0 {
                core.push((u, v));
                m[0] += fu;
                m[1] += fv;
                m[2] += fu * fu;
                m[3] += fv * fv;
                m[4] += fu * fv;
            }
            let edge = u == 0
                || v == 0
                || u + 1 == w
                || v + 1 == h
                || mask.is_some_and(|m| {
                    !(m[v * w + u - 1] && m[v * w + u + 1] && m[v * w + u - w] && m[v * w + u + w])
                });
            clipped |= edge;
            core_clipped |= edge && x > 0.0;
        }
        Moments {
            sw,
            su,
            sv,
            m,
            core,
            clipped,
            core_clipped,
        }
    }
}

/// A spot's core (`core` pixels, weights `core_wts`) cut in two ([`split_core`]) and each half
/// cut in two again (three or four imprints joined); `None` for fewer than `min_px` pixels.
fn halves_of(core: &[(usize, usize)], core_wts: &[f64], min_px: usize) -> Option<[Half; 2]> {
    split_core(core, core_wts, min_px).map(|(hs, sides)| {
        // each half cut in two again (three or four imprints joined)
        let mut out = hs;
        for (k, h) in out.iter_mut().enumerate() {
            let (px, ws): (Vec<(usize, usize)>, Vec<f64>) = core
                .iter()
                .zip(core_wts)
                .zip(&sides)
                .filter(|(_, &sd)| usize::from(sd) == k)
                .map(|((&q, &x), _)| (q, x))
                .unzip();
            h.parts = split_core(&px, &ws, min_px).map(|(ps, _)| {
                ps.map(|q| Part {
                    u_px: q.u_px,
                    v_px: q.v_px,
                    area_px: q.area_px,
                })
            });
        }
        out
    })
}

pub use assign::{
    assign_ids, assign_ids_through, Assignment, CaptureOutcome, CaptureSpots, Observation,
    MAX_PINS_PER_CAPTURE,
};

/// The ids a capture's file name lists in ring order (the R-Tac0 authors' convention:
/// `01_02_06_14_22.png` holds pins 1, 2, 6, 14 and 22): the stem's `_`-separated numbers; for
/// a file whose stem is `image`, its folder's name (`01_02_06_14_22/image.png`, as `fabkit
/// groundtruth --pin-captures --images` writes a capture). `None` when the name is not such a
/// list.
pub fn ids_from_file_name(path: &std::path::Path) -> Option<Vec<u32>> {
    ids_of(&capture_name(path)?)
}

/// A capture's name: its file's stem, or for a file whose stem is `image` its folder's name
/// (`01_02_06/image.png`: `01_02_06`, as `fabkit groundtruth --pin-captures --images` writes
/// a capture). Names the files made per capture (overlays, re-rendered captures).
pub fn capture_name(path: &std::path::Path) -> Option<String> {
    let stem = path.file_stem()?;
    let named = if stem == "image" {
        path.parent()?.file_name()?
    } else {
        stem
    };
    Some(named.to_string_lossy().into_owned())
}

/// The `_`-separated numbers of `name`; `None` when it is not such a list.
fn ids_of(name: &str) -> Option<Vec<u32>> {
    name.split('_')
        .map(|t| {
            (!t.is_empty() && t.chars().all(|c| c.is_ascii_digit()))
                .then(|| t.parse::<u32>().ok())
                .flatten()
        })
        .collect()
}

/// The first pin a capture lists more than once, with how often: a capture presses each pin
/// once (`01_01_01_01_01.png` lists pin 1 five times). `None` when every pin is listed once.
pub fn repeated_pin(ids: &[u32]) -> Option<(u32, usize)> {
    ids.iter()
        .find(|id| ids.iter().filter(|x| x == id).count() > 1)
        .map(|&id| (id, ids.iter().filter(|&&x| x == id).count()))
}

pub mod synthetic;
