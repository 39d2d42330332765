//! STEP files through the CadQuery twin (issue 7): each part is rebuilt as an exact B-rep
//! (planes, cylinders, cones, spheres, tori and B-spline surfaces of revolution) from its
//! resolved parameters by `tests/oracles/twins` and written by OpenCASCADE, so CAD users get
//! editable surfaces instead of facets.
//!
//! The twin scripts are compiled into fabkit and run by a Python that has CadQuery: the
//! `FABKIT_CADQUERY_PYTHON` environment variable, else `<repo>/.venv-cadquery/bin/python`
//! (what `scripts/setup-cadquery` builds). Before a file is written the twin's exact volume
//! must agree with fabkit's mesh within the chord-tolerance bound (surface area x tolerance)
//! and its bounding box within the tolerance; otherwise the export fails naming the part.

use crate::{ExportError, ManifestPart};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The twin package, embedded: (file name, text).
const TWINS: &[(&str, &str)] = &[
    (
        "__init__.py",
        include_str!("../../tests/oracles/twins/__init__.py"),
    ),
    (
        "cq_common.py",
        include_str!("../../tests/oracles/twins/cq_common.py"),
    ),
    (
        "cq_molds.py",
        include_str!("../../tests/oracles/twins/cq_molds.py"),
    ),
    (
        "cq_layers.py",
        include_str!("../../tests/oracles/twins/cq_layers.py"),
    ),
    (
        "cq_housing.py",
        include_str!("../../tests/oracles/twins/cq_housing.py"),
    ),
    (
        "cq_fixtures.py",
        include_str!("../../tests/oracles/twins/cq_fixtures.py"),
    ),
    (
        "cq_twin.py",
        include_str!("../../tests/oracles/twins/cq_twin.py"),
    ),
    (
        "families.py",
        include_str!("../../tests/oracles/twins/families.py"),
    ),
    (
        "step_export.py",
        include_str!("../../tests/oracles/twins/step_export.py"),
    ),
];

/// How to get the CadQuery environment, for error messages.
pub const INSTALL_HINT: &str = "STEP export runs the CadQuery twin (tests/oracles/twins) in a \
     Python with CadQuery 2.8: run `scripts/setup-cadquery` in the fabkit repository (builds \
     .venv-cadquery, about 2.4 GB, from tests/oracles/requirements-cadquery.txt), or set \
     FABKIT_CADQUERY_PYTHON to a python that can `import cadquery`";

/// The Python that runs the twins: `FABKIT_CADQUERY_PYTHON`, else the repository's
/// `.venv-cadquery`. Whether cadquery imports there is told by `step_export.py` itself (exit
/// status 4), so it is imported once per export, not twice.
///
/// # Errors
/// [`ExportError::StepUnavailable`] when that Python does not exist.
pub fn cadquery_python() -> Result<PathBuf, ExportError> {
    let python = match std::env::var_os("FABKIT_CADQUERY_PYTHON") {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(".venv-cadquery/bin/python"),
    };
    if python.components().count() > 1 && !python.exists() {
        return Err(ExportError::StepUnavailable {
            reason: format!("no Python at {}", python.display()),
        });
    }
    Ok(python)
}

/// One STEP file per part (same order as `parts`), built by the CadQuery twin from the parts'
/// params. `chord_tolerance_mm` sets the agreement bound checked before writing.
///
/// # Errors
/// [`ExportError::StepUnavailable`] without CadQuery; [`ExportError::Step`] when a twin fails
/// or disagrees with fabkit's part; [`ExportError::Io`] for the scratch directory.
pub fn render(
    parts: &[ManifestPart],
    chord_tolerance_mm: f64,
) -> Result<Vec<Vec<u8>>, ExportError> {
    let python = cadquery_python()?;
    let scratch = Scratch::new()?;
    let pkg = scratch.0.join("twins");
    std::fs::create_dir(&pkg).map_err(ExportError::io("creating", &pkg))?;
    for (name, text) in TWINS {
        let p = pkg.join(name);
        std::fs::write(&p, text).map_err(ExportError::io("writing", &p))?;
    }
    let input = scratch.0.join("parts.json");
    let doc = serde_json::json!({"chord_tolerance_mm": chord_tolerance_mm, "parts": parts});
    std::fs::write(&input, serde_json::to_vec(&doc)?)
        .map_err(ExportError::io("writing", &input))?;
    let out_dir = scratch.0.join("step");
    let out = Command::new(&python)
        .current_dir(&scratch.0)
        .args(["-m", "twins.step_export"])
        .arg(&input)
        .arg(&out_dir)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .map_err(|e| ExportError::StepUnavailable {
            reason: format!("no Python at {} ({e})", python.display()),
        })?;
    if out.status.code() == Some(4) {
        return Err(ExportError::StepUnavailable {
            reason: format!("{} cannot import cadquery", python.display()),
        });
    }
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("(no message)");
        let part = last
            .strip_prefix("step_export: part ")
            .and_then(|r| r.split(':').next())
            .unwrap_or("?")
            .to_string();
        return Err(ExportError::Step {
            part,
            reason: last.to_string(),
        });
    }
    parts
        .iter()
        .map(|p| {
            let f = out_dir.join(format!("{}.step", p.name));
            std::fs::read(&f).map_err(ExportError::io("reading", &f))
        })
        .collect()
}

/// A scratch directory removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Result<Self, ExportError> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let p = std::env::temp_dir().join(format!("fabkit-step-{}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&p).map_err(ExportError::io("creating", &p))?;
        Ok(Self(p))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
