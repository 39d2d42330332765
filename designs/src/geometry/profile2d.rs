//! 2D profile polylines in the (r, z) half-plane and their tessellation by chord tolerance.

use super::ChordTolerance;

/// A polyline in the (r, z) half-plane, mm. As a profile to revolve it is closed implicitly
/// (last point joins the first).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Polyline2 {
    pub points: Vec<[f64; 2]>,
}

impl Polyline2 {
    /// Appends `p` unless it repeats the last point.
    pub fn push(&mut self, p: [f64; 2]) {
        if self.points.last() != Some(&p) {
            self.points.push(p);
        }
    }

    /// Appends the points of `other` in order (skipping a repeated joint).
    pub fn extend(&mut self, other: &Polyline2) {
        for &p in &other.points {
            self.push(p);
        }
    }

    /// The same points in reverse order.
    pub fn reversed(&self) -> Polyline2 {
        let mut points = self.points.clone();
        points.reverse();
        Polyline2 { points }
    }
}

/// Appends a circular arc about `center` of radius `radius` from angle `a0` to `a1` (radians,
/// measured from the +r axis towards +z), endpoints included, with uniform segments whose
/// sagitta is within `tol.facet_mm()`.
pub fn push_arc(
    pl: &mut Polyline2,
    center: [f64; 2],
    radius: f64,
    a0: f64,
    a1: f64,
    tol: ChordTolerance,
) {
    let sweep = (a1 - a0).abs();
    let n_full = tol.circle_segments(radius) as f64;
    let n = ((sweep / (2.0 * std::f64::consts::PI) * n_full).ceil() as usize).max(1);
    for i in 0..=n {
        let a = if i == n {
            a1
        } else {
            a0 + (a1 - a0) * i as f64 / n as f64
        };
        let (s, c) = a.sin_cos();
        let mut p = [center[0] + radius * c, center[1] + radius * s];
        // Points meant to be on the axis land there exactly.
        if p[0].abs() < 1e-12 {
            p[0] = 0.0;
        }
        pl.push(p);
    }
}

/// Appends the curve `f(t)` for t in [t0, t1], endpoints included, bisecting parameter intervals
/// until every sampled point of a sub-curve is within `tol.facet_mm()` of its chord.
/// Deterministic.
///
/// `f` must be smooth on the interval; the check samples 8 interior points per chord, which
/// bounds the error for curves whose curvature varies slowly across one chord (all the
/// profiles here: arcs, ellipses and their offsets).
pub fn push_curve(
    pl: &mut Polyline2,
    f: &dyn Fn(f64) -> [f64; 2],
    t0: f64,
    t1: f64,
    tol: ChordTolerance,
) {
    fn rec(
        pl: &mut Polyline2,
        f: &dyn Fn(f64) -> [f64; 2],
        t0: f64,
        t1: f64,
        tol: f64,
        depth: u32,
    ) {
        let (a, b) = (f(t0), f(t1));
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let mut worst: f64 = 0.0;
        for i in 1..8 {
            let p = f(t0 + (t1 - t0) * i as f64 / 8.0);
            let dist = if len > 0.0 {
                ((p[0] - a[0]) * d[1] - (p[1] - a[1]) * d[0]).abs() / len
            } else {
                ((p[0] - a[0]).powi(2) + (p[1] - a[1]).powi(2)).sqrt()
            };
            worst = worst.max(dist);
        }
        if worst <= tol || depth >= 30 {
            pl.push(b);
        } else {
            let tm = 0.5 * (t0 + t1);
            rec(pl, f, t0, tm, tol, depth + 1);
            rec(pl, f, tm, t1, tol, depth + 1);
        }
    }
    let mut a = f(t0);
    if a[0].abs() < 1e-12 {
        a[0] = 0.0;
    }
    pl.push(a);
    // Start from 4 intervals so that a symmetric curve never looks straight to the sampler.
    for i in 0..4 {
        let s0 = t0 + (t1 - t0) * i as f64 / 4.0;
        let s1 = t0 + (t1 - t0) * (i + 1) as f64 / 4.0;
        rec(pl, f, s0, s1, tol.facet_mm(), 0);
    }
}

/// Largest distance from any point of the curve `f` on [t0, t1] (densely sampled) to the
/// polyline `pl`; used by tests to verify tessellations.
pub fn max_deviation(
    pl: &Polyline2,
    f: &dyn Fn(f64) -> [f64; 2],
    t0: f64,
    t1: f64,
    samples: usize,
) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..=samples {
        let p = f(t0 + (t1 - t0) * i as f64 / samples as f64);
        let mut best = f64::INFINITY;
        for w in pl.points.windows(2) {
            best = best.min(point_segment_distance(p, w[0], w[1]));
        }
        worst = worst.max(best);
    }
    worst
}

/// Distance from `p` to the segment `a`-`b`.
pub fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
    (q[0] * q[0] + q[1] * q[1]).sqrt()
}
