//! Marker patterns on surfaces of revolution, and marker features (a radial cylinder with a
//! hemispherical end, raised or recessed).
//!
//! Sources: ShadowTac Sec. III-IV (dimples: cylinder with a hemispheric tip, 0.45 mm base,
//! 0.5 mm height, concentric, 1.4 mm spacing); UVDtact Sec. III (slots and protrusions: 0.5 mm
//! radius cylinder of 0.5 mm height ending in a 0.5 mm radius hemisphere); Pestell et al.
//! Sec. III-A, III-D (TacTip pins ending in white dots, four layouts).
//!
//! Positions are on an offset surface of the body profile (sensor frame); a marker's
//! arc length `s` is measured along the profile curve from the pole, its azimuth from +x
//! towards +y. Its polar angle is the angle between +z and the direction from the origin to
//! the marker (for spherical profiles: the usual polar angle).

use crate::geometry::profile2d::push_arc;
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use crate::profile::BodyProfile;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

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
/// stands out of the skin (its mold carries a recess). The same as [`Polarity::Recessed`] and
/// [`Polarity::Raised`] of the surface that carries the feature.
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

/// The turn of the odd rings of an alternating [`RingAzimuthOffset`].
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
    /// (field below `pattern`, value, rule). [`place`] checks these first and the rest
    /// (room on the surface, rings beyond the rim) while placing.
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
    fn ring_offset_rad(&self, k: u32, n: usize) -> f64 {
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

/// Count and spacing of a placed pattern, distances measured on the surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatternStats {
    pub count: usize,
    /// Smallest nearest-neighbour distance on the surface, mm (0 for fewer than 2 markers).
    pub min_spacing_mm: f64,
    pub median_spacing_mm: f64,
    /// The pair with the smallest distance.
    pub closest_pair: Option<(usize, usize)>,
}

/// An offset surface of a body profile, parametrised by arc length from the pole.
#[derive(Debug, Clone)]
pub struct Surface {
    pub body: BodyProfile,
    pub offset_mm: f64,
    /// (t, s): profile parameter and arc length, increasing, for the curved part.
    table: Vec<(f64, f64)>,
    /// Arc length of the curved part (pole to the rim on the base plane, or to the equator
    /// for the hemisphere on cylinder).
    curved_arc_mm: f64,
    /// Straight cylinder below the curved part (hemisphere on cylinder), mm.
    cylinder_mm: f64,
}

const TABLE_SAMPLES: usize = 4096;

impl Surface {
    pub fn new(body: &BodyProfile, offset_mm: f64) -> Self {
        let mut table = Vec::with_capacity(TABLE_SAMPLES + 1);
        let mut s = 0.0;
        let mut prev = body.offset_point(offset_mm, 0.0);
        table.push((0.0, 0.0));
        for i in 1..=TABLE_SAMPLES {
            let t = i as f64 / TABLE_SAMPLES as f64;
            let p = body.offset_point(offset_mm, t);
            // Chord of a fine sample; for arcs the exact length follows below.
            s += ((p[0] - prev[0]).powi(2) + (p[1] - prev[1]).powi(2)).sqrt();
            table.push((t, s));
            prev = p;
        }
        // Spherical profiles: exact arc length rho * angle (t is linear in angle).
        if let Some(r) = body.sphere_radius_mm() {
            let rho = r + offset_mm;
            let a_end =
                body.offset_normal(offset_mm, 1.0)[1].atan2(body.offset_normal(offset_mm, 1.0)[0]);
            let total = rho * (FRAC_PI_2 - a_end);
            for e in &mut table {
                e.1 = total * e.0;
            }
        }
        let curved_arc_mm = table.last().map(|e| e.1).unwrap_or(0.0);
        let cylinder_mm = match *body {
            BodyProfile::HemisphereOnCylinder {
                cylinder_length_mm, ..
            } => cylinder_length_mm,
            _ => 0.0,
        };
        Self {
            body: body.clone(),
            offset_mm,
            table,
            curved_arc_mm,
            cylinder_mm,
        }
    }

    /// Arc length from the pole to the base plane, mm.
    pub fn total_arc_mm(&self) -> f64 {
        self.curved_arc_mm + self.cylinder_mm
    }

