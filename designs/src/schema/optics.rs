//! The `optics` section of a design: how the inside is lit and imaged (lights, the skin's
//! reflectance, the markers' albedo, the camera's response), with its rules. The light model
//! and how a render resolves these are in [`crate::optics`].

use crate::error::ParamError;
use crate::optics::elements::Light;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The `optics` section of a design: every key optional.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OpticsParams {
    /// The lights, sensor frame; when not given, the lights of the design's section families
    /// (the housing's LED ring, the casing's LEDs, the shaft body's LED ring, the fingertip
    /// base's LEDs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lights: Option<Vec<Light>>,
    /// The reflectance of the skin's inner surface that the camera sees.
    #[serde(default)]
    pub surface: Reflectance,
    /// RGB albedo of the markers' faces the camera sees (pin tips, printed dots), each in
    /// [0, 1]; dimples have the skin's albedo and show by their shading and shadows.
    #[serde(default = "white_markers")]
    pub marker_albedo_rgb: [f64; 3],
    /// How the camera turns light into pixel values.
    #[serde(default)]
    pub camera: CameraResponse,
}

fn white_markers() -> [f64; 3] {
    [0.9, 0.9, 0.9]
}

impl Default for OpticsParams {
    fn default() -> Self {
        Self {
            lights: None,
            surface: Reflectance::default(),
            marker_albedo_rgb: white_markers(),
            camera: CameraResponse::default(),
        }
    }
}

/// The skin's inner surface: Lambertian albedo plus a specular lobe; for a darkness-mapping
/// skin, the brightness its thinning takes away.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Reflectance {
    /// Diffuse albedo, RGB, each in [0, 1]. Default: a light grey coat, 0.6.
    pub albedo_rgb: [f64; 3],
    /// Fraction reflected by the specular lobe at normal incidence, in [0, 1]. Default 0.04,
    /// the Fresnel reflectance of silicone (n = 1.41).
    #[schemars(extend("minimum" = 0, "maximum" = 1))]
    pub specular: f64,
    /// Roughness of the specular lobe, in (0, 1]: small is glossy, 1 spreads it over the
    /// hemisphere. Default 0.5 (a matte paint).
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub roughness: f64,
    /// A darkness-mapping skin (DTact, Lin et al., ICRA 2023; R-Tac0 Sec. II: "darkness
    /// mapping through optical reflection of the semitransparent elastomer"): the light the
    /// camera sees is scattered back from within a translucent layer, so a pressed point's
    /// brightness follows how far the surface sank there, not its slope: the fraction of
    /// the unpressed brightness lost per mm of sink along the skin's normal, in (0, 10]
    /// (brightness `1 - darkness_per_mm x sink`, at least 0). When given, a pressed point is
    /// shaded with the unpressed skin's normal at its pixel. Not given: the skin is an opaque
    /// surface whose slope shades it (a GelSight-like coat).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 10))]
    pub darkness_per_mm: Option<f64>,
}

impl Default for Reflectance {
    fn default() -> Self {
        Self {
            albedo_rgb: [0.6, 0.6, 0.6],
            specular: 0.04,
            roughness: 0.5,
            darkness_per_mm: None,
        }
    }
}

/// The camera's response: gain, vignetting, noise and bit depth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CameraResponse {
    /// Pixel value, as a fraction of full scale, per unit of radiance, > 0. When not given,
    /// the exposure is set once on the reference image (its 99th-percentile pixel at 0.8 of
    /// full scale) and held for every frame of the set, as a camera in manual exposure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub gain: Option<f64>,
    /// Light lost at the image's corners, a fraction in [0, 1): the response falls as
    /// `1 - vignetting x (r / r_corner)^2` with the distance `r` from the principal point.
    /// Default 0.
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 1))]
    pub vignetting: f64,
    /// Electrons at full scale, for the photon (shot) noise, at least 1. Default 10000.
    #[schemars(extend("minimum" = 1))]
    pub full_well_electrons: f64,
    /// Read noise, electrons (standard deviation), >= 0. Default 5.
    #[schemars(extend("minimum" = 0))]
    pub read_noise_electrons: f64,
    /// Bits per channel of the written images: 8 or 16. Default 8.
    #[schemars(extend("enum" = [8, 16]))]
    pub bit_depth: u32,
    /// Seed of the noise: the same seed gives the same bytes. Default 0.
    pub seed: u64,
}

impl Default for CameraResponse {
    fn default() -> Self {
        Self {
            gain: None,
            vignetting: 0.0,
            full_well_electrons: 10_000.0,
            read_noise_electrons: 5.0,
            bit_depth: 8,
            seed: 0,
        }
    }
}

/// Most lights a design may give (`optics.lights`): the render's work grows with lights x
/// pixels x frames, and this bounds it before anything is rendered.
pub const MAX_LIGHTS: usize = 64;

