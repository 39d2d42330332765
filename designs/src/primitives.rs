//! Exact geometry descriptions: the machine-readable form of protrusions and indenters.
//!
//! Lives in the geometry core because two crates read it: fixtures builds and writes it
//! (`protrusions/<pattern>.json`, `indenters/<part>.json`), calibration intersects rays with it
//! (`fabkit groundtruth`); one type keeps the printed and the rendered geometry the same.
//!
//! A [`Geometry`] is the union of analytic [`Primitive`]s in one named frame (the sensor frame
//! for semi-dome protrusions, the indenter frame for indenters). The ground-truth renderer
//! intersects rays with these primitives exactly; [`Geometry::solid`] meshes the same
//! primitives, so what is printed and what is described cannot drift apart.
//!
//! JSON form (all lengths mm):
//! ```json
//! {"frame": "sensor", "primitives": [
//!   {"type": "sphere", "centre_mm": [0, 0, 14.5], "radius_mm": 2.0},
//!   {"type": "cylinder", "base_mm": [..], "top_mm": [..], "radius_mm": 1.0},
//!   {"type": "cone", "apex_mm": [..], "base_mm": [..], "base_radius_mm": 1.2},
//!   {"type": "capsule", "p0_mm": [..], "p1_mm": [..], "radius_mm": 0.8},
//!   {"type": "box", "centre_mm": [..], "axes": [[..], [..], [..]], "half_extents_mm": [..]},
//!   {"type": "prism", "origin_mm": [..], "x_axis": [..], "y_axis": [..],
//!    "polygon_mm": [[x, y], ..], "height_mm": 10.0}
//! ]}
//! ```
//! Cylinders are flat-capped at both ends; cones are solid with a flat base disc; a capsule is
//! the set of points within `radius_mm` of the segment p0-p1; a box's `axes` are orthonormal
//! rows; a prism extrudes a simple counter-clockwise polygon (in the x_axis/y_axis plane at
//! `origin_mm`) along x_axis x y_axis by `height_mm`.

use crate::geometry::{
    cone, cuboid, profile2d::push_arc, revolve, sphere, Affine, ChordTolerance, GeometryError,
    Mesh, Polyline2, Solid,
};
use crate::markers::frame_to;
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// One analytic solid. See the module documentation for the JSON form.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Primitive {
    Sphere {
        centre_mm: [f64; 3],
        radius_mm: f64,
    },
    Cylinder {
        base_mm: [f64; 3],
        top_mm: [f64; 3],
        radius_mm: f64,
    },
    Cone {
        apex_mm: [f64; 3],
        base_mm: [f64; 3],
        base_radius_mm: f64,
    },
    Capsule {
        p0_mm: [f64; 3],
        p1_mm: [f64; 3],
        radius_mm: f64,
    },
    Box {
        centre_mm: [f64; 3],
        axes: [[f64; 3]; 3],
        half_extents_mm: [f64; 3],
    },
    Prism {
        origin_mm: [f64; 3],
        x_axis: [f64; 3],
        y_axis: [f64; 3],
        polygon_mm: Vec<[f64; 2]>,
        height_mm: f64,
    },
}

/// A union of primitives in a named frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// `sensor` (docs/conventions.md) or `indenter` (origin at the contact point, +z along the
    /// stem, away from the contact).
    pub frame: String,
    pub primitives: Vec<Primitive>,
}

/// a - b.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// a + b.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// a s.
#[inline]
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// a . b.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// a x b.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// |a|.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
/// a / |a|.
#[inline]
pub fn unit(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / norm(a))
}

fn invalid(msg: String) -> GeometryError {
    GeometryError::InvalidPrimitive(msg)
}

/// A solid of revolution about local +z, placed with its local origin at `at` and +z along `dir`.
fn placed(
    profile: &Polyline2,
    at: [f64; 3],
    dir: [f64; 3],
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    Ok(Solid::from_mesh(&revolve(profile, tol)?)?.transform(&frame_to(at, unit(dir))))
}

