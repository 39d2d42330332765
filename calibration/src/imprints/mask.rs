//! The mask of the pixels that can hold an imprint ([`reference_mask`]): the skin of the
//! reference image less its LED reflections and what lies beyond their ring.

use super::{median, GrayImage};

/// Sectors (about the skin's centre) in which [`reference_mask`] looks for the ring of LED
/// reflections at the rim ...
const RING_SECTORS: usize = 12;
/// ... which is a ring when this many of them hold a reflection.
const RING_MIN_SECTORS: usize = 9;

/// The pixels that can hold an imprint, from the reference image: skin (brighter than a
/// quarter of the median grey) and not an LED reflection (at most halfway from the median to
/// `white`), the reflections grown by `margin_px`. When the reflections ring the skin (as the
/// LEDs at an R-Tac0's rim do: reflections in at least [`RING_MIN_SECTORS`] of
/// [`RING_SECTORS`] sectors about the skin's centroid), only the disc inside the ring counts,
/// less `margin_px`: the dark notches between the highlights and whatever lies beyond them
/// are not skin a pin can press. The ring's inner radius is the median over the sectors of
/// the nearest reflection in each, so that one stray reflection does not shrink the disc.
pub fn reference_mask(reference: &GrayImage, white: f32, margin_px: usize) -> Vec<bool> {
    let (w, h) = (reference.width, reference.height);
    let mut all = reference.data.clone();
    let med = skin_level(&mut all);
    let bright = 0.5 * (med + white);
    let mut mask: Vec<bool> = reference.data.iter().map(|&g| g > 0.25 * med).collect();
    if let Some((c, radius)) = reflection_ring(reference, &mask, bright) {
        let r2 = (radius - margin_px as f64).max(0.0).powi(2);
        // each row keeps the columns within the disc
        for (v, row) in mask.chunks_exact_mut(w).enumerate() {
            let half = (r2 - (v as f64 - c[1]).powi(2)).max(0.0).sqrt();
            let a = (c[0] - half).ceil().clamp(0.0, w as f64) as usize;
            let b = ((c[0] + half).floor() + 1.0).clamp(a as f64, w as f64) as usize;
            if half <= 0.0 {
                row.fill(false);
                continue;
            }
            row[..a].fill(false);
            row[b..].fill(false);
        }
    }
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

/// The skin's grey level in a reference image, for [`reference_mask`]: the median grey, or,
/// when the skin covers under half of the frame (a camera far under a small dome: the median is
/// the dark outside, under half the level of the pixels brighter than Otsu's threshold between
/// the two, Otsu 1979), the median of those brighter pixels. `v` is reordered.
fn skin_level(v: &mut [f32]) -> f32 {
    let med = median(v);
    // Otsu's threshold over 256 bins of 0..=255 grey
    let mut hist = [0u64; 256];
    for &g in v.iter() {
        hist[g.clamp(0.0, 255.0) as usize] += 1;
    }
    let total = v.len() as f64;
    let sum_all: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    let (mut w0, mut sum0, mut best, mut split) = (0.0, 0.0, -1.0, 0usize);
    for (i, &c) in hist.iter().enumerate() {
        w0 += c as f64;
        sum0 += i as f64 * c as f64;
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let (m0, m1) = (sum0 / w0, (sum_all - sum0) / w1);
        let between = w0 * w1 * (m0 - m1).powi(2);
        if between > best {
            (best, split) = (between, i);
        }
    }
    let mut bright: Vec<f32> = v.iter().copied().filter(|&g| g > split as f32).collect();
    let upper = median(&mut bright);
    if med < 0.5 * upper {
        upper
    } else {
        med
    }
}

/// The centre (the centroid of the `lit` pixels, px) and inner radius (px) of a ring of
/// reflections (pixels above `bright`) about it; `None` when the reflections do not ring it
/// ([`reference_mask`]).
fn reflection_ring(reference: &GrayImage, lit: &[bool], bright: f32) -> Option<([f64; 2], f64)> {
    let w = reference.width;
    let (mut n, mut su, mut sv) = (0usize, 0usize, 0usize);
    for (v, row) in lit.chunks_exact(w).enumerate() {
        let (mut rn, mut ru) = (0usize, 0usize);
        for (u, _) in row.iter().enumerate().filter(|(_, l)| **l) {
            rn += 1;
            ru += u;
        }
        n += rn;
        su += ru;
        sv += rn * v;
    }
    let (su, sv) = (su as f64, sv as f64);
    if n == 0 {
        return None;
    }
    let c = [su / n as f64, sv / n as f64];
    let mut nearest = [f64::INFINITY; RING_SECTORS];
    for (i, _) in reference
        .data
        .iter()
        .enumerate()
        .filter(|(_, g)| **g > bright)
    {
        let (du, dv) = ((i % w) as f64 - c[0], (i / w) as f64 - c[1]);
        let turn = (dv.atan2(du) / std::f64::consts::TAU).rem_euclid(1.0);
        let k = ((turn * RING_SECTORS as f64) as usize).min(RING_SECTORS - 1);
        nearest[k] = nearest[k].min(du.hypot(dv));
    }
    let mut found: Vec<f64> = nearest.into_iter().filter(|d| d.is_finite()).collect();
    if found.len() < RING_MIN_SECTORS {
        return None;
    }
    let m = found.len() / 2;
    Some((c, *found.select_nth_unstable_by(m, f64::total_cmp).1))
}
