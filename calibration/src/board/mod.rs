//! A flat sensor's camera from one board press (9DTact, Lin et al., RA-L 2024, Sec. III-C: a
//! printed board of 7 x 9 bumps on a 2.5 mm grid pressed into the gel; `fabkit fixtures` builds
//! it and writes its point table): the bumps' imprints are found against the reference image,
//! each is given its grid id by walking the lattice they form, and the camera model that maps
//! the gel plane to pixels is solved from them, with the map from pixels back to the plane.
//! A grid plate pressed a few pins at a time (Soter et al.'s, with its capture plan) is the
//! same flow over several captures: the imprints of all of them form the lattice
//! ([`find_bumps_in_captures`]).
//!
//! What one planar view determines (Zhang, "A flexible new technique for camera calibration",
//! IEEE TPAMI 22(11), 2000, Sec. 2-3: a plane gives two constraints on the intrinsics per
//! view): the distortion and its centre, the aspect, and the plane's tilt and lateral offset;
//! for a plane seen square on, the focal length and the plane's distance trade one for the
//! other (only their ratio, the scale in px per mm, is seen). The focal length is therefore
//! held at the value that puts the plane at `plane_distance_mm`, and every parameter the
//! press does not constrain is held and said so ([`crate::refine`]'s condition rule).
//!
//! The rays are straight from the lens: the window's and the gel's refraction (a flat slab
//! bends each ray by an amount that depends on its angle off the axis only, which for a plane
//! seen square on is a radial distortion of the image) is taken up by the radial
//! coefficients; the model so holds for points on this plane, which is what the press
//! calibrates.
//!
//! Frames: sensor frame, mm (docs/conventions.md); pixel (0, 0) the centre of the top-left
//! pixel.

pub mod synthetic;

use crate::camera::{CameraModel, Distortion, Intrinsics};
use crate::imprints::{detect, DetectParams, GrayImage, Spot};
use crate::pnp::{solve_pnp, PnpOptions};
use crate::refine::{refine_intrinsics, RefineParameters, RefinedParameter};
use crate::tables::PointTable;
use nalgebra::{Isometry3, Vector2, Vector3};
use serde::Serialize;

/// Why a board press cannot be calibrated; each names the option or file and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoardError {
    #[error("--points {file}: {rule}")]
    Table { file: String, rule: String },
    #[error("--image {file}: {rule}")]
    Press { file: String, rule: String },
    #[error("--reference {file}: {rule}")]
    Reference { file: String, rule: String },
    #[error("--capture-plan {file}: {rule}")]
    Plan { file: String, rule: String },
    #[error("--plane-distance-mm = {value}: {rule}")]
    PlaneDistance { value: String, rule: String },
    #[error("--board-turn = {value}: {rule}")]
    Turn { value: String, rule: String },
    #[error("the camera model: {0}")]
    Solve(String),
}

/// How the board's grid lies in the image: the camera mounted turned about its optical axis
/// by a number of quarter turns (`--board-turn`, degrees). With the turn `t` the sensor's +x
/// runs in the image along `(cos t, sin t)` in (u, v), from u towards v (clockwise as an
/// image is shown, v down), and +y along `(-sin t, cos t)`: the rotation of T_cam_sensor is
/// the unturned one followed by `t` about the camera's z (its optical axis). An image of the
/// unturned camera turned by the image crate's `rotate90` (clockwise) is one of `Deg90`.
///
/// The board's grid is symmetric under a half turn (and a square grid under a quarter turn),
/// so the turn cannot be seen in a capture: it is given, and ids are placed as it says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoardTurn {
    /// The image's u along the sensor's +x, v along +y.
    #[default]
    Deg0,
    /// u along -y, v along +x.
    Deg90,
    /// u along -x, v along -y.
    Deg180,
    /// u along +y, v along -x.
    Deg270,
}

impl BoardTurn {
    /// The four turns, in order.
    pub const ALL: [BoardTurn; 4] = [Self::Deg0, Self::Deg90, Self::Deg180, Self::Deg270];

    /// The turn of `deg` degrees: 0, 90, 180 or 270.
    ///
    /// # Errors
    /// [`BoardError::Turn`] for any other value (a multiple of 90 outside 0..=270 is told its
    /// equivalent).
    pub fn from_deg(deg: f64) -> Result<Self, BoardError> {
        if let Some(t) = Self::ALL.iter().find(|t| f64::from(t.deg()) == deg) {
            return Ok(*t);
        }
        let mut rule = "must be 0, 90, 180 or 270: the board's grid turned in the image by quarter turns, degrees from the image's u towards its v".to_string();
        if deg.is_finite() && deg % 90.0 == 0.0 {
            rule += &format!(" ({} is {})", crate::shown_f64(deg), deg.rem_euclid(360.0));
        }
        Err(BoardError::Turn {
            value: crate::shown_f64(deg),
            rule,
        })
    }

    /// The turn, degrees: 0, 90, 180 or 270.
    pub fn deg(self) -> u32 {
        match self {
            Self::Deg0 => 0,
            Self::Deg90 => 90,
            Self::Deg180 => 180,
            Self::Deg270 => 270,
        }
    }

    /// (cos t, sin t), exact.
    fn cos_sin(self) -> (f64, f64) {
        match self {
            Self::Deg0 => (1.0, 0.0),
            Self::Deg90 => (0.0, 1.0),
            Self::Deg180 => (-1.0, 0.0),
            Self::Deg270 => (0.0, -1.0),
        }
    }

    /// An image vector (u, v), px, turned back by `-t`: where it would lie in the unturned
    /// camera's image (about the origin; exact, as a quarter turn only swaps and negates).
    pub fn unturn(self, p: Vector2<f64>) -> Vector2<f64> {
        let (c, s) = self.cos_sin();
        Vector2::new(c * p.x + s * p.y, -s * p.x + c * p.y)
    }

    /// The image's directions along which the sensor's +x and +y run, in words (`"+u"`, ...).
    pub fn axes_in_image(self) -> (&'static str, &'static str) {
        match self {
            Self::Deg0 => ("+u", "+v"),
            Self::Deg90 => ("+v", "-u"),
            Self::Deg180 => ("-u", "-v"),
            Self::Deg270 => ("-v", "+u"),
        }
    }
}

/// One bump of the board: its id (the point table's), its place in the grid and its point on
/// the plane, sensor frame, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPoint {
    pub id: String,
    pub row: u32,
    pub column: u32,
    pub point_mm: Vector3<f64>,
}

/// The board's grid as its point table gives it: `rows` along y, `columns` along x, at
/// `pitch_mm`, every point on the plane `z = plane_z_mm`.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardGrid {
    pub rows: u32,
    pub columns: u32,
    pub pitch_mm: f64,
    pub plane_z_mm: f64,
    /// Row by row from -y, each from -x.
    pub points: Vec<GridPoint>,
}

impl BoardGrid {
    /// The point at (`row`, `column`).
    pub fn at(&self, row: u32, column: u32) -> Option<&GridPoint> {
        self.points
            .iter()
            .find(|p| p.row == row && p.column == column)
    }
}

/// How far a table point may lie off its grid place or off the plane, mm.
const GRID_TOLERANCE_MM: f64 = 1e-6;

