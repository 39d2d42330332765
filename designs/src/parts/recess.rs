//! The seat of an optic under a solid skin (`layers[0].recess`): a recess open on the base
//! plane whose roof is a spherical cap seen from the base, on a cone that narrows upward by
//! its draft, the edge between them rounded by a fillet. The DIGIT Pinki gel carries one
//! (facebookresearch/digit-design, `DIGIT_Pinki/gel/Pinki Gel.step`: cap R7.4389, cone of
//! 2 deg, fillet R0.25); its mold's insert is the same solid
//! ([`crate::parts::layers`], `open` strategy).
//!
//! Frame: the sensor frame (docs/conventions.md). The recess is a solid of revolution about
//! the z axis; its heights `h` are measured up from the base plane (`z = base_z + h`).

use crate::error::ParamError;
use crate::geometry::profile2d::{point_segment_distance, push_arc};
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use crate::schema::{Design, LayerProcess, MoldStrategy};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The largest draft of the recess's cone, degrees (exclusive).
pub const MAX_DRAFT_DEG: f64 = 45.0;

/// The recess under a solid skin, open on the base plane (the seat of the optic the camera
/// looks through). All lengths mm, angles degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Recess {
    /// Diameter of the recess's mouth on the base plane, mm, > 0: below the skin's diameter
    /// there.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub base_diameter_mm: f64,
    /// Height of the roof's apex over the base plane, on the axis, mm, > 0: below the skin's
    /// height.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub depth_mm: f64,
    /// Radius of the roof's sphere (its centre on the axis, `cap_radius_mm` under the apex),
    /// mm, > 0: large enough that the sphere holds the mouth's edge, and the roof meets the
    /// cone on the sphere's upper half (no undercut that would lock the insert in the skin).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cap_radius_mm: f64,
    /// Draft of the wall from the axis direction, degrees, in [0, 45): the wall narrows from
    /// the mouth upward, so that the insert that forms it pulls out downward.
    #[serde(default)]
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 45))]
    pub draft_angle_deg: f64,
    /// Radius of the fillet between the wall and the roof, mm, >= 0 (0: a sharp edge); it
    /// must touch the wall above the base plane.
    #[serde(default)]
    #[schemars(extend("minimum" = 0))]
    pub fillet_radius_mm: f64,
}

/// The resolved outline of a [`Recess`] in the (r, h) half-plane, h up from the base plane,
/// mm: the wall from the mouth `(mouth_radius_mm, 0)` up to `wall_top`, the fillet arc (centre
/// `fillet_centre`, radius `fillet_radius_mm`) from `wall_top` to `roof_edge`, and the roof's
/// arc (centre `(0, cap_centre_h_mm)`, radius `cap_radius_mm`) from `roof_edge` to the apex
/// `(0, depth_mm)`. Without a fillet, `wall_top == roof_edge == fillet_centre`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RecessOutline {
    pub mouth_radius_mm: f64,
    pub depth_mm: f64,
    pub cap_radius_mm: f64,
    pub cap_centre_h_mm: f64,
    pub draft_angle_deg: f64,
    pub fillet_radius_mm: f64,
    pub fillet_centre: [f64; 2],
    pub wall_top: [f64; 2],
    pub roof_edge: [f64; 2],
}

