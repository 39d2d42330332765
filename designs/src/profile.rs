//! Sensor body profiles: the outer surface of the sensor skin as a 2D curve in the (r, z)
//! half-plane, revolved about the sensor axis z. Layers are true offsets of this curve along
//! its normal (an ellipse's offset is not an ellipse).
//!
//! Frame (docs/conventions.md): z is the sensor axis, pointing out through the pole of the
//! skin; the origin is the centre of curvature of the tip (sphere centre, or ellipsoid centre);
//! the skin ends on the base plane z = `base_z_mm()`.

use crate::error::ParamError;
use crate::geometry::profile2d::{push_arc, push_curve};
use crate::geometry::{ChordTolerance, Polyline2};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// The outer surface of a sensor skin. In YAML: a mapping with `profile:` (the variant name in
/// snake case) and that variant's fields.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BodyYaml", into = "BodyYaml")]
pub enum BodyProfile {
    /// A spherical cap: base circle of `base_diameter_mm` on the base plane, pole
    /// `height_mm` above it (ShadowTac skin: 35 mm x 8 mm, ShadowTac Sec. III). In YAML it may
    /// instead be given by `sphere_radius_mm` and `rim_diameter_mm` (the authors' ShadowTac
    /// CAD: R22.5 cut to a 35 mm rim), from which `height_mm` = R - sqrt(R^2 - (rim / 2)^2);
    /// it is written back in the base/height form.
    SphericalCap {
        base_diameter_mm: f64,
        height_mm: f64,
    },
    /// A hemisphere of `radius_mm` on a cylinder of the same radius and
    /// `cylinder_length_mm` (the test-tube shape of R-Tac0, Sec. III-B1).
    HemisphereOnCylinder {
        radius_mm: f64,
        cylinder_length_mm: f64,
    },
    /// Half an ellipsoid of revolution: `diameter_mm` across the base, `height_mm` from the
    /// base plane to the pole (UVDtact, Sec. III).
    HalfEllipsoid { diameter_mm: f64, height_mm: f64 },
    /// A flat skin (Soter et al. Sec. II-A; GelSight, DIGIT): a rounded rectangle
    /// `width_mm` (x) by `length_mm` (y), corners rounded to `corner_radius_mm`, its contact
    /// face `thickness_mm` above the base plane z = 0 ([`crate::parts::flat`]). Offsets move the face
    /// along z; the (r, z) forms below give its section through the x axis.
    Flat {
        width_mm: f64,
        length_mm: f64,
        corner_radius_mm: f64,
        thickness_mm: f64,
    },
}

