//! The bayonet joint: a socket (the outer part, a skirt with inward lugs) that goes axially
//! over a spigot (the inner part, a round end with one L-shaped groove per lug in its outer
//! surface) and locks by a turn (Pestell et al. Sec. III-A: the TacTip's tip and body
//! "interlock via a bayonet fitting"; Sec. III-C: the body is attached to the robot's mount
//! "via a bayonet mechanism").
//!
//! Each groove is an entry groove, axial from the spigot's end down to the lug's level, and a
//! locking groove that runs on round the spigot by the lock angle. The locking groove's faces
//! fall by the ramp angle along the turn, so turning the socket home draws it down onto the
//! spigot (the lug's top face rides on the groove's upper face). The lugs and the grooves are
//! built in the locked position: lug `k`'s centre at azimuth `first_lug_deg + k 360 / n`,
//! its entry groove `lock_angle_deg` before it along the turn that locks (counter-clockwise
//! seen from +z unless `clockwise`).
//!
//! Inward (the tip on the shaft): the lugs reach in from the socket's skirt into grooves in
//! the spigot's outer surface. Outward (the body in the robot's mount): the lugs stand out
//! from the inner part into grooves in the bore of a cup; `groove_radius_mm` is then the
//! bore's radius.
//!
//! The lug count, the ramp and the clearance come from the printer profile of the part that
//! carries the grooves ([`BayonetProfile`], `printers.<technology>.bayonet`): how fine a
//! lug prints and how loose a printed fit must be are properties of the printer.

use crate::geometry::{ChordTolerance, GeometryError, Mesh, Solid};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The bayonet's lugs (on the tip's skirt) and grooves (round the shaft's top); the lug
/// count, ramp and clearance come from `printers.fdm.bayonet`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BayonetLugs {
    /// Lug width along the shaft's circumference, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lug_width_mm: f64,
    /// Lug height, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lug_height_mm: f64,
    /// How far a lug reaches into the shaft, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lug_depth_mm: f64,
    /// Turn from entry to locked, degrees, in (0, 90).
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 90))]
    pub lock_angle_deg: f64,
    /// Groove width along the circumference, mm; the lug's width plus the clearance on each
    /// side when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub groove_width_mm: Option<f64>,
}

/// A printer's bayonet settings (`printers.<technology>.bayonet`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct BayonetProfile {
    /// Lugs round the joint, 2..=8 (and they must fit round the spigot with their grooves).
    pub lug_count: u32,
    /// Fall of the locking groove along the turn, degrees from the horizontal, in [0, 15).
    pub ramp_deg: f64,
    /// Clearance between a lug and its groove on every side, mm, at least half the nozzle
    /// (`xy_resolution_mm`).
    pub clearance_mm: f64,
}

impl Default for BayonetProfile {
    /// Three lugs, a 2 deg ramp and 0.2 mm clearance: a twist-lock that prints on a 0.4 mm
    /// nozzle and holds without a tool (fabkit's choice).
    fn default() -> Self {
        Self {
            lug_count: 3,
            ramp_deg: 2.0,
            clearance_mm: 0.2,
        }
    }
}

/// One bayonet joint, resolved: sizes and levels in the sensor frame, mm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bayonet {
    /// Radius of the grooved surface, mm: the spigot's outer surface (inward lugs) or the
    /// cup's bore (outward lugs).
    pub spigot_radius_mm: f64,
    /// Lugs stand out from the inner part into grooves in a cup's bore.
    pub outward: bool,
    /// The lugs' part turns clockwise (seen from +z) to lock.
    pub clockwise: bool,
    pub lug_count: u32,
    /// Lug width, measured along the spigot's circumference, mm.
    pub lug_width_mm: f64,
    /// Lug height along z, mm.
    pub lug_height_mm: f64,
    /// How far a lug reaches in from the spigot's surface, mm.
    pub lug_depth_mm: f64,
    /// Width of the entry and locking grooves along the circumference, mm (by default the
    /// lug's width plus the clearance on each side).
    pub groove_width_mm: f64,
    pub clearance_mm: f64,
    /// Turn from the entry groove to the locked position, degrees.
    pub lock_angle_deg: f64,
    pub ramp_deg: f64,
    /// Azimuth of the first lug's centre, locked, degrees.
    pub first_lug_deg: f64,
    /// z of the lugs' centres, locked, mm.
    pub lug_z_mm: f64,
    /// z of the spigot's end where the entry grooves open, mm.
    pub spigot_end_z_mm: f64,
}

