//! The housing as a section family ([`HousingFamily`]): its shell parts, its members of the
//! assembled sensor (the filling gel, the LED ring PCB, the camera board and the diffuser), its
//! bought items, its laser-cut diffuser, the filling gel's pour, the insertion paths down the
//! round tube and its assembly steps (R-Tac0 Sec. III-B1..B4).

use super::{
    build_shell, check_housing_params, filling_gel_profile, filling_gel_volume_mm3, gel_fill,
    joint_screw_name, levels, HousingParams, HousingStyle, ShellLevels,
};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cuboid, cylinder, revolve, ChordTolerance, GeometryError, Solid};
use crate::materials::{cure_text, CastReport, MaterialKind};
use crate::optics::elements::{ring_of_lights, FlatInterface, Lens, Light};
use crate::parts::axial_ring;
use crate::parts::context::{Context, Stack};
use crate::parts::cut_part::{CutPart, Operation, Outline};
use crate::parts::family::envelope;
use crate::parts::family::{
    named, AssemblyInput, AssemblyStep, Built, Family, FamilyInput, FillingPour, InnerCavity,
    InsertionPath, FILLING_GEL,
};
use crate::parts::fasteners::{metric_from_pilot, metric_name};
use crate::parts::{ExactShape, Member, MemberKind, Part, ProcedureAction, ProcedureStep};
use crate::schema::shared::GelFill;
use serde_json::json;

/// The housing (`housing` in a design): the sensor shell in one of its two styles.
pub struct HousingFamily;

/// The shell's levels of `h` around the stack's core; `None` without a core (the checks refuse
/// a housing without one).
fn shell_levels(ctx: &Context<'_>, h: &HousingParams, stack: &Stack) -> Option<ShellLevels> {
    stack.core.as_ref().map(|core| levels(ctx, h, core))
}