impl Recess {
    /// The recess's outline, or the field and the rule its sizes break together (for
    /// [`check_recess`], which checks each size on its own first: above 0, the draft in
    /// [0, 45) degrees).
    pub fn outline(&self) -> Result<RecessOutline, (&'static str, String)> {
        let r0 = self.base_diameter_mm / 2.0;
        let (d, cap, rf) = (self.depth_mm, self.cap_radius_mm, self.fillet_radius_mm);
        let a = self.draft_angle_deg.to_radians();
        let (t, c, s) = (a.tan(), a.cos(), a.sin());
        let hs = d - cap;
        // the sphere through the apex must hold the mouth's edge
        if r0 * r0 + hs * hs >= cap * cap {
            let least = (r0 * r0 + d * d) / (2.0 * d);
            return Err((
                "cap_radius_mm",
                format!(
                    "must exceed (r^2 + depth^2) / (2 depth) = {least:.4} mm (r: the mouth's radius) so that the roof meets the wall above the base plane"
                ),
            ));
        }
        // Where a circle of radius `cap - k` about the sphere's centre meets the wall moved
        // in by `k` (its larger height): the wall's top (k = 0) or the fillet's centre (k = rf).
        let meet = |k: f64| -> Option<f64> {
            let a0 = r0 - k / c;
            let rr = cap - k;
            let qa = 1.0 + t * t;
            let qb = -2.0 * (a0 * t + hs);
            let qc = a0 * a0 + hs * hs - rr * rr;
            let disc = qb * qb - 4.0 * qa * qc;
            (disc >= 0.0).then(|| (-qb + disc.sqrt()) / (2.0 * qa))
        };
        let Some(h_meet) = meet(0.0) else {
            return Err((
                "cap_radius_mm",
                "the roof's sphere does not meet the wall".into(),
            ));
        };
        if h_meet < hs {
            return Err((
                "cap_radius_mm",
                format!(
                    "the roof must meet the wall on its sphere's upper half (here {h_meet:.4} mm over the base plane, the sphere's centre at {hs:.4} mm): an undercut would lock the insert in the skin"
                ),
            ));
        }
        if rf == 0.0 {
            let p = [r0 - h_meet * t, h_meet];
            return Ok(self.resolved(p, p, p, hs));
        }
        if rf >= cap {
            return Err((
                "fillet_radius_mm",
                format!("must be below cap_radius_mm ({cap})"),
            ));
        }
        let Some(hc) = meet(rf) else {
            return Err((
                "fillet_radius_mm",
                "too large: no fillet touches both the wall and the roof".into(),
            ));
        };
        let centre = [r0 - hc * t - rf / c, hc];
        let wall_top = [centre[0] + rf * c, centre[1] + rf * s];
        let (dr, dh) = (centre[0], centre[1] - hs);
        let len = dr.hypot(dh);
        let roof_edge = [dr / len * cap, hs + dh / len * cap];
        if !(centre[0] > 0.0 && wall_top[1] >= 0.0 && roof_edge[1] >= wall_top[1] && dh >= 0.0) {
            return Err((
                "fillet_radius_mm",
                "too large: the fillet must touch the wall above the base plane and the roof on its sphere's upper half".into(),
            ));
        }
        Ok(self.resolved(centre, wall_top, roof_edge, hs))
    }

    fn resolved(
        &self,
        fillet_centre: [f64; 2],
        wall_top: [f64; 2],
        roof_edge: [f64; 2],
        cap_centre_h_mm: f64,
    ) -> RecessOutline {
        RecessOutline {
            mouth_radius_mm: self.base_diameter_mm / 2.0,
            depth_mm: self.depth_mm,
            cap_radius_mm: self.cap_radius_mm,
            cap_centre_h_mm,
            draft_angle_deg: self.draft_angle_deg,
            fillet_radius_mm: self.fillet_radius_mm,
            fillet_centre,
            wall_top,
            roof_edge,
        }
    }
}

impl RecessOutline {
    /// The recess's surface as an (r, z) polyline from the apex `(0, base_z + depth)` down
    /// the roof, the fillet and the wall to the mouth `(r, base_z)`, continued straight down
    /// `below_base_mm` (the wall's line) when above 0; arcs within `tol` of the true surface.
    pub fn polyline(&self, base_z_mm: f64, below_base_mm: f64, tol: ChordTolerance) -> Polyline2 {
        let mut pl = Polyline2::default();
        let cap_c = [0.0, base_z_mm + self.cap_centre_h_mm];
        let edge = [self.roof_edge[0], base_z_mm + self.roof_edge[1]];
        let a_edge = (edge[1] - cap_c[1]).atan2(edge[0]);
        push_arc(
            &mut pl,
            cap_c,
            self.cap_radius_mm,
            std::f64::consts::FRAC_PI_2,
            a_edge,
            tol,
        );
        if self.fillet_radius_mm > 0.0 {
            let fc = [self.fillet_centre[0], base_z_mm + self.fillet_centre[1]];
            push_arc(
                &mut pl,
                fc,
                self.fillet_radius_mm,
                a_edge,
                self.draft_angle_deg.to_radians(),
                tol,
            );
        }
        let t = self.draft_angle_deg.to_radians().tan();
        pl.push([self.mouth_radius_mm, base_z_mm]);
        if below_base_mm > 0.0 {
            pl.push([
                self.mouth_radius_mm + below_base_mm * t,
                base_z_mm - below_base_mm,
            ]);
        }
        pl
    }

