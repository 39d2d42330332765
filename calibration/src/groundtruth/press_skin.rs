//! The skin of a flat design as a fitted sphere's press deforms it ([`crate::elastic`]): the
//! skin's layers taken as one elastic layer bonded to a rigid base, pressed by the sphere to
//! the fitted depth; the outer surface (in the contact the sphere's shape, round it sinking
//! smoothly back to the face) and the face the camera sees (under an opaque coat: 9DTact's
//! black layer) everywhere, sampled along the camera's rays.
//!
//! The model, and what it assumes (each said in press.json):
//! - the skin is the design's flat body, `thickness_mm` from its base plane to its contact
//!   face, bonded at the base plane to a rigid part: the window a flat housing seats (9DTact:
//!   3 mm acrylic, modulus about 3 GPa against the gel's 0.1 MPa, so rigid to 1e-4), or the
//!   plate the skin is cast on;
//! - its layers are one material (ASSUMPTION: the translucent gel and the coat have the same
//!   modulus; a coat stiffer than the gel spreads the dent wider);
//! - Poisson's ratio 0.5 (ASSUMPTION: silicone rubbers are incompressible to within 1e-3,
//!   their bulk modulus about 1 GPa against a shear modulus under 1 MPa); for a given depth
//!   the skin's shape does not depend on its modulus (linear elasticity), so none is needed;
//! - the sphere is rigid and frictionless, the strains small (a 4 mm ball 1.7 mm deep is not:
//!   large strains and friction widen the contact somewhat).

use nalgebra::Vector3;
use serde::Serialize;

use super::rays::PixelRays;
use super::SurfaceHits;
use crate::elastic::{
    influence_at_depth, sphere_heights, ContactError, ContactGrid, ContactSolver, Convolver, Skin,
};

/// Poisson's ratio of the skin (module docs).
pub const SKIN_POISSON: f64 = 0.5;
/// The grid's cell, mm, at most (finer for a thin skin: a quarter of its thickness).
pub const CELL_MM: f64 = 0.15;
/// Most cells a side.
pub const MAX_CELLS: usize = 320;

/// The skin of a flat design for the elastic contact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkinModel {
    /// From the base plane to the contact face, mm.
    pub thickness_mm: f64,
    pub poisson: f64,
    /// Depth under the contact face of the face the camera sees (the inner face of the
    /// outermost run of opaque layers; 0 when every layer is clear), mm.
    pub seen_depth_mm: f64,
    /// What the camera sees, in words.
    pub seen: String,
}

impl SkinModel {
    /// The skin of `design` (a flat body): its thickness, and the face the camera sees, the
    /// inner face of the first layer from the camera out whose material has no refractive
    /// index in `materials` (an opaque one). `None` for a design without a flat body.
    pub fn of(
        design: &fabkit_designs::Design,
        materials: &fabkit_designs::materials::MaterialsTable,
    ) -> Option<SkinModel> {
        design.body.flat_outline()?;
        // to a micrometre's thousandth: 2.8 - 2.5 is 0.3, not 0.29999999999999982
        let nm = |v: f64| (v * 1e9).round() / 1e9;
        let thickness_mm = nm(design.body.pole_z_mm(0.0) - design.body.base_z_mm());
        let mut seen_depth_mm = 0.0;
        let mut seen = "the contact face (every layer is clear)".to_string();
        let mut below = 0.0;
        for l in &design.layers {
            let clear = materials
                .get(&l.material)
                .is_some_and(|m| m.refractive_index.is_some());
            if !clear {
                seen_depth_mm = nm((thickness_mm - below).max(0.0));
                seen = format!("the inner face of the opaque layer {}", l.name);
                break;
            }
            below += l.thickness_mm.unwrap_or(0.0);
        }
        Some(SkinModel {
            thickness_mm,
            poisson: SKIN_POISSON,
            seen_depth_mm,
            seen,
        })
    }

    /// The elastic skin (the modulus only scales the load: 1 MPa).
    pub fn skin(&self) -> Skin {
        Skin::BondedLayer {
            young_mpa: 1.0,
            poisson: self.poisson,
            thickness_mm: self.thickness_mm,
        }
    }
}

