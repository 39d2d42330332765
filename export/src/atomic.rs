//! Replacing an output directory without ever leaving a mixed state under its name.
//!
//! Everything is written into a fresh sibling `.<name>.tmp-<pid>-<n>` and synced; then a
//! previous output is renamed to `.<name>.old-<pid>-<n>`, the new directory is renamed into
//! place and the old one deleted. Between the two renames the name is briefly absent (a POSIX
//! rename cannot swap two directories), but it never holds a half-written output.
//!
//! Every folder written here carries a marker, [`OUTPUT_MARKER`]: the command that wrote it,
//! its job, and the list of the folder's files with their sizes and SHA-256. A folder is
//! replaced only when it is empty or when its marker lists every file in it, each still with
//! the bytes fabkit wrote, and the marker names the same command ([`OutputClaim`]) and, unless
//! forced, the same job. A folder a user made, a fabkit output a user added to or edited, and
//! another command's output are refused whole and left untouched.

use crate::ExportError;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::ffi::OsString;
use std::fs;
use std::io::{ErrorKind, Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

/// Sibling names from one process never repeat.
static SIBLING_COUNTER: AtomicU32 = AtomicU32::new(0);

/// Name of the marker file in every output folder fabkit writes (JSON: `format`, `command`,
/// `job` and `files`, each file's `/`-separated path, size in bytes and SHA-256, sorted by
/// path; the marker itself is not listed). Its bytes depend only on the folder's files and
/// its claim: same input, same bytes.
pub const OUTPUT_MARKER: &str = ".fabkit-output";
const MARKER_FORMAT: &str = "fabkit-output/2";
/// The marker of earlier fabkit versions: paths and sizes only, which a user's folder can
/// imitate; such a folder is not replaced.
const MARKER_FORMAT_V1: &str = "fabkit-output/1";

/// The fabkit command that writes an output folder, recorded in its marker: a command replaces
/// only its own kind of output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputCommand {
    /// `fabkit export` (and `Kit.export` in Python).
    Export,
    /// `fabkit fixtures` (and a fixtures kit's `export` in Python).
    Fixtures,
    /// `fabkit groundtruth`.
    Groundtruth,
    /// `fabkit calibrate extrinsics`.
    CalibrateExtrinsics,
    /// `fabkit calibrate photometric`.
    CalibratePhotometric,
    /// `fabkit calibrate board`.
    CalibrateBoard,
    /// `fabkit calibrate nominal`.
    CalibrateNominal,
    /// One variant's folder of `fabkit sweep` (`variants/<id>/`).
    SweepVariant,
}

impl OutputCommand {
    /// The command as the user types it after `fabkit ` (`calibrate extrinsics`), as the
    /// marker records it.
    pub fn name(self) -> &'static str {
        match self {
            OutputCommand::Export => "export",
            OutputCommand::Fixtures => "fixtures",
            OutputCommand::Groundtruth => "groundtruth",
            OutputCommand::CalibrateExtrinsics => "calibrate extrinsics",
            OutputCommand::CalibratePhotometric => "calibrate photometric",
            OutputCommand::CalibrateBoard => "calibrate board",
            OutputCommand::CalibrateNominal => "calibrate nominal",
            OutputCommand::SweepVariant => "sweep",
        }
    }
}

/// Who writes an output folder: the command, the job (what distinguishes one output of the
/// command from another, e.g. `kit 'rtac0' at chord tolerance 0.05 mm`) and whether an
/// earlier output of another job of the same command may be replaced (`--force`). Another
/// command's output is never replaced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputClaim {
    pub command: OutputCommand,
    /// A short human description, compared as a whole and quoted in refusals.
    pub job: String,
    pub force: bool,
    /// The input files the output is computed from: none may lie inside the output directory,
    /// which is replaced whole ([`ExportError::InputInsideOutput`]).
    pub inputs: Vec<PathBuf>,
}

impl OutputClaim {
    /// The claim of a kit's folder (export, fixtures or a sweep variant): the job is the kit
    /// (its name: the design, its preset and mold strategy) and the chord tolerance.
    pub fn kit(
        command: OutputCommand,
        kit_name: &str,
        chord_tolerance_mm: f64,
        force: bool,
    ) -> OutputClaim {
        OutputClaim {
            command,
            job: format!("kit '{kit_name}' at chord tolerance {chord_tolerance_mm} mm"),
            force,
            inputs: Vec::new(),
        }
    }
}

