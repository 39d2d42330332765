//! The pins of a pin dome as the ground-truth caster's solids: what a capture of the dome
//! presses into the skin (R-Tac0 Sec. IV-A, Fig. 5: the pin dome's pins, each pressed to its
//! indentation depth by the dome). Read from the output folder of `fabkit fixtures`.

use std::path::Path;

use crate::groundtruth::exact::ExactPrimitives;
use crate::groundtruth::inputs::{json, read_with_hash, Configuration, Fixtures, InputError};
use crate::groundtruth::surface::ReferenceSurface;
use fabkit_designs::primitives::Geometry;

/// A calibration pin of the pin dome as solids for the ground-truth caster: its hemispherical
/// tip of `tip_radius_mm` whose lowest point is `tip_mm`, the 45 deg cone to the shaft (when
/// the shaft is wider), and the shaft of `shaft_radius_mm` up to `length_mm` from the tip,
/// along `axis` (unit, from the tip towards the head; the point table's `axis`). The profile of
/// `fixtures`' pin solid (pindome.rs `pin_solid_of`), the head left out (it never reaches the
/// skin). The cone, whose apex is the tip, lies inside the hemisphere below the tip's centre.
pub fn pin_primitives(
    tip_mm: [f64; 3],
    axis: [f64; 3],
    tip_radius_mm: f64,
    shaft_radius_mm: f64,
    length_mm: f64,
) -> Vec<fabkit_designs::primitives::Primitive> {
    use fabkit_designs::primitives::Primitive;
    let at = |h: f64| -> [f64; 3] { std::array::from_fn(|k| tip_mm[k] + h * axis[k]) };
    let (rt, rs) = (tip_radius_mm, shaft_radius_mm.max(tip_radius_mm));
    let mut out = vec![Primitive::Sphere {
        centre_mm: at(rt),
        radius_mm: rt,
    }];
    if rs > rt {
        out.push(Primitive::Cone {
            apex_mm: tip_mm,
            base_mm: at(rs),
            base_radius_mm: rs,
        });
    }
    let from = if rs > rt { rs } else { rt };
    if length_mm > from {
        out.push(Primitive::Cylinder {
            base_mm: at(from),
            top_mm: at(length_mm),
            radius_mm: rs,
        });
    }
    out
}

/// The pins of a pin dome as `fabkit fixtures` wrote them: each pin's id with its tip and
/// axis (points/point_table.csv) and the pin's shape (the `pin` part of manifest.json).
#[derive(Debug, Clone, PartialEq)]
pub struct Pins {
    /// (id, tip mm, unit axis from the tip towards the head), sensor frame, in file order.
    pub rows: Vec<(String, [f64; 3], [f64; 3])>,
    pub tip_radius_mm: f64,
    pub shaft_radius_mm: f64,
    /// From the tip to the head's underside, mm.
    pub length_mm: f64,
}

impl Pins {
    /// The solids of the pins `ids` ([`pin_primitives`]).
    ///
    /// # Errors
    /// The first id that is not in the table.
    pub fn primitives(
        &self,
        ids: &[String],
    ) -> Result<Vec<fabkit_designs::primitives::Primitive>, String> {
        let mut out = Vec::new();
        for id in ids {
            let (_, tip, axis) = self
                .rows
                .iter()
                .find(|r| &r.0 == id)
                .ok_or_else(|| id.clone())?;
            out.extend(pin_primitives(
                *tip,
                *axis,
                self.tip_radius_mm,
                self.shaft_radius_mm,
                self.length_mm,
            ));
        }
        Ok(out)
    }

    /// The pins moved by `motion` (sensor frame): each tip moved, each axis turned.
    pub fn moved(&self, motion: &nalgebra::Isometry3<f64>) -> Pins {
        let rows = self
            .rows
            .iter()
            .map(|(id, tip, axis)| {
                let t = motion * nalgebra::Point3::from(*tip);
                let a = motion.rotation * nalgebra::Vector3::from(*axis);
                (id.clone(), [t.x, t.y, t.z], [a.x, a.y, a.z])
            })
            .collect();
        Pins {
            rows,
            ..self.clone()
        }
    }

