//! The extrinsics result and residual report (`extrinsics.json` / `extrinsics.yaml`).

use nalgebra::Point3;
use serde::Serialize;

use crate::pnp::PnpSolution;
use crate::refraction::Imaging;
use crate::tables::Pairs;

/// Where the inputs came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Provenance {
    pub fabkit_version: String,
    pub command_line: String,
    pub camera_file: String,
    pub points_file: String,
    /// `tip` or `contact` (fixtures tables) or `xyz` (plain tables).
    pub points_from: String,
    pub observation_files: Vec<String>,
    /// The capture plan the observation files were checked against (one file per capture).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture_plan: Option<String>,
    /// Pins of the capture plan with no observation (not used in the solve), plan order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unobserved_ids: Vec<String>,
    /// The reference image the capture images were compared with (observations found in
    /// images; `observation_files` are then the capture images).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_image: Option<String>,
}

/// One observed point's residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointResidual {
    pub id: String,
    /// Sensor-frame point, mm.
    pub point_mm: [f64; 3],
    /// Observed pixel, px.
    pub observed_px: [f64; 2],
    /// Reprojected pixel at the solved pose, px (`null` if it does not project).
    pub reprojected_px: Option<[f64; 2]>,
    /// |reprojected - observed|, px.
    pub reprojection_error_px: Option<f64>,
    /// Used in the fit (false: rejected by RANSAC as an outlier).
    pub inlier: bool,
}

/// Residual summary and per-point table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualReport {
    /// RMS reprojection error over the inliers, px.
    pub rms_px: f64,
    /// Largest inlier reprojection error, px, and its id.
    pub worst_px: f64,
    pub worst_id: String,
    pub observations: usize,
    pub inliers: usize,
    /// Ids rejected by RANSAC.
    pub outlier_ids: Vec<String>,
    /// RANSAC inlier threshold used, px: `--ransac-threshold-px`, or from the data (sqrt(2 ln(n /
    /// 0.002)) robust standard deviations by least median of squares, 4.4 for 30 pins, at least 3 px, at most a tenth of the pixels' spread); `null` without RANSAC.
    pub ransac_threshold_px: Option<f64>,
    /// The camera's optical centre in the sensor frame, mm.
    pub camera_centre_in_sensor_mm: [f64; 3],
    /// The reprojection errors by the points' polar angle about the sensor axis (a dome's
    /// rings), inliers and outliers alike: errors that grow towards the edge of the lens's
    /// field say that the camera file's model does not follow the lens there.
    pub by_polar_angle: Vec<RingResidual>,
    pub points: Vec<PointResidual>,
}

/// The reprojection errors of the points in one band of polar angle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RingResidual {
    /// Smallest and largest polar angle of the band's points about the sensor z axis, deg.
    pub polar_deg: [f64; 2],
    pub points: usize,
    pub inliers: usize,
    /// The band's points that project at the solved pose and intrinsics.
    pub projected: usize,
    /// RMS reprojection error of the band's points that project (outliers included), px; 0
    /// when none does (`projected` = 0).
    pub rms_px: f64,
}

impl RingResidual {
    /// `18 deg`, or `12-30 deg` for a band.
    pub fn angles(&self) -> String {
        let [lo, hi] = self.polar_deg;
        if hi - lo < 0.5 {
            format!("{lo:.0} deg")
        } else {
            format!("{lo:.0}-{hi:.0} deg")
        }
    }
}

/// Points whose polar angles are within this of their neighbours' share a ring, deg.
const RING_GAP_DEG: f64 = 3.0;
/// With fewer than 2 or more than this many rings the points are split in 5 bands of equal
/// count instead.
const MAX_RINGS: usize = 8;

/// The polar angle of `p` about the sensor z axis, deg.
fn polar_deg(p: &nalgebra::Vector3<f64>) -> f64 {
    p.xy().norm().atan2(p.z).to_degrees()
}

