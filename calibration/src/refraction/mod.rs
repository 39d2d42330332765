//! The optical path between the lens and the skin: clear media bounded by flat interfaces
//! normal to the sensor's z axis (a filling gel's free surface, a clear plate, flat cast
//! layers) and then by the curved faces of a core ([`shells`]), each ray bent at every
//! interface by Snell's law, and the projection of a
//! sensor-frame point through them ([`Imaging`]). Sensor frame, mm (docs/conventions.md).
//!
//! Snell's law at a plane, n1 sin(theta1) = n2 sin(theta2) with the ray staying in the plane of
//! incidence (Hecht, *Optics*, 5th ed., Sec. 4.4), makes `s = n sin(theta)` (theta from the
//! interfaces' common normal) the same in every medium, and the ray's lateral run through a
//! medium of thickness `t` and index `n` is `t s / sqrt(n^2 - s^2)`. The ray from the camera's
//! centre `C` to a point `P` is therefore the one whose `s` solves
//!
//! ```text
//! sum_i t_i s / sqrt(n_i^2 - s^2) = |(P - C)_xy|,
//! ```
//!
//! a sum increasing in `s` from 0 on [0, min n_i): one root, found by safeguarded Newton steps.
//! Paraxially, a point at depth `d` below one interface seen straight along its normal appears
//! at depth `d / n` (Hecht Sec. 5.2.3, the apparent depth), as the tests check.
//!
//! Above the planes the ray may cross curved interfaces of revolution about the z axis, a
//! glass core's faces and the cast layers on it ([`shells`]): there the ray leaves each shell
//! once and bends by Snell's law in vector form, and the ray to a point is found by
//! Gauss-Newton on its direction from the camera, started from the ray through the planes
//! alone (see [`OpticalLayers::direction_to`]).
//!
//! Assumed: the flat interfaces are planes normal to the sensor's z axis, the curved ones
//! spheres on cylinders coaxial with it, and the media homogeneous and isotropic; the camera
//! file describes the lens in the medium the camera's centre sits in (air for every library
//! sensor: it was calibrated there).

pub mod shells;

use crate::camera::CameraModel;
use nalgebra::{Matrix2x6, Matrix3, Rotation3, Vector2, Vector3};
pub use shells::Shell;

/// Largest refractive index a medium may have (exclusive), as the materials table.
pub const MAX_INDEX: f64 = 3.0;

/// A bad optical path: what is wrong, with the value and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {rule}")]
pub struct LayersError {
    pub field: String,
    pub value: String,
    pub rule: &'static str,
}

/// Clear media bounded by planes `z = z_k` of the sensor frame: the medium below the first
/// plane, between consecutive planes, and above the last, each with its refractive index;
/// then, in the medium above the last plane, nested curved interfaces ([`Shell`]) each with
/// the index outside it.
#[derive(Debug, Clone, PartialEq)]
pub struct OpticalLayers {
    planes_z_mm: Vec<f64>,
    indices: Vec<f64>,
    shells: Vec<Shell>,
}

impl OpticalLayers {
    /// `planes_z_mm` (K, mm, strictly increasing, finite) and `indices` (K + 1, each in
    /// [1, 3)): the medium below `planes_z_mm[0]`, then each medium above a plane.
    ///
    /// # Errors
    /// [`LayersError`] naming the entry, its value and the rule.
    pub fn new(planes_z_mm: Vec<f64>, indices: Vec<f64>) -> Result<OpticalLayers, LayersError> {
        if indices.len() != planes_z_mm.len() + 1 {
            return Err(LayersError {
                field: "indices".into(),
                value: format!("{} entries", indices.len()),
                rule: "one index per medium: one more than the planes",
            });
        }
        for (k, z) in planes_z_mm.iter().enumerate() {
            if !z.is_finite() || (k > 0 && !(*z > planes_z_mm[k - 1])) {
                return Err(LayersError {
                    field: format!("planes_z_mm[{k}]"),
                    value: crate::shown_f64(*z),
                    rule: "must be finite and above the plane before it",
                });
            }
        }
        for (k, n) in indices.iter().enumerate() {
            if !(*n >= 1.0 && *n < MAX_INDEX) {
                return Err(LayersError {
                    field: format!("indices[{k}]"),
                    value: crate::shown_f64(*n),
                    rule: "a refractive index must be from 1 to below 3",
                });
            }
        }
        Ok(OpticalLayers {
            planes_z_mm,
            indices,
            shells: Vec::new(),
        })
    }

