//! SQPnP on bearing vectors: the globally optimal PnP of Terzakis and Lourakis, "A Consistently
//! Fast and Globally Optimal Solution to the Perspective-n-Point Problem", ECCV 2020.
//!
//! The object-space cost `sum |(I - b b^T)(R M + t)|^2` is written with unit bearings `b`
//! (not points on the z = 1 plane), so rays beyond 90 deg off axis from a fisheye lens work.
//! `t` is eliminated in closed form, leaving `r^T Omega r` over `r = vec(R)` (row-major); SQP runs
//! from the nearest rotations to the eigenvectors of the smallest eigenvalues of `Omega`.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

type M9 = SMatrix<f64, 9, 9>;
type V9 = SVector<f64, 9>;
type M39 = SMatrix<f64, 3, 9>;

/// A pose with its object-space cost.
#[derive(Debug, Clone, Copy)]
pub struct SqpnpPose {
    /// Rotation of T_cam_sensor.
    pub rotation: Matrix3<f64>,
    /// Translation of T_cam_sensor, mm.
    pub translation_mm: Vector3<f64>,
    /// `r^T Omega r`, mm^2.
    pub cost: f64,
}

/// Globally optimal pose minimising the object-space error of `points_mm` (sensor frame) on the
/// rays `bearings` (unit vectors, camera frame). Needs at least 3 points; returns `None` when the
/// layout is degenerate (all rays parallel) or no solution puts the points in front of the rays.
pub fn sqpnp(points_mm: &[Vector3<f64>], bearings: &[Vector3<f64>]) -> Option<SqpnpPose> {
    let n = points_mm.len();
    if n < 3 || bearings.len() != n {
        return None;
    }
    // Centre the points for conditioning: R M + t = R (M - c) + (t + R c).
    let c = points_mm.iter().sum::<Vector3<f64>>() / n as f64;
    let mut qs = Matrix3::zeros();
    let mut s = M39::zeros();
    let mut omega = M9::zeros();
    for (m0, b) in points_mm.iter().zip(bearings) {
        let m = m0 - c;
        let q = Matrix3::identity() - b * b.transpose() / b.norm_squared();
        qs += q;
        // S[j, 3k + l] += Q[j, k] M[l]
        for j in 0..3 {
            for k in 0..3 {
                for l in 0..3 {
                    s[(j, 3 * k + l)] += q[(j, k)] * m[l];
                }
            }
        }
        // A^T Q A: block (j, k) = Q[j, k] M M^T (upper blocks; mirrored below).
        let mm = m * m.transpose();
        for j in 0..3 {
            for k in j..3 {
                let qjk = q[(j, k)];
                for a in 0..3 {
                    for bb in 0..3 {
                        omega[(3 * j + a, 3 * k + bb)] += qjk * mm[(a, bb)];
                    }
                }
            }
        }
    }
    for j in 0..3 {
        for k in 0..j {
            for a in 0..3 {
                for bb in 0..3 {
                    omega[(3 * j + a, 3 * k + bb)] = omega[(3 * k + bb, 3 * j + a)];
                }
            }
        }
    }
    let qs_inv = qs.try_inverse()?;
    let p: M39 = -(qs_inv * s); // t = P r
    omega += s.transpose() * p;
    omega = (omega + omega.transpose()) * 0.5;

    // Eigenvalues to 1e-12 relative are plenty for choosing the start points (SQP and the
    // reprojection refinement polish the result).
    let eps = 1e-12 * omega.amax().max(1e-300);
    let eig =
        nalgebra::SymmetricEigen::try_new(omega, eps, 0).unwrap_or_else(|| omega.symmetric_eigen());
    let mut order: [usize; 9] = [0, 1, 2, 3, 4, 5, 6, 7, 8];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let ev = |i: usize| eig.eigenvalues[order[i]];
    let vec = |i: usize| -> V9 { eig.eigenvectors.column(order[i]).into_owned() };

    let null_tol = 1e-7 * ev(8).abs().max(1e-300);
    let n_null = (0..9).take_while(|&i| ev(i) < null_tol).count().clamp(1, 9);

    let mut best: Option<SqpnpPose> = None;
    let consider = |r: V9, best: &mut Option<SqpnpPose>| {
        let t = p * r;
        let cost = (r.transpose() * omega * r)[0];
        let rot = Matrix3::new(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8]);
        // In front of the rays: most points have b . (R M + t) > 0.
        let front = points_mm
            .iter()
            .zip(bearings)
            .filter(|(m, b)| b.dot(&(rot * (*m - c) + t)) > 0.0)
            .count();
        if 2 * front <= n {
            return;
        }
        if best.is_none_or(|bst| cost < bst.cost) {
            *best = Some(SqpnpPose {
                rotation: rot,
                translation_mm: t - rot * c,
                cost,
            });
        }
    };
    let sqrt3 = 3f64.sqrt();
    let try_index = |i: usize, best: &mut Option<SqpnpPose>| {
        let e = vec(i) * sqrt3;
        let em = Matrix3::new(e[0], e[1], e[2], e[3], e[4], e[5], e[6], e[7], e[8]);
        let orth_err = (em * em.transpose() - Matrix3::identity()).norm_squared();
        if orth_err < 1e-8 {
            let r = if em.determinant() < 0.0 { -e } else { e };
            consider(r, best);
        } else {
            // r and -r give mirrored poses (t = P r flips too): the depths b . (R M + t) change
            // sign exactly, so only the sign that puts most points in front of their rays can
            // lead to a valid solution. Run SQP from that one.
            let t = p * e;
            let ahead: f64 = points_mm
                .iter()
                .zip(bearings)
                .map(|(m, b)| b.dot(&(em * (*m - c) + t)).signum())
                .sum();
            let sign = if ahead >= 0.0 { 1.0 } else { -1.0 };
            let r0 = nearest_rotation(&(em * sign));
            consider(run_sqp(&omega, r0), best);
        }
    };
    for i in 0..n_null {
        try_index(i, &mut best);
    }
    let mut i = n_null;
    while i < 9 && best.is_none_or(|b| b.cost > 3.0 * ev(i)) {
        try_index(i, &mut best);
        i += 1;
    }
    best
}

