//! Every file of a kit's export, in memory, in the order they are filed: the parts' STL files
//! and manifest entries, the kit 3MF, the plates (3MF and picture), the parts' pictures, the
//! machined parts (STL and drawing), the STEP files, the section view, the cut parts and
//! boards, the assembly 3MF, the data files, and last the manifest and the fabrication sheet.
//! One function per output; [`render`] runs them in that order.

use crate::layout::{self, Plate};
use crate::section::SectionView;
use crate::zip_package::Deflated;
use crate::{
    assembly_3mf, bbox_of, check_printable_mesh, check_printable_meshes, html, package_metadata,
    part_entry, placed_objects, preview, product_name, raster, section, sha256_hex, sheet, step,
    step_files, stl_file, three_mf, two_d, ExportError, ExportOptions, Manifest, ManifestAssembly,
    ManifestAssemblyStep, ManifestCutPart, ManifestDataFile, ManifestDesign, ManifestKit3mf,
    ManifestMachinedPart, ManifestObject, ManifestPart, ManifestPcbOutline, ManifestPlate,
    ManifestPlateObject, ManifestVolume, Rendered, CUT_DIR, FRAME, MACHINED_DIR, PARTS_DIR,
    PCB_DIR, PLATES_DIR, PREVIEWS_DIR, SECTION_PNG, STEP_DIR,
};
use fabkit_designs::geometry::Mesh;
use fabkit_designs::kit::Kit;
use fabkit_designs::materials::MaterialsTable;

/// The files of an export, `/`-separated relative paths with their bytes, in filing order.
type Files = Vec<(String, Vec<u8>)>;

/// The kit 3MF's objects and bytes; `None` without 3MF.
type Kit3mf<'m> = Option<(Vec<three_mf::Object<'m>>, Vec<u8>)>;

/// (picture, 3MF, its objects) of each plate.
type PlateFiles<'m> = Vec<(Vec<u8>, Vec<u8>, Vec<three_mf::Object<'m>>)>;

/// The assembled sensor's meshes, the section view's picture, and its 3MF (its error is
/// reported where it is filed, after the meshes' checks).
type AssemblyFiles = (
    Vec<Mesh>,
    Option<(Vec<u8>, SectionView)>,
    Option<Result<(ManifestAssembly, Vec<u8>), ExportError>>,
);

