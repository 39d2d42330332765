//! The model's images ([`PhotometricModel::render`], [`PhotometricModel::image`]) and their
//! difference from a capture ([`rms_over_skin`]).

use super::model::PhotometricModel;
use super::shadows::{shadow_map, ShadowMap};
use super::terms::{features, light_features, spatial, FEATURES, LIGHT_TERMS, SPATIAL_TERMS};
use crate::groundtruth::exact::ExactPrimitives;
use crate::groundtruth::hits::SurfaceHits;
use crate::groundtruth::rays::PixelRays;

impl PhotometricModel {
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
