//! The robot mount of a shaft body (Pestell et al. Sec. III-A3: "A custom 3D-printed mount is
//! bolted to the rotating (wrist) section of the arm to which the sensor is attached via a
//! bayonet mechanism"; the arm is an ABB IRB 120).
//!
//! A plate bolted to the robot's tool flange (ISO 9409-1: bolts on a pitch circle, counterbored
//! from the top, and a locating pin hole from below), and on it a cup whose bore takes the
//! body's base. Lugs standing out of the base's foot lock into grooves in the cup's bore
//! ([`crate::parts::bayonet`], outward) by a clockwise turn, the opposite of the tip's, so that
//! twisting a tip off does not loosen the body. A window in the cup's wall passes the camera's
//! cable (on +y) over the turn.
//!
//! Sensor frame, mm: the plate from `bottom_z - plate_thickness_mm` up to the base's bottom
//! `bottom_z` ([`crate::parts::shaft_body::ShaftLevels`]), the cup from there up by
//! `cup_height_mm`.

use super::{Part, PrintTechnology};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cylinder, ChordTolerance, GeometryError, Solid};
use crate::parts::bayonet::{band, Bayonet};
use crate::parts::context::Context;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::shaft_body::{levels, BayonetLugs, ShaftBodyParams, CABLE_SLOT_MM, OVERLAP_MM};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;

/// The robot mount (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RobotMount {
    /// The robot and its tool flange, for the fabrication sheet.
    pub robot: String,
    /// Material key of the mount (printed FDM), e.g. `abs`.
    pub material: String,
    /// Thickness of the plate along the axis, from its bottom face (on the robot's tool
    /// flange) up to the base's bottom, mm, > 0; it must hold the bolts' counterbores and the
    /// pin hole with the FDM minimum wall between them.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub plate_thickness_mm: f64,
    /// Wall of the cup outside its grooves, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cup_wall_mm: f64,
    /// Height of the cup over the plate, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cup_height_mm: f64,
    /// Pitch circle of the flange's bolts, mm (ISO 9409-1 d1).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_circle_diameter_mm: f64,
    /// Bolts on the pitch circle, 2..=8; the first at 45 deg from +x.
    #[schemars(extend("minimum" = 2, "maximum" = 8))]
    pub bolt_count: u32,
    /// Diameter of the bolts' holes through the plate, mm, > 0; below the counterbore's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_clearance_diameter_mm: f64,
    /// Counterbore for the bolt's head, from the plate's top, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_head_diameter_mm: f64,
    /// Depth of the counterbores down from the plate's top, mm, > 0; with the pin hole and
    /// the FDM minimum wall between them it must fit in `plate_thickness_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_head_depth_mm: f64,
    /// Locating pin hole on the pitch circle at +x, from the plate's bottom, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_hole_diameter_mm: f64,
    /// Depth of the locating pin hole up from the plate's bottom, mm, > 0; with the
    /// counterbores and the FDM minimum wall between them it must fit in
    /// `plate_thickness_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_hole_depth_mm: f64,
    /// The bayonet's lugs on the base's foot (count, ramp and clearance from
    /// `printers.fdm.bayonet`).
    pub bayonet: BayonetLugs,
}

/// The base's lugs stand this far above its bottom face, so that their grooves stay clear of
/// the plate, mm.
pub const LUG_LIFT_MM: f64 = 1.0;

/// Azimuth of the first lug, locked, degrees: the lugs and their grooves clear of the cable
/// window on +y.
pub const FIRST_LUG_DEG: f64 = -90.0;

/// Radii of the cup, mm: (bore, outside).
pub fn cup_radii(sb: &ShaftBodyParams, m: &RobotMount, ctx: &Context<'_>) -> (f64, f64) {
    let bore = sb.base.outer_diameter_mm / 2.0 + sb.fit_clearance_mm;
    let c = ctx.printers.fdm.bayonet.clearance_mm;
    (bore, bore + m.bayonet.lug_depth_mm + c + m.cup_wall_mm)
}

/// The body-to-mount bayonet, locked.
pub fn mount_bayonet(ctx: &Context<'_>, sb: &ShaftBodyParams, m: &RobotMount) -> Bayonet {
    let zb = levels(ctx, sb).bottom_z_mm;
    Bayonet {
        spigot_radius_mm: cup_radii(sb, m, ctx).0,
        outward: true,
        clockwise: true,
        first_lug_deg: FIRST_LUG_DEG,
        lug_z_mm: zb + LUG_LIFT_MM + m.bayonet.lug_height_mm / 2.0,
        spigot_end_z_mm: zb + m.cup_height_mm,
        ..Bayonet::sized(&ctx.printers.fdm.bayonet, &m.bayonet)
    }
}

/// The cable window's azimuth range, radians: the base's slot on +y (locked) and where it
/// comes from over the turn, with the fit clearance on each side.
pub fn window_azimuths(sb: &ShaftBodyParams, m: &RobotMount, ctx: &Context<'_>) -> (f64, f64) {
    let bore = cup_radii(sb, m, ctx).0;
    let w = (CABLE_SLOT_MM[0] / 2.0 + sb.fit_clearance_mm) / bore;
    let up = PI / 2.0;
    (up - w, up + m.bayonet.lock_angle_deg.to_radians() + w)
}