/// The JSON Schema of the YAML form ([`BodyYaml`]), written by hand because the form is checked
/// by [`TryFrom`]: one branch per profile (and two for a spherical cap: base/height or
/// sphere/rim), each with exactly the keys [`BodyProfile::try_from`] accepts for it. Bounds that
/// the validation checks on one key alone (above 0, 0 or more) are given; those between keys
/// (a cap no taller than half its base, the corner radius below half the shorter side) are
/// not. Every length is mm.
impl schemars::JsonSchema for BodyProfile {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "BodyProfile".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        use serde_json::{json, Map, Value};
        let above0 = |d: &str| json!({"type": "number", "exclusiveMinimum": 0, "description": d});
        let at_least0 = |d: &str| json!({"type": "number", "minimum": 0, "description": d});
        let branch = |profile: &str, d: &str, keys: Vec<(&str, Value)>, required: &[&str]| {
            let mut props = Map::new();
            props.insert(
                "profile".into(),
                json!({"const": profile, "description": "The profile's name."}),
            );
            for (k, v) in keys {
                props.insert(k.into(), v);
            }
            let mut req = vec![Value::from("profile")];
            req.extend(required.iter().map(|k| Value::from(*k)));
            json!({
                "description": d,
                "type": "object",
                "properties": props,
                "required": req,
                "additionalProperties": false,
            })
        };
        let corner = json!({
            "type": ["number", "null"],
            "minimum": 0,
            "description": "Corner radius of the outline, mm (0 when not given), below half the shorter side.",
        });
        let branches = vec![
            branch(
                "spherical_cap",
                "A spherical cap by its base circle and height (ShadowTac skin: 35 mm x 8 mm).",
                vec![
                    ("base_diameter_mm", above0("Diameter of the base circle on the base plane, mm, > 0.")),
                    ("height_mm", above0("From the base plane to the pole, mm, > 0, at most half the base diameter.")),
                ],
                &["base_diameter_mm", "height_mm"],
            ),
            branch(
                "spherical_cap",
                "A spherical cap by its sphere (the authors' ShadowTac CAD: R22.5 cut to a 35 mm rim).",
                vec![
                    ("sphere_radius_mm", above0("Radius of the sphere, mm, > 0.")),
                    ("rim_diameter_mm", above0("Diameter of the rim on the base plane, mm, > 0, at most the sphere's diameter.")),
                ],
                &["sphere_radius_mm", "rim_diameter_mm"],
            ),
            branch(
                "hemisphere_on_cylinder",
                "A hemisphere on a cylinder of the same radius (the test-tube shape of R-Tac0).",
                vec![
                    ("radius_mm", above0("Radius of the hemisphere and the cylinder, mm, > 0.")),
                    ("cylinder_length_mm", at_least0("Length of the cylinder below the hemisphere, mm, >= 0.")),
                ],
                &["radius_mm", "cylinder_length_mm"],
            ),
            branch(
                "half_ellipsoid",
                "Half an ellipsoid of revolution (UVDtact).",
                vec![
                    ("diameter_mm", above0("Diameter across the base, mm, > 0.")),
                    ("height_mm", above0("From the base plane to the pole, mm, > 0.")),
                ],
                &["diameter_mm", "height_mm"],
            ),
            branch(
                "flat",
                "A flat skin: a rounded rectangle, its contact face `thickness_mm` above the base plane.",
                vec![
                    ("width_mm", above0("Across x, mm, > 0.")),
                    ("length_mm", above0("Along y, mm, > 0.")),
                    ("corner_radius_mm", corner),
                    ("thickness_mm", above0("From the base plane to the contact face, mm, > 0.")),
                ],
                &["width_mm", "length_mm", "thickness_mm"],
            ),
        ];
        let mut schema = json!({
            "description": "The outer surface of the skin: a mapping with `profile` and that profile's keys (lengths in mm).",
            "type": "object",
            "required": ["profile"],
            "oneOf": branches,
        });
        if let Value::Object(m) = &mut schema {
            m.insert(
                "properties".into(),
                json!({"profile": {"enum": ["spherical_cap", "hemisphere_on_cylinder", "half_ellipsoid", "flat"]}}),
            );
        }
        schemars::Schema::try_from(schema).unwrap_or_default()
    }
}

/// The YAML form of [`BodyProfile`]: one flat mapping, so that an unknown key is reported at
/// its own line and column (serde's internally tagged enums lose locations).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyYaml {
    pub profile: ProfileKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cylinder_length_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_diameter_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_mm: Option<f64>,
    /// Spherical cap given by its sphere: radius, mm (with `rim_diameter_mm`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere_radius_mm: Option<f64>,
    /// Spherical cap given by its sphere: diameter of the rim on the base plane, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rim_diameter_mm: Option<f64>,
    /// Flat skin: across x, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_mm: Option<f64>,
    /// Flat skin: along y, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_mm: Option<f64>,
    /// Flat skin: corner radius of the outline, mm (0 when not given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner_radius_mm: Option<f64>,
    /// Flat skin: from the base plane to the contact face, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_mm: Option<f64>,
}

/// The profile names of the YAML `profile` key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileKind {
    SphericalCap,
    HemisphereOnCylinder,
    HalfEllipsoid,
    Flat,
}

