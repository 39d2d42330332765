//! `manifest.json`: what was exported, from what, and the numbers of every written solid.
//!
//! Keys are written in the field order of these structs (serde derives keep it), so the text
//! is stable. Every number about a part is computed from the f32-rounded mesh that is written,
//! so an independent reader of the STL or 3MF gets the same numbers.

use fabkit_designs::geometry::Aabb;
use fabkit_designs::kit::{CastReport, PrintTechnology};
use serde::{Deserialize, Serialize};

/// The `frame` string of every manifest.
pub const FRAME: &str =
    "sensor frame (docs/conventions.md); parts are in print orientation on z = 0";

/// The whole `manifest.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// fabkit version that wrote the export.
    pub fabkit_version: String,
    pub design: ManifestDesign,
    /// Largest facet-to-true-surface distance the kit was tessellated with, mm.
    pub chord_tolerance_mm: f64,
    /// The command line that produced the export, one argument per entry.
    pub command_line: Vec<String>,
    /// The frame the part coordinates are given in; always [`FRAME`].
    pub frame: String,
    /// One entry per part, in kit order.
    pub parts: Vec<ManifestPart>,
    /// The kit 3MF, `null` when 3MF was not requested.
    pub kit_3mf: Option<ManifestKit3mf>,
    /// The print plates (`plates/<design>_<technology>_<material>_<n>.3mf`), when 3MF was
    /// requested: every part on exactly one, inside its printer's bed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plates: Vec<ManifestPlate>,
    /// The assembled sensor (`assembly.3mf`, every part in the sensor frame), when 3MF was
    /// requested and the kit is a sensor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub assembly_3mf: Option<ManifestAssembly>,
    /// The assembled sensor as exact B-reps (`assembly.step`, one named solid per member, in
    /// the sensor frame), when STEP was requested and the kit is a sensor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub assembly_step: Option<ManifestAssemblyStep>,
    /// `--format mjcf`: the simulator files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sim: Option<ManifestSim>,
    /// `section.png`, the assembled sensor cut through its axis, and its legend; for a kit
    /// that is a sensor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section_view: Option<crate::section::SectionView>,
    /// Laser-cut parts with their DXF and SVG files.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cut_parts: Vec<ManifestCutPart>,
    /// Printed circuit boards' outlines with their DXF files, for PCB tools.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pcb_outlines: Vec<ManifestPcbOutline>,
    /// Parts made to order by a machine shop, with their drawings (and STEP files).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub machined_parts: Vec<ManifestMachinedPart>,
    /// Pours in casting order, as the design computed them.
    pub casts: Vec<CastReport>,
    /// Parts that are bought or cut rather than printed, one line each.
    pub bought_items: Vec<String>,
    /// The fabrication procedure in order (`action`, `text`), as the design derived it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub procedure: Vec<fabkit_designs::kit::ProcedureStep>,
    /// Sensor-frame facts from the design build (envelope, derived radii, ...).
    pub summary: serde_json::Value,
    /// Data files written beside the meshes (point tables, geometry descriptions), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub data_files: Vec<ManifestDataFile>,
}

/// The simulator files of the export (`--format mjcf,urdf`): the models and the meshes they
/// load, their hashes, the camera file, where the camera comes from and the notes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestSim {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mjcf: Option<ManifestDataFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub urdf: Option<ManifestDataFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub usd: Option<ManifestDataFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera_file: Option<ManifestDataFile>,
    pub meshes: Vec<ManifestDataFile>,
    /// What the camera is (absent: the model has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<String>,
    pub notes: Vec<String>,
}

/// A data file of the export and its hash.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestDataFile {
    /// Path relative to the export directory, `/`-separated.
    pub file: String,
    pub sha256: String,
}

/// Where the design came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestDesign {
    /// Design name, e.g. `rtac0`; also the stem of the 3MF file.
    pub name: String,
    /// A path to the YAML design, or `embedded:<name>` for a built-in design.
    pub source: String,
    /// sha256 of the design text, 64 lowercase hex digits.
    pub sha256: String,
}

