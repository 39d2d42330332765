//! A part cut from sheet stock or a circuit board's outline: its outlines in the plane, for
//! DXF and SVG (export crate), in mm, centred on the sensor axis (x and y of the sensor frame).

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
    /// A circle of radius `radius_mm` on the sensor axis (centre (0, 0)), mm.
    pub fn centred_circle(radius_mm: f64) -> Outline {
        Outline::Circle {
            centre_mm: [0.0, 0.0],
            radius_mm,
        }
    }

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