/// Every file of the export of `kit` (its parts' written `meshes`), with the manifest.
pub(crate) fn render(
    kit: &Kit,
    meshes: &[Mesh],
    data_files: &[(String, Vec<u8>)],
    opts: &ExportOptions,
    step_progress: Option<step::StepProgress<'_>>,
) -> Result<Rendered, ExportError> {
    let t = fabkit_designs::timings::stage("STL files and part entries");
    let mut files = Vec::new();
    // product names and densities of the printed materials
    let materials = MaterialsTable::embedded().ok();
    let mut parts = part_files(kit, meshes, opts, materials.as_ref(), &mut files)?;
    let groups: Vec<_> = parts.iter().map(|p| p.group.as_deref()).collect();
    let units = layout::units(&groups);
    drop(t);
    let t = fabkit_designs::timings::stage("plates");
    // the plates first: a part larger than its bed stops the export before anything is made
    let plates = if opts.formats.threemf {
        let keyed: Vec<_> = kit
            .parts
            .iter()
            .zip(&parts)
            .map(|(p, m)| (p.print_technology, p.material.as_str(), m.bbox_mm))
            .collect();
        let names: Vec<&str> = kit.parts.iter().map(|p| p.name.as_str()).collect();
        // a unit as many times as its first part's copies (the fixtures' pins: one per hole)
        let copies: Vec<usize> = units.iter().map(|u| kit.parts[u[0]].copies()).collect();
        layout::plates(
            &keyed,
            &names,
            &units,
            &copies,
            &opts.printers,
            layout::GAP_MM,
        )?
    } else {
        Vec::new()
    };
    drop(t);
    // The kit 3MF (its thumbnail rendered), the pictures and the section view are independent:
    // made in parallel, then filed in this order. Each is deterministic, so the bytes do not
    // depend on the thread count.
    let t = fabkit_designs::timings::stage("kit 3MF, pictures and section view (in parallel)");
    let ((assembly_made, part_pngs), (kit_3mf_made, plate_pngs)) = rayon::join(
        || {
            rayon::join(
                || assembly_section(kit, opts),
                || part_pictures(kit, meshes, opts),
            )
        },
        || {
            // each unit's mesh element deflated once, for the kit 3MF and its plate
            let unit_meshes = match unit_meshes(kit, meshes, &units, opts) {
                Ok(m) => m,
                // reported as the kit 3MF's (filed first)
                Err(e) => return (Err(e), Ok(Vec::new())),
            };
            rayon::join(
                || kit_3mf(kit, meshes, &parts, &units, &unit_meshes, opts),
                || plate_files(kit, meshes, &plates, &units, &unit_meshes, opts),
            )
        },
    );
    drop(t);
    let t = fabkit_designs::timings::stage("kit and plate 3MF files, pictures filed");
    let kit_3mf =
        kit_3mf_made?.map(|(objects, bytes)| file_kit_3mf(kit, &objects, bytes, &mut files));
    let part_pngs = part_pngs?;
    let (manifest_plates, plate_picture_files) =
        file_plates(kit, &plates, plate_pngs?, &units, &parts, &mut files);
    for (p, png) in parts.iter_mut().zip(part_pngs) {
        let rel = format!("{PREVIEWS_DIR}/{}.png", p.name);
        p.preview_sha256 = Some(sha256_hex(&png));
        p.preview = Some(rel.clone());
        files.push((rel, png));
    }
    files.extend(plate_picture_files);
    drop(t);
    let (assembly_meshes, section_png, assembly_3mf_made) = assembly_made?;
    let t = fabkit_designs::timings::stage("assembly checks, machined parts and drawings");
    let names: Vec<&str> = kit.assembly.iter().map(|m| m.name.as_str()).collect();
    check_printable_meshes(&names, &assembly_meshes)?;
    let mut machined_parts = machined_files(kit, opts, materials.as_ref(), &mut files)?;
    drop(t);
    let t = opts
        .formats
        .step
        .then(|| fabkit_designs::timings::stage("STEP (CadQuery twin)"));
    let assembly_step = if opts.formats.step {
        step_outputs(
            kit,
            &mut parts,
            &mut machined_parts,
            &assembly_meshes,
            opts,
            step_progress,
            &mut files,
        )?
    } else {
        None
    };
    drop(t);
    let t = fabkit_designs::timings::stage("cut parts, boards and the assembly 3MF");
    let section_view = section_png.map(|(bytes, mut view)| {
        view.file = SECTION_PNG.into();
        view.sha256 = sha256_hex(&bytes);
        files.push((SECTION_PNG.into(), bytes));
        view
    });
    let cut_parts = cut_part_files(kit, opts, materials.as_ref(), &mut files)?;
    let sim = if (opts.formats.mjcf || opts.formats.urdf || opts.formats.usd)
        && !kit.assembly.is_empty()
    {
        let (entry, sim_files) = crate::sim_files(kit, &assembly_meshes, opts)?;
        files.extend(sim_files);
        Some(entry)
    } else {
        None
    };
    let pcb_outlines = pcb_files(kit, &mut files)?;
    let assembly_3mf = match assembly_3mf_made {
        Some(made) => {
            let (manifest_assembly, bytes) = made?;
            files.push((manifest_assembly.file.clone(), bytes));
            Some(manifest_assembly)
        }
        None => None,
    };
    drop(t);
    let t = fabkit_designs::timings::stage("manifest, FABRICATION.md and .html");
    let manifest = Manifest {
        fabkit_version: opts.fabkit_version.clone(),
        design: ManifestDesign {
            name: kit.design.clone(),
            source: opts.design_source.clone(),
            sha256: opts.design_sha256.clone(),
        },
        chord_tolerance_mm: opts.chord_tolerance_mm,
        command_line: opts.command_line.clone(),
        frame: FRAME.to_owned(),
        parts,
        kit_3mf,
        plates: manifest_plates,
        assembly_3mf,
        assembly_step,
        sim,
        section_view,
        cut_parts,
        pcb_outlines,
        machined_parts,
        casts: kit.casts.clone(),
        bought_items: kit.bought_items.clone(),
        procedure: kit.procedure.clone(),
        summary: kit.summary.clone(),
        data_files: data_files
            .iter()
            .map(|(rel, bytes)| ManifestDataFile {
                file: rel.clone(),
                sha256: sha256_hex(bytes),
            })
            .collect(),
    };
    file_manifest_and_sheet(kit, &manifest, data_files, &mut files)?;
    drop(t);
    Ok(Rendered { files, manifest })
}

