//! The `master` strategy: a printed master pattern of the cavity and a drafted mold box for a Mold
//! Star 30 silicone mold, with the core holder as casting jig (R-Tac0 Sec. III-B1).

use super::frame::sprue_text;
use super::frame::{
    cavity_profile, material_for, CastMold, CastPlan, CoreMold, MoldFrame, BOX_FLOOR_MM,
    BOX_FREEBOARD_MM, BOX_WALL_MM, LOCATING_PIN_HEIGHT_MM, LOCATING_PIN_RADIUS_MM,
};
use super::strategy::PourInput;
use super::strategy::{CastPieces, CoreMoldInput, Strategy};
use crate::error::{DesignError, GeometryContext};
use crate::geometry::{revolve, ChordTolerance, Solid};
use crate::parts::part::ProcedureStep;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::stack_input::StackInput;
use crate::parts::ProcedureAction;
use crate::parts::{Part, PrintTechnology};
use crate::schema::MoldStrategy as Kind;
use serde_json::json;

/// The parts of a `master` mold: the master pattern (the cavity of the cast with its plinth
/// and locating pin) and the drafted box that holds it while the Mold Star 30 mold cures, then
/// the casting jig; the silicone pours into the master and box, the gel into the silicone
/// mold and the jig.
pub(crate) fn master_mold_parts(
    si: &StackInput<'_>,
    plan: &CastPlan,
    tol: ChordTolerance,
    c: CastMold,
    with_features: &(dyn Fn(Solid) -> Result<Solid, DesignError> + Sync),
) -> Result<CoreMold, DesignError> {
    let (name, f) = (c.name, &c.f);
    let m = &si.mold;
    let cavity_tech: PrintTechnology = m.cavity_print_technology.into();
    let fixture_tech: PrintTechnology = m.fixture_print_technology.into();
    let cavity_material = material_for(cavity_tech);
    let fixture_material = material_for(fixture_tech);
    // The master and the box are independent: built side by side.
    let (master, mold_box_fill) = rayon::join(
        || {
            with_features(
                Solid::from_mesh(
                    &revolve(
                        &cavity_profile(si, f, plan.cavity_offset_mm, true, tol),
                        tol,
                    )
                    .part(name)?,
                )
                .part(name)?,
            )
        },
        || master_box(si, f, tol).part(name),
    );
    let (master, (mold_box, fill)) = (master?, mold_box_fill?);
    let silicone = fill.difference(&master).part(name)?.volume();
    let mut params = c.common.clone();
    params["master"] = json!({
        "silicone_wall_mm": m.silicone_wall_mm,
        "draft_angle_deg": m.draft_angle_deg,
        "locating_pin": {"radius_mm": LOCATING_PIN_RADIUS_MM.min(f.plinth_radius_mm / 3.0), "height_mm": LOCATING_PIN_HEIGHT_MM},
        "box_floor_mm": BOX_FLOOR_MM, "box_wall_mm": BOX_WALL_MM, "box_freeboard_mm": BOX_FREEBOARD_MM,
        "pin_socket_radius_mm": LOCATING_PIN_RADIUS_MM.min(f.plinth_radius_mm / 3.0) + m.core_holder.fit_clearance_mm,
        "fill_z_mm": f.cavity_pole_z_mm + m.silicone_wall_mm,
    });
    let (master_placed, master_pose) = place_posed(&master, &crate::geometry::Affine::identity());
    let (box_placed, box_pose) = place_posed(&mold_box, &crate::geometry::Affine::identity());
    let master_name = format!("{name}_master_pattern");
    let box_name = format!("{name}_mold_box");
    let parts = vec![
        Part {
            name: master_name.clone(),
            role: "master_pattern".into(),
            description: format!(
                "Positive of the {name} cavity with its plinth, to cast a Mold Star 30 mold"
            ),
            material: cavity_material.into(),
            print_technology: cavity_tech,
            solid: master_placed,
            params: with_pose(params.clone(), &master_pose),
            group: None,
        },
        Part {
            name: box_name.clone(),
            role: "mold_box".into(),
            description: format!(
                "Drafted cup that holds the {name} master pattern while Mold Star 30 cures"
            ),
            material: fixture_material.into(),
            print_technology: fixture_tech,
            solid: box_placed,
            params: with_pose(params, &box_pose),
            group: None,
        },
        c.holder_part,
    ];
    Ok(CoreMold {
        parts,
        silicone_pour: Some((silicone, vec![master_name, box_name])),
        pour_parts: vec![format!("silicone_mold:{name}"), c.holder_name],
    })
}

