//! Point tables and pixel observations (CSV).
//!
//! Point table: the table `fabkit fixtures` writes (`id,ring,tip_x_mm,tip_y_mm,tip_z_mm,
//! contact_x_mm,...`; tip columns by default, contact columns on request) or any CSV with
//! `id,x_mm,y_mm,z_mm`; sensor frame (`docs/conventions.md`), mm. Observations: `id,u_px,v_px`,
//! px (pixel (0, 0) is the centre of the top-left pixel); several files may split the pins
//! between captures. Lines starting with `#` and blank lines are skipped: fabkit's own tables
//! start with their header row (their notes are in JSON sidecars), and tables of older fabkit
//! versions, which began with `#` lines, still read. Errors name
//! file:line, the column, the value and the rule.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Vector2, Vector3};

/// A table that cannot be read or paired.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}: {message}")]
    Format {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}:{line}: {column} = {value}: {rule}")]
    Field {
        file: String,
        line: usize,
        column: String,
        value: String,
        rule: String,
    },
    #[error("id {id} is given twice: {first} and {second}")]
    Duplicate {
        id: String,
        first: String,
        second: String,
    },
    /// Every bad row of a table (more than one), each on its own line; past
    /// [`MAX_REPORTED_ROWS`] the rest are counted.
    #[error("{}", shown_rows(.0))]
    Rows(Vec<TableError>),
    #[error("{camera}: the image is {width} x {height} px (u from -0.5 to {} px, v from -0.5 to {} px, pixel (0, 0) the centre of the top-left pixel), but {} outside it:\n{}", *.width as f64 - 0.5, *.height as f64 - 0.5, if .rows.len() == 1 { "this observation is".to_string() } else { format!("these {} observations are", .rows.len()) }, shown_lines(.rows))]
    OutsideImage {
        camera: String,
        width: u32,
        height: u32,
        /// `file:line: id <id>: u_px = .., v_px = ..`, one per row.
        rows: Vec<String>,
    },
    #[error("observed ids not in the point table {points}: {}", .ids.join(", "))]
    UnknownIds { points: String, ids: Vec<String> },
    #[error("{plan} has {captures} captures but {files} observation files were given (one per capture, in capture order)")]
    CaptureCount {
        plan: String,
        captures: usize,
        files: usize,
    },
    #[error("{origin}: id {id} is not in capture {capture} of {plan} ({where_})")]
    NotInCapture {
        origin: String,
        id: String,
        capture: usize,
        plan: String,
        where_: String,
    },
}

/// Bad rows listed in one error; the rest are counted.
pub const MAX_REPORTED_ROWS: usize = 20;

fn shown_lines(lines: &[String]) -> String {
    let mut out: Vec<String> = lines.iter().take(MAX_REPORTED_ROWS).cloned().collect();
    if lines.len() > MAX_REPORTED_ROWS {
        out.push(format!("and {} more rows", lines.len() - MAX_REPORTED_ROWS));
    }
    out.join("\n")
}

fn shown_rows(errors: &[TableError]) -> String {
    shown_lines(&errors.iter().map(ToString::to_string).collect::<Vec<_>>())
}

/// `Ok` for no error, the error itself for one, [`TableError::Rows`] for several.
fn all_rows(mut errors: Vec<TableError>) -> Result<(), TableError> {
    match errors.len() {
        0 => Ok(()),
        1 => Err(errors.remove(0)),
        _ => Err(TableError::Rows(errors)),
    }
}

/// Which point of a fixtures table to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointsFrom {
    /// `tip_*_mm` columns (where the pin tip touches the skin), the default.
    Tip,
    /// `contact_*_mm` columns.
    Contact,
}

/// A row's source, `file:line`.
pub type Origin = String;

/// Sensor-frame points by id.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTable {
    pub file: String,
    /// (id, point mm, origin) in file order.
    pub rows: Vec<(String, Vector3<f64>, Origin)>,
}

/// Pixel observations by id.
#[derive(Debug, Clone, PartialEq)]
pub struct Observations {
    /// (id, pixel px, origin) in file order, files in the order given.
    pub rows: Vec<(String, Vector2<f64>, Origin)>,
}

/// Points and pixels paired by id, in observation order.
#[derive(Debug, Clone, PartialEq)]
pub struct Pairs {
    pub ids: Vec<String>,
    pub points_mm: Vec<Vector3<f64>>,
    pub pixels_px: Vec<Vector2<f64>>,
}

struct Csv<'a> {
    file: &'a str,
    header: Vec<String>,
    header_line: usize,
    rows: Vec<(usize, Vec<&'a str>)>,
    /// Rows whose cell count differs from the header's (left out of `rows`).
    bad: Vec<TableError>,
}