impl Family for HousingFamily {
    type Params = HousingParams;
    const PATH: &'static str = "housing";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[
        ("shell_collar", &["housing"]),
        ("shell_tube", &["housing"]),
        ("shell_base", &["housing"]),
        ("shell_half", &["housing"]),
    ];

    fn materials(h: &HousingParams) -> Vec<(String, &str, &'static [MaterialKind])> {
        let mut out = vec![(
            "housing.material".to_string(),
            h.material.as_str(),
            &[MaterialKind::Print][..],
        )];
        if let Some(f) = &h.filling_gel {
            out.push((
                "housing.filling_gel.material".into(),
                f.material.as_str(),
                &[MaterialKind::Cast],
            ));
        }
        out
    }

    fn check(h: &HousingParams, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>) {
        match &stack.core {
            Some(core) => check_housing_params(ctx, h, Some(core), errs),
            None => errs.push(ParamError::new(
                "housing",
                "given",
                "the housing seats a core: give core: or remove housing:",
            )),
        }
    }

    fn check_without_stack(h: &HousingParams, ctx: &Context<'_>, errs: &mut Vec<ParamError>) {
        check_housing_params(ctx, h, None, errs);
    }

    fn build(h: &HousingParams, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let (parts, levels) = build_shell(h, input)?;
        Ok(Built {
            parts,
            summary: vec![
                ("shell_levels", json!(&levels)),
                envelope(input.ctx, h.outer_width_mm, levels.envelope_height_mm),
            ],
        })
    }

    fn members(h: &HousingParams, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        let FamilyInput { ctx, stack, tol } = input;
        let Some(lv) = shell_levels(ctx, h, stack) else {
            return Ok(Vec::new());
        };
        let mut out = Vec::new();
        if let (Some(f), Some(c)) = (&h.filling_gel, &stack.core) {
            let pl = filling_gel_profile(ctx, h, c, &lv, tol);
            let solid = revolve(&pl, tol)
                .and_then(|m| Solid::from_mesh(&m))
                .part(FILLING_GEL)?;
            out.push(Member {
                name: FILLING_GEL.into(),
                kind: MemberKind::Cast,
                description: match gel_fill(h) {
                    Some(GelFill::Core) => {
                        format!("Internal filling gel ({}): the core to its open end", f.material)
                    }
                    _ => format!(
                        "Internal filling gel ({}): the core, the diffuser's opening and the light chamber",
                        f.material
                    ),
                },
                solid,
                fix: match gel_fill(h) {
                    Some(GelFill::Core) => vec!["core.length_mm".into()],
                    _ => vec![
                        "housing.light_chamber_diameter_mm".into(),
                        "housing.diffuser.inner_diameter_mm".into(),
                    ],
                },
                // inside the core's inner surface above the core's end, and under it only
                // where no layer is: nested with the layers and the core by construction
                nested_by_stack: true,
                features: Default::default(),
                exact: Some(ExactShape::Revolved {
                    profile_rz_mm: pl.points.clone(),
                }),
                material: Some(f.material.clone()),
            });
        }
        out.extend(bought_envelopes(h, &lv, tol)?);
        Ok(out)
    }

    fn lights(h: &HousingParams, ctx: &Context<'_>, stack: &Stack) -> Vec<Light> {
        // the LEDs on the ring PCB's top face, at its mid-width, facing the skin (R-Tac0
        // Sec. III-B2: eight LUXEON 2835 white LEDs, evenly spaced; the first on +x)
        let Some(lv) = shell_levels(ctx, h, stack) else {
            return Vec::new();
        };
        let r = (h.led_pcb.outer_diameter_mm + h.led_pcb.inner_diameter_mm) / 4.0;
        ring_of_lights(
            h.led_pcb.led_count,
            r,
            lv.chamber_z_mm,
            0.0,
            Some([0.0, 0.0, 1.0]),
            |_| [1.0, 1.0, 1.0],
        )
    }

    fn lens(h: &HousingParams, ctx: &Context<'_>, stack: &Stack) -> Option<Lens> {
        let lv = shell_levels(ctx, h, stack)?;
        Some(Lens {
            front_z_mm: super::lens_front_z_mm(h, &lv)?,
            view_angle_deg: h.camera.view_angle_deg,
            what: "housing.camera.lens_height_mm: the lens's front over the board's mount".into(),
        })
    }

    fn flat_interfaces(h: &HousingParams, ctx: &Context<'_>, stack: &Stack) -> Vec<FlatInterface> {
        // the gel's flat free surface: the camera's rays enter the gel there (issue 97)
        let (Some(gel), Some(lv)) = (&h.filling_gel, shell_levels(ctx, h, stack)) else {
            return Vec::new();
        };
        let Some(z_mm) = super::gel_free_surface_z_mm(h, &lv) else {
            return Vec::new();
        };
        let at = match gel_fill(h) {
            Some(GelFill::Core) => "at the core's open end",
            _ => "at the LED PCB's face",
        };
        vec![FlatInterface {
            z_mm,
            above: gel.material.clone(),
            what: format!("housing.filling_gel: the gel's free surface {at}"),
        }]
    }

    fn filling_pour<'p>(
        h: &'p HousingParams,
        input: FamilyInput<'_>,
        _cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'p>>, DesignError> {
        let FamilyInput { ctx, stack, .. } = input;
        let (Some(gel), Some(core)) = (&h.filling_gel, &stack.core) else {
            return Ok(None);
        };
        let lv = levels(ctx, h, core);
        Ok(Some(FillingPour {
            gel,
            volume_mm3: filling_gel_volume_mm3(ctx, h, core, &lv),
            holder_roles: &["shell_collar", "shell_tube", "shell_half"],
            how: match gel_fill(h) {
                Some(GelFill::Core) => "Poured into the assembled shell, pole-down, before the camera goes on: it fills the core up to its open end, flush with the diffuser's top face, and leaves the diffuser's opening and the light chamber air; its flat free surface is the window the camera looks through (R-Tac0 Sec. III-B1).",
                _ => "Poured into the assembled shell, pole-down, before the camera goes on: it fills the core, the diffuser's opening and the light chamber up to the LED PCB's face (R-Tac0 Sec. III-B1).",
            },
            member: None,
        }))
    }

    fn insertion_paths(
        h: &HousingParams,
        input: FamilyInput<'_>,
    ) -> Result<Vec<InsertionPath>, DesignError> {
        insertion_paths(h, input)
    }

    fn cut_parts(h: &HousingParams) -> Vec<CutPart> {
        let d = &h.diffuser;
        vec![CutPart {
            name: "diffuser".into(),
            description: format!(
                "Diffuser ring: double-sided frosted acrylic, {:.1} mm thick, outer diameter \
                 {:.1} mm, inner diameter {:.1} mm (R-Tac0 Sec. III-B2)",
                d.thickness_mm, d.outer_diameter_mm, d.inner_diameter_mm
            ),
            material: "pmma".into(),
            thickness_mm: d.thickness_mm,
            outlines: vec![
                (
                    Operation::Cut,
                    Outline::centred_circle(d.outer_diameter_mm / 2.0),
                ),
                (
                    Operation::Cut,
                    Outline::centred_circle(d.inner_diameter_mm / 2.0),
                ),
            ],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        }]
    }

    fn bought_items(h: &HousingParams) -> Vec<String> {
        bought_items(h)
    }

    fn assembly_steps(h: &HousingParams, input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let AssemblyInput { parts, filling, .. } = input;
        assembly_steps(h, parts, filling)
    }
}

