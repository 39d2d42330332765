//! write_kit end to end: files read back by independent readers (stl_io, threemf, zip),
//! determinism, formats, and the output-directory rules.

use fabkit_designs::geometry::{cuboid, cylinder, sphere, Aabb, ChordTolerance};
use fabkit_designs::kit::{CastComponent, CastReport, Kit, Part, PrintTechnology};
use fabkit_export::{
    write_kit, ExportError, ExportOptions, Formats, Manifest, ManifestVolume, OUTPUT_MARKER,
};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

fn part(name: &str, tech: PrintTechnology, solid: fabkit_designs::geometry::Solid) -> Part {
    Part {
        name: name.into(),
        role: "test_part".into(),
        description: format!("{name} for the export tests"),
        material: "pla_black".into(),
        print_technology: tech,
        solid,
        params: serde_json::json!({ "name": name, "size_mm": [1.0, 2.0], "zeta": true, "alpha": 1 }),
        group: None,
    }
}

/// Five parts: a wide plate and a wide tray (they force a second row on the plate), a
/// cylinder, a sphere resting on z = 0 and a ring (genus 1).
fn test_kit() -> Kit {
    let tol = ChordTolerance::new(0.05).unwrap();
    let ring = cuboid([-10.0, -10.0, 0.0], [10.0, 10.0, 3.0])
        .unwrap()
        .difference(&cylinder(5.0, 5.0, tol).unwrap().translate([0.0, 0.0, -1.0]))
        .unwrap();
    Kit {
        design: "tiny".into(),
        parts: vec![
            part(
                "base_plate",
                PrintTechnology::Fdm,
                cuboid([-75.0, -15.0, 0.0], [75.0, 15.0, 4.0]).unwrap(),
            ),
            part(
                "pillar",
                PrintTechnology::Fdm,
                cylinder(10.0, 6.0, tol).unwrap(),
            ),
            part(
                "dome",
                PrintTechnology::Sla,
                sphere(8.0, tol).unwrap().translate([0.0, 0.0, 8.0]),
            ),
            part("ring", PrintTechnology::Sla, ring),
            part(
                "wide_tray",
                PrintTechnology::Fdm,
                cuboid([0.0, 0.0, 0.0], [120.0, 40.0, 2.0]).unwrap(),
            ),
        ],
        casts: vec![CastReport {
            step: 1,
            cast: "transparent_gel".into(),
            material: "solaris".into(),
            material_name: "Smooth-On Solaris".into(),
            mold_parts: vec!["ring".into(), "dome".into()],
            cavity_volume_ml: 3.2109,
            layer_volume_ml: Some(2.5),
            waste_allowance: 0.2,
            mix_ratio: "1:1 by weight".into(),
            components: vec![
                CastComponent {
                    name: "Part A".into(),
                    mass_g: 1.9265,
                    volume_ml: None,
                },
                CastComponent {
                    name: "Part B".into(),
                    mass_g: 1.9265,
                    volume_ml: None,
                },
            ],
            total_mass_g: 3.853,
            notes: "pot life 15 min | degas 3 min".into(),
            min_batch: None,
            coats: vec![],
            treatments: vec![],
        }],
        bought_items: vec!["acrylic tube, 30 mm OD".into()],
        procedure: vec![],
        assembly: vec![],
        cut_parts: vec![],
        pcb_outlines: vec![],
        machined_parts: Vec::new(),
        summary: serde_json::json!({ "envelope_radius_mm": 15.0 }),
    }
}

fn opts() -> ExportOptions {
    ExportOptions {
        formats: Formats::default(),
        command_line: vec![
            "fabkit".into(),
            "build".into(),
            "tiny.yaml".into(),
            "--out".into(),
            "out dir".into(),
        ],
        design_source: "designs/library/tiny.yaml".into(),
        design_sha256: "0123456789abcdef".repeat(4),
        chord_tolerance_mm: 0.05,
        fabkit_version: "0.1.0".into(),
        printers: Default::default(),
        command: fabkit_export::OutputCommand::Export,
        force: false,
        sim: Default::default(),
    }
}

fn read_manifest(dir: &Path) -> Manifest {
    serde_json::from_slice(&fs::read(dir.join("manifest.json")).unwrap()).unwrap()
}

fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The vertices of a 3MF mesh as read back, mm.
pub(crate) fn vertices_of(mesh: &threemf::model::Mesh) -> Vec<[f64; 3]> {
    mesh.vertices
        .vertex
        .iter()
        .map(|v| [v.x, v.y, v.z])
        .collect()
}

pub(crate) fn signed_volume(
    vertices: &[[f64; 3]],
    triangles: impl Iterator<Item = [usize; 3]>,
) -> f64 {
    let mut v = 0.0;
    for t in triangles {
        let (a, b, c) = (vertices[t[0]], vertices[t[1]], vertices[t[2]]);
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    v / 6.0
}

fn bbox(points: impl Iterator<Item = [f64; 3]>) -> Aabb {
    points.fold(
        Aabb {
            min: [f64::MAX; 3],
            max: [f64::MIN; 3],
        },
        |b, p| Aabb {
            min: [b.min[0].min(p[0]), b.min[1].min(p[1]), b.min[2].min(p[2])],
            max: [b.max[0].max(p[0]), b.max[1].max(p[1]), b.max[2].max(p[2])],
        },
    )
}

fn assert_close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-9 * b.abs().max(1.0),
        "{what}: {a} vs {b}"
    );
}

