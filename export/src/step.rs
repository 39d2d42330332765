//! STEP files through the CadQuery twin (issue 7): each part is rebuilt as an exact B-rep
//! (planes, cylinders, cones, spheres, tori and B-spline surfaces of revolution) from its
//! resolved parameters by the twin package `export/python/twins` and written by OpenCASCADE,
//! so CAD users get editable surfaces instead of facets.
//!
//! The twin modules are compiled into fabkit and run by a Python that has CadQuery, found by
//! [`cadquery_python`]: the `FABKIT_CADQUERY_PYTHON` environment variable, else the venv that
//! `scripts/setup-cadquery` installs in the user's data directory,
//! `$XDG_DATA_HOME/fabkit/venv-cadquery/bin/python` (`XDG_DATA_HOME` defaulting to
//! `$HOME/.local/share`), so an installed `fabkit` finds it from any directory. Before a file
//! is written the twin's exact volume must agree with fabkit's mesh within the chord-tolerance
//! bound (surface area x tolerance) and its bounding box within the tolerance; otherwise the
//! export fails naming the part. The twin reports each part as it starts it (about 3 s a part),
//! which [`render`] passes on to an optional [`StepProgress`] callback.
//!
//! In the same run the twin writes `assembly.step`, the assembled sensor in the sensor frame
//! (one STEP assembly named after the design, one named solid per member, see
//! [`StepMember`]): printed members are their parts' twins moved back by the inverse of
//! `params.T_print_sensor`, the other members are built from their
//! [`fabkit_designs::assembly::ExactShape`] or, without one, sewn from their mesh. Each member
//! passes the same volume and box checks against fabkit's mesh, must be valid and closed, and
//! must have as many shells as the mesh (a member of separate pieces, such as marker tips, is
//! one named compound of solids).

use crate::{ExportError, ManifestPart};
use fabkit_designs::assembly::{ExactShape, MemberKind};
use fabkit_designs::geometry::{Aabb, Mesh};
use serde::{Serialize, Serializer};
use std::ffi::OsString;
use std::io::BufRead as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The twin package, embedded: (file name, text) of every `cq_*.py` family twin and the
/// package's modules, listed by `build.rs`.
const TWINS: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/twins.rs"));

/// The environment variable that names the CadQuery Python explicitly.
pub const PYTHON_VAR: &str = "FABKIT_CADQUERY_PYTHON";

/// Where `scripts/setup-cadquery` installs the venv's Python, relative to the XDG data
/// directory (`$XDG_DATA_HOME`, default `$HOME/.local/share`).
pub const DATA_HOME_PYTHON: &str = "fabkit/venv-cadquery/bin/python";

/// How to get the CadQuery environment, for error messages.
pub const INSTALL_HINT: &str = "STEP export runs fabkit's CadQuery twin in a Python with \
     CadQuery 2.8: run `scripts/setup-cadquery` from a clone of the fabkit repository (installs \
     the venv at $XDG_DATA_HOME/fabkit/venv-cadquery, XDG_DATA_HOME defaulting to \
     ~/.local/share; about 2.4 GB, from tests/oracles/requirements-cadquery.txt), or set \
     FABKIT_CADQUERY_PYTHON to a python that can `import cadquery`";

/// The rule for `FABKIT_CADQUERY_PYTHON`, for error messages.
const PYTHON_VAR_RULE: &str = "it must name an executable Python with CadQuery: a path \
     (relative ones from the current directory) or a command on PATH; unset or empty for \
     $XDG_DATA_HOME/fabkit/venv-cadquery/bin/python";

/// Called while STEP files are built: `(part, parts, name)` when the CadQuery twin starts on
/// part number `part` (1 to `parts`) of `parts`, named `name`; parts come in kit order.
pub type StepProgress<'a> = &'a dyn Fn(usize, usize, &str);