    fn t_of_s(&self, s: f64) -> f64 {
        let s = s.clamp(0.0, self.curved_arc_mm);
        let i = self
            .table
            .partition_point(|e| e.1 < s)
            .clamp(1, self.table.len() - 1);
        let (t0, s0) = self.table[i - 1];
        let (t1, s1) = self.table[i];
        if s1 > s0 {
            t0 + (t1 - t0) * (s - s0) / (s1 - s0)
        } else {
            t0
        }
    }

    /// (r, z) and the outward normal (nr, nz) at arc length `s`.
    pub fn profile_at(&self, s: f64) -> ([f64; 2], [f64; 2]) {
        if s > self.curved_arc_mm {
            let p = self.body.offset_point(self.offset_mm, 1.0);
            ([p[0], p[1] - (s - self.curved_arc_mm)], [1.0, 0.0])
        } else {
            let t = self.t_of_s(s);
            (
                self.body.offset_point(self.offset_mm, t),
                self.body.offset_normal(self.offset_mm, t),
            )
        }
    }

    /// Position and outward normal in the sensor frame at (arc length, azimuth in radians).
    pub fn point(&self, s: f64, azimuth: f64) -> ([f64; 3], [f64; 3]) {
        let (p, n) = self.profile_at(s);
        let (sa, ca) = azimuth.sin_cos();
        ([p[0] * ca, p[0] * sa, p[1]], [n[0] * ca, n[0] * sa, n[1]])
    }

    /// Radius (distance from the axis) at arc length `s`.
    pub fn radius_at(&self, s: f64) -> f64 {
        self.profile_at(s).0[0]
    }

    /// Polar angle (degrees, from +z, seen from the origin) at arc length `s`.
    pub fn polar_deg_at(&self, s: f64) -> f64 {
        let p = self.profile_at(s).0;
        p[0].atan2(p[1]).to_degrees()
    }