/// Relative paths of all files under `dir`, sorted.
fn tree(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn stl_files_read_back_with_the_manifest_numbers() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    let kit = test_kit();
    let summary = write_kit(&kit, &out, &opts()).unwrap();
    let m = read_manifest(&out);
    assert_eq!(m, summary.manifest);
    assert_eq!(m.parts.len(), 5);
    for (p, mp) in kit.parts.iter().zip(&m.parts) {
        assert_eq!(p.name, mp.name);
        let file = mp.file.as_deref().unwrap();
        assert_eq!(file, format!("parts/{}.stl", p.name));
        let bytes = fs::read(out.join(file)).unwrap();
        assert_eq!(mp.sha256.as_deref(), Some(sha256_hex(&bytes).as_str()));
        assert!(!bytes.starts_with(b"solid"));
        let header = String::from_utf8_lossy(&bytes[..80]).into_owned();
        assert!(
            header.starts_with(&format!(
                "fabkit 0.1.0 tiny {} sha256:0123456789abcdef mm",
                p.name
            )),
            "{header}"
        );

        let stl = stl_io::read_stl(&mut std::io::Cursor::new(&bytes)).unwrap();
        stl.validate().unwrap();
        assert_eq!(stl.faces.len(), mp.triangles);
        // No vertex is lost or duplicated by a position-merging reader.
        assert_eq!(stl.vertices.len(), mp.vertices);
        let verts: Vec<[f64; 3]> = stl.vertices.iter().map(|v| v.0.map(f64::from)).collect();
        let vol = signed_volume(&verts, stl.faces.iter().map(|f| f.vertices));
        assert_close(vol, mp.volume_mm3, &p.name);
        assert!(vol > 0.0);
        let bb = bbox(verts.iter().copied());
        assert_eq!(bb, mp.bbox_mm, "{}", p.name);
        assert_eq!(bb.min[2], 0.0);
        // Stored normals point out: along the right-hand normal of the stored winding.
        for f in &stl.faces {
            let [a, b, c] = f.vertices.map(|i| verts[i]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let dot: f64 = (0..3).map(|k| n[k] * f64::from(f.normal.0[k])).sum();
            assert!(dot > 0.0);
        }
    }
    let genus: Vec<i64> = m.parts.iter().map(|p| p.genus).collect();
    assert_eq!(genus, vec![0, 0, 0, 1, 0]);
    assert_close(
        m.parts[0].volume_mm3,
        150.0 * 30.0 * 4.0,
        "base_plate volume",
    );
}

#[test]
fn threemf_reads_back_named_objects_in_millimetres_laid_out_apart() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    let kit = test_kit();
    write_kit(&kit, &out, &opts()).unwrap();
    let m = read_manifest(&out);
    let k3 = m.kit_3mf.as_ref().unwrap();
    assert_eq!(k3.file, "tiny.3mf");
    let bytes = fs::read(out.join(&k3.file)).unwrap();
    assert_eq!(k3.sha256, sha256_hex(&bytes));

    let models = threemf::read(std::io::Cursor::new(&bytes)).unwrap();
    assert_eq!(models.len(), 1);
    let model = &models[0];
    assert!(matches!(model.unit, threemf::model::Unit::Millimeter));
    let title = model
        .metadata
        .iter()
        .find(|md| md.name == "Application")
        .and_then(|md| md.value.clone());
    assert_eq!(title.as_deref(), Some("fabkit 0.1.0"));
    let objects = &model.resources.object;
    let names: Vec<&str> = objects.iter().map(|o| o.name.as_deref().unwrap()).collect();
    let kit_names: Vec<&str> = kit.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, kit_names);

    let mut placed = Vec::new();
    for (o, mp) in objects.iter().zip(&m.parts) {
        let mesh = o.mesh.as_ref().unwrap();
        let verts = vertices_of(mesh);
        let unique: BTreeSet<[u64; 3]> = verts.iter().map(|v| v.map(f64::to_bits)).collect();
        assert_eq!(
            unique.len(),
            verts.len(),
            "{}: duplicated vertices",
            mp.name
        );
        assert_eq!(verts.len(), mp.vertices);
        assert_eq!(mesh.triangles.triangle.len(), mp.triangles);
        let vol = signed_volume(
            &verts,
            mesh.triangles.triangle.iter().map(|t| [t.v1, t.v2, t.v3]),
        );
        assert_close(vol, mp.volume_mm3, &mp.name);

        let item = model
            .build
            .item
            .iter()
            .find(|i| i.objectid == o.id)
            .unwrap();
        let t = item.transform.unwrap();
        assert_eq!(&t[..9], &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        let tr = [t[9], t[10], t[11]];
        let bb = bbox(
            verts
                .iter()
                .map(|v| [v[0] + tr[0], v[1] + tr[1], v[2] + tr[2]]),
        );
        assert_eq!(bb.min[2], 0.0, "{}", mp.name);
        assert!(
            bb.min[0] >= -1e-9 && bb.min[1] >= -1e-9,
            "{}: {bb:?}",
            mp.name
        );
        placed.push((mp.name.clone(), bb));
    }
    for (i, (na, a)) in placed.iter().enumerate() {
        for (nb, b) in &placed[i + 1..] {
            let gap = 5.0 - 1e-6;
            let apart = a.max[0] + gap <= b.min[0]
                || b.max[0] + gap <= a.min[0]
                || a.max[1] + gap <= b.min[1]
                || b.max[1] + gap <= a.min[1];
            assert!(apart, "{na} {a:?} and {nb} {b:?} overlap");
        }
    }
}

#[test]
fn same_kit_gives_byte_identical_files() {
    let root = tempfile::tempdir().unwrap();
    let (a, b) = (root.path().join("a"), root.path().join("b"));
    write_kit(&test_kit(), &a, &opts()).unwrap();
    write_kit(&test_kit(), &b, &opts()).unwrap();
    let files = tree(&a);
    assert_eq!(files, tree(&b));
    // parts, manifest, 3MF, FABRICATION.md, the marker, the FDM and SLA plates, the parts'
    // and plates' pictures, FABRICATION.html
    assert_eq!(files.len(), 5 + 3 + 1 + 2 + 5 + 2 + 1);
    for f in &files {
        assert_eq!(
            fs::read(a.join(f)).unwrap(),
            fs::read(b.join(f)).unwrap(),
            "{}",
            f.display()
        );
    }
    // Identical bytes from one second could still hide a clock: the zip entries carry the
    // fixed DOS epoch.
    let mut zip = zip::ZipArchive::new(fs::File::open(a.join("tiny.3mf")).unwrap()).unwrap();
    let mut names = Vec::new();
    for i in 0..zip.len() {
        let e = zip.by_index(i).unwrap();
        assert_eq!(e.last_modified(), Some(zip::DateTime::default()));
        names.push(e.name().unwrap().into_owned());
    }
    assert_eq!(
        names,
        [
            "[Content_Types].xml",
            "_rels/.rels",
            "3D/3dmodel.model",
            "Metadata/thumbnail.png"
        ]
    );
}

