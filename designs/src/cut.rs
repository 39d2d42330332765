//! Laser-cut parts: their outlines in the plane, for DXF and SVG (export crate).
//!
//! R-Tac0's diffuser is laser-cut from double-sided frosted acrylic (Sec. III-B2); ShadowTac's
//! skin is glued to a PMMA plate (Sec. IV-A). Each part is drawn in its own plane, in mm, centred
//! on the sensor axis (x and y of the sensor frame).

use crate::schema::Design;
use serde::{Deserialize, Serialize};

/// What the laser does along an outline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Operation {
    /// Cut through the sheet.
    Cut,
    /// Mark the surface only.
    Engrave,
}

/// One closed outline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outline {
    /// A circle, centre (x, y) and radius, mm.
    Circle { centre_mm: [f64; 2], radius_mm: f64 },
    /// A closed polygon, its vertices (x, y) in mm without the closing vertex (a laser-cut
    /// sheet's boundary, arcs as chords within the chord tolerance).
    Polygon { points_mm: Vec<[f64; 2]> },
}

impl Outline {
    /// Enclosed area, mm^2 (unsigned).
    pub fn area_mm2(&self) -> f64 {
        match self {
            Self::Circle { radius_mm, .. } => std::f64::consts::PI * radius_mm * radius_mm,
            Self::Polygon { points_mm } => ring_area_mm2(points_mm).abs(),
        }
    }

    /// The largest |x| and |y| of the outline, mm.
    pub fn extent_mm(&self) -> f64 {
        match self {
            Self::Circle {
                centre_mm,
                radius_mm,
            } => centre_mm[0].abs().max(centre_mm[1].abs()) + radius_mm,
            Self::Polygon { points_mm } => points_mm
                .iter()
                .map(|p| p[0].abs().max(p[1].abs()))
                .fold(0.0, f64::max),
        }
    }
}

/// Signed area of a closed polygon (shoelace), mm^2: positive when counter-clockwise.
pub fn ring_area_mm2(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// A part cut from sheet stock.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CutPart {
    /// File stem, `[a-z0-9_]+`.
    pub name: String,
    pub description: String,
    /// Material key in the materials table.
    pub material: String,
    /// Sheet thickness, mm.
    pub thickness_mm: f64,
    /// The outlines with their operation: the first is the part's outer outline, the others
    /// holes in it. For a part with a kerf, the laser's paths: the part's outline offset by
    /// half the kerf away from the part (out of its outer outline, into its holes).
    pub outlines: Vec<(Operation, Outline)>,
    /// The laser's kerf (width of the cut) the outlines are compensated for, mm (0: none).
    #[serde(default)]
    pub kerf_mm: f64,
    /// How many to cut.
    #[serde(default = "one")]
    pub quantity: u32,
    /// The part as it comes off the laser (the nominal part) when it is a polygonal sheet: its
    /// boundary rings, outer first (counter-clockwise, holes clockwise), mm; for its 3D sheet
    /// and its area. `None` for parts whose outlines are their own (circles, no kerf).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_rings_mm: Option<Vec<Vec<[f64; 2]>>>,
}

fn one() -> u32 {
    1
}

impl CutPart {
    /// Area enclosed by the outlines, mm^2: the outer outline less the holes (the laser's
    /// paths for a part with a kerf; [`Self::nominal_area_mm2`] is the part's).
    pub fn area_mm2(&self) -> f64 {
        let mut cuts = self
            .outlines
            .iter()
            .filter(|(op, _)| *op == Operation::Cut)
            .map(|(_, o)| o.area_mm2());
        let outer = cuts.next().unwrap_or(0.0);
        outer - cuts.sum::<f64>()
    }

    /// Area of the part as it comes off the laser, mm^2: of [`Self::nominal_rings_mm`] when
    /// given, else of the outlines.
    pub fn nominal_area_mm2(&self) -> f64 {
        match &self.nominal_rings_mm {
            Some(rings) => {
                let mut a = rings.iter().map(|r| ring_area_mm2(r).abs());
                let outer = a.next().unwrap_or(0.0);
                outer - a.sum::<f64>()
            }
            None => self.area_mm2(),
        }
    }
}

