//! The one interface every section family implements ([`Family`]): a family owns the
//! parameters under one key of a design (`casing`, `shaft_body` ...), their rules, its
//! printable parts, its members of the assembled sensor, its bought items and its assembly
//! steps. It sees the rest of the design only through a [`Context`] and the resolved
//! [`Stack`]; [`crate::parts::registry`] lists the families, and the validation, the build, the
//! assembly and the procedure loop over that list (docs/src/development.md, "Adding a part
//! family").

use crate::error::{DesignError, ParamError};
use crate::geometry::{ChordTolerance, GeometryError, Solid};
use crate::materials::{CastReport, MaterialKind};
use crate::optics::elements::{FlatInterface, Lens, Light};
use crate::parts::context::{Context, Stack};
use crate::parts::cut_part::CutPart;
use crate::parts::member::Member;
use crate::parts::part::SkinVolume;
use crate::parts::part::{Part, ProcedureStep};
use crate::schema::shared::FillingGel;

/// The cast name of the internal filling gel ([`FillingGel`]): poured during the assembly, not
/// in a mold.
pub const FILLING_GEL: &str = "filling_gel";

/// The inner cavity of layer `i` of the stack, as a solid (the space inside its inner surface
/// down to the base plane, less its marker features): what a gel poured against the layer
/// fills; with the layer's twin parameters
/// ([`crate::parts::layers::layer_twin_params`]), from which the CadQuery twin builds the
/// same cavity exactly ([`crate::parts::ExactShape::InnerCavity`]). The build passes it to
/// [`Family::filling_pour`].
pub type InnerCavity<'a> = &'a dyn Fn(usize) -> Result<(Solid, serde_json::Value), GeometryError>;

/// A gel poured into the assembled sensor (the filling gel, cast [`FILLING_GEL`]).
#[derive(Debug, Clone)]
pub struct FillingPour<'p> {
    /// The gel and its material.
    pub gel: &'p FillingGel,
    /// The volume to fill, mm^3.
    pub volume_mm3: f64,
    /// The roles of the kit parts it is poured into.
    pub holder_roles: &'static [&'static str],
    /// How it is poured, a sentence before the material's own notes.
    pub how: &'static str,
    /// Its member of the assembly when the family's [`Family::members`] does not give it:
    /// placed after every family's members.
    pub member: Option<Member>,
}

/// The swept path of one member through one printed part on its way in along the sensor
/// axis, sensor frame, mm ([`crate::insertion`]).
#[derive(Debug, Clone)]
pub struct InsertionPath {
    /// The member that moves (an assembly member's name).
    pub member: String,
    /// The printed part it passes (an assembly member's name).
    pub through: String,
    /// The member's outer cylinder from its seat up past the part's top.
    pub solid: Solid,
    /// The parameters that size the passage, for the error.
    pub fix: Vec<String>,
}

/// What a family's build adds to the kit: its printable parts (print orientation, on the bed)
/// and the entries it sets in the manifest's `summary` object, in order (a later family's
/// entry replaces an earlier one of the same key, as `envelope_mm`).
#[derive(Debug, Clone, Default)]
pub struct Built {
    pub parts: Vec<Part>,
    pub summary: Vec<(&'static str, serde_json::Value)>,
}

/// The manifest's `envelope_mm` summary entry of a family whose parts stand round the axis:
/// `[w, w, height_mm]`, `w` the larger of its outer width and the skin's rim diameter, mm.
pub fn envelope(
    ctx: &Context<'_>,
    outer_width_mm: f64,
    height_mm: f64,
) -> (&'static str, serde_json::Value) {
    let w = outer_width_mm.max(2.0 * ctx.body.rim_radius_mm(0.0));
    ("envelope_mm", serde_json::json!([w, w, height_mm]))
}

/// One assembly step of a family, in order: a sentence of the `Assemble` step, or a pour
/// that goes in between (the filling gel poured once the parts before it are together).
#[derive(Debug, Clone, PartialEq)]
pub enum AssemblyStep {
    /// What to do, one sentence or a few; the procedure prefixes `Assemble: `.
    Text(String),
    /// A whole step of its own (a pour), placed after the sentences before it.
    Step(ProcedureStep),
}

/// What a family's build, members, paths and estimate see besides the family's own
/// parameters: the design's [`Context`], the resolved [`Stack`] and the chord tolerance the
/// solids are tessellated to.
#[derive(Debug, Clone, Copy)]
pub struct FamilyInput<'a> {
    pub ctx: &'a Context<'a>,
    pub stack: &'a Stack,
    pub tol: ChordTolerance,
}

/// What a family's assembly steps see besides the family's own parameters: the design's
/// [`Context`], the kit's parts (to name them) and the filling gel's pour if the kit has one.
#[derive(Debug, Clone, Copy)]
pub struct AssemblyInput<'a> {
    pub ctx: &'a Context<'a>,
    pub parts: &'a [Part],
    pub filling: Option<&'a CastReport>,
}

/// A section family: the parameters under [`Family::PATH`] and what they make. Every method
/// takes the family's own parameters and the narrow context, never the whole design. A family
/// is registered once, in [`crate::parts::registry::FAMILIES`].
pub trait Family {
    /// The family's parameter type (the value under [`Family::PATH`] in a design).
    type Params: Sync + 'static;
    /// The design key of the parameters (`casing`), the first step of every error path the
    /// family reports.
    const PATH: &'static str;
    /// The roles of its printed parts that belong to the assembled sensor (the rest are molds
    /// and tooling), each with the parameter paths that size it, which a fit error names.
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[];

