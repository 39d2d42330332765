//! Camera files: OpenCV FileStorage YAML (`%YAML:1.0`, `!!opencv-matrix`), ROS `camera_info`
//! YAML and fabkit's JSON form. Reading detects the form; errors name the file, line and field.
//!
//! Keys (OpenCV and ROS share them): `image_width`, `image_height`, `camera_matrix` (3 x 3,
//! `[fx 0 cx; 0 fy cy; 0 0 1]`, px), `distortion_model` (`fisheye` or `equidistant`, `plumb_bob`,
//! `rational_polynomial`) and `distortion_coefficients` (OpenCV order). A file without
//! `distortion_model` is read as `plumb_bob` for 5 coefficients and `rational_polynomial` for 8
//! (what `cv2.calibrateCamera` writes); 4 coefficients without a model name are refused as
//! ambiguous.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::camera::{CameraModel, Distortion, Intrinsics};

/// A camera file that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CameraFileError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        file: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{file}:{line}: {field} = {value}: {rule}")]
    Field {
        file: String,
        line: usize,
        field: String,
        value: String,
        rule: String,
    },
    #[error("{file}: {field}: missing ({hint})")]
    Missing {
        file: String,
        field: &'static str,
        hint: &'static str,
    },
}

/// The written forms of a camera file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraFileFormat {
    /// OpenCV FileStorage YAML, as `cv::FileStorage` writes it.
    OpenCvYaml,
    /// ROS `camera_info` YAML (camera_calibration_parsers).
    RosYaml,
    /// fabkit's JSON form ([`CameraJson`]).
    Json,
}

/// fabkit's JSON camera file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraJson {
    /// Always `fabkit-camera`.
    pub format: String,
    /// `fisheye`, `plumb_bob` or `rational_polynomial`.
    pub distortion_model: String,
    pub image_width_px: u32,
    pub image_height_px: u32,
    pub fx_px: f64,
    pub fy_px: f64,
    pub cx_px: f64,
    pub cy_px: f64,
    /// OpenCV order: fisheye k1..k4; plumb_bob k1, k2, p1, p2, k3; rational k1, k2, p1, p2, k3..k6.
    pub distortion_coefficients: Vec<f64>,
}

#[derive(Deserialize)]
struct YamlMatrix {
    rows: usize,
    cols: usize,
    #[serde(default)]
    dt: Option<String>,
    data: Vec<f64>,
}

#[derive(Deserialize)]
struct YamlCamera {
    image_width: Option<u32>,
    image_height: Option<u32>,
    camera_matrix: Option<YamlMatrix>,
    distortion_model: Option<String>,
    distortion_coefficients: Option<YamlMatrix>,
}

/// Reads and validates a camera file (form detected from the content).
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field.
pub fn read_camera_file(path: &Path) -> Result<CameraModel, CameraFileError> {
    let file = path.display().to_string();
    let text = crate::read_text(path).map_err(|source| CameraFileError::Io {
        file: file.clone(),
        source,
    })?;
    parse_camera(&text, &file)
}

/// Parses and validates camera-file text; `file` names it in errors.
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field.
pub fn parse_camera(text: &str, file: &str) -> Result<CameraModel, CameraFileError> {
    let intr = if text.trim_start().starts_with('{') {
        parse_json(text, file)?
    } else {
        parse_yaml(text, file)?
    };
    CameraModel::new(intr).map_err(|e| match e {
        crate::camera::CameraError::Invalid { field, value, rule } => CameraFileError::Field {
            file: file.to_string(),
            line: line_of(text, key_of_field(field)),
            field: field.to_string(),
            value,
            rule: rule.to_string(),
        },
        other => CameraFileError::Field {
            file: file.to_string(),
            line: 0,
            field: "camera".into(),
            value: String::new(),
            rule: other.to_string(),
        },
    })
}

fn key_of_field(field: &str) -> &str {
    match field {
        "fx_px" | "fy_px" | "cx_px" | "cy_px" => "camera_matrix",
        f => f,
    }
}

/// 1-based line of the first `key:` (YAML) or `"key"` (JSON) in `text`, or 0.
fn line_of(text: &str, key: &str) -> usize {
    let yaml = format!("{key}:");
    let json = format!("\"{key}\"");
    text.lines()
        .position(|l| {
            let t = l.trim_start();
            t.starts_with(&yaml) || t.starts_with(&json)
        })
        .map_or(0, |i| i + 1)
}