    /// These layers with nested curved interfaces above the last plane, innermost first: the
    /// medium inside the first is the one above the last plane (the filling gel), outside
    /// each its `index_outside`. A shell whose outside index is its inside one bends nothing
    /// and is left out (two clear silicones of the same index: the ray's last stretch then
    /// starts at the last shell that bends it).
    ///
    /// # Errors
    /// [`LayersError`] naming `shells[k]` and its field: not finite, a radius not above 0, a
    /// join below the centre or beyond the sphere, a bottom above the join, an index outside
    /// [1, 3), a shell not about the same centre as the first or not larger than the one
    /// inside it.
    pub fn with_shells(mut self, shells: Vec<Shell>) -> Result<OpticalLayers, LayersError> {
        let bad = |k: usize, f: &str, v: f64, rule: &'static str| LayersError {
            field: format!("shells[{k}].{f}"),
            value: crate::shown_f64(v),
            rule,
        };
        for (k, s) in shells.iter().enumerate() {
            for (f, v) in [
                ("radius_mm", s.radius_mm),
                ("centre_z_mm", s.centre_z_mm),
                ("join_z_mm", s.join_z_mm),
                ("bottom_z_mm", s.bottom_z_mm),
                ("outside_bottom_z_mm", s.outside_bottom_z_mm),
            ] {
                if !v.is_finite() {
                    return Err(bad(k, f, v, "must be finite"));
                }
            }
            if !(s.radius_mm > 0.0) {
                return Err(bad(k, "radius_mm", s.radius_mm, "must be above 0"));
            }
            if !(s.join_z_mm >= s.centre_z_mm && s.join_z_mm < s.centre_z_mm + s.radius_mm) {
                return Err(bad(
                    k,
                    "join_z_mm",
                    s.join_z_mm,
                    "must be at or above the centre and below the sphere's top",
                ));
            }
            if !(s.bottom_z_mm <= s.join_z_mm) {
                return Err(bad(
                    k,
                    "bottom_z_mm",
                    s.bottom_z_mm,
                    "must be at or below the join",
                ));
            }
            if !(s.index_outside >= 1.0 && s.index_outside < MAX_INDEX) {
                return Err(bad(
                    k,
                    "index_outside",
                    s.index_outside,
                    "a refractive index must be from 1 to below 3",
                ));
            }
            if k > 0 {
                let inner = &shells[k - 1];
                if s.centre_z_mm != shells[0].centre_z_mm {
                    return Err(bad(
                        k,
                        "centre_z_mm",
                        s.centre_z_mm,
                        "nested shells share the first one's centre",
                    ));
                }
                if !(s.radius_mm > inner.radius_mm)
                    || !(s.cylinder_radius_mm() > inner.cylinder_radius_mm())
                {
                    return Err(bad(
                        k,
                        "radius_mm",
                        s.radius_mm,
                        "must be larger than the shell inside it (sphere and cylinder)",
                    ));
                }
            }
        }
        let mut kept: Vec<Shell> = Vec::new();
        for s in shells {
            let inside = kept
                .last()
                .map_or(*self.indices.last().unwrap_or(&1.0), |k| k.index_outside);
            // the first is kept: the index inside it (the gel's) may be refined
            if kept.is_empty() || s.index_outside != inside {
                kept.push(s);
            }
        }
        self.shells = kept;
        Ok(self)
    }

    /// The curved interfaces that bend rays, innermost first ([`OpticalLayers::with_shells`]).
    pub fn shells(&self) -> &[Shell] {
        &self.shells
    }

    /// How many shells, from the innermost, a ray crosses to reach `p`: up to the first that
    /// holds `p`.
    pub fn shells_before(&self, p: &Vector3<f64>) -> usize {
        self.shells
            .iter()
            .position(|s| s.contains(p))
            .unwrap_or(self.shells.len())
    }

    /// Traces the ray at `o` along `d` (in the medium above the last plane, at or above it)
    /// out of the first `count` shells: where it leaves the last of them and its unit
    /// direction beyond. A ray below the first shell's open bottom enters it there. `None`
    /// when the ray does not enter the first shell through its open end (it meets the core's
    /// rim or what holds it), leaves a shell through its open end or below where the medium
    /// outside it begins ([`Shell::outside_bottom_z_mm`]), or is totally internally
    /// reflected.
    pub fn trace_shells(
        &self,
        o: &Vector3<f64>,
        d: &Vector3<f64>,
        count: usize,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let mut d = d.try_normalize(0.0)?;
        let mut o = *o;
        let Some(first) = self.shells.first().filter(|_| count > 0) else {
            return Some((o, d));
        };
        if !(o.z > first.bottom_z_mm) {
            if !(d.z > 0.0) {
                return None;
            }
            o += (first.bottom_z_mm - o.z) / d.z * d;
            o.z = first.bottom_z_mm;
            let rho = first.cylinder_radius_mm();
            if !(o.xy().norm_squared() < rho * rho) {
                return None;
            }
        } else if !first.contains(&o) {
            return None;
        }
        let mut n_in = *self.indices.last().unwrap_or(&1.0);
        for s in self.shells.iter().take(count) {
            let (p, normal) = s.exit(&o, &d)?;
            // below where the medium outside begins: what holds the shell
            if !(p.z >= s.outside_bottom_z_mm) {
                return None;
            }
            d = shells::refract(&d, &normal, n_in, s.index_outside)?;
            o = p;
            n_in = s.index_outside;
        }
        Some((o, d))
    }

    /// One plane at `z_mm` between a medium of index `below` and one of index `above`.
    ///
    /// # Errors
    /// As [`OpticalLayers::new`].
    pub fn single(z_mm: f64, below: f64, above: f64) -> Result<OpticalLayers, LayersError> {
        OpticalLayers::new(vec![z_mm], vec![below, above])
    }

    /// The layers of a design's optical path (`fabkit_designs::optics::optical_path`): air
    /// (n = 1) under its lowest plane, where the camera sits, then each plane's medium, then
    /// its curved faces ([`OpticalLayers::with_shells`]).
    ///
    /// # Errors
    /// As [`OpticalLayers::new`] and [`OpticalLayers::with_shells`].
    pub fn from_optical_path(
        path: &fabkit_designs::optics::OpticalPath,
    ) -> Result<OpticalLayers, LayersError> {
        let mut indices = vec![1.0];
        indices.extend(path.planes.iter().map(|p| p.index_above));
        OpticalLayers::new(path.planes.iter().map(|p| p.z_mm).collect(), indices)?.with_shells(
            path.shells
                .iter()
                .map(|s| Shell {
                    radius_mm: s.radius_mm,
                    centre_z_mm: s.centre_z_mm,
                    join_z_mm: s.join_z_mm,
                    bottom_z_mm: s.bottom_z_mm,
                    index_outside: s.index_outside,
                    outside_bottom_z_mm: s.outside_bottom_z_mm,
                })
                .collect(),
        )
    }

    /// The planes' heights, sensor frame z, mm, increasing.
    pub fn planes_z_mm(&self) -> &[f64] {
        &self.planes_z_mm
    }

    /// The media's refractive indices, from below the first plane to above the last.
    pub fn indices(&self) -> &[f64] {
        &self.indices
    }

    /// The index of the medium at height `z_mm` (a point on a plane counts as below it).
    pub fn index_at(&self, z_mm: f64) -> f64 {
        self.indices[self.planes_z_mm.iter().filter(|&&p| p < z_mm).count()]
    }

    /// The thickness along z (mm) and index of each medium the segment from height `z0` to
    /// height `z1` passes through, in either direction.
    fn runs(&self, z0: f64, z1: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let (lo, hi) = if z0 <= z1 { (z0, z1) } else { (z1, z0) };
        let k = self.planes_z_mm.len();
        (0..=k).filter_map(move |i| {
            let bottom = if i == 0 {
                lo
            } else {
                self.planes_z_mm[i - 1].max(lo)
            };
            let top = if i == k {
                hi
            } else {
                self.planes_z_mm[i].min(hi)
            };
            (top > bottom).then_some((top - bottom, self.indices[i]))
        })
    }

    /// The unit direction (sensor frame) in which the ray that reaches `to` leaves `from`, in
    /// the medium at `from`. Through the planes alone: the root of the lateral-run equation
    /// of the module docs. Through shells as well (`to` beyond the first): Gauss-Newton on
    /// the direction's two angles about that root, the ray's miss of `to` measured across
    /// the line of sight from the last exit to `to`, with forward-difference derivatives
    /// (steps 1e-7 rad), step halving while the miss does not fall, until it stops falling
    /// below 1e-12 mm. `None` when the points coincide or are not finite, or through shells
    /// when no ray reaches `to` (blocked by a shell's open end or totally reflected) or the
    /// miss stays above 1e-9 mm.
    pub fn direction_to(&self, from: &Vector3<f64>, to: &Vector3<f64>) -> Option<Vector3<f64>> {
        let d0 = self.direction_through_planes(from, to)?;
        let count = self.shells_before(to);
        if count == 0 {
            return Some(d0);
        }
        let end = |d: &Vector3<f64>| -> Option<(Vector3<f64>, Vector3<f64>)> {
            let (o, e) = self.trace_beyond_planes(from, d)?;
            self.trace_shells(&o, &e, count)
        };
        // from the ray through the planes, or the straight one where that is blocked
        let (d0, (o0, _)) = match end(&d0) {
            Some(e) => (d0, e),
            None => {
                let straight = (to - from).try_normalize(0.0)?;
                (straight, end(&straight)?)
            }
        };
        let w = (to - o0).try_normalize(0.0)?;
        let (f1, f2) = across(&w);
        let miss = |d: &Vector3<f64>| -> Option<nalgebra::Vector2<f64>> {
            let (o, u) = end(d)?;
            let uw = u.dot(&w);
            if !(uw > 0.0) {
                return None;
            }
            let x = o + ((to - o).dot(&w) / uw) * u - to;
            Some(nalgebra::Vector2::new(x.dot(&f1), x.dot(&f2)))
        };
        let along = |d: &Vector3<f64>, a: f64, b: f64| -> Vector3<f64> {
            let (e1, e2) = across(d);
            (d + a * e1 + b * e2).normalize()
        };
        let mut d = d0;
        let mut r = miss(&d)?;
        let h = 1e-7;
        for _ in 0..60 {
            if r.norm() <= 1e-12 {
                break;
            }
            let j = nalgebra::Matrix2::from_columns(&[
                (miss(&along(&d, h, 0.0))? - r) / h,
                (miss(&along(&d, 0.0, h))? - r) / h,
            ]);
            let step = j.try_inverse()? * (-r);
            let mut scale = 1.0;
            let mut better = None;
            for _ in 0..30 {
                let dn = along(&d, scale * step.x, scale * step.y);
                if let Some(rn) = miss(&dn) {
                    if rn.norm() < r.norm() {
                        better = Some((dn, rn));
                        break;
                    }
                }
                scale *= 0.5;
            }
            let Some((dn, rn)) = better else { break };
            (d, r) = (dn, rn);
        }
        (r.norm() <= 1e-9).then_some(d)
    }

    /// [`direction_to`](Self::direction_to) through the planes alone (every medium above the
    /// last plane taken as the one just above it).
    fn direction_through_planes(
        &self,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let h = to - from;
        let run = h.xy().norm();
        if !(h.norm() > 0.0) || !h.iter().all(|v| v.is_finite()) {
            return None;
        }
        // the media's runs, walked afresh at each use (no allocation per projection)
        let runs = || self.runs(from.z, to.z);
        let n_from = self.index_at(from.z);
        if runs().next().is_none() || run == 0.0 || runs().all(|(_, n)| n == n_from) {
            return Some(h / h.norm());
        }
        let n_min = runs().map(|(_, n)| n).fold(f64::INFINITY, f64::min);
        let f = |s: f64| {
            runs().fold((-run, 0.0), |(v, d), (t, n)| {
                let c2 = n * n - s * s;
                (v + t * s / c2.sqrt(), d + t * n * n / (c2 * c2.sqrt()))
            })
        };
        // Newton from the straight ray's invariant, kept inside a shrinking bracket [lo, hi].
        let (mut lo, mut hi) = (0.0, n_min);
        let mut s = (n_from * run / h.norm()).min(0.5 * n_min);
        for _ in 0..200 {
            let (v, d) = f(s);
            if v == 0.0 {
                break;
            }
            if v < 0.0 {
                lo = s;
            } else {
                hi = s;
            }
            let newton = s - v / d;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - s).abs() <= 4.0 * f64::EPSILON * n_min {
                s = next;
                break;
            }
            s = next;
        }
        let sin = (s / n_from).min(1.0);
        let along = h.xy() / run;
        Some(Vector3::new(
            sin * along.x,
            sin * along.y,
            (1.0 - sin * sin).sqrt().copysign(h.z),
        ))
    }

    /// Traces the ray leaving `from` along `direction` (any length above 0, in the medium at
    /// `from`) to the height `z_mm`, bending it at every plane between: the point where it
    /// reaches that height and its unit direction there. `None` when the ray runs parallel to
    /// the planes or away from `z_mm`, or is totally internally reflected on the way.
    pub fn trace_to_z(
        &self,
        from: &Vector3<f64>,
        direction: &Vector3<f64>,
        z_mm: f64,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let d = direction.try_normalize(0.0)?;
        if !(d.z != 0.0 && (z_mm - from.z) * d.z >= 0.0) {
            return None;
        }
        let s = self.index_at(from.z) * d.xy().norm();
        let along = if d.xy().norm() > 0.0 {
            d.xy() / d.xy().norm()
        } else {
            Vector2::zeros()
        };
        let runs: Vec<(f64, f64)> = self.runs(from.z, z_mm).collect();
        let mut lateral = 0.0;
        for &(t, n) in &runs {
            if !(s < n) {
                return None;
            }
            lateral += t * s / (n * n - s * s).sqrt();
        }
        // the medium the ray is in when it reaches z_mm: the last one on its way
        let last = if d.z > 0.0 { runs.last() } else { runs.first() };
        let n_end = last.map_or(self.index_at(from.z), |&(_, n)| n);
        let sin = s / n_end;
        if !(sin < 1.0) {
            return None;
        }
        let end = Vector3::new(from.x + lateral * along.x, from.y + lateral * along.y, z_mm);
        let dir = Vector3::new(
            sin * along.x,
            sin * along.y,
            (1.0 - sin * sin).sqrt().copysign(d.z),
        );
        Some((end, dir))
    }
}

