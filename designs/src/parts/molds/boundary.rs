//! The `boundary` strategy: outer and inner master patterns in cups, to cast the two silicone
//! molds the layer is poured between (UVDtact Sec. III).

use super::frame::material_for;
use super::strategy::{CastPieces, Strategy};
use super::strategy::{DemoldInput, PourInput};
use crate::error::{DesignError, GeometryContext};
use crate::geometry::{revolve, GeometryError, Solid};
use crate::parts::layers::{apply_features, layer_solid, set_forming, LayerBuild, LayerOutput};
use crate::parts::part::ProcedureStep;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::ProcedureAction;
use crate::parts::{Part, PrintTechnology};
use crate::schema::MoldStrategy as Kind;
use serde_json::json;

/// The parts of a cast layer with the `boundary` strategy: the outer master (the outer
/// boundary with its features, plinth and locating pin) with its drafted mold box, and the
/// inner negative (a cup whose cavity casts the inner silicone core); three pours: the outer
/// and inner Mold Star 30 molds, then the layer's gel between them, mm^3.
pub(crate) fn build_boundary_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (si, stack, i, tol, l, name) = (b.si, b.stack, b.i, b.tol, b.l, &b.name);
    let (fixture_tech, cavity_tech) = (b.fixture_tech, b.cavity_tech);
    let m = &si.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    let zb = si.ctx.body.base_z_mm();
    let rim = si.ctx.body.rim_radius_mm(l.outer_offset_mm);
    let r_p = rim + m.plinth.margin_mm;
    let z_lo = zb - m.plinth.height_mm;
    let fit = m.core_holder.fit_clearance_mm;
    // Outer boundary: master (positive) with plinth and locating pin, and a drafted box.
    let mut pl = si
        .ctx
        .body
        .offset_polyline(l.outer_offset_mm, 0.0, tol.half());
    let pin_r = 3.0f64.min(r_p / 3.0);
    for p in [
        [r_p, zb],
        [r_p, z_lo],
        [pin_r, z_lo],
        [pin_r, z_lo - 2.0],
        [0.0, z_lo - 2.0],
    ] {
        pl.push(p);
    }
    let master_base = g(revolve(&pl, tol).and_then(|mesh| Solid::from_mesh(&mesh)))?;
    let master = g(apply_features(si.shared, master_base, &b.outer, tol, false))?;
    let pole = master.bounding_box().map(|b| b.max[2]).unwrap_or(0.0);
    let (mold_box, fill) = crate::parts::molds::drafted_box(si, r_p, z_lo, pole, tol).part(name)?;
    let silicone_outer = g(fill.difference(&master))?.volume();
    // Inner boundary: a cup whose cavity casts the inner silicone core; the core's
    // plinth fits the outer mold's plinth recess (with clearance), which centres it.
    let inner_pl = {
        let mut q = si
            .ctx
            .body
            .offset_polyline(l.inner_offset_mm, 0.0, tol.half());
        for p in [[r_p - fit, zb], [r_p - fit, z_lo - 1.0], [0.0, z_lo - 1.0]] {
            q.push(p);
        }
        q
    };
    let core_pos = g(revolve(&inner_pl, tol)
        .and_then(|mesh| Solid::from_mesh(&mesh))
        .and_then(|s| apply_features(si.shared, s, &b.inner, tol, false)))?;
    let top = core_pos.bounding_box().map(|b| b.max[2]).unwrap_or(0.0) + BOUNDARY_CUP_FLOOR_MM;
    let cup_r = r_p + BOUNDARY_CUP_WALL_MM;
    let cup =
        g(crate::geometry::cylinder(top - z_lo, cup_r, tol)
            .map(|c| c.translate([0.0, 0.0, z_lo])))?;
    let inner_negative = g(cup.difference(&core_pos))?;
    let silicone_inner = g(core_pos.intersection(&cup))?.volume();
    let gel = g(layer_solid(si, stack, i, tol))?.volume();
    let boundary = json!({
        "locating_pin": {"radius_mm": pin_r, "height_mm": 2.0},
        "master_top_z_mm": pole,
        "inner_plinth_bottom_z_mm": z_lo - 1.0,
        "cup": {"radius_mm": cup_r, "bottom_z_mm": z_lo, "top_z_mm": top},
        "box_floor_mm": 2.0, "box_wall_mm": 2.0, "box_freeboard_mm": 2.0,
        "pin_socket_radius_mm": pin_r + fit,
    });
    let mk = |suffix: &str,
              role: &str,
              desc: String,
              tech: PrintTechnology,
              (solid, pose): (Solid, crate::geometry::Affine)| Part {
        name: format!("{name}_{suffix}"),
        role: role.into(),
        description: desc,
        material: material_for(tech).into(),
        print_technology: tech,
        solid,
        params: with_pose(
            json!({"base": b.base_params, "plinth_radius_mm": r_p, "plinth_height_mm": m.plinth.height_mm, "fit_clearance_mm": fit, "draft_angle_deg": m.draft_angle_deg, "silicone_wall_mm": m.silicone_wall_mm, "boundary": boundary}),
            &pose,
        ),
        group: None,
    };
    let parts = vec![
        mk("outer_master", "master_pattern", format!("Positive of the outer boundary of {name} with its features, to cast the outer Mold Star 30 mold"), cavity_tech, place_posed(&master, &crate::geometry::Affine::identity())),
        mk("outer_mold_box", "mold_box", format!("Drafted cup for the outer Mold Star 30 mold of {name}"), fixture_tech, place_posed(&mold_box, &crate::geometry::Affine::identity())),
        mk("inner_negative", "negative_mold", format!("Negative of the inner boundary of {name} with its features: pour Mold Star 30 in it for the inner silicone mold"), cavity_tech, place_posed(&inner_negative, &crate::geometry::rotation_deg(180.0, 0.0, 0.0))),
    ];
    let names: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &names[..1], &names[2..3], 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![
            (
                format!("silicone_mold:{name}:outer"),
                "mold_star_30".into(),
                silicone_outer,
                vec![names[0].clone(), names[1].clone()],
            ),
            (
                format!("silicone_mold:{name}:inner"),
                "mold_star_30".into(),
                silicone_inner,
                vec![names[2].clone()],
            ),
            (
                name.clone(),
                l.material.clone(),
                gel,
                vec![
                    format!("silicone_mold:{name}:outer"),
                    format!("silicone_mold:{name}:inner"),
                ],
            ),
        ],
        markers,
    })
}

