//! Reading the files a design names (marker CSV files, `pattern.csv_file`) and the design and
//! sweep files themselves, within bounds.
//!
//! - A data file must resolve (symbolic links and `..` followed) to a place inside the design
//!   file's folder, or inside a folder the user allows on the command line
//!   (`--allow-data-dir`): a design cannot make fabkit read `/etc/passwd` or `~/.ssh`.
//! - Every input file must be a regular file: a character device (`/dev/zero`), a FIFO or a
//!   socket is refused before it is read, so nothing reads forever or until memory runs out.
//! - Every input file is bounded in size ([`DataFileRules::max_bytes`] for data files,
//!   [`MAX_DESIGN_FILE_BYTES`] for design and sweep files), checked before and while reading.
//! - A refused file's contents are never read, so no error can quote them.

use std::io::Read as _;
use std::path::{Path, PathBuf};

use crate::error::DesignError;

/// Default size bound of one data file, bytes (1 MiB: a marker CSV of about 50,000 points).
pub const DEFAULT_MAX_DATA_FILE_BYTES: u64 = 1 << 20;
/// Largest size bound a user may set for data files, bytes (64 MiB).
pub const MAX_DATA_FILE_BYTES_LIMIT: u64 = 64 << 20;
/// Size bound of a YAML input file (design, sweep, fixture parameters), bytes (16 MiB; the library's designs are a few kB).
pub const MAX_DESIGN_FILE_BYTES: u64 = 16 << 20;

/// Which data files a design read from a file may read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DataFileRules {
    /// Folders besides the design file's own (and their subfolders) that data files may be read
    /// from, resolved (absolute, no symbolic links). See [`DataFileRules::allow_dir`].
    pub allowed_dirs: Vec<PathBuf>,
    /// Largest data file, bytes: 1 to [`MAX_DATA_FILE_BYTES_LIMIT`].
    pub max_bytes: u64,
}

impl Default for DataFileRules {
    fn default() -> Self {
        Self {
            allowed_dirs: Vec::new(),
            max_bytes: DEFAULT_MAX_DATA_FILE_BYTES,
        }
    }
}

impl DataFileRules {
    /// Checks a size bound given as text (the `--max-data-file-bytes` value).
    ///
    /// # Errors
    /// The rule, for a value that is not a whole number from 1 to [`MAX_DATA_FILE_BYTES_LIMIT`].
    pub fn parse_max_bytes(value: &str) -> Result<u64, String> {
        match value.trim().parse::<u64>() {
            Ok(n) if (1..=MAX_DATA_FILE_BYTES_LIMIT).contains(&n) => Ok(n),
            _ => Err(format!(
                "must be a whole number of bytes from 1 to {MAX_DATA_FILE_BYTES_LIMIT} (64 MiB)"
            )),
        }
    }

    /// Resolves a folder to allow data files from (the `--allow-data-dir` value).
    ///
    /// # Errors
    /// The rule, for a path that is not an existing folder.
    pub fn allow_dir(path: &Path) -> Result<PathBuf, String> {
        if path.as_os_str().is_empty() {
            return Err("must name an existing folder".into());
        }
        match std::fs::canonicalize(path) {
            Ok(p) if p.is_dir() => Ok(p),
            Ok(p) => Err(format!(
                "must name an existing folder ({} is not a folder)",
                p.display()
            )),
            Err(e) => Err(format!("must name an existing folder ({e})")),
        }
    }
}