impl OutputClaim {
    /// The claim of an output computed from input files (ground truth, a calibration): the job
    /// is `what` followed by a SHA-256 over the inputs' contents, in order, so that an output
    /// of other inputs (other captures, another camera file) is another job. Only regular
    /// files of at most [`MAX_HASHED_INPUT_BYTES`] are read; any other path (missing, a FIFO,
    /// a folder, a larger file, one that cannot be read) counts by its path alone, and the
    /// command's own reader reports it.
    pub fn of_inputs(
        command: OutputCommand,
        what: &str,
        inputs: &[&Path],
        force: bool,
    ) -> OutputClaim {
        let mut h = Sha256::new();
        for p in inputs {
            let regular =
                fs::metadata(p).is_ok_and(|m| m.is_file() && m.len() <= MAX_HASHED_INPUT_BYTES);
            match regular.then(|| sha256_of_file(p).ok()).flatten() {
                Some(file) => h.update(format!("file {file}\n")),
                None => h.update(format!("path {}\n", p.display())),
            }
        }
        let digest = hex(&h.finalize());
        OutputClaim {
            command,
            job: format!("{what} (inputs sha256 {})", &digest[..16]),
            force,
            inputs: inputs.iter().map(|p| p.to_path_buf()).collect(),
        }
    }
}

/// Free bytes for an unprivileged user on the file system that would hold `out` (its nearest
/// existing ancestor); `None` where that cannot be told.
pub fn free_bytes(out: &Path) -> Option<u64> {
    let abs = std::path::absolute(out).ok()?;
    let dir = abs.ancestors().find(|a| a.exists())?;
    #[cfg(unix)]
    {
        let s = rustix::fs::statvfs(dir).ok()?;
        Some(s.f_bavail.saturating_mul(s.f_frsize))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// Largest input file [`OutputClaim::of_inputs`] reads, bytes (1 GiB).
pub const MAX_HASHED_INPUT_BYTES: u64 = 1 << 30;

/// One file of an output folder as the marker lists it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MarkedFile {
    path: String,
    bytes: u64,
    sha256: String,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Marker {
    format: String,
    command: String,
    job: String,
    files: Vec<MarkedFile>,
}

/// Only the format of a marker, to tell an earlier fabkit's marker from a foreign file.
#[derive(serde::Deserialize)]
struct MarkerFormat {
    format: String,
}

/// A file found on disk: relative `/`-separated path and size.
#[derive(Debug)]
struct FoundFile {
    path: String,
    bytes: u64,
}

/// SHA-256 of bytes, 64 lowercase hex digits.
pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of a file's content, streamed.
fn sha256_of_file(path: &Path) -> Result<String, ExportError> {
    let mut f = fs::File::open(path).map_err(ExportError::io("reading", path))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf).map_err(ExportError::io("reading", path))?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(hex(&h.finalize()))
}

/// SHA-256 of the files written into a temporary output folder, by relative path, recorded
/// as they are written (so that the marker does not read them back).
#[derive(Debug, Default)]
pub(crate) struct WrittenHashes(Mutex<BTreeMap<String, String>>);

impl WrittenHashes {
    pub(crate) fn record(&self, rel: &str, bytes: &[u8]) {
        self.insert(rel, sha256_hex(bytes));
    }

    /// Records the SHA-256 `h` (64 hex digits) of the file `rel`, computed by the caller.
    pub(crate) fn insert(&self, rel: &str, h: String) {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .insert(rel.to_string(), h);
    }

    fn into_map(self) -> BTreeMap<String, String> {
        self.0
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// Every regular file under `dir` (relative `/`-separated path and size, sorted), or the first
/// entry that is neither a regular file nor a folder (a symlink, a FIFO, ...) as `Err`.
fn list_tree(dir: &Path) -> Result<Result<Vec<FoundFile>, String>, ExportError> {
    let mut files = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), String::new())];
    while let Some((d, prefix)) = stack.pop() {
        for e in fs::read_dir(&d).map_err(ExportError::io("listing", &d))? {
            let e = e.map_err(ExportError::io("listing", &d))?;
            let rel = format!("{prefix}{}", e.file_name().to_string_lossy());
            let md =
                fs::symlink_metadata(e.path()).map_err(ExportError::io("inspecting", e.path()))?;
            if md.is_dir() {
                stack.push((e.path(), format!("{rel}/")));
            } else if md.is_file() {
                files.push(FoundFile {
                    path: rel,
                    bytes: md.len(),
                });
            } else {
                return Ok(Err(rel));
            }
        }
    }
    files.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(Ok(files))
}