fn to_v9(m: &Matrix3<f64>) -> V9 {
    V9::from_row_slice(&[
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
    ])
}

/// The rotation nearest to `m` in the Frobenius norm (SVD, determinant fixed to +1).
pub fn nearest_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Matrix3::identity();
    };
    let mut r = u * vt;
    if r.determinant() < 0.0 {
        let mut d = Matrix3::identity();
        d[(2, 2)] = -1.0;
        r = u * d * vt;
    }
    r
}

/// SQP iterations on `min r^T Omega r` subject to R R^T = I, from the rotation `r0`.
///
/// SQPnP's SQP step ignores the curvature of the constraints, so it converges only linearly when
/// the cost at the optimum is large (outliers among the points). Once the steps are small it
/// hands over to Newton's method on the rotation manifold, which converges quadratically.
fn run_sqp(omega: &M9, r0: Matrix3<f64>) -> V9 {
    let mut r = to_v9(&r0);
    let mut polish = false;
    for _ in 0..15 {
        let delta = sqp_step(omega, &r);
        r += delta;
        let d2 = delta.norm_squared();
        if d2 < 1e-10 {
            break;
        }
        if d2 < 1e-4 {
            polish = true;
            break;
        }
    }
    let rm = Matrix3::new(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8]);
    let mut det = rm.determinant();
    let mut rm = rm;
    if det < 0.0 {
        rm = -rm;
        det = -det;
    }
    if det > 1.001 || (rm * rm.transpose() - Matrix3::identity()).norm_squared() > 1e-12 {
        rm = nearest_rotation(&rm);
    }
    if polish {
        for _ in 0..8 {
            match newton_step(omega, &rm) {
                Some(w) => {
                    rm = *nalgebra::Rotation3::new(w).matrix() * rm;
                    if w.norm_squared() < 1e-16 {
                        break;
                    }
                }
                None => break,
            }
        }
    }
    to_v9(&rm)
}