    /// The recess as a solid (the mold's insert when `below_base_mm` is 0): its surface
    /// ([`Self::polyline`]) closed by the plane `below_base_mm` under the base plane,
    /// revolved at `tol`. Sensor frame, mm.
    ///
    /// # Errors
    /// Only on a kernel failure.
    pub fn solid(
        &self,
        base_z_mm: f64,
        below_base_mm: f64,
        tol: ChordTolerance,
    ) -> Result<Solid, GeometryError> {
        let mut pl = self.polyline(base_z_mm, below_base_mm, tol.half());
        pl.push([0.0, base_z_mm - below_base_mm]);
        Solid::from_mesh(&revolve(&pl, tol)?)
    }

    /// The recess's volume above the base plane, mm^3, from its exact outline.
    pub fn volume_mm3(&self) -> f64 {
        use std::f64::consts::PI;
        let r0 = self.mouth_radius_mm;
        let t = self.draft_angle_deg.to_radians().tan();
        let h1 = self.wall_top[1];
        // the wall: pi * integral of (r0 - t h)^2 over [0, h1]
        let wall = if t == 0.0 {
            PI * r0 * r0 * h1
        } else {
            PI * (r0.powi(3) - (r0 - t * h1).powi(3)) / (3.0 * t)
        };
        // the fillet: r = rc + sqrt(rf^2 - v^2), v = h - hc, over the arc's heights
        let fillet = if self.fillet_radius_mm > 0.0 {
            let (rc, hc, rf) = (
                self.fillet_centre[0],
                self.fillet_centre[1],
                self.fillet_radius_mm,
            );
            let prim = |v: f64| {
                let w = (rf * rf - v * v).max(0.0).sqrt();
                (rc * rc + rf * rf) * v - v.powi(3) / 3.0
                    + rc * (v * w + rf * rf * (v / rf).clamp(-1.0, 1.0).asin())
            };
            PI * (prim(self.roof_edge[1] - hc) - prim(h1 - hc))
        } else {
            0.0
        };
        // the roof: pi * integral of (R^2 - u^2), u = h - hs
        let (cap, hs) = (self.cap_radius_mm, self.cap_centre_h_mm);
        let prim = |u: f64| cap * cap * u - u.powi(3) / 3.0;
        let roof = PI * (prim(self.depth_mm - hs) - prim(self.roof_edge[1] - hs));
        wall + fillet + roof
    }

    /// The area of the recess's surface above the base plane (wall, fillet and roof), mm^2,
    /// from its exact outline: the wall a cone frustum, the roof a spherical zone, the fillet
    /// the surface its arc sweeps (Pappus).
    pub fn surface_area_mm2(&self) -> f64 {
        use std::f64::consts::PI;
        let (r0, [r1, h1]) = (self.mouth_radius_mm, self.wall_top);
        let wall = PI * (r0 + r1) * (r0 - r1).hypot(h1);
        let fillet = if self.fillet_radius_mm > 0.0 {
            let (rc, rf) = (self.fillet_centre[0], self.fillet_radius_mm);
            let a0 = self.draft_angle_deg.to_radians();
            let a1 = (self.roof_edge[1] - self.fillet_centre[1])
                .atan2(self.roof_edge[0] - self.fillet_centre[0]);
            2.0 * PI * rf * (rc * (a1 - a0) + rf * (a1.sin() - a0.sin()))
        } else {
            0.0
        };
        let roof = 2.0 * PI * self.cap_radius_mm * (self.depth_mm - self.roof_edge[1]);
        wall + fillet + roof
    }

