//! A printed spacer ring under the skin's base (`spacer` in a design): it raises a contact
//! module by its height over whatever it is mounted on, the skin's rim resting on its top face
//! and the core, if any, passing through its bore. The smallest complete section family, and
//! the worked example of docs/src/development.md ("Adding a part family"): its parameters,
//! rules, printed part, member of the assembly, bought items and assembly step are all here,
//! and one line of [`crate::parts::registry`] registers it; its CadQuery twin is
//! `export/python/twins/cq_spacer.py`.
//!
//! Frame: the sensor frame (docs/conventions.md): the ring stands from
//! `z = base_z - height_mm` up to the base plane `z = base_z`, centred on the axis.

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{ChordTolerance, GeometryError, Solid};
use crate::materials::MaterialKind;
use crate::parts::context::{Context, Stack};
use crate::parts::family::{named, AssemblyInput, AssemblyStep, Built, Family, FamilyInput};
use crate::parts::part::{Part, PrintTechnology};
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::{check_above_zero, z_cylinder};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The spacer ring's parameters (`spacer` in a design).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpacerParams {
    /// Material key in the materials table; a print material (`pla_black`).
    pub material: String,
    /// Outer diameter of the ring, mm, > 0: at least the skin's diameter at the base plane,
    /// whose rim rests on the ring's top face.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the bore, mm, > 0: below the skin's diameter at the base plane (the rim
    /// must rest on the ring), above the core's outer diameter there (the core passes
    /// through), and leaving the FDM printer's `min_wall_mm` to the outer diameter.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Height of the ring along the axis, from the base plane down, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
}

/// The spacer family.
pub struct SpacerFamily;

impl Family for SpacerFamily {
    type Params = SpacerParams;
    const PATH: &'static str = "spacer";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[(
        "spacer",
        &["spacer.inner_diameter_mm", "spacer.outer_diameter_mm"],
    )];

    fn materials(p: &SpacerParams) -> Vec<(String, &str, &'static [MaterialKind])> {
        vec![(
            "spacer.material".into(),
            &p.material,
            &[MaterialKind::Print],
        )]
    }

    fn check(p: &SpacerParams, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>) {
        if check_above_zero("spacer.", p, &[], errs) {
            return;
        }
        let rim_mm = 2.0 * ctx.body.rim_radius_mm(0.0);
        if p.outer_diameter_mm < rim_mm {
            errs.push(ParamError::new(
                "spacer.outer_diameter_mm",
                p.outer_diameter_mm,
                format!("must carry the skin's rim: at least its diameter at the base plane ({rim_mm:.3} mm)"),
            ));
        }
        let wall = ctx.printers.fdm.min_wall_mm;
        if p.inner_diameter_mm > p.outer_diameter_mm - 2.0 * wall {
            errs.push(ParamError::new(
                "spacer.inner_diameter_mm",
                p.inner_diameter_mm,
                format!(
                    "must leave the FDM printer's min wall ({wall} mm) each side: at most {:.3} mm",
                    p.outer_diameter_mm - 2.0 * wall
                ),
            ));
        } else if p.inner_diameter_mm >= rim_mm {
            errs.push(ParamError::new(
                "spacer.inner_diameter_mm",
                p.inner_diameter_mm,
                format!("must be below the skin's diameter at the base plane ({rim_mm:.3} mm), so that the skin's rim rests on the ring"),
            ));
        }
        if let Some(c) = &stack.core {
            let core_mm = 2.0 * ctx.body.rim_radius_mm(c.outer_offset_mm);
            if p.inner_diameter_mm <= core_mm {
                errs.push(ParamError::new(
                    "spacer.inner_diameter_mm",
                    p.inner_diameter_mm,
                    format!("must clear the core: above its outer diameter at the base plane ({core_mm:.3} mm)"),
                ));
            }
        }
    }

    fn build(p: &SpacerParams, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let FamilyInput { ctx, tol, .. } = input;
        let ring = ring_solid(p, ctx, tol).part("spacer")?;
        let (placed, pose) = place_posed(&ring, &crate::geometry::Affine::identity());
        let zb = ctx.body.base_z_mm();
        let part = Part {
            name: "spacer".into(),
            role: "spacer".into(),
            description: format!(
                "Spacer ring: {:.1} mm outer, {:.1} mm bore, {:.1} mm high, under the skin's base",
                p.outer_diameter_mm, p.inner_diameter_mm, p.height_mm
            ),
            material: p.material.clone(),
            print_technology: PrintTechnology::Fdm,
            solid: placed,
            params: with_pose(json!({"spacer": p, "base_z_mm": zb}), &pose),
            group: None,
        };
        let w = p.outer_diameter_mm;
        let height = ctx.body.pole_z_mm(0.0) - (zb - p.height_mm);
        Ok(Built {
            parts: vec![part],
            summary: vec![("envelope_mm", json!([w, w, height]))],
        })
    }

    fn bought_items(_p: &SpacerParams) -> Vec<String> {
        vec!["Cyanoacrylate glue (gel): the skin's rim onto the spacer's top face".into()]
    }

    fn assembly_steps(_p: &SpacerParams, input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let AssemblyInput { parts, .. } = input;
        let spacer = named(parts, "spacer")
            .first()
            .cloned()
            .unwrap_or_else(|| "the spacer".into());
        vec![AssemblyStep::Text(format!(
            "Glue the skin's rim onto the top face of {spacer}, centred, with cyanoacrylate gel."
        ))]
    }
}

/// The ring in the sensor frame: from `base_z - height_mm` up to the base plane.
fn ring_solid(
    p: &SpacerParams,
    ctx: &Context<'_>,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let zb = ctx.body.base_z_mm();
    let z0 = zb - p.height_mm;
    z_cylinder(p.outer_diameter_mm / 2.0, z0, zb, [0.0; 2], tol)?.difference(&z_cylinder(
        p.inner_diameter_mm / 2.0,
        z0 - 1.0,
        zb + 1.0,
        [0.0; 2],
        tol,
    )?)
}
