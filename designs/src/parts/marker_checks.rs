//! The rules of the markers on each layer ([`check_markers`]): their shapes, sizes and layout
//! against the layer's thickness, its printer profile and the layers and coats around it, and
//! which printers can form them ([`printable_with`]).

use crate::error::ParamError;
use crate::markers::{self, MarkerSpec, MarkerSurface, Polarity, Surface};
use crate::parts::context::ResolvedLayer;
use crate::parts::layer_markers::{
    direction, feature_end_centres, feature_technology, formed_on_stack_layer, max_inward_reach,
    recess_clearance_to_base_mm, rim_margin, surface_offset,
};
use crate::parts::stack_input::StackInput;
use crate::schema::{LayerProcess, PrinterProfile, Technology};

/// Rules on marker patterns: they place, do not overlap, leave the printer's minimum wall,
/// and their features print on the technology that makes them (the mold's cavity printer for
/// a cast layer, the layer's own for a printed one).
pub fn check_markers(si: &StackInput<'_>, layers: &[ResolvedLayer], errs: &mut Vec<ParamError>) {
    for l in layers {
        let tech = feature_technology(si, &si.layers[l.index]);
        let own = marker_errors(si, l, tech);
        let clean = own.is_empty();
        errs.extend(own);
        if clean {
            coat_former_errors(si, layers, l, errs);
        }
    }
}

/// How far the cavity of the mold that casts layer `l` lies beyond the layer's outer surface,
/// mm: the coats sprayed into it before the pour ([`crate::parts::molds::cast_plans`]) plus
/// the mold's clearance; 0 for a layer not cast in a `direct` or `master` mold (the other
/// strategies form the layer's outer surface itself).
pub fn cavity_gap_mm(si: &StackInput<'_>, layers: &[ResolvedLayer], l: &ResolvedLayer) -> f64 {
    if l.process != LayerProcess::Cast || !l.mold_strategy.holds_core() {
        return 0.0;
    }
    let outer = layers[l.index + 1..]
        .iter()
        .take_while(|s| s.process == LayerProcess::Sprayed)
        .last()
        .map_or(l.outer_offset_mm, |s| s.outer_offset_mm);
    outer + si.mold.cavity_clearance_mm - l.outer_offset_mm
}

/// A dimple on the outer surface of a cast layer under sprayed coats is formed by a pin in the
/// mold's cavity that the coats cover: the pin is the dimple shrunk by the coats' thickness
/// all round ([`PlacedMarkers::conformal`]), and it must be a feature the cavity's printer
/// makes. A dimple of up to twice the coats' thickness is filled by the coat.
fn coat_former_errors(
    si: &StackInput<'_>,
    layers: &[ResolvedLayer],
    l: &ResolvedLayer,
    errs: &mut Vec<ParamError>,
) {
    // Bumps on a layer that the next layer is cast onto stand into that layer: they must
    // leave its printer's minimum wall of it over them (else they show through its surface).
    if let Some(next) = layers
        .get(l.index + 1)
        .filter(|n| n.process == LayerProcess::Cast && formed_on_stack_layer(n))
    {
        let min_wall = si
            .ctx
            .printers
            .get(si.mold.cavity_print_technology)
            .min_wall_mm;
        for (j, spec) in si.layers[l.index].markers.iter().enumerate() {
            let f = &spec.feature;
            if spec.surface == MarkerSurface::Outer
                && f.side() == Polarity::Raised
                && f.height_mm > next.thickness_mm - min_wall
            {
                errs.push(ParamError::new(
                    format!("layers[{}].markers[{j}].feature.height_mm", l.index),
                    f.height_mm,
                    format!(
                        "the bumps stand into layer '{}' cast over them ({:.3} mm thick) and would leave less than the minimum wall {min_wall} mm of it; give at most {:.3} mm, or put them on the outer surface of '{}'",
                        next.name,
                        next.thickness_mm,
                        next.thickness_mm - min_wall,
                        next.name
                    ),
                ));
            }
        }
    }
    let t = cavity_gap_mm(si, layers, l);
    if t <= 0.0 {
        return;
    }
    let tech = si.mold.cavity_print_technology;
    let min = si.ctx.printers.get(tech).min_feature_mm;
    let coats: Vec<&str> = layers[l.index + 1..]
        .iter()
        .take_while(|s| s.process == LayerProcess::Sprayed)
        .map(|s| s.name.as_str())
        .collect();
    for (j, spec) in si.layers[l.index].markers.iter().enumerate() {
        if spec.surface != MarkerSurface::Outer || spec.feature.side() != Polarity::Recessed {
            continue;
        }
        let former = spec.feature.diameter_mm - 2.0 * t;
        if former < min {
            errs.push(ParamError::new(
                format!("layers[{}].markers[{j}].feature.diameter_mm", l.index),
                spec.feature.diameter_mm,
                format!(
                    "the {t:.3} mm sprayed into the mold over layer '{}' ({}{}) covers the pin that forms each dimple: the pin is {former:.3} mm across, below the minimum feature {min} mm of printer profile '{}' that prints the mold (a coat fills a dimple of up to twice its thickness); give at least {:.3} mm, or put the markers on a surface no coat covers",
                    l.name,
                    coats.join(", "),
                    if si.mold.cavity_clearance_mm > 0.0 { " and the cavity clearance" } else { "" },
                    format!("{tech:?}").to_lowercase(),
                    min + 2.0 * t
                ),
            ));
        }
    }
}

