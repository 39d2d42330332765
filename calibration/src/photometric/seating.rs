//! A pin dome's seating for one capture, refined from the capture's own imprints: the dome is
//! put on the skin again for every capture, and lands a little turned or shifted (issue 101:
//! the same pin's imprint moves 2.7 px RMS between real R-Tac0 captures), while the camera's
//! extrinsics stay one per sensor.
//!
//! The seating is a small rigid motion of the whole dome, a rotation `omega` (a rotation vector,
//! small) about `pivot` (the mean of the dome's pin tips) and a translation `t`:
//! `X -> pivot + R(omega) (X - pivot) + t`. It is found from the offsets between each imprint's
//! centroid of darkening in the capture and in the model's rendering (the fit's, with the
//! dome where the extrinsics put it): an imprint lies where its pin meets the skin, so a motion
//! of the pin moves it along the skin by the motion's tangential part, `dX = t + omega x (X -
//! pivot)` at the imprint's surface point `X`, and its pixel by `(A^T A)^-1 A^T dX`, `A` the
//! 3 x 2 derivative of the surface point the pixels see with respect to the pixel (from the
//! reference surface's hits at the neighbouring pixels: refraction and distortion included).
//! The six numbers are the maximum a posteriori estimate under a Gaussian prior (zero mean:
//! where the extrinsics put the dome; [`SeatingPrior`]) from the centroids' offsets, each of
//! `centroid_sigma_px`, one linear solve; a motion past the bounds is scaled back to them.
//! Moving a pin along its own axis does not move its imprint, but presses it deeper: the dome's
//! seat sets its pins' depths (ASSUMPTION), so every pin's move along its axis is held near 0
//! (`depth_sigma_mm`); on a round skin what is left is the dome turning about the skin's
//! centre, on a flat one its sliding and turning in the plane.

use nalgebra::{Isometry3, Matrix3, Matrix3x2, Matrix6, Translation3};
use nalgebra::{UnitQuaternion, Vector2, Vector3, Vector6};

use crate::groundtruth::rays::PixelRays;
use crate::groundtruth::SurfaceHits;

/// The prior on a dome's seating and its bounds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SeatingPrior {
    /// Standard deviation of each translation component, mm.
    pub translation_sigma_mm: f64,
    /// Standard deviation of each rotation component, degrees.
    pub rotation_sigma_deg: f64,
    /// The most translation and rotation (their norms), mm and degrees.
    pub max_translation_mm: f64,
    pub max_rotation_deg: f64,
    /// Standard deviation of an imprint's centroid offset (the rendering's and the capture's
    /// noise, the model's bias), px.
    pub centroid_sigma_px: f64,
    /// Standard deviation of each pin's move along its own axis, mm: the dome's seat sets how
    /// deep its pins press, so a seating moves them along the skin.
    pub depth_sigma_mm: f64,
}

/// The prior `calibrate photometric` uses: a dome re-seated by hand on its sensor lands within
/// a few tenths of a millimetre and about a degree (ASSUMPTION: R-Tac0's imprints move 2.7 px
/// RMS between captures, about 0.1 mm on its skin), centroids to half a pixel.
pub const SEATING_PRIOR: SeatingPrior = SeatingPrior {
    translation_sigma_mm: 0.2,
    rotation_sigma_deg: 1.0,
    max_translation_mm: 0.5,
    max_rotation_deg: 3.0,
    centroid_sigma_px: 0.5,
    depth_sigma_mm: 0.005,
};

/// A dome's seating for one capture (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DomeSeating {
    /// `t`, sensor frame, mm.
    pub translation_mm: [f64; 3],
    /// `omega` (a rotation vector: axis times angle), sensor frame, degrees.
    pub rotation_deg: [f64; 3],
    /// The point the dome turns about, sensor frame, mm.
    pub pivot_mm: [f64; 3],
    /// The imprints it was found from (those with a centroid in both images).
    pub imprints: usize,
    /// The motion was scaled back to the bounds.
    pub bounded: bool,
    /// How much of the centroids' offsets the motion explains: the drop of their sum of
    /// squares over `centroid_sigma_px^2` (chi-square); the motion is kept only past
    /// [`SEATING_CHI2`] (otherwise none: the offsets are the centroids' noise and the model's
    /// bias, not a seating).
    pub chi2_explained: f64,
}

