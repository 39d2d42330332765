//! [`Solid`]: our own handle on the boolean kernel (`manifold-rust`), so that the kernel can be
//! swapped without touching the part code.

use super::transform::{self, Affine};
use super::{Aabb, Mesh, TopologyError};
use manifold_rust::linalg::{Mat3x4, Vec3};
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error as KernelStatus, MeshGLP};
use std::sync::Arc;

/// Errors of the geometry core.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    #[error("invalid profile: {0}")]
    InvalidProfile(String),
    #[error("invalid primitive: {0}")]
    InvalidPrimitive(String),
    #[error("the boolean kernel rejected the mesh: {0}")]
    Kernel(String),
    #[error("the result is not a closed, consistently oriented 2-manifold: {0}")]
    Topology(#[from] TopologyError),
}

/// A closed, oriented 2-manifold solid, mm. Immutable: every operation returns a new solid.
///
/// Each solid also remembers how it was made (a CSG tree of leaf meshes, booleans and
/// transforms, shared by reference), so that an independent kernel can redo the same booleans
/// (see [`csg_json`]).
#[derive(Clone)]
pub struct Solid {
    m: Manifold,
    csg: Arc<CsgNode>,
}

/// How a solid was built.
#[derive(Debug)]
pub enum CsgNode {
    Empty,
    Mesh(Mesh),
    Union(Vec<Arc<CsgNode>>),
    Difference(Arc<CsgNode>, Arc<CsgNode>),
    Intersection(Arc<CsgNode>, Arc<CsgNode>),
    Compose(Vec<Arc<CsgNode>>),
    Transform(Affine, Arc<CsgNode>),
    /// Keep the side of the plane n.x = offset that n points to (`positive`) or the other.
    SplitKeep {
        normal: [f64; 3],
        offset: f64,
        positive: bool,
        child: Arc<CsgNode>,
    },
}

/// sin and cos of an angle in degrees, exact at multiples of 90.
fn sincos_deg(d: f64) -> (f64, f64) {
    let r = d.rem_euclid(360.0);
    if r % 90.0 == 0.0 {
        match (r / 90.0) as i32 {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        d.to_radians().sin_cos()
    }
}

/// The rotation about x, then y, then z (degrees), as an affine map.
pub fn rotation_deg(x: f64, y: f64, z: f64) -> Affine {
    use nalgebra::Matrix3;
    let (sx, cx) = sincos_deg(x);
    let (sy, cy) = sincos_deg(y);
    let (sz, cz) = sincos_deg(z);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx);
    let ry = Matrix3::new(cy, 0.0, sy, 0.0, 1.0, 0.0, -sy, 0.0, cy);
    let rz = Matrix3::new(cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0);
    transform::with_translation(&(rz * (ry * rx)), [0.0; 3])
}

impl std::fmt::Debug for Solid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Solid")
            .field("triangles", &self.m.num_tri())
            .field("volume_mm3", &self.m.volume())
            .finish()
    }
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

impl Solid {
    fn wrap(m: Manifold, csg: CsgNode) -> Result<Self, GeometryError> {
        match m.status() {
            KernelStatus::NoError => Ok(Self {
                m,
                csg: Arc::new(csg),
            }),
            s => Err(GeometryError::Kernel(format!("{s:?}"))),
        }
    }

    /// The empty solid (identity of union).
    pub fn empty() -> Self {
        Self {
            m: Manifold::empty(),
            csg: Arc::new(CsgNode::Empty),
        }
    }

    /// How this solid was built.
    pub fn csg(&self) -> &Arc<CsgNode> {
        &self.csg
    }

    /// Imports a closed, consistently oriented triangle mesh.
    ///
    /// # Errors
    /// [`GeometryError::Topology`] when the mesh is open, non-manifold or inside-out, and
    /// [`GeometryError::Kernel`] when the kernel refuses it.
    pub fn from_mesh(mesh: &Mesh) -> Result<Self, GeometryError> {
        mesh.check_closed_manifold()?;
        let gl = MeshGLP::<f64, u32> {
            num_prop: 3,
            vert_properties: mesh.vertices.iter().flatten().copied().collect(),
            tri_verts: mesh.triangles.iter().flatten().copied().collect(),
            ..Default::default()
        };
        Self::wrap(Manifold::from_mesh_glp(&gl), CsgNode::Mesh(mesh.clone()))
    }

