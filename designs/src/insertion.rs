//! Insertion paths: a part that goes into the shell along the sensor axis must pass every
//! printed part on its way, not only fit where it ends up (the fit check, [`crate::assembly`]).
//! In the round shell (R-Tac0 Sec. III-B2, B4) the LED ring PCB goes down the tube's light
//! chamber onto its ledge before the diffuser disc and the collar go on, and the contact
//! module's core goes down the collar onto the diffuser; each path is the part's outer
//! cylinder swept from its seat up past the top of the part it passes.
//!
//! A path that overlaps the part it passes by more than the fit check's thresholds
//! ([`crate::assembly::MIN_OVERLAP_MM3`], thicker than the chord tolerance) is an error naming
//! both, the overlap and the parameters that would clear it.

use crate::assembly::{Interference, Member, MIN_OVERLAP_MM3};
use crate::error::{DesignError, GeometryContext};
use crate::geometry::ChordTolerance;
use crate::parts::context::Stack;
use crate::parts::registry::{SectionInput, FAMILIES};
use crate::schema::Design;

pub use crate::parts::family::InsertionPath;

/// The insertion paths of `design`'s assembly: every family's
/// ([`crate::parts::family::Family::insertion_paths`]: the round shell's LED PCB through the
/// tube and core through the collar; the square shell's halves close around their parts).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn paths(
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
) -> Result<Vec<InsertionPath>, DesignError> {
    let mut out = Vec::new();
    for f in FAMILIES {
        out.extend(f.insertion_paths(SectionInput { design, stack, tol })?);
    }
    Ok(out)
}

/// The paths that overlap the part they pass (`member` as `a`, the part as `b`), with the
/// overlap's volume and mean thickness; a path whose part is not among `members` is skipped.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn blocked(
    members: &[Member],
    paths: &[InsertionPath],
    tol: ChordTolerance,
) -> Result<Vec<Interference>, DesignError> {
    let mut out = Vec::new();
    for p in paths {
        let Some(part) = members.iter().find(|m| m.name == p.through) else {
            continue;
        };
        let overlap = p
            .solid
            .intersection(&part.solid)
            .part(&format!("insertion of {} through {}", p.member, p.through))?;
        let v = overlap.volume();
        let thickness = 2.0 * v / overlap.surface_area().max(f64::MIN_POSITIVE);
        if v > MIN_OVERLAP_MM3 && thickness > tol.mm() {
            out.push(Interference {
                a: p.member.clone(),
                b: p.through.clone(),
                volume_mm3: v,
                thickness_mm: thickness,
                fix: p.fix.clone(),
            });
        }
    }
    Ok(out)
}

/// [`blocked`] paths as parameter errors ([`crate::assembly::overlap_errors`]): the path is
/// the first parameter that sizes the passage (with its value in `design`), the rule names the
/// member, the part and the overlap.
pub fn errors(design: &Design, found: &[Interference]) -> Option<DesignError> {
    crate::assembly::overlap_errors(design, found, |f| {
        format!(
            "insertion check: `{}` cannot go in from the top: on its way it overlaps `{}` by {:.3} mm³; change {}",
            f.a,
            f.b,
            f.volume_mm3,
            f.fix.join(" or ")
        )
    })
}
