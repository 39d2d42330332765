//! Fitting the model ([`PhotometricModel::fit`]) from the reference image and the captures.

use super::contact::capture_gain;
use super::faults::{capture_fault, image_fault};
use super::model::{Capture, PhotometricModel};
use super::render::rms_over_skin;
use super::shadows::{ShadowPixel, ShadowRings};
use super::terms::{
    features, light_features, optical_axis, spatial, COEFFICIENTS, FEATURES, LIGHT_TERMS,
    MIN_REFERENCE_COUNTS, SHADOW_TERMS, SPATIAL_TERMS,
};
use crate::groundtruth::hits::SurfaceHits;
use crate::groundtruth::rays::PixelRays;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

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
        let model = Self::fit_unrendered(rays, reference, reference_image, captures, full_scale)?;
        Ok(model.with_residuals(rays, reference, captures))
    }

    /// [`Self::fit`] without rendering the captures for their residuals: the same model with
    /// `residual_rms` empty, for a caller that renders each capture with the model itself
    /// (`calibrate photometric`'s seating rounds and its final fit) and would otherwise render
    /// every capture twice.
    ///
    /// # Errors
    /// As [`Self::fit`].
    pub fn fit_unrendered(
        rays: &PixelRays,
        reference: &SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &[Capture<'_>],
        full_scale: f64,
    ) -> Result<PhotometricModel, String> {
        check_inputs(rays, reference, reference_image, captures, full_scale)?;
        let gains = Self::reference_gains(rays, reference, reference_image, captures, full_scale);
        Self::fit_checked(
            rays,
            reference,
            reference_image,
            captures,
            gains,
            full_scale,
        )
    }

    /// Each capture's gain against `reference_image` ([`capture_gain`]), as [`Self::fit`]
    /// measures it: one capture's gain does not depend on the others, so a caller fitting
    /// several subsets of the same captures (the leave-one-out) measures them once.
    pub fn reference_gains(
        rays: &PixelRays,
        reference: &SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &[Capture<'_>],
        full_scale: f64,
    ) -> Vec<f64> {
        let (w, h) = (rays.width, rays.height);
        captures
            .par_iter()
            .map(|c| capture_gain(c, reference_image, reference, w, h, full_scale))
            .collect()
    }

    /// [`Self::fit`] with each capture's gain given ([`Self::reference_gains`] of the same
    /// captures): the same model.
    ///
    /// # Errors
    /// As [`Self::fit`], and when `gains` has not one value per capture.
    pub fn fit_with_gains(
        rays: &PixelRays,
        reference: &SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &[Capture<'_>],
        gains: &[f64],
        full_scale: f64,
    ) -> Result<PhotometricModel, String> {
        check_inputs(rays, reference, reference_image, captures, full_scale)?;
        if gains.len() != captures.len() {
            return Err(format!(
                "{} gains for {} captures",
                gains.len(),
                captures.len()
            ));
        }
        let model = Self::fit_checked(
            rays,
            reference,
            reference_image,
            captures,
            gains.to_vec(),
            full_scale,
        )?;
        Ok(model.with_residuals(rays, reference, captures))
    }

    /// [`Self::fit_unrendered`] of checked inputs with their gains.
    fn fit_checked(
        rays: &PixelRays,
        reference: &SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &[Capture<'_>],
        gains: Vec<f64>,
        full_scale: f64,
    ) -> Result<PhotometricModel, String> {
        let (problem, appearance) = Problem::of(
            rays,
            reference,
            reference_image,
            captures,
            gains,
            full_scale,
        )?;
        problem.solve(appearance, &problem.rows(), None)
    }

    /// This model (fitted on every one of `captures`, its `gains` theirs) with each capture's
    /// residual RMS over its skin.
    fn with_residuals(
        mut self,
        rays: &PixelRays,
        reference: &SurfaceHits,
        captures: &[Capture<'_>],
    ) -> PhotometricModel {
        let residuals = captures
            .par_iter()
            .zip(&self.gains)
            .map(|(c, g)| {
                rms_over_skin(
                    &self.render(rays, reference, c.hits, c.shadows, *g),
                    c.image,
                )
            })
            .collect();
        self.residual_rms = residuals;
        self
    }
}

/// The candidate light rings of `rays` over `reference` ([`ShadowRings::of`]).
///
/// # Errors
/// A message naming the first capture whose shadows are of other rings.
fn rings_of(
    rays: &PixelRays,
    reference: &SurfaceHits,
    captures: &[Capture<'_>],
) -> Result<ShadowRings, String> {
    let rings = ShadowRings::of(rays, reference);
    if let Some(k) = captures.iter().position(|c| c.shadows.rings != rings) {
        return Err(format!(
            "capture {k}: its shadows are of other light rings than this camera's"
        ));
    }
    Ok(rings)
}

/// What a fit of some of `captures` shares with every other: the camera's rays, the
/// reference surface, each capture's gain, the light rings and the full scale.
struct Problem<'a> {
    rays: &'a PixelRays,
    reference: &'a SurfaceHits,
    captures: &'a [Capture<'a>],
    gains: Vec<f64>,
    rings: ShadowRings,
    full_scale: f64,
}

impl<'a> Problem<'a> {
    /// The problem of the fit on checked inputs with their gains, and its appearance
    /// ([`appearance`]).
    ///
    /// # Errors
    /// When a capture's shadows are of other light rings ([`rings_of`]).
    fn of(
        rays: &'a PixelRays,
        reference: &'a SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &'a [Capture<'a>],
        gains: Vec<f64>,
        full_scale: f64,
    ) -> Result<(Problem<'a>, Vec<[f64; 3]>), String> {
        let problem = Problem::new(rays, reference, captures, gains, full_scale)?;
        let appearance = appearance(reference, reference_image, captures, &problem.gains);
        Ok((problem, appearance))
    }

    /// The problem of `captures` with their gains, and the camera's light rings.
    ///
    /// # Errors
    /// When a capture's shadows are of other light rings ([`rings_of`]).
    fn new(
        rays: &'a PixelRays,
        reference: &'a SurfaceHits,
        captures: &'a [Capture<'a>],
        gains: Vec<f64>,
        full_scale: f64,
    ) -> Result<Problem<'a>, String> {
        Ok(Problem {
            rays,
            reference,
            captures,
            gains,
            rings: rings_of(rays, reference, captures)?,
            full_scale,
        })
    }
}

impl Problem<'_> {
    /// The model of `appearance` fitted over `rows` but capture `skip`'s, carrying the gains
    /// of the captures it is fitted on; its `residual_rms` is left empty.
    ///
    /// # Errors
    /// When those rows hold fewer pressed pixels than twice the unknowns.
    fn solve(
        &self,
        appearance: Vec<[f64; 3]>,
        rows: &Rows<'_>,
        skip: Option<usize>,
    ) -> Result<PhotometricModel, String> {
        let (rays, rings) = (self.rays, self.rings);
        let pressed = rows.pressed.iter().sum::<usize>() - skip.map_or(0, |k| rows.pressed[k]);
        let model_gains = (0..self.gains.len())
            .filter(|&j| Some(j) != skip)
            .map(|j| self.gains[j])
            .collect();
        // The response to tilt and the shadows, by least squares on the pressed and the
        // shadowed pixels of every capture.
        let unknowns = COEFFICIENTS + SHADOW_TERMS;
        if pressed < 2 * unknowns {
            return Err(format!(
                "the captures press {} pixels of the skin, fewer than the {} the fit needs (twice its {unknowns} unknowns): give captures with more imprints",
                pressed,
                2 * unknowns
            ));
        }
        let design = Design {
            captures: self.captures,
            appearance: &appearance,
            gains: &self.gains,
            full_scale: self.full_scale,
        };
        let mut coefficients: [Vec<f64>; 3] = Default::default();
        let mut shadow_coefficients = [[0.0; SHADOW_TERMS]; 3];
        // the channels are independent problems: solved in parallel, kept in channel order
        let solved: Vec<DVector<f64>> = (0..3)
            .into_par_iter()
            .map(|ch| design.solve(ch, rows, skip))
            .collect();
        for (ch, (coef, x)) in coefficients.iter_mut().zip(&solved).enumerate() {
            *coef = x.iter().take(COEFFICIENTS).copied().collect();
            shadow_coefficients[ch] = std::array::from_fn(|m| x[COEFFICIENTS + m]);
        }
        Ok(PhotometricModel {
            width: rays.width,
            height: rays.height,
            reference: appearance,
            coefficients,
            axis: optical_axis(rays),
            rings,
            shadow_coefficients,
            gains: model_gains,
            full_scale: self.full_scale,
            residual_rms: Vec::new(),
        })
    }
}

impl<'a> Problem<'a> {
    /// The rows of the fit with their terms ([`Rows`]).
    fn rows(&self) -> Rows<'a> {
        let (rays, reference, captures) = (self.rays, self.reference, self.captures);
        let (w, h) = (rays.width, rays.height);
        let (rows, _) = fit_rows(reference, captures, w * h);
        let mut pressed = vec![0; captures.len()];
        for &(k, i, _) in &rows {
            pressed[k] += usize::from(captures[k].hits.contact[i]);
        }
        let (axis, lights) = (optical_axis(rays), self.rings.point_lights());
        let terms: Vec<Option<[f64; UNKNOWNS]>> = rows
            .par_iter()
            .map(|&(k, i, sh)| {
                let f = features(i, captures[k].hits, reference, axis)?;
                let mut row = [0.0; UNKNOWNS];
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
                row[FEATURES * SPATIAL_TERMS..COEFFICIENTS].copy_from_slice(&lf);
                for (m, x) in row[COEFFICIENTS..].iter_mut().enumerate() {
                    *x = -sh.map_or(0.0, |f| f.rings[m]);
                }
                Some(row)
            })
            .collect();
        Rows {
            rows,
            terms,
            pressed,
        }
    }
}

