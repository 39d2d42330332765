//! A photometric model fitted from calibration captures: how the real camera's intensities
//! respond to the skin's surface normal, so that images of any protrusion set can be rendered
//! in a sensor's own appearance.
//!
//! Each capture pairs known geometry (the pins' imprints through the solved pose: every
//! pixel's surface point and normal, [`crate::groundtruth::SurfaceHits`]) with the
//! intensities the camera recorded. The model, per colour channel, is
//!
//! `I(x, n) = gain x R(x) x (1 + sum_k sum_m c_km P_m(x) f_k(n, x) + sum_l w_l G_l(x, n)
//!            - sum_j b_j S_j(x))`
//!
//! - `R(x)`: the unindented appearance, per pixel: the reference image, averaged with the
//!   unpressed pixels of every capture (each divided by its gain) to lower its noise;
//! - `f_k`: the change of the surface normal from the reference normal in the reference
//!   surface's local frame about the camera's optical axis (`a` along the tangent away from
//!   the axis, `r` round it, `c` along the reference normal: one minus the tilt's cosine), the
//!   monomials of `a` and `r` up to degree 3 (`a^2, ar, r^2, a^3, a^2 r, a r^2, r^3`), and the
//!   indentation depth along the ray (mm);
//! - `P_m(x)`: powers of the pixel's normalised distance from the image centre up to
//!   [`SPATIAL_DEGREE`]: the lights' directions and fall-off change slowly over the skin;
//! - `G_l(x, n)`: candidate point lights ([`LIGHT_TERMS`]: twelve azimuths at three heights
//!   about the optical axis): the change of light `l`'s Lambertian irradiance (incidence
//!   cosine over squared distance, zero where the protrusions block it) from the reference
//!   surface to the pressed one, over all candidates' irradiance of the reference; they follow
//!   lights at a few azimuths, which the spatial term (round the axis) cannot;
//! - `S_j(x)`: the shadows ([`shadow_map`]): the share of candidate ring `j`'s light (rings of
//!   effective lights about the optical axis, [`ShadowRings`]) that the protrusions block at
//!   the pixel, beside an imprint or inside it; `b_j` the share of the pixel's light the ring
//!   stands for;
//! - `gain`: each capture's global gain against the reference (exposure and LED drift), the
//!   least-squares ratio over its skin further than [`GAIN_CLEARANCE_PX`] (30 px) from every
//!   imprint and unshadowed, outliers (moving highlights, specks) left out
//!   ([`PhotometricModel::gain_of`]); applied wherever a capture is rendered.
//!
//! The fit is judged where the pins press as well as over the whole skin
//! ([`PhotometricModel::contact_region`]): the RMS within [`CONTACT_REACH_PX`] (15 px) of each
//! imprint, and the distance between the centroids of the capture's and the rendering's
//! darkening at each imprint.
//!
//! Why this form: under Lambertian lights the radiance is a sum of clamped cosines
//! `max(0, n . l_k)`, a smooth function of the normal. With `n = (1 - c) n0 - a e_a - r e_r`
//! each cosine is linear in `a`, `r` and `c` until it clamps, and low-order polynomials in the
//! tilt take the clamping and the lights' spread (order 2 already holds most of a clamped
//! cosine's energy, Ramamoorthi and Hanrahan 2001; `c` keeps the walls of a deep imprint,
//! tilted near 90 deg, from bending the polynomial). Divided by the reference, the response is
//! `1` at no tilt, and what remains varies slowly over the skin; moving the surface by the
//! indentation changes the distances to the lights to first order in the depth. Fitting the
//! ratio, not the intensity, leaves every pixel's own appearance (rim LEDs, vignetting, the
//! skin's albedo) to the reference and only the response to tilt to the captures. A look-up
//! table over binned normals (Taxim) needs a flat sensor and many more imprints per bin than a
//! pin dome gives; a low-order spatial term is what a curved skin's few dozen imprints can
//! fix. A pin pressed deeper than its tip's radius shadows the skin beside its imprint from
//! lights at grazing incidence; the lights are not known, so the shadow term spans candidate
//! rings of them and the fit weighs each (with R-Tac0's LED ring the weight goes to the ring
//! nearest it, about 0.9 of the light).
//!
//! Limits: the spatial term and the candidate rings are round the optical axis, so the model
//! is closest for lights in a ring about it (R-Tac0's, the TacTip's, UVDtact's). For lights at
//! a few azimuths (ShadowTac's three single-colour LEDs) the candidate point lights halve the
//! error but leave about 5 grey levels (balls) to 6.5 (R-Tac0's pins) in the leave-one-out
//! test: their weights are divided by all candidates' irradiance, not the unknown lights'.
//! Penumbrae are those of the sampled rings (24 lights each).

