//! Layer solids with their marker features, the checks on marker patterns, and the parts of
//! the `open` and `boundary` mold strategies and of printed layers.
//!
//! A layer's solid is the solid enclosed by its outer boundary minus the solid enclosed by its
//! inner boundary. A boundary's enclosed solid gains the features that point outward from it
//! and loses those that point inward; a raised feature on an outer surface points outward, on
//! an inner surface inward. The same feature solid thus makes a slot in one layer and the
//! protrusion that fills it in the next (UVDtact Sec. III).

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use crate::markers::{self, Marker, MarkerSpec, MarkerSurface, PatternStats, Polarity, Surface};
use crate::parts::context::{ResolvedLayer, Stack};
use crate::parts::family::FamilyInput;
use crate::parts::layer_feature::{solid_layer_profile, InsertInput};
use crate::parts::layer_registry::{open_mold_inserts, seat_of};
use crate::parts::member::{FeatureKey, MemberFeatures};
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::{Part, PrintTechnology};
use crate::schema::{Design, LayerProcess, MoldStrategy, PrinterProfile, Technology};
use crate::values::MAX_LENGTH_MM;
use serde_json::json;

/// Markers placed on one surface of a layer.
#[derive(Debug, Clone)]
pub struct PlacedMarkers {
    pub spec: MarkerSpec,
    pub markers: Vec<Marker>,
    pub stats: PatternStats,
    /// Offset of the carrying surface, mm.
    pub offset_mm: f64,
    /// +1 when features point outward from the surface (along its normal), -1 inward.
    pub direction: f64,
    /// Depth behind the surface the feature solids reach, mm.
    pub embed_mm: f64,
    /// How far the carrying surface lies beyond the surface the features were designed on,
    /// mm: 0 for a layer's own features; for the features a sprayed coat (or the cavity it is
    /// sprayed into) takes from the cast layer under it, the coats' thickness between, and the
    /// features are that much larger all round ([`markers::local_feature_dilated`]).
    pub dilation_mm: f64,
}

impl PlacedMarkers {
    /// The same features seen from the offset surface `t_mm` beyond this one, grown by
    /// `t_mm` all round: what a conformal coat of thickness `t_mm` over this surface carries
    /// on its outer face, and what the mold cavity that forms the coat must carry
    /// ([`markers::local_feature_dilated`]). Positions move `t_mm` along their normals.
    pub fn conformal(&self, t_mm: f64) -> PlacedMarkers {
        let mut out = self.clone();
        for m in &mut out.markers {
            for k in 0..3 {
                m.position_mm[k] += t_mm * m.normal[k];
            }
        }
        out.offset_mm += t_mm;
        out.dilation_mm += t_mm;
        // The embedding covers the gap between the tangent plane and the surface over the
        // base disc (second order in the radius, markers::embed_depth_mm): scaled with the
        // radius it grows to, and reaching back to the surface the features were designed on.
        let r = self.spec.feature.radius_mm();
        let grown = (self.radius_mm() + t_mm * self.direction.max(0.0)) / r;
        out.embed_mm = self.embed_mm * grown.powi(2).max(1.0) + t_mm;
        out
    }

    /// The features' radius on this surface, mm: the designed radius grown (raised) or shrunk
    /// (recessed) by [`Self::dilation_mm`].
    pub fn radius_mm(&self) -> f64 {
        self.spec.feature.radius_mm() + self.direction * self.dilation_mm
    }
}

fn surface_offset(l: &ResolvedLayer, s: MarkerSurface) -> f64 {
    match s {
        MarkerSurface::Outer => l.outer_offset_mm,
        MarkerSurface::Inner => l.inner_offset_mm,
    }
}

fn direction(spec: &MarkerSpec) -> f64 {
    match (spec.surface, spec.feature.side()) {
        (MarkerSurface::Outer, Polarity::Raised) | (MarkerSurface::Inner, Polarity::Recessed) => {
            1.0
        }
        _ => -1.0,
    }
}

/// The print technology that makes the surface carrying a layer's features.
pub(crate) fn feature_technology(design: &Design, layer: &crate::schema::Layer) -> Technology {
    match layer.process {
        LayerProcess::Printed => layer.print_technology.unwrap_or(Technology::Polyjet),
        _ => design.mold.cavity_print_technology,
    }
}

