//! Layer solids with their marker features, their twin parameters, and the parts of printed
//! layers; what every strategy builds a layer from ([`LayerBuild`]). Where the markers sit is
//! [`crate::parts::layer_markers`], their rules [`crate::parts::marker_checks`], the molds
//! [`crate::parts::molds`].
//!
//! A layer's solid is the solid enclosed by its outer boundary minus the solid enclosed by its
//! inner boundary. A boundary's enclosed solid gains the features that point outward from it
//! and loses those that point inward; a raised feature on an outer surface points outward, on
//! an inner surface inward. The same feature solid thus makes a slot in one layer and the
//! protrusion that fills it in the next (UVDtact Sec. III).

use crate::error::{DesignError, GeometryContext};
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use crate::markers::{self, MarkerSurface};
use crate::parts::context::{ResolvedLayer, Stack};
use crate::parts::layer_feature::solid_layer_profile;
use crate::parts::layer_registry::seat_of;
use crate::parts::member::{FeatureKey, MemberFeatures};
use crate::parts::part::SkinVolume;
use crate::parts::placement::with_pose;
use crate::parts::stack_input::StackInput;
use crate::parts::{Part, PrintTechnology};
use crate::schema::{LayerProcess, Technology};
use serde_json::json;

pub use crate::parts::layer_markers::{
    cavity_features, feature_end_centres, formed_outer_features, outer_feature_copies,
    place_layer_markers, recess_clearance_to_base_mm, taken_features, PlacedMarkers,
};
use crate::parts::layer_markers::{feature_technology, on_surface};
pub use crate::parts::marker_checks::{
    cavity_gap_mm, check_markers, marker_errors, printable_with,
};

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

/// What [`feature_solids`] reads of a group of marker sets, to the bit: each set's feature
/// (all its fields), direction, dilation, depth behind the surface and every marker's position
/// and normal, with the chord tolerance and `stems_only`. Two groups with equal keys compose
/// to the same solid.
#[derive(Debug, PartialEq)]
struct ComposeKey {
    features: Vec<String>,
    bits: Vec<u64>,
}

fn compose_key(sets: &[&PlacedMarkers], tol: ChordTolerance, stems_only: bool) -> ComposeKey {
    let mut bits = vec![tol.mm().to_bits(), u64::from(stems_only), sets.len() as u64];
    let mut features = Vec::with_capacity(sets.len());
    for pm in sets {
        features.push(serde_json::to_string(&pm.spec.feature).unwrap_or_default());
        bits.extend([
            pm.direction.to_bits(),
            pm.dilation_mm.to_bits(),
            pm.embed_mm.to_bits(),
            pm.markers.len() as u64,
        ]);
        for m in &pm.markers {
            bits.extend(m.position_mm.iter().chain(&m.normal).map(|c| c.to_bits()));
        }
    }
    ComposeKey { features, bits }
}

/// The marker feature compositions of a kit build, made once before its molds, printed layers
/// and the assembly's cast layers are built ([`share_feature_solids`]), and read through
/// [`StackInput::shared`]: a mold strategy that forms the same features (the pins of
/// ShadowTac's cavity block are its skin's dimples; UVDtact's boundary molds and their layers
/// share the 85 slots) and the assembly's layer then read one composition instead of each
/// making its own (ShadowTac's 469 pins took about 0.14 CPU-s a composition).
///
/// Why a build makes them before anything reads them, rather than whoever comes first: the
/// kernel orders an exported mesh's triangles by the order in which its source solids were
/// made, so every reader must find its composition made before its own solids, whatever the
/// thread count; a composition made beside the readers would be found or not by timing.
///
/// It also holds the whole solids ([`layer_solid`]) of the layers that both a mold and the
/// assembly read (UVDtact's boundary molds read each layer's solid for the gel's volume:
/// about 0.17 CPU-s a layer), by layer index: one value serves one design's stack at one chord
/// tolerance.
#[derive(Debug, Default)]
pub struct SharedFeatureSolids {
    composed: Vec<(ComposeKey, Solid)>,
    tol: Option<ChordTolerance>,
    layers: Vec<(usize, Solid)>,
}