/// The grid of a point table: its points must lie on one plane of constant z and fill a
/// rectangular grid of one pitch along x and y (as `fabkit fixtures` writes the board's), at
/// least 2 x 2.
///
/// # Errors
/// [`BoardError::Table`] naming the rule the table breaks.
pub fn board_grid(table: &PointTable) -> Result<BoardGrid, BoardError> {
    let bad = |rule: String| BoardError::Table {
        file: table.file.clone(),
        rule,
    };
    let pts = &table.rows;
    if pts.len() < 4 {
        return Err(bad(format!(
            "{} points: a board has at least a 2 x 2 grid",
            pts.len()
        )));
    }
    let z = pts[0].1.z;
    if let Some((id, p, at)) = pts
        .iter()
        .find(|(_, p, _)| (p.z - z).abs() > GRID_TOLERANCE_MM)
    {
        return Err(bad(format!(
            "point {id} ({at}) has z = {} mm but the first has {z} mm: a board's points lie on one plane of constant z",
            p.z
        )));
    }
    let distinct = |f: fn(&Vector3<f64>) -> f64| -> Vec<f64> {
        let mut v: Vec<f64> = pts.iter().map(|(_, p, _)| f(p)).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() <= GRID_TOLERANCE_MM);
        v
    };
    let (xs, ys) = (distinct(|p| p.x), distinct(|p| p.y));
    let (columns, rows) = (xs.len() as u32, ys.len() as u32);
    if columns < 2 || rows < 2 || (columns * rows) as usize != pts.len() {
        return Err(bad(format!(
            "{} points on {} distinct x and {} distinct y: a board's points fill a rectangular grid of at least 2 x 2",
            pts.len(),
            columns,
            rows
        )));
    }
    let pitch = xs[1] - xs[0];
    let uneven = xs
        .windows(2)
        .chain(ys.windows(2))
        .find(|w| ((w[1] - w[0]) - pitch).abs() > GRID_TOLERANCE_MM);
    if let Some(w) = uneven {
        return Err(bad(format!(
            "the grid's steps differ ({} mm and {pitch} mm): a board's bumps are at one pitch along x and y",
            w[1] - w[0]
        )));
    }
    let place = |v: f64, axis: &[f64]| axis.iter().position(|a| (a - v).abs() <= GRID_TOLERANCE_MM);
    let mut points: Vec<GridPoint> = pts
        .iter()
        .map(|(id, p, _)| GridPoint {
            id: id.clone(),
            row: place(p.y, &ys).unwrap_or(0) as u32,
            column: place(p.x, &xs).unwrap_or(0) as u32,
            point_mm: *p,
        })
        .collect();
    points.sort_by_key(|p| (p.row, p.column));
    if let Some(w) = points
        .windows(2)
        .find(|w| (w[0].row, w[0].column) == (w[1].row, w[1].column))
    {
        return Err(bad(format!(
            "points {} and {} are at one place of the grid",
            w[0].id, w[1].id
        )));
    }
    Ok(BoardGrid {
        rows,
        columns,
        pitch_mm: pitch,
        plane_z_mm: z,
        points,
    })
}

/// The detector's settings for a board press: the difference smoothed over 1 px, spots from 4
/// noise sigmas grown down to 4/3, at least 12 px. A board's imprints are soft and shallow
/// (9DTact's peak 15 to 20 grey levels over a noise of about 2) and cover a good part of the
/// image, which raises the robust noise estimate: 6 sigmas found 4 of 9DTact's 63.
pub fn board_detect_params() -> DetectParams {
    DetectParams {
        smooth_sigma_px: 1.0,
        threshold_sigma: 4.0,
        grow_sigma: 4.0 / 3.0,
        min_area_px: 12,
        edge_tolerance_px: 2,
        compensate_gain: true,
        core_fraction: 0.0,
    }
}

/// A spot the lattice walk took for a bump, with its grid place.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FoundBump {
    pub id: String,
    pub row: u32,
    pub column: u32,
    pub u_px: f64,
    pub v_px: f64,
}

/// A spot that is no bump, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExtraSpot {
    pub u_px: f64,
    pub v_px: f64,
    pub why: String,
}

/// What the lattice walk made of the spots.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridFind {
    /// Grid order (row by row from -y).
    pub found: Vec<FoundBump>,
    /// Ids of the board with no spot.
    pub missing: Vec<String>,
    pub extra: Vec<ExtraSpot>,
    /// The spacing of neighbouring imprints at the walk's start (the imprint nearest the
    /// spots' centre), px.
    pub pitch_px_at_start: f64,
    /// How the ids were placed on the walked lattice, in words.
    pub notes: Vec<String>,
}

/// A spot within this fraction of a step of where the walk expects a neighbour is that
/// neighbour.
const STEP_TOLERANCE: f64 = 0.3;

/// Assigns grid ids to `spots` (centres, px) with the camera unturned: [`assign_grid_turned`]
/// with [`BoardTurn::Deg0`] (the image's u along the sensor's +x, v along +y).
///
/// # Errors
/// As [`assign_grid_turned`].
pub fn assign_grid(
    spots: &[(f64, f64)],
    grid: &BoardGrid,
    centre_px: (f64, f64),
    file: &str,
) -> Result<GridFind, BoardError> {
    assign_grid_turned(spots, grid, centre_px, BoardTurn::Deg0, file)
}