    /// The mean of the pins' tips, sensor frame, mm (the origin for no pin).
    pub fn mean_tip_mm(&self) -> [f64; 3] {
        let n = self.rows.len().max(1) as f64;
        std::array::from_fn(|k| self.rows.iter().map(|r| r.1[k]).sum::<f64>() / n)
    }
}

#[derive(serde::Deserialize)]
struct FixturesManifest {
    parts: Vec<ManifestPart>,
}

#[derive(serde::Deserialize)]
struct ManifestPart {
    name: String,
    #[serde(default)]
    params: serde_json::Value,
}

/// Reads the pins of the fixtures folder `dir`: points/point_table.csv (columns `id`,
/// `tip_x_mm`, `tip_y_mm`, `tip_z_mm`, `axis_x`, `axis_y`, `axis_z`, any order, others
/// ignored) and the `pin` part's `params.pin` (`tip_radius_mm`, `shaft_diameter_mm`) and
/// `params.length_mm` in manifest.json.
///
/// # Errors
/// [`InputError`] naming the file, the line or field, the value and the rule: a missing
/// column, a number that does not parse or is not finite, an axis that is not a unit vector
/// (to 1e-6), a repeated id, no pin part, a pin size that is missing or not above 0.
pub fn read_pins(dir: &std::path::Path) -> Result<Pins, InputError> {
    let (table, _) = CsvTable::read(&dir.join("points").join("point_table.csv"))?;
    let field = |f: String, value: String, rule: &str| table.error(f, value, rule);
    let header = &table.header;
    let id_col = table.col("id")?;
    let cols: Vec<usize> = [
        "tip_x_mm", "tip_y_mm", "tip_z_mm", "axis_x", "axis_y", "axis_z",
    ]
    .iter()
    .map(|c| table.col(c))
    .collect::<Result<_, _>>()?;
    let mut rows: Vec<(String, [f64; 3], [f64; 3])> = Vec::new();
    for (k, cells) in &table.rows {
        let k = *k;
        let at = |c: usize| cells.get(c).map_or("", String::as_str);
        let id = at(id_col).to_string();
        let mut v = [0.0; 6];
        for (j, &c) in cols.iter().enumerate() {
            v[j] = at(c)
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    field(
                        format!("line {} {}", k + 1, header[c]),
                        format!("{:?}", at(c)),
                        "must be a finite number",
                    )
                })?;
        }
        // the design's bounds on a length (fabkit_designs::values), as the fixtures were built
        let max = fabkit_designs::values::MAX_LENGTH_MM;
        if let Some(j) = (0..3).find(|&j| v[j].abs() > max) {
            return Err(field(
                format!("line {} {}", k + 1, header[cols[j]]),
                format!("{:e}", v[j]),
                &format!("must be within +-{max} mm (a pin tip of the sensor's pin dome)"),
            ));
        }
        let axis = [v[3], v[4], v[5]];
        if ((axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt() - 1.0).abs() > 1e-6 {
            return Err(field(
                format!("line {} axis", k + 1),
                format!("{axis:?}"),
                "must be a unit vector (to 1e-6)",
            ));
        }
        if rows.iter().any(|r| r.0 == id) {
            return Err(field(format!("line {} id", k + 1), id, "is given twice"));
        }
        rows.push((id, [v[0], v[1], v[2]], axis));
    }
    let manifest = dir.join("manifest.json");
    let (bytes, _) = read_with_hash(&manifest)?;
    let m: FixturesManifest = json(&bytes, &manifest)?;
    let mfile = manifest.display().to_string();
    let part = m.parts.iter().find(|p| p.name == "pin").ok_or_else(|| InputError::Field {
        file: mfile.clone(),
        field: "parts".into(),
        value: "(no part named pin)".into(),
        rule: "must list the pin dome's pin (hint: pass the output folder of `fabkit fixtures` with a pin dome)".into(),
    })?;
    let size = |path: &[&str]| -> Result<f64, InputError> {
        let v = path.iter().fold(&part.params, |v, k| &v[*k]);
        let (lo, hi) = (
            fabkit_designs::values::MIN_LENGTH_MM,
            fabkit_designs::values::MAX_LENGTH_MM,
        );
        v.as_f64()
            .filter(|x| (lo..=hi).contains(x))
            .ok_or_else(|| InputError::Field {
                file: mfile.clone(),
                field: format!("parts[pin].params.{}", path.join(".")),
                value: v.to_string(),
                rule: format!("must be a length from {lo} to {hi} mm (the design's bounds)"),
            })
    };
    Ok(Pins {
        rows,
        tip_radius_mm: size(&["pin", "tip_radius_mm"])?,
        shaft_radius_mm: size(&["pin", "shaft_diameter_mm"])? / 2.0,
        length_mm: size(&["length_mm"])?,
    })
}