/// Each part's manifest entry and STL, made in parallel and filed in kit order (the first
/// error in that order).
fn part_files(
    kit: &Kit,
    meshes: &[Mesh],
    opts: &ExportOptions,
    materials: Option<&MaterialsTable>,
    files: &mut Files,
) -> Result<Vec<ManifestPart>, ExportError> {
    let made: Vec<Result<_, ExportError>> = {
        use rayon::prelude::*;
        kit.parts
            .par_iter()
            .zip(meshes)
            .map(|(part, mesh)| {
                let entry = part_entry(part, mesh, materials)?;
                let mut stl = Vec::new();
                let named = stl_file(kit, opts, PARTS_DIR, &part.name, mesh, &mut stl)?;
                Ok((entry, named, stl))
            })
            .collect()
    };
    let mut parts = Vec::with_capacity(kit.parts.len());
    for m in made {
        let (mut entry, (file, sha256), stl) = m?;
        entry.file = file;
        entry.sha256 = sha256;
        parts.push(entry);
        files.extend(stl);
    }
    Ok(parts)
}

/// Each unit's `<mesh>` element deflated (in parallel), when 3MF is written: the kit 3MF and
/// the unit's plate hold the same element.
fn unit_meshes(
    kit: &Kit,
    meshes: &[Mesh],
    units: &[Vec<usize>],
    opts: &ExportOptions,
) -> Result<Vec<Deflated>, ExportError> {
    use rayon::prelude::*;
    if !opts.formats.threemf {
        return Ok(Vec::new());
    }
    units
        .par_iter()
        .map(|u| three_mf::mesh_deflated(&unit_object(kit, meshes, u, [0.0; 3], false)))
        .collect()
}

/// A unit's 3MF object: its parts (`members`, indices into the kit's parts) as volumes, with
/// their role, material and technology, at translation `t`, turned or not.
fn unit_object<'m>(
    kit: &'m Kit,
    meshes: &'m [Mesh],
    members: &[usize],
    t: [f64; 3],
    turned: bool,
) -> three_mf::Object<'m> {
    let first = &kit.parts[members[0]];
    let joined = |f: &dyn Fn(&fabkit_designs::kit::Part) -> String| {
        let mut v: Vec<String> = Vec::new();
        for &i in members {
            let s = f(&kit.parts[i]);
            if !v.contains(&s) {
                v.push(s);
            }
        }
        v.join("+")
    };
    three_mf::Object {
        name: members
            .iter()
            .map(|&i| kit.parts[i].name.as_str())
            .collect::<Vec<_>>()
            .join("+"),
        group: first.group.as_deref(),
        volumes: members
            .iter()
            .map(|&i| three_mf::Volume {
                name: &kit.parts[i].name,
                mesh: &meshes[i],
            })
            .collect(),
        translation_mm: t,
        turned,
        metadata: vec![
            ("role", joined(&|p| p.role.clone())),
            ("material", joined(&|p| p.material.clone())),
            ("technology", joined(&|p| p.print_technology.to_string())),
        ],
    }
}