/// Assigns grid ids to `spots` (centres, px): the lattice they form is walked from the spot
/// nearest their centre, each step predicted from the last one taken in that direction (the
/// spacing changes across a distorted image), across a missing imprint by a double step.
/// The board's x (its columns) runs along the image's u turned by `turn` and its y (its rows)
/// along v turned by `turn` ([`BoardTurn`]): unturned, the camera looks up at the skin along
/// +z with its image's right along +x (docs/conventions.md), so that the right-handed camera
/// frame has the sensor frame's axes. The walk runs on the spots turned back by `turn`, so a
/// 7 x 9 board seen a quarter turned (9 tall and 7 wide in the image) walks as 7 x 9. A walked
/// lattice smaller than the grid is placed on it so that the imprint nearest the image's
/// centre `centre_px` is as near the grid's centre as it can be (said in `notes`). The answer
/// does not depend on the spots' order.
///
/// # Errors
/// [`BoardError::Press`] (`file` the capture) when fewer than 4 spots lie on the lattice, or
/// the lattice is larger than the grid (another board, or the grid turned against the image
/// otherwise than `turn` says: the message says which turn fits).
pub fn assign_grid_turned(
    spots: &[(f64, f64)],
    grid: &BoardGrid,
    centre_px: (f64, f64),
    turn: BoardTurn,
    file: &str,
) -> Result<GridFind, BoardError> {
    let bad = |rule: String| BoardError::Press {
        file: file.to_string(),
        rule,
    };
    // (the spot turned back into the unturned image, the spot's pixel), in the unturned
    // image's order, so that a turned capture walks as the unturned one
    let mut pairs: Vec<(Vector2<f64>, Vector2<f64>)> = spots
        .iter()
        .map(|&(u, v)| (turn.unturn(Vector2::new(u, v)), Vector2::new(u, v)))
        .collect();
    pairs.sort_by(|a, b| a.0.y.total_cmp(&b.0.y).then(a.0.x.total_cmp(&b.0.x)));
    let (pts, pixels): (Vec<Vector2<f64>>, Vec<Vector2<f64>>) = pairs.into_iter().unzip();
    if pts.len() < 4 {
        return Err(bad(format!(
            "{} imprints found: at least 4 of the board's {} are needed",
            pts.len(),
            grid.points.len()
        )));
    }
    // the typical spacing: the median distance to the nearest other spot
    let mut nn: Vec<f64> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            pts.iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, q)| (q - p).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let spacing = crate::median_sorting(&mut nn);
    let mean = pts.iter().sum::<Vector2<f64>>() / pts.len() as f64;
    let start = nearest(&pts, &mean, f64::INFINITY).unwrap_or(0);
    // the first steps: the neighbours most along +u and +v within 1.6 spacings
    let axis_step = |dir: Vector2<f64>| -> Vector2<f64> {
        let p = pts[start];
        let best = pts
            .iter()
            .map(|q| q - p)
            .filter(|d| d.norm() > 0.5 * spacing && d.norm() < 1.6 * spacing)
            .map(|d| (d.dot(&dir) / d.norm(), d))
            .filter(|(c, _)| c.abs() > std::f64::consts::FRAC_1_SQRT_2)
            .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
        match best {
            Some((c, d)) if c < 0.0 => -d,
            Some((_, d)) => d,
            None => dir * spacing,
        }
    };
    let (step_u, step_v) = (axis_step(Vector2::x()), axis_step(Vector2::y()));
    let pitch_px_at_start = (step_u.norm() + step_v.norm()) / 2.0;
    // breadth-first walk: (spot, lattice (i, j), its steps along i and j)
    let mut place: Vec<Option<(i64, i64)>> = vec![None; pts.len()];
    let mut steps: Vec<(Vector2<f64>, Vector2<f64>)> = vec![(step_u, step_v); pts.len()];
    place[start] = Some((0, 0));
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(k) = queue.pop_front() {
        let Some((i, j)) = place[k] else { continue };
        let (su, sv) = steps[k];
        for (di, dj, s) in [(1, 0, su), (-1, 0, -su), (0, 1, sv), (0, -1, -sv)] {
            for n in [1i64, 2] {
                let at = pts[k] + s * n as f64;
                let Some(q) = nearest(&pts, &at, STEP_TOLERANCE * s.norm() * n as f64) else {
                    continue;
                };
                if place[q].is_none() {
                    place[q] = Some((i + di * n, j + dj * n));
                    let taken = (pts[q] - pts[k]) / n as f64;
                    steps[q] = if di != 0 {
                        (taken * di as f64, sv)
                    } else {
                        (su, taken * dj as f64)
                    };
                    queue.push_back(q);
                }
                break;
            }
        }
    }
    let walked: Vec<(usize, (i64, i64))> = place
        .iter()
        .enumerate()
        .filter_map(|(k, p)| p.map(|p| (k, p)))
        .collect();
    let (imin, imax) = min_max(walked.iter().map(|(_, p)| p.0));
    let (jmin, jmax) = min_max(walked.iter().map(|(_, p)| p.1));
    let (wide, tall) = ((imax - imin + 1) as u32, (jmax - jmin + 1) as u32);
    if wide > grid.columns || tall > grid.rows {
        let (x_dir, y_dir) = turn.axes_in_image();
        let hint = if wide <= grid.rows && tall <= grid.columns {
            let quarter = |k: u32| (turn.deg() + k) % 360;
            format!(
                "the camera turned a quarter turn against the sensor's x otherwise than --board-turn {} says (--board-turn {} or {} fits this lattice)",
                turn.deg(),
                quarter(90),
                quarter(270)
            )
        } else {
            "or a lattice larger than the board".to_string()
        };
        return Err(bad(format!(
            "the imprints form a lattice {wide} wide (along the image's {x_dir}) and {tall} tall (along its {y_dir}), larger than the board's {} columns (along x) and {} rows (along y): another board, or {hint}",
            grid.columns, grid.rows
        )));
    }
    let mut notes = Vec::new();
    let centre = turn.unturn(Vector2::new(centre_px.0, centre_px.1));
    let middle = walked
        .iter()
        .min_by(|a, b| {
            (pts[a.0] - centre)
                .norm()
                .total_cmp(&(pts[b.0] - centre).norm())
                .then(a.1.cmp(&b.1))
        })
        .map(|(_, p)| *p)
        .unwrap_or((0, 0));
    let mut offset = |lo: i64, n: u32, at: i64, size: u32, what: &str| -> i64 {
        if n == size {
            return -lo;
        }
        // place the walked part so that `at` is nearest the grid's middle
        let target = (size as f64 - 1.0) / 2.0;
        let best = (0..=(size - n) as i64)
            .min_by(|a, b| {
                let da = ((at - lo + a) as f64 - target).abs();
                let db = ((at - lo + b) as f64 - target).abs();
                da.total_cmp(&db)
            })
            .unwrap_or(0);
        notes.push(format!(
            "{n} of the board's {size} {what} have imprints: placed with the imprint nearest the image's centre in the board's middle {}",
            if what == "columns" { "column" } else { "row" }
        ));
        best - lo
    };
    let di = offset(imin, wide, middle.0, grid.columns, "columns");
    let dj = offset(jmin, tall, middle.1, grid.rows, "rows");
    let mut found = Vec::new();
    for (k, (i, j)) in &walked {
        let (column, row) = ((i + di) as u32, (j + dj) as u32);
        if let Some(g) = grid.at(row, column) {
            found.push(FoundBump {
                id: g.id.clone(),
                row,
                column,
                u_px: pixels[*k].x,
                v_px: pixels[*k].y,
            });
        }
    }
    found.sort_by_key(|f| (f.row, f.column));
    let missing = grid
        .points
        .iter()
        .filter(|g| !found.iter().any(|f| f.id == g.id))
        .map(|g| g.id.clone())
        .collect();
    let extra = place
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_none())
        .map(|(k, _)| ExtraSpot {
            u_px: pixels[k].x,
            v_px: pixels[k].y,
            why: "not on the lattice the other imprints form".into(),
        })
        .collect();
    if found.len() < 4 {
        return Err(bad(format!(
            "{} imprints lie on one lattice: at least 4 of the board's {} are needed",
            found.len(),
            grid.points.len()
        )));
    }
    Ok(GridFind {
        found,
        missing,
        extra,
        pitch_px_at_start,
        notes,
    })
}

/// The index of the point of `pts` nearest `at` within `within`, the first on a tie.
fn nearest(pts: &[Vector2<f64>], at: &Vector2<f64>, within: f64) -> Option<usize> {
    pts.iter()
        .enumerate()
        .map(|(k, p)| (k, (p - at).norm()))
        .filter(|(_, d)| *d <= within)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

fn min_max(v: impl Iterator<Item = i64>) -> (i64, i64) {
    v.fold((i64::MAX, i64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)))
}

/// The camera solved from a board press.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardCamera {
    pub camera: CameraModel,
    /// T_cam_sensor: sensor-frame points (mm) into the camera frame (mm).
    pub t_cam_sensor: Isometry3<f64>,
    /// The intrinsics, each refined with its standard deviation or held with why.
    pub parameters: Vec<RefinedParameter>,
    pub condition_number: f64,
    /// Per found bump (grid order), reprojected minus observed, px.
    pub residuals_px: Vec<Vector2<f64>>,
    /// RMS of the residuals' lengths, px.
    pub rms_px: f64,
    /// Standard deviations of the pose: rotation about the camera's axes, degrees, and
    /// translation along them, mm.
    pub pose_std: Option<([f64; 3], [f64; 3])>,
}

/// Solves the camera (plumb_bob model) and the plane's pose from the found bumps: the focal
/// length held at the value that puts the solved plane `plane_distance_mm` from the lens's
/// centre of projection (in air: each layer's thickness over its refractive index, paraxial;
/// along the sensor's z), the pose by PnP, then the pose and every intrinsic the press constrains
/// by Levenberg-Marquardt on the reprojection error ([`crate::refine`]: a parameter that
/// trades against the pose, such as the principal point against the plane's offset, is held
/// and the report says with what; the focal length is held in any case).
///
/// # Errors
/// [`BoardError::Solve`] when the pose or the refinement fails.
pub fn solve_board_camera(
    grid: &BoardGrid,
    find: &GridFind,
    size_px: (u32, u32),
    plane_distance_mm: f64,
) -> Result<BoardCamera, BoardError> {
    let (points, pixels): (Vec<Vector3<f64>>, Vec<Vector2<f64>>) = find
        .found
        .iter()
        .filter_map(|b| {
            grid.at(b.row, b.column)
                .map(|g| (g.point_mm, Vector2::new(b.u_px, b.v_px)))
        })
        .unzip();
    // The focal length that puts the solved plane at its distance: started from the spacing
    // at the walk's start (which the distortion and the tilt stretch by a few per cent), then
    // scaled by the distance the solve gives over the one wanted until they agree (3 solves
    // on a synthetic press: 15.35, 15.0015, 15.0000 mm)
    let mut f = plane_distance_mm * find.pitch_px_at_start / grid.pitch_mm;
    let mut solved = None;
    for _ in 0..MAX_FOCAL_PASSES {
        let r = solve_at_focal(f, size_px, &points, &pixels)?;
        let centre = r.t_cam_sensor.inverse().translation.vector;
        let d = grid.plane_z_mm - centre.z;
        let done = !(d > 0.0) || (d / plane_distance_mm - 1.0).abs() < 1e-9;
        let freed = r
            .parameters
            .iter()
            .any(|p| (p.name == "fx" || p.name == "fy") && p.held.is_none());
        solved = Some(r);
        if done || freed {
            break;
        }
        f *= plane_distance_mm / d;
    }
    let Some(r) = solved else {
        return Err(BoardError::Solve("no solve".into()));
    };
    let residuals_px: Vec<Vector2<f64>> = points
        .iter()
        .zip(&pixels)
        .map(|(p, px)| {
            r.camera
                .project(&(r.t_cam_sensor * nalgebra::Point3::from(*p)).coords)
                .map_or(Vector2::new(f64::NAN, f64::NAN), |q| q - px)
        })
        .collect();
    let rms_px = (residuals_px.iter().map(|e| e.norm_squared()).sum::<f64>()
        / residuals_px.len() as f64)
        .sqrt();
    let mut parameters = r.parameters.clone();
    for p in &mut parameters {
        if (p.name == "fx" || p.name == "fy") && p.held.is_some() {
            p.held = Some(format!(
                "a plane seen square on shows the focal length only over its distance: held at {:.3} px, which puts the plane {:.4} mm from the lens",
                p.value, plane_distance_mm
            ));
        }
    }
    Ok(BoardCamera {
        camera: r.camera,
        t_cam_sensor: r.t_cam_sensor,
        parameters,
        condition_number: r.condition_number,
        residuals_px,
        rms_px,
        pose_std: r.pose_std,
    })
}