    /// The triangle mesh of this solid (shared vertices, outward winding).
    pub fn mesh(&self) -> Mesh {
        let gl = self.m.get_mesh_glp::<f64, u32>(0);
        let np = gl.num_prop as usize;
        Mesh {
            vertices: gl
                .vert_properties
                .chunks(np)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            triangles: gl.tri_verts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        }
    }

    /// Boolean union.
    ///
    /// # Errors
    /// [`GeometryError::Kernel`] if the kernel reports a failure.
    pub fn union(&self, other: &Solid) -> Result<Solid, GeometryError> {
        Self::wrap(
            self.m.union(&other.m),
            CsgNode::Union(vec![self.csg.clone(), other.csg.clone()]),
        )
    }

    /// Boolean difference `self - other`.
    ///
    /// # Errors
    /// As [`Solid::union`].
    pub fn difference(&self, other: &Solid) -> Result<Solid, GeometryError> {
        Self::wrap(
            self.m.difference(&other.m),
            CsgNode::Difference(self.csg.clone(), other.csg.clone()),
        )
    }

    /// Boolean intersection.
    ///
    /// # Errors
    /// As [`Solid::union`].
    pub fn intersection(&self, other: &Solid) -> Result<Solid, GeometryError> {
        Self::wrap(
            self.m.intersection(&other.m),
            CsgNode::Intersection(self.csg.clone(), other.csg.clone()),
        )
    }

    /// Union of many solids in one kernel call (balanced, much faster than a fold).
    ///
    /// # Errors
    /// As [`Solid::union`].
    pub fn union_all(parts: &[Solid]) -> Result<Solid, GeometryError> {
        if parts.is_empty() {
            return Ok(Solid::empty());
        }
        let ms: Vec<Manifold> = parts.iter().map(|s| s.m.clone()).collect();
        Self::wrap(
            Manifold::batch_boolean(&ms, manifold_rust::types::OpType::Add),
            CsgNode::Union(parts.iter().map(|s| s.csg.clone()).collect()),
        )
    }

    /// Puts solids that do not touch into one solid without any boolean work. The caller
    /// guarantees they are disjoint (use [`Solid::union_all`] otherwise).
    pub fn compose(parts: &[Solid]) -> Solid {
        let ms: Vec<Manifold> = parts.iter().map(|s| s.m.clone()).collect();
        Solid {
            m: Manifold::compose(&ms),
            csg: Arc::new(CsgNode::Compose(
                parts.iter().map(|s| s.csg.clone()).collect(),
            )),
        }
    }

    /// This solid under the affine map `a` (p' = R p + t).
    pub fn transform(&self, a: &Affine) -> Solid {
        let m = a.matrix();
        let col = |j: usize| Vec3::new(m[(0, j)], m[(1, j)], m[(2, j)]);
        let m = Mat3x4 {
            x: col(0),
            y: col(1),
            z: col(2),
            w: col(3),
        };
        Solid {
            m: self.m.transform(&m),
            csg: Arc::new(CsgNode::Transform(*a, self.csg.clone())),
        }
    }

    /// Translated by `d` mm.
    pub fn translate(&self, d: [f64; 3]) -> Solid {
        self.transform(&transform::translation(d))
    }

    /// Rotated about x, then y, then z, by the given angles in degrees (exact for multiples
    /// of 90 degrees).
    pub fn rotate_deg(&self, x: f64, y: f64, z: f64) -> Solid {
        self.transform(&rotation_deg(x, y, z))
    }

