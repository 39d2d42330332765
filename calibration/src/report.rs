//! The extrinsics result and residual report (`extrinsics.json` / `extrinsics.yaml`).

use nalgebra::Point3;
use serde::Serialize;

use crate::camera::CameraModel;
use crate::pnp::PnpSolution;
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
    /// RANSAC inlier threshold, px (`null` without RANSAC).
    pub ransac_threshold_px: Option<f64>,
    /// The camera's optical centre in the sensor frame, mm.
    pub camera_centre_in_sensor_mm: [f64; 3],
    pub points: Vec<PointResidual>,
}

/// `extrinsics.json`: T_cam_sensor and the residual report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExtrinsicsReport {
    /// What the numbers mean (frames and units).
    pub description: String,
    pub provenance: Provenance,
    /// `fisheye`, `plumb_bob` or `rational_polynomial`.
    pub distortion_model: String,
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
}

impl ExtrinsicsReport {
    /// Builds the report of a solution over its pairs.
    pub fn new(
        camera: &CameraModel,
        pairs: &Pairs,
        sol: &PnpSolution,
        ransac_threshold_px: Option<f64>,
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
        ExtrinsicsReport {
            description: "T_cam_sensor maps sensor-frame points (mm; docs/conventions.md) into the camera frame (mm; x right, y down, z forward). rvec/tvec_mm follow OpenCV's solvePnP convention: x_cam = R(rvec) x_sensor + tvec_mm. Pixels: (0, 0) is the centre of the top-left pixel.".into(),
            provenance,
            distortion_model: camera.intrinsics().distortion.name().into(),
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
                ransac_threshold_px,
                camera_centre_in_sensor_mm: [centre.x, centre.y, centre.z],
                points,
            },
        }
    }

    /// Pretty JSON, stable key order, newline-terminated.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// The same content as YAML.
    ///
    /// # Errors
    /// The YAML serialiser's message.
    pub fn to_yaml(&self) -> Result<String, String> {
        serde_saphyr::to_string(self).map_err(|e| e.to_string())
    }
}