/// The residuals by ring ([`ResidualReport::by_polar_angle`]): the points sorted by polar
/// angle, a new ring at every gap of more than [`RING_GAP_DEG`]; 5 bands of equal count when
/// that makes fewer than 2 or more than [`MAX_RINGS`] rings.
fn ring_residuals(pairs: &Pairs, sol: &PnpSolution) -> Vec<RingResidual> {
    let n = pairs.points_mm.len();
    let mut order: Vec<usize> = (0..n).collect();
    let polar: Vec<f64> = pairs.points_mm.iter().map(polar_deg).collect();
    order.sort_by(|&a, &b| polar[a].total_cmp(&polar[b]));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for &i in &order {
        match groups.last_mut() {
            Some(g) if polar[i] - polar[*g.last().expect("never empty")] <= RING_GAP_DEG => {
                g.push(i)
            }
            _ => groups.push(vec![i]),
        }
    }
    if groups.len() < 2 || groups.len() > MAX_RINGS {
        let bands = 5.min(n);
        groups = (0..bands)
            .map(|b| order[b * n / bands..(b + 1) * n / bands].to_vec())
            .filter(|g| !g.is_empty())
            .collect();
    }
    groups
        .iter()
        .map(|g| {
            let errs: Vec<f64> = g
                .iter()
                .filter_map(|&i| sol.residuals_px[i].map(|r| r.norm_squared()))
                .collect();
            RingResidual {
                polar_deg: [polar[g[0]], polar[*g.last().expect("never empty")]],
                points: g.len(),
                inliers: g.iter().filter(|&&i| sol.inliers[i]).count(),
                projected: errs.len(),
                rms_px: (errs.iter().sum::<f64>() / errs.len().max(1) as f64).sqrt(),
            }
        })
        .collect()
}

/// The outermost ring's RMS is above this, px, ...
const GROWING_MIN_PX: f64 = 2.0;
/// ... and this many times the median of the inner half's rings: the residuals grow with the
/// polar angle.
const GROWING_RATIO: f64 = 3.0;

/// The start of the warning of [`growing_residuals`].
const GROWING: &str = "the reprojection errors grow with the polar angle";

/// A warning when the residuals grow towards the edge of the field (at least 3 rings);
/// `refined`: after `--refine-intrinsics`.
fn growing_residuals(rings: &[RingResidual], refined: bool) -> Option<String> {
    if rings.len() < 3 {
        return None;
    }
    let last = rings.last().expect("at least 3");
    if last.projected == 0 {
        return Some(format!(
            "{GROWING}: the outermost ring ({}) does not project at all at the solved pose{}",
            last.angles(),
            if refined {
                " and the refined intrinsics"
            } else {
                ""
            }
        ));
    }
    let outer = last.rms_px;
    let mut inner: Vec<f64> = rings[..rings.len().div_ceil(2)]
        .iter()
        .map(|r| r.rms_px)
        .collect();
    inner.sort_by(f64::total_cmp);
    let median = inner[inner.len() / 2];
    (outer > GROWING_MIN_PX && outer > GROWING_RATIO * median).then(|| {
        format!(
            "{GROWING} (RMS {}): {}",
            rings
                .iter()
                .map(|r| format!("{:.1} px at {}", r.rms_px, r.angles()))
                .collect::<Vec<_>>()
                .join(", "),
            if refined {
                "the refined model still does not follow the lens towards the edge of its field, where the pins beyond the RANSAC threshold are left out (the pose rests on the others); a camera file calibrated over the whole field (e.g. the fisheye model for a wide-angle lens) would use them"
            } else {
                "the camera file's model does not follow the lens towards the edge of its field; try --refine-intrinsics (the intrinsics refined with the pose over the pins kept), or a camera file calibrated over the whole field (e.g. the fisheye model for a wide-angle lens)"
            }
        )
    })
}

