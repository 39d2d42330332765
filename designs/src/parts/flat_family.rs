//! The one interface every part family of a flat sensor implements ([`FlatFamily`]) and their
//! list ([`FLAT_FAMILIES`]). A flat skin has no body of revolution, no core and no resolved
//! curved stack, so the section families of [`crate::parts::family`] (which see the design
//! through a [`crate::parts::Context`] of the curved body) do not fit it: a flat family sees
//! the flat layers and the skin's outline instead. The flat validation
//! ([`crate::stack::flat::validate`]) and the flat kit's build loop over the list and name no
//! family (docs/src/development.md, "Adding a part family").

use std::marker::PhantomData;

use crate::error::{DesignError, ParamError};
use crate::geometry::ChordTolerance;
use crate::materials::MaterialKind;
use crate::parts::channels::FlatLayer;
use crate::parts::cut_part::CutPart;
use crate::parts::member::Member;
use crate::parts::part::Part;
use crate::schema::Design;

/// What a flat family sees besides its own parameters: the skin's layers (inner, on the base
/// plane z = 0, to outer) and the chord tolerance.
#[derive(Debug, Clone, Copy)]
pub struct FlatFamilyInput<'a> {
    pub layers: &'a [FlatLayer],
    pub tol: ChordTolerance,
}

/// What a flat family adds to the kit: its printed parts (print orientation, each with its
/// `T_print_sensor`), its bought and cut members of the assembled sensor (sensor frame) and its
/// cut parts (drawings for the laser or the shop).
#[derive(Debug, Clone, Default)]
pub struct FlatBuilt {
    pub parts: Vec<Part>,
    pub members: Vec<Member>,
    pub cut_parts: Vec<CutPart>,
}

/// A part family of a flat sensor: the parameters under [`FlatFamily::PATH`] and what they
/// make. Registered once, in [`FLAT_FAMILIES`].
pub trait FlatFamily {
    /// The family's parameter type.
    type Params: Sync + 'static;
    /// The design key of the parameters, the first step of every error path it reports.
    const PATH: &'static str;

    /// Its material keys, each with its parameter path and the kinds it may be.
    fn materials(p: &Self::Params) -> Vec<(String, &str, &'static [MaterialKind])>;

    /// Appends every violated rule of `p` to `errs`, by path under `PATH.`; `layers` is `None`
    /// when the skin's layers are not sound (the family then checks its own sizes only).
    fn check(p: &Self::Params, layers: Option<&[FlatLayer]>, errs: &mut Vec<ParamError>);

    /// Its triangles at `tol`, estimated before anything is built.
    fn estimated_triangles(p: &Self::Params, tol: ChordTolerance) -> f64;

    /// Its printed parts, members and cut parts.
    ///
    /// # Errors
    /// [`DesignError::Geometry`] naming the failing part if the kernel fails.
    fn build(p: &Self::Params, input: FlatFamilyInput<'_>) -> Result<FlatBuilt, DesignError>;

    /// Its bought items, one line each, for the fabrication sheet.
    fn bought_items(p: &Self::Params) -> Vec<String>;

    /// Its assembly sentences, in order; `parts` names the kit's parts.
    fn assembly_steps(p: &Self::Params, parts: &[Part]) -> Vec<String>;
}

/// A registered flat family as the loops see it: every method does nothing for a design
/// without its parameters.
pub trait FlatSection: Sync {
    /// [`FlatFamily::PATH`].
    fn path(&self) -> &'static str;
    /// Whether the design gives the family's parameters.
    fn given(&self, d: &Design) -> bool;
    /// [`FlatFamily::materials`].
    fn materials<'d>(&self, d: &'d Design) -> Vec<(String, &'d str, &'static [MaterialKind])>;
    /// [`FlatFamily::check`].
    fn check(&self, d: &Design, layers: Option<&[FlatLayer]>, errs: &mut Vec<ParamError>);
    /// [`FlatFamily::estimated_triangles`]; 0 without the family.
    fn estimated_triangles(&self, d: &Design, tol: ChordTolerance) -> f64;
    /// [`FlatFamily::build`]; `None` without the family.
    fn build(
        &self,
        d: &Design,
        input: FlatFamilyInput<'_>,
    ) -> Option<Result<FlatBuilt, DesignError>>;
    /// [`FlatFamily::bought_items`].
    fn bought_items(&self, d: &Design) -> Vec<String>;
    /// [`FlatFamily::assembly_steps`].
    fn assembly_steps(&self, d: &Design, parts: &[Part]) -> Vec<String>;
}

/// A flat family `F` with where its parameters sit in a design.
pub struct FlatRegistered<F: FlatFamily> {
    params: fn(&Design) -> Option<&F::Params>,
    family: PhantomData<fn() -> F>,
}

impl<F: FlatFamily> FlatRegistered<F> {
    /// The family `F` with its parameters at `params`.
    pub const fn at(params: fn(&Design) -> Option<&F::Params>) -> Self {
        FlatRegistered {
            params,
            family: PhantomData,
        }
    }
}

impl<F: FlatFamily> FlatSection for FlatRegistered<F> {
    fn path(&self) -> &'static str {
        F::PATH
    }

    fn given(&self, d: &Design) -> bool {
        (self.params)(d).is_some()
    }

    fn materials<'d>(&self, d: &'d Design) -> Vec<(String, &'d str, &'static [MaterialKind])> {
        (self.params)(d).map_or_else(Vec::new, F::materials)
    }

    fn check(&self, d: &Design, layers: Option<&[FlatLayer]>, errs: &mut Vec<ParamError>) {
        if let Some(p) = (self.params)(d) {
            F::check(p, layers, errs);
        }
    }

    fn estimated_triangles(&self, d: &Design, tol: ChordTolerance) -> f64 {
        (self.params)(d).map_or(0.0, |p| F::estimated_triangles(p, tol))
    }

    fn build(
        &self,
        d: &Design,
        input: FlatFamilyInput<'_>,
    ) -> Option<Result<FlatBuilt, DesignError>> {
        (self.params)(d).map(|p| F::build(p, input))
    }

    fn bought_items(&self, d: &Design) -> Vec<String> {
        (self.params)(d).map_or_else(Vec::new, F::bought_items)
    }

    fn assembly_steps(&self, d: &Design, parts: &[Part]) -> Vec<String> {
        (self.params)(d).map_or_else(Vec::new, |p| F::assembly_steps(p, parts))
    }
}

/// The flat sensor's part families, in the order their parts, members, bought items and
/// assembly steps appear in a kit.
pub static FLAT_FAMILIES: &[&dyn FlatSection] = &[&FlatRegistered::<
    crate::parts::flat_housing::FlatHousingFamily,
>::at(|d| d.flat_housing.as_ref())];

/// Every flat family's estimated triangles for `design` at `tol` (0 without any).
pub fn estimated_triangles(design: &Design, tol: ChordTolerance) -> f64 {
    FLAT_FAMILIES
        .iter()
        .map(|f| f.estimated_triangles(design, tol))
        .sum()
}