/// The mold box (sensor frame) and the solid the Mold Star fills up to its fill level.
pub(crate) fn master_box(
    si: &StackInput<'_>,
    f: &MoldFrame,
    tol: ChordTolerance,
) -> Result<(Solid, Solid), crate::geometry::GeometryError> {
    drafted_box(
        si,
        f.plinth_radius_mm,
        f.open_face_z_mm,
        f.cavity_pole_z_mm,
        tol,
    )
}

/// A drafted cup standing on the plane `z0` (the master's plinth face) around a master of
/// plinth radius `plinth_radius_mm` reaching up to `pole_z`, with a socket for the master's
/// locating pin; and the solid the Mold Star fills up to `silicone_wall_mm` over the pole.
///
/// # Errors
/// Only on a kernel failure.
pub fn drafted_box(
    si: &StackInput<'_>,
    plinth_radius_mm: f64,
    z0: f64,
    pole_z: f64,
    tol: ChordTolerance,
) -> Result<(Solid, Solid), crate::geometry::GeometryError> {
    let m = &si.mold;
    let z_fill = pole_z + m.silicone_wall_mm;
    let z_top = z_fill + BOX_FREEBOARD_MM;
    let r0 = plinth_radius_mm + m.silicone_wall_mm;
    let slope = m.draft_angle_deg.to_radians().tan();
    let r_at = |z: f64| r0 + slope * (z - z0);
    let r_out = r_at(z_top) + BOX_WALL_MM;
    let outer = crate::geometry::cylinder(z_top - (z0 - BOX_FLOOR_MM), r_out, tol)?.translate([
        0.0,
        0.0,
        z0 - BOX_FLOOR_MM,
    ]);
    let inner = crate::geometry::cone(z_top + 1.0 - z0, r0, r_at(z_top + 1.0), tol)?
        .translate([0.0, 0.0, z0]);
    let pin_r = LOCATING_PIN_RADIUS_MM.min(plinth_radius_mm / 3.0) + m.core_holder.fit_clearance_mm;
    let socket = crate::geometry::cylinder(BOX_FLOOR_MM + 2.0, pin_r, tol)?.translate([
        0.0,
        0.0,
        z0 - BOX_FLOOR_MM - 1.0,
    ]);
    let cup = outer.difference(&inner.union(&socket)?)?;
    let fill = crate::geometry::cone(z_fill - z0, r0, r_at(z_fill), tol)?.translate([0.0, 0.0, z0]);
    Ok((cup, fill))
}

/// The `master` strategy ([`super::STRATEGIES`]).
pub struct Master;

impl Strategy for Master {
    fn kind(&self) -> Kind {
        Kind::Master
    }

    /// The silicone mold in its box, then the core pressed in on its jig.
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        let (n, mix) = (p.step, p.mix);
        let Some(h) = p.holder else {
            return Vec::new();
        };
        vec![ProcedureStep::new(
            ProcedureAction::Pour,
            format!(
                "Step {n}: stand the silicone mold pole-down in its mold box, mix and degas \
                 {mix} and pour it in, then press the core on `{}` in until its flange rests \
                 on the mold: the surplus rises through the sprue ({}) and the vents.",
                h.name,
                sprue_text(h)
            ),
        )]
    }

    fn core_mold(
        &self,
        input: CoreMoldInput<'_>,
        c: CastMold,
    ) -> Option<Result<CoreMold, DesignError>> {
        Some(master_mold_parts(
            input.si,
            input.plan,
            input.tol,
            c,
            input.with_features,
        ))
    }

    /// The master pattern within the envelope (the silicone mold cast on it is its negative).
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError> {
        let master = c.need("master_pattern")?;
        Ok((
            c.named(c.in_sensor(master)?.intersection(c.envelope()))?,
            vec![master],
        ))
    }
}
