//! The markers' types: what a design gives (the surface, the pattern and its layout, the
//! feature's shape: [`MarkerSpec`]), the checks of a pattern's own fields, and one placed
//! [`Marker`].

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which surface of a layer carries the markers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MarkerSurface {
    Outer,
    Inner,
}

/// Whether a feature stands out of the part's surface or is cut into it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Polarity {
    Raised,
    Recessed,
}

/// Which side of the skin a feature is on, in a maker's words: a `dimple` is cut into the
/// skin (its mold carries a pin standing out of the cavity wall into the cavity), a `bump`
/// stands out of the skin (its mold carries a recess). The same as `polarity: recessed` and
/// `polarity: raised` of the surface that carries the feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum OnSkin {
    Dimple,
    Bump,
}

impl From<OnSkin> for Polarity {
    fn from(s: OnSkin) -> Self {
        match s {
            OnSkin::Dimple => Polarity::Recessed,
            OnSkin::Bump => Polarity::Raised,
        }
    }
}

/// A radial cylinder ending in a hemisphere of the same diameter. Give exactly one of
/// `on_skin` and `polarity` (validation names `...feature` otherwise).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FeatureShape {
    /// Cylinder (and hemisphere) diameter, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// From the surface to the tip of the hemisphere, along the normal, mm (>= radius).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Whether the feature stands out of the surface that carries it or is cut into it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarity: Option<Polarity>,
    /// The same choice in a maker's words: `dimple` (cut into the skin) or `bump`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on_skin: Option<OnSkin>,
}

impl FeatureShape {
    /// A feature of the given polarity (given as `polarity`).
    pub fn new(diameter_mm: f64, height_mm: f64, polarity: Polarity) -> Self {
        Self {
            diameter_mm,
            height_mm,
            polarity: Some(polarity),
            on_skin: None,
        }
    }

    /// The polarity the feature was given, as `polarity` or as `on_skin`. On a shape that
    /// gives neither or both (validation rejects those), `on_skin` wins, then raised.
    pub fn side(&self) -> Polarity {
        match (self.on_skin, self.polarity) {
            (Some(s), _) => s.into(),
            (None, Some(p)) => p,
            (None, None) => Polarity::Raised,
        }
    }

    /// Sets the polarity, in the form (`on_skin` or `polarity`) the shape already uses.
    pub fn set_side(&mut self, p: Polarity) {
        if self.on_skin.is_some() {
            self.on_skin = Some(match p {
                Polarity::Raised => OnSkin::Bump,
                Polarity::Recessed => OnSkin::Dimple,
            });
        } else {
            self.polarity = Some(p);
        }
    }

    pub fn radius_mm(&self) -> f64 {
        self.diameter_mm / 2.0
    }

    /// Volume beyond the tangent plane: cylinder of height (height - radius) plus hemisphere, mm^3.
    pub fn nominal_volume_mm3(&self) -> f64 {
        let r = self.radius_mm();
        PI * r * r * (self.height_mm - r) + 2.0 / 3.0 * PI * r.powi(3)
    }
}

/// The layout of a pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// A centre marker and rings k = 1..rings of 6k markers, ring k at arc length
    /// k x `pitch_arc_mm` or at polar angle k x `polar_step_deg` (exactly one of the two).
    /// The ShadowTac authors' mold: 12 rings, 469 markers, 3.9474 deg apart; TacTipGenerator's
    /// default: 8 rings, 217 pins, 9.3836 deg apart, odd rings turned by half a step.
    #[serde(rename = "concentric_6k")]
    Concentric6k,
    /// A centre marker and rings every `spacing_mm` of arc (or every `polar_step_deg` of polar
    /// angle); round(circumference / spacing) markers per ring.
    Concentric,
    /// A hexagonal lattice of pitch `spacing_mm`, wrapped onto the surface by arc length from
    /// the pole (azimuthal equidistant).
    HexGrid,
    /// Equal-area golden-angle spiral: `count` markers, or as many as the area holds at
    /// `spacing_mm` (hexagonal packing density).
    GoldenSpiral,
    /// Explicit (polar, azimuth) angles in degrees, from `points` or `csv_file`.
    List,
}