    /// The least thickness of skin between the recess and the outer surface, the body's offset
    /// surface at `outer_offset_mm`, mm, measured between their polylines at `tol` (so within
    /// `tol` of the exact figure); 0 when a point of the recess lies outside that surface.
    pub fn skin_mm(
        &self,
        body: &crate::profile::BodyProfile,
        outer_offset_mm: f64,
        tol: ChordTolerance,
    ) -> f64 {
        use geo::Contains;
        let zb = body.base_z_mm();
        let outer = body.offset_polyline(outer_offset_mm, 0.0, tol).points;
        let mut ring: Vec<geo::Coord> = outer
            .iter()
            .map(|p| geo::coord! {x: p[0], y: p[1]})
            .collect();
        ring.push(geo::coord! {x: 0.0, y: zb});
        let section = geo::Polygon::new(geo::LineString::new(ring), vec![]);
        let mut least = f64::INFINITY;
        for p in self.polyline(zb, 0.0, tol).points {
            if p[1] > zb && p[0] > 0.0 && !section.contains(&geo::point! {x: p[0], y: p[1]}) {
                return 0.0;
            }
            for w in outer.windows(2) {
                least = least.min(point_segment_distance(p, w[0], w[1]));
            }
        }
        least
    }

    /// The distance from the point (r, h) (h up from the base plane) to the recess's surface
    /// above the base plane (wall, fillet and roof), mm.
    pub fn distance_mm(&self, p: [f64; 2]) -> f64 {
        let t = self.draft_angle_deg.to_radians();
        // the wall: the segment from the mouth to the wall's top
        let wall = point_segment_distance(p, [self.mouth_radius_mm, 0.0], self.wall_top);
        let arc = |centre: [f64; 2], radius: f64, a0: f64, a1: f64| {
            let ang = (p[1] - centre[1]).atan2(p[0] - centre[0]);
            let (lo, hi) = (a0.min(a1), a0.max(a1));
            if (lo..=hi).contains(&ang) {
                ((p[0] - centre[0]).hypot(p[1] - centre[1]) - radius).abs()
            } else {
                [a0, a1]
                    .iter()
                    .map(|a| {
                        (p[0] - centre[0] - radius * a.cos())
                            .hypot(p[1] - centre[1] - radius * a.sin())
                    })
                    .fold(f64::INFINITY, f64::min)
            }
        };
        let cap_c = [0.0, self.cap_centre_h_mm];
        let a_edge = (self.roof_edge[1] - cap_c[1]).atan2(self.roof_edge[0]);
        let roof = arc(
            cap_c,
            self.cap_radius_mm,
            a_edge,
            std::f64::consts::FRAC_PI_2,
        );
        let fillet = if self.fillet_radius_mm > 0.0 {
            arc(self.fillet_centre, self.fillet_radius_mm, t, a_edge)
        } else {
            f64::INFINITY
        };
        wall.min(roof).min(fillet)
    }
}

/// The recess of layer `index` of `design`, resolved: `None` when the layer has none (or
/// its rules do not hold, which validation reports).
pub fn layer_recess(design: &Design, index: usize) -> Option<RecessOutline> {
    design.layers.get(index)?.recess.as_ref()?.outline().ok()
}

/// The closed (r, z) profile of a solid layer whose outer surface is the body's offset
/// surface at `outer_offset_mm`: down that surface to the base plane, then, with a `recess`,
/// in to its mouth and up its wall, fillet and roof to the apex; without one, in along the
/// base plane to the axis. Arcs within `tol`.
pub fn solid_layer_profile(
    body: &crate::profile::BodyProfile,
    outer_offset_mm: f64,
    recess: Option<&RecessOutline>,
    tol: ChordTolerance,
) -> Polyline2 {
    match recess {
        None => body.solid_profile(outer_offset_mm, 0.0, tol),
        Some(r) => {
            let mut pl = body.offset_polyline(outer_offset_mm, 0.0, tol);
            pl.extend(&r.polyline(body.base_z_mm(), 0.0, tol).reversed());
            pl
        }
    }
}

