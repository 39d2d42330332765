//! The model's files: its section of photometric.json ([`PhotometricModel::model_json`]) and
//! the model read back from it and appearance.npy ([`PhotometricModel::read`],
//! [`PhotometricModel::from_json`]), with the inputs it was fitted with ([`FittedWith`]).

use super::model::PhotometricModel;
use super::shadows::ShadowRings;
use super::terms::{
    ANGULAR_ORDER, COEFFICIENTS, FEATURES, LIGHT_AZIMUTHS, LIGHT_HEIGHTS, LIGHT_RADIUS,
    LIGHT_TERMS, SHADOW_AZIMUTHS, SHADOW_HEIGHTS, SHADOW_RADII, SHADOW_TERMS, SPATIAL_DEGREE,
    SPATIAL_TERMS,
};

impl PhotometricModel {
    /// The model's section of photometric.json (`fabkit calibrate photometric`): the basis
    /// (feature names and counts, the candidate lights and rings), the optical axis, the full
    /// scale and the coefficients per channel. The appearance goes to its own file
    /// (appearance.npy, (H, W, 3) float32).
    pub fn model_json(&self) -> serde_json::Value {
        serde_json::json!({
            "features": ["a", "r", "c", "depth_mm", "a^2", "r^2", "a r", "a^3", "a^2 r", "a r^2", "r^3"],
            "feature_count": FEATURES, "spatial_degree": SPATIAL_DEGREE, "angular_order": ANGULAR_ORDER,
            "spatial_terms": SPATIAL_TERMS, "optical_axis": self.axis, "full_scale_counts": self.full_scale,
            "coefficients_rgb": self.coefficients, "appearance": "appearance.npy",
            "light_terms": LIGHT_TERMS, "shadow_terms": SHADOW_TERMS, "shadow_azimuths": SHADOW_AZIMUTHS,
            "lights": {"heights": LIGHT_HEIGHTS, "radius": LIGHT_RADIUS, "azimuths": LIGHT_AZIMUTHS,
                       "notes": "candidate point lights l = h x azimuths + j at height heights[h] x scale_mm along the axis from the camera centre and radius radius x scale_mm, azimuth j x 360 / azimuths deg from the axis x e1 with e1 = axis x (x or y); scale_mm and centre_mm as in shadow.rings"},
            "shadow": {
                "rings": {"centre_mm": self.rings.centre_mm, "axis": self.rings.axis, "scale_mm": self.rings.scale_mm,
                          "heights": SHADOW_HEIGHTS, "radii": SHADOW_RADII,
                          "notes": "candidate rings of effective lights about the optical axis, ring m at height heights[m / 3] x scale_mm along the axis from the camera centre (centre_mm) and radius radii[m % 3] x scale_mm, each sampled by shadow_azimuths lights; scale_mm is the skin's median range"},
                "coefficients_rgb": self.shadow_coefficients,
            },
        })
    }