/// The technologies that could make the features of marker pattern `j` of layer `l`: those
/// for which [`marker_errors`], the rules that validate the design, report nothing on that
/// pattern (nor on the layer's markers as a whole).
pub fn printable_with(si: &StackInput<'_>, l: &ResolvedLayer, j: usize) -> Vec<Technology> {
    let own = format!("layers[{}].markers[{j}]", l.index);
    let shared = format!("layers[{}].markers", l.index);
    [Technology::Fdm, Technology::Sla, Technology::Polyjet]
        .into_iter()
        .filter(|&t| {
            marker_errors(si, l, t).iter().all(|e| {
                !(e.path == own || e.path.starts_with(&format!("{own}.")) || e.path == shared)
            })
        })
        .collect()
}

/// What the printer checks of one marker set see: the stack, its layer `l`, the printer
/// profile that makes its features (named `tech_name`), the set's path
/// (`layers[i].markers[j]`) and the set itself.
#[derive(Clone, Copy)]
struct MarkerCheck<'a> {
    si: &'a StackInput<'a>,
    l: &'a ResolvedLayer,
    profile: &'a PrinterProfile,
    tech_name: &'a str,
    path: &'a str,
    spec: &'a MarkerSpec,
}

/// Every violation of the marker rules of layer `l` when its features are made by printer
/// technology `tech` (its profile's minimum wall, hole and feature, and the rim margin that
/// follows from them). [`check_markers`] applies it with the layer's own technology,
/// [`printable_with`] with each.
pub fn marker_errors(si: &StackInput<'_>, l: &ResolvedLayer, tech: Technology) -> Vec<ParamError> {
    let mut errs = Vec::new();
    let spec_layer = &si.layers[l.index];
    let tech_name = format!("{tech:?}").to_lowercase();
    let profile = si.ctx.printers.get(tech);
    for (j, spec) in spec_layer.markers.iter().enumerate() {
        let path = format!("layers[{}].markers[{j}]", l.index);
        if !marker_shape_errors(si, l, &path, spec, &mut errs) {
            continue;
        }
        let check = MarkerCheck {
            si,
            l,
            profile,
            tech_name: &tech_name,
            path: &path,
            spec,
        };
        if !marker_size_errors(&check, &mut errs) {
            continue;
        }
        marker_layout_errors(&check, &mut errs);
    }
    // Recesses from both surfaces of a shell must leave the minimum wall between them.
    if !l.solid {
        let depth = |surface: MarkerSurface| {
            spec_layer
                .markers
                .iter()
                .filter(|m| m.surface == surface && m.feature.side() == Polarity::Recessed)
                .map(|m| m.feature.height_mm)
                .fold(0.0, f64::max)
        };
        let (o, i) = (depth(MarkerSurface::Outer), depth(MarkerSurface::Inner));
        if o > 0.0 && i > 0.0 && o + i > l.thickness_mm - profile.min_wall_mm {
            errs.push(ParamError::new(
                    format!("layers[{}].markers", l.index),
                    format!("recesses {o} mm (outer) + {i} mm (inner)"),
                    format!(
                        "together cut through the {:.3} mm layer '{}' or leave less than the minimum wall {} mm of printer profile '{tech_name}'",
                        l.thickness_mm, l.name, profile.min_wall_mm
                    ),
                ));
        }
    }
    errs
}