    /// Arc length where the polar angle is `polar_deg` (it grows monotonically with s).
    pub fn s_at_polar_deg(&self, polar_deg: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, self.total_arc_mm());
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.polar_deg_at(mid) < polar_deg {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Surface area between the pole and arc length `s` (Pappus, trapezoid on 2000 panels), mm^2.
    pub fn area_to(&self, s: f64) -> f64 {
        let n = 2000;
        let h = s / n as f64;
        (0..n)
            .map(|i| PI * (self.radius_at(i as f64 * h) + self.radius_at((i + 1) as f64 * h)) * h)
            .sum()
    }

    /// Principal curvatures (meridian, parallel) at arc length `s`, 1/mm; positive for a
    /// surface that curves away from its outward normal (convex).
    pub fn curvatures_at(&self, s: f64) -> (f64, f64) {
        let h = 1e-4;
        let s0 = (s - h).max(0.0);
        let s1 = (s + h).min(self.total_arc_mm());
        let (n0, n1) = (self.profile_at(s0).1, self.profile_at(s1).1);
        let a0 = n0[1].atan2(n0[0]);
        let a1 = n1[1].atan2(n1[0]);
        let k_meridian = if s1 > s0 { (a0 - a1) / (s1 - s0) } else { 0.0 };
        let (p, n) = self.profile_at(s);
        let k_parallel = if p[0] > 1e-9 { n[0] / p[0] } else { k_meridian };
        (k_meridian, k_parallel)
    }

    /// Length of the straight chord between two surface points projected onto the surface
    /// (16 segments), mm: the on-surface distance for nearby markers.
    pub fn surface_distance(&self, a: &Marker, b: &Marker) -> f64 {
        let steps = 16;
        let mut prev = a.position_mm;
        let mut len = 0.0;
        for i in 1..=steps {
            let f = i as f64 / steps as f64;
            let q = if i == steps {
                b.position_mm
            } else {
                let c = [
                    a.position_mm[0] + f * (b.position_mm[0] - a.position_mm[0]),
                    a.position_mm[1] + f * (b.position_mm[1] - a.position_mm[1]),
                    a.position_mm[2] + f * (b.position_mm[2] - a.position_mm[2]),
                ];
                self.project(c, a.arc_mm + f * (b.arc_mm - a.arc_mm))
            };
            len += ((q[0] - prev[0]).powi(2) + (q[1] - prev[1]).powi(2) + (q[2] - prev[2]).powi(2))
                .sqrt();
            prev = q;
        }
        len
    }

    /// The closest surface point to `c`, starting the search at arc length `s_guess`.
    fn project(&self, c: [f64; 3], s_guess: f64) -> [f64; 3] {
        let r = (c[0] * c[0] + c[1] * c[1]).sqrt();
        let az = c[1].atan2(c[0]);
        let mut s = s_guess;
        for _ in 0..8 {
            let (p, n) = self.profile_at(s);
            // tangent (pointing to growing s) is the normal rotated by -90 degrees
            let t = [n[1], -n[0]];
            let step = (r - p[0]) * t[0] + (c[2] - p[1]) * t[1];
            s = (s + step).clamp(0.0, self.total_arc_mm());
            if step.abs() < 1e-12 {
                break;
            }
        }
        self.point(s, az).0
    }
}

/// Most markers one pattern may place. Counts are estimated from the parameters before any
/// marker is placed (a golden spiral of 1e8 markers once aborted on an 8.8 GB allocation);
/// the library's patterns have 85 to 627 markers.
pub const MAX_MARKERS_PER_PATTERN: usize = 100_000;

/// How the rule of a parameter that the rest of the design ignores begins (a sweep refuses to
/// vary such a parameter: every variant would be the same).
pub const NO_EFFECT: &str = "has no effect";

/// The arc lengths (mm, from the pole) between which `pattern` places its markers on
/// `surface`: its polar limits, else the pole and the rim less `rim_margin_mm`.
///
/// # Errors
/// A polar limit beyond the surface, or limits that leave no room.
fn patterned_arc(
    surface: &Surface,
    pattern: &Pattern,
    rim_margin_mm: f64,
) -> Result<(f64, f64), PatternError> {
    let err = |f: &str, v: String, rule: &str| Err((f.to_string(), v, rule.to_string()));
    let surface_max_deg = surface.polar_deg_at(surface.total_arc_mm());
    if let Some(p) = pattern.max_polar_deg.filter(|&p| p > surface_max_deg) {
        return err(
            "max_polar_deg",
            p.to_string(),
            &format!(
                "must be at most the surface's polar range, {surface_max_deg:.3} deg at its rim"
            ),
        );
    }
    let s_max = match pattern.max_polar_deg {
        Some(p) => surface.s_at_polar_deg(p),
        None => surface.total_arc_mm() - rim_margin_mm,
    };
    let s_min = pattern
        .min_polar_deg
        .map(|p| surface.s_at_polar_deg(p))
        .unwrap_or(0.0);
    if !(s_max > s_min) {
        // name the limit that was given: the minimum when only it is (the maximum is the rim)
        return match (pattern.max_polar_deg, pattern.min_polar_deg) {
            (Some(p), _) => err(
                "max_polar_deg",
                p.to_string(),
                "leaves no room for markers between the polar limits and the rim",
            ),
            (None, Some(p)) => err(
                "min_polar_deg",
                p.to_string(),
                &format!(
                    "leaves no room for markers between it and the rim margin ({rim_margin_mm:.3} mm of arc below {surface_max_deg:.3} deg)"
                ),
            ),
            (None, None) => err(
                "feature.diameter_mm",
                format!("{rim_margin_mm}"),
                "leaves no room for markers: the rim margin (one feature diameter) covers the surface",
            ),
        };
    }
    Ok((s_min, s_max))
}

/// Every point of a `list` pattern that cannot be placed on `surface`, as (`points[i]`, value,
/// rule), in list order; empty for other layouts or when the polar limits are themselves wrong
/// ([`place`] reports those).
pub fn point_errors(surface: &Surface, pattern: &Pattern, rim_margin_mm: f64) -> Vec<PatternError> {
    let (Some(pts), Ok((s_min, s_max))) = (
        pattern.points.as_ref(),
        patterned_arc(surface, pattern, rim_margin_mm),
    ) else {
        return Vec::new();
    };
    bad_points(surface, pts, s_min, s_max)
}

fn bad_points(surface: &Surface, pts: &[[f64; 2]], s_min: f64, s_max: f64) -> Vec<PatternError> {
    let mut out = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        let rule = if !(p[0] >= 0.0 && p[0].is_finite() && p[1].is_finite()) {
            "polar angle must be >= 0 and both angles finite"
        } else {
            let s = surface.s_at_polar_deg(p[0]);
            if s > s_max + 1e-9 || s < s_min - 1e-9 {
                "lies outside the patterned region"
            } else {
                continue;
            }
        };
        out.push((format!("points[{i}]"), format!("{p:?}"), rule.to_string()));
    }
    out
}

