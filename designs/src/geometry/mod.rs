//! The geometry core: chord tolerance, the [`Solid`] wrapper over the boolean kernel
//! (`manifold-rust`), primitives and the revolve of 2D profiles.
//!
//! Every constructor takes a [`ChordTolerance`] explicitly; there is no global quality state,
//! so parallel builds with different tolerances can share a process.

mod mesh;
pub mod profile2d;
mod solid;
pub mod transform;

pub use mesh::{triangle_cross, Aabb, MassProperties, Mesh, TopologyError};
pub use profile2d::Polyline2;
pub use solid::{csg_json, rotation_deg, CsgNode, GeometryError, Solid};
pub use transform::Affine;

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The largest distance between an exported mesh and the exact solid it approximates, mm (> 0).
///
/// Every faceted surface is meshed to [`ChordTolerance::facet_mm`] = tol / sqrt(2), so that
/// where two such surfaces meet at an edge (a boolean seam) with an angle of 90 deg or wider on
/// either side, the mesh corner stays within tol of the exact edge: two facets each within d of
/// their surfaces meet up to d / sin(beta / 2) from the exact edge, sqrt(2) d at beta = 90 deg.
/// Primitives and revolves split the facet deviation between the profile direction and the
/// circumferential direction (half each), so a facet of a surface of revolution stays within it.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct ChordTolerance(f64);

impl ChordTolerance {
    /// The default, 0.01 mm: finer than FDM and SLA printer resolution.
    pub const DEFAULT_MM: f64 = 0.01;

    /// The finest tolerance accepted, 0.001 mm: 25 times finer than the finest SLA layer, and
    /// already 10 times the triangles of the default (the triangle count grows as 1 / tol).
    /// A finer tolerance only costs time and memory: 1e-4 mm took 20-48 s and 3.5 GB for one
    /// library design, 1e-9 mm aborted on a 6 GB allocation.
    pub const MIN_MM: f64 = 0.001;

    /// # Errors
    /// When `mm` is not a finite number of at least [`Self::MIN_MM`].
    pub fn new(mm: f64) -> Result<Self, String> {
        if mm.is_finite() && mm >= Self::MIN_MM {
            Ok(Self(mm))
        } else if mm.is_finite() && mm > 0.0 {
            Err(format!(
                "chord tolerance = {mm} mm: must be at least {} mm (finer than any printer \
                 resolves; the mesh grows as 1 / tolerance)",
                Self::MIN_MM
            ))
        } else {
            Err(format!(
                "chord tolerance = {mm} mm: must be a finite number of at least {} mm",
                Self::MIN_MM
            ))
        }
    }

    /// The tolerance in mm.
    pub fn mm(self) -> f64 {
        self.0
    }

    /// The deviation each faceted surface is meshed to, mm: tol / sqrt(2) (see the type's doc:
    /// it keeps boolean seams of 90 deg or wider within tol).
    pub fn facet_mm(self) -> f64 {
        self.0 * std::f64::consts::FRAC_1_SQRT_2
    }

    /// Number of segments of a full circle of radius `radius_mm` whose chords stay within
    /// [`Self::facet_mm`] of the circle: the smallest multiple of 4 (so that the planes x = 0
    /// and y = 0 pass through vertices) with `r (1 - cos(pi / n)) <= facet_mm`, and at least 8.
    pub fn circle_segments(self, radius_mm: f64) -> usize {
        let d = self.facet_mm();
        if radius_mm <= d {
            return 8;
        }
        let half_angle = (1.0 - d / radius_mm).acos();
        let n = (PI / half_angle).ceil() as usize;
        n.max(8).div_ceil(4) * 4
    }

    /// Half this tolerance (one share of the profile / circumferential split).
    pub fn half(self) -> Self {
        Self(self.0 / 2.0)
    }
}

impl Default for ChordTolerance {
    fn default() -> Self {
        Self(Self::DEFAULT_MM)
    }
}

impl TryFrom<f64> for ChordTolerance {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        Self::new(v)
    }
}

impl From<ChordTolerance> for f64 {
    fn from(t: ChordTolerance) -> f64 {
        t.0
    }
}

/// Revolves a closed 2D profile about the z axis into a closed mesh.
///
/// `profile` is a closed polygon in the (r, z) half-plane, r >= 0, either winding; vertices with
/// r == 0 lie on the axis and become single poles. The circumferential segment count follows
/// from the largest radius and `tol.half()`; the profile itself must already honour the other
/// half (see [`profile2d`]).
///
/// # Errors
/// [`GeometryError::InvalidProfile`] for fewer than 3 points, negative r or a non-finite point.
pub fn revolve(profile: &Polyline2, tol: ChordTolerance) -> Result<Mesh, GeometryError> {
    let pts = &profile.points;
    if pts.len() < 3 {
        return Err(GeometryError::InvalidProfile("fewer than 3 points".into()));
    }
    if pts
        .iter()
        .any(|p| !p[0].is_finite() || !p[1].is_finite() || p[0] < 0.0)
    {
        return Err(GeometryError::InvalidProfile(
            "points must be finite with r >= 0".into(),
        ));
    }
    let r_max = pts.iter().map(|p| p[0]).fold(0.0, f64::max);
    let n = tol.half().circle_segments(r_max);
    Ok(revolve_rings(pts, &vec![n; pts.len()]))
}