/// The unknowns of the fit: the response's coefficients, then the shadows' weights.
const UNKNOWNS: usize = COEFFICIENTS + SHADOW_TERMS;

/// The rows of the fit ([`fit_rows`]) with each row's terms before weighting, the same for
/// every channel and every subset of the captures: the features times the spatial terms, the
/// light features and the shadows (negated); `None` where the features are undefined.
struct Rows<'a> {
    rows: Vec<FitRow<'a>>,
    terms: Vec<Option<[f64; UNKNOWNS]>>,
    /// How many of each capture's rows are pressed pixels.
    pressed: Vec<usize>,
}

/// The leave-one-out of a fit: for each capture, the model fitted on the others
/// ([`Self::model`]), without refitting from the images. The inputs are checked and each
/// capture's gain measured once; the appearance's per-pixel medians are sorted once, and
/// the median without one capture is read from the values around the middle (the same value
/// as sorting the others); the normal equations are summed over the others' rows.
pub struct LeaveOneOut<'a> {
    problem: Problem<'a>,
    /// Per pixel and channel, the sorted values of the appearance's median ([`appearance`]):
    /// their number and the three from `(len - 2) / 2` (NaN past the end), and their median.
    middles: Vec<[Middle; 3]>,
    rows: Rows<'a>,
}

