//! Laser-cut parts: their outlines in the plane, for DXF and SVG (export crate).
//!
//! R-Tac0's diffuser is laser-cut from double-sided frosted acrylic (Sec. III-B2); ShadowTac's
//! skin is glued to a PMMA plate (Sec. IV-A). Each part is drawn in its own plane, in mm, centred
//! on the sensor axis (x and y of the sensor frame).

use crate::schema::Design;

pub use crate::parts::cut_part::{ring_area_mm2, CutPart, Operation, Outline};
use crate::parts::registry::FAMILIES;

/// The laser-cut parts of a design: every family's ([`crate::parts::family::Family::cut_parts`]:
/// the housing's diffuser ring, the shaft body's lens window ...), then the backing plate.
pub fn cut_parts(design: &Design) -> Vec<CutPart> {
    let mut out = Vec::new();
    for f in FAMILIES {
        out.extend(f.cut_parts(design));
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
            outlines: vec![(Operation::Cut, Outline::centred_circle(b.diameter_mm / 2.0))],
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
    let mut out = Vec::new();
    for f in FAMILIES {
        out.extend(f.pcb_outlines(design));
    }
    out
}