/// A marker pattern on a surface. Which fields apply depends on `layout`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Pattern {
    pub layout: Layout,
    /// `concentric_6k`: the rings round the centre marker, ring k = 1..rings holding 6k
    /// markers (ShadowTac authors' mold: 12); required there, ignored by the other layouts.
    /// The last ring must lie in the patterned region.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rings: Option<u32>,
    /// `concentric_6k`: the arc length between rings along the surface, mm, > 0; ring k lies
    /// k x pitch from the pole. Give exactly one of it and `polar_step_deg`; ignored by the
    /// other layouts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_arc_mm: Option<f64>,
    /// Marker spacing measured on the surface, mm, > 0, for `concentric`, `hex_grid` and
    /// `golden_spiral`; refused on `concentric_6k`, ignored by `list`.
    ///
    /// `concentric`: the arc length between rings (unless `polar_step_deg` is given) and the
    /// spacing along each ring (round(circumference / spacing) markers, at least 1);
    /// `hex_grid`: the lattice's pitch; `golden_spiral` without `count`: the count is the
    /// patterned area over that of one marker at this spacing in hexagonal packing. However
    /// laid out, neighbouring features must keep the printer's minimum wall between them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spacing_mm: Option<f64>,
    /// `golden_spiral`: the number of markers, 1 to 100,000; when given it decides the count
    /// instead of `spacing_mm`. Ignored by the other layouts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// (polar_deg, azimuth_deg) pairs for `list`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
    /// CSV file with columns `polar_deg, azimuth_deg` (a header line is allowed), relative to
    /// the design file; read into `points` when the design is loaded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_file: Option<String>,
    /// Whether concentric layouts put a marker on the pole (default true).
    #[serde(default = "yes")]
    pub center_marker: bool,
    /// Limits of the patterned region, polar angle in degrees (default: the whole surface less
    /// a margin of one feature diameter at the rim).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 180))]
    pub max_polar_deg: Option<f64>,
    /// Lower limit of the patterned region, polar angle seen from the sensor-frame origin,
    /// degrees, in [0, 180) and below `max_polar_deg` (default: the pole). When given, the
    /// concentric layouts place no centre marker and `concentric` puts its first ring on the
    /// limit; `concentric_6k` still counts its rings from the pole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 180))]
    pub min_polar_deg: Option<f64>,
    /// Concentric layouts: the polar angle between rings, degrees, finite and above 0. Ring k
    /// sits at polar angle k x step seen from the sensor-frame origin (from `min_polar_deg`
    /// on when that is set, for `concentric`). For `concentric_6k` it replaces
    /// `pitch_arc_mm` (give exactly one); for `concentric` it replaces `spacing_mm` as the
    /// ring pitch, and `spacing_mm` still sets the markers per ring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub polar_step_deg: Option<f64>,
    /// Concentric layouts: how far each ring is turned about the axis (default: none, every
    /// ring has a marker at azimuth 0, on +x).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ring_azimuth_offset: Option<RingAzimuthOffset>,
}

/// Azimuth offset of the rings of a concentric pattern. Rings are numbered k = 1, 2, ... from
/// the pole (the centre marker is ring 0); an offset turns a ring from +x towards +y.
///
/// YAML: `ring_azimuth_offset: {alternate: half_step}` or
/// `ring_azimuth_offset: {per_ring_deg: [0.0, 30.0, ...]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RingAzimuthOffset {
    /// Every odd ring (k = 1, 3, 5, ...) turned by the given fraction of its own azimuth step
    /// (360 / n_k degrees for a ring of n_k markers); even rings keep a marker on +x.
    /// TacTipGenerator's layout (`pointsCalculator` in its skinGenerator.py) is `half_step`.
    Alternate(AlternateOffset),
    /// One offset per ring k = 1..rings, degrees, each finite; as many entries as the pattern
    /// has rings.
    PerRingDeg(
        /// The turn of each ring k = 1, 2, ... in order, degrees from +x towards +y, each
        /// finite: one entry per ring (`rings` of `concentric_6k`; the rings `concentric`
        /// places).
        Vec<f64>,
    ),
}

/// The turn of the odd rings of an alternating ring azimuth offset (`RingAzimuthOffset`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AlternateOffset {
    /// Half the ring's own azimuth step: 180 / n_k degrees.
    HalfStep,
}

/// A pattern error: (field below `pattern`, value, rule).
pub type PatternError = (String, String, String);

impl Pattern {
    /// Whether the layout is one of the concentric ones.
    pub fn is_concentric(&self) -> bool {
        matches!(self.layout, Layout::Concentric | Layout::Concentric6k)
    }

