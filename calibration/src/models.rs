//! Before pins are rejected, the models that might explain them are compared (issue 97: a ring
//! whose residuals grow together is a model question, not a set of outliers).
//!
//! When RANSAC leaves pins out, three models are fitted to every pin (none left out), each
//! jointly with the pose:
//!
//! - `as given`: the camera file's intrinsics and the optical path as given (6 parameters);
//! - `gel surface refined`: the filling gel's free surface height and index refined under
//!   their priors ([`crate::refraction::refine_plane`]; 8 parameters), when the optical path
//!   has such a surface;
//! - `radial terms refined`: the lens's k1 and k2 refined ([`crate::refine`]; 8 parameters).
//!
//! They are compared by the Bayesian information criterion (Schwarz 1978), `BIC = N ln(RSS /
//! N) + p ln N` over the N = 2 n pixel coordinates, the lowest preferred. A model explains
//! every pin when each reprojects within the RANSAC threshold. When the preferred model that
//! explains every pin is the refined gel surface (physics the design names, under priors), it
//! is taken and no pin is rejected; when it is the radial terms (a change of the camera file,
//! the user's call), a warning says so and suggests `--refine-intrinsics`; otherwise RANSAC's
//! rejection stands, and the report says the models were compared.

use nalgebra::{Vector2, Vector3};
use serde::Serialize;

use crate::pnp::{solve_pnp_through, PnpOptions, PnpSolution};
use crate::refine::{refine_intrinsics_keeping, solution_at, RefineParameters};
use crate::refraction::{refine_plane, Imaging, OpticalLayers, PlaneFit, PlanePrior};
use crate::CameraModel;

/// One model fitted to every pin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelScore {
    /// `as given`, `gel surface refined` or `radial terms refined`.
    pub model: String,
    /// Parameters fitted (the pose's 6 and the model's own).
    pub parameters: usize,
    /// RMS reprojection error over every pin, px.
    pub rms_px: f64,
    /// The largest reprojection error, px.
    pub worst_px: f64,
    /// The Bayesian information criterion, N ln(RSS / N) + p ln N (N = 2 x pins).
    pub bic: f64,
    /// Every pin reprojects within the RANSAC threshold.
    pub explains_every_pin: bool,
}

/// The comparison ([`compare`]) as `extrinsics.json` reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelComparison {
    pub description: String,
    /// The RANSAC threshold the pins were rejected at, px.
    pub threshold_px: f64,
    pub models: Vec<ModelScore>,
    /// The model the pose is solved with: `RANSAC` (the rejection stands) or
    /// `gel surface refined` (every pin kept).
    pub chosen: String,
}

/// What [`compare`] found, with the refined gel surface's fit when it is taken.
pub struct Compared {
    pub report: ModelComparison,
    /// The gel surface's fit and the solution over every pin at it, when that model is taken.
    pub taken: Option<(PlaneFit, PnpSolution)>,
    /// A warning when the radial terms are preferred and explain every pin.
    pub warning: Option<String>,
}

/// The residual sum of squares and the worst residual of `sol` over every pair, `None` when a
/// pair does not project.
fn rss(sol: &PnpSolution) -> Option<(f64, f64)> {
    sol.residuals_px
        .iter()
        .try_fold((0.0, 0.0f64), |(s, w), r| {
            let r = (*r)?;
            Some((s + r.norm_squared(), w.max(r.norm())))
        })
}

/// [`ModelScore`] of a solution over `n` pins with `p` parameters.
fn score(model: &str, p: usize, sol: &PnpSolution, threshold: f64) -> Option<ModelScore> {
    let (s, worst) = rss(sol)?;
    let n = sol.residuals_px.len();
    let big_n = (2 * n) as f64;
    Some(ModelScore {
        model: model.into(),
        parameters: p,
        rms_px: (s / n as f64).sqrt(),
        worst_px: worst,
        bic: big_n * (s.max(1e-300) / big_n).ln() + p as f64 * big_n.ln(),
        explains_every_pin: worst <= threshold,
    })
}

