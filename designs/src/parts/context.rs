//! What a family sees of a design beyond its own parameters: the design's name, body
//! profile, printer profiles and backing plate ([`Context`]), and the resolved layer stack
//! ([`Stack`]: every surface placed). Families take these, never the whole design, so that a
//! family depends on no other family's parameters. The layer stack's modules (layers, their
//! markers and features, the molds) take [`crate::parts::stack_input::StackInput`].

use crate::profile::BodyProfile;
use crate::schema::printers::PrinterProfiles;
use crate::schema::shared::{Backing, Core, LayerProcess, MoldStrategy};
use serde::Serialize;

/// The parts of a design every family may read: built from a design by
/// [`crate::schema::Design::context`].
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// The design's name (`[a-z0-9_]+`), for titles and file names.
    pub name: &'a str,
    /// The body profile: the skin's outer surface, mm.
    pub body: &'a BodyProfile,
    /// The printer profiles (walls, holes, features, bayonet fit, beds).
    pub printers: &'a PrinterProfiles,
    /// The backing plate the skin is glued to, if any.
    pub backing: Option<&'a Backing>,
    /// The bought core as the design gives it (its resolved offsets are in [`Stack::core`]).
    pub core: Option<&'a Core>,
}

/// A layer with its surfaces resolved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResolvedLayer {
    pub index: usize,
    pub name: String,
    pub material: String,
    pub process: LayerProcess,
    /// Offset of the inner surface from the body surface, mm (negative inward).
    pub inner_offset_mm: f64,
    /// Offset of the outer surface, mm.
    pub outer_offset_mm: f64,
    pub thickness_mm: f64,
    pub mold_strategy: MoldStrategy,
    /// The layer fills the body down to the base plane (`inner_offset_mm` is -infinity).
    pub solid: bool,
}

/// The rigid core with its surfaces resolved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResolvedCore {
    pub inner_offset_mm: f64,
    pub outer_offset_mm: f64,
    /// How far the core continues straight down below the base plane, mm.
    pub below_base_mm: f64,
    /// Outer radius for spherical profiles, mm.
    pub outer_radius_mm: Option<f64>,
    pub inner_radius_mm: Option<f64>,
}

/// A validated design with every surface placed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stack {
    /// `None` for a design without core.
    pub core: Option<ResolvedCore>,
    pub layers: Vec<ResolvedLayer>,
}