/// How far inward from the offset surface at `off` a feature may reach before the offset
/// surface at its end stops being valid ([`crate::profile::BodyProfile::offset_is_valid`]), mm
/// (bisection; 0 when the surface itself is not valid).
fn max_inward_reach(design: &Design, off: f64) -> f64 {
    let body = &design.body;
    if !body.offset_is_valid(off) {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, MAX_LENGTH_MM);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if body.offset_is_valid(off - mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The rim margin of a pattern: one feature diameter plus the printer's minimum wall.
fn rim_margin(spec: &MarkerSpec, min_wall: f64) -> f64 {
    spec.feature.diameter_mm + min_wall
}

/// Every pattern of `layer` that places (a pattern that does not is the validation's to
/// report): the spec, its surface offset, the surface and the markers.
pub(crate) fn placed_patterns<'a>(
    design: &'a Design,
    layer: &ResolvedLayer,
) -> Vec<(&'a MarkerSpec, f64, Surface, Vec<markers::Marker>)> {
    let spec_layer = &design.layers[layer.index];
    let profile = design.printers.get(feature_technology(design, spec_layer));
    spec_layer
        .markers
        .iter()
        .filter_map(|spec| {
            let offset = surface_offset(layer, spec.surface);
            let surface = Surface::new(&design.body, offset);
            let markers = markers::place(
                &surface,
                &spec.pattern,
                rim_margin(spec, profile.min_wall_mm),
            )
            .ok()?;
            Some((spec, offset, surface, markers))
        })
        .collect()
}

/// Places every marker pattern of layer `i`.
pub fn place_layer_markers(
    design: &Design,
    layer: &ResolvedLayer,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    placed_patterns(design, layer)
        .into_iter()
        .map(|(spec, offset, surface, markers)| {
            let stats = markers::stats(&surface, &markers);
            let max_k = (0..=64)
                .map(|i| {
                    let (a, b) = surface.curvatures_at(surface.total_arc_mm() * i as f64 / 64.0);
                    a.abs().max(b.abs())
                })
                .fold(0.0, f64::max);
            PlacedMarkers {
                spec: spec.clone(),
                markers,
                stats,
                offset_mm: offset,
                direction: direction(spec),
                embed_mm: markers::embed_depth_mm(&spec.feature, max_k, tol),
                dilation_mm: 0.0,
            }
        })
        .collect()
}

/// Whether layer `i` is formed against the layers under it: a sprayed coat (sprayed into the
/// mold of the layer under it) or a layer cast in a `direct` or `master` mold onto the core and
/// the layers already on it. Its inner surface is then the outer surface of layer `i - 1` as
/// the stack formed it ([`formed_outer_features`]).
fn formed_on_stack(stack: &Stack, i: usize) -> bool {
    i > 0 && formed_on_stack_layer(&stack.layers[i])
}

/// [`formed_on_stack`] for a layer that has one under it.
fn formed_on_stack_layer(l: &ResolvedLayer) -> bool {
    l.process == LayerProcess::Sprayed
        || (l.process == LayerProcess::Cast
            && matches!(l.mold_strategy, MoldStrategy::Direct | MoldStrategy::Master))
}

/// The features on the outer surface of layer `i` as the stack forms them: its own, and for
/// a sprayed coat those of the layer under it, grown by the coat's thickness
/// ([`PlacedMarkers::conformal`]: the coat takes the shape of the cavity it is sprayed into).
pub fn formed_outer_features(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    let l = &stack.layers[i];
    let mut own: Vec<PlacedMarkers> = place_layer_markers(design, l, tol)
        .into_iter()
        .filter(|p| p.spec.surface == MarkerSurface::Outer)
        .collect();
    if l.process == LayerProcess::Sprayed && i > 0 {
        let under = &stack.layers[i - 1];
        own.extend(
            formed_outer_features(design, stack, i - 1, tol)
                .iter()
                .map(|p| p.conformal(l.outer_offset_mm - under.outer_offset_mm)),
        );
    }
    own
}

/// The features layer `i` takes from the layers under it when it is formed against them
/// (`formed_on_stack`): on its inner surface, the outer features of layer `i - 1` as the stack
/// formed them; on the outer surface of a sprayed coat, the same grown by its thickness.
/// (outer sets, inner sets); both empty for a layer formed by molds of its own.
pub fn taken_features(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> (Vec<PlacedMarkers>, Vec<PlacedMarkers>) {
    if !formed_on_stack(stack, i) {
        return (Vec::new(), Vec::new());
    }
    let (l, under) = (&stack.layers[i], &stack.layers[i - 1]);
    let below = formed_outer_features(design, stack, i - 1, tol);
    let at = |offset_mm: f64| -> Vec<PlacedMarkers> {
        below
            .iter()
            .map(|p| p.conformal(offset_mm - under.outer_offset_mm))
            .collect()
    };
    let outer = if l.process == LayerProcess::Sprayed {
        at(l.outer_offset_mm)
    } else {
        Vec::new()
    };
    (outer, at(l.inner_offset_mm))
}

/// How many meshes besides layer `i` itself carry its outer features: the cavity of its
/// `direct` or `master` mold, each face of the coats sprayed over it, and the layer cast onto
/// it (or onto those coats) in a `direct` or `master` mold (`formed_on_stack`).
pub fn outer_feature_copies(stack: &Stack, i: usize) -> usize {
    let l = &stack.layers[i];
    let mut copies = usize::from(
        l.process == LayerProcess::Cast
            && matches!(l.mold_strategy, MoldStrategy::Direct | MoldStrategy::Master),
    );
    for above in &stack.layers[i + 1..] {
        if above.process == LayerProcess::Sprayed {
            copies += 2;
        } else {
            copies += usize::from(formed_on_stack_layer(above));
            break;
        }
    }
    copies
}

/// The features the cavity of cast layer `i`'s mold carries when the cavity is the offset
/// surface `cavity_offset_mm` (the outermost coat sprayed into it, plus the mold's clearance):
/// the layer's outer-surface features grown by the distance between
/// ([`PlacedMarkers::conformal`]), so that the coats sprayed into the cavity and the layer
/// poured behind them take the designed features. Sensor frame, mm.
/// (A sprayed coat's own markers are refused: [`check_markers`].)
pub fn cavity_features(
    design: &Design,
    stack: &Stack,
    i: usize,
    cavity_offset_mm: f64,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(design, l, tol);
    on_surface(&placed, MarkerSurface::Outer)
        .into_iter()
        .map(|p| p.conformal(cavity_offset_mm - l.outer_offset_mm))
        .collect()
}

/// The placed patterns that sit on `surface`.
fn on_surface(placed: &[PlacedMarkers], surface: MarkerSurface) -> Vec<&PlacedMarkers> {
    placed
        .iter()
        .filter(|p| p.spec.surface == surface)
        .collect()
}

/// Centres of the features' end hemispheres, sensor frame, mm: each marker's position moved
/// (height - radius) along its normal, outward for `dir` = +1, inward for -1. The wall between
/// converging features is their distance minus the diameter.
pub fn feature_end_centres(
    markers: &[Marker],
    f: &markers::FeatureShape,
    dir: f64,
) -> Vec<[f64; 3]> {
    let h = f.height_mm - f.radius_mm();
    markers
        .iter()
        .map(|m| [0, 1, 2].map(|k| m.position_mm[k] + dir * h * m.normal[k]))
        .collect()
}

/// The least material left between inward recesses of a solid layer and its base plane at
/// `base_z_mm`, mm: the lowest point of each recess (its depth along the normal plus the
/// cylinder's radius sideways) above the plane.
pub fn recess_clearance_to_base_mm(
    markers: &[Marker],
    f: &markers::FeatureShape,
    base_z_mm: f64,
) -> f64 {
    markers
        .iter()
        .map(|m| {
            let side = (1.0 - m.normal[2] * m.normal[2]).max(0.0).sqrt() * f.radius_mm();
            m.position_mm[2] - f.height_mm * m.normal[2] - side - base_z_mm
        })
        .fold(f64::INFINITY, f64::min)
}

/// Rules on marker patterns: they place, do not overlap, leave the printer's minimum wall,
/// and their features print on the technology that makes them (the mold's cavity printer for
/// a cast layer, the layer's own for a printed one).
pub fn check_markers(design: &Design, layers: &[ResolvedLayer], errs: &mut Vec<ParamError>) {
    for l in layers {
        let tech = feature_technology(design, &design.layers[l.index]);
        let own = marker_errors(design, l, tech);
        let clean = own.is_empty();
        errs.extend(own);
        if clean {
            coat_former_errors(design, layers, l, errs);
        }
    }
}

/// How far the cavity of the mold that casts layer `l` lies beyond the layer's outer surface,
/// mm: the coats sprayed into it before the pour ([`crate::parts::molds::cast_plans`]) plus
/// the mold's clearance; 0 for a layer not cast in a `direct` or `master` mold (the other
/// strategies form the layer's outer surface itself).
pub fn cavity_gap_mm(design: &Design, layers: &[ResolvedLayer], l: &ResolvedLayer) -> f64 {
    if l.process != LayerProcess::Cast
        || !matches!(l.mold_strategy, MoldStrategy::Direct | MoldStrategy::Master)
    {
        return 0.0;
    }
    let outer = layers[l.index + 1..]
        .iter()
        .take_while(|s| s.process == LayerProcess::Sprayed)
        .last()
        .map_or(l.outer_offset_mm, |s| s.outer_offset_mm);
    outer + design.mold.cavity_clearance_mm - l.outer_offset_mm
}

/// A dimple on the outer surface of a cast layer under sprayed coats is formed by a pin in the
/// mold's cavity that the coats cover: the pin is the dimple shrunk by the coats' thickness
/// all round ([`PlacedMarkers::conformal`]), and it must be a feature the cavity's printer
/// makes. A dimple of up to twice the coats' thickness is filled by the coat.
fn coat_former_errors(
    design: &Design,
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
        let min_wall = design
            .printers
            .get(design.mold.cavity_print_technology)
            .min_wall_mm;
        for (j, spec) in design.layers[l.index].markers.iter().enumerate() {
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
    let t = cavity_gap_mm(design, layers, l);
    if t <= 0.0 {
        return;
    }
    let tech = design.mold.cavity_print_technology;
    let min = design.printers.get(tech).min_feature_mm;
    let coats: Vec<&str> = layers[l.index + 1..]
        .iter()
        .take_while(|s| s.process == LayerProcess::Sprayed)
        .map(|s| s.name.as_str())
        .collect();
    for (j, spec) in design.layers[l.index].markers.iter().enumerate() {
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
                    if design.mold.cavity_clearance_mm > 0.0 { " and the cavity clearance" } else { "" },
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
pub fn printable_with(design: &Design, l: &ResolvedLayer, j: usize) -> Vec<Technology> {
    let own = format!("layers[{}].markers[{j}]", l.index);
    let shared = format!("layers[{}].markers", l.index);
    [Technology::Fdm, Technology::Sla, Technology::Polyjet]
        .into_iter()
        .filter(|&t| {
            marker_errors(design, l, t).iter().all(|e| {
                !(e.path == own || e.path.starts_with(&format!("{own}.")) || e.path == shared)
            })
        })
        .collect()
}

/// Every violation of the marker rules of layer `l` when its features are made by printer
/// technology `tech` (its profile's minimum wall, hole and feature, and the rim margin that
/// follows from them). [`check_markers`] applies it with the layer's own technology,
/// [`printable_with`] with each.
pub fn marker_errors(design: &Design, l: &ResolvedLayer, tech: Technology) -> Vec<ParamError> {
    let mut errs = Vec::new();
    let spec_layer = &design.layers[l.index];
    let tech_name = format!("{tech:?}").to_lowercase();
    let profile = design.printers.get(tech);
    for (j, spec) in spec_layer.markers.iter().enumerate() {
        let path = format!("layers[{}].markers[{j}]", l.index);
        if !marker_shape_errors(design, l, &path, spec, &mut errs) {
            continue;
        }
        if !marker_size_errors(design, l, profile, &tech_name, &path, spec, &mut errs) {
            continue;
        }
        marker_layout_errors(design, l, profile, &tech_name, &path, spec, &mut errs);
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
    design: &Design,
    l: &ResolvedLayer,
    path: &str,
    spec: &MarkerSpec,
    errs: &mut Vec<ParamError>,
) -> bool {
    let spec_layer = &design.layers[l.index];
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
            .find(|&k| design.layers[k].process != LayerProcess::Sprayed);
        errs.push(ParamError::new(
            path.to_string(),
            format!("{} markers on sprayed layer '{}'", markers::layout_name(spec.pattern.layout), l.name),
            match under {
                Some(k) => format!(
                    "a sprayed coat follows the surface it is sprayed onto and forms no features of its own; put them on layers[{k}].markers with surface: outer (layer '{}' under the coat): its mold carries them through the coat",
                    design.layers[k].name
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
    if molded && spec.surface == MarkerSurface::Inner && l.mold_strategy != MoldStrategy::Boundary {
        errs.push(ParamError::new(
                format!("{path}.surface"),
                "inner",
                format!(
                    "features on the inner surface of a cast layer need the boundary strategy (its mold strategy is {:?}): {}",
                    l.mold_strategy,
                    match l.index.checked_sub(1) {
                        Some(k) => format!(
                            "the layer is cast onto layer '{}', whose mold forms this surface; put them on layers[{k}].markers with surface: outer and the opposite polarity",
                            design.layers[k].name
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
    if direction(spec) < 0.0 && !design.body.offset_is_valid(off - f.height_mm) {
        errs.push(ParamError::new(
            format!("{path}.feature.height_mm"),
            f.height_mm,
            format!(
                "must be below {:.3} mm: the features point inward from the {} surface (offset {off:.3} mm) and must end before the body's centre of curvature, its axis and its base plane",
                max_inward_reach(design, off),
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
fn marker_size_errors(
    design: &Design,
    l: &ResolvedLayer,
    profile: &PrinterProfile,
    tech_name: &str,
    path: &str,
    spec: &MarkerSpec,
    errs: &mut Vec<ParamError>,
) -> bool {
    let f = &spec.feature;
    let molded = design.layers[l.index].process == LayerProcess::Cast;
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
fn marker_layout_errors(
    design: &Design,
    l: &ResolvedLayer,
    profile: &PrinterProfile,
    tech_name: &str,
    path: &str,
    spec: &MarkerSpec,
    errs: &mut Vec<ParamError>,
) {
    let f = &spec.feature;
    let surface = Surface::new(&design.body, surface_offset(l, spec.surface));
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
        let worst = recess_clearance_to_base_mm(&placed, f, design.body.base_z_mm());
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

fn feature_solids(
    pm: &PlacedMarkers,
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Vec<Solid>, GeometryError> {
    // One mesh in the feature's own frame, placed at every marker by a rigid transform.
    let local = if stems_only {
        // the cylinder only: a hemisphere-free feature of height (height - radius)
        let mut shape = pm.spec.feature.clone();
        shape.height_mm -= shape.radius_mm();
        stem_solid(&shape, [0.0; 3], [0.0, 0.0, 1.0], pm.embed_mm, tol)?
    } else {
        markers::local_feature_dilated(
            &pm.spec.feature,
            pm.direction * pm.dilation_mm,
            pm.embed_mm,
            tol,
        )?
    };
    Ok(pm
        .markers
        .iter()
        .map(|m| {
            local.transform(&markers::frame_to(
                m.position_mm,
                m.normal.map(|c| c * pm.direction),
            ))
        })
        .collect())
}

/// A plain cylinder from `embed` behind the surface to `height` beyond it.
fn stem_solid(
    shape: &markers::FeatureShape,
    position: [f64; 3],
    dir: [f64; 3],
    embed: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let r = shape.radius_mm();
    let pl = Polyline2 {
        points: vec![
            [0.0, -embed],
            [r, -embed],
            [r, shape.height_mm],
            [0.0, shape.height_mm],
        ],
    };
    Ok(Solid::from_mesh(&revolve(
        &pl,
        ChordTolerance::new(tol.mm() * 2.0).unwrap_or(tol),
    )?)?
    .transform(&markers::frame_to(position, dir)))
}

/// The hemispherical tips (flat face at height - radius) of raised features.
fn tip_solids(pm: &PlacedMarkers, tol: ChordTolerance) -> Result<Vec<Solid>, GeometryError> {
    let r = pm.spec.feature.radius_mm();
    let hc = pm.spec.feature.height_mm - r;
    let mut pl = Polyline2::default();
    pl.push([0.0, 0.0]);
    crate::geometry::profile2d::push_arc(
        &mut pl,
        [0.0, 0.0],
        r,
        0.0,
        std::f64::consts::FRAC_PI_2,
        tol.half(),
    );
    let local = Solid::from_mesh(&revolve(&pl, tol)?)?;
    pm.markers
        .iter()
        .map(|m| {
            let dir = m.normal.map(|c| c * pm.direction);
            let base = [
                m.position_mm[0] + hc * dir[0],
                m.position_mm[1] + hc * dir[1],
                m.position_mm[2] + hc * dir[2],
            ];
            Ok(local.transform(&markers::frame_to(base, dir)))
        })
        .collect()
}

/// The solid bounded by the body's surface at `offset_mm`, continued `extend_mm` below the
/// base plane (see [`crate::profile::BodyProfile::solid_profile`]), revolved at `tol`.
fn body_solid(
    design: &Design,
    offset_mm: f64,
    extend_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    revolve(
        &design.body.solid_profile(offset_mm, extend_mm, tol.half()),
        tol,
    )
    .and_then(|mesh| Solid::from_mesh(&mesh))
}

/// The highest z of the surface at `offset_mm` with its outward features: the pole plus the
/// tallest outward feature, mm (sensor frame).
fn features_top_z_mm(design: &Design, offset_mm: f64, sets: &[&PlacedMarkers]) -> f64 {
    design.body.pole_z_mm(offset_mm)
        + sets
            .iter()
            .filter(|p| p.direction > 0.0)
            .map(|p| p.spec.feature.height_mm)
            .fold(0.0, f64::max)
}

/// Adds the outward features and removes the inward ones: one compose and one boolean each.
pub(crate) fn apply_features(
    base: Solid,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    apply_features_signed(base, sets, tol, stems_only, 1.0)
}

/// As [`apply_features`] for `sign` = 1; with `sign` = -1 for the complement of the enclosed
/// solid (a mold around it): outward features are cut, inward ones added.
fn apply_features_signed(
    base: Solid,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
    sign: f64,
) -> Result<Solid, GeometryError> {
    let mut add = Vec::new();
    let mut cut = Vec::new();
    for pm in sets {
        let f = feature_solids(pm, tol, stems_only)?;
        if pm.direction * sign > 0.0 {
            add.extend(f);
        } else {
            cut.extend(f);
        }
    }
    let mut s = base;
    if !add.is_empty() {
        s = s.union(&Solid::compose(&add))?;
    }
    if !cut.is_empty() {
        s = s.difference(&Solid::compose(&cut))?;
    }
    Ok(s)
}

/// The solid enclosed by a boundary surface (offset `offset_mm`), continued `below_base_mm`
/// under the base plane, with the features carried by that surface.
fn enclosed(
    design: &Design,
    offset_mm: f64,
    below_base_mm: f64,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    let base = Solid::from_mesh(&revolve(
        &design
            .body
            .solid_profile(offset_mm, below_base_mm, tol.half()),
        tol,
    )?)?;
    apply_features(base, sets, tol, stems_only)
}

/// The solid that solid layer `l` fills, with the features `sets` of its outer surface: the
/// solid under its outer surface down to the base plane, less the seat a layer feature cuts
/// into it ([`crate::parts::layer_registry::seat_of`]).
fn solid_enclosed(
    design: &Design,
    l: &ResolvedLayer,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    let Some(r) = seat_of(design, l.index) else {
        return enclosed(design, l.outer_offset_mm, 0.0, sets, tol, stems_only);
    };
    let pl = solid_layer_profile(&design.body, l.outer_offset_mm, Some(&r), tol.half());
    apply_features(
        Solid::from_mesh(&revolve(&pl, tol)?)?,
        sets,
        tol,
        stems_only,
    )
}

/// The solid of layer `i` with its features (for printed layers with separate tips, the
/// stems only), closed on the base plane.
///
/// # Errors
/// Only on a kernel failure.
pub fn layer_solid(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(design, l, tol);
    let stems_only = placed.iter().any(|p| p.spec.tip_material.is_some());
    let (coat_outer, coat_inner) = taken_features(design, stack, i, tol);
    let (mut outer, mut inner) = (
        on_surface(&placed, MarkerSurface::Outer),
        on_surface(&placed, MarkerSurface::Inner),
    );
    outer.extend(&coat_outer);
    inner.extend(&coat_inner);
    if l.solid {
        return solid_enclosed(design, l, &outer, tol, stems_only);
    }
    let o = enclosed(design, l.outer_offset_mm, 0.0, &outer, tol, stems_only)?;
    let inn = enclosed(design, l.inner_offset_mm, 1.0, &inner, tol, stems_only)?;
    o.difference(&inn)
}

/// The marker features of layer `i` for the fit check ([`MemberFeatures`]): the sets that grow
/// it beyond the shell between its two offsets (outward on its outer surface, inward on its
/// inner surface) with their solids as [`layer_solid`] places them, and the keys of the sets
/// that cut into it.
///
/// # Errors
/// Only on a kernel failure.
pub fn layer_features(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<MemberFeatures, GeometryError> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(design, l, tol);
    let stems_only = placed.iter().any(|p| p.spec.tip_material.is_some());
    let (coat_outer, coat_inner) = taken_features(design, stack, i, tol);
    let mut out = MemberFeatures::default();
    let sets = placed
        .iter()
        .map(|pm| (pm, pm.spec.surface))
        .chain(coat_outer.iter().map(|pm| (pm, MarkerSurface::Outer)))
        .chain(coat_inner.iter().map(|pm| (pm, MarkerSurface::Inner)));
    for (pm, surface) in sets {
        let outward = pm.direction > 0.0;
        let grows = match surface {
            MarkerSurface::Outer => outward,
            MarkerSurface::Inner if l.solid => continue,
            MarkerSurface::Inner => !outward,
        };
        let key = feature_key(pm, stems_only);
        if grows {
            out.grow
                .push((key, Solid::compose(&feature_solids(pm, tol, stems_only)?)));
        } else {
            out.cut.push(key);
        }
    }
    Ok(out)
}

/// A solid that holds layer `i` ([`layer_solid`]), for a fit check that needs the exact layer
/// only where something overlaps it: the shell between the layer's two offsets (the same
/// surfaces as the layer's) united with `features`' growing sets; the features that cut into
/// the layer are left in. Sensor frame, mm.
///
/// # Errors
/// Only on a kernel failure.
pub fn layer_stand_in(
    design: &Design,
    stack: &Stack,
    i: usize,
    features: &MemberFeatures,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let l = &stack.layers[i];
    let shell = if l.solid {
        solid_enclosed(design, l, &[], tol, false)?
    } else {
        enclosed(design, l.outer_offset_mm, 0.0, &[], tol, false)?.difference(&enclosed(
            design,
            l.inner_offset_mm,
            1.0,
            &[],
            tol,
            false,
        )?)?
    };
    if features.grow.is_empty() {
        return Ok(shell);
    }
    let mut all = vec![shell];
    all.extend(features.grow.iter().map(|(_, s)| s.clone()));
    Solid::union_all(&all)
}

/// The [`FeatureKey`] of a placed marker set: what [`feature_solids`] builds its solids from
/// but the depth they reach behind the surface.
fn feature_key(pm: &PlacedMarkers, stems_only: bool) -> FeatureKey {
    let f = &pm.spec.feature;
    let mut bits = vec![
        f.diameter_mm.to_bits(),
        f.height_mm.to_bits(),
        pm.offset_mm.to_bits(),
        pm.direction.to_bits(),
        u64::from(stems_only),
    ];
    if pm.dilation_mm != 0.0 {
        bits.push(pm.dilation_mm.to_bits());
    }
    for m in &pm.markers {
        bits.extend(m.position_mm.iter().chain(&m.normal).map(|c| c.to_bits()));
    }
    FeatureKey(bits)
}

/// The space inside layer `i` above the base plane, sensor frame, mm: the solid under its
/// inner surface with its inner features (stems and tips) taken out (what the clear gel of a
/// printed TacTip tip fills, Pestell et al. Sec. III-A). Its surfaces are the layer's own
/// (the same tessellation), so that it meets the layer without slivers.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn inner_cavity(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(design, l, tol);
    let inner = on_surface(&placed, MarkerSurface::Inner);
    // whole features (stems and tips as one solid each): no seam where a tip meets its stem
    enclosed(design, l.inner_offset_mm, 0.0, &inner, tol, false)
}

/// Parts and pour numbers of one cast or printed layer built here.
pub struct LayerOutput {
    pub parts: Vec<Part>,
    /// (what, material, volume mm^3, parts holding it) in pouring order.
    pub pours: Vec<(String, String, f64, Vec<String>)>,
    pub markers: Vec<serde_json::Value>,
}

pub(crate) fn marker_summary(
    l: &ResolvedLayer,
    placed: &[PlacedMarkers],
    tech: Technology,
    design: &Design,
) -> Vec<serde_json::Value> {
    placed
        .iter()
        .map(|p| {
            // The technologies whose printer profile passes the same marker rules that
            // validate the design (feature or hole size, walls, rim margin).
            let printable: Vec<&str> = design.layers[l.index]
                .markers
                .iter()
                .position(|s| *s == p.spec)
                .map(|j| printable_with(design, l, j))
                .unwrap_or_default()
                .into_iter()
                .map(|t| match t {
                    Technology::Fdm => "FDM",
                    Technology::Sla => "SLA",
                    Technology::Polyjet => "PolyJet",
                })
                .collect();
            json!({
                "layer": l.name,
                "surface": p.spec.surface,
                "feature": p.spec.feature,
                "pattern": p.spec.pattern,
                "count": p.stats.count,
                "min_spacing_mm": p.stats.min_spacing_mm,
                "median_spacing_mm": p.stats.median_spacing_mm,
                "printed_with": format!("{tech:?}"),
                "printable_with": printable,
                "needs_sla_or_finer": !printable.contains(&"FDM"),
                // Resolved placements for twins: the surface (normal offset of the body
                // profile) and each marker's (polar, azimuth) angle in degrees, seen from the
                // sensor-frame origin; +1 when features point along the outward normal.
                "tip_material": p.spec.tip_material,
                "surface_offset_mm": p.offset_mm,
                "direction": p.direction,
                "placements_deg": p.markers.iter().map(|m| [m.polar_deg, m.azimuth_deg]).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// Adds to each entry of a layer's marker summary the parts that carry its features
/// (`formed_by`: `outer` for the features of the outer surface, `inner` for the inner one) and
/// the diameter of the features on them (`former_diameter_mm`: the feature grown, raised, or
/// shrunk, recessed, by `gap_mm`, the coats sprayed into the mold before the pour and the
/// mold's clearance, [`PlacedMarkers::conformal`]), with `gap_mm` as `coat_mm`.
pub fn set_forming(
    entries: &mut [serde_json::Value],
    outer: &[String],
    inner: &[String],
    gap_mm: f64,
) {
    for e in entries {
        let on_outer = e["surface"] == json!(MarkerSurface::Outer);
        let d = e["feature"]["diameter_mm"].as_f64().unwrap_or(0.0);
        let sign = e["direction"].as_f64().unwrap_or(1.0);
        e["formed_by"] = json!(if on_outer { outer } else { inner });
        e["former_diameter_mm"] = json!(((d + 2.0 * sign * gap_mm) * 1e9).round() / 1e9);
        e["coat_mm"] = json!((gap_mm * 1e9).round() / 1e9);
    }
}

/// The parameter paths a layer's parts are built from: the layer, and the mold for a cast one.
fn layer_params(design: &Design, i: usize) -> Vec<String> {
    let mut p = vec![format!("layers[{i}]")];
    if design.layers[i].process == LayerProcess::Cast {
        p.push("mold".into());
    }
    p
}

/// Builds the parts of a cast layer with the `open` or `boundary` strategy, or of a printed
/// layer.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails, naming the parameters (`layers[i]`, and
/// `mold` for a cast layer).
pub fn build_layer(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<LayerOutput, DesignError> {
    build_layer_parts(design, stack, i, tol).map_err(|e| e.from_params(&layer_params(design, i)))
}

/// The parameters of layer `i` that its parts carry and the CadQuery twin builds the layer
/// from (`export/python/twins/cq_layers.py`): `layer`, `body`, `outer_offset_mm`,
/// `inner_offset_mm` (`null` for a solid layer), `solid` and `markers` (one entry per marker
/// set with its feature, surface, direction and placements, degrees). Sensor frame, mm.
/// `i` must index `stack.layers` (panics otherwise, as [`layer_solid`]).
pub fn layer_twin_params(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> serde_json::Value {
    let l = &stack.layers[i];
    let placed = place_layer_markers(design, l, tol);
    let tech = feature_technology(design, &design.layers[i]);
    let mut sets = marker_summary(l, &placed, tech, design);
    let (outer, inner) = taken_features(design, stack, i, tol);
    sets.extend(
        outer
            .iter()
            .map(|p| twin_marker_set(p, MarkerSurface::Outer)),
    );
    sets.extend(
        inner
            .iter()
            .map(|p| twin_marker_set(p, MarkerSurface::Inner)),
    );
    twin_params(design, l, json!(sets))
}

/// A placed marker set as the CadQuery twins build it (`export/python/twins/cq_layers.py`):
/// its feature, the surface it sits on and that surface's offset, its direction, how much the
/// features are grown ([`PlacedMarkers::dilation_mm`]) and each marker's (polar, azimuth)
/// angle seen from the sensor-frame origin, degrees.
pub fn twin_marker_set(p: &PlacedMarkers, surface: MarkerSurface) -> serde_json::Value {
    json!({
        "surface": surface,
        "feature": p.spec.feature,
        "tip_material": p.spec.tip_material,
        "surface_offset_mm": p.offset_mm,
        "direction": p.direction,
        "dilation_mm": p.dilation_mm,
        "placements_deg": p.markers.iter().map(|m| {
            let [x, y, z] = m.position_mm;
            [x.hypot(y).atan2(z).to_degrees(), m.azimuth_deg]
        }).collect::<Vec<_>>(),
    })
}

fn twin_params(
    design: &Design,
    l: &ResolvedLayer,
    markers: serde_json::Value,
) -> serde_json::Value {
    let mut v = json!({
        "layer": l.name, "body": design.body, "outer_offset_mm": l.outer_offset_mm,
        "inner_offset_mm": if l.solid { serde_json::Value::Null } else { json!(l.inner_offset_mm) },
        "solid": l.solid, "markers": markers,
    });
    crate::parts::layer_registry::twin_params(design, l.index, &mut v);
    v
}

fn build_layer_parts(
    design: &Design,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<LayerOutput, DesignError> {
    let l = &stack.layers[i];
    let name = l.name.clone();
    let placed = place_layer_markers(design, l, tol);
    let spec_layer = &design.layers[i];
    let tech_setting = feature_technology(design, spec_layer);
    let markers_json = marker_summary(l, &placed, tech_setting, design);
    let fixture_tech: PrintTechnology = design.mold.fixture_print_technology.into();
    let cavity_tech: PrintTechnology = design.mold.cavity_print_technology.into();
    let (outer, inner) = (
        on_surface(&placed, MarkerSurface::Outer),
        on_surface(&placed, MarkerSurface::Inner),
    );
    let base_params = twin_params(design, l, json!(markers_json));
    let b = LayerBuild {
        design,
        stack,
        i,
        tol,
        l,
        name,
        placed: &placed,
        outer,
        inner,
        markers_json,
        base_params,
        fixture_tech,
        cavity_tech,
    };
    match (l.process, l.mold_strategy) {
        (LayerProcess::Printed, _) => build_printed_layer(b),
        (_, MoldStrategy::Open) => build_open_mold_layer(b),
        (_, MoldStrategy::TwoPieceOpen) => build_two_piece_open_layer(b),
        (_, MoldStrategy::Boundary) => build_boundary_layer(b),
        _ => unreachable!("direct and master molds are built by molds::build_mold"),
    }
}

/// What every strategy of [`build_layer_parts`] builds from: layer `i` of `stack` (`l`), its
/// name, its placed markers (all, on the outer surface, on the inner surface), its marker
/// summary, the twin parameters its parts carry, and the print technologies of the mold's
/// fixtures and cavities.
struct LayerBuild<'a> {
    design: &'a Design,
    stack: &'a Stack,
    i: usize,
    tol: ChordTolerance,
    l: &'a ResolvedLayer,
    name: String,
    placed: &'a [PlacedMarkers],
    outer: Vec<&'a PlacedMarkers>,
    inner: Vec<&'a PlacedMarkers>,
    markers_json: Vec<serde_json::Value>,
    base_params: serde_json::Value,
    fixture_tech: PrintTechnology,
    cavity_tech: PrintTechnology,
}

/// The parts of a printed layer: the skin with its features (stems only when the tips are
/// separate), one `marker_tips` part per marker set with a `tip_material`, and for the
/// outermost layer of a design with a `shaft_body` the tip's fitting; all moved onto the
/// plate by the same translation, and grouped when there is more than the skin. No pours.
fn build_printed_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (design, stack, i, tol, l, name) = (b.design, b.stack, b.i, b.tol, b.l, &b.name);
    let spec_layer = &design.layers[i];
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    let skin = g(layer_solid(design, stack, i, tol))?;
    let tech: PrintTechnology = spec_layer
        .print_technology
        .unwrap_or(Technology::Polyjet)
        .into();
    // The tip's fitting of a shaft body prints with the outermost (printed) layer, as
    // a further volume of its object (Pestell et al. Sec. III-A).
    let fitting = match &design.shaft_body {
        Some(sb) if i + 1 == stack.layers.len() => {
            Some(g(crate::parts::shaft_body::tip_fitting_solid(
                sb,
                FamilyInput {
                    ctx: &design.context(),
                    stack,
                    tol,
                },
            ))?)
        }
        _ => None,
    };
    let group = (b.placed.iter().any(|p| p.spec.tip_material.is_some()) || fitting.is_some())
        .then(|| name.clone());
    // Skin, tips and fitting move together onto the plate (same translation).
    let extent = match &fitting {
        Some(f) => Solid::compose(&[skin.clone(), f.clone()]),
        None => skin.clone(),
    };
    let shift = extent
        .bounding_box()
        .map(|b| {
            [
                -(b.min[0] + b.max[0]) / 2.0,
                -(b.min[1] + b.max[1]) / 2.0,
                -b.min[2],
            ]
        })
        .unwrap_or([0.0; 3]);
    let pose = crate::geometry::transform::translation(shift);
    let mut parts = vec![Part {
        name: name.clone(),
        role: "printed_skin".into(),
        description: format!("Printed {name} layer with its marker features"),
        material: l.material.clone(),
        print_technology: tech,
        solid: skin.translate(shift),
        params: with_pose(b.base_params.clone(), &pose),
        group: group.clone(),
    }];
    for p in b.placed.iter().filter(|p| p.spec.tip_material.is_some()) {
        let tips = Solid::compose(&tip_solids(p, tol).part(name)?);
        parts.push(Part {
            name: format!("{name}_tips"),
            role: "marker_tips".into(),
            description: format!(
                "{} marker tips of {name}, printed in the second material with the skin",
                p.stats.count
            ),
            material: p.spec.tip_material.clone().unwrap_or_default(),
            print_technology: tech,
            solid: tips.translate(shift),
            params: with_pose(b.base_params.clone(), &pose),
            group: group.clone(),
        });
    }
    if let (Some(f), Some(sb)) = (fitting, &design.shaft_body) {
        parts.push(Part {
            name: "tip_fitting".into(),
            role: "tip_fitting".into(),
            description: format!(
                "The tip's rigid bayonet fitting, printed in the second material with {name} (Pestell et al. Sec. III-A)"
            ),
            material: sb.tip_fitting.material.clone(),
            print_technology: tech,
            solid: f.translate(shift),
            params: with_pose(
                crate::parts::shaft_body::twin_params(&design.context(), sb, stack),
                &pose,
            ),
            group: group.clone(),
        });
    }
    let mut markers = b.markers_json;
    let carriers: Vec<String> = parts
        .iter()
        .filter(|p| p.role != "tip_fitting")
        .map(|p| p.name.clone())
        .collect();
    set_forming(&mut markers, &carriers, &carriers, 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![],
        markers,
    })
}

/// The one-piece open mold of a solid cast layer (`open` strategy): a block
/// `mold.wall_thickness_mm` beyond the rim and the tallest outward feature, less the cavity
/// (the outer surface with its features), printed open face up; one pour of the layer's
/// material, its volume block - mold, mm^3.
fn build_open_mold_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (design, tol, l, name, outer) = (b.design, b.tol, b.l, &b.name, &b.outer);
    let (base_params, cavity_tech) = (&b.base_params, b.cavity_tech);
    let m = &design.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    // mold = (block - plain cavity) with the features cut or added: one boolean with
    // the features, and the skin's volume falls out as block - mold.
    let plain = g(body_solid(design, l.outer_offset_mm, 1.0, tol))?;
    let rim = design.body.rim_radius_mm(l.outer_offset_mm);
    let top = features_top_z_mm(design, l.outer_offset_mm, outer);
    let zb = design.body.base_z_mm();
    let (half, z_top) = match &m.open_block {
        Some(ob) => (ob.width_mm / 2.0, zb + ob.height_mm),
        None => (rim + m.wall_thickness_mm, top + m.wall_thickness_mm),
    };
    let block = g(crate::geometry::cuboid(
        [-half, -half, zb],
        [half, half, z_top],
    ))?;
    let mold = g(block
        .difference(&plain)
        .and_then(|b| apply_features_signed(b, outer, tol, false, -1.0)))?;
    // the features' inserts set in the open face (the optic's seat)
    let inserts = open_mold_inserts(
        design,
        l.index,
        InsertInput {
            layer_name: name,
            base_z_mm: zb,
            base_params,
            technology: cavity_tech,
            material: material_for(cavity_tech),
            tol,
        },
    )
    .part(name)?;
    let inserts_volume: f64 = inserts.iter().map(|i| i.volume_mm3).sum();
    let skin_volume = block.volume() - mold.volume() - inserts_volume;
    let (mold_placed, mold_pose) =
        place_posed(&mold, &crate::geometry::rotation_deg(180.0, 0.0, 0.0));
    let part = Part {
        name: format!("{name}_open_mold"),
        role: "open_mold".into(),
        description: format!(
            "One-piece mold for the solid {name} skin, open face up: pour to the brim"
        ),
        material: material_for(cavity_tech).into(),
        print_technology: cavity_tech,
        solid: mold_placed,
        params: with_pose(
            json!({"base": base_params, "open_face": "the base plane, printed face up", "wall_thickness_mm": m.wall_thickness_mm,
            "block_mm": {"min": [-half, -half, zb], "max": [half, half, z_top]}}),
            &mold_pose,
        ),
        group: None,
    };
    let mut parts = vec![part];
    parts.extend(inserts.into_iter().map(|i| i.part));
    let pour_parts = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &[format!("{name}_open_mold")], &[], 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![(name.clone(), l.material.clone(), skin_volume, pour_parts)],
        markers,
    })
}

/// The two-piece open mold of a solid cast layer (`two_piece_open` strategy, frame
/// [`crate::parts::molds::TwoPieceFrame`]). Builds its solids: the cavity block (the outline from the
/// parting face to `mold.wall_thickness_mm` beyond the tallest outward feature, less the
/// cavity, the pocket and the bolt holes, with the features) and the top piece (plate and
/// boss, less the reservoir bore and the bolt holes); [`two_piece_open_parts`] makes their
/// parts.
fn build_two_piece_open_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (design, tol, l) = (b.design, b.tol, b.l);
    let m = &design.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(&b.name);
    // Cavity block: the outline from the parting face to the wall beyond the pole,
    // less the cavity (continued 1 mm into the pocket), the pocket and the bolt holes,
    // with the features: a dimple is a pin standing into the cavity.
    let f = crate::parts::molds::TwoPieceFrame::new(design);
    let zb = f.base_z_mm;
    let plain = g(body_solid(design, l.outer_offset_mm, 1.0, tol))?;
    let cap = g(body_solid(design, l.outer_offset_mm, 0.0, tol))?;
    let top = features_top_z_mm(design, l.outer_offset_mm, &b.outer);
    let z_far = top + m.wall_thickness_mm;
    let [ox, oy] = f.outer_half_mm;
    let [px, py] = f.pocket_half_mm;
    let [bx, by] = f.boss_half_mm;
    let pocket = g(crate::geometry::cuboid(
        [-px, -py, f.parting_z_mm - 1.0],
        [px, py, zb],
    ))?;
    // The bolt holes of one piece: through both, each piece with its own diameter.
    let bolt_holes = |diameter_mm: f64| -> Result<Solid, DesignError> {
        let hole = g(crate::geometry::cylinder(
            z_far - f.top_z_mm + 2.0,
            diameter_mm / 2.0,
            tol,
        ))?;
        Ok(Solid::compose(
            &f.bolts_xy_mm
                .iter()
                .map(|b| hole.translate([b[0], b[1], f.top_z_mm - 1.0]))
                .collect::<Vec<_>>(),
        ))
    };
    let bolts = bolt_holes(f.cavity_block_bolt_hole_mm)?;
    let top_bolts = bolt_holes(f.top_piece_bolt_hole_mm)?;
    let block = g(crate::geometry::cuboid(
        [-ox, -oy, f.parting_z_mm],
        [ox, oy, z_far],
    ))?;
    let bare = g(block
        .difference(&plain)
        .and_then(|b| b.difference(&pocket))
        .and_then(|b| b.difference(&bolts)))?;
    let bottom = g(apply_features_signed(
        bare.clone(),
        &b.outer,
        tol,
        false,
        -1.0,
    ))?;
    // The skin: the cap less what the features added to the block, plus what they cut.
    let skin_volume = cap.volume() - (bottom.volume() - bare.volume());
    // Top piece: plate and boss, less the reservoir bore and the bolt holes.
    let plate = g(crate::geometry::cuboid(
        [-ox, -oy, f.top_z_mm],
        [ox, oy, f.parting_z_mm],
    ))?;
    let boss = g(crate::geometry::cuboid(
        [-bx, -by, f.parting_z_mm],
        [bx, by, zb],
    ))?;
    let bore = g(
        crate::geometry::cylinder(zb - f.top_z_mm + 2.0, f.reservoir_radius_mm, tol)
            .map(|c| c.translate([0.0, 0.0, f.top_z_mm - 1.0])),
    )?;
    let top_piece = g(plate
        .union(&boss)
        .and_then(|t| t.difference(&Solid::compose(&[bore, top_bolts]))))?;
    Ok(two_piece_open_parts(
        b,
        &f,
        z_far,
        bottom,
        top_piece,
        skin_volume,
    ))
}

/// The two parts of a two-piece open mold of frame `f` from its solids (`bottom`, the cavity
/// block, and `top_piece`, sensor frame), the cavity block reaching up to `z_far` mm: the
/// cavity block printed parting face up and the reservoir top, with the frame, bolt grip and
/// reservoir volume in their parameters; one pour of the layer's material, `skin_volume`
/// mm^3, into both.
fn two_piece_open_parts(
    b: LayerBuild,
    f: &crate::parts::molds::TwoPieceFrame,
    z_far: f64,
    bottom: Solid,
    top_piece: Solid,
    skin_volume: f64,
) -> LayerOutput {
    let (design, l, name, cavity_tech) = (b.design, b.l, &b.name, b.cavity_tech);
    let m = &design.mold;
    let zb = f.base_z_mm;
    let reservoir_mm3 = std::f64::consts::PI * f.reservoir_radius_mm.powi(2) * (zb - f.top_z_mm);
    let params = json!({
        "base": b.base_params,
        "two_piece": m.two_piece,
        "frame": f,
        "cavity_block_z_mm": [f.parting_z_mm, z_far],
        "bolt_holes_z_mm": [f.top_z_mm - 1.0, z_far + 1.0],
        "bolt_grip_mm": z_far - f.top_z_mm,
        "registration_clearance_mm": m.registration_key.clearance_mm,
        "reservoir_volume_mm3": reservoir_mm3,
        "pull_direction": "along the sensor axis: the top piece off the cavity block, then the skin out of the cavity",
    });
    let (bottom_placed, bottom_pose) =
        place_posed(&bottom, &crate::geometry::rotation_deg(180.0, 0.0, 0.0));
    let (top_placed, top_pose) = place_posed(&top_piece, &crate::geometry::Affine::identity());
    let piece = |suffix: &str, which: &str, desc: String, solid, pose| {
        let mut p = params.clone();
        p["piece"] = json!(which);
        Part {
            name: format!("{name}_{suffix}"),
            role: "open_mold_piece".into(),
            description: desc,
            material: material_for(cavity_tech).into(),
            print_technology: cavity_tech,
            solid,
            params: with_pose(p, &pose),
            group: None,
        }
    };
    let n_bolts = f.bolts_xy_mm.len();
    let parts = vec![
        piece(
            "cavity_block",
            "cavity_block",
            format!(
                "Bottom piece of the two-piece mold for the solid {name} skin: the cavity, printed parting face up, with the pocket for the top piece's boss and {n_bolts} bolt holes"
            ),
            bottom_placed,
            bottom_pose,
        ),
        piece(
            "reservoir_top",
            "reservoir_top",
            format!(
                "Top piece of the two-piece mold for the {name} skin: its {} mm bore is the pour reservoir that forms the skin's back; boss down into the cavity block's pocket, {n_bolts} bolts",
                2.0 * f.reservoir_radius_mm
            ),
            top_placed,
            top_pose,
        ),
    ];
    let pour_parts = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &[format!("{name}_cavity_block")], &[], 0.0);
    LayerOutput {
        parts,
        pours: vec![(name.clone(), l.material.clone(), skin_volume, pour_parts)],
        markers,
    }
}

/// The parts of a cast layer with the `boundary` strategy: the outer master (the outer
/// boundary with its features, plinth and locating pin) with its drafted mold box, and the
/// inner negative (a cup whose cavity casts the inner silicone core); three pours: the outer
/// and inner Mold Star 30 molds, then the layer's gel between them, mm^3.
fn build_boundary_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (design, stack, i, tol, l, name) = (b.design, b.stack, b.i, b.tol, b.l, &b.name);
    let (fixture_tech, cavity_tech) = (b.fixture_tech, b.cavity_tech);
    let m = &design.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    let zb = design.body.base_z_mm();
    let rim = design.body.rim_radius_mm(l.outer_offset_mm);
    let r_p = rim + m.plinth.margin_mm;
    let z_lo = zb - m.plinth.height_mm;
    let fit = m.core_holder.fit_clearance_mm;
    // Outer boundary: master (positive) with plinth and locating pin, and a drafted box.
    let mut pl = design
        .body
        .offset_polyline(l.outer_offset_mm, 0.0, tol.half());
    let pin_r = 3.0f64.min(r_p / 3.0);
    for p in [
        [r_p, zb],
        [r_p, z_lo],
        [pin_r, z_lo],
        [pin_r, z_lo - 2.0],
        [0.0, z_lo - 2.0],
    ] {
        pl.push(p);
    }
    let master_base = g(revolve(&pl, tol).and_then(|mesh| Solid::from_mesh(&mesh)))?;
    let master = g(apply_features(master_base, &b.outer, tol, false))?;
    let pole = master.bounding_box().map(|b| b.max[2]).unwrap_or(0.0);
    let (mold_box, fill) =
        crate::parts::molds::drafted_box(design, r_p, z_lo, pole, tol).part(name)?;
    let silicone_outer = g(fill.difference(&master))?.volume();
    // Inner boundary: a cup whose cavity casts the inner silicone core; the core's
    // plinth fits the outer mold's plinth recess (with clearance), which centres it.
    let inner_pl = {
        let mut q = design
            .body
            .offset_polyline(l.inner_offset_mm, 0.0, tol.half());
        for p in [[r_p - fit, zb], [r_p - fit, z_lo - 1.0], [0.0, z_lo - 1.0]] {
            q.push(p);
        }
        q
    };
    let core_pos = g(revolve(&inner_pl, tol)
        .and_then(|mesh| Solid::from_mesh(&mesh))
        .and_then(|s| apply_features(s, &b.inner, tol, false)))?;
    let top = core_pos.bounding_box().map(|b| b.max[2]).unwrap_or(0.0) + BOUNDARY_CUP_FLOOR_MM;
    let cup_r = r_p + BOUNDARY_CUP_WALL_MM;
    let cup =
        g(crate::geometry::cylinder(top - z_lo, cup_r, tol)
            .map(|c| c.translate([0.0, 0.0, z_lo])))?;
    let inner_negative = g(cup.difference(&core_pos))?;
    let silicone_inner = g(core_pos.intersection(&cup))?.volume();
    let gel = g(layer_solid(design, stack, i, tol))?.volume();
    let boundary = json!({
        "locating_pin": {"radius_mm": pin_r, "height_mm": 2.0},
        "master_top_z_mm": pole,
        "inner_plinth_bottom_z_mm": z_lo - 1.0,
        "cup": {"radius_mm": cup_r, "bottom_z_mm": z_lo, "top_z_mm": top},
        "box_floor_mm": 2.0, "box_wall_mm": 2.0, "box_freeboard_mm": 2.0,
        "pin_socket_radius_mm": pin_r + fit,
    });
    let mk = |suffix: &str,
              role: &str,
              desc: String,
              tech: PrintTechnology,
              (solid, pose): (Solid, crate::geometry::Affine)| Part {
        name: format!("{name}_{suffix}"),
        role: role.into(),
        description: desc,
        material: material_for(tech).into(),
        print_technology: tech,
        solid,
        params: with_pose(
            json!({"base": b.base_params, "plinth_radius_mm": r_p, "plinth_height_mm": m.plinth.height_mm, "fit_clearance_mm": fit, "draft_angle_deg": m.draft_angle_deg, "silicone_wall_mm": m.silicone_wall_mm, "boundary": boundary}),
            &pose,
        ),
        group: None,
    };
    let parts = vec![
        mk("outer_master", "master_pattern", format!("Positive of the outer boundary of {name} with its features, to cast the outer Mold Star 30 mold"), cavity_tech, place_posed(&master, &crate::geometry::Affine::identity())),
        mk("outer_mold_box", "mold_box", format!("Drafted cup for the outer Mold Star 30 mold of {name}"), fixture_tech, place_posed(&mold_box, &crate::geometry::Affine::identity())),
        mk("inner_negative", "negative_mold", format!("Negative of the inner boundary of {name} with its features: pour Mold Star 30 in it for the inner silicone mold"), cavity_tech, place_posed(&inner_negative, &crate::geometry::rotation_deg(180.0, 0.0, 0.0))),
    ];
    let names: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &names[..1], &names[2..3], 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![
            (
                format!("silicone_mold:{name}:outer"),
                "mold_star_30".into(),
                silicone_outer,
                vec![names[0].clone(), names[1].clone()],
            ),
            (
                format!("silicone_mold:{name}:inner"),
                "mold_star_30".into(),
                silicone_inner,
                vec![names[2].clone()],
            ),
            (
                name.clone(),
                l.material.clone(),
                gel,
                vec![
                    format!("silicone_mold:{name}:outer"),
                    format!("silicone_mold:{name}:inner"),
                ],
            ),
        ],
        markers,
    })
}

const BOUNDARY_CUP_WALL_MM: f64 = 5.0;
const BOUNDARY_CUP_FLOOR_MM: f64 = 5.0;

fn material_for(t: PrintTechnology) -> &'static str {
    match t {
        PrintTechnology::Fdm => "pla",
        PrintTechnology::Sla => "sla_standard_resin",
        PrintTechnology::Polyjet => "tango_black_plus",
    }
}
