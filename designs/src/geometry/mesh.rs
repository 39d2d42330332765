//! Indexed triangle meshes: the form in which solids leave the kernel.

use serde::{Deserialize, Serialize};

/// An axis-aligned bounding box, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Aabb {
    /// Edge lengths along x, y, z, mm.
    pub fn size(&self) -> [f64; 3] {
        [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ]
    }
}

/// A closed triangle mesh with shared vertices, mm.
///
/// `triangles` index into `vertices`; each triangle is counter-clockwise seen from outside
/// (right-hand normal points out of the solid), the convention of STL, 3MF and Manifold.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertex positions, shape (V, 3), mm.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices, shape (T, 3).
    pub triangles: Vec<[u32; 3]>,
}

/// What [`Mesh::check_closed_manifold`] found wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TopologyError {
    #[error("mesh has no triangles")]
    Empty,
    #[error("triangle {0} indexes a vertex that does not exist")]
    BadIndex(usize),
    #[error("triangle {0} repeats a vertex (degenerate)")]
    RepeatedVertex(usize),
    #[error("{0} edges are not shared by exactly two triangles (open or non-manifold)")]
    OpenOrNonManifoldEdges(usize),
    #[error("{0} edges are used twice in the same direction (inconsistent winding)")]
    InconsistentWinding(usize),
    #[error("signed volume {0} mm^3 is not positive (inside-out)")]
    NonPositiveVolume(f64),
    #[error("vertex coordinate is not finite")]
    NonFinite,
}

/// (b - a) x (c - a): the triangle's normal scaled by twice its area (outward for CCW winding).
pub fn triangle_cross(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ]
}

/// The mass properties of a solid of uniform density 1 ([`Mesh::mass_properties`]): its
/// volume, centroid and inertia tensor about the centroid. For a density rho (g/mm^3) the mass
/// is rho x volume (g) and the inertia rho x `inertia_mm5` (g mm^2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Enclosed volume, mm^3.
    pub volume_mm3: f64,
    /// Centroid (the centre of mass at uniform density), in the mesh's frame, mm.
    pub centroid_mm: [f64; 3],
    /// Inertia tensor about the centroid, axes of the mesh's frame, per unit density, mm^5:
    /// [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]], the products of inertia with their
    /// minus sign (Ixy = -integral of x y dV), as URDF, MJCF's `fullinertia` and USD take it.
    pub inertia_mm5: [[f64; 3]; 3],
}