/// A sphere's press solved on the skin: the displacement of the outer surface and of the seen
/// face on a grid centred under the sphere.
#[derive(Debug, Clone)]
pub struct PressedSkin {
    pub model: SkinModel,
    pub grid: ContactGrid,
    /// The grid's centre over the contact face (the sphere's centre), sensor frame x, y, mm.
    pub centre_mm: [f64; 2],
    /// The outer surface's displacement into the skin, per cell (row-major), mm.
    pub surface_mm: Vec<f64>,
    /// The seen face's displacement into the skin, per cell, mm.
    pub seen_mm: Vec<f64>,
    pub in_contact: Vec<bool>,
    /// The radius of a disc of the contact's area, mm.
    pub contact_radius_mm: f64,
    /// The sphere's radius, mm (0: other indenters), and the indenters' lowest point's depth
    /// under the contact face, mm.
    pub sphere_radius_mm: f64,
    pub depth_mm: f64,
}

/// Which face of a [`PressedSkin`] to sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Face {
    /// The outer surface (the contact face deformed).
    Surface,
    /// The face the camera sees ([`SkinModel::seen_depth_mm`] under the contact face).
    Seen,
}

impl PressedSkin {
    /// Solves the press of a sphere of `radius_mm` centred over `centre_mm`, its lowest point
    /// `depth_mm` below the contact face, on `model`'s skin: on the grid
    /// ([`PressedSkin::grid_for`]) reaching four thicknesses past the sphere's intersection
    /// with the face.
    ///
    /// # Errors
    /// [`ContactError`] of the solver (a depth that is not finite or negative).
    pub fn solve(
        model: &SkinModel,
        radius_mm: f64,
        centre_mm: [f64; 2],
        depth_mm: f64,
    ) -> Result<PressedSkin, ContactError> {
        let d = depth_mm.min(radius_mm);
        let a = (2.0 * radius_mm * d - d * d).max(0.0).sqrt();
        let grid = PressedSkin::grid_for(model, a + 4.0 * model.thickness_mm);
        let heights = sphere_heights(grid, radius_mm, 0.0, 0.0);
        let mut k = PressedSkin::solve_heights(model, grid, centre_mm, &heights, depth_mm)?;
        k.sphere_radius_mm = radius_mm;
        Ok(k)
    }

    /// The grid reaching `half_width_mm` from its centre each way, of cells of [`CELL_MM`] (a
    /// quarter of the thickness for a thin skin, at most the seen face's depth), at most
    /// [`MAX_CELLS`] a side (coarser cells past that).
    pub fn grid_for(model: &SkinModel, half_width_mm: f64) -> ContactGrid {
        let mut cell = CELL_MM.min(model.thickness_mm / 4.0);
        if model.seen_depth_mm > 0.0 {
            cell = cell.min(model.seen_depth_mm);
        }
        let mut n = (2.0 * half_width_mm / cell).ceil() as usize;
        if n > MAX_CELLS {
            n = MAX_CELLS;
            cell = 2.0 * half_width_mm / n as f64;
        }
        ContactGrid {
            n: n.max(8),
            cell_mm: cell,
        }
    }

    /// Solves the press of rigid indenters whose height above their lowest point at each cell
    /// of `grid` (centred over `centre_mm`) is `heights_mm`, pressed `depth_mm` into the skin
    /// (no sphere: [`PressedSkin::sample`] interpolates the surface in the contact too).
    ///
    /// # Errors
    /// [`ContactError`] of the solver.
    pub fn solve_heights(
        model: &SkinModel,
        grid: ContactGrid,
        centre_mm: [f64; 2],
        heights_mm: &[f64],
        depth_mm: f64,
    ) -> Result<PressedSkin, ContactError> {
        SkinSolver::new(model, grid)?.press(centre_mm, heights_mm, depth_mm)
    }