/// The bought envelopes of the housing: the LED ring PCB, the camera board and the diffuser,
/// in the sensor frame at the shell's levels `lv`.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
fn bought_envelopes(
    h: &HousingParams,
    lv: &ShellLevels,
    tol: ChordTolerance,
) -> Result<Vec<Member>, DesignError> {
    type Exact = Result<(Solid, ExactShape), GeometryError>;
    let block = |min_mm: [f64; 3], max_mm: [f64; 3]| -> Exact {
        Ok((cuboid(min_mm, max_mm)?, ExactShape::Box { min_mm, max_mm }))
    };
    let bought = |name: &str, description: String, r: Exact, fix: &[&str]| {
        Ok::<_, DesignError>(crate::assembly::bought(
            name,
            description,
            r.part(name)?,
            fix,
        ))
    };
    // a board's envelope: diameters [outer, inner] and [bottom z, thickness], mm; sized by
    // `housing.<key>`'s outer diameter and thickness
    let annulus = |name: &str, description: String, key: &str, d: [f64; 2], z: [f64; 2]| {
        let fix = [
            format!("housing.{key}.outer_diameter_mm"),
            format!("housing.{key}.thickness_mm"),
        ];
        let r = axial_ring(d[0] / 2.0, d[1] / 2.0, z[0], z[0] + z[1], tol);
        bought(name, description, r, &[fix[0].as_str(), fix[1].as_str()])
    };
    let bw = h.camera.board_width_mm / 2.0;
    let (z0, z1) = match (h.style, lv.base_top_z_mm) {
        (HousingStyle::RoundTube, Some(top)) => (top, top + h.camera.bay_height_mm),
        _ => (lv.bulkhead_z_mm - h.camera.bay_height_mm, lv.bulkhead_z_mm),
    };
    Ok(vec![
        annulus(
            "led_pcb_envelope",
            format!("LED ring PCB (bought), {} LEDs", h.led_pcb.led_count),
            "led_pcb",
            [h.led_pcb.outer_diameter_mm, h.led_pcb.inner_diameter_mm],
            [lv.pcb_z_mm, h.led_pcb.thickness_mm],
        )?,
        // after the LED PCB: an overlap names the later member's parameters first, and the
        // board's height is what a board that reaches the PCB needs changed
        bought(
            "camera_board_envelope",
            format!(
                "Camera board with its components (bought): {}",
                h.camera.module
            ),
            block([-bw, -bw, z0], [bw, bw, z1]),
            &[
                "housing.camera.bay_height_mm",
                "housing.camera.board_width_mm",
            ],
        )?,
        annulus(
            "diffuser_envelope",
            "Diffuser ring (laser-cut acrylic)".into(),
            "diffuser",
            [h.diffuser.outer_diameter_mm, h.diffuser.inner_diameter_mm],
            [lv.diffuser_z_mm, h.diffuser.thickness_mm],
        )?,
    ])
}