impl TryFrom<BodyYaml> for BodyProfile {
    type Error = String;
    fn try_from(y: BodyYaml) -> Result<Self, String> {
        let fields = [
            ("radius_mm", y.radius_mm),
            ("cylinder_length_mm", y.cylinder_length_mm),
            ("base_diameter_mm", y.base_diameter_mm),
            ("diameter_mm", y.diameter_mm),
            ("height_mm", y.height_mm),
            ("sphere_radius_mm", y.sphere_radius_mm),
            ("rim_diameter_mm", y.rim_diameter_mm),
            ("width_mm", y.width_mm),
            ("length_mm", y.length_mm),
            ("thickness_mm", y.thickness_mm),
        ];
        if y.corner_radius_mm.is_some() && y.profile != ProfileKind::Flat {
            return Err("body.corner_radius_mm applies to profile flat only".to_string());
        }
        // A cap by its sphere: exactly this form or the base/height form.
        let by_sphere = y.profile == ProfileKind::SphericalCap
            && (y.sphere_radius_mm.is_some() || y.rim_diameter_mm.is_some());
        if by_sphere && (y.base_diameter_mm.is_some() || y.height_mm.is_some()) {
            return Err(
                "body: give a spherical cap either by base_diameter_mm and height_mm or by sphere_radius_mm and rim_diameter_mm, not both forms"
                    .to_string(),
            );
        }
        let (kind, wanted): (&str, &[&str]) = match y.profile {
            ProfileKind::SphericalCap if by_sphere => {
                ("spherical_cap", &["sphere_radius_mm", "rim_diameter_mm"])
            }
            ProfileKind::SphericalCap => ("spherical_cap", &["base_diameter_mm", "height_mm"]),
            ProfileKind::HemisphereOnCylinder => (
                "hemisphere_on_cylinder",
                &["radius_mm", "cylinder_length_mm"],
            ),
            ProfileKind::HalfEllipsoid => ("half_ellipsoid", &["diameter_mm", "height_mm"]),
            ProfileKind::Flat => ("flat", &["width_mm", "length_mm", "thickness_mm"]),
        };
        let mut problems = Vec::new();
        for (name, v) in fields {
            match (wanted.contains(&name), v) {
                (true, None) => {
                    problems.push(format!("body.{name} is required for profile {kind}"))
                }
                (false, Some(_)) => problems.push(format!(
                    "body.{name} does not apply to profile {kind} (it takes {})",
                    wanted.join(", ")
                )),
                _ => {}
            }
        }
        if !problems.is_empty() {
            return Err(problems.join("; "));
        }
        let g = |n: &str| {
            fields
                .iter()
                .find(|(k, _)| *k == n)
                .and_then(|(_, v)| *v)
                .unwrap_or_default()
        };
        if by_sphere {
            let (r, rim) = (g("sphere_radius_mm"), g("rim_diameter_mm"));
            if !(r > 0.0 && r.is_finite()) {
                problems.push(format!("body.sphere_radius_mm = {r}: must be above 0"));
            }
            if !(rim > 0.0 && rim.is_finite()) {
                problems.push(format!("body.rim_diameter_mm = {rim}: must be above 0"));
            } else if r > 0.0 && r.is_finite() && rim > 2.0 * r {
                problems.push(format!(
                    "body.rim_diameter_mm = {rim}: must not exceed the sphere's diameter 2 x body.sphere_radius_mm = {}",
                    2.0 * r
                ));
            }
            if !problems.is_empty() {
                return Err(problems.join("; "));
            }
            let b = rim / 2.0;
            return Ok(Self::SphericalCap {
                base_diameter_mm: rim,
                height_mm: r - ((r - b) * (r + b)).sqrt(),
            });
        }
        Ok(match y.profile {
            ProfileKind::SphericalCap => Self::SphericalCap {
                base_diameter_mm: g("base_diameter_mm"),
                height_mm: g("height_mm"),
            },
            ProfileKind::HemisphereOnCylinder => Self::HemisphereOnCylinder {
                radius_mm: g("radius_mm"),
                cylinder_length_mm: g("cylinder_length_mm"),
            },
            ProfileKind::HalfEllipsoid => Self::HalfEllipsoid {
                diameter_mm: g("diameter_mm"),
                height_mm: g("height_mm"),
            },
            ProfileKind::Flat => Self::Flat {
                width_mm: g("width_mm"),
                length_mm: g("length_mm"),
                corner_radius_mm: y.corner_radius_mm.unwrap_or(0.0),
                thickness_mm: g("thickness_mm"),
            },
        })
    }
}

impl From<BodyProfile> for BodyYaml {
    fn from(b: BodyProfile) -> Self {
        let mut y = BodyYaml {
            profile: ProfileKind::SphericalCap,
            radius_mm: None,
            cylinder_length_mm: None,
            base_diameter_mm: None,
            diameter_mm: None,
            height_mm: None,
            sphere_radius_mm: None,
            rim_diameter_mm: None,
            width_mm: None,
            length_mm: None,
            corner_radius_mm: None,
            thickness_mm: None,
        };
        match b {
            BodyProfile::SphericalCap {
                base_diameter_mm,
                height_mm,
            } => {
                y.base_diameter_mm = Some(base_diameter_mm);
                y.height_mm = Some(height_mm);
            }
            BodyProfile::HemisphereOnCylinder {
                radius_mm,
                cylinder_length_mm,
            } => {
                y.profile = ProfileKind::HemisphereOnCylinder;
                y.radius_mm = Some(radius_mm);
                y.cylinder_length_mm = Some(cylinder_length_mm);
            }
            BodyProfile::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => {
                y.profile = ProfileKind::HalfEllipsoid;
                y.diameter_mm = Some(diameter_mm);
                y.height_mm = Some(height_mm);
            }
            BodyProfile::Flat {
                width_mm,
                length_mm,
                corner_radius_mm,
                thickness_mm,
            } => {
                y.profile = ProfileKind::Flat;
                y.width_mm = Some(width_mm);
                y.length_mm = Some(length_mm);
                y.corner_radius_mm = Some(corner_radius_mm);
                y.thickness_mm = Some(thickness_mm);
            }
        }
        y
    }
}

