//! fabkit-export: writes a built [`Kit`] to disk.
//!
//! [`write_kit`] produces, in one output directory:
//! - `parts/<part>.stl`: binary STL per part, mm, provenance in the 80-byte header, in the
//!   part's coordinates as given (never moved: grouped parts share coordinates);
//! - `<design>.3mf`: `unit="millimeter"`, laid out on one plate: one named object per
//!   ungrouped part, and one object per multi-material group
//!   ([`fabkit_designs::kit::Part::group`]) holding its parts as named volumes in their shared
//!   coordinates, so a slicer loads the group as one object (one material per volume) and the
//!   parts stay registered (see the `three_mf` module);
//! - with STEP, `step/<part>.step` per part (print orientation) and `assembly.step`, the
//!   assembled sensor as exact B-reps in the sensor frame, one named solid per member (see the
//!   `step` module);
//! - with STL or 3MF, `previews/<part>.png`, a shaded picture of each part from two sides, and
//!   with 3MF `previews/plate_<plate>.png`, each plate as placed on its bed (also the plate
//!   3MF's thumbnail; the kit 3MF's thumbnail shows its layout); see the `preview` module;
//! - `manifest.json`: provenance and the numbers of every written solid ([`Manifest`]);
//! - `FABRICATION.md`: the human fabrication sheet (print list, cast order, bought items).
//!
//! The export is all or nothing (a temporary sibling directory renamed into place) and
//! reproducible (the same kit and options give byte-identical files: no timestamps, no hash-map
//! order). Every written solid is checked to be a closed, consistently oriented 2-manifold.

mod atomic;
mod check;
mod error;
pub mod hold;
mod html;
mod layout;
mod manifest;
pub mod mass;
pub mod mjcf;
pub mod preview;
pub mod raster;
mod render;
pub mod section;
mod sheet;
pub mod sim;
pub mod urdf;
pub mod usd;
pub use sheet::{marker_feature_words, marker_formers};
pub mod step;
mod stl;
mod three_mf;
pub mod two_d;
mod zip_package;

pub use atomic::{check_out_dir, free_bytes, OutputClaim, OutputCommand, StagedDir, OUTPUT_MARKER};
pub use check::check_printable_mesh;
pub use error::ExportError;
pub use manifest::{
    Manifest, ManifestAssembly, ManifestAssemblyStep, ManifestCutPart, ManifestDataFile,
    ManifestDesign, ManifestKit3mf, ManifestMachinedPart, ManifestMember, ManifestObject,
    ManifestPart, ManifestPcbOutline, ManifestPlate, ManifestPlateObject, ManifestSim,
    ManifestStepMember, ManifestVolume, StepGeometry, FRAME,
};

use fabkit_designs::assembly::{ExactShape, MemberKind};
use fabkit_designs::geometry::{Aabb, Mesh, TopologyError};
use fabkit_designs::kit::Kit;
use std::path::{Path, PathBuf};

/// Which mesh formats to write. `manifest.json` and `FABRICATION.md` are always written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Formats {
    /// `parts/<part>.stl`, one binary STL per part.
    pub stl: bool,
    /// `<design>.3mf`, one 3MF for the whole kit.
    pub threemf: bool,
    /// `step/<part>.step`, exact B-rep per part through the CadQuery twin, and for a sensor
    /// `assembly.step`, the assembly's members in the sensor frame (see [`step`]).
    pub step: bool,
    /// `sim/<design>.xml` and `sim/meshes/*.stl`: the assembled sensor for MuJoCo
    /// ([`mjcf`]).
    pub mjcf: bool,
    /// `sim/<design>.urdf` and `sim/meshes/*.stl`: the assembled sensor as a URDF (PyBullet,
    /// ROS; [`urdf`]).
    pub urdf: bool,
    /// `sim/<design>.usda` and `sim/meshes/*.stl`: the assembled sensor as a USD layer (Isaac
    /// Sim, Isaac Lab; [`usd`]).
    pub usd: bool,
}