/// One printed part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestPart {
    pub name: String,
    /// Path of the part's STL relative to the export directory (`parts/<name>.stl`), `null`
    /// when STL was not requested.
    pub file: Option<String>,
    pub role: String,
    pub description: String,
    /// Material key in the materials table.
    pub material: String,
    /// The material's product name (the materials table's `name`; the key when the table has
    /// no such material).
    #[serde(default)]
    pub material_name: String,
    /// Printed mass, g: the volume times the material's density (0 when the table has no
    /// such material).
    #[serde(default)]
    pub mass_g: f64,
    /// `"FDM"`, `"SLA"` or `"PolyJet"`.
    pub print_technology: PrintTechnology,
    /// Multi-material print group, `null` for a part printed on its own. Parts of one group
    /// share coordinates and are printed together in one job (one material each); the kit
    /// 3MF holds them as the volumes of one object.
    pub group: Option<String>,
    /// Enclosed volume of the written mesh, mm^3.
    pub volume_mm3: f64,
    /// Surface area of the written mesh, mm^2.
    pub surface_area_mm2: f64,
    /// Bounding box of the written mesh in print orientation, mm: `{min: [x, y, z], max: [x, y, z]}`.
    pub bbox_mm: Aabb,
    /// Number of vertices of the indexed mesh (the 3MF object holds exactly these).
    pub vertices: usize,
    /// Number of triangles (the STL holds exactly these).
    pub triangles: usize,
    /// Genus of the solid (number of through-holes for a single shell).
    pub genus: i64,
    /// sha256 of the STL file bytes, `null` when STL was not requested.
    pub sha256: Option<String>,
    /// Path of the part's STEP file (`step/<name>.step`, exact B-rep from the CadQuery twin),
    /// absent when STEP was not requested.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_file: Option<String>,
    /// sha256 of the STEP file bytes, absent when STEP was not requested.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_sha256: Option<String>,
    /// Path of the part's picture (`previews/<name>.png`: shaded, isometric from
    /// above-front-right and from below-back-left, side by side), present when STL or 3MF
    /// was written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview: Option<String>,
    /// sha256 of the picture's bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview_sha256: Option<String>,
    /// The resolved parameters the part was built from.
    pub params: serde_json::Value,
}

/// The assembly 3MF: one object per member, in the sensor frame (no build-item translation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestAssembly {
    /// `assembly.3mf`, relative to the export directory.
    pub file: String,
    pub sha256: String,
    /// One entry per member, in the 3MF's object order (ids 1, 2, ...).
    pub members: Vec<ManifestMember>,
    /// The assembled sensor's mass, centre of mass and inertia: its members with a material
    /// combined ([`crate::mass::sensor_mass`]).
    pub mass: crate::mass::SensorMass,
}

/// One member of the assembly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestMember {
    /// 3MF object name: the kit part's or layer's name; bought envelopes end in `_envelope`.
    pub name: String,
    /// `printed`, `cast` or `bought` (a simple envelope).
    pub kind: fabkit_designs::assembly::MemberKind,
    pub description: String,
    /// Volume of the written mesh, mm^3, and its box in the sensor frame, mm.
    pub volume_mm3: f64,
    pub bbox_mm: Aabb,
    /// Its material (a key of designs/materials.yaml); absent for a bought item whose
    /// envelope is not its material (a camera board, an LED PCB).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Its mass properties from the written mesh at the material's density; absent without a
    /// material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<crate::mass::MemberMass>,
}

/// The assembly STEP file: one STEP assembly named after the design, one component (a named
/// solid, or a compound of solids for a member of separate pieces) per member, in the sensor
/// frame, mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestAssemblyStep {
    /// `assembly.step`, relative to the export directory.
    pub file: String,
    pub sha256: String,
    /// One entry per member, in the file's component order (the assembly's member order).
    pub members: Vec<ManifestStepMember>,
}