fn parse_csv<'a>(text: &'a str, file: &'a str) -> Result<Csv<'a>, TableError> {
    // a spreadsheet's "CSV UTF-8" starts with a byte order mark
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut header: Option<(usize, Vec<String>)> = None;
    let mut rows = Vec::new();
    let mut bad = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = t.split(',').map(str::trim).collect();
        match &header {
            None => header = Some((i + 1, cells.iter().map(|c| c.to_string()).collect())),
            Some((_, h)) => {
                if cells.len() != h.len() {
                    bad.push(TableError::Format {
                        file: file.into(),
                        line: i + 1,
                        message: format!(
                            "{} cells but the header has {} columns",
                            cells.len(),
                            h.len()
                        ),
                    });
                    continue;
                }
                rows.push((i + 1, cells));
            }
        }
    }
    let (header_line, header) = header.ok_or_else(|| TableError::Format {
        file: file.into(),
        line: 1,
        message: "no header line".into(),
    })?;
    Ok(Csv {
        file,
        header,
        header_line,
        rows,
        bad,
    })
}

impl Csv<'_> {
    fn column(&self, name: &str, expected: &str) -> Result<usize, TableError> {
        self.header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| TableError::Format {
                file: self.file.into(),
                line: self.header_line,
                message: format!("no column '{name}' in the header (expected {expected})"),
            })
    }

    fn number(&self, line: usize, cells: &[&str], col: usize) -> Result<f64, TableError> {
        let s = cells[col];
        let v: f64 = s.parse().map_err(|_| TableError::Field {
            file: self.file.into(),
            line,
            column: self.header[col].clone(),
            value: s.into(),
            rule: "must be a number".into(),
        })?;
        if !v.is_finite() {
            return Err(TableError::Field {
                file: self.file.into(),
                line,
                column: self.header[col].clone(),
                value: s.into(),
                rule: "must be finite".into(),
            });
        }
        Ok(v)
    }

    fn id(&self, line: usize, cells: &[&str], col: usize) -> Result<String, TableError> {
        let s = cells[col];
        if s.is_empty() {
            return Err(TableError::Field {
                file: self.file.into(),
                line,
                column: "id".into(),
                value: String::new(),
                rule: "must not be empty".into(),
            });
        }
        Ok(s.to_string())
    }
}

/// The line an error of one table names (its second place for a duplicate id), for ordering.
fn line_of(e: &TableError) -> usize {
    match e {
        TableError::Format { line, .. } | TableError::Field { line, .. } => *line,
        TableError::Duplicate { second, .. } => second
            .rsplit(':')
            .next()
            .and_then(|l| l.parse().ok())
            .unwrap_or(usize::MAX),
        _ => usize::MAX,
    }
}

/// Checks every observation against the camera's image: `u_px` from -0.5 to `width - 0.5`,
/// `v_px` from -0.5 to `height - 0.5` (pixel (0, 0) is the centre of the top-left pixel, so
/// these are the outer edges of the image). `camera` names the camera file in the error.
///
/// # Errors
/// [`TableError::OutsideImage`] listing every row outside the image (file:line, id, values).
pub fn check_inside_image(
    obs: &Observations,
    width: u32,
    height: u32,
    camera: &str,
) -> Result<(), TableError> {
    let (umax, vmax) = (f64::from(width) - 0.5, f64::from(height) - 0.5);
    let rows: Vec<String> = obs
        .rows
        .iter()
        .filter(|(_, uv, _)| !((-0.5..=umax).contains(&uv.x) && (-0.5..=vmax).contains(&uv.y)))
        .map(|(id, uv, origin)| {
            format!(
                "{origin}: id {id}: u_px = {}, v_px = {}",
                crate::shown_f64(uv.x),
                crate::shown_f64(uv.y)
            )
        })
        .collect();
    if rows.is_empty() {
        return Ok(());
    }
    Err(TableError::OutsideImage {
        camera: camera.into(),
        width,
        height,
        rows,
    })
}

fn read(path: &Path) -> Result<(String, String), TableError> {
    let file = path.display().to_string();
    let text = crate::read_text(path).map_err(|source| TableError::Io {
        file: file.clone(),
        source,
    })?;
    Ok((file, text))
}

/// Reads a point table file. See [`parse_point_table`].
///
/// # Errors
/// [`TableError`] naming file:line and the column.
pub fn read_point_table(path: &Path, from: PointsFrom) -> Result<PointTable, TableError> {
    let (file, text) = read(path)?;
    parse_point_table(&text, &file, from)
}