const BOUNDARY_CUP_WALL_MM: f64 = 5.0;

const BOUNDARY_CUP_FLOOR_MM: f64 = 5.0;

/// The `boundary` strategy ([`super::STRATEGIES`]).
pub struct Boundary;

impl Strategy for Boundary {
    fn kind(&self) -> Kind {
        Kind::Boundary
    }

    /// The gel's volume is the layer's ([`crate::parts::layers::layer_solid`]).
    fn reads_layer_solid(&self) -> bool {
        true
    }

    /// The outer silicone mold poured, the inner one (or the layers cast so far on it) pressed
    /// in (UVDtact Sec. III).
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        let (n, mix) = (p.step, p.mix);
        let inner = if p.on_inner_mold {
            "the layers cast so far, on the first inner silicone mold,"
        } else {
            "the inner silicone mold"
        };
        vec![ProcedureStep::new(
            ProcedureAction::Pour,
            format!(
                "Step {n}: stand the outer silicone mold pole-down, mix and degas {mix}, pour \
                 it in, then press {inner} in until the plinth seats in the outer mold's \
                 recess."
            ),
        )]
    }

    fn keeps_inner_mold(&self) -> bool {
        true
    }

    /// The layers cast so far, still on the first inner silicone mold, take the place of this
    /// pour's inner silicone mold (UVDtact Sec. III).
    fn seat_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        if !p.on_inner_mold {
            return Vec::new();
        }
        vec![ProcedureStep::new(
            ProcedureAction::MoveCore,
            format!(
                "Step {}: the layers cast so far, still on the first inner silicone mold, \
                 take the place of `{}` (UVDtact Sec. III).",
                p.step,
                p.mold_parts
                    .iter()
                    .find(|m| m.ends_with(":inner"))
                    .map_or("the inner silicone mold", |s| s.as_str())
            ),
        )]
    }

    /// The outer silicone mold comes off; the layer stays on the inner one while another pour
    /// follows.
    fn demold_text(&self, d: DemoldInput<'_>) -> Option<String> {
        let (n, cure) = (d.step, d.cure);
        Some(if d.poured_again {
            format!(
                "Step {n}: let it cure ({cure}) and remove the outer silicone mold; keep `{}` on \
                 the inner silicone mold for the next pour.",
                d.layer
            )
        } else {
            format!(
                "Step {n}: let it cure ({cure}) and take the skin out of the outer silicone mold \
                 and off the inner one."
            )
        })
    }

    fn pour_note(&self) -> Option<&'static str> {
        Some("Pour into the outer silicone mold, then press the inner silicone mold in: its plinth centres it in the outer mold's recess. For a layer after the first, the layers already cast, still on their inner silicone mold, can take the inner mold's place (UVDtact Sec. III).")
    }

    /// The drafted Mold Star box round the outer master: about 14 circles of the layer's rim.
    fn estimated_triangles(
        &self,
        body: &crate::profile::BodyProfile,
        l: &crate::parts::context::ResolvedLayer,
        tol: crate::geometry::ChordTolerance,
    ) -> f64 {
        14.0 * tol
            .half()
            .circle_segments(body.rim_radius_mm(l.outer_offset_mm)) as f64
    }

    fn build_layer(&self, b: LayerBuild<'_>) -> Option<Result<LayerOutput, DesignError>> {
        Some(build_boundary_layer(b))
    }

    /// The outer master within the envelope, less the inner silicone core (what Mold Star
    /// fills in the inner negative's cup).
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError> {
        let (outer, inner) = (c.need("outer_master")?, c.need("inner_negative")?);
        let cup = &inner.params["boundary"]["cup"];
        let num = |k: &str| {
            cup[k]
                .as_f64()
                .ok_or_else(|| c.missing(format!("the cup of {}", inner.name)))
        };
        let (r, z0, z1) = (num("radius_mm")?, num("bottom_z_mm")?, num("top_z_mm")?);
        let cup = c.named(
            crate::geometry::cylinder(z1 - z0, r, c.tol()).map(|s| s.translate([0.0, 0.0, z0])),
        )?;
        // the inner silicone core: what Mold Star fills in the negative's cup
        let core = c.named(cup.difference(&c.in_sensor(inner)?))?;
        Ok((
            c.named(
                c.in_sensor(outer)?
                    .intersection(c.envelope())
                    .and_then(|s| s.difference(&core)),
            )?,
            vec![outer, inner],
        ))
    }
}