/// What kind of file system entry `md` describes, for messages.
fn kind(md: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        let t = md.file_type();
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if md.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// Why [`read_bounded`] refused or failed; the message is a rule, not file contents.
#[derive(Debug)]
enum Refusal {
    /// The file cannot be opened or read (the OS's message).
    Io(std::io::Error),
    /// Not a regular file (what it is).
    NotRegular(&'static str),
    /// Over the bound (size in bytes, or `None` when it grew while being read).
    TooLarge(Option<u64>),
}

/// "N bytes, " when the size is known.
fn size_prefix(n: Option<u64>) -> String {
    n.map(|n| format!("{n} bytes, ")).unwrap_or_default()
}

/// Reads the regular file at `path` of at most `max_bytes`. The file is opened without
/// blocking (a FIFO does not wait for a writer) and checked through the open handle, so a file
/// swapped after the check is caught too.
fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, Refusal> {
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt as _;
        opts.custom_flags(libc::O_NONBLOCK);
    }
    // Check the type first where it can be done without opening (opening some devices acts).
    let md = std::fs::metadata(path).map_err(Refusal::Io)?;
    if !md.is_file() {
        return Err(Refusal::NotRegular(kind(&md)));
    }
    let f = opts.open(path).map_err(Refusal::Io)?;
    let md = f.metadata().map_err(Refusal::Io)?;
    if !md.is_file() {
        return Err(Refusal::NotRegular(kind(&md)));
    }
    if md.len() > max_bytes {
        return Err(Refusal::TooLarge(Some(md.len())));
    }
    let mut bytes = Vec::with_capacity(md.len() as usize);
    f.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(Refusal::Io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(Refusal::TooLarge(None));
    }
    Ok(bytes)
}

/// Reads the regular file at `path`, of at most `max_bytes`: the bounded read behind every input
/// file fabkit takes (design and sweep files, camera files, point tables, observations, images,
/// fixture outputs).
///
/// # Errors
/// The OS's error, or one of kind `InvalidInput` whose message is the rule broken (`is a FIFO
/// (named pipe); only regular files are read`, `is N bytes, over the limit of M bytes`). The
/// message never quotes the file.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> std::io::Result<Vec<u8>> {
    read_bounded(path, max_bytes).map_err(|r| match r {
        Refusal::Io(e) => e,
        Refusal::NotRegular(k) => std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("is {k}; only regular files are read"),
        ),
        Refusal::TooLarge(n) => std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "is {}over the limit of {max_bytes} bytes for this input",
                size_prefix(n)
            ),
        ),
    })
}

/// [`read_regular_file`] as UTF-8 text, without the byte order mark a spreadsheet's "CSV
/// UTF-8" or an editor may put first (the same text as without one).
///
/// # Errors
/// As [`read_regular_file`], and one of kind `InvalidData` (`is not UTF-8 text`).
pub fn read_text_file(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let mut text = String::from_utf8(read_regular_file(path, max_bytes)?)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "is not UTF-8 text"))?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Reads a YAML input file the user named: a design, a sweep file, fixture parameters (regular
/// file, at most [`MAX_DESIGN_FILE_BYTES`]).
///
/// # Errors
/// [`DesignError::Io`] naming the path and the rule broken.
pub fn read_design_file(path: &Path) -> Result<String, DesignError> {
    read_text_file(path, MAX_DESIGN_FILE_BYTES).map_err(|e| DesignError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// Reads the data file `value` named by the parameter `param` of the design file in `design_dir`,
/// under `rules`.
///
/// # Errors
/// [`DesignError::Params`] with one [`crate::ParamError`] (`param = "value": rule`): outside the
/// design's folder and every allowed folder, not a regular file, over the size bound, not
/// text, or unreadable. The file's contents are never quoted.
pub(crate) fn read_data_file(
    design_dir: &Path,
    param: &str,
    value: &str,
    rules: &DataFileRules,
) -> Result<String, DesignError> {
    let refuse = |rule: String| {
        DesignError::Params(crate::ParamErrors(vec![crate::ParamError::new(
            param,
            format!("{value:?}"),
            rule,
        )]))
    };
    let dir = if design_dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        design_dir
    };
    let root = std::fs::canonicalize(dir).map_err(|e| {
        refuse(format!(
            "the design's folder {} cannot be resolved ({e})",
            dir.display()
        ))
    })?;
    let path = dir.join(value);
    let resolved = std::fs::canonicalize(&path).map_err(|e| {
        refuse(format!(
            "cannot be read: {e} (looked for {})",
            path.display()
        ))
    })?;
    let inside =
        resolved.starts_with(&root) || rules.allowed_dirs.iter().any(|d| resolved.starts_with(d));
    if !inside {
        return Err(refuse(format!(
            "resolves to {}, outside the design's folder {}; data files are read only from the \
             design's folder and its subfolders (hint: copy the file there, or allow its folder \
             with --allow-data-dir)",
            resolved.display(),
            root.display()
        )));
    }
    let bytes = read_bounded(&resolved, rules.max_bytes).map_err(|r| {
        refuse(match r {
            Refusal::Io(e) => format!("cannot be read: {e}"),
            Refusal::NotRegular(k) => {
                format!("is {k}; a data file must be a regular file")
            }
            Refusal::TooLarge(n) => format!(
                "is {}over the data file limit of {} bytes (hint: --max-data-file-bytes, up to \
                 {MAX_DATA_FILE_BYTES_LIMIT})",
                size_prefix(n),
                rules.max_bytes
            ),
        })
    })?;
    String::from_utf8(bytes)
        .map_err(|_| refuse("is not UTF-8 text; a data file is a CSV text file".into()))
}
