//! The one interface every layer feature implements ([`LayerFeature`]): a feature is a value
//! under a key of one layer (`layers[i].recess`) that adds to the layer's rules, changes the
//! solid it fills, adds parts to its mold and goes into its twin's parameters. A feature is
//! one module in `parts/` with its field in [`crate::schema::Layer`] and one line in
//! [`crate::parts::layer_registry::LAYER_FEATURES`]; the validation, the layer solids, the
//! volumes, the estimates, the molds, the cast check and the procedure loop over that list and
//! name no feature (docs/src/development.md, "Adding a layer feature").

use crate::error::ParamError;
use crate::geometry::{ChordTolerance, GeometryError, Polyline2};
use crate::markers::MarkerSpec;
use crate::parts::context::Context;
use crate::parts::part::{Part, PrintTechnology};
pub use crate::parts::seat::Seat;
use crate::profile::{BodyProfile, FlatOutline};
use crate::schema::shared::{LayerProcess, MoldStrategy};

/// What a feature's rules see besides its own parameters.
#[derive(Debug, Clone, Copy)]
pub struct LayerInput<'a> {
    /// The design's context (its body, printers, core).
    pub ctx: &'a Context<'a>,
    /// The layer's index in `layers`.
    pub index: usize,
    /// The layer's part name (`layers[i].name`).
    pub name: &'a str,
    /// Whether it fills the body down to the base plane (`layers[i].solid`).
    pub solid: bool,
    /// How it is made (`layers[i].process`).
    pub process: LayerProcess,
    /// The marker patterns it carries (`layers[i].markers`).
    pub markers: &'a [MarkerSpec],
    /// The layer's mold strategy: its own `mold_strategy`, else the design's `mold.strategy`.
    pub strategy: MoldStrategy,
    /// Whether the body's own rules hold (its sizes may be measured).
    pub body_ok: bool,
}

impl LayerInput<'_> {
    /// The parameter path of feature `key` of this layer (`layers[0].recess`).
    pub fn path(&self, key: &str) -> String {
        format!("layers[{}].{key}", self.index)
    }
}

/// What a feature's mold inserts see: the layer's part name (`gel`), its base plane, the
/// mold's shared parameters for the manifest, and the technology and material the mold's
/// cavity parts print in.
#[derive(Debug, Clone, Copy)]
pub struct InsertInput<'a> {
    pub layer_name: &'a str,
    pub base_z_mm: f64,
    pub base_params: &'a serde_json::Value,
    pub technology: PrintTechnology,
    pub material: &'static str,
    pub tol: ChordTolerance,
}

/// What a flat skin's feature rules see ([`LayerFeature::check_flat`]): the layer's index,
/// its thickness once the layers are stacked, and the skin's outline.
#[derive(Debug, Clone, Copy)]
pub struct FlatInput<'a> {
    /// The layer's index in `layers` (0: the innermost, on the base plane).
    pub index: usize,
    /// The layer's thickness, mm.
    pub thickness_mm: f64,
    /// The skin's outline.
    pub outline: &'a FlatOutline,
}

impl FlatInput<'_> {
    /// The prefix of every error path of feature `key` of this layer (`layers[1].channels.`).
    pub fn prefix(&self, key: &str) -> String {
        format!("layers[{}].{key}.", self.index)
    }
}

/// A part set into a mold to form a feature, with the volume it takes from the cavity, mm^3.
#[derive(Debug, Clone)]
pub struct MoldInsert {
    pub part: Part,
    pub volume_mm3: f64,
}

/// A layer feature: the parameters under [`LayerFeature::KEY`] of a layer and what they make.
/// Every method takes the feature's own parameters and a narrow input, never the whole design.
pub trait LayerFeature {
    /// The feature's parameter type (the value under [`LayerFeature::KEY`] in a layer).
    type Params: Sync + 'static;
    /// The layer key of the parameters (`recess`), the last step of every error path the
    /// feature reports (`layers[i].recess`).
    const KEY: &'static str;
    /// The rule a flat skin's layer breaks by giving the feature; `None` when flat skins take
    /// it.
    const FLAT_RULE: Option<&'static str> = None;
    /// Whether only flat skins take it (`channels`, `marker_grid`): a curved skin's validation
    /// refuses it by its path.
    const FLAT_ONLY: bool = false;
    /// The role of the parts it sets into a mold ([`LayerFeature::open_mold_inserts`]), which
    /// the cast check counts as mold and the procedure places; `None` when it has none.
    const INSERT_ROLE: Option<&'static str> = None;

    /// Appends every violated rule of `p` to `errs`, each with its path under
    /// `layers[i].KEY`, its value and the rule.
    fn check(p: &Self::Params, input: LayerInput<'_>, errs: &mut Vec<ParamError>);

    /// The rule layer `index` of a flat skin breaks by holding the feature there (channels
    /// need a layer under them, the marker grid stands on the innermost); `None` by default.
    fn flat_place_rule(_index: usize) -> Option<&'static str> {
        None
    }

    /// Appends every violated rule of `p` in a flat skin's stacked layer (`input`), each with
    /// its path under `layers[i].KEY.`; nothing by default.
    fn check_flat(_p: &Self::Params, _input: FlatInput<'_>, _errs: &mut Vec<ParamError>) {}

    /// The seat it cuts into its solid layer from below; `None` by default, and when its
    /// rules do not hold (validation reports them).
    fn seat(_p: &Self::Params) -> Option<Seat> {
        None
    }

    /// Its parameters in the layer's twin (under `KEY`); `None` by default.
    fn twin_params(_p: &Self::Params) -> Option<serde_json::Value> {
        None
    }

    /// The parts set into the layer's one-piece open mold to form it; none by default.
    ///
    /// # Errors
    /// Only on a kernel failure.
    fn open_mold_inserts(
        _p: &Self::Params,
        _input: InsertInput<'_>,
    ) -> Result<Vec<MoldInsert>, GeometryError> {
        Ok(Vec::new())
    }
}

/// The closed (r, z) profile of a solid layer whose outer surface is the body's offset
/// surface at `outer_offset_mm`: down that surface to the base plane, then, with a `seat`, in
/// to its mouth and up its wall, fillet and roof to the apex; without one, in along the base
/// plane to the axis. Arcs within `tol`.
pub fn solid_layer_profile(
    body: &BodyProfile,
    outer_offset_mm: f64,
    seat: Option<&Seat>,
    tol: ChordTolerance,
) -> Polyline2 {
    match seat {
        None => body.solid_profile(outer_offset_mm, 0.0, tol),
        Some(r) => {
            let mut pl = body.offset_polyline(outer_offset_mm, 0.0, tol);
            pl.extend(&r.polyline(body.base_z_mm(), 0.0, tol).reversed());
            pl
        }
    }
}
