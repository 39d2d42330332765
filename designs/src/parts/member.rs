//! What a part family contributes to the assembled sensor ([`crate::assembly`]): its members,
//! each a solid in the sensor frame with where it comes from, the parameters that size it and
//! what an exact B-rep of it is built from. The families build these; the assembly collects
//! and fit-checks them.

use crate::geometry::{cylinder, ChordTolerance, GeometryError, Solid};
use serde::{Deserialize, Serialize};

/// Where a member of the assembly comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MemberKind {
    /// A printed part of the kit.
    Printed,
    /// A cast or sprayed layer of the skin.
    Cast,
    /// A bought part, modelled as a simple envelope.
    Bought,
}

/// One part of the assembled sensor.
#[derive(Debug, Clone)]
pub struct Member {
    /// The kit part's or layer's name; bought envelopes end in `_envelope`.
    pub name: String,
    pub kind: MemberKind,
    pub description: String,
    /// The solid in the sensor frame, mm.
    pub solid: Solid,
    /// The parameter paths that size or place this member: what a fit-check error suggests
    /// changing.
    pub fix: Vec<String>,
    /// The member is a surface of revolution between two offsets of the body profile with
    /// nothing on it (a cast layer without markers, the core), or the filling gel inside the
    /// core's inner surface, or a printed skin, its marker tips and the gel filling it (the
    /// gel is the skin's cavity less the very pin and tip solids the skin and tips are made
    /// of): the stack's validation and their construction already nest such members without
    /// overlap, so the fit check skips pairs of them. A cast layer with markers is nested too,
    /// outside its features ([`Member::features`]).
    pub nested_by_stack: bool,
    /// Of a nested member: the marker features that grow it beyond what the stack nests and
    /// those that cut into it ([`MemberFeatures`]); empty for every member but a cast layer
    /// with markers.
    pub features: MemberFeatures,
    /// What an exact B-rep of the member is built from (STEP export, `export/src/step.rs`),
    /// in the sensor frame, mm; `None` for a printed member (its kit part's own parameters
    /// describe it) and for a member that has no exact description (STEP export then sews its
    /// mesh).
    pub exact: Option<ExactShape>,
    /// The material the member is made of (a key of designs/materials.yaml), whose density
    /// gives its mass ([`crate::geometry::Mesh::mass_properties`]); `None` for a bought
    /// item whose envelope is not its material (a camera board, an LED PCB and its parts).
    pub material: Option<String>,
}

/// The marker features of a nested member (a cast layer), for the fit check
/// ([`crate::assembly::interferences`]): outside the features that grow it (outward ones on its
/// outer surface, inward ones on its inner surface) the layer is the featureless shell between
/// its two offsets, which the stack nests against its neighbours; so two nested members can
/// overlap only inside the growth of either. A growing marker set of one layer that its
/// neighbour cuts into itself as the very same features (the same shape, surface offset,
/// direction and placements: a layer's protrusions in the slots of the layer under it) is
/// nested by construction too, and not intersected.
#[derive(Debug, Clone, Default)]
pub struct MemberFeatures {
    /// Each growing marker set: its key and its features' solids composed, sensor frame, mm.
    pub grow: Vec<(FeatureKey, Solid)>,
    /// The keys of the marker sets that cut into the member.
    pub cut: Vec<FeatureKey>,
    /// `Some(i)` when the member's solid stands in for cast layer `i` in a build that only
    /// fit-checks the assembly ([`crate::build::AssemblyScope::FitCheck`]): the featureless shell
    /// with the growing features, which holds the layer; the fit check builds the layer's exact
    /// solid ([`crate::parts::layers::layer_solid`]) only when the stand-in overlaps another
    /// member.
    pub stand_in_for_layer: Option<usize>,
}

/// What makes two marker sets' features the same solids where they meet the surface: the
/// feature's diameter and height, the surface's offset, the direction the features point, whether
/// only stems are built, and every marker's position and normal (the bit patterns, mm).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FeatureKey(pub Vec<u64>);

