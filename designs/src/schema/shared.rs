//! Parameter types that families read besides their own: the rigid core and its machining,
//! how a layer is made and molded, the backing plate, the filling gel.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A flat plate the skin is glued to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Backing {
    /// Material key in the materials table (designs/materials.yaml), a bought or a printed
    /// material (ShadowTac: `pmma`, Sec. IV-A).
    pub material: String,
    /// Diameter of the disc, mm, > 0; at least the skin's diameter on the base plane, since
    /// the skin is glued onto it by its whole base.
    ///
    /// With a `casing`, the plate must also cover the casing's window with a 1 mm glue land
    /// all round (`casing.window_diameter_mm`).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Thickness of the disc along the axis, from the base plane (its top face, under the
    /// skin) down, mm, > 0.
    ///
    /// With a `casing`, the camera's view of the skin's rim is refracted through it (PMMA,
    /// index 1.49) on its way to the casing's window.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// What the plate is and how the skin is fixed to it, for the bought-items list and the
    /// cut list (ShadowTac: "PMMA acrylic disc, glued with Smooth-On Sil-Poxy"); empty when
    /// not given.
    #[serde(default)]
    pub description: String,
}

/// A coat brushed onto a cast layer after demolding (ShadowTac Sec. IV-A: the reflective layer
/// of Smooth-On PsychoPaint with aluminium powder, Silc Pig white and a silicone solvent). Its
/// amounts are the maker's: the sheet lists the components and the step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BrushedCoat {
    /// What the coat does, for the sheet (e.g. "reflective layer").
    pub purpose: String,
    /// The products mixed into it, at least one.
    pub components: Vec<String>,
    /// Where the coat goes and how, for the sheet.
    #[serde(default)]
    pub notes: String,
}

/// The rigid transparent shell (R-Tac0: a glass test tube, Sec. III-B1). Its outer surface is
/// the inner surface of the innermost layer; it is an offset of the body profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Core {
    /// What the core is, for the bought-items list (R-Tac0: "borosilicate glass test tube,
    /// round bottom", Sec. III-B1); empty when not given.
    #[serde(default)]
    pub description: String,
    /// Material key in the materials table (designs/materials.yaml), a bought or a printed
    /// material (R-Tac0: `borosilicate_glass`; UVDtact: `pmma`).
    pub material: String,
    /// Wall thickness, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// Length from the pole to the open end, mm; the part below the base plane is held by
    /// the mold's core holder and seats in the housing.
    pub length_mm: f64,
    /// Outer diameter, mm (spherical profiles only). When given, it must equal the inner
    /// diameter of the innermost layer; layers given by `outer_radius_mm` are measured from it.
    #[serde(default)]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: Option<f64>,
    /// Primer wiped onto the core's outer surface before the first layer is cast on it, so
    /// that the layer bonds to it: a `primer` key of the materials table (R-Tac0: `pr_1200_rtv`,
    /// Sec. III-B1); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub primer: Option<String>,
    /// A core made to order by a machine shop (UVDtact's acrylic shell, CNC machined and
    /// vapour polished, Sec. III): `fabkit export` writes its dimensioned drawing, and with
    /// `--format step` its STEP file, to order it. None for a bought core (a test tube).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machining: Option<CoreMachining>,
}

/// How a core made to order is described to the shop (`core.machining`). Its inner surface
/// is the core's outer surface offset inward by its wall.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CoreMachining {
    /// File stem of its drawing and STEP file, `[a-z0-9_]+`, unique among the kit's parts.
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub part_name: String,
    /// Surface finish the shop is asked for, printed on the drawing.
    pub finish: String,
    /// General tolerance of the drawing's dimensions (+/-), mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub general_tolerance_mm: f64,
}

/// How a layer is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LayerProcess {
    /// Poured into a mold around the core and the layers under it.
    Cast,
    /// Sprayed or brushed onto the mold's cavity before the next layer inward is poured
    /// (R-Tac0's black coating, Sec. III-B1); it gets no mold of its own.
    Sprayed,
    /// Printed directly (TacTip skin in Tango Black+, Pestell et al. Sec. III-A).
    Printed,
}

/// How a cast layer's mold is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MoldStrategy {
    /// A printed two-piece mold split on a parting plane through the axis.
    Direct,
    /// A printed master pattern and mold box for a Mold Star 30 silicone mold, plus a casting
    /// jig (R-Tac0 Sec. III-B1, UVDtact Sec. III).
    Master,
    /// A one-piece printed mold open on the base plane, for a solid skin cast pole-down
    /// (ShadowTac Sec. IV-A).
    Open,
    /// A solid skin cast pole-down in two printed pieces (the authors' ShadowTac mold,
    /// authors' CAD, measured): the cavity block, and a top piece whose bore is the pour
    /// reservoir that forms the skin's back, registered by a boss in a pocket and joined by
    /// clamp bolts around the flange (`mold.two_piece`).
    TwoPieceOpen,
    /// Printed negatives for Mold Star 30 silicone molds of the outer and of the inner boundary
    /// of the layer; the layer is cast between the two silicone molds (UVDtact Sec. III).
    Boundary,
}

impl MoldStrategy {
    /// Whether the mold holds a bought core that the layer is cast onto (`direct`, `master`:
    /// the core holder or casting jig closes the mold and carries the sprue and vents), so
    /// the layer's inner surface is the core's and the build plans its pour
    /// ([`crate::parts::molds::cast_plans`]).
    pub fn holds_core(self) -> bool {
        matches!(self, MoldStrategy::Direct | MoldStrategy::Master)
    }

    /// Whether its mold is open on the base plane and sets the inserts of the layer's
    /// features there (`open`: [`crate::parts::layer_feature::LayerFeature::open_mold_inserts`]).
    pub fn sets_inserts(self) -> bool {
        matches!(self, MoldStrategy::Open)
    }

    /// Whether its molds form the layer's inner surface too (`boundary`: an inner master
    /// pattern), so that features may stand on it.
    pub fn forms_inner_surface(self) -> bool {
        matches!(self, MoldStrategy::Boundary)
    }
}

/// The internal filling gel (R-Tac0 Sec. III-B1): poured into the assembled shell with the
/// sensor pole-down, before the camera goes on; it diffuses the LEDs' light and, cured, glues
/// the core to the shell. Its flat free surface is the interface through which the camera
/// looks into it (`calibration::refraction`): where it lies is set by `fills`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FillingGel {
    /// Material key in the materials table; a cast material (R-Tac0: `solaris`).
    pub material: String,
    /// How far the gel is poured (housing only; the shaft body's gel always reaches its lens
    /// window): `chamber` (the default) fills the core, the diffuser's opening and the light
    /// chamber up to the LED PCB's face, which is then its free surface; `core` fills the core
    /// to its open end, whose plane is then the free surface and the diffuser and chamber stay
    /// air.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fills: Option<GelFill>,
}

/// How far a housing's filling gel is poured (`filling_gel.fills`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum GelFill {
    /// The core only, to its open end.
    Core,
    /// The core, the diffuser's opening and the light chamber, to the LED PCB's face.
    Chamber,
}
