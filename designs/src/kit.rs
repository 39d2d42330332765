//! The output of a design build: printable parts and the numbers needed to cast.

pub use crate::materials::{
    CastComponent, CastReport, CoatReport, MinBatch, TreatmentReport, MIN_WEIGHABLE_G,
};
pub use crate::parts::{Part, PrintTechnology, ProcedureAction, ProcedureStep};

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
    /// (fixtures). A kit built with [`crate::build::AssemblyScope::FitCheck`] leaves out the
    /// cast layers whose exact solids the fit check did not need.
    pub assembly: Vec<crate::parts::Member>,
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