    /// The two parts on either side of the plane `n . x = offset` (`n` need not be unit):
    /// (the side `n` points to, the other side).
    pub fn split_by_plane(&self, n: [f64; 3], offset: f64) -> (Solid, Solid) {
        let (a, b) = self.m.split_by_plane(v3(n), offset);
        let node = |positive| {
            Arc::new(CsgNode::SplitKeep {
                normal: n,
                offset,
                positive,
                child: self.csg.clone(),
            })
        };
        (
            Solid {
                m: a,
                csg: node(true),
            },
            Solid {
                m: b,
                csg: node(false),
            },
        )
    }

    /// Enclosed volume, mm^3.
    pub fn volume(&self) -> f64 {
        self.m.volume()
    }

    /// Surface area, mm^2.
    pub fn surface_area(&self) -> f64 {
        self.m.surface_area()
    }

    /// Genus (number of handles) of the solid; a ball is 0, a ring 1.
    pub fn genus(&self) -> i32 {
        self.m.genus()
    }

    /// Whether the solid is empty.
    pub fn is_empty(&self) -> bool {
        self.m.is_empty()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.m.num_tri()
    }

    /// Bounding box, mm; `None` when empty.
    pub fn bounding_box(&self) -> Option<Aabb> {
        if self.is_empty() {
            return None;
        }
        let b = self.m.bounding_box();
        Some(Aabb {
            min: [b.min.x, b.min.y, b.min.z],
            max: [b.max.x, b.max.y, b.max.z],
        })
    }

    /// Number of disjoint shells.
    pub fn shell_count(&self) -> usize {
        self.m.decompose().len()
    }
}

/// The CSG trees of `parts` as one "fabkit-csg/1" JSON document (format in
/// `docs/csg-format.md`): nodes in topological order, shared subtrees written once.
pub fn csg_json(parts: &[(&str, &Solid)]) -> serde_json::Value {
    use serde_json::json;
    use std::collections::HashMap;
    fn visit(
        n: &Arc<CsgNode>,
        ids: &mut HashMap<*const CsgNode, usize>,
        out: &mut Vec<serde_json::Value>,
    ) -> usize {
        let key = Arc::as_ptr(n);
        if let Some(&id) = ids.get(&key) {
            return id;
        }
        let kids = |v: &[&Arc<CsgNode>],
                    ids: &mut HashMap<*const CsgNode, usize>,
                    out: &mut Vec<serde_json::Value>| {
            v.iter().map(|c| visit(c, ids, out)).collect::<Vec<_>>()
        };
        let node = match &**n {
            CsgNode::Empty => json!({"op": "union", "children": []}),
            CsgNode::Mesh(m) => {
                json!({"op": "mesh", "vertices": m.vertices, "triangles": m.triangles})
            }
            CsgNode::Union(c) => {
                json!({"op": "union", "children": kids(&c.iter().collect::<Vec<_>>(), ids, out)})
            }
            CsgNode::Compose(c) => {
                json!({"op": "compose", "children": kids(&c.iter().collect::<Vec<_>>(), ids, out)})
            }
            CsgNode::Difference(a, b) => {
                json!({"op": "difference", "children": kids(&[a, b], ids, out)})
            }
            CsgNode::Intersection(a, b) => {
                json!({"op": "intersection", "children": kids(&[a, b], ids, out)})
            }
            CsgNode::Transform(a, c) => {
                json!({"op": "transform", "matrix": transform::rows(a), "children": kids(&[c], ids, out)})
            }
            CsgNode::SplitKeep {
                normal,
                offset,
                positive,
                child,
            } => json!({
                "op": "split_keep", "normal": normal, "offset": offset,
                "side": if *positive { "positive" } else { "negative" },
                "children": kids(&[child], ids, out)}),
        };
        out.push(node);
        let id = out.len() - 1;
        ids.insert(key, id);
        id
    }
    let mut ids = HashMap::new();
    let mut nodes = Vec::new();
    let parts_json: Vec<_> = parts
        .iter()
        .map(|(name, s)| {
            let root = visit(&s.csg, &mut ids, &mut nodes);
            json!({"name": name, "root": root, "volume_mm3": s.volume(), "triangles": s.triangle_count()})
        })
        .collect();
    json!({"format": "fabkit-csg/1", "parts": parts_json, "nodes": nodes})
}