/// Writes the marker of the finished folder `dir` (every file in it, see [`OUTPUT_MARKER`]):
/// the SHA-256 of a file is taken from `written` where recorded, read from disk otherwise.
fn write_marker(
    dir: &Path,
    claim: &OutputClaim,
    written: WrittenHashes,
) -> Result<(), ExportError> {
    let files = match list_tree(dir)? {
        Ok(f) => f,
        Err(entry) => {
            return Err(ExportError::Io {
                action: "listing (not a regular file)",
                path: dir.join(entry),
                source: std::io::Error::from(ErrorKind::InvalidData),
            })
        }
    };
    let written = written.into_map();
    let files = files
        .into_iter()
        .map(|f| {
            let sha256 = match written.get(&f.path) {
                Some(h) => h.clone(),
                None => sha256_of_file(&crate::join_rel(dir, &f.path))?,
            };
            Ok(MarkedFile {
                path: f.path,
                bytes: f.bytes,
                sha256,
            })
        })
        .collect::<Result<Vec<_>, ExportError>>()?;
    let marker = Marker {
        format: MARKER_FORMAT.into(),
        command: claim.command.name().into(),
        job: claim.job.clone(),
        files,
    };
    let mut bytes = serde_json::to_vec_pretty(&marker).map_err(|e| ExportError::Encode {
        what: OUTPUT_MARKER.into(),
        reason: e.to_string(),
    })?;
    bytes.push(b'\n');
    write_file_synced(&dir.join(OUTPUT_MARKER), &bytes)
}

/// What [`replace_dir`] did besides succeeding.
#[derive(Debug)]
pub(crate) struct Replaced {
    /// An earlier export (or an empty directory) was replaced.
    pub replaced_previous: bool,
    /// Non-fatal problems (e.g. an old export that could not be deleted).
    pub warnings: Vec<String>,
}

/// Fills a fresh temporary sibling of `out_dir` with `fill` and moves it into place. `fill`
/// records the SHA-256 of what it writes in the [`WrittenHashes`] it is given (a file it does
/// not record is read back for the marker).
///
/// `out_dir` may be missing (its parents are created), an empty directory, or an earlier
/// fabkit output that `claim` may replace (see [`check_out_dir`]), which is replaced whole.
///
/// # Errors
/// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
/// [`ExportError::ForeignDirectory`], [`ExportError::OtherCommand`],
/// [`ExportError::OtherJob`], [`ExportError::Io`], or `fill`'s error. On every error
/// `out_dir` is as it was and the temporary directory is removed.
pub(crate) fn replace_dir(
    out_dir: &Path,
    claim: &OutputClaim,
    fill: impl FnOnce(&Path, &WrittenHashes) -> Result<(), ExportError>,
) -> Result<Replaced, ExportError> {
    let (parent, name) = split(out_dir)?;
    let created = create_parents(&parent)?;
    let result = (|| {
        let existing = inspect_existing(out_dir, claim)?;
        let tmp = create_unique_sibling(&parent, &name, "tmp")?;
        let written = WrittenHashes::default();
        if let Err(e) = fill(&tmp, &written)
            .and_then(|()| write_marker(&tmp, claim, written))
            .and_then(|()| sync_dir(&tmp))
        {
            let _ = fs::remove_dir_all(&tmp);
            return Err(e);
        }
        move_into_place(out_dir, &parent, &name, &tmp, existing)
    })();
    if result.is_err() {
        remove_created(&created);
    }
    result
}

/// Creates `dir` and its missing ancestors; returns the folders it created, outermost first.
///
/// # Errors
/// [`ExportError::Io`]; the folders created so far are removed again.
fn create_parents(dir: &Path) -> Result<Vec<PathBuf>, ExportError> {
    let mut missing = Vec::new();
    let mut d = Some(dir);
    while let Some(p) = d.filter(|p| !p.as_os_str().is_empty() && fs::symlink_metadata(p).is_err())
    {
        missing.push(p.to_path_buf());
        d = p.parent();
    }
    missing.reverse();
    for (k, p) in missing.iter().enumerate() {
        if let Err(e) = fs::create_dir(p) {
            if !(e.kind() == std::io::ErrorKind::AlreadyExists && p.is_dir()) {
                remove_created(&missing[..k]);
                return Err(ExportError::io("creating parent directory", p)(e));
            }
        }
    }
    Ok(missing)
}

/// Removes the folders [`create_parents`] created, innermost first, as long as they are empty:
/// a failed run leaves no folder behind.
fn remove_created(created: &[PathBuf]) {
    for p in created.iter().rev() {
        if fs::remove_dir(p).is_err() {
            break;
        }
    }
}