    /// The model from its section of photometric.json ([`Self::model_json`]) and its
    /// appearance (row-major, `width` x `height`, counts; NaN off the skin).
    ///
    /// # Errors
    /// A message naming the key (`model.<key>`), the value and the rule: another basis than
    /// this fabkit's (fit the model again), coefficients of another length, an axis, ring or
    /// full scale that is not one, an appearance of another size.
    pub fn from_json(
        model: &serde_json::Value,
        appearance: Vec<[f64; 3]>,
        width: usize,
        height: usize,
    ) -> Result<PhotometricModel, String> {
        use serde_json::from_value;
        let m = model;
        let basis = [
            ("feature_count", FEATURES),
            ("spatial_degree", SPATIAL_DEGREE),
            ("angular_order", ANGULAR_ORDER),
            ("spatial_terms", SPATIAL_TERMS),
            ("shadow_terms", SHADOW_TERMS),
            ("light_terms", LIGHT_TERMS),
            ("shadow_azimuths", SHADOW_AZIMUTHS),
        ];
        for (key, want) in basis {
            if m[key].as_u64() != Some(want as u64) {
                return Err(format!(
                    "model.{key} = {}: this fabkit's model has {want} (fit it again with this version)",
                    m[key]
                ));
            }
        }
        // the candidate lights and rings the basis is made of
        let lights_basis = [
            (
                "lights.heights",
                &m["lights"]["heights"],
                serde_json::json!(LIGHT_HEIGHTS),
            ),
            (
                "lights.radius",
                &m["lights"]["radius"],
                serde_json::json!(LIGHT_RADIUS),
            ),
            (
                "lights.azimuths",
                &m["lights"]["azimuths"],
                serde_json::json!(LIGHT_AZIMUTHS),
            ),
            (
                "shadow.rings.heights",
                &m["shadow"]["rings"]["heights"],
                serde_json::json!(SHADOW_HEIGHTS),
            ),
            (
                "shadow.rings.radii",
                &m["shadow"]["rings"]["radii"],
                serde_json::json!(SHADOW_RADII),
            ),
        ];
        for (key, have, want) in lights_basis {
            if *have != want {
                return Err(format!(
                    "model.{key} = {have}: this fabkit's model has {want} (fit it again with this version)"
                ));
            }
        }
        let coefficients: [Vec<f64>; 3] = from_value(m["coefficients_rgb"].clone())
            .ok()
            .filter(|c: &[Vec<f64>; 3]| c.iter().all(|x| x.len() == COEFFICIENTS))
            .ok_or_else(|| {
                format!("model.coefficients_rgb must be 3 lists of {COEFFICIENTS} numbers")
            })?;
        let axis: [f64; 3] = from_value(m["optical_axis"].clone())
            .map_err(|_| "model.optical_axis must be 3 numbers".to_string())?;
        let shadow_coefficients: [[f64; SHADOW_TERMS]; 3] =
            from_value(m["shadow"]["coefficients_rgb"].clone()).map_err(|_| {
                format!("model.shadow.coefficients_rgb must be 3 lists of {SHADOW_TERMS} numbers")
            })?;
        let ring = &m["shadow"]["rings"];
        let rings = match (
            from_value::<[f64; 3]>(ring["centre_mm"].clone()),
            from_value::<[f64; 3]>(ring["axis"].clone()),
            ring["scale_mm"].as_f64().filter(|x| *x > 0.0),
        ) {
            (Ok(centre_mm), Ok(axis), Some(scale_mm)) => ShadowRings {
                centre_mm,
                axis,
                scale_mm,
            },
            _ => {
                return Err("model.shadow.rings must hold centre_mm and axis (3 numbers each) and scale_mm (above 0)".into())
            }
        };
        let full_scale = m["full_scale_counts"]
            .as_f64()
            .filter(|f| *f == 255.0 || *f == 65535.0)
            .ok_or_else(|| "model.full_scale_counts must be 255 or 65535".to_string())?;
        check_model_values(&coefficients, axis, &shadow_coefficients, &rings)?;
        if appearance.len() != width * height {
            return Err(format!(
                "the appearance has {} pixels, the camera {width} x {height}",
                appearance.len()
            ));
        }
        if let Some((k, c, v)) = appearance.iter().enumerate().find_map(|(k, p)| {
            (0..3)
                .find(|&c| {
                    !(p[c].is_nan() || (0.0..=APPEARANCE_HEADROOM * full_scale).contains(&p[c]))
                })
                .map(|c| (k, c, p[c]))
        }) {
            return Err(format!(
                "appearance.npy: pixel ({}, {}) channel {c} = {v}: must be NaN (off the skin) or a count from 0 to {} ({APPEARANCE_HEADROOM} x the full scale {full_scale}: the captures over their gains)",
                k % width.max(1),
                k / width.max(1),
                APPEARANCE_HEADROOM * full_scale
            ));
        }
        Ok(PhotometricModel {
            width,
            height,
            reference: appearance,
            coefficients,
            axis,
            rings,
            shadow_coefficients,
            gains: Vec::new(),
            full_scale,
            residual_rms: Vec::new(),
        })
    }
}

/// JSON `text` with the numbers JSON cannot hold quoted as strings: the `NaN`, `Infinity` and
/// `-Infinity` that Python's `json` module writes, and numbers past the f64 range (`1e999`).
/// The model's reader then names the field that holds one (a number is expected there)
/// instead of failing on the syntax.
pub fn quote_non_finite(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let (mut i, mut start) = (0, 0);
    let mut in_string = false;
    while i < b.len() {
        let c = b[i];
        if in_string {
            match c {
                b'\\' => i += 1,
                b'"' => in_string = false,
                _ => {}
            }
            i += 1;
            continue;
        }
        let word = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|w| b[i..].starts_with(w.as_bytes()));
        let token = if let Some(w) = word {
            Some(w.len())
        } else if c == b'-' || c.is_ascii_digit() {
            let n = b[i..]
                .iter()
                .take_while(|x| x.is_ascii_digit() || matches!(x, b'-' | b'+' | b'.' | b'e' | b'E'))
                .count();
            // the token's bytes are ASCII: a char boundary on both sides
            let finite = text[i..i + n].parse::<f64>().is_ok_and(f64::is_finite);
            if finite {
                i += n;
                continue;
            }
            Some(n)
        } else {
            None
        };
        match token {
            Some(n) => {
                out.push_str(&text[start..i]);
                out.push('"');
                out.push_str(&text[i..i + n]);
                out.push('"');
                i += n;
                start = i;
            }
            None => {
                in_string = c == b'"';
                i += 1;
            }
        }
    }
    out.push_str(&text[start..]);
    out
}