/// The kit 3MF (every unit packed in rows, its thumbnail rendered); `None` without 3MF.
fn kit_3mf<'m>(
    kit: &'m Kit,
    meshes: &'m [Mesh],
    parts: &[ManifestPart],
    units: &[Vec<usize>],
    unit_meshes: &[Deflated],
    opts: &ExportOptions,
) -> Result<Kit3mf<'m>, ExportError> {
    if !opts.formats.threemf {
        return Ok(None);
    }
    let boxes: Vec<_> = parts.iter().map(|p| p.bbox_mm).collect();
    let translations = layout::pack_units(&boxes, units, layout::ROW_WIDTH_MM, layout::GAP_MM);
    let objects: Vec<three_mf::Object<'_>> = units
        .iter()
        .zip(&translations)
        .map(|(members, t)| unit_object(kit, meshes, members, *t, false))
        .collect();
    let metadata = package_metadata(
        format!("fabkit kit {}", kit.design),
        opts,
        format!(
            "design {} from {}, sha256:{}, chord tolerance {} mm; command line: {}",
            kit.design,
            opts.design_source,
            opts.design_sha256,
            opts.chord_tolerance_mm,
            sheet::shell_words(&opts.command_line)
        ),
    );
    let thumbnail = || {
        preview::render_plate(&placed_objects(&objects), None).png(&format!(
            "fabkit kit {}: the kit 3MF's layout seen from above-front",
            kit.design
        ))
    };
    let premade: Vec<&Deflated> = unit_meshes.iter().collect();
    let (bytes, _) = three_mf::encode_drawn(&objects, &premade, &metadata, Some(thumbnail))?;
    Ok(Some((objects, bytes)))
}

/// Every part's preview, whenever a mesh format is written.
fn part_pictures(
    kit: &Kit,
    meshes: &[Mesh],
    opts: &ExportOptions,
) -> Result<Vec<Vec<u8>>, ExportError> {
    if !(opts.formats.stl || opts.formats.threemf) {
        return Ok(Vec::new());
    }
    let named: Vec<(&str, &Mesh)> = kit
        .parts
        .iter()
        .zip(meshes)
        .map(|(p, m)| (p.name.as_str(), m))
        .collect();
    preview::part_pngs(&named)
}

