//! The list of layer features ([`LAYER_FEATURES`]) and the loops over it: the validation
//! ([`check_layer_features`], [`flat_refusals`], [`flat_only_given`], [`flat_misplaced`],
//! [`check_flat_features`]), the solid a layer fills and its volume
//! ([`seat_of`]), the open mold's inserts ([`open_mold_inserts`], [`insert_roles`]) and the
//! layer's twin ([`twin_params`]). Adding a feature is one module in `parts/`, its field in
//! [`crate::schema::Layer`] and one line here (docs/src/development.md, "Adding a layer
//! feature").

use std::marker::PhantomData;

use crate::error::ParamError;
use crate::geometry::GeometryError;
use crate::parts::layer_feature::{
    FlatInput, InsertInput, LayerFeature, LayerInput, MoldInsert, Seat,
};
use crate::parts::stack_input::StackInput;
use crate::parts::{channels, marker_grid, recess};
use crate::schema::Layer;

/// A registered layer feature, as the loops see it: each method does nothing (or returns
/// nothing) for a layer without the feature.
pub trait Feature: Sync {
    /// [`LayerFeature::KEY`].
    fn key(&self) -> &'static str;
    /// Whether the layer gives the feature.
    fn given(&self, l: &Layer) -> bool;
    /// [`LayerFeature::FLAT_RULE`].
    fn flat_rule(&self) -> Option<&'static str>;
    /// [`LayerFeature::FLAT_ONLY`].
    fn flat_only(&self) -> bool;
    /// [`LayerFeature::flat_place_rule`].
    fn flat_place_rule(&self, index: usize) -> Option<&'static str>;
    /// [`LayerFeature::check_flat`] of layer `l`'s parameters.
    fn check_flat(&self, l: &Layer, input: FlatInput<'_>, errs: &mut Vec<ParamError>);
    /// [`LayerFeature::INSERT_ROLE`].
    fn insert_role(&self) -> Option<&'static str>;
    /// [`LayerFeature::check`] of layer `l`'s parameters.
    fn check(&self, l: &Layer, input: LayerInput<'_>, errs: &mut Vec<ParamError>);
    /// [`LayerFeature::seat`].
    fn seat(&self, l: &Layer) -> Option<Seat>;
    /// [`LayerFeature::twin_params`].
    fn twin_params(&self, l: &Layer) -> Option<serde_json::Value>;
    /// [`LayerFeature::open_mold_inserts`].
    ///
    /// # Errors
    /// As [`LayerFeature::open_mold_inserts`].
    fn open_mold_inserts(
        &self,
        l: &Layer,
        input: InsertInput<'_>,
    ) -> Result<Vec<MoldInsert>, GeometryError>;
}

/// A feature `F` with where its parameters sit in a layer.
pub struct RegisteredFeature<F: LayerFeature> {
    /// The feature's parameters in a layer, if given.
    pub params: fn(&Layer) -> Option<&F::Params>,
    pub feature: PhantomData<fn() -> F>,
}

impl<F: LayerFeature> RegisteredFeature<F> {
    /// The feature `F` with its parameters at `params`.
    pub const fn at(params: fn(&Layer) -> Option<&F::Params>) -> Self {
        RegisteredFeature {
            params,
            feature: PhantomData,
        }
    }
}

impl<F: LayerFeature> Feature for RegisteredFeature<F> {
    fn key(&self) -> &'static str {
        F::KEY
    }

    fn given(&self, l: &Layer) -> bool {
        (self.params)(l).is_some()
    }

    fn flat_rule(&self) -> Option<&'static str> {
        F::FLAT_RULE
    }

    fn flat_only(&self) -> bool {
        F::FLAT_ONLY
    }

    fn flat_place_rule(&self, index: usize) -> Option<&'static str> {
        F::flat_place_rule(index)
    }

    fn check_flat(&self, l: &Layer, input: FlatInput<'_>, errs: &mut Vec<ParamError>) {
        if let Some(p) = (self.params)(l) {
            F::check_flat(p, input, errs);
        }
    }

    fn insert_role(&self) -> Option<&'static str> {
        F::INSERT_ROLE
    }

    fn check(&self, l: &Layer, input: LayerInput<'_>, errs: &mut Vec<ParamError>) {
        if let Some(p) = (self.params)(l) {
            F::check(p, input, errs);
        }
    }

    fn seat(&self, l: &Layer) -> Option<Seat> {
        (self.params)(l).and_then(F::seat)
    }

    fn twin_params(&self, l: &Layer) -> Option<serde_json::Value> {
        (self.params)(l).and_then(F::twin_params)
    }

    fn open_mold_inserts(
        &self,
        l: &Layer,
        input: InsertInput<'_>,
    ) -> Result<Vec<MoldInsert>, GeometryError> {
        (self.params)(l).map_or_else(|| Ok(Vec::new()), |p| F::open_mold_inserts(p, input))
    }
}

