//! The designs shipped inside fabkit (`designs/library/*.yaml`), embedded at build time.

use crate::error::DesignError;
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