/// The rules of a recess at `path` (`layers[0].recess`) in a skin whose rim radius on the base
/// plane is `rim_radius_mm` and whose height over it is `height_mm`: sizes above 0, the draft
/// in [0, 45) degrees, the fillet 0 or more, the outline that they make
/// ([`Recess::outline`]), and the recess inside the skin.
pub fn check_recess(
    path: &str,
    r: &Recess,
    rim_radius_mm: f64,
    height_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let prefix = format!("{path}.");
    let mut bad = crate::parts::check_above_zero(&prefix, r, &[], errs);
    if !(r.fillet_radius_mm >= 0.0 && r.fillet_radius_mm.is_finite()) {
        errs.push(ParamError::new(
            format!("{prefix}fillet_radius_mm"),
            r.fillet_radius_mm,
            "must be 0 or more",
        ));
        bad = true;
    }
    if !(0.0..MAX_DRAFT_DEG).contains(&r.draft_angle_deg) {
        errs.push(ParamError::new(
            format!("{prefix}draft_angle_deg"),
            r.draft_angle_deg,
            format!("must be in [0, {MAX_DRAFT_DEG})"),
        ));
        bad = true;
    }
    if bad {
        return;
    }
    if r.base_diameter_mm / 2.0 >= rim_radius_mm {
        errs.push(ParamError::new(
            format!("{prefix}base_diameter_mm"),
            r.base_diameter_mm,
            format!(
                "must be below the skin's diameter on the base plane ({:.3} mm)",
                2.0 * rim_radius_mm
            ),
        ));
    }
    if r.depth_mm >= height_mm {
        errs.push(ParamError::new(
            format!("{prefix}depth_mm"),
            r.depth_mm,
            format!("must be below the skin's height over the base plane ({height_mm:.3} mm)"),
        ));
    }
    if let Err((field, rule)) = r.outline() {
        let value = match field {
            "fillet_radius_mm" => r.fillet_radius_mm,
            _ => r.cap_radius_mm,
        };
        errs.push(ParamError::new(format!("{prefix}{field}"), value, rule));
    }
}