/// `extrinsics.json`: T_cam_sensor and the residual report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExtrinsicsReport {
    /// What the numbers mean (frames and units).
    pub description: String,
    pub provenance: Provenance,
    /// `fisheye`, `plumb_bob` or `rational_polynomial`.
    pub distortion_model: String,
    /// The optical path the rays were bent along (the point table's design or `--design`: the
    /// filling gel's surface, a window's or a plate's faces, a spherical core's faces, each
    /// with its refractive index and source); absent: straight rays from the lens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optical_path: Option<fabkit_designs::optics::OpticalPath>,
    /// Where `optical_path` comes from: `--design NAME [--preset P]`, or `design NAME, the
    /// point table's (point_table.json)` when the point table's sidecar names it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optical_path_from: Option<String>,
    /// RANSAC left pins out: the models fitted to every pin and compared before they were
    /// rejected ([`crate::models`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_comparison: Option<crate::models::ModelComparison>,
    /// The filling gel's surface refined with the pose (`--refine-optical-path`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optical_path_fit: Option<PlaneFitReport>,
    /// Rotation of T_cam_sensor as an OpenCV rotation vector (axis times angle), radians.
    pub rvec: [f64; 3],
    /// Translation of T_cam_sensor (the sensor origin in the camera frame), mm.
    pub tvec_mm: [f64; 3],
    /// T_cam_sensor, 4 x 4, rows; maps sensor-frame points (mm) into the camera frame (mm).
    #[serde(rename = "T_cam_sensor")]
    pub t_cam_sensor: [[f64; 4]; 4],
    /// RMS reprojection error over the inliers, px.
    pub rms_reprojection_error_px: f64,
    pub residuals: ResidualReport,
    /// How well the inliers' geometry fixes the pose ([`crate::pose_uncertainty`]); absent when
    /// it does not.
    pub pose_uncertainty: Option<PoseUncertaintyReport>,
    /// What the user should know about the solution (a weak geometry); empty when nothing.
    pub warnings: Vec<String>,
    /// The intrinsics refined with the pose (`--refine-intrinsics`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intrinsics_refinement: Option<crate::refine::RefinementReport>,
    /// From capture images: per capture, the spots found, kept with ids, discarded with why,
    /// the pins missing, or why it is left out; absent for observation files.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub captures: Vec<CaptureReport>,
}

/// A spot of a capture image, px.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpotReport {
    /// The pin's id (kept spots only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    pub u_px: f64,
    pub v_px: f64,
    /// The imprint's peak over the noise sigma.
    pub score: f64,
    /// Why it was discarded (discarded spots only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// A planned pin without a spot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissingPin {
    pub id: String,
    pub reason: String,
}

/// What the detector found in one capture image and what became of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaptureReport {
    pub capture: String,
    pub spots_found: usize,
    pub kept: Vec<SpotReport>,
    pub discarded: Vec<SpotReport>,
    pub missing: Vec<MissingPin>,
    /// Spots cut in two because two of the capture's pins project onto their halves (two
    /// imprints that touch): the whole spot, its `id` the two pins' ids (`"14+22"`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub split: Vec<SpotReport>,
    /// Why the capture is left out (nothing kept); absent when it is used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub left_out: Option<String>,
}

impl From<&crate::imprints::CaptureOutcome> for CaptureReport {
    fn from(o: &crate::imprints::CaptureOutcome) -> Self {
        let spot =
            |id: Option<String>, s: &crate::imprints::Spot, reason: Option<String>| SpotReport {
                id,
                u_px: s.u_px,
                v_px: s.v_px,
                score: s.score,
                reason,
            };
        CaptureReport {
            capture: o.name.clone(),
            spots_found: o.spots_found,
            kept: o
                .kept
                .iter()
                .map(|(id, s)| spot(Some(id.to_string()), s, None))
                .collect(),
            discarded: o
                .discarded
                .iter()
                .map(|(s, why)| spot(None, s, Some(why.clone())))
                .collect(),
            missing: o
                .missing
                .iter()
                .map(|(id, why)| MissingPin {
                    id: id.to_string(),
                    reason: why.clone(),
                })
                .collect(),
            split: o
                .split
                .iter()
                .map(|(s, [a, b])| spot(Some(format!("{a}+{b}")), s, None))
                .collect(),
            left_out: o.left_out.clone(),
        }
    }
}

