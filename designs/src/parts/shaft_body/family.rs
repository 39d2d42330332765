//! The shaft body as a section family ([`ShaftBodyFamily`]): its parts (the body and the
//! robot mount), the lens window's optics, the LED ring's lights, its cut lens window, its
//! members and bought items, the filling gel's pour and the assembly steps.

use super::checks::check_params;
use super::dimensions::{levels, radii, twin_params};
use super::members::{bought_items, members};
use super::params::ShaftBodyParams;
use super::solids::{build_body, filling_gel_solid, tip_fitting_solid};
use super::view::view_fraction;
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::materials::CastReport;
use crate::optics::elements::{ring_of_lights, FlatInterface, Lens, Light};
use crate::parts::context::{Context, Stack};
use crate::parts::cut_part::{CutPart, Operation, Outline};
use crate::parts::family::envelope;
use crate::parts::family::{
    named, AssemblyInput, AssemblyStep, Built, Family, FamilyInput, FillingPour, InnerCavity,
    FILLING_GEL,
};
use crate::parts::part::SkinVolume;
use crate::parts::{Member, MemberKind, ProcedureAction, ProcedureStep};
use serde_json::json;

/// The shaft-body family (`shaft_body`, with its `robot_mount`): the body, the tip's fitting
/// with the printed skin, the bayonet, the camera and the LED ring (Pestell et al. Sec. III-A).
pub struct ShaftBodyFamily;