/// The values around the middle of one pixel's and channel's sorted appearance values.
#[derive(Clone, Copy)]
struct Middle {
    len: u32,
    around: [f64; 3],
    median: f64,
}

impl<'a> LeaveOneOut<'a> {
    /// Prepares the fit of [`PhotometricModel::fit`] on the same inputs ([`Self::all`]) and
    /// its leave-one-out ([`Self::model`]), each capture's gain measured once against the
    /// reference image ([`PhotometricModel::reference_gains`]).
    ///
    /// # Errors
    /// As [`PhotometricModel::fit`]'s checks of its inputs.
    pub fn new(
        rays: &'a PixelRays,
        reference: &'a SurfaceHits,
        reference_image: &[[f64; 3]],
        captures: &'a [Capture<'a>],
        full_scale: f64,
    ) -> Result<LeaveOneOut<'a>, String> {
        check_inputs(rays, reference, reference_image, captures, full_scale)?;
        let gains = PhotometricModel::reference_gains(
            rays,
            reference,
            reference_image,
            captures,
            full_scale,
        );
        let problem = Problem::new(rays, reference, captures, gains, full_scale)?;
        let gains = &problem.gains;
        let n = rays.width * rays.height;
        let middles = (0..n)
            .into_par_iter()
            .map_init(Vec::new, |v, i| {
                std::array::from_fn(|ch| {
                    if !reference.t_mm[i].is_finite() {
                        return Middle {
                            len: 0,
                            around: [f64::NAN; 3],
                            median: f64::NAN,
                        };
                    }
                    appearance_values(v, i, ch, reference_image, captures, gains);
                    let median = crate::median_sorting(v);
                    let from = first_around(v.len());
                    Middle {
                        len: v.len() as u32,
                        around: std::array::from_fn(|q| {
                            v.get(from + q).copied().unwrap_or(f64::NAN)
                        }),
                        median,
                    }
                })
            })
            .collect();
        let rows = problem.rows();
        Ok(LeaveOneOut {
            problem,
            middles,
            rows,
        })
    }

    /// The model [`PhotometricModel::fit`] fits on every capture, the same to the bit.
    ///
    /// # Errors
    /// As that fit's (too few pressed pixels).
    pub fn all(&self) -> Result<PhotometricModel, String> {
        let p = &self.problem;
        Ok(self
            .all_unrendered()?
            .with_residuals(p.rays, p.reference, p.captures))
    }

    /// [`Self::all`] with `residual_rms` empty, as [`PhotometricModel::fit_unrendered`].
    ///
    /// # Errors
    /// As [`Self::all`].
    pub fn all_unrendered(&self) -> Result<PhotometricModel, String> {
        let appearance = self.middles.iter().map(|m| m.map(|m| m.median)).collect();
        self.problem.solve(appearance, &self.rows, None)
    }

    /// The model [`PhotometricModel::fit_with_gains`] fits on every capture but `k` with
    /// their gains, the same to the bit, except that its `residual_rms` is empty (the
    /// others are not rendered).
    ///
    /// # Errors
    /// As that fit's (too few pressed pixels without capture `k`); `k` out of range.
    pub fn model(&self, k: usize) -> Result<PhotometricModel, String> {
        let p = &self.problem;
        let Some(left) = p.captures.get(k) else {
            return Err(format!("no capture {k} of {}", p.captures.len()));
        };
        let gain = p.gains[k];
        let appearance = self
            .middles
            .par_iter()
            .enumerate()
            .map(|(i, m)| {
                std::array::from_fn(|ch| {
                    let m = &m[ch];
                    if m.len == 0 || left.hits.contact[i] {
                        // off the skin, or capture k pressed here: not among the values
                        return m.median;
                    }
                    without(m, left.image[i][ch] / gain)
                })
            })
            .collect();
        p.solve(appearance, &self.rows, Some(k))
    }
}