impl Bayonet {
    /// The sizes of a joint from its lugs and the printer's profile (the groove's width
    /// defaults to the lug's plus the clearance on each side); the placement (radius, turn,
    /// levels) left at zero, for the caller to set.
    pub fn sized(p: &BayonetProfile, b: &BayonetLugs) -> Self {
        Self {
            spigot_radius_mm: 0.0,
            outward: false,
            clockwise: false,
            lug_count: p.lug_count,
            lug_width_mm: b.lug_width_mm,
            lug_height_mm: b.lug_height_mm,
            lug_depth_mm: b.lug_depth_mm,
            groove_width_mm: b
                .groove_width_mm
                .unwrap_or(b.lug_width_mm + 2.0 * p.clearance_mm),
            clearance_mm: p.clearance_mm,
            lock_angle_deg: b.lock_angle_deg,
            ramp_deg: p.ramp_deg,
            first_lug_deg: 0.0,
            lug_z_mm: 0.0,
            spigot_end_z_mm: 0.0,
        }
    }

    /// Azimuths of the lugs' centres, locked, degrees.
    pub fn lug_azimuths_deg(&self) -> Vec<f64> {
        (0..self.lug_count)
            .map(|k| self.first_lug_deg + f64::from(k) * 360.0 / f64::from(self.lug_count))
            .collect()
    }

    /// The rise of the locking groove from the locked end to the entry, mm: the socket sits
    /// this much higher when its lugs come down the entry grooves.
    pub fn rise_mm(&self) -> f64 {
        self.lock_angle_deg.to_radians() * self.spigot_radius_mm * self.ramp_deg.to_radians().tan()
    }

    /// The lugs in the locked position, each from `lug_depth_mm` past the grooved surface
    /// (inside the spigot, or out into the cup's wall) back to `attach_radius_mm` (into the
    /// part that carries them, so that their union with it is clean).
    ///
    /// # Errors
    /// [`GeometryError`] on a degenerate size.
    pub fn lugs(&self, attach_radius_mm: f64, tol: ChordTolerance) -> Result<Solid, GeometryError> {
        let r = self.spigot_radius_mm;
        let half = self.lug_width_mm / 2.0 / r;
        let z0 = self.lug_z_mm - self.lug_height_mm / 2.0;
        let radial = if self.outward {
            (attach_radius_mm, r + self.lug_depth_mm)
        } else {
            (r - self.lug_depth_mm, attach_radius_mm)
        };
        let mut out = Vec::new();
        for a in self.lug_azimuths_deg() {
            let a = a.to_radians();
            out.push(Solid::from_mesh(&band(
                radial,
                (a - half, a + half),
                (z0, z0 + self.lug_height_mm),
                0.0,
                tol,
            ))?);
        }
        Ok(Solid::compose(&out))
    }