fn parse_json(text: &str, file: &str) -> Result<Intrinsics, CameraFileError> {
    let c: CameraJson = serde_json::from_str(text).map_err(|e| CameraFileError::Syntax {
        file: file.into(),
        line: e.line(),
        column: e.column(),
        message: e
            .to_string()
            .split(" at line ")
            .next()
            .unwrap_or("")
            .to_string(),
    })?;
    let field = |f: &str, v: String, rule: String| CameraFileError::Field {
        file: file.into(),
        line: line_of(text, f),
        field: f.into(),
        value: v,
        rule,
    };
    if c.format != "fabkit-camera" {
        return Err(field(
            "format",
            c.format.clone(),
            "must be \"fabkit-camera\"".into(),
        ));
    }
    let distortion = Distortion::from_name(&c.distortion_model, &c.distortion_coefficients)
        .map_err(|rule| {
            field(
                "distortion_coefficients",
                format!("{:?}", c.distortion_coefficients),
                rule,
            )
        })?;
    Ok(Intrinsics {
        image_width_px: c.image_width_px,
        image_height_px: c.image_height_px,
        fx_px: c.fx_px,
        fy_px: c.fy_px,
        cx_px: c.cx_px,
        cy_px: c.cy_px,
        distortion,
    })
}

fn parse_yaml(text: &str, file: &str) -> Result<Intrinsics, CameraFileError> {
    // OpenCV FileStorage: a `%YAML:1.0` directive (not YAML 1.2 syntax) and `!!opencv-matrix`
    // tags. Blank the directive line and the tags, keeping every line and column in place.
    let mut clean = String::with_capacity(text.len());
    for (i, l) in text.lines().enumerate() {
        if i == 0 && l.trim_start().starts_with("%YAML") {
            clean.push('\n');
            continue;
        }
        clean.push_str(&l.replace("!!opencv-matrix", "               "));
        clean.push('\n');
    }
    let y: YamlCamera = serde_saphyr::from_str(&clean).map_err(|e| {
        let msg = e.to_string();
        let first = msg.lines().next().unwrap_or(&msg).to_string();
        let (line, column) = e
            .location()
            .map_or((0, 0), |l| (l.line() as usize, l.column() as usize));
        CameraFileError::Syntax {
            file: file.into(),
            line,
            column,
            message: first,
        }
    })?;
    let field = |f: &str, v: String, rule: String| CameraFileError::Field {
        file: file.into(),
        line: line_of(text, f),
        field: f.into(),
        value: v,
        rule,
    };
    let missing = |f: &'static str, hint: &'static str| CameraFileError::Missing {
        file: file.into(),
        field: f,
        hint,
    };
    let w = y
        .image_width
        .ok_or_else(|| missing("image_width", "image width in px"))?;
    let h = y
        .image_height
        .ok_or_else(|| missing("image_height", "image height in px"))?;
    let k = y
        .camera_matrix
        .ok_or_else(|| missing("camera_matrix", "3 x 3 [fx 0 cx; 0 fy cy; 0 0 1], px"))?;
    let check = |name: &str, m: &YamlMatrix| -> Result<(), CameraFileError> {
        if m.rows * m.cols != m.data.len() {
            return Err(field(
                name,
                format!(
                    "rows {} x cols {} with {} data values",
                    m.rows,
                    m.cols,
                    m.data.len()
                ),
                "rows x cols must equal the number of data values".into(),
            ));
        }
        if let Some(dt) = &m.dt {
            if dt != "d" && dt != "f" {
                return Err(field(
                    name,
                    format!("dt: {dt}"),
                    "must be d (double) or f (float)".into(),
                ));
            }
        }
        Ok(())
    };
    check("camera_matrix", &k)?;
    if k.rows != 3 || k.cols != 3 {
        return Err(field(
            "camera_matrix",
            format!("{} x {}", k.rows, k.cols),
            "must be 3 x 3".into(),
        ));
    }
    let km = &k.data;
    if km[1] != 0.0 || km[3] != 0.0 || km[6] != 0.0 || km[7] != 0.0 || km[8] != 1.0 {
        return Err(field(
            "camera_matrix",
            format!("{km:?}"),
            "must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)".into(),
        ));
    }
    let d = y.distortion_coefficients.ok_or_else(|| {
        missing(
            "distortion_coefficients",
            "OpenCV order, e.g. k1, k2, k3, k4 for fisheye",
        )
    })?;
    check("distortion_coefficients", &d)?;
    if d.rows != 1 && d.cols != 1 {
        return Err(field(
            "distortion_coefficients",
            format!("{} x {}", d.rows, d.cols),
            "must be a row or a column".into(),
        ));
    }
    let model = match y.distortion_model.as_deref() {
        Some(m) => m.to_string(),
        None => match d.data.len() {
            5 => "plumb_bob".into(),
            8 => "rational_polynomial".into(),
            n => {
                return Err(field(
                    "distortion_coefficients",
                    format!("{n} values"),
                    "without distortion_model only 5 (plumb_bob) or 8 (rational_polynomial) coefficients are unambiguous; add distortion_model: fisheye, plumb_bob or rational_polynomial".into(),
                ))
            }
        },
    };
    let distortion = Distortion::from_name(&model, &d.data).map_err(|rule| {
        if y.distortion_model.is_some() && rule.starts_with("unknown") {
            field("distortion_model", model.clone(), rule)
        } else {
            field("distortion_coefficients", format!("{:?}", d.data), rule)
        }
    })?;
    Ok(Intrinsics {
        image_width_px: w,
        image_height_px: h,
        fx_px: km[0],
        fy_px: km[4],
        cx_px: km[2],
        cy_px: km[5],
        distortion,
    })
}