impl OpticalLayers {
    /// Where a point appears to a camera in the medium under the lowest plane looking along
    /// the planes' normal: each medium's run above that plane scaled by the camera's medium's
    /// index over its own (the paraxial apparent depth, Hecht Sec. 5.2.3: `d / n` under one
    /// interface). Exact only on the axis; what the straight-ray closed-form and minimal
    /// solvers of PnP take, so that their poses start the refinement through the layers near
    /// the camera's true height rather than too close by the missing bend. Points under the
    /// lowest plane are returned as they are.
    pub fn apparent(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let Some(&z0) = self.planes_z_mm.first() else {
            return *p;
        };
        if !(p.z > z0) {
            return *p;
        }
        let n0 = self.indices[0];
        let z = z0 + self.runs(z0, p.z).map(|(t, n)| t * n0 / n).sum::<f64>();
        Vector3::new(p.x, p.y, z)
    }

    /// Traces the ray leaving `from` along `direction` (in the medium at `from`, under the
    /// planes or inside the first shell) across every plane it meets and, going up, out of
    /// every shell ([`OpticalLayers::trace_shells`]): where it leaves the last interface and
    /// its unit direction in the medium beyond. No interface on its way: `from` and the
    /// direction. `None` when the ray runs parallel to the planes, is totally internally
    /// reflected, or is blocked at a shell's open end.
    pub fn trace_beyond(
        &self,
        from: &Vector3<f64>,
        direction: &Vector3<f64>,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let (o, d) = self.trace_beyond_planes(from, direction)?;
        if self.shells.is_empty() || !(d.z > 0.0) {
            return Some((o, d));
        }
        self.trace_shells(&o, &d, self.shells.len())
    }