/// Moves the complete temporary sibling `tmp` to `out_dir` (moving a previous export aside and
/// deleting it), then syncs the parent. On error `out_dir` is as it was and `tmp` is removed.
fn move_into_place(
    out_dir: &Path,
    parent: &Path,
    name: &OsString,
    tmp: &Path,
    existing: bool,
) -> Result<Replaced, ExportError> {
    let mut warnings = Vec::new();
    if existing {
        let backup = unique_sibling_path(parent, name, "old");
        if let Err(e) = fs::rename(out_dir, &backup) {
            let _ = fs::remove_dir_all(tmp);
            return Err(ExportError::io(
                "moving the previous export aside from",
                out_dir,
            )(e));
        }
        if let Err(e) = fs::rename(tmp, out_dir) {
            let restored = fs::rename(&backup, out_dir);
            let _ = fs::remove_dir_all(tmp);
            if let Err(r) = restored {
                warnings.push(format!(
                    "could not move the previous export back from {}: {r}",
                    backup.display()
                ));
            }
            return Err(ExportError::io(
                "moving the new export into place at",
                out_dir,
            )(e));
        }
        if let Err(e) = fs::remove_dir_all(&backup) {
            warnings.push(format!(
                "the previous export was moved to {} but could not be deleted ({e}); delete it by hand",
                backup.display()
            ));
        }
    } else if let Err(e) = fs::rename(tmp, out_dir) {
        let _ = fs::remove_dir_all(tmp);
        return Err(ExportError::io(
            "moving the new export into place at",
            out_dir,
        )(e));
    }
    remove_stale_siblings(parent, name, &mut warnings);
    // Make the renames durable; a failure here does not undo a complete export.
    if let Err(e) = sync_dir(parent) {
        let cause = std::error::Error::source(&e)
            .map(ToString::to_string)
            .unwrap_or_default();
        warnings.push(format!("{e}: {cause}"));
    }
    Ok(Replaced {
        replaced_previous: existing,
        warnings,
    })
}

/// An output folder written file by file (e.g. a dataset too large to hold in memory): files go
/// into a fresh temporary sibling of the folder; [`StagedDir::commit`] moves it into place
/// exactly as [`crate::write_kit`] does (a missing folder, an empty one, or an earlier fabkit
/// output that the claim may replace, see [`check_out_dir`]; anything else, a symbolic link
/// included, is refused before writing).
/// Dropped without a commit, the temporary folder is removed and the output is untouched.
#[derive(Debug)]
pub struct StagedDir {
    out_dir: PathBuf,
    parent: PathBuf,
    name: OsString,
    tmp: PathBuf,
    existing: bool,
    done: bool,
    /// The parent folders this output created, removed again if it is dropped uncommitted.
    created: Vec<PathBuf>,
    claim: OutputClaim,
    written: WrittenHashes,
}

impl StagedDir {
    /// Checks `out_dir` for `claim` (see [`check_out_dir`]) and creates the temporary sibling.
    ///
    /// # Errors
    /// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
    /// [`ExportError::ForeignDirectory`], [`ExportError::OtherCommand`],
    /// [`ExportError::OtherJob`], [`ExportError::Io`].
    pub fn new(out_dir: &Path, claim: OutputClaim) -> Result<StagedDir, ExportError> {
        let (parent, name) = split(out_dir)?;
        let created = create_parents(&parent)?;
        let staged = inspect_existing(out_dir, &claim)
            .and_then(|existing| Ok((existing, create_unique_sibling(&parent, &name, "tmp")?)));
        let (existing, tmp) = match staged {
            Ok(x) => x,
            Err(e) => {
                remove_created(&created);
                return Err(e);
            }
        };
        Ok(StagedDir {
            out_dir: out_dir.to_path_buf(),
            parent,
            name,
            tmp,
            existing,
            done: false,
            created,
            claim,
            written: WrittenHashes::default(),
        })
    }

    /// Writes one file (relative `/`-separated path of `[A-Za-z0-9_.-]` components; parent
    /// folders are created) and syncs it. Safe to call from several threads for different
    /// files.
    ///
    /// # Errors
    /// [`ExportError::InvalidOption`] for a bad path or one written twice, [`ExportError::Io`].
    pub fn write(&self, rel: &str, bytes: &[u8]) -> Result<(), ExportError> {
        check_relative_path("file", rel)?;
        let path = rel.split('/').fold(self.tmp.clone(), |p, c| p.join(c));
        if let Some(dir) = path.parent() {
            fs::create_dir_all(dir).map_err(ExportError::io("creating", dir))?;
        }
        write_file_synced(&path, bytes)?;
        self.written.record(rel, bytes);
        Ok(())
    }