    /// The displacement of `face` into the skin at (x, y) over the contact face (sensor frame,
    /// mm) and its gradient: the outer surface in the contact is the sphere's exactly; elsewhere
    /// bilinear over the cells' centres (their gradients by central differences); 0 outside
    /// the grid.
    pub fn sample(&self, face: Face, x: f64, y: f64) -> (f64, [f64; 2]) {
        if face == Face::Surface && self.sphere_radius_mm > 0.0 && self.touching(x, y) {
            // in the contact the surface is the sphere's
            let (dx, dy) = (x - self.centre_mm[0], y - self.centre_mm[1]);
            let r = self.sphere_radius_mm;
            let root = (r * r - dx * dx - dy * dy).max(1e-12).sqrt();
            return (self.depth_mm - (r - root), [-dx / root, -dy / root]);
        }
        let n = self.grid.n;
        let c = self.grid.cell_mm;
        let field = match face {
            Face::Surface => &self.surface_mm,
            Face::Seen => &self.seen_mm,
        };
        let fi = (x - self.centre_mm[0]) / c + (n as f64 - 1.0) / 2.0;
        let fj = (y - self.centre_mm[1]) / c + (n as f64 - 1.0) / 2.0;
        if !(fi >= 0.0 && fj >= 0.0 && fi < (n - 1) as f64 && fj < (n - 1) as f64) {
            return (0.0, [0.0, 0.0]);
        }
        let (i0, j0) = (fi as usize, fj as usize);
        let (wx, wy) = (fi - i0 as f64, fj - j0 as f64);
        // the 4 x 4 cells round the point (clamped at the grid's edges), read once
        let col = |d: isize| (i0 as isize + d).clamp(0, n as isize - 1) as usize;
        let row = |d: isize| (j0 as isize + d).clamp(0, n as isize - 1) as usize;
        let (cols, rows) = (
            [col(-1), col(0), col(1), col(2)],
            [row(-1), row(0), row(1), row(2)],
        );
        let mut patch = [[0.0; 4]; 4];
        for (b, &j) in rows.iter().enumerate() {
            for (a, &i) in cols.iter().enumerate() {
                patch[b][a] = field[j * n + i];
            }
        }
        // the central differences at the corners (a, b) in 1..=2 of the patch (one-sided at
        // the grid's edges)
        let grad = |a: usize, b: usize| -> [f64; 2] {
            [
                (patch[b][a + 1] - patch[b][a - 1]) / ((cols[a + 1] - cols[a - 1]) as f64 * c),
                (patch[b + 1][a] - patch[b - 1][a]) / ((rows[b + 1] - rows[b - 1]) as f64 * c),
            ]
        };
        let (g00, g10, g01, g11) = (grad(1, 1), grad(2, 1), grad(1, 2), grad(2, 2));
        let mix = |v00: f64, v10: f64, v01: f64, v11: f64| {
            v00 * (1.0 - wx) * (1.0 - wy)
                + v10 * wx * (1.0 - wy)
                + v01 * (1.0 - wx) * wy
                + v11 * wx * wy
        };
        let u = mix(patch[1][1], patch[1][2], patch[2][1], patch[2][2]);
        let gx = mix(g00[0], g10[0], g01[0], g11[0]);
        let gy = mix(g00[1], g10[1], g01[1], g11[1]);
        (u, [gx, gy])
    }

    /// In contact at (x, y) (the nearest cell).
    pub fn touching(&self, x: f64, y: f64) -> bool {
        let n = self.grid.n;
        let c = self.grid.cell_mm;
        let fi = ((x - self.centre_mm[0]) / c + (n as f64 - 1.0) / 2.0).round();
        let fj = ((y - self.centre_mm[1]) / c + (n as f64 - 1.0) / 2.0).round();
        if !(fi >= 0.0 && fj >= 0.0 && fi < n as f64 && fj < n as f64) {
            return false;
        }
        self.in_contact[fj as usize * n + fi as usize]
    }