/// The first of the values a [`Middle`] of `len` sorted values keeps: `(len - 2) / 2`, the
/// position of the lower middle once one value is taken out.
fn first_around(len: usize) -> usize {
    (len.max(2) - 2) / 2
}

/// The median of the sorted values `m` stands for, with one value equal to `v` taken out
/// (`v` is among them; at least one remains): the value at position `q` of the rest is
/// `s[q]` where `s[q] < v`, else `s[q + 1]`, and the rest's middle positions lie within
/// `m.around`.
fn without(m: &Middle, v: f64) -> f64 {
    let from = first_around(m.len as usize);
    let len = m.len as usize - 1;
    // the rest's value at position q (q in from..from + 2)
    let at = |q: usize| {
        let s = m.around[q - from];
        if s.total_cmp(&v).is_lt() {
            s
        } else {
            m.around[q - from + 1]
        }
    };
    let mid = len / 2;
    if len % 2 == 1 {
        at(mid)
    } else {
        0.5 * (at(mid - 1) + at(mid))
    }
}

/// [`PhotometricModel::fit`]'s checks of its inputs: the reference image, the reference
/// surface and every capture of the camera's size, the reference lit and not overexposed
/// ([`image_fault`]), every capture showing its imprints ([`capture_fault`]).
///
/// # Errors
/// A message naming the image and what is wrong with it.
fn check_inputs(
    rays: &PixelRays,
    reference: &SurfaceHits,
    reference_image: &[[f64; 3]],
    captures: &[Capture<'_>],
    full_scale: f64,
) -> Result<(), String> {
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
    // each capture checked on its own, in parallel; the first fault in the captures' order
    let faults: Vec<_> = captures
        .par_iter()
        .map(|c| capture_fault(reference, reference_image, c, full_scale))
        .collect();
    if let Some((k, f)) = faults
        .into_iter()
        .enumerate()
        .find_map(|(k, f)| Some((k, f?)))
    {
        return Err(format!("capture {k}: {f}"));
    }
    Ok(())
}

/// The unindented appearance: per pixel and channel, the median of the reference and every
/// capture's unpressed value divided by its gain (a highlight or a speck that only one image
/// shows does not move it; with no capture unpressed there, the reference); NaN off the skin.
fn appearance(
    reference: &SurfaceHits,
    reference_image: &[[f64; 3]],
    captures: &[Capture<'_>],
    gains: &[f64],
) -> Vec<[f64; 3]> {
    (0..reference_image.len())
        .into_par_iter()
        .map_init(Vec::new, |v, i| {
            if !reference.t_mm[i].is_finite() {
                return [f64::NAN; 3];
            }
            std::array::from_fn(|ch| {
                appearance_values(v, i, ch, reference_image, captures, gains);
                crate::median_selecting(v)
            })
        })
        .collect()
}

/// The values whose median is the appearance of pixel `i` in channel `ch` ([`appearance`]),
/// into `v` (emptied first): the reference's, then each capture's where it is unpressed,
/// divided by its gain.
fn appearance_values(
    v: &mut Vec<f64>,
    i: usize,
    ch: usize,
    reference_image: &[[f64; 3]],
    captures: &[Capture<'_>],
    gains: &[f64],
) {
    v.clear();
    v.push(reference_image[i][ch]);
    v.extend(
        captures
            .iter()
            .zip(gains)
            .filter(|(c, _)| !c.hits.contact[i])
            .map(|(c, g)| c.image[i][ch] / g),
    );
}

/// The dot product of `x` and `y` (of one length), summed in four interleaved partial sums
/// (so that it vectorises), then the rest in order: the same value on every machine.
fn dot_product(x: &[f64], y: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (xs, ys) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xs.remainder(), ys.remainder());
    for (a, b) in xs.zip(ys) {
        for q in 0..4 {
            acc[q] += a[q] * b[q];
        }
    }
    let mut sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (a, b) in xr.iter().zip(yr) {
        sum += a * b;
    }
    sum
}

/// Adds to the upper triangle of `ata` (`m` x `m`) the dot products of the columns of
/// `block` (column-major, columns `stride` apart, the first `filled` values of each): each
/// element exactly [`dot_product`] of its two columns, the same bits, computed a tile of
/// columns at a time so that each column's values are loaded once for several products.
/// With AVX2 (detected at run time) the same operations run four lanes wide: the result is
/// the same on every machine (IEEE products and sums in one order, never fused).
fn add_upper_products(ata: &mut DMatrix<f64>, block: &[f64], stride: usize, filled: usize) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked above), all the function requires.
        unsafe { add_upper_products_avx2(ata, block, stride, filled) };
        return;
    }
    add_upper_products_tiled::<2>(ata, block, stride, filled);
}

