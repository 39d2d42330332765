//! Whether an image can serve the fit: lit, not overexposed, and showing its imprints
//! ([`ImageFault`]).

use super::model::Capture;
use super::terms::{median, median_gain, MIN_REFERENCE_COUNTS};
use crate::groundtruth::hits::SurfaceHits;

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
    /// RMS over their `values` (pixels x channels), `signal_counts` with the skin's noise
    /// elsewhere (`noise_counts`, robust standard deviation) taken out in quadrature, which
    /// is no more than noise alone gives ([`IMPRINT_NOISE_FACTOR`]) or [`MIN_IMPRINT_COUNTS`]:
    /// the camera saw no imprint at the pins (a copy of the reference, an unpressed frame).
    NoImprint {
        imprint_counts: f64,
        signal_counts: f64,
        noise_counts: f64,
        values: usize,
    },
}

/// How far a capture's pressed pixels must stand out of the skin's noise: their mean square
/// difference from the reference less the noise's variance `s^2`, in standard deviations of
/// what an unpressed frame of Gaussian noise gives over `n` values (`s^2 sqrt(2 / n)`, the
/// chi-square's with `n` degrees of freedom over `n`). At 3 an unpressed frame passes about once
/// in 700; a darkness-mapping skin's faint imprint (0.1 of its grey under a 0.5 mm pin, over a
/// hundred pixels) is far above it, where a per-pixel rule (its RMS over 3 noise standard
/// deviations) refuses it.
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
                signal_counts,
                noise_counts,
                values,
            } => write!(
                f,
                "no imprint at its pins: the pressed pixels differ from the reference by {imprint_counts:.2} counts RMS ({signal_counts:.2} with the skin's noise elsewhere, {noise_counts:.2} counts, taken out), within {IMPRINT_NOISE_FACTOR} standard deviations of what that noise gives over their {values} values, or {MIN_IMPRINT_COUNTS} count; a capture must show its pins pressed into the skin (a copy of the reference or an unpressed frame fits nothing)"
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
/// values divided by its gain differ from the reference's by more than the noise of the
/// unpressed, unshadowed skin (1.4826 times the median absolute difference there) gives over
/// as many values ([`IMPRINT_NOISE_FACTOR`]) and, with that noise taken out, by more than
/// [`MIN_IMPRINT_COUNTS`] RMS.
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
    let gain = median_gain(capture.image, reference_image, |i| capture.hits.contact[i]);
    let mut shadowed = vec![false; capture.image.len()];
    for p in &capture.shadows.pixels {
        if let Some(s) = shadowed.get_mut(p.pixel as usize) {
            *s = true;
        }
    }
    let usable = |i: usize| {
        (0..3).all(|c| {
            let (y, r) = (capture.image[i][c], reference_image[i][c]);
            y.is_finite() && r.is_finite() && y < full_scale && r < full_scale
        }) && reference_image[i]
            .iter()
            .any(|&r| r >= MIN_REFERENCE_COUNTS)
    };
    let (mut pressed_sq, mut pressed_n) = (0.0, 0usize);
    // the magnitudes of the differences on the unpressed, unshadowed skin
    let mut quiet: Vec<f64> = Vec::new();
    for i in (0..capture.image.len()).filter(|&i| on_skin(i) && usable(i)) {
        let d: [f64; 3] =
            std::array::from_fn(|c| capture.image[i][c] / gain - reference_image[i][c]);
        if capture.hits.contact[i] {
            pressed_sq += d.iter().map(|x| x * x).sum::<f64>();
            pressed_n += 3;
        } else if !shadowed[i] {
            quiet.extend(d.map(f64::abs));
        }
    }
    let imprint_counts = if pressed_n == 0 {
        0.0
    } else {
        (pressed_sq / pressed_n as f64).sqrt()
    };
    let noise_counts = median(quiet).unwrap_or(0.0) * 1.4826;
    let floor = MIN_IMPRINT_COUNTS * full_scale / 255.0;
    let noise_var = noise_counts * noise_counts;
    let excess = imprint_counts * imprint_counts - noise_var;
    let by_chance = IMPRINT_NOISE_FACTOR * noise_var * (2.0 / (pressed_n.max(1) as f64)).sqrt();
    let signal_counts = excess.max(0.0).sqrt();
    (pressed_n == 0 || excess <= by_chance || signal_counts <= floor).then_some(
        ImageFault::NoImprint {
            imprint_counts,
            signal_counts,
            noise_counts,
            values: pressed_n,
        },
    )
}
