//! The YAML design schema. Field names are the YAML keys; every length is mm, every angle
//! degrees. Unknown keys are errors.

use crate::error::DesignError;
use crate::profile::BodyProfile;
use crate::values::{unit_of, Unit};
use crate::yaml::{preset_value_location, written_scalar};
pub use crate::yaml::{
    refuse_quoted_numbers, yaml_error, yaml_error_in, yaml_from_str, yaml_location, yaml_options,
    yaml_scalar_path_at,
};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub mod mold;
pub mod optics;
pub mod printers;
pub mod shared;
pub use crate::parts::housing::{
    CameraBay, Diffuser, HousingParams, HousingStyle, JointScrew, LedPcb, RoundTube,
};
pub use crate::parts::lasercut::{LaserCutParams, SheetRegistration, SheetStock};
pub use mold::{
    ClampBolt, CoreHolderParams, MoldParams, OpenBlock, Plinth, RegistrationBoss, RegistrationKey,
    Sprue, TwoPieceOpenParams, Vent,
};
pub use printers::{
    shipped_printers, Bed, PrinterFile, PrinterProfile, PrinterProfiles, Technology,
};
pub use shared::{
    Backing, BrushedCoat, Core, CoreMachining, FillingGel, GelFill, LayerProcess, MoldStrategy,
};

/// Lengths of a design that may be negative ([`crate::values::check_values`]): the lights'
/// positions in the sensor frame (`optics.lights[i].position_mm`) and the centres of a
/// laser-cut plate's holes (`mold.laser_cut.plate.holes.xy_mm`).
pub const DESIGN_SIGNED_MM: &[&str] = &["position_mm", "xy_mm", "y_mm", "ramp_y_mm"];

/// A sensor design: body profile, rigid core, layer stack, molds, housing, printers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Design {
    /// Short name, `[a-z0-9_]+`; names the output folder and the 3MF.
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub name: String,
    /// One line saying what the design is, for people (`fabkit designs` lists it beside the
    /// name of each library design); empty when not given.
    #[serde(default)]
    pub description: String,
    /// The paper the design reproduces.
    #[serde(default)]
    pub source: String,
    /// The outer surface of the skin (the reference surface).
    pub body: BodyProfile,
    /// The rigid transparent shell the skin is cast onto or bonded to (none for a solid or
    /// printed skin).
    #[serde(default)]
    pub core: Option<Core>,
    /// A flat backing plate the skin is glued to (ShadowTac: PMMA disc, Sec. IV-A); bought.
    #[serde(default)]
    pub backing: Option<Backing>,
    /// Skin layers from inner to outer.
    pub layers: Vec<Layer>,
    #[serde(default)]
    pub mold: MoldParams,
    #[serde(default)]
    pub housing: Option<HousingParams>,
    /// The tip's fitting and the shaft body it locks onto by a bayonet (the dual-modal
    /// TacTip, Pestell et al. Sec. III-A, Fig. 1); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shaft_body: Option<crate::parts::shaft_body::ShaftBodyParams>,
    /// The casing that holds the camera, the LEDs and the skin's backing plate, and the base
    /// that mounts it on a gripper (ShadowTac Sec. IV-B, Fig. 5); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub casing: Option<crate::parts::casing::CasingParams>,
    /// The shell holder, sensor base, camera holder and diffusion ring of a fingertip whose
    /// skin is cast onto a rigid shell (UVDtact Sec. III-C, Fig. 2); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fingertip_base: Option<crate::parts::fingertip_base::FingertipBase>,
    /// A printed spacer ring under the skin's base that raises the contact module by its
    /// height; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spacer: Option<crate::parts::spacer::SpacerParams>,
    /// The shell, base, isolation ring and window of a flat sensor (9DTact, Lin et al. RA-L
    /// 2024); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flat_housing: Option<crate::parts::flat_housing::FlatHousingParams>,
    /// How the inside is lit and imaged, for rendering what the camera sees; the families'
    /// lights and default reflectance and camera response when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optics: Option<optics::OpticsParams>,
    #[serde(default)]
    pub printers: PrinterProfiles,
    #[serde(default)]
    pub casting: CastingParams,
    /// Named variants: each maps parameter paths (`layers[0].markers[0].pattern.rings`) to the
    /// values that replace them (`fabkit export DESIGN --preset NAME`).
    #[serde(default)]
    pub presets:
        std::collections::BTreeMap<String, std::collections::BTreeMap<String, serde_json::Value>>,
}