/// [`add_upper_products`] compiled for AVX2, in 3 x 3 tiles (nine four-lane accumulators).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn add_upper_products_avx2(ata: &mut DMatrix<f64>, block: &[f64], stride: usize, filled: usize) {
    add_upper_products_tiled::<3>(ata, block, stride, filled);
}

/// [`add_upper_products`] in `T` x `T` tiles of columns; the columns past the last whole tile
/// by [`dot_product`].
#[inline(always)]
fn add_upper_products_tiled<const T: usize>(
    ata: &mut DMatrix<f64>,
    block: &[f64],
    stride: usize,
    filled: usize,
) {
    let m = ata.nrows();
    let col = |a: usize| &block[a * stride..a * stride + filled];
    let whole = m / T * T;
    for c0 in (0..whole).step_by(T) {
        for a0 in (0..=c0).step_by(T) {
            let tile = tile_products::<T>(
                std::array::from_fn(|i| col(a0 + i)),
                std::array::from_fn(|j| col(c0 + j)),
            );
            for (i, row) in tile.iter().enumerate() {
                for (j, x) in row.iter().enumerate() {
                    if a0 + i <= c0 + j {
                        ata[(a0 + i, c0 + j)] += x;
                    }
                }
            }
        }
    }
    for c in whole..m {
        for a in 0..=c {
            ata[(a, c)] += dot_product(col(a), col(c));
        }
    }
}