impl Default for Formats {
    /// Both formats.
    fn default() -> Self {
        Self {
            stl: true,
            threemf: true,
            step: false,
            mjcf: false,
            urdf: false,
            usd: false,
        }
    }
}

/// Everything [`write_kit`] needs besides the kit: formats and provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    pub formats: Formats,
    /// The command line that produced the export, one argument per entry (recorded verbatim).
    pub command_line: Vec<String>,
    /// Path of the YAML design, or `embedded:<name>` for a built-in design.
    pub design_source: String,
    /// sha256 of the design text, 64 lowercase hex digits.
    pub design_sha256: String,
    /// Chord tolerance the kit was built with, mm (> 0); recorded, not applied.
    pub chord_tolerance_mm: f64,
    /// fabkit version, e.g. `0.1.0`; goes into every file.
    pub fabkit_version: String,
    /// The printers whose beds the plates are laid out in (the design's `printers`, with any
    /// `--printer` applied); a technology without a bed gets its shipped printer.
    pub printers: fabkit_designs::schema::PrinterProfiles,
    /// The command whose output this is, recorded in the folder's marker: an earlier output
    /// of another command is never replaced.
    pub command: OutputCommand,
    /// Replace an earlier output of the same command for another kit or chord tolerance
    /// (`--force`).
    pub force: bool,
    /// The camera and lights of the simulator files ([`Formats::mjcf`]).
    pub sim: sim::SimScene,
}

impl ExportOptions {
    /// The options of an export of the design read from `design_source` (its path, or
    /// `embedded:<name>`) whose text hashes to `design_sha256`, built at `chord_tolerance_mm`,
    /// by `command_line`, onto the beds of `printers`; this fabkit's version; the output of
    /// `fabkit export`, not forced.
    pub fn for_design(
        formats: Formats,
        command_line: Vec<String>,
        design_source: &str,
        design_sha256: &str,
        chord_tolerance_mm: f64,
        printers: fabkit_designs::schema::PrinterProfiles,
    ) -> ExportOptions {
        ExportOptions {
            formats,
            command_line,
            design_source: design_source.to_string(),
            design_sha256: design_sha256.to_string(),
            chord_tolerance_mm,
            fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
            printers,
            command: OutputCommand::Export,
            force: false,
            sim: sim::SimScene::default(),
        }
    }

    /// The claim on the output folder of `kit_name` (the kit's `design`) written with these
    /// options: this command, the kit and chord tolerance as the job, and `force`. What
    /// [`write_kit`] checks; a command checks it with [`check_out_dir`] before building.
    pub fn claim(&self, kit_name: &str) -> OutputClaim {
        OutputClaim::kit(self.command, kit_name, self.chord_tolerance_mm, self.force)
    }
}

/// What [`write_kit`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSummary {
    /// The output directory, as given.
    pub out_dir: PathBuf,
    /// Every file written, as `out_dir` joined with its relative path, in order:
    /// `parts/*.stl` (kit order), `<design>.3mf`, `plates/*.3mf`, `previews/*.png` (parts in
    /// kit order, then plates), `step/*.step` (kit order), `assembly.step`,
    /// `section.png`, `cut/*`, `assembly.3mf`, data files, `manifest.json`, `FABRICATION.md`
    /// (each when written).
    pub files: Vec<PathBuf>,
    /// `out_dir` held a previous export (or was an empty directory) and was replaced.
    pub replaced_previous_export: bool,
    /// Non-fatal problems, e.g. a previous export that was moved aside but not deleted.
    pub warnings: Vec<String>,
    /// The manifest as written to `manifest.json`.
    pub manifest: Manifest,
}

