//! The one interface every mold strategy implements ([`Strategy`]): a strategy is one module
//! of `parts/molds/` that builds the molds of a cast layer and says which of their parts form
//! the cast. The build ([`super::build_layer`], [`super::build_mold`]) and the cast check
//! ([`crate::cast_check`]) loop over [`super::STRATEGIES`] and name no strategy
//! (docs/src/development.md, "Adding a mold strategy").

use crate::error::{DesignError, ParamError};
use crate::geometry::{ChordTolerance, Solid};
use crate::parts::context::ResolvedLayer;
use crate::parts::layers::{LayerBuild, LayerOutput};
use crate::parts::part::Part;
use crate::parts::stack_input::StackInput;
use crate::profile::BodyProfile;
use crate::schema::MoldStrategy;

use super::frame::{CastMold, CastPlan, MoldOutput};

/// What a core-holding strategy's parts are built from besides the [`CastMold`]: the design,
/// the pour's plan, the cavity solid with its features, and the function that adds the
/// cavity's features to a solid.
pub struct CoreMoldInput<'a> {
    pub si: &'a StackInput<'a>,
    pub plan: &'a CastPlan,
    pub cavity: &'a Solid,
    pub with_features: &'a dyn Fn(Solid) -> Result<Solid, DesignError>,
    pub tol: ChordTolerance,
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
    ) -> Option<Result<MoldOutput, DesignError>> {
        None
    }

    /// The solid its pieces cast above the base plane (sensor frame) and the pieces that form
    /// it, from the kit's parts ([`crate::cast_check::cast_layer`]).
    ///
    /// # Errors
    /// [`DesignError::Geometry`] if the kernel fails or one of its parts is missing.
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError>;
}