/// [`crate::PoseUncertainty`] as reported.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseUncertaintyReport {
    /// What the numbers mean.
    pub description: String,
    /// Standard deviation of the rotation about the camera's x, y, z axes per px of pixel
    /// noise, degrees.
    pub rotation_std_deg_per_px: [f64; 3],
    /// Standard deviation of the translation along x, y, z per px of pixel noise, mm.
    pub translation_std_mm_per_px: [f64; 3],
    /// Covariance of (rotation perturbation w, rad; translation t, mm) for 1 px of noise, 6 x 6.
    pub covariance_per_px2: [[f64; 6]; 6],
}

/// A plane of the optical path refined with the pose ([`crate::refraction::refine_plane`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlaneFitReport {
    pub description: String,
    /// Which plane (`housing.filling_gel: the gel's free surface at ...`).
    pub plane: String,
    /// The design's height, mm, and the prior's standard deviation about it.
    pub prior_height_mm: f64,
    pub prior_height_sd_mm: f64,
    /// The refined height, mm, and its standard deviation.
    pub height_mm: f64,
    pub height_sd_mm: f64,
    /// The materials table's index above it, and the prior's standard deviation.
    pub prior_index: f64,
    pub prior_index_sd: f64,
    /// The refined index and its standard deviation.
    pub index: f64,
    pub index_sd: f64,
    /// Pixel noise per coordinate the fit estimated from its residuals, px.
    pub sigma_px: f64,
}

impl PlaneFitReport {
    pub fn new(f: &crate::refraction::PlaneFit, plane: &str) -> PlaneFitReport {
        PlaneFitReport {
            description: "The plane's height and the index above it refined with the pose, maximum a posteriori under Gaussian pixel noise (estimated from the residuals) and the Gaussian priors given; standard deviations from the inverse normal matrix at the solution, below the prior's where the pins say more than it. The pose and residuals of this report are at the refined plane.".into(),
            plane: plane.to_string(),
            prior_height_mm: f.prior_height_mm,
            prior_height_sd_mm: f.prior.height_sd_mm,
            height_mm: f.height_mm,
            height_sd_mm: f.height_sd_mm,
            prior_index: f.prior_index,
            prior_index_sd: f.prior.index_sd,
            index: f.index,
            index_sd: f.index_sd,
            sigma_px: f.sigma_px,
        }
    }
}