/// A CSV file of `fabkit fixtures`' points/ folder: its header and its rows, cells trimmed,
/// blank lines left out, a leading byte-order mark ignored.
struct CsvTable {
    file: String,
    header: Vec<String>,
    /// (0-based line index, cells)
    rows: Vec<(usize, Vec<String>)>,
}

impl CsvTable {
    /// The table in `path` and the file's sha256.
    fn read(path: &Path) -> Result<(CsvTable, String), InputError> {
        let (bytes, sha) = read_with_hash(path)?;
        let text = String::from_utf8_lossy(&bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let cells = |l: &str| l.split(',').map(|c| c.trim().to_string()).collect();
        let mut lines = text.lines().enumerate();
        let header = lines.next().map(|(_, l)| cells(l)).unwrap_or_default();
        let rows = lines
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(k, l)| (k, cells(l)))
            .collect();
        let file = path.display().to_string();
        Ok((CsvTable { file, header, rows }, sha))
    }

    /// The index of column `name`, or the error naming the header.
    fn col(&self, name: &str) -> Result<usize, InputError> {
        self.header.iter().position(|h| h == name).ok_or_else(|| {
            self.error(
                "header".into(),
                self.header.join(","),
                &format!("has no column {name}"),
            )
        })
    }

    fn error(&self, field: String, value: String, rule: &str) -> InputError {
        InputError::Field {
            file: self.file.clone(),
            field,
            value,
            rule: rule.to_string(),
        }
    }
}

/// The name of a pin capture: its pins' ids in the given order joined by `_`, numeric ids
/// with two digits (`01_02_06_14_22`), the file names `fabkit calibrate images` and
/// `fabkit calibrate photometric` read a capture's pins from (the R-Tac0 authors' convention).
pub fn capture_name(ids: &[String]) -> String {
    ids.iter()
        .map(|id| match id.parse::<u32>() {
            Ok(n) => format!("{n:02}"),
            Err(_) => id.clone(),
        })
        .collect::<Vec<_>>()
        .join("_")
}

/// The captures of the pin dome in the fixtures folder `dir` as ground-truth configurations:
/// one per capture of points/capture_plan.csv (columns `capture`, `id`, any order, others
/// ignored; rows of one capture together), its planned pins pressed in ([`read_pins`]: tips
/// and axes from the point table, the pin's shape from manifest.json). Each configuration is
/// named by its pins ([`capture_name`]), at orientation 0, its description file
/// `points/capture_plan.csv`; the folder's `patterns` is empty.
///
/// # Errors
/// [`InputError`] naming the file, the line and the rule: what [`read_pins`] refuses, a point
/// table made for another design than `design_name` (its provenance names the design), a
/// missing column, a capture number that does not parse, a capture whose rows are apart, a pin
/// the point table does not have, a pin twice in one capture, a plan with no capture, or pins
/// whose solids the caster refuses.
pub fn read_pin_captures(dir: &Path, design_name: &str) -> Result<Fixtures, InputError> {
    let pins = read_pins(dir)?;
    check_made_for(dir, design_name)?;
    read_plan(dir, pins)
}