/// One skin layer. Give exactly one of `thickness_mm` and `outer_radius_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// `[a-z0-9_]+`, unique.
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub name: String,
    /// Key in the materials table.
    pub material: String,
    pub process: LayerProcess,
    /// Thickness along the surface normal, mm.
    #[serde(default)]
    pub thickness_mm: Option<f64>,
    /// Radius of the layer's outer surface, mm (spherical profiles only).
    #[serde(default)]
    pub outer_radius_mm: Option<f64>,
    /// Overrides `mold.strategy` for this layer.
    #[serde(default)]
    pub mold_strategy: Option<MoldStrategy>,
    /// The layer fills the body down to the base plane (no inner surface; innermost layer of
    /// a design without core). Give neither thickness_mm nor outer_radius_mm.
    #[serde(default)]
    pub solid: bool,
    /// The seat of an optic under a solid layer, open on the base plane (DIGIT Pinki's gel);
    /// none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recess: Option<crate::parts::recess::Recess>,
    /// Marker features on this layer's surfaces.
    #[serde(default)]
    pub markers: Vec<crate::markers::MarkerSpec>,
    /// Technology of a printed layer (default polyjet).
    #[serde(default)]
    pub print_technology: Option<Technology>,
    /// A coat brushed onto the layer once it is out of its mold; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub brushed_coat: Option<BrushedCoat>,
    /// Liquid channels in the layer (flat skins only; Soter et al. Sec. II-A).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channels: Option<crate::parts::channels::ChannelSet>,
    /// A grid of markers on the layer's bottom face (flat skins only; Soter et al. Sec. II-A).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub marker_grid: Option<crate::parts::marker_grid::MarkerGrid>,
    /// The layer wraps the layers under it (flat skins only; 9DTact's black gel over its
    /// translucent gel): it covers their top and their sides down to the base plane, its
    /// outline theirs grown by this much, mm, above 0. It is cast over them once they have
    /// cured, in a pocket of its own outline as deep as the stack to its top. Every layer from
    /// the second up wraps when one does; not on the innermost layer, nor with channels or a
    /// marker grid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrap_mm: Option<f64>,
}

/// Pour calculator settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CastingParams {
    /// Extra material mixed for losses in cups, sprue and vents, fraction in [0, 1].
    #[schemars(extend("minimum" = 0, "maximum" = 1))]
    pub waste_allowance: f64,
    /// Release agent sprayed into each mold before a skin layer is poured: a `release` key of
    /// the materials table; `null` for none. Default `ease_release_200` (R-Tac0 Sec. III-B1,
    /// ShadowTac Sec. III).
    pub mold_release: Option<String>,
}
defaults!(CastingParams {
    waste_allowance: 0.2,
    mold_release: Some("ease_release_200".into())
});

/// `$id` of the design file's JSON Schema ([`design_json_schema`]).
pub const DESIGN_SCHEMA_ID: &str = "urn:fabkit:design";

/// Title of the design file's JSON Schema.
pub const DESIGN_SCHEMA_TITLE: &str = "fabkit design";

/// The JSON Schema (draft 2020-12) of a design file, generated from [`Design`] and the types it
/// holds: every key with its type and its doc comment as description, unknown keys refused
/// (`additionalProperties: false`), optional keys not required, defaults given.
///
/// Bounds: the range every number gets from its unit by [`crate::values::check_values`]
/// (`_mm`: 0 to [`crate::values::MAX_LENGTH_MM`] mm; `_deg`: +-[`crate::values::MAX_ANGLE_DEG`]
/// degrees; any other number +-[`crate::values::MAX_PLAIN`]), and the bounds the validation
/// checks on single keys (above 0, `[a-z0-9_]+` names). Rules between keys (a marker spacing
/// above the feature diameter, a layer stack the core can hold) are left to
/// [`crate::build::validate_design`]. The output is deterministic.
pub fn design_json_schema() -> serde_json::Value {
    let generator = schemars::generate::SchemaSettings::draft2020_12().into_generator();
    let mut v = generator.into_root_schema_for::<Design>().to_value();
    unit_bounds(&mut v, Unit::Plain, false);
    plain_descriptions(&mut v);
    if let serde_json::Value::Object(m) = &mut v {
        m.insert("$id".into(), DESIGN_SCHEMA_ID.into());
        m.insert("title".into(), DESIGN_SCHEMA_TITLE.into());
    }
    v
}

