//! Transforms of space: [`Affine`] (nalgebra's `Affine3<f64>`, p' = R p + t) for every map a
//! solid, a primitive or a pose goes through, built from the columns of R and t, and its JSON
//! form: the 3 x 4 rows `[[R00, R01, R02, t0], ...]` that a part's `params.T_print_sensor`, an
//! indenter's `T_print_indenter` and a CSG tree's `transform` nodes record
//! (`docs/conventions.md`).

use nalgebra::{Matrix3, Matrix4, Vector3};

/// An affine map of space, p' = R p + t (mm).
pub type Affine = nalgebra::Affine3<f64>;

/// The map whose linear part has columns `x`, `y`, `z` and whose translation is `t`: the
/// frame with axes `x`, `y`, `z` at origin `t`, in the coordinates of the frame it is given in.
pub fn from_columns(x: [f64; 3], y: [f64; 3], z: [f64; 3], t: [f64; 3]) -> Affine {
    let r = Matrix3::from_columns(&[Vector3::from(x), Vector3::from(y), Vector3::from(z)]);
    with_translation(&r, t)
}

/// The map p -> r p + t.
pub fn with_translation(r: &Matrix3<f64>, t: [f64; 3]) -> Affine {
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&Vector3::from(t));
    Affine::from_matrix_unchecked(m)
}

/// The translation by `d` mm.
pub fn translation(d: [f64; 3]) -> Affine {
    with_translation(&Matrix3::identity(), d)
}

/// The three rows `[R_i0, R_i1, R_i2, t_i]` of `a` (its JSON form).
pub fn rows(a: &Affine) -> Vec<[f64; 4]> {
    let m = a.matrix();
    (0..3).map(|r| std::array::from_fn(|c| m[(r, c)])).collect()
}

/// `a` as its JSON rows.
pub fn to_json(a: &Affine) -> serde_json::Value {
    serde_json::json!(rows(a))
}

/// The map of JSON rows (three rows of four numbers; the homogeneous matrix's last row is
/// (0, 0, 0, 1)); `None` for anything else.
pub fn from_json(v: &serde_json::Value) -> Option<Affine> {
    let rows = <Vec<[f64; 4]> as serde::Deserialize>::deserialize(v).ok()?;
    if rows.len() != 3 {
        return None;
    }
    let mut m = Matrix4::identity();
    for (r, row) in rows.iter().enumerate() {
        for (c, x) in row.iter().enumerate() {
            m[(r, c)] = *x;
        }
    }
    Some(Affine::from_matrix_unchecked(m))
}