/// The 3MF package metadata of `plate`.
fn plate_metadata(kit: &Kit, plate: &Plate, opts: &ExportOptions) -> [(&'static str, String); 3] {
    package_metadata(
        format!(
            "fabkit plate {} {} {} {}",
            kit.design, plate.technology, plate.material, plate.number
        ),
        opts,
        format!(
            "{} plate {} of design {} (sha256:{}) for the {} ({} x {} x {} mm, {} mm margin), parts in print orientation",
            plate.technology,
            plate.number,
            kit.design,
            opts.design_sha256,
            plate.bed.name,
            plate.bed.size_mm[0],
            plate.bed.size_mm[1],
            plate.bed.size_mm[2],
            plate.bed.margin_mm
        ),
    )
}

/// Each plate's picture (also its 3MF's thumbnail), its 3MF and the 3MF's objects, in
/// parallel.
fn plate_files<'m>(
    kit: &'m Kit,
    meshes: &'m [Mesh],
    plates: &[Plate],
    units: &[Vec<usize>],
    unit_meshes: &[Deflated],
    opts: &ExportOptions,
) -> Result<PlateFiles<'m>, ExportError> {
    use rayon::prelude::*;
    plates
        .par_iter()
        .map(|plate| {
            let names: Vec<String> = plate
                .items
                .iter()
                .map(|it| {
                    units[it.unit]
                        .iter()
                        .map(|&i| kit.parts[i].name.as_str())
                        .collect::<Vec<_>>()
                        .join("+")
                })
                .collect();
            let objects: Vec<preview::PlacedObject<'_>> = plate
                .items
                .iter()
                .zip(&names)
                .map(|(it, name)| preview::PlacedObject {
                    name,
                    meshes: units[it.unit].iter().map(|&i| &meshes[i]).collect(),
                    turned: it.turned,
                    translation_mm: it.translation_mm,
                })
                .collect();
            let bed = preview::BedOutline {
                size_xy_mm: [plate.bed.size_mm[0], plate.bed.size_mm[1]],
                margin_mm: plate.bed.margin_mm,
            };
            let png = || {
                preview::render_plate(&objects, Some(bed)).png(&format!(
                    "fabkit {} plate {} of design {} ({}) on the {} bed, seen from above-front",
                    plate.technology, plate.number, kit.design, plate.material, plate.bed.name
                ))
            };
            let objects: Vec<three_mf::Object<'_>> = plate
                .items
                .iter()
                .map(|it| {
                    let u = &units[it.unit];
                    unit_object(kit, meshes, u, it.translation_mm, it.turned)
                })
                .collect();
            // each item's mesh element as deflated for the kit 3MF
            let premade: Vec<&Deflated> = plate
                .items
                .iter()
                .map(|it| unit_meshes.get(it.unit))
                .collect::<Option<_>>()
                .unwrap_or_default();
            let (bytes, png) = three_mf::encode_drawn(
                &objects,
                &premade,
                &plate_metadata(kit, plate, opts),
                Some(png),
            )?;
            Ok((png.unwrap_or_default(), bytes, objects))
        })
        .collect()
}

/// The assembled sensor's meshes, made once for the section view, the STEP and the 3MF, the
/// section view's picture and the assembly 3MF, the last two in parallel.
fn assembly_section(kit: &Kit, opts: &ExportOptions) -> Result<AssemblyFiles, ExportError> {
    use rayon::prelude::*;
    let assembly_meshes: Vec<Mesh> = kit
        .assembly
        .par_iter()
        .map(|m| m.solid.mesh().rounded_to_f32())
        .collect();
    if kit.assembly.is_empty() {
        return Ok((assembly_meshes, None, None));
    }
    // its 3MF's error, if any, is reported where the 3MF is filed, after the meshes' checks
    let three_mf = || {
        opts.formats
            .threemf
            .then(|| assembly_3mf(kit, &assembly_meshes, opts))
    };
    let section_view = || {
        let members: Vec<_> = kit
            .assembly
            .iter()
            .zip(&assembly_meshes)
            .map(|(m, mesh)| (m.name.as_str(), m.kind, mesh))
            .collect();
        let (rgb, view) = section::render(&members);
        raster::png_rgb8(
            view.width_px,
            view.height_px,
            &rgb,
            &[(
                "Description",
                "fabkit section view: the assembled sensor cut by the plane y = 0, x right, z up",
            )],
        )
        .map(|bytes| (bytes, view))
    };
    let (three_mf, section) = rayon::join(three_mf, section_view);
    Ok((assembly_meshes, Some(section?), three_mf))
}

