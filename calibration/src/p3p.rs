//! Minimal P3P solver for RANSAC hypotheses: Grunert's formulation (Haralick et al., "Review and
//! analysis of solutions of the three point perspective pose estimation problem", IJCV 1994),
//! with the quartic's coefficients built by polynomial arithmetic from the law-of-cosines system,
//! on unit bearings (rays beyond 90 deg off axis work).

use nalgebra::{Matrix3, Vector3};

/// Up to four poses (R, t) with `s_i b_i = R P_i + t`, `s_i > 0`, for three sensor-frame points
/// `p` (mm) seen along the unit bearings `b`.
pub fn p3p(
    p: &[Vector3<f64>; 3],
    b: &[Vector3<f64>; 3],
    out: &mut Vec<(Matrix3<f64>, Vector3<f64>)>,
) {
    out.clear();
    let a2 = (p[1] - p[2]).norm_squared();
    let b2 = (p[0] - p[2]).norm_squared();
    let c2 = (p[0] - p[1]).norm_squared();
    if a2 < 1e-18 || b2 < 1e-18 || c2 < 1e-18 {
        return;
    }
    let ca = b[1].dot(&b[2]);
    let cb = b[0].dot(&b[2]);
    let cg = b[0].dot(&b[1]);
    let k = (a2 - c2) / b2;
    let cc = c2 / b2;
    // u = N(v) / D(v); (1 + u^2 - 2 u cg) = cc (1 + v^2 - 2 v cb) times D^2.
    let nn = [1.0 + k, -2.0 * k * cb, k - 1.0]; // ascending powers of v
    let dd = [2.0 * cg, -2.0 * ca];
    let d2 = mul(&dd, &dd);
    let n2 = mul(&nn, &nn);
    let nd = mul(&nn, &dd);
    let e = [1.0, -2.0 * cb, 1.0];
    let ed2 = mul(&e, &d2);
    let mut poly = [0.0f64; 5];
    for i in 0..5 {
        let g = |v: &[f64]| v.get(i).copied().unwrap_or(0.0);
        poly[i] = g(&d2) + g(&n2) - 2.0 * cg * g(&nd) - cc * g(&ed2);
    }
    let mut roots = [0.0f64; 4];
    let nr = quartic_roots(&poly, &mut roots);
    for &v in &roots[..nr] {
        if !(v > 0.0) {
            continue;
        }
        let dv = dd[0] + dd[1] * v;
        if dv.abs() < 1e-14 {
            continue;
        }
        let u = (nn[0] + nn[1] * v + nn[2] * v * v) / dv;
        let q = 1.0 + v * v - 2.0 * v * cb;
        if !(u > 0.0) || !(q > 0.0) {
            continue;
        }
        let s1 = (b2 / q).sqrt();
        let x = [b[0] * s1, b[1] * (u * s1), b[2] * (v * s1)];
        let (Some(fw), Some(fc)) = (frame(p), frame(&x)) else {
            continue;
        };
        let r = fc * fw.transpose();
        out.push((r, x[0] - r * p[0]));
    }
}

/// Orthonormal frame of a triangle: columns e1 along P1P2, e3 normal, e2 = e3 x e1.
fn frame(p: &[Vector3<f64>; 3]) -> Option<Matrix3<f64>> {
    let e1 = (p[1] - p[0]).try_normalize(1e-15)?;
    let e3 = e1.cross(&(p[2] - p[0])).try_normalize(1e-15)?;
    let e2 = e3.cross(&e1);
    Some(Matrix3::from_columns(&[e1, e2, e3]))
}

fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            r[i + j] += x * y;
        }
    }
    r
}