/// Parses a point table: the fixtures table (`tip_*_mm` or `contact_*_mm` by `from`) or a plain
/// `id,x_mm,y_mm,z_mm` CSV (`from` does not apply to it).
///
/// # Errors
/// [`TableError`]: no header or missing columns; for the rows, a wrong cell count, a non-numeric
/// or non-finite value, an empty or duplicate id, every bad row in one
/// [`TableError::Rows`] (a single one as itself).
pub fn parse_point_table(
    text: &str,
    file: &str,
    from: PointsFrom,
) -> Result<PointTable, TableError> {
    let mut csv = parse_csv(text, file)?;
    let expected = "id,x_mm,y_mm,z_mm or the fixtures table's id,ring,tip_x_mm,...";
    let id = csv.column("id", expected)?;
    let fixtures = csv
        .header
        .iter()
        .any(|h| h == "tip_x_mm" || h == "contact_x_mm");
    let prefix = match (fixtures, from) {
        (false, _) => "",
        (true, PointsFrom::Tip) => "tip_",
        (true, PointsFrom::Contact) => "contact_",
    };
    let cols = [
        csv.column(&format!("{prefix}x_mm"), expected)?,
        csv.column(&format!("{prefix}y_mm"), expected)?,
        csv.column(&format!("{prefix}z_mm"), expected)?,
    ];
    let mut rows = Vec::with_capacity(csv.rows.len());
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    // every bad row, in line order (cell counts first: they are known before the columns)
    let mut bad = std::mem::take(&mut csv.bad);
    for (line, cells) in &csv.rows {
        let mut errs = Vec::new();
        let i = csv.id(*line, cells, id).map_err(|e| errs.push(e)).ok();
        let xyz = cols.map(|c| csv.number(*line, cells, c).map_err(|e| errs.push(e)).ok());
        if let Some(i) = &i {
            if let Some(first) = seen.insert(i.clone(), *line) {
                errs.push(TableError::Duplicate {
                    id: i.clone(),
                    first: format!("{file}:{first}"),
                    second: format!("{file}:{line}"),
                });
            }
        }
        match (i, xyz) {
            (Some(i), [Some(x), Some(y), Some(z)]) if errs.is_empty() => {
                rows.push((i, Vector3::new(x, y, z), format!("{file}:{line}")))
            }
            _ => bad.extend(errs),
        }
    }
    bad.sort_by_key(line_of);
    all_rows(bad)?;
    Ok(PointTable {
        file: file.into(),
        rows,
    })
}

/// Reads observation files (`id,u_px,v_px`), in order. An id may appear once over all files.
///
/// # Errors
/// [`TableError`] naming file:line and the column; a duplicate id names both places. Every bad
/// row of every file is listed in one [`TableError::Rows`] (a single one as itself).
pub fn read_observations(paths: &[&Path]) -> Result<Observations, TableError> {
    with_texts(paths, parse_observations)
}

