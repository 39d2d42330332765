//! [`ExportError`]: everything that can stop an export.

use fabkit_designs::geometry::TopologyError;
use std::path::PathBuf;

/// Why an export was refused or failed. Whatever the variant, the output directory is left
/// exactly as it was and no temporary directory is left behind.
///
/// Display messages do not repeat their `source`; print the cause chain to see it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The part's f32-rounded mesh (the one that would be written) is open, non-manifold,
    /// inconsistently wound or inside-out.
    #[error(
        "part `{part}` is not a closed, consistently oriented 2-manifold after rounding to f32"
    )]
    NotManifold {
        part: String,
        #[source]
        source: TopologyError,
    },
    /// Distinct vertices of the part land on the same f32 position: a reader that merges
    /// vertices by position (every STL reader) would see a pinched, non-manifold solid.
    #[error(
        "part `{part}`: {count} vertices share their position with another vertex after rounding \
         to f32 (pinched or sliver geometry; a position-based reader would see a non-manifold \
         solid)"
    )]
    CoincidentVertices { part: String, count: usize },
    /// Binary STL stores the triangle count in 32 bits.
    #[error("part `{part}` has {triangles} triangles; a binary STL holds at most 4294967295")]
    TooManyTriangles { part: String, triangles: usize },
    /// Part names become file names and 3MF object names.
    #[error("part name `{name}`: must be non-empty and use only a-z, 0-9 and _ (it becomes a file name)")]
    InvalidPartName { name: String },
    #[error("two parts are named `{name}`: part names must be unique in a kit")]
    DuplicatePartName { name: String },
    /// A group name goes into the manifest and the fabrication sheet's print list.
    #[error(
        "part `{part}`: group {group:?}: must be non-empty and one line without surrounding \
         spaces (or no group)"
    )]
    InvalidGroupName { part: String, group: String },
    /// The design name becomes the 3MF file name.
    #[error(
        "design name `{name}`: must be non-empty and use only A-Z, a-z, 0-9, _ and - \
         (it becomes a file name)"
    )]
    InvalidDesignName { name: String },
    #[error("part `{part}` ({technology}, {:.1} x {:.1} x {:.1} mm) does not fit the {printer} bed ({} x {} x {} mm, {} x {} mm inside its {margin} mm margin, either way round); give a larger printer: --printer FILE.yaml or printers.{key}.bed in the design", size_mm[0], size_mm[1], size_mm[2], bed_mm[0], bed_mm[1], bed_mm[2], bed_mm[0] - 2.0 * margin, bed_mm[1] - 2.0 * margin, key = technology.to_string().to_lowercase())]
    TooLargeForBed {
        part: String,
        technology: fabkit_designs::kit::PrintTechnology,
        size_mm: [f64; 3],
        printer: String,
        bed_mm: [f64; 3],
        margin: f64,
    },
    #[error("kit `{design}` has no parts to export")]
    NoParts { design: String },
    /// A field of [`crate::ExportOptions`] breaks its rule.
    #[error("export option {field} = {value:?}: {rule}")]
    InvalidOption {
        field: &'static str,
        value: String,
        rule: &'static str,
    },
    /// The output path cannot name a directory to replace (e.g. `/`, `..`, a symlink).
    #[error("output directory {}: {reason}", path.display())]
    InvalidOutDir { path: PathBuf, reason: String },
    #[error(
        "output path {} exists and is not a directory (hint: choose another path, or move the \
         file away yourself)",
        path.display()
    )]
    NotADirectory { path: PathBuf },
    /// The output directory is not empty and is not an output fabkit wrote, unchanged since
    /// (see [`crate::OUTPUT_MARKER`]): it is not replaced, and nothing in it is touched.
    #[error(
        "output directory {} is not a folder fabkit wrote: `{entry}` {why}; refusing to \
         replace it (hint: choose a new or empty directory, or move its contents away yourself)",
        path.display()
    )]
    ForeignDirectory {
        path: PathBuf,
        entry: String,
        why: String,
    },
    /// The output directory holds another command's output (its marker names `command`):
    /// a command replaces only its own kind of output, even with `--force`.
    #[error(
        "output directory {} holds the output of `fabkit {command}` ({job}), which `fabkit \
         {this_command}` does not replace; refusing to replace it (hint: choose another \
         directory, or delete it yourself if you no longer need it)",
        path.display()
    )]
    OtherCommand {
        path: PathBuf,
        command: String,
        job: String,
        this_command: &'static str,
    },
    /// The output directory holds an output of the same command for another job (another
    /// kit, tolerance or inputs): replaced only when forced.
    #[error(
        "output directory {} holds the output of `fabkit {command}` for {job}, made with other \
         options or inputs than this one ({this_job}): refusing to replace it (hint: choose \
         another directory, or give --force (Python: force=True) to replace it)",
        path.display()
    )]
    OtherJob {
        path: PathBuf,
        command: String,
        job: String,
        this_job: String,
    },
    /// An input of the command lies inside the output directory it would replace.
    #[error(
        "{} is an input of this command and lies inside its output directory {}, which the \
         command replaces (with --force too): refusing before anything is written (hint: move \
         the input out of it, or choose another output directory)",
        input.display(),
        path.display()
    )]
    InputInsideOutput { path: PathBuf, input: PathBuf },
    /// A file-system operation failed; `action` says which (e.g. `writing`).
    #[error("{action} {}", path.display())]
    Io {
        action: &'static str,
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The in-memory 3MF (zip) archive could not be built.
    #[error("building the 3MF archive: {reason}")]
    ThreeMf { reason: String },
    #[error("encoding {what}: {reason}")]
    Encode { what: String, reason: String },
    /// `--format step` needs the CadQuery twin's Python environment.
    #[error("STEP export is not available: {reason} (hint: {hint})", hint = crate::step::INSTALL_HINT)]
    StepUnavailable { reason: String },
    /// The CadQuery twin could not build a part, or its exact solid disagrees with fabkit's.
    #[error("STEP export of part `{part}` failed: {reason}")]
    Step { part: String, reason: String },
    /// The CadQuery twin could not build a member of `assembly.step`, or it is not a valid
    /// closed solid, or it disagrees with fabkit's mesh of the member.
    #[error("STEP export of assembly member `{member}` (assembly.step) failed: {reason}")]
    StepAssembly { member: String, reason: String },
    #[error("serializing manifest.json")]
    Json(#[from] serde_json::Error),
}

impl ExportError {
    pub(crate) fn io(
        action: &'static str,
        path: impl Into<PathBuf>,
    ) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io {
            action,
            path,
            source,
        }
    }
}