impl Family for ShaftBodyFamily {
    type Params = ShaftBodyParams;
    const PATH: &'static str = "shaft_body";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[
        (
            "tip_fitting",
            &["shaft_body.bayonet.lug_width_mm", "shaft_body.tip_fitting"],
        ),
        (
            "shaft_body",
            &["shaft_body.bayonet.groove_width_mm", "shaft_body"],
        ),
        (
            "robot_mount",
            &[
                "shaft_body.robot_mount.bayonet.groove_width_mm",
                "shaft_body.robot_mount",
            ],
        ),
    ];

    fn flat_interfaces(
        sb: &ShaftBodyParams,
        ctx: &Context<'_>,
        _stack: &Stack,
    ) -> Vec<FlatInterface> {
        // the acrylic lens window's faces (Pestell et al. Sec. III-A: "an inserted acrylic
        // lens"), the filling gel over it when there is one, else the air of the tip's inside
        let lv = levels(ctx, sb);
        let (above, what) = match &sb.filling_gel {
            Some(g) => (g.material.clone(), "under the filling gel"),
            None => (
                crate::optics::elements::AIR.to_string(),
                "under the tip's air",
            ),
        };
        vec![
            FlatInterface {
                z_mm: lv.shaft_top_z_mm,
                // the window is acrylic (Sec. III-A): the materials table's `pmma`
                above: "pmma".into(),
                what: "shaft_body.lens_window: the acrylic window's bottom face".into(),
            },
            FlatInterface {
                z_mm: lv.lip_z_mm,
                above,
                what: format!("shaft_body.lens_window: the window's top face, {what}"),
            },
        ]
    }

    fn lens(sb: &ShaftBodyParams, ctx: &Context<'_>, _stack: &Stack) -> Option<Lens> {
        Some(Lens {
            front_z_mm: levels(ctx, sb).lens_z_mm,
            view_angle_deg: Some(sb.camera.view_angle_deg),
            what: "shaft_body.camera.lens_height_mm: the lens's front over the board's top".into(),
        })
    }

    fn lights(sb: &ShaftBodyParams, ctx: &Context<'_>, _stack: &Stack) -> Vec<Light> {
        // the LEDs' tops at the shaft's top face, under the window, at the ring's mid-width,
        // facing the skin (Pestell et al. Sec. III-A: "a PCB ring of six LEDs"; white and the
        // first on +x, not given)
        let l = &sb.led_ring;
        ring_of_lights(
            l.led_count,
            (l.outer_diameter_mm + l.inner_diameter_mm) / 4.0,
            levels(ctx, sb).shaft_top_z_mm,
            0.0,
            Some([0.0, 0.0, 1.0]),
            |_| [1.0, 1.0, 1.0],
        )
    }

    fn estimated_triangles(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> f64 {
        let FamilyInput { ctx, stack, tol } = input;
        // the body's and the fitting's cylinders, seats and bayonet bands: about 30 and 27
        // circles of their outer radius
        let r = radii(ctx, sb, stack);
        30.0 * tol.circle_segments(r.base_outer_mm) as f64
            + 27.0 * tol.circle_segments(r.fitting_outer_mm) as f64
    }

    fn cut_parts(sb: &ShaftBodyParams) -> Vec<CutPart> {
        let w = &sb.lens_window;
        vec![CutPart {
            name: "lens_window".into(),
            description: format!(
                "Lens window: clear acrylic, {:.1} mm thick, diameter {:.1} mm (Pestell et al. \
                 Sec. III-A: the acrylic lens the gel is filled against)",
                w.thickness_mm, w.diameter_mm
            ),
            material: "pmma".into(),
            thickness_mm: w.thickness_mm,
            outlines: vec![(Operation::Cut, Outline::centred_circle(w.diameter_mm / 2.0))],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        }]
    }

    fn check(sb: &ShaftBodyParams, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>) {
        check_params(ctx, sb, stack, errs);
    }

    fn build(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let FamilyInput { ctx, tol, .. } = input;
        let mut parts = vec![build_body(sb, input)?];
        if let Some(m) = &sb.robot_mount {
            parts.push(crate::parts::robot_mount::build_mount(ctx, sb, m, tol)?);
        }
        let lv = levels(ctx, sb);
        let camera_view = json!({
            "tip_inner_surface_fraction_seen": view_fraction(sb, input),
            "lens_z_mm": lv.lens_z_mm,
            "view_angle_deg": sb.camera.view_angle_deg,
            "focal_length_mm": sb.camera.focal_length_mm,
            "rule": "area fraction of the skin's inner surface above the base plane inside the lens's view cone whose ray passes the lip's opening, the LED ring's bore and the shaft's bore (the pins' shadows and the gel's refraction ignored)",
        });
        Ok(Built {
            parts,
            summary: vec![
                ("shaft_levels", json!(&lv)),
                envelope(ctx, sb.base.outer_diameter_mm, lv.envelope_height_mm),
                ("camera_view", camera_view),
            ],
        })
    }

    fn printed_with_skin(
        sb: &ShaftBodyParams,
        input: FamilyInput<'_>,
    ) -> Result<Vec<SkinVolume>, DesignError> {
        // The tip's fitting prints with the outermost (printed) layer, as a further volume of
        // its object (Pestell et al. Sec. III-A).
        let name = input.stack.layers.last().map_or("", |l| l.name.as_str());
        Ok(vec![SkinVolume {
            name: "tip_fitting".into(),
            role: "tip_fitting".into(),
            description: format!(
                "The tip's rigid bayonet fitting, printed in the second material with {name} (Pestell et al. Sec. III-A)"
            ),
            material: sb.tip_fitting.material.clone(),
            solid: tip_fitting_solid(sb, input).part(name)?,
            params: twin_params(input.ctx, sb, input.stack),
        }])
    }

    fn members(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        members(input.ctx, sb, input.tol)
    }

    fn bought_items(sb: &ShaftBodyParams) -> Vec<String> {
        let mut v = bought_items(sb);
        if let Some(m) = &sb.robot_mount {
            v.extend(crate::parts::robot_mount::bought_items(m));
        }
        v
    }

    fn filling_pour<'p>(
        sb: &'p ShaftBodyParams,
        input: FamilyInput<'_>,
        cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'p>>, DesignError> {
        // The clear gel between the skin and the lens window (Pestell et al. Sec. III-A).
        let Some(f) = &sb.filling_gel else {
            return Ok(None);
        };
        let (gel, exact) = cavity(0)
            .and_then(|c| filling_gel_solid(sb, input, c))
            .part(FILLING_GEL)?;
        Ok(Some(FillingPour {
            gel: f,
            volume_mm3: gel.volume(),
            holder_roles: &["printed_skin", "tip_fitting"],
            how: "Poured into the tip, pole-down, round the pins and up into the lip's opening; the lens window is then laid on (Pestell et al. Sec. III-A).",
            member: Some(Member {
                name: FILLING_GEL.into(),
                kind: MemberKind::Cast,
                description: format!(
                    "Clear gel ({}) between the skin and the lens window, round the pins",
                    f.material
                ),
                solid: gel,
                fix: vec!["shaft_body.tip_fitting.lip_width_mm".into()],
                // the skin's cavity less its pins and tips: nested with them by construction
                nested_by_stack: true,
                features: Default::default(),
                exact: Some(exact),
                material: Some(f.material.clone()),
            }),
        }))
    }

    fn assembly_steps(sb: &ShaftBodyParams, input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let AssemblyInput {
            ctx,
            parts,
            filling,
        } = input;
        let mut out = Vec::new();
        let body = named(parts, "shaft_body")
            .first()
            .cloned()
            .unwrap_or_else(|| "the body".into());
        let fitting = named(parts, "tip_fitting")
            .first()
            .cloned()
            .unwrap_or_else(|| "the tip's fitting".into());
        let screws = crate::parts::fasteners::metric_from_pilot(sb.camera.mount_pilot_diameter_mm)
            .map_or_else(String::new, |d| format!(" M{d}"));
        let bayonet = &ctx.printers.fdm.bayonet;
        out.push(AssemblyStep::Text(format!(
            "Press the LED ring PCB ({} LEDs, facing up) into its seat at the top of {body}, its \
             wires down the bore, through the ceiling's hole beside the lens and out through the \
             cable slot (Pestell et al. Sec. III-A).",
            sb.led_ring.led_count
        )));
        out.push(AssemblyStep::Text(format!(
            "Screw the camera board into the pocket under {body}, up against the ceiling, with 4 \
             self-tapping screws{screws} ({:.1} mm pilots), the lens up through the ceiling's \
             hole and the cable out through the slot; focus the adjustable lens on the pins once \
             the tip is on (Pestell et al. Sec. III-A2).",
            sb.camera.mount_pilot_diameter_mm
        )));
        if let Some(c) = filling {
            out.push(AssemblyStep::Step(tip_filling_step(c, &fitting)));
        }
        if let Some(m) = &sb.robot_mount {
            out.push(AssemblyStep::Text(format!(
                "Bolt `robot_mount` to the tool flange of the {} with {} socket head cap \
                 screws, its locating pin in the flange's pin hole; set the base of {body} into \
                 its cup, the {n} lugs down the entry grooves and the camera's cable out through \
                 the window, and turn {body} {:.0} deg clockwise (seen from the tip's pole) \
                 until it stops (Pestell et al. Sec. III-A3: the body attaches to the robot's \
                 mount by a bayonet).",
                m.robot,
                m.bolt_count,
                m.bayonet.lock_angle_deg,
                n = bayonet.lug_count
            )));
        }
        out.push(AssemblyStep::Text(format!(
            "Twist the tip onto {body}: the {n} lugs of {fitting} down the {n} entry grooves, \
             push it home, then turn it {:.0} deg counter-clockwise (seen from the tip's pole) \
             until the lugs stop at the grooves' closed ends; the {:.0} deg ramp draws it down \
             onto the shaft (Pestell et al. Sec. III-A: a bayonet mount for replacing tips).",
            sb.bayonet.lock_angle_deg,
            bayonet.ramp_deg,
            n = bayonet.lug_count
        )));
        out
    }
}

/// The filling gel's pour into the printed tip, pole-down, closed by the lens window
/// (Pestell et al. Sec. III-A).
pub fn tip_filling_step(c: &CastReport, fitting: &str) -> ProcedureStep {
    ProcedureStep {
        action: ProcedureAction::Pour,
        text: format!(
            "Step {}: stand the tip pole-down, {fitting} up, mix and degas {} and pour it into \
             the tip round the pins until it is level with the top of the lip's opening \
             ({:.2} mL to fill); lay the lens window into its seat in {fitting} on the lip, \
             sliding it on from one side so that no air is caught (Pestell et al. Sec. III-A). \
             Let it cure ({}) before the tip goes on the body.",
            c.step,
            c.mix_text(),
            c.layer_volume_ml.unwrap_or(c.cavity_volume_ml),
            crate::materials::cure_text(&c.notes)
        ),
    }
}
