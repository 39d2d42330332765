//! The one interface every mold strategy implements ([`Strategy`]): a strategy is one module
//! of `parts/molds/` that builds the molds of a cast layer and says which of their parts form
//! the cast. The build ([`super::build_layer`], [`super::build_mold`]) and the cast check
//! ([`crate::cast_check`]) loop over [`super::STRATEGIES`] and name no strategy
//! (docs/src/development.md, "Adding a mold strategy").

use crate::error::{DesignError, ParamError};
use crate::geometry::{ChordTolerance, Solid};
use crate::parts::context::ResolvedLayer;
use crate::parts::layers::{LayerBuild, LayerOutput};
use crate::parts::part::{Part, ProcedureStep};
use crate::parts::stack_input::StackInput;
use crate::profile::BodyProfile;
use crate::schema::MoldStrategy;

use super::frame::{CastMold, CastPlan, CoreMold};

/// What a core-holding strategy's parts are built from besides the [`CastMold`]: the design,
/// the pour's plan, the cavity solid with its features, and the function that adds the
/// cavity's features to a solid.
pub struct CoreMoldInput<'a> {
    pub si: &'a StackInput<'a>,
    pub plan: &'a CastPlan,
    pub cavity: &'a Solid,
    pub with_features: &'a (dyn Fn(Solid) -> Result<Solid, DesignError> + Sync),
    pub tol: ChordTolerance,
}

/// What a strategy's pour steps are written from ([`Strategy::pour_steps`],
/// [`Strategy::seat_steps`]): the pour's step number and mix, its mold's parts by role and by
/// name, the clamp bolts' words and whether an earlier pour's layers stay on an inner mold.
#[derive(Debug, Clone, Copy)]
pub struct PourInput<'a> {
    /// The pour's step number ([`crate::materials::CastReport::step`]).
    pub step: u32,
    /// The mix, with its amounts ([`crate::materials::CastReport::mix_text`]).
    pub mix: &'a str,
    /// The mold's core holder or casting jig, if it has one.
    pub holder: Option<&'a Part>,
    /// The mold's halves (`mold_half`).
    pub halves: &'a [&'a Part],
    /// The open mold's pieces (`open_mold_piece`, `open_mold`), without the inserts.
    pub pieces: &'a [&'a Part],
    /// The layer features' inserts set into the mold
    /// ([`crate::parts::layer_registry::insert_roles`]).
    pub inserts: &'a [&'a Part],
    /// ` and tighten the 4 clamp bolts (M3 x 60, with nuts)`, or empty for a mold without.
    pub bolt_text: &'a str,
    /// The names of every part that holds the pour
    /// ([`crate::materials::CastReport::mold_parts`]), silicone molds included.
    pub mold_parts: &'a [String],
    /// Whether an earlier pour's layers stay on their inner mold
    /// ([`Strategy::keeps_inner_mold`]): they take the inner mold's place (UVDtact Sec. III).
    pub on_inner_mold: bool,
}

/// What the demold step of a pour is written from ([`Strategy::demold_text`]).
#[derive(Debug, Clone, Copy)]
pub struct DemoldInput<'a> {
    /// The pour's step number.
    pub step: u32,
    /// The cure, in the words of the materials table ([`crate::materials::cure_text`]).
    pub cure: &'a str,
    /// The layer poured (`layers[i].name`).
    pub layer: &'a str,
    /// Whether a later pour in the same strategy follows (the layer then stays on its mold).
    pub poured_again: bool,
}

/// The clamp bolts one part of a mold carries ([`Strategy::clamp_bolts`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoldBolts {
    pub count: usize,
    /// The thickness they clamp, mm.
    pub grip_mm: f64,
    /// The clearance hole's diameter, mm.
    pub clearance_mm: f64,
}

/// What the cast check asks a strategy for: the kit's parts of the layer by the suffix of
/// their names (`need` fails naming a missing one), a part's solid in the sensor frame, the
/// space closed pieces leave within the cavity's envelope, and the envelope itself.
pub trait CastPieces<'k> {
    /// The layer's part `<layer>_<suffix>`, if the kit has it.
    fn part(&self, suffix: &str) -> Option<&'k Part>;
    /// The layer's part `<layer>_<suffix>`.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] naming the missing part.
    fn need(&self, suffix: &str) -> Result<&'k Part, DesignError>;
    /// The part's solid in the sensor frame.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] when the part has no print pose.
    fn in_sensor(&self, p: &Part) -> Result<Solid, DesignError>;
    /// The space the closed `pieces` leave within the envelope.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] on a kernel failure.
    fn negative(&self, pieces: &[&Part]) -> Result<Solid, DesignError>;
    /// The cavity's envelope: its offset surface beyond the tallest feature, closed on the
    /// base plane.
    fn envelope(&self) -> &Solid;
    /// The error for `what` missing from the kit.
    fn missing(&self, what: String) -> DesignError;
    /// The chord tolerance of the check.
    fn tol(&self) -> ChordTolerance;
    /// `r` with a kernel error named after the layer.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] from `r`.
    fn named(&self, r: Result<Solid, crate::geometry::GeometryError>)
        -> Result<Solid, DesignError>;
}