/// The chi-square the centroids' offsets must drop by for a seating to be kept: chi-square's
/// 99th percentile for three degrees of freedom (a dome held at its pins' depths moves in
/// three: on a round skin it turns about the skin's centre, on a flat one it slides and turns in
/// the plane). Below it the offsets are noise and the model's bias: moving the dome to them
/// would move its sharp rendered imprints off the real ones (issue 101, R-Tac0 synthetic: a
/// dome moved 0.01 mm by 0.2 px offsets re-renders its imprints 1 count worse).
pub const SEATING_CHI2: f64 = 11.34;

impl DomeSeating {
    /// No motion about `pivot_mm`.
    pub fn none(pivot_mm: [f64; 3]) -> DomeSeating {
        DomeSeating {
            translation_mm: [0.0; 3],
            rotation_deg: [0.0; 3],
            pivot_mm,
            imprints: 0,
            bounded: false,
            chi2_explained: 0.0,
        }
    }

    /// The motion as an isometry of the sensor frame (`X -> pivot + R (X - pivot) + t`).
    pub fn isometry(&self) -> Isometry3<f64> {
        let omega = Vector3::from(self.rotation_deg).map(f64::to_radians);
        let r = UnitQuaternion::from_scaled_axis(omega);
        let p = Vector3::from(self.pivot_mm);
        let t = Vector3::from(self.translation_mm);
        Isometry3::from_parts(Translation3::from(p + t - r * p), r)
    }

    /// This seating followed by `then` (about the same pivot): the isometry `then * self`
    /// expressed again as a translation and a rotation vector about the pivot.
    pub fn then(&self, then: &DomeSeating) -> DomeSeating {
        let m = then.isometry() * self.isometry();
        let p = Vector3::from(self.pivot_mm);
        let r = m.rotation;
        let t = m.translation.vector + r * p - p;
        let omega = r.scaled_axis().map(f64::to_degrees);
        DomeSeating {
            translation_mm: t.into(),
            rotation_deg: omega.into(),
            pivot_mm: self.pivot_mm,
            imprints: then.imprints,
            bounded: self.bounded || then.bounded,
            chi2_explained: then.chi2_explained,
        }
    }

    /// How far the seating moves a point at `radius_mm` from the pivot at most: the
    /// translation's norm plus the rotation's angle times the radius, mm.
    pub fn reach_mm(&self, radius_mm: f64) -> f64 {
        Vector3::from(self.translation_mm).norm()
            + Vector3::from(self.rotation_deg).norm().to_radians() * radius_mm
    }
}

/// The surface point pixel `p` sees on `reference` (NaN where its ray misses).
fn point(rays: &PixelRays, reference: &SurfaceHits, p: usize) -> Vector3<f64> {
    let (o, d, t) = (rays.origin(p), rays.dirs[p], reference.t_mm[p]);
    Vector3::new(o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2])
}