/// Places the markers of `pattern` on `surface`.
///
/// `rim_margin_mm` keeps marker centres that far (in arc length) from the base plane when no
/// polar limit is given.
///
/// # Errors
/// The first violation as (field below `pattern`, value, rule); the caller adds the path.
/// [`Pattern::field_errors`] lists every violation of the fields themselves.
pub fn place(
    surface: &Surface,
    pattern: &Pattern,
    rim_margin_mm: f64,
) -> Result<Vec<Marker>, PatternError> {
    if let Some(e) = pattern.field_errors().into_iter().next() {
        return Err(e);
    }
    let (s_min, s_max) = patterned_arc(surface, pattern, rim_margin_mm)?;
    let region = Region {
        surface,
        pattern,
        rim_margin_mm,
        s_min,
        s_max,
        polar_max: surface.polar_deg_at(s_max),
        centre: pattern.center_marker && s_min == 0.0,
    };
    let raw = match pattern.layout {
        Layout::Concentric6k => concentric_6k_raw(&region)?,
        Layout::Concentric => concentric_raw(&region)?,
        Layout::HexGrid => hex_grid_raw(&region)?,
        Layout::GoldenSpiral => golden_spiral_raw(&region)?,
        Layout::List => list_raw(&region)?,
    };
    Ok(raw
        .into_iter()
        .enumerate()
        .map(|(id, (s, az, ring))| {
            let (position_mm, normal) = surface.point(s, az);
            Marker {
                id,
                ring,
                arc_mm: s,
                azimuth_deg: az.to_degrees(),
                polar_deg: surface.polar_deg_at(s),
                position_mm,
                normal,
            }
        })
        .collect())
}

/// What every layout places its markers in: the pattern on its surface, and the patterned
/// region between `s_min` and `s_max` mm of arc from the pole (`polar_max` deg at its outer
/// edge); `centre`: a marker goes on the pole.
struct Region<'a> {
    surface: &'a Surface,
    pattern: &'a Pattern,
    rim_margin_mm: f64,
    s_min: f64,
    s_max: f64,
    polar_max: f64,
    centre: bool,
}

impl Region<'_> {
    /// The rule that bounds the region, for messages: `max_polar_deg` when given, else the rim
    /// less `rim_margin_mm` mm of arc.
    fn limit(&self) -> String {
        match self.pattern.max_polar_deg {
            Some(p) => format!("max_polar_deg {p}"),
            None => format!(
                "the rim at {:.3} deg less a margin of {:.3} mm of arc",
                self.surface.polar_deg_at(self.surface.total_arc_mm()),
                self.rim_margin_mm
            ),
        }
    }
}

/// A marker before it is placed: (arc length mm, azimuth radians, ring).
type RawMarker = (f64, f64, u32);

/// A pattern error as an `Err`: (field below `pattern`, value, rule).
fn pattern_err<T>(f: &str, v: String, rule: &str) -> Result<T, PatternError> {
    Err((f.to_string(), v, rule.to_string()))
}

/// The value `v` of field `f` of `pattern` when it is finite and above 0; the violation
/// otherwise (a missing value is required by the pattern's layout).
fn positive(pattern: &Pattern, f: &str, v: Option<f64>) -> Result<f64, PatternError> {
    match v {
        Some(x) if x > 0.0 && x.is_finite() => Ok(x),
        Some(x) => Err((f.to_string(), x.to_string(), "must be above 0".into())),
        None => Err((
            f.to_string(),
            "missing".into(),
            format!("is required for layout {}", layout_name(pattern.layout)),
        )),
    }
}