/// Most solves [`solve_board_camera`] makes to put the plane at its distance.
const MAX_FOCAL_PASSES: usize = 10;

/// The pose by PnP and the intrinsics the press constrains, from a plumb_bob camera of focal
/// length `f` px, the principal point at the image's centre and no distortion.
fn solve_at_focal(
    f: f64,
    size_px: (u32, u32),
    points: &[Vector3<f64>],
    pixels: &[Vector2<f64>],
) -> Result<crate::refine::Refinement, BoardError> {
    let start = Intrinsics {
        image_width_px: size_px.0,
        image_height_px: size_px.1,
        fx_px: f,
        fy_px: f,
        cx_px: (size_px.0 as f64 - 1.0) / 2.0,
        cy_px: (size_px.1 as f64 - 1.0) / 2.0,
        distortion: Distortion::PlumbBob([0.0; 5]),
    };
    let camera = CameraModel::new(start).map_err(|e| BoardError::Solve(e.to_string()))?;
    let pose = solve_pnp(
        &camera,
        points,
        pixels,
        &PnpOptions {
            ransac: None,
            max_iterations: 100,
        },
    )
    .map_err(|e| BoardError::Solve(e.to_string()))?;
    refine_intrinsics(
        &camera,
        points,
        pixels,
        &pose.t_cam_sensor,
        &RefineParameters::Constrained,
    )
    .map_err(|e| BoardError::Solve(e.to_string()))
}

/// Where the ray of each pixel meets the plane `z = plane_z_mm` (sensor frame), mm: `[x, y]`
/// per pixel, row-major (`(v * width + u) * 2`), NaN where the pixel does not unproject or its
/// ray misses the plane.
pub fn pixel_to_plane_mm(bc: &BoardCamera, plane_z_mm: f64) -> Vec<f32> {
    let i = bc.camera.intrinsics();
    let (w, h) = (i.image_width_px as usize, i.image_height_px as usize);
    let inv = bc.t_cam_sensor.inverse();
    let mut out = vec![f32::NAN; w * h * 2];
    for v in 0..h {
        for u in 0..w {
            let px = Vector2::new(u as f64, v as f64);
            if let Some(p) = pixel_on_plane(&bc.camera, &inv, plane_z_mm, px) {
                out[(v * w + u) * 2] = p.x as f32;
                out[(v * w + u) * 2 + 1] = p.y as f32;
            }
        }
    }
    out
}

/// Where the ray of pixel `px` meets the plane `z = plane_z_mm`: its (x, y) in the sensor
/// frame, mm, with `t_sensor_cam` the camera's pose in the sensor frame (the inverse of
/// T_cam_sensor); `None` when the pixel does not unproject or its ray runs parallel to the
/// plane or away from it.
pub fn pixel_on_plane(
    camera: &CameraModel,
    t_sensor_cam: &Isometry3<f64>,
    plane_z_mm: f64,
    px: Vector2<f64>,
) -> Option<Vector2<f64>> {
    let d = t_sensor_cam.rotation * camera.unproject(&px).ok()?;
    let o = t_sensor_cam.translation.vector;
    let t = (plane_z_mm - o.z) / d.z;
    (t.is_finite() && t > 0.0).then(|| {
        let p = o + d * t;
        Vector2::new(p.x, p.y)
    })
}

/// The plane's scale at pixel `at_px`: the square root of the area on the plane one pixel
/// covers there (the Jacobian's determinant of the pixel-to-plane map), mm per px.
pub fn mm_per_px_at(bc: &BoardCamera, plane_z_mm: f64, at_px: Vector2<f64>) -> Option<f64> {
    let inv = bc.t_cam_sensor.inverse();
    let on_plane = |px: Vector2<f64>| pixel_on_plane(&bc.camera, &inv, plane_z_mm, px);
    let e = 0.5;
    let du = on_plane(at_px + Vector2::new(e, 0.0))? - on_plane(at_px - Vector2::new(e, 0.0))?;
    let dv = on_plane(at_px + Vector2::new(0.0, e))? - on_plane(at_px - Vector2::new(0.0, e))?;
    Some(((du.x * dv.y - du.y * dv.x).abs() / (4.0 * e * e)).sqrt())
}

/// A board press to calibrate: the files and the plane's distance.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardJob {
    /// The board's point table (`points/board_table.csv` of `fabkit fixtures`).
    pub points: std::path::PathBuf,
    /// Which of its points lie on the plane the press calibrates (`contact`: the skin's face).
    pub points_from: crate::tables::PointsFrom,
    /// The skin with no contact, and the board pressed in (one capture or several, each
    /// pressing some of the bumps): same camera, lighting and size.
    pub reference: std::path::PathBuf,
    pub images: Vec<std::path::PathBuf>,
    /// Which ids each capture presses (`points/capture_plan.csv` of `fabkit fixtures`), the
    /// captures in `images`' order; none: every spot on the lattice counts.
    pub capture_plan: Option<std::path::PathBuf>,
    /// The plane's distance from the lens's centre of projection in air, mm, and where it
    /// comes from in words.
    pub plane_distance_mm: f64,
    pub plane_distance_from: String,
    /// The board's grid turned in the images (the camera turned about its optical axis):
    /// the ids are placed as [`BoardTurn`] says.
    pub board_turn: BoardTurn,
    pub command_line: String,
}