/// One solid of the assembly STEP file and the mesh numbers it was checked against: its
/// exact volume is within surface area x chord tolerance (+ 1e-6 relative) of `volume_mm3`
/// and its box within the chord tolerance + 1 um of `bbox_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestStepMember {
    /// The solid's name (its STEP product and component): the member's name.
    pub name: String,
    /// `printed`, `cast` or `bought`.
    pub kind: fabkit_designs::assembly::MemberKind,
    /// What the solid was built from.
    pub geometry: StepGeometry,
    /// Volume of fabkit's written mesh of the member, mm^3.
    pub volume_mm3: f64,
    /// Surface area of that mesh, mm^2.
    pub surface_area_mm2: f64,
    /// Its box in the sensor frame, mm.
    pub bbox_mm: Aabb,
    /// Number of shells of that mesh and of the STEP solids: 1 for a member in one piece, one
    /// per piece (a compound of solids under the member's name) for marker tips.
    pub shells: usize,
}

/// How a solid of the assembly STEP file was built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StepGeometry {
    /// The printed part's exact twin (the B-rep of its `step/<part>.step`), moved back by the
    /// inverse of its `T_print_sensor`.
    ExactPart,
    /// The layer's exact twin, from the same parameters as its parts.
    ExactLayer,
    /// The core's exact shell: its outer offset surface and inner surface (a machined core's
    /// `step/<name>.step` holds the same solid).
    ExactCoreShell,
    /// The exact space inside a layer less its inner features, with the opening a filling gel
    /// runs down through (a printed TacTip tip's gel, Pestell et al. Sec. III-A).
    ExactInnerCavity,
    /// The exact solid of revolution of the member's (r, z) profile polygon (planes, cylinders,
    /// cones); the polygon is within half the chord tolerance of the true profile.
    RevolvedProfile,
    /// An exact cylinder, ring or box (a bought part's envelope).
    ExactEnvelope,
    /// The member's mesh, one planar OCCT face per triangle, joined at the mesh's shared edges
    /// into closed shells (faceted).
    SewnMesh,
}

/// A part cut from sheet stock and its 2D files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestCutPart {
    pub name: String,
    pub description: String,
    /// Material key and product name.
    pub material: String,
    pub material_name: String,
    pub thickness_mm: f64,
    /// How many to cut.
    pub quantity: u32,
    /// The laser's kerf the paths are offset for (half of it away from the part), mm.
    pub kerf_mm: f64,
    /// Area enclosed by the paths in the files (outer outline less the holes), mm^2.
    pub area_mm2: f64,
    /// Area of the part as it comes off the laser, mm^2 (= `area_mm2` with no kerf).
    pub nominal_area_mm2: f64,
    /// `cut/<name>.dxf` (R2000, mm, layers `cut` and `engrave`) and `cut/<name>.svg` (mm).
    pub dxf: String,
    pub dxf_sha256: String,
    pub svg: String,
    pub svg_sha256: String,
    /// `cut/preview/<name>.svg`: the part to look at (0.25 mm strokes, its face shaded, its
    /// name, sheet and count, a scale bar); not for the laser.
    #[serde(default)]
    pub preview_svg: String,
    #[serde(default)]
    pub preview_svg_sha256: String,
    /// `cut/<name>.stl`: one sheet as a solid (the nominal part extruded by its thickness,
    /// from z = 0), for a sheet with polygonal outlines.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stl: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stl_sha256: Option<String>,
}

/// A printed circuit board's outline (`pcb/<name>.dxf`: R2000, mm, the edge and holes on
/// layer `cut`, component places on `engrave`), for a PCB tool's board edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestPcbOutline {
    pub name: String,
    pub description: String,
    pub thickness_mm: f64,
    /// Area of the board (outer edge less the holes), mm^2.
    pub area_mm2: f64,
    pub dxf: String,
    pub dxf_sha256: String,
}