/// Revolves the closed shell between two surfaces of revolution about the z axis: `outer` and
/// `inner` each run from the axis (r = 0) down to a rim point, both rims on one plane z, and the
/// shell is closed by the annulus between the two rims on that plane. Each surface gets the
/// circumferential segment count of its own largest radius (with `tol.half()`, as [`revolve`]),
/// so the mesh is the one the difference of the two enclosed solids gives ([`revolve`] of each
/// surface closed to the axis, the inner one continued under the rim plane), without the
/// boolean: the same vertices on both surfaces, the same triangles on them, and the annulus
/// triangulated between rings of different counts (by angle). [`revolve`] of the joined profile
/// would give the inner surface the outer's finer count instead: another mesh of the same
/// surfaces, with a volume up to about 1e-4 relative apart.
///
/// # Errors
/// [`GeometryError::InvalidProfile`] when a surface has fewer than 2 points, does not start on
/// the axis, the rims are not on one plane, or a point is not finite with r >= 0.
pub fn revolve_shell(
    outer: &Polyline2,
    inner: &Polyline2,
    tol: ChordTolerance,
) -> Result<Mesh, GeometryError> {
    let (o, i) = (&outer.points, &inner.points);
    if o.len() < 2 || i.len() < 2 {
        return Err(GeometryError::InvalidProfile(
            "each surface needs at least 2 points".into(),
        ));
    }
    if o.iter()
        .chain(i)
        .any(|p| !p[0].is_finite() || !p[1].is_finite() || p[0] < 0.0)
    {
        return Err(GeometryError::InvalidProfile(
            "points must be finite with r >= 0".into(),
        ));
    }
    let (o_rim, i_rim) = (o[o.len() - 1], i[i.len() - 1]);
    if o[0][0] != 0.0 || i[0][0] != 0.0 || o_rim[1] != i_rim[1] || !(o_rim[0] > i_rim[0]) {
        return Err(GeometryError::InvalidProfile(
            "both surfaces start on the axis and end on one plane, the outer rim outside the inner"
                .into(),
        ));
    }
    let segments = |pl: &[[f64; 2]]| {
        tol.half()
            .circle_segments(pl.iter().map(|p| p[0]).fold(0.0, f64::max))
    };
    let (n_o, n_i) = (segments(o), segments(i));
    let pts: Vec<[f64; 2]> = o.iter().chain(i.iter().rev()).copied().collect();
    let rings: Vec<usize> = std::iter::repeat_n(n_o, o.len())
        .chain(std::iter::repeat_n(n_i, i.len()))
        .collect();
    Ok(revolve_rings(&pts, &rings))
}