/// The exact shape of a non-printed assembly member, from which the CadQuery twin
/// (`export/python/twins/step_export.py`) builds its B-rep. Sensor frame, mm; serialized with a
/// `shape` tag (`layer`, `revolved`, `cylinder`, `ring`, `box`, `core_shell`, `inner_cavity`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum ExactShape {
    /// A cast or sprayed layer: the same parameters as its printed or molded parts carry
    /// (`layer`, `body`, `outer_offset_mm`, `inner_offset_mm`, `solid`, `markers`, see
    /// [`crate::parts::layers::layer_twin_params`]), built exactly by the twin.
    Layer { params: serde_json::Value },
    /// The solid of revolution about z of a closed (r, z) polygon, mm (r >= 0): exact for the
    /// polygon (planes, cylinders, cones), which itself lies within half the chord tolerance
    /// of the true profile.
    Revolved { profile_rz_mm: Vec<[f64; 2]> },
    /// A disc about the z axis from `z0_mm` to `z1_mm`.
    Cylinder {
        radius_mm: f64,
        z0_mm: f64,
        z1_mm: f64,
    },
    /// A flat ring about the z axis from `z0_mm` to `z1_mm`.
    Ring {
        outer_radius_mm: f64,
        inner_radius_mm: f64,
        z0_mm: f64,
        z1_mm: f64,
    },
    /// An axis-aligned box.
    Box { min_mm: [f64; 3], max_mm: [f64; 3] },
    /// A core with a bore ([`crate::parts::core_shell::exact_shape`]): `body`,
    /// `outer_offset_mm`, `wall_thickness_mm`, `below_base_mm`; the twin builds its outer
    /// surface exactly and its inner surface by the rule of
    /// [`crate::profile::BodyProfile::shell_inner_surface`].
    CoreShell { params: serde_json::Value },
    /// The space inside a layer above the base plane less its inner features, whole (stems
    /// and tips: [`crate::parts::layers::inner_cavity`]; `params` as for `Layer`, of that
    /// layer), united with the disc about the z axis of radius `opening_radius_mm` from
    /// `opening_z0_mm` up to `opening_z1_mm`: a printed TacTip tip's filling gel, which runs
    /// down through the tip fitting's lip to the lens window (Pestell et al. Sec. III-A).
    InnerCavity {
        params: serde_json::Value,
        opening_radius_mm: f64,
        opening_z0_mm: f64,
        opening_z1_mm: f64,
    },
}

/// A bought part's envelope about the sensor axis: the cylinder of radius `r_mm` from `z0_mm`
/// up to `z1_mm` (sensor frame), tessellated at `tol`, with its exact shape.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn axial_cylinder(
    r_mm: f64,
    z0_mm: f64,
    z1_mm: f64,
    tol: ChordTolerance,
) -> Result<(Solid, ExactShape), GeometryError> {
    let solid = cylinder(z1_mm - z0_mm, r_mm, tol)?.translate([0.0, 0.0, z0_mm]);
    let exact = ExactShape::Cylinder {
        radius_mm: r_mm,
        z0_mm,
        z1_mm,
    };
    Ok((solid, exact))
}

/// [`axial_cylinder`] of radius `outer_mm` less its bore of radius `inner_mm` (a ring PCB, a
/// diffuser ring), with its exact shape.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn axial_ring(
    outer_mm: f64,
    inner_mm: f64,
    z0_mm: f64,
    z1_mm: f64,
    tol: ChordTolerance,
) -> Result<(Solid, ExactShape), GeometryError> {
    // the bore passes both faces so that the difference is clean
    let (outer, _) = axial_cylinder(outer_mm, z0_mm, z1_mm, tol)?;
    let (bore, _) = axial_cylinder(inner_mm, z0_mm - 1.0, z1_mm + 1.0, tol)?;
    let exact = ExactShape::Ring {
        outer_radius_mm: outer_mm,
        inner_radius_mm: inner_mm,
        z0_mm,
        z1_mm,
    };
    Ok((outer.difference(&bore)?, exact))
}