/// The seating of a dome about `pivot_mm` whose imprints' centroids of darkening are
/// `rendered_px` in the model's rendering (the dome where the extrinsics put it) and `real_px`
/// in the capture, pairwise (module docs); imprints whose surface point or its neighbours'
/// do not see the reference skin are left out. No imprint left: no motion.
pub fn seat_dome(
    rays: &PixelRays,
    reference: &SurfaceHits,
    pairs: &[([f64; 2], [f64; 2])],
    pins: &[([f64; 3], [f64; 3])],
    pivot_mm: [f64; 3],
    prior: &SeatingPrior,
) -> DomeSeating {
    let (w, h) = (rays.width, rays.height);
    let pivot = Vector3::from(pivot_mm);
    let mut ata = Matrix6::<f64>::zeros();
    let mut atb = Vector6::<f64>::zeros();
    // the offsets' sum of squares and their normal matrix alone (for the chi-square)
    let mut btb = 0.0;
    let mut used = 0;
    let wc = 1.0 / prior.centroid_sigma_px.powi(2);
    for (rendered, real) in pairs {
        let (u, v) = (rendered[0].round(), rendered[1].round());
        if !(u >= 1.0 && v >= 1.0 && u < (w - 1) as f64 && v < (h - 1) as f64) {
            continue;
        }
        let (u, v) = (u as usize, v as usize);
        let at = |du: isize, dv: isize| {
            let p = (v as isize + dv) as usize * w + (u as isize + du) as usize;
            point(rays, reference, p)
        };
        let (x, xu0, xu1, xv0, xv1) = (at(0, 0), at(-1, 0), at(1, 0), at(0, -1), at(0, 1));
        let a = Matrix3x2::from_columns(&[(xu1 - xu0) / 2.0, (xv1 - xv0) / 2.0]);
        if !(x.iter().chain(a.iter()).all(|c| c.is_finite())) {
            continue;
        }
        let Some(ata_inv) = (a.transpose() * a).try_inverse() else {
            continue;
        };
        let to_px: nalgebra::Matrix2x3<f64> = ata_inv * a.transpose();
        // dX = t + omega x (X - pivot) = [I | -[X - pivot]x] (t, omega)
        let arm = x - pivot;
        let cross = Matrix3::new(
            0.0, arm.z, -arm.y, //
            -arm.z, 0.0, arm.x, //
            arm.y, -arm.x, 0.0,
        );
        let mut m = nalgebra::Matrix3x6::<f64>::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&cross);
        let j = to_px * m;
        let d = Vector2::new(real[0] - rendered[0], real[1] - rendered[1]);
        if !d.iter().all(|c| c.is_finite()) {
            continue;
        }
        ata += j.transpose() * j * wc;
        atb += j.transpose() * d * wc;
        btb += d.norm_squared() * wc;
        used += 1;
    }
    let data = ata;
    let mut seating = DomeSeating::none(pivot_mm);
    if used == 0 {
        return seating;
    }
    // every pin of the dome keeps its depth: its tip's move along its axis, a . dX, held
    let wd = 1.0 / prior.depth_sigma_mm.powi(2);
    for (tip, axis) in pins {
        let (arm, a) = (Vector3::from(*tip) - pivot, Vector3::from(*axis));
        // a . (t + omega x arm) = a . t + omega . (arm x a)
        let row = Vector6::new(a.x, a.y, a.z, 0.0, 0.0, 0.0) + {
            let c = arm.cross(&a);
            Vector6::new(0.0, 0.0, 0.0, c.x, c.y, c.z)
        };
        ata += row * row.transpose() * wd;
    }
    let (st, sr) = (
        prior.translation_sigma_mm,
        prior.rotation_sigma_deg.to_radians(),
    );
    for k in 0..3 {
        ata[(k, k)] += 1.0 / (st * st);
        ata[(k + 3, k + 3)] += 1.0 / (sr * sr);
    }
    let Some(x) = ata.cholesky().map(|c| c.solve(&atb)) else {
        return seating;
    };
    let mut t = Vector3::new(x[0], x[1], x[2]);
    let mut omega = Vector3::new(x[3], x[4], x[5]);
    let (tn, an) = (t.norm(), omega.norm().to_degrees());
    if tn > prior.max_translation_mm {
        t *= prior.max_translation_mm / tn;
        seating.bounded = true;
    }
    if an > prior.max_rotation_deg {
        omega *= prior.max_rotation_deg / an;
        seating.bounded = true;
    }
    // the drop of the offsets' chi-square: |d|^2 - |d - J x|^2 = 2 x.A^T d - x.A^T A x
    let x = Vector6::new(t.x, t.y, t.z, omega.x, omega.y, omega.z);
    let explained = 2.0 * x.dot(&atb) - (x.transpose() * data * x)[(0, 0)];
    seating.imprints = used;
    seating.chi2_explained = explained;
    if explained.is_finite() && explained > SEATING_CHI2 && explained <= btb {
        seating.translation_mm = t.into();
        seating.rotation_deg = omega.map(f64::to_degrees).into();
    } else {
        seating.bounded = false;
    }
    seating
}