/// A TacTip-like group: a skin and its dots (two touching solids in shared coordinates, the
/// dots on the skin's top and reaching past its edge), with an ungrouped plate between them
/// in kit order.
fn group_kit() -> Kit {
    let mut skin = part(
        "skin",
        PrintTechnology::Polyjet,
        cuboid([-15.0, -15.0, 0.0], [15.0, 15.0, 10.0]).unwrap(),
    );
    skin.material = "tango_black_plus".into();
    skin.group = Some("tactip".into());
    let mut dots = part(
        "dots",
        PrintTechnology::Polyjet,
        cuboid([-5.0, -5.0, 10.0], [20.0, 5.0, 12.0]).unwrap(),
    );
    dots.material = "vero_white".into();
    dots.group = Some("tactip".into());
    let plate = part(
        "plate",
        PrintTechnology::Fdm,
        cuboid([0.0, 0.0, 0.0], [150.0, 30.0, 4.0]).unwrap(),
    );
    Kit {
        design: "grouped".into(),
        parts: vec![skin, plate, dots],
        casts: vec![],
        bought_items: vec![],
        procedure: vec![],
        assembly: vec![],
        cut_parts: vec![],
        pcb_outlines: vec![],
        machined_parts: Vec::new(),
        summary: serde_json::json!({}),
    }
}

fn offset(b: &Aabb, t: [f64; 3]) -> Aabb {
    Aabb {
        min: [0, 1, 2].map(|k| b.min[k] + t[k]),
        max: [0, 1, 2].map(|k| b.max[k] + t[k]),
    }
}

/// The entry `name` of the zip `bytes`, as text.
fn zip_text(bytes: &[u8], name: &str) -> Option<String> {
    use std::io::Read;
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    let mut entry = zip.by_name(name).ok()?;
    let mut text = String::new();
    entry.read_to_string(&mut text).unwrap();
    Some(text)
}

