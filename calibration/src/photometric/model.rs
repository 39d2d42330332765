//! The fitted model ([`PhotometricModel`]) and a capture to fit it to ([`Capture`]).

use super::shadows::{ShadowMap, ShadowRings};
use super::terms::SHADOW_TERMS;
use crate::groundtruth::hits::SurfaceHits;

/// A fitted photometric model of one camera at one pose.
#[derive(Debug, Clone)]
pub struct PhotometricModel {
    pub width: usize,
    pub height: usize,
    /// The unindented appearance per pixel and channel, counts (NaN off the skin).
    pub reference: Vec<[f64; 3]>,
    /// Per channel, the coefficients `c_km` at `k * SPATIAL_TERMS + m`, then the weights of the
    /// candidate point lights ([`COEFFICIENTS`](super::terms::COEFFICIENTS) in all).
    pub coefficients: [Vec<f64>; 3],
    /// The camera's optical axis in the sensor frame (the local frame of the features).
    pub axis: [f64; 3],
    /// The candidate light rings of the shadow term.
    pub rings: ShadowRings,
    /// Per channel, the weight of each candidate ring's shadow ([`ShadowMap`]): the fraction
    /// of a pixel's light its ring stands for.
    pub shadow_coefficients: [[f64; SHADOW_TERMS]; 3],
    /// The gain of each fitted capture against the reference image: the least-squares ratio
    /// over its skin far from every imprint ([`PhotometricModel::gain_of`]).
    pub gains: Vec<f64>,
    /// The images' full scale, counts: rendered values are clipped to it.
    pub full_scale: f64,
    /// Root-mean-square residual of each fitted capture over its skin, counts (all channels).
    pub residual_rms: Vec<f64>,
}

/// One capture to fit: its image (row-major, per channel, counts), its surface and the
/// shadows its protrusions cast ([`shadow_map`](super::shadows::shadow_map)).
#[derive(Debug, Clone, Copy)]
pub struct Capture<'a> {
    pub image: &'a [[f64; 3]],
    pub hits: &'a SurfaceHits,
    pub shadows: &'a ShadowMap,
}