/// The round shell's insertion paths: the LED PCB down the tube's light chamber and the core
/// down the collar (the square shell's halves close around their parts: no paths).
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
fn insertion_paths(
    h: &HousingParams,
    input: FamilyInput<'_>,
) -> Result<Vec<InsertionPath>, DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let Some(core) = &stack.core else {
        return Ok(Vec::new());
    };
    if h.style != HousingStyle::RoundTube {
        return Ok(Vec::new());
    }
    let lv = levels(ctx, h, core);
    let cyl = |name: &str, r: f64, z0: f64, z1: f64| {
        cylinder(z1 - z0, r, tol)
            .map(|s| s.translate([0.0, 0.0, z0]))
            .part(name)
    };
    Ok(vec![
        InsertionPath {
            member: "led_pcb_envelope".into(),
            through: "shell_tube".into(),
            solid: cyl(
                "led_pcb_envelope",
                h.led_pcb.outer_diameter_mm / 2.0,
                lv.pcb_z_mm,
                lv.diffuser_z_mm + 1.0,
            )?,
            fix: vec![
                "housing.light_chamber_diameter_mm".into(),
                "housing.led_pcb.outer_diameter_mm".into(),
            ],
        },
        InsertionPath {
            member: "core_envelope".into(),
            through: "shell_collar".into(),
            solid: cyl(
                "core_envelope",
                ctx.body.rim_radius_mm(core.outer_offset_mm),
                lv.seat_z_mm,
                lv.top_z_mm + 1.0,
            )?,
            fix: vec![
                "housing.fit_clearance_mm".into(),
                "core.outer_diameter_mm".into(),
            ],
        },
    ])
}

/// The housing's lines of the bought-items list: the camera, the LED ring PCB, the diffuser,
/// the joint screws and (round tube) the glue.
fn bought_items(h: &HousingParams) -> Vec<String> {
    let mut v = vec![
        format!(
            "Camera: {} on a {:.1} mm square board, fixed with 4 self-tapping screws{} ({:.1} mm pilots, {:.1} mm square pattern)",
            h.camera.module,
            h.camera.board_width_mm,
            metric_from_pilot(h.camera.mount_pilot_diameter_mm)
                .map(|d| format!(" {}", metric_name(d)))
                .unwrap_or_default(),
            h.camera.mount_pilot_diameter_mm,
            h.camera.mount_hole_spacing_mm
        ),
        format!(
            "LED ring PCB: {} LEDs, outer diameter {:.1} mm, inner diameter {:.1} mm, {:.1} mm thick",
            h.led_pcb.led_count, h.led_pcb.outer_diameter_mm, h.led_pcb.inner_diameter_mm, h.led_pcb.thickness_mm
        ),
        format!(
            "Diffuser: laser-cut double-sided frosted acrylic (cut/diffuser.dxf), outer diameter {:.1} mm, inner diameter {:.1} mm, {:.1} mm thick, {:.1} mm above the PCB",
            h.diffuser.outer_diameter_mm, h.diffuser.inner_diameter_mm, h.diffuser.thickness_mm, h.diffuser.gap_above_pcb_mm
        ),
        format!(
            "2 joint screws{}{}: {:.1} mm clearance, {:.1} mm head, length about {:.0} mm (clamp {:.1} mm + pilot {:.1} mm)",
            joint_screw_name(h)
            .map(|n| format!(" {n}"))
            .unwrap_or_default(),
            match h.style {
                HousingStyle::RoundTube =>
                    " (pan head), up through the base's flange into the tube wall",
                HousingStyle::SquareSplit => " across the two halves",
            },
            h.joint_screw.clearance_diameter_mm,
            h.joint_screw.head_diameter_mm,
            (h.joint_screw.clamp_length_mm + h.joint_screw.pilot_depth_mm - 0.5).floor(),
            h.joint_screw.clamp_length_mm,
            h.joint_screw.pilot_depth_mm
        ),
    ];
    if h.style == HousingStyle::RoundTube {
        v.push(
            "Cyanoacrylate glue (gel): the diffuser disc onto the tube's top face, the collar \
             onto the diffuser"
                .into(),
        );
    }
    v
}

