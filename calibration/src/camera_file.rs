//! Camera files: OpenCV FileStorage YAML (`%YAML:1.0` or `%YAML 1.2`, `!!opencv-matrix`) and XML
//! (`<opencv_storage>`, `type_id="opencv-matrix"`), ROS `camera_info` YAML (camera_calibration_parsers,
//! or the `sensor_msgs/CameraInfo` message as `rostopic echo` / `ros2 topic echo` print it) and
//! fabkit's JSON form, or JSON with the OpenCV keys. Reading detects the form; errors name the
//! file, line and field.
//!
//! Keys (OpenCV and ROS share them): `image_width` (also `width`), `image_height` (also
//! `height`), `camera_matrix` (3 x 3, `[fx 0 cx; 0 fy cy; 0 0 1]`, px; also read as `K`, `k` or
//! `cameraMatrix`), `distortion_model` (`fisheye` or `equidistant`, `plumb_bob`,
//! `rational_polynomial`) and `distortion_coefficients` (OpenCV order; also read as `D`, `d`,
//! `distCoeffs` or `dist_coeffs`); [`SPELLINGS`]. A matrix is an `opencv-matrix` (or ROS) map of
//! `rows`, `cols`, `dt`, `data`, or a plain list: 9 numbers row-major or 3 rows of 3 for the
//! camera matrix, the coefficients flat or as one row or column. Two spellings of one quantity
//! in a file are an error naming both; [`read_camera_file_keys`] says which were read.
//!
//! A file without `distortion_model` is read as `plumb_bob` for 5 coefficients and `rational_polynomial` for 8
//! (what `cv2.calibrateCamera` writes), or for 12 or 14 (`CALIB_THIN_PRISM_MODEL`,
//! `CALIB_RATIONAL_MODEL` in OpenCV 5) whose thin-prism and tilt coefficients s1..s4, tauX, tauY
//! are all 0 (they are not modelled: any other value is an error). 4 coefficients
//! (`cv2.fisheye.calibrate`'s D) are read as fisheye when the file has `fisheye_model: 1` (the key
//! OpenCV's camera_calibration sample writes) or the caller gives [`DistortionModelHint::Fisheye`]
//! (`--camera-model fisheye`); otherwise they are refused as ambiguous. A hint applies only to a
//! file that names no model: a file naming another model, or a coefficient count the hinted model
//! does not take, is an error.

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

/// The distortion model a caller gives for a camera file that names none (`fabkit calibrate
/// extrinsics --camera-model`), e.g. the 4 coefficients of `cv2.fisheye.calibrate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DistortionModelHint {
    /// [`Distortion::Fisheye`] (Kannala-Brandt, k1..k4).
    Fisheye,
    /// [`Distortion::PlumbBob`] (k1, k2, p1, p2, k3; 4 coefficients: k3 = 0).
    PlumbBob,
    /// [`Distortion::RationalPolynomial`] (k1, k2, p1, p2, k3..k6).
    RationalPolynomial,
}

impl DistortionModelHint {
    /// The model's name as camera files and `--camera-model` spell it.
    pub fn name(self) -> &'static str {
        match self {
            DistortionModelHint::Fisheye => "fisheye",
            DistortionModelHint::PlumbBob => "plumb_bob",
            DistortionModelHint::RationalPolynomial => "rational_polynomial",
        }
    }

    /// The model a file's `distortion_model` names (the names [`Distortion::from_name`] takes).
    fn of_name(name: &str) -> Option<DistortionModelHint> {
        match name {
            "fisheye" | "equidistant" | "kannala_brandt" => Some(DistortionModelHint::Fisheye),
            "plumb_bob" | "radtan" => Some(DistortionModelHint::PlumbBob),
            "rational_polynomial" => Some(DistortionModelHint::RationalPolynomial),
            _ => None,
        }
    }
}

impl std::fmt::Display for DistortionModelHint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
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
    /// OpenCV FileStorage XML, as `cv::FileStorage` writes it.
    OpenCvXml,
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

/// A matrix of a camera file: an OpenCV or ROS map (`rows`, `cols`, `dt`, `data`, row-major)
/// or a plain list (`[fx, 0, cx, 0, fy, cy, 0, 0, 1]`, or nested by rows as numpy's `tolist()`
/// writes it).
#[derive(Deserialize)]
struct YamlMatrix {
    rows: usize,
    cols: usize,
    #[serde(default)]
    dt: Option<String>,
    data: Vec<f64>,
    /// Given as a flat list of numbers (shape `1 x n` until the key says otherwise).
    #[serde(skip)]
    flat: bool,
}

