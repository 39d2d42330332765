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
    use dxf::enums::{AcadVersion, DrawingUnits, Units};
    use dxf::tables::Layer;
    let mut d = dxf::Drawing::new();
    d.header.version = AcadVersion::R2000;
    // $INSUNITS 4 (millimetres) and $MEASUREMENT 1 (metric) agree: a CAD or laser program
    // that reads either scales the same
    d.header.default_drawing_units = Units::Millimeters;
    d.header.drawing_units = DrawingUnits::Metric;
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
            Outline::Polygon { points_mm } => {
                let mut poly = dxf::entities::LwPolyline::default();
                poly.set_is_closed(true);
                poly.vertices = points_mm
                    .iter()
                    .map(|p| dxf::LwPolylineVertex {
                        x: p[0],
                        y: p[1],
                        ..Default::default()
                    })
                    .collect();
                Entity::new(EntityType::LwPolyline(poly))
            }
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

/// The SVG of `part` for the laser: a `width`/`height` in mm with a viewBox in mm, one group
/// per operation, hairline strokes (0.01 mm: what laser software takes as a vector cut).
pub fn svg_text(part: &CutPart) -> String {
    let extent = cut_extent(part);
    let size = 2.0 * extent;
    let mut doc = svg::Document::new()
        .set("width", format!("{size}mm"))
        .set("height", format!("{size}mm"))
        .set("viewBox", (-extent, -extent, size, size));
    for g in operation_groups(part, 0.01) {
        doc = doc.add(g);
    }
    doc.to_string()
}

/// The SVG of `part` to look at (a browser, a viewer): its outlines in 0.25 mm strokes over
/// the part's face shaded, its name, sheet and count under it, and a 10 mm scale bar. Not for
/// the laser (it would cut the label): `svg_text` is.
pub fn svg_preview_text(part: &CutPart, material_name: &str) -> String {
    use svg::node::element::{Line, Path, Text};
    let extent = cut_extent(part);
    let size = 2.0 * extent;
    let label_mm = 3.0;
    let height = size + 2.0 * label_mm + 1.0;
    let mut doc = svg::Document::new()
        .set("width", format!("{size}mm"))
        .set("height", format!("{height}mm"))
        .set("viewBox", (-extent, -extent, size, height));
    // the face: every outline in one path, filled even-odd (the holes open)
    let face: String = part
        .outlines
        .iter()
        .filter(|(o, _)| *o == Operation::Cut)
        .map(|(_, outline)| outline_path(outline))
        .collect::<Vec<_>>()
        .join(" ");
    doc = doc.add(
        Path::new()
            .set("d", face)
            .set("fill", "#f2e6d0")
            .set("fill-rule", "evenodd")
            .set("stroke", "none"),
    );
    for g in operation_groups(part, 0.25) {
        doc = doc.add(g);
    }
    let count = if part.quantity > 1 {
        format!("{} x ", part.quantity)
    } else {
        String::new()
    };
    let text = format!(
        "{count}{}: {material_name}, {} mm sheet",
        part.name, part.thickness_mm
    );
    let font = (label_mm * 0.8).min(size / (0.6 * text.len().max(1) as f64));
    doc = doc.add(
        Text::new(text)
            .set("x", -extent + 0.5)
            .set("y", extent + label_mm)
            .set("font-family", "sans-serif")
            .set("font-size", font)
            .set("fill", "#202020"),
    );
    // a 10 mm scale bar (shorter on a small part), labelled
    let bar = if size > 24.0 { 10.0 } else { 5.0 };
    let y = extent + 2.0 * label_mm;
    doc = doc.add(
        Line::new()
            .set("x1", -extent + 0.5)
            .set("y1", y)
            .set("x2", -extent + 0.5 + bar)
            .set("y2", y)
            .set("stroke", "#202020")
            .set("stroke-width", 0.35),
    );
    doc = doc.add(
        Text::new(format!("{bar} mm"))
            .set("x", -extent + 1.0 + bar)
            .set("y", y + 0.8)
            .set("font-family", "sans-serif")
            .set("font-size", font.min(2.0))
            .set("fill", "#202020"),
    );
    doc.to_string()
}

/// Half the side of the square a cut part's drawing fills, mm: its farthest outline point
/// from the axis and 1 mm.
fn cut_extent(part: &CutPart) -> f64 {
    part.outlines
        .iter()
        .map(|(_, o)| o.extent_mm())
        .fold(0.0, f64::max)
        + 1.0
}

/// An outline as SVG path data, y flipped (SVG's y runs down).
fn outline_path(outline: &Outline) -> String {
    match outline {
        Outline::Circle {
            centre_mm,
            radius_mm,
        } => {
            let (x, y, r) = (centre_mm[0], -centre_mm[1], *radius_mm);
            format!(
                "M{},{} A{r},{r} 0 1 0 {},{} A{r},{r} 0 1 0 {},{} Z",
                x - r,
                y,
                x + r,
                y,
                x - r,
                y
            )
        }
        Outline::Polygon { points_mm } => {
            points_mm
                .iter()
                .enumerate()
                .map(|(i, p)| format!("{}{},{}", if i == 0 { "M" } else { "L" }, p[0], -p[1]))
                .collect::<Vec<_>>()
                .join(" ")
                + " Z"
        }
    }
}