impl BodyProfile {
    /// Short name, as in the YAML `profile` tag.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::SphericalCap { .. } => "spherical_cap",
            Self::HemisphereOnCylinder { .. } => "hemisphere_on_cylinder",
            Self::HalfEllipsoid { .. } => "half_ellipsoid",
            Self::Flat { .. } => "flat",
        }
    }

    /// Every parameter violation as (path, value, rule).
    pub fn violations(&self) -> Vec<(String, f64, String)> {
        let mut v = Vec::new();
        let mut pos = |name: &str, x: f64| {
            if !(x > 0.0 && x.is_finite()) {
                v.push((format!("body.{name}"), x, "must be above 0".to_string()));
            }
        };
        match *self {
            Self::SphericalCap {
                base_diameter_mm,
                height_mm,
            } => {
                pos("base_diameter_mm", base_diameter_mm);
                pos("height_mm", height_mm);
                if height_mm > base_diameter_mm / 2.0 {
                    v.push((
                        "body.height_mm".into(),
                        height_mm,
                        format!(
                            "must not exceed half the base diameter ({} mm): a taller cap is not a cap",
                            base_diameter_mm / 2.0
                        ),
                    ));
                }
            }
            Self::HemisphereOnCylinder {
                radius_mm,
                cylinder_length_mm,
            } => {
                pos("radius_mm", radius_mm);
                if !(cylinder_length_mm >= 0.0 && cylinder_length_mm.is_finite()) {
                    v.push((
                        "body.cylinder_length_mm".into(),
                        cylinder_length_mm,
                        "must be 0 or more".into(),
                    ));
                }
            }
            Self::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => {
                pos("diameter_mm", diameter_mm);
                pos("height_mm", height_mm);
            }
            Self::Flat {
                width_mm,
                length_mm,
                corner_radius_mm,
                thickness_mm,
            } => {
                pos("width_mm", width_mm);
                pos("length_mm", length_mm);
                pos("thickness_mm", thickness_mm);
                let half = width_mm.min(length_mm) / 2.0;
                if !(corner_radius_mm >= 0.0 && corner_radius_mm < half) && half > 0.0 {
                    v.push((
                        "body.corner_radius_mm".into(),
                        corner_radius_mm,
                        format!("must be 0 or more and below half the shorter side ({half} mm)"),
                    ));
                }
            }
        }
        v
    }

    /// The outline of a flat body; `None` for the other profiles.
    pub fn flat_outline(&self) -> Option<FlatOutline> {
        match *self {
            Self::Flat {
                width_mm,
                length_mm,
                corner_radius_mm,
                ..
            } => Some(FlatOutline {
                width_mm,
                length_mm,
                corner_radius_mm,
            }),
            _ => None,
        }
    }

    /// Whether the profile is a sphere (offsets are spheres, radii make sense).
    pub fn sphere_radius_mm(&self) -> Option<f64> {
        match *self {
            Self::SphericalCap { .. } => Some(self.cap_sphere().0),
            Self::HemisphereOnCylinder { radius_mm, .. } => Some(radius_mm),
            Self::HalfEllipsoid { .. } | Self::Flat { .. } => None,
        }
    }

    /// (sphere radius, z of the base plane) of a spherical cap, origin at the sphere centre.
    fn cap_sphere(&self) -> (f64, f64) {
        match *self {
            Self::SphericalCap {
                base_diameter_mm,
                height_mm,
            } => {
                let b = base_diameter_mm / 2.0;
                let r = (b * b + height_mm * height_mm) / (2.0 * height_mm);
                (r, r - height_mm)
            }
            _ => unreachable!("cap_sphere on a non-cap profile"),
        }
    }

    /// z of the base plane, mm, in the sensor frame.
    pub fn base_z_mm(&self) -> f64 {
        match *self {
            Self::SphericalCap { .. } => self.cap_sphere().1,
            Self::HemisphereOnCylinder {
                cylinder_length_mm, ..
            } => -cylinder_length_mm,
            Self::HalfEllipsoid { .. } | Self::Flat { .. } => 0.0,
        }
    }

    /// Smallest radius of curvature of the profile curve, mm. An inward offset must stay
    /// below it or the offset curve folds over itself.
    pub fn min_curvature_radius_mm(&self) -> f64 {
        match *self {
            Self::SphericalCap { .. } => self.cap_sphere().0,
            Self::HemisphereOnCylinder { radius_mm, .. } => radius_mm,
            Self::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => {
                let (a, c) = (diameter_mm / 2.0, height_mm);
                (a * a / c).min(c * c / a)
            }
            Self::Flat { .. } => f64::INFINITY,
        }
    }

    /// The offset curve at signed normal distance `d` (negative inward), as a function of a
    /// parameter t in [0, 1] from the pole (r = 0) to the rim on the base plane.
    pub fn offset_point(&self, d: f64, t: f64) -> [f64; 2] {
        match *self {
            Self::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => {
                let (a, c) = (diameter_mm / 2.0, height_mm);
                let th = FRAC_PI_2 * (1.0 - t);
                let (s, co) = th.sin_cos();
                let n = [c * co, a * s];
                let nl = (n[0] * n[0] + n[1] * n[1]).sqrt();
                let r = a * co + d * n[0] / nl;
                [if t == 0.0 { 0.0 } else { r }, c * s + d * n[1] / nl]
            }
            Self::Flat {
                width_mm,
                thickness_mm,
                ..
            } => [t * width_mm / 2.0, thickness_mm + d],
            _ => {
                let (rho, a_end) = self.sphere_arc(d);
                let a = FRAC_PI_2 + (a_end - FRAC_PI_2) * t;
                [if t == 0.0 { 0.0 } else { rho * a.cos() }, rho * a.sin()]
            }
        }
    }

    /// Outward unit normal of the offset curve at distance `d` and parameter t (the point
    /// [`Self::offset_point`] gives).
    pub fn offset_normal(&self, d: f64, t: f64) -> [f64; 2] {
        match *self {
            Self::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => {
                let (a, c) = (diameter_mm / 2.0, height_mm);
                let th = FRAC_PI_2 * (1.0 - t);
                let (s, co) = th.sin_cos();
                let n = [c * co, a * s];
                let nl = (n[0] * n[0] + n[1] * n[1]).sqrt();
                [n[0] / nl, n[1] / nl]
            }
            Self::Flat { .. } => [0.0, 1.0],
            _ => {
                let (_, a_end) = self.sphere_arc(d);
                let a = FRAC_PI_2 + (a_end - FRAC_PI_2) * t;
                [a.cos(), a.sin()]
            }
        }
    }

    /// (radius, end angle from +r axis) of the offset arc of a spherical profile.
    fn sphere_arc(&self, d: f64) -> (f64, f64) {
        match *self {
            Self::HemisphereOnCylinder { radius_mm, .. } => (radius_mm + d, 0.0),
            Self::SphericalCap { .. } => {
                let (r, zb) = self.cap_sphere();
                let rho = r + d;
                (rho, (zb / rho).clamp(-1.0, 1.0).asin())
            }
            Self::HalfEllipsoid { .. } | Self::Flat { .. } => (0.0, FRAC_PI_2),
        }
    }

    /// Pole height (z of the point on the axis) of the offset surface at distance `d`.
    pub fn pole_z_mm(&self, d: f64) -> f64 {
        self.offset_point(d, 0.0)[1]
    }

    /// Radius where the offset surface meets the base plane, mm.
    pub fn rim_radius_mm(&self, d: f64) -> f64 {
        match *self {
            Self::HemisphereOnCylinder { radius_mm, .. } => radius_mm + d,
            Self::SphericalCap { .. } => {
                let (r, zb) = self.cap_sphere();
                ((r + d).powi(2) - zb * zb).max(0.0).sqrt()
            }
            Self::HalfEllipsoid { .. } | Self::Flat { .. } => self.offset_point(d, 1.0)[0],
        }
    }

    /// Whether the offset surface at `d` is a valid surface: it keeps a positive rim radius and
    /// the pole above the base plane, and does not fold (d > -min curvature radius).
    pub fn offset_is_valid(&self, d: f64) -> bool {
        d > -self.min_curvature_radius_mm()
            && self.rim_radius_mm(d) > 0.0
            && self.pole_z_mm(d) > self.base_z_mm()
    }

    /// The offset curve at `d` from the pole to the rim, tessellated within `tol`, followed (for
    /// the hemisphere on cylinder) by the cylinder down to the base plane, then straight down
    /// by `below_base_mm`. Points run from the pole (r = 0) to the bottom of the rim.
    pub fn offset_polyline(&self, d: f64, below_base_mm: f64, tol: ChordTolerance) -> Polyline2 {
        let mut pl = Polyline2::default();
        match *self {
            Self::HalfEllipsoid { .. } => {
                push_curve(&mut pl, &|t| self.offset_point(d, t), 0.0, 1.0, tol);
            }
            Self::Flat { .. } => {
                pl.push(self.offset_point(d, 0.0));
                pl.push(self.offset_point(d, 1.0));
            }
            _ => {
                let (rho, a_end) = self.sphere_arc(d);
                push_arc(&mut pl, [0.0, 0.0], rho, FRAC_PI_2, a_end, tol);
            }
        }
        let zb = self.base_z_mm();
        let rim = self.rim_radius_mm(d);
        if let Some(last) = pl.points.last_mut() {
            // The arc or curve ends on the base plane exactly (or at the equator, z = 0, for the
            // hemisphere on cylinder, which continues down the cylinder).
            if !matches!(self, Self::HemisphereOnCylinder { .. }) {
                *last = [rim, zb];
            }
        }
        pl.push([rim, zb]);
        if below_base_mm > 0.0 {
            pl.push([rim, zb - below_base_mm]);
        }
        pl
    }

    /// The closed profile of the solid bounded by the offset surface at `d` and the plane
    /// `below_base_mm` under the base plane.
    pub fn solid_profile(&self, d: f64, below_base_mm: f64, tol: ChordTolerance) -> Polyline2 {
        let mut pl = self.offset_polyline(d, below_base_mm, tol);
        pl.push([0.0, self.base_z_mm() - below_base_mm]);
        pl
    }

    /// The closed profile of the shell between the offset surfaces at `d_in` < `d_out`,
    /// closed by the plane `below_base_mm` under the base plane.
    pub fn shell_profile(
        &self,
        d_in: f64,
        d_out: f64,
        below_base_mm: f64,
        tol: ChordTolerance,
    ) -> Polyline2 {
        let mut pl = self.offset_polyline(d_out, below_base_mm, tol);
        pl.extend(&self.offset_polyline(d_in, below_base_mm, tol).reversed());
        pl
    }

    /// The inner surface of a shell of `wall_mm` whose outer surface is the offset surface at
    /// `d_out` (a core): `(body, d)`, the surface being `body`'s offset at `d`. On spherical
    /// profiles it is the concentric sphere (`self` at `d_out - wall_mm`). The normal offsets of
    /// a half ellipsoid fold once the wall passes the pole's radius of curvature (UVDtact's
    /// 2 mm acrylic shell under a 9 x 24 mm skin, pole radius 3.375 mm, Sec. III), so its
    /// inner surface is the half ellipsoid whose rim radius and pole height are the outer
    /// surface's less the wall: the wall is `wall_mm` at the pole and at the rim and thinner
    /// between ([`Self::least_wall_mm`]); the shape a machine shop cuts.
    ///
    /// `None` when the wall leaves no bore: the inner rim radius or pole height is not above 0.
    pub fn shell_inner_surface(&self, d_out: f64, wall_mm: f64) -> Option<(BodyProfile, f64)> {
        let rim = self.rim_radius_mm(d_out) - wall_mm;
        let height = self.pole_z_mm(d_out) - wall_mm - self.base_z_mm();
        if !(rim > 0.0 && height > 0.0) {
            return None;
        }
        match self {
            Self::HalfEllipsoid { .. } => Some((
                Self::HalfEllipsoid {
                    diameter_mm: 2.0 * rim,
                    height_mm: height,
                },
                0.0,
            )),
            _ => Some((self.clone(), d_out - wall_mm)),
        }
    }

    /// The closed (r, z) profile of the shell between the offset surface at `d_out` and its
    /// inner surface ([`Self::shell_inner_surface`]), both continued straight down
    /// `below_base_mm` under the base plane and closed there: the outer curve from the pole to
    /// the rim, then the inner one back up to its pole. `None` as for the inner surface.
    pub fn core_shell_profile(
        &self,
        d_out: f64,
        wall_mm: f64,
        below_base_mm: f64,
        tol: ChordTolerance,
    ) -> Option<Polyline2> {
        let (inner, d_in) = self.shell_inner_surface(d_out, wall_mm)?;
        let mut pl = self.offset_polyline(d_out, below_base_mm, tol);
        pl.extend(&inner.offset_polyline(d_in, below_base_mm, tol).reversed());
        Some(pl)
    }

    /// The thinnest wall of the shell of [`Self::core_shell_profile`] above the base plane,
    /// mm, and the polar angle from +z (degrees, seen from the origin) of the inner surface's
    /// point where it is: the distance from the inner surface to the outer one, measured on
    /// 2001 points of the inner surface against the outer one drawn within 1 µm (within about
    /// 1 µm). `None` as for the inner surface.
    pub fn least_wall_mm(&self, d_out: f64, wall_mm: f64) -> Option<(f64, f64)> {
        let (inner, d_in) = self.shell_inner_surface(d_out, wall_mm)?;
        let tol = ChordTolerance::new(ChordTolerance::MIN_MM).ok()?;
        let outer = self.offset_polyline(d_out, 0.0, tol);
        let n = 2000;
        let mut best = (f64::INFINITY, 0.0);
        for i in 0..=n {
            let p = inner.offset_point(d_in, i as f64 / n as f64);
            let d = outer
                .points
                .windows(2)
                .map(|w| point_segment_distance(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min);
            if d < best.0 {
                best = (d, p[0].atan2(p[1]).to_degrees());
            }
        }
        Some(best)
    }

    /// Area of the offset surface at `d` from the pole down to the base plane, mm^2: the
    /// surface of revolution of [`Self::offset_polyline`] at a 1 µm chord tolerance (Pappus;
    /// the inscribed polyline comes out short by about the chord tolerance over the radius of
    /// curvature, under 1e-4 relative for radii of 10 mm and more). The surface a release
    /// agent or a primer covers.
    pub fn surface_area_mm2(&self, d: f64) -> f64 {
        if let Some(o) = self.flat_outline() {
            return o.area_mm2();
        }
        let tol =
            ChordTolerance::new(ChordTolerance::MIN_MM).expect("the minimum tolerance is valid");
        let pl = self.offset_polyline(d, 0.0, tol);
        pl.points
            .windows(2)
            .map(|w| {
                let ([r0, z0], [r1, z1]) = (w[0], w[1]);
                std::f64::consts::PI * (r0 + r1) * (r1 - r0).hypot(z1 - z0)
            })
            .sum()
    }

    /// Enclosed volume of the solid at offset `d` with `below_base_mm`, mm^3, from the exact
    /// curve (closed form for spheres, 2000-point Gauss-Legendre for ellipse offsets).
    pub fn analytic_solid_volume_mm3(&self, d: f64, below_base_mm: f64) -> f64 {
        use std::f64::consts::PI;
        let rim = self.rim_radius_mm(d);
        let ext = PI * rim * rim * below_base_mm;
        match *self {
            Self::Flat { thickness_mm, .. } => {
                let area = self.flat_outline().map_or(0.0, |o| o.area_mm2());
                area * (thickness_mm + d + below_base_mm)
            }
            Self::HemisphereOnCylinder {
                radius_mm,
                cylinder_length_mm,
            } => {
                let r = radius_mm + d;
                2.0 / 3.0 * PI * r.powi(3) + PI * r * r * cylinder_length_mm + ext
            }
            Self::SphericalCap { .. } => {
                let (r, zb) = self.cap_sphere();
                let h = r + d - zb;
                PI * h * h * (3.0 * (r + d) - h) / 3.0 + ext
            }
            Self::HalfEllipsoid { .. } => {
                // V = integral of pi r^2 dz along the curve (z decreasing from pole to rim).
                let n = 2000;
                let mut v = 0.0;
                for i in 0..n {
                    let (t0, t1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                    // 3-point Gauss on each panel
                    let g = [
                        (-0.774_596_669_241_483_4, 5.0 / 9.0),
                        (0.0, 8.0 / 9.0),
                        (0.774_596_669_241_483_4, 5.0 / 9.0),
                    ];
                    for (x, w) in g {
                        let t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * x;
                        let h = 1e-6;
                        let p = self.offset_point(d, t);
                        let pa = self.offset_point(d, (t - h).max(0.0));
                        let pb = self.offset_point(d, (t + h).min(1.0));
                        let dz = (pb[1] - pa[1]) / ((t + h).min(1.0) - (t - h).max(0.0));
                        v += -PI * p[0] * p[0] * dz * w * 0.5 * (t1 - t0);
                    }
                }
                v + ext
            }
        }
    }
}

/// Distance from `p` to the segment `a`-`b` in the plane, mm.
fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = ux * ux + uy * uy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * ux).hypot(p[1] - a[1] - t * uy)
}

