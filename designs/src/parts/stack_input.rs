//! What the layer stack's modules (layers, their markers and features, the molds) see of a
//! design ([`StackInput`]): the [`Context`], the layers as the design gives them and the mold
//! parameters; never another section, so that no layer module depends on a family.

use crate::parts::context::Context;
use crate::parts::layers::SharedFeatureSolids;
use crate::schema::mold::MoldParams;
use crate::schema::{Design, Layer};

/// What the layer stack's modules see of a design: its [`Context`], its layers as it gives
/// them (`layers`) and its mold parameters (`mold`); never another section. Built by
/// [`crate::schema::Design::stack_input`].
#[derive(Debug, Clone, Copy)]
pub struct StackInput<'a> {
    /// The design's context (name, body, printers, backing, core).
    pub ctx: Context<'a>,
    /// The layers as the design gives them, innermost first.
    pub layers: &'a [Layer],
    /// The mold parameters (`mold`).
    pub mold: &'a MoldParams,
    /// The marker feature compositions a kit build made once for its molds and layers to
    /// share ([`crate::parts::layers::share_feature_solids`]); `None` outside a kit build.
    pub shared: Option<&'a SharedFeatureSolids>,
}

impl<'a> StackInput<'a> {
    /// The same input, reading the feature compositions `shared` holds.
    pub fn sharing(self, shared: Option<&'a SharedFeatureSolids>) -> Self {
        Self { shared, ..self }
    }
}

impl Design {
    /// What the layer stack's modules see of this design ([`StackInput`]).
    pub fn stack_input(&self) -> StackInput<'_> {
        StackInput {
            ctx: self.context(),
            layers: &self.layers,
            mold: &self.mold,
            shared: None,
        }
    }
}
