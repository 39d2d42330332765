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

pub mod printers;
pub mod shared;
pub use crate::parts::housing::{
    CameraBay, Diffuser, HousingParams, HousingStyle, JointScrew, LedPcb, RoundTube,
};
pub use printers::{
    shipped_printers, Bed, PrinterFile, PrinterProfile, PrinterProfiles, Technology,
};
pub use shared::{
    Backing, BrushedCoat, Core, CoreMachining, FillingGel, LayerProcess, MoldStrategy,
};

/// Lengths of a design that may be negative ([`crate::values::check_values`]): none.
pub const DESIGN_SIGNED_MM: &[&str] = &[];

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
    pub marker_grid: Option<crate::parts::channels::MarkerGrid>,
}

/// Mold parameters shared by every cast layer. Geometry: R-Tac0 Sec. III-B1 and Fig. 4.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MoldParams {
    pub strategy: MoldStrategy,
    /// Added to the layer's outer surface to form the cavity, mm, >= 0.
    pub cavity_clearance_mm: f64,
    /// Material between the cavity and the outside of a mold half, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// Width of the mold-half flange that carries bolts and keys, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub flange_width_mm: f64,
    /// Draft of the master-strategy mold box wall from the pull direction, degrees, [0, 10).
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 10))]
    pub draft_angle_deg: f64,
    pub plinth: Plinth,
    pub registration_key: RegistrationKey,
    pub clamp_bolt: ClampBolt,
    pub sprue: Sprue,
    pub vent: Vent,
    pub core_holder: CoreHolderParams,
    /// Mold Star thickness around the master pattern (master strategy), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub silicone_wall_mm: f64,
    /// The top piece and the flange of the `two_piece_open` strategy.
    pub two_piece: TwoPieceOpenParams,
    /// Technology of parts whose surface forms the skin (mold halves, master patterns).
    pub cavity_print_technology: Technology,
    /// Technology of holders, jigs and boxes.
    pub fixture_print_technology: Technology,
    /// Flat skins: make each casting tray as a stack of laser-cut sheets (DXF and SVG per
    /// sheet) whose union is also written as the printable tray ([`crate::lasercut`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub laser_cut: Option<LaserCutParams>,
}

/// Laser-cut molds of a flat skin (Soter et al. Sec. II-A: the molds are laser-cut): the sheet
/// stock and the registration holes that align a stack of sheets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct LaserCutParams {
    /// The sheet stock, in the order fabkit picks from: each level of a tray is made of the
    /// first stock whose thickness, taken 1 to 8 times, equals the level's; the base sheet is
    /// the first stock.
    #[schemars(extend("minItems" = 1))]
    pub stock: Vec<SheetStock>,
    /// Dowel holes through every sheet of a stack, one in each corner of the tray's wall.
    pub registration: SheetRegistration,
}
defaults!(LaserCutParams {
    stock: vec![
        SheetStock {
            name: "acrylic_3mm".into(),
            material: "pmma".into(),
            thickness_mm: 3.0,
            kerf_mm: 0.15,
        },
        SheetStock {
            name: "acrylic_2mm".into(),
            material: "pmma".into(),
            thickness_mm: 2.0,
            kerf_mm: 0.12,
        },
        SheetStock {
            name: "acrylic_1_5mm".into(),
            material: "pmma".into(),
            thickness_mm: 1.5,
            kerf_mm: 0.1,
        },
    ],
    registration: SheetRegistration::default(),
});

/// One sheet material profile: what the sheet is and what the laser takes out of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SheetStock {
    /// `[a-z0-9_]+`, for file names and the bill of materials.
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub name: String,
    /// Material key in the materials table (designs/materials.yaml).
    pub material: String,
    /// Thickness of the sheet, mm, above 0 and at most 25 (a laser cutter's sheet). Every
    /// level of a tray is 1 to 8 sheets of the first stock whose thickness makes it; the
    /// tray's base sheet is one sheet of the first stock.
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 25))]
    pub thickness_mm: f64,
    /// Width of the laser's cut in this sheet, mm: every path is offset by half of it.
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 2))]
    pub kerf_mm: f64,
}

