//! The offset surface of a body profile that carries markers ([`Surface`]), parametrised by
//! arc length from the pole: points, normals, polar angles, areas, curvatures and distances on
//! it.

use super::spec::Marker;
use crate::profile::BodyProfile;
use std::f64::consts::{FRAC_PI_2, PI};

/// An offset surface of a body profile, parametrised by arc length from the pole.
#[derive(Debug, Clone)]
pub struct Surface {
    pub body: BodyProfile,
    pub offset_mm: f64,
    /// (t, s): profile parameter and arc length, increasing, for the curved part.
    table: Vec<(f64, f64)>,
    /// Arc length of the curved part (pole to the rim on the base plane, or to the equator
    /// for the hemisphere on cylinder).
    curved_arc_mm: f64,
    /// Straight cylinder below the curved part (hemisphere on cylinder), mm.
    cylinder_mm: f64,
}

const TABLE_SAMPLES: usize = 4096;

impl Surface {
    pub fn new(body: &BodyProfile, offset_mm: f64) -> Self {
        let mut table = Vec::with_capacity(TABLE_SAMPLES + 1);
        let mut s = 0.0;
        let mut prev = body.offset_point(offset_mm, 0.0);
        table.push((0.0, 0.0));
        for i in 1..=TABLE_SAMPLES {
            let t = i as f64 / TABLE_SAMPLES as f64;
            let p = body.offset_point(offset_mm, t);
            // Chord of a fine sample; for arcs the exact length follows below.
            s += ((p[0] - prev[0]).powi(2) + (p[1] - prev[1]).powi(2)).sqrt();
            table.push((t, s));
            prev = p;
        }
        // Spherical profiles: exact arc length rho * angle (t is linear in angle).
        if let Some(r) = body.sphere_radius_mm() {
            let rho = r + offset_mm;
            let a_end =
                body.offset_normal(offset_mm, 1.0)[1].atan2(body.offset_normal(offset_mm, 1.0)[0]);
            let total = rho * (FRAC_PI_2 - a_end);
            for e in &mut table {
                e.1 = total * e.0;
            }
        }
        let curved_arc_mm = table.last().map(|e| e.1).unwrap_or(0.0);
        let cylinder_mm = match *body {
            BodyProfile::HemisphereOnCylinder {
                cylinder_length_mm, ..
            } => cylinder_length_mm,
            _ => 0.0,
        };
        Self {
            body: body.clone(),
            offset_mm,
            table,
            curved_arc_mm,
            cylinder_mm,
        }
    }

    /// Arc length from the pole to the base plane, mm.
    pub fn total_arc_mm(&self) -> f64 {
        self.curved_arc_mm + self.cylinder_mm
    }

    fn t_of_s(&self, s: f64) -> f64 {
        let s = s.clamp(0.0, self.curved_arc_mm);
        let i = self
            .table
            .partition_point(|e| e.1 < s)
            .clamp(1, self.table.len() - 1);
        let (t0, s0) = self.table[i - 1];
        let (t1, s1) = self.table[i];
        if s1 > s0 {
            t0 + (t1 - t0) * (s - s0) / (s1 - s0)
        } else {
            t0
        }
    }

    /// (r, z) and the outward normal (nr, nz) at arc length `s`.
    pub fn profile_at(&self, s: f64) -> ([f64; 2], [f64; 2]) {
        if s > self.curved_arc_mm {
            let p = self.body.offset_point(self.offset_mm, 1.0);
            ([p[0], p[1] - (s - self.curved_arc_mm)], [1.0, 0.0])
        } else {
            let t = self.t_of_s(s);
            (
                self.body.offset_point(self.offset_mm, t),
                self.body.offset_normal(self.offset_mm, t),
            )
        }
    }