impl Primitive {
    /// The triangles [`Self::solid`] makes at `tol`, computed from the dimensions alone (the
    /// same segment counts, nothing tessellated): for a work estimate before a build.
    pub fn estimated_triangles(&self, tol: ChordTolerance) -> f64 {
        // a full circle's segments at the tolerance of the profile arcs and of the revolution
        let around = |r: f64| tol.half().circle_segments(r) as f64;
        match self {
            // n / 2 arc points revolved at n segments
            Primitive::Sphere { radius_mm, .. } => around(*radius_mm).powi(2),
            // straight generators: 4 profile points (caps and side) at the whole tolerance
            Primitive::Cylinder { radius_mm, .. } => 4.0 * tol.circle_segments(*radius_mm) as f64,
            Primitive::Cone { base_radius_mm, .. } => {
                3.0 * tol.circle_segments(*base_radius_mm) as f64
            }
            // two quarter arcs and the side
            Primitive::Capsule { radius_mm, .. } => {
                let n = around(*radius_mm);
                n * (n / 2.0 + 4.0)
            }
            Primitive::Box { .. } => 12.0,
            Primitive::Prism { polygon_mm, .. } => 4.0 * polygon_mm.len() as f64,
        }
    }

    /// The primitive as a closed solid within `tol` of the exact surface.
    ///
    /// # Errors
    /// [`GeometryError::InvalidPrimitive`] for non-positive sizes, coincident end points or a
    /// degenerate polygon.
    pub fn solid(&self, tol: ChordTolerance) -> Result<Solid, GeometryError> {
        match self {
            Primitive::Sphere {
                centre_mm,
                radius_mm,
            } => Ok(sphere(*radius_mm, tol)?.translate(*centre_mm)),
            Primitive::Cylinder {
                base_mm,
                top_mm,
                radius_mm,
            } => {
                let axis = sub(*top_mm, *base_mm);
                let h = norm(axis);
                if !(h > 0.0 && *radius_mm > 0.0) {
                    return Err(invalid(format!(
                        "cylinder of length {h} mm, radius {radius_mm} mm"
                    )));
                }
                Ok(
                    cone(h, *radius_mm, *radius_mm, tol)?
                        .transform(&frame_to(*base_mm, unit(axis))),
                )
            }
            Primitive::Cone {
                apex_mm,
                base_mm,
                base_radius_mm,
            } => {
                let axis = sub(*apex_mm, *base_mm);
                let h = norm(axis);
                if !(h > 0.0 && *base_radius_mm > 0.0) {
                    return Err(invalid(format!(
                        "cone of height {h} mm, base radius {base_radius_mm} mm"
                    )));
                }
                Ok(cone(h, *base_radius_mm, 0.0, tol)?.transform(&frame_to(*base_mm, unit(axis))))
            }
            Primitive::Capsule {
                p0_mm,
                p1_mm,
                radius_mm,
            } => {
                let axis = sub(*p1_mm, *p0_mm);
                let h = norm(axis);
                let r = *radius_mm;
                if !(h > 0.0 && r > 0.0) {
                    return Err(invalid(format!("capsule of length {h} mm, radius {r} mm")));
                }
                let mut pl = Polyline2::default();
                push_arc(&mut pl, [0.0, 0.0], r, -FRAC_PI_2, 0.0, tol.half());
                push_arc(&mut pl, [0.0, h], r, 0.0, FRAC_PI_2, tol.half());
                placed(&pl, *p0_mm, axis, tol)
            }
            Primitive::Box {
                centre_mm,
                axes,
                half_extents_mm,
            } => {
                let e = half_extents_mm;
                let b = cuboid([-e[0], -e[1], -e[2]], [e[0], e[1], e[2]])?;
                let a = axes;
                let m = crate::geometry::transform::from_columns(a[0], a[1], a[2], *centre_mm);
                Ok(b.transform(&m))
            }
            Primitive::Prism {
                origin_mm,
                x_axis,
                y_axis,
                polygon_mm,
                height_mm,
            } => {
                let mesh = extrude(polygon_mm, *height_mm)?;
                let z = cross(*x_axis, *y_axis);
                let m = crate::geometry::transform::from_columns(*x_axis, *y_axis, z, *origin_mm);
                Ok(Solid::from_mesh(&mesh)?.transform(&m))
            }
        }
    }
}

