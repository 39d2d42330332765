//! The inputs of `fabkit groundtruth`: the extrinsics of `fabkit calibrate extrinsics`
//! (`extrinsics.json`) and the protrusion descriptions of `fabkit fixtures`
//! (`protrusions/index.json`, `protrusions/<pattern>.json`). The file formats are the
//! interface; nothing here depends on the fixtures crate.

use std::path::{Path, PathBuf};

use fabkit_designs::primitives::Geometry;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use sha2::{Digest, Sha256};

use super::exact::{ExactPrimitives, PrimitiveError};

/// An input of `fabkit groundtruth` that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}:{column}: {message}")]
    Json {
        file: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{file}: {field} = {value}: {rule}")]
    Field {
        file: String,
        field: String,
        value: String,
        rule: String,
    },
    #[error("{file}: orientation {orientation_deg} deg, {source}")]
    Primitive {
        file: String,
        orientation_deg: u32,
        #[source]
        source: PrimitiveError,
    },
}

/// A file's bytes and sha256 (hex).
pub fn read_with_hash(path: &Path) -> Result<(Vec<u8>, String), InputError> {
    let bytes = crate::read_binary(path).map_err(|source| InputError::Io {
        file: path.display().to_string(),
        source,
    })?;
    let sha = sha256_hex(&bytes);
    Ok((bytes, sha))
}

/// sha256 of `bytes` as 64 lowercase hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A JSON input file; a leading UTF-8 byte order mark (an editor's "UTF-8 with BOM") is
/// skipped, as the CSV readers skip it.
pub(crate) fn json<T: for<'de> Deserialize<'de>>(
    bytes: &[u8],
    file: &Path,
) -> Result<T, InputError> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    serde_json::from_slice(bytes).map_err(|e| InputError::Json {
        file: file.display().to_string(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })
}

#[derive(Deserialize)]
struct ExtrinsicsFile {
    #[serde(rename = "T_cam_sensor")]
    t_cam_sensor: Option<[[f64; 4]; 4]>,
    rvec: Option<[f64; 3]>,
    tvec_mm: Option<[f64; 3]>,
}

/// Reads `T_cam_sensor` from an `extrinsics.json` of `fabkit calibrate extrinsics` (the 4 x 4
/// `T_cam_sensor`, or `rvec` (radians, OpenCV) and `tvec_mm`; when both are given they must
/// agree to 1e-6). Returns the transform and the file's sha256.
///
/// # Errors
/// [`InputError`] naming the file and the field: unreadable, not JSON (line:column), neither
/// form present, non-finite numbers, a matrix whose rotation is not orthonormal with
/// determinant +1 (to 1e-6) or whose last row is not `[0, 0, 0, 1]`, or forms that disagree.
pub fn read_extrinsics(path: &Path) -> Result<(Isometry3<f64>, String), InputError> {
    let (bytes, sha) = read_with_hash(path)?;
    let e: ExtrinsicsFile = json(&bytes, path)?;
    let file = path.display().to_string();
    let field = |field: &str, value: String, rule: &str| InputError::Field {
        file: file.clone(),
        field: field.into(),
        value,
        rule: rule.into(),
    };
    let from_matrix = match e.t_cam_sensor {
        Some(m) => Some(isometry_of(&m).map_err(|(f, v, rule)| field(&f, v, rule))?),
        None => None,
    };
    let from_vecs = match (e.rvec, e.tvec_mm) {
        (Some(r), Some(t)) => {
            if r.iter().chain(&t).any(|v| !v.is_finite()) {
                return Err(field(
                    "rvec, tvec_mm",
                    format!("{r:?}, {t:?}"),
                    "must be finite",
                ));
            }
            Some(Isometry3::from_parts(
                Translation3::new(t[0], t[1], t[2]),
                UnitQuaternion::from_scaled_axis(Vector3::new(r[0], r[1], r[2])),
            ))
        }
        _ => None,
    };
    match (from_matrix, from_vecs) {
        (Some(a), Some(b)) => {
            let dr = a.rotation.angle_to(&b.rotation);
            let dt = (a.translation.vector - b.translation.vector).norm();
            if dr > 1e-6 || dt > 1e-6 {
                return Err(field(
                    "T_cam_sensor",
                    format!("differs from rvec/tvec_mm by {dr:.3e} rad, {dt:.3e} mm"),
                    "the two forms must agree (to 1e-6)",
                ));
            }
            Ok((a, sha))
        }
        (Some(a), None) | (None, Some(a)) => Ok((a, sha)),
        (None, None) => Err(field(
            "T_cam_sensor",
            "missing".into(),
            "give the 4 x 4 T_cam_sensor or rvec and tvec_mm (what `fabkit calibrate extrinsics` writes)",
        )),
    }
}

