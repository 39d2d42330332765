//! The numbers recorded for each variant: part volumes and triangles, pour volumes and
//! masses, marker count and spacing, the thinnest wall, and a printability verdict per printer
//! profile.

use crate::build::{build_kit_scoped, AssemblyScope};
use crate::kit::{Kit, PrintTechnology};
use crate::markers::{nearest_neighbours, MarkerSurface, Polarity};
use crate::materials::MaterialsTable;
use crate::parts::layers::{
    feature_end_centres, place_layer_markers, recess_clearance_to_base_mm, PlacedMarkers,
};
use crate::schema::{Design, LayerProcess, Technology};
use crate::stack::{validate, ResolvedLayer, Stack};
use crate::{ChordTolerance, DesignError};
use serde::{Deserialize, Serialize};

/// The numbers of one feasible variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Every part of the kit, in kit order.
    pub parts: Vec<PartMetrics>,
    /// Every pour, in casting order.
    pub casts: Vec<CastMetrics>,
    /// Every marker pattern, per layer from the inside out.
    pub markers: Vec<MarkerMetrics>,
    /// The thinnest wall of [`min_wall`], mm; `None` when the design has none of those walls.
    pub min_wall_mm: Option<f64>,
    /// Where that wall is (a parameter path and what it separates).
    pub min_wall_at: Option<String>,
    /// Triangles of all parts together.
    pub triangles: usize,
}

/// One part, measured on the mesh that `fabkit export` writes ([`crate::kit::Part::written_mesh`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartMetrics {
    pub name: String,
    pub print_technology: PrintTechnology,
    /// Enclosed volume, mm^3 (the manifest's `volume_mm3`).
    pub volume_mm3: f64,
    pub triangles: usize,
}

/// One pour, as the kit computes it for the fabrication sheet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CastMetrics {
    /// A layer name, or `silicone_mold:<layer>`.
    pub cast: String,
    pub material: String,
    /// Cavity volume, mL.
    pub cavity_volume_ml: f64,
    /// Mass to mix including the waste allowance, g (density from `designs/materials.yaml`).
    pub total_mass_g: f64,
}

/// One marker pattern, distances measured on the surface ([`crate::markers::stats`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarkerMetrics {
    pub layer: String,
    pub surface: MarkerSurface,
    pub count: usize,
    /// Smallest nearest-neighbour distance, mm (0 for fewer than two markers).
    pub min_spacing_mm: f64,
    pub median_spacing_mm: f64,
}

/// Whether the design can be made on one printer profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// `fdm`, `sla` or `polyjet` (the keys of the design's `printers`).
    pub profile: String,
    pub printable: bool,
    /// The rules broken on this profile (`path = value: rule`), empty when printable.
    pub violations: Vec<String>,
}

/// The printer profiles a verdict is given for, in order.
pub const PROFILES: [(&str, Technology); 3] = [
    ("fdm", Technology::Fdm),
    ("sla", Technology::Sla),
    ("polyjet", Technology::Polyjet),
];

/// The outcome of building one variant.
#[derive(Debug)]
pub enum Outcome {
    /// Built and measured.
    Ok { metrics: Metrics, kit: Box<Kit> },
    /// The design breaks rules: every violation, `path = value: rule`.
    Infeasible(Vec<String>),
    /// The build failed on valid parameters (a kernel failure: a fabkit defect).
    Error(String),
}

/// Validates and builds `design`, then measures the kit.
pub fn evaluate(design: &Design, materials: &MaterialsTable, tol: ChordTolerance) -> Outcome {
    evaluate_bounded(
        design,
        materials,
        tol,
        crate::estimate::DEFAULT_MAX_TRIANGLES,
    )
}

/// [`evaluate`] with a bound on the estimated triangles ([`crate::estimate::check_work`]): a
/// variant past it is an [`Outcome::Error`] naming the estimate and the limit, before its kit
/// is built.
pub fn evaluate_bounded(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
    max_triangles: u64,
) -> Outcome {
    evaluate_scoped(design, materials, tol, max_triangles, AssemblyScope::Whole)
}

/// [`evaluate_bounded`] with the kit's assembly made as `scope` says: the same outcome and
/// metrics, and with [`AssemblyScope::FitCheck`] (a variant measured and not written) a kit
/// whose assembly leaves out the cast layers the fit check did not need.
pub fn evaluate_scoped(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
    max_triangles: u64,
    scope: AssemblyScope,
) -> Outcome {
    let stack = match validate(design, materials, tol) {
        Ok(s) => s,
        Err(e) => return Outcome::Infeasible(e.0.iter().map(ToString::to_string).collect()),
    };
    if let Err(e) = crate::estimate::check_work(design, &stack, tol, max_triangles) {
        return Outcome::Error(e.to_string());
    }
    let kit = match build_kit_scoped(design, tol, u64::MAX, scope) {
        Ok(k) => k,
        Err(DesignError::Params(e)) => {
            return Outcome::Infeasible(e.0.iter().map(ToString::to_string).collect())
        }
        Err(e) => return Outcome::Error(e.to_string()),
    };
    let parts: Vec<PartMetrics> = kit
        .parts
        .iter()
        .map(|p| {
            let mesh = p.written_mesh();
            PartMetrics {
                name: p.name.clone(),
                print_technology: p.print_technology,
                volume_mm3: mesh.signed_volume(),
                triangles: mesh.triangles.len(),
            }
        })
        .collect();
    let casts = kit
        .casts
        .iter()
        .map(|c| CastMetrics {
            cast: c.cast.clone(),
            material: c.material.clone(),
            cavity_volume_ml: c.cavity_volume_ml,
            total_mass_g: c.total_mass_g,
        })
        .collect();
    let mut markers = Vec::new();
    let mut placed_all = Vec::new();
    for l in &stack.layers {
        let placed = place_layer_markers(&design.stack_input(), l, tol);
        for p in &placed {
            markers.push(MarkerMetrics {
                layer: l.name.clone(),
                surface: p.spec.surface,
                count: p.stats.count,
                min_spacing_mm: p.stats.min_spacing_mm,
                median_spacing_mm: p.stats.median_spacing_mm,
            });
        }
        placed_all.push((l, placed));
    }
    let (min_wall_mm, min_wall_at) = match min_wall(design, &stack, &placed_all) {
        Some((w, at)) => (Some(w), Some(at)),
        None => (None, None),
    };
    let triangles = parts.iter().map(|p| p.triangles).sum();
    Outcome::Ok {
        metrics: Metrics {
            parts,
            casts,
            markers,
            min_wall_mm,
            min_wall_at,
            triangles,
        },
        kit: Box::new(kit),
    }
}