/// The violation of a pattern whose `field` (of `value`) places about `n` markers, more than
/// [`MAX_MARKERS_PER_PATTERN`].
fn too_many(field: &str, value: String, n: f64) -> PatternError {
    // Counts are bounded before anything is placed.
    (
        field.to_string(),
        value,
        format!(
            "places about {n:.0} markers, more than the {MAX_MARKERS_PER_PATTERN} one pattern may have"
        ),
    )
}

/// Pushes onto `raw` ring `k` of `n` markers at arc length `s` mm, evenly spaced in azimuth
/// from the ring's offset (`ring_azimuth_offset` of `pattern`).
fn push_ring(pattern: &Pattern, raw: &mut Vec<RawMarker>, s: f64, k: u32, n: usize) {
    let off = pattern.ring_offset_rad(k, n);
    for j in 0..n {
        raw.push((s, off + 2.0 * PI * j as f64 / n as f64, k));
    }
}

/// The markers of a `concentric_6k` pattern as (arc length mm, azimuth radians, ring): the
/// centre marker when `centre`, then ring k of 6k markers at k pitches (`pitch_arc_mm` of arc
/// or `polar_step_deg`), each ring within the patterned region (up to `s_max` mm of arc,
/// `polar_max` deg).
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn concentric_6k_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_max, polar_max, centre) =
        (r.surface, r.pattern, r.s_max, r.polar_max, r.centre);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let rings = pattern.rings.ok_or_else(|| {
        (
            "rings".to_string(),
            "missing".to_string(),
            "is required for concentric_6k".to_string(),
        )
    })?;
    let n = 1.0 + 3.0 * f64::from(rings) * (f64::from(rings) + 1.0);
    if n > cap {
        return Err(too_many("rings", rings.to_string(), n));
    }
    if centre {
        raw.push((0.0, 0.0, 0));
    }
    if let Some(step) = pattern.polar_step_deg {
        let last = rings as f64 * step;
        if last > polar_max + 1e-9 {
            return pattern_err(
                "polar_step_deg",
                step.to_string(),
                &format!(
                    "puts ring {rings} at {rings} x {step} = {last:.4} deg, beyond the patterned region (up to {polar_max:.4} deg: {})",
                    r.limit()
                ),
            );
        }
        for k in 1..=rings {
            let s = surface.s_at_polar_deg(k as f64 * step);
            push_ring(pattern, &mut raw, s, k, 6 * k as usize);
        }
    } else {
        let pitch = positive(pattern, "pitch_arc_mm", pattern.pitch_arc_mm)?;
        for k in 1..=rings {
            let s = k as f64 * pitch;
            if s > s_max + 1e-9 {
                return pattern_err("rings", rings.to_string(), &format!("ring {k} at {s:.3} mm of arc lies beyond the patterned region ({s_max:.3} mm: {})", r.limit()));
            }
            push_ring(pattern, &mut raw, s, k, 6 * k as usize);
        }
    }
    Ok(raw)
}

