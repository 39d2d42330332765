//! The solid of one marker feature (a radial cylinder with a hemispherical end), grown or
//! shrunk by a coat, how deep it reaches into the body, and the frame that stands it on the
//! surface.

use super::spec::FeatureShape;
use crate::geometry::profile2d::push_arc;
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use std::f64::consts::{FRAC_PI_2, PI};

/// How deep a feature reaches behind the surface so that it joins the body without a gap:
/// the sagitta of its base disc on the most curved direction, plus the chord tolerance, plus
/// a margin.
pub fn embed_depth_mm(shape: &FeatureShape, max_curvature: f64, tol: ChordTolerance) -> f64 {
    let r = shape.radius_mm();
    r * r * max_curvature.abs() + 2.0 * tol.mm() + 0.02
}

/// The solid of one feature along `dir` (unit) from `position`: from `embed_mm` behind the
/// surface to `height_mm` beyond it. Built as a revolve about its own axis.
///
/// # Errors
/// Only on a kernel failure.
pub fn feature_solid(
    shape: &FeatureShape,
    position: [f64; 3],
    dir: [f64; 3],
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    Ok(local_feature(shape, embed_mm, tol)?.transform(&frame_to(position, dir)))
}

/// The feature in its own frame: axis +z, the surface point at the origin.
///
/// # Errors
/// Only on a kernel failure.
pub fn local_feature(
    shape: &FeatureShape,
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    local_feature_dilated(shape, 0.0, embed_mm, tol)
}

/// The feature of `shape` grown by `dilation_mm` all round (its Minkowski sum with a ball,
/// the rounding of its rim left out), seen from the offset surface `dilation_mm` beyond the
/// one that carries it: what a coat of that thickness, sprayed into the mold so that it
/// follows the cavity, needs from the cavity so that the layer under it gets `shape`. Its own
/// frame: axis +z along the feature, the point on the offset surface at the origin. The
/// radius becomes r + t and the hemisphere's centre moves t closer to the new surface; the
/// height from the new surface stays `height_mm` (the coat offsets both the surface and the
/// feature's end). For a recessed feature give `dilation_mm` < 0: the former shrinks by the
/// coat (r - t), its centre moves t deeper. 0 gives [`local_feature`]. Sources: the coat as
/// a conformal film of uniform thickness (the model of a sprayed coat, Sec. III-B1 of the
/// R-Tac0 paper: sprayed into the mold, it takes the cavity's shape).
///
/// # Errors
/// Only on a kernel failure.
pub fn local_feature_dilated(
    shape: &FeatureShape,
    dilation_mm: f64,
    embed_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let r = shape.radius_mm() + dilation_mm;
    let hc = shape.height_mm - shape.radius_mm() - dilation_mm;
    let embed_mm = embed_mm.max(-hc + tol.mm());
    let mut pl = Polyline2::default();
    pl.push([0.0, -embed_mm]);
    pl.push([r, -embed_mm]);
    push_arc(&mut pl, [0.0, hc], r, 0.0, FRAC_PI_2, tol.half());
    Solid::from_mesh(&revolve(&pl, tol)?)
}

/// The affine map taking the local +z axis at the origin to `dir` at `position`.
pub fn frame_to(position: [f64; 3], dir: [f64; 3]) -> crate::geometry::Affine {
    use nalgebra::Vector3;
    let z = Vector3::from(dir);
    // any vector not parallel to z
    let helper = if z[2].abs() < 0.9 {
        Vector3::z()
    } else {
        Vector3::x()
    };
    let x = helper.cross(&z).normalize();
    let y = z.cross(&x);
    crate::geometry::transform::from_columns(x.into(), y.into(), dir, position)
}

/// Volume of the gap between the tangent plane and the surface over the feature's base disc,
/// mm^3 (second order in the curvatures: pi r^4 (k1 + k2) / 8); positive for a convex surface.
pub fn tangent_gap_volume_mm3(shape: &FeatureShape, k1: f64, k2: f64) -> f64 {
    let r = shape.radius_mm();
    PI * r.powi(4) * (k1 + k2) / 8.0
}
