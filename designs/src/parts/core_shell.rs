//! The core as a shell of revolution, and a core made to order by a machine shop (UVDtact's
//! acrylic shell, CNC machined and vapour polished, Sec. III): its solid, its exact shape for
//! the STEP file and its dimensioned drawing (a section through the axis).
//!
//! The outer surface is the inner surface of the innermost layer (an offset of the body
//! profile); the inner one is [`BodyProfile::shell_inner_surface`]: the concentric sphere on
//! spherical profiles, the half ellipsoid of the outer rim radius and pole height less the wall
//! on the half ellipsoid. Both continue straight down `below_base_mm` under the base plane to
//! the open end.

use super::ExactShape;
use crate::error::{DesignError, GeometryContext as _};
use crate::geometry::{revolve, ChordTolerance, Polyline2, Solid};
use crate::parts::context::Context;
use crate::parts::context::ResolvedCore;
use crate::profile::BodyProfile;
use crate::schema::shared::{Core, CoreMachining};

/// The closed (r, z) profile of the core, sensor frame, mm: the shell between its outer and
/// inner surfaces ([`BodyProfile::core_shell_profile`]), or, when the wall leaves no bore,
/// the solid under its outer surface.
pub fn profile(ctx: &Context<'_>, c: &ResolvedCore, spec: &Core, tol: ChordTolerance) -> Polyline2 {
    ctx.body
        .core_shell_profile(
            c.outer_offset_mm,
            spec.wall_thickness_mm,
            c.below_base_mm,
            tol.half(),
        )
        .unwrap_or_else(|| {
            ctx.body
                .solid_profile(c.outer_offset_mm, c.below_base_mm, tol.half())
        })
}

/// The exact shape of a core with a bore, for the CadQuery twin: `{"shape": "core_shell",
/// "params": {"body", "outer_offset_mm", "wall_thickness_mm", "below_base_mm"}}` (the twin
/// derives the inner surface by the same rule); `None` without a bore.
pub fn exact_shape(ctx: &Context<'_>, c: &ResolvedCore, spec: &Core) -> Option<ExactShape> {
    ctx.body
        .shell_inner_surface(c.outer_offset_mm, spec.wall_thickness_mm)?;
    Some(ExactShape::CoreShell {
        params: serde_json::json!({
            "body": ctx.body,
            "outer_offset_mm": c.outer_offset_mm,
            "wall_thickness_mm": spec.wall_thickness_mm,
            "below_base_mm": c.below_base_mm,
        }),
    })
}

/// A part made to order by a machine shop rather than printed: written as a dimensioned
/// drawing (SVG) and, with STEP export, as its exact solid.
#[derive(Debug, Clone)]
pub struct MachinedPart {
    /// File stem, `[a-z0-9_]+`, unique among the kit's parts.
    pub name: String,
    pub description: String,
    /// Material key in the materials table (`pmma`).
    pub material: String,
    /// Surface finish asked of the shop.
    pub finish: String,
    /// The solid in the sensor frame, mm (as it sits in the assembly).
    pub solid: Solid,
    /// Its exact shape, for the STEP file.
    pub exact: ExactShape,
    /// The drawing to order it by.
    pub drawing: Drawing,
    /// Numbers worth printing in the manifest (least wall...).
    pub params: serde_json::Value,
}

/// A dimensioned drawing of a solid of revolution: its section through the axis (the (r, z)
/// profile drawn at x = r and mirrored at x = -r), dimensions and notes. Drawing plane: x
/// across, z up (the sensor frame's y = 0 plane), mm.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Drawing {
    pub title: String,
    /// The closed (r, z) profile of the section's right half, mm.
    pub section_rz_mm: Vec<[f64; 2]>,
    pub dimensions: Vec<Dimension>,
    /// One line each, in order: what the surfaces are, material, finish, tolerance.
    pub notes: Vec<String>,
}

