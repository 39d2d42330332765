//! The undeformed sensor surface, intersected in closed form.
//!
//! The surface rendered is the outer surface of the skin, the body profile at offset 0
//! (`docs/conventions.md`, "The sensor frame"), from the pole down to the base plane
//! `z = z_base`. The camera looks at it from inside: the **sensor body** is the region inside
//! that surface, continued straight down below the base plane as a cylinder of the rim radius
//! (where the housing is). It is convex for every profile, so a ray from a camera inside it
//! leaves it exactly once; the ray hits the surface if it leaves above the base plane and
//! misses (it sees the housing) if it leaves below.

use fabkit_designs::primitives::dot;
use fabkit_designs::profile::BodyProfile;

/// The outer skin surface of one body profile, in closed form (sensor frame, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReferenceSurface {
    /// Sphere of `radius_mm` about the origin, for z >= `base_z_mm` (spherical cap).
    Cap { radius_mm: f64, base_z_mm: f64 },
    /// Sphere of `radius_mm` about the origin for z >= 0 on a cylinder of the same radius down
    /// to `base_z_mm` (R-Tac0, Sec. III-B1).
    HemisphereOnCylinder { radius_mm: f64, base_z_mm: f64 },
    /// Ellipsoid `(x^2 + y^2) / a^2 + z^2 / c^2 = 1` for z >= 0 (UVDtact).
    HalfEllipsoid { a_mm: f64, c_mm: f64 },
    /// A flat skin (Soter et al. Sec. II-A): the plane `z = top_z_mm` over a rounded
    /// rectangle (half sizes along x and y, corner radius) centred on the z axis; its side
    /// walls continue below the base plane z = 0 (docs/conventions.md, flat skins).
    Flat {
        half_width_mm: f64,
        half_length_mm: f64,
        corner_radius_mm: f64,
        top_z_mm: f64,
    },
}

/// A ray's exit from the sensor body: distance along the ray (mm), unit outward normal (sensor
/// frame), and whether the exit is on the skin (above the base plane) rather than below it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exit {
    pub t_mm: f64,
    pub normal: [f64; 3],
    pub on_skin: bool,
}

/// Far root of `a t^2 + 2 b t + c = 0` (a > 0), or None without real roots.
#[inline]
fn far_root(a: f64, b: f64, c: f64) -> Option<f64> {
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return None;
    }
    let s = disc.sqrt();
    // Stable form: the far root is (-b + s) / a; when b > 0 use c / (-b - s).
    Some(if b <= 0.0 { (-b + s) / a } else { c / (-b - s) })
}

impl ReferenceSurface {
    /// The outer skin surface (offset 0) of `body`. Always `Some` for the profiles there are;
    /// `None` is kept for a profile without a reference surface.
    pub fn of(body: &BodyProfile) -> Option<ReferenceSurface> {
        Some(match *body {
            BodyProfile::SphericalCap { .. } => ReferenceSurface::Cap {
                radius_mm: body.sphere_radius_mm().unwrap_or(0.0),
                base_z_mm: body.base_z_mm(),
            },
            BodyProfile::HemisphereOnCylinder { radius_mm, .. } => {
                ReferenceSurface::HemisphereOnCylinder {
                    radius_mm,
                    base_z_mm: body.base_z_mm(),
                }
            }
            BodyProfile::HalfEllipsoid {
                diameter_mm,
                height_mm,
            } => ReferenceSurface::HalfEllipsoid {
                a_mm: diameter_mm / 2.0,
                c_mm: height_mm,
            },
            BodyProfile::Flat {
                width_mm,
                length_mm,
                corner_radius_mm,
                thickness_mm,
            } => ReferenceSurface::Flat {
                half_width_mm: width_mm / 2.0,
                half_length_mm: length_mm / 2.0,
                corner_radius_mm,
                top_z_mm: thickness_mm,
            },
        })
    }

