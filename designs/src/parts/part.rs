//! One printable part of a kit, as every family builds it: its name, role, material, print
//! technology and solid in print orientation ([`crate::kit::Kit`] holds them).

use crate::geometry::Solid;
use serde::{Deserialize, Serialize};

/// How a part is meant to be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PrintTechnology {
    /// Fused deposition modelling (filament).
    #[serde(rename = "FDM")]
    Fdm,
    /// Stereolithography / masked SLA (resin).
    #[serde(rename = "SLA")]
    Sla,
    /// Material jetting of several materials in one print (Stratasys PolyJet: Tango Black+,
    /// Vero White; Pestell et al. Sec. III-A).
    #[serde(rename = "PolyJet")]
    Polyjet,
}

impl std::fmt::Display for PrintTechnology {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Fdm => "FDM",
            Self::Sla => "SLA",
            Self::Polyjet => "PolyJet",
        })
    }
}

/// One printable part of a kit.
#[derive(Debug, Clone)]
pub struct Part {
    /// File stem and 3MF object name, unique in the kit, `[a-z0-9_]+`.
    pub name: String,
    /// What the part is for, e.g. `mold_half`, `core_holder`, `master_pattern`, `mold_box`,
    /// `casting_jig`, `shell_half`.
    pub role: String,
    /// Human description, one line.
    pub description: String,
    /// Material key in the materials table (e.g. `pla_black`, `sla_standard_resin`).
    pub material: String,
    pub print_technology: PrintTechnology,
    /// The solid in print orientation: resting on the build plate z = 0, mm.
    pub solid: Solid,
    /// The resolved parameters the part was built from (for the manifest and twins).
    pub params: serde_json::Value,
    /// Parts of one multi-material print share a group name: they are built in the same
    /// coordinates and the 3MF places them with one translation, so they stay registered
    /// (TacTip skin and pin-tip dots). `None` for a part printed on its own.
    pub group: Option<String>,
}

/// A part printed as a further volume of the outermost layer's object
/// ([`crate::parts::family::Family::printed_with_skin`]): the layer's build gives it the
/// layer's print technology, group and plate pose, so it has none of its own.
#[derive(Debug, Clone)]
pub struct SkinVolume {
    /// As [`Part::name`].
    pub name: String,
    /// As [`Part::role`].
    pub role: String,
    /// As [`Part::description`].
    pub description: String,
    /// As [`Part::material`].
    pub material: String,
    /// The solid in the sensor frame, mm.
    pub solid: Solid,
    /// Its parameters without a pose.
    pub params: serde_json::Value,
}

impl Part {
    /// How many of the part one kit needs, each placed on the print plates: its parameters'
    /// `quantity` (the fixtures' calibration pins: one per hole, plus spares), else 1.
    pub fn copies(&self) -> usize {
        self.params
            .get("quantity")
            .and_then(serde_json::Value::as_u64)
            .map_or(1, |q| q.max(1) as usize)
    }

    /// The mesh that is written and measured: the solid's mesh with every coordinate rounded to
    /// `f32` ([`crate::Mesh::rounded_to_f32`]). The export's files and manifest numbers
    /// (volume, triangles, genus) and the sweep metrics are all computed from this form, so
    /// that they agree with each other and with an independent reader of the STL or 3MF.
    pub fn written_mesh(&self) -> crate::Mesh {
        self.solid.mesh().rounded_to_f32()
    }
}

/// What a step of the procedure does; the steps of a kit come in a fixed order per pour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProcedureAction {
    /// Print and check the parts.
    Print,
    /// Seat a master pattern in its mold box (or a negative mold level) for a Mold Star pour.
    SeatMaster,
    /// Pour Mold Star 30 around a master, up to the fill height.
    FillMoldStar,
    /// Take a cured silicone mold off its master or out of its negative.
    DemoldSiliconeMold,
    /// Wipe primer onto the core.
    PrimeCore,
    /// Mount the core on its holder or jig.
    MountCore,
    /// Move the core with the layers cast so far to the next layer's mold.
    MoveCore,
    /// Spray release agent into the mold.
    SprayRelease,
    /// Spray a coat into the mold before the pour.
    SprayCoat,
    /// Close the mold: halves or pieces together, clamp bolts in.
    CloseMold,
    /// Mix, degas and pour, mold pole-down, through the sprue.
    Pour,
    /// Cure and take the cast layer out of the mold.
    Demold,
    /// Brush a coat onto the demolded layer.
    BrushCoat,
    /// Assemble the sensor.
    Assemble,
}

/// One step of the fabrication procedure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProcedureStep {
    pub action: ProcedureAction,
    /// The instruction, with the parts by name and the numbers it needs.
    pub text: String,
}

impl ProcedureStep {
    /// The step `action` with its instruction `text`.
    pub fn new(action: ProcedureAction, text: String) -> Self {
        ProcedureStep { action, text }
    }
}