/// The markers of a `concentric` pattern as (arc length mm, azimuth radians, ring): the
/// centre marker when `centre`, then rings one `polar_step_deg` (or else one `spacing_mm` of
/// arc) apart, the first at the inner limit (`min_polar_deg`, `s_min` mm of arc) when there is
/// one and one step from the pole otherwise, up to `s_max` mm of arc (`polar_max` deg); each
/// ring holds markers about `spacing_mm` apart.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn concentric_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let (polar_max, centre) = (r.polar_max, r.centre);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let sp = positive(pattern, "spacing_mm", pattern.spacing_mm)?;
    if centre {
        raw.push((0.0, 0.0, 0));
    }
    // Ring k's arc length, or None beyond the region.
    let ring_s = |k: u32| -> Option<f64> {
        match pattern.polar_step_deg {
            Some(step) => {
                let p0 = pattern.min_polar_deg.filter(|_| s_min > 0.0);
                let polar = match p0 {
                    Some(p0) => p0 + (k - 1) as f64 * step,
                    None => k as f64 * step,
                };
                (polar <= polar_max + 1e-9).then(|| surface.s_at_polar_deg(polar))
            }
            None => {
                let s = if s_min > 0.0 {
                    s_min + (k - 1) as f64 * sp
                } else {
                    k as f64 * sp
                };
                (s <= s_max + 1e-9).then_some(s)
            }
        }
    };
    // Each ring is counted before it is placed.
    let mut total = usize::from(centre);
    let mut k = 1;
    while let Some(s) = ring_s(k) {
        // counted in f64 and compared before the cast: a spacing of 1e-300 mm makes
        // a ratio past usize::MAX
        let n_f = (2.0 * PI * surface.radius_at(s) / sp).round().max(1.0);
        let count_f = total as f64 + n_f;
        if count_f > cap {
            // The parameter that drives the count: the ring pitch when there are more
            // rings than markers on a ring, else the spacing along the rings.
            let (field, value) = match pattern.polar_step_deg {
                Some(step) if f64::from(k) * f64::from(k) > count_f => {
                    ("polar_step_deg", step.to_string())
                }
                _ => ("spacing_mm", sp.to_string()),
            };
            return Err((
                field.to_string(),
                value,
                format!(
                    "places more than {MAX_MARKERS_PER_PATTERN} markers (by ring {k}), the most one pattern may have"
                ),
            ));
        }
        let n = n_f as usize;
        total += n;
        push_ring(pattern, &mut raw, s, k, n);
        k += 1;
    }
    if let Some(RingAzimuthOffset::PerRingDeg(v)) = &pattern.ring_azimuth_offset {
        if v.len() != (k - 1) as usize {
            return pattern_err(
                "ring_azimuth_offset.per_ring_deg",
                format!("{} entries", v.len()),
                &format!("needs one entry per ring (the pattern has {} rings)", k - 1),
            );
        }
    }
    Ok(raw)
}

/// The markers of a `hex_grid` pattern as (arc length mm, azimuth radians, 0): the points of a
/// hexagonal lattice of pitch `spacing_mm`, laid out in arc length (mm) and azimuth about the
/// pole, from `s_min` to `s_max` mm of arc; ordered by arc length, then azimuth.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn hex_grid_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (pattern, s_min, s_max) = (r.pattern, r.s_min, r.s_max);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let a = positive(pattern, "spacing_mm", pattern.spacing_mm)?;
    // Lattice points in the disc of radius s_max (the loop visits its bounding square).
    let n = PI * s_max * s_max / (a * a * 3f64.sqrt() / 2.0);
    if n > cap {
        return Err(too_many("spacing_mm", a.to_string(), n));
    }
    let m = (s_max / a).ceil() as i64 + 1;
    // rows are (sqrt 3 / 2) a apart, and row j is shifted by j/2 pitches
    let rows = (s_max / (a * 3f64.sqrt() / 2.0)).ceil() as i64 + 1;
    for j in -rows..=rows {
        let w = m + (j.abs() + 1) / 2;
        for i in -w..=w {
            let x = a * (i as f64 + 0.5 * j as f64);
            let y = a * (3f64.sqrt() / 2.0) * j as f64;
            let s = (x * x + y * y).sqrt();
            if s >= s_min - 1e-12 && s <= s_max + 1e-12 {
                raw.push((s, y.atan2(x), 0));
            }
        }
    }
    // deterministic order: by arc length, then azimuth
    raw.sort_by(|p, q| {
        (p.0, p.1)
            .partial_cmp(&(q.0, q.1))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(raw)
}

/// The markers of a `golden_spiral` pattern as (arc length mm, azimuth radians, 0): `count`
/// markers (or as many as `spacing_mm` gives) at equal steps of surface area from `s_min` to
/// `s_max` mm of arc, turned by the golden angle one to the next.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn golden_spiral_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    // cumulative area table from s_min to s_max, inverted by interpolation
    let k = 4096;
    let ss: Vec<f64> = (0..=k)
        .map(|i| s_min + (s_max - s_min) * i as f64 / k as f64)
        .collect();
    let rs: Vec<f64> = ss.iter().map(|&x| surface.radius_at(x)).collect();
    let mut area = vec![0.0; k + 1];
    for i in 1..=k {
        area[i] = area[i - 1] + PI * (rs[i - 1] + rs[i]) * (ss[i] - ss[i - 1]);
    }
    let a_total = area[k];
    let n = match (pattern.count, pattern.spacing_mm) {
        (Some(c), _) if c as usize > MAX_MARKERS_PER_PATTERN => {
            return Err(too_many("count", c.to_string(), f64::from(c)))
        }
        (Some(c), _) if c > 0 => c as usize,
        (Some(c), _) => return pattern_err("count", c.to_string(), "must be above 0"),
        (None, sp) => {
            let sp = positive(pattern, "spacing_mm", sp)?;
            let n = (a_total / (sp * sp * 3f64.sqrt() / 2.0)).round();
            if n > cap {
                return Err(too_many("spacing_mm", sp.to_string(), n));
            }
            (n as usize).max(1)
        }
    };
    let golden = PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let target = (i as f64 + 0.5) / n as f64 * a_total;
        let j = area.partition_point(|&a| a < target).clamp(1, k);
        let f = (target - area[j - 1]) / (area[j] - area[j - 1]).max(f64::MIN_POSITIVE);
        let s = ss[j - 1] + f * (ss[j] - ss[j - 1]);
        raw.push((s, (i as f64 * golden).rem_euclid(2.0 * PI), 0));
    }
    Ok(raw)
}