/// [`design_json_schema`] as pretty-printed JSON with a final newline: the bytes of
/// `designs/design.schema.json` and of `fabkit schema`.
pub fn design_json_schema_text() -> String {
    let mut s = serde_json::to_string_pretty(&design_json_schema())
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
    s.push('\n');
    s
}

/// Every `description` of the schema `v` through [`plain_text`], leaving values a design may
/// hold (`default`, `examples`, `const`, `enum`) as they are; a key named like one of those
/// (under `properties`) is a schema like any other.
fn plain_descriptions(v: &mut serde_json::Value) {
    use serde_json::Value;
    match v {
        Value::Object(m) => {
            for (k, sub) in m.iter_mut() {
                match (k.as_str(), &mut *sub) {
                    ("description", Value::String(d)) => *d = plain_text(d),
                    ("default" | "examples" | "const" | "enum", _) => {}
                    ("properties" | "patternProperties" | "$defs", Value::Object(named)) => {
                        named.values_mut().for_each(plain_descriptions);
                    }
                    _ => plain_descriptions(sub),
                }
            }
        }
        Value::Array(a) => a.iter_mut().for_each(plain_descriptions),
        _ => {}
    }
}

/// A doc comment as plain text for a JSON Schema description, which editors show as it is:
/// rustdoc's links lose their brackets and Rust paths their modules.
///
/// - `` [`Foo`] `` and `` [`Foo::bar`] `` keep the code span (`` `Foo` ``, `` `Foo::bar` ``),
///   without a disambiguator (`fn@`) and without the modules before the first type
///   (`` [`crate::values::check_values`] `` is `` `check_values` ``);
/// - `[text](https://...)` is `text (https://...)`;
/// - `` [`x`](crate::y) `` and `` [`x`][crate::y] `` (a link to a Rust item) are `` `x` ``.
///
/// Other brackets (`[0, 10)`, `[a-z0-9_]+`) are left alone.
///
/// ```
/// use fabkit_designs::schema::plain_text;
/// assert_eq!(plain_text("see [`crate::lasercut::SheetStock`]"), "see `SheetStock`");
/// assert_eq!(plain_text("[R-Tac](https://example.org/r)"), "R-Tac (https://example.org/r)");
/// assert_eq!(plain_text("[`fills`](FillingGel::fills), in [0, 10)"), "`fills`, in [0, 10)");
/// ```
pub fn plain_text(doc: &str) -> String {
    let mut out = String::with_capacity(doc.len());
    let mut rest = doc;
    while let Some(i) = rest.find('[') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        match doc_link(after) {
            Some((text, used)) => {
                out.push_str(&text);
                rest = &after[used..];
            }
            None => {
                out.push('[');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The plain text of the rustdoc link that starts just after a `[` in `s`, and the bytes of `s`
/// it takes; `None` when the bracket opens no link.
fn doc_link(s: &str) -> Option<(String, usize)> {
    let close = s.find(']')?;
    let inner = &s[..close];
    // an interval (`[0, 10)`) or a character class is no link text
    if inner.is_empty()
        || inner.contains('[')
        || inner.matches('(').count() != inner.matches(')').count()
    {
        return None;
    }
    let after = &s[close + 1..];
    // `[text](target)` and `[text][target]`: the target is a URL or a Rust path
    for (open, shut) in [('(', ')'), ('[', ']')] {
        let Some(t) = after.strip_prefix(open) else {
            continue;
        };
        let Some(end) = t.find(shut) else { continue };
        let target = &t[..end];
        if target.is_empty() || target.contains(char::is_whitespace) {
            continue;
        }
        let inner = code_path(inner).map_or_else(|| inner.to_string(), |c| format!("`{c}`"));
        let text = if target.contains("://") {
            format!("{inner} ({target})")
        } else {
            inner
        };
        return Some((text, close + 1 + 1 + end + 1));
    }
    // `[`path`]`: an intra-doc link
    Some((format!("`{}`", code_path(inner)?), close + 1))
}

/// The path of a code span that holds one (`` `crate::a::B` `` gives `B`, see [`short_path`]).
fn code_path(span: &str) -> Option<&str> {
    let code = span.strip_prefix('`')?.strip_suffix('`')?;
    if code.is_empty() || code.contains(['`', ' ', '\n', '\t']) {
        return None;
    }
    Some(short_path(code))
}

/// A Rust path without its disambiguator (`fn@`, `struct@`) and without the modules before its
/// first type (`crate::profile::BodyProfile::outer` is `BodyProfile::outer`), or its last
/// segment when it names no type (`crate::values::check_values` is `check_values`).
fn short_path(path: &str) -> &str {
    let path = path.split_once('@').map_or(path, |(_, p)| p);
    let mut start = 0;
    for seg in path.split("::") {
        if seg.starts_with(|c: char| c.is_ascii_uppercase()) {
            return &path[start..];
        }
        start += seg.len() + 2;
    }
    path.rsplit("::").next().unwrap_or(path)
}

/// Adds the ranges of [`crate::values::check_values`] to every number of the schema `v`
/// under `unit` (a key ending `_mm` or `_deg` sets the unit for everything under it, as there),
/// leaving bounds already given alone, and the unit as description of a key that has none.
/// `signed`: under a length of [`DESIGN_SIGNED_MM`], which may be negative.
fn unit_bounds(v: &mut serde_json::Value, unit: Unit, signed: bool) {
    use crate::values::{MAX_ANGLE_DEG, MAX_LENGTH_MM, MAX_PLAIN};
    use serde_json::Value;
    let Value::Object(m) = v else { return };
    let is_number = match m.get("type") {
        Some(Value::String(t)) => t == "number",
        Some(Value::Array(ts)) => ts.iter().any(|t| t == "number"),
        _ => false,
    };
    if is_number {
        let (lo, hi) = match unit {
            Unit::Mm if signed => (-MAX_LENGTH_MM, MAX_LENGTH_MM),
            Unit::Mm => (0.0, MAX_LENGTH_MM),
            Unit::Deg => (-MAX_ANGLE_DEG, MAX_ANGLE_DEG),
            Unit::Plain => (-MAX_PLAIN, MAX_PLAIN),
        };
        if !m.contains_key("minimum") && !m.contains_key("exclusiveMinimum") {
            m.insert("minimum".into(), lo.into());
        }
        if !m.contains_key("maximum") && !m.contains_key("exclusiveMaximum") {
            m.insert("maximum".into(), hi.into());
        }
    }
    if let Some(Value::Object(props)) = m.get_mut("properties") {
        for (key, sub) in props.iter_mut() {
            let own = unit_of(key);
            if let (Value::Object(sm), Some(u)) = (&mut *sub, own) {
                let said = if u == Unit::Mm {
                    "Length, mm."
                } else {
                    "Angle, degrees."
                };
                sm.entry("description").or_insert_with(|| said.into());
            }
            let signed = match own {
                Some(_) => DESIGN_SIGNED_MM.contains(&key.as_str()),
                None => signed,
            };
            unit_bounds(sub, own.unwrap_or(unit), signed);
        }
    }
    for key in ["items", "additionalProperties"] {
        if let Some(sub) = m.get_mut(key) {
            unit_bounds(sub, unit, signed);
        }
    }
    for key in ["prefixItems", "anyOf", "oneOf", "allOf"] {
        if let Some(Value::Array(subs)) = m.get_mut(key) {
            for sub in subs {
                unit_bounds(sub, unit, signed);
            }
        }
    }
    if let Some(Value::Object(defs)) = m.get_mut("$defs") {
        for sub in defs.values_mut() {
            unit_bounds(sub, Unit::Plain, false);
        }
    }
}

impl Layer {
    /// The layer's mold strategy: its own `mold_strategy`, else the design's `mold.strategy`
    /// (`default`): the one place that rule is written. A printed layer is cast in none.
    pub fn strategy_or(&self, default: MoldStrategy) -> MoldStrategy {
        self.mold_strategy.unwrap_or(default)
    }
}

impl Design {
    /// What a family sees of this design beyond its own parameters
    /// ([`crate::parts::Context`]).
    pub fn context(&self) -> crate::parts::context::Context<'_> {
        crate::parts::context::Context {
            name: &self.name,
            body: &self.body,
            printers: &self.printers,
            backing: self.backing.as_ref(),
            core: self.core.as_ref(),
        }
    }
}

impl Design {
    /// Parses a design from YAML text. `origin` names the file in error messages.
    ///
    /// # Errors
    /// [`DesignError::Yaml`] with `origin:line:column` for syntax errors, unknown keys,
    /// wrong types, missing fields, a number or boolean where text is expected and unknown tags
    /// ([`yaml_options`]); naming the parameter path of a number written quoted, and of a value
    /// of the wrong type (`... (at core.wall_thickness_mm)`).
    pub fn from_yaml(text: &str, origin: &str) -> Result<Design, DesignError> {
        let d = yaml_from_str::<Design>(text)
            .map_err(|e| DesignError::Yaml(yaml_error_in(origin, text, &e)))?;
        refuse_quoted_numbers(&d, text, origin)?;
        Ok(d)
    }
}

impl Design {
    /// The design with preset `name` applied: each path of the preset is set to its value and
    /// the result is checked against the schema again; the design is renamed `<name>_<preset>`.
    ///
    /// # Errors
    /// [`DesignError::Yaml`] naming `presets.<name>` and the path when the preset is unknown,
    /// a path does not exist or a value has the wrong type.
    pub fn with_preset(&self, preset: &str) -> Result<Design, DesignError> {
        self.with_preset_from(preset, None)
    }

    /// [`Self::with_preset`], with the design's YAML `text` and its `origin` (the file name)
    /// so that an error names the `file:line:column` of the preset's value.
    ///
    /// # Errors
    /// As [`Self::with_preset`]; a value of the wrong type or range is reported as
    /// `file:line:column: presets.<name>: <path> = <value>: <rule>`, like the same value
    /// written directly.
    pub fn with_preset_in(
        &self,
        preset: &str,
        text: &str,
        origin: &str,
    ) -> Result<Design, DesignError> {
        self.with_preset_from(preset, Some((text, origin)))
    }

    fn with_preset_from(
        &self,
        preset: &str,
        source: Option<(&str, &str)>,
    ) -> Result<Design, DesignError> {
        let overrides = self.presets.get(preset).ok_or_else(|| {
            DesignError::Yaml(format!(
                "no preset '{preset}' in design '{}'; its presets: {}",
                self.name,
                if self.presets.is_empty() {
                    "none".to_string()
                } else {
                    self.presets.keys().cloned().collect::<Vec<_>>().join(", ")
                }
            ))
        })?;
        let mut v = serde_json::to_value(self).map_err(|e| DesignError::Yaml(e.to_string()))?;
        for (path, value) in overrides {
            let slot = value_at(&mut v, path).ok_or_else(|| {
                DesignError::Yaml(format!(
                    "presets.{preset}: '{path}' is not a parameter path of design '{}'",
                    self.name
                ))
            })?;
            *slot = value.clone();
        }
        let mut d: Design = serde_json::from_value(v).map_err(|e| {
            DesignError::Yaml(
                self.preset_value_errors(preset, source)
                    .unwrap_or_else(|| format!("presets.{preset}: {e}")),
            )
        })?;
        d.name = format!("{}_{preset}", self.name);
        Ok(d)
    }

    /// Each value of preset `preset` that the schema refuses on its own, as
    /// `[file:line:column: ]presets.<name>: <path> = <value>: <rule>`, one per line; `None`
    /// when each value alone fits (only their combination does not).
    fn preset_value_errors(&self, preset: &str, source: Option<(&str, &str)>) -> Option<String> {
        let base = serde_json::to_value(self).ok()?;
        let mut lines = Vec::new();
        for (path, value) in self.presets.get(preset)? {
            let mut v = base.clone();
            let Some(slot) = value_at(&mut v, path) else {
                continue;
            };
            *slot = value.clone();
            let Err(e) = serde_json::from_value::<Design>(v) else {
                continue;
            };
            let located = source.and_then(|(text, origin)| {
                let (l, c) = preset_value_location(text, preset, path)?;
                Some((format!("{origin}:{l}:{c}: "), written_scalar(text, l, c)))
            });
            let (at, written) = located.unwrap_or_default();
            // the value as written where it is found (2^64 reads back as a float)
            let shown =
                written.unwrap_or_else(|| crate::error::compact_numbers(&value.to_string()));
            lines.push(format!("{at}presets.{preset}: {path} = {shown}: {e}"));
        }
        (!lines.is_empty()).then(|| lines.join("\n"))
    }
}

impl Design {
    /// Reads the marker point lists named by `csv_file` (relative to `base_dir`, the design
    /// file's folder) into `points`. A CSV row is `polar_deg, azimuth_deg`; a first line that is
    /// not numeric is a header; `#` starts a comment. Each file must be a regular file inside
    /// `base_dir` or a folder `rules` allows, of at most `rules.max_bytes`
    /// ([`crate::input_files`]).
    ///
    /// Returns the text of every file read, in order, so that provenance hashes can cover them.
    ///
    /// # Errors
    /// [`DesignError::Params`] naming `layers[i].markers[j].pattern.csv_file`, its value and the
    /// rule for a file that is refused or cannot be read; [`DesignError::Yaml`] naming
    /// `file:line` for a malformed row.
    pub fn load_marker_files(
        &mut self,
        base_dir: &std::path::Path,
        rules: &crate::input_files::DataFileRules,
    ) -> Result<Vec<String>, DesignError> {
        let mut read = Vec::new();
        for (i, l) in self.layers.iter_mut().enumerate() {
            for (j, m) in l.markers.iter_mut().enumerate() {
                let Some(file) = m.pattern.csv_file.clone() else {
                    continue;
                };
                if m.pattern.points.is_some() {
                    return Err(DesignError::Yaml(format!(
                        "layers[{i}].markers[{j}].pattern: give points or csv_file, not both"
                    )));
                }
                let param = format!("layers[{i}].markers[{j}].pattern.csv_file");
                let text = crate::input_files::read_data_file(base_dir, &param, &file, rules)?;
                let path = base_dir.join(&file);
                m.pattern.points = Some(parse_angle_csv(&text, &path.display().to_string())?);
                read.push(text);
            }
        }
        Ok(read)
    }
}

/// Parses `polar_deg, azimuth_deg` rows. A first line that is not numeric is a header, `#`
/// starts a comment, and a UTF-8 byte order mark (spreadsheet "CSV UTF-8") is skipped.
///
/// # Errors
/// [`DesignError::Yaml`] with `origin:line` and the rule for every malformed row (the first
/// [`MAX_REPORTED_ROWS`] listed, then how many more).
pub fn parse_angle_csv(text: &str, origin: &str) -> Result<Vec<[f64; 2]>, DesignError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out = Vec::new();
    let mut bad = Vec::new();
    let mut seen_row = false;
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let nums: Vec<Option<f64>> = cols.iter().map(|c| c.parse::<f64>().ok()).collect();
        match nums.as_slice() {
            [Some(p), Some(a)] => out.push([*p, *a]),
            _ if !seen_row && nums.iter().all(Option::is_none) => {} // header
            _ => {
                // At most 40 characters of the row: enough to see the mistake.
                let shown: String = line.chars().take(40).collect();
                let more = if shown.len() < line.len() { "..." } else { "" };
                bad.push(format!(
                    "{origin}:{}: expected two numbers `polar_deg, azimuth_deg`, found `{shown}{more}`",
                    n + 1
                ));
            }
        }
        seen_row = true;
    }
    if bad.is_empty() {
        return Ok(out);
    }
    let n_bad = bad.len();
    bad.truncate(MAX_REPORTED_ROWS);
    if n_bad > MAX_REPORTED_ROWS {
        bad.push(format!(
            "{origin}: and {} more malformed rows",
            n_bad - MAX_REPORTED_ROWS
        ));
    }
    Err(DesignError::Yaml(bad.join("\n")))
}

