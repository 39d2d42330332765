//! The kit 3MF: one named mesh object per plate unit (an ungrouped part, or all parts of one
//! multi-material group as the volumes of one object), laid out on the plate by build items.
//!
//! Why our own writer rather than `threemf::write` (threemf 0.8.1):
//! it starts every zip entry with `SimpleFileOptions::default()`, whose timestamp is the
//! current time as soon as any crate in the build enables zip's `time` feature (Cargo feature
//! unification; zip's default features include it), and whose host-system byte follows the
//! platform, so the same kit would not give byte-identical files; it offers no way to pass a
//! fixed time. `threemf` is still used as an independent reader in the tests.
//!
//! The package is written by [`crate::zip_package`] from pieces deflated beforehand: each
//! object's `<mesh>` element (which depends on its meshes alone) and the text between them, so
//! that the kit 3MF and a plate holding the same part deflate its mesh once, and a large mesh
//! is deflated on every core. The model inflates to the same text as before; only the deflate
//! bytes differ from one stream (packages within 0.6 % of their former size).
//!
//! Coordinates are the f32-rounded values printed as the shortest decimal that reads back to
//! the same f64 (e.g. `0.10000000149011612` for 0.1f32): readers that parse f32 (slicers) and
//! readers that parse f64 (trimesh, `threemf`) both get exactly the mesh the manifest describes.
//!
//! The XML follows the 3MF Core Specification 1.3: `model` in the 2015/02 core namespace,
//! `unit="millimeter"`, well-known metadata names only (plus one namespaced name, below),
//! `type="model"` objects, and build items whose `transform` is
//! `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32` (row vectors, translation last).
//!
//! # Multi-material groups: one object, one volume per part
//!
//! A slicer assigns materials (extruders) to the volumes of one object; separate objects are
//! sliced separately, so pin-tip dots floating inside a skin would be an object with empty
//! layers of its own (PrusaSlicer: "Empty layer between ..."). A group is therefore written as
//! ONE mesh object whose mesh is its members' meshes one after the other (each member's
//! vertices and triangles unchanged, in part coordinates, so the members stay registered),
//! named after its members joined by `+` (`skin+skin_tips`; `+` is not allowed in a part
//! name, so the names of a kit's objects are unique), with one build item.
//!
//! The core specification has no way to name a range of triangles, and its `<components>` do
//! not help: PrusaSlicer turns every mesh object a component refers to into an object of its
//! own (checked with 2.5.0; `_create_object_instance` in `src/libslic3r/Format/3mf.cpp` still
//! does so). So the volumes are described where PrusaSlicer reads them, in
//! `Metadata/Slic3r_PE_model.config`, as PrusaSlicer itself writes them:
//!
//! ```text
//! <config>
//!  <object id="1">
//!   <metadata type="object" key="name" value="skin+skin_tips"/>
//!   <volume firstid="0" lastid="21675">            (0-based triangle range in the mesh)
//!    <metadata type="volume" key="name" value="skin"/>
//!    <metadata type="volume" key="volume_type" value="ModelPart"/>
//!    <metadata type="volume" key="extruder" value="1"/>
//!   </volume>
//!   <volume firstid="21676" lastid="52491"> ... value="skin_tips" ... value="2" ... </volume>
//!  </object>
//! </config>
//! ```
//!
//! Volume `k` (0-based, in kit order) of a group gets extruder `k + 1`, so a multi-material
//! printer profile prints each part from its own extruder; the material names are in the
//! manifest and the fabrication sheet (PrusaSlicer 2.5.0 silently drops a per-volume key it
//! does not know, so a material name has no place in this file). Ungrouped objects get no
//! entry: PrusaSlicer loads them as one volume named after the object.
//!
//! When the file holds a group, the model also says `<metadata name="slic3rpe:Version3mf">1`
//! (namespace `http://schemas.slic3r.org/3mf/2017/06`): PrusaSlicer treats a version-0 file
//! (another application's) by baking the build transform into the first volume only and
//! then resetting it, which would leave the other volumes of a moved object behind.
//! Version 1 is the plain format (meshes in object coordinates, build item transforms kept);
//! readers other than PrusaSlicer ignore both the metadata and the config.

use crate::zip_package::Deflated;
use crate::ExportError;
use fabkit_designs::geometry::Mesh;
use std::fmt::Write as _;