/// The markers of a `list` pattern as (arc length mm, azimuth radians, 0), in list order, each
/// point within `s_min` to `s_max` mm of arc.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn list_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let mut raw = Vec::new();
    let pts = pattern.points.as_ref().ok_or_else(|| {
        (
            "points".to_string(),
            "missing".to_string(),
            "is required for layout list (or csv_file)".to_string(),
        )
    })?;
    if pts.len() > MAX_MARKERS_PER_PATTERN {
        return Err(too_many(
            "points",
            format!("{} points", pts.len()),
            pts.len() as f64,
        ));
    }
    if let Some(e) = bad_points(surface, pts, s_min, s_max).into_iter().next() {
        return Err(e);
    }
    for p in pts {
        raw.push((surface.s_at_polar_deg(p[0]), p[1].to_radians(), 0));
    }
    Ok(raw)
}

/// For each point, (index, chord distance) of its nearest other point, by a bucket grid.
/// Needs at least two points.
pub fn nearest_neighbours(points: &[[f64; 3]]) -> Vec<(usize, f64)> {
    let n = points.len();
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let cell = (diag / (n as f64).sqrt()).max(1e-6);
    let key = |p: [f64; 3]| {
        [
            (p[0] / cell).floor() as i64,
            (p[1] / cell).floor() as i64,
            (p[2] / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::new();
    for (i, p) in points.iter().enumerate() {
        grid.entry(key(*p)).or_default().push(i);
    }
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let k = key(p);
            let mut best = (usize::MAX, f64::INFINITY);
            let mut radius = 1;
            loop {
                for dx in -radius..=radius {
                    for dy in -radius..=radius {
                        for dz in -radius..=radius {
                            if let Some(v) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                                for &j in v {
                                    if j != i {
                                        let d = dist(p, points[j]);
                                        if d < best.1 || (d == best.1 && j < best.0) {
                                            best = (j, d);
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
                // a neighbour found within `radius` cells is the nearest if its distance is
                // below radius x cell
                if best.1 <= radius as f64 * cell || radius > 1 << 20 {
                    break;
                }
                radius *= 2;
            }
            best
        })
        .collect()
}

/// Count and nearest-neighbour spacing on the surface.
pub fn stats(surface: &Surface, markers: &[Marker]) -> PatternStats {
    let n = markers.len();
    if n < 2 {
        return PatternStats {
            count: n,
            min_spacing_mm: 0.0,
            median_spacing_mm: 0.0,
            closest_pair: None,
        };
    }
    let points: Vec<[f64; 3]> = markers.iter().map(|m| m.position_mm).collect();
    let neighbours = nearest_neighbours(&points);
    let mut nn = Vec::with_capacity(n);
    let mut best_pair = (0, 1, f64::INFINITY);
    for (i, m) in markers.iter().enumerate() {
        let best = neighbours[i];
        let d = surface.surface_distance(m, &markers[best.0]);
        if d < best_pair.2 {
            best_pair = (i.min(best.0), i.max(best.0), d);
        }
        nn.push(d);
    }
    nn.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    let median = if n % 2 == 1 {
        nn[n / 2]
    } else {
        0.5 * (nn[n / 2 - 1] + nn[n / 2])
    };
    PatternStats {
        count: n,
        min_spacing_mm: nn[0],
        median_spacing_mm: median,
        closest_pair: Some((best_pair.0, best_pair.1)),
    }
}

/// How deep a feature reaches behind the surface so that it joins the body without a gap:
/// the sagitta of its base disc on the most curved direction, plus the chord tolerance, plus
/// a margin.
pub fn embed_depth_mm(shape: &FeatureShape, max_curvature: f64, tol: ChordTolerance) -> f64 {
    let r = shape.radius_mm();
    r * r * max_curvature.abs() + 2.0 * tol.mm() + 0.02
}

/// The solid of one feature along `dir` (unit) from `position`: from `embed_mm` behind the
/// surface to `height_mm` beyond it. Built as a revolve about its own axis.
///
/// # Errors
/// Only on a kernel failure.
pub fn feature_solid(
    shape: &FeatureShape,
    position: [f64; 3],
    dir: [f64; 3],
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    Ok(local_feature(shape, embed_mm, tol)?.transform(&frame_to(position, dir)))
}

/// The feature in its own frame: axis +z, the surface point at the origin.
///
/// # Errors
/// Only on a kernel failure.
pub fn local_feature(
    shape: &FeatureShape,
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    local_feature_dilated(shape, 0.0, embed_mm, tol)
}

/// The feature of `shape` grown by `dilation_mm` all round (its Minkowski sum with a ball,
/// the rounding of its rim left out), seen from the offset surface `dilation_mm` beyond the
/// one that carries it: what a coat of that thickness, sprayed into the mold so that it
/// follows the cavity, needs from the cavity so that the layer under it gets `shape`. Its own
/// frame: axis +z along the feature, the point on the offset surface at the origin. The
/// radius becomes r + t and the hemisphere's centre moves t closer to the new surface; the
/// height from the new surface stays `height_mm` (the coat offsets both the surface and the
/// feature's end). For a recessed feature give `dilation_mm` < 0: the former shrinks by the
/// coat (r - t), its centre moves t deeper. 0 gives [`local_feature`]. Sources: the coat as
/// a conformal film of uniform thickness (the model of a sprayed coat, Sec. III-B1 of the
/// R-Tac0 paper: sprayed into the mold, it takes the cavity's shape).
///
/// # Errors
/// Only on a kernel failure.
pub fn local_feature_dilated(
    shape: &FeatureShape,
    dilation_mm: f64,
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let r = shape.radius_mm() + dilation_mm;
    let hc = shape.height_mm - shape.radius_mm() - dilation_mm;
    let embed_mm = embed_mm.max(-hc + tol.mm());
    let mut pl = Polyline2::default();
    pl.push([0.0, -embed_mm]);
    pl.push([r, -embed_mm]);
    push_arc(&mut pl, [0.0, hc], r, 0.0, FRAC_PI_2, tol.half());
    Solid::from_mesh(&revolve(&pl, tol)?)
}

/// The affine map taking the local +z axis at the origin to `dir` at `position`.
pub fn frame_to(position: [f64; 3], dir: [f64; 3]) -> crate::geometry::Affine {
    use nalgebra::Vector3;
    let z = Vector3::from(dir);
    // any vector not parallel to z
    let helper = if z[2].abs() < 0.9 {
        Vector3::z()
    } else {
        Vector3::x()
    };
    let x = helper.cross(&z).normalize();
    let y = z.cross(&x);
    crate::geometry::transform::from_columns(x.into(), y.into(), dir, position)
}

/// Volume of the gap between the tangent plane and the surface over the feature's base disc,
/// mm^3 (second order in the curvatures: pi r^4 (k1 + k2) / 8); positive for a convex surface.
pub fn tangent_gap_volume_mm3(shape: &FeatureShape, k1: f64, k2: f64) -> f64 {
    let r = shape.radius_mm();
    PI * r.powi(4) * (k1 + k2) / 8.0
}