    /// The hits of the rays on `face` deformed, placed at the contact face `plane_z_mm` (the
    /// seen face's displacement applied to the contact face: the offset of the seen face is
    /// the same in the reference and the press, so the differences are the seen face's):
    /// where a ray's `reference` hit is on the contact face, the point where it meets
    /// `z = plane_z_mm - u(x, y)` (by fixed-point steps along the ray: the field's slope
    /// times the ray's obliquity is below 1), with the normal `(du/dx, du/dy, 1)` normalised
    /// (out of the skin); elsewhere the reference's hit.
    pub fn hits(
        &self,
        face: Face,
        rays: &PixelRays,
        reference: &SurfaceHits,
        plane_z_mm: f64,
    ) -> SurfaceHits {
        let mut h = reference.clone();
        for (p, d) in rays.dirs.iter().enumerate() {
            let t0 = reference.t_mm[p];
            if !t0.is_finite() || d[2].abs() < 1e-9 {
                continue;
            }
            let o = rays.origin(p);
            let on_face = ((o[2] + t0 * d[2]) - plane_z_mm).abs() < 1e-6;
            if !on_face {
                continue;
            }
            let mut t = t0;
            let mut u = (0.0, [0.0, 0.0]);
            for _ in 0..50 {
                let (x, y) = (o[0] + t * d[0], o[1] + t * d[1]);
                u = self.sample(face, x, y);
                let next = (plane_z_mm - u.0 - o[2]) / d[2];
                let step = (next - t).abs();
                t = next;
                if step < 1e-10 {
                    break;
                }
            }
            let (x, y) = (o[0] + t * d[0], o[1] + t * d[1]);
            let nrm = Vector3::new(u.1[0], u.1[1], 1.0).normalize();
            h.t_mm[p] = t;
            h.normal[p] = [nrm.x, nrm.y, nrm.z];
            h.contact[p] = self.touching(x, y);
            h.t_exit_mm[p] = t;
        }
        h
    }
}

/// The solver of a skin's presses on one grid: the contact's influence and the seen face's
/// transformed once ([`ContactSolver`], [`Convolver`]), for many presses of the same skin (a
/// seating's refinement, a capture's frames).
pub struct SkinSolver {
    model: SkinModel,
    contact: ContactSolver,
    /// The seen face's convolver (none when it is the surface: a seen depth under a cell).
    seen: Option<Convolver>,
}

impl SkinSolver {
    /// The solver of `model`'s skin on `grid`.
    ///
    /// # Errors
    /// [`ContactError`] of [`ContactSolver::new`]; a seen face not inside the layer.
    pub fn new(model: &SkinModel, grid: ContactGrid) -> Result<SkinSolver, ContactError> {
        let skin = model.skin();
        let contact = ContactSolver::new(grid, skin)?;
        let seen = if model.seen_depth_mm >= grid.cell_mm {
            if !(model.seen_depth_mm < model.thickness_mm) {
                return Err(ContactError::Value {
                    name: "depth_mm",
                    value: model.seen_depth_mm,
                    rule: "must be 0 or at least a cell, and inside the layer",
                });
            }
            Some(Convolver::new(
                grid.n,
                &influence_at_depth(grid, skin, model.seen_depth_mm),
            ))
        } else {
            None
        };
        Ok(SkinSolver {
            model: model.clone(),
            contact,
            seen,
        })
    }

    /// The grid.
    pub fn grid(&self) -> ContactGrid {
        self.contact.grid()
    }

    /// The press of rigid indenters whose height above their lowest point at each cell of the
    /// grid (centred over `centre_mm`) is `heights_mm`, pressed `depth_mm` into the skin (as
    /// [`PressedSkin::solve_heights`]).
    ///
    /// # Errors
    /// [`ContactError`] of the solver.
    pub fn press(
        &self,
        centre_mm: [f64; 2],
        heights_mm: &[f64],
        depth_mm: f64,
    ) -> Result<PressedSkin, ContactError> {
        let grid = self.grid();
        let contact = self.contact.solve(heights_mm, depth_mm)?;
        let seen_mm = match &self.seen {
            Some(c) => c.apply(&contact.pressure_mpa),
            None => contact.displacement_mm.clone(),
        };
        let cells = contact.in_contact.iter().filter(|&&c| c).count() as f64;
        Ok(PressedSkin {
            model: self.model.clone(),
            grid,
            centre_mm,
            contact_radius_mm: (cells * grid.cell_mm * grid.cell_mm / std::f64::consts::PI).sqrt(),
            surface_mm: contact.displacement_mm,
            seen_mm,
            in_contact: contact.in_contact,
            sphere_radius_mm: 0.0,
            depth_mm,
        })
    }
}