/// The thinnest of the walls that fabkit's printability rules measure, mm, and where it is:
///
/// - between neighbouring marker features, at their bases (nearest-neighbour spacing on the
///   surface minus the feature diameter) and at their ends (distance between the hemisphere
///   centres minus the diameter): mold material between recesses, or skin between pins;
/// - behind a recessed feature: the layer thickness minus the feature height (shell layers),
///   or the distance from the recess to the base plane (solid layers);
/// - a printed layer's thickness;
/// - a solid layer's skin between its recess and its outer surface;
/// - `mold.wall_thickness_mm` when a layer is cast in a printed mold sized by it, or the walls
///   of `mold.open_block` beside and beyond the cavity of an `open` mold.
///
/// `None` when the design has none of these. The housing's walls are not included.
pub fn min_wall(
    design: &Design,
    stack: &Stack,
    placed: &[(&ResolvedLayer, Vec<PlacedMarkers>)],
) -> Option<(f64, String)> {
    let mut walls: Vec<(f64, String)> = Vec::new();
    for (l, patterns) in placed {
        let spec_layer = &design.layers[l.index];
        let mut j = 0;
        for (k, spec) in spec_layer.markers.iter().enumerate() {
            // place_layer_markers skips patterns that do not place; keep indices aligned.
            let Some(pm) = patterns.get(j).filter(|p| p.spec == *spec) else {
                continue;
            };
            j += 1;
            let path = format!("layers[{}].markers[{k}]", l.index);
            let f = &pm.spec.feature;
            if pm.markers.len() > 1 {
                walls.push((
                    pm.stats.min_spacing_mm - f.diameter_mm,
                    format!("{path}: between neighbouring features at their bases"),
                ));
                let ends = feature_end_centres(&pm.markers, f, pm.direction);
                let closest = nearest_neighbours(&ends)
                    .iter()
                    .map(|n| n.1)
                    .fold(f64::INFINITY, f64::min);
                walls.push((
                    closest - f.diameter_mm,
                    format!("{path}: between neighbouring features at their ends"),
                ));
            }
            if f.side() == Polarity::Recessed {
                if l.solid {
                    let worst =
                        recess_clearance_to_base_mm(&pm.markers, f, design.body.base_z_mm());
                    walls.push((
                        worst,
                        format!("{path}: between recesses and the base plane"),
                    ));
                } else {
                    walls.push((
                        l.thickness_mm - f.height_mm,
                        format!("{path}: behind the recesses in layer '{}'", l.name),
                    ));
                }
            }
        }
    }
    for l in &stack.layers {
        if l.process == LayerProcess::Printed && !l.solid {
            walls.push((
                l.thickness_mm,
                format!("layers[{}]: printed layer '{}'", l.index, l.name),
            ));
        }
    }
    let b = &design.body;
    for l in &stack.layers {
        if let Some((key, r)) =
            crate::parts::layer_registry::layer_seat(&design.stack_input(), l.index)
        {
            walls.push((
                r.skin_mm(b, l.outer_offset_mm, ChordTolerance::default().half()),
                format!(
                    "layers[{}].{key}: the skin between the seat and the outer surface",
                    l.index
                ),
            ));
        }
    }
    // each strategy's walls around the layers cast in it, or the mold's wall_thickness_mm
    let si = design.stack_input();
    let mut sized_by_wall = false;
    for s in crate::parts::molds::STRATEGIES {
        let cast = crate::parts::molds::cast_in(&stack.layers, s.kind());
        if cast.is_empty() {
            continue;
        }
        match s.walls(&si, &cast) {
            Some(w) => walls.extend(w),
            None => sized_by_wall = true,
        }
    }
    if sized_by_wall {
        walls.push((
            design.mold.wall_thickness_mm,
            "mold.wall_thickness_mm: mold wall around the cavity".into(),
        ));
    }
    walls
        .into_iter()
        .filter(|w| w.0.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// A verdict per printer profile ([`PROFILES`]): the design validates when the parts that
/// form the skin (mold cavities, master patterns, printed layers) are made on that profile.
/// Holders, jigs, mold boxes and the housing keep the technology the design gives them.
pub fn printability(
    design: &Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
) -> Vec<Verdict> {
    PROFILES
        .iter()
        .map(|(name, tech)| {
            let mut d = design.clone();
            d.mold.cavity_print_technology = *tech;
            for l in &mut d.layers {
                if l.process == LayerProcess::Printed {
                    l.print_technology = Some(*tech);
                }
            }
            let violations = match validate(&d, materials, tol) {
                Ok(_) => vec![],
                Err(e) => e.0.iter().map(ToString::to_string).collect(),
            };
            Verdict {
                profile: (*name).to_string(),
                printable: violations.is_empty(),
                violations,
            }
        })
        .collect()
}