#[test]
fn a_group_is_one_3mf_object_with_a_volume_per_part_and_stls_stay_put() {
    let root = tempfile::tempdir().unwrap();
    let (a, b) = (root.path().join("a"), root.path().join("b"));
    let kit = group_kit();
    write_kit(&kit, &a, &opts()).unwrap();
    let m = read_manifest(&a);
    let groups: Vec<Option<&str>> = m.parts.iter().map(|p| p.group.as_deref()).collect();
    assert_eq!(groups, [Some("tactip"), None, Some("tactip")]);
    let text = fs::read_to_string(a.join("manifest.json")).unwrap();
    assert!(text.contains("\"print_technology\": \"PolyJet\",\n      \"group\": \"tactip\",\n"));
    assert!(text.contains("\"print_technology\": \"FDM\",\n      \"group\": null,\n"));

    // STLs: each part in its own (shared) coordinates, not moved.
    for (p, mp) in kit.parts.iter().zip(&m.parts) {
        let bytes = fs::read(a.join(mp.file.as_deref().unwrap())).unwrap();
        let stl = stl_io::read_stl(&mut std::io::Cursor::new(&bytes)).unwrap();
        let bb = bbox(stl.vertices.iter().map(|v| v.0.map(f64::from)));
        assert_eq!(bb, p.solid.bounding_box().unwrap(), "{}", p.name);
        assert_eq!(bb, mp.bbox_mm);
    }

    // Manifest: two objects, the group first (where its first part is in kit order).
    let k3 = m.kit_3mf.as_ref().unwrap();
    let names: Vec<&str> = k3.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["skin+dots", "plate"]);
    let (skin, dots, plate) = (&m.parts[0], &m.parts[2], &m.parts[1]);
    let group = &k3.objects[0];
    assert_eq!((group.id, group.group.as_deref()), (1, Some("tactip")));
    assert_eq!(
        group.volumes,
        [
            ManifestVolume {
                part: "skin".into(),
                first_triangle: 0,
                last_triangle: skin.triangles - 1,
                extruder: 1,
            },
            ManifestVolume {
                part: "dots".into(),
                first_triangle: skin.triangles,
                last_triangle: skin.triangles + dots.triangles - 1,
                extruder: 2,
            },
        ]
    );
    assert_eq!(
        (k3.objects[1].id, k3.objects[1].group.as_deref()),
        (2, None)
    );
    assert_eq!(k3.objects[1].volumes.len(), 1);
    assert_eq!(k3.objects[1].volumes[0].part, "plate");

    // 3MF, read back by `threemf`: one mesh object per plate unit, one build item each.
    let bytes = fs::read(a.join(&k3.file)).unwrap();
    let models = threemf::read(std::io::Cursor::new(&bytes)).unwrap();
    let model = &models[0];
    assert_eq!(model.resources.object.len(), 2);
    assert_eq!(model.build.item.len(), 2);
    let mut placed = Vec::new();
    for (o, mo) in model.resources.object.iter().zip(&k3.objects) {
        assert_eq!(o.id as u32, mo.id);
        assert_eq!(o.name.as_deref(), Some(mo.name.as_str()));
        let item = model
            .build
            .item
            .iter()
            .find(|i| i.objectid == o.id)
            .unwrap();
        let t = item.transform.unwrap();
        assert_eq!(&t[..9], &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        let tr = [t[9], t[10], t[11]];
        assert_eq!(mo.translation_mm, tr, "{}", mo.name);
        let mesh = o.mesh.as_ref().unwrap();
        let verts = vertices_of(mesh);
        let tris: Vec<[usize; 3]> = mesh
            .triangles
            .triangle
            .iter()
            .map(|t| [t.v1, t.v2, t.v3])
            .collect();
        assert_eq!(
            tris.len(),
            mo.volumes.last().unwrap().last_triangle + 1,
            "{}",
            mo.name
        );
        // Each volume is its part, unmoved in the object (so the group stays registered):
        // its triangles hold exactly the part's volume and box.
        for v in &mo.volumes {
            let mp = m.parts.iter().find(|p| p.name == v.part).unwrap();
            let range = &tris[v.first_triangle..=v.last_triangle];
            assert_eq!(range.len(), mp.triangles);
            assert_close(
                signed_volume(&verts, range.iter().copied()),
                mp.volume_mm3,
                &mp.name,
            );
            let used: BTreeSet<usize> = range.iter().flatten().copied().collect();
            assert_eq!(used.len(), mp.vertices, "{}", mp.name);
            assert_eq!(
                bbox(used.iter().map(|&i| verts[i])),
                mp.bbox_mm,
                "{}",
                mp.name
            );
            placed.push((v.part.clone(), offset(&mp.bbox_mm, tr)));
        }
    }
    let placed_box = |name: &str| placed.iter().find(|(n, _)| n == name).unwrap().1;
    let (skin_on_plate, dots_on_plate, plate_on_plate) =
        (placed_box("skin"), placed_box("dots"), placed_box("plate"));
    assert_eq!(skin_on_plate, offset(&skin.bbox_mm, group.translation_mm));
    assert_eq!(skin_on_plate.min[2], 0.0);
    assert_eq!(dots_on_plate.min[2], 10.0);
    assert!(skin_on_plate.min[0] >= 0.0 && skin_on_plate.min[1] >= 0.0);
    assert_eq!(plate_on_plate.min[2], 0.0);
    assert_eq!(plate.name, "plate");
    // the group, as a whole, clears the ungrouped plate by the gap
    for member in [skin_on_plate, dots_on_plate] {
        let gap = 5.0 - 1e-6;
        let p = plate_on_plate;
        let apart = member.max[0] + gap <= p.min[0]
            || p.max[0] + gap <= member.min[0]
            || member.max[1] + gap <= p.min[1]
            || p.max[1] + gap <= member.min[1];
        assert!(apart, "{member:?} and plate {p:?} overlap");
    }

    // PrusaSlicer reads the volumes from its config (exact text) and, for a version-1 file,
    // keeps the build transform for every volume.
    let model_text = zip_text(&bytes, "3D/3dmodel.model").unwrap();
    assert!(model_text.contains(
        " xmlns:slic3rpe=\"http://schemas.slic3r.org/3mf/2017/06\" xmlns:fabkit=\"http://schemas.fabkit.org/3mf/2026\">\n"
    ));
    assert!(model_text.contains("\n <metadata name=\"slic3rpe:Version3mf\">1</metadata>\n"));
    let config = zip_text(&bytes, "Metadata/Slic3r_PE_model.config").unwrap();
    assert_eq!(
        config,
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<config>\n \
             <object id=\"1\" instances_count=\"1\">\n  \
             <metadata type=\"object\" key=\"name\" value=\"skin+dots\"/>\n  \
             <volume firstid=\"0\" lastid=\"{}\">\n   \
             <metadata type=\"volume\" key=\"name\" value=\"skin\"/>\n   \
             <metadata type=\"volume\" key=\"volume_type\" value=\"ModelPart\"/>\n   \
             <metadata type=\"volume\" key=\"extruder\" value=\"1\"/>\n  </volume>\n  \
             <volume firstid=\"{}\" lastid=\"{}\">\n   \
             <metadata type=\"volume\" key=\"name\" value=\"dots\"/>\n   \
             <metadata type=\"volume\" key=\"volume_type\" value=\"ModelPart\"/>\n   \
             <metadata type=\"volume\" key=\"extruder\" value=\"2\"/>\n  </volume>\n \
             </object>\n</config>\n",
            skin.triangles - 1,
            skin.triangles,
            skin.triangles + dots.triangles - 1
        )
    );
    let types = zip_text(&bytes, "[Content_Types].xml").unwrap();
    assert!(types.contains(r#"<Default Extension="config" ContentType="application/xml"/>"#));

    let sheet = fs::read_to_string(a.join("FABRICATION.md")).unwrap();
    for needle in [
        "| 1 | `skin` | `parts/skin.stl` | PolyJet | `tactip` | Stratasys Tango Black+ (PolyJet, Shore A 26-28) |",
        "| 2 | `plate` | `parts/plate.stl` | FDM | – | Black PLA filament |",
        "### Multi-material groups",
        "- group `tactip` (PolyJet): print together as one multi-material job: object \
         `skin+dots` of `grouped.3mf` holds them in place as its parts (one volume each), \
         assign materials: `skin` Stratasys Tango Black+ (PolyJet, Shore A 26-28) (extruder 1), \
         `dots` Stratasys Vero White (PolyJet, rigid) (extruder 2).",
        "- kit 3MF: `grouped.3mf` (2 objects in one file, for viewing the whole kit; print from the plates below)",
    ] {
        assert!(sheet.contains(needle), "missing {needle:?} in\n{sheet}");
    }

    // determinism with groups
    write_kit(&group_kit(), &b, &opts()).unwrap();
    let files = tree(&a);
    assert_eq!(files, tree(&b));
    for f in &files {
        assert_eq!(
            fs::read(a.join(f)).unwrap(),
            fs::read(b.join(f)).unwrap(),
            "{}",
            f.display()
        );
    }

    // without a 3MF the sheet names the STLs to load together
    let stl_only = root.path().join("stl");
    let mut o = opts();
    o.formats = Formats {
        stl: true,
        threemf: false,
        step: false,
        mjcf: false,
        urdf: false,
        usd: false,
    };
    write_kit(&group_kit(), &stl_only, &o).unwrap();
    let sheet = fs::read_to_string(stl_only.join("FABRICATION.md")).unwrap();
    assert!(
        sheet.contains(
            "load `parts/skin.stl`, `parts/dots.stl` as parts of one object without moving \
             them (shared coordinates), assign materials: `skin` Stratasys Tango Black+ \
             (PolyJet, Shore A 26-28), `dots` Stratasys Vero White (PolyJet, rigid)."
        ),
        "{sheet}"
    );
}

#[test]
fn a_kit_without_groups_has_no_prusaslicer_parts() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let m = read_manifest(&out);
    let k3 = m.kit_3mf.unwrap();
    let bytes = fs::read(out.join(&k3.file)).unwrap();
    assert!(zip_text(&bytes, "Metadata/Slic3r_PE_model.config").is_none());
    let model_text = zip_text(&bytes, "3D/3dmodel.model").unwrap();
    assert!(!model_text.contains("slic3rpe"));
    // one object and one whole-mesh volume per part, in kit order
    for ((o, p), id) in k3.objects.iter().zip(&m.parts).zip(1u32..) {
        assert_eq!(
            (o.id, o.name.as_str(), o.group.as_deref()),
            (id, p.name.as_str(), None)
        );
        assert_eq!(
            o.volumes,
            [ManifestVolume {
                part: p.name.clone(),
                first_triangle: 0,
                last_triangle: p.triangles - 1,
                extruder: 1,
            }]
        );
    }
}