    /// Syncs every folder and moves the finished output into place; returns warnings (e.g. a
    /// previous output that could not be deleted).
    ///
    /// # Errors
    /// [`ExportError::Io`]; the output is then as it was.
    pub fn commit(mut self) -> Result<Vec<String>, ExportError> {
        write_marker(&self.tmp, &self.claim, std::mem::take(&mut self.written))?;
        let mut dirs = vec![self.tmp.clone()];
        let mut k = 0;
        while k < dirs.len() {
            for e in fs::read_dir(&dirs[k]).map_err(ExportError::io("listing", &dirs[k]))? {
                let e = e.map_err(ExportError::io("listing", &dirs[k]))?;
                if e.file_type().map(|t| t.is_dir()).unwrap_or(false) {
                    dirs.push(e.path());
                }
            }
            k += 1;
        }
        for d in dirs.iter().rev() {
            sync_dir(d)?;
        }
        self.done = true;
        match move_into_place(
            &self.out_dir,
            &self.parent,
            &self.name,
            &self.tmp,
            self.existing,
        ) {
            Ok(r) => Ok(r.warnings),
            Err(e) => {
                remove_created(&self.created);
                Err(e)
            }
        }
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.done {
            let _ = fs::remove_dir_all(&self.tmp);
            remove_created(&self.created);
        }
    }
}

/// A file path inside an output folder: relative, `/`-separated, each component made of
/// `[A-Za-z0-9_.-]` and neither `.` nor `..`.
///
/// # Errors
/// [`ExportError::InvalidOption`] naming `field` and the path.
pub(crate) fn check_relative_path(field: &'static str, rel: &str) -> Result<(), ExportError> {
    let ok = !rel.is_empty()
        && rel.split('/').all(|c| {
            !c.is_empty()
                && c != "."
                && c != ".."
                && c.chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || "_.-".contains(ch))
        });
    if ok {
        Ok(())
    } else {
        Err(ExportError::InvalidOption {
            field,
            value: rel.to_string(),
            rule: "must be a relative path of [A-Za-z0-9_.-] components",
        })
    }
}

/// Writes `bytes` to a new file at `path` and syncs it to disk.
pub(crate) fn write_file_synced(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    let mut f = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(ExportError::io("creating", path))?;
    f.write_all(bytes)
        .map_err(ExportError::io("writing", path))?;
    f.sync_all().map_err(ExportError::io("syncing", path))
}

