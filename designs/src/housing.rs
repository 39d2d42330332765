//! The two-piece sensor shell (R-Tac0 Sec. III-B2..B4, Fig. 2).
//!
//! From the bottom up, in the sensor frame: the camera bay (square, open at the bottom, the
//! board screws up against the bulkhead), the bulkhead with the lens hole and the board's
//! mounting pilot holes, the LED ring PCB seat on the bulkhead, the light chamber, the diffuser
//! seat `gap_above_pcb_mm` above the PCB (10 mm in the paper), and the contact-module seat: a
//! bore that takes the part of the core below the base plane, whose rim rests on the diffuser;
//! the skin's base rests on the shell's top face (the base plane). The halves split on the
//! plane x = 0 and are joined by two screws across it.

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cuboid, cylinder, ChordTolerance, Solid};
use crate::kit::{Part, PrintTechnology};
use crate::molds::{place_posed, with_pose};
use crate::schema::{Design, HousingParams};
use crate::stack::{ResolvedCore, Stack};
use serde_json::json;

/// z levels of the shell, sensor frame, mm (bottom to top).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ShellLevels {
    pub bottom_z_mm: f64,
    pub bulkhead_z_mm: f64,
    pub pcb_z_mm: f64,
    pub chamber_z_mm: f64,
    pub diffuser_z_mm: f64,
    pub seat_z_mm: f64,
    pub top_z_mm: f64,
    /// Overall sensor height from the shell bottom to the skin's pole, mm.
    pub envelope_height_mm: f64,
}

fn levels(design: &Design, h: &HousingParams, core: &ResolvedCore) -> ShellLevels {
    let top = design.body.base_z_mm();
    let seat = top - core.below_base_mm;
    let diffuser = seat - h.diffuser.thickness_mm;
    let chamber = diffuser - h.diffuser.gap_above_pcb_mm;
    let pcb = chamber - h.led_pcb.thickness_mm;
    let bulkhead = pcb - h.bulkhead_thickness_mm;
    let bottom = bulkhead - h.camera.bay_height_mm;
    ShellLevels {
        bottom_z_mm: bottom,
        bulkhead_z_mm: bulkhead,
        pcb_z_mm: pcb,
        chamber_z_mm: chamber,
        diffuser_z_mm: diffuser,
        seat_z_mm: seat,
        top_z_mm: top,
        envelope_height_mm: design.body.pole_z_mm(0.0) - bottom,
    }
}

/// y position of the joint screws (they run along x across the parting plane): centred
/// between the clearance hole's wall to the light chamber and the head's wall to the outside.
fn screw_y_mm(design: &Design, h: &HousingParams) -> f64 {
    let (lo, hi) = screw_y_range(design, h);
    0.5 * (lo + hi)
}

fn screw_y_range(design: &Design, h: &HousingParams) -> (f64, f64) {
    let m = design.printers.fdm.min_wall_mm;
    (
        h.light_chamber_diameter_mm / 2.0 + h.joint_screw.clearance_diameter_mm / 2.0 + m,
        h.outer_width_mm / 2.0 - h.joint_screw.head_diameter_mm / 2.0 - m,
    )
}

/// The two blind dowel holes in the shell's top face that key calibration fixtures (pin dome,
/// semi-dome holder) to the sensor in one orientation only: at two adjacent corners (azimuths
/// 45 and 135 deg), so no rotation of a square fixture by 90, 180 or 270 deg fits.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FixtureDowelHoles {
    pub diameter_mm: f64,
    pub depth_mm: f64,
    /// Hole centres in the sensor frame (x, y), mm; the holes go down from the base plane.
    pub positions_xy_mm: [[f64; 2]; 2],
}

/// Dowel hole diameter (a 2 mm printed peg with clearance), depth, and inset of the hole centre
/// from the two outer faces at the corner, mm.
const DOWEL_HOLE_DIAMETER_MM: f64 = 2.0;
const DOWEL_HOLE_DEPTH_MM: f64 = 3.0;
const DOWEL_INSET_MM: f64 = 1.8;