/// Newton step of `f(R) = vec(R)^T Omega vec(R)` over left increments `R <- exp([w]x) R`:
/// with `A = d vec / dw` (9 x 3, columns `vec([e_k]x R)`) and `G = mat(Omega vec(R))`, the
/// gradient is `2 A^T Omega r` and the Hessian `2 A^T Omega A + 2 (sym(R G^T) - tr(G^T R) I)`
/// (the second term from `[w]x^2 = w w^T - |w|^2 I`). `None` when the Hessian is not positive
/// definite (then the SQP result stands).
fn newton_step(omega: &M9, rm: &Matrix3<f64>) -> Option<Vector3<f64>> {
    let r = to_v9(rm);
    let or = omega * r;
    let mut a = SMatrix::<f64, 9, 3>::zeros();
    for k in 0..3 {
        let mut e = Vector3::zeros();
        e[k] = 1.0;
        a.set_column(k, &to_v9(&(e.cross_matrix() * rm)));
    }
    let g = a.transpose() * or;
    let gm = Matrix3::new(
        or[0], or[1], or[2], or[3], or[4], or[5], or[6], or[7], or[8],
    );
    let rg = rm * gm.transpose();
    let s = (rg + rg.transpose()) * 0.5 - Matrix3::identity() * (gm.transpose() * rm).trace();
    let h = a.transpose() * omega * a + s;
    h.cholesky().map(|c| -c.solve(&g))
}

/// One SQP step: delta = H x + N y with H an orthonormal basis of the constraint gradients
/// (Gram-Schmidt, so `G = H T` with T upper triangular) and N of their complement.
fn sqp_step(omega: &M9, r: &V9) -> V9 {
    let r1 = Vector3::new(r[0], r[1], r[2]);
    let r2 = Vector3::new(r[3], r[4], r[5]);
    let r3 = Vector3::new(r[6], r[7], r[8]);
    let z = Vector3::zeros();
    let cat = |a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>| {
        V9::from_row_slice(&[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z])
    };
    // Constraint values h (want 0) and gradients.
    let h = [
        r1.norm_squared() - 1.0,
        r2.norm_squared() - 1.0,
        r3.norm_squared() - 1.0,
        r1.dot(&r2),
        r1.dot(&r3),
        r2.dot(&r3),
    ];
    let g = [
        cat(&(2.0 * r1), &z, &z),
        cat(&z, &(2.0 * r2), &z),
        cat(&z, &z, &(2.0 * r3)),
        cat(&r2, &r1, &z),
        cat(&r3, &z, &r1),
        cat(&z, &r3, &r2),
    ];
    // Gram-Schmidt: q_i orthonormal, g_i = sum_{j<=i} t[j][i] q_j.
    let mut q = [V9::zeros(); 9];
    let mut t = [[0.0f64; 6]; 6];
    for i in 0..6 {
        let mut v = g[i];
        for j in 0..i {
            t[j][i] = q[j].dot(&g[i]);
            v -= q[j] * t[j][i];
        }
        t[i][i] = v.norm();
        if t[i][i] < 1e-12 {
            return V9::zeros();
        }
        q[i] = v / t[i][i];
    }
    // Null space: tangent directions vec(S_k R), orthogonalised.
    let rm = Matrix3::new(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8]);
    for k in 0..3 {
        let mut w = Vector3::zeros();
        w[k] = 1.0;
        let mut v = to_v9(&(w.cross_matrix() * rm));
        for j in 0..(6 + k) {
            v -= q[j] * q[j].dot(&v);
        }
        let nv = v.norm();
        if nv < 1e-12 {
            return V9::zeros();
        }
        q[6 + k] = v / nv;
    }
    // G^T delta = -h, G^T H = T^T (lower triangular): forward substitution for x.
    let mut x = [0.0f64; 6];
    for i in 0..6 {
        let mut acc = -h[i];
        for j in 0..i {
            acc -= t[j][i] * x[j];
        }
        x[i] = acc / t[i][i];
    }
    let mut delta = V9::zeros();
    for i in 0..6 {
        delta += q[i] * x[i];
    }
    // y minimises (r + delta + N y)^T Omega (r + delta + N y).
    let nm = SMatrix::<f64, 9, 3>::from_columns(&[q[6], q[7], q[8]]);
    let ont = omega * nm;
    let w = nm.transpose() * ont;
    let rhs = -(ont.transpose() * (r + delta));
    if let Some(y) = w.cholesky().map(|c| c.solve(&rhs)) {
        delta += nm * y;
    }
    delta
}