impl ExtrinsicsReport {
    /// Builds the report of a solution over its pairs.
    pub fn new(
        camera: &Imaging<'_>,
        pairs: &Pairs,
        sol: &PnpSolution,
        provenance: Provenance,
    ) -> ExtrinsicsReport {
        let iso = &sol.t_cam_sensor;
        let rvec = iso.rotation.scaled_axis();
        let h = iso.to_homogeneous();
        let centre = iso.inverse() * Point3::origin();
        let mut points = Vec::with_capacity(pairs.ids.len());
        let (mut worst_px, mut worst_id) = (0.0f64, String::new());
        let mut outlier_ids = Vec::new();
        for (k, id) in pairs.ids.iter().enumerate() {
            let p = pairs.points_mm[k];
            let uv = pairs.pixels_px[k];
            let res = sol.residuals_px[k];
            let err = res.map(|r| r.norm());
            if sol.inliers[k] {
                if let Some(e) = err {
                    if e > worst_px || worst_id.is_empty() {
                        worst_px = e;
                        worst_id = id.clone();
                    }
                }
            } else {
                outlier_ids.push(id.clone());
            }
            points.push(PointResidual {
                id: id.clone(),
                point_mm: [p.x, p.y, p.z],
                observed_px: [uv.x, uv.y],
                reprojected_px: res.map(|r| [uv.x + r.x, uv.y + r.y]),
                reprojection_error_px: err,
                inlier: sol.inliers[k],
            });
        }
        let uncertainty = crate::pnp::pose_uncertainty_through(
            camera,
            &pairs.points_mm,
            &pairs.pixels_px,
            &sol.inliers,
            iso,
        );
        let mut warnings = Vec::new();
        let by_polar_angle = ring_residuals(pairs, sol);
        warnings.extend(growing_residuals(&by_polar_angle, false));
        let inlier_polar_deg = || {
            pairs
                .points_mm
                .iter()
                .zip(&sol.inliers)
                .filter(|(_, &b)| b)
                .map(|(p, _)| {
                    (p.z / p.norm().max(1e-12))
                        .clamp(-1.0, 1.0)
                        .acos()
                        .to_degrees()
                })
                .fold(0.0f64, f64::max)
        };
        match &uncertainty {
            Some(u) => {
                let r = u.rotation_std_deg_per_px.iter().copied().fold(0.0, f64::max);
                let t = u.translation_std_mm_per_px.iter().copied().fold(0.0, f64::max);
                if r > crate::pnp::WEAK_POSE_DEG_PER_PX || t > crate::pnp::WEAK_POSE_MM_PER_PX {
                    warnings.push(format!(
                        "weak geometry: the pose is uncertain by up to {r:.2} deg and {t:.3} mm per px of pixel noise (above {} deg or {} mm; {} pins, the farthest {:.1} deg from the sensor axis): a low RMS does not make it accurate; observe more pins, spread farther from the pole",
                        crate::pnp::WEAK_POSE_DEG_PER_PX,
                        crate::pnp::WEAK_POSE_MM_PER_PX,
                        sol.inliers.iter().filter(|&&b| b).count(),
                        inlier_polar_deg()
                    ));
                }
            }
            None => warnings.push(
                "weak geometry: the pins do not determine the pose (its covariance is singular); observe more pins, spread farther from the pole".into(),
            ),
        }
        ExtrinsicsReport {
            pose_uncertainty: uncertainty.map(|u| PoseUncertaintyReport {
                description: "First-order covariance of the pose from the reprojection error's Jacobian at the solution, for a pixel noise of 1 px in u and v: multiply the standard deviations by the noise in px (the RMS reprojection error is an estimate of it). w is the rotation of T_cam_sensor perturbed on the left, about the camera axes, rad; t its translation, mm.".into(),
                rotation_std_deg_per_px: u.rotation_std_deg_per_px,
                translation_std_mm_per_px: u.translation_std_mm_per_px,
                covariance_per_px2: u.covariance_per_px2,
            }),
            warnings,
            intrinsics_refinement: None,
            captures: Vec::new(),
            description: "T_cam_sensor maps sensor-frame points (mm; docs/conventions.md) into the camera frame (mm; x right, y down, z forward). rvec/tvec_mm follow OpenCV's solvePnP convention: x_cam = R(rvec) x_sensor + tvec_mm. Pixels: (0, 0) is the centre of the top-left pixel.".into(),
            provenance,
            distortion_model: camera.camera.intrinsics().distortion.name().into(),
            optical_path: None,
            optical_path_from: None,
            model_comparison: None,
            optical_path_fit: None,
            rvec: [rvec.x, rvec.y, rvec.z],
            tvec_mm: [iso.translation.x, iso.translation.y, iso.translation.z],
            t_cam_sensor: std::array::from_fn(|i| std::array::from_fn(|j| h[(i, j)])),
            rms_reprojection_error_px: sol.rms_reprojection_error_px,
            residuals: ResidualReport {
                rms_px: sol.rms_reprojection_error_px,
                worst_px,
                worst_id,
                observations: pairs.ids.len(),
                inliers: sol.inliers.iter().filter(|&&b| b).count(),
                outlier_ids,
                ransac_threshold_px: sol.ransac_threshold_px,
                camera_centre_in_sensor_mm: [centre.x, centre.y, centre.z],
                by_polar_angle,
                points,
            },
        }
    }