    /// The grooves, to be cut from the grooved part: per lug the entry groove from the
    /// spigot's end (or the cup's rim) down and the ramped locking groove, `clearance_mm`
    /// round the lug on every side, reaching 1 mm out of the grooved surface.
    ///
    /// # Errors
    /// [`GeometryError`] on a degenerate size.
    pub fn grooves(&self, tol: ChordTolerance) -> Result<Solid, GeometryError> {
        let r = self.spigot_radius_mm;
        let c = self.clearance_mm;
        let radial = if self.outward {
            (r - 1.0, r + self.lug_depth_mm + c)
        } else {
            (r - self.lug_depth_mm - c, r + 1.0)
        };
        let half = (self.groove_width_mm / 2.0) / r;
        let lock = self.lock_angle_deg.to_radians();
        let h = self.lug_height_mm / 2.0 + c;
        // +1 when the lugs turn counter-clockwise to lock
        let turn = if self.clockwise { -1.0 } else { 1.0 };
        let tan = self.ramp_deg.to_radians().tan();
        // the locking groove's centre falls by tan(ramp) per mm of turn towards the lock
        let slope = -turn * r * tan;
        let mut out = Vec::new();
        for a in self.lug_azimuths_deg() {
            let a = a.to_radians();
            let entry = a - turn * lock;
            let z_at = |az: f64| self.lug_z_mm + turn * r * tan * (a - az);
            let a0 = entry.min(a) - half;
            let a1 = entry.max(a) + half;
            let lock_groove = band(radial, (a0, a1), (z_at(a0) - h, z_at(a0) + h), slope, tol);
            // entry groove: from the spigot's end down to the locking groove's floor there
            let floor = z_at(entry) - h;
            let entry_groove = band(
                radial,
                (entry - half, entry + half),
                (floor, self.spigot_end_z_mm + 1.0),
                0.0,
                tol,
            );
            out.push(Solid::from_mesh(&lock_groove)?.union(&Solid::from_mesh(&entry_groove)?)?);
        }
        Solid::union_all(&out)
    }
}

/// A closed annular sector `r0 <= r <= r1`, `a0 <= azimuth <= a1` (radians), whose z range
/// `[z0, z1]` at `a0` moves by `slope_mm_per_rad` per radian of azimuth (a helical band; flat
/// for slope 0), tessellated so that its arcs stay within the chord tolerance.
pub fn band(
    (r0, r1): (f64, f64),
    (a0, a1): (f64, f64),
    (z0, z1): (f64, f64),
    slope_mm_per_rad: f64,
    tol: ChordTolerance,
) -> Mesh {
    let n = ((tol.circle_segments(r1) as f64) * (a1 - a0) / (2.0 * PI))
        .ceil()
        .max(1.0) as usize;
    let mut vertices = Vec::with_capacity(4 * (n + 1));
    for i in 0..=n {
        let a = a0 + (a1 - a0) * i as f64 / n as f64;
        let dz = slope_mm_per_rad * (a - a0);
        let (s, c) = a.sin_cos();
        // 0: inner bottom, 1: outer bottom, 2: outer top, 3: inner top
        vertices.push([r0 * c, r0 * s, z0 + dz]);
        vertices.push([r1 * c, r1 * s, z0 + dz]);
        vertices.push([r1 * c, r1 * s, z1 + dz]);
        vertices.push([r0 * c, r0 * s, z1 + dz]);
    }
    let mut triangles = Vec::with_capacity(8 * n + 4);
    let v = |i: usize, k: usize| (4 * i + k) as u32;
    for i in 0..n {
        let j = i + 1;
        // bottom (normal -z), outer (+r), top (+z), inner (-r); azimuth grows from i to j
        for (k0, k1) in [(0, 1), (1, 2), (2, 3), (3, 0)] {
            triangles.push([v(i, k0), v(j, k1), v(i, k1)]);
            triangles.push([v(i, k0), v(j, k0), v(j, k1)]);
        }
    }
    // end caps: at a0 facing -azimuth, at a1 facing +azimuth
    triangles.push([v(0, 0), v(0, 1), v(0, 2)]);
    triangles.push([v(0, 0), v(0, 2), v(0, 3)]);
    triangles.push([v(n, 0), v(n, 2), v(n, 1)]);
    triangles.push([v(n, 0), v(n, 3), v(n, 2)]);
    Mesh {
        vertices,
        triangles,
    }
}