/// The laser-cut parts of a design: the housing's diffuser ring, the shaft body's lens window,
/// the backing plate.
pub fn cut_parts(design: &Design) -> Vec<CutPart> {
    let circle = |r: f64| Outline::Circle {
        centre_mm: [0.0, 0.0],
        radius_mm: r,
    };
    let mut out = Vec::new();
    if let Some(h) = &design.housing {
        let d = &h.diffuser;
        out.push(CutPart {
            name: "diffuser".into(),
            description: format!(
                "Diffuser ring: double-sided frosted acrylic, {:.1} mm thick, outer diameter \
                 {:.1} mm, inner diameter {:.1} mm (R-Tac0 Sec. III-B2)",
                d.thickness_mm, d.outer_diameter_mm, d.inner_diameter_mm
            ),
            material: "pmma".into(),
            thickness_mm: d.thickness_mm,
            outlines: vec![
                (Operation::Cut, circle(d.outer_diameter_mm / 2.0)),
                (Operation::Cut, circle(d.inner_diameter_mm / 2.0)),
            ],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        });
    }
    if let Some(sb) = &design.shaft_body {
        let w = &sb.lens_window;
        out.push(CutPart {
            name: "lens_window".into(),
            description: format!(
                "Lens window: clear acrylic, {:.1} mm thick, diameter {:.1} mm (Pestell et al. \
                 Sec. III-A: the acrylic lens the gel is filled against)",
                w.thickness_mm, w.diameter_mm
            ),
            material: "pmma".into(),
            thickness_mm: w.thickness_mm,
            outlines: vec![(Operation::Cut, circle(w.diameter_mm / 2.0))],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        });
    }
    if let Some(b) = &design.backing {
        out.push(CutPart {
            name: "backing".into(),
            description: format!(
                "Backing plate: {}, {:.1} mm thick, diameter {:.1} mm",
                b.description, b.thickness_mm, b.diameter_mm
            ),
            material: b.material.clone(),
            thickness_mm: b.thickness_mm,
            outlines: vec![(Operation::Cut, circle(b.diameter_mm / 2.0))],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        });
    }
    out
}

/// The printed circuit boards' outlines of a design, for PCB tools: the fingertip's lighting
/// PCB (UVDtact Sec. III-C): its edge and bore on `cut`, a circle the LED's length across at
/// each LED's place on `engrave` (white on +x, then UV and white alternating every 45 deg).
pub fn pcb_outlines(design: &Design) -> Vec<CutPart> {
    let circle = |[x, y]: [f64; 2], r: f64| Outline::Circle {
        centre_mm: [x, y],
        radius_mm: r,
    };
    let mut out = Vec::new();
    if let Some(f) = &design.fingertip_base {
        let p = &f.led_pcb;
        let mut outlines = vec![
            (Operation::Cut, circle([0.0; 2], p.outer_diameter_mm / 2.0)),
            (Operation::Cut, circle([0.0; 2], p.inner_diameter_mm / 2.0)),
        ];
        let r = p.led_circle_diameter_mm / 2.0;
        for (a, _) in crate::parts::fingertip_base::leds() {
            let (s, c) = a.to_radians().sin_cos();
            outlines.push((
                Operation::Engrave,
                circle([r * c, r * s], p.led_length_mm / 2.0),
            ));
        }
        out.push(CutPart {
            name: "lighting_pcb".into(),
            description: format!(
                "Lighting PCB outline: {:.1} mm board with a {:.1} mm bore, {:.1} mm thick; 8 LED places on a {:.1} mm circle, white on +x then UV and white alternating every 45 deg (UVDtact Sec. III-C)",
                p.outer_diameter_mm, p.inner_diameter_mm, p.thickness_mm, p.led_circle_diameter_mm
            ),
            material: "fr4".into(),
            thickness_mm: p.thickness_mm,
            outlines,
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        });
    }
    out
}