#[test]
fn manifest_keys_are_in_schema_order_with_a_trailing_newline() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let text = fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(text.ends_with("}\n"));
    let keys = [
        "\"fabkit_version\"",
        "\"design\"",
        "\"chord_tolerance_mm\"",
        "\"command_line\"",
        "\"frame\"",
        "\"parts\"",
        "\"kit_3mf\"",
        "\"casts\"",
        "\"bought_items\"",
        "\"summary\"",
    ];
    let pos: Vec<usize> = keys
        .iter()
        .map(|k| text.find(&format!("\n  {k}: ")).unwrap())
        .collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{pos:?}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["parts"][2]["print_technology"], "SLA");
    assert_eq!(v["parts"][2]["group"], serde_json::Value::Null);
    // `group` follows `print_technology` in every part
    let part_keys = ["\"print_technology\"", "\"group\"", "\"volume_mm3\""];
    let pos: Vec<usize> = part_keys
        .iter()
        .map(|k| text.find(&format!("\n      {k}: ")).unwrap())
        .collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{pos:?}");
    assert_eq!(text.matches("\n      \"group\": null,\n").count(), 5);
    assert_eq!(
        v["parts"][0]["bbox_mm"]["max"],
        serde_json::json!([75.0, 15.0, 4.0])
    );
    assert_eq!(
        v["frame"],
        "sensor frame (docs/conventions.md); parts are in print orientation on z = 0"
    );
    assert_eq!(v["command_line"][4], "out dir");
}

#[test]
fn fabrication_sheet_lists_provenance_parts_casts_and_checks() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let s = fs::read_to_string(out.join("FABRICATION.md")).unwrap();
    for needle in [
        "# Fabrication sheet: tiny",
        "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef",
        "`fabkit build tiny.yaml --out 'out dir'`",
        "| 1 | `base_plate` | `parts/base_plate.stl` | FDM | – | Black PLA filament | 18000.0 | 150.00 × 30.00 × 4.00 |",
        "## Shopping list",
        "| Smooth-On Solaris | 3.85 g |",
        "### Step 1: transparent_gel",
        "- material: Smooth-On Solaris",
        "- layer volume: 2.50 mL (the cast layer alone, from the exact profile)",
        "- pour volume: 3.21 mL (the cavity with its reservoir and sprue)",
        "- waste allowance: 20 %",
        "  - Part A: 1.93 g",
        "  - total: 3.85 g",
        "pot life 15 min \\| degas 3 min",
        "- acrylic tube, 30 mm OD",
        "## Checking the prints",
    ] {
        assert!(s.contains(needle), "missing {needle:?} in\n{s}");
    }
    // the printed grams: each part's volume times the PLA density (1.24 g/cm3)
    let m = read_manifest(&out);
    let pla: f64 = m
        .parts
        .iter()
        .filter(|p| p.material == "pla_black")
        .map(|p| {
            assert!(
                (p.mass_g - p.volume_mm3 / 1000.0 * 1.24).abs() < 1e-9,
                "{}",
                p.name
            );
            p.mass_g
        })
        .sum();
    assert!(pla > 0.0);
    assert!(
        s.contains(&format!("| Black PLA filament | {pla:.1} g |")),
        "{s}"
    );
    assert!(!s.contains("Multi-material"), "{s}");
}

#[test]
fn formats_select_the_mesh_files() {
    let root = tempfile::tempdir().unwrap();
    let (stl_only, mf_only) = (root.path().join("stl"), root.path().join("3mf"));
    let mut o = opts();
    o.formats = Formats {
        stl: true,
        threemf: false,
        step: false,
        mjcf: false,
        urdf: false,
        usd: false,
    };
    write_kit(&test_kit(), &stl_only, &o).unwrap();
    assert!(!stl_only.join("tiny.3mf").exists());
    assert!(stl_only.join("parts/ring.stl").exists());
    let m = read_manifest(&stl_only);
    assert!(m.kit_3mf.is_none());
    // pictures of the parts with any mesh format; no plates, so no plate pictures
    assert!(m
        .parts
        .iter()
        .all(|p| p.preview.as_deref() == Some(&format!("previews/{}.png", p.name))));
    assert!(stl_only.join("previews/ring.png").exists());
    assert_eq!(fs::read_dir(stl_only.join("previews")).unwrap().count(), 5);

    o.formats = Formats {
        stl: false,
        threemf: true,
        step: false,
        mjcf: false,
        urdf: false,
        usd: false,
    };
    let s = write_kit(&test_kit(), &mf_only, &o).unwrap();
    assert_eq!(
        tree(&mf_only),
        [
            PathBuf::from(".fabkit-output"),
            "FABRICATION.html".into(),
            "FABRICATION.md".into(),
            "manifest.json".into(),
            "plates/tiny_fdm_pla_black_1.3mf".into(),
            "plates/tiny_sla_pla_black_1.3mf".into(),
            "previews/base_plate.png".into(),
            "previews/dome.png".into(),
            "previews/pillar.png".into(),
            "previews/plate_tiny_fdm_pla_black_1.png".into(),
            "previews/plate_tiny_sla_pla_black_1.png".into(),
            "previews/ring.png".into(),
            "previews/wide_tray.png".into(),
            "tiny.3mf".into()
        ]
    );
    assert_eq!(s.files.len(), 13);
    let m = read_manifest(&mf_only);
    assert_eq!(
        m.plates
            .iter()
            .map(|p| (
                p.preview.clone().unwrap(),
                p.preview_sha256.clone().unwrap()
            ))
            .collect::<Vec<_>>(),
        ["tiny_fdm_pla_black_1", "tiny_sla_pla_black_1"].map(|stem| {
            let rel = format!("previews/plate_{stem}.png");
            let sha = sha256_hex(&fs::read(mf_only.join(&rel)).unwrap());
            (rel, sha)
        })
    );
    // each plate's picture is its 3MF's package thumbnail, related from the package root
    let plate = fs::read(mf_only.join("plates/tiny_fdm_pla_black_1.3mf")).unwrap();
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(&plate[..])).unwrap();
    let mut thumbnail = Vec::new();
    std::io::Read::read_to_end(
        &mut zip.by_name("Metadata/thumbnail.png").unwrap(),
        &mut thumbnail,
    )
    .unwrap();
    assert_eq!(
        thumbnail,
        fs::read(mf_only.join("previews/plate_tiny_fdm_pla_black_1.png")).unwrap()
    );
    assert!(zip_text(&plate, "_rels/.rels").unwrap().contains(
        r#"<Relationship Target="/Metadata/thumbnail.png" Id="rel1" Type="http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"/>"#
    ));
    assert!(zip_text(&plate, "[Content_Types].xml")
        .unwrap()
        .contains(r#"<Default Extension="png" ContentType="image/png"/>"#));
    assert!(m
        .parts
        .iter()
        .all(|p| p.file.is_none() && p.sha256.is_none()));
    assert!(fs::read_to_string(mf_only.join("FABRICATION.md"))
        .unwrap()
        .contains("(in the 3MF only)"));
}

#[test]
fn unrelated_directory_is_refused_and_untouched() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("photos");
    fs::create_dir(&out).unwrap();
    fs::write(out.join("holiday.jpg"), b"not a kit").unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(
        matches!(err, ExportError::ForeignDirectory { ref entry, .. } if entry == "holiday.jpg"),
        "{err}"
    );
    assert!(err.to_string().contains("hint"));
    assert_eq!(entries(&out), ["holiday.jpg"]);
    assert_eq!(fs::read(out.join("holiday.jpg")).unwrap(), b"not a kit");
    assert_eq!(entries(root.path()), ["photos"]);
}