/// A double as OpenCV FileStorage writes it: `215.` for integral values, else `%.16e`
/// (`3.1950000000000000e+02`).
fn cv_double(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        return format!("{}.", v as i64);
    }
    let s = format!("{v:.16e}");
    // Rust writes `3.195e2`-style exponents; C writes `e+02`.
    match s.split_once('e') {
        Some((m, e)) => {
            let (sign, digits) = match e.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', e),
            };
            format!("{m}e{sign}{digits:0>2}")
        }
        None => s,
    }
}

fn cv_matrix(out: &mut String, name: &str, rows: usize, cols: usize, data: &[f64]) {
    let vals: Vec<String> = data.iter().map(|v| cv_double(*v)).collect();
    out.push_str(&format!(
        "{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {} ]\n",
        vals.join(", ")
    ));
}

fn plain_list(data: &[f64]) -> String {
    let vals: Vec<String> = data.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", vals.join(", "))
}

/// Writes intrinsics in one of the camera-file forms (deterministic text; values round-trip
/// exactly). `distortion_model` is written with the ROS name in ROS form (`equidistant` for the
/// fisheye model) and the fabkit/OpenCV name otherwise.
pub fn write_camera(intr: &Intrinsics, format: CameraFileFormat) -> String {
    let k = [
        intr.fx_px, 0.0, intr.cx_px, 0.0, intr.fy_px, intr.cy_px, 0.0, 0.0, 1.0,
    ];
    let d = intr.distortion.coefficients();
    match format {
        CameraFileFormat::OpenCvYaml => {
            let mut s = String::from("%YAML:1.0\n---\n");
            s.push_str(&format!(
                "image_width: {}\nimage_height: {}\n",
                intr.image_width_px, intr.image_height_px
            ));
            cv_matrix(&mut s, "camera_matrix", 3, 3, &k);
            s.push_str(&format!("distortion_model: {}\n", intr.distortion.name()));
            // cv::fisheye::calibrate returns D as 4 x 1; cv::calibrateCamera as 1 x N.
            let (r, c) = match intr.distortion {
                Distortion::Fisheye(_) => (4, 1),
                _ => (1, d.len()),
            };
            cv_matrix(&mut s, "distortion_coefficients", r, c, d);
            s
        }
        CameraFileFormat::RosYaml => {
            let model = match intr.distortion {
                Distortion::Fisheye(_) => "equidistant",
                other => other.name(),
            };
            let p = [
                intr.fx_px, 0.0, intr.cx_px, 0.0, 0.0, intr.fy_px, intr.cy_px, 0.0, 0.0, 0.0, 1.0,
                0.0,
            ];
            format!(
                "image_width: {}\nimage_height: {}\ncamera_name: fabkit\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: {}\n\
                 distortion_model: {model}\ndistortion_coefficients:\n  rows: 1\n  cols: {}\n  data: {}\n\
                 rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n\
                 projection_matrix:\n  rows: 3\n  cols: 4\n  data: {}\n",
                intr.image_width_px,
                intr.image_height_px,
                plain_list(&k),
                d.len(),
                plain_list(d),
                plain_list(&p)
            )
        }
        CameraFileFormat::Json => {
            let j = CameraJson {
                format: "fabkit-camera".into(),
                distortion_model: intr.distortion.name().into(),
                image_width_px: intr.image_width_px,
                image_height_px: intr.image_height_px,
                fx_px: intr.fx_px,
                fy_px: intr.fy_px,
                cx_px: intr.cx_px,
                cy_px: intr.cy_px,
                distortion_coefficients: d.to_vec(),
            };
            let mut s = serde_json::to_string_pretty(&j).unwrap_or_default();
            s.push('\n');
            s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cv_double_matches_opencv_text() {
        assert_eq!(cv_double(215.0), "215.");
        assert_eq!(cv_double(0.0), "0.");
        assert_eq!(cv_double(319.5), "3.1950000000000000e+02");
        assert_eq!(cv_double(-0.0015), "-1.5000000000000000e-03");
    }
}