/// The outline of a flat skin: a rectangle `width_mm` (x) by `length_mm` (y) with corners
/// rounded to `corner_radius_mm`, centred on the z axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlatOutline {
    /// Across x, mm, > 0.
    pub width_mm: f64,
    /// Along y (the channels' direction), mm, > 0.
    pub length_mm: f64,
    /// Corner radius, mm, in [0, half the shorter side).
    #[serde(default)]
    pub corner_radius_mm: f64,
}

impl FlatOutline {
    /// Exact area, mm^2: w l - (4 - pi) r^2.
    pub fn area_mm2(&self) -> f64 {
        let r = self.corner_radius_mm;
        self.width_mm * self.length_mm - (4.0 - PI) * r * r
    }

    /// The signed distance from (x, y) `p` to the outline, mm: negative inside, 0 on it,
    /// positive outside (exact for the rounded rectangle).
    pub fn signed_distance_mm(&self, p: [f64; 2]) -> f64 {
        let r = self.corner_radius_mm;
        let qx = p[0].abs() - (self.width_mm / 2.0 - r);
        let qy = p[1].abs() - (self.length_mm / 2.0 - r);
        let outside = qx.max(0.0).hypot(qy.max(0.0));
        outside + qx.max(qy).min(0.0) - r
    }

    /// The outline as a convex counter-clockwise polygon, its corner arcs inscribed within
    /// `tol` (vertices on the arcs).
    pub fn polygon(&self, tol: ChordTolerance) -> Vec<[f64; 2]> {
        let (hw, hl, r) = (
            self.width_mm / 2.0,
            self.length_mm / 2.0,
            self.corner_radius_mm,
        );
        if r <= 0.0 {
            return vec![[-hw, -hl], [hw, -hl], [hw, hl], [-hw, hl]];
        }
        let per_quarter = tol.circle_segments(r).div_ceil(4).max(1);
        let mut pts = Vec::with_capacity(4 * (per_quarter + 1));
        // corner centres counter-clockwise from the (+x, -y) corner, each arc's start angle
        for (k, (cx, cy)) in [
            (hw - r, -hl + r),
            (hw - r, hl - r),
            (-hw + r, hl - r),
            (-hw + r, -hl + r),
        ]
        .into_iter()
        .enumerate()
        {
            let a0 = -FRAC_PI_2 + k as f64 * FRAC_PI_2;
            for i in 0..=per_quarter {
                let a = a0 + FRAC_PI_2 * i as f64 / per_quarter as f64;
                let p = [cx + r * a.cos(), cy + r * a.sin()];
                if pts.last() != Some(&p) {
                    pts.push(p);
                }
            }
        }
        pts
    }