/// The optical path an extrinsics file was solved through (`optical_path` of `fabkit calibrate
/// extrinsics --design`, its gel surface as `optical_path_fit` refined it): the layers, air
/// under the lowest plane, then its curved faces (`optical_path.shells`), and the planes and
/// faces as used (z_mm, index_above, what; the shells' fields) for a manifest.
/// `None` when the file has none (straight rays).
///
/// # Errors
/// [`InputError`] naming the file and the field of a plane that is not a number or of layers
/// that are not valid ([`crate::refraction::OpticalLayers::new`]).
pub fn read_optical_path(
    path: &Path,
) -> Result<Option<(crate::refraction::OpticalLayers, serde_json::Value)>, InputError> {
    let (bytes, _) = read_with_hash(path)?;
    let v: serde_json::Value = json(&bytes, path)?;
    let Some(planes) = v.get("optical_path").and_then(|p| p.get("planes")) else {
        return Ok(None);
    };
    let file = path.display().to_string();
    let bad = |field: String, value: String, rule: &str| InputError::Field {
        file: file.clone(),
        field,
        value,
        rule: rule.into(),
    };
    // the number at `key` of the entry `at` (`planes[k]`, `shells[k]`) of optical_path
    let number = |entry: &serde_json::Value, at: &str, key: &str| {
        entry
            .get(key)
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| {
                bad(
                    format!("optical_path.{at}.{key}"),
                    entry.get(key).map_or("missing".into(), |x| x.to_string()),
                    "must be a number",
                )
            })
    };
    let fit = v.get("optical_path_fit");
    let mut used = Vec::new();
    for (k, p) in planes.as_array().into_iter().flatten().enumerate() {
        let num = |key: &str| number(p, &format!("planes[{k}]"), key);
        let what = p.get("what").and_then(|w| w.as_str()).unwrap_or("");
        let (mut z, mut n) = (num("z_mm")?, num("index_above")?);
        if let Some(f) = fit.filter(|f| f.get("plane").and_then(|w| w.as_str()) == Some(what)) {
            let g = |key: &str| f.get(key).and_then(serde_json::Value::as_f64);
            if let (Some(fz), Some(fn_)) = (g("height_mm"), g("index")) {
                (z, n) = (fz, fn_);
            }
        }
        used.push((z, n, what.to_string()));
    }
    let shells_json = v
        .get("optical_path")
        .and_then(|p| p.get("shells"))
        .and_then(serde_json::Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut shells = Vec::new();
    for (k, s) in shells_json.iter().enumerate() {
        let num = |key: &str| number(s, &format!("shells[{k}]"), key);
        shells.push(crate::refraction::Shell {
            radius_mm: num("radius_mm")?,
            centre_z_mm: num("centre_z_mm")?,
            join_z_mm: num("join_z_mm")?,
            bottom_z_mm: num("bottom_z_mm")?,
            index_outside: num("index_outside")?,
            outside_bottom_z_mm: num("outside_bottom_z_mm")?,
        });
    }
    let mut indices = vec![1.0];
    indices.extend(used.iter().map(|u| u.1));
    let layers = crate::refraction::OpticalLayers::new(used.iter().map(|u| u.0).collect(), indices)
        .and_then(|l| l.with_shells(shells))
        .map_err(|e| bad(format!("optical_path.{}", e.field), e.value, e.rule))?;
    let mut summary = serde_json::json!({
        "from": file,
        "planes": used.iter().map(|(z, n, what)| serde_json::json!({"z_mm": z, "index_above": n, "what": what})).collect::<Vec<_>>(),
    });
    if !shells_json.is_empty() {
        summary["shells"] = shells_json
            .iter()
            .map(|s| {
                let mut o = serde_json::Map::new();
                for key in [
                    "radius_mm",
                    "centre_z_mm",
                    "join_z_mm",
                    "bottom_z_mm",
                    "outside_bottom_z_mm",
                    "index_outside",
                    "what",
                ] {
                    if let Some(x) = s.get(key) {
                        o.insert(key.into(), x.clone());
                    }
                }
                serde_json::Value::Object(o)
            })
            .collect();
    }
    Ok(Some((layers, summary)))
}