    /// [`trace_beyond`](Self::trace_beyond) across the planes only.
    pub fn trace_beyond_planes(
        &self,
        from: &Vector3<f64>,
        direction: &Vector3<f64>,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let d = direction.try_normalize(0.0)?;
        let last = if d.z > 0.0 {
            self.planes_z_mm.iter().rev().find(|&&z| z > from.z)
        } else {
            self.planes_z_mm.iter().find(|&&z| z < from.z)
        };
        let Some(&z) = last else {
            return Some((*from, d));
        };
        let (at, _) = self.trace_to_z(from, &d, z)?;
        let s = self.index_at(from.z) * d.xy().norm();
        let beyond = if d.z > 0.0 {
            self.index_at(z + 1.0)
        } else {
            self.index_at(z)
        };
        let sin = s / beyond;
        if !(sin < 1.0) {
            return None;
        }
        let along = d.xy().try_normalize(0.0).unwrap_or_else(Vector2::zeros);
        Some((
            at,
            Vector3::new(
                sin * along.x,
                sin * along.y,
                (1.0 - sin * sin).sqrt().copysign(d.z),
            ),
        ))
    }
}

/// Two unit vectors across the unit vector `v`, each perpendicular to it and to the other.
fn across(v: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let e1 = v
        .cross(&Vector3::z())
        .try_normalize(1e-9)
        .unwrap_or_else(|| v.cross(&Vector3::x()).normalize());
    (e1, v.cross(&e1))
}