/// A linear dimension between two points of the drawing plane (x, z), mm, measured along
/// `axis`, its dimension line at `at_mm` (z for a horizontal dimension, x for a vertical one).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Dimension {
    pub axis: DimensionAxis,
    pub from_mm: [f64; 2],
    pub to_mm: [f64; 2],
    pub at_mm: f64,
    /// The measured length, mm: |to - from| along `axis`.
    pub value_mm: f64,
    /// What is written: the value with two decimals, `Ø` before a diameter.
    pub label: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DimensionAxis {
    Horizontal,
    Vertical,
}

impl Dimension {
    fn new(
        axis: DimensionAxis,
        from_mm: [f64; 2],
        to_mm: [f64; 2],
        at_mm: f64,
        diameter: bool,
    ) -> Self {
        let k = match axis {
            DimensionAxis::Horizontal => 0,
            DimensionAxis::Vertical => 1,
        };
        let value_mm = (to_mm[k] - from_mm[k]).abs();
        let label = format!("{}{value_mm:.2}", if diameter { "Ø" } else { "" });
        Self {
            axis,
            from_mm,
            to_mm,
            at_mm,
            value_mm,
            label,
        }
    }
}

/// The core made to order, when `core.machining` is given and the core has a bore.
///
/// # Errors
/// [`DesignError::Geometry`] when its solid cannot be built.
pub fn machined_part(
    ctx: &Context<'_>,
    c: &ResolvedCore,
    spec: &Core,
    tol: ChordTolerance,
) -> Result<Option<MachinedPart>, DesignError> {
    let Some(m) = &spec.machining else {
        return Ok(None);
    };
    let body = &ctx.body;
    let w = spec.wall_thickness_mm;
    let (Some(exact), Some((inner, d_in)), Some(pl)) = (
        exact_shape(ctx, c, spec),
        body.shell_inner_surface(c.outer_offset_mm, w),
        body.core_shell_profile(c.outer_offset_mm, w, c.below_base_mm, tol.half()),
    ) else {
        return Ok(None);
    };
    let solid = revolve(&pl, tol)
        .and_then(|mesh| Solid::from_mesh(&mesh))
        .part(&m.part_name)?;
    let (least_wall_mm, least_wall_polar_deg) =
        body.least_wall_mm(c.outer_offset_mm, w).unwrap_or((w, 0.0));
    let drawing = drawing(
        ctx,
        c,
        spec,
        m,
        (&inner, d_in),
        &pl,
        least_wall_mm,
        least_wall_polar_deg,
    );
    let params = serde_json::json!({
        "outer_rim_diameter_mm": 2.0 * body.rim_radius_mm(c.outer_offset_mm),
        "bore_diameter_mm": 2.0 * inner.rim_radius_mm(d_in),
        "outer_pole_z_mm": body.pole_z_mm(c.outer_offset_mm),
        "inner_pole_z_mm": inner.pole_z_mm(d_in),
        "open_end_z_mm": body.base_z_mm() - c.below_base_mm,
        "length_mm": spec.length_mm,
        "wall_thickness_mm": w,
        "least_wall_mm": least_wall_mm,
        "least_wall_polar_deg": least_wall_polar_deg,
        "general_tolerance_mm": m.general_tolerance_mm,
    });
    Ok(Some(MachinedPart {
        name: m.part_name.clone(),
        description: format!(
            "{} (made to order from the drawing {}.svg or the STEP file)",
            if spec.description.is_empty() {
                "Core"
            } else {
                spec.description.as_str()
            },
            m.part_name
        ),
        material: spec.material.clone(),
        finish: m.finish.clone(),
        solid,
        exact,
        drawing,
        params,
    }))
}