/// [`dot_product`] of every column of `xs` with every column of `ys` (all of one length).
#[inline(always)]
fn tile_products<const T: usize>(xs: [&[f64]; T], ys: [&[f64]; T]) -> [[f64; T]; T] {
    let len = xs[0].len();
    let n4 = len / 4;
    let xc: [&[[f64; 4]]; T] = std::array::from_fn(|i| &xs[i][..len].as_chunks::<4>().0[..n4]);
    let yc: [&[[f64; 4]]; T] = std::array::from_fn(|j| &ys[j][..len].as_chunks::<4>().0[..n4]);
    let mut acc = [[[0.0f64; 4]; T]; T];
    for t in 0..n4 {
        let x: [[f64; 4]; T] = std::array::from_fn(|i| xc[i][t]);
        let y: [[f64; 4]; T] = std::array::from_fn(|j| yc[j][t]);
        for i in 0..T {
            for j in 0..T {
                for q in 0..4 {
                    acc[i][j][q] += x[i][q] * y[j][q];
                }
            }
        }
    }
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let a = &acc[i][j];
            let mut sum = (a[0] + a[1]) + (a[2] + a[3]);
            for r in 4 * n4..len {
                sum += xs[i][r] * ys[j][r];
            }
            sum
        })
    })
}

/// Writes the rows `picked` (each row's terms and its weight `r`), each times its weight, into
/// the first `picked.len()` values of the columns of `block` (column-major, columns `stride`
/// apart), eight columns at a time so that each row's terms are read once per eight columns
/// and each column is written in order.
fn fill_columns(block: &mut [f64], stride: usize, picked: &[(&[f64; UNKNOWNS], f64)]) {
    for a0 in (0..UNKNOWNS).step_by(8) {
        let a1 = (a0 + 8).min(UNKNOWNS);
        for (t, (row, r)) in picked.iter().enumerate() {
            for (a, x) in row.iter().enumerate().take(a1).skip(a0) {
                block[a * stride + t] = r * x;
            }
        }
    }
}

/// Rows of the fit multiplied at a time into its normal equations.
const NORMAL_BLOCK: usize = 1024;

/// A row of the fit: (capture, pixel, its shadow if shadowed).
type FitRow<'a> = (usize, usize, Option<&'a ShadowPixel>);

/// The rows of the fit: every capture's pressed or shadowed pixels on the skin (of `n`),
/// capture major, and how many of them are pressed.
fn fit_rows<'a>(
    reference: &SurfaceHits,
    captures: &[Capture<'a>],
    n: usize,
) -> (Vec<FitRow<'a>>, usize) {
    let on_skin = |i: usize| reference.t_mm[i].is_finite();
    let mut rows: Vec<FitRow<'a>> = Vec::new();
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
    (rows, pressed)
}

/// The least-squares problem of the fit, one channel at a time: the captures with their
/// gains, the appearance and the full scale.
struct Design<'a> {
    captures: &'a [Capture<'a>],
    appearance: &'a [[f64; 3]],
    gains: &'a [f64],
    full_scale: f64,
}