/// How far under the lowest plane [`Imaging::admissible_start`] puts a camera that a start
/// had beyond it, mm.
pub const START_BELOW_PLANE_MM: f64 = 1.0;

/// A camera and the optical path in front of it: what projects a sensor-frame point at a
/// pose. `layers: None` is the straight-ray pinhole or fisheye projection of the camera file
/// alone.
#[derive(Debug, Clone, Copy)]
pub struct Imaging<'a> {
    pub camera: &'a CameraModel,
    pub layers: Option<&'a OpticalLayers>,
}

impl<'a> Imaging<'a> {
    /// [`OpticalLayers::apparent`] of each point, or the points as they are for straight rays.
    pub fn apparent_points(&self, points: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        match self.layers {
            None => points.to_vec(),
            Some(l) => points.iter().map(|p| l.apparent(p)).collect(),
        }
    }

    /// `camera` behind `layers` (`None`: straight rays).
    pub fn new(camera: &'a CameraModel, layers: Option<&'a OpticalLayers>) -> Imaging<'a> {
        Imaging { camera, layers }
    }

    /// The camera file's model with straight rays.
    pub fn straight(camera: &'a CameraModel) -> Imaging<'a> {
        Imaging {
            camera,
            layers: None,
        }
    }

    /// The pixel (px) of the sensor-frame point `p` (mm) seen by the camera at the pose
    /// T_cam_sensor = (`r`, `t`) through the layers: the lens projects the direction in which
    /// the ray that reaches `p` leaves the camera's centre. `None` where the camera model's
    /// field ends.
    #[inline]
    pub fn project(
        &self,
        r: &Matrix3<f64>,
        t: &Vector3<f64>,
        p: &Vector3<f64>,
    ) -> Option<Vector2<f64>> {
        match self.layers {
            None => self.camera.project(&(r * p + t)),
            Some(l) => {
                let centre = -(r.transpose() * t);
                // the model puts the camera in the air under the layers
                if l.planes_z_mm.first().is_some_and(|&z| !(centre.z < z)) {
                    return None;
                }
                let d = l.direction_to(&centre, p)?;
                self.camera.project(&(r * d))
            }
        }
    }

    /// A pose to start a refinement through the layers from: `t` as given when the camera
    /// centre is under the lowest plane, else the centre moved along the sensor's z to
    /// [`START_BELOW_PLANE_MM`] under it (a straight-ray solution puts the camera too close to
    /// what it sees through a denser medium, often beyond the plane, where no ray bends).
    pub fn admissible_start(&self, r: &Matrix3<f64>, t: &Vector3<f64>) -> Vector3<f64> {
        let Some(&z0) = self.layers.and_then(|l| l.planes_z_mm.first()) else {
            return *t;
        };
        let mut centre = -(r.transpose() * t);
        if centre.z < z0 - START_BELOW_PLANE_MM {
            return *t;
        }
        centre.z = z0 - START_BELOW_PLANE_MM;
        -(r * centre)
    }

    /// The pose `(r, t)` with the camera centre moved along the sensor's z the fraction `frac`
    /// (in [0, 1]) of the way up to [`START_BELOW_PLANE_MM`] under the lowest plane: a start
    /// from which the view through a core's open end is wider. `t` as given without planes or
    /// when the centre is already that high.
    pub fn start_nearer_plane(
        &self,
        r: &Matrix3<f64>,
        t: &Vector3<f64>,
        frac: f64,
    ) -> Vector3<f64> {
        let Some(&z0) = self.layers.and_then(|l| l.planes_z_mm.first()) else {
            return *t;
        };
        let mut centre = -(r.transpose() * t);
        let top = z0 - START_BELOW_PLANE_MM;
        if !(centre.z < top) {
            return *t;
        }
        centre.z += frac.clamp(0.0, 1.0) * (top - centre.z);
        -(r * centre)
    }

    /// [`project`](Self::project) and its 2 x 6 Jacobian with respect to the pose, the
    /// rotation perturbed on the left (R <- exp(w) R, w in rad) then t (mm): analytic for
    /// straight rays, central differences through the layers (steps 1e-6 rad and 1e-6 mm,
    /// truncation error of order 1e-12 of the derivative against a root solved to rounding).
    pub fn project_with_jacobian(
        &self,
        r: &Matrix3<f64>,
        t: &Vector3<f64>,
        p: &Vector3<f64>,
    ) -> Option<(Vector2<f64>, Matrix2x6<f64>)> {
        let Some(_) = self.layers else {
            let q = r * p;
            let (uv, j) = self.camera.project_with_jacobian(&(q + t))?;
            // d(pc)/dw = -[q]x, d(pc)/dt = I.
            let jw = j * (-q.cross_matrix());
            let mut out = Matrix2x6::zeros();
            out.fixed_view_mut::<2, 3>(0, 0).copy_from(&jw);
            out.fixed_view_mut::<2, 3>(0, 3).copy_from(&j);
            return Some((uv, out));
        };
        let uv = self.project(r, t, p)?;
        let h = 1e-6;
        let mut out = Matrix2x6::zeros();
        for k in 0..6 {
            let mut e = Vector3::zeros();
            e[k % 3] = h;
            let (plus, minus) = if k < 3 {
                let (rp, rm) = (
                    Rotation3::new(e).matrix() * r,
                    Rotation3::new(-e).matrix() * r,
                );
                (self.project(&rp, t, p)?, self.project(&rm, t, p)?)
            } else {
                (self.project(r, &(t + e), p)?, self.project(r, &(t - e), p)?)
            };
            out.set_column(k, &((plus - minus) / (2.0 * h)));
        }
        Some((uv, out))
    }
}