/// How a surface is made, in words: `half ellipsoid 18.00 mm across, 24.00 mm high` ...
fn surface_words(body: &BodyProfile, d: f64) -> String {
    let shape = match *body {
        BodyProfile::HalfEllipsoid {
            diameter_mm,
            height_mm,
        } => format!("the half ellipsoid Ø{diameter_mm:.2} x {height_mm:.2} mm high (semi-axes {:.2} and {height_mm:.2} mm) on the base plane", diameter_mm / 2.0),
        BodyProfile::SphericalCap {
            base_diameter_mm,
            height_mm,
        } => format!("the spherical cap Ø{base_diameter_mm:.2} x {height_mm:.2} mm high"),
        BodyProfile::HemisphereOnCylinder {
            radius_mm,
            cylinder_length_mm,
        } => format!("the hemisphere R{radius_mm:.2} on a {cylinder_length_mm:.2} mm cylinder"),
        BodyProfile::Flat {
            width_mm,
            length_mm,
            thickness_mm,
            ..
        } => format!("the flat face {width_mm:.2} x {length_mm:.2} mm, {thickness_mm:.2} mm above the base plane"),
    };
    if d == 0.0 {
        shape
    } else {
        format!(
            "{shape}, offset {:.2} mm {}",
            d.abs(),
            if d < 0.0 { "inward" } else { "outward" }
        )
    }
}

#[allow(clippy::too_many_arguments)]
fn drawing(
    ctx: &Context<'_>,
    c: &ResolvedCore,
    spec: &Core,
    m: &CoreMachining,
    (inner, d_in): (&BodyProfile, f64),
    pl: &Polyline2,
    least_wall_mm: f64,
    least_wall_polar_deg: f64,
) -> Drawing {
    use DimensionAxis::{Horizontal, Vertical};
    let body = &ctx.body;
    let (ro, ri) = (
        body.rim_radius_mm(c.outer_offset_mm),
        inner.rim_radius_mm(d_in),
    );
    let zb = body.base_z_mm();
    let z_end = zb - c.below_base_mm;
    let (po, pi) = (body.pole_z_mm(c.outer_offset_mm), inner.pole_z_mm(d_in));
    let gap = 2.5;
    let mut dimensions = vec![
        Dimension::new(Vertical, [ro, z_end], [0.0, po], ro + 2.0 * gap, false),
        Dimension::new(
            Horizontal,
            [-ro, z_end],
            [ro, z_end],
            z_end - 2.0 * gap,
            true,
        ),
        Dimension::new(Horizontal, [-ri, z_end], [ri, z_end], z_end - gap, true),
        Dimension::new(Vertical, [-ri, z_end], [0.0, pi], -ro - gap, false),
        Dimension::new(Vertical, [0.0, pi], [0.0, po], -ro - 2.0 * gap, false),
    ];
    if c.below_base_mm > 0.0 {
        dimensions.push(Dimension::new(
            Vertical,
            [ro, z_end],
            [ro, zb],
            ro + gap,
            false,
        ));
    }
    let mut notes = vec![
        format!(
            "{}: {}",
            m.part_name,
            if spec.description.is_empty() { "core" } else { spec.description.as_str() }
        ),
        format!("Material: {}. Finish: {}.", spec.material, m.finish),
        format!(
            "Outer surface: {}; straight down {:.2} mm below the base plane to the open end.",
            surface_words(body, c.outer_offset_mm),
            c.below_base_mm
        ),
        format!(
            "Inner surface: {}; a Ø{:.2} mm bore down to the open end.",
            surface_words(inner, d_in),
            2.0 * ri
        ),
        format!(
            "Wall {:.2} mm at the pole and the rim, {least_wall_mm:.2} mm at its thinnest ({least_wall_polar_deg:.1} deg from the axis).",
            spec.wall_thickness_mm
        ),
        format!(
            "Section through the axis. Dimensions in mm; general tolerance +/-{:.2} mm. The STEP file {}.step holds the exact surfaces.",
            m.general_tolerance_mm, m.part_name
        ),
    ];
    if c.below_base_mm > 0.0 {
        notes.push(format!(
            "Base plane (datum): {:.2} mm above the open end; the foot below it seats in its holder.",
            c.below_base_mm
        ));
    }
    Drawing {
        title: format!("{} {}", ctx.name, m.part_name),
        section_rz_mm: pl.points.clone(),
        dimensions,
        notes,
    }
}