    /// Position and outward normal in the sensor frame at (arc length, azimuth in radians).
    pub fn point(&self, s: f64, azimuth: f64) -> ([f64; 3], [f64; 3]) {
        let (p, n) = self.profile_at(s);
        let (sa, ca) = azimuth.sin_cos();
        ([p[0] * ca, p[0] * sa, p[1]], [n[0] * ca, n[0] * sa, n[1]])
    }

    /// Radius (distance from the axis) at arc length `s`.
    pub fn radius_at(&self, s: f64) -> f64 {
        self.profile_at(s).0[0]
    }

    /// Polar angle (degrees, from +z, seen from the origin) at arc length `s`.
    pub fn polar_deg_at(&self, s: f64) -> f64 {
        let p = self.profile_at(s).0;
        p[0].atan2(p[1]).to_degrees()
    }

    /// Arc length where the polar angle is `polar_deg` (it grows monotonically with s).
    pub fn s_at_polar_deg(&self, polar_deg: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, self.total_arc_mm());
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.polar_deg_at(mid) < polar_deg {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Surface area between the pole and arc length `s` (Pappus, trapezoid on 2000 panels), mm^2.
    pub fn area_to(&self, s: f64) -> f64 {
        let n = 2000;
        let h = s / n as f64;
        (0..n)
            .map(|i| PI * (self.radius_at(i as f64 * h) + self.radius_at((i + 1) as f64 * h)) * h)
            .sum()
    }

    /// Principal curvatures (meridian, parallel) at arc length `s`, 1/mm; positive for a
    /// surface that curves away from its outward normal (convex).
    pub fn curvatures_at(&self, s: f64) -> (f64, f64) {
        let h = 1e-4;
        let s0 = (s - h).max(0.0);
        let s1 = (s + h).min(self.total_arc_mm());
        let (n0, n1) = (self.profile_at(s0).1, self.profile_at(s1).1);
        let a0 = n0[1].atan2(n0[0]);
        let a1 = n1[1].atan2(n1[0]);
        let k_meridian = if s1 > s0 { (a0 - a1) / (s1 - s0) } else { 0.0 };
        let (p, n) = self.profile_at(s);
        let k_parallel = if p[0] > 1e-9 { n[0] / p[0] } else { k_meridian };
        (k_meridian, k_parallel)
    }

    /// Length of the straight chord between two surface points projected onto the surface
    /// (16 segments), mm: the on-surface distance for nearby markers.
    pub fn surface_distance(&self, a: &Marker, b: &Marker) -> f64 {
        let steps = 16;
        let mut prev = a.position_mm;
        let mut len = 0.0;
        for i in 1..=steps {
            let f = i as f64 / steps as f64;
            let q = if i == steps {
                b.position_mm
            } else {
                let c = [
                    a.position_mm[0] + f * (b.position_mm[0] - a.position_mm[0]),
                    a.position_mm[1] + f * (b.position_mm[1] - a.position_mm[1]),
                    a.position_mm[2] + f * (b.position_mm[2] - a.position_mm[2]),
                ];
                self.project(c, a.arc_mm + f * (b.arc_mm - a.arc_mm))
            };
            len += ((q[0] - prev[0]).powi(2) + (q[1] - prev[1]).powi(2) + (q[2] - prev[2]).powi(2))
                .sqrt();
            prev = q;
        }
        len
    }

    /// The closest surface point to `c`, starting the search at arc length `s_guess`.
    fn project(&self, c: [f64; 3], s_guess: f64) -> [f64; 3] {
        let r = (c[0] * c[0] + c[1] * c[1]).sqrt();
        let az = c[1].atan2(c[0]);
        let mut s = s_guess;
        for _ in 0..8 {
            let (p, n) = self.profile_at(s);
            // tangent (pointing to growing s) is the normal rotated by -90 degrees
            let t = [n[1], -n[0]];
            let step = (r - p[0]) * t[0] + (c[2] - p[1]) * t[1];
            s = (s + step).clamp(0.0, self.total_arc_mm());
            if step.abs() < 1e-12 {
                break;
            }
        }
        self.point(s, az).0
    }
}