/// `extrinsics.json`: what the press gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoardReport {
    pub fabkit_version: String,
    pub command_line: String,
    pub points_file: String,
    pub reference_image: String,
    pub capture_images: Vec<String>,
    pub capture_plan: Option<String>,
    pub image_size_px: [u32; 2],
    pub grid: GridSummary,
    /// The board's grid turned in the image, degrees (0, 90, 180 or 270; [`BoardTurn`]): the
    /// sensor's +x runs along the image's u turned this much towards v.
    pub board_turn_deg: u32,
    /// Spots the detector found.
    pub spots: usize,
    pub found: usize,
    pub missing_ids: Vec<String>,
    pub extra_spots: Vec<ExtraSpot>,
    pub notes: Vec<String>,
    /// What each capture showed, in the order given.
    pub captures: Vec<CaptureFind>,
    /// Per found bump, grid order.
    pub bumps: Vec<BumpResidual>,
    /// RMS of the reprojection errors' lengths, px, and the largest with its id.
    pub rms_reprojection_error_px: f64,
    pub worst_px: f64,
    pub worst_id: String,
    pub camera_model: &'static str,
    pub parameters: Vec<RefinedParameter>,
    pub condition_number: f64,
    pub plane_distance_mm: f64,
    pub plane_distance_from: String,
    pub optical_path: String,
    /// T_cam_sensor: rotation vector, rad, translation, mm, and the 4 x 4 matrix (row-major).
    pub rvec: [f64; 3],
    pub tvec_mm: [f64; 3],
    #[serde(rename = "T_cam_sensor")]
    pub t_cam_sensor: [[f64; 4]; 4],
    /// Standard deviations of the pose: rotation about the camera's x, y, z, deg; translation
    /// along them, mm.
    pub pose_std: Option<([f64; 3], [f64; 3])>,
    /// The middle bump's pixel (the grid's centre, or the bump nearest it), px.
    pub centre_bump_px: [f64; 2],
    pub centre_bump_id: String,
    /// The plane's scale at the middle bump under the solved model, mm per px.
    pub mm_per_px_at_centre: Option<f64>,
    /// The pitch over the mean distance from the middle bump to its four neighbours, each
    /// centre rounded to whole pixels (9DTact's camera calibration), mm per px.
    pub mm_per_px_neighbours: Option<f64>,
}

/// The grid of the board.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridSummary {
    pub rows: u32,
    pub columns: u32,
    pub pitch_mm: f64,
    pub plane_z_mm: f64,
}

/// One found bump's residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BumpResidual {
    pub id: String,
    pub row: u32,
    pub column: u32,
    pub point_mm: [f64; 3],
    /// The mean of its pixels over the captures that show it (`observations` of them).
    pub observed_px: [f64; 2],
    pub observations: usize,
    pub reprojected_px: [f64; 2],
    pub reprojection_error_px: f64,
}

/// The result: the report and the files of the output folder.
#[derive(Debug, Clone)]
pub struct BoardOutput {
    pub report: BoardReport,
    /// (file name, bytes): `extrinsics.json` and `extrinsics.yaml` (this report, the pose
    /// among it, as `calibrate extrinsics` writes them), `camera.yaml` (OpenCV),
    /// `camera_info.yaml` (ROS), `camera.json`, `observations.csv`, `pixel_to_plane_mm.npy`
    /// (float32, H x W x 2: x and y on the plane, mm; NaN off it), `overlay.png` (on the
    /// darkest of the captures at each pixel, so that every capture's imprints show).
    pub files: Vec<(String, Vec<u8>)>,
}

/// The claim on a board calibration's output folder (`--out`): the job is the point table,
/// the reference, the captures and the capture plan, by content
/// ([`fabkit_export::OutputClaim::of_inputs`]), so that an earlier calibration in the folder is
/// replaced only by one of the same inputs (or with `force`).
pub fn board_claim(job: &BoardJob, force: bool) -> fabkit_export::OutputClaim {
    let inputs: Vec<&std::path::Path> = [job.points.as_path(), job.reference.as_path()]
        .into_iter()
        .chain(job.images.iter().map(std::path::PathBuf::as_path))
        .chain(job.capture_plan.as_deref())
        .collect();
    fabkit_export::OutputClaim::of_inputs(
        fabkit_export::OutputCommand::CalibrateBoard,
        "a board press",
        &inputs,
        force,
    )
}

/// The design a point table's sidecar (`<table>.json`, as `fabkit fixtures` writes it) names in
/// its provenance (`fabkit V, design NAME (SOURCE, sha256 H)`): its name, the `--design`
/// argument that loads it (the library name for an embedded one) and its sha256; `None` when
/// the sidecar is missing or names no design.
pub fn point_table_design(points: &std::path::Path) -> Option<(String, String, String)> {
    let side = points.with_extension("json");
    let prov = std::fs::read(&side)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|v| v.get("provenance")?.as_str().map(str::to_string))?;
    let (name, inside) = prov.split_once(", design ")?.1.split_once(" (")?;
    let (source, rest) = inside.split_once(", sha256 ")?;
    let arg = source.strip_prefix("embedded:").unwrap_or(source);
    Some((
        name.to_string(),
        arg.to_string(),
        rest.trim_end_matches(')').to_string(),
    ))
}

/// The image size of `path`, px, or why it cannot be read.
fn image_size(path: &std::path::Path) -> Result<(u32, u32), String> {
    image::ImageReader::open(path)
        .map_err(|e| format!("cannot read: {e}"))?
        .with_guessed_format()
        .map_err(|e| format!("cannot read: {e}"))?
        .into_dimensions()
        .map_err(|e| format!("not a readable PNG or JPEG image: {e}"))
}