/// Writes `kit` into `out_dir`: STL per part and/or one 3MF (per `opts.formats`), plus
/// `manifest.json` and `FABRICATION.md`. Parts must already be in print orientation, in mm.
///
/// Each part is meshed and rounded to f32 ([`Mesh::rounded_to_f32`]) once; that mesh is what
/// every file holds and what every number in the manifest is computed from.
///
/// `out_dir` may be missing (parent directories are created), an empty directory, or a
/// previous output that [`ExportOptions::claim`] may replace (see [`check_out_dir`]: the
/// same command, every file as fabkit wrote it, and unless `opts.force` the same kit and
/// tolerance), which is replaced as a whole. Nothing is written under `out_dir` until every
/// file is complete and synced in a temporary sibling directory.
///
/// # Errors
/// - names, options and meshes are checked before anything touches the disk:
///   [`ExportError::InvalidDesignName`], [`ExportError::NoParts`],
///   [`ExportError::InvalidPartName`], [`ExportError::DuplicatePartName`],
///   [`ExportError::InvalidGroupName`],
///   [`ExportError::InvalidOption`], [`ExportError::NotManifold`],
///   [`ExportError::CoincidentVertices`], [`ExportError::TooManyTriangles`];
/// - output path: [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
///   [`ExportError::ForeignDirectory`] (a non-empty directory fabkit did not write, or one
///   changed since), [`ExportError::OtherCommand`], [`ExportError::OtherJob`];
/// - [`ExportError::Io`], [`ExportError::ThreeMf`], [`ExportError::Json`].
///
/// On every error `out_dir` is left exactly as it was and no temporary directory remains.
pub fn write_kit(
    kit: &Kit,
    out_dir: &Path,
    opts: &ExportOptions,
) -> Result<ExportSummary, ExportError> {
    write_kit_with_files(kit, &[], out_dir, opts)
}

/// [`write_kit`] plus data files (relative `/`-separated path, bytes) written beside the meshes
/// and listed with their sha256 in the manifest's `data_files` (point tables, geometry
/// descriptions). Same atomicity and errors as [`write_kit`]; a data file path must be
/// relative, made of `[A-Za-z0-9_.-]` components, and must not collide with another file.
pub fn write_kit_with_files(
    kit: &Kit,
    data_files: &[(String, Vec<u8>)],
    out_dir: &Path,
    opts: &ExportOptions,
) -> Result<ExportSummary, ExportError> {
    write_kit_reporting(kit, data_files, out_dir, opts, None)
}

/// [`write_kit_with_files`] that reports the progress of STEP export (about 3 s a part, when
/// `opts.formats.step`) to `step_progress`: called on this thread as the CadQuery twin starts
/// each part, with (part number from 1, number of parts, part name), in kit order. Same files,
/// atomicity and errors as [`write_kit_with_files`].
pub fn write_kit_reporting(
    kit: &Kit,
    data_files: &[(String, Vec<u8>)],
    out_dir: &Path,
    opts: &ExportOptions,
    step_progress: Option<step::StepProgress<'_>>,
) -> Result<ExportSummary, ExportError> {
    for (rel, _) in data_files {
        atomic::check_relative_path("data_files", rel)?;
    }
    let t = fabkit_designs::timings::stage("written meshes");
    let meshes: Vec<Mesh> = {
        use rayon::prelude::*;
        kit.parts.par_iter().map(|p| p.written_mesh()).collect()
    };
    drop(t);
    write_kit_meshes(kit, &meshes, data_files, out_dir, opts, step_progress)
}