    /// Records the intrinsics refinement (`--refine-intrinsics`) and words the warning on
    /// residuals that grow with the polar angle for it.
    pub fn set_refinement(&mut self, r: crate::refine::RefinementReport) {
        self.intrinsics_refinement = Some(r);
        let refined = growing_residuals(&self.residuals.by_polar_angle, true);
        self.warnings.retain(|w| !w.starts_with(GROWING));
        self.warnings.extend(refined);
    }

    /// Pretty JSON, stable key order, newline-terminated.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// The same content as YAML that `cv::FileStorage` reads ([`opencv_yaml`]): `rvec` (3 x 1,
    /// rad), `tvec_mm` (3 x 1) and `T_cam_sensor` (4 x 4) as `!!opencv-matrix` nodes
    /// ([`POSE_MATRICES`]), so that `fs.getNode("T_cam_sensor").mat()` is the matrix.
    ///
    /// # Errors
    /// The YAML serialiser's message.
    pub fn to_yaml(&self) -> Result<String, String> {
        opencv_yaml(self, POSE_MATRICES)
    }
}

/// The pose's matrices in `extrinsics.yaml` (key, rows, cols), as OpenCV shapes them: `rvec`
/// and `tvec_mm` 3 x 1 (what `cv::solvePnP` returns), `T_cam_sensor` 4 x 4.
pub const POSE_MATRICES: &[(&str, usize, usize)] =
    &[("rvec", 3, 1), ("tvec_mm", 3, 1), ("T_cam_sensor", 4, 4)];