    /// The outline offset outwards by `by_mm` (its exact offset: each side `by_mm` further out,
    /// the corner radius `by_mm` larger).
    pub fn grown(&self, by_mm: f64) -> Self {
        Self {
            width_mm: self.width_mm + 2.0 * by_mm,
            length_mm: self.length_mm + 2.0 * by_mm,
            corner_radius_mm: self.corner_radius_mm + by_mm,
        }
    }

    /// Distance from `(x, y)` inside the outline to its edge, mm (negative outside).
    pub fn inset_mm(&self, [x, y]: [f64; 2]) -> f64 {
        let (hw, hl, r) = (
            self.width_mm / 2.0,
            self.length_mm / 2.0,
            self.corner_radius_mm,
        );
        let (dx, dy) = (x.abs() - (hw - r), y.abs() - (hl - r));
        if dx > 0.0 && dy > 0.0 {
            r - dx.hypot(dy)
        } else {
            (hw - x.abs()).min(hl - y.abs())
        }
    }

    /// Every violation under `prefix` (`body.`).
    pub fn errors(&self, prefix: &str) -> Vec<ParamError> {
        let mut errs = Vec::new();
        crate::parts::check_positive(
            prefix,
            &[("width_mm", self.width_mm), ("length_mm", self.length_mm)],
            &mut errs,
        );
        let half = self.width_mm.min(self.length_mm) / 2.0;
        if !(self.corner_radius_mm >= 0.0 && self.corner_radius_mm < half) && errs.is_empty() {
            errs.push(ParamError::new(
                format!("{prefix}corner_radius_mm"),
                self.corner_radius_mm,
                format!("must be 0 or more and below half the shorter side ({half} mm)"),
            ));
        }
        errs
    }
}