/// A closed prism over a simple counter-clockwise polygon, z from 0 to `height_mm`. The caps
/// are triangulated by ear clipping.
fn extrude(poly: &[[f64; 2]], height_mm: f64) -> Result<Mesh, GeometryError> {
    let n = poly.len();
    let area2: f64 = (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if n < 3 || !(area2 > 0.0) || !(height_mm > 0.0) {
        return Err(invalid(format!(
            "prism of {n} points, signed area {} mm2, height {height_mm} mm: needs a counter-clockwise polygon and a height above 0",
            area2 / 2.0
        )));
    }
    let cap = ear_clip(poly).ok_or_else(|| invalid("prism polygon is not simple".into()))?;
    let mut vertices: Vec<[f64; 3]> = poly.iter().map(|p| [p[0], p[1], 0.0]).collect();
    vertices.extend(poly.iter().map(|p| [p[0], p[1], height_mm]));
    let n32 = n as u32;
    let mut triangles = Vec::with_capacity(4 * n);
    for t in &cap {
        triangles.push([t[0], t[2], t[1]]);
        triangles.push([t[0] + n32, t[1] + n32, t[2] + n32]);
    }
    for i in 0..n32 {
        let j = (i + 1) % n32;
        triangles.push([i, j, j + n32]);
        triangles.push([i, j + n32, i + n32]);
    }
    Ok(Mesh {
        vertices,
        triangles,
    })
}

/// Ear clipping of a simple counter-clockwise polygon; `None` when no ear is found.
fn ear_clip(poly: &[[f64; 2]]) -> Option<Vec<[u32; 3]>> {
    let mut idx: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::new();
    let cross2 = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (
                poly[idx[(k + m - 1) % m]],
                poly[idx[k]],
                poly[idx[(k + 1) % m]],
            );
            if cross2(a, b, c) <= 0.0 {
                return false;
            }
            idx.iter().all(|&q| {
                let p = poly[q];
                if p == a || p == b || p == c {
                    return true;
                }
                !(cross2(a, b, p) >= 0.0 && cross2(b, c, p) >= 0.0 && cross2(c, a, p) >= 0.0)
            })
        })?;
        out.push([
            idx[(ear + m - 1) % m] as u32,
            idx[ear] as u32,
            idx[(ear + 1) % m] as u32,
        ]);
        idx.remove(ear);
    }
    out.push([idx[0] as u32, idx[1] as u32, idx[2] as u32]);
    Some(out)
}

impl Geometry {
    /// The triangles of [`Self::solid`] before the union: the sum of
    /// [`Primitive::estimated_triangles`].
    pub fn estimated_triangles(&self, tol: ChordTolerance) -> f64 {
        self.primitives
            .iter()
            .map(|p| p.estimated_triangles(tol))
            .sum()
    }

    /// The union of the primitives as one solid (disjoint or overlapping).
    ///
    /// # Errors
    /// As [`Primitive::solid`], or a kernel failure.
    pub fn solid(&self, tol: ChordTolerance) -> Result<Solid, GeometryError> {
        let parts = self
            .primitives
            .iter()
            .map(|p| p.solid(tol))
            .collect::<Result<Vec<_>, _>>()?;
        Solid::union_all(&parts)
    }

    /// The same geometry moved by a rigid map `m` (rotation rows + translation column).
    pub fn transformed(&self, m: &Affine) -> Geometry {
        let p = |v: [f64; 3]| -> [f64; 3] {
            m.transform_point(&nalgebra::Point3::from(v)).coords.into()
        };
        let d =
            |v: [f64; 3]| -> [f64; 3] { m.transform_vector(&nalgebra::Vector3::from(v)).into() };
        let primitives = self
            .primitives
            .iter()
            .map(|q| match q.clone() {
                Primitive::Sphere {
                    centre_mm,
                    radius_mm,
                } => Primitive::Sphere {
                    centre_mm: p(centre_mm),
                    radius_mm,
                },
                Primitive::Cylinder {
                    base_mm,
                    top_mm,
                    radius_mm,
                } => Primitive::Cylinder {
                    base_mm: p(base_mm),
                    top_mm: p(top_mm),
                    radius_mm,
                },
                Primitive::Cone {
                    apex_mm,
                    base_mm,
                    base_radius_mm,
                } => Primitive::Cone {
                    apex_mm: p(apex_mm),
                    base_mm: p(base_mm),
                    base_radius_mm,
                },
                Primitive::Capsule {
                    p0_mm,
                    p1_mm,
                    radius_mm,
                } => Primitive::Capsule {
                    p0_mm: p(p0_mm),
                    p1_mm: p(p1_mm),
                    radius_mm,
                },
                Primitive::Box {
                    centre_mm,
                    axes,
                    half_extents_mm,
                } => Primitive::Box {
                    centre_mm: p(centre_mm),
                    axes: [d(axes[0]), d(axes[1]), d(axes[2])],
                    half_extents_mm,
                },
                Primitive::Prism {
                    origin_mm,
                    x_axis,
                    y_axis,
                    polygon_mm,
                    height_mm,
                } => Primitive::Prism {
                    origin_mm: p(origin_mm),
                    x_axis: d(x_axis),
                    y_axis: d(y_axis),
                    polygon_mm,
                    height_mm,
                },
            })
            .collect();
        Geometry {
            frame: self.frame.clone(),
            primitives,
        }
    }
}
