//! Curved interfaces of revolution about the sensor's z axis: the faces of a round-bottomed
//! core (a glass test tube) and of the cast layers on it, each a sphere above a cylinder of
//! the same section ([`Shell`]). A ray leaves each shell once (the shells are convex and
//! nested) and bends there by Snell's law in vector form (Hecht, *Optics*, 5th ed., Sec. 4.4,
//! Eq. 4.4 with the plane of incidence holding the ray and the surface normal):
//!
//! ```text
//! t = eta d + (sqrt(1 - eta^2 (1 - (d.n)^2)) - eta (d.n)) n,   eta = n_inside / n_outside,
//! ```
//!
//! for the unit ray `d` and the unit outward normal `n` at the exit (`d.n > 0`); under the
//! root below 0 the ray is totally internally reflected. Sensor frame, mm.

use nalgebra::Vector3;

/// One curved interface: the sphere of radius `radius_mm` centred on the z axis at
/// `centre_z_mm`, above the height `join_z_mm` (at or above the centre), and below that the
/// cylinder of the sphere's section there, down to `bottom_z_mm` where the shell is open (the
/// hemisphere on a cylinder of a test tube when `join_z_mm` is the centre). The medium
/// outside it has the index `index_outside` and begins at `outside_bottom_z_mm`: a ray that
/// leaves the shell below that height meets what holds the shell (a housing's seat) and ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shell {
    pub radius_mm: f64,
    pub centre_z_mm: f64,
    pub join_z_mm: f64,
    pub bottom_z_mm: f64,
    pub index_outside: f64,
    pub outside_bottom_z_mm: f64,
}

impl Shell {
    /// The cylinder's radius: the sphere's section at `join_z_mm`, mm.
    pub fn cylinder_radius_mm(&self) -> f64 {
        let h = self.join_z_mm - self.centre_z_mm;
        (self.radius_mm * self.radius_mm - h * h).max(0.0).sqrt()
    }

    /// Whether `p` is strictly inside the shell (above its open bottom).
    pub fn contains(&self, p: &Vector3<f64>) -> bool {
        if !(p.z > self.bottom_z_mm) {
            return false;
        }
        let rho = self.cylinder_radius_mm();
        if p.z <= self.join_z_mm {
            p.xy().norm_squared() < rho * rho
        } else {
            (p - Vector3::new(0.0, 0.0, self.centre_z_mm)).norm_squared()
                < self.radius_mm * self.radius_mm
        }
    }

    /// Where the ray from `o` (inside the shell or on its surface from inside) along the unit
    /// `d` leaves it, and the unit outward normal there. `None` when it leaves through the
    /// open bottom or never leaves (not a unit, finite direction).
    pub fn exit(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let rho = self.cylinder_radius_mm();
        // the infinite cylinder: |o_xy + t d_xy| = rho, the larger root
        let a = d.xy().norm_squared();
        let t_cyl = if a > 0.0 {
            let b = o.xy().dot(&d.xy());
            let c = o.xy().norm_squared() - rho * rho;
            let disc = b * b - a * c;
            (disc >= 0.0).then(|| (-b + disc.sqrt()) / a)
        } else {
            None
        };
        // the sphere, the larger root, counted where it is above the join
        let oc = o - Vector3::new(0.0, 0.0, self.centre_z_mm);
        let b = oc.dot(d);
        let disc = b * b - (oc.norm_squared() - self.radius_mm * self.radius_mm);
        let t_sph = (disc >= 0.0)
            .then(|| -b + disc.sqrt())
            .filter(|t| o.z + t * d.z >= self.join_z_mm);
        let (t, on_sphere) = match (t_cyl.filter(|t| o.z + t * d.z <= self.join_z_mm), t_sph) {
            (Some(tc), Some(ts)) if ts < tc => (ts, true),
            (Some(tc), _) => (tc, false),
            (None, Some(ts)) => (ts, true),
            (None, None) => return None,
        };
        if !(t >= 0.0) || !t.is_finite() {
            return None;
        }
        let p = o + t * d;
        // leaving through the open end first
        if p.z < self.bottom_z_mm {
            return None;
        }
        let n = if on_sphere {
            (p - Vector3::new(0.0, 0.0, self.centre_z_mm)) / self.radius_mm
        } else {
            Vector3::new(p.x, p.y, 0.0) / rho
        };
        Some((p, n))
    }
}

/// Snell's law in vector form at a surface with unit normal `n` on the side the ray goes to
/// (`d.n > 0`), from index `n1` into `n2`: the unit refracted direction, `None` when the ray is
/// totally internally reflected (module docs; Hecht Sec. 4.4).
pub fn refract(d: &Vector3<f64>, n: &Vector3<f64>, n1: f64, n2: f64) -> Option<Vector3<f64>> {
    let eta = n1 / n2;
    let cos_i = d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if !(k >= 0.0) {
        return None;
    }
    Some((eta * d + (k.sqrt() - eta * cos_i) * n).normalize())
}
