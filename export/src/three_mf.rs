//! The kit 3MF: one named mesh object per part, laid out on the plate by build items.
//!
//! Why our own writer rather than `threemf::write` (threemf 0.8.1):
//! it starts every zip entry with `SimpleFileOptions::default()`, whose timestamp is the
//! current time as soon as any crate in the build enables zip's `time` feature (Cargo feature
//! unification; zip's default features include it), and whose host-system byte follows the
//! platform, so the same kit would not give byte-identical files; it offers no way to pass a
//! fixed time. `threemf` is still used as an independent reader in the tests.
//!
//! Coordinates are the f32-rounded values printed as the shortest decimal that reads back to
//! the same f64 (e.g. `0.10000000149011612` for 0.1f32): readers that parse f32 (slicers) and
//! readers that parse f64 (trimesh, `threemf`) both get exactly the mesh the manifest describes.
//!
//! The XML follows the 3MF Core Specification 1.3: `model` in the 2015/02 core namespace,
//! `unit="millimeter"`, well-known metadata names only, `type="model"` objects, and build
//! items whose `transform` is `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32` (row vectors,
//! translation last).

use crate::ExportError;
use fabkit_designs::geometry::Mesh;
use std::fmt::Write as _;
use std::io::{Cursor, Write as _};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, System, ZipWriter};

const CONTENT_TYPES: &str = concat!(
    r#"<?xml version="1.0" encoding="UTF-8"?>"#,
    "\n",
    r#"<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">"#,
    r#"<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>"#,
    r#"<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>"#,
    "</Types>\n"
);

const RELS: &str = concat!(
    r#"<?xml version="1.0" encoding="UTF-8"?>"#,
    "\n",
    r#"<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">"#,
    r#"<Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>"#,
    "</Relationships>\n"
);

/// One object of the 3MF and its build item.
pub(crate) struct Object<'a> {
    /// Object name (the part name).
    pub name: &'a str,
    /// Mesh in part coordinates, f32-rounded, shared vertices, outward winding.
    pub mesh: &'a Mesh,
    /// Build-item translation, mm.
    pub translation_mm: [f64; 3],
}

/// The `3D/3dmodel.model` XML. Object ids are 1, 2, ... in input order.
pub(crate) fn model_xml(objects: &[Object<'_>], metadata: &[(&str, String)]) -> String {
    let mut x = String::new();
    // `write!` into a String cannot fail; the results are ignored on purpose.
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(
        "<model unit=\"millimeter\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n",
    );
    for (name, value) in metadata {
        let _ = writeln!(
            x,
            " <metadata name=\"{}\">{}</metadata>",
            escape(name),
            escape(value)
        );
    }
    x.push_str(" <resources>\n");
    for (i, o) in objects.iter().enumerate() {
        let _ = writeln!(
            x,
            "  <object id=\"{}\" name=\"{}\" type=\"model\">",
            i + 1,
            escape(o.name)
        );
        x.push_str("   <mesh>\n    <vertices>\n");
        for v in &o.mesh.vertices {
            let _ = writeln!(
                x,
                "     <vertex x=\"{}\" y=\"{}\" z=\"{}\"/>",
                coord_text(v[0]),
                coord_text(v[1]),
                coord_text(v[2])
            );
        }
        x.push_str("    </vertices>\n    <triangles>\n");
        for t in &o.mesh.triangles {
            let _ = writeln!(
                x,
                "     <triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>",
                t[0], t[1], t[2]
            );
        }
        x.push_str("    </triangles>\n   </mesh>\n  </object>\n");
    }
    x.push_str(" </resources>\n <build>\n");
    for (i, o) in objects.iter().enumerate() {
        let [tx, ty, tz] = o.translation_mm.map(f64_text);
        let _ = writeln!(
            x,
            "  <item objectid=\"{}\" transform=\"1 0 0 0 1 0 0 0 1 {tx} {ty} {tz}\"/>",
            i + 1
        );
    }
    x.push_str(" </build>\n</model>\n");
    x
}

/// The whole 3MF package as bytes: `[Content_Types].xml`, `_rels/.rels`, `3D/3dmodel.model`,
/// deflated at level 6, every entry dated 1980-01-01 00:00:00 with host system Unix and mode
/// 0644, so the bytes depend only on the input (and the deflate implementation).
///
/// # Errors
/// [`ExportError::ThreeMf`] if the zip writer fails (it writes to memory).
pub(crate) fn encode(
    objects: &[Object<'_>],
    metadata: &[(&str, String)],
) -> Result<Vec<u8>, ExportError> {
    let model = model_xml(objects, metadata);
    let zip_err = |e: zip::result::ZipError| ExportError::ThreeMf {
        reason: e.to_string(),
    };
    let io_err = |e: std::io::Error| ExportError::ThreeMf {
        reason: e.to_string(),
    };
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let opts = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .compression_level(Some(6))
        .last_modified_time(DateTime::default())
        .system(System::Unix)
        .unix_permissions(0o644)
        .large_file(model.len() as u64 >= u64::from(u32::MAX));
    for (name, body) in [
        ("[Content_Types].xml", CONTENT_TYPES),
        ("_rels/.rels", RELS),
        ("3D/3dmodel.model", model.as_str()),
    ] {
        zip.start_file(name, opts).map_err(zip_err)?;
        zip.write_all(body.as_bytes()).map_err(io_err)?;
    }
    Ok(zip.finish().map_err(zip_err)?.into_inner())
}

/// The coordinate rounded to f32, as the shortest decimal that reads back to that value as
/// f64 (and so also as f32); `0` for both zeros.
fn coord_text(c: f64) -> String {
    f64_text(f64::from(c as f32))
}

/// Shortest decimal that reads back to the same f64; `0` for both zeros.
fn f64_text(c: f64) -> String {
    if c == 0.0 {
        "0".to_owned()
    } else {
        c.to_string()
    }
}

/// Escapes text for XML attribute values and element content.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // XML 1.0 forbids most control characters; keep tab, newline, carriage return.
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_short_and_exact() {
        let tenth = f64::from(0.1f32);
        assert_eq!(coord_text(tenth), "0.10000000149011612");
        assert_eq!(coord_text(tenth).parse::<f64>().unwrap(), tenth);
        assert_eq!(coord_text(tenth).parse::<f32>().unwrap(), 0.1f32);
        assert_eq!(coord_text(-0.0), "0");
        assert_eq!(coord_text(12.5), "12.5");
        assert_eq!(coord_text(1e-7).parse::<f32>().unwrap(), 1e-7f32);
        assert_eq!(f64_text(-0.0), "0");
    }

    #[test]
    fn escape_covers_markup() {
        assert_eq!(escape("a<b & \"c\"\u{1}"), "a&lt;b &amp; &quot;c&quot; ");
    }
}