/// Real roots of `c[0] + c[1] x + ... + c[4] x^4` (Ferrari, polished by Newton); the count.
pub(crate) fn quartic_roots(c: &[f64; 5], out: &mut [f64; 4]) -> usize {
    let ev = |x: f64| (((c[4] * x + c[3]) * x + c[2]) * x + c[1]) * x + c[0];
    let dev = |x: f64| ((4.0 * c[4] * x + 3.0 * c[3]) * x + 2.0 * c[2]) * x + c[1];
    let scale = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0) || c[4].abs() < 1e-12 * scale {
        return 0;
    }
    let (b, cc, d, e) = (c[3] / c[4], c[2] / c[4], c[1] / c[4], c[0] / c[4]);
    let p = cc - 3.0 * b * b / 8.0;
    let q = d - b * cc / 2.0 + b * b * b / 8.0;
    let r = e - b * d / 4.0 + b * b * cc / 16.0 - 3.0 * b.powi(4) / 256.0;
    let mut ys = [0.0f64; 4];
    let mut n = 0;
    let quad = |a1: f64, a0: f64, ys: &mut [f64; 4], n: &mut usize| {
        let disc = a1 * a1 - 4.0 * a0;
        if disc >= 0.0 {
            let s = disc.sqrt();
            ys[*n] = (-a1 + s) / 2.0;
            ys[*n + 1] = (-a1 - s) / 2.0;
            *n += 2;
        }
    };
    if q.abs() < 1e-14 * (1.0 + p.abs() + r.abs()) {
        // Biquadratic: y^2 = z, z^2 + p z + r = 0.
        let disc = p * p - 4.0 * r;
        if disc >= 0.0 {
            for z in [(-p + disc.sqrt()) / 2.0, (-p - disc.sqrt()) / 2.0] {
                if z >= 0.0 {
                    ys[n] = z.sqrt();
                    ys[n + 1] = -z.sqrt();
                    n += 2;
                }
            }
        }
    } else {
        // Resolvent cubic 8 m^3 + 8 p m^2 + (2 p^2 - 8 r) m - q^2 = 0 has a root m > 0.
        let m = cubic_positive_root(p, (p * p - 4.0 * r) / 4.0, -q * q / 8.0);
        let s = (2.0 * m).sqrt();
        if s > 0.0 {
            let h = q / (2.0 * s);
            quad(-s, p / 2.0 + m + h, &mut ys, &mut n);
            quad(s, p / 2.0 + m - h, &mut ys, &mut n);
        }
    }
    let mut k = 0;
    for &y in &ys[..n] {
        let mut x = y - b / 4.0;
        for _ in 0..3 {
            let dx = dev(x);
            if dx.abs() > 1e-300 {
                x -= ev(x) / dx;
            }
        }
        if x.is_finite() {
            out[k] = x;
            k += 1;
        }
    }
    k
}

/// The largest real root of m^3 + a m^2 + b m + c (c <= 0, so a root m >= 0 exists).
fn cubic_positive_root(a: f64, b: f64, c: f64) -> f64 {
    let f = |m: f64| ((m + a) * m + b) * m + c;
    let df = |m: f64| (3.0 * m + 2.0 * a) * m + b;
    // Cardano on the depressed cubic.
    let p = b - a * a / 3.0;
    let q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
    let disc = q * q / 4.0 + p * p * p / 27.0;
    let mut m = if disc >= 0.0 {
        let s = disc.sqrt();
        (-q / 2.0 + s).cbrt() + (-q / 2.0 - s).cbrt() - a / 3.0
    } else {
        let r = (-p / 3.0).sqrt();
        let phi = (-q / (2.0 * r * r * r)).clamp(-1.0, 1.0).acos();
        2.0 * r * (phi / 3.0).cos() - a / 3.0
    };
    for _ in 0..3 {
        let d = df(m);
        if d.abs() > 1e-300 {
            m -= f(m) / d;
        }
    }
    m.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn p3p_recovers_a_noise_free_pose_among_its_solutions() {
        let r = *Rotation3::from_scaled_axis(Vector3::new(0.1, -0.2, 0.3)).matrix();
        let t = Vector3::new(0.5, -0.3, 10.0);
        let p = [
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(-4.0, 1.0, 6.0),
            Vector3::new(2.0, -5.0, 4.0),
        ];
        let b = [0, 1, 2].map(|i| (r * p[i] + t).normalize());
        let mut out = Vec::new();
        p3p(&p, &b, &mut out);
        assert!(!out.is_empty());
        let best = out
            .iter()
            .map(|(r1, t1)| (r1 - r).norm() + (t1 - t).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(best < 1e-8, "best {best}, solutions {out:?}");
    }

    #[test]
    fn quartic_roots_are_found() {
        // (x - 1)(x + 2)(x - 3)(x - 0.5) = x^4 - 2.5x^3 - 4x^2 + 8.5x - 3
        let mut out = [0.0; 4];
        let n = quartic_roots(&[-3.0, 8.5, -4.0, -2.5, 1.0], &mut out);
        let mut r = out[..n].to_vec();
        r.sort_by(f64::total_cmp);
        assert_eq!(n, 4);
        for (a, b) in r.iter().zip([-2.0, 0.5, 1.0, 3.0]) {
            assert!((a - b).abs() < 1e-10, "{r:?}");
        }
    }
}