/// Syncs a directory's entries to disk (Unix; elsewhere directories cannot be opened for it).
pub(crate) fn sync_dir(dir: &Path) -> Result<(), ExportError> {
    #[cfg(unix)]
    {
        fs::File::open(dir)
            .and_then(|d| d.sync_all())
            .map_err(ExportError::io("syncing directory", dir))?;
    }
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// Checks `out_dir` as an output folder of `claim` before any work is done, creating nothing:
/// it must have a final name (not `/` or `..`), its nearest existing ancestor must be a
/// folder, and it must be missing, an empty folder, or an earlier fabkit output that `claim`
/// may replace: every file in it listed in its [`OUTPUT_MARKER`] with the SHA-256 fabkit
/// wrote, written by the same command, and (unless `claim.force`) for the same job. These are
/// the rules [`StagedDir::new`] and [`crate::write_kit`] apply when they write it. A command
/// runs this first, so that a folder it would refuse is refused before building or rendering
/// for seconds. An earlier output's files are read in full to check them.
///
/// # Errors
/// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
/// [`ExportError::ForeignDirectory`] (naming the first file that is not fabkit's as written),
/// [`ExportError::OtherCommand`], [`ExportError::OtherJob`], [`ExportError::Io`].
pub fn check_out_dir(out_dir: &Path, claim: &OutputClaim) -> Result<(), ExportError> {
    let (parent, _) = split(out_dir)?;
    if let Some(existing) = parent.ancestors().find(|a| fs::symlink_metadata(a).is_ok()) {
        if !existing.is_dir() {
            return Err(ExportError::NotADirectory {
                path: existing.to_path_buf(),
            });
        }
    }
    inspect_existing(out_dir, claim).map(|_| ())
}

/// (parent directory, final name) of `out_dir`; an empty parent means the current directory.
fn split(out_dir: &Path) -> Result<(PathBuf, OsString), ExportError> {
    let name = out_dir
        .file_name()
        .ok_or_else(|| ExportError::InvalidOutDir {
            path: out_dir.to_path_buf(),
            reason: "has no final directory name (hint: give a path such as `out/rtac0`)".into(),
        })?;
    let parent = match out_dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((parent, name.to_os_string()))
}

/// `Ok(true)` for a directory that `claim` may replace, `Ok(false)` when nothing is there.
fn inspect_existing(out_dir: &Path, claim: &OutputClaim) -> Result<bool, ExportError> {
    let md = match fs::symlink_metadata(out_dir) {
        Ok(md) => md,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(ExportError::io("inspecting", out_dir)(e)),
    };
    if md.file_type().is_symlink() {
        return Err(ExportError::InvalidOutDir {
            path: out_dir.to_path_buf(),
            reason: "is a symbolic link; replacing it would replace the link, not its target \
                     (hint: pass the target directory itself)"
                .into(),
        });
    }
    if !md.is_dir() {
        return Err(ExportError::NotADirectory {
            path: out_dir.to_path_buf(),
        });
    }
    let empty = fs::read_dir(out_dir)
        .map_err(ExportError::io("listing", out_dir))?
        .next()
        .is_none();
    if empty {
        return Ok(true);
    }
    check_earlier_output(out_dir, claim).map(|()| true)
}

/// `Ok(())` when the non-empty folder `dir` is an output that `claim` may replace: its marker
/// (this fabkit's format) lists every file in it, each still at the size and SHA-256 fabkit
/// wrote (files the user deleted do not matter), names `claim`'s command and, unless
/// `claim.force`, its job. Otherwise the error names the first entry that shows it is not, or
/// the other command or job. Names and sizes are checked before any file is read; every
/// file's SHA-256 before the command and job, so that a forged marker is refused by the
/// user's file it names.
fn check_earlier_output(dir: &Path, claim: &OutputClaim) -> Result<(), ExportError> {
    let foreign = |entry: String, why: String| ExportError::ForeignDirectory {
        path: dir.to_path_buf(),
        entry,
        why,
    };
    let files = match list_tree(dir)? {
        Ok(f) => f,
        Err(entry) => return Err(foreign(entry, "is neither a file nor a folder".into())),
    };
    let marker_path = dir.join(OUTPUT_MARKER);
    let marker_bytes = fs::symlink_metadata(&marker_path)
        .ok()
        .filter(|m| m.is_file() && m.len() <= MAX_MARKER_BYTES)
        .and_then(|_| fs::read(&marker_path).ok());
    let marker: Option<Marker> = marker_bytes
        .as_deref()
        .and_then(|b| serde_json::from_slice(b).ok())
        .filter(|m: &Marker| m.format == MARKER_FORMAT);
    let Some(marker) = marker else {
        // The user's first file (not a look-alike manifest.json), for the message.
        let first = files
            .iter()
            .find(|f| f.path != "manifest.json" && f.path != OUTPUT_MARKER)
            .or(files.first())
            .map(|f| f.path.clone())
            .unwrap_or_default();
        let earlier = marker_bytes
            .as_deref()
            .and_then(|b| serde_json::from_slice::<MarkerFormat>(b).ok())
            .is_some_and(|m| m.format == MARKER_FORMAT_V1);
        let why = if earlier {
            format!(
                "is there, and the folder's {OUTPUT_MARKER} is the marker of an earlier fabkit, \
                 without checksums, which a folder of your own can imitate (delete the folder \
                 yourself if it is an output you no longer need)"
            )
        } else if files.iter().any(|f| f.path == OUTPUT_MARKER) {
            format!("is there, and the folder's {OUTPUT_MARKER} is not a fabkit marker")
        } else {
            format!("is there, and the folder has no {OUTPUT_MARKER} marker (an output of an older fabkit has none: delete it yourself)")
        };
        return Err(foreign(first, why));
    };
    let listed: BTreeMap<&str, &MarkedFile> =
        marker.files.iter().map(|f| (f.path.as_str(), f)).collect();
    let mut to_hash = Vec::new();
    for f in files.iter().filter(|f| f.path != OUTPUT_MARKER) {
        match listed.get(f.path.as_str()) {
            None => {
                return Err(foreign(
                    f.path.clone(),
                    format!("is not one of the files fabkit wrote there (not in {OUTPUT_MARKER})"),
                ))
            }
            Some(m) if m.bytes != f.bytes => {
                return Err(foreign(
                    f.path.clone(),
                    format!(
                        "was changed after fabkit wrote it ({} bytes, written {})",
                        f.bytes, m.bytes
                    ),
                ))
            }
            Some(m) => to_hash.push(*m),
        }
    }
    for m in to_hash {
        if sha256_of_file(&crate::join_rel(dir, &m.path))? != m.sha256 {
            return Err(foreign(
                m.path.clone(),
                "was changed after fabkit wrote it (same size, other bytes: its SHA-256 is not \
                 the one fabkit recorded)"
                    .into(),
            ));
        }
    }
    if marker.command != claim.command.name() {
        return Err(ExportError::OtherCommand {
            path: dir.to_path_buf(),
            command: marker.command,
            job: marker.job,
            this_command: claim.command.name(),
        });
    }
    if marker.job != claim.job && !claim.force {
        return Err(ExportError::OtherJob {
            path: dir.to_path_buf(),
            command: marker.command,
            job: marker.job,
            this_job: claim.job.clone(),
        });
    }
    // The folder is one this command would replace: an input inside it would be deleted with
    // it, --force or not.
    if let Ok(canonical) = fs::canonicalize(dir) {
        for input in &claim.inputs {
            if fs::canonicalize(input).is_ok_and(|p| p.starts_with(&canonical)) {
                return Err(ExportError::InputInsideOutput {
                    path: dir.to_path_buf(),
                    input: input.clone(),
                });
            }
        }
    }
    Ok(())
}

/// Largest marker file read back, bytes (a list of files, not a dataset).
const MAX_MARKER_BYTES: u64 = 64 << 20;

/// After a complete output is in place: removes the temporary siblings of the same output
/// (`.<name>.tmp-<pid>-<n>`, `.<name>.old-<pid>-<n>`) that a killed run left behind, those of
/// processes that are no longer running, and says so in `warnings`. Siblings of live
/// processes (another fabkit writing the same folder now) and anything that is not a folder
/// are left alone; where running processes cannot be listed (no `/proc`), nothing is removed.
fn remove_stale_siblings(parent: &Path, name: &OsString, warnings: &mut Vec<String>) {
    let proc_fs = Path::new("/proc/self").exists();
    if !proc_fs {
        return;
    }
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = fs::read_dir(parent) else {
        return;
    };
    let me = std::process::id();
    let mut stale: Vec<(PathBuf, u32)> = entries
        .filter_map(Result::ok)
        .filter_map(|e| {
            let file_name = e.file_name();
            let rest = file_name.to_str()?.strip_prefix(&prefix)?.to_string();
            let rest = rest
                .strip_prefix("tmp-")
                .or_else(|| rest.strip_prefix("old-"))?;
            let (pid, n) = rest.split_once('-')?;
            let pid: u32 = pid.parse().ok()?;
            n.parse::<u32>().ok()?;
            Some((e.path(), pid))
        })
        .filter(|(p, pid)| {
            *pid != me
                && !Path::new("/proc").join(pid.to_string()).exists()
                && fs::symlink_metadata(p).is_ok_and(|m| m.is_dir())
        })
        .collect();
    stale.sort();
    for (p, pid) in stale {
        match fs::remove_dir_all(&p) {
            Ok(()) => warnings.push(format!(
                "removed {}, a temporary folder left by an interrupted fabkit run (process {pid}, no longer running)",
                p.display()
            )),
            Err(e) => warnings.push(format!(
                "could not remove {}, a temporary folder left by an interrupted fabkit run ({e}); delete it by hand",
                p.display()
            )),
        }
    }
}

fn unique_sibling_path(parent: &Path, name: &OsString, kind: &str) -> PathBuf {
    loop {
        let n = SIBLING_COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut s = OsString::from(".");
        s.push(name);
        s.push(format!(".{kind}-{}-{n}", std::process::id()));
        let p = parent.join(s);
        if fs::symlink_metadata(&p).is_err() {
            return p;
        }
    }
}

fn create_unique_sibling(
    parent: &Path,
    name: &OsString,
    kind: &str,
) -> Result<PathBuf, ExportError> {
    loop {
        let p = unique_sibling_path(parent, name, kind);
        match fs::create_dir(&p) {
            Ok(()) => return Ok(p),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(ExportError::io("creating temporary directory", p)(e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn claim() -> OutputClaim {
        OutputClaim {
            command: OutputCommand::Groundtruth,
            job: "design 'rtac0'".into(),
            force: false,
            inputs: Vec::new(),
        }
    }

    fn siblings(parent: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(parent)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn failing_fill_leaves_nothing_behind() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        let r = replace_dir(&out, &claim(), |tmp, _| {
            write_file_synced(&tmp.join("half.stl"), b"x")?;
            Err(ExportError::ThreeMf {
                reason: "injected".into(),
            })
        });
        assert!(matches!(r, Err(ExportError::ThreeMf { .. })));
        assert!(siblings(root.path()).is_empty());
    }

    #[test]
    fn failing_fill_keeps_the_previous_export() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        replace_dir(&out, &claim(), |tmp, _| {
            write_file_synced(
                &tmp.join("manifest.json"),
                b"{\"fabkit_version\": \"0.0.1\"}\n",
            )
        })
        .unwrap();
        let r = replace_dir(&out, &claim(), |_, _| {
            Err(ExportError::ThreeMf {
                reason: "injected".into(),
            })
        });
        assert!(r.is_err());
        assert_eq!(siblings(root.path()), vec!["kit"]);
        assert_eq!(siblings(&out), vec![OUTPUT_MARKER, "manifest.json"]);
    }

    /// Siblings left by a killed run (a process no longer running) are removed by the next
    /// complete output, which says so; those of a live process and look-alike names are kept.
    #[test]
    fn stale_siblings_of_dead_processes_are_removed_and_reported() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let live = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let stale_tmp = root.path().join(format!(".kit.tmp-{dead}-0"));
        let stale_old = root.path().join(format!(".kit.old-{dead}-3"));
        let busy = root.path().join(format!(".kit.tmp-{}-0", live.id()));
        let other = root.path().join(format!(".kits.tmp-{dead}-0"));
        let odd = root.path().join(format!(".kit.tmp-{dead}-x"));
        for d in [&stale_tmp, &stale_old, &busy, &other, &odd] {
            fs::create_dir(d).unwrap();
            fs::write(d.join("half.stl"), b"x").unwrap();
        }
        let r = replace_dir(&out, &claim(), |tmp, _| {
            write_file_synced(&tmp.join("a.stl"), b"a")
        })
        .unwrap();
        let mut live = live;
        let _ = live.kill();
        let _ = live.wait();
        assert!(!stale_tmp.exists() && !stale_old.exists());
        assert!(busy.exists() && other.exists() && odd.exists());
        assert_eq!(r.warnings.len(), 2, "{:?}", r.warnings);
        for (w, p) in r.warnings.iter().zip([&stale_old, &stale_tmp]) {
            assert!(
                w.contains(&p.display().to_string()) && w.contains(&dead.to_string()),
                "{w}"
            );
        }
    }

    #[test]
    fn root_and_dot_dot_are_refused() {
        assert!(matches!(
            split(Path::new("/")),
            Err(ExportError::InvalidOutDir { .. })
        ));
        assert!(matches!(
            split(Path::new("a/..")),
            Err(ExportError::InvalidOutDir { .. })
        ));
        assert_eq!(split(Path::new("kit")).unwrap().0, PathBuf::from("."));
    }

    #[test]
    fn foreign_manifest_is_not_a_previous_export() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("kit");
        fs::create_dir(&out).unwrap();
        fs::write(out.join("manifest.json"), "{\"name\": \"web app\"}").unwrap();
        let r = replace_dir(&out, &claim(), |_, _| Ok(()));
        assert!(
            matches!(r, Err(ExportError::ForeignDirectory { ref entry, .. }) if entry == "manifest.json")
        );
        assert_eq!(siblings(root.path()), vec!["kit"]);
    }

    #[test]
    fn staged_dir_commits_whole_or_leaves_nothing() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("gt");
        {
            let st = StagedDir::new(&out, claim()).unwrap();
            st.write("a/b.bin", b"x").unwrap();
            assert!(st.write("../c", b"y").is_err());
            // dropped without commit
        }
        assert!(siblings(root.path()).is_empty());
        let st = StagedDir::new(&out, claim()).unwrap();
        st.write("a/b.bin", b"x").unwrap();
        st.write("manifest.json", b"{\"fabkit_version\": \"0\"}")
            .unwrap();
        assert!(st.commit().unwrap().is_empty());
        assert_eq!(siblings(root.path()), vec!["gt"]);
        assert_eq!(fs::read(out.join("a/b.bin")).unwrap(), b"x");
        // A previous output is replaced; a foreign folder is refused.
        let st = StagedDir::new(&out, claim()).unwrap();
        st.write("manifest.json", b"{\"fabkit_version\": \"1\"}")
            .unwrap();
        st.commit().unwrap();
        assert!(!out.join("a").exists());
        let foreign = root.path().join("mine");
        fs::create_dir(&foreign).unwrap();
        fs::write(foreign.join("notes.txt"), "keep").unwrap();
        assert!(matches!(
            StagedDir::new(&foreign, claim()),
            Err(ExportError::ForeignDirectory { .. })
        ));
    }
}