/// Registration (dowel) holes through a stack of sheets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SheetRegistration {
    /// Hole diameter, mm (a dowel pin of this diameter, a sliding fit after the kerf).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
}
defaults!(SheetRegistration { diameter_mm: 3.0 });
defaults!(MoldParams {
    strategy: MoldStrategy::Direct,
    cavity_clearance_mm: 0.0,
    wall_thickness_mm: 4.0,
    flange_width_mm: 8.0,
    draft_angle_deg: 2.0,
    plinth: Plinth::default(),
    registration_key: RegistrationKey::default(),
    clamp_bolt: ClampBolt::default(),
    sprue: Sprue::default(),
    vent: Vent::default(),
    core_holder: CoreHolderParams::default(),
    silicone_wall_mm: 5.0,
    two_piece: TwoPieceOpenParams::default(),
    cavity_print_technology: Technology::Sla,
    fixture_print_technology: Technology::Fdm,
    laser_cut: None,
});

/// The disc-shaped recess at the open end of the cavity: it centres the core holder (its
/// spigot plugs into it) and leaves a reservoir ring that feeds the cavity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Plinth {
    /// Radial margin beyond the cavity rim, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub margin_mm: f64,
    /// Depth of the recess, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Depth left free under the holder's spigot as a reservoir, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub reservoir_depth_mm: f64,
}
defaults!(Plinth {
    margin_mm: 5.0,
    height_mm: 3.0,
    reservoir_depth_mm: 1.5
});

/// Hemispherical registration keys on the parting plane: male on one half, female with
/// clearance on the other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RegistrationKey {
    /// Diameter of the keys' spheres, mm, > 0: one key each side of the cavity, in the middle
    /// of the flange and half-way up the mold, on the parting plane of a `direct` mold's two
    /// halves. At least the cavity printer's `min_feature_mm`; with twice `clearance_mm` and
    /// twice the cavity printer's `min_wall_mm` at most `mold.flange_width_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Radial clearance of the female socket, mm.
    pub clearance_mm: f64,
}
defaults!(RegistrationKey {
    diameter_mm: 3.0,
    clearance_mm: 0.15
});

/// Clamp bolts through both mold halves, perpendicular to the parting plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ClampBolt {
    /// Through-hole diameter, mm (3.4 for M3).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
}
defaults!(ClampBolt {
    clearance_diameter_mm: 3.4
});

/// The top piece of a `two_piece_open` mold and how it joins the cavity block. The cavity
/// block's face lies `boss.height_mm` beyond the cavity's rim plane; a pocket in it (the boss
/// plus `registration_key.clearance_mm` on every side) reaches down to the rim plane. The top
/// piece stands `reservoir_height_mm` beyond the rim plane, its boss sits in the pocket, and a
/// bore through it opens the whole cavity: the pour reservoir whose level forms the skin's
/// back. `bolt_count` clamp bolts (`clamp_bolt.clearance_diameter_mm` holes through both
/// pieces) stand on the centre line of the flange (`flange_width_mm` wide) around the pocket,
/// one at each corner and the rest spread evenly over the sides.
/// Defaults: the authors' ShadowTac mold (authors' CAD, measured).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct TwoPieceOpenParams {
    /// Diameter of the reservoir bore, mm (authors: 45).
    pub reservoir_diameter_mm: f64,
    /// Height of the top piece above the cavity's rim plane, mm (authors: 14).
    pub reservoir_height_mm: f64,
    /// Clamp bolts through the flange, even, >= 4 (authors: 20).
    pub bolt_count: u32,
    /// Bolt hole diameter in the cavity block, mm (authors: 3.5); default
    /// `mold.clamp_bolt.clearance_diameter_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cavity_block_bolt_hole_mm: Option<f64>,
    /// Bolt hole diameter in the top piece, mm (authors: 3.4); default
    /// `mold.clamp_bolt.clearance_diameter_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub top_piece_bolt_hole_mm: Option<f64>,
    pub boss: RegistrationBoss,
}
defaults!(TwoPieceOpenParams {
    reservoir_diameter_mm: 45.0,
    reservoir_height_mm: 14.0,
    bolt_count: 20,
    cavity_block_bolt_hole_mm: None,
    top_piece_bolt_hole_mm: None,
    boss: RegistrationBoss::default(),
});