/// [`write_kit`] with the written meshes given (one per part, in kit order), so that tests can
/// hand in meshes no [`fabkit_designs::geometry::Solid`] can hold.
fn write_kit_meshes(
    kit: &Kit,
    meshes: &[Mesh],
    data_files: &[(String, Vec<u8>)],
    out_dir: &Path,
    opts: &ExportOptions,
    step_progress: Option<step::StepProgress<'_>>,
) -> Result<ExportSummary, ExportError> {
    check::check_options(opts)?;
    check::check_names(kit)?;
    let t = fabkit_designs::timings::stage("printable-mesh checks");
    let names: Vec<&str> = kit.parts.iter().map(|p| p.name.as_str()).collect();
    check_printable_meshes(&names, meshes)?;
    drop(t);
    let rendered = render::render(kit, meshes, data_files, opts, step_progress)?;
    let claim = opts.claim(&kit.design);
    let t = fabkit_designs::timings::stage("file hashes");
    let hashes: Vec<String> = {
        use rayon::prelude::*;
        rendered
            .files
            .par_iter()
            .map(|(_, b)| sha256_hex(b))
            .collect()
    };
    drop(t);
    let t = fabkit_designs::timings::stage("write, fsync and rename the folder");
    let done = atomic::replace_dir(out_dir, &claim, |tmp, written| {
        if opts.formats.stl {
            let parts_dir = tmp.join(PARTS_DIR);
            std::fs::create_dir(&parts_dir).map_err(ExportError::io("creating", &parts_dir))?;
        }
        // the folders first, then the files written and synced in parallel (their syncs
        // overlap); the first error in file order
        let paths: Vec<PathBuf> = rendered
            .files
            .iter()
            .map(|(rel, _)| join_rel(tmp, rel))
            .collect();
        for path in &paths {
            if let Some(parent) = path.parent() {
                if parent != tmp && !parent.exists() {
                    std::fs::create_dir_all(parent).map_err(ExportError::io("creating", parent))?;
                }
            }
        }
        let synced: Vec<Result<(), ExportError>> = {
            use rayon::prelude::*;
            paths
                .par_iter()
                .zip(&rendered.files)
                .map(|(path, (_, bytes))| atomic::write_file_synced(path, bytes))
                .collect()
        };
        for (((rel, _), sha256), r) in rendered.files.iter().zip(hashes).zip(synced) {
            r?;
            written.insert(rel, sha256);
        }
        // every file in the temporary sibling, none under the final name yet
        hold::hold_point("export-written");
        if opts.formats.stl {
            atomic::sync_dir(&tmp.join(PARTS_DIR))?;
        }
        Ok(())
    })?;
    drop(t);
    Ok(ExportSummary {
        out_dir: out_dir.to_path_buf(),
        files: rendered
            .files
            .iter()
            .map(|(rel, _)| join_rel(out_dir, rel))
            .collect(),
        replaced_previous_export: done.replaced_previous,
        warnings: done.warnings,
        manifest: rendered.manifest,
    })
}