/// A mold strategy: what its molds are and which of their parts form the cast.
pub trait Strategy: Sync {
    /// Its name in the schema (`mold.strategy`, `layers[i].mold_strategy`).
    fn kind(&self) -> MoldStrategy;

    /// Whether it casts solid layers only (an open face on the base plane takes no inner
    /// surface); validation refuses it for a layer that is not solid.
    fn solid_only(&self) -> bool {
        false
    }

    /// Appends the rules of its own mold parameters (`mold.open_block`, `mold.two_piece_open`)
    /// against `cast`: the sound stack's cast layers whose strategy it is (possibly none), or
    /// `None` when the stack is not sound (then only the rules that need no layer). Nothing by
    /// default.
    fn check_layers(
        &self,
        _si: &StackInput<'_>,
        _cast: Option<&[&ResolvedLayer]>,
        _errs: &mut Vec<ParamError>,
    ) {
    }

    /// The walls of its molds around the layers `cast` in it (not empty), each thickness in mm
    /// with what it is, for the thinnest-wall metric
    /// ([`crate::variant::metrics`]); `None` when `mold.wall_thickness_mm` sizes them (the
    /// default).
    fn walls(&self, _si: &StackInput<'_>, _cast: &[&ResolvedLayer]) -> Option<Vec<(f64, String)>> {
        None
    }

    /// The steps that close its mold and pour a layer in it, in the words of the fabrication
    /// sheet ([`crate::procedure::procedure`]: `CloseMold`, `Pour`).
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep>;

    /// The clamp bolts its mold part `p` carries (one part per bolted mold names them, from
    /// its parameters); `None` for every other part, and by default.
    fn clamp_bolts(&self, _si: &StackInput<'_>, _p: &Part) -> Option<MoldBolts> {
        None
    }

    /// Whether a layer cast in it stays on the mold's inner part for the next pour in it, the
    /// layers so far then taking that part's place (boundary: on the inner silicone mold,
    /// UVDtact Sec. III); false by default.
    fn keeps_inner_mold(&self) -> bool {
        false
    }

    /// The steps before the release agent of a pour in it, in the words of the fabrication
    /// sheet (`MoveCore`); none by default.
    fn seat_steps(&self, _p: PourInput<'_>) -> Vec<ProcedureStep> {
        Vec::new()
    }

    /// The words of a pour's demold step (`Demold`) in it; `None` for the default ("open the
    /// mold and take it out").
    fn demold_text(&self, _d: DemoldInput<'_>) -> Option<String> {
        None
    }

    /// A sentence the notes of a pour in its mold start with; `None` by default.
    fn pour_note(&self) -> Option<&'static str> {
        None
    }

    /// Its share of the triangle estimate of a layer `l` cast in it beyond the layer's own
    /// surfaces ([`crate::estimate::estimate`]); 0 by default.
    fn estimated_triangles(
        &self,
        _body: &BodyProfile,
        _l: &ResolvedLayer,
        _tol: ChordTolerance,
    ) -> f64 {
        0.0
    }

    /// Whether its parts of a layer read the layer's whole solid
    /// ([`crate::parts::layers::layer_solid`]: boundary, for the gel's volume); a kit build
    /// that also puts the layer into its assembly then makes that solid once for both
    /// ([`crate::parts::layers::share_feature_solids`]). False by default.
    fn reads_layer_solid(&self) -> bool {
        false
    }

    /// The parts of a layer cast in it, for a strategy that casts without a core; `None` for
    /// a core-holding one ([`Strategy::core_mold`]).
    fn build_layer(&self, _b: LayerBuild<'_>) -> Option<Result<LayerOutput, DesignError>> {
        None
    }

    /// The mold parts of a pour onto the core, for a core-holding strategy
    /// ([`MoldStrategy::holds_core`]); `None` for the others ([`Strategy::build_layer`]).
    fn core_mold(
        &self,
        _input: CoreMoldInput<'_>,
        _c: CastMold,
    ) -> Option<Result<CoreMold, DesignError>> {
        None
    }

    /// The solid its pieces cast above the base plane (sensor frame) and the pieces that form
    /// it, from the kit's parts ([`crate::cast_check::cast_layer`]).
    ///
    /// # Errors
    /// [`DesignError::Geometry`] if the kernel fails or one of its parts is missing.
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError>;
}