    /// Its material keys to look up in the materials table, each with its parameter path and
    /// the kinds of material it may be.
    fn materials(_p: &Self::Params) -> Vec<(String, &str, &'static [MaterialKind])> {
        Vec::new()
    }

    /// Appends every violated rule of `p` to `errs`, each with its parameter path under
    /// `PATH.`, its value and the rule. Called once the layer stack is sound.
    fn check(p: &Self::Params, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>);

    /// Appends the violated rules of `p` that need no resolved stack, when the layer stack is
    /// not sound (its own sizes and walls, so that one run names them with the stack's
    /// errors); nothing by default.
    fn check_without_stack(_p: &Self::Params, _ctx: &Context<'_>, _errs: &mut Vec<ParamError>) {}

    /// The family's printable parts and manifest summary entries.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] naming the failing part if the kernel fails.
    fn build(p: &Self::Params, input: FamilyInput<'_>) -> Result<Built, DesignError>;

    /// The parts it prints with the outermost layer when that layer is printed, as further
    /// volumes of the layer's object (the TacTip's rigid tip fitting printed with its skin,
    /// Pestell et al. Sec. III-A): each solid in the sensor frame and its `params` without a
    /// pose; the layer's build gives them its print technology, its group and its plate
    /// pose. None by default.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] naming the outermost layer if the kernel fails.
    fn printed_with_skin(
        _p: &Self::Params,
        _input: FamilyInput<'_>,
    ) -> Result<Vec<SkinVolume>, DesignError> {
        Ok(Vec::new())
    }

    /// Its bought and cut members of the assembled sensor, in the sensor frame (its printed
    /// parts join the assembly from [`Family::build`] through their `T_print_sensor`).
    ///
    /// # Errors
    /// [`DesignError::Geometry`] if the kernel fails.
    fn members(_p: &Self::Params, _input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        Ok(Vec::new())
    }

    /// The gel it pours into the assembled sensor, if any. `cavity` gives the inner cavity of
    /// a layer of the stack.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] naming the filling gel if the kernel fails.
    fn filling_pour<'p>(
        _p: &'p Self::Params,
        _input: FamilyInput<'_>,
        _cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'p>>, DesignError> {
        Ok(None)
    }

    /// The paths its members take into its printed parts along the sensor axis, checked
    /// against the assembly's members ([`crate::insertion::blocked`]).
    ///
    /// # Errors
    /// [`DesignError::Geometry`] if the kernel fails.
    fn insertion_paths(
        _p: &Self::Params,
        _input: FamilyInput<'_>,
    ) -> Result<Vec<InsertionPath>, DesignError> {
        Ok(Vec::new())
    }

    /// Its lights, sensor frame (the LEDs it carries), for rendering what the camera sees when
    /// the design gives no `optics.lights` ([`crate::optics`]).
    fn lights(_p: &Self::Params, _ctx: &Context<'_>, _stack: &Stack) -> Vec<Light> {
        Vec::new()
    }

    /// Its flat interfaces between the camera and the skin, normal to the sensor's z axis,
    /// sensor frame ([`crate::optics::FlatInterface`]): a filling gel's free surface, a window's
    /// or a plate's faces, each with the material above it; the optical path the camera's rays
    /// bend along ([`crate::optics::optical_path`]).
    fn flat_interfaces(
        _p: &Self::Params,
        _ctx: &Context<'_>,
        _stack: &Stack,
    ) -> Vec<FlatInterface> {
        Vec::new()
    }

    /// The camera's lens it carries, sensor frame ([`crate::optics::Lens`]): where the
    /// camera looks from and how wide, which the calibration fixtures keep their points in
    /// view of; `None` when it carries no camera or its design does not say where the lens is.
    fn lens(_p: &Self::Params, _ctx: &Context<'_>, _stack: &Stack) -> Option<Lens> {
        None
    }

    /// About how many triangles its parts' surfaces make at `tol`, for the work bound checked
    /// before a build ([`crate::estimate::estimate`]).
    fn estimated_triangles(_p: &Self::Params, _input: FamilyInput<'_>) -> f64 {
        0.0
    }

    /// Its parts cut from sheet stock (laser-cut windows, plates), for DXF and SVG.
    fn cut_parts(_p: &Self::Params) -> Vec<CutPart> {
        Vec::new()
    }

    /// Its printed circuit boards' outlines, for PCB tools.
    fn pcb_outlines(_p: &Self::Params) -> Vec<CutPart> {
        Vec::new()
    }

    /// Its lines of the bought-items list.
    fn bought_items(_p: &Self::Params) -> Vec<String> {
        Vec::new()
    }

    /// Its assembly steps, given the kit's parts (to name them) and the filling gel's pour if
    /// the kit has one ([`AssemblyInput`]).
    fn assembly_steps(_p: &Self::Params, _input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        Vec::new()
    }
}

/// The names of the parts of role `role`, each in backticks, in kit order (for the steps'
/// text).
pub fn named(parts: &[Part], role: &str) -> Vec<String> {
    parts
        .iter()
        .filter(|p| p.role == role)
        .map(|p| format!("`{}`", p.name))
        .collect()
}