#[test]
fn file_in_place_of_the_directory_is_refused() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    fs::write(&out, b"a file").unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(matches!(err, ExportError::NotADirectory { .. }), "{err}");
    assert_eq!(fs::read(&out).unwrap(), b"a file");
    assert_eq!(entries(root.path()), ["kit"]);
}

#[test]
fn reexport_replaces_the_previous_export() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    let first = write_kit(&test_kit(), &out, &opts()).unwrap();
    assert!(!first.replaced_previous_export);
    let mut smaller = test_kit();
    smaller.parts.truncate(2);
    let second = write_kit(&smaller, &out, &opts()).unwrap();
    assert!(second.replaced_previous_export);
    assert!(second.warnings.is_empty(), "{:?}", second.warnings);
    assert_eq!(
        entries(&out.join("parts")),
        ["base_plate.stl", "pillar.stl"]
    );
    assert_eq!(read_manifest(&out).parts.len(), 2);
    // no temporary or backup sibling is left
    assert_eq!(entries(root.path()), ["kit"]);
    for f in &second.files {
        assert!(f.is_file(), "{}", f.display());
    }
}

#[test]
fn empty_directory_and_missing_parents_are_fine() {
    let root = tempfile::tempdir().unwrap();
    let empty = root.path().join("empty");
    fs::create_dir(&empty).unwrap();
    write_kit(&test_kit(), &empty, &opts()).unwrap();
    assert!(empty.join("manifest.json").is_file());
    let deep = root.path().join("a").join("b").join("kit");
    write_kit(&test_kit(), &deep, &opts()).unwrap();
    assert!(deep.join("tiny.3mf").is_file());
    assert_eq!(entries(&root.path().join("a").join("b")), ["kit"]);
}

/// Whether `prusa-slicer` runs. Without it scripts/test (FABKIT_REQUIRE_ORACLES=1) and CI
/// fail, a plain `cargo test` skips with a message.
fn prusa_slicer_available() -> bool {
    if std::process::Command::new("prusa-slicer")
        .arg("--help")
        .output()
        .is_ok()
    {
        return true;
    }
    let required = std::env::var("FABKIT_REQUIRE_ORACLES").is_ok_and(|v| v == "1")
        || std::env::var("CI").is_ok_and(|v| v == "true");
    assert!(
        !required,
        "prusa-slicer is required here; run scripts/setup-system"
    );
    eprintln!("SKIPPED: prusa-slicer not on PATH");
    false
}