/// The rigid transform of a 4 x 4 matrix `m` (rows), such as `T_cam_sensor`.
///
/// # Errors
/// (field, value, rule): a non-finite entry, a last row other than `[0, 0, 0, 1]`, or a 3 x 3
/// block that is not a rotation (orthonormal, determinant +1, to 1e-6).
pub fn isometry_of(m: &[[f64; 4]; 4]) -> Result<Isometry3<f64>, (String, String, &'static str)> {
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(("T_cam_sensor".into(), format!("{m:?}"), "must be finite"));
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err((
            "T_cam_sensor[3]".into(),
            format!("{:?}", m[3]),
            "must be [0, 0, 0, 1]",
        ));
    }
    let r = Matrix3::from_fn(|i, j| m[i][j]);
    let err = (r.transpose() * r - Matrix3::identity()).abs().max();
    if err > 1e-6 || (r.determinant() - 1.0).abs() > 1e-6 {
        return Err((
            "T_cam_sensor".into(),
            format!("{m:?}"),
            "the 3 x 3 block must be a rotation (orthonormal, determinant +1, to 1e-6)",
        ));
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Ok(Isometry3::from_parts(
        Translation3::new(m[0][3], m[1][3], m[2][3]),
        rot,
    ))
}

#[derive(Deserialize)]
struct IndexFile {
    patterns: Vec<IndexEntry>,
}

#[derive(Deserialize)]
struct IndexEntry {
    pattern: String,
    file: String,
}

#[derive(Deserialize)]
struct PatternFile {
    pattern: String,
    design: String,
    orientations: Vec<OrientationEntry>,
}

#[derive(Deserialize)]
struct OrientationEntry {
    orientation_deg: u32,
    geometry: Geometry,
}

/// One semi-dome configuration: a pattern at orientation 0 (pattern half on +x) or 180 deg
/// (turned about the sensor axis, pattern on -x).
#[derive(Debug, Clone)]
pub struct Configuration {
    pub pattern: String,
    pub orientation_deg: u32,
    /// Output folder name, `<pattern>_<orientation_deg>`.
    pub name: String,
    /// The description file, relative to the fixtures folder (`protrusions/<pattern>.json`).
    pub description_file: String,
    pub description_sha256: String,
    /// The primitives (sensor frame, mm) as described.
    pub geometry: Geometry,
    pub primitives: ExactPrimitives,
    /// A pin dome's capture ([`crate::groundtruth::pins::read_pin_captures`]): the ids of the
    /// pins pressed in, in the capture plan's order; empty for a protrusion pattern.
    pub pins: Vec<String>,
}

/// The protrusion descriptions of a fixtures folder.
#[derive(Debug, Clone)]
pub struct Fixtures {
    pub dir: PathBuf,
    /// sha256 of `protrusions/index.json` (of `points/capture_plan.csv` for a pin dome's
    /// captures).
    pub index_sha256: String,
    /// Pattern names in index order (none for a pin dome's captures).
    pub patterns: Vec<String>,
    /// Two per pattern (0 and 180 deg), in index order; or one per capture of a pin dome.
    pub configurations: Vec<Configuration>,
}