/// The checks of marker set `spec` (at `path`) of layer `l` that do not depend on the printer:
/// the feature's diameter and height, exactly one of `on_skin` and `polarity`, the surface
/// (no inner surface on a solid layer; on a cast layer only with the `boundary` strategy), the
/// reach of inward features, and `tip_material` only with raised features on a printed layer.
/// Pushes its errors to `errs`; false when the checks that follow no longer apply.
fn marker_shape_errors(
    si: &StackInput<'_>,
    l: &ResolvedLayer,
    path: &str,
    spec: &MarkerSpec,
    errs: &mut Vec<ParamError>,
) -> bool {
    let spec_layer = &si.layers[l.index];
    let f = &spec.feature;
    if !(f.diameter_mm > 0.0 && f.diameter_mm.is_finite()) {
        errs.push(ParamError::new(
            format!("{path}.feature.diameter_mm"),
            f.diameter_mm,
            "must be above 0",
        ));
        return false;
    }
    if !(f.height_mm >= f.diameter_mm / 2.0 && f.height_mm.is_finite()) {
        errs.push(ParamError::new(
            format!("{path}.feature.height_mm"),
            f.height_mm,
            format!(
                "must be at least the radius {} mm (a cylinder ending in a hemisphere)",
                f.diameter_mm / 2.0
            ),
        ));
        return false;
    }
    if let (Some(_), Some(_)) | (None, None) = (f.polarity, f.on_skin) {
        errs.push(ParamError::new(
            format!("{path}.feature"),
            match (f.polarity, f.on_skin) {
                (Some(p), Some(s)) => format!("polarity: {p:?}, on_skin: {s:?}").to_lowercase(),
                _ => "neither on_skin nor polarity".to_string(),
            },
            "give exactly one of on_skin (dimple | bump) and polarity (raised | recessed)",
        ));
        return false;
    }
    if spec_layer.process == LayerProcess::Sprayed {
        let under = (0..l.index)
            .rev()
            .find(|&k| si.layers[k].process != LayerProcess::Sprayed);
        errs.push(ParamError::new(
            path.to_string(),
            format!("{} markers on sprayed layer '{}'", markers::layout_name(spec.pattern.layout), l.name),
            match under {
                Some(k) => format!(
                    "a sprayed coat follows the surface it is sprayed onto and forms no features of its own; put them on layers[{k}].markers with surface: outer (layer '{}' under the coat): its mold carries them through the coat",
                    si.layers[k].name
                ),
                None => "a sprayed coat follows the surface it is sprayed onto and forms no features of its own".to_string(),
            },
        ));
        return false;
    }
    if l.solid && spec.surface == MarkerSurface::Inner {
        errs.push(ParamError::new(
            format!("{path}.surface"),
            "inner",
            "a solid layer has no inner surface",
        ));
        return false;
    }
    let molded = spec_layer.process == LayerProcess::Cast;
    if molded && spec.surface == MarkerSurface::Inner && !l.mold_strategy.forms_inner_surface() {
        errs.push(ParamError::new(
                format!("{path}.surface"),
                "inner",
                format!(
                    "features on the inner surface of a cast layer need the boundary strategy (its mold strategy is {:?}): {}",
                    l.mold_strategy,
                    match l.index.checked_sub(1) {
                        Some(k) => format!(
                            "the layer is cast onto layer '{}', whose mold forms this surface; put them on layers[{k}].markers with surface: outer and the opposite polarity",
                            si.layers[k].name
                        ),
                        None => "the core forms this surface and no mold touches it; put them on the outer surface".to_string(),
                    }
                ),
            ));
        return false;
    }
    // Features pointing inward must end before the body's centre of curvature: past it
    // they cross each other and the axis (the offset surface at their ends folds).
    let off = surface_offset(l, spec.surface);
    if direction(spec) < 0.0 && !si.ctx.body.offset_is_valid(off - f.height_mm) {
        errs.push(ParamError::new(
            format!("{path}.feature.height_mm"),
            f.height_mm,
            format!(
                "must be below {:.3} mm: the features point inward from the {} surface (offset {off:.3} mm) and must end before the body's centre of curvature, its axis and its base plane",
                max_inward_reach(si, off),
                match spec.surface {
                    MarkerSurface::Outer => "outer",
                    MarkerSurface::Inner => "inner",
                }
            ),
        ));
        return false;
    }
    if spec.tip_material.is_some()
        && (spec_layer.process != LayerProcess::Printed || f.side() != Polarity::Raised)
    {
        errs.push(ParamError::new(
            format!("{path}.tip_material"),
            spec.tip_material.clone().unwrap_or_default(),
            "separate tips need raised features on a printed layer",
        ));
    }
    true
}

