//! Part families that any sensor design can use, one module per family (../shared/STYLE.md):
//! each with its parameters, its rules and its solids.

pub mod bayonet;
pub mod casing;
pub mod channels;
pub mod context;
pub mod core_shell;
pub mod cut_part;
pub mod family;
pub mod fasteners;
pub mod fingertip_base;
pub mod flat;
pub mod flat_family;
pub mod flat_housing;
pub mod housing;
pub mod lasercut;
pub mod layer_feature;
pub mod layer_markers;
pub mod layer_registry;
pub mod layers;
pub mod marker_checks;
pub mod marker_grid;
mod member;
pub mod molds;
mod part;
pub mod placement;
pub mod recess;
pub mod registry;
pub mod robot_mount;
pub mod seat;
pub mod shaft_body;
pub mod spacer;
pub mod stack_input;

pub use context::{Context, ResolvedCore, ResolvedLayer, Stack};
pub use member::{
    axial_cylinder, axial_ring, ExactShape, FeatureKey, Member, MemberFeatures, MemberKind,
};
pub use part::{Part, PrintTechnology, ProcedureAction, ProcedureStep};

use crate::error::ParamError;
use crate::geometry::{cylinder, ChordTolerance, GeometryError, Solid};

/// The rule on lengths and sizes: "must be above 0" for each `(path, value)` that is not a
/// positive finite number, the path under `prefix` (`pin_dome.`, `body.` ...); whether any
/// broke it. For parameters without a JSON Schema (the fixtures) or with a hand-written one
/// (the body profile); a design section with a derived schema uses [`check_above_zero`].
pub fn check_positive(prefix: &str, values: &[(&str, f64)], errs: &mut Vec<ParamError>) -> bool {
    let before = errs.len();
    for &(p, v) in values {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(
                format!("{prefix}{p}"),
                v,
                "must be above 0",
            ));
        }
    }
    errs.len() > before
}

/// The rule "must be above 0" for every number of `value` whose JSON Schema bound is only
/// `exclusiveMinimum: 0`, so that the published schema (`fabkit schema`) and the validation
/// cannot disagree: a new field marked `#[schemars(extend("exclusiveMinimum" = 0))]` is checked
/// by that mark alone. A number with a range of its own (`camera.view_angle_deg` in (0, 180)) is
/// left to its own rule and message; so are the top-level keys in `skip` (a nested family that
/// checks itself). Optional fields are checked when given, arrays element by element
/// (`bolt_spacing_mm[1]`).
///
/// Paths are under `prefix` (`casing.`), in the schema's (alphabetical) order. Returns whether
/// any number broke the rule.
pub fn check_above_zero<T: schemars::JsonSchema + serde::Serialize>(
    prefix: &str,
    value: &T,
    skip: &[&str],
    errs: &mut Vec<ParamError>,
) -> bool {
    let schema = schemars::generate::SchemaSettings::draft2020_12()
        .into_generator()
        .into_root_schema_for::<T>()
        .to_value();
    let before = errs.len();
    match serde_value::to_value(value) {
        Ok(v) => AboveZero {
            root: &schema,
            skip,
            errs,
        }
        .walk(&schema, &v, prefix, true),
        // Serialize of a schema type does not fail; say so rather than pass silently.
        Err(e) => errs.push(ParamError::new(
            prefix,
            "?",
            format!("cannot be read as numbers: {e}"),
        )),
    }
    errs.len() > before
}

/// The walk of [`check_above_zero`]: a schema and a serialized value side by side.
struct AboveZero<'a> {
    root: &'a serde_json::Value,
    skip: &'a [&'a str],
    errs: &'a mut Vec<ParamError>,
}

impl AboveZero<'_> {
    fn walk(&mut self, s: &serde_json::Value, v: &serde_value::Value, path: &str, top: bool) {
        use serde_value::Value as V;
        let v = match v {
            V::Option(None) | V::Unit => return,
            V::Option(Some(inner)) | V::Newtype(inner) => return self.walk(s, inner, path, top),
            v => v,
        };
        let s = resolve(self.root, s, v);
        let only_above_zero = s.get("exclusiveMinimum").and_then(|b| b.as_f64()) == Some(0.0)
            && ["minimum", "maximum", "exclusiveMaximum"]
                .iter()
                .all(|k| s.get(k).is_none());
        if only_above_zero {
            if let Some(x) = number(v) {
                if !(x > 0.0 && x.is_finite()) {
                    self.errs.push(ParamError::new(path, x, "must be above 0"));
                }
            }
        }
        let join = |k: &str| {
            if top {
                format!("{path}{k}")
            } else {
                format!("{path}.{k}")
            }
        };
        match v {
            V::Map(m) => {
                let Some(props) = s.get("properties").and_then(|p| p.as_object()) else {
                    return;
                };
                for (k, sub) in props {
                    if top && self.skip.contains(&k.as_str()) {
                        continue;
                    }
                    if let Some(x) = m.get(&V::String(k.clone())) {
                        self.walk(sub, x, &join(k), false);
                    }
                }
            }
            V::Seq(items) => {
                if let Some(sub) = s.get("items").filter(|i| i.is_object()) {
                    for (i, x) in items.iter().enumerate() {
                        self.walk(sub, x, &format!("{path}[{i}]"), false);
                    }
                }
            }
            _ => {}
        }
    }
}