/// Compares the models of the module docs over every pair (`points_mm`, `pixels_px`), RANSAC
/// having left some out at `threshold_px`. `layers` is the optical path as given, `gel` the
/// prior of its filling gel's surface when it has one. Each model starts from the pose of the
/// model as given over every pin. `None` when even the model as given
/// cannot be fitted to every pin (a pin that does not project).
pub fn compare(
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    gel: Option<PlanePrior>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    threshold_px: f64,
) -> Option<Compared> {
    let given = Imaging::new(camera, layers);
    let every = PnpOptions {
        ransac: None,
        ..Default::default()
    };
    let all = solve_pnp_through(&given, points_mm, pixels_px, &every).ok()?;
    let mut models = vec![score("as given", 6, &all, threshold_px)?];
    let mut plane: Option<(PlaneFit, PnpSolution)> = None;
    if let (Some(l), Some(prior)) = (layers, gel) {
        if let Some(fit) = refine_plane(camera, l, prior, points_mm, pixels_px, &all.t_cam_sensor) {
            let sol = solution_at(
                &Imaging::new(camera, Some(&fit.layers)),
                points_mm,
                pixels_px,
                &all,
                fit.t_cam_sensor,
            );
            if let Some(s) = score("gel surface refined", 8, &sol, threshold_px) {
                models.push(s);
                plane = Some((fit, sol));
            }
        }
    }
    let radial = RefineParameters::Only(vec!["k1".into(), "k2".into()]);
    if let Ok(r) = refine_intrinsics_keeping(
        camera,
        layers,
        points_mm,
        pixels_px,
        &all.t_cam_sensor,
        &radial,
        points_mm,
    ) {
        let sol = solution_at(
            &Imaging::new(&r.camera, layers),
            points_mm,
            pixels_px,
            &all,
            r.t_cam_sensor,
        );
        if let Some(s) = score("radial terms refined", 8, &sol, threshold_px) {
            models.push(s);
        }
    }
    let best = models
        .iter()
        .filter(|m| m.explains_every_pin)
        .min_by(|a, b| a.bic.total_cmp(&b.bic))
        .map(|m| m.model.clone());
    let (chosen, taken, warning) = match best.as_deref() {
        Some("gel surface refined") => ("gel surface refined", plane, None),
        Some("radial terms refined") => (
            "RANSAC",
            None,
            Some(format!(
                "the pins RANSAC leaves out are explained by refining the lens's k1 and k2 (the Bayesian information criterion prefers it over every other model that keeps every pin: {}); the camera file's model may not follow the lens there: try --refine-intrinsics",
                bic_list(&models)
            )),
        ),
        _ => ("RANSAC", None, None),
    };
    Some(Compared {
        report: ModelComparison {
            description: "RANSAC left pins out; before they were rejected, models fitted to every pin with the pose were compared by the Bayesian information criterion, BIC = N ln(RSS / N) + p ln N over the N = 2 x pins pixel coordinates (Schwarz 1978), the lowest preferred among those that reproject every pin within the threshold. The refined gel surface (physics the design names, under its priors) is taken when preferred; refined radial terms (a change of the camera file) only suggested.".into(),
            threshold_px,
            models,
            chosen: chosen.into(),
        },
        taken,
        warning,
    })
}

/// The prior of the filling gel's free surface of `path` ([`crate::refraction::refine_plane`]:
/// [`crate::refraction::GEL_SURFACE_HEIGHT_SD_MM`] and [`crate::refraction::SILICONE_INDEX_SD`]
/// about the design's height and the materials table's index) and what the plane is; `None`
/// when the path has no such surface.
pub fn gel_prior(path: &fabkit_designs::optics::OpticalPath) -> Option<(PlanePrior, String)> {
    let plane = path
        .planes
        .iter()
        .position(|p| p.what.starts_with("housing.filling_gel"))?;
    Some((
        PlanePrior {
            plane,
            height_sd_mm: crate::refraction::GEL_SURFACE_HEIGHT_SD_MM,
            index_sd: crate::refraction::SILICONE_INDEX_SD,
        },
        path.planes[plane].what.clone(),
    ))
}

/// [`compare`] when `sol` left pins out at a RANSAC threshold (else `None`), with the gel
/// surface of `path` when it has one.
pub fn compare_if_rejected(
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    path: Option<&fabkit_designs::optics::OpticalPath>,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    sol: &PnpSolution,
) -> Option<Compared> {
    let threshold = sol.ransac_threshold_px?;
    if sol.inliers.iter().all(|&b| b) {
        return None;
    }
    let gel = path.and_then(gel_prior).map(|g| g.0);
    compare(camera, layers, gel, points_mm, pixels_px, threshold)
}

/// `model BIC b (RMS r px)` for each model.
fn bic_list(models: &[ModelScore]) -> String {
    models
        .iter()
        .map(|m| format!("{} BIC {:.1} (RMS {:.2} px)", m.model, m.bic, m.rms_px))
        .collect::<Vec<_>>()
        .join(", ")
}