/// Runs the calibration of `job` (one capture or several, [`find_bumps_in_captures`]); reads
/// only its input files and writes nothing.
///
/// # Errors
/// [`BoardError`]: an unreadable or invalid point table (not one plane, not a grid), an
/// unreadable capture plan, one of another length than the images or with an id the table
/// lacks, an unreadable image or one of another size than the reference, too few imprints on one
/// lattice or a lattice larger than the board, a plane distance that is not finite and
/// positive, a failed solve.
pub fn calibrate_board(job: &BoardJob) -> Result<BoardOutput, BoardError> {
    if !(job.plane_distance_mm.is_finite() && job.plane_distance_mm > 0.0) {
        return Err(BoardError::PlaneDistance {
            value: crate::shown_f64(job.plane_distance_mm),
            rule: "must be finite and > 0".into(),
        });
    }
    let points_file = job.points.display().to_string();
    let table = crate::tables::read_point_table(&job.points, job.points_from).map_err(|e| {
        BoardError::Table {
            file: points_file.clone(),
            rule: e.to_string(),
        }
    })?;
    let grid = board_grid(&table)?;
    let plan = read_plan(job, &grid)?;
    let ref_file = job.reference.display().to_string();
    let size = image_size(&job.reference).map_err(|rule| BoardError::Reference {
        file: ref_file.clone(),
        rule,
    })?;
    if job.images.is_empty() {
        return Err(BoardError::Press {
            file: String::new(),
            rule: "no capture given: at least one".into(),
        });
    }
    for image in &job.images {
        let cap_file = image.display().to_string();
        let cap_size = image_size(image).map_err(|rule| BoardError::Press {
            file: cap_file.clone(),
            rule,
        })?;
        if cap_size != size {
            return Err(BoardError::Press {
                file: cap_file,
                rule: format!(
                    "the image is {} x {} px but the reference {ref_file} is {} x {} px; a press and its reference are taken by one camera",
                    cap_size.0, cap_size.1, size.0, size.1
                ),
            });
        }
    }
    let read = |path: &std::path::Path, option| {
        crate::capture_images::read_gray(path, option, size, "(the reference's size)")
    };
    let reference = read(&job.reference, "--reference").map_err(|e| BoardError::Reference {
        file: ref_file.clone(),
        rule: e.to_string(),
    })?;
    let captures = job
        .images
        .iter()
        .map(|image| {
            let file = image.display().to_string();
            read(image, "--image")
                .map(|g| (file.clone(), g))
                .map_err(|e| BoardError::Press {
                    file,
                    rule: e.to_string(),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let found = find_bumps_in_captures_turned(
        &reference,
        &captures,
        &grid,
        plan.as_deref(),
        job.board_turn,
    )?;
    let bc = solve_board_camera(&grid, &found.find, size, job.plane_distance_mm)?;
    let report = board_report(job, &grid, &found, &bc, size);
    let files = board_files(&report, &bc, &grid, &job.images)?;
    Ok(BoardOutput { report, files })
}

/// The job's capture plan, checked against its images and grid: one capture per image, every
/// id the board's.
fn read_plan(job: &BoardJob, grid: &BoardGrid) -> Result<Option<Vec<Vec<String>>>, BoardError> {
    let Some(path) = &job.capture_plan else {
        return Ok(None);
    };
    let file = path.display().to_string();
    let bad = |rule: String| BoardError::Plan {
        file: file.clone(),
        rule,
    };
    let plan = crate::tables::read_capture_plan(path).map_err(|e| bad(e.to_string()))?;
    if plan.captures.len() != job.images.len() {
        return Err(bad(format!(
            "{} captures but {} --image given: one image per capture, in the plan's order",
            plan.captures.len(),
            job.images.len()
        )));
    }
    for (k, ids) in plan.captures.iter().enumerate() {
        if let Some(id) = ids
            .iter()
            .find(|id| !grid.points.iter().any(|g| &g.id == *id))
        {
            return Err(bad(format!(
                "capture {} presses id {id}, which the point table {} does not hold",
                k + 1,
                job.points.display()
            )));
        }
    }
    Ok(Some(plan.captures))
}

/// The spots of a board press (`capture` against `reference`, grey levels) and the grid they
/// walk ([`assign_grid`]); `file` names the capture in errors. A spot under a fifth of the
/// spots' upper quartile area is left out (`extra`: noise or dust, not an imprint). This is
/// [`find_bumps_in_captures`] of one capture without a plan.
///
/// # Errors
/// [`BoardError::Press`]: no imprint at all, the sizes differ, or [`assign_grid`]'s.
pub fn find_bumps(
    reference: &GrayImage,
    capture: &GrayImage,
    grid: &BoardGrid,
    file: &str,
) -> Result<(Vec<Spot>, GridFind), BoardError> {
    let spots = detect_board_spots(reference, capture, file)?;
    let found = group_and_walk(
        vec![(file.to_string(), spots.clone())],
        image_centre_px(capture),
        grid,
        None,
        BoardTurn::Deg0,
    )?;
    Ok((spots, found.find))
}

/// The image's centre, px.
fn image_centre_px(img: &GrayImage) -> (f64, f64) {
    (
        (img.width as f64 - 1.0) / 2.0,
        (img.height as f64 - 1.0) / 2.0,
    )
}

/// The imprints of one board press (`capture` against `reference`), with
/// [`board_detect_params`]; `file` names the capture in errors.
///
/// # Errors
/// [`BoardError::Press`]: the sizes differ, or no imprint at all.
pub fn detect_board_spots(
    reference: &GrayImage,
    capture: &GrayImage,
    file: &str,
) -> Result<Vec<Spot>, BoardError> {
    let bad = |rule: String| BoardError::Press {
        file: file.to_string(),
        rule,
    };
    let spots =
        detect(reference, capture, None, &board_detect_params()).map_err(|e| bad(e.to_string()))?;
    if spots.is_empty() {
        return Err(bad(
            "no imprint differs from the reference: is the board pressed in, and the reference the same sensor's?".into(),
        ));
    }
    Ok(spots)
}

/// What one capture of a board calibration showed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaptureFind {
    /// 1, 2, ... in the order the captures were given (the plan's, with a plan).
    pub capture: usize,
    pub image: String,
    /// Spots the detector found in it.
    pub spots: usize,
    /// Its spots at the grid places the walk gave them (and, with a plan, that it plans),
    /// grid order, px.
    pub found: Vec<FoundBump>,
    /// Ids its plan presses with no spot in it (empty without a plan).
    pub missing_planned_ids: Vec<String>,
    /// Its spots left out of the solve, and why.
    pub extra: Vec<ExtraSpot>,
}

/// What [`find_bumps_in_captures`] made of several captures.
#[derive(Debug, Clone, PartialEq)]
pub struct CapturesFind {
    /// One pixel per found id (the mean of its observations over the captures), the ids no
    /// capture shows, every capture's spots left out, the walk's notes and its spacing at the
    /// start.
    pub find: GridFind,
    /// Per found id (as `find.found`), how many captures' spots the pixel averages.
    pub observations: Vec<usize>,
    pub captures: Vec<CaptureFind>,
    /// Spots found in all captures.
    pub spots: usize,
}

/// The bumps of a board pressed over several captures, each against one `reference`
/// (captures: (file, image), in order): each capture's imprints are found
/// ([`detect_board_spots`]); spots of different captures closer than the smaller one's
/// radius (the radius of a disc of its area) are one bump pressed in both (single linkage, so
/// the grouping does not depend on the captures' order); the groups' centres form the lattice
/// [`assign_grid`] walks once, and each capture's spots take their group's id. With `plan`
/// (one list of ids per capture, in the captures' order, as [`crate::tables::CapturePlan`]),
/// a spot at a place its capture does not plan is left out (in its capture's `extra`, with
/// why) and a planned id without a spot is `missing_planned_ids`. A bump seen in several
/// captures is solved at the mean of its pixels (taken in order of u then v, so the same
/// captures in any order give the same pixels). With one capture and no plan the result is
/// [`find_bumps`]'.
///
/// # Errors
/// [`BoardError::Press`]: a capture with no imprint, [`assign_grid`]'s on the union (named
/// by every capture's file), or fewer than 4 bumps left after the plan.
pub fn find_bumps_in_captures(
    reference: &GrayImage,
    captures: &[(String, GrayImage)],
    grid: &BoardGrid,
    plan: Option<&[Vec<String>]>,
) -> Result<CapturesFind, BoardError> {
    find_bumps_in_captures_turned(reference, captures, grid, plan, BoardTurn::Deg0)
}

/// [`find_bumps_in_captures`] with the board's grid turned in the images by `turn`
/// ([`BoardTurn`], [`assign_grid_turned`]): the ids placed as if the image's u ran along the
/// sensor's x turned by `turn`.
///
/// # Errors
/// As [`find_bumps_in_captures`].
pub fn find_bumps_in_captures_turned(
    reference: &GrayImage,
    captures: &[(String, GrayImage)],
    grid: &BoardGrid,
    plan: Option<&[Vec<String>]>,
    turn: BoardTurn,
) -> Result<CapturesFind, BoardError> {
    let Some((_, first)) = captures.first() else {
        return Err(BoardError::Press {
            file: String::new(),
            rule: "no capture given: at least one".into(),
        });
    };
    let spots = captures
        .iter()
        .map(|(file, img)| Ok((file.clone(), detect_board_spots(reference, img, file)?)))
        .collect::<Result<Vec<_>, BoardError>>()?;
    group_and_walk(spots, image_centre_px(first), grid, plan, turn)
}

/// A spot under this fraction of the spots' upper quartile area is no imprint.
const SMALL_SPOT_FRACTION: f64 = 0.2;

/// [`find_bumps_in_captures`] from each capture's spots.
fn group_and_walk(
    spots: Vec<(String, Vec<Spot>)>,
    centre_px: (f64, f64),
    grid: &BoardGrid,
    plan: Option<&[Vec<String>]>,
    turn: BoardTurn,
) -> Result<CapturesFind, BoardError> {
    let files: Vec<&str> = spots.iter().map(|(f, _)| f.as_str()).collect();
    let union_file = files.join(", ");
    let per_capture_spots: Vec<usize> = spots.iter().map(|(_, s)| s.len()).collect();
    // noise and dust: spots far smaller than the imprints (sparse captures leave a few)
    let mut areas: Vec<usize> = spots
        .iter()
        .flat_map(|(_, s)| s.iter().map(|s| s.area_px))
        .collect();
    areas.sort_unstable();
    let upper_quartile = areas.get(areas.len() * 3 / 4).copied().unwrap_or(0);
    let small_below = SMALL_SPOT_FRACTION * upper_quartile as f64;
    let mut small: Vec<Vec<ExtraSpot>> = vec![Vec::new(); spots.len()];
    // every other spot: (capture, u, v, radius)
    let mut all: Vec<(usize, f64, f64, f64)> = Vec::new();
    for (k, (_, list)) in spots.iter().enumerate() {
        for s in list {
            if (s.area_px as f64) < small_below {
                small[k].push(ExtraSpot {
                    u_px: s.u_px,
                    v_px: s.v_px,
                    why: format!(
                        "{} px, under a fifth of the spots' upper quartile area ({upper_quartile} px): noise or dust, not an imprint",
                        s.area_px
                    ),
                });
                continue;
            }
            let r = (s.area_px as f64 / std::f64::consts::PI).sqrt();
            all.push((k, s.u_px, s.v_px, r));
        }
    }
    // single-linkage groups of spots of different captures
    let mut parent: Vec<usize> = (0..all.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for a in 0..all.len() {
        for b in a + 1..all.len() {
            let (sa, sb) = (all[a], all[b]);
            if sa.0 != sb.0 && (sa.1 - sb.1).hypot(sa.2 - sb.2) < sa.3.min(sb.3) {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let group_of: Vec<usize> = (0..all.len()).map(|i| root(&mut parent, i)).collect();
    let mut roots: Vec<usize> = group_of.clone();
    roots.sort_unstable();
    roots.dedup();
    let centres: Vec<(f64, f64)> = roots
        .iter()
        .map(|&g| {
            let members: Vec<(f64, f64)> = (0..all.len())
                .filter(|&i| group_of[i] == g)
                .map(|i| (all[i].1, all[i].2))
                .collect();
            mean_in_order(members)
        })
        .collect();
    let walked = assign_grid_turned(&centres, grid, centre_px, turn, &union_file)?;
    // the place of each group: the found bump whose pixel is its centre (copied exactly)
    let id_of_group = |g: usize| -> Option<&FoundBump> {
        let c = centres[roots.binary_search(&g).ok()?];
        walked.found.iter().find(|b| b.u_px == c.0 && b.v_px == c.1)
    };
    let several = files.len() > 1;
    // per grid place (row, column): its id and its pixels over the captures
    type Seen = (String, Vec<(f64, f64)>);
    let mut per_id: std::collections::BTreeMap<(u32, u32), Seen> = Default::default();
    let mut capture_finds = Vec::new();
    for (k, file) in files.iter().enumerate() {
        let planned = plan.and_then(|p| p.get(k));
        let mut found = Vec::new();
        let mut extra = std::mem::take(&mut small[k]);
        for (i, s) in all.iter().enumerate().filter(|(_, s)| s.0 == k) {
            match id_of_group(group_of[i]) {
                Some(b) if planned.is_none_or(|p| p.contains(&b.id)) => {
                    found.push(FoundBump {
                        u_px: s.1,
                        v_px: s.2,
                        ..b.clone()
                    });
                    per_id
                        .entry((b.row, b.column))
                        .or_insert_with(|| (b.id.clone(), Vec::new()))
                        .1
                        .push((s.1, s.2));
                }
                Some(b) => extra.push(ExtraSpot {
                    u_px: s.1,
                    v_px: s.2,
                    why: format!(
                        "at the place of bump {}, which capture {} does not press (--capture-plan)",
                        b.id,
                        k + 1
                    ),
                }),
                None => extra.push(ExtraSpot {
                    u_px: s.1,
                    v_px: s.2,
                    why: if several {
                        "not on the lattice the imprints of all captures form".into()
                    } else {
                        "not on the lattice the other imprints form".into()
                    },
                }),
            }
        }
        found.sort_by_key(|f| (f.row, f.column));
        extra.sort_by(|a, b| a.v_px.total_cmp(&b.v_px).then(a.u_px.total_cmp(&b.u_px)));
        let missing_planned_ids = planned.map_or_else(Vec::new, |p| {
            p.iter()
                .filter(|id| !found.iter().any(|f| &f.id == *id))
                .cloned()
                .collect()
        });
        capture_finds.push(CaptureFind {
            capture: k + 1,
            image: file.to_string(),
            spots: per_capture_spots[k],
            found,
            missing_planned_ids,
            extra,
        });
    }
    let mut observations = Vec::new();
    let found: Vec<FoundBump> = per_id
        .into_iter()
        .map(|((row, column), (id, px))| {
            observations.push(px.len());
            let (u_px, v_px) = mean_in_order(px);
            FoundBump {
                id,
                row,
                column,
                u_px,
                v_px,
            }
        })
        .collect();
    if found.len() < 4 {
        return Err(BoardError::Press {
            file: union_file,
            rule: format!(
                "{} bumps found where their captures press them: at least 4 of the board's {} are needed",
                found.len(),
                grid.points.len()
            ),
        });
    }
    let missing = grid
        .points
        .iter()
        .filter(|g| !found.iter().any(|f| f.id == g.id))
        .map(|g| g.id.clone())
        .collect();
    let mut extra: Vec<ExtraSpot> = capture_finds
        .iter()
        .flat_map(|c| {
            c.extra.iter().map(move |e| ExtraSpot {
                why: if several {
                    format!("capture {} ({}): {}", c.capture, c.image, e.why)
                } else {
                    e.why.clone()
                },
                ..e.clone()
            })
        })
        .collect();
    extra.sort_by(|a, b| a.v_px.total_cmp(&b.v_px).then(a.u_px.total_cmp(&b.u_px)));
    Ok(CapturesFind {
        find: GridFind {
            found,
            missing,
            extra,
            pitch_px_at_start: walked.pitch_px_at_start,
            notes: walked.notes,
        },
        observations,
        captures: capture_finds,
        spots: per_capture_spots.iter().sum(),
    })
}

/// The mean of `px`, summed in order of u then v (so that it does not depend on their order).
fn mean_in_order(mut px: Vec<(f64, f64)>) -> (f64, f64) {
    px.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let n = px.len().max(1) as f64;
    let (su, sv) = px
        .iter()
        .fold((0.0, 0.0), |(su, sv), (u, v)| (su + u, sv + v));
    (su / n, sv / n)
}

fn board_report(
    job: &BoardJob,
    grid: &BoardGrid,
    found: &CapturesFind,
    bc: &BoardCamera,
    size: (u32, u32),
) -> BoardReport {
    let find = &found.find;
    let bumps: Vec<BumpResidual> = find
        .found
        .iter()
        .zip(&bc.residuals_px)
        .zip(&found.observations)
        .map(|((b, e), &observations)| {
            let p = grid
                .at(b.row, b.column)
                .map_or(Vector3::zeros(), |g| g.point_mm);
            BumpResidual {
                id: b.id.clone(),
                row: b.row,
                column: b.column,
                point_mm: [p.x, p.y, p.z],
                observed_px: [b.u_px, b.v_px],
                observations,
                reprojected_px: [b.u_px + e.x, b.v_px + e.y],
                reprojection_error_px: e.norm(),
            }
        })
        .collect();
    let worst = bumps
        .iter()
        .max_by(|a, b| a.reprojection_error_px.total_cmp(&b.reprojection_error_px));
    let (mr, mc) = (grid.rows / 2, grid.columns / 2);
    let centre = find
        .found
        .iter()
        .min_by_key(|b| (b.row.abs_diff(mr) + b.column.abs_diff(mc), b.row, b.column));
    let at = |r: i64, c: i64| {
        find.found
            .iter()
            .find(|b| i64::from(b.row) == r && i64::from(b.column) == c)
            .map(|b| Vector2::new(b.u_px.round(), b.v_px.round()))
    };
    let neighbours = centre.and_then(|c| {
        let (r, k) = (i64::from(c.row), i64::from(c.column));
        let mid = Vector2::new(c.u_px.round(), c.v_px.round());
        let d: Option<Vec<f64>> = [(r - 1, k), (r + 1, k), (r, k - 1), (r, k + 1)]
            .iter()
            .map(|&(r, k)| at(r, k).map(|q| (q - mid).norm()))
            .collect();
        d.map(|d| grid.pitch_mm / (d.iter().sum::<f64>() / 4.0))
    });
    let iso = &bc.t_cam_sensor;
    let m = iso.to_homogeneous();
    let rvec = iso.rotation.scaled_axis();
    let t = iso.translation.vector;
    BoardReport {
        fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
        command_line: job.command_line.clone(),
        points_file: job.points.display().to_string(),
        reference_image: job.reference.display().to_string(),
        capture_images: job.images.iter().map(|p| p.display().to_string()).collect(),
        capture_plan: job.capture_plan.as_ref().map(|p| p.display().to_string()),
        image_size_px: [size.0, size.1],
        grid: GridSummary {
            rows: grid.rows,
            columns: grid.columns,
            pitch_mm: grid.pitch_mm,
            plane_z_mm: grid.plane_z_mm,
        },
        board_turn_deg: job.board_turn.deg(),
        spots: found.spots,
        found: find.found.len(),
        missing_ids: find.missing.clone(),
        extra_spots: find.extra.clone(),
        notes: find.notes.clone(),
        captures: found.captures.clone(),
        rms_reprojection_error_px: bc.rms_px,
        worst_px: worst.map_or(0.0, |w| w.reprojection_error_px),
        worst_id: worst.map_or(String::new(), |w| w.id.clone()),
        bumps,
        camera_model: bc.camera.intrinsics().distortion.name(),
        parameters: bc.parameters.clone(),
        condition_number: bc.condition_number,
        plane_distance_mm: job.plane_distance_mm,
        plane_distance_from: job.plane_distance_from.clone(),
        optical_path: "straight rays: the refraction of the flat layers between the lens and the plane is taken up by the radial distortion, which so holds for points on this plane".into(),
        rvec: [rvec.x, rvec.y, rvec.z],
        tvec_mm: [t.x, t.y, t.z],
        t_cam_sensor: std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)])),
        pose_std: bc.pose_std,
        centre_bump_px: centre.map_or([f64::NAN; 2], |c| [c.u_px, c.v_px]),
        centre_bump_id: centre.map_or(String::new(), |c| c.id.clone()),
        mm_per_px_at_centre: centre.and_then(|c| {
            mm_per_px_at(bc, grid.plane_z_mm, Vector2::new(c.u_px, c.v_px))
        }),
        mm_per_px_neighbours: neighbours,
    }
}

fn board_files(
    report: &BoardReport,
    bc: &BoardCamera,
    grid: &BoardGrid,
    captures: &[std::path::PathBuf],
) -> Result<Vec<(String, Vec<u8>)>, BoardError> {
    use crate::camera_file::{write_camera, CameraFileFormat};
    let intr = bc.camera.intrinsics();
    let mut json =
        serde_json::to_vec_pretty(report).map_err(|e| BoardError::Solve(e.to_string()))?;
    json.push(b'\n');
    let yaml = crate::report::opencv_yaml(report, crate::report::POSE_MATRICES)
        .map_err(BoardError::Solve)?;
    let mut files = vec![
        ("extrinsics.json".to_string(), json),
        ("extrinsics.yaml".to_string(), yaml.into_bytes()),
        (
            "transform.yaml".to_string(),
            crate::report::transform_stamped_yaml(&report.t_cam_sensor, &report.fabkit_version)
                .into_bytes(),
        ),
        (
            "camera.yaml".to_string(),
            write_camera(intr, CameraFileFormat::OpenCvYaml).into_bytes(),
        ),
        (
            "camera_info.yaml".to_string(),
            write_camera(intr, CameraFileFormat::RosYaml).into_bytes(),
        ),
        (
            "camera.json".to_string(),
            write_camera(intr, CameraFileFormat::Json).into_bytes(),
        ),
    ];
    let mut csv = String::from("id,u_px,v_px\n");
    for b in &report.bumps {
        csv += &format!("{},{:.4},{:.4}\n", b.id, b.observed_px[0], b.observed_px[1]);
    }
    files.push(("observations.csv".into(), csv.into_bytes()));
    let (w, h) = (intr.image_width_px as usize, intr.image_height_px as usize);
    files.push((
        "pixel_to_plane_mm.npy".into(),
        fabkit_export::raster::npy_f32(&[h, w, 2], &pixel_to_plane_mm(bc, grid.plane_z_mm)),
    ));
    // the darkest of the captures at each pixel: every capture's imprints show
    let mut img: Option<crate::overlay::Rgb8> = None;
    for capture in captures {
        let next =
            crate::overlay::read_png_rgb8_sized(capture, (w as u32, h as u32)).map_err(|e| {
                BoardError::Press {
                    file: capture.display().to_string(),
                    rule: e.to_string(),
                }
            })?;
        img = Some(match img {
            None => next,
            Some(mut acc) => {
                for (a, b) in acc.data.iter_mut().zip(&next.data) {
                    *a = (*a).min(*b);
                }
                acc
            }
        });
    }
    let Some(img) = img else {
        return Err(BoardError::Solve("no capture to draw on".into()));
    };
    files.push(("overlay.png".into(), board_overlay(img, report)?));
    Ok(files)
}

/// The capture (the darkest of the captures) with each found bump circled (green) and its id, its reprojection (red cross)
/// and the spots taken for no bump (magenta).
fn board_overlay(mut img: crate::overlay::Rgb8, r: &BoardReport) -> Result<Vec<u8>, BoardError> {
    const GREEN: [u8; 3] = [0, 220, 0];
    const RED: [u8; 3] = [255, 40, 40];
    const MAGENTA: [u8; 3] = [255, 0, 255];
    for b in &r.bumps {
        let [u, v] = b.observed_px;
        img.circle(u, v, 5.0, GREEN);
        let [ru, rv] = b.reprojected_px;
        img.line(ru - 3.0, rv, ru + 3.0, rv, RED);
        img.line(ru, rv - 3.0, ru, rv + 3.0, RED);
        img.text(u + 7.0, v - 12.0, &b.id, 2, GREEN);
    }
    for e in &r.extra_spots {
        img.circle(e.u_px, e.v_px, 7.0, MAGENTA);
    }
    img.to_png().map_err(|e| BoardError::Solve(e.to_string()))
}

/// The distance in air from the lens's centre of projection to the surface the camera sees of
/// a flat design with a `flat_housing` (the inner face of its innermost opaque layer, where an
/// imprint shows; the contact face if every layer is clear), mm, with how it was found in
/// words; `None` for a design without one.
///
/// ASSUMPTION: the lens's centre of projection lies at the shell plate's underside, where the
/// lens looks up through the isolation ring (the housing gives no lens; 9DTact's camera module
/// stands on the base's bosses below the plate). From there the ray crosses the ring's bore and
/// the collar in air, then the window, then the clear layers; each solid counts its thickness
/// over its refractive index, the paraxial apparent depth (Hecht, Optics, 5th ed., Sec.
/// 5.2.3): the distance at which a camera in air sees the surface at the scale the press
/// shows. A layer whose material has no refractive index in the materials table is opaque.
pub fn plane_distance_of_design(
    design: &fabkit_designs::Design,
    materials: &fabkit_designs::materials::MaterialsTable,
) -> Option<(f64, String)> {
    let h = design.flat_housing.as_ref()?;
    let index = |key: &str| {
        materials
            .get(key)
            .and_then(|m| m.refractive_index.as_ref())
            .map(|r| r.n)
    };
    let mm = |v: f64| (v * 1e6).round() / 1e6;
    let air = h.shell.plate_mm + h.shell.collar.height_mm;
    let window = h.window_thickness_mm();
    let n_window = index(&h.window.material).unwrap_or(1.0);
    let mut d = air + window / n_window;
    let mut words = vec![
        format!("{} mm of air (the plate and the collar)", mm(air)),
        format!(
            "{} mm of {} (n = {n_window})",
            mm(window),
            h.window.material
        ),
    ];
    let mut seen = "the contact face".to_string();
    for l in &design.layers {
        let t = l.thickness_mm.unwrap_or(0.0);
        match index(&l.material) {
            Some(n) => {
                d += t / n;
                words.push(format!("{} mm of {} (n = {n})", mm(t), l.material));
            }
            None => {
                seen = format!("the inner face of the opaque layer {}", l.name);
                break;
            }
        }
    }
    Some((
        d,
        format!(
            "the design {}: the lens at the shell plate's underside (an assumption), then {}, each over its index, up to {seen}",
            design.name,
            words.join(", ")
        ),
    ))
}
