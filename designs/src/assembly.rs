//! The assembled sensor: every part that is printed, cast or bought, in the sensor frame
//! (docs/conventions.md), and the fit check between them.
//!
//! Printed sensor parts (shell, printed skin) come from the kit, turned back from their print
//! pose (`params.T_print_sensor`); cast and sprayed layers are the layer solids with their
//! features; bought items are simple envelopes, named as such: the core (tube or shell), the
//! backing plate, the camera board, the LED ring PCB and the diffuser (R-Tac0 Sec. III-B,
//! Fig. 2; ShadowTac Sec. IV-A).
//!
//! The fit check intersects every pair of members with the boolean kernel. Parts that are
//! designed to touch share a surface, and two tessellations of one surface cross each other
//! by up to the chord tolerance; an overlap counts as an interference when it is thicker than
//! that: its mean thickness (2 x volume / surface area, for a thin slab) passes the chord
//! tolerance and its volume passes [`MIN_OVERLAP_MM3`].

pub use crate::build::AssemblyScope;
use crate::error::{DesignError, GeometryContext, ParamError, ParamErrors};
use crate::geometry::{revolve, ChordTolerance, GeometryError, Solid};
use crate::parts::context::Stack;
use crate::parts::layers::SharedFeatureSolids;
use crate::parts::registry::FAMILIES;
use crate::parts::Part;
pub use crate::parts::{ExactShape, FeatureKey, Member, MemberFeatures, MemberKind};
use crate::schema::{Design, LayerProcess};

/// Roles of kit parts that are part of the sensor besides the section families' own
/// ([`crate::parts::family::Family::SENSOR_PARTS`]); the rest are molds and tooling.
pub const SENSOR_ROLES: [&str; 6] = [
    "shell_collar",
    "shell_tube",
    "shell_base",
    "shell_half",
    "printed_skin",
    "marker_tips",
];

/// Whether a kit part of role `role` is part of the assembled sensor.
fn in_sensor(role: &str) -> bool {
    SENSOR_ROLES.contains(&role) || FAMILIES.iter().any(|f| f.sensor_part(role).is_some())
}

/// The parameter paths that size a printed member of `role`.
fn printed_fix(role: &str) -> Vec<String> {
    if let Some(fix) = FAMILIES.iter().find_map(|f| f.sensor_part(role)) {
        return fix.iter().map(|f| (*f).to_string()).collect();
    }
    match role {
        "printed_skin" | "marker_tips" => vec!["layers".into()],
        _ => vec!["housing".into()],
    }
}

/// Overlaps smaller than this are not interferences, mm^3.
pub const MIN_OVERLAP_MM3: f64 = 1e-3;

/// A bought part's envelope as a member: never nested by the stack.
pub(crate) fn bought(
    name: &str,
    description: String,
    (solid, exact): (Solid, ExactShape),
    fix: &[&str],
) -> Member {
    Member {
        name: name.into(),
        kind: MemberKind::Bought,
        description,
        solid,
        fix: fix.iter().map(|f| (*f).to_string()).collect(),
        nested_by_stack: false,
        features: Default::default(),
        exact: Some(exact),
        material: None,
    }
}

/// A kit part in the sensor frame: its solid moved back by the inverse of
/// `params.T_print_sensor`; `None` when the part records no pose.
pub fn in_sensor_frame(part: &Part) -> Option<Solid> {
    let t = crate::geometry::transform::from_json(part.params.get("T_print_sensor")?)?;
    // rigid: the inverse is (R^T, -R^T t)
    let r = t.matrix().fixed_view::<3, 3>(0, 0).transpose();
    let back = -(r * t.matrix().fixed_view::<3, 1>(0, 3));
    Some(
        part.solid
            .transform(&crate::geometry::transform::with_translation(
                &r,
                back.into(),
            )),
    )
}

/// The members of the assembled sensor that no family gives, in order: printed sensor parts,
/// cast layers (inner to outer), the bought core's and backing plate's envelopes. The
/// families' members follow ([`crate::parts::family::Family::members`]).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn members(
    design: &Design,
    stack: &Stack,
    parts: &[Part],
    tol: ChordTolerance,
) -> Result<Vec<Member>, DesignError> {
    let mut out = printed_members(parts);
    out.extend(unprinted_members(
        design,
        stack,
        tol,
        AssemblyScope::Whole,
        None,
    )?);
    Ok(out)
}