    /// The outer skin surface of `design`: [`ReferenceSurface::of`] its body, where a flat
    /// skin's outline is its outermost layer's (`layers[i].wrap_mm` grows it: 9DTact's black gel
    /// wraps the translucent gel's sides, its contact face 31.1 x 24.1 mm R1.8 over the body's
    /// 29.5 x 22.5 mm R1.0), so that the ground truth ranges to the face the assembly and the
    /// molds give the skin.
    pub fn of_design(design: &fabkit_designs::Design) -> Option<ReferenceSurface> {
        let mut surface = ReferenceSurface::of(&design.body)?;
        if let ReferenceSurface::Flat {
            half_width_mm,
            half_length_mm,
            corner_radius_mm,
            ..
        } = &mut surface
        {
            let layers = fabkit_designs::stack::flat::flat_layers(design).unwrap_or_default();
            if let Some(outer) = layers.last() {
                *half_width_mm = outer.outline.width_mm / 2.0;
                *half_length_mm = outer.outline.length_mm / 2.0;
                *corner_radius_mm = outer.outline.corner_radius_mm;
            }
        }
        Some(surface)
    }

    /// z of the base plane, mm.
    pub fn base_z_mm(&self) -> f64 {
        match *self {
            ReferenceSurface::Cap { base_z_mm, .. }
            | ReferenceSurface::HemisphereOnCylinder { base_z_mm, .. } => base_z_mm,
            ReferenceSurface::HalfEllipsoid { .. } | ReferenceSurface::Flat { .. } => 0.0,
        }
    }

    /// Radius of the rim (where the skin meets the base plane), mm.
    pub fn rim_radius_mm(&self) -> f64 {
        match *self {
            ReferenceSurface::Cap {
                radius_mm,
                base_z_mm,
            } => (radius_mm * radius_mm - base_z_mm * base_z_mm)
                .max(0.0)
                .sqrt(),
            ReferenceSurface::HemisphereOnCylinder { radius_mm, .. } => radius_mm,
            ReferenceSurface::HalfEllipsoid { a_mm, .. } => a_mm,
            // the largest circle inside the outline
            ReferenceSurface::Flat {
                half_width_mm,
                half_length_mm,
                ..
            } => half_width_mm.min(half_length_mm),
        }
    }

    /// A flat skin's outline: distance from (x, y) to its edge (negative outside) and the
    /// outward unit normal of the nearest edge point, in the xy plane.
    fn flat_inset(hw: f64, hl: f64, r: f64, x: f64, y: f64) -> (f64, [f64; 2]) {
        let (dx, dy) = (x.abs() - (hw - r), y.abs() - (hl - r));
        if dx > 0.0 && dy > 0.0 {
            let l = dx.hypot(dy);
            (r - l, [dx / l * x.signum(), dy / l * y.signum()])
        } else if hw - x.abs() <= hl - y.abs() {
            (hw - x.abs(), [x.signum(), 0.0])
        } else {
            (hl - y.abs(), [0.0, y.signum()])
        }
    }

    /// Whether `p` (sensor frame, mm) is strictly inside the sensor body (see the module
    /// documentation), with a margin of `margin_mm`.
    pub fn contains(&self, p: [f64; 3], margin_mm: f64) -> bool {
        if let ReferenceSurface::Flat {
            half_width_mm,
            half_length_mm,
            corner_radius_mm,
            top_z_mm,
        } = *self
        {
            let (inset, _) =
                Self::flat_inset(half_width_mm, half_length_mm, corner_radius_mm, p[0], p[1]);
            return inset > margin_mm && p[2] < top_z_mm - margin_mm;
        }
        let rho = p[0].hypot(p[1]);
        let zb = self.base_z_mm();
        if p[2] < zb {
            return rho < self.rim_radius_mm() - margin_mm;
        }
        match *self {
            ReferenceSurface::Cap { radius_mm, .. } => dot(p, p).sqrt() < radius_mm - margin_mm,
            ReferenceSurface::HemisphereOnCylinder { radius_mm, .. } => {
                if p[2] <= 0.0 {
                    rho < radius_mm - margin_mm
                } else {
                    dot(p, p).sqrt() < radius_mm - margin_mm
                }
            }
            ReferenceSurface::HalfEllipsoid { a_mm, c_mm } => {
                let (a, c) = (a_mm - margin_mm, c_mm - margin_mm);
                a > 0.0 && c > 0.0 && (rho / a).powi(2) + (p[2] / c).powi(2) < 1.0
            }
            ReferenceSurface::Flat { .. } => unreachable!("handled above"),
        }
    }

