//! Replacing an output directory without ever leaving a mixed state under its name.
//!
//! Everything is written into a fresh sibling `.<name>.tmp-<pid>-<n>` and synced; then a
//! previous export is renamed to `.<name>.old-<pid>-<n>`, the new directory is renamed into
//! place and the old one deleted. Between the two renames the name is briefly absent (a POSIX
//! rename cannot swap two directories), but it never holds a half-written export.
//!
//! Every folder written here carries a marker, [`OUTPUT_MARKER`]: the list of the folder's
//! files with their sizes. A folder is replaced only when it is empty or when its marker lists
//! every file in it (at its listed size): a folder a user made, or a fabkit output a user added
//! to or edited, is refused whole and left untouched.

use crate::ExportError;
use std::ffi::OsString;
use std::fs;
use std::io::{ErrorKind, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

/// Sibling names from one process never repeat.
static SIBLING_COUNTER: AtomicU32 = AtomicU32::new(0);

/// Name of the marker file in every output folder fabkit writes (JSON: `format` and `files`,
/// each file's `/`-separated path and size in bytes, sorted by path; the marker itself is not
/// listed). Its bytes depend only on the folder's files: same input, same bytes.
pub const OUTPUT_MARKER: &str = ".fabkit-output";
const MARKER_FORMAT: &str = "fabkit-output/1";

/// One file of an output folder as the marker lists it.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MarkedFile {
    path: String,
    bytes: u64,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Marker {
    format: String,
    files: Vec<MarkedFile>,
}

/// Every regular file under `dir` (relative `/`-separated path and size, sorted), or the first
/// entry that is neither a regular file nor a folder (a symlink, a FIFO, ...) as `Err`.
fn list_tree(dir: &Path) -> Result<Result<Vec<MarkedFile>, String>, ExportError> {
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
                files.push(MarkedFile {
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

/// Writes the marker of the finished folder `dir` (every file in it, see [`OUTPUT_MARKER`]).
fn write_marker(dir: &Path) -> Result<(), ExportError> {
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
    let marker = Marker {
        format: MARKER_FORMAT.into(),
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

/// Fills a fresh temporary sibling of `out_dir` with `fill` and moves it into place.
///
/// `out_dir` may be missing (its parents are created), an empty directory, or an earlier
/// fabkit output that its [`OUTPUT_MARKER`] lists whole, which is replaced as a whole.
///
/// # Errors
/// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
/// [`ExportError::ForeignDirectory`], [`ExportError::Io`], or `fill`'s error. On every error
/// `out_dir` is as it was and the temporary directory is removed.
pub(crate) fn replace_dir(
    out_dir: &Path,
    fill: impl FnOnce(&Path) -> Result<(), ExportError>,
) -> Result<Replaced, ExportError> {
    let (parent, name) = split(out_dir)?;
    let created = create_parents(&parent)?;
    let result = (|| {
        let existing = inspect_existing(out_dir)?;
        let tmp = create_unique_sibling(&parent, &name, "tmp")?;
        if let Err(e) = fill(&tmp)
            .and_then(|()| write_marker(&tmp))
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
/// output whose [`OUTPUT_MARKER`] lists every file in it is replaced; anything else, a symbolic
/// link included, is refused before writing).
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
}

impl StagedDir {
    /// Checks `out_dir` and creates the temporary sibling.
    ///
    /// # Errors
    /// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
    /// [`ExportError::ForeignDirectory`], [`ExportError::Io`].
    pub fn new(out_dir: &Path) -> Result<StagedDir, ExportError> {
        let (parent, name) = split(out_dir)?;
        let created = create_parents(&parent)?;
        let staged = inspect_existing(out_dir)
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
        write_file_synced(&path, bytes)
    }

    /// Syncs every folder and moves the finished output into place; returns warnings (e.g. a
    /// previous output that could not be deleted).
    ///
    /// # Errors
    /// [`ExportError::Io`]; the output is then as it was.
    pub fn commit(mut self) -> Result<Vec<String>, ExportError> {
        write_marker(&self.tmp)?;
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

/// Checks `out_dir` as an output folder before any work is done, creating nothing: it must
/// have a final name (not `/` or `..`), its nearest existing ancestor must be a folder, and it
/// must be missing, an empty folder, or an earlier fabkit output (the rules [`StagedDir::new`]
/// and [`crate::write_kit`] apply when they write it). A command runs this first, so that a
/// folder it would refuse is refused before building or rendering for seconds.
///
/// # Errors
/// [`ExportError::InvalidOutDir`], [`ExportError::NotADirectory`],
/// [`ExportError::ForeignDirectory`], [`ExportError::Io`].
pub fn check_out_dir(out_dir: &Path) -> Result<(), ExportError> {
    let (parent, _) = split(out_dir)?;
    if let Some(existing) = parent.ancestors().find(|a| fs::symlink_metadata(a).is_ok()) {
        if !existing.is_dir() {
            return Err(ExportError::NotADirectory {
                path: existing.to_path_buf(),
            });
        }
    }
    inspect_existing(out_dir).map(|_| ())
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

/// `Ok(true)` for a directory that may be replaced, `Ok(false)` when nothing is there.
fn inspect_existing(out_dir: &Path) -> Result<bool, ExportError> {
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
    match foreign_entry(out_dir)? {
        None => Ok(true),
        Some((entry, why)) => Err(ExportError::ForeignDirectory {
            path: out_dir.to_path_buf(),
            entry,
            why,
        }),
    }
}

/// `None` when the non-empty folder `dir` is an output fabkit wrote and nobody changed: its
/// marker lists every file in it at its size (files the user deleted do not matter). Otherwise
/// the first entry that shows it is not, and why.
fn foreign_entry(dir: &Path) -> Result<Option<(String, String)>, ExportError> {
    let files = match list_tree(dir)? {
        Ok(f) => f,
        Err(entry) => return Ok(Some((entry, "is neither a file nor a folder".into()))),
    };
    let marker_path = dir.join(OUTPUT_MARKER);
    let marker: Option<Marker> = fs::symlink_metadata(&marker_path)
        .ok()
        .filter(|m| m.is_file() && m.len() <= MAX_MARKER_BYTES)
        .and_then(|_| fs::read(&marker_path).ok())
        .and_then(|b| serde_json::from_slice(&b).ok())
        .filter(|m: &Marker| m.format == MARKER_FORMAT);
    let Some(marker) = marker else {
        // The user's first file (not a look-alike manifest.json), for the message.
        let first = files
            .iter()
            .find(|f| f.path != "manifest.json" && f.path != OUTPUT_MARKER)
            .or(files.first())
            .map(|f| f.path.clone())
            .unwrap_or_default();
        let why = if files.iter().any(|f| f.path == OUTPUT_MARKER) {
            format!("is there, and the folder's {OUTPUT_MARKER} is not a fabkit marker")
        } else {
            format!("is there, and the folder has no {OUTPUT_MARKER} marker (an output of an older fabkit has none: delete it yourself)")
        };
        return Ok(Some((first, why)));
    };
    let listed: std::collections::BTreeMap<&str, u64> = marker
        .files
        .iter()
        .map(|f| (f.path.as_str(), f.bytes))
        .collect();
    for f in files.iter().filter(|f| f.path != OUTPUT_MARKER) {
        match listed.get(f.path.as_str()) {
            None => {
                return Ok(Some((
                    f.path.clone(),
                    format!("is not one of the files fabkit wrote there (not in {OUTPUT_MARKER})"),
                )))
            }
            Some(&n) if n != f.bytes => {
                return Ok(Some((
                    f.path.clone(),
                    format!(
                        "was changed after fabkit wrote it ({} bytes, written {n})",
                        f.bytes
                    ),
                )))
            }
            Some(_) => {}
        }
    }
    Ok(None)
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
        let r = replace_dir(&out, |tmp| {
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
        replace_dir(&out, |tmp| {
            write_file_synced(
                &tmp.join("manifest.json"),
                b"{\"fabkit_version\": \"0.0.1\"}\n",
            )
        })
        .unwrap();
        let r = replace_dir(&out, |_| {
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
        let r = replace_dir(&out, |tmp| write_file_synced(&tmp.join("a.stl"), b"a")).unwrap();
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
        let r = replace_dir(&out, |_| Ok(()));
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
            let st = StagedDir::new(&out).unwrap();
            st.write("a/b.bin", b"x").unwrap();
            assert!(st.write("../c", b"y").is_err());
            // dropped without commit
        }
        assert!(siblings(root.path()).is_empty());
        let st = StagedDir::new(&out).unwrap();
        st.write("a/b.bin", b"x").unwrap();
        st.write("manifest.json", b"{\"fabkit_version\": \"0\"}")
            .unwrap();
        assert!(st.commit().unwrap().is_empty());
        assert_eq!(siblings(root.path()), vec!["gt"]);
        assert_eq!(fs::read(out.join("a/b.bin")).unwrap(), b"x");
        // A previous output is replaced; a foreign folder is refused.
        let st = StagedDir::new(&out).unwrap();
        st.write("manifest.json", b"{\"fabkit_version\": \"1\"}")
            .unwrap();
        st.commit().unwrap();
        assert!(!out.join("a").exists());
        let foreign = root.path().join("mine");
        fs::create_dir(&foreign).unwrap();
        fs::write(foreign.join("notes.txt"), "keep").unwrap();
        assert!(matches!(
            StagedDir::new(&foreign),
            Err(ExportError::ForeignDirectory { .. })
        ));
    }
}