mod contact;
mod faults;
mod fit;
mod model;
mod model_file;
mod render;
pub mod seating;
mod shadows;
mod terms;

pub use crate::groundtruth::pins::{pin_primitives, read_pins, Pins};
pub use contact::{
    ContactRegion, ImprintFit, ImprintMap, CONTACT_REACH_PX, DARKENING_NOISE_SIGMAS,
    GAIN_CLEARANCE_PX, GAIN_OUTLIER_SIGMAS,
};
pub use faults::{
    capture_fault, image_fault, ImageFault, IMPRINT_NOISE_FACTOR, MIN_IMPRINT_COUNTS,
};
pub use fit::LeaveOneOut;
pub use model::{Capture, PhotometricModel};
pub use model_file::{
    quote_non_finite, FittedWith, APPEARANCE_HEADROOM, MAX_COEFFICIENT, SCALE_RANGE_MM,
};
pub use render::rms_over_skin;
pub use shadows::{shadow_map, ShadowMap, ShadowPixel, ShadowRings};
pub use terms::{
    ANGULAR_ORDER, COEFFICIENTS, FEATURES, LIGHT_AZIMUTHS, LIGHT_HEIGHTS, LIGHT_RADIUS,
    LIGHT_TERMS, MIN_REFERENCE_COUNTS, SHADOW_AZIMUTHS, SHADOW_HEIGHTS, SHADOW_RADII, SHADOW_REACH,
    SHADOW_TERMS, SPATIAL_DEGREE, SPATIAL_TERMS,
};

// Reading the files stays here beside the re-export of groundtruth's pins: the submodules
// import nothing from groundtruth's input readers.
impl PhotometricModel {
    /// The model `fabkit calibrate photometric` wrote to `dir` (photometric.json and the
    /// (H, W, 3) float32 appearance.npy), the sha256 of its photometric.json, and the inputs
    /// it records it was fitted with ([`FittedWith`]).
    ///
    /// # Errors
    /// A message naming the file and what does not fit: unreadable, not JSON, an appearance
    /// that is not (H, W, 3) float32, or what [`Self::from_json`] refuses.
    pub fn read(dir: &std::path::Path) -> Result<(PhotometricModel, String, FittedWith), String> {
        use crate::groundtruth::inputs::read_with_hash;
        let jpath = dir.join("photometric.json");
        let (bytes, sha) = read_with_hash(&jpath).map_err(|e| e.to_string())?;
        let text = quote_non_finite(&String::from_utf8_lossy(&bytes));
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not JSON: {e}", jpath.display()))?;
        let apath = dir.join("appearance.npy");
        let (abytes, _) = read_with_hash(&apath).map_err(|e| e.to_string())?;
        let (shape, data) = fabkit_export::raster::read_npy_f32(&abytes)
            .map_err(|e| format!("{}: {e}", apath.display()))?;
        let [h, w, 3] = shape[..] else {
            return Err(format!(
                "{}: shape {shape:?}, not (H, W, 3)",
                apath.display()
            ));
        };
        let appearance = data
            .chunks_exact(3)
            .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])])
            .collect();
        let model = PhotometricModel::from_json(&v["model"], appearance, w, h)
            .map_err(|e| format!("{}: {e}", jpath.display()))?;
        let fitted = FittedWith::of_record(&v, jpath.display().to_string());
        Ok((model, sha, fitted))
    }
}