impl SharedFeatureSolids {
    fn get(&self, key: &ComposeKey) -> Option<&Solid> {
        self.composed.iter().find(|(k, _)| k == key).map(|(_, s)| s)
    }

    fn layer(&self, i: usize, tol: ChordTolerance) -> Option<&Solid> {
        if self.tol != Some(tol) {
            return None;
        }
        self.layers.iter().find(|(j, _)| *j == i).map(|(_, s)| s)
    }
}

/// The feature solids of `sets` ([`feature_solids`] of each, in order) as one solid
/// ([`Solid::compose`]): `shared`'s when it holds that composition, else composed here.
fn composed_features<'s>(
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
    shared: Option<&'s SharedFeatureSolids>,
) -> Result<std::borrow::Cow<'s, Solid>, GeometryError> {
    if let Some(s) = shared.and_then(|sh| sh.get(&compose_key(sets, tol, stems_only))) {
        return Ok(std::borrow::Cow::Borrowed(s));
    }
    let mut parts = Vec::new();
    for pm in sets {
        parts.extend(feature_solids(pm, tol, stems_only)?);
    }
    Ok(std::borrow::Cow::Owned(Solid::compose(&parts)))
}

/// Composes, once, the feature solids that [`layer_solid`] adds to and cuts from each layer
/// of `stack` (its own markers and the coats' it takes, each surface's outward and inward
/// sets apart) and those [`layer_features`] composes set by set, then builds the whole solids
/// of the layers `layers` (in parallel), for a kit build to share ([`SharedFeatureSolids`]).
/// A solid that fails is left out: whoever needs it builds it and reports the error.
pub fn share_feature_solids(
    si: &StackInput<'_>,
    stack: &Stack,
    tol: ChordTolerance,
    layers: &[usize],
) -> SharedFeatureSolids {
    let mut shared = SharedFeatureSolids {
        tol: Some(tol),
        ..SharedFeatureSolids::default()
    };
    let mut add = |group: &[&PlacedMarkers], stems_only: bool| {
        let key = compose_key(group, tol, stems_only);
        if shared.get(&key).is_none() {
            if let Ok(s) = composed_features(group, tol, stems_only, None) {
                shared.composed.push((key, s.into_owned()));
            }
        }
    };
    for (i, l) in stack.layers.iter().enumerate() {
        let (outer, inner, stems_only) = layer_feature_sets(si, stack, i, tol);
        for (sets, on_outer) in [(&outer, true), (&inner, false)] {
            for outward in [true, false] {
                let group: Vec<&PlacedMarkers> = sets
                    .iter()
                    .filter(|pm| (pm.direction > 0.0) == outward)
                    .collect();
                if !group.is_empty() {
                    add(&group, stems_only);
                }
            }
            // the sets that grow a cast or sprayed layer, one by one, as layer_features
            // composes them for the assembly
            if l.process != LayerProcess::Printed && (on_outer || !l.solid) {
                for pm in sets.iter().filter(|pm| (pm.direction > 0.0) == on_outer) {
                    add(&[pm], stems_only);
                }
            }
        }
    }
    use rayon::prelude::*;
    let si = si.sharing(Some(&shared));
    let solids: Vec<(usize, Solid)> = layers
        .par_iter()
        .filter_map(|&i| Some((i, layer_solid(&si, stack, i, tol).ok()?)))
        .collect();
    shared.layers = solids;
    shared
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
pub(crate) fn body_solid(
    si: &StackInput<'_>,
    offset_mm: f64,
    extend_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    revolve(
        &si.ctx.body.solid_profile(offset_mm, extend_mm, tol.half()),
        tol,
    )
    .and_then(|mesh| Solid::from_mesh(&mesh))
}

/// The highest z of the surface at `offset_mm` with its outward features: the pole plus the
/// tallest outward feature, mm (sensor frame).
pub(crate) fn features_top_z_mm(
    si: &StackInput<'_>,
    offset_mm: f64,
    sets: &[&PlacedMarkers],
) -> f64 {
    si.ctx.body.pole_z_mm(offset_mm)
        + sets
            .iter()
            .filter(|p| p.direction > 0.0)
            .map(|p| p.spec.feature.height_mm)
            .fold(0.0, f64::max)
}

/// Adds the outward features and removes the inward ones: one compose and one boolean each.
pub(crate) fn apply_features(
    shared: Option<&SharedFeatureSolids>,
    base: Solid,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    apply_features_signed(shared, base, sets, tol, stems_only, 1.0)
}

/// As [`apply_features`] for `sign` = 1; with `sign` = -1 for the complement of the enclosed
/// solid (a mold around it): outward features are cut, inward ones added.
pub(crate) fn apply_features_signed(
    shared: Option<&SharedFeatureSolids>,
    base: Solid,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
    sign: f64,
) -> Result<Solid, GeometryError> {
    let (add, cut): (Vec<&PlacedMarkers>, Vec<&PlacedMarkers>) =
        sets.iter().partition(|pm| pm.direction * sign > 0.0);
    let mut s = base;
    if !add.is_empty() {
        s = s.union(&*composed_features(&add, tol, stems_only, shared)?)?;
    }
    if !cut.is_empty() {
        s = s.difference(&*composed_features(&cut, tol, stems_only, shared)?)?;
    }
    Ok(s)
}

/// The solid enclosed by a boundary surface (offset `offset_mm`), continued `below_base_mm`
/// under the base plane, with the features carried by that surface.
fn enclosed(
    si: &StackInput<'_>,
    offset_mm: f64,
    below_base_mm: f64,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    let base = Solid::from_mesh(&revolve(
        &si.ctx
            .body
            .solid_profile(offset_mm, below_base_mm, tol.half()),
        tol,
    )?)?;
    apply_features(si.shared, base, sets, tol, stems_only)
}

/// The solid that solid layer `l` fills, with the features `sets` of its outer surface: the
/// solid under its outer surface down to the base plane, less the seat a layer feature cuts
/// into it ([`crate::parts::layer_registry::seat_of`]).
fn solid_enclosed(
    si: &StackInput<'_>,
    l: &ResolvedLayer,
    sets: &[&PlacedMarkers],
    tol: ChordTolerance,
    stems_only: bool,
) -> Result<Solid, GeometryError> {
    let Some(r) = seat_of(si, l.index) else {
        return enclosed(si, l.outer_offset_mm, 0.0, sets, tol, stems_only);
    };
    let pl = solid_layer_profile(si.ctx.body, l.outer_offset_mm, Some(&r), tol.half());
    apply_features(
        si.shared,
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
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    if let Some(s) = si.shared.and_then(|sh| sh.layer(i, tol)) {
        return Ok(s.clone());
    }
    let l = &stack.layers[i];
    let (outer, inner, stems_only) = layer_feature_sets(si, stack, i, tol);
    let outer: Vec<&PlacedMarkers> = outer.iter().collect();
    let inner: Vec<&PlacedMarkers> = inner.iter().collect();
    if outer.is_empty() && inner.is_empty() {
        // no feature on either surface: the revolved layer itself, no boolean
        return stack.layer_solid(si, i, tol);
    }
    if l.solid {
        return solid_enclosed(si, l, &outer, tol, stems_only);
    }
    let o = enclosed(si, l.outer_offset_mm, 0.0, &outer, tol, stems_only)?;
    let inn = enclosed(si, l.inner_offset_mm, 1.0, &inner, tol, stems_only)?;
    o.difference(&inn)
}

/// The marker sets [`layer_solid`] gives layer `i`: on its outer surface, on its inner
/// surface (its own, then those it takes from the coats: [`taken_features`]), and whether only
/// the stems are built (printed tips).
fn layer_feature_sets(
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> (Vec<PlacedMarkers>, Vec<PlacedMarkers>, bool) {
    let placed = place_layer_markers(si, &stack.layers[i], tol);
    let stems_only = placed.iter().any(|p| p.spec.tip_material.is_some());
    let (coat_outer, coat_inner) = taken_features(si, stack, i, tol);
    let (mut outer, mut inner): (Vec<PlacedMarkers>, Vec<PlacedMarkers>) = placed
        .into_iter()
        .partition(|p| p.spec.surface == MarkerSurface::Outer);
    outer.extend(coat_outer);
    inner.extend(coat_inner);
    (outer, inner, stems_only)
}

/// The marker features of layer `i` for the fit check ([`MemberFeatures`]): the sets that grow
/// it beyond the shell between its two offsets (outward on its outer surface, inward on its
/// inner surface) with their solids as [`layer_solid`] places them, and the keys of the sets
/// that cut into it.
///
/// # Errors
/// Only on a kernel failure.
pub fn layer_features(
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<MemberFeatures, GeometryError> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(si, l, tol);
    let stems_only = placed.iter().any(|p| p.spec.tip_material.is_some());
    let (coat_outer, coat_inner) = taken_features(si, stack, i, tol);
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
            out.grow.push((
                key,
                composed_features(&[pm], tol, stems_only, si.shared)?.into_owned(),
            ));
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
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    features: &MemberFeatures,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let l = &stack.layers[i];
    let shell = if l.solid {
        solid_enclosed(si, l, &[], tol, false)?
    } else {
        enclosed(si, l.outer_offset_mm, 0.0, &[], tol, false)?.difference(&enclosed(
            si,
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
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let l = &stack.layers[i];
    let placed = place_layer_markers(si, l, tol);
    let inner = on_surface(&placed, MarkerSurface::Inner);
    // whole features (stems and tips as one solid each): no seam where a tip meets its stem
    enclosed(si, l.inner_offset_mm, 0.0, &inner, tol, false)
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
    si: &StackInput<'_>,
) -> Vec<serde_json::Value> {
    placed
        .iter()
        .map(|p| {
            // The technologies whose printer profile passes the same marker rules that
            // validate the design (feature or hole size, walls, rim margin).
            let printable: Vec<&str> = si.layers[l.index]
                .markers
                .iter()
                .position(|s| *s == p.spec)
                .map(|j| printable_with(si, l, j))
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
pub(crate) fn layer_params(si: &StackInput<'_>, i: usize) -> Vec<String> {
    let mut p = vec![format!("layers[{i}]")];
    if si.layers[i].process == LayerProcess::Cast {
        p.push("mold".into());
    }
    p
}

/// The parameters of layer `i` that its parts carry and the CadQuery twin builds the layer
/// from (`export/python/twins/cq_layers.py`): `layer`, `body`, `outer_offset_mm`,
/// `inner_offset_mm` (`null` for a solid layer), `solid` and `markers` (one entry per marker
/// set with its feature, surface, direction and placements, degrees). Sensor frame, mm.
/// `i` must index `stack.layers` (panics otherwise, as [`layer_solid`]).
pub fn layer_twin_params(
    si: &StackInput<'_>,
    stack: &Stack,
    i: usize,
    tol: ChordTolerance,
) -> serde_json::Value {
    let l = &stack.layers[i];
    let placed = place_layer_markers(si, l, tol);
    let tech = feature_technology(si, &si.layers[i]);
    let mut sets = marker_summary(l, &placed, tech, si);
    let (outer, inner) = taken_features(si, stack, i, tol);
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
    twin_params(si, l, json!(sets))
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
    si: &StackInput<'_>,
    l: &ResolvedLayer,
    markers: serde_json::Value,
) -> serde_json::Value {
    let mut v = json!({
        "layer": l.name, "body": si.ctx.body, "outer_offset_mm": l.outer_offset_mm,
        "inner_offset_mm": if l.solid { serde_json::Value::Null } else { json!(l.inner_offset_mm) },
        "solid": l.solid, "markers": markers,
    });
    crate::parts::layer_registry::twin_params(si, l.index, &mut v);
    v
}

/// `build` of what every strategy builds layer `i` of `stack` from ([`LayerBuild`]): its
/// placed markers, their summary, its twin parameters and the mold's print technologies.
pub(crate) fn with_layer_build<'d, T>(
    si: &'d StackInput<'d>,
    stack: &'d Stack,
    i: usize,
    tol: ChordTolerance,
    with_skin: WithSkin<'d>,
    build: impl FnOnce(LayerBuild<'_>) -> T,
) -> T {
    let l = &stack.layers[i];
    let name = l.name.clone();
    let placed = place_layer_markers(si, l, tol);
    let spec_layer = &si.layers[i];
    let tech_setting = feature_technology(si, spec_layer);
    let markers_json = marker_summary(l, &placed, tech_setting, si);
    let fixture_tech: PrintTechnology = si.mold.fixture_print_technology.into();
    let cavity_tech: PrintTechnology = si.mold.cavity_print_technology.into();
    let (outer, inner) = (
        on_surface(&placed, MarkerSurface::Outer),
        on_surface(&placed, MarkerSurface::Inner),
    );
    let base_params = twin_params(si, l, json!(markers_json));
    let b = LayerBuild {
        si,
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
        with_skin,
    };
    build(b)
}

/// The parts the families print with the outermost layer when it is printed
/// ([`crate::parts::registry::printed_with_skin`]), asked only when that layer is built.
pub type WithSkin<'a> = &'a (dyn Fn() -> Result<Vec<SkinVolume>, DesignError> + Sync);

/// What a printed layer and every strategy of [`crate::parts::molds::build_layer`] build
/// from: layer `i` of `stack` (`l`), its name, its placed markers (all, on the outer surface,
/// on the inner surface), its marker summary, the twin parameters its parts carry, the print
/// technologies of the mold's fixtures and cavities, and the families' parts printed with the
/// outermost layer.
pub struct LayerBuild<'a> {
    pub(crate) si: &'a StackInput<'a>,
    pub(crate) stack: &'a Stack,
    pub(crate) i: usize,
    pub(crate) tol: ChordTolerance,
    pub(crate) l: &'a ResolvedLayer,
    pub(crate) name: String,
    pub(crate) placed: &'a [PlacedMarkers],
    pub(crate) outer: Vec<&'a PlacedMarkers>,
    pub(crate) inner: Vec<&'a PlacedMarkers>,
    pub(crate) markers_json: Vec<serde_json::Value>,
    pub(crate) base_params: serde_json::Value,
    pub(crate) fixture_tech: PrintTechnology,
    pub(crate) cavity_tech: PrintTechnology,
    pub(crate) with_skin: WithSkin<'a>,
}

/// The parts of a printed layer: the skin with its features (stems only when the tips are
/// separate), one `marker_tips` part per marker set with a `tip_material`, and for the
/// outermost layer the families' parts printed with it (a shaft body's tip fitting,
/// [`LayerBuild::with_skin`]); all moved onto the plate by the same translation, and grouped
/// when there is more than the skin. No pours.
pub(crate) fn build_printed_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (si, stack, i, tol, l, name) = (b.si, b.stack, b.i, b.tol, b.l, &b.name);
    let spec_layer = &si.layers[i];
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    let skin = g(layer_solid(si, stack, i, tol))?;
    let tech: PrintTechnology = spec_layer
        .print_technology
        .unwrap_or(Technology::Polyjet)
        .into();
    // The families' parts printed with the outermost layer, as further volumes of its
    // object (the shaft body's tip fitting).
    let with_skin = if i + 1 == stack.layers.len() {
        (b.with_skin)()?
    } else {
        Vec::new()
    };
    let group = (b.placed.iter().any(|p| p.spec.tip_material.is_some()) || !with_skin.is_empty())
        .then(|| name.clone());
    // Skin, tips and the families' parts move together onto the plate (same translation).
    let extent = if with_skin.is_empty() {
        skin.clone()
    } else {
        let mut all = vec![skin.clone()];
        all.extend(with_skin.iter().map(|p| p.solid.clone()));
        Solid::compose(&all)
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
    let carriers: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
    for p in with_skin {
        parts.push(Part {
            name: p.name,
            role: p.role,
            description: p.description,
            material: p.material,
            print_technology: tech,
            solid: p.solid.translate(shift),
            params: with_pose(p.params, &pose),
            group: group.clone(),
        });
    }
    let mut markers = b.markers_json;
    set_forming(&mut markers, &carriers, &carriers, 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![],
        markers,
    })
}