/// The schema `s` stands for where it describes `v`: behind a `$ref` into `root`'s `$defs`,
/// the non-null branch of an `Option`'s `anyOf`, or, of several branches (an enum's variants),
/// the first whose properties hold every key of the mapping `v`.
fn resolve<'s>(
    root: &'s serde_json::Value,
    s: &'s serde_json::Value,
    v: &serde_value::Value,
) -> &'s serde_json::Value {
    if let Some(r) = s.get("$ref").and_then(|r| r.as_str()) {
        let def = r
            .strip_prefix("#/$defs/")
            .and_then(|name| root.get("$defs")?.get(name));
        return def.map_or(s, |d| resolve(root, d, v));
    }
    for key in ["anyOf", "oneOf", "allOf"] {
        let Some(branches) = s.get(key).and_then(|b| b.as_array()) else {
            continue;
        };
        let real: Vec<_> = branches
            .iter()
            .filter(|b| b.get("type").and_then(|t| t.as_str()) != Some("null"))
            .map(|b| resolve(root, b, v))
            .collect();
        let fits = |b: &&serde_json::Value| match (v, b.get("properties")) {
            (serde_value::Value::Map(m), Some(props)) => m.keys().all(|k| match k {
                serde_value::Value::String(k) => props.get(k).is_some(),
                _ => false,
            }),
            _ => false,
        };
        if let [only] = real.as_slice() {
            return only;
        }
        if let Some(b) = real.iter().copied().find(fits) {
            return b;
        }
    }
    s
}

/// A number of a serialized value, as f64.
fn number(v: &serde_value::Value) -> Option<f64> {
    use serde_value::Value as V;
    Some(match *v {
        V::F64(x) => x,
        V::F32(x) => f64::from(x),
        V::I8(x) => f64::from(x),
        V::I16(x) => f64::from(x),
        V::I32(x) => f64::from(x),
        V::I64(x) => x as f64,
        V::U8(x) => f64::from(x),
        V::U16(x) => f64::from(x),
        V::U32(x) => f64::from(x),
        V::U64(x) => x as f64,
        _ => return None,
    })
}

/// Smallest LED package fabkit counts around a ring, mm along the ring: the 0402 package
/// (1.0 x 0.5 mm), the smallest in common use.
pub const MIN_LED_PITCH_MM: f64 = 1.0;

/// The LED count of a ring PCB of `outer_diameter_mm` and `inner_diameter_mm` (positive,
/// checked): at least 1 and at most as many [`MIN_LED_PITCH_MM`] packages as fit around the
/// ring's mid-line.
pub(crate) fn check_led_count(
    path: &str,
    led_count: u32,
    outer_diameter_mm: f64,
    inner_diameter_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let mid_circumference_mm = std::f64::consts::PI * (outer_diameter_mm + inner_diameter_mm) / 2.0;
    let fit = (mid_circumference_mm / MIN_LED_PITCH_MM).floor().max(1.0);
    if led_count == 0 {
        errs.push(ParamError::new(path, 0, "must be 1 or more"));
    } else if f64::from(led_count) > fit {
        errs.push(ParamError::new(
            path,
            led_count,
            format!(
                "at most {fit:.0} LEDs fit around the ring ({mid_circumference_mm:.1} mm at mid-width, {MIN_LED_PITCH_MM} mm per LED, the 0402 package)"
            ),
        ));
    }
}

/// A cylinder of radius `r` about the vertical through `(x, y)`, from `z0` up to `z1`, mm.
pub(crate) fn z_cylinder(
    r: f64,
    z0: f64,
    z1: f64,
    [x, y]: [f64; 2],
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    cylinder(z1 - z0, r, tol).map(|s| s.translate([x, y, z0]))
}