/// Reads `DIR/protrusions/index.json` and every pattern file it lists.
///
/// # Errors
/// [`InputError`] naming the file: unreadable, not JSON (line:column), a pattern file of
/// another design than `design_name`, a pattern name that differs from the index or is not
/// `[a-z0-9_]+`, a duplicated pattern, orientations other than exactly 0 and 180, a frame
/// other than `sensor`, or an unusable primitive (index and rule).
pub fn read_fixtures(dir: &Path, design_name: &str) -> Result<Fixtures, InputError> {
    let index_path = dir.join("protrusions").join("index.json");
    let (bytes, index_sha256) = read_with_hash(&index_path)?;
    let index: IndexFile = json(&bytes, &index_path)?;
    let mut patterns = Vec::new();
    let mut configurations = Vec::new();
    for (k, e) in index.patterns.iter().enumerate() {
        let ifile = index_path.display().to_string();
        let bad_name = e.pattern.is_empty()
            || !e
                .pattern
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if bad_name || patterns.contains(&e.pattern) {
            return Err(InputError::Field {
                file: ifile,
                field: format!("patterns[{k}].pattern"),
                value: e.pattern.clone(),
                rule: "must be [a-z0-9_]+ and unique".into(),
            });
        }
        let rel_ok = !e.file.is_empty()
            && !e.file.starts_with('/')
            && e.file.split('/').all(|c| !c.is_empty() && c != "..");
        if !rel_ok {
            return Err(InputError::Field {
                file: ifile,
                field: format!("patterns[{k}].file"),
                value: e.file.clone(),
                rule: "must be a path relative to the fixtures folder".into(),
            });
        }
        let path = e.file.split('/').fold(dir.to_path_buf(), |p, c| p.join(c));
        let (bytes, sha) = read_with_hash(&path)?;
        let pf: PatternFile = json(&bytes, &path)?;
        let file = path.display().to_string();
        let field = |field: &str, value: String, rule: String| InputError::Field {
            file: file.clone(),
            field: field.into(),
            value,
            rule,
        };
        if pf.pattern != e.pattern {
            return Err(field(
                "pattern",
                pf.pattern,
                format!("must be '{}' as in protrusions/index.json", e.pattern),
            ));
        }
        if pf.design != design_name {
            return Err(field(
                "design",
                pf.design,
                format!("the fixtures were made for another design than '{design_name}' (hint: pass the design the fixtures were built from)"),
            ));
        }
        let mut degs: Vec<u32> = pf.orientations.iter().map(|o| o.orientation_deg).collect();
        degs.sort_unstable();
        if degs != [0, 180] {
            return Err(field(
                "orientations",
                format!("{degs:?}"),
                "must hold orientation_deg 0 and 180 once each".into(),
            ));
        }
        for deg in [0, 180] {
            let Some(o) = pf.orientations.iter().find(|o| o.orientation_deg == deg) else {
                continue;
            };
            if o.geometry.frame != "sensor" {
                return Err(field(
                    &format!("orientations[{deg} deg].geometry.frame"),
                    o.geometry.frame.clone(),
                    "must be 'sensor'".into(),
                ));
            }
            let primitives = ExactPrimitives::new(&o.geometry.primitives).map_err(|source| {
                InputError::Primitive {
                    file: file.clone(),
                    orientation_deg: deg,
                    source,
                }
            })?;
            configurations.push(Configuration {
                pattern: e.pattern.clone(),
                orientation_deg: deg,
                name: format!("{}_{deg}", e.pattern),
                description_file: e.file.clone(),
                description_sha256: sha.clone(),
                geometry: o.geometry.clone(),
                primitives,
                pins: Vec::new(),
            });
        }
        patterns.push(e.pattern.clone());
    }
    Ok(Fixtures {
        dir: dir.to_path_buf(),
        index_sha256,
        patterns,
        configurations,
    })
}

/// What `pairs.csv` holds: the `notes` of its entry in the ground truth's manifest.
pub const PAIRS_NOTES: &str = "stitched pairs: depth = right_dir/* on right_mask.png, left_dir/* on left_mask.png (R-Tac0 Sec. IV-B)";

/// `pairs.csv`: every stitched left/right pair (R-Tac0 Sec. IV-B, Fig. 6 right): the right
/// (+x) half of `<right_pattern>_0` (pattern on +x, empty half on -x) with the left (-x) half
/// of `<left_pattern>_180` (pattern on -x). N patterns give N x N rows, right pattern major.
/// The header row comes first; what the columns mean ([`PAIRS_NOTES`]) is in the manifest's
/// `pairs.csv` entry.
pub fn pairs_csv(patterns: &[String]) -> String {
    let mut s = super::files::PAIRS_HEADER.join(",") + "\n";
    let mut k = 0;
    for r in patterns {
        for l in patterns {
            s.push_str(&format!("{k},{r},{r}_0,{l},{l}_180\n"));
            k += 1;
        }
    }
    s
}