/// Where the fixture dowel holes of a housing are.
pub fn fixture_dowel_holes(h: &HousingParams) -> FixtureDowelHoles {
    let a = h.outer_width_mm / 2.0 - DOWEL_INSET_MM;
    FixtureDowelHoles {
        diameter_mm: DOWEL_HOLE_DIAMETER_MM,
        depth_mm: DOWEL_HOLE_DEPTH_MM,
        positions_xy_mm: [[a, a], [-a, a]],
    }
}

/// Rules on the housing: parts fit inside each other and the walls print.
pub fn check_housing_params(
    design: &Design,
    h: &HousingParams,
    core: Option<&ResolvedCore>,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &design.printers.fdm;
    let half = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let errors_before = errs.len();
    let mut pos = |path: &str, v: f64| {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(path, v, "must be above 0"));
        }
    };
    for (p, v) in [
        ("housing.outer_width_mm", h.outer_width_mm),
        ("housing.camera.board_width_mm", h.camera.board_width_mm),
        ("housing.camera.bay_height_mm", h.camera.bay_height_mm),
        (
            "housing.camera.lens_hole_diameter_mm",
            h.camera.lens_hole_diameter_mm,
        ),
        (
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
        ),
        (
            "housing.camera.mount_pilot_diameter_mm",
            h.camera.mount_pilot_diameter_mm,
        ),
        ("housing.bulkhead_thickness_mm", h.bulkhead_thickness_mm),
        (
            "housing.led_pcb.outer_diameter_mm",
            h.led_pcb.outer_diameter_mm,
        ),
        ("housing.led_pcb.thickness_mm", h.led_pcb.thickness_mm),
        (
            "housing.diffuser.outer_diameter_mm",
            h.diffuser.outer_diameter_mm,
        ),
        ("housing.diffuser.thickness_mm", h.diffuser.thickness_mm),
        (
            "housing.diffuser.inner_diameter_mm",
            h.diffuser.inner_diameter_mm,
        ),
        (
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
        ),
        (
            "housing.diffuser.gap_above_pcb_mm",
            h.diffuser.gap_above_pcb_mm,
        ),
        (
            "housing.light_chamber_diameter_mm",
            h.light_chamber_diameter_mm,
        ),
        (
            "housing.joint_screw.clearance_diameter_mm",
            h.joint_screw.clearance_diameter_mm,
        ),
        (
            "housing.joint_screw.pilot_diameter_mm",
            h.joint_screw.pilot_diameter_mm,
        ),
        (
            "housing.joint_screw.head_diameter_mm",
            h.joint_screw.head_diameter_mm,
        ),
        (
            "housing.joint_screw.clamp_length_mm",
            h.joint_screw.clamp_length_mm,
        ),
        (
            "housing.joint_screw.pilot_depth_mm",
            h.joint_screw.pilot_depth_mm,
        ),
    ] {
        pos(p, v);
    }
    if errs.len() > errors_before {
        return;
    }
    let wall = |errs: &mut Vec<ParamError>, path: &str, value: f64, room: f64, what: &str| {
        if room < fdm.min_wall_mm {
            errs.push(ParamError::new(
                path,
                value,
                format!("leaves {room:.2} mm of wall {what}, below the minimum wall {} mm of printer profile 'fdm'", fdm.min_wall_mm),
            ));
        }
    };
    wall(
        errs,
        "housing.camera.board_width_mm",
        h.camera.board_width_mm,
        half - (h.camera.board_width_mm / 2.0 + c),
        "beside the camera bay",
    );
    wall(
        errs,
        "housing.led_pcb.outer_diameter_mm",
        h.led_pcb.outer_diameter_mm,
        half - (h.led_pcb.outer_diameter_mm / 2.0 + c),
        "around the LED PCB seat",
    );
    wall(
        errs,
        "housing.diffuser.outer_diameter_mm",
        h.diffuser.outer_diameter_mm,
        half - (h.diffuser.outer_diameter_mm / 2.0 + c),
        "around the diffuser seat",
    );
    let dowels = fixture_dowel_holes(h);
    let [dx, dy] = dowels.positions_xy_mm[0];
    let skin_r = design.body.rim_radius_mm(0.0);
    if (dx * dx + dy * dy).sqrt() - dowels.diameter_mm / 2.0 < skin_r + c {
        errs.push(ParamError::new(
            "housing.outer_width_mm",
            h.outer_width_mm,
            format!(
                "too narrow for the fixture dowel holes at the corners: they would cut into the skin's footprint (radius {skin_r:.2} mm)"
            ),
        ));
    }
    let ledge =
        |errs: &mut Vec<ParamError>, path: &str, v: f64, inner: f64, outer: f64, what: &str| {
            if inner >= outer {
                errs.push(ParamError::new(
                    path,
                    v,
                    format!(
                        "must be smaller than {what} ({outer:.2} mm) so it has a ledge to rest on"
                    ),
                ));
            }
        };
    ledge(
        errs,
        "housing.light_chamber_diameter_mm",
        h.light_chamber_diameter_mm,
        h.light_chamber_diameter_mm,
        h.diffuser.outer_diameter_mm,
        "the diffuser",
    );
    ledge(
        errs,
        "housing.camera.lens_hole_diameter_mm",
        h.camera.lens_hole_diameter_mm,
        h.camera.lens_hole_diameter_mm,
        h.led_pcb.outer_diameter_mm,
        "the LED PCB",
    );
    if h.led_pcb.inner_diameter_mm < h.camera.lens_hole_diameter_mm {
        errs.push(ParamError::new(
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
            format!(
                "must pass the lens barrel (housing.camera.lens_hole_diameter_mm = {})",
                h.camera.lens_hole_diameter_mm
            ),
        ));
    }
    for (path, inner, outer) in [
        (
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
            h.led_pcb.outer_diameter_mm,
        ),
        (
            "housing.diffuser.inner_diameter_mm",
            h.diffuser.inner_diameter_mm,
            h.diffuser.outer_diameter_mm,
        ),
    ] {
        if inner >= outer {
            errs.push(ParamError::new(
                path,
                inner,
                format!("must be below the outer diameter ({outer} mm)"),
            ));
        }
    }
    if h.camera.mount_hole_spacing_mm > h.camera.board_width_mm {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            "must fit on the camera board",
        ));
    }
    // Mount pilots stay in solid material beside the PCB seat and inside the outer wall.
    let r_mount = h.camera.mount_hole_spacing_mm / 2.0 * std::f64::consts::SQRT_2;
    if r_mount - h.camera.mount_pilot_diameter_mm / 2.0
        < h.led_pcb.outer_diameter_mm / 2.0 + c + fdm.min_wall_mm
    {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            "puts the board's mounting holes under the LED PCB seat",
        ));
    }
    if h.camera.mount_pilot_diameter_mm < fdm.min_hole_diameter_mm
        || h.joint_screw.pilot_diameter_mm < fdm.min_hole_diameter_mm
    {
        errs.push(ParamError::new(
            "housing.joint_screw.pilot_diameter_mm",
            h.joint_screw
                .pilot_diameter_mm
                .min(h.camera.mount_pilot_diameter_mm),
            format!(
                "below the minimum hole {} mm of printer profile 'fdm'",
                fdm.min_hole_diameter_mm
            ),
        ));
    }
    // Joint screws run along x at y = +-screw_y beside the light chamber.
    let (lo, hi) = screw_y_range(design, h);
    if lo > hi {
        errs.push(ParamError::new(
            "housing.joint_screw.head_diameter_mm",
            h.joint_screw.head_diameter_mm,
            format!(
                "the joint screws do not fit between the light chamber and the outer wall with {} mm walls (short by {:.2} mm)",
                fdm.min_wall_mm,
                lo - hi
            ),
        ));
    }
    if h.joint_screw.clamp_length_mm + 1.0 > half {
        errs.push(ParamError::new(
            "housing.joint_screw.clamp_length_mm",
            h.joint_screw.clamp_length_mm,
            "leaves no room for the screw head counterbore",
        ));
    }
    if h.joint_screw.pilot_depth_mm > half - fdm.min_wall_mm {
        errs.push(ParamError::new(
            "housing.joint_screw.pilot_depth_mm",
            h.joint_screw.pilot_depth_mm,
            "runs through the far wall of the shell",
        ));
    }
    if h.diffuser.gap_above_pcb_mm
        < h.joint_screw
            .head_diameter_mm
            .max(h.joint_screw.clearance_diameter_mm)
            + 2.0 * fdm.min_wall_mm
    {
        errs.push(ParamError::new(
            "housing.diffuser.gap_above_pcb_mm",
            h.diffuser.gap_above_pcb_mm,
            "leaves no height for the joint screws beside the light chamber",
        ));
    }
    if let Some(core) = core {
        let r_core = design.body.rim_radius_mm(core.outer_offset_mm);
        if r_core + c >= h.diffuser.outer_diameter_mm / 2.0 {
            errs.push(ParamError::new(
                "housing.diffuser.outer_diameter_mm",
                h.diffuser.outer_diameter_mm,
                format!("must exceed the core's outer diameter ({:.2} mm): the core's rim rests on the diffuser", 2.0 * r_core),
            ));
        }
        if r_core + c + fdm.min_wall_mm > half {
            errs.push(ParamError::new(
                "housing.outer_width_mm",
                h.outer_width_mm,
                "does not fit around the core",
            ));
        }
        if core.below_base_mm < 1.0 {
            errs.push(ParamError::new(
                "core.length_mm",
                design.core.as_ref().map_or(0.0, |c| c.length_mm),
                "the core must reach at least 1 mm below the base plane to seat in the housing",
            ));
        }
    }
}