fn bolt_xy(m: &RobotMount) -> Vec<[f64; 2]> {
    let r = m.bolt_circle_diameter_mm / 2.0;
    (0..m.bolt_count)
        .map(|k| {
            let a = (45.0 + f64::from(k) * 360.0 / f64::from(m.bolt_count)).to_radians();
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

fn pin_xy(m: &RobotMount) -> [f64; 2] {
    [m.bolt_circle_diameter_mm / 2.0, 0.0]
}

/// Rules on the mount, paths under `shaft_body.robot_mount`.
pub fn check_params(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    m: &RobotMount,
    errs: &mut Vec<ParamError>,
) {
    let before = errs.len();
    let path = |p: &str| format!("shaft_body.robot_mount.{p}");
    crate::parts::check_above_zero("shaft_body.robot_mount.", m, &[], errs);
    if !(2..=8).contains(&m.bolt_count) {
        errs.push(ParamError::new(
            path("bolt_count"),
            m.bolt_count,
            "must be 2 to 8",
        ));
    }
    if !(m.bayonet.lock_angle_deg > 0.0 && m.bayonet.lock_angle_deg < 90.0) {
        errs.push(ParamError::new(
            path("bayonet.lock_angle_deg"),
            m.bayonet.lock_angle_deg,
            "must be above 0 and below 90",
        ));
    }
    if errs.len() > before {
        return;
    }
    let wall = ctx.printers.fdm.min_wall_mm;
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let (bore, outside) = cup_radii(sb, m, ctx);
    rule(
        m.cup_wall_mm >= wall,
        "cup_wall_mm",
        m.cup_wall_mm,
        format!("must be at least the FDM minimum wall ({wall:.2} mm)"),
    );
    rule(
        m.bolt_head_diameter_mm > m.bolt_clearance_diameter_mm,
        "bolt_head_diameter_mm",
        m.bolt_head_diameter_mm,
        format!(
            "the counterbore must be wider than the bolt's clearance hole ({:.2} mm)",
            m.bolt_clearance_diameter_mm
        ),
    );
    rule(
        m.bolt_head_depth_mm + m.pin_hole_depth_mm + wall <= m.plate_thickness_mm,
        "plate_thickness_mm",
        m.plate_thickness_mm,
        format!(
            "must hold the counterbores ({:.2} mm), the pin hole ({:.2} mm) and a {wall:.2} mm wall between them",
            m.bolt_head_depth_mm, m.pin_hole_depth_mm
        ),
    );
    rule(
        m.bolt_circle_diameter_mm / 2.0 + m.bolt_head_diameter_mm.max(m.pin_hole_diameter_mm) / 2.0 + wall
            <= outside,
        "bolt_circle_diameter_mm",
        m.bolt_circle_diameter_mm,
        format!(
            "the bolts' counterbores and the pin hole must stay {wall:.2} mm inside the mount's outside (diameter {:.2} mm)",
            2.0 * outside
        ),
    );
    let b = mount_bayonet(ctx, sb, m);
    let tan = b.ramp_deg.to_radians().tan();
    let half = b.groove_width_mm / 2.0 / bore;
    let lock = b.lock_angle_deg.to_radians();
    let groove_top =
        b.lug_z_mm + bore * tan * (lock + half) + b.lug_height_mm / 2.0 + b.clearance_mm;
    let zb = levels(ctx, sb).bottom_z_mm;
    rule(
        groove_top + wall <= zb + m.cup_height_mm,
        "cup_height_mm",
        m.cup_height_mm,
        format!(
            "the locking grooves reach {:.2} mm over the plate: the cup must keep a {wall:.2} mm wall over them",
            groove_top - zb
        ),
    );
    // the grooves (each from its lug back over the turn), the walls between them and the
    // cable window must fit round the cup
    let (w0, w1) = window_azimuths(sb, m, ctx);
    let mut spans: Vec<(f64, f64)> = b
        .lug_azimuths_deg()
        .iter()
        .map(|a| {
            let a = a.to_radians();
            (a - half, a + lock + half)
        })
        .collect();
    spans.push((w0, w1));
    let gap = wall / bore;
    let clash = spans.iter().enumerate().any(|(i, x)| {
        spans[i + 1..].iter().any(|y| {
            // angular distance between the two arcs, on the circle
            let mid = |s: &(f64, f64)| (s.0 + s.1) / 2.0;
            let d = (mid(x) - mid(y)).rem_euclid(2.0 * PI);
            let d = d.min(2.0 * PI - d);
            d < (x.1 - x.0) / 2.0 + (y.1 - y.0) / 2.0 + gap
        })
    });
    rule(
        !clash,
        "bayonet.lock_angle_deg",
        m.bayonet.lock_angle_deg,
        format!(
            "{} grooves, each the lock's turn plus the groove's width, and the cable window ({:.1} deg) must fit round the cup's bore with a {wall:.1} mm wall between them: fewer lugs, a narrower lug or a smaller turn",
            b.lug_count,
            (w1 - w0).to_degrees()
        ),
    );
}

/// The mount's parameters for its twin, and the base's lugs for the body's twin.
pub fn twin_params(ctx: &Context<'_>, sb: &ShaftBodyParams, m: &RobotMount) -> serde_json::Value {
    let b = mount_bayonet(ctx, sb, m);
    let (bore, outside) = cup_radii(sb, m, ctx);
    let (w0, w1) = window_azimuths(sb, m, ctx);
    json!({
        "bayonet": b,
        "lug_azimuths_deg": b.lug_azimuths_deg(),
        "lug_attach_radius_mm": sb.base.outer_diameter_mm / 2.0 - OVERLAP_MM,
        "bore_radius_mm": bore,
        "outside_radius_mm": outside,
        "window_azimuths_rad": [w0, w1],
        "bolt_xy_mm": bolt_xy(m),
        "pin_xy_mm": pin_xy(m),
        "robot_mount": m,
    })
}

/// The base's lugs, to be united with the body, sensor frame.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn base_lugs(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    m: &RobotMount,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    mount_bayonet(ctx, sb, m).lugs(sb.base.outer_diameter_mm / 2.0 - OVERLAP_MM, tol)
}

/// The mount, printed standing on its plate.
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_mount(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    m: &RobotMount,
    tol: ChordTolerance,
) -> Result<Part, DesignError> {
    let g = |x: Result<Solid, GeometryError>| x.part("robot_mount");
    let cyl = |r: f64, z0: f64, z1: f64, [x, y]: [f64; 2]| {
        cylinder(z1 - z0, r, tol).map(|s| s.translate([x, y, z0]))
    };
    let zb = levels(ctx, sb).bottom_z_mm;
    let z0 = zb - m.plate_thickness_mm;
    let (bore, outside) = cup_radii(sb, m, ctx);
    let (w0, w1) = window_azimuths(sb, m, ctx);
    let e = OVERLAP_MM;
    let cup = g(
        cyl(outside, zb - e, zb + m.cup_height_mm, [0.0; 2]).and_then(|o| {
            o.difference(&cyl(
                bore,
                zb - 2.0 * e,
                zb + m.cup_height_mm + 1.0,
                [0.0; 2],
            )?)
        }),
    )?;
    let window = g(Solid::from_mesh(&band(
        (bore - 1.0, outside + 1.0),
        (w0, w1),
        (zb - 1.0, zb + m.cup_height_mm + 1.0),
        0.0,
        tol,
    )))?;
    let grooves = g(mount_bayonet(ctx, sb, m).grooves(tol))?;
    let cup = g(cup.difference(&g(window.union(&grooves))?))?;
    let plate = g(cyl(outside, z0, zb, [0.0; 2]))?;
    let mut cuts = Vec::new();
    for xy in bolt_xy(m) {
        cuts.push(g(cyl(
            m.bolt_clearance_diameter_mm / 2.0,
            z0 - 1.0,
            zb + 1.0,
            xy,
        ))?);
        cuts.push(g(cyl(
            m.bolt_head_diameter_mm / 2.0,
            zb - m.bolt_head_depth_mm,
            zb + 1.0,
            xy,
        ))?);
    }
    cuts.push(g(cyl(
        m.pin_hole_diameter_mm / 2.0,
        z0 - 1.0,
        z0 + m.pin_hole_depth_mm,
        pin_xy(m),
    ))?);
    let mount = g(g(plate.union(&cup))?.difference(&g(Solid::union_all(&cuts))?))?;
    let (placed, pose) = place_posed(&mount, &crate::geometry::Affine::identity());
    Ok(Part {
        name: "robot_mount".into(),
        role: "robot_mount".into(),
        description: format!(
            "Robot mount: plate for the tool flange of the {} and the bayonet cup that locks the body's base (Pestell et al. Sec. III-A3)",
            m.robot
        ),
        material: m.material.clone(),
        print_technology: PrintTechnology::Fdm,
        solid: placed,
        params: with_pose(
            json!({"mount": twin_params(ctx, sb, m), "levels": levels(ctx, sb)}),
            &pose,
        ),
        group: None,
    })
}

/// The mount's bought items: bolts and the locating pin.
pub fn bought_items(m: &RobotMount) -> Vec<String> {
    vec![format!(
        "Robot mount to the tool flange of the {}: {} socket head cap screws through {:.1} mm holes on a {:.1} mm pitch circle, {:.1} mm under the head plus the thread depth of the flange, and a {:.1} mm locating pin ({:.1} mm into the mount)",
        m.robot,
        m.bolt_count,
        m.bolt_clearance_diameter_mm,
        m.bolt_circle_diameter_mm,
        m.plate_thickness_mm - m.bolt_head_depth_mm,
        m.pin_hole_diameter_mm,
        m.pin_hole_depth_mm
    )]
}