/// The Python that runs the twins: `FABKIT_CADQUERY_PYTHON` when set and not empty (a path,
/// made absolute from the current directory, or a command looked up on `PATH`), else
/// `$XDG_DATA_HOME/fabkit/venv-cadquery/bin/python`, where `XDG_DATA_HOME` defaults to
/// `$HOME/.local/share` and, per the XDG Base Directory specification, is ignored unless it
/// is an absolute path. Whether cadquery imports there is told by `step_export.py` itself
/// (exit status 4), so it is imported once per export, not twice.
///
/// # Errors
/// [`ExportError::StepUnavailable`] when `FABKIT_CADQUERY_PYTHON` names no executable file
/// (the message names the variable, its value and the rule), when the default Python does
/// not exist or is not executable, or when neither `XDG_DATA_HOME` nor `HOME` is absolute.
pub fn cadquery_python() -> Result<PathBuf, ExportError> {
    locate_python(&|k| std::env::var_os(k)).map(|(python, _)| python)
}

/// [`cadquery_python`] with the environment read through `var`; also returns how the Python
/// was found, for messages (`FABKIT_CADQUERY_PYTHON=...` or the default location).
fn locate_python(var: &dyn Fn(&str) -> Option<OsString>) -> Result<(PathBuf, String), ExportError> {
    let unavailable = |reason: String| ExportError::StepUnavailable { reason };
    if let Some(value) = var(PYTHON_VAR).filter(|v| !v.is_empty()) {
        let shown = format!("{PYTHON_VAR}={}", Path::new(&value).display());
        let given = PathBuf::from(&value);
        let python = if given.components().count() > 1 || given.is_absolute() {
            let python = std::path::absolute(&given)
                .map_err(|e| unavailable(format!("{shown}: {e} ({PYTHON_VAR_RULE})")))?;
            if let Err(why) = executable_file(&python) {
                return Err(unavailable(format!("{shown}: {why} ({PYTHON_VAR_RULE})")));
            }
            python
        } else {
            var("PATH")
                .iter()
                .flat_map(std::env::split_paths)
                .filter(|dir| dir.is_absolute())
                .map(|dir| dir.join(&given))
                .find(|p| executable_file(p).is_ok())
                .ok_or_else(|| {
                    unavailable(format!(
                        "{shown}: no executable of that name on PATH ({PYTHON_VAR_RULE})"
                    ))
                })?
        };
        return Ok((python, shown));
    }
    let absolute = |k: &str| var(k).map(PathBuf::from).filter(|p| p.is_absolute());
    let ignored = match var("XDG_DATA_HOME") {
        Some(v) if !v.is_empty() && !Path::new(&v).is_absolute() => format!(
            "; XDG_DATA_HOME={} is ignored: the XDG Base Directory specification requires an \
             absolute path",
            Path::new(&v).display()
        ),
        _ => String::new(),
    };
    let data_home = absolute("XDG_DATA_HOME")
        .or_else(|| absolute("HOME").map(|h| h.join(".local/share")))
        .ok_or_else(|| {
            unavailable(format!(
                "{PYTHON_VAR} is not set, and without an absolute XDG_DATA_HOME or HOME there is \
                 no default location ($XDG_DATA_HOME/{DATA_HOME_PYTHON}, XDG_DATA_HOME \
                 defaulting to $HOME/.local/share){ignored}"
            ))
        })?;
    let python = data_home.join(DATA_HOME_PYTHON);
    let shown = format!(
        "{PYTHON_VAR} is not set (or empty); the default is $XDG_DATA_HOME/{DATA_HOME_PYTHON}, XDG_DATA_HOME \
         defaulting to $HOME/.local/share{ignored}"
    );
    if let Err(why) = executable_file(&python) {
        let why = if python.exists() {
            why
        } else {
            "no CadQuery Python there".to_string()
        };
        return Err(unavailable(format!(
            "{}: {why} ({shown})",
            python.display()
        )));
    }
    Ok((python, shown))
}

/// Ok when `path` (symbolic links followed) is a file that can be executed.
fn executable_file(path: &Path) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        _ => e.to_string(),
    })?;
    if !meta.is_file() {
        return Err("not a file".to_string());
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        if meta.permissions().mode() & 0o111 == 0 {
            return Err("not executable (no execute permission)".to_string());
        }
    }
    Ok(())
}

