//! Where each layer's markers sit: their patterns placed on the layer's surfaces
//! ([`place_layer_markers`], [`PlacedMarkers`]), the features a layer takes from the layers
//! and coats around it, and the clearances the checks measure
//! ([`crate::parts::marker_checks`]).

use crate::geometry::ChordTolerance;
use crate::markers::{self, Marker, MarkerSpec, MarkerSurface, PatternStats, Polarity, Surface};
use crate::parts::context::{ResolvedLayer, Stack};
use crate::parts::stack_input::StackInput;
use crate::schema::{LayerProcess, Technology};
use crate::values::MAX_LENGTH_MM;

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

pub(crate) fn surface_offset(l: &ResolvedLayer, s: MarkerSurface) -> f64 {
    match s {
        MarkerSurface::Outer => l.outer_offset_mm,
        MarkerSurface::Inner => l.inner_offset_mm,
    }
}

pub(crate) fn direction(spec: &MarkerSpec) -> f64 {
    match (spec.surface, spec.feature.side()) {
        (MarkerSurface::Outer, Polarity::Raised) | (MarkerSurface::Inner, Polarity::Recessed) => {
            1.0
        }
        _ => -1.0,
    }
}

/// The print technology that makes the surface carrying a layer's features.
pub(crate) fn feature_technology(si: &StackInput<'_>, layer: &crate::schema::Layer) -> Technology {
    match layer.process {
        LayerProcess::Printed => layer.print_technology.unwrap_or(Technology::Polyjet),
        _ => si.mold.cavity_print_technology,
    }
}

/// How far inward from the offset surface at `off` a feature may reach before the offset
/// surface at its end stops being valid ([`crate::profile::BodyProfile::offset_is_valid`]), mm
/// (bisection; 0 when the surface itself is not valid).
pub(crate) fn max_inward_reach(si: &StackInput<'_>, off: f64) -> f64 {
    let body = &si.ctx.body;
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
pub(crate) fn rim_margin(spec: &MarkerSpec, min_wall: f64) -> f64 {
    spec.feature.diameter_mm + min_wall
}

/// Every pattern of `layer` that places (a pattern that does not is the validation's to
/// report): the spec, its surface offset, the surface and the markers.
pub(crate) fn placed_patterns<'a>(
    si: &'a StackInput<'a>,
    layer: &ResolvedLayer,
) -> Vec<(&'a MarkerSpec, f64, Surface, Vec<markers::Marker>)> {
    let spec_layer = &si.layers[layer.index];
    let profile = si.ctx.printers.get(feature_technology(si, spec_layer));
    spec_layer
        .markers
        .iter()
        .filter_map(|spec| {
            let offset = surface_offset(layer, spec.surface);
            let surface = Surface::new(si.ctx.body, offset);
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
    si: &StackInput<'_>,
    layer: &ResolvedLayer,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    placed_patterns(si, layer)
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
pub(crate) fn formed_on_stack(stack: &Stack, i: usize) -> bool {
    i > 0 && formed_on_stack_layer(&stack.layers[i])
}

/// [`formed_on_stack`] for a layer that has one under it.
pub(crate) fn formed_on_stack_layer(l: &ResolvedLayer) -> bool {
    l.process == LayerProcess::Sprayed
        || (l.process == LayerProcess::Cast && l.mold_strategy.holds_core())
}

/// The features on the outer surface of layer `i` as the stack forms them: its own, and for
/// a sprayed coat those of the layer under it, grown by the coat's thickness
/// ([`PlacedMarkers::conformal`]: the coat takes the shape of the cavity it is sprayed into).
pub fn formed_outer_features(
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    let l = &stack.layers[i];
    let mut own: Vec<PlacedMarkers> = place_layer_markers(si, l, tol)
        .into_iter()
        .filter(|p| p.spec.surface == MarkerSurface::Outer)
        .collect();
    if l.process == LayerProcess::Sprayed && i > 0 {
        let under = &stack.layers[i - 1];
        own.extend(
            formed_outer_features(si, stack, i - 1, tol)
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
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> (Vec<PlacedMarkers>, Vec<PlacedMarkers>) {
    if !formed_on_stack(stack, i) {
        return (Vec::new(), Vec::new());
    }
    let (l, under) = (&stack.layers[i], &stack.layers[i - 1]);
    let below = formed_outer_features(si, stack, i - 1, tol);
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
    let mut copies = usize::from(l.process == LayerProcess::Cast && l.mold_strategy.holds_core());
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
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    cavity_offset_mm: f64,
    tol: ChordTolerance,
) -> Vec<PlacedMarkers> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(si, l, tol);
    on_surface(&placed, MarkerSurface::Outer)
        .into_iter()
        .map(|p| p.conformal(cavity_offset_mm - l.outer_offset_mm))
        .collect()
}

/// The placed patterns that sit on `surface`.
pub(crate) fn on_surface(placed: &[PlacedMarkers], surface: MarkerSurface) -> Vec<&PlacedMarkers> {
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