/// Runs `prusa-slicer` with `args`; panics with its output unless it succeeds. Returns stdout.
fn prusa_slicer(args: &[&std::ffi::OsStr]) -> String {
    let o = std::process::Command::new("prusa-slicer")
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

#[test]
fn prusa_slicer_reports_every_object_manifold() {
    if !prusa_slicer_available() {
        return;
    }
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let text = prusa_slicer(&["--info".as_ref(), out.join("tiny.3mf").as_os_str()]);
    assert_eq!(text.matches("manifold = yes").count(), 5, "{text}");
    assert!(!text.contains("manifold = no"), "{text}");
}

/// The regression behind the group layout: the dots of a TacTip skin written as an object of
/// their own were sliced alone ("Empty layer between ..."). PrusaSlicer must load a group as
/// ONE object whose volumes are the parts, named, with their extruders, in place.
#[test]
fn prusa_slicer_loads_a_group_as_one_object_with_named_volumes() {
    if !prusa_slicer_available() {
        return;
    }
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&group_kit(), &out, &opts()).unwrap();
    let m = read_manifest(&out);
    let input = out.join("grouped.3mf");
    let text = prusa_slicer(&["--info".as_ref(), input.as_os_str()]);
    // one section per object: the group and the plate
    assert_eq!(text.matches("[grouped.3mf]").count(), 2, "{text}");
    assert_eq!(text.matches("manifold = yes").count(), 2, "{text}");
    let facets = m.parts[0].triangles + m.parts[2].triangles;
    assert!(
        text.contains(&format!("number_of_facets = {facets}\n")),
        "{text}"
    );

    // What PrusaSlicer loaded, as it saves it again: volumes, names and extruders.
    let saved = root.path().join("saved.3mf");
    prusa_slicer(&[
        "--dont-arrange".as_ref(),
        "--export-3mf".as_ref(),
        "-o".as_ref(),
        saved.as_os_str(),
        input.as_os_str(),
    ]);
    let config = zip_text(
        &fs::read(&saved).unwrap(),
        "Metadata/Slic3r_PE_model.config",
    )
    .unwrap();
    let objects: Vec<&str> = config.split("<object ").skip(1).collect();
    assert_eq!(objects.len(), 2, "{config}");
    let group = objects
        .iter()
        .find(|o| o.contains(r#"key="name" value="skin+dots""#))
        .unwrap_or_else(|| panic!("no object skin+dots in\n{config}"));
    let volumes: Vec<&str> = group.split("<volume ").skip(1).collect();
    assert_eq!(volumes.len(), 2, "{config}");
    for (v, (name, extruder)) in volumes.iter().zip([("skin", "1"), ("dots", "2")]) {
        assert!(v.contains(&format!(r#"key="name" value="{name}""#)), "{v}");
        assert!(
            v.contains(&format!(r#"key="extruder" value="{extruder}""#)),
            "{v}"
        );
    }
}

/// The marker names the command and the job, and lists every other file of the output with
/// its size and SHA-256 (computed here from the files on disk), sorted, and nothing else.
#[test]
fn marker_lists_every_file_of_the_output() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let marker: serde_json::Value =
        serde_json::from_slice(&fs::read(out.join(OUTPUT_MARKER)).unwrap()).unwrap();
    assert_eq!(marker["format"], "fabkit-output/2");
    assert_eq!(marker["command"], "export");
    assert_eq!(marker["job"], "kit 'tiny' at chord tolerance 0.05 mm");
    let listed: Vec<(PathBuf, u64, String)> = marker["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                PathBuf::from(f["path"].as_str().unwrap()),
                f["bytes"].as_u64().unwrap(),
                f["sha256"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let on_disk: Vec<(PathBuf, u64, String)> = tree(&out)
        .into_iter()
        .filter(|p| p != Path::new(OUTPUT_MARKER))
        .map(|p| {
            let bytes = fs::read(out.join(&p)).unwrap();
            (p, bytes.len() as u64, sha256_hex(&bytes))
        })
        .collect();
    assert!(on_disk.len() >= 3, "{on_disk:?}");
    assert_eq!(listed, on_disk);
}

/// A folder of the user's own files with a forged marker naming them at their sizes (in this
/// fabkit's format with made-up checksums, or in the earlier format without any) is refused,
/// naming the user's file, and nothing in it is touched.
#[test]
fn forged_marker_naming_the_users_files_is_refused() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("thesis");
    fs::create_dir(&out).unwrap();
    fs::write(out.join("thesis.tex"), b"\\section{Results}").unwrap();
    let n = fs::metadata(out.join("thesis.tex")).unwrap().len();
    let forged = [
        serde_json::json!({"format": "fabkit-output/1",
                           "files": [{"path": "thesis.tex", "bytes": n}]}),
        serde_json::json!({"format": "fabkit-output/2", "command": "export",
                           "job": "kit 'tiny' at chord tolerance 0.05 mm",
                           "files": [{"path": "thesis.tex", "bytes": n,
                                      "sha256": "0".repeat(64)}]}),
    ];
    for marker in forged {
        fs::write(out.join(OUTPUT_MARKER), marker.to_string()).unwrap();
        for force in [false, true] {
            let o = ExportOptions { force, ..opts() };
            let err = write_kit(&test_kit(), &out, &o).unwrap_err();
            assert!(
                matches!(err, ExportError::ForeignDirectory { ref entry, .. } if entry == "thesis.tex"),
                "{marker}: {err}"
            );
            assert_eq!(
                fs::read(out.join("thesis.tex")).unwrap(),
                b"\\section{Results}"
            );
        }
    }
    assert_eq!(entries(&out), [OUTPUT_MARKER, "thesis.tex"]);
}

/// An output of another command is never replaced, even with force; one of the same command
/// for another kit or tolerance only with force.
#[test]
fn another_commands_output_is_kept_and_another_job_only_with_force() {
    use fabkit_export::{OutputClaim, OutputCommand, StagedDir};
    let root = tempfile::tempdir().unwrap();
    let calib = root.path().join("calib");
    let claim = OutputClaim::of_inputs(
        OutputCommand::CalibrateExtrinsics,
        "extrinsics from 1 captures",
        &[],
        false,
    );
    let st = StagedDir::new(&calib, claim.clone()).unwrap();
    st.write("extrinsics.json", b"{}\n").unwrap();
    st.commit().unwrap();
    for force in [false, true] {
        let o = ExportOptions { force, ..opts() };
        let err = write_kit(&test_kit(), &calib, &o).unwrap_err();
        assert!(matches!(err, ExportError::OtherCommand { .. }), "{err}");
        let text = err.to_string();
        assert!(
            text.contains("`fabkit calibrate extrinsics`") && text.contains("`fabkit export`"),
            "{text}"
        );
        assert_eq!(fs::read(calib.join("extrinsics.json")).unwrap(), b"{}\n");
    }
    // and the other way round
    let kit = root.path().join("kit");
    write_kit(&test_kit(), &kit, &opts()).unwrap();
    let err = StagedDir::new(
        &kit,
        OutputClaim {
            force: true,
            ..claim.clone()
        },
    )
    .unwrap_err();
    assert!(matches!(err, ExportError::OtherCommand { .. }), "{err}");
    assert!(kit.join("manifest.json").is_file());
    // the same command at another tolerance: only with force
    let other = ExportOptions {
        chord_tolerance_mm: 0.02,
        ..opts()
    };
    let err = write_kit(&test_kit(), &kit, &other).unwrap_err();
    assert!(
        matches!(err, ExportError::OtherJob { ref job, ref this_job, .. }
            if job == "kit 'tiny' at chord tolerance 0.05 mm"
            && this_job == "kit 'tiny' at chord tolerance 0.02 mm"),
        "{err}"
    );
    assert!(err.to_string().contains("--force"), "{err}");
    let forced = ExportOptions {
        force: true,
        ..other
    };
    write_kit(&test_kit(), &kit, &forced).unwrap();
    let marker: serde_json::Value =
        serde_json::from_slice(&fs::read(kit.join(OUTPUT_MARKER)).unwrap()).unwrap();
    assert_eq!(marker["job"], "kit 'tiny' at chord tolerance 0.02 mm");
    // a calibration of the same inputs replaces its own output
    let st = StagedDir::new(&calib, claim).unwrap();
    st.write("extrinsics.json", b"{\"v\": 2}\n").unwrap();
    st.commit().unwrap();
    assert_eq!(
        fs::read(calib.join("extrinsics.json")).unwrap(),
        b"{\"v\": 2}\n"
    );
}

/// A user's folder holding a look-alike fabkit manifest.json is not taken for an output:
/// refused, and none of its files touched.
#[test]
fn look_alike_manifest_folder_is_refused_and_untouched() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("notes");
    fs::create_dir(&out).unwrap();
    let manifest = b"{\"fabkit_version\": \"0.1.0\", \"parts\": []}\n";
    fs::write(out.join("manifest.json"), manifest).unwrap();
    fs::write(out.join("thesis.tex"), b"keep me").unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(
        matches!(err, ExportError::ForeignDirectory { ref entry, .. } if entry == "thesis.tex"),
        "{err}"
    );
    assert!(err.to_string().contains(OUTPUT_MARKER), "{err}");
    assert_eq!(entries(&out), ["manifest.json", "thesis.tex"]);
    assert_eq!(fs::read(out.join("manifest.json")).unwrap(), manifest);
    assert_eq!(fs::read(out.join("thesis.tex")).unwrap(), b"keep me");
    assert_eq!(entries(root.path()), ["notes"]);
    // A copied marker does not make the folder fabkit's: it lists neither file.
    let kit = root.path().join("kit");
    write_kit(&test_kit(), &kit, &opts()).unwrap();
    fs::copy(kit.join(OUTPUT_MARKER), out.join(OUTPUT_MARKER)).unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(matches!(err, ExportError::ForeignDirectory { .. }), "{err}");
    assert_eq!(fs::read(out.join("thesis.tex")).unwrap(), b"keep me");
}

/// A previous output is replaced only as fabkit wrote it: a file added to it or a file edited
/// in it (another size) makes it the user's, refused and untouched; a deleted file does not.
#[test]
fn previous_output_changed_by_the_user_is_refused_and_untouched() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("kit");
    write_kit(&test_kit(), &out, &opts()).unwrap();
    let before = tree(&out);

    fs::write(out.join("parts/notes.txt"), b"mine").unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(
        matches!(err, ExportError::ForeignDirectory { ref entry, .. } if entry == "parts/notes.txt"),
        "{err}"
    );
    assert_eq!(fs::read(out.join("parts/notes.txt")).unwrap(), b"mine");
    fs::remove_file(out.join("parts/notes.txt")).unwrap();
    assert_eq!(tree(&out), before);

    let original = fs::read(out.join("FABRICATION.md")).unwrap();
    let mut md = original.clone();
    md.extend_from_slice(b"\nmy notes\n");
    fs::write(out.join("FABRICATION.md"), &md).unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(
        matches!(err, ExportError::ForeignDirectory { ref entry, .. } if entry == "FABRICATION.md"),
        "{err}"
    );
    assert_eq!(fs::read(out.join("FABRICATION.md")).unwrap(), md);

    // an edit that keeps the size: the SHA-256 tells it
    let mut same_size = original.clone();
    let k = same_size
        .iter()
        .position(|b| b.is_ascii_lowercase())
        .unwrap();
    same_size[k] = same_size[k].to_ascii_uppercase();
    fs::write(out.join("FABRICATION.md"), &same_size).unwrap();
    let err = write_kit(&test_kit(), &out, &opts()).unwrap_err();
    assert!(
        matches!(err, ExportError::ForeignDirectory { ref entry, ref why, .. }
            if entry == "FABRICATION.md" && why.contains("SHA-256")),
        "{err}"
    );
    assert_eq!(fs::read(out.join("FABRICATION.md")).unwrap(), same_size);

    fs::remove_file(out.join("FABRICATION.md")).unwrap();
    write_kit(&test_kit(), &out, &opts()).unwrap();
    assert_eq!(tree(&out), before);
    assert_eq!(entries(root.path()), ["kit"]);
}

/// The sheet's print settings and its "checking the prints" list name only what the kit has:
/// supports kept off the surfaces that form the skin, leak-tight mold boxes; registration keys for
/// the halves of a direct mold, the boss and pocket of a two-piece open mold, the mold boxes of
/// master patterns (ShadowTac's two-piece mold and the printed TacTip skin have no registration
/// keys, and the sheet once told their makers to check them).
#[test]
fn checking_the_prints_lists_only_the_kits_own_fits() {
    use fabkit_designs::schema::MoldStrategy;
    let tol = ChordTolerance::new(0.05).unwrap();
    let mut designs: Vec<fabkit_designs::Design> = fabkit_designs::library::LIBRARY
        .iter()
        .map(|(n, _)| fabkit_designs::library::load(n).unwrap())
        .collect();
    let mut direct = fabkit_designs::library::load("rtac0").unwrap();
    direct.mold.strategy = MoldStrategy::Direct;
    direct.name = "rtac0_mold_direct".into();
    designs.push(direct);
    let root = tempfile::tempdir().unwrap();
    let mut seen_keys = 0;
    for d in &designs {
        let kit = fabkit_designs::build_kit(d, tol).unwrap();
        let out = root.path().join(&d.name);
        write_kit(&kit, &out, &opts()).unwrap();
        let sheet = fs::read_to_string(out.join("FABRICATION.md")).unwrap();
        let checks = &sheet[sheet.find("## Checking the prints").unwrap()..];
        let roles = |r: &str| kit.parts.iter().filter(|p| p.role == r).count();
        let keys = checks.contains("registration keys");
        assert_eq!(keys, roles("mold_half") > 0, "{}: {checks}", d.name);
        assert_eq!(
            checks.contains("boss"),
            roles("open_mold_piece") > 1,
            "{}: {checks}",
            d.name
        );
        assert_eq!(
            checks.contains("mold box"),
            roles("mold_box") > 0,
            "{}: {checks}",
            d.name
        );
        // print settings: no supports on skin-forming surfaces, leak-tight mold boxes
        let forming = [
            "master_pattern",
            "mold_half",
            "open_mold_piece",
            "negative_mold",
        ]
        .iter()
        .map(|r| roles(r))
        .sum::<usize>();
        assert_eq!(
            sheet.contains("- Surfaces that form the skin ("),
            forming > 0,
            "{}",
            d.name
        );
        assert_eq!(
            sheet.contains("the walls must be leak-tight"),
            roles("mold_box") > 0,
            "{}",
            d.name
        );
        seen_keys += usize::from(keys);
    }
    assert_eq!(seen_keys, 1, "only the direct kit has registration keys");
}