/// The STEP files of the parts and, for a sensor, of the assembly (`assembly.step`), from the
/// CadQuery twin in one run (see [`step::render`]): `meshes` are the assembly members' written
/// meshes (checked closed 2-manifolds, in `kit.assembly` order). Returns the files and the
/// assembly's manifest entry, its `sha256` still empty.
fn step_files(
    kit: &Kit,
    parts: &[ManifestPart],
    meshes: &[Mesh],
    opts: &ExportOptions,
    step_progress: Option<step::StepProgress<'_>>,
) -> Result<(step::StepFiles, Option<ManifestAssemblyStep>), ExportError> {
    let machined_meshes: Vec<Mesh> = kit
        .machined_parts
        .iter()
        .map(|m| m.solid.mesh().rounded_to_f32())
        .collect();
    let mut machined = Vec::with_capacity(machined_meshes.len());
    for (m, mesh) in kit.machined_parts.iter().zip(&machined_meshes) {
        machined.push(step::StepMember {
            name: &m.name,
            kind: MemberKind::Bought,
            volume_mm3: mesh.signed_volume(),
            surface_area_mm2: mesh.surface_area(),
            bbox_mm: bbox_of(&m.name, mesh)?,
            shells: mesh.shell_count(),
            source: step::StepSource::Exact(&m.exact),
        });
    }
    if kit.assembly.is_empty() {
        let files = step::render(
            parts,
            &machined,
            None,
            opts.chord_tolerance_mm,
            step_progress,
        )?;
        return Ok((files, None));
    }
    let mut members = Vec::with_capacity(meshes.len());
    let mut entries = Vec::with_capacity(meshes.len());
    for (m, mesh) in kit.assembly.iter().zip(meshes) {
        let printed = kit
            .parts
            .iter()
            .find(|p| m.kind == MemberKind::Printed && p.name == m.name);
        let (source, geometry) = match (printed, &m.exact) {
            (Some(p), _) => (step::StepSource::Part(&p.name), StepGeometry::ExactPart),
            (None, Some(e)) => (
                step::StepSource::Exact(e),
                match e {
                    ExactShape::Layer { .. } => StepGeometry::ExactLayer,
                    ExactShape::CoreShell { .. } => StepGeometry::ExactCoreShell,
                    ExactShape::InnerCavity { .. } => StepGeometry::ExactInnerCavity,
                    ExactShape::Revolved { .. } => StepGeometry::RevolvedProfile,
                    ExactShape::Cylinder { .. }
                    | ExactShape::Ring { .. }
                    | ExactShape::Box { .. } => StepGeometry::ExactEnvelope,
                },
            ),
            (None, None) => (step::StepSource::Mesh(mesh), StepGeometry::SewnMesh),
        };
        let bbox_mm = bbox_of(&m.name, mesh)?;
        let (volume_mm3, surface_area_mm2) = (mesh.signed_volume(), mesh.surface_area());
        let shells = mesh.shell_count();
        members.push(step::StepMember {
            name: &m.name,
            kind: m.kind,
            volume_mm3,
            surface_area_mm2,
            bbox_mm,
            shells,
            source,
        });
        entries.push(ManifestStepMember {
            name: m.name.clone(),
            kind: m.kind,
            geometry,
            volume_mm3,
            surface_area_mm2,
            bbox_mm,
            shells,
        });
    }
    let assembly = step::StepAssembly {
        name: &kit.design,
        members,
    };
    let files = step::render(
        parts,
        &machined,
        Some(&assembly),
        opts.chord_tolerance_mm,
        step_progress,
    )?;
    Ok((
        files,
        Some(ManifestAssemblyStep {
            file: ASSEMBLY_STEP.into(),
            sha256: String::new(),
            members: entries,
        }),
    ))
}

/// The manifest's entry of each assembly member (`meshes`: their written meshes, in kit
/// order), with its mass where its material is known, and the sensor's mass.
///
/// # Errors
/// [`ExportError::NotManifold`] for a mesh without vertices.
fn assembly_members(
    kit: &Kit,
    meshes: &[Mesh],
) -> Result<(Vec<ManifestMember>, mass::SensorMass), ExportError> {
    let materials = fabkit_designs::materials::MaterialsTable::embedded().ok();
    let mut members = Vec::with_capacity(meshes.len());
    for (m, mesh) in kit.assembly.iter().zip(meshes) {
        let density = m
            .material
            .as_deref()
            .and_then(|k| mass::density(materials.as_ref(), k));
        members.push(ManifestMember {
            name: m.name.clone(),
            kind: m.kind,
            description: m.description.clone(),
            volume_mm3: mesh.signed_volume(),
            bbox_mm: bbox_of(&m.name, mesh)?,
            material: m.material.clone(),
            mass: density.map(|d| mass::member_mass(mesh, d)),
        });
    }
    let sensor_mass = mass::sensor_mass(members.iter().map(|m| (m.name.as_str(), m.mass.as_ref())));
    Ok((members, sensor_mass))
}

/// Files as (path relative to the output folder, bytes).
type FileList = Vec<(String, Vec<u8>)>;

/// `sim/`: the simulator models, their meshes and the camera file ([`sim::files`]), and
/// their manifest entry.
///
/// # Errors
/// As [`assembly_members`] and the STL writer's.
pub(crate) fn sim_files(
    kit: &Kit,
    meshes: &[Mesh],
    opts: &ExportOptions,
) -> Result<(ManifestSim, FileList), ExportError> {
    let (members, sensor_mass) = assembly_members(kit, meshes)?;
    let files = sim::files(&kit.design, opts, &members, meshes, &sensor_mass)?;
    let entries: Vec<ManifestDataFile> = files
        .iter()
        .map(|(f, b)| ManifestDataFile {
            file: f.clone(),
            sha256: sha256_hex(b),
        })
        .collect();
    let pick = |ext: &str| entries.iter().find(|e| e.file.ends_with(ext)).cloned();
    Ok((
        ManifestSim {
            mjcf: pick(".xml"),
            urdf: pick(".urdf"),
            usd: pick(".usda"),
            camera_file: pick("/camera.yaml"),
            meshes: entries
                .iter()
                .filter(|e| e.file.ends_with(".stl"))
                .cloned()
                .collect(),
            camera: opts.sim.camera.as_ref().map(|c| c.what.clone()),
            notes: opts.sim.notes.clone(),
        },
        files,
    ))
}