/// The inputs a model was fitted with, as `fabkit calibrate photometric` records them in
/// photometric.json: per input (`design`, `camera`, `extrinsics`), its name or file and its
/// sha256. A model belongs to one sensor, camera and pose.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FittedWith {
    /// (input, name or file, sha256), in the record's order.
    pub inputs: Vec<(String, String, String)>,
    /// The record, for messages.
    pub file: String,
}

impl FittedWith {
    /// The inputs recorded in photometric.json's record `v` (none for a record without
    /// them), `file` naming it in messages.
    pub fn of_record(v: &serde_json::Value, file: String) -> FittedWith {
        let inputs = ["design", "camera", "extrinsics"]
            .iter()
            .filter_map(|&key| {
                let sha = v[key]["sha256"].as_str()?;
                let name = v[key]["name"]
                    .as_str()
                    .or(v[key]["file"].as_str())
                    .unwrap_or("?");
                Some((key.to_string(), name.to_string(), sha.to_string()))
            })
            .collect();
        FittedWith { inputs, file }
    }

    /// Refuses `input` (`design`, `camera` or `extrinsics`) with sha256 `sha`, named `ours`
    /// (a file or a design), when the model was fitted with another.
    ///
    /// # Errors
    /// Naming the record, the input, both names and both hashes (first 12 digits).
    pub fn check(&self, input: &str, sha: &str, ours: &str) -> Result<(), String> {
        let Some((_, name, theirs)) = self.inputs.iter().find(|(k, _, _)| k == input) else {
            return Ok(());
        };
        if theirs == sha {
            return Ok(());
        }
        let short = |s: &str| s.chars().take(12).collect::<String>();
        Err(format!(
            "{}: the model was fitted with another {input} ({name}, sha256 {}...), not {ours} (sha256 {}...): a photometric model belongs to one sensor, camera and pose; fit one for these with fabkit calibrate photometric",
            self.file,
            short(theirs),
            short(sha)
        ))
    }
}

/// How far above the full scale an appearance value may lie: the appearance is the captures'
/// counts over their gains, and a gain below 1 lifts a saturated pixel past the full scale.
pub const APPEARANCE_HEADROOM: f64 = 16.0;

/// Largest coefficient a model may hold: a coefficient is the relative change of a pixel's
/// intensity per unit of its feature (or the share of its light a ring or a light stands
/// for), so past it every pressed pixel saturates; fits give values of order 1.
pub const MAX_COEFFICIENT: f64 = 1000.0;

/// Shortest and longest median range from the camera to the skin a model may hold, mm.
pub const SCALE_RANGE_MM: (f64, f64) = (0.1, 1000.0);

/// The numbers of a model read back ([`PhotometricModel::from_json`]): coefficients finite and
/// within [`MAX_COEFFICIENT`], the axes unit vectors, the rings' centre finite and within
/// 1000 mm, their scale within [`SCALE_RANGE_MM`]. Names the first value that is not.
fn check_model_values(
    coefficients: &[Vec<f64>; 3],
    axis: [f64; 3],
    shadow_coefficients: &[[f64; SHADOW_TERMS]; 3],
    rings: &ShadowRings,
) -> Result<(), String> {
    let lists = coefficients
        .iter()
        .enumerate()
        .flat_map(|(c, l)| {
            l.iter()
                .enumerate()
                .map(move |(k, x)| (format!("coefficients_rgb[{c}][{k}]"), *x))
        })
        .chain(shadow_coefficients.iter().enumerate().flat_map(|(c, l)| {
            l.iter()
                .enumerate()
                .map(move |(k, x)| (format!("shadow.coefficients_rgb[{c}][{k}]"), *x))
        }));
    for (key, x) in lists {
        if !(x.is_finite() && x.abs() <= MAX_COEFFICIENT) {
            return Err(format!(
                "model.{key} = {x}: must be a finite number within +-{MAX_COEFFICIENT} (a relative change of the intensity; past it every pressed pixel saturates): not a model fabkit fits"
            ));
        }
    }
    for (key, a) in [("optical_axis", axis), ("shadow.rings.axis", rings.axis)] {
        let n = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(a.iter().all(|x| x.is_finite()) && (n - 1.0).abs() <= 1e-6) {
            return Err(format!(
                "model.{key} = {a:?}: must be a unit vector (length {n})"
            ));
        }
    }
    let max = fabkit_designs::values::MAX_LENGTH_MM;
    if let Some(x) = rings
        .centre_mm
        .iter()
        .find(|x| !(x.is_finite() && x.abs() <= max))
    {
        return Err(format!(
            "model.shadow.rings.centre_mm = {:?}: each coordinate must be finite and within +-{max} mm ({x})",
            rings.centre_mm
        ));
    }
    let (lo, hi) = SCALE_RANGE_MM;
    if !(lo..=hi).contains(&rings.scale_mm) {
        return Err(format!(
            "model.shadow.rings.scale_mm = {}: must be from {lo} to {hi} mm (the skin's median range from the camera)",
            rings.scale_mm
        ));
    }
    Ok(())
}
