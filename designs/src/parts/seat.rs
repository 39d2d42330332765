//! A seat cut into a solid layer from below, open on the base plane (the optic's seat of DIGIT
//! Pinki's gel): a solid of revolution about the z axis, its outline a wall that narrows upward
//! by its draft, a fillet and a spherical roof. Its heights `h` are measured up from the base
//! plane (`z = base_z + h`), in the sensor frame (docs/conventions.md). A layer feature makes
//! one ([`crate::parts::layer_feature::LayerFeature::seat`]); the layer solid, the volumes, the
//! estimates and the mold's insert are made from it.
use crate::geometry::profile2d::{point_segment_distance, push_arc};
use crate::geometry::{revolve, ChordTolerance, GeometryError, Polyline2, Solid};
use serde::Serialize;

/// The resolved outline of a seat (a [`crate::parts::recess::Recess`]) in the (r, h) half-plane, h up from the base plane,
/// mm: the wall from the mouth `(mouth_radius_mm, 0)` up to `wall_top`, the fillet arc (centre
/// `fillet_centre`, radius `fillet_radius_mm`) from `wall_top` to `roof_edge`, and the roof's
/// arc (centre `(0, cap_centre_h_mm)`, radius `cap_radius_mm`) from `roof_edge` to the apex
/// `(0, depth_mm)`. Without a fillet, `wall_top == roof_edge == fillet_centre`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Seat {
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

impl Seat {
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
