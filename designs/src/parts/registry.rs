//! The list of section families ([`FAMILIES`]): the validation ([`crate::stack::validate`]),
//! the build ([`crate::build::build_kit_bounded`]), the assembly and the procedure loop over
//! it and name no family. Adding a family is one module in `parts/`, its field in
//! [`crate::schema::Design`] and one line here (docs/src/development.md, "Adding a part
//! family").

use crate::parts::part::SkinVolume;
use std::marker::PhantomData;

use crate::error::{DesignError, ParamError};
use crate::geometry::ChordTolerance;
use crate::materials::{CastReport, MaterialKind};
use crate::optics::elements::{FlatInterface, Lens, Light};
use crate::parts::context::Stack;
use crate::parts::cut_part::CutPart;
use crate::parts::family::{
    AssemblyInput, AssemblyStep, Built, Family, FamilyInput, FillingPour, InnerCavity,
    InsertionPath,
};
use crate::parts::member::Member;
use crate::parts::part::Part;
use crate::parts::{casing, fingertip_base, housing, shaft_body, spacer};
use crate::schema::Design;

/// A registered family, as the loops see it: each method does nothing (or returns nothing)
/// for a design without the family's parameters.
pub trait Section: Sync {
    /// The design key of the family's parameters.
    fn path(&self) -> &'static str;
    /// Whether the design gives the family's parameters.
    fn given(&self, d: &Design) -> bool;
    /// The parameter paths that size its printed sensor part of role `role`
    /// ([`Family::SENSOR_PARTS`]); `None` for a role it does not make.
    fn sensor_part(&self, role: &str) -> Option<&'static [&'static str]>;
    /// [`Family::materials`]; empty without the family.
    fn materials<'d>(&self, d: &'d Design) -> Vec<(String, &'d str, &'static [MaterialKind])>;
    /// [`Family::estimated_triangles`]; 0 without the family.
    fn estimated_triangles(&self, at: SectionInput<'_>) -> f64;
    /// [`Family::cut_parts`].
    fn cut_parts(&self, d: &Design) -> Vec<CutPart>;
    /// [`Family::pcb_outlines`].
    fn pcb_outlines(&self, d: &Design) -> Vec<CutPart>;
    /// [`Family::check`] with the sound stack `stack`, or [`Family::check_without_stack`]
    /// when the stack is not sound (`None`).
    fn check(&self, d: &Design, stack: Option<&Stack>, errs: &mut Vec<ParamError>);
    /// [`Family::lights`]; empty without the family.
    fn lights(&self, d: &Design, stack: &Stack) -> Vec<Light>;
    /// [`Family::flat_interfaces`]; empty without the family.
    fn flat_interfaces(&self, d: &Design, stack: &Stack) -> Vec<FlatInterface>;
    /// [`Family::lens`]; `None` without the family.
    fn lens(&self, d: &Design, stack: &Stack) -> Option<Lens>;
    /// [`Family::filling_pour`]; `None` without the family.
    ///
    /// # Errors
    /// As [`Family::filling_pour`].
    fn filling_pour<'d>(
        &self,
        at: SectionInput<'d>,
        cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'d>>, DesignError>;
    /// [`Family::insertion_paths`].
    ///
    /// # Errors
    /// As [`Family::insertion_paths`].
    fn insertion_paths(&self, at: SectionInput<'_>) -> Result<Vec<InsertionPath>, DesignError>;
    /// [`Family::build`]; `None` without the family.
    fn build(&self, at: SectionInput<'_>) -> Option<Result<Built, DesignError>>;
    /// [`Family::members`].
    ///
    /// # Errors
    /// As [`Family::members`].
    fn members(&self, at: SectionInput<'_>) -> Result<Vec<Member>, DesignError>;
    /// [`Family::printed_with_skin`]; none without the family.
    ///
    /// # Errors
    /// As [`Family::printed_with_skin`].
    fn printed_with_skin(&self, at: SectionInput<'_>) -> Result<Vec<SkinVolume>, DesignError>;
    /// [`Family::bought_items`].
    fn bought_items(&self, d: &Design) -> Vec<String>;
    /// [`Family::assembly_steps`].
    fn assembly_steps(
        &self,
        d: &Design,
        parts: &[Part],
        filling: Option<&CastReport>,
    ) -> Vec<AssemblyStep>;
}

/// What the loops give a registered family's build-time methods: the design, its resolved
/// stack and the chord tolerance.
#[derive(Debug, Clone, Copy)]
pub struct SectionInput<'d> {
    pub design: &'d Design,
    pub stack: &'d Stack,
    pub tol: ChordTolerance,
}

/// A family `F` with where its parameters sit in a design.
pub struct Registered<F: Family> {
    /// The family's parameters in a design, if given.
    pub params: fn(&Design) -> Option<&F::Params>,
    pub family: PhantomData<fn() -> F>,
}

impl<F: Family> Registered<F> {
    /// The family `F` with its parameters at `params`.
    pub const fn at(params: fn(&Design) -> Option<&F::Params>) -> Self {
        Registered {
            params,
            family: PhantomData,
        }
    }

    /// `f` of the family's parameters in `at.design` and its [`FamilyInput`]; `None` without
    /// the family.
    fn with<'d, T>(
        &self,
        at: SectionInput<'d>,
        f: impl FnOnce(&'d F::Params, FamilyInput<'_>) -> T,
    ) -> Option<T> {
        let p = (self.params)(at.design)?;
        let ctx = at.design.context();
        let input = FamilyInput {
            ctx: &ctx,
            stack: at.stack,
            tol: at.tol,
        };
        Some(f(p, input))
    }
}

impl<F: Family> Section for Registered<F> {
    fn path(&self) -> &'static str {
        F::PATH
    }

    fn given(&self, d: &Design) -> bool {
        (self.params)(d).is_some()
    }

    fn sensor_part(&self, role: &str) -> Option<&'static [&'static str]> {
        F::SENSOR_PARTS
            .iter()
            .find(|(r, _)| *r == role)
            .map(|(_, fix)| *fix)
    }

    fn materials<'d>(&self, d: &'d Design) -> Vec<(String, &'d str, &'static [MaterialKind])> {
        (self.params)(d).map_or_else(Vec::new, F::materials)
    }

    fn estimated_triangles(&self, at: SectionInput<'_>) -> f64 {
        self.with(at, F::estimated_triangles).unwrap_or(0.0)
    }

    fn cut_parts(&self, d: &Design) -> Vec<CutPart> {
        (self.params)(d).map_or_else(Vec::new, F::cut_parts)
    }

    fn pcb_outlines(&self, d: &Design) -> Vec<CutPart> {
        (self.params)(d).map_or_else(Vec::new, F::pcb_outlines)
    }

    fn check(&self, d: &Design, stack: Option<&Stack>, errs: &mut Vec<ParamError>) {
        match ((self.params)(d), stack) {
            (Some(p), Some(stack)) => F::check(p, &d.context(), stack, errs),
            (Some(p), None) => F::check_without_stack(p, &d.context(), errs),
            (None, _) => {}
        }
    }

    fn lights(&self, d: &Design, stack: &Stack) -> Vec<Light> {
        (self.params)(d).map_or_else(Vec::new, |p| F::lights(p, &d.context(), stack))
    }

    fn flat_interfaces(&self, d: &Design, stack: &Stack) -> Vec<FlatInterface> {
        (self.params)(d).map_or_else(Vec::new, |p| F::flat_interfaces(p, &d.context(), stack))
    }

    fn lens(&self, d: &Design, stack: &Stack) -> Option<Lens> {
        (self.params)(d).and_then(|p| F::lens(p, &d.context(), stack))
    }

    fn filling_pour<'d>(
        &self,
        at: SectionInput<'d>,
        cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'d>>, DesignError> {
        self.with(at, |p, input| F::filling_pour(p, input, cavity))
            .unwrap_or(Ok(None))
    }

    fn insertion_paths(&self, at: SectionInput<'_>) -> Result<Vec<InsertionPath>, DesignError> {
        self.with(at, F::insertion_paths)
            .unwrap_or_else(|| Ok(Vec::new()))
    }

    fn build(&self, at: SectionInput<'_>) -> Option<Result<Built, DesignError>> {
        self.with(at, F::build)
    }

    fn members(&self, at: SectionInput<'_>) -> Result<Vec<Member>, DesignError> {
        self.with(at, F::members).unwrap_or_else(|| Ok(Vec::new()))
    }

    fn printed_with_skin(&self, at: SectionInput<'_>) -> Result<Vec<SkinVolume>, DesignError> {
        self.with(at, F::printed_with_skin)
            .unwrap_or_else(|| Ok(Vec::new()))
    }

    fn bought_items(&self, d: &Design) -> Vec<String> {
        (self.params)(d).map_or_else(Vec::new, F::bought_items)
    }

    fn assembly_steps(
        &self,
        d: &Design,
        parts: &[Part],
        filling: Option<&CastReport>,
    ) -> Vec<AssemblyStep> {
        (self.params)(d).map_or_else(Vec::new, |p| {
            let ctx = d.context();
            F::assembly_steps(
                p,
                AssemblyInput {
                    ctx: &ctx,
                    parts,
                    filling,
                },
            )
        })
    }
}

/// The section families, in the order their parts, summary entries, members, bought items and
/// assembly steps appear in a kit.
pub static FAMILIES: &[&dyn Section] = &[
    &Registered::<housing::HousingFamily>::at(|d| d.housing.as_ref()),
    &Registered::<shaft_body::ShaftBodyFamily>::at(|d| d.shaft_body.as_ref()),
    &Registered::<casing::CasingFamily>::at(|d| d.casing.as_ref()),
    &Registered::<fingertip_base::FingertipBaseFamily>::at(|d| d.fingertip_base.as_ref()),
    &Registered::<spacer::SpacerFamily>::at(|d| d.spacer.as_ref()),
];

/// The parts every family prints with the outermost layer of `design` when it is printed
/// ([`Family::printed_with_skin`]), family by family.
///
/// # Errors
/// As [`Family::printed_with_skin`].
pub fn printed_with_skin(
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
) -> Result<Vec<SkinVolume>, DesignError> {
    let at = SectionInput { design, stack, tol };
    let mut out = Vec::new();
    for f in FAMILIES {
        out.extend(f.printed_with_skin(at)?);
    }
    Ok(out)
}
