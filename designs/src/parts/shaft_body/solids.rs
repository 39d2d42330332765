//! The shaft body's solids: the tip's fitting (its ring of revolution and the lugs), the body
//! (the shaft and the base with their seats, bore, pocket, grooves and pilots) and the filling
//! gel.

use super::dimensions::{
    levels, mount_holes, radii, tip_bayonet, twin_params, ShaftLevels, ShaftRadii,
};
use super::params::{ShaftBodyParams, CABLE_SLOT_MM, OVERLAP_MM};
use crate::error::{DesignError, GeometryContext};
use crate::geometry::{cuboid, cylinder, revolve, GeometryError, Polyline2, Solid};
use crate::parts::family::FamilyInput;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::{ExactShape, Part, PrintTechnology};

/// The fitting's profile of revolution (r, z), closed, counter-clockwise.
fn fitting_profile(r: &ShaftRadii, lv: &ShaftLevels) -> Polyline2 {
    Polyline2 {
        points: vec![
            [r.skirt_bore_mm, lv.fitting_bottom_z_mm],
            [r.fitting_outer_mm, lv.fitting_bottom_z_mm],
            [r.fitting_outer_mm, lv.skin_base_z_mm],
            [r.lip_inner_mm, lv.skin_base_z_mm],
            [r.lip_inner_mm, lv.lip_z_mm],
            [r.window_seat_mm, lv.lip_z_mm],
            [r.window_seat_mm, lv.shaft_top_z_mm],
            [r.skirt_bore_mm, lv.shaft_top_z_mm],
        ],
    }
}

/// The tip's fitting in the sensor frame: the ring of revolution and the lugs (locked).
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn tip_fitting_solid(
    sb: &ShaftBodyParams,
    input: FamilyInput<'_>,
) -> Result<Solid, GeometryError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let ring = Solid::from_mesh(&revolve(&fitting_profile(&r, &lv), tol)?)?;
    let lugs = tip_bayonet(ctx, sb).lugs(r.skirt_bore_mm + OVERLAP_MM, tol)?;
    ring.union(&lugs)
}

/// The body (see the module docs), printed standing on its base.
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_body(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Part, DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let g = |x: Result<Solid, GeometryError>| x.part("shaft_body");
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    let e = OVERLAP_MM;
    let outer = g(
        cyl(r.base_outer_mm, lv.bottom_z_mm, lv.base_top_z_mm).and_then(|b| {
            b.union(&cyl(
                r.shaft_outer_mm,
                lv.base_top_z_mm - e,
                lv.shaft_top_z_mm,
            )?)
        }),
    )?;
    let p = r.board_pocket_half_mm;
    let (sw, sh) = (CABLE_SLOT_MM[0] / 2.0, CABLE_SLOT_MM[1]);
    let cam = &sb.camera;
    let mut cuts = vec![
        g(cyl(r.led_seat_mm, lv.led_pcb_z_mm, lv.shaft_top_z_mm + 1.0))?,
        g(cyl(r.shaft_bore_mm, lv.base_top_z_mm, lv.led_pcb_z_mm + e))?,
        g(cyl(
            r.lens_hole_mm,
            lv.ceiling_z_mm - e,
            lv.base_top_z_mm + e,
        ))?,
        g(cuboid(
            [-p, -p, lv.bottom_z_mm - 1.0],
            [p, p, lv.ceiling_z_mm],
        ))?,
        g(cuboid(
            [-sw, 0.0, lv.bottom_z_mm - 1.0],
            [sw, r.base_outer_mm + 1.0, lv.bottom_z_mm + sh],
        ))?,
        g(tip_bayonet(ctx, sb).grooves(tol))?,
    ];
    for [x, y] in mount_holes(sb) {
        cuts.push(g(cyl(
            cam.mount_pilot_diameter_mm / 2.0,
            lv.ceiling_z_mm - e,
            lv.ceiling_z_mm + cam.mount_pilot_depth_mm,
        )
        .map(|s| s.translate([x, y, 0.0])))?);
    }
    // the lugs that lock the base into the robot's mount
    let outer = match &sb.robot_mount {
        Some(m) => g(outer.union(&g(crate::parts::robot_mount::base_lugs(ctx, sb, m, tol))?))?,
        None => outer,
    };
    let body = g(outer.difference(&g(Solid::union_all(&cuts))?))?;
    let (placed, pose) = place_posed(&body, &crate::geometry::Affine::identity());
    let fdm_tech = PrintTechnology::Fdm;
    Ok(Part {
        name: "shaft_body".into(),
        role: "shaft_body".into(),
        description: format!(
            "Body: {:.1} mm shaft, {:.1} mm long, with the bayonet for the tip, the LED ring's seat and the camera's pocket (Pestell et al. Sec. III-A)",
            sb.shaft_diameter_mm, sb.shaft_length_mm
        ),
        material: sb.material.clone(),
        print_technology: fdm_tech,
        solid: placed,
        params: with_pose(twin_params(ctx, sb, stack), &pose),
        group: None,
    })
}

/// The filling gel's solid, sensor frame: `cavity`, the innermost layer's inside above the
/// base plane round the pins and their tips (`layers::inner_cavity`), and the lip's opening
/// down to the window; with its exact shape, from the innermost layer's twin parameters
/// `cavity_params`.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn filling_gel_solid(
    sb: &ShaftBodyParams,
    input: FamilyInput<'_>,
    (cavity, cavity_params): (Solid, serde_json::Value),
) -> Result<(Solid, ExactShape), GeometryError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    // 0.01 mm into the cavity, so that the union has no coplanar faces
    let (z0, z1) = (lv.lip_z_mm, lv.skin_base_z_mm + 0.01);
    let lip = cylinder(z1 - z0, r.lip_inner_mm, tol)?.translate([0.0, 0.0, z0]);
    let exact = ExactShape::InnerCavity {
        params: cavity_params,
        opening_radius_mm: r.lip_inner_mm,
        opening_z0_mm: z0,
        opening_z1_mm: z1,
    };
    Ok((cavity.union(&lip)?, exact))
}
