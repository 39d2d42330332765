//! What the layer stack's modules (layers, their markers and features, the molds) see of a
//! design ([`StackInput`]): the [`Context`], the layers as the design gives them and the mold
//! parameters; never another section, so that no layer module depends on a family.

use crate::parts::context::Context;
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
}

impl Design {
    /// What the layer stack's modules see of this design ([`StackInput`]).
    pub fn stack_input(&self) -> StackInput<'_> {
        StackInput {
            ctx: self.context(),
            layers: &self.layers,
            mold: &self.mold,
        }
    }
}
