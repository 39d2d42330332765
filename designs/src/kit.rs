//! The output of a design build: printable parts and the numbers needed to cast.

pub use crate::parts::{Part, PrintTechnology};
use serde::{Deserialize, Serialize};

/// Casting numbers for one pour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CastReport {
    /// Order in which the pours are made, from 1.
    pub step: u32,
    /// What is cast: a layer name (`transparent_gel`) or `silicone_mold:<layer>` for a
    /// Mold Star mold made from a master pattern.
    pub cast: String,
    /// Material key in the materials table.
    pub material: String,
    /// The material's product name (the table's `name`), for the fabrication sheet.
    pub material_name: String,
    /// Names of the parts that hold this pour.
    pub mold_parts: Vec<String>,
    /// Volume to fill, mL (= cm^3): the cavity with its reservoir and sprue (the pour).
    pub cavity_volume_ml: f64,
    /// Volume of the cast layer itself, mL: the solid between its inner and outer surfaces
    /// down to the base plane, from the exact profile (marker features not counted); `None`
    /// for a silicone mold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer_volume_ml: Option<f64>,
    /// Fraction added for losses in cups, sprue and vents (0.2 = 20 %).
    pub waste_allowance: f64,
    /// Mix ratio as written on the datasheet, e.g. `10:1 by weight`.
    pub mix_ratio: String,
    /// Mass of each component to weigh out, g, in datasheet order (Part A, Part B, ...).
    pub components: Vec<CastComponent>,
    /// Total mass to mix, g.
    pub total_mass_g: f64,
    /// Pot life, cure time and handling notes from the materials table.
    pub notes: String,
    /// The smallest batch that can be weighed by hand when a component of `components` is
    /// below [`MIN_WEIGHABLE_G`]: every component scaled up until the smallest is that much;
    /// `None` when the pour's own amounts can be weighed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_batch: Option<MinBatch>,
    /// Coats sprayed into the mold before this pour (R-Tac0's black coating), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coats: Vec<CoatReport>,
    /// Primer and release agent applied before this pour, in order (the core primed before
    /// the first layer cast on it, the mold's surfaces released).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub treatments: Vec<TreatmentReport>,
}

/// A primer or release agent applied to a surface before a pour, with its amount.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TreatmentReport {
    /// Material key in the materials table (kind `primer` or `release`), and its product name.
    pub material: String,
    pub material_name: String,
    /// `primer` or `release`.
    pub kind: crate::materials::MaterialKind,
    /// What is treated, e.g. `the core's outer surface`, `the cavity of transparent_gel`.
    pub surface: String,
    /// Area treated, cm^2 (the exact profile's surface, features not counted).
    pub area_cm2: f64,
    /// Amount used, mL: `area_cm2` x the material's `applied_ml_per_cm2`.
    pub amount_ml: f64,
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

/// A layer sprayed or brushed into a mold before a pour: its mix and amount.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoatReport {
    /// The sprayed layer's name.
    pub layer: String,
    /// Material key in the materials table, and its product name.
    pub material: String,
    pub material_name: String,
    pub thickness_mm: f64,
    /// Volume of the coat itself, mL (the layer's own volume from the exact profile).
    pub coat_volume_ml: f64,
    /// Mix ratio as on the datasheet or in the paper, e.g. `100:3:500 by weight`.
    pub mix_ratio: String,
    /// Components that evaporate (a thinner).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evaporates: Vec<String>,
    /// The mix that leaves the coat's mass once the thinner is gone, g, per component (no
    /// spray loss included).
    pub components: Vec<CastComponent>,
    pub total_mass_g: f64,
    /// The smallest batch weighable by hand, when a component is below [`MIN_WEIGHABLE_G`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_batch: Option<MinBatch>,
}

/// Least mass of one component that a kitchen scale weighs to about 10 % (0.1 g resolution), g.
pub const MIN_WEIGHABLE_G: f64 = 1.0;

/// A batch larger than the pour needs, so that every component can be weighed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MinBatch {
    /// Each component, in datasheet order; the smallest is [`MIN_WEIGHABLE_G`].
    pub components: Vec<CastComponent>,
    /// Total mass to mix, g.
    pub total_mass_g: f64,
    /// What is left over after the pour (waste allowance included), g.
    pub leftover_g: f64,
}

/// One component of a mix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CastComponent {
    pub name: String,
    pub mass_g: f64,
    /// Volume to measure out, mL, for a mix by volume (Mold Star 30 is mixed 1A:1B by volume);
    /// `None` for a mix by weight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume_ml: Option<f64>,
}

/// Everything one design build produces.
#[derive(Debug, Clone)]
pub struct Kit {
    /// Design name, e.g. `rtac0`.
    pub design: String,
    pub parts: Vec<Part>,
    /// Pours, in casting order.
    pub casts: Vec<CastReport>,
    /// Parts that are bought or cut rather than printed (tube, PCB, diffuser, screws), one
    /// line each, for the fabrication sheet.
    pub bought_items: Vec<String>,
    /// The fabrication procedure, in order ([`crate::procedure::procedure`]).
    pub procedure: Vec<ProcedureStep>,
    /// The assembled sensor: every printed, cast and bought part in the sensor frame
    /// ([`crate::assembly::members`]), fit-checked; empty for a kit that is not a sensor
    /// (fixtures).
    pub assembly: Vec<crate::assembly::Member>,
    /// Parts cut from sheet stock, as outlines for DXF and SVG ([`crate::cut::cut_parts`]).
    pub cut_parts: Vec<crate::cut::CutPart>,
    /// Printed circuit boards' outlines, for PCB tools as DXF ([`crate::cut::pcb_outlines`]):
    /// the board's edge and holes on `cut`, its components' places on `engrave`.
    pub pcb_outlines: Vec<crate::cut::CutPart>,
    /// Parts made to order by a machine shop (UVDtact's acrylic shell), each with its
    /// dimensioned drawing and exact shape ([`crate::parts::core_shell::machined_part`]).
    pub machined_parts: Vec<crate::parts::core_shell::MachinedPart>,
    /// Sensor-frame facts worth printing in the manifest (envelope, derived radii...).
    pub summary: serde_json::Value,
}