/// Every layer feature, in the order their rules are reported and their twin keys written.
pub static LAYER_FEATURES: &[&dyn Feature] = &[
    &RegisteredFeature::<recess::RecessFeature>::at(|l| l.recess.as_ref()),
    &RegisteredFeature::<channels::ChannelsFeature>::at(|l| l.channels.as_ref()),
    &RegisteredFeature::<marker_grid::MarkerGridFeature>::at(|l| l.marker_grid.as_ref()),
];

/// The rules of every feature of every layer `si` gives (`body_ok`: the body's own rules
/// hold), layer by layer.
pub fn check_layer_features(si: &StackInput<'_>, body_ok: bool, errs: &mut Vec<ParamError>) {
    let ctx = si.ctx;
    for (index, layer) in si.layers.iter().enumerate() {
        let input = LayerInput {
            ctx: &ctx,
            index,
            name: &layer.name,
            solid: layer.solid,
            process: layer.process,
            markers: &layer.markers,
            strategy: layer.strategy_or(si.mold.strategy),
            body_ok,
        };
        for f in LAYER_FEATURES {
            f.check(layer, input, errs);
        }
    }
}

/// The features layer `l` of a flat skin gives that flat skins do not take: each key with
/// the rule it breaks.
pub fn flat_refusals(l: &Layer) -> Vec<(&'static str, &'static str)> {
    LAYER_FEATURES
        .iter()
        .filter(|f| f.given(l))
        .filter_map(|f| Some((f.key(), f.flat_rule()?)))
        .collect()
}

/// The keys of the features layer `l` of a curved skin gives that only flat skins take.
pub fn flat_only_given(l: &Layer) -> Vec<&'static str> {
    LAYER_FEATURES
        .iter()
        .filter(|f| f.flat_only() && f.given(l))
        .map(|f| f.key())
        .collect()
}

/// The features layer `l` (index `index`) of a flat skin holds where the stack does not take
/// them: each key with the rule it breaks.
pub fn flat_misplaced(l: &Layer, index: usize) -> Vec<(&'static str, &'static str)> {
    LAYER_FEATURES
        .iter()
        .filter(|f| f.given(l))
        .filter_map(|f| Some((f.key(), f.flat_place_rule(index)?)))
        .collect()
}

/// The rules of every feature of a flat skin's stacked layer `l` ([`LayerFeature::check_flat`]).
pub fn check_flat_features(l: &Layer, input: FlatInput<'_>, errs: &mut Vec<ParamError>) {
    for f in LAYER_FEATURES {
        f.check_flat(l, input, errs);
    }
}

/// The seat cut into layer `index` of `si` from below, with the key of the feature that cuts
/// it; `None` when no feature does (or its rules do not hold).
pub fn layer_seat(si: &StackInput<'_>, index: usize) -> Option<(&'static str, Seat)> {
    let l = si.layers.get(index)?;
    LAYER_FEATURES
        .iter()
        .find_map(|f| Some((f.key(), f.seat(l)?)))
}

/// The seat of layer `index` of `si` ([`layer_seat`]) without its key.
pub fn seat_of(si: &StackInput<'_>, index: usize) -> Option<Seat> {
    layer_seat(si, index).map(|(_, s)| s)
}

/// The roles of the parts the features set into molds.
pub fn insert_roles() -> Vec<&'static str> {
    LAYER_FEATURES
        .iter()
        .filter_map(|f| f.insert_role())
        .collect()
}

/// Adds the twin parameters of layer `index`'s features to its twin's parameters `v`, each
/// under its key.
pub fn twin_params(si: &StackInput<'_>, index: usize, v: &mut serde_json::Value) {
    let Some(l) = si.layers.get(index) else {
        return;
    };
    for f in LAYER_FEATURES {
        if let Some(p) = f.twin_params(l) {
            v[f.key()] = p;
        }
    }
}

/// The inserts of layer `index`'s features in its one-piece open mold.
///
/// # Errors
/// Only on a kernel failure.
pub fn open_mold_inserts(
    si: &StackInput<'_>,
    index: usize,
    input: InsertInput<'_>,
) -> Result<Vec<MoldInsert>, GeometryError> {
    let Some(l) = si.layers.get(index) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for f in LAYER_FEATURES {
        out.extend(f.open_mold_inserts(l, input)?);
    }
    Ok(out)
}