/// The prior on one plane of an optical path for [`refine_plane`]: the design's height and the
/// materials table's index are the means; these are their standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanePrior {
    /// Which plane (index into [`OpticalLayers::planes_z_mm`]).
    pub plane: usize,
    /// Standard deviation of the plane's height about the given one, mm, > 0.
    pub height_sd_mm: f64,
    /// Standard deviation of the index of the medium above the plane about the given one, > 0.
    pub index_sd: f64,
}

/// How far a poured gel's free surface may sit from where the design puts it, one standard
/// deviation, mm. ASSUMPTION: a hand pour levelled by eye at a tube's mouth, a meniscus of a
/// few tenths of a millimetre.
pub const GEL_SURFACE_HEIGHT_SD_MM: f64 = 0.5;
/// How far a clear silicone's index may be from the materials table's, one standard
/// deviation. ASSUMPTION: clear platinum-cure silicones span about 1.40 to 1.43 at 589 nm.
pub const SILICONE_INDEX_SD: f64 = 0.01;

/// A plane of the optical path refined with the pose ([`refine_plane`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneFit {
    pub t_cam_sensor: nalgebra::Isometry3<f64>,
    /// The layers with the refined height and index.
    pub layers: OpticalLayers,
    pub prior: PlanePrior,
    /// The prior's means: the given height (mm) and index.
    pub prior_height_mm: f64,
    pub prior_index: f64,
    /// The refined height, mm, and its standard deviation (data and prior together).
    pub height_mm: f64,
    pub height_sd_mm: f64,
    /// The refined index above the plane and its standard deviation.
    pub index: f64,
    pub index_sd: f64,
    /// Pixel noise per coordinate estimated from the residuals, px.
    pub sigma_px: f64,
    /// RMS reprojection error over the pairs, px.
    pub rms_px: f64,
}