/// A part made to order by a machine shop (`machined/<name>.svg`: its dimensioned drawing, a
/// section through its axis; `machined/<name>.stl` with STL, `step/<name>.step` with STEP:
/// its solid in the sensor frame, mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestMachinedPart {
    pub name: String,
    pub description: String,
    pub material: String,
    pub material_name: String,
    pub finish: String,
    /// Enclosed volume of the written mesh, mm^3.
    pub volume_mm3: f64,
    pub mass_g: f64,
    /// Bounding box in the sensor frame, mm.
    pub bbox_mm: Aabb,
    /// The drawing, `machined/<name>.svg`.
    pub drawing: String,
    pub drawing_sha256: String,
    /// The drawing's dimensions (what a shop measures), mm.
    pub dimensions: Vec<fabkit_designs::parts::core_shell::Dimension>,
    /// The part's numbers: diameters, pole heights, wall and least wall, tolerance.
    pub params: serde_json::Value,
    /// Its exact shape (the CadQuery twin builds the STEP solid from it).
    pub exact: fabkit_designs::assembly::ExactShape,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_sha256: Option<String>,
}

/// The kit 3MF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestKit3mf {
    /// Path relative to the export directory (`<design>.3mf`).
    pub file: String,
    /// sha256 of the 3MF file bytes.
    pub sha256: String,
    /// One entry per 3MF object, in kit order of each object's first part.
    pub objects: Vec<ManifestObject>,
}

/// One print plate: parts of one technology and material inside one printer's bed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestPlate {
    /// Path relative to the export directory.
    pub file: String,
    /// sha256 of the 3MF file bytes.
    pub sha256: String,
    pub print_technology: fabkit_designs::kit::PrintTechnology,
    /// Material key (a multi-material group's keys joined by `+`).
    pub material: String,
    /// The printer: its name, build volume (x, y, z, mm) and the margin kept clear (mm).
    pub printer: String,
    pub bed_mm: [f64; 3],
    pub margin_mm: f64,
    /// The plate's picture (`previews/plate_<plate file stem>.png`: the objects on the bed seen
    /// from above-front; also the 3MF's `Metadata/thumbnail.png`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview_sha256: Option<String>,
    /// The plate's objects, each with its translation (and turn) from part coordinates.
    pub objects: Vec<ManifestPlateObject>,
}

/// One object of a plate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestPlateObject {
    /// The part name, or a group's part names joined by `+`.
    pub name: String,
    /// Turn about z before the translation, degrees (0 or 90, counter-clockwise from above).
    pub turn_deg: f64,
    /// Build-item translation, mm.
    pub translation_mm: [f64; 3],
    /// The object's footprint on the plate, mm: [x_min, y_min, x_max, y_max].
    pub footprint_mm: [f64; 4],
}

/// One object of the kit 3MF and where its build item puts it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestObject {
    /// 3MF object id (1, 2, ...).
    pub id: u32,
    /// Object name: the part name, or for a group its parts' names joined by `+`
    /// (`skin+skin_tips`).
    pub name: String,
    /// The multi-material group the object holds, `null` for one ungrouped part.
    pub group: Option<String>,
    /// Build-item translation from part coordinates to the plate, mm (one for all volumes).
    pub translation_mm: [f64; 3],
    /// The object's parts in mesh order: one volume per part (one for an ungrouped part).
    pub volumes: Vec<ManifestVolume>,
}

/// One part of a 3MF object: a range of the object's triangles, in part coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestVolume {
    /// Part name; also the volume name in the PrusaSlicer config of a group object.
    pub part: String,
    /// First triangle of the part in the object's mesh, 0-based (PrusaSlicer's `firstid`).
    pub first_triangle: usize,
    /// Last triangle of the part in the object's mesh, 0-based, inclusive (`lastid`).
    pub last_triangle: usize,
    /// Extruder (1-based) the volume is assigned in the PrusaSlicer config: the part's
    /// position in its group; 1 (PrusaSlicer's default, nothing written) for an ungrouped part.
    pub extruder: u32,
}
