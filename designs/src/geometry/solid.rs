//! [`Solid`]: our own handle on the boolean kernel (`manifold-rust`), so that the kernel can be
//! swapped without touching the part code.

use super::{Aabb, Mesh, TopologyError};
use manifold_rust::linalg::Vec3;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error as KernelStatus, MeshGLP};

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
#[derive(Clone)]
pub struct Solid {
    m: Manifold,
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
    fn wrap(m: Manifold) -> Result<Self, GeometryError> {
        match m.status() {
            KernelStatus::NoError => Ok(Self { m }),
            s => Err(GeometryError::Kernel(format!("{s:?}"))),
        }
    }

    /// The empty solid (identity of union).
    pub fn empty() -> Self {
        Self { m: Manifold::empty() }
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
        Self::wrap(Manifold::from_mesh_glp(&gl))
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
        Self::wrap(self.m.union(&other.m))
    }

    /// Boolean difference `self - other`.
    ///
    /// # Errors
    /// As [`Solid::union`].
    pub fn difference(&self, other: &Solid) -> Result<Solid, GeometryError> {
        Self::wrap(self.m.difference(&other.m))
    }

    /// Boolean intersection.
    ///
    /// # Errors
    /// As [`Solid::union`].
    pub fn intersection(&self, other: &Solid) -> Result<Solid, GeometryError> {
        Self::wrap(self.m.intersection(&other.m))
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
        Self::wrap(Manifold::batch_boolean(&ms, manifold_rust::types::OpType::Add))
    }

    /// Puts solids that do not touch into one solid without any boolean work. The caller
    /// guarantees they are disjoint (use [`Solid::union_all`] otherwise).
    pub fn compose(parts: &[Solid]) -> Solid {
        let ms: Vec<Manifold> = parts.iter().map(|s| s.m.clone()).collect();
        Solid { m: Manifold::compose(&ms) }
    }

    /// Translated by `d` mm.
    pub fn translate(&self, d: [f64; 3]) -> Solid {
        Solid { m: self.m.translate(v3(d)) }
    }

    /// Rotated about x, then y, then z, by the given angles in degrees (exact for multiples
    /// of 90 degrees).
    pub fn rotate_deg(&self, x: f64, y: f64, z: f64) -> Solid {
        Solid { m: self.m.rotate(x, y, z) }
    }

    /// Mirrored through the plane through the origin with normal `n`.
    pub fn mirror(&self, n: [f64; 3]) -> Solid {
        Solid { m: self.m.mirror(v3(n)) }
    }

    /// Scaled about the origin.
    pub fn scale(&self, s: [f64; 3]) -> Solid {
        Solid { m: self.m.scale(v3(s)) }
    }

    /// The two parts on either side of the plane `n . x = offset` (`n` need not be unit):
    /// (the side `n` points to, the other side).
    pub fn split_by_plane(&self, n: [f64; 3], offset: f64) -> (Solid, Solid) {
        let (a, b) = self.m.split_by_plane(v3(n), offset);
        (Solid { m: a }, Solid { m: b })
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