/// Refines the pose together with the height of one plane of `layers` and the index above it,
/// from sensor-frame points (N, mm) and their pixels (N, px), starting at `start`: maximum a
/// posteriori under Gaussian pixel noise and the Gaussian `prior` (Levenberg-Marquardt on the
/// reprojection errors over the noise and the prior's two terms; the noise from the residuals,
/// sqrt(sum e^2 / (2N - 6)), fitted again once at it). The standard deviations are the square
/// roots of the diagonal of the inverse normal matrix at the solution (Hartley & Zisserman,
/// Multiple View Geometry, 2nd ed., Sec. 5.2): below the prior's where the captures say more
/// than it. `None` when a point does not project at the start or the normal matrix is singular.
pub fn refine_plane(
    camera: &CameraModel,
    layers: &OpticalLayers,
    prior: PlanePrior,
    points_mm: &[Vector3<f64>],
    pixels_px: &[Vector2<f64>],
    start: &nalgebra::Isometry3<f64>,
) -> Option<PlaneFit> {
    use nalgebra::{DMatrix, DVector, UnitQuaternion};
    let k = prior.plane;
    let (z0, n0) = (*layers.planes_z_mm.get(k)?, *layers.indices.get(k + 1)?);
    let n = points_mm.len();
    // state: rotation, translation, height, index
    #[derive(Clone)]
    struct S {
        r: Matrix3<f64>,
        t: Vector3<f64>,
        z: f64,
        idx: f64,
    }
    let with = |s: &S| {
        let mut l = layers.clone();
        l.planes_z_mm[k] = s.z;
        l.indices[k + 1] = s.idx;
        OpticalLayers::new(l.planes_z_mm, l.indices)
            .ok()?
            .with_shells(layers.shells.clone())
            .ok()
    };
    let residuals = |s: &S, sigma: f64| -> Option<DVector<f64>> {
        let l = with(s)?;
        let im = Imaging::new(camera, Some(&l));
        let mut e = DVector::zeros(2 * n + 2);
        for (i, (p, q)) in points_mm.iter().zip(pixels_px).enumerate() {
            let d = im.project(&s.r, &s.t, p)? - q;
            e[2 * i] = d.x / sigma;
            e[2 * i + 1] = d.y / sigma;
        }
        e[2 * n] = (s.z - z0) / prior.height_sd_mm;
        e[2 * n + 1] = (s.idx - n0) / prior.index_sd;
        Some(e)
    };
    let step = |s: &S, d: &[f64]| S {
        r: Rotation3::new(Vector3::new(d[0], d[1], d[2])).matrix() * s.r,
        t: s.t + Vector3::new(d[3], d[4], d[5]),
        z: s.z + d[6],
        idx: s.idx + d[7],
    };
    let jacobian = |s: &S, sigma: f64| -> Option<DMatrix<f64>> {
        let mut j = DMatrix::zeros(2 * n + 2, 8);
        for c in 0..8 {
            let h = match c {
                0..=2 => 1e-7,
                7 => 1e-7,
                _ => 1e-6,
            };
            let mut d = [0.0; 8];
            d[c] = h;
            let plus = residuals(&step(s, &d), sigma)?;
            d[c] = -h;
            let minus = residuals(&step(s, &d), sigma)?;
            j.set_column(c, &((plus - minus) / (2.0 * h)));
        }
        Some(j)
    };
    let mut s = S {
        r: *start.rotation.to_rotation_matrix().matrix(),
        t: start.translation.vector,
        z: z0,
        idx: n0,
    };
    let pixel_cost = |s: &S| -> Option<f64> {
        let e = residuals(s, 1.0)?;
        Some(e.rows(0, 2 * n).norm_squared())
    };
    let dof = (2 * n).saturating_sub(6).max(1) as f64;
    let mut sigma = (pixel_cost(&s)? / dof).sqrt().max(1e-3);
    for _pass in 0..2 {
        let mut lambda = 1e-4;
        let mut e = residuals(&s, sigma)?;
        for _ in 0..100 {
            let j = jacobian(&s, sigma)?;
            let jtj = j.transpose() * &j;
            let g = j.transpose() * &e;
            let mut a = jtj.clone();
            for c in 0..8 {
                a[(c, c)] += lambda * jtj[(c, c)].max(1e-12);
            }
            let Some(ch) = a.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let d = ch.solve(&(-&g));
            let s1 = step(&s, d.as_slice());
            match residuals(&s1, sigma) {
                Some(e1) if e1.norm_squared() <= e.norm_squared() => {
                    let done =
                        e.norm_squared() - e1.norm_squared() <= 1e-12 * e.norm_squared().max(1e-30);
                    (s, e) = (s1, e1);
                    lambda = (lambda * 0.1).max(1e-12);
                    if done {
                        break;
                    }
                }
                _ => {
                    lambda *= 10.0;
                    if lambda > 1e10 {
                        break;
                    }
                }
            }
        }
        sigma = (pixel_cost(&s)? / dof).sqrt().max(1e-3);
    }
    let j = jacobian(&s, sigma)?;
    let cov = (j.transpose() * &j).try_inverse()?;
    let (var_z, var_n) = (cov[(6, 6)], cov[(7, 7)]);
    if !(var_z >= 0.0 && var_n >= 0.0) {
        return None;
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(s.r));
    let layers = with(&s)?;
    Some(PlaneFit {
        t_cam_sensor: nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::from(s.t),
            UnitQuaternion::new_normalize(rot.into_inner()),
        ),
        layers,
        prior,
        prior_height_mm: z0,
        prior_index: n0,
        height_mm: s.z,
        height_sd_mm: var_z.sqrt(),
        index: s.idx,
        index_sd: var_n.sqrt(),
        sigma_px: sigma,
        rms_px: (pixel_cost(&s)? / n as f64).sqrt(),
    })
}