impl TwoPieceOpenParams {
    /// (cavity block, top piece) bolt hole diameters, mm: the per-piece values, else
    /// `clearance_mm` (`mold.clamp_bolt.clearance_diameter_mm`).
    pub fn bolt_holes_mm(&self, clearance_mm: f64) -> (f64, f64) {
        (
            self.cavity_block_bolt_hole_mm.unwrap_or(clearance_mm),
            self.top_piece_bolt_hole_mm.unwrap_or(clearance_mm),
        )
    }
}

/// A rectangular boss on the top piece of a two-piece mold that registers it in a pocket of
/// the cavity block (authors' ShadowTac mold: 60 x 65 x 2 mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RegistrationBoss {
    /// Along x, mm.
    pub width_mm: f64,
    /// Along y, mm.
    pub length_mm: f64,
    /// Along the pull direction (the sensor axis), mm.
    pub height_mm: f64,
}
defaults!(RegistrationBoss {
    width_mm: 60.0,
    length_mm: 65.0,
    height_mm: 2.0
});

/// The pour opening through the core holder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Sprue {
    /// Diameter of the pour hole, mm, > 0: through the core holder parallel to the axis, at
    /// azimuth 0, centred between the core's groove and the spigot's edge. At least the
    /// fixture printer's `min_hole_diameter_mm`, and it must fit that room, which
    /// `mold.plinth.margin_mm` widens.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
}
defaults!(Sprue { diameter_mm: 3.0 });

/// Air vents through the core holder at the cavity's high points (cast pole-down).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Vent {
    /// Diameter of each vent hole, mm, > 0: through the core holder parallel to the axis, on a
    /// circle that leaves `core_holder.min_wall_mm` between the holes and the spigot's edge.
    /// At least the fixture printer's `min_hole_diameter_mm`, and it must fit in the holder
    /// beside the core, as the sprue.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Number of vents, at least 1, spread round the axis with the sprue at equal steps of
    /// 360 / (count + 1) degrees, the sprue at azimuth 0; at most as many as keep
    /// `core_holder.min_wall_mm` between neighbouring holes.
    #[schemars(extend("minimum" = 1))]
    pub count: u32,
}
defaults!(Vent {
    diameter_mm: 1.2,
    count: 2
});

/// The core holder (casting jig): keeps the core concentric with the cavity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CoreHolderParams {
    /// Radial clearance between the centring pin and the core's bore, and around the core
    /// wall, mm.
    pub fit_clearance_mm: f64,
    /// Thickness along the axis of the holder's flange, the disc that lies on the mold's open
    /// face (the outer face of the plinth recess) and reaches 3 mm beyond the plinth, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub flange_thickness_mm: f64,
    /// Length of the centring pin that enters the core's open end, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_length_mm: f64,
    /// Smallest wall left around holes in the holder, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_wall_mm: f64,
}
defaults!(CoreHolderParams {
    fit_clearance_mm: 0.1,
    flange_thickness_mm: 3.0,
    pin_length_mm: 6.0,
    min_wall_mm: 1.5,
});

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
    unit_bounds(&mut v, Unit::Plain);
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

/// Adds the ranges of [`crate::values::check_values`] to every number of the schema `v`
/// under `unit` (a key ending `_mm` or `_deg` sets the unit for everything under it, as there),
/// leaving bounds already given alone, and the unit as description of a key that has none.
fn unit_bounds(v: &mut serde_json::Value, unit: Unit) {
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
            unit_bounds(sub, own.unwrap_or(unit));
        }
    }
    for key in ["items", "additionalProperties"] {
        if let Some(sub) = m.get_mut(key) {
            unit_bounds(sub, unit);
        }
    }
    for key in ["prefixItems", "anyOf", "oneOf", "allOf"] {
        if let Some(Value::Array(subs)) = m.get_mut(key) {
            for sub in subs {
                unit_bounds(sub, unit);
            }
        }
    }
    if let Some(Value::Object(defs)) = m.get_mut("$defs") {
        for sub in defs.values_mut() {
            unit_bounds(sub, Unit::Plain);
        }
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