/// One element of a plain-list matrix: a number, or a row of numbers.
enum ListElement {
    Number(f64),
    Row(Vec<f64>),
}

impl<'de> Deserialize<'de> for ListElement {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = ListElement;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number or a list of numbers")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ListElement, E> {
                Ok(ListElement::Number(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ListElement, E> {
                Ok(ListElement::Number(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ListElement, E> {
                Ok(ListElement::Number(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<ListElement, A::Error> {
                let mut row = Vec::new();
                while let Some(v) = seq.next_element::<f64>()? {
                    row.push(v);
                }
                Ok(ListElement::Row(row))
            }
        }
        d.deserialize_any(V)
    }
}

/// [`YamlMatrix`] in either form.
struct AnyMatrix(YamlMatrix);

impl<'de> Deserialize<'de> for AnyMatrix {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = AnyMatrix;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a matrix: a map of rows, cols, dt and data, or a list of numbers (flat or by rows)")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<AnyMatrix, A::Error> {
                YamlMatrix::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(AnyMatrix)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<AnyMatrix, A::Error> {
                use serde::de::Error;
                let mut numbers = Vec::new();
                let mut rows: Vec<Vec<f64>> = Vec::new();
                while let Some(e) = seq.next_element::<ListElement>()? {
                    match e {
                        ListElement::Number(v) => numbers.push(v),
                        ListElement::Row(r) => rows.push(r),
                    }
                }
                if !numbers.is_empty() && !rows.is_empty() {
                    return Err(A::Error::custom(
                        "a list of numbers or a list of rows, not both",
                    ));
                }
                if rows.is_empty() {
                    return Ok(AnyMatrix(YamlMatrix {
                        rows: 1,
                        cols: numbers.len(),
                        dt: None,
                        data: numbers,
                        flat: true,
                    }));
                }
                let cols = rows[0].len();
                if rows.iter().any(|r| r.len() != cols) {
                    let lengths: Vec<String> = rows.iter().map(|r| r.len().to_string()).collect();
                    return Err(A::Error::custom(format!(
                        "rows of {} numbers: every row must be as long",
                        lengths.join(", ")
                    )));
                }
                Ok(AnyMatrix(YamlMatrix {
                    rows: rows.len(),
                    cols,
                    dt: None,
                    data: rows.concat(),
                    flat: false,
                }))
            }
        }
        d.deserialize_any(V)
    }
}

/// The keys of a YAML or JSON camera file, every spelling ([`SPELLINGS`]) its own field.
#[derive(Deserialize)]
#[allow(non_snake_case)]
struct RawCamera {
    image_width: Option<u32>,
    width: Option<u32>,
    image_height: Option<u32>,
    height: Option<u32>,
    camera_matrix: Option<AnyMatrix>,
    K: Option<AnyMatrix>,
    k: Option<AnyMatrix>,
    cameraMatrix: Option<AnyMatrix>,
    distortion_model: Option<String>,
    /// OpenCV's camera_calibration sample: 1 for `cv::fisheye`, 0 otherwise.
    fisheye_model: Option<i64>,
    distortion_coefficients: Option<AnyMatrix>,
    D: Option<AnyMatrix>,
    d: Option<AnyMatrix>,
    distCoeffs: Option<AnyMatrix>,
    dist_coeffs: Option<AnyMatrix>,
}

impl RawCamera {
    fn keys(self) -> YamlCamera {
        fn given<T>(all: Vec<(&'static str, Option<T>)>) -> Vec<(&'static str, T)> {
            all.into_iter()
                .filter_map(|(k, v)| v.map(|v| (k, v)))
                .collect()
        }
        let m = |v: Option<AnyMatrix>| v.map(|m| m.0);
        YamlCamera {
            image_width: given(vec![
                ("image_width", self.image_width),
                ("width", self.width),
            ]),
            image_height: given(vec![
                ("image_height", self.image_height),
                ("height", self.height),
            ]),
            camera_matrix: given(vec![
                ("camera_matrix", m(self.camera_matrix)),
                ("K", m(self.K)),
                ("k", m(self.k)),
                ("cameraMatrix", m(self.cameraMatrix)),
            ]),
            distortion_model: self.distortion_model,
            fisheye_model: self.fisheye_model,
            distortion_coefficients: given(vec![
                ("distortion_coefficients", m(self.distortion_coefficients)),
                ("D", m(self.D)),
                ("d", m(self.d)),
                ("distCoeffs", m(self.distCoeffs)),
                ("dist_coeffs", m(self.dist_coeffs)),
            ]),
        }
    }
}

/// The keys of a camera file in any form: each quantity with every spelling the file gives it.
struct YamlCamera {
    image_width: Vec<(&'static str, u32)>,
    image_height: Vec<(&'static str, u32)>,
    camera_matrix: Vec<(&'static str, YamlMatrix)>,
    distortion_model: Option<String>,
    fisheye_model: Option<i64>,
    distortion_coefficients: Vec<(&'static str, YamlMatrix)>,
}

/// The spellings of the keys that calibration scripts and ROS write, read as the OpenCV keys:
/// `K`, `D` (`fs.write("K", K)`, ROS 1 `sensor_msgs/CameraInfo`), `k`, `d` (ROS 2
/// `sensor_msgs/msg/CameraInfo` as `ros2 topic echo` prints it), `cameraMatrix`, `distCoeffs`
/// (as OpenCV's functions name them), `dist_coeffs`, and the message's `width` and `height`.
pub const SPELLINGS: &[(&str, &[&str])] = &[
    ("image_width", &["image_width", "width"]),
    ("image_height", &["image_height", "height"]),
    (
        "camera_matrix",
        &["camera_matrix", "K", "k", "cameraMatrix"],
    ),
    (
        "distortion_coefficients",
        &[
            "distortion_coefficients",
            "D",
            "d",
            "distCoeffs",
            "dist_coeffs",
        ],
    ),
];

/// The spellings of `key` a file may use ([`SPELLINGS`]; the key alone for the others).
fn spellings(key: &str) -> Vec<&str> {
    SPELLINGS
        .iter()
        .find(|(k, _)| *k == key)
        .map_or_else(|| vec![key], |(_, all)| all.to_vec())
}

/// The 1-based line of `key` in `text` under any of its spellings; 0 when absent.
fn line_of_any(text: &str, key: &str) -> usize {
    spellings(key)
        .into_iter()
        .map(|k| line_of(text, k))
        .find(|&l| l > 0)
        .unwrap_or(0)
}

/// The keys a camera file's values were read from: the spelling of each ([`SPELLINGS`]), or
/// the fields of fabkit's JSON form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeysRead {
    /// The intrinsic matrix: `camera_matrix`, `K`, `k` or `cameraMatrix`; `fx_px, fy_px, cx_px,
    /// cy_px` in fabkit's JSON form.
    pub intrinsics: &'static str,
    /// The distortion coefficients: `distortion_coefficients`, `D`, `d`, `distCoeffs` or
    /// `dist_coeffs`.
    pub distortion: &'static str,
}

impl std::fmt::Display for KeysRead {
    /// `K (intrinsics), D (distortion)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} (intrinsics), {} (distortion)",
            self.intrinsics, self.distortion
        )
    }
}

/// A camera file as read: the camera and the keys its values came from.
#[derive(Debug, Clone)]
pub struct CameraFileRead {
    pub camera: CameraModel,
    pub keys_read: KeysRead,
}

/// Reads and validates a camera file (form detected from the content).
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field.
pub fn read_camera_file(path: &Path) -> Result<CameraModel, CameraFileError> {
    read_camera_file_as(path, None)
}

/// [`read_camera_file`] with the distortion model to assume when the file names none
/// ([`DistortionModelHint`]; `None`: infer it from the coefficient count as [`read_camera_file`]).
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field; also a file that names a model
/// other than `model`, or whose coefficient count `model` does not take.
pub fn read_camera_file_as(
    path: &Path,
    model: Option<DistortionModelHint>,
) -> Result<CameraModel, CameraFileError> {
    read_camera_file_keys(path, model).map(|r| r.camera)
}

/// [`read_camera_file_as`] with the keys the values were read from ([`KeysRead`]), for a
/// caller that says which spellings it took (`camera: K (intrinsics), D (distortion) read from
/// cam.yaml`).
///
/// # Errors
/// As [`read_camera_file_as`].
pub fn read_camera_file_keys(
    path: &Path,
    model: Option<DistortionModelHint>,
) -> Result<CameraFileRead, CameraFileError> {
    let file = path.display().to_string();
    let text = crate::read_text(path).map_err(|source| CameraFileError::Io {
        file: file.clone(),
        source,
    })?;
    parse_camera_keys(&text, &file, model)
}

/// Parses and validates camera-file text; `file` names it in errors.
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field.
pub fn parse_camera(text: &str, file: &str) -> Result<CameraModel, CameraFileError> {
    parse_camera_as(text, file, None)
}

/// [`parse_camera`] with the distortion model to assume when the file names none
/// ([`read_camera_file_as`]).
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field.
pub fn parse_camera_as(
    text: &str,
    file: &str,
    model: Option<DistortionModelHint>,
) -> Result<CameraModel, CameraFileError> {
    parse_camera_keys(text, file, model).map(|r| r.camera)
}

/// [`parse_camera_as`] with the keys the values were read from ([`KeysRead`]).
///
/// # Errors
/// [`CameraFileError`] naming the file, the line and the field; also two spellings of one
/// quantity (`K` and `camera_matrix`), named both.
pub fn parse_camera_keys(
    text: &str,
    file: &str,
    model: Option<DistortionModelHint>,
) -> Result<CameraFileRead, CameraFileError> {
    // a file saved by an editor as "UTF-8 with BOM" reads as the same file without one
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let start = text.trim_start();
    let (intr, keys_read) = if start.starts_with('{') {
        parse_json(text, file, model)?
    } else if start.starts_with('<') {
        parse_xml(text, file, model)?
    } else {
        parse_yaml(text, file, model)?
    };
    let line_of_field = |field: &str| match key_of_field(field) {
        "camera_matrix" => line_of(text, keys_read.intrinsics),
        key => line_of_any(text, key),
    };
    let camera = CameraModel::new(intr).map_err(|e| match e {
        crate::camera::CameraError::Invalid { field, value, rule } => CameraFileError::Field {
            file: file.to_string(),
            line: line_of_field(field),
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
    })?;
    Ok(CameraFileRead { camera, keys_read })
}

fn key_of_field(field: &str) -> &str {
    match field {
        "fx_px" | "fy_px" | "cx_px" | "cy_px" => "camera_matrix",
        f => f,
    }
}

/// 1-based line of the first `key:` (YAML), `"key":` (JSON, anywhere in a line) or `<key>` (XML)
/// in `text`, or 0.
fn line_of(text: &str, key: &str) -> usize {
    let yaml = format!("{key}:");
    let json = format!("\"{key}\"");
    let xml = format!("<{key}");
    text.lines()
        .position(|l| {
            let t = l.trim_start();
            t.starts_with(&yaml)
                || t.match_indices(&json)
                    .any(|(i, _)| t[i + json.len()..].trim_start().starts_with(':'))
                || (t.starts_with(&xml)
                    && t[xml.len()..].starts_with(|c: char| c == '>' || c.is_whitespace()))
        })
        .map_or(0, |i| i + 1)
}

/// 1-based line and column of byte `pos` of `text`.
fn line_column(text: &str, pos: usize) -> (usize, usize) {
    let before = &text.as_bytes()[..pos.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    (
        line,
        String::from_utf8_lossy(&before[start..]).chars().count() + 1,
    )
}

/// Names of the coefficients after the rational model's eight (OpenCV order).
const PRISM_AND_TILT: [&str; 6] = ["s1", "s2", "s3", "s4", "tauX", "tauY"];

/// The distortion of a file from what it says about its model (`distortion_model`, OpenCV's
/// camera_calibration `fisheye_model`), the caller's hint and the coefficients (OpenCV order).
/// `err(field, value, rule)` makes a [`CameraFileError::Field`] at the field's line.
fn resolve_distortion(
    named: Option<&str>,
    fisheye_model: Option<i64>,
    hint: Option<DistortionModelHint>,
    coefficients: &[f64],
    err: &dyn Fn(&str, String, String) -> CameraFileError,
) -> Result<Distortion, CameraFileError> {
    use DistortionModelHint as M;
    let flag = match fisheye_model {
        None => None,
        Some(0) => Some(false),
        Some(1) => Some(true),
        Some(v) => {
            return Err(err(
                "fisheye_model",
                v.to_string(),
                "must be 0 or 1 (1: cv::fisheye, as OpenCV's camera_calibration sample writes)"
                    .into(),
            ))
        }
    };
    let file_model = match named {
        Some(n) => Some(M::of_name(n).ok_or_else(|| {
            err(
                "distortion_model",
                n.to_string(),
                format!("unknown distortion model '{n}': must be fisheye (or equidistant), plumb_bob or rational_polynomial"),
            )
        })?),
        None => None,
    };
    if let (Some(m), Some(n), Some(f)) = (file_model, named, flag) {
        if (m == M::Fisheye) != f {
            return Err(err(
                "fisheye_model",
                u8::from(f).to_string(),
                format!("contradicts the file's distortion_model: {n}"),
            ));
        }
    }
    if let Some(h) = hint {
        if let (Some(m), Some(n)) = (file_model, named) {
            if m != h {
                return Err(err(
                    "distortion_model",
                    n.to_string(),
                    format!("the file names this model but --camera-model {h} was given (it is for files that name none): drop --camera-model or give --camera-model {m}"),
                ));
            }
        } else if let Some(f) = flag {
            if f != (h == M::Fisheye) {
                return Err(err(
                    "fisheye_model",
                    u8::from(f).to_string(),
                    format!("the file's fisheye_model: {} contradicts --camera-model {h}: drop --camera-model or fix the file", u8::from(f)),
                ));
            }
        }
    }
    let n = coefficients.len();
    let (model, from) = match (file_model, flag, hint) {
        (Some(m), _, _) => (m, None),
        (None, Some(true), _) => (M::Fisheye, Some("fisheye_model: 1".to_string())),
        (None, _, Some(h)) => (h, Some(format!("--camera-model {h}"))),
        (None, flag, None) => match n {
            5 => (M::PlumbBob, None),
            4 if flag == Some(false) => (M::PlumbBob, Some("fisheye_model: 0".to_string())),
            8 | 12 | 14 => (M::RationalPolynomial, None),
            4 => {
                return Err(err(
                    "distortion_coefficients",
                    "4 values".into(),
                    "without a model name 4 coefficients are ambiguous (fisheye k1..k4, as cv2.fisheye.calibrate writes, or plumb_bob k1, k2, p1, p2): add `fisheye_model: 1` (as OpenCV's camera_calibration sample writes) or `distortion_model: fisheye` to the file, or give `--camera-model fisheye`".into(),
                ))
            }
            n => {
                return Err(err(
                    "distortion_coefficients",
                    format!("{n} values"),
                    "without distortion_model only 5 (plumb_bob) or 8, 12, 14 (rational_polynomial) coefficients are unambiguous; add distortion_model: fisheye, plumb_bob or rational_polynomial, or give --camera-model".into(),
                ))
            }
        },
    };
    // calibrateCamera's 12 (thin prism) or 14 (tilted sensor) coefficients: the rational
    // model's eight when the rest are 0.
    let mut k = coefficients;
    if model == M::RationalPolynomial && (n == 12 || n == 14) {
        let extra: Vec<String> = coefficients[8..]
            .iter()
            .zip(PRISM_AND_TILT)
            .filter(|(v, _)| **v != 0.0)
            .map(|(v, name)| format!("{name} = {v:?}"))
            .collect();
        if !extra.is_empty() {
            return Err(err(
                "distortion_coefficients",
                format!("{n} values with {}", extra.join(", ")),
                "thin-prism and tilt coefficients s1..s4, tauX, tauY are not modelled, must be 0 (rational_polynomial is k1, k2, p1, p2, k3, k4, k5, k6)".into(),
            ));
        }
        k = &coefficients[..8];
    }
    Distortion::from_name(named.unwrap_or(model.name()), k).map_err(|rule| {
        let rule = match from {
            Some(from) => format!("{rule} (the model is from {from}; the file names none)"),
            None => rule,
        };
        err("distortion_coefficients", format!("{coefficients:?}"), rule)
    })
}

/// fabkit's JSON form ([`CameraJson`], told by its `format` key), or a JSON file with the keys
/// of the OpenCV and ROS forms (`{"K": [[..], [..], [..]], "D": [..], "image_width": ..}`, as
/// calibration scripts dump numpy's `tolist()`).
fn parse_json(
    text: &str,
    file: &str,
    hint: Option<DistortionModelHint>,
) -> Result<(Intrinsics, KeysRead), CameraFileError> {
    let syntax = |e: serde_json::Error| CameraFileError::Syntax {
        file: file.into(),
        line: e.line(),
        column: e.column(),
        message: e
            .to_string()
            .split(" at line ")
            .next()
            .unwrap_or("")
            .to_string(),
    };
    let object: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(text).map_err(syntax)?;
    if !object.contains_key("format") {
        let raw: RawCamera = serde_json::from_str(text).map_err(syntax)?;
        return camera_of(raw.keys(), file, hint, &|key| line_of(text, key));
    }
    let c: CameraJson = serde_json::from_str(text).map_err(syntax)?;
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
    let distortion = resolve_distortion(
        Some(&c.distortion_model),
        None,
        hint,
        &c.distortion_coefficients,
        &field,
    )?;
    Ok((
        Intrinsics {
            image_width_px: c.image_width_px,
            image_height_px: c.image_height_px,
            fx_px: c.fx_px,
            fy_px: c.fy_px,
            cx_px: c.cx_px,
            cy_px: c.cy_px,
            distortion,
        },
        KeysRead {
            intrinsics: "fx_px, fy_px, cx_px, cy_px",
            distortion: "distortion_coefficients",
        },
    ))
}

fn parse_yaml(
    text: &str,
    file: &str,
    hint: Option<DistortionModelHint>,
) -> Result<(Intrinsics, KeysRead), CameraFileError> {
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
    let y: RawCamera = serde_saphyr::from_str(&clean).map_err(|e| {
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
    camera_of(y.keys(), file, hint, &|key| line_of(text, key))
}

/// The one spelling of `quantity` a file gives ([`SPELLINGS`]), or an error naming both when it
/// gives two; `line(key)` is a key's 1-based line.
fn one_spelling<T>(
    quantity: &str,
    mut given: Vec<(&'static str, T)>,
    file: &str,
    line: &dyn Fn(&str) -> usize,
) -> Result<Option<(&'static str, T)>, CameraFileError> {
    if given.len() > 1 {
        let mut keys: Vec<&str> = given.iter().map(|(k, _)| *k).collect();
        keys.sort_by_key(|k| line(k));
        return Err(CameraFileError::Field {
            file: file.into(),
            line: line(keys[1]),
            field: quantity.into(),
            value: keys.join(" and "),
            rule: format!(
                "the file gives {} twice, spelled {}: keep one",
                quantity,
                keys.join(" and ")
            ),
        });
    }
    Ok(given.pop())
}

/// Intrinsics from the keys of an OpenCV or ROS file, and the keys read; `line(key)` is the
/// 1-based line of `key` as spelled.
fn camera_of(
    y: YamlCamera,
    file: &str,
    hint: Option<DistortionModelHint>,
    line: &dyn Fn(&str) -> usize,
) -> Result<(Intrinsics, KeysRead), CameraFileError> {
    let w = one_spelling("image_width", y.image_width, file, line)?;
    let h = one_spelling("image_height", y.image_height, file, line)?;
    let k = one_spelling("camera_matrix", y.camera_matrix, file, line)?;
    let d = one_spelling(
        "distortion_coefficients",
        y.distortion_coefficients,
        file,
        line,
    )?;
    // each quantity's line under the spelling the file gives it
    let k_spelled = k.as_ref().map(|(s, _)| *s);
    let d_spelled = d.as_ref().map(|(s, _)| *s);
    let spelled = |f: &str| -> usize {
        let key = match f {
            "camera_matrix" => k_spelled.unwrap_or(f),
            "distortion_coefficients" => d_spelled.unwrap_or(f),
            _ => f,
        };
        line(key)
    };
    let field = |f: &str, v: String, rule: String| CameraFileError::Field {
        file: file.into(),
        line: spelled(f),
        field: f.into(),
        value: v,
        rule,
    };
    let missing = |f: &'static str, hint: &'static str| CameraFileError::Missing {
        file: file.into(),
        field: f,
        hint,
    };
    let (_, w) =
        w.ok_or_else(|| missing("image_width", "image width in px; also read as width"))?;
    let (_, h) =
        h.ok_or_else(|| missing("image_height", "image height in px; also read as height"))?;
    let (k_key, mut k) = k.ok_or_else(|| {
        missing(
            "camera_matrix",
            "3 x 3 [fx 0 cx; 0 fy cy; 0 0 1], px; read as camera_matrix, K, k or cameraMatrix, an opencv-matrix or a list of 9 numbers or 3 rows",
        )
    })?;
    let (d_key, d) = d.ok_or_else(|| {
        missing(
            "distortion_coefficients",
            "OpenCV order, e.g. k1, k2, k3, k4 for fisheye; read as distortion_coefficients, D, d, distCoeffs or dist_coeffs",
        )
    })?;
    if k.flat && k.data.len() == 9 {
        (k.rows, k.cols, k.flat) = (3, 3, false);
    }
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
    if k.flat {
        return Err(field(
            "camera_matrix",
            format!("a list of {} numbers", k.data.len()),
            "must be 9 numbers (row-major) or 3 rows of 3".into(),
        ));
    }
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
    check("distortion_coefficients", &d)?;
    if d.rows != 1 && d.cols != 1 {
        return Err(field(
            "distortion_coefficients",
            format!("{} x {}", d.rows, d.cols),
            "must be a row or a column".into(),
        ));
    }
    let distortion = resolve_distortion(
        y.distortion_model.as_deref(),
        y.fisheye_model,
        hint,
        &d.data,
        &field,
    )?;
    Ok((
        Intrinsics {
            image_width_px: w,
            image_height_px: h,
            fx_px: km[0],
            fy_px: km[4],
            cx_px: km[2],
            cy_px: km[5],
            distortion,
        },
        KeysRead {
            intrinsics: k_key,
            distortion: d_key,
        },
    ))
}

/// One element of an XML file: name, 1-based line of its start tag, text, child elements.
struct XmlElement {
    name: String,
    line: usize,
    text: String,
    children: Vec<XmlElement>,
}

/// The element tree of an XML file (quick-xml events; entities resolved, comments dropped).
fn xml_tree(text: &str, file: &str) -> Result<XmlElement, CameraFileError> {
    use quick_xml::events::Event;
    let syntax = |pos: usize, message: String| {
        let (line, column) = line_column(text, pos);
        CameraFileError::Syntax {
            file: file.into(),
            line,
            column,
            message,
        }
    };
    let mut reader = quick_xml::Reader::from_str(text);
    let mut open: Vec<XmlElement> = Vec::new();
    let mut root: Option<XmlElement> = None;
    let mut close = |el: XmlElement, open: &mut Vec<XmlElement>, pos: usize| match open.last_mut() {
        Some(parent) => {
            parent.children.push(el);
            Ok(())
        }
        None if root.is_none() => {
            root = Some(el);
            Ok(())
        }
        None => Err(syntax(pos, format!("a second root element <{}>", el.name))),
    };
    loop {
        let pos = reader.buffer_position() as usize;
        let event = reader
            .read_event()
            .map_err(|e| syntax(reader.error_position() as usize, e.to_string()))?;
        let element = |name: &str| XmlElement {
            name: name.to_string(),
            line: line_column(text, pos).0,
            text: String::new(),
            children: Vec::new(),
        };
        match event {
            Event::Start(s) => open.push(element(s.name().as_ref())),
            Event::Empty(s) => close(element(s.name().as_ref()), &mut open, pos)?,
            Event::End(_) => {
                if let Some(el) = open.pop() {
                    close(el, &mut open, pos)?;
                }
            }
            Event::Text(t) => {
                if let Some(el) = open.last_mut() {
                    el.text.push_str(&t.xml10_content());
                }
            }
            Event::CData(t) => {
                if let Some(el) = open.last_mut() {
                    el.text.push_str(&t.xml10_content());
                }
            }
            Event::GeneralRef(r) => {
                let resolved = match r.resolve_char_ref() {
                    Ok(Some(c)) => Some(c.to_string()),
                    Ok(None) => {
                        quick_xml::escape::resolve_predefined_entity(&r).map(str::to_string)
                    }
                    Err(_) => None,
                };
                let Some(s) = resolved else {
                    return Err(syntax(pos, format!("unknown entity &{};", &*r)));
                };
                if let Some(el) = open.last_mut() {
                    el.text.push_str(&s);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if let Some(el) = open.last() {
        return Err(syntax(text.len(), format!("<{}> is not closed", el.name)));
    }
    root.ok_or_else(|| syntax(text.len(), "no root element".into()))
}

/// OpenCV FileStorage XML: `<opencv_storage>` holding the same keys as the YAML form, matrices
/// as `<rows>`, `<cols>`, `<dt>`, `<data>` (numbers separated by white space).
fn parse_xml(
    text: &str,
    file: &str,
    hint: Option<DistortionModelHint>,
) -> Result<(Intrinsics, KeysRead), CameraFileError> {
    let root = xml_tree(text, file)?;
    let field = |line: usize, f: &str, v: String, rule: &str| CameraFileError::Field {
        file: file.into(),
        line,
        field: f.into(),
        value: v,
        rule: rule.into(),
    };
    if root.name != "opencv_storage" {
        return Err(field(
            root.line,
            "root element",
            format!("<{}>", root.name),
            "must be <opencv_storage> (OpenCV FileStorage XML)",
        ));
    }
    let mut seen: Vec<(&str, usize)> = Vec::new();
    for el in &root.children {
        if let Some((_, first)) = seen.iter().find(|(n, _)| *n == el.name) {
            return Err(field(
                el.line,
                &el.name,
                "given twice".into(),
                &format!("must be given once (first on line {first})"),
            ));
        }
        seen.push((&el.name, el.line));
    }
    let get = |name: &str| root.children.iter().find(|el| el.name == name);
    // OpenCV writes strings with spaces in double quotes inside the element.
    let string = |el: &XmlElement| {
        let t = el.text.trim();
        t.strip_prefix('"')
            .and_then(|t| t.strip_suffix('"'))
            .unwrap_or(t)
            .to_string()
    };
    let whole = |el: &XmlElement, what: &str| -> Result<i64, CameraFileError> {
        let t = el.text.trim();
        t.parse::<i64>()
            .map_err(|_| field(el.line, what, t.to_string(), "must be a whole number"))
    };
    let size = |name: &str| -> Result<Option<u32>, CameraFileError> {
        get(name)
            .map(|el| {
                let v = whole(el, name)?;
                u32::try_from(v).map_err(|_| {
                    field(
                        el.line,
                        name,
                        v.to_string(),
                        "must be a whole number of px >= 0",
                    )
                })
            })
            .transpose()
    };
    let matrix = |name: &str| -> Result<Option<YamlMatrix>, CameraFileError> {
        let Some(m) = get(name) else {
            return Ok(None);
        };
        let part = |p: &str| {
            m.children.iter().find(|c| c.name == p).ok_or_else(|| {
                field(
                    m.line,
                    name,
                    format!("no <{p}>"),
                    "an opencv-matrix has <rows>, <cols>, <dt> and <data>",
                )
            })
        };
        let count = |p: &str| -> Result<usize, CameraFileError> {
            let el = part(p)?;
            let v = whole(el, &format!("{name}.{p}"))?;
            usize::try_from(v).map_err(|_| {
                field(
                    el.line,
                    &format!("{name}.{p}"),
                    v.to_string(),
                    "must be >= 0",
                )
            })
        };
        let data = part("data")?;
        let values = data
            .text
            .split_whitespace()
            .map(|v| {
                v.parse::<f64>().map_err(|_| {
                    field(
                        data.line,
                        &format!("{name}.data"),
                        v.to_string(),
                        "must be numbers separated by white space",
                    )
                })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        Ok(Some(YamlMatrix {
            rows: count("rows")?,
            cols: count("cols")?,
            dt: m
                .children
                .iter()
                .find(|c| c.name == "dt")
                .map(|el| el.text.trim().to_string()),
            data: values,
            flat: false,
        }))
    };
    // every spelling the file gives of a quantity ([`SPELLINGS`])
    let all = |key: &str| -> Vec<&'static str> {
        SPELLINGS
            .iter()
            .find(|(k, _)| *k == key)
            .map_or_else(Vec::new, |(_, all)| all.to_vec())
            .into_iter()
            .filter(|s| get(s).is_some())
            .collect()
    };
    let sizes = |key: &str| -> Result<Vec<(&'static str, u32)>, CameraFileError> {
        all(key)
            .into_iter()
            .filter_map(|s| size(s).transpose().map(|v| v.map(|v| (s, v))))
            .collect()
    };
    let matrices = |key: &str| -> Result<Vec<(&'static str, YamlMatrix)>, CameraFileError> {
        all(key)
            .into_iter()
            .filter_map(|s| matrix(s).transpose().map(|m| m.map(|m| (s, m))))
            .collect()
    };
    let y = YamlCamera {
        image_width: sizes("image_width")?,
        image_height: sizes("image_height")?,
        camera_matrix: matrices("camera_matrix")?,
        distortion_model: get("distortion_model").map(string),
        fisheye_model: get("fisheye_model")
            .map(|el| whole(el, "fisheye_model"))
            .transpose()?,
        distortion_coefficients: matrices("distortion_coefficients")?,
    };
    let line = |key: &str| get(key).map_or(0, |el| el.line);
    camera_of(y, file, hint, &line)
}

/// A double as OpenCV FileStorage writes it: `215.` for integral values, else `%.16e`
/// (`3.1950000000000000e+02`).
pub(crate) fn cv_double(v: f64) -> String {
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

pub(crate) fn cv_matrix(out: &mut String, name: &str, rows: usize, cols: usize, data: &[f64]) {
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
        CameraFileFormat::OpenCvXml => {
            let matrix = |name: &str, rows: usize, cols: usize, data: &[f64]| {
                let vals: Vec<String> = data.iter().map(|v| cv_double(*v)).collect();
                format!(
                    "<{name} type_id=\"opencv-matrix\">\n  <rows>{rows}</rows>\n  <cols>{cols}</cols>\n  <dt>d</dt>\n  <data>\n    {}</data></{name}>\n",
                    vals.join(" ")
                )
            };
            let (r, c) = match intr.distortion {
                Distortion::Fisheye(_) => (4, 1),
                _ => (1, d.len()),
            };
            format!(
                "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>{}</image_width>\n<image_height>{}</image_height>\n{}<distortion_model>{}</distortion_model>\n{}</opencv_storage>\n",
                intr.image_width_px,
                intr.image_height_px,
                matrix("camera_matrix", 3, 3, &k),
                intr.distortion.name(),
                matrix("distortion_coefficients", r, c, d)
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