/// The recesses of a design's layers: each on a solid layer of a curved body (`body_ok`: its
/// rules hold), cast in an `open` mold when cast (its insert sets in the open face), without
/// recessed markers on the same layer (their clearance to the recess is not checked), and
/// within its own rules ([`check_recess`]).
pub fn check_layer_recesses(design: &Design, body_ok: bool, errs: &mut Vec<ParamError>) {
    for (i, l) in design.layers.iter().enumerate() {
        let Some(r) = &l.recess else { continue };
        let path = format!("layers[{i}].recess");
        if !l.solid {
            errs.push(ParamError::new(
                &path,
                "given",
                format!(
                    "a recess is cut into the base of a solid layer; layer '{}' is not solid",
                    l.name
                ),
            ));
            continue;
        }
        let strategy = l.mold_strategy.unwrap_or(design.mold.strategy);
        if l.process == LayerProcess::Cast && strategy != MoldStrategy::Open {
            errs.push(ParamError::new(
                &path,
                "given",
                format!(
                    "a cast layer with a recess needs the open mold strategy (the recess's insert sets in the mold's open face); this layer's is {}",
                    serde_json::to_value(strategy).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default()
                ),
            ));
        }
        if l.markers
            .iter()
            .any(|m| m.feature.side() == crate::markers::Polarity::Recessed)
        {
            errs.push(ParamError::new(
                &path,
                "given",
                format!("layer '{}' carries recessed markers too: their clearance to the recess is not checked, so the two are not taken together", l.name),
            ));
        }
        if body_ok {
            let b = &design.body;
            let before = errs.len();
            let height = b.pole_z_mm(0.0) - b.base_z_mm();
            check_recess(&path, r, b.rim_radius_mm(0.0), height, errs);
            let outline = r.outline().ok().filter(|_| errs.len() == before);
            if outline.is_some_and(|o| o.skin_mm(b, 0.0, ChordTolerance::default()) <= 0.0) {
                errs.push(ParamError::new(
                    &path,
                    "given",
                    "breaks through the skin's outer surface: the roof or the wall reaches it",
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published DIGIT Pinki recess (`Pinki Gel.step`, mm, base plane z = -8.5).
    fn pinki() -> Recess {
        Recess {
            base_diameter_mm: 9.853289,
            depth_mm: 3.298931,
            cap_radius_mm: 7.438943,
            draft_angle_deg: 2.0,
            fillet_radius_mm: 0.25,
        }
    }

    #[test]
    fn the_outline_meets_the_published_torus_and_circles() {
        let o = pinki().outline().unwrap();
        // torus: major radius 4.628990 about the axis, centre plane z = -7.139707
        assert!((o.fillet_centre[0] - 4.628990).abs() < 2e-5, "{o:?}");
        assert!(
            (o.fillet_centre[1] - (8.5 - 7.139707)).abs() < 2e-5,
            "{o:?}"
        );
        // the cone's top circle R4.878837 at z = -7.130982; the roof's edge R4.789966 at z = -6.948430
        assert!(
            (o.wall_top[0] - 4.878837).abs() < 2e-5
                && (o.wall_top[1] - (8.5 - 7.130982)).abs() < 2e-5
        );
        assert!(
            (o.roof_edge[0] - 4.789966).abs() < 2e-5
                && (o.roof_edge[1] - (8.5 - 6.948430)).abs() < 2e-5
        );
        assert!((o.cap_centre_h_mm - (8.5 - 12.640012)).abs() < 2e-5);
    }

    #[test]
    fn the_volume_is_the_revolved_outline_and_the_mesh_holds_it() {
        let r = pinki();
        let o = r.outline().unwrap();
        // the published gel: 2132.3 mm^3 = the R7.5 hemisphere on 8.1 mm of cylinder less the recess
        let outer =
            2.0 / 3.0 * std::f64::consts::PI * 7.5f64.powi(3) + std::f64::consts::PI * 56.25 * 8.1;
        assert!(
            ((outer - o.volume_mm3()) - 2132.3).abs() < 0.05,
            "{}",
            outer - o.volume_mm3()
        );
        let tol = ChordTolerance::new(0.002).unwrap();
        let s = o.solid(-8.5, 0.0, tol).unwrap();
        assert!(
            (s.volume() - o.volume_mm3()).abs() / o.volume_mm3() < 2e-3,
            "{} {}",
            s.volume(),
            o.volume_mm3()
        );
        for v in s.mesh().vertices.iter().filter(|v| v[2] > -8.5 + 1e-9) {
            let p = [v[0].hypot(v[1]), v[2] + 8.5];
            assert!(o.distance_mm(p) < 1e-9, "{p:?}: {}", o.distance_mm(p));
        }
    }

    #[test]
    fn the_surface_area_is_the_meshs() {
        let o = pinki().outline().unwrap();
        let tol = ChordTolerance::new(0.001).unwrap();
        let mesh = o.solid(-8.5, 0.0, tol).unwrap().mesh().clone();
        // the mesh's area less its flat base (the mouth's disc)
        let mut area = 0.0;
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            if [a, b, c].iter().all(|v| v[2] == -8.5) {
                continue;
            }
            let (u, v) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        }
        let exact = o.surface_area_mm2();
        assert!((area - exact).abs() / exact < 1e-3, "{area} {exact}");
    }

    #[test]
    fn a_sharp_edge_is_where_the_cone_leaves_the_sphere() {
        let mut r = pinki();
        r.fillet_radius_mm = 0.0;
        let o = r.outline().unwrap();
        assert_eq!(o.wall_top, o.roof_edge);
        let [rr, h] = o.wall_top;
        assert!((rr.hypot(h - o.cap_centre_h_mm) - r.cap_radius_mm).abs() < 1e-12);
        assert!((rr - (4.926644 - h * 2f64.to_radians().tan())).abs() < 1e-6);
    }

    #[test]
    fn broken_rules_name_their_field() {
        let mut errs = Vec::new();
        let mut r = pinki();
        r.cap_radius_mm = 3.0; // the sphere through the apex misses the mouth's edge
        check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
        assert_eq!(errs.len(), 1, "{errs:?}");
        assert_eq!(errs[0].path, "layers[0].recess.cap_radius_mm");
        let mut r = pinki();
        r.fillet_radius_mm = 3.0;
        errs.clear();
        check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
        assert_eq!(
            errs[0].path, "layers[0].recess.fillet_radius_mm",
            "{errs:?}"
        );
        let mut r = pinki();
        r.base_diameter_mm = 15.0;
        r.depth_mm = 20.0;
        r.draft_angle_deg = 45.0;
        errs.clear();
        check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
        assert_eq!(errs.len(), 1, "{errs:?}");
        r.draft_angle_deg = 2.0;
        errs.clear();
        check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert!(
            paths.contains(&"layers[0].recess.base_diameter_mm")
                && paths.contains(&"layers[0].recess.depth_mm"),
            "{paths:?}"
        );
    }
}