/// Files the kit 3MF and gives its manifest entry.
fn file_kit_3mf(
    kit: &Kit,
    objects: &[three_mf::Object<'_>],
    bytes: Vec<u8>,
    files: &mut Files,
) -> ManifestKit3mf {
    let rel = format!("{}.3mf", kit.design);
    let sha = sha256_hex(&bytes);
    files.push((rel.clone(), bytes));
    ManifestKit3mf {
        file: rel,
        sha256: sha,
        objects: objects
            .iter()
            .zip(1u32..)
            .map(|(o, id)| ManifestObject {
                id,
                name: o.name.clone(),
                group: o.group.map(str::to_owned),
                translation_mm: o.translation_mm,
                volumes: o
                    .volumes
                    .iter()
                    .zip(o.triangle_ranges())
                    .zip(1u32..)
                    .map(|((v, (first, last)), extruder)| ManifestVolume {
                        part: v.name.to_owned(),
                        first_triangle: first,
                        last_triangle: last,
                        extruder,
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Files each plate's 3MF and gives the plates' manifest entries with their pictures, which
/// the caller files after the parts' pictures.
fn file_plates(
    kit: &Kit,
    plates: &[Plate],
    plate_pngs: PlateFiles<'_>,
    units: &[Vec<usize>],
    parts: &[ManifestPart],
    files: &mut Files,
) -> (Vec<ManifestPlate>, Files) {
    let mut plate_picture_files = Vec::with_capacity(plates.len());
    let mut manifest_plates = Vec::with_capacity(plates.len());
    for (plate, (png, bytes, objects)) in plates.iter().zip(plate_pngs) {
        let tech = plate.technology.to_string().to_lowercase();
        let material: String = plate
            .material
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '+' || c == '-' {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect();
        // numbers padded to the set's count, so that the files list in plate order
        let count = plates
            .iter()
            .filter(|p| p.technology == plate.technology && p.material == plate.material)
            .count();
        let rel = format!(
            "{PLATES_DIR}/{}_{tech}_{material}_{:0w$}.3mf",
            kit.design,
            plate.number,
            w = count.to_string().len()
        );
        let sha = sha256_hex(&bytes);
        let picture = format!(
            "{PREVIEWS_DIR}/plate_{}.png",
            rel.trim_start_matches(&format!("{PLATES_DIR}/"))
                .trim_end_matches(".3mf")
        );
        let picture_sha = sha256_hex(&png);
        files.push((rel.clone(), bytes));
        plate_picture_files.push((picture.clone(), png));
        manifest_plates.push(ManifestPlate {
            file: rel,
            sha256: sha,
            preview: Some(picture),
            preview_sha256: Some(picture_sha),
            print_technology: plate.technology,
            material: plate.material.clone(),
            printer: plate.bed.name.clone(),
            bed_mm: plate.bed.size_mm,
            margin_mm: plate.bed.margin_mm,
            objects: plate
                .items
                .iter()
                .zip(&objects)
                .map(|(it, o)| plate_object(it, o, units, parts))
                .collect(),
        });
    }
    (manifest_plates, plate_picture_files)
}

/// The manifest entry of one object `o` of a plate, placed by `it`: its turn, translation and
/// footprint on the bed (its parts' boxes turned and moved).
fn plate_object(
    it: &layout::PlateItem,
    o: &three_mf::Object<'_>,
    units: &[Vec<usize>],
    parts: &[ManifestPart],
) -> ManifestPlateObject {
    let t = it.translation_mm;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &i in &units[it.unit] {
        let b = parts[i].bbox_mm;
        for (x, y) in [
            (b.min[0], b.min[1]),
            (b.max[0], b.min[1]),
            (b.min[0], b.max[1]),
            (b.max[0], b.max[1]),
        ] {
            let (x, y) = if it.turned { (-y, x) } else { (x, y) };
            lo = [lo[0].min(x + t[0]), lo[1].min(y + t[1])];
            hi = [hi[0].max(x + t[0]), hi[1].max(y + t[1])];
        }
    }
    ManifestPlateObject {
        name: o.name.clone(),
        turn_deg: if it.turned { 90.0 } else { 0.0 },
        translation_mm: t,
        footprint_mm: [lo[0], lo[1], hi[0], hi[1]],
    }
}

/// Each machined part's STL (checked) and drawing, filed in turn, with their manifest entries.
fn machined_files(
    kit: &Kit,
    opts: &ExportOptions,
    materials: Option<&MaterialsTable>,
    files: &mut Files,
) -> Result<Vec<ManifestMachinedPart>, ExportError> {
    let mut machined_parts = Vec::with_capacity(kit.machined_parts.len());
    for m in &kit.machined_parts {
        let mesh = m.solid.mesh().rounded_to_f32();
        check_printable_mesh(&m.name, &mesh)?;
        let bbox = bbox_of(&m.name, &mesh)?;
        let drawing = format!("{MACHINED_DIR}/{}.svg", m.name);
        let drawing_bytes = two_d::drawing_svg(&m.drawing).into_bytes();
        let (file, sha256) = stl_file(kit, opts, MACHINED_DIR, &m.name, &mesh, files)?;
        machined_parts.push(ManifestMachinedPart {
            name: m.name.clone(),
            description: m.description.clone(),
            material: m.material.clone(),
            material_name: product_name(materials, &m.material),
            finish: m.finish.clone(),
            volume_mm3: mesh.signed_volume(),
            mass_g: materials
                .and_then(|t| t.materials.get(&m.material))
                .map_or(0.0, |t| mesh.signed_volume() / 1000.0 * t.density_g_per_cm3),
            bbox_mm: bbox,
            drawing_sha256: sha256_hex(&drawing_bytes),
            drawing: drawing.clone(),
            dimensions: m.drawing.dimensions.clone(),
            params: m.params.clone(),
            exact: m.exact.clone(),
            file,
            sha256,
            step_file: None,
            step_sha256: None,
        });
        files.push((drawing, drawing_bytes));
    }
    Ok(machined_parts)
}

/// The STEP files through the CadQuery twin: each part's, each machined part's and the
/// assembly's, filed in that order and entered in their manifest entries; the assembly's
/// manifest entry.
fn step_outputs(
    kit: &Kit,
    parts: &mut [ManifestPart],
    machined_parts: &mut [ManifestMachinedPart],
    assembly_meshes: &[Mesh],
    opts: &ExportOptions,
    step_progress: Option<step::StepProgress<'_>>,
    files: &mut Files,
) -> Result<Option<ManifestAssemblyStep>, ExportError> {
    let (steps, assembly) = step_files(kit, parts, assembly_meshes, opts, step_progress)?;
    for (p, bytes) in parts.iter_mut().zip(steps.parts) {
        let rel = format!("{STEP_DIR}/{}.step", p.name);
        p.step_sha256 = Some(sha256_hex(&bytes));
        p.step_file = Some(rel.clone());
        files.push((rel, bytes));
    }
    for (p, bytes) in machined_parts.iter_mut().zip(steps.machined) {
        let rel = format!("{STEP_DIR}/{}.step", p.name);
        p.step_sha256 = Some(sha256_hex(&bytes));
        p.step_file = Some(rel.clone());
        files.push((rel, bytes));
    }
    Ok(match (assembly, steps.assembly) {
        (Some(mut a), Some(bytes)) => {
            a.sha256 = sha256_hex(&bytes);
            files.push((a.file.clone(), bytes));
            Some(a)
        }
        _ => None,
    })
}

/// Each cut part's DXF and SVG (and, for a polygonal sheet, the nominal part extruded by its
/// thickness as STL), filed in turn, with their manifest entries.
fn cut_part_files(
    kit: &Kit,
    opts: &ExportOptions,
    materials: Option<&MaterialsTable>,
    files: &mut Files,
) -> Result<Vec<ManifestCutPart>, ExportError> {
    let mut cut_parts = Vec::with_capacity(kit.cut_parts.len());
    for c in &kit.cut_parts {
        let (dxf, svg) = (
            format!("{CUT_DIR}/{}.dxf", c.name),
            format!("{CUT_DIR}/{}.svg", c.name),
        );
        let dxf_bytes = two_d::dxf_bytes(c)?;
        let svg_bytes = two_d::svg_text(c).into_bytes();
        let material_name = product_name(materials, &c.material);
        let preview = format!("{CUT_DIR}/preview/{}.svg", c.name);
        let preview_bytes = two_d::svg_preview_text(c, &material_name).into_bytes();
        // a polygonal sheet also as a solid: the nominal part extruded by its thickness
        let (stl, stl_sha256) =
            match &c.nominal_rings_mm {
                Some(rings) => {
                    let solid = fabkit_designs::geometry::extrude(rings, 0.0, c.thickness_mm)
                        .map_err(|e| ExportError::Encode {
                            what: format!("{CUT_DIR}/{}.stl", c.name),
                            reason: e.to_string(),
                        })?;
                    // as every exported solid: rounded to f32 once, then checked as written
                    let mesh = solid.mesh().rounded_to_f32();
                    check_printable_mesh(&c.name, &mesh)?;
                    stl_file(kit, opts, CUT_DIR, &c.name, &mesh, files)?
                }
                None => (None, None),
            };
        cut_parts.push(ManifestCutPart {
            name: c.name.clone(),
            description: c.description.clone(),
            material: c.material.clone(),
            material_name,
            thickness_mm: c.thickness_mm,
            quantity: c.quantity,
            kerf_mm: c.kerf_mm,
            area_mm2: c.area_mm2(),
            nominal_area_mm2: c.nominal_area_mm2(),
            dxf_sha256: sha256_hex(&dxf_bytes),
            svg_sha256: sha256_hex(&svg_bytes),
            dxf: dxf.clone(),
            svg: svg.clone(),
            preview_svg_sha256: sha256_hex(&preview_bytes),
            preview_svg: preview.clone(),
            stl,
            stl_sha256,
        });
        files.push((dxf, dxf_bytes));
        files.push((svg, svg_bytes));
        files.push((preview, preview_bytes));
    }
    Ok(cut_parts)
}

/// Each board's outline as DXF, filed in turn, with their manifest entries.
fn pcb_files(kit: &Kit, files: &mut Files) -> Result<Vec<ManifestPcbOutline>, ExportError> {
    let mut pcb_outlines = Vec::with_capacity(kit.pcb_outlines.len());
    for c in &kit.pcb_outlines {
        let dxf = format!("{PCB_DIR}/{}.dxf", c.name);
        let dxf_bytes = two_d::dxf_bytes(c)?;
        pcb_outlines.push(ManifestPcbOutline {
            name: c.name.clone(),
            description: c.description.clone(),
            thickness_mm: c.thickness_mm,
            area_mm2: c.area_mm2(),
            dxf_sha256: sha256_hex(&dxf_bytes),
            dxf: dxf.clone(),
        });
        files.push((dxf, dxf_bytes));
    }
    Ok(pcb_outlines)
}

/// Files the data files (none may collide with another file of the export), then the
/// manifest, FABRICATION.md and FABRICATION.html.
fn file_manifest_and_sheet(
    kit: &Kit,
    manifest: &Manifest,
    data_files: &[(String, Vec<u8>)],
    files: &mut Files,
) -> Result<(), ExportError> {
    for (rel, bytes) in data_files {
        if files.iter().any(|(f, _)| f == rel) || rel == "manifest.json" || rel == "FABRICATION.md"
        {
            return Err(ExportError::InvalidOption {
                field: "data_files",
                value: rel.clone(),
                rule: "collides with another file of the export",
            });
        }
        files.push((rel.clone(), bytes.clone()));
    }
    let mut json = serde_json::to_vec_pretty(manifest)?;
    json.push(b'\n');
    files.push(("manifest.json".to_owned(), json));
    let sheet_md = sheet::render(manifest);
    let sheet_html = html::render(
        &sheet_md,
        &format!("fabkit {}: fabrication", kit.design),
        files,
    );
    files.push(("FABRICATION.md".to_owned(), sheet_md.into_bytes()));
    files.push(("FABRICATION.html".to_owned(), sheet_html.into_bytes()));
    Ok(())
}