impl Mesh {
    /// Volume, centroid and inertia tensor of the closed, outward-wound mesh at uniform density
    /// 1, exact for the polyhedron: the divergence theorem over each triangle's tetrahedron,
    /// after D. Eberly, "Polyhedral Mass Properties (Revisited)", Geometric Tools (2002),
    /// whose integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz and zx this sums. The vertices are
    /// taken relative to the first one, so that a part far from the origin keeps its digits.
    /// An empty mesh has zero volume and a NaN centroid.
    pub fn mass_properties(&self) -> MassProperties {
        let o = self.vertices.first().copied().unwrap_or([0.0; 3]);
        // 1, x, y, z, x^2, y^2, z^2, xy, yz, zx
        let mut int = [0.0f64; 10];
        let sub = |w0: f64, w1: f64, w2: f64| {
            let t0 = w0 + w1;
            let f1 = t0 + w2;
            let t1 = w0 * w0;
            let t2 = t1 + w1 * t0;
            let f2 = t2 + w2 * f1;
            let f3 = w0 * t1 + w1 * t2 + w2 * f2;
            let g = [
                f2 + w0 * (f1 + w0),
                f2 + w1 * (f1 + w1),
                f2 + w2 * (f1 + w2),
            ];
            (f1, f2, f3, g)
        };
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| {
                let v = self.vertices[i as usize];
                [v[0] - o[0], v[1] - o[1], v[2] - o[2]]
            });
            let d = triangle_cross(a, b, c);
            let (f1x, f2x, f3x, gx) = sub(a[0], b[0], c[0]);
            let (_, f2y, f3y, gy) = sub(a[1], b[1], c[1]);
            let (_, f2z, f3z, gz) = sub(a[2], b[2], c[2]);
            int[0] += d[0] * f1x;
            int[1] += d[0] * f2x;
            int[2] += d[1] * f2y;
            int[3] += d[2] * f2z;
            int[4] += d[0] * f3x;
            int[5] += d[1] * f3y;
            int[6] += d[2] * f3z;
            int[7] += d[0] * (a[1] * gx[0] + b[1] * gx[1] + c[1] * gx[2]);
            int[8] += d[1] * (a[2] * gy[0] + b[2] * gy[1] + c[2] * gy[2]);
            int[9] += d[2] * (a[0] * gz[0] + b[0] * gz[1] + c[0] * gz[2]);
        }
        let scale = [6.0, 24.0, 24.0, 24.0, 60.0, 60.0, 60.0, 120.0, 120.0, 120.0];
        for (v, s) in int.iter_mut().zip(scale) {
            *v /= s;
        }
        let v = int[0];
        let c = [int[1] / v, int[2] / v, int[3] / v];
        let xx = int[5] + int[6] - v * (c[1] * c[1] + c[2] * c[2]);
        let yy = int[4] + int[6] - v * (c[2] * c[2] + c[0] * c[0]);
        let zz = int[4] + int[5] - v * (c[0] * c[0] + c[1] * c[1]);
        let xy = -(int[7] - v * c[0] * c[1]);
        let yz = -(int[8] - v * c[1] * c[2]);
        let zx = -(int[9] - v * c[2] * c[0]);
        MassProperties {
            volume_mm3: v,
            centroid_mm: [c[0] + o[0], c[1] + o[1], c[2] + o[2]],
            inertia_mm5: [[xx, xy, zx], [xy, yy, yz], [zx, yz, zz]],
        }
    }

    /// Enclosed volume by the divergence theorem, mm^3 (positive for outward winding).
    pub fn signed_volume(&self) -> f64 {
        let mut v = 0.0;
        for t in &self.triangles {
            let a = self.vertices[t[0] as usize];
            let b = self.vertices[t[1] as usize];
            let c = self.vertices[t[2] as usize];
            v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
        v / 6.0
    }

    /// Total triangle area, mm^2.
    pub fn surface_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let n = triangle_cross(
                    self.vertices[t[0] as usize],
                    self.vertices[t[1] as usize],
                    self.vertices[t[2] as usize],
                );
                0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
            })
            .sum()
    }

    /// Bounding box of the vertices; `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<Aabb> {
        let first = *self.vertices.first()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for v in &self.vertices {
            for (k, &c) in v.iter().enumerate() {
                b.min[k] = b.min[k].min(c);
                b.max[k] = b.max[k].max(c);
            }
        }
        Some(b)
    }

    /// Genus from the Euler characteristic of a closed, connected-per-shell mesh:
    /// `genus = shells - chi / 2` where chi = V - E + F. A solid ball has genus 0, a ring 1.
    pub fn genus(&self) -> i64 {
        let v = self.vertices.len() as i64;
        let f = self.triangles.len() as i64;
        let e = 3 * f / 2;
        let chi = v - e + f;
        self.shell_count() as i64 - chi / 2
    }

    /// Number of edge-connected shells.
    pub fn shell_count(&self) -> usize {
        let roots = self.vertex_roots();
        let mut used = vec![false; self.vertices.len()];
        for t in &self.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        (0..roots.len())
            .filter(|&i| used[i] && roots[i] == i)
            .count()
    }

    /// The volume (mm^3, divergence theorem) and surface area (mm^2) of each edge-connected
    /// shell, in the order of their lowest root vertex.
    pub fn shell_volumes_and_areas(&self) -> Vec<(f64, f64)> {
        let roots = self.vertex_roots();
        let mut by_root = std::collections::BTreeMap::<usize, (f64, f64)>::new();
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.vertices[i as usize]);
            let v = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            let n = triangle_cross(a, b, c);
            let e = by_root.entry(roots[t[0] as usize]).or_default();
            e.0 += v / 6.0;
            e.1 += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        }
        by_root.into_values().collect()
    }

    /// Each vertex's shell, as the root vertex of its union-find tree over the triangles'
    /// edges.
    fn vertex_roots(&self) -> Vec<usize> {
        let n = self.vertices.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for t in &self.triangles {
            let a = t[0] as usize;
            for &o in &t[1..] {
                let (ra, ro) = (find(&mut parent, a), find(&mut parent, o as usize));
                if ra != ro {
                    parent[ra] = ro;
                }
            }
        }
        (0..n).map(|i| find(&mut parent, i)).collect()
    }

    /// Checks that the mesh is a closed, consistently oriented 2-manifold with positive volume:
    /// every directed edge appears exactly once and its reverse exactly once.
    ///
    /// # Errors
    /// The first [`TopologyError`] found.
    pub fn check_closed_manifold(&self) -> Result<(), TopologyError> {
        if self.triangles.is_empty() {
            return Err(TopologyError::Empty);
        }
        if self.vertices.iter().flatten().any(|c| !c.is_finite()) {
            return Err(TopologyError::NonFinite);
        }
        use rayon::prelude::*;
        let nv = self.vertices.len() as u32;
        // each directed edge (a, b) as the number a << 32 | b, its twin (b, a) that number
        // rotated by 32 bits: sorted, an edge is paired by a binary search
        let edge = |a: u32, b: u32| (u64::from(a) << 32) | u64::from(b);
        let mut directed: Vec<u64> = Vec::with_capacity(self.triangles.len() * 3);
        for (i, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&x| x >= nv) {
                return Err(TopologyError::BadIndex(i));
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(TopologyError::RepeatedVertex(i));
            }
            directed.extend([edge(t[0], t[1]), edge(t[1], t[2]), edge(t[2], t[0])]);
        }
        // large meshes (the whole kit's parts) on every core; the counts do not depend on it
        const PARALLEL_EDGES: usize = 1 << 16;
        let large = directed.len() >= PARALLEL_EDGES;
        if large {
            directed.par_sort_unstable();
        } else {
            directed.sort_unstable();
        }
        let dup = directed.windows(2).filter(|w| w[0] == w[1]).count();
        if dup > 0 {
            return Err(TopologyError::InconsistentWinding(dup));
        }
        let twinless = |&e: &u64| directed.binary_search(&e.rotate_right(32)).is_err();
        let unpaired = if large {
            directed.par_iter().filter(|e| twinless(e)).count()
        } else {
            directed.iter().filter(|e| twinless(e)).count()
        };
        if unpaired > 0 {
            return Err(TopologyError::OpenOrNonManifoldEdges(unpaired));
        }
        let vol = self.signed_volume();
        if vol.is_nan() || vol <= 0.0 {
            return Err(TopologyError::NonPositiveVolume(vol));
        }
        Ok(())
    }

    /// The same mesh with every coordinate rounded to `f32`, as STL and most 3MF readers store it.
    /// Statistics written beside a file are computed on this form so that they match the file.
    ///
    /// x and y round to the nearest `f32`; z, the build direction of a part in print orientation,
    /// rounds up to the nearest `f32` not below it (at most one unit in the last place: 2.4e-7 mm
    /// at 2-4 mm, 7.6e-6 mm at 64-128 mm). A slicer sizes its layer stack from the top of the mesh
    /// and drops what lies past the last whole layer: PrusaSlicer truncates the top z to whole
    /// nanometres and adds a layer while `first + k * layer <= top` (`SLAPrint::Steps::slice_model`),
    /// so a 2.8 mm part stored as the nearest `f32`, 2.79999995 mm, is sliced into 55 layers of
    /// 0.05 mm, 2.75 mm tall. Rounded up, a part resting on z = 0 whose height is a whole number of
    /// layers keeps every layer.
    pub fn rounded_to_f32(&self) -> Mesh {
        Mesh {
            vertices: self
                .vertices
                .iter()
                .map(|&[x, y, z]| [x as f32 as f64, y as f32 as f64, f32_not_below(z)])
                .collect(),
            triangles: self.triangles.clone(),
        }
    }
}

/// The nearest `f32` not below `z`, as f64 (`z` itself when it is an `f32`; NaN stays NaN, a
/// value past `f32::MAX` becomes infinite as `as f32` makes it).
fn f32_not_below(z: f64) -> f64 {
    let f = z as f32;
    if (f as f64) < z {
        f.next_up() as f64
    } else {
        f as f64
    }
}