/// One member of `assembly.step` as the twin gets it: fabkit's numbers of the member's written
/// mesh (sensor frame, mm) for the checks, and what the exact solid is built from.
#[derive(Debug, Clone, Serialize)]
pub struct StepMember<'a> {
    /// The member's name; it names the solid (its product and component) in the STEP file.
    pub name: &'a str,
    pub kind: MemberKind,
    /// Enclosed volume of the member's written mesh, mm^3.
    pub volume_mm3: f64,
    /// Surface area of the member's written mesh, mm^2.
    pub surface_area_mm2: f64,
    /// Bounding box of the member's written mesh in the sensor frame, mm.
    pub bbox_mm: Aabb,
    /// Number of shells (connected components) of the member's written mesh: the exact
    /// solids must have as many (1 for a member in one piece; marker tips have one each).
    pub shells: usize,
    /// What the solid is built from.
    #[serde(flatten)]
    pub source: StepSource<'a>,
}

/// Where the exact solid of a [`StepMember`] comes from.
#[derive(Debug, Clone)]
pub enum StepSource<'a> {
    /// The twin of the printed part of this name (one of the parts given to [`render`]), moved
    /// back into the sensor frame by the inverse of its `params.T_print_sensor`.
    Part(&'a str),
    /// An exact shape in the sensor frame.
    Exact(&'a ExactShape),
    /// A mesh in the sensor frame (a closed 2-manifold): one planar face per triangle, joined at
    /// the shared edges into a solid.
    Mesh(&'a Mesh),
}

impl Serialize for StepSource<'_> {
    /// `{"part": name}`, `{"exact": shape}` or `{"mesh": {"vertices", "triangles"}}`, for
    /// flattening into [`StepMember`].
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap as _;
        let mut map = s.serialize_map(Some(1))?;
        match self {
            Self::Part(name) => map.serialize_entry("part", name)?,
            Self::Exact(shape) => map.serialize_entry("exact", shape)?,
            Self::Mesh(mesh) => map.serialize_entry(
                "mesh",
                &serde_json::json!({"vertices": mesh.vertices, "triangles": mesh.triangles}),
            )?,
        }
        map.end()
    }
}

/// The assembly to write as `assembly.step`: its name (the design's) and members in order.
#[derive(Debug, Clone)]
pub struct StepAssembly<'a> {
    pub name: &'a str,
    pub members: Vec<StepMember<'a>>,
}

/// What [`render`] built: the STEP file bytes per part, in the order given, and of the
/// assembly when one was given.
#[derive(Debug, Clone, PartialEq)]
pub struct StepFiles {
    pub parts: Vec<Vec<u8>>,
    pub assembly: Option<Vec<u8>>,
    /// Per machined part, in the order given.
    pub machined: Vec<Vec<u8>>,
}