    /// Where the ray `o + t d` (o inside the sensor body, d a unit vector; sensor frame, mm)
    /// leaves the sensor body. `None` only for a non-finite direction.
    #[inline]
    pub fn exit(&self, o: [f64; 3], d: [f64; 3]) -> Option<Exit> {
        if !(d[0].is_finite() && d[1].is_finite() && d[2].is_finite()) {
            return None;
        }
        let zb = self.base_z_mm();
        let at = |t: f64| [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        // The vertical wall below the base plane (and the cylinder of R-Tac0): r = radius.
        let wall = |radius: f64| -> Option<(f64, [f64; 3])> {
            let a = d[0] * d[0] + d[1] * d[1];
            if !(a > 0.0) {
                return None;
            }
            let b = o[0] * d[0] + o[1] * d[1];
            let c = o[0] * o[0] + o[1] * o[1] - radius * radius;
            let t = far_root(a, b, c)?;
            let p = at(t);
            Some((t, [p[0] / radius, p[1] / radius, 0.0]))
        };
        let below = |rim: f64| -> Option<Exit> {
            // Leaves through the wall below the base plane (or, straight down, never: report
            // the base plane itself as a miss).
            match wall(rim) {
                Some((t, n)) => Some(Exit {
                    t_mm: t,
                    normal: n,
                    on_skin: false,
                }),
                None => Some(Exit {
                    t_mm: f64::INFINITY,
                    normal: [0.0, 0.0, -1.0],
                    on_skin: false,
                }),
            }
        };
        match *self {
            ReferenceSurface::Cap { radius_mm, .. } => {
                let b = dot(o, d);
                let c = dot(o, o) - radius_mm * radius_mm;
                if let Some(t) = far_root(1.0, b, c) {
                    let p = at(t);
                    if p[2] >= zb {
                        let r = radius_mm;
                        return Some(Exit {
                            t_mm: t,
                            normal: [p[0] / r, p[1] / r, p[2] / r],
                            on_skin: true,
                        });
                    }
                }
                below(self.rim_radius_mm())
            }
            ReferenceSurface::HemisphereOnCylinder { radius_mm, .. } => {
                let b = dot(o, d);
                let c = dot(o, o) - radius_mm * radius_mm;
                if let Some(t) = far_root(1.0, b, c) {
                    let p = at(t);
                    if p[2] >= 0.0 {
                        let r = radius_mm;
                        return Some(Exit {
                            t_mm: t,
                            normal: [p[0] / r, p[1] / r, p[2] / r],
                            on_skin: true,
                        });
                    }
                }
                match wall(radius_mm) {
                    Some((t, n)) => Some(Exit {
                        t_mm: t,
                        normal: n,
                        on_skin: at(t)[2] >= zb,
                    }),
                    None => below(radius_mm),
                }
            }
            ReferenceSurface::HalfEllipsoid { a_mm, c_mm } => {
                let (ia, ic) = (1.0 / (a_mm * a_mm), 1.0 / (c_mm * c_mm));
                let qa = (d[0] * d[0] + d[1] * d[1]) * ia + d[2] * d[2] * ic;
                let qb = (o[0] * d[0] + o[1] * d[1]) * ia + o[2] * d[2] * ic;
                let qc = (o[0] * o[0] + o[1] * o[1]) * ia + o[2] * o[2] * ic - 1.0;
                if let Some(t) = far_root(qa, qb, qc) {
                    let p = at(t);
                    if p[2] >= 0.0 {
                        let g = [p[0] * ia, p[1] * ia, p[2] * ic];
                        let l = dot(g, g).sqrt();
                        return Some(Exit {
                            t_mm: t,
                            normal: [g[0] / l, g[1] / l, g[2] / l],
                            on_skin: true,
                        });
                    }
                }
                below(a_mm)
            }
            ReferenceSurface::Flat {
                half_width_mm: hw,
                half_length_mm: hl,
                corner_radius_mm: r,
                top_z_mm,
            } => {
                // the contact face
                if d[2] > 0.0 {
                    let t = (top_z_mm - o[2]) / d[2];
                    let p = at(t);
                    if Self::flat_inset(hw, hl, r, p[0], p[1]).0 >= 0.0 {
                        return Some(Exit {
                            t_mm: t,
                            normal: [0.0, 0.0, 1.0],
                            on_skin: true,
                        });
                    }
                }
                // the side walls: the far end of the ray's chord through the outline's prism
                let (ax, ay) = (d[0], d[1]);
                if !(ax * ax + ay * ay > 0.0) {
                    return Some(Exit {
                        t_mm: f64::INFINITY,
                        normal: [0.0, 0.0, -1.0],
                        on_skin: false,
                    });
                }
                let mut t = f64::INFINITY;
                for (dd, oo, h) in [(ax, o[0], hw), (ay, o[1], hl)] {
                    if dd != 0.0 {
                        t = t.min((h * dd.signum() - oo) / dd);
                    }
                }
                let p = at(t);
                let (cx, cy) = (hw - r, hl - r);
                let t = if r > 0.0 && p[0].abs() > cx && p[1].abs() > cy {
                    // past a straight edge's end: the corner's circle (the far root)
                    let (ccx, ccy) = (cx * p[0].signum(), cy * p[1].signum());
                    let a = ax * ax + ay * ay;
                    let b = (o[0] - ccx) * ax + (o[1] - ccy) * ay;
                    let c = (o[0] - ccx).powi(2) + (o[1] - ccy).powi(2) - r * r;
                    far_root(a, b, c).unwrap_or(t)
                } else {
                    t
                };
                let p = at(t);
                let (_, n) = Self::flat_inset(hw, hl, r, p[0], p[1]);
                Some(Exit {
                    t_mm: t,
                    normal: [n[0], n[1], 0.0],
                    on_skin: p[2] >= 0.0,
                })
            }
        }
    }
}

impl ReferenceSurface {
    /// [`exit`](Self::exit) for every direction of `dirs` from `o`: writes the exit distance
    /// (`t_exit_mm`, NaN for a non-finite direction), the skin hit distance (`t_skin_mm`, NaN
    /// where the ray leaves below the base plane) and, if given, the skin normal (written only
    /// on a skin hit). The common case (the spherical part) is one branch-free pass over the
    /// rays; the rays that leave elsewhere are redone with [`exit`](Self::exit).
    ///
    /// # Panics
    /// If the output slices are not as long as `dirs`.
    pub fn exit_all(
        &self,
        o: [f64; 3],
        dirs: &[[f64; 3]],
        t_exit_mm: &mut [f64],
        t_skin_mm: &mut [f64],
        mut normal: Option<&mut [[f64; 3]]>,
    ) {
        assert!(t_exit_mm.len() == dirs.len() && t_skin_mm.len() == dirs.len());
        assert!(normal.as_ref().is_none_or(|n| n.len() == dirs.len()));
        let slow = |p: usize,
                    t_exit_mm: &mut [f64],
                    t_skin_mm: &mut [f64],
                    normal: &mut Option<&mut [[f64; 3]]>| {
            let e = self.exit(o, dirs[p]);
            t_exit_mm[p] = e.map_or(f64::NAN, |e| e.t_mm);
            t_skin_mm[p] = match e {
                Some(e) if e.on_skin => {
                    if let Some(n) = normal.as_deref_mut() {
                        n[p] = e.normal;
                    }
                    e.t_mm
                }
                _ => f64::NAN,
            };
        };
        // Sphere radius, base plane, radius of the wall below (the rim; R-Tac0's cylinder
        // starts at z = 0), and where the sphere stops being the surface.
        let (r, zb, rw, zs) = match *self {
            ReferenceSurface::Cap {
                radius_mm,
                base_z_mm,
            } => (radius_mm, base_z_mm, self.rim_radius_mm(), base_z_mm),
            ReferenceSurface::HemisphereOnCylinder {
                radius_mm,
                base_z_mm,
            } => (radius_mm, base_z_mm, radius_mm, 0.0),
            ReferenceSurface::HalfEllipsoid { .. } | ReferenceSurface::Flat { .. } => {
                for p in 0..dirs.len() {
                    slow(p, t_exit_mm, t_skin_mm, &mut normal);
                }
                return;
            }
        };
        let c = dot(o, o) - r * r;
        let cw = o[0] * o[0] + o[1] * o[1] - rw * rw;
        // Pass 1, branch-free: the far roots of the sphere and of the wall (o inside both:
        // c, cw < 0, the roots are real and positive). With the camera well inside (c, cw
        // below -1 % of the radius squared) s - b loses at most a few ulp; otherwise, and for
        // rays the pass cannot decide (NaN: a non-finite or vertical direction), pass 2 uses
        // [`exit`](Self::exit).
        let well_inside = c < -0.01 * r * r && cw < -0.01 * rw * rw;
        if well_inside {
            for (p, d) in dirs.iter().enumerate() {
                let b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
                let ts = (b * b - c).sqrt() - b;
                let z_s = o[2] + ts * d[2];
                let aw = d[0] * d[0] + d[1] * d[1];
                let bw = o[0] * d[0] + o[1] * d[1];
                let tw = ((bw * bw - aw * cw).sqrt() - bw) / aw;
                let z_w = o[2] + tw * d[2];
                let on_sphere = z_s >= zs;
                let exit = if on_sphere { ts } else { tw };
                let skin = if on_sphere {
                    ts
                } else if z_w >= zb {
                    tw
                } else {
                    f64::NAN
                };
                t_exit_mm[p] = if exit.is_finite() { exit } else { f64::NAN };
                t_skin_mm[p] = skin;
            }
        } else {
            t_exit_mm.fill(f64::NAN);
        }
        // Pass 2: the undecided rays, and the normals.
        let (inv_r, inv_rw) = (1.0 / r, 1.0 / rw);
        for p in 0..dirs.len() {
            if t_exit_mm[p].is_nan() {
                slow(p, t_exit_mm, t_skin_mm, &mut normal);
                continue;
            }
            let t = t_skin_mm[p];
            if let (Some(n), true) = (normal.as_deref_mut(), t.is_finite()) {
                let d = dirs[p];
                let q = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
                n[p] = if q[2] >= zs {
                    [q[0] * inv_r, q[1] * inv_r, q[2] * inv_r]
                } else {
                    [q[0] * inv_rw, q[1] * inv_rw, 0.0]
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rtac0_rays_leave_through_sphere_cylinder_and_below_the_base() {
        let s = ReferenceSurface::HemisphereOnCylinder {
            radius_mm: 15.0,
            base_z_mm: -6.0,
        };
        let o = [0.0, 0.0, -10.0];
        assert!(s.contains(o, 0.0));
        // Straight up: the pole.
        let e = s.exit(o, [0.0, 0.0, 1.0]).unwrap();
        assert!((e.t_mm - 25.0).abs() < 1e-12 && e.on_skin);
        // Sideways: the wall below the base plane, a miss.
        let e = s.exit(o, [1.0, 0.0, 0.0]).unwrap();
        assert!((e.t_mm - 15.0).abs() < 1e-12 && !e.on_skin);
        // Up at 45 deg: the cylinder at z = -10 + 15.0 = 5.0 > 0, so the sphere.
        let q = std::f64::consts::FRAC_1_SQRT_2;
        let e = s.exit(o, [q, 0.0, q]).unwrap();
        let p = [e.t_mm * q, 0.0, -10.0 + e.t_mm * q];
        assert!((dot(p, p).sqrt() - 15.0).abs() < 1e-12 && p[2] > 0.0);
    }

    /// A flat skin 80 x 80 mm with 5 mm corners, its face 5 mm up: straight up through the
    /// face, sideways through a wall below the base plane (a miss), along the diagonal through
    /// the corner's arc (35 sqrt 2 + 5 mm out, normal along the diagonal), and up at 45 deg
    /// through the face.
    #[test]
    fn flat_rays_leave_through_face_walls_and_corner_arcs() {
        let s = ReferenceSurface::Flat {
            half_width_mm: 40.0,
            half_length_mm: 40.0,
            corner_radius_mm: 5.0,
            top_z_mm: 5.0,
        };
        let e = s.exit([0.0, 0.0, -10.0], [0.0, 0.0, 1.0]).unwrap();
        assert!((e.t_mm - 15.0).abs() < 1e-12 && e.on_skin && e.normal == [0.0, 0.0, 1.0]);
        let e = s.exit([0.0, 0.0, -10.0], [1.0, 0.0, 0.0]).unwrap();
        assert!((e.t_mm - 40.0).abs() < 1e-12 && !e.on_skin && e.normal == [1.0, 0.0, 0.0]);
        let q = std::f64::consts::FRAC_1_SQRT_2;
        let e = s.exit([0.0, 0.0, 2.0], [q, q, 0.0]).unwrap();
        assert!((e.t_mm - (35.0 * 2f64.sqrt() + 5.0)).abs() < 1e-9, "{e:?}");
        assert!(e.on_skin && (e.normal[0] - q).abs() < 1e-12 && (e.normal[1] - q).abs() < 1e-12);
        let e = s.exit([0.0, 0.0, 0.0], [q, 0.0, q]).unwrap();
        assert!((e.t_mm - 5.0 * 2f64.sqrt()).abs() < 1e-12 && e.on_skin);
        assert!(s.contains([39.0, 0.0, -50.0], 0.5) && !s.contains([39.0, 39.0, 0.0], 0.0));
        assert!(!s.contains([0.0, 0.0, 5.0], 0.0));
    }

    /// The branch-free pass agrees with the per-ray exit for every profile, camera well inside
    /// and near the surface, over directions in all of space.
    #[test]
    fn exit_all_agrees_with_exit() {
        let surfaces = [
            ReferenceSurface::HemisphereOnCylinder {
                radius_mm: 15.1,
                base_z_mm: -6.0,
            },
            ReferenceSurface::Cap {
                radius_mm: 23.1,
                base_z_mm: 15.1,
            },
            ReferenceSurface::HalfEllipsoid {
                a_mm: 9.0,
                c_mm: 24.0,
            },
            ReferenceSurface::Flat {
                half_width_mm: 40.0,
                half_length_mm: 30.0,
                corner_radius_mm: 5.0,
                top_z_mm: 5.0,
            },
        ];
        let dirs: Vec<[f64; 3]> = (0..2000)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / 2000.0;
                let a = i as f64 * 2.399_963;
                let s = (1.0 - z * z).sqrt();
                [s * a.cos(), s * a.sin(), z]
            })
            .chain([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [f64::NAN; 3]])
            .collect();
        for s in surfaces {
            for o in [
                [0.3, -0.2, s.base_z_mm() - 4.0],
                [0.0, 0.0, s.base_z_mm() + 0.5],
                [s.rim_radius_mm() - 0.05, 0.0, s.base_z_mm() - 1.0],
            ] {
                assert!(s.contains(o, 0.0), "{s:?} {o:?}");
                let n = dirs.len();
                let (mut te, mut ts, mut nn) = (vec![0.0; n], vec![0.0; n], vec![[9.0; 3]; n]);
                s.exit_all(o, &dirs, &mut te, &mut ts, Some(&mut nn));
                for (p, d) in dirs.iter().enumerate() {
                    match s.exit(o, *d) {
                        None => assert!(te[p].is_nan() && ts[p].is_nan()),
                        Some(e) => {
                            let close = |a: f64, b: f64| {
                                a == b || (a - b).abs() <= 1e-12 * b.abs().max(1.0)
                            };
                            assert!(
                                close(te[p], e.t_mm),
                                "{s:?} {o:?} {d:?}: exit {} vs {}",
                                te[p],
                                e.t_mm
                            );
                            if e.on_skin {
                                assert!(close(ts[p], e.t_mm));
                                assert!(
                                    (0..3).all(|k| (nn[p][k] - e.normal[k]).abs() < 1e-12),
                                    "{:?} vs {:?}",
                                    nn[p],
                                    e.normal
                                );
                            } else {
                                assert!(ts[p].is_nan());
                            }
                        }
                    }
                }
            }
        }
    }
}