/// Appends every violated rule of `o` to `errs`, each path under `optics.`.
pub fn check(o: &OpticsParams, errs: &mut Vec<ParamError>) {
    if let Some(lights) = &o.lights {
        if lights.is_empty() {
            errs.push(ParamError::new(
                "optics.lights",
                "[]",
                "give at least one light, or leave the key out for the families' lights",
            ));
        }
        if lights.len() > MAX_LIGHTS {
            errs.push(ParamError::new(
                "optics.lights",
                format!("{} lights", lights.len()),
                format!(
                    "give at most {MAX_LIGHTS}: each light adds a shading and a shadow pass over every pixel of every rendered frame (a sensor's ring of LEDs is 3 to 16)"
                ),
            ));
            return;
        }
        for (i, l) in lights.iter().enumerate() {
            check_light(&format!("optics.lights[{i}]"), l, errs);
        }
    }
    check_rgb(
        "optics.surface.albedo_rgb",
        o.surface.albedo_rgb,
        false,
        errs,
    );
    check_fraction("optics.surface.specular", o.surface.specular, errs);
    let r = o.surface.roughness;
    if !(r > 0.0 && r <= 1.0) {
        errs.push(ParamError::new(
            "optics.surface.roughness",
            r,
            "must be above 0 and at most 1",
        ));
    }
    if let Some(k) = o.surface.darkness_per_mm {
        if !(k > 0.0 && k <= 10.0) {
            errs.push(ParamError::new(
                "optics.surface.darkness_per_mm",
                k,
                "must be above 0 and at most 10 (the fraction of the brightness lost per mm of sink)",
            ));
        }
    }
    check_rgb("optics.marker_albedo_rgb", o.marker_albedo_rgb, false, errs);
    let c = &o.camera;
    if let Some(g) = c.gain {
        if !(g > 0.0) {
            errs.push(ParamError::new(
                "optics.camera.gain",
                g,
                "must be above 0 (or leave it out for the exposure set on the reference image)",
            ));
        }
    }
    if !(0.0..1.0).contains(&c.vignetting) {
        errs.push(ParamError::new(
            "optics.camera.vignetting",
            c.vignetting,
            "must be at least 0 and below 1",
        ));
    }
    if !(c.full_well_electrons >= 1.0) {
        errs.push(ParamError::new(
            "optics.camera.full_well_electrons",
            c.full_well_electrons,
            "must be at least 1",
        ));
    }
    if !(c.read_noise_electrons >= 0.0) {
        errs.push(ParamError::new(
            "optics.camera.read_noise_electrons",
            c.read_noise_electrons,
            "must be at least 0",
        ));
    }
    if !matches!(c.bit_depth, 8 | 16) {
        errs.push(ParamError::new(
            "optics.camera.bit_depth",
            c.bit_depth,
            "must be 8 or 16",
        ));
    }
}

/// The rules of one light under `path`.
fn check_light(path: &str, l: &Light, errs: &mut Vec<ParamError>) {
    let len = l.direction.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(len > 1e-9) {
        // all zero: the vector; else its longest component, the one too short to aim it
        let longest = (0..3)
            .filter(|&k| l.direction[k] != 0.0)
            .max_by(|&a, &b| l.direction[a].abs().total_cmp(&l.direction[b].abs()));
        errs.push(match longest {
            None => ParamError::new(
                format!("{path}.direction"),
                format!("{:?}", l.direction),
                "must be a vector longer than 0",
            ),
            Some(k) => ParamError::new(
                format!("{path}.direction[{k}]"),
                l.direction[k],
                format!(
                    "is the longest component of {:?}, which must be a vector longer than 1e-9 to give a direction",
                    l.direction
                ),
            ),
        });
    }
    let a = l.cone_half_angle_deg;
    if !(a > 0.0 && a <= 90.0) {
        errs.push(ParamError::new(
            format!("{path}.cone_half_angle_deg"),
            a,
            "must be above 0 and at most 90",
        ));
    }
    check_rgb(&format!("{path}.colour_rgb"), l.colour_rgb, true, errs);
    if !(l.intensity > 0.0) {
        errs.push(ParamError::new(
            format!("{path}.intensity"),
            l.intensity,
            "must be above 0",
        ));
    }
}

fn check_fraction(path: &str, x: f64, errs: &mut Vec<ParamError>) {
    if !(0.0..=1.0).contains(&x) {
        errs.push(ParamError::new(path, x, "must be in [0, 1]"));
    }
}

/// Each channel in [0, 1]; with `lit`, not all 0 (a light that gives no light).
fn check_rgb(path: &str, rgb: [f64; 3], lit: bool, errs: &mut Vec<ParamError>) {
    for (i, &x) in rgb.iter().enumerate() {
        check_fraction(&format!("{path}[{i}]"), x, errs);
    }
    if lit && rgb.iter().all(|&x| x == 0.0) {
        errs.push(ParamError::new(
            path,
            format!("{rgb:?}"),
            "a light must have some colour: at least one channel above 0",
        ));
    }
}