/// The members of [`members`] that do not come from the kit's parts: the cast layers, the
/// core's and the backing's envelopes (what a kit builds alongside its parts); with
/// [`AssemblyScope::FitCheck`] the cast layers are stand-ins
/// ([`MemberFeatures::stand_in_for_layer`]).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn unprinted_members(
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
    scope: AssemblyScope,
    shared: Option<&SharedFeatureSolids>,
) -> Result<Vec<Member>, DesignError> {
    let mut out = Vec::new();
    push_cast_layers(&mut out, design, stack, tol, scope, shared)?;
    push_core(&mut out, design, stack, tol)?;
    push_backing(&mut out, design, tol)?;
    Ok(out)
}

/// The printed sensor parts among `parts` as members, in their order, each turned back into
/// the sensor frame (parts that record no pose are left out); in parallel.
pub fn printed_members(parts: &[Part]) -> Vec<Member> {
    use rayon::prelude::*;
    parts
        .par_iter()
        .filter(|p| in_sensor(&p.role))
        .filter_map(|p| {
            let solid = in_sensor_frame(p)?;
            Some(Member {
                name: p.name.clone(),
                kind: MemberKind::Printed,
                description: p.description.clone(),
                solid,
                fix: printed_fix(&p.role),
                // a printed skin and its tips are made from the same placed features, and a
                // tip's filling gel is their cavity less those features
                nested_by_stack: matches!(p.role.as_str(), "printed_skin" | "marker_tips"),
                features: Default::default(),
                exact: None,
                material: Some(p.material.clone()),
            })
        })
        .collect()
}

/// Pushes onto `out` the cast layers of `stack` (every layer not printed), inner to outer; their
/// solids are made in parallel.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
fn push_cast_layers(
    out: &mut Vec<Member>,
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
    scope: AssemblyScope,
    shared: Option<&SharedFeatureSolids>,
) -> Result<(), DesignError> {
    let si = design.stack_input().sharing(shared);
    // The layers' solids in parallel (each single-threaded, collected in order: the same
    // members whatever the thread count).
    use rayon::prelude::*;
    let cast: Vec<usize> = (0..stack.layers.len())
        .filter(|&i| stack.layers[i].process != LayerProcess::Printed)
        .collect();
    let solids = cast
        .par_iter()
        .map(|&i| {
            let name = &stack.layers[i].name;
            let mut features =
                crate::parts::layers::layer_features(&si, stack, i, tol).part(name)?;
            let solid = match scope {
                AssemblyScope::Whole => crate::parts::layers::layer_solid(&si, stack, i, tol),
                AssemblyScope::FitCheck => {
                    features.stand_in_for_layer = Some(i);
                    crate::parts::layers::layer_stand_in(&si, stack, i, &features, tol)
                }
            }
            .part(name)?;
            Ok((solid, features))
        })
        .collect::<Result<Vec<_>, DesignError>>()?;
    for (&i, (solid, features)) in cast.iter().zip(solids) {
        let l = &stack.layers[i];
        out.push(Member {
            name: l.name.clone(),
            kind: MemberKind::Cast,
            description: format!("{} layer, {:.2} mm", l.name, l.thickness_mm),
            solid,
            fix: vec![format!("layers[{i}]")],
            nested_by_stack: true,
            features,
            exact: Some(ExactShape::Layer {
                params: crate::parts::layers::layer_twin_params(
                    &design.stack_input(),
                    stack,
                    i,
                    tol,
                ),
            }),
            material: Some(l.material.clone()),
        });
    }
    Ok(())
}

