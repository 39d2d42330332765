//! 2D outputs of laser-cut parts ([`fabkit_designs::cut`]): DXF (R2000, mm, one layer per
//! operation: `cut`, `engrave`) through the `dxf` crate, and SVG (mm, hairline strokes: cut in
//! red, engrave in blue) through the `svg` crate. Both in the part's plane, y up in the DXF and
//! down in the SVG (the SVG's convention), centred on the sensor axis.

use crate::error::ExportError;
use fabkit_designs::cut::{CutPart, Operation, Outline};

/// Layer name of an operation (DXF layer, SVG group id).
fn layer(op: Operation) -> &'static str {
    match op {
        Operation::Cut => "cut",
        Operation::Engrave => "engrave",
    }
}

/// The DXF of `part`. The header's dates are fixed (2000-01-01) and its GUIDs derived from the
/// part's name, so that the same part gives the same bytes.
///
/// # Errors
/// [`ExportError::Encode`] if the writer fails.
pub fn dxf_bytes(part: &CutPart) -> Result<Vec<u8>, ExportError> {
    use chrono::TimeZone;
    use dxf::entities::{Circle, Entity, EntityType};
    use dxf::enums::{AcadVersion, Units};
    use dxf::tables::Layer;
    let mut d = dxf::Drawing::new();
    d.header.version = AcadVersion::R2000;
    d.header.default_drawing_units = Units::Millimeters;
    let epoch = chrono::Utc.with_ymd_and_hms(2000, 1, 1, 0, 0, 0).unwrap();
    d.header.creation_date = epoch.with_timezone(&chrono::Local);
    d.header.update_date = epoch.with_timezone(&chrono::Local);
    d.header.creation_date_universal = epoch;
    d.header.update_date_universal = epoch;
    let guid = {
        use sha2::Digest;
        let h = sha2::Sha256::digest(format!("fabkit cut part {}", part.name));
        let mut b = [0u8; 16];
        b.copy_from_slice(&h[..16]);
        uuid::Uuid::from_bytes(b)
    };
    d.header.fingerprint_guid = guid;
    d.header.version_guid = guid;
    for (op, colour) in [(Operation::Cut, 1u8), (Operation::Engrave, 5u8)] {
        if part.outlines.iter().any(|(o, _)| *o == op) {
            d.add_layer(Layer {
                name: layer(op).into(),
                color: dxf::Color::from_index(colour),
                ..Default::default()
            });
        }
    }
    for (op, outline) in &part.outlines {
        let mut e = match outline {
            Outline::Circle {
                centre_mm,
                radius_mm,
            } => Entity::new(EntityType::Circle(Circle::new(
                dxf::Point::new(centre_mm[0], centre_mm[1], 0.0),
                *radius_mm,
            ))),
        };
        e.common.layer = layer(*op).into();
        d.add_entity(e);
    }
    let mut out = Vec::new();
    let encode = |reason: String| ExportError::Encode {
        what: format!("{}.dxf", part.name),
        reason,
    };
    d.save(&mut out).map_err(|e| encode(e.to_string()))?;
    let text = String::from_utf8(out).map_err(|e| encode(e.to_string()))?;
    Ok(with_table_handles(&text).into_bytes())
}

/// First handle given to a table head, far above the handles the `dxf` crate assigns.
const TABLE_HANDLE_BASE: u64 = 0x10000;

/// `text` (a DXF written by the `dxf` crate) with a handle (code 5) and an owner (code 330,
/// the root) on every table head, and `$HANDSEED` past them: R2000 requires them, and the
/// crate leaves them out (ezdxf's audit then reports "invalid table head handle").
fn with_table_handles(text: &str) -> String {
    let lines: Vec<&str> = text.split("\r\n").collect();
    let mut out: Vec<String> = Vec::with_capacity(lines.len() + 32);
    let mut next = TABLE_HANDLE_BASE;
    let mut k = 0;
    while k + 1 < lines.len() {
        let (code, value) = (lines[k], lines[k + 1]);
        out.push(code.to_string());
        out.push(value.to_string());
        let after_table = k >= 2 && lines[k - 2].trim() == "0" && lines[k - 1] == "TABLE";
        if code.trim() == "2" && after_table {
            out.extend([
                "  5".to_string(),
                format!("{next:X}"),
                "330".to_string(),
                "0".to_string(),
            ]);
            next += 1;
        }
        k += 2;
    }
    out.extend(lines[k..].iter().map(|l| (*l).to_string()));
    // $HANDSEED: the next free handle
    if let Some(i) = out.iter().position(|l| l == "$HANDSEED") {
        if i + 2 < out.len() {
            out[i + 2] = format!("{next:X}");
        }
    }
    out.join("\r\n")
}

/// The SVG of `part`: a `width`/`height` in mm with a viewBox in mm, one group per operation.
pub fn svg_text(part: &CutPart) -> String {
    use svg::node::element::{Circle, Group};
    let extent = part
        .outlines
        .iter()
        .map(|(_, o)| match o {
            Outline::Circle {
                centre_mm,
                radius_mm,
            } => centre_mm[0].abs().max(centre_mm[1].abs()) + radius_mm,
        })
        .fold(0.0, f64::max)
        + 1.0;
    let size = 2.0 * extent;
    let mut doc = svg::Document::new()
        .set("width", format!("{size}mm"))
        .set("height", format!("{size}mm"))
        .set("viewBox", (-extent, -extent, size, size));
    for (op, colour) in [(Operation::Cut, "#ff0000"), (Operation::Engrave, "#0000ff")] {
        let mut g = Group::new()
            .set("id", layer(op))
            .set("fill", "none")
            .set("stroke", colour)
            .set("stroke-width", 0.01);
        let mut any = false;
        for (o, outline) in &part.outlines {
            if *o != op {
                continue;
            }
            any = true;
            g = g.add(match outline {
                Outline::Circle {
                    centre_mm,
                    radius_mm,
                } => Circle::new()
                    .set("cx", centre_mm[0])
                    .set("cy", -centre_mm[1])
                    .set("r", *radius_mm),
            });
        }
        if any {
            doc = doc.add(g);
        }
    }
    doc.to_string()
}