/// The package's content types (`[Content_Types].xml`) with the types given after the
/// relationships' and the 3D model's: a `concat!` of literals, so that both forms below are
/// `&'static str` constants.
macro_rules! content_types {
    ($($extra:literal),*) => {
        concat!(
            r#"<?xml version="1.0" encoding="UTF-8"?>"#,
            "\n",
            r#"<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">"#,
            r#"<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>"#,
            r#"<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>"#,
            $($extra,)*
            "</Types>\n"
        )
    };
}

/// The content types of the relationships and the 3D model.
const CONTENT_TYPES: &str = content_types!();

/// [`CONTENT_TYPES`] plus the type of the PrusaSlicer config part (OPC wants a content type
/// for every part; PrusaSlicer itself declares none for it).
const CONTENT_TYPES_WITH_CONFIG: &str =
    content_types!(r#"<Default Extension="config" ContentType="application/xml"/>"#);

/// The content type line of the package thumbnail (OPC wants one for every part).
const PNG_CONTENT_TYPE: &str = r#"<Default Extension="png" ContentType="image/png"/>"#;

/// Where the package thumbnail goes (PrusaSlicer reads and writes it there).
pub(crate) const THUMBNAIL_PATH: &str = "Metadata/thumbnail.png";

/// The package relationships (`_rels/.rels`) with the relationships given after the 3D model's:
/// a `concat!` of literals, so that both forms below are `&'static str` constants.
macro_rules! package_rels {
    ($($extra:literal),*) => {
        concat!(
            r#"<?xml version="1.0" encoding="UTF-8"?>"#,
            "\n",
            r#"<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">"#,
            r#"<Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>"#,
            $($extra,)*
            "</Relationships>\n"
        )
    };
}

/// [`RELS`] plus the package thumbnail: the OPC relationship of the 3MF core specification
/// (Sec. 6.1, "Package Thumbnail"), from the package root to [`THUMBNAIL_PATH`].
const RELS_WITH_THUMBNAIL: &str = package_rels!(
    r#"<Relationship Target="/Metadata/thumbnail.png" Id="rel1" Type="http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"/>"#
);

/// Where PrusaSlicer reads the volumes of its objects.
pub(crate) const PRUSA_CONFIG_PATH: &str = "Metadata/Slic3r_PE_model.config";

/// The package relationships: the 3D model's only.
const RELS: &str = package_rels!();

/// One part inside an object: a range of the object's triangles.
pub(crate) struct Volume<'a> {
    /// Volume name (the part name).
    pub name: &'a str,
    /// Mesh in part coordinates, f32-rounded, shared vertices, outward winding.
    pub mesh: &'a Mesh,
}

/// One object of the 3MF and its build item.
pub(crate) struct Object<'a> {
    /// Object name: the part name, or for a group its members' names joined by `+`.
    pub name: String,
    /// The multi-material group the object holds, `None` for one ungrouped part. Group objects
    /// are described volume by volume in the PrusaSlicer config.
    pub group: Option<&'a str>,
    /// The object's parts, in mesh order (at least one).
    pub volumes: Vec<Volume<'a>>,
    /// Build-item translation, mm.
    pub translation_mm: [f64; 3],
    /// Turned 90 deg about z (counter-clockwise from above) before the translation.
    pub turned: bool,
    /// Object metadata in the `fabkit:` namespace ([`FABKIT_NS`]): (key, value), e.g.
    /// (`role`, `mold_half`); keys unique.
    pub metadata: Vec<(&'static str, String)>,
}

/// The namespace of fabkit's object metadata (`fabkit:role`, `fabkit:material`,
/// `fabkit:technology`), declared on the model.
pub(crate) const FABKIT_NS: &str = "http://schemas.fabkit.org/3mf/2026";

impl Object<'_> {
    /// First and last triangle (0-based, inclusive) of each volume in the object's mesh.
    pub(crate) fn triangle_ranges(&self) -> Vec<(usize, usize)> {
        let mut first = 0;
        self.volumes
            .iter()
            .map(|v| {
                let n = v.mesh.triangles.len();
                let range = (first, (first + n).saturating_sub(1));
                first += n;
                range
            })
            .collect()
    }
}

