//! The synthetic extrinsics benchmark scene of issue 5, shared by the tests, the criterion bench
//! and the `extrinsics_benchmark` example.
//!
//! Kannala-Brandt 160 deg lens, f = 215 px, 640 x 480; 30 pin tips on a sphere of radius 15 mm
//! centred at the sensor origin, polar angles 0..75 deg (golden-angle spiral, equal area, first
//! pin at the pole, last at 75 deg); camera 10 mm below the sphere centre looking along +z
//! (nominal T_cam_sensor = [I | (0, 0, 10) mm]), perturbed per trial by a rotation of up to 3 deg
//! about a random axis and up to 0.5 mm per axis; pixel noise N(0, sigma^2) on u and v.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::camera::{CameraModel, Distortion, Intrinsics};

/// Intrinsics of the benchmark lens: f = 215 px, 640 x 480, principal point at the image centre,
/// mild Kannala-Brandt distortion (80 deg off axis lands 290 px from the centre: a 160 deg field).
pub fn benchmark_intrinsics() -> Intrinsics {
    Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 215.0,
        fy_px: 215.0,
        cx_px: 319.5,
        cy_px: 239.5,
        distortion: Distortion::Fisheye([-0.02, 0.004, -0.0015, 0.0002]),
    }
}

/// The benchmark camera.
pub fn benchmark_camera() -> CameraModel {
    CameraModel::new(benchmark_intrinsics()).expect("benchmark intrinsics are valid")
}

/// `n` pin tips (mm, sensor frame) on a sphere of radius `radius_mm` about the origin, polar
/// angles from 0 (the pole) to `max_polar_deg`, equal-area golden-angle spiral.
pub fn pin_layout(n: usize, radius_mm: f64, max_polar_deg: f64) -> Vec<Vector3<f64>> {
    let cmax = max_polar_deg.to_radians().cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let f = if n > 1 {
                i as f64 / (n - 1) as f64
            } else {
                0.0
            };
            let polar = (1.0 - f * (1.0 - cmax)).acos();
            let az = i as f64 * golden;
            radius_mm * Vector3::new(polar.sin() * az.cos(), polar.sin() * az.sin(), polar.cos())
        })
        .collect()
}

/// One seeded trial.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Trial {
    pub seed: u64,
    /// True T_cam_sensor: rotation as a row-major 3 x 3 and translation, mm.
    pub rotation: [[f64; 3]; 3],
    pub translation_mm: [f64; 3],
    /// Pin tips, mm, sensor frame (N, 3).
    pub points_mm: Vec<[f64; 3]>,
    /// Noisy (and possibly swapped) pixels, px (N, 2).
    pub pixels_px: Vec<[f64; 2]>,
    /// Indices whose observations were cyclically swapped (mislabelled pins).
    pub swapped: Vec<usize>,
}

impl Trial {
    pub fn t_cam_sensor(&self) -> Isometry3<f64> {
        let r = nalgebra::Matrix3::from_fn(|i, j| self.rotation[i][j]);
        Isometry3::from_parts(
            Translation3::new(
                self.translation_mm[0],
                self.translation_mm[1],
                self.translation_mm[2],
            ),
            UnitQuaternion::from_matrix(&r),
        )
    }
    pub fn points(&self) -> Vec<Vector3<f64>> {
        self.points_mm
            .iter()
            .map(|p| Vector3::new(p[0], p[1], p[2]))
            .collect()
    }
    pub fn pixels(&self) -> Vec<Vector2<f64>> {
        self.pixels_px
            .iter()
            .map(|p| Vector2::new(p[0], p[1]))
            .collect()
    }
}

fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    // Box-Muller.
    let u1 = 1.0 - uniform(rng);
    let u2 = uniform(rng);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// A seeded trial of the benchmark scene: 30 pins, noise `sigma_px`, and `n_swapped` pins whose
/// observations are cyclically permuted (`n_swapped` = 0 or >= 2).
pub fn benchmark_trial(seed: u64, sigma_px: f64, n_swapped: usize) -> Trial {
    let camera = benchmark_camera();
    let points = pin_layout(30, 15.0, 75.0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let axis = loop {
        let v = Vector3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng));
        if v.norm() > 1e-6 {
            break v.normalize();
        }
    };
    let angle = (3.0f64).to_radians() * uniform(&mut rng);
    let rot = UnitQuaternion::from_scaled_axis(axis * angle);
    let t = Vector3::new(0.0, 0.0, 10.0)
        + Vector3::from_fn(|_, _| 0.5 * (2.0 * uniform(&mut rng) - 1.0));
    let iso = Isometry3::from_parts(Translation3::from(t), rot);
    let mut pixels: Vec<[f64; 2]> = points
        .iter()
        .map(|p| {
            let uv = camera
                .project(&(iso * nalgebra::Point3::from(*p)).coords)
                .expect("pins are in view");
            [
                uv.x + sigma_px * gaussian(&mut rng),
                uv.y + sigma_px * gaussian(&mut rng),
            ]
        })
        .collect();
    let mut swapped = Vec::new();
    while swapped.len() < n_swapped {
        let i = (rng.next_u64() % points.len() as u64) as usize;
        if !swapped.contains(&i) {
            swapped.push(i);
        }
    }
    if swapped.len() >= 2 {
        let first = pixels[swapped[0]];
        for k in 0..swapped.len() - 1 {
            pixels[swapped[k]] = pixels[swapped[k + 1]];
        }
        let last = swapped[swapped.len() - 1];
        pixels[last] = first;
    }
    let rm = rot.to_rotation_matrix();
    Trial {
        seed,
        rotation: std::array::from_fn(|i| std::array::from_fn(|j| rm[(i, j)])),
        translation_mm: [t.x, t.y, t.z],
        points_mm: points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        pixels_px: pixels,
        swapped,
    }
}

/// Rotation error between two poses, degrees (angle of R_a R_b^T).
pub fn rotation_error_deg(a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
    a.rotation.angle_to(&b.rotation).to_degrees()
}

/// Translation error between two poses (of T_cam_sensor's translation), mm.
pub fn translation_error_mm(a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
    (a.translation.vector - b.translation.vector).norm()
}