/// One group per operation of `part` (cut red, engrave blue) with strokes `stroke_mm` wide:
/// circles as circles, polygons as closed paths, y flipped.
fn operation_groups(part: &CutPart, stroke_mm: f64) -> Vec<svg::node::element::Group> {
    use svg::node::element::{Circle, Group, Path};
    let mut out = Vec::new();
    for (op, colour) in [(Operation::Cut, "#ff0000"), (Operation::Engrave, "#0000ff")] {
        let mut g = Group::new()
            .set("id", layer(op))
            .set("fill", "none")
            .set("stroke", colour)
            .set("stroke-width", stroke_mm);
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
                    .set("r", *radius_mm)
                    .into(),
                Outline::Polygon { .. } => {
                    let node: Box<dyn svg::Node> =
                        Box::new(Path::new().set("d", outline_path(outline)));
                    node
                }
            });
        }
        if any {
            out.push(g);
        }
    }
    out
}

/// The extents of drawing `d` in the model, dimensions included: [x0, x1, z0, z1], mm (the
/// section mirrored about the axis).
fn drawing_extents(d: &fabkit_designs::parts::core_shell::Drawing) -> [f64; 4] {
    use fabkit_designs::parts::core_shell::DimensionAxis;
    let (mut x0, mut x1, mut z0, mut z1) = (0.0f64, 0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    for &[r, z] in &d.section_rz_mm {
        x1 = x1.max(r);
        z0 = z0.min(z);
        z1 = z1.max(z);
    }
    x0 = x0.min(-x1);
    for dim in &d.dimensions {
        match dim.axis {
            DimensionAxis::Horizontal => {
                z0 = z0.min(dim.at_mm);
                z1 = z1.max(dim.at_mm);
            }
            DimensionAxis::Vertical => {
                x0 = x0.min(dim.at_mm);
                x1 = x1.max(dim.at_mm);
            }
        }
    }
    [x0, x1, z0, z1]
}

/// The drawing's definitions: the section's 45 deg hatch and the dimension lines' arrow.
fn drawing_definitions() -> svg::node::element::Definitions {
    use svg::node::element::{Definitions, Line, Marker, Path, Pattern};
    let hatch = Pattern::new()
        .set("id", "hatch")
        .set("patternUnits", "userSpaceOnUse")
        .set("width", 1.5)
        .set("height", 1.5)
        .set("patternTransform", "rotate(45)")
        .add(
            Line::new()
                .set("x1", 0)
                .set("y1", 0)
                .set("x2", 0)
                .set("y2", 1.5)
                .set("stroke", "#000000")
                .set("stroke-width", 0.18),
        );
    let arrow = Marker::new()
        .set("id", "arrow")
        .set("viewBox", "0 0 10 10")
        .set("refX", 10)
        .set("refY", 5)
        .set("markerUnits", "userSpaceOnUse")
        .set("markerWidth", 3)
        .set("markerHeight", 3)
        .set("orient", "auto-start-reverse")
        .add(
            Path::new()
                .set("d", "M 0 2 L 10 5 L 0 8 z")
                .set("fill", "#000000"),
        );
    Definitions::new().add(hatch).add(arrow)
}

/// The dimensions of drawing `d` at scale `k` (paper mm per model mm), text `font` mm high:
/// each with its extension lines, arrowed dimension line and value.
fn dimensions_group(
    d: &fabkit_designs::parts::core_shell::Drawing,
    k: f64,
    font: f64,
) -> svg::node::element::Group {
    use fabkit_designs::parts::core_shell::DimensionAxis;
    use svg::node::element::{Group, Line, Text};
    let fmt = |v: f64| format!("{v:.3}");
    let (px, pz) = (|x: f64| k * x, |z: f64| -k * z);
    let mut dims = Group::new()
        .set("id", "dimensions")
        .set("stroke", "#000000")
        .set("stroke-width", 0.18)
        .set("font-family", "sans-serif")
        .set("font-size", font);
    let line = |a: [f64; 2], b: [f64; 2]| {
        Line::new()
            .set("x1", fmt(a[0]))
            .set("y1", fmt(a[1]))
            .set("x2", fmt(b[0]))
            .set("y2", fmt(b[1]))
    };
    for dim in &d.dimensions {
        let (f, t) = (
            [px(dim.from_mm[0]), pz(dim.from_mm[1])],
            [px(dim.to_mm[0]), pz(dim.to_mm[1])],
        );
        let (a, b, label_at, rotate) = match dim.axis {
            DimensionAxis::Horizontal => {
                let y = pz(dim.at_mm);
                let a = [f[0], y];
                let b = [t[0], y];
                let ext = if y > f[1] { 1.5 } else { -1.5 };
                dims = dims
                    .add(line([f[0], f[1]], [f[0], y + ext]))
                    .add(line([t[0], t[1]], [t[0], y + ext]));
                (a, b, [(a[0] + b[0]) / 2.0, y - 0.8], false)
            }
            DimensionAxis::Vertical => {
                let x = px(dim.at_mm);
                let a = [x, f[1]];
                let b = [x, t[1]];
                let ext = if x > f[0] { 1.5 } else { -1.5 };
                dims = dims
                    .add(line([f[0], f[1]], [x + ext, f[1]]))
                    .add(line([t[0], t[1]], [x + ext, t[1]]));
                (a, b, [x - 0.8, (a[1] + b[1]) / 2.0], true)
            }
        };
        dims = dims.add(
            line(a, b)
                .set("marker-start", "url(#arrow)")
                .set("marker-end", "url(#arrow)"),
        );
        let mut text = Text::new(dim.label.clone())
            .set("x", fmt(label_at[0]))
            .set("y", fmt(label_at[1]))
            .set("text-anchor", "middle")
            .set("stroke", "none")
            .set("fill", "#000000");
        if rotate {
            text = text.set(
                "transform",
                format!("rotate(-90 {} {})", fmt(label_at[0]), fmt(label_at[1])),
            );
        }
        dims = dims.add(text);
    }
    dims
}

/// The SVG of a dimensioned drawing ([`fabkit_designs::parts::core_shell::Drawing`]): the
/// section through the axis hatched, the axis as a chain line, each dimension with its
/// extension lines, arrowed dimension line and value, then the title and notes. Paper units
/// are mm (`width`/`height` in mm), the drawing at a scale of 1, 2, 4, 5 or 10 to 1 (the
/// largest that keeps it under 170 mm high), given in the title line.
pub fn drawing_svg(d: &fabkit_designs::parts::core_shell::Drawing) -> String {
    use svg::node::element::{Group, Line, Polygon, Text, Title};
    let [x0, x1, z0, z1] = drawing_extents(d);
    let height = (z1 - z0).max(1e-3);
    let k = [10.0, 5.0, 4.0, 2.0, 1.0]
        .into_iter()
        .find(|k| k * height <= 170.0)
        .unwrap_or(1.0);
    let font = 3.0;
    let margin = 12.0;
    let (px, pz) = (|x: f64| k * x, |z: f64| -k * z);
    let left = px(x0) - margin;
    let top = pz(z1) - margin;
    // the title line and the notes, wrapped at 95 characters (under 0.6 em each in a
    // sans-serif font)
    let heading = format!("{}: section through the axis, scale {k}:1, mm", d.title);
    let lines: Vec<String> = std::iter::once(&heading)
        .chain(&d.notes)
        .flat_map(|n| wrap(n, 95))
        .collect();
    let notes_h = (lines.len() as f64 + 2.0) * font * 1.5;
    let longest = lines.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    let width = (px(x1) - px(x0) + 2.0 * margin).max(longest as f64 * 0.6 * font + 8.0);
    let paper_h = pz(z0) - pz(z1) + 2.0 * margin + notes_h;
    let fmt = |v: f64| format!("{v:.3}");
    let points = |sign: f64| {
        d.section_rz_mm
            .iter()
            .map(|&[r, z]| format!("{},{}", fmt(px(sign * r)), fmt(pz(z))))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut doc = svg::Document::new()
        .set("width", format!("{}mm", fmt(width)))
        .set("height", format!("{}mm", fmt(paper_h)))
        .set("viewBox", (fmt(left), fmt(top), fmt(width), fmt(paper_h)))
        .add(Title::new(d.title.clone()))
        .add(drawing_definitions());
    let mut section = Group::new()
        .set("id", "section")
        .set("fill", "url(#hatch)")
        .set("stroke", "#000000")
        .set("stroke-width", 0.35);
    for sign in [1.0, -1.0] {
        section = section.add(Polygon::new().set("points", points(sign)));
    }
    doc = doc.add(section).add(
        Line::new()
            .set("id", "axis")
            .set("x1", 0)
            .set("y1", fmt(pz(z1) - 3.0))
            .set("x2", 0)
            .set("y2", fmt(pz(z0) + 3.0))
            .set("stroke", "#000000")
            .set("stroke-width", 0.18)
            .set("stroke-dasharray", "6 1.5 1 1.5"),
    );
    doc = doc.add(dimensions_group(d, k, font));
    let mut notes = Group::new()
        .set("id", "notes")
        .set("font-family", "sans-serif")
        .set("font-size", font)
        .set("fill", "#000000");
    let y0 = pz(z0) + margin;
    for (i, n) in lines.iter().enumerate() {
        notes = notes.add(
            Text::new(n.clone())
                .set("x", fmt(left + 4.0))
                .set("y", fmt(y0 + (i as f64 + 1.0) * font * 1.5)),
        );
    }
    doc.add(notes).to_string()
}

/// `text` broken at spaces into lines of at most `width` characters (a longer word keeps its
/// own line).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for word in text.split(' ') {
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut cur));
        }
        if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(word);
    }
    lines.push(cur);
    lines
}
