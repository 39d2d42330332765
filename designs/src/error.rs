//! Errors of design loading, validation and building.

use crate::geometry::GeometryError;

/// An error's message, then each cause the lines above do not already state on its own
/// `  caused by: ` line (an I/O error that the message quotes is said once): the text the CLI
/// prints after `error: ` and the Python exceptions carry.
pub fn error_report(e: &(dyn std::error::Error + 'static)) -> String {
    let mut out = e.to_string();
    let mut src = e.source();
    while let Some(s) = src {
        let text = s.to_string();
        if !out.contains(&text) {
            out.push_str(&format!("\n  caused by: {text}"));
        }
        src = s.source();
    }
    out
}

/// One violated rule of a design parameter: `path = value: rule`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError {
    /// Path of the parameter in the design, as in the YAML (`layers[2].thickness_mm`).
    pub path: String,
    /// The offending value, as written.
    pub value: String,
    /// The rule it breaks, with a hint where one helps.
    pub rule: String,
}

impl ParamError {
    pub fn new(
        path: impl Into<String>,
        value: impl std::fmt::Display,
        rule: impl Into<String>,
    ) -> Self {
        Self {
            path: path.into(),
            value: compact_numbers(&value.to_string()),
            rule: compact_numbers(&rule.into()),
        }
    }
}

/// `text` with every decimal number of more than 24 characters (`1e300` printed by `{}` is
/// 301 digits, `5e-324` 327) rewritten in scientific notation, so that an extreme value reads
/// as the reader wrote it; an integer up to 2^64 (20 digits) keeps its digits.
pub fn compact_numbers(text: &str) -> String {
    const LONG: usize = 24;
    if text.len() <= LONG {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        let (head, tail) = rest.split_at(start);
        let len = tail
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(tail.len());
        let number = &tail[..len];
        out.push_str(head);
        match number.parse::<f64>() {
            Ok(x) if len > LONG && x.is_finite() => out.push_str(&format!("{x:e}")),
            _ => out.push_str(number),
        }
        rest = &tail[len..];
    }
    out.push_str(rest);
    out
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {}: {}", self.path, self.value, self.rule)
    }
}

/// Every violation found in a design, reported at once.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamErrors(pub Vec<ParamError>);

impl std::fmt::Display for ParamErrors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} invalid design parameter(s):", self.0.len())?;
        for e in &self.0 {
            write!(f, "\n  {e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ParamErrors {}

/// Why a design could not be loaded or built.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The YAML does not parse or does not fit the schema; the message carries file:line:column.
    #[error("{0}")]
    Yaml(String),
    /// The design parses but breaks geometric or printability rules.
    #[error(transparent)]
    Params(#[from] ParamErrors),
    /// The geometry kernel failed on valid parameters (a fabkit defect: please report it).
    /// `params` are the parameter paths the failing solid was built from (`layers[2]`, `mold`),
    /// so that the design can be changed around the failure.
    #[error("building {part}{}: {source}", params_suffix(params))]
    Geometry {
        part: String,
        params: Vec<String>,
        #[source]
        source: GeometryError,
    },
    #[error("reading {path}: {message}")]
    Io { path: String, message: String },
    /// The estimated work of a build is past its limit ([`crate::estimate`]); the message gives
    /// the estimate, the limit and how to raise it.
    #[error("{0}")]
    WorkLimit(String),
    #[error("no library design named '{0}' (see `fabkit designs`)")]
    UnknownDesign(String),
}

fn params_suffix(params: &[String]) -> String {
    if params.is_empty() {
        String::new()
    } else {
        format!(" (from the parameters {})", params.join(", "))
    }
}

impl DesignError {
    /// The error with the parameter paths the failing solid was built from, when it is a
    /// kernel error that names none yet; any other error unchanged.
    pub fn from_params(self, params: &[String]) -> Self {
        match self {
            DesignError::Geometry {
                part,
                params: p,
                source,
            } if p.is_empty() => DesignError::Geometry {
                part,
                params: params.to_vec(),
                source,
            },
            e => e,
        }
    }
}

/// Adds the part name to a geometry error.
pub trait GeometryContext<T> {
    fn part(self, part: &str) -> Result<T, DesignError>;
}

impl<T> GeometryContext<T> for Result<T, GeometryError> {
    fn part(self, part: &str) -> Result<T, DesignError> {
        self.map_err(|source| DesignError::Geometry {
            part: part.to_string(),
            params: Vec::new(),
            source,
        })
    }
}