/// Pushes onto `out` the bought core's envelope, when the design has a core.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
fn push_core(
    out: &mut Vec<Member>,
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
) -> Result<(), DesignError> {
    let g = |name: &str, r: Result<Solid, crate::geometry::GeometryError>| r.part(name);
    if let (Some(c), Some(spec)) = (&stack.core, &design.core) {
        let pl = crate::parts::core_shell::profile(&design.context(), c, spec, tol);
        let solid = g(
            "core_envelope",
            revolve(&pl, tol).and_then(|m| Solid::from_mesh(&m)),
        )?;
        // the profile polygon revolved (planes, cones, cylinders): OCCT writes it with the same
        // bytes every run; the exact shell (spheres, B-splines) goes to a machined core's own
        // STEP file
        let exact = ExactShape::Revolved {
            profile_rz_mm: pl.points.clone(),
        };
        out.push(Member {
            nested_by_stack: true,
            features: Default::default(),
            material: Some(spec.material.clone()),
            ..bought(
                "core_envelope",
                format!("Core (bought): {}", spec.description),
                (solid, exact),
                &["core.wall_thickness_mm", "core.length_mm"],
            )
        });
    }
    Ok(())
}

/// Pushes onto `out` the backing plate's envelope, when the design has one.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
fn push_backing(
    out: &mut Vec<Member>,
    design: &Design,
    tol: ChordTolerance,
) -> Result<(), DesignError> {
    let Some(b) = &design.backing else {
        return Ok(());
    };
    let zb = design.body.base_z_mm();
    let envelope = crate::parts::axial_cylinder(b.diameter_mm / 2.0, zb - b.thickness_mm, zb, tol)
        .part("backing_envelope")?;
    out.push(Member {
        material: Some(b.material.clone()),
        ..bought(
            "backing_envelope",
            format!("Backing plate (bought): {}", b.description),
            envelope,
            &["backing.diameter_mm", "backing.thickness_mm"],
        )
    });
    Ok(())
}

/// The cast layers' exact solids for the members of `members` that stand in for them
/// ([`MemberFeatures::stand_in_for_layer`]), in parallel; the other members as they are.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn with_exact_layers(
    members: Vec<Member>,
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
) -> Result<Vec<Member>, DesignError> {
    use rayon::prelude::*;
    members
        .into_par_iter()
        .map(|mut m| {
            if let Some(i) = m.features.stand_in_for_layer.take() {
                m.solid = crate::parts::layers::layer_solid(&design.stack_input(), stack, i, tol)
                    .part(&m.name)?;
            }
            Ok(m)
        })
        .collect()
}

/// Two members that overlap.
#[derive(Debug, Clone, PartialEq)]
pub struct Interference {
    pub a: String,
    pub b: String,
    /// Volume of the overlap, mm^3.
    pub volume_mm3: f64,
    /// Mean thickness of the overlap (2 x volume / surface area), mm.
    pub thickness_mm: f64,
    /// The parameter paths of both members.
    pub fix: Vec<String>,
}

/// Every pair of members that overlaps by more than a tessellation can: thicker than
/// `tol` and larger than [`MIN_OVERLAP_MM3`]. Pairs whose boxes do not meet are skipped; a
/// pair that the stack nests ([`Member::nested_by_stack`]) can overlap only inside the features
/// that grow either ([`MemberFeatures`]), and is intersected only there (none: skipped); the
/// rest are intersected whole. In parallel, the result in pair order.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn interferences(
    members: &[Member],
    tol: ChordTolerance,
) -> Result<Vec<Interference>, DesignError> {
    overlaps(members, tol.mm())
}