    /// Checks of the pattern's own fields that need no surface: every violation, each as
    /// (field below `pattern`, value, rule). [`place`](super::place) checks these first and
    /// the rest (room on the surface, rings beyond the rim) while placing.
    pub fn field_errors(&self) -> Vec<PatternError> {
        let mut errs: Vec<PatternError> = Vec::new();
        let mut push = |f: &str, v: String, rule: &str| {
            errs.push((f.to_string(), v, rule.to_string()));
        };
        // The polar limits: angles from the sensor axis, min below max.
        if let Some(x) = self.max_polar_deg {
            if !(x > 0.0 && x <= 180.0) {
                push(
                    "max_polar_deg",
                    x.to_string(),
                    "must be a polar angle above 0 and at most 180 deg",
                );
            }
        }
        if let Some(x) = self.min_polar_deg {
            if !(0.0..180.0).contains(&x) {
                push(
                    "min_polar_deg",
                    x.to_string(),
                    "must be a polar angle from 0 to below 180 deg",
                );
            } else if let Some(m) = self.max_polar_deg.filter(|&m| !(x < m)) {
                push(
                    "min_polar_deg",
                    x.to_string(),
                    &format!("must be below max_polar_deg ({m} deg)"),
                );
            }
        }
        if let Some(x) = self.polar_step_deg {
            if !self.is_concentric() {
                push(
                    "polar_step_deg",
                    x.to_string(),
                    &format!(
                        "{NO_EFFECT} on layout {}: it applies only to the concentric layouts",
                        layout_name(self.layout)
                    ),
                );
            } else if !(x > 0.0 && x.is_finite()) {
                push(
                    "polar_step_deg",
                    x.to_string(),
                    "must be a finite angle above 0",
                );
            }
        }
        if self.layout == Layout::Concentric6k {
            if let Some(sp) = self.spacing_mm {
                push(
                    "spacing_mm",
                    sp.to_string(),
                    &format!("{NO_EFFECT} on concentric_6k (ring k holds 6k markers; its pitch is pitch_arc_mm or polar_step_deg): remove it or use layout concentric"),
                );
            }
            match (self.pitch_arc_mm, self.polar_step_deg) {
                (Some(p), Some(x)) => push(
                    "polar_step_deg",
                    x.to_string(),
                    &format!("give exactly one of pitch_arc_mm and polar_step_deg for concentric_6k (pitch_arc_mm is {p} too)"),
                ),
                (None, None) => push(
                    "pitch_arc_mm",
                    "missing".into(),
                    "concentric_6k needs exactly one of pitch_arc_mm and polar_step_deg",
                ),
                _ => {}
            }
        }
        if let Some(off) = &self.ring_azimuth_offset {
            if !self.is_concentric() {
                push(
                    "ring_azimuth_offset",
                    format!("{off:?}"),
                    &format!(
                        "{NO_EFFECT} on layout {}: it applies only to the concentric layouts",
                        layout_name(self.layout)
                    ),
                );
            } else if let RingAzimuthOffset::PerRingDeg(v) = off {
                for (i, x) in v.iter().enumerate() {
                    if !x.is_finite() {
                        push(
                            &format!("ring_azimuth_offset.per_ring_deg[{i}]"),
                            x.to_string(),
                            "must be a finite angle",
                        );
                    }
                }
                if let (Layout::Concentric6k, Some(r)) = (self.layout, self.rings) {
                    if v.len() != r as usize {
                        push(
                            "ring_azimuth_offset.per_ring_deg",
                            format!("{} entries", v.len()),
                            &format!("needs one entry per ring (rings is {r})"),
                        );
                    }
                }
            }
        }
        errs
    }

    /// The azimuth offset of ring k (>= 1) of `n` markers, radians.
    pub(super) fn ring_offset_rad(&self, k: u32, n: usize) -> f64 {
        match &self.ring_azimuth_offset {
            Some(RingAzimuthOffset::Alternate(AlternateOffset::HalfStep)) if k % 2 == 1 => {
                PI / n as f64
            }
            None | Some(RingAzimuthOffset::Alternate(_)) => 0.0,
            Some(RingAzimuthOffset::PerRingDeg(v)) => {
                v.get(k as usize - 1).copied().unwrap_or(0.0).to_radians()
            }
        }
    }
}

/// The YAML name of a layout (`concentric_6k`, `hex_grid`, ...).
pub fn layout_name(l: Layout) -> String {
    serde_json::to_value(l)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{l:?}"))
}

fn yes() -> bool {
    true
}

/// Markers of one surface of a layer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MarkerSpec {
    pub surface: MarkerSurface,
    pub pattern: Pattern,
    pub feature: FeatureShape,
    /// For printed multi-material parts: the end of each feature (its hemisphere) is a
    /// separate object of this material (TacTip white dots, Pestell et al. Sec. III-A).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_material: Option<String>,
}

/// One placed marker.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Marker {
    pub id: usize,
    /// Ring index for concentric layouts (0 = centre), else 0.
    pub ring: u32,
    /// Arc length from the pole along the profile, mm.
    pub arc_mm: f64,
    pub azimuth_deg: f64,
    pub polar_deg: f64,
    /// Position on the surface, sensor frame, mm.
    pub position_mm: [f64; 3],
    /// Outward unit normal of the surface there.
    pub normal: [f64; 3],
}

/// How the rule of a parameter that the rest of the design ignores begins (a sweep refuses to
/// vary such a parameter: every variant would be the same).
pub const NO_EFFECT: &str = "has no effect";
