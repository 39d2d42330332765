//! The `direct` strategy: the printed block split on the parting plane y = 0, with registration
//! keys, clamp bolt holes and the core holder (R-Tac0 Sec. III-B1, Fig. 4).

use super::frame::sprue_pour_text;
use super::frame::{material_for, CastMold, CoreMold, MoldFrame};
use super::strategy::{CastPieces, CoreMoldInput, Strategy};
use super::strategy::{MoldBolts, PourInput};
use crate::error::{DesignError, GeometryContext};
use crate::geometry::{cuboid, sphere, Affine, ChordTolerance, Solid};
use crate::parts::part::ProcedureStep;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::stack_input::StackInput;
use crate::parts::ProcedureAction;
use crate::parts::{Part, PrintTechnology};
use crate::schema::MoldStrategy as Kind;
use serde_json::json;

/// The parts of a `direct` mold: the two mold halves split at the parting plane y = 0 around
/// `cavity` (male and female registration keys) and the core holder; the gel pours into all
/// three.
pub(crate) fn direct_mold_parts(
    si: &StackInput<'_>,
    cavity: &Solid,
    tol: ChordTolerance,
    c: CastMold,
) -> Result<CoreMold, DesignError> {
    let (name, f) = (c.name, &c.f);
    let m = &si.mold;
    let cavity_tech: PrintTechnology = m.cavity_print_technology.into();
    let cavity_material = material_for(cavity_tech);
    let ((a, pose_a), (b, pose_b)) = direct_halves(si, f, cavity, tol).part(name)?;
    let mut params = c.common.clone();
    params["direct"] = json!({
        "parting_plane": "y = 0 (through the sensor axis)",
        "pull_direction": "+y for half a, -y for half b",
        "half_width_mm": f.plinth_radius_mm + m.flange_width_mm,
        "z_min_mm": f.open_face_z_mm,
        "z_max_mm": f.cavity_pole_z_mm + m.wall_thickness_mm,
        "registration_key": m.registration_key,
        "clamp_bolt": m.clamp_bolt,
        "feature_x_mm": f.plinth_radius_mm + m.flange_width_mm / 2.0,
        "print_orientation": "parting face up",
    });
    let half = |s: Solid, pose: Affine, tag: &str, keys: &str| Part {
        name: format!("{name}_mold_half_{tag}"),
        role: "mold_half".into(),
        description: format!(
            "Two-piece mold for the {name} layer, half {tag} ({keys} registration keys)"
        ),
        material: cavity_material.into(),
        print_technology: cavity_tech,
        solid: s,
        params: with_pose(params.clone(), &pose),
        group: None,
    };
    let parts = vec![
        half(a, pose_a, "a", "male"),
        half(b, pose_b, "b", "female"),
        c.holder_part,
    ];
    let pour_parts = parts.iter().map(|p| p.name.clone()).collect();
    Ok(CoreMold {
        parts,
        silicone_pour: None,
        pour_parts,
    })
}

/// The two halves of a direct mold, each in print orientation (parting face up).
pub(crate) fn direct_halves(
    si: &StackInput<'_>,
    f: &MoldFrame,
    cavity: &Solid,
    tol: ChordTolerance,
) -> Result<(Posed, Posed), crate::geometry::GeometryError> {
    let m = &si.mold;
    let b = f.plinth_radius_mm + m.flange_width_mm;
    let z_lo = f.open_face_z_mm;
    let z_hi = f.cavity_pole_z_mm + m.wall_thickness_mm;
    let block = cuboid([-b, -b, z_lo], [b, b, z_hi])?.difference(cavity)?;
    let (pos, neg) = block.split_by_plane([0.0, 1.0, 0.0], 0.0);
    let x_f = f.plinth_radius_mm + m.flange_width_mm / 2.0;
    let e = m.flange_width_mm / 2.0;
    let z_mid = 0.5 * (z_lo + z_hi);
    let r_key = m.registration_key.diameter_mm / 2.0;
    let key_at = |r: f64| -> Result<Vec<Solid>, crate::geometry::GeometryError> {
        let s = sphere(r, tol)?;
        Ok(vec![
            s.translate([x_f, 0.0, z_mid]),
            s.translate([-x_f, 0.0, z_mid]),
        ])
    };
    let bolt =
        crate::geometry::cylinder(2.0 * b + 2.0, m.clamp_bolt.clearance_diameter_mm / 2.0, tol)?
            .rotate_deg(-90.0, 0.0, 0.0);
    let mut bolts = Vec::new();
    for x in [x_f, -x_f] {
        for z in [z_lo + e, z_hi - e] {
            bolts.push(bolt.translate([x, -b - 1.0, z]));
        }
    }
    let bolts = Solid::compose(&bolts);
    // the two halves side by side
    let (a, bh) = rayon::join(
        || {
            pos.union(&Solid::compose(&key_at(r_key)?))?
                .difference(&bolts)
        },
        || {
            neg.difference(&Solid::compose(&key_at(
                r_key + m.registration_key.clearance_mm,
            )?))?
            .difference(&bolts)
        },
    );
    let (a, bh) = (a?, bh?);
    Ok((
        place_posed(&a, &crate::geometry::rotation_deg(-90.0, 0.0, 0.0)),
        place_posed(&bh, &crate::geometry::rotation_deg(90.0, 0.0, 0.0)),
    ))
}

/// A solid in print orientation with its `T_print_sensor`.
pub(crate) type Posed = (Solid, Affine);

/// The `direct` strategy ([`super::STRATEGIES`]).
pub struct Direct;

impl Strategy for Direct {
    fn kind(&self) -> Kind {
        Kind::Direct
    }

    /// The halves closed round the core holder, then the pour through its sprue.
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        let n = p.step;
        let name = |i: usize| p.halves.get(i).map_or("", |h| h.name.as_str());
        let (a, b) = (name(0), name(1));
        let h = p.holder.map_or("the core holder", |h| h.name.as_str());
        vec![
            ProcedureStep::new(
                ProcedureAction::CloseMold,
                format!(
                    "Step {n}: set the plinth of `{h}` into the recess of `{a}`, close `{b}` over \
                     it on the registration keys{}.",
                    p.bolt_text
                ),
            ),
            ProcedureStep::new(ProcedureAction::Pour, sprue_pour_text(n, p.mix, p.holder)),
        ]
    }

    /// Four bolts across both halves (perpendicular to the parting plane), named on half `_a`.
    fn clamp_bolts(&self, si: &StackInput<'_>, p: &Part) -> Option<MoldBolts> {
        if p.role != "mold_half" || !p.name.ends_with("_a") {
            return None;
        }
        let half_width = p.params["direct"]["half_width_mm"].as_f64()?;
        Some(MoldBolts {
            count: 4,
            grip_mm: 2.0 * half_width,
            clearance_mm: si.mold.clamp_bolt.clearance_diameter_mm,
        })
    }

    fn core_mold(
        &self,
        input: CoreMoldInput<'_>,
        c: CastMold,
    ) -> Option<Result<CoreMold, DesignError>> {
        Some(direct_mold_parts(input.si, input.cavity, input.tol, c))
    }

    /// The space the closed halves and the core holder leave.
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError> {
        let p = vec![
            c.need("mold_half_a")?,
            c.need("mold_half_b")?,
            c.need("core_holder")?,
        ];
        Ok((c.negative(&p)?, p))
    }
}