/// The mesh of the closed profile `pts` revolved about the z axis, point `k` on a ring of
/// `rings[k]` segments (a single pole when r == 0), outward winding. Neighbouring rings of
/// one count are joined by quads (two triangles each); of different counts, by triangles taken
/// in order of angle.
fn revolve_rings(pts: &[[f64; 2]], rings: &[usize]) -> Mesh {
    // The sines and cosines of each count (at most a few counts per profile).
    let mut tables: Vec<(usize, Vec<f64>, Vec<f64>)> = Vec::new();
    for &n in rings {
        if tables.iter().all(|t| t.0 != n) {
            let (sin, cos): (Vec<f64>, Vec<f64>) = (0..n)
                .map(|j| (2.0 * PI * j as f64 / n as f64).sin_cos())
                .unzip();
            tables.push((n, sin, cos));
        }
    }
    // Snap the quarter angles so that x = 0 and y = 0 hold exactly there.
    let snap = |v: f64| if v.abs() < 1e-15 { 0.0 } else { v };

    let mut vertices: Vec<[f64; 3]> = Vec::new();
    // first vertex index of each profile point, and its ring's count (0 on the axis)
    let mut first: Vec<(u32, usize)> = Vec::with_capacity(pts.len());
    for (p, &n) in pts.iter().zip(rings) {
        let start = vertices.len() as u32;
        if p[0] == 0.0 {
            vertices.push([0.0, 0.0, p[1]]);
            first.push((start, 0));
        } else {
            let (_, sin, cos) = tables.iter().find(|t| t.0 == n).expect("a table per count");
            for j in 0..n {
                vertices.push([snap(p[0] * cos[j]), snap(p[0] * sin[j]), p[1]]);
            }
            first.push((start, n));
        }
    }
    let idx = |k: usize, j: usize| -> u32 {
        let (s, n) = first[k];
        if n == 0 {
            s
        } else {
            s + (j % n) as u32
        }
    };
    let mut triangles = Vec::new();
    for k in 0..pts.len() {
        let k2 = (k + 1) % pts.len();
        let (na, nb) = (first[k].1, first[k2].1);
        if na == 0 && nb == 0 {
            continue;
        }
        if na == 0 || nb == 0 || na == nb {
            for j in 0..na.max(nb) {
                let (p0, p1, q0, q1) = (idx(k, j), idx(k, j + 1), idx(k2, j), idx(k2, j + 1));
                if na == 0 {
                    triangles.push([p0, q1, q0]);
                } else if nb == 0 {
                    triangles.push([p0, p1, q0]);
                } else {
                    triangles.push([p0, p1, q1]);
                    triangles.push([p0, q1, q0]);
                }
            }
        } else {
            // Rings of different counts: advance along whichever ring's next vertex comes
            // first by angle (a tie moves along ring k), so the triangles cover the band once.
            let (mut a, mut b) = (0usize, 0usize);
            while a < na || b < nb {
                if b == nb || (a < na && (a + 1) * nb <= (b + 1) * na) {
                    triangles.push([idx(k, a), idx(k, a + 1), idx(k2, b)]);
                    a += 1;
                } else {
                    triangles.push([idx(k, a), idx(k2, b + 1), idx(k2, b)]);
                    b += 1;
                }
            }
        }
    }
    let mut mesh = Mesh {
        vertices,
        triangles,
    };
    if mesh.signed_volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    mesh
}

/// A sphere of radius `radius_mm` centred at the origin, within `tol` of the true sphere.
///
/// # Errors
/// [`GeometryError::InvalidPrimitive`] for a radius that is not above zero.
pub fn sphere(radius_mm: f64, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    if !(radius_mm > 0.0 && radius_mm.is_finite()) {
        return Err(GeometryError::InvalidPrimitive(format!(
            "sphere radius = {radius_mm} mm: must be above 0"
        )));
    }
    let mut pl = Polyline2::default();
    profile2d::push_arc(
        &mut pl,
        [0.0, 0.0],
        radius_mm,
        -PI / 2.0,
        PI / 2.0,
        tol.half(),
    );
    Solid::from_mesh(&revolve(&pl, tol)?)
}

/// A cone frustum along +z from z = 0 to `height_mm`, radius `r_low_mm` at the bottom and
/// `r_high_mm` at the top (either may be 0, not both).
///
/// # Errors
/// [`GeometryError::InvalidPrimitive`] for a non-positive height or negative radii.
pub fn cone(
    height_mm: f64,
    r_low_mm: f64,
    r_high_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    if !(height_mm > 0.0 && r_low_mm >= 0.0 && r_high_mm >= 0.0 && r_low_mm.max(r_high_mm) > 0.0) {
        return Err(GeometryError::InvalidPrimitive(format!(
            "cone height {height_mm} mm, radii {r_low_mm}/{r_high_mm} mm: need height > 0, radii >= 0, one radius > 0"
        )));
    }
    let pl = Polyline2 {
        points: vec![
            [0.0, 0.0],
            [r_low_mm, 0.0],
            [r_high_mm, height_mm],
            [0.0, height_mm],
        ],
    };
    // Straight generators: the whole tolerance may go to the circumference.
    Solid::from_mesh(&revolve(&dedup_axis(pl), ChordTolerance(tol.0 * 2.0))?)
}

fn dedup_axis(mut pl: Polyline2) -> Polyline2 {
    pl.points.dedup();
    if pl.points.len() > 1 && pl.points.first() == pl.points.last() {
        pl.points.pop();
    }
    pl
}

/// A cylinder along +z from z = 0 to `height_mm` with radius `radius_mm`.
///
/// # Errors
/// As [`cone`].
pub fn cylinder(
    height_mm: f64,
    radius_mm: f64,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    cone(height_mm, radius_mm, radius_mm, tol)
}