/// Refuses a pin dome made for another design than `design_name`: its point table's
/// provenance (`points/point_table.json`) names the design it was built from.
///
/// # Errors
/// [`InputError::Field`] naming the file, its provenance and the design.
pub fn check_made_for(dir: &Path, design_name: &str) -> Result<(), InputError> {
    let table_json = dir.join("points").join("point_table.json");
    if let Ok((bytes, _)) = read_with_hash(&table_json) {
        let t: serde_json::Value = json(&bytes, &table_json)?;
        let provenance = t["provenance"].as_str().unwrap_or("");
        if let Some(rest) = provenance.split("design ").nth(1) {
            let made_for = rest.split_whitespace().next().unwrap_or("");
            if made_for != design_name {
                return Err(InputError::Field {
                    file: table_json.display().to_string(),
                    field: "provenance".into(),
                    value: provenance.into(),
                    rule: format!("the pin dome was made for another design than '{design_name}' (hint: pass the design the fixtures were built from)"),
                });
            }
        }
    }
    Ok(())
}

/// How far (mm) a pin's recorded contact point may lie from the design's skin: the point
/// table is written to 1e-9 mm from the same closed-form surface, so anything above a micron
/// is another geometry.
pub const CONTACT_TOLERANCE_MM: f64 = 1e-3;