/// The `3D/3dmodel.model` XML. Object ids are 1, 2, ... in input order: [`model_texts`] with
/// each object's [`mesh_xml`] between them.
#[cfg(test)]
pub(crate) fn model_xml(objects: &[Object<'_>], metadata: &[(&str, String)]) -> String {
    let texts = model_texts(objects, metadata);
    let mut x = texts[0].clone();
    for (o, t) in objects.iter().zip(&texts[1..]) {
        x.push_str(&mesh_xml(o));
        x.push_str(t);
    }
    x
}

/// The model XML but for the objects' `<mesh>` elements: n + 1 texts for n objects, object
/// k's mesh going between text k and text k + 1.
fn model_texts(objects: &[Object<'_>], metadata: &[(&str, String)]) -> Vec<String> {
    let mut texts = Vec::with_capacity(objects.len() + 1);
    let mut x = String::new();
    // `write!` into a String cannot fail; the results are ignored on purpose.
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let with_groups = objects.iter().any(|o| o.group.is_some());
    x.push_str(
        "<model unit=\"millimeter\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\"",
    );
    if with_groups {
        x.push_str(" xmlns:slic3rpe=\"http://schemas.slic3r.org/3mf/2017/06\"");
    }
    if objects.iter().any(|o| !o.metadata.is_empty()) {
        let _ = write!(x, " xmlns:fabkit=\"{FABKIT_NS}\"");
    }
    x.push_str(">\n");
    for (name, value) in metadata {
        let _ = writeln!(
            x,
            " <metadata name=\"{}\">{}</metadata>",
            escape(name),
            escape(value)
        );
    }
    if with_groups {
        x.push_str(" <metadata name=\"slic3rpe:Version3mf\">1</metadata>\n");
    }
    x.push_str(" <resources>\n");
    for (i, o) in objects.iter().enumerate() {
        let _ = writeln!(
            x,
            "  <object id=\"{}\" name=\"{}\" type=\"model\">",
            i + 1,
            escape(&o.name)
        );
        if !o.metadata.is_empty() {
            x.push_str("   <metadatagroup>\n");
            for (k, v) in &o.metadata {
                let _ = writeln!(
                    x,
                    "    <metadata name=\"fabkit:{}\" preserve=\"1\">{}</metadata>",
                    escape(k),
                    escape(v)
                );
            }
            x.push_str("   </metadatagroup>\n");
        }
        texts.push(std::mem::take(&mut x));
        x.push_str("  </object>\n");
    }
    x.push_str(" </resources>\n <build>\n");
    for (i, o) in objects.iter().enumerate() {
        let [tx, ty, tz] = o.translation_mm.map(f64_text);
        // row vectors times the matrix: turned, (x, y) -> (-y, x)
        let r = if o.turned {
            "0 1 0 -1 0 0 0 0 1"
        } else {
            "1 0 0 0 1 0 0 0 1"
        };
        let _ = writeln!(
            x,
            "  <item objectid=\"{}\" transform=\"{r} {tx} {ty} {tz}\"/>",
            i + 1
        );
    }
    x.push_str(" </build>\n</model>\n");
    texts.push(x);
    texts
}

/// The `<mesh>` element of an object (its lines, indented as in the model): its volumes'
/// vertices one after the other, then their triangles, each volume's indices shifted by the
/// vertices before it. It depends on the meshes alone, so two packages holding the same
/// meshes hold the same element.
fn mesh_xml(o: &Object<'_>) -> String {
    let vertices: usize = o.volumes.iter().map(|v| v.mesh.vertices.len()).sum();
    let triangles: usize = o.volumes.iter().map(|v| v.mesh.triangles.len()).sum();
    let mut x = String::with_capacity(64 + 80 * vertices + 56 * triangles);
    x.push_str("   <mesh>\n    <vertices>\n");
    // The bulk of the file: pushed piece by piece rather than through `write!`.
    let mut num = Numbers::default();
    for v in o.volumes.iter().flat_map(|v| &v.mesh.vertices) {
        x.push_str("     <vertex x=\"");
        x.push_str(num.coord(v[0]));
        x.push_str("\" y=\"");
        x.push_str(num.coord(v[1]));
        x.push_str("\" z=\"");
        x.push_str(num.coord(v[2]));
        x.push_str("\"/>\n");
    }
    x.push_str("    </vertices>\n    <triangles>\n");
    let mut base = 0usize;
    for v in &o.volumes {
        for t in &v.mesh.triangles {
            let [a, b, c] = t.map(|i| i as usize + base);
            x.push_str("     <triangle v1=\"");
            x.push_str(num.index(a));
            x.push_str("\" v2=\"");
            x.push_str(num.index(b));
            x.push_str("\" v3=\"");
            x.push_str(num.index(c));
            x.push_str("\"/>\n");
        }
        base += v.mesh.vertices.len();
    }
    x.push_str("    </triangles>\n   </mesh>\n");
    x
}

/// An object's `<mesh>` element deflated ([`mesh_xml`], [`Deflated::of`]): made once for a
/// part that several packages hold.
///
/// # Errors
/// [`ExportError::ThreeMf`] if the deflater fails.
pub(crate) fn mesh_deflated(o: &Object<'_>) -> Result<Deflated, ExportError> {
    Deflated::of(mesh_xml(o).as_bytes())
}

/// The PrusaSlicer config ([`PRUSA_CONFIG_PATH`]) describing the volumes of every group
/// object (see the module docs), `None` when no object holds a group.
pub(crate) fn prusa_config_xml(objects: &[Object<'_>]) -> Option<String> {
    if objects.iter().all(|o| o.group.is_none()) {
        return None;
    }
    let mut x = String::new();
    // `write!` into a String cannot fail; the results are ignored on purpose.
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<config>\n");
    for (i, o) in objects.iter().enumerate() {
        if o.group.is_none() {
            continue;
        }
        let _ = writeln!(x, " <object id=\"{}\" instances_count=\"1\">", i + 1);
        let _ = writeln!(
            x,
            "  <metadata type=\"object\" key=\"name\" value=\"{}\"/>",
            escape(&o.name)
        );
        for (k, (v, (first, last))) in o.volumes.iter().zip(o.triangle_ranges()).enumerate() {
            let _ = writeln!(x, "  <volume firstid=\"{first}\" lastid=\"{last}\">");
            let _ = writeln!(
                x,
                "   <metadata type=\"volume\" key=\"name\" value=\"{}\"/>",
                escape(v.name)
            );
            x.push_str("   <metadata type=\"volume\" key=\"volume_type\" value=\"ModelPart\"/>\n");
            let _ = writeln!(
                x,
                "   <metadata type=\"volume\" key=\"extruder\" value=\"{}\"/>",
                k + 1
            );
            x.push_str("  </volume>\n");
        }
        x.push_str(" </object>\n");
    }
    x.push_str("</config>\n");
    Some(x)
}

/// The whole 3MF package as bytes, without a thumbnail: [`encode_drawn`] with none.
///
/// # Errors
/// [`ExportError::ThreeMf`] if the zip writer fails (it writes to memory).
pub(crate) fn encode(
    objects: &[Object<'_>],
    metadata: &[(&str, String)],
) -> Result<Vec<u8>, ExportError> {
    encode_drawn(
        objects,
        &[],
        metadata,
        None::<fn() -> Result<Vec<u8>, ExportError>>,
    )
    .map(|(bytes, _)| bytes)
}

/// The whole 3MF package as bytes: `[Content_Types].xml`, `_rels/.rels`, `3D/3dmodel.model`
/// and, when an object holds a group, [`PRUSA_CONFIG_PATH`], and with `thumbnail` the package
/// thumbnail [`THUMBNAIL_PATH`] (its root relationship in `_rels/.rels`, the `png` content
/// type declared); deflated at level 4, every entry dated 1980-01-01 00:00:00 with host system
/// Unix and mode 0644, so the bytes depend only on the input (and the deflate implementation).
/// The model is deflated in pieces ([`crate::zip_package`]): each object's `<mesh>` element
/// on its own, and the text between them. `premade` is empty, or holds every object's
/// [`mesh_deflated`] made beforehand (when another package holds the same elements: a part in
/// the kit 3MF and on its plate). The thumbnail (PNG bytes) is drawn by `thumbnail` while the
/// model is written and deflated (it is the package's last entry), and returned with the
/// package.
///
/// # Errors
/// [`ExportError::ThreeMf`] if the deflater fails, the package has too many entries or
/// `premade` is neither empty nor one per object; the thumbnail's own error first.
pub(crate) fn encode_drawn<F>(
    objects: &[Object<'_>],
    premade: &[&Deflated],
    metadata: &[(&str, String)],
    thumbnail: Option<F>,
) -> Result<(Vec<u8>, Option<Vec<u8>>), ExportError>
where
    F: FnOnce() -> Result<Vec<u8>, ExportError> + Send,
{
    if !premade.is_empty() && premade.len() != objects.len() {
        return Err(ExportError::ThreeMf {
            reason: format!(
                "{} deflated meshes for {} objects",
                premade.len(),
                objects.len()
            ),
        });
    }
    let with_thumbnail = thumbnail.is_some();
    let (entries, png) = rayon::join(
        || model_entries(objects, premade.is_empty(), metadata, with_thumbnail),
        || thumbnail.map(|f| f()),
    );
    // the thumbnail's error first, as when it is drawn before the package
    let png = png.transpose()?;
    let entries = entries?;
    let png_deflated = png.as_deref().map(Deflated::of).transpose()?;
    let meshes: Vec<&Deflated> = if premade.is_empty() {
        entries.meshes.iter().collect()
    } else {
        premade.to_vec()
    };
    let mut model: Vec<&Deflated> = vec![&entries.texts[0]];
    for (mesh, text) in meshes.into_iter().zip(&entries.texts[1..]) {
        model.extend([mesh, text]);
    }
    let mut parts: Vec<(&str, Vec<&Deflated>)> = vec![
        ("[Content_Types].xml", vec![&entries.content_types]),
        ("_rels/.rels", vec![&entries.rels]),
        ("3D/3dmodel.model", model),
    ];
    if let Some(c) = &entries.config {
        parts.push((PRUSA_CONFIG_PATH, vec![c]));
    }
    if let Some(p) = &png_deflated {
        parts.push((THUMBNAIL_PATH, vec![p]));
    }
    Ok((crate::zip_package::package(&parts, false)?, png))
}

/// A package's entries up to the thumbnail, deflated: content types and relationships
/// (naming the thumbnail when asked), the model's texts, the objects' meshes (in object order;
/// none when they were made beforehand) and PrusaSlicer's config.
struct ModelEntries {
    content_types: Deflated,
    rels: Deflated,
    texts: Vec<Deflated>,
    meshes: Vec<Deflated>,
    config: Option<Deflated>,
}

fn model_entries(
    objects: &[Object<'_>],
    with_meshes: bool,
    metadata: &[(&str, String)],
    with_thumbnail: bool,
) -> Result<ModelEntries, ExportError> {
    use rayon::prelude::*;
    let config = prusa_config_xml(objects);
    let content_types = if config.is_some() {
        CONTENT_TYPES_WITH_CONFIG
    } else {
        CONTENT_TYPES
    };
    let content_types = if with_thumbnail {
        content_types.replace("</Types>", &format!("{PNG_CONTENT_TYPE}</Types>"))
    } else {
        content_types.to_owned()
    };
    let rels = if with_thumbnail {
        RELS_WITH_THUMBNAIL
    } else {
        RELS
    };
    // the largest first: the meshes, each deflated in parallel pieces
    let meshes = if with_meshes {
        objects
            .par_iter()
            .map(mesh_deflated)
            .collect::<Result<Vec<_>, _>>()?
    } else {
        Vec::new()
    };
    let texts = model_texts(objects, metadata)
        .iter()
        .map(|t| Deflated::of(t.as_bytes()))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ModelEntries {
        content_types: Deflated::of(content_types.as_bytes())?,
        rels: Deflated::of(rels.as_bytes())?,
        texts,
        meshes,
        config: config.map(|c| Deflated::of(c.as_bytes())).transpose()?,
    })
}

/// The coordinate rounded to f32, as the shortest decimal that reads back to that value as
/// f64 (and so also as f32); `0` for both zeros. The mesh lines' text ([`Numbers::coord`]).
#[cfg(test)]
fn coord_text(c: f64) -> String {
    Numbers::default().coord(c).to_owned()
}

/// Number formatting for the mesh lines, coordinates and vertex indices, without the `fmt`
/// machinery or an allocation per number.
#[derive(Default)]
struct Numbers {
    float: zmij::Buffer,
    int: itoa::Buffer,
    fallback: String,
}

impl Numbers {
    /// `c` rounded to f32, as the shortest decimal that reads back to that value as f64 (and
    /// so also as f32); `0` for both zeros. zmij's shortest round-trip digits (Schubfach),
    /// written in positional notation as std writes floats (no `.0` on an integer; std's own
    /// text for the exponent form zmij uses below 1e-5 and from 1e16, and for non-finite
    /// values). The digits are std's but for a value exactly halfway between two shortest
    /// decimals, where zmij takes the even last digit and std the one above (0.61f32 as f64,
    /// 0.61100006103515625, is `0.6110000610351562` here): the same f64 either way.
    fn coord(&mut self, c: f64) -> &str {
        let c = f64::from(c as f32);
        if c == 0.0 {
            return "0";
        }
        if !c.is_finite() {
            self.fallback = c.to_string();
            return &self.fallback;
        }
        let s = self.float.format_finite(c);
        if s.contains('e') {
            self.fallback = c.to_string();
            return &self.fallback;
        }
        s.strip_suffix(".0").unwrap_or(s)
    }

    /// `i` in decimal.
    fn index(&mut self, i: usize) -> &str {
        self.int.format(i)
    }
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

    /// The mesh lines' numbers read back to the very f32 value, as f64 and as f32, with as few
    /// digits as std's shortest text, which they equal but for the last digit of a halfway
    /// value: coordinates spread over every magnitude a mesh can hold (and the exponent forms
    /// beyond), both signs, f32 neighbours of round numbers; and the integers.
    #[test]
    fn the_mesh_lines_numbers_are_shortest_and_exact() {
        let mut num = Numbers::default();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut cases: Vec<f64> = vec![
            0.0, -0.0, 1.0, -1.0, 0.1, 12.5, 1e-7, 3e-5, 1e15, 1e16, 2e17,
        ];
        for k in -3..=4 {
            for m in 1..=1000 {
                let round = f64::from(m) * 10f64.powi(k) / 1000.0;
                let f = round as f32;
                cases.extend([f, f.next_up(), f.next_down()].map(f64::from));
            }
        }
        for _ in 0..200_000 {
            // a fixed sequence (xorshift), every magnitude from 1e-9 to 1e9 mm
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let mantissa = (state >> 11) as f64 / (1u64 << 53) as f64;
            let exponent = ((state & 0xff) as i32 % 19) - 9;
            let sign = if state & 0x100 == 0 { 1.0 } else { -1.0 };
            cases.push(sign * mantissa * 10f64.powi(exponent));
        }
        let (mut halfway, total) = (0, cases.len());
        for c in cases {
            let f = f64::from(c as f32);
            let (ours, std) = (num.coord(c).to_owned(), f64_text(f));
            assert_eq!(ours.parse::<f64>().unwrap(), f, "{c:e}: {ours}");
            assert_eq!(ours.parse::<f32>().unwrap(), c as f32, "{c:e}: {ours}");
            assert!(!ours.contains('e') || std.contains('e'), "{c:e}: {ours}");
            if ours != std {
                // a halfway value: the same length, the last digit one apart
                let (a, b) = (ours.as_bytes(), std.as_bytes());
                assert_eq!(a.len(), b.len(), "{c:e}: {ours} against {std}");
                assert_eq!(
                    a[..a.len() - 1],
                    b[..b.len() - 1],
                    "{c:e}: {ours} against {std}"
                );
                assert_eq!(
                    a[a.len() - 1].abs_diff(b[b.len() - 1]),
                    1,
                    "{c:e}: {ours} against {std}"
                );
                halfway += 1;
            }
        }
        // about 1 % of f32 values are halfway at f64's 17th digit
        assert!(
            halfway > 0 && halfway * 20 < total,
            "{halfway} halfway values of {total}"
        );
        for i in [0usize, 7, 10, 99, 12_345, 4_294_967_295] {
            assert_eq!(num.index(i), i.to_string());
        }
    }

    fn tetra(x: f64) -> Mesh {
        Mesh {
            vertices: vec![[x, 0., 0.], [x + 1., 0., 0.], [x, 1., 0.], [x, 0., 1.]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
    }

    /// A package inflates to the model XML whether an object's mesh element was deflated
    /// with it or beforehand (as the kit 3MF and its plates share one), with the same bytes.
    #[test]
    fn a_mesh_deflated_beforehand_gives_the_same_package() {
        use std::io::Read;
        let (a, b) = (tetra(0.0), tetra(5.0));
        let object = |mesh, name: &str| Object {
            name: name.into(),
            group: None,
            volumes: vec![Volume { name: "x", mesh }],
            translation_mm: [1.0, 2.0, 0.0],
            turned: true,
            metadata: vec![("role", "mold & half".into())],
        };
        let plain = [object(&a, "a"), object(&b, "b")];
        let made: Vec<Deflated> = plain.iter().map(|o| mesh_deflated(o).unwrap()).collect();
        let meta = [("Title", "t <1>".to_owned())];
        let png = || Ok(vec![137u8, 80, 78, 71]);
        let (bytes, _) = encode_drawn(&plain, &[], &meta, Some(png)).unwrap();
        let (again, thumb) = encode_drawn(&plain, &[&made[0], &made[1]], &meta, Some(png)).unwrap();
        assert_eq!(bytes, again);
        assert!(encode_drawn(&plain, &[&made[0]], &meta, Some(png)).is_err());
        assert_eq!(thumb.as_deref(), Some(&[137u8, 80, 78, 71][..]));
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(&bytes)).unwrap();
        let mut model = String::new();
        zip.by_name("3D/3dmodel.model")
            .unwrap()
            .read_to_string(&mut model)
            .unwrap();
        assert_eq!(model, model_xml(&plain, &meta));
        let names: Vec<String> = zip.file_names().map(|n| n.unwrap().to_string()).collect();
        assert_eq!(
            names,
            [
                "[Content_Types].xml",
                "_rels/.rels",
                "3D/3dmodel.model",
                THUMBNAIL_PATH
            ]
        );
    }

    #[test]
    fn group_object_concatenates_its_volumes_and_is_described_for_prusaslicer() {
        let (a, b, c) = (tetra(0.0), tetra(5.0), tetra(9.0));
        let objects = [
            Object {
                name: "c".into(),
                group: None,
                volumes: vec![Volume {
                    name: "c",
                    mesh: &c,
                }],
                translation_mm: [1.0, 2.0, 0.0],
                turned: false,
                metadata: Vec::new(),
            },
            Object {
                name: "a+b".into(),
                group: Some("g"),
                volumes: vec![
                    Volume {
                        name: "a",
                        mesh: &a,
                    },
                    Volume {
                        name: "b",
                        mesh: &b,
                    },
                ],
                translation_mm: [0.5, 0.0, 0.0],
                turned: false,
                metadata: Vec::new(),
            },
        ];
        assert_eq!(objects[1].triangle_ranges(), [(0, 3), (4, 7)]);
        assert_eq!(objects[0].triangle_ranges(), [(0, 3)]);
        let x = model_xml(&objects, &[]);
        // b's triangles follow a's, indices shifted by a's 4 vertices; one build item per object
        assert!(x.contains("<object id=\"2\" name=\"a+b\" type=\"model\">"));
        assert!(x.contains("     <triangle v1=\"4\" v2=\"6\" v3=\"5\"/>\n"));
        assert_eq!(x.matches("<vertex ").count(), 12);
        assert_eq!(x.matches("<item ").count(), 2);
        assert!(x.contains("<item objectid=\"2\" transform=\"1 0 0 0 1 0 0 0 1 0.5 0 0\"/>"));
        assert!(x.contains("<metadata name=\"slic3rpe:Version3mf\">1</metadata>"));
        let config = prusa_config_xml(&objects).unwrap();
        assert!(!config.contains("object id=\"1\""), "{config}");
        assert!(config.contains(
            "  <volume firstid=\"4\" lastid=\"7\">\n   \
             <metadata type=\"volume\" key=\"name\" value=\"b\"/>\n"
        ));
        assert!(config.contains("<metadata type=\"volume\" key=\"extruder\" value=\"2\"/>"));
        // without a group: neither the config nor the PrusaSlicer namespace
        assert!(prusa_config_xml(&objects[..1]).is_none());
        assert!(!model_xml(&objects[..1], &[]).contains("slic3rpe"));
    }

    #[test]
    fn escape_covers_markup() {
        assert_eq!(escape("a<b & \"c\"\u{1}"), "a&lt;b &amp; &quot;c&quot; ");
    }
}