/// One STEP file per part (same order as `parts`), built by the CadQuery twin from the parts'
/// params, one per machined part (`machined`, exact shapes in the sensor frame, checked as
/// assembly members are), and with `assembly` the assembly's STEP file (see the module docs).
/// `chord_tolerance_mm` sets the agreement bound checked before writing. `progress`, if given,
/// is called as the twin starts each part (see [`StepProgress`]), on this thread; assembly
/// members are not reported (the printed ones reuse their parts' twins, the others take well
/// under a second each).
///
/// # Errors
/// [`ExportError::StepUnavailable`] without CadQuery (see [`cadquery_python`]);
/// [`ExportError::Step`] when a twin fails or disagrees with fabkit's part (the part is the
/// one the twin's last message names, else the one it was building);
/// [`ExportError::StepAssembly`] when an assembly member cannot be built, is not a valid
/// closed solid, or disagrees with fabkit's mesh of it (named likewise);
/// [`ExportError::Io`] for the scratch directory.
pub fn render(
    parts: &[ManifestPart],
    machined: &[StepMember<'_>],
    assembly: Option<&StepAssembly<'_>>,
    chord_tolerance_mm: f64,
    progress: Option<StepProgress<'_>>,
) -> Result<StepFiles, ExportError> {
    let (python, found) = locate_python(&|k| std::env::var_os(k))?;
    render_with(
        &python,
        &found,
        parts,
        machined,
        assembly,
        chord_tolerance_mm,
        progress,
    )
}

/// [`render`] by `python`, found as `found` says (for messages).
fn render_with(
    python: &Path,
    found: &str,
    parts: &[ManifestPart],
    machined: &[StepMember<'_>],
    assembly: Option<&StepAssembly<'_>>,
    chord_tolerance_mm: f64,
    progress: Option<StepProgress<'_>>,
) -> Result<StepFiles, ExportError> {
    let scratch = Scratch::new()?;
    let pkg = scratch.0.join("twins");
    std::fs::create_dir(&pkg).map_err(ExportError::io("creating", &pkg))?;
    for (name, text) in TWINS {
        let p = pkg.join(name);
        std::fs::write(&p, text).map_err(ExportError::io("writing", &p))?;
    }
    let input = scratch.0.join("parts.json");
    let mut doc = serde_json::json!({"chord_tolerance_mm": chord_tolerance_mm, "parts": parts,
        "machined": serde_json::to_value(machined)?});
    if let Some(a) = assembly {
        doc["design"] = serde_json::json!(a.name);
        doc["assembly"] = serde_json::to_value(&a.members)?;
    }
    std::fs::write(&input, serde_json::to_vec(&doc)?)
        .map_err(ExportError::io("writing", &input))?;
    let out_dir = scratch.0.join("step");
    // beside the parts' folder, so that no part name can collide with it
    let assembly_file = scratch.0.join("assembly.step");
    let mut child = Command::new(python)
        .current_dir(&scratch.0)
        .args(["-m", "twins.step_export"])
        .arg(&input)
        .arg(&out_dir)
        .args(assembly.map(|_| &assembly_file))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("PYTHONUNBUFFERED", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| ExportError::StepUnavailable {
            reason: format!("{} does not run ({e}; {found})", python.display()),
        })?;
    // stderr line by line: progress as it comes, the last message for errors
    let mut last = String::new();
    let mut current: Option<String> = None;
    let mut member: Option<String> = None;
    if let Some(stderr) = child.stderr.take() {
        for line in std::io::BufReader::new(stderr).split(b'\n') {
            let Ok(line) = line else { break };
            let line = String::from_utf8_lossy(&line).trim_end().to_string();
            if let Some((i, n, name)) = parse_progress(&line) {
                current = Some(name.to_string());
                if let Some(f) = progress {
                    f(i, n, name);
                }
            } else if let Some(name) = line
                .strip_prefix("step_export: member ")
                .filter(|r| !r.contains(':'))
            {
                member = Some(name.to_string());
            } else if !line.trim().is_empty() {
                last = line;
            }
        }
    }
    let status = child
        .wait()
        .map_err(ExportError::io("waiting for", python))?;
    if status.code() == Some(4) {
        return Err(ExportError::StepUnavailable {
            reason: format!("{} cannot import cadquery ({found})", python.display()),
        });
    }
    if !status.success() {
        if let Some(rest) = last.strip_prefix("step_export: member ") {
            let named = rest.split(':').next().map(str::to_string);
            return Err(ExportError::StepAssembly {
                member: named.or(member).unwrap_or_else(|| "?".to_string()),
                reason: last.clone(),
            });
        }
        if let (Some(m), true) = (&member, last.is_empty()) {
            return Err(ExportError::StepAssembly {
                member: m.clone(),
                reason: format!(
                    "{} exited with {status} without a message",
                    python.display()
                ),
            });
        }
        let named = last
            .strip_prefix("step_export: part ")
            .and_then(|r| r.split(':').next())
            .map(str::to_string);
        let part = named.or(current).unwrap_or_else(|| "?".to_string());
        let reason = if last.is_empty() {
            format!(
                "{} exited with {status} without a message",
                python.display()
            )
        } else {
            last
        };
        return Err(ExportError::Step { part, reason });
    }
    let read = |name: &str| {
        let f = out_dir.join(format!("{name}.step"));
        std::fs::read(&f).map_err(ExportError::io("reading", &f))
    };
    let parts = parts
        .iter()
        .map(|p| read(&p.name))
        .collect::<Result<_, _>>()?;
    let machined = machined
        .iter()
        .map(|m| read(m.name))
        .collect::<Result<_, _>>()?;
    let assembly = match assembly {
        Some(_) => Some(
            std::fs::read(&assembly_file).map_err(ExportError::io("reading", &assembly_file))?,
        ),
        None => None,
    };
    Ok(StepFiles {
        parts,
        assembly,
        machined,
    })
}

/// `step_export: I/N NAME` (the twin starts part I of N) as (I, N, NAME).
fn parse_progress(line: &str) -> Option<(usize, usize, &str)> {
    let rest = line.strip_prefix("step_export: ")?;
    let (count, name) = rest.split_once(' ')?;
    let (i, n) = count.split_once('/')?;
    Some((i.parse().ok()?, n.parse().ok()?, name))
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        let m: HashMap<&str, &str> = pairs.iter().copied().collect();
        move |k| m.get(k).map(OsString::from)
    }

    fn reason(r: Result<(PathBuf, String), ExportError>) -> String {
        match r {
            Err(ExportError::StepUnavailable { reason }) => reason,
            other => panic!("expected StepUnavailable, got {other:?}"),
        }
    }

    /// An executable file and a plain one in a fresh directory.
    fn files() -> (tempfile::TempDir, PathBuf, PathBuf) {
        use std::os::unix::fs::PermissionsExt as _;
        let t = tempfile::tempdir().unwrap();
        let exe = t.path().join("python");
        std::fs::write(&exe, "#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
        let plain = t.path().join("plain");
        std::fs::write(&plain, "").unwrap();
        std::fs::set_permissions(&plain, std::fs::Permissions::from_mode(0o644)).unwrap();
        (t, exe, plain)
    }

    #[test]
    fn the_variable_wins_and_bad_values_name_it_its_value_and_the_rule() {
        let (t, exe, plain) = files();
        let exe_s = exe.to_str().unwrap();
        let (p, how) =
            locate_python(&env(&[(PYTHON_VAR, exe_s), ("HOME", "/nonexistent")])).unwrap();
        assert_eq!(p, exe);
        assert_eq!(how, format!("FABKIT_CADQUERY_PYTHON={exe_s}"));
        let dir = t.path().to_str().unwrap();
        for (value, why) in [
            ("/nonexistent/python", "no such file"),
            (plain.to_str().unwrap(), "not executable"),
            (dir, "not a file"),
            (
                "no-such-python-anywhere",
                "no executable of that name on PATH",
            ),
        ] {
            let r = reason(locate_python(&env(&[(PYTHON_VAR, value), ("PATH", dir)])));
            assert!(
                r.starts_with(&format!("FABKIT_CADQUERY_PYTHON={value}: {why}"))
                    && r.contains("it must name an executable Python with CadQuery"),
                "{value}: {r}"
            );
        }
        // a bare name is looked up on PATH (absolute entries only)
        let (p, _) = locate_python(&env(&[
            (PYTHON_VAR, "python"),
            ("PATH", &format!("rel:{dir}")),
        ]))
        .unwrap();
        assert_eq!(p, exe);
    }

    #[test]
    fn the_default_is_in_the_xdg_data_home_and_a_relative_one_is_ignored() {
        let (t, exe, _) = files();
        let data = t.path().join("data");
        let py = data.join(DATA_HOME_PYTHON);
        std::fs::create_dir_all(py.parent().unwrap()).unwrap();
        std::fs::copy(&exe, &py).unwrap();
        let data_s = data.to_str().unwrap();
        // XDG_DATA_HOME absolute: used; an empty FABKIT_CADQUERY_PYTHON counts as unset
        let (p, _) = locate_python(&env(&[
            ("XDG_DATA_HOME", data_s),
            (PYTHON_VAR, ""),
            ("HOME", "/nonexistent"),
        ]))
        .unwrap();
        assert_eq!(p, py);
        // unset: $HOME/.local/share
        let home = t.path().join("home");
        let home_py = home.join(".local/share").join(DATA_HOME_PYTHON);
        std::fs::create_dir_all(home_py.parent().unwrap()).unwrap();
        std::fs::copy(&exe, &home_py).unwrap();
        let home_s = home.to_str().unwrap();
        let (p, _) = locate_python(&env(&[("HOME", home_s)])).unwrap();
        assert_eq!(p, home_py);
        // relative: ignored, and said so when nothing is found
        let (p, _) = locate_python(&env(&[("HOME", home_s), ("XDG_DATA_HOME", "data")])).unwrap();
        assert_eq!(p, home_py);
        let r = reason(locate_python(&env(&[
            ("HOME", "/nonexistent"),
            ("XDG_DATA_HOME", "data"),
        ])));
        assert!(
            r.starts_with("/nonexistent/.local/share/fabkit/venv-cadquery/bin/python: no CadQuery Python there")
                && r.contains("FABKIT_CADQUERY_PYTHON is not set")
                && r.contains("XDG_DATA_HOME=data is ignored"),
            "{r}"
        );
        let r = reason(locate_python(&env(&[("HOME", "relative")])));
        assert!(
            r.contains("without an absolute XDG_DATA_HOME or HOME"),
            "{r}"
        );
    }

    /// A stand-in for the CadQuery Python: a shell script that ignores its arguments.
    fn fake_python(dir: &Path, script: &str) -> PathBuf {
        use std::os::unix::fs::PermissionsExt as _;
        let p = dir.join("python");
        std::fs::write(&p, format!("#!/bin/sh\n{script}")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        p
    }

    #[test]
    fn progress_is_passed_on_and_a_failure_names_its_part() {
        let t = tempfile::tempdir().unwrap();
        let seen = std::cell::RefCell::new(Vec::new());
        let record =
            |i: usize, n: usize, name: &str| seen.borrow_mut().push(format!("{i}/{n} {name}"));
        // the twin names the failing part in its last line
        let py = fake_python(
            t.path(),
            "echo 'step_export: 1/2 a' >&2\necho 'step_export: 2/2 b' >&2\n\
             echo 'step_export: part b: ValueError: off' >&2\nexit 3\n",
        );
        match render_with(&py, "test", &[], &[], None, 0.01, Some(&record)) {
            Err(ExportError::Step { part, reason }) => {
                assert_eq!(part, "b");
                assert_eq!(reason, "step_export: part b: ValueError: off");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(*seen.borrow(), ["1/2 a", "2/2 b"]);
        // a crash without a message: the part it was building
        let py = fake_python(t.path(), "echo 'step_export: 1/2 a' >&2\nkill -9 $$\n");
        match render_with(&py, "test", &[], &[], None, 0.01, None) {
            Err(ExportError::Step { part, reason }) => {
                assert_eq!(part, "a");
                assert!(reason.contains("without a message"), "{reason}");
            }
            other => panic!("{other:?}"),
        }
        // an assembly member is named as such
        let py = fake_python(
            t.path(),
            "echo 'step_export: 1/1 a' >&2\necho 'step_export: member gel' >&2\n\
             echo 'step_export: member gel: ValueError: off' >&2\nexit 3\n",
        );
        match render_with(&py, "test", &[], &[], None, 0.01, None) {
            Err(ExportError::StepAssembly { member, reason }) => {
                assert_eq!(member, "gel");
                assert_eq!(reason, "step_export: member gel: ValueError: off");
            }
            other => panic!("{other:?}"),
        }
        // exit status 4: no cadquery there
        let py = fake_python(t.path(), "exit 4\n");
        match render_with(&py, "FABKIT_CADQUERY_PYTHON=x", &[], &[], None, 0.01, None) {
            Err(ExportError::StepUnavailable { reason }) => {
                assert!(
                    reason.ends_with("cannot import cadquery (FABKIT_CADQUERY_PYTHON=x)"),
                    "{reason}"
                );
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn progress_lines_are_parsed_and_others_are_not() {
        assert_eq!(
            parse_progress("step_export: 3/8 skin_mold_top"),
            Some((3, 8, "skin_mold_top"))
        );
        assert_eq!(parse_progress("step_export: part a: ValueError: x"), None);
        assert_eq!(parse_progress("Traceback (most recent call last):"), None);
    }
}