/// Reads every file, then parses their (text, file name) pairs in order.
fn with_texts<T>(
    paths: &[&Path],
    parse: impl FnOnce(&[(&str, &str)]) -> Result<T, TableError>,
) -> Result<T, TableError> {
    let texts = paths
        .iter()
        .map(|p| read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let refs: Vec<(&str, &str)> = texts
        .iter()
        .map(|(f, t)| (t.as_str(), f.as_str()))
        .collect();
    parse(&refs)
}

/// Parses observation texts given as (text, file name) pairs. See [`read_observations`].
///
/// # Errors
/// As [`read_observations`].
pub fn parse_observations(texts: &[(&str, &str)]) -> Result<Observations, TableError> {
    let mut rows = Vec::new();
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    // every bad row of every file, files in order, lines in order within a file
    let mut bad = Vec::new();
    for (text, file) in texts {
        let mut csv = parse_csv(text, file)?;
        let expected = "id,u_px,v_px";
        let id = csv.column("id", expected)?;
        let cu = csv.column("u_px", expected)?;
        let cv = csv.column("v_px", expected)?;
        let mut in_file = std::mem::take(&mut csv.bad);
        for (line, cells) in &csv.rows {
            let mut errs = Vec::new();
            let i = csv.id(*line, cells, id).map_err(|e| errs.push(e)).ok();
            let u = csv.number(*line, cells, cu).map_err(|e| errs.push(e)).ok();
            let v = csv.number(*line, cells, cv).map_err(|e| errs.push(e)).ok();
            let origin = format!("{file}:{line}");
            if let Some(i) = &i {
                if let Some(first) = seen.insert(i.clone(), origin.clone()) {
                    errs.push(TableError::Duplicate {
                        id: i.clone(),
                        first,
                        second: origin.clone(),
                    });
                }
            }
            match (i, u, v) {
                (Some(i), Some(u), Some(v)) if errs.is_empty() => {
                    rows.push((i, Vector2::new(u, v), origin))
                }
                _ => in_file.extend(errs),
            }
        }
        in_file.sort_by_key(line_of);
        bad.extend(in_file);
    }
    all_rows(bad)?;
    Ok(Observations { rows })
}

/// Pairs observations with the table's points by id (observation order). Points without an
/// observation are left out.
///
/// # Errors
/// [`TableError::UnknownIds`] listing every observed id that the table does not have.
pub fn pair(points: &PointTable, obs: &Observations) -> Result<Pairs, TableError> {
    let by_id: BTreeMap<&str, &Vector3<f64>> = points
        .rows
        .iter()
        .map(|(i, p, _)| (i.as_str(), p))
        .collect();
    let unknown: Vec<String> = obs
        .rows
        .iter()
        .filter(|(i, _, _)| !by_id.contains_key(i.as_str()))
        .map(|(i, _, o)| format!("{i} ({o})"))
        .collect();
    if !unknown.is_empty() {
        return Err(TableError::UnknownIds {
            points: points.file.clone(),
            ids: unknown,
        });
    }
    let mut pairs = Pairs {
        ids: Vec::new(),
        points_mm: Vec::new(),
        pixels_px: Vec::new(),
    };
    for (i, uv, _) in &obs.rows {
        pairs.ids.push(i.clone());
        pairs.points_mm.push(*by_id[i.as_str()]);
        pairs.pixels_px.push(*uv);
    }
    Ok(pairs)
}

/// The capture plan `fabkit fixtures` writes (`points/capture_plan.csv`: `capture,id,ring`):
/// the ids of the pins inserted together for each capture, captures numbered from 1.
#[derive(Debug, Clone, PartialEq)]
pub struct CapturePlan {
    pub file: String,
    /// Ids per capture, capture 1 first.
    pub captures: Vec<Vec<String>>,
}

/// Reads a capture plan (`capture,id,ring`; captures numbered 1, 2, ... without gaps; a pin may
/// stay in for several captures, once per capture).
///
/// # Errors
/// [`TableError`] naming file:line: missing columns, a capture number that is not a positive
/// integer or skips one, an id listed twice in one capture.
pub fn read_capture_plan(path: &Path) -> Result<CapturePlan, TableError> {
    let (file, text) = read(path)?;
    parse_capture_plan(&text, &file)
}

/// Parses a capture plan's text. See [`read_capture_plan`].
///
/// # Errors
/// As [`read_capture_plan`].
pub fn parse_capture_plan(text: &str, file: &str) -> Result<CapturePlan, TableError> {
    let mut csv = parse_csv(text, file)?;
    all_rows(std::mem::take(&mut csv.bad))?;
    let expected = "capture,id,ring";
    let cc = csv.column("capture", expected)?;
    let ci = csv.column("id", expected)?;
    let mut captures: Vec<Vec<String>> = Vec::new();
    let mut seen: BTreeMap<(usize, String), usize> = BTreeMap::new();
    for (line, cells) in &csv.rows {
        let raw = cells[cc];
        let k: usize = raw
            .parse()
            .ok()
            .filter(|&k| k >= 1)
            .ok_or_else(|| TableError::Field {
                file: file.into(),
                line: *line,
                column: "capture".into(),
                value: raw.into(),
                rule: "must be a positive integer".into(),
            })?;
        if k > captures.len() + 1 {
            return Err(TableError::Field {
                file: file.into(),
                line: *line,
                column: "capture".into(),
                value: raw.into(),
                rule: format!(
                    "captures are numbered without gaps (next is {})",
                    captures.len() + 1
                ),
            });
        }
        if k == captures.len() + 1 {
            captures.push(Vec::new());
        }
        let id = csv.id(*line, cells, ci)?;
        if let Some(first) = seen.insert((k, id.clone()), *line) {
            return Err(TableError::Duplicate {
                id,
                first: format!("{file}:{first}"),
                second: format!("{file}:{line}"),
            });
        }
        captures[k - 1].push(id);
    }
    Ok(CapturePlan {
        file: file.into(),
        captures,
    })
}

/// Least robust noise of a pin's centroid, px, per axis, when its observations are combined
/// ([`combine_observations`]): observations that agree closer than this are all kept.
pub const MIN_CENTROID_NOISE_PX: f64 = 0.02;

/// One pin's observations from several captures combined into one pixel, px. The camera does
/// not move between captures, so they differ by the centroids' noise, unless one is bad (a spot
/// merged with a neighbour's, or grown into the imprint's halo). Two or fewer: their mean. More:
/// about the coordinate-wise median `m`, the robust noise per axis `sigma` = median |p - m| /
/// sqrt(2 ln 2) (the median length of a 2D Gaussian error), at least
/// [`MIN_CENTROID_NOISE_PX`]; the mean of the observations within
/// [`crate::pnp::threshold_sigmas`]`(n)` sigma of `m` (none of n good ones left out but with
/// probability 0.002). The result does not depend on the observations' order but for the
/// rounding of a sum.
pub fn combine_observations(px: &[Vector2<f64>]) -> Vector2<f64> {
    let n = px.len();
    let mean = |v: &[Vector2<f64>]| v.iter().sum::<Vector2<f64>>() / v.len().max(1) as f64;
    if n <= 2 {
        return mean(px);
    }
    let median = |mut v: Vec<f64>| crate::median_sorting(&mut v);
    let m = Vector2::new(
        median(px.iter().map(|p| p.x).collect()),
        median(px.iter().map(|p| p.y).collect()),
    );
    let sigma = (median(px.iter().map(|p| (p - m).norm()).collect())
        / (2.0 * std::f64::consts::LN_2).sqrt())
    .max(MIN_CENTROID_NOISE_PX);
    let reach = crate::pnp::threshold_sigmas(n) * sigma;
    let mut kept: Vec<Vector2<f64>> = px
        .iter()
        .copied()
        .filter(|p| (p - m).norm() <= reach)
        .collect();
    // a consistent order for the sum
    kept.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    mean(&kept)
}

/// Reads observation files given one per capture, in capture order, and checks them against
/// the plan: every id of file k must be a pin of capture k. A pin that stays in for several
/// captures (the pole pin of a fixtures plan) may be observed in each of them; the camera does
/// not move between captures, so its observations are combined into one
/// ([`combine_observations`]; origins joined by ` + `).
/// Pins of the plan that were not observed are allowed (a pin the detector missed); they are
/// returned, in plan order, with the merged observations (first-seen order).
///
/// # Errors
/// [`TableError::CaptureCount`] when the number of files differs from the number of captures;
/// [`TableError::NotInCapture`] naming the row of the first id observed in the wrong capture;
/// the errors of [`read_observations`] for each file (a duplicate id within one file).
pub fn read_captures(
    paths: &[&Path],
    plan: &CapturePlan,
) -> Result<(Observations, Vec<String>), TableError> {
    with_texts(paths, |refs| parse_captures(refs, plan))
}

/// [`read_captures`] on (text, file name) pairs.
///
/// # Errors
/// As [`read_captures`].
pub fn parse_captures(
    texts: &[(&str, &str)],
    plan: &CapturePlan,
) -> Result<(Observations, Vec<String>), TableError> {
    if texts.len() != plan.captures.len() {
        return Err(TableError::CaptureCount {
            plan: plan.file.clone(),
            captures: plan.captures.len(),
            files: texts.len(),
        });
    }
    // id -> (pixels, origins), in first-seen order.
    let mut merged: Vec<(String, Vec<Vector2<f64>>, Vec<Origin>)> = Vec::new();
    for (k, pair) in texts.iter().enumerate() {
        let obs = parse_observations(std::slice::from_ref(pair))?;
        for (id, uv, origin) in obs.rows {
            if !plan.captures[k].contains(&id) {
                let home = plan.captures.iter().position(|c| c.contains(&id));
                return Err(TableError::NotInCapture {
                    origin,
                    id,
                    capture: k + 1,
                    plan: plan.file.clone(),
                    where_: match home {
                        Some(c) => format!("the plan has it in capture {}", c + 1),
                        None => "the plan does not list it".into(),
                    },
                });
            }
            match merged.iter_mut().find(|m| m.0 == id) {
                Some(m) => {
                    m.1.push(uv);
                    m.2.push(origin);
                }
                None => merged.push((id, vec![uv], vec![origin])),
            }
        }
    }
    let unobserved = plan
        .captures
        .iter()
        .flatten()
        .filter(|i| !merged.iter().any(|m| &m.0 == *i))
        .fold(Vec::<String>::new(), |mut v, i| {
            if !v.contains(i) {
                v.push(i.clone());
            }
            v
        });
    let rows = merged
        .into_iter()
        .map(|(id, px, origins)| (id, combine_observations(&px), origins.join(" + ")))
        .collect();
    Ok((Observations { rows }, unobserved))
}