/// Refuses a pin dome built for another skin than `surface` (the design's reference surface,
/// sensor frame, mm), whatever its name: each pin of points/point_table.csv whose row gives
/// its contact point (`contact_x_mm`, `contact_y_mm`, `contact_z_mm`: where the hole axis
/// meets the undeformed surface) must have its tip inside the skin and that point on it,
/// within [`CONTACT_TOLERANCE_MM`] of where its axis leaves `surface`. A table without the
/// contact columns is not checked (read_pins does not need them).
///
/// # Errors
/// [`InputError::Field`] naming the file, the pin's line and the distance from the skin.
pub fn check_on_skin(
    dir: &Path,
    pins: &Pins,
    surface: &ReferenceSurface,
) -> Result<(), InputError> {
    let (table, _) = CsvTable::read(&dir.join("points").join("point_table.csv"))?;
    let cols: Vec<usize> = ["contact_x_mm", "contact_y_mm", "contact_z_mm"]
        .iter()
        .filter_map(|c| table.header.iter().position(|h| h == c))
        .collect();
    let Ok(id_col) = table.col("id") else {
        return Ok(());
    };
    if cols.len() != 3 {
        return Ok(());
    }
    let hint = "the pin dome was built for another skin than this design's (hint: pass the design the fixtures were built from, or build the fixtures again from this one)";
    for (k, cells) in &table.rows {
        let at = |c: usize| cells.get(c).map_or("", String::as_str);
        let Some((_, tip, axis)) = pins.rows.iter().find(|r| r.0 == at(id_col)) else {
            continue;
        };
        let contact: Vec<f64> = cols.iter().filter_map(|&c| at(c).parse().ok()).collect();
        let field = format!("line {} contact_mm", k + 1);
        let value = format!("{contact:?}");
        if contact.len() != 3 || contact.iter().any(|x: &f64| !x.is_finite()) {
            return Err(table.error(field, value, "must be three finite numbers"));
        }
        if !surface.contains(*tip, 0.0) {
            return Err(table.error(
                field,
                value,
                &format!(
                    "pin {}'s tip {tip:?} lies outside the design's skin: {hint}",
                    at(id_col)
                ),
            ));
        }
        let Some(exit) = surface.exit(*tip, *axis) else {
            continue;
        };
        let on = std::array::from_fn::<f64, 3, _>(|j| tip[j] + exit.t_mm * axis[j]);
        let off = (0..3)
            .map(|j| (on[j] - contact[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        if !(off <= CONTACT_TOLERANCE_MM) {
            return Err(table.error(
                field,
                value,
                &format!(
                    "lies {off:.4} mm from where pin {}'s axis meets the design's skin ({:.4}, {:.4}, {:.4}), more than {CONTACT_TOLERANCE_MM} mm: {hint}",
                    at(id_col), on[0], on[1], on[2]
                ),
            ));
        }
    }
    Ok(())
}

/// The pin captures of `points/capture_plan.csv` with the pins `pins` of the point table.
fn read_plan(dir: &Path, pins: Pins) -> Result<Fixtures, InputError> {
    let (table, sha) = CsvTable::read(&dir.join("points").join("capture_plan.csv"))?;
    let file = table.file.clone();
    let field = |f: String, value: String, rule: &str| table.error(f, value, rule);
    let (capture_col, id_col) = (table.col("capture")?, table.col("id")?);
    let mut captures: Vec<(String, Vec<String>)> = Vec::new();
    for (k, cells) in &table.rows {
        let k = *k;
        let at = |c: usize| cells.get(c).cloned().unwrap_or_default();
        let (capture, id) = (at(capture_col), at(id_col));
        if capture.parse::<u32>().is_err() {
            return Err(field(
                format!("line {} capture", k + 1),
                format!("{capture:?}"),
                "must be a whole number",
            ));
        }
        if !pins.rows.iter().any(|r| r.0 == id) {
            return Err(field(
                format!("line {} id", k + 1),
                format!("{id:?}"),
                "must be a pin of points/point_table.csv",
            ));
        }
        match captures.last_mut() {
            Some((c, ids)) if *c == capture => {
                if ids.contains(&id) {
                    return Err(field(
                        format!("line {} id", k + 1),
                        id,
                        "is in this capture twice",
                    ));
                }
                ids.push(id);
            }
            _ => {
                if captures.iter().any(|(c, _)| *c == capture) {
                    return Err(field(
                        format!("line {} capture", k + 1),
                        capture,
                        "must have its rows together",
                    ));
                }
                captures.push((capture, vec![id]));
            }
        }
    }
    if captures.is_empty() {
        return Err(field(
            "rows".into(),
            "(none)".into(),
            "must plan at least one capture",
        ));
    }
    // two captures of the same pins would write one folder twice (its name is its pins)
    for (k, (capture, ids)) in captures.iter().enumerate() {
        let mut sorted = ids.clone();
        sorted.sort();
        if let Some((first, _)) = captures[..k].iter().find(|(_, other)| {
            let mut o = other.clone();
            o.sort();
            o == sorted
        }) {
            return Err(field(
                format!("capture {capture}"),
                capture_name(ids),
                &format!("presses the same pins as capture {first}: plan each capture once"),
            ));
        }
    }
    let mut configurations = Vec::new();
    for (capture, ids) in captures {
        let primitives = pins
            .primitives(&ids)
            .expect("ids checked against the table");
        let name = capture_name(&ids);
        let exact = ExactPrimitives::new(&primitives).map_err(|source| InputError::Field {
            file: file.clone(),
            field: format!("capture {capture}"),
            value: name.clone(),
            rule: format!("its pins' solids are not usable: {source}"),
        })?;
        configurations.push(Configuration {
            pattern: name.clone(),
            orientation_deg: 0,
            name,
            description_file: "points/capture_plan.csv".into(),
            description_sha256: sha.clone(),
            geometry: Geometry {
                frame: "sensor".into(),
                primitives,
            },
            primitives: exact,
            pins: ids,
        });
    }
    Ok(Fixtures {
        dir: dir.to_path_buf(),
        index_sha256: sha,
        patterns: Vec::new(),
        configurations,
    })
}