/// The printer checks of the feature size of marker set `spec` (at `path`) of layer `l`
/// made with printer profile `profile` (named `tech_name`): the diameter at least its minimum
/// feature (or, for a hole in the part or its mold, its minimum hole), a recess into a shell
/// leaving its minimum wall, then the fields of the pattern. Pushes its errors to `errs`;
/// false when the checks that follow no longer apply.
fn marker_size_errors(c: &MarkerCheck<'_>, errs: &mut Vec<ParamError>) -> bool {
    let MarkerCheck {
        si,
        l,
        profile,
        tech_name,
        path,
        spec,
    } = *c;
    let f = &spec.feature;
    let molded = si.layers[l.index].process == LayerProcess::Cast;
    // Printability: in a mold, a raised feature is a hole and a recessed one a bump.
    let (what, min) = match (molded, f.side()) {
        (true, Polarity::Raised) | (false, Polarity::Recessed) => {
            ("minimum hole", profile.min_hole_diameter_mm)
        }
        _ => ("minimum feature", profile.min_feature_mm),
    };
    if f.diameter_mm < min {
        errs.push(ParamError::new(
            format!("{path}.feature.diameter_mm"),
            f.diameter_mm,
            format!(
                "below the {what} {min} mm of printer profile '{tech_name}' that {} this layer",
                if molded {
                    "prints the mold of"
                } else {
                    "prints"
                }
            ),
        ));
        return false;
    }
    // A feature cut into a shell layer must leave its minimum wall behind it.
    let cut_in = f.side() == Polarity::Recessed;
    if cut_in && !l.solid && f.height_mm > l.thickness_mm - profile.min_wall_mm {
        errs.push(ParamError::new(
                format!("{path}.feature.height_mm"),
                f.height_mm,
                format!(
                    "cuts {} mm into a {:.3} mm layer, leaving less than the minimum wall {} mm of printer profile '{tech_name}'",
                    f.height_mm, l.thickness_mm, profile.min_wall_mm
                ),
            ));
        return false;
    }
    let field_errs = spec.pattern.field_errors();
    if !field_errs.is_empty() {
        for (field, value, rule) in field_errs {
            errs.push(ParamError::new(
                format!("{path}.pattern.{field}"),
                value,
                rule,
            ));
        }
        return false;
    }
    true
}