/// `value` as YAML that `cv::FileStorage` reads as OpenCV writes it: `%YAML:1.0` and `---`
/// first, the top-level keys of `matrices` (key, rows, cols; the value a list of rows x cols
/// numbers, flat or by rows) as `!!opencv-matrix` nodes (`rows`, `cols`, `dt: d`, `data`,
/// each number to 17 significant digits, so they read back exactly), and everything else as
/// YAML that OpenCV's reader (not a full YAML parser) takes: every sequence indented under its
/// key and every string on one line (a multi-line string double-quoted with `\n`), as OpenCV
/// reads neither indentless sequences nor block scalars. OpenCV reads strings of up to 4095
/// bytes. PyYAML reads the file after the directive line is dropped and a constructor is given
/// for the `opencv-matrix` tag.
///
/// # Errors
/// The YAML serialiser's message, or a listed key whose value is not rows x cols numbers.
pub fn opencv_yaml<T: Serialize>(
    value: &T,
    matrices: &[(&str, usize, usize)],
) -> Result<String, String> {
    let options = serde_saphyr::ser_options! {
        prefer_block_scalars: false,
        compact_list_indent: false,
    };
    let body = serde_saphyr::to_string_with_options(value, options).map_err(|e| e.to_string())?;
    let json = serde_json::to_value(value).map_err(|e| e.to_string())?;
    let mut out = String::from("%YAML:1.0\n---\n");
    let mut skipping = false;
    for line in body.lines() {
        let top_level = !line.starts_with(|c: char| c.is_whitespace() || c == '-');
        if skipping && !top_level {
            continue;
        }
        skipping = false;
        let key = line.split_once(':').map(|(k, _)| k);
        match matrices
            .iter()
            .find(|(k, _, _)| top_level && Some(*k) == key)
        {
            Some(&(k, rows, cols)) => {
                let data: Vec<f64> = match &json[k] {
                    serde_json::Value::Array(a) => a
                        .iter()
                        .flat_map(|v| match v {
                            serde_json::Value::Array(r) => r.clone(),
                            v => vec![v.clone()],
                        })
                        .map(|v| {
                            v.as_f64()
                                .ok_or_else(|| format!("{k}: {v} is not a number"))
                        })
                        .collect::<Result<_, _>>()?,
                    v => return Err(format!("{k}: {v} is not a matrix")),
                };
                if data.len() != rows * cols {
                    return Err(format!("{k}: {} numbers, not {rows} x {cols}", data.len()));
                }
                crate::camera_file::cv_matrix(&mut out, k, rows, cols, &data);
                skipping = true;
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Ok(out)
}

/// The camera frame's name in `transform.yaml`: fabkit's camera frame (x right, y down, z
/// forward) is what ROS (REP 103) calls an optical frame.
pub const CAMERA_FRAME_ID: &str = "camera_optical_frame";
/// The sensor frame's name in `transform.yaml` (`docs/conventions.md`).
pub const SENSOR_FRAME_ID: &str = "sensor";

/// `v` as a YAML float that PyYAML (YAML 1.1, which wants a `.` and a signed exponent) and
/// YAML 1.2 readers both take, and that reads back exactly.
fn yaml_float(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains('e') || !s.contains('.') {
        crate::camera_file::cv_double(v)
    } else {
        s
    }
}

/// `T_cam_sensor` (4 x 4, mm) as ROS wants a pose: translation in metres `[x, y, z]` and the
/// rotation as a unit quaternion `[x, y, z, w]` with w >= 0.
pub fn ros_pose(t_cam_sensor: &[[f64; 4]; 4]) -> ([f64; 3], [f64; 4]) {
    let m = t_cam_sensor;
    let r = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(r),
    );
    let q = if q.w < 0.0 {
        -q.into_inner()
    } else {
        q.into_inner()
    };
    (
        [m[0][3] / 1000.0, m[1][3] / 1000.0, m[2][3] / 1000.0],
        [q.i, q.j, q.k, q.w],
    )
}

/// The `ros2 run tf2_ros static_transform_publisher` command that publishes `T_cam_sensor`
/// ([`ros_pose`]) from [`CAMERA_FRAME_ID`] (the parent, `--frame-id`) to [`SENSOR_FRAME_ID`]
/// (the child): tf2's transform from parent to child maps child-frame points into the parent
/// frame, as `T_cam_sensor` maps sensor-frame points into the camera frame.
pub fn static_transform_publisher(t_cam_sensor: &[[f64; 4]; 4]) -> String {
    let ([x, y, z], [qx, qy, qz, qw]) = ros_pose(t_cam_sensor);
    format!(
        "ros2 run tf2_ros static_transform_publisher --x {x:?} --y {y:?} --z {z:?} --qx {qx:?} --qy {qy:?} --qz {qz:?} --qw {qw:?} --frame-id {CAMERA_FRAME_ID} --child-frame-id {SENSOR_FRAME_ID}"
    )
}

/// `transform.yaml`: `T_cam_sensor` as a ROS 2 `geometry_msgs/msg/TransformStamped` message in
/// YAML, as `ros2 topic echo` prints one (`header.stamp` 0, `header.frame_id` the camera frame
/// [`CAMERA_FRAME_ID`], `child_frame_id` the sensor frame [`SENSOR_FRAME_ID`],
/// `transform.translation` in metres, `transform.rotation` a unit quaternion x, y, z, w), with
/// comments naming its source (`fabkit_version`) and the equivalent
/// [`static_transform_publisher`] command.
pub fn transform_stamped_yaml(t_cam_sensor: &[[f64; 4]; 4], fabkit_version: &str) -> String {
    let ([x, y, z], [qx, qy, qz, qw]) = ros_pose(t_cam_sensor);
    let f = yaml_float;
    format!(
        "# geometry_msgs/msg/TransformStamped: T_cam_sensor of extrinsics.json (fabkit {fabkit_version}),\n\
         # mapping sensor-frame points into the camera frame (x right, y down, z forward);\n\
         # translation in metres. Rename the frames to those of your TF tree. The same transform:\n\
         # {}\n\
         header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: {CAMERA_FRAME_ID}\n\
         child_frame_id: {SENSOR_FRAME_ID}\n\
         transform:\n  translation:\n    x: {}\n    y: {}\n    z: {}\n\
         \x20 rotation:\n    x: {}\n    y: {}\n    z: {}\n    w: {}\n",
        static_transform_publisher(t_cam_sensor),
        f(x),
        f(y),
        f(z),
        f(qx),
        f(qy),
        f(qz),
        f(qw)
    )
}