/// `assembly.3mf`: the kit's assembled sensor, one object per member (`meshes`, checked closed
/// 2-manifolds, in kit order), in the sensor frame.
fn assembly_3mf(
    kit: &Kit,
    meshes: &[Mesh],
    opts: &ExportOptions,
) -> Result<(ManifestAssembly, Vec<u8>), ExportError> {
    let (members, sensor_mass) = assembly_members(kit, meshes)?;
    let objects: Vec<three_mf::Object<'_>> = kit
        .assembly
        .iter()
        .zip(meshes)
        .map(|(m, mesh)| three_mf::Object {
            name: m.name.clone(),
            group: None,
            volumes: vec![three_mf::Volume {
                name: &m.name,
                mesh,
            }],
            translation_mm: [0.0; 3],
            turned: false,
            metadata: vec![
                (
                    "role",
                    format!("assembly member ({:?})", m.kind).to_lowercase(),
                ),
                ("description", m.description.clone()),
            ],
        })
        .collect();
    let metadata = package_metadata(
        format!("fabkit assembly {}", kit.design),
        opts,
        format!(
            "the assembled sensor in the sensor frame (docs/conventions.md); bought parts are envelopes; design {} sha256:{}",
            kit.design, opts.design_sha256
        ),
    );
    let bytes = three_mf::encode(&objects, &metadata)?;
    Ok((
        ManifestAssembly {
            file: ASSEMBLY_3MF.into(),
            sha256: sha256_hex(&bytes),
            members,
            mass: sensor_mass,
        },
        bytes,
    ))
}