/// [`interferences`] thicker than `thickness_mm` (0: every overlap larger than
/// [`MIN_OVERLAP_MM3`], whatever its thickness).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn overlaps(members: &[Member], thickness_mm: f64) -> Result<Vec<Interference>, DesignError> {
    use rayon::prelude::*;
    let boxes: Vec<_> = members.iter().map(|m| m.solid.bounding_box()).collect();
    let mut pairs = Vec::new();
    for i in 0..members.len() {
        for j in i + 1..members.len() {
            let (Some(a), Some(b)) = (&boxes[i], &boxes[j]) else {
                continue;
            };
            let apart = (0..3).any(|k| a.max[k] <= b.min[k] || b.max[k] <= a.min[k]);
            let nested = members[i].nested_by_stack && members[j].nested_by_stack;
            let grown =
                !members[i].features.grow.is_empty() || !members[j].features.grow.is_empty();
            if !apart && (!nested || grown) {
                pairs.push((i, j));
            }
        }
    }
    let found: Vec<Option<Interference>> = pairs
        .par_iter()
        .map(|&(i, j)| {
            let (ma, mb) = (&members[i], &members[j]);
            let overlap = if ma.nested_by_stack && mb.nested_by_stack {
                overlap_in_growth(ma, mb)
            } else {
                ma.solid.intersection(&mb.solid).map(Some)
            }
            .part(&format!("fit check {} / {}", ma.name, mb.name))?;
            let Some(overlap) = overlap else {
                return Ok(None);
            };
            let v = overlap.volume();
            let thickness = 2.0 * v / overlap.surface_area().max(f64::MIN_POSITIVE);
            Ok(
                (v > MIN_OVERLAP_MM3 && thickness > thickness_mm).then(|| Interference {
                    a: ma.name.clone(),
                    b: mb.name.clone(),
                    volume_mm3: v,
                    thickness_mm: thickness,
                    // the later member first: the envelopes and layers come after the shell
                    fix: mb.fix.iter().chain(&ma.fix).cloned().collect(),
                }),
            )
        })
        .collect::<Result<_, DesignError>>()?;
    Ok(found.into_iter().flatten().collect())
}

/// The overlap of two nested members: `a` ∩ `b` within the features that grow either (outside
/// them the stack nests the two apart), but for a growing set the other member cuts into
/// itself as the same features ([`MemberFeatures`]); the growth's piece of the other member is
/// cut first (it is small, where the whole members' surfaces coincide over their shared
/// offset). `None` when no growth meets the other member.
fn overlap_in_growth(a: &Member, b: &Member) -> Result<Option<Solid>, GeometryError> {
    let mut pieces = Vec::new();
    for (own, other) in [(a, b), (b, a)] {
        let grow = Solid::compose(
            &own.features
                .grow
                .iter()
                .filter(|(key, _)| !other.features.cut.contains(key))
                .map(|(_, s)| s.clone())
                .collect::<Vec<_>>(),
        );
        let meets = match (grow.bounding_box(), other.solid.bounding_box()) {
            (Some(x), Some(y)) => (0..3).all(|k| x.min[k] < y.max[k] && y.min[k] < x.max[k]),
            _ => false,
        };
        if !meets {
            continue;
        }
        let piece = grow.intersection(&other.solid)?;
        if !piece.is_empty() {
            pieces.push(piece.intersection(&own.solid)?);
        }
    }
    Ok(match pieces.len() {
        0 => None,
        1 => pieces.pop(),
        _ => Some(pieces[0].union(&pieces[1])?),
    })
}

/// [`interferences`] as parameter errors, one per overlapping pair: the path is the first
/// parameter that sizes either part (with its value in `design`), the rule names both parts,
/// the overlap and every parameter that would fix it.
pub fn fit_errors(design: &Design, found: &[Interference]) -> Option<DesignError> {
    overlap_errors(design, found, |f| {
        format!(
            "fit check: `{}` and `{}` overlap by {:.3} mm³ (about {:.3} mm deep); change {}",
            f.a,
            f.b,
            f.volume_mm3,
            f.thickness_mm,
            f.fix.join(" or ")
        )
    })
}

/// Overlaps as parameter errors, one each: the path is the overlap's first `fix` parameter
/// with its value in `design` (`?` when the design has none there), the rule `rule`'s text;
/// `None` when there are none.
pub fn overlap_errors(
    design: &Design,
    found: &[Interference],
    rule: impl Fn(&Interference) -> String,
) -> Option<DesignError> {
    if found.is_empty() {
        return None;
    }
    let json = serde_json::to_value(design).unwrap_or_default();
    Some(DesignError::Params(ParamErrors(
        found
            .iter()
            .map(|f| {
                let path = f.fix.first().cloned().unwrap_or_default();
                let value = crate::schema::value_at(&mut json.clone(), &path)
                    .map_or_else(|| "?".to_string(), |v| v.to_string());
                ParamError::new(path, value, rule(f))
            })
            .collect(),
    )))
}