/// The checks of the placement of marker set `spec` (at `path`) of layer `l` made with
/// printer profile `profile` (named `tech_name`): the pattern places at least one marker
/// (every point of a point list that cannot be placed is reported), neighbouring features
/// leave its minimum wall between them at their bases and, when they converge, at their
/// ends, and recesses into a solid layer leave its minimum wall above the base plane.
/// Pushes its errors to `errs`.
fn marker_layout_errors(c: &MarkerCheck<'_>, errs: &mut Vec<ParamError>) {
    let MarkerCheck {
        si,
        l,
        profile,
        tech_name,
        path,
        spec,
    } = *c;
    let f = &spec.feature;
    let surface = Surface::new(si.ctx.body, surface_offset(l, spec.surface));
    let margin = rim_margin(spec, profile.min_wall_mm);
    let placed = match markers::place(&surface, &spec.pattern, margin) {
        Ok(m) => m,
        Err(first) => {
            // a point list reports every point that cannot be placed
            let all = if first.0.starts_with("points[") {
                markers::point_errors(&surface, &spec.pattern, margin)
            } else {
                vec![first]
            };
            for (field, value, rule) in all {
                errs.push(ParamError::new(
                    format!("{path}.pattern.{field}"),
                    value,
                    rule,
                ));
            }
            return;
        }
    };
    if placed.is_empty() {
        errs.push(ParamError::new(
            format!("{path}.pattern"),
            "0 markers",
            "places no marker",
        ));
        return;
    }
    let st = markers::stats(&surface, &placed);
    let gap = st.min_spacing_mm - f.diameter_mm;
    if placed.len() > 1 && gap < profile.min_wall_mm {
        let (a, b) = st.closest_pair.unwrap_or((0, 0));
        errs.push(ParamError::new(
                format!("{path}.pattern"),
                markers::layout_name(spec.pattern.layout),
                format!(
                    "markers {a} and {b} are {:.3} mm apart on the surface: features of {} mm {} (wall {:.3} mm, minimum {} mm of printer profile '{tech_name}')",
                    st.min_spacing_mm,
                    f.diameter_mm,
                    if gap < 0.0 { "overlap" } else { "leave too thin a wall" },
                    gap,
                    profile.min_wall_mm
                ),
            ));
        return;
    }
    // Features that converge (pointing into a concave side) must stay apart at their
    // ends too: the hemisphere centres keep the same clearance as the bases.
    let ends = feature_end_centres(&placed, f, direction(spec));
    if ends.len() > 1 {
        let nn = markers::nearest_neighbours(&ends);
        if let Some((a, (b, d))) = nn.iter().enumerate().min_by(|x, y| {
            x.1 .1
                .partial_cmp(&y.1 .1)
                .unwrap_or(std::cmp::Ordering::Equal)
        }) {
            if d - f.diameter_mm < profile.min_wall_mm {
                errs.push(ParamError::new(
                        format!("{path}.feature.height_mm"),
                        f.height_mm,
                        format!(
                            "features {a} and {b} converge: their ends are {d:.3} mm apart, closer than the diameter {} mm plus the minimum wall {} mm of printer profile '{tech_name}'",
                            f.diameter_mm, profile.min_wall_mm
                        ),
                    ));
                return;
            }
        }
    }
    // A recess into a solid layer must not cut through its flat base.
    if l.solid && f.side() == Polarity::Recessed {
        let worst = recess_clearance_to_base_mm(&placed, f, si.ctx.body.base_z_mm());
        if worst < profile.min_wall_mm {
            errs.push(ParamError::new(
                    format!("{path}.feature.height_mm"),
                    f.height_mm,
                    format!(
                        "recesses reach within {worst:.3} mm of the base plane, below the minimum wall {} mm of printer profile '{tech_name}'",
                        profile.min_wall_mm
                    ),
                ));
        }
    }
}