/// A 3MF package's metadata: its title, fabkit's version as the application, its description.
fn package_metadata(
    title: String,
    opts: &ExportOptions,
    description: String,
) -> [(&'static str, String); 3] {
    [
        ("Title", title),
        ("Application", format!("fabkit {}", opts.fabkit_version)),
        ("Description", description),
    ]
}

/// The product name of a material key (the key itself when the table lacks it).
fn product_name(
    materials: Option<&fabkit_designs::materials::MaterialsTable>,
    key: &str,
) -> String {
    materials
        .and_then(|t| t.materials.get(key))
        .map_or_else(|| key.to_owned(), |m| m.name.clone())
}

/// The folder of the print plates.
pub const PLATES_DIR: &str = "plates";

/// The folder of the pictures of the parts and plates ([`preview`]).
pub const PREVIEWS_DIR: &str = "previews";

/// The section view's file name ([`section`]).
pub const SECTION_PNG: &str = "section.png";

/// The assembly model's file name.
pub const ASSEMBLY_3MF: &str = "assembly.3mf";

/// The assembly's STEP file name, beside [`ASSEMBLY_3MF`] (the top level holds the whole-kit
/// and whole-sensor files; `step/` holds the parts in print orientation).
pub const ASSEMBLY_STEP: &str = "assembly.step";

const PARTS_DIR: &str = "parts";
/// Folder of the laser-cut parts' DXF and SVG files.
const CUT_DIR: &str = "cut";
/// Folder of the PCB outlines' DXF files.
const PCB_DIR: &str = "pcb";
/// Folder of the parts made to order by a machine shop (drawings, meshes).
const MACHINED_DIR: &str = "machined";
const STEP_DIR: &str = "step";

/// Every file of the export, in memory, with `/`-separated relative paths.
struct Rendered {
    files: Vec<(String, Vec<u8>)>,
    manifest: Manifest,
}

/// The bounding box of `mesh`, the mesh of part or member `name`, mm.
///
/// # Errors
/// [`ExportError::NotManifold`] for a mesh without vertices.
fn bbox_of(name: &str, mesh: &Mesh) -> Result<Aabb, ExportError> {
    mesh.bounding_box().ok_or_else(|| ExportError::NotManifold {
        part: name.to_string(),
        source: TopologyError::Empty,
    })
}

/// The manifest's numbers of `part` whose written mesh ([`fabkit_designs::Part::written_mesh`])
/// is `mesh`: volume (mm³), mass (g, from the density in `materials`; 0 when absent), surface
/// area (mm²), bounding box (mm, print orientation), vertex and triangle counts, genus, and the
/// part's role, material and parameters. `file` and `sha256` are `None`: what a written
/// file adds.
///
/// # Errors
/// [`ExportError::NotManifold`] for a mesh without triangles.
pub fn part_entry(
    part: &fabkit_designs::kit::Part,
    mesh: &Mesh,
    materials: Option<&fabkit_designs::materials::MaterialsTable>,
) -> Result<ManifestPart, ExportError> {
    let bbox = bbox_of(&part.name, mesh)?;
    Ok(ManifestPart {
        name: part.name.clone(),
        file: None,
        role: part.role.clone(),
        description: part.description.clone(),
        material: part.material.clone(),
        material_name: product_name(materials, &part.material),
        mass_g: materials
            .and_then(|t| t.materials.get(&part.material))
            .map_or(0.0, |m| mesh.signed_volume() / 1000.0 * m.density_g_per_cm3),
        print_technology: part.print_technology,
        group: part.group.clone(),
        volume_mm3: mesh.signed_volume(),
        surface_area_mm2: mesh.surface_area(),
        bbox_mm: bbox,
        vertices: mesh.vertices.len(),
        triangles: mesh.triangles.len(),
        genus: mesh.genus(),
        sha256: None,
        step_file: None,
        step_sha256: None,
        preview: None,
        preview_sha256: None,
        params: part.params.clone(),
    })
}

/// With STL on, `<dir>/<name>.stl` of `mesh` (provenance in its header) pushed onto `files`,
/// and its relative path and sha256; `(None, None)` otherwise.
/// [`check_printable_mesh`] of each `(name, mesh)` pair, in parallel; the first failure in
/// their order.
///
/// # Errors
/// As [`check_printable_mesh`].
fn check_printable_meshes(names: &[&str], meshes: &[Mesh]) -> Result<(), ExportError> {
    use rayon::prelude::*;
    let checked: Vec<Result<(), ExportError>> = names
        .par_iter()
        .zip(meshes)
        .map(|(name, mesh)| check_printable_mesh(name, mesh))
        .collect();
    checked.into_iter().collect()
}

fn stl_file(
    kit: &Kit,
    opts: &ExportOptions,
    dir: &str,
    name: &str,
    mesh: &Mesh,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<(Option<String>, Option<String>), ExportError> {
    if !opts.formats.stl {
        return Ok((None, None));
    }
    let header = stl::header(&opts.fabkit_version, &kit.design, name, &opts.design_sha256);
    let bytes = stl::encode(name, mesh, &header)?;
    let rel = format!("{dir}/{name}.stl");
    let sha = sha256_hex(&bytes);
    files.push((rel.clone(), bytes));
    Ok((Some(rel), Some(sha)))
}

/// The objects of a 3MF as the preview draws them: their volumes' meshes under their build
/// items' turn and translation.
fn placed_objects<'a>(objects: &'a [three_mf::Object<'a>]) -> Vec<preview::PlacedObject<'a>> {
    objects
        .iter()
        .map(|o| preview::PlacedObject {
            name: &o.name,
            meshes: o.volumes.iter().map(|v| v.mesh).collect(),
            turned: o.turned,
            translation_mm: o.translation_mm,
        })
        .collect()
}

fn join_rel(base: &Path, rel: &str) -> PathBuf {
    rel.split('/').fold(base.to_path_buf(), |p, c| p.join(c))
}

use atomic::sha256_hex;

#[cfg(test)]
mod tests {
    use super::*;
    use fabkit_designs::geometry::cuboid;
    use fabkit_designs::kit::{Part, PrintTechnology};

    fn kit() -> Kit {
        let part = |name: &str, x: f64| Part {
            name: name.into(),
            role: "test".into(),
            description: "a box".into(),
            material: "pla_black".into(),
            print_technology: PrintTechnology::Fdm,
            solid: cuboid([x, 0.0, 0.0], [x + 10.0, 10.0, 5.0]).unwrap(),
            params: serde_json::json!({}),
            group: None,
        };
        Kit {
            design: "tiny".into(),
            parts: vec![part("a", 0.0), part("lid", 20.0)],
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

    fn opts() -> ExportOptions {
        ExportOptions {
            formats: Formats::default(),
            command_line: vec!["fabkit".into()],
            design_source: "embedded:tiny".into(),
            design_sha256: "0".repeat(64),
            chord_tolerance_mm: 0.01,
            fabkit_version: "0.1.0".into(),
            printers: Default::default(),
            command: OutputCommand::Export,
            force: false,
            sim: sim::SimScene::default(),
        }
    }

    #[test]
    fn open_mesh_refuses_export_and_leaves_nothing() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("nested").join("kit");
        let k = kit();
        let mut meshes: Vec<Mesh> = k
            .parts
            .iter()
            .map(|p| p.solid.mesh().rounded_to_f32())
            .collect();
        meshes[1].triangles.pop();
        let err = write_kit_meshes(&k, &meshes, &[], &out, &opts(), None).unwrap_err();
        assert!(
            matches!(err, ExportError::NotManifold { ref part, .. } if part == "lid"),
            "{err}"
        );
        assert!(err.to_string().contains("`lid`"));
        assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 0);
    }

    #[test]
    fn open_mesh_keeps_a_previous_export() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        let k = kit();
        let first = write_kit(&k, &out, &opts()).unwrap();
        let before: Vec<Vec<u8>> = first
            .files
            .iter()
            .map(|f| std::fs::read(f).unwrap())
            .collect();
        let mut meshes: Vec<Mesh> = k
            .parts
            .iter()
            .map(|p| p.solid.mesh().rounded_to_f32())
            .collect();
        meshes[0].triangles[0].swap(1, 2);
        assert!(write_kit_meshes(&k, &meshes, &[], &out, &opts(), None).is_err());
        let after: Vec<Vec<u8>> = first
            .files
            .iter()
            .map(|f| std::fs::read(f).unwrap())
            .collect();
        assert_eq!(before, after);
        assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 1);
    }

    #[test]
    fn bad_names_and_options_are_refused() {
        let mut k = kit();
        k.parts[1].name = "a".into();
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        assert!(matches!(
            write_kit(&k, &out, &opts()),
            Err(ExportError::DuplicatePartName { .. })
        ));
        k.parts[1].name = "../up".into();
        assert!(matches!(
            write_kit(&k, &out, &opts()),
            Err(ExportError::InvalidPartName { .. })
        ));
        k.parts[1].name = "lid".into();
        k.parts[1].group = Some(" ".into());
        let err = write_kit(&k, &out, &opts()).unwrap_err();
        assert!(
            matches!(err, ExportError::InvalidGroupName { ref part, .. } if part == "lid"),
            "{err}"
        );
        assert_eq!(
            err.to_string(),
            "part `lid`: group \" \": must be non-empty and one line without surrounding spaces \
             (or no group)"
        );
        let mut o = opts();
        o.design_sha256 = "abc".into();
        assert!(matches!(
            write_kit(&kit(), &out, &o),
            Err(ExportError::InvalidOption {
                field: "design_sha256",
                ..
            })
        ));
        assert!(!out.exists());
    }
}
