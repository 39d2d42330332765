//! The designs shipped inside fabkit (`designs/library/*.yaml`), embedded at build time.

use crate::error::DesignError;
use crate::input_files::DataFileRules;
use crate::schema::Design;

/// (name, YAML text) of every library design; the first is the default.
pub const LIBRARY: &[(&str, &str)] = &[
    ("rtac0", include_str!("../library/rtac0.yaml")),
    ("shadowtac", include_str!("../library/shadowtac.yaml")),
    ("uvdtact", include_str!("../library/uvdtact.yaml")),
    (
        "tactip_dualmodal",
        include_str!("../library/tactip_dualmodal.yaml"),
    ),
    (
        "soter_channels",
        include_str!("../library/soter_channels.yaml"),
    ),
    ("digit_pinki", include_str!("../library/digit_pinki.yaml")),
    ("ninedtact", include_str!("../library/ninedtact.yaml")),
];

/// The default design of `fabkit export` without a design argument.
pub const DEFAULT_DESIGN: &str = "rtac0";

/// The YAML text of a library design.
pub fn yaml(name: &str) -> Option<&'static str> {
    LIBRARY.iter().find(|(n, _)| *n == name).map(|(_, y)| *y)
}

/// Parses a library design.
///
/// # Errors
/// [`DesignError::UnknownDesign`] or a parse error (a defect covered by tests).
pub fn load(name: &str) -> Result<Design, DesignError> {
    let text = yaml(name).ok_or_else(|| DesignError::UnknownDesign(name.to_string()))?;
    Design::from_yaml(text, &format!("designs/library/{name}.yaml"))
}

/// A design read from a YAML file or the library, with where it came from.
#[derive(Debug, Clone)]
pub struct LoadedDesign {
    /// The parsed design, marker CSV files read into their patterns.
    pub design: Design,
    /// The path as given, or `embedded:<name>` for a library design.
    pub source: String,
    /// sha256 of the YAML text followed by every marker CSV file it reads, in order; 64
    /// lowercase hex digits.
    pub sha256: String,
    /// The YAML text and the name its errors give (`file` or `designs/library/<name>.yaml`),
    /// for errors that point into it after loading.
    yaml: (String, String),
}

impl LoadedDesign {
    /// The numbers of the design's YAML that are implausible in their key's unit and plausible
    /// in another ([`crate::plausible::unit_warnings`]), each at its `file:line:column`.
    pub fn unit_warnings(&self) -> Vec<String> {
        crate::plausible::unit_warnings(&self.yaml.0, &self.yaml.1)
    }

    /// Applies preset `name` to the design ([`Design::with_preset_in`]): an error names the
    /// preset value's `file:line:column`.
    ///
    /// # Errors
    /// As [`Design::with_preset_in`].
    pub fn apply_preset(&mut self, name: &str) -> Result<(), DesignError> {
        self.design = self
            .design
            .with_preset_in(name, &self.yaml.0, &self.yaml.1)?;
        Ok(())
    }
}

/// Reads the design named by `arg`: a YAML file when it names an existing file, ends in
/// `.yaml` / `.yml` or contains a `/`, else the library design of that name. A relative file
/// path is taken relative to `relative_to` (`""` for the current directory); marker CSV files
/// relative to the design file's folder.
///
/// # Errors
/// [`DesignError::Io`] for an unreadable file, [`DesignError::UnknownDesign`], or the
/// design's own YAML errors (`file:line:column`).
pub fn load_source(arg: &str, relative_to: &std::path::Path) -> Result<LoadedDesign, DesignError> {
    load_source_with(arg, relative_to, &DataFileRules::default())
}

/// [`load_source`] with the rules for the data files the design reads (its marker CSV files):
/// see [`crate::input_files`]. A design file must be a regular file of at most
/// [`crate::input_files::MAX_DESIGN_FILE_BYTES`].
///
/// # Errors
/// As [`load_source`]; a refused data file is a [`DesignError::Params`] naming its parameter.
pub fn load_source_with(
    arg: &str,
    relative_to: &std::path::Path,
    rules: &DataFileRules,
) -> Result<LoadedDesign, DesignError> {
    use sha2::{Digest, Sha256};
    let path = relative_to.join(arg);
    let looks_like_file =
        path.is_file() || arg.ends_with(".yaml") || arg.ends_with(".yml") || arg.contains('/');
    let (text, source, origin) = if looks_like_file {
        let text = crate::input_files::read_design_file(&path)?;
        let shown = path.display().to_string();
        (text, shown.clone(), shown)
    } else {
        let text = yaml(arg).ok_or_else(|| DesignError::UnknownDesign(arg.to_string()))?;
        (
            text.to_string(),
            format!("embedded:{arg}"),
            format!("designs/library/{arg}.yaml"),
        )
    };
    let mut design = Design::from_yaml(&text, &origin)?;
    let mut hasher = Sha256::new();
    hasher.update(text.as_bytes());
    if looks_like_file {
        let dir = path.parent().unwrap_or(std::path::Path::new("."));
        for extra in design.load_marker_files(dir, rules)? {
            hasher.update(extra.as_bytes());
        }
    }
    let sha256 = hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(LoadedDesign {
        design,
        source,
        sha256,
        yaml: (text, origin),
    })
}