/// Builds the two shell halves, in print orientation (parting face down).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn build_shell(
    design: &Design,
    h: &HousingParams,
    stack: &Stack,
    tol: ChordTolerance,
) -> Result<(Vec<Part>, ShellLevels), DesignError> {
    let core = stack.core.as_ref().ok_or_else(|| {
        DesignError::Params(crate::error::ParamErrors(vec![ParamError::new(
            "housing",
            "given",
            "the housing seats a core",
        )]))
    })?;
    let lv = levels(design, h, core);
    let w = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let r_core = design.body.rim_radius_mm(core.outer_offset_mm);
    let g = |r: Result<Solid, _>| r.part("shell");
    let shell = g(cuboid([-w, -w, lv.bottom_z_mm], [w, w, lv.top_z_mm]))?;
    let bw = h.camera.board_width_mm / 2.0 + c;
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    // Stacked internal cavities, each overlapping the next by a hair so the union is clean.
    let e = 0.01;
    let mut cut = vec![
        g(cuboid(
            [-bw, -bw, lv.bottom_z_mm - 1.0],
            [bw, bw, lv.bulkhead_z_mm],
        ))?,
        g(cyl(
            h.camera.lens_hole_diameter_mm / 2.0,
            lv.bulkhead_z_mm - e,
            lv.pcb_z_mm + e,
        ))?,
        g(cyl(
            h.led_pcb.outer_diameter_mm / 2.0 + c,
            lv.pcb_z_mm,
            lv.chamber_z_mm + e,
        ))?,
        g(cyl(
            h.light_chamber_diameter_mm / 2.0,
            lv.chamber_z_mm,
            lv.diffuser_z_mm + e,
        ))?,
        g(cyl(
            h.diffuser.outer_diameter_mm / 2.0 + c,
            lv.diffuser_z_mm,
            lv.seat_z_mm + e,
        ))?,
        g(cyl(r_core + c, lv.seat_z_mm, lv.top_z_mm + 1.0))?,
    ];
    let mut holes = Vec::new();
    // Camera board mounting pilots, up from the bay through the bulkhead into solid material.
    let s = h.camera.mount_hole_spacing_mm / 2.0;
    let pilot_depth = h.bulkhead_thickness_mm + 4.0;
    for (x, y) in [(s, s), (-s, s), (-s, -s), (s, -s)] {
        holes.push(g(cyl(
            h.camera.mount_pilot_diameter_mm / 2.0,
            lv.bulkhead_z_mm - 1.0,
            lv.bulkhead_z_mm + pilot_depth,
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    // Joint screws along x: counterbore and clearance in the +x half, pilot in the -x half.
    let js = &h.joint_screw;
    let y = screw_y_mm(design, h);
    let z = 0.5 * (lv.chamber_z_mm + lv.diffuser_z_mm);
    let along_x = |r: f64, x0: f64, x1: f64| {
        cylinder(x1 - x0, r, tol).map(|p| p.rotate_deg(0.0, 90.0, 0.0).translate([x0, 0.0, 0.0]))
    };
    let screw = Solid::union_all(&[
        g(along_x(js.pilot_diameter_mm / 2.0, -js.pilot_depth_mm, e))?,
        g(along_x(
            js.clearance_diameter_mm / 2.0,
            0.0,
            js.clamp_length_mm + e,
        ))?,
        g(along_x(
            js.head_diameter_mm / 2.0,
            js.clamp_length_mm,
            w + 1.0,
        ))?,
    ])
    .part("shell")?;
    for sy in [y, -y] {
        holes.push(screw.translate([0.0, sy, z]));
    }
    // Fixture dowel holes, down from the top face.
    let dowels = fixture_dowel_holes(h);
    for [x, y] in dowels.positions_xy_mm {
        holes.push(g(cyl(
            dowels.diameter_mm / 2.0,
            lv.top_z_mm - dowels.depth_mm,
            lv.top_z_mm + 1.0,
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    cut.push(Solid::compose(&holes));
    let body = shell
        .difference(&Solid::union_all(&cut).part("shell")?)
        .part("shell")?;
    let (pos, neg) = body.split_by_plane([1.0, 0.0, 0.0], 0.0);
    let params = json!({
        "levels": lv,
        "housing": h,
        "core_seat_radius_mm": r_core + c,
        "parting_plane": "x = 0 (through the sensor axis)",
        "joint_screws": {"y_mm": [y, -y], "z_mm": z, "axis": "x"},
        "fixture_dowel_holes": dowels,
        "camera_mount_holes_xy_mm": [[s, s], [-s, s], [-s, -s], [s, -s]],
        "camera_mount_pilot_z_mm": [lv.bulkhead_z_mm - 1.0, lv.bulkhead_z_mm + pilot_depth],
        // Each internal cavity overlaps the next one up by this much (a hair, see above).
        "overlap_mm": e,
        "print_orientation": "parting face down",
    });
    let tech = PrintTechnology::Fdm;
    let part = |(solid, pose): (Solid, crate::geometry::Affine), tag: &str, what: &str| {
        Part {
        name: format!("shell_half_{tag}"),
        role: "shell_half".into(),
        description: format!("Sensor shell half {tag} ({what}); camera bay, LED PCB, diffuser and contact-module seats"),
        material: h.material.clone(),
        print_technology: tech,
        solid,
        params: with_pose(params.clone(), &pose),
        group: None,
    }
    };
    let parts = vec![
        part(
            place_posed(&pos, &crate::geometry::rotation_deg(0.0, -90.0, 0.0)),
            "a",
            "screw heads",
        ),
        part(
            place_posed(&neg, &crate::geometry::rotation_deg(0.0, 90.0, 0.0)),
            "b",
            "screw pilots",
        ),
    ];
    Ok((parts, lv))
}