/// Malformed rows of a table listed in one error; the rest are counted.
pub const MAX_REPORTED_ROWS: usize = 20;

/// The value at a parameter path like `layers[0].markers[0].pattern.rings` (also
/// `layers.0.markers.0...`). A missing last key of an existing object is created (an optional
/// field that was not written out).
pub fn value_at<'a>(v: &'a mut serde_json::Value, path: &str) -> Option<&'a mut serde_json::Value> {
    let mut keys: Vec<String> = Vec::new();
    for part in path.split('.') {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            keys.push(rest[..i].to_string());
            rest = &rest[i..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let j = stripped.find(']')?;
                keys.push(stripped[..j].to_string());
                rest = &stripped[j + 1..];
            }
            if !rest.is_empty() {
                return None;
            }
        } else {
            keys.push(rest.to_string());
        }
    }
    let n = keys.len();
    let mut cur = v;
    for (k, key) in keys.iter().enumerate() {
        cur = match cur {
            serde_json::Value::Array(a) => a.get_mut(key.parse::<usize>().ok()?)?,
            serde_json::Value::Object(o) => {
                if k + 1 == n && !o.contains_key(key) {
                    o.insert(key.clone(), serde_json::Value::Null);
                }
                o.get_mut(key)?
            }
            _ => return None,
        };
    }
    Some(cur)
}