impl Design<'_> {
    /// Channel `ch`'s coefficients over `rows` but capture `skip`'s ([`COEFFICIENTS`] of
    /// the response, then [`SHADOW_TERMS`] of the shadows): the normal equations solved by
    /// Cholesky, else by SVD; zero for a channel without light (all pixels below the floor).
    fn solve(&self, ch: usize, rows: &Rows<'_>, skip: Option<usize>) -> DVector<f64> {
        let unknowns = UNKNOWNS;
        let (ata, atb) = self.normal_equations(ch, rows, skip);
        // a channel without light (all pixels below the floor) keeps zero coefficients
        ata.clone()
            .cholesky()
            .map(|c| c.solve(&atb))
            .or_else(|| ata.svd(true, true).solve(&atb, 1e-12).ok())
            .unwrap_or_else(|| DVector::zeros(unknowns))
    }

    /// The normal equations `A^T W A x = A^T W y` of channel `ch` over `rows` but capture
    /// `skip`'s: each usable row (lit, not saturated) the ratio's change `y` against the
    /// row's terms ([`Rows`]), weighted by the reference squared so that each row counts in
    /// grey levels.
    fn normal_equations(
        &self,
        ch: usize,
        rows: &Rows<'_>,
        skip: Option<usize>,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let (captures, gains, full_scale) = (self.captures, self.gains, self.full_scale);
        let unknowns = UNKNOWNS;
        let mut ata = DMatrix::<f64>::zeros(unknowns, unknowns);
        let mut atb = DVector::<f64>::zeros(unknowns);
        // the weighted rows, a block at a time: A^T W A accumulated by matrix products
        let mut block = DMatrix::<f64>::zeros(NORMAL_BLOCK, unknowns);
        let mut block_y = DVector::<f64>::zeros(NORMAL_BLOCK);
        // the block's rows (their terms and weight), written into its columns when it is full
        let mut picked: Vec<(&[f64; UNKNOWNS], f64)> = Vec::with_capacity(NORMAL_BLOCK);
        let mut flush = |block: &mut DMatrix<f64>,
                         block_y: &DVector<f64>,
                         picked: &[(&[f64; UNKNOWNS], f64)]| {
            let filled = picked.len();
            fill_columns(block.as_mut_slice(), NORMAL_BLOCK, picked);
            // the upper triangle only, of the (column-major) block's columns
            add_upper_products(&mut ata, block.as_slice(), NORMAL_BLOCK, filled);
            atb.gemv_tr(1.0, &block.rows(0, filled), &block_y.rows(0, filled), 1.0);
        };
        for (&(k, i, _), terms) in rows.rows.iter().zip(&rows.terms) {
            if skip == Some(k) {
                continue;
            }
            let r = self.appearance[i][ch];
            let y_counts = captures[k].image[i][ch];
            if !(r >= MIN_REFERENCE_COUNTS) || y_counts >= full_scale || r * gains[k] >= full_scale
            {
                continue;
            }
            let Some(row) = terms else {
                continue;
            };
            // the ratio's change, weighted by the reference (the row and its value times r:
            // weight r^2) so that each row counts in grey levels
            let y = y_counts / (gains[k] * r) - 1.0;
            block_y[picked.len()] = r * y;
            picked.push((row, r));
            if picked.len() == NORMAL_BLOCK {
                flush(&mut block, &block_y, &picked);
                picked.clear();
            }
        }
        if !picked.is_empty() {
            flush(&mut block, &block_y, &picked);
        }
        // exactly symmetric: the upper triangle mirrored
        for a in 0..unknowns {
            for b in 0..a {
                ata[(a, b)] = ata[(b, a)];
            }
        }
        (ata, atb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every tiling of the normal equations' products (the portable 2 x 2, the 3 x 3, and AVX2
    /// where the machine has it) gives each element of the upper triangle the bits of
    /// [`dot_product`] of its two columns, with a column count and a fill that leave partial
    /// tiles and a remainder of rows; the lower triangle is left alone.
    #[test]
    fn the_tiled_normal_equations_are_the_dot_products_to_the_bit() {
        let (m, stride, filled) = (11, 40, 37);
        let block: Vec<f64> = (0..m * stride)
            .map(|k| ((k * 7919 % 1013) as f64 * 0.37).sin() * 10f64.powi((k % 5) as i32 - 2))
            .collect();
        let col = |a: usize| &block[a * stride..a * stride + filled];
        let start = DMatrix::<f64>::from_fn(m, m, |a, c| (a * m + c) as f64 * 0.5);
        let mut want = start.clone();
        for c in 0..m {
            for a in 0..=c {
                want[(a, c)] += dot_product(col(a), col(c));
            }
        }
        let mut tiled: Vec<(&str, DMatrix<f64>)> =
            vec![("2 x 2", start.clone()), ("3 x 3", start.clone())];
        add_upper_products_tiled::<2>(&mut tiled[0].1, &block, stride, filled);
        add_upper_products_tiled::<3>(&mut tiled[1].1, &block, stride, filled);
        let mut dispatched = start.clone();
        add_upper_products(&mut dispatched, &block, stride, filled);
        tiled.push(("dispatched", dispatched));
        for (name, got) in &tiled {
            for a in 0..m {
                for c in 0..m {
                    assert_eq!(
                        got[(a, c)].to_bits(),
                        want[(a, c)].to_bits(),
                        "{name}: element ({a}, {c})"
                    );
                }
            }
        }
    }
}
