//! The work of a build estimated from the parameters, before any solid is built: the triangles
//! of the kit's meshes, which set its time and memory (about 1 KB of peak memory per triangle
//! of the written meshes, measured on the library designs).
//!
//! The estimate counts the facets the tessellation will make (the same segment counts as
//! [`crate::geometry::revolve`] and the feature primitives) for every layer surface and every
//! marker feature, each counted once (and once more for each mold cavity, coat or layer cast
//! onto it that the features of a layer under a direct or master mold's coats or cast layers
//! also shape): on the library designs and presets that is 0.87 to 2.28 times the built kits
//! (measured; a test keeps it within 0.75 to 2.6).

use crate::error::DesignError;
use crate::geometry::ChordTolerance;
use crate::parts::context::Stack;
use crate::parts::registry::{SectionInput, FAMILIES};
use crate::schema::Design;

/// Default bound on the estimated triangles of one build: 4,000,000 (about 4 GB of peak memory;
/// the library's kits have 40,000 to 170,000 at the default tolerance).
pub const DEFAULT_MAX_TRIANGLES: u64 = 4_000_000;
/// Largest bound a user may set (`--max-triangles`): 100,000,000.
pub const MAX_TRIANGLES_LIMIT: u64 = 100_000_000;

/// The estimated work of building a design's kit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkEstimate {
    /// Estimated triangles of all parts.
    pub triangles: u64,
    /// Of which from marker features.
    pub marker_triangles: u64,
    /// Markers placed by every pattern.
    pub markers: u64,
}

/// Triangles of a closed profile of `points` points revolved about z with its largest radius
/// `r_max_mm` (as [`crate::geometry::revolve`]: two per profile edge and circumferential
/// segment, at `tol.half()` around).
pub fn revolved_triangles(points: usize, r_max_mm: f64, tol: ChordTolerance) -> f64 {
    2.0 * points as f64 * tol.half().circle_segments(r_max_mm) as f64
}

/// Triangles of the revolved surface at `offset_mm` from the body surface (one side of a
/// layer or a shell); 0 where the body has no such offset.
pub fn offset_surface_triangles(design: &Design, offset_mm: f64, tol: ChordTolerance) -> f64 {
    surface_triangles(design, offset_mm, tol)
}

/// Triangles of one revolved surface at `offset_mm` from the body surface.
fn surface_triangles(design: &Design, offset_mm: f64, tol: ChordTolerance) -> f64 {
    let b = &design.body;
    if !b.offset_is_valid(offset_mm) {
        return 0.0;
    }
    let profile = b.offset_polyline(offset_mm, 0.0, tol.half()).points.len() as f64;
    let around = tol.half().circle_segments(b.rim_radius_mm(offset_mm)) as f64;
    2.0 * profile * around
}

/// Triangles of one marker feature (a cylinder ending in a hemisphere of `radius_mm`).
fn feature_triangles(radius_mm: f64, tol: ChordTolerance) -> f64 {
    let n = tol.half().circle_segments(radius_mm) as f64;
    // the hemisphere's n / 4 latitude bands, the cylinder's band and the closing cap
    2.0 * n * (n / 4.0 + 2.0)
}

/// Estimates the triangles of the kit of `design` at `tol` from its validated `stack`. Costs
/// one placement of every marker pattern (bounded by
/// [`crate::markers::MAX_MARKERS_PER_PATTERN`]) and the 1D profiles of the layer surfaces.
pub fn estimate(design: &Design, stack: &Stack, tol: ChordTolerance) -> WorkEstimate {
    let mut surfaces = 0.0;
    for l in &stack.layers {
        surfaces += surface_triangles(design, l.outer_offset_mm, tol);
        if !l.solid {
            surfaces += surface_triangles(design, l.inner_offset_mm, tol);
        }
        if let Some(r) = crate::parts::layer_registry::seat_of(&design.stack_input(), l.index) {
            // the recess's surface three times: in the layer's part, its assembly member and
            // the mold's insert
            let profile = r.polyline(0.0, 0.0, tol.half()).points.len() as f64;
            let around = tol
                .half()
                .circle_segments(design.body.rim_radius_mm(l.outer_offset_mm))
                as f64;
            surfaces += 3.0 * 2.0 * profile * around;
        }
    }
    for l in &stack.layers {
        if l.process == crate::schema::LayerProcess::Cast {
            surfaces += crate::parts::molds::strategy_of(l.mold_strategy).estimated_triangles(
                &design.body,
                l,
                tol,
            );
        }
    }
    if let Some(c) = &stack.core {
        surfaces += surface_triangles(design, c.outer_offset_mm, tol);
        surfaces += surface_triangles(design, c.inner_offset_mm, tol);
    }
    for f in FAMILIES {
        surfaces += f.estimated_triangles(SectionInput { design, stack, tol });
    }
    let (mut markers, mut feature_tris) = (0u64, 0.0);
    for l in &stack.layers {
        // outer features also in a direct or master mold's cavity, the coats over the layer
        // and the layer cast onto it (crate::parts::layers::taken_features)
        let copies = 1.0 + crate::parts::layers::outer_feature_copies(stack, l.index) as f64;
        for (spec, _, _, placed) in
            crate::parts::layer_markers::placed_patterns(&design.stack_input(), l)
        {
            let n = placed.len();
            markers += n as u64;
            let k = if spec.surface == crate::markers::MarkerSurface::Outer {
                copies
            } else {
                1.0
            };
            feature_tris += k * n as f64 * feature_triangles(spec.feature.radius_mm(), tol);
        }
    }
    let marker_triangles = feature_tris;
    WorkEstimate {
        triangles: (surfaces + marker_triangles).round() as u64,
        marker_triangles: marker_triangles.round() as u64,
        markers,
    }
}

/// [`estimate`], refused past `max_triangles`.
///
/// # Errors
/// [`DesignError::WorkLimit`] giving the estimate (and the part of it from marker features),
/// the limit and how to raise it, before anything is built.
pub fn check_work(
    design: &Design,
    stack: &Stack,
    tol: ChordTolerance,
    max_triangles: u64,
) -> Result<WorkEstimate, DesignError> {
    let e = estimate(design, stack, tol);
    if e.triangles > max_triangles {
        return Err(DesignError::WorkLimit(format!(
            "{}: the kit would have about {} triangles at chord tolerance {} mm ({} of them in \
             {} marker features), more than the limit of {max_triangles} (about 1 KB of memory \
             each; raise it with --max-triangles, up to {MAX_TRIANGLES_LIMIT}, or coarsen \
             --chord-tolerance-mm)",
            design.name,
            e.triangles,
            tol.mm(),
            e.marker_triangles,
            e.markers
        )));
    }
    Ok(e)
}

/// Checks a `--max-triangles` value given as text.
///
/// # Errors
/// The rule, for a value that is not a whole number from 1 to [`MAX_TRIANGLES_LIMIT`].
pub fn parse_max_triangles(value: &str) -> Result<u64, String> {
    match value.trim().parse::<u64>() {
        Ok(n) if (1..=MAX_TRIANGLES_LIMIT).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of triangles from 1 to {MAX_TRIANGLES_LIMIT}"
        )),
    }
}