/// The housing's assembly steps, the shell from the inside out: LED PCB, diffuser, contact
/// module, camera, the shell joined, with the filling gel's pour where it goes in (R-Tac0
/// Sec. III-B1..B4).
fn assembly_steps(
    h: &HousingParams,
    parts: &[Part],
    filling: Option<&CastReport>,
) -> Vec<AssemblyStep> {
    let mut out = Vec::new();
    let named = |role: &str| named(parts, role);
    let joint = joint_screw_name(h).map_or_else(
        || "the joint screws".to_string(),
        |n| format!("the 2 joint screws {n}"),
    );
    let camera = metric_from_pilot(h.camera.mount_pilot_diameter_mm)
        .map_or_else(String::new, |d| format!(" M{d}"));
    let tube = named("shell_tube");
    let collar = named("shell_collar");
    let base = named("shell_base");
    let halves = named("shell_half");
    match (tube.first(), collar.first(), halves.first()) {
        (Some(t), Some(k), _) => {
            out.push(AssemblyStep::Text(format!(
                "Drop the LED ring PCB ({} LEDs, facing up) down the light chamber of {t} \
                 onto the ledge above the camera bay (R-Tac0 Sec. III-B2: press-fitted), \
                 its wires down through the bay.",
                h.led_pcb.led_count
            )));
            out.push(AssemblyStep::Text(format!(
                "Glue the diffuser disc onto the top face of {t} with cyanoacrylate gel, \
                 {:.1} mm above the PCB and centred on the chamber; then glue {k} onto the \
                 diffuser, flush with the tube's outside.",
                h.diffuser.gap_above_pcb_mm
            )));
            out.push(AssemblyStep::Text(format!(
                "Push the contact module (the core with its layers) into {k} until the \
                 core's rim rests on the diffuser's inner edge."
            )));
            if let Some(c) = filling {
                out.push(AssemblyStep::Step(filling_step(c)));
            }
        }
        (t, _, a) => {
            let (into, module_seat) = match (t, a) {
                (Some(t), _) => (
                    t.clone(),
                    format!("the contact-module seat at the top of {t}"),
                ),
                (None, Some(a)) => (a.clone(), format!("the contact-module seat of {a}")),
                (None, None) => ("the shell".into(), "its seat".into()),
            };
            out.push(AssemblyStep::Text(format!(
                "Press the LED ring PCB ({} LEDs, facing up) into its seat in {into} \
                 (R-Tac0 Sec. III-B2: press-fitted), its wires down through the camera bay.",
                h.led_pcb.led_count
            )));
            out.push(AssemblyStep::Text(format!(
                "Lay the diffuser ring into its seat, {:.1} mm above the PCB.",
                h.diffuser.gap_above_pcb_mm
            )));
            out.push(AssemblyStep::Text(format!(
                "Push the contact module (the core with its layers) into {module_seat} \
                 until its rim rests on the diffuser."
            )));
        }
    }
    let into = tube
        .first()
        .or(halves.first())
        .cloned()
        .unwrap_or_else(|| "the shell".into());
    match (base.first(), halves.get(1)) {
        (Some(b), _) => {
            out.push(AssemblyStep::Text(format!(
                "Screw the camera board onto the spigot of {b} with 4 self-tapping \
                 screws{camera} ({:.1} mm pilots), its cable through the slot.",
                h.camera.mount_pilot_diameter_mm
            )));
            out.push(AssemblyStep::Text(format!(
                "Set {b} under {into}, spigot into the bay, and join them with {joint} up \
                 through the flange."
            )));
        }
        (None, Some(b)) => {
            // the bulkhead spans both halves: close them before the camera goes on
            out.push(AssemblyStep::Text(format!(
                "Close {b} onto {into} and join the halves with {joint} across them."
            )));
            if let Some(c) = filling {
                out.push(AssemblyStep::Step(filling_step(c)));
            }
            out.push(AssemblyStep::Text(format!(
                "Screw the camera board up against the bulkhead with 4 self-tapping \
                 screws{camera} ({:.1} mm pilots), lens through the lens hole.",
                h.camera.mount_pilot_diameter_mm
            )));
        }
        _ => {}
    }
    out
}

/// The filling gel's pour and cure, with the sensor pole-down and the camera not yet on
/// (R-Tac0 Sec. III-B1).
fn filling_step(c: &CastReport) -> ProcedureStep {
    ProcedureStep {
        action: ProcedureAction::Pour,
        text: format!(
            "Step {}: stand the shell pole-down (the contact module in its seat, the camera not \
             yet on), mix and degas {} and pour it through the LED PCB's bore until it wets \
             the PCB's underside all round ({:.2} mL to fill): it fills the core, the diffuser's \
             opening and the light chamber and glues the core to the shell (R-Tac0 \
             Sec. III-B1). Let it cure ({}) before the camera goes on.",
            c.step,
            c.mix_text(),
            c.layer_volume_ml.unwrap_or(c.cavity_volume_ml),
            cure_text(&c.notes)
        ),
    }
}