/// A box with one corner at `min` and the opposite at `max`, mm.
///
/// # Errors
/// [`GeometryError::InvalidPrimitive`] when any edge is not positive.
pub fn cuboid(min: [f64; 3], max: [f64; 3]) -> Result<Solid, GeometryError> {
    let size = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
    if size.iter().any(|&s| !(s > 0.0 && s.is_finite())) {
        return Err(GeometryError::InvalidPrimitive(format!(
            "box from {min:?} to {max:?} mm: every edge must be above 0"
        )));
    }
    let v = [
        [min[0], min[1], min[2]],
        [max[0], min[1], min[2]],
        [max[0], max[1], min[2]],
        [min[0], max[1], min[2]],
        [min[0], min[1], max[2]],
        [max[0], min[1], max[2]],
        [max[0], max[1], max[2]],
        [min[0], max[1], max[2]],
    ];
    let t = [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    Solid::from_mesh(&Mesh {
        vertices: v.to_vec(),
        triangles: t.to_vec(),
    })
}

/// The region bounded by `rings` (each a closed polygon without its closing vertex: the
/// outer boundaries counter-clockwise, the holes in them clockwise; none crossing another)
/// extruded from `z0_mm` up to `z1_mm`: a laser-cut sheet. The kernel triangulates the faces.
///
/// # Errors
/// [`GeometryError::InvalidPrimitive`] for a ring of fewer than 3 vertices, a non-finite
/// vertex, z1 not above z0, or a region of no area; [`GeometryError::Topology`] /
/// [`GeometryError::Kernel`] if the kernel's mesh is not a closed 2-manifold.
pub fn extrude(rings: &[Vec<[f64; 2]>], z0_mm: f64, z1_mm: f64) -> Result<Solid, GeometryError> {
    let ok = !rings.is_empty()
        && rings
            .iter()
            .all(|r| r.len() >= 3 && r.iter().flatten().all(|v| v.is_finite()))
        && z1_mm > z0_mm
        && z0_mm.is_finite()
        && z1_mm.is_finite();
    if !ok {
        return Err(GeometryError::InvalidPrimitive(format!(
            "extrusion of {} rings from z = {z0_mm} to {z1_mm} mm: needs rings of 3 or more finite vertices and z1 above z0",
            rings.len()
        )));
    }
    let polys: manifold_rust::types::Polygons = rings
        .iter()
        .map(|r| {
            r.iter()
                .map(|p| manifold_rust::linalg::Vec2::new(p[0], p[1]))
                .collect()
        })
        .collect();
    let m = manifold_rust::manifold::Manifold::extrude(
        &polys,
        z1_mm - z0_mm,
        0,
        0.0,
        manifold_rust::linalg::Vec2::new(1.0, 1.0),
    );
    let gl = m.get_mesh_glp::<f64, u32>(0);
    if gl.tri_verts.is_empty() {
        return Err(GeometryError::InvalidPrimitive(format!(
            "extrusion of {} rings: the region has no area",
            rings.len()
        )));
    }
    let np = gl.num_prop as usize;
    let mesh = Mesh {
        vertices: gl
            .vert_properties
            .chunks(np)
            .map(|c| [c[0], c[1], c[2] + z0_mm])
            .collect(),
        triangles: gl.tri_verts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
    };
    Solid::from_mesh(&mesh)
}

/// The right prism over a convex polygon (counter-clockwise (x, y) vertices, mm) from `z0_mm`
/// up to `z1_mm`: both caps fanned from their first vertex, one quad per side.
///
/// # Errors
/// [`GeometryError::InvalidPrimitive`] for fewer than 3 vertices, a non-finite coordinate,
/// `z1_mm <= z0_mm`, or a polygon that is not convex and counter-clockwise.
pub fn prism(polygon: &[[f64; 2]], z0_mm: f64, z1_mm: f64) -> Result<Solid, GeometryError> {
    let n = polygon.len();
    let finite = polygon.iter().flatten().all(|v| v.is_finite());
    let convex = n >= 3
        && (0..n).all(|i| {
            let (a, b, c) = (polygon[i], polygon[(i + 1) % n], polygon[(i + 2) % n]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) > 0.0
        });
    if !(finite && convex && z1_mm > z0_mm && z0_mm.is_finite() && z1_mm.is_finite()) {
        return Err(GeometryError::InvalidPrimitive(format!(
            "prism of {n} vertices from z = {z0_mm} to {z1_mm} mm: needs 3 or more finite vertices of a convex counter-clockwise polygon and z1 above z0"
        )));
    }
    let mut vertices: Vec<[f64; 3]> = polygon.iter().map(|p| [p[0], p[1], z0_mm]).collect();
    vertices.extend(polygon.iter().map(|p| [p[0], p[1], z1_mm]));
    let n32 = n as u32;
    let mut triangles = Vec::with_capacity(4 * n);
    for i in 1..n32 - 1 {
        triangles.push([0, i + 1, i]); // bottom, facing -z
        triangles.push([n32, n32 + i, n32 + i + 1]); // top, facing +z
    }
    for i in 0..n32 {
        let j = (i + 1) % n32;
        triangles.push([i, j, n32 + j]);
        triangles.push([i, n32 + j, n32 + i]);
    }
    Solid::from_mesh(&Mesh {
        vertices,
        triangles,
    })
}
