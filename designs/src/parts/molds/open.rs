//! The `open` strategy: a one-piece block open on the base plane, printed open face up and poured
//! to the brim, with the inserts of the layer's features (DIGIT Pinki).

use super::frame::material_for;
use super::frame::open_cavity_mm;
use super::strategy::PourInput;
use super::strategy::{CastPieces, Strategy};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{GeometryError, Solid};
use crate::parts::context::ResolvedLayer;
use crate::parts::layer_feature::InsertInput;
use crate::parts::layer_registry::open_mold_inserts;
use crate::parts::layers::{
    apply_features_signed, body_solid, features_top_z_mm, set_forming, LayerBuild, LayerOutput,
};
use crate::parts::part::ProcedureStep;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::stack_input::StackInput;
use crate::parts::Part;
use crate::parts::ProcedureAction;
use crate::schema::MoldStrategy as Kind;
use serde_json::json;

/// The one-piece open mold of a solid cast layer (`open` strategy): a block
/// `mold.wall_thickness_mm` beyond the rim and the tallest outward feature, less the cavity
/// (the outer surface with its features), printed open face up; one pour of the layer's
/// material, its volume block - mold, mm^3.
pub(crate) fn build_open_mold_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (si, tol, l, name, outer) = (b.si, b.tol, b.l, &b.name, &b.outer);
    let (base_params, cavity_tech) = (&b.base_params, b.cavity_tech);
    let m = &si.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(name);
    // mold = (block - plain cavity) with the features cut or added: one boolean with
    // the features, and the skin's volume falls out as block - mold.
    let plain = g(body_solid(si, l.outer_offset_mm, 1.0, tol))?;
    let rim = si.ctx.body.rim_radius_mm(l.outer_offset_mm);
    let top = features_top_z_mm(si, l.outer_offset_mm, outer);
    let zb = si.ctx.body.base_z_mm();
    let (half, z_top) = match &m.open_block {
        Some(ob) => (ob.width_mm / 2.0, zb + ob.height_mm),
        None => (rim + m.wall_thickness_mm, top + m.wall_thickness_mm),
    };
    let block = g(crate::geometry::cuboid(
        [-half, -half, zb],
        [half, half, z_top],
    ))?;
    let mold = g(block
        .difference(&plain)
        .and_then(|b| apply_features_signed(si.shared, b, outer, tol, false, -1.0)))?;
    // the features' inserts set in the open face (the optic's seat)
    let inserts = open_mold_inserts(
        si,
        l.index,
        InsertInput {
            layer_name: name,
            base_z_mm: zb,
            base_params,
            technology: cavity_tech,
            material: material_for(cavity_tech),
            tol,
        },
    )
    .part(name)?;
    let inserts_volume: f64 = inserts.iter().map(|i| i.volume_mm3).sum();
    let skin_volume = block.volume() - mold.volume() - inserts_volume;
    let (mold_placed, mold_pose) =
        place_posed(&mold, &crate::geometry::rotation_deg(180.0, 0.0, 0.0));
    let part = Part {
        name: format!("{name}_open_mold"),
        role: "open_mold".into(),
        description: format!(
            "One-piece mold for the solid {name} skin, open face up: pour to the brim"
        ),
        material: material_for(cavity_tech).into(),
        print_technology: cavity_tech,
        solid: mold_placed,
        params: with_pose(
            json!({"base": base_params, "open_face": "the base plane, printed face up", "wall_thickness_mm": m.wall_thickness_mm,
            "block_mm": {"min": [-half, -half, zb], "max": [half, half, z_top]}}),
            &mold_pose,
        ),
        group: None,
    };
    let mut parts = vec![part];
    parts.extend(inserts.into_iter().map(|i| i.part));
    let pour_parts = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &[format!("{name}_open_mold")], &[], 0.0);
    Ok(LayerOutput {
        parts,
        pours: vec![(name.clone(), l.material.clone(), skin_volume, pour_parts)],
        markers,
    })
}

/// The `open` strategy ([`super::STRATEGIES`]).
pub struct Open;

impl Strategy for Open {
    fn kind(&self) -> Kind {
        Kind::Open
    }

    /// The block poured to the brim, then the features' inserts pressed in.
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        let (n, mix) = (p.step, p.mix);
        let Some(block) = p.pieces.first() else {
            return Vec::new();
        };
        let mut out = vec![ProcedureStep::new(
            ProcedureAction::Pour,
            format!(
                "Step {n}: stand `{}` level, open face up, mix and degas {mix} and pour it to \
                 the brim.",
                block.name
            ),
        )];
        for insert in p.inserts {
            out.push(ProcedureStep::new(
                ProcedureAction::CloseMold,
                format!(
                    "Step {n}: press `{}` into the gel dome first, centred on the cavity, until \
                     its flat face lies in the open face of `{}`; wipe off the gel it pushes out.",
                    insert.name, block.name
                ),
            ));
        }
        out
    }

    fn solid_only(&self) -> bool {
        true
    }

    /// `mold.open_block` against the layers cast in an open mold: the largest cavity (its rim
    /// on the base plane, its height with the tallest raised outward feature) with the cavity
    /// printer's minimum wall around it; its sizes alone when the stack is not sound.
    fn check_layers(
        &self,
        si: &StackInput<'_>,
        cast: Option<&[&ResolvedLayer]>,
        errs: &mut Vec<ParamError>,
    ) {
        let Some(block) = &si.mold.open_block else {
            return;
        };
        let Some(cast) = cast else {
            crate::parts::check_above_zero("mold.open_block.", block, &[], errs);
            return;
        };
        let open: Vec<_> = cast.iter().map(|l| open_cavity_mm(si, l)).collect();
        let rim = open.iter().map(|c| c.0).fold(0.0, f64::max);
        let height = open.iter().map(|c| c.1).fold(0.0, f64::max);
        let min_wall = si
            .ctx
            .printers
            .get(si.mold.cavity_print_technology)
            .min_wall_mm;
        block.check(!open.is_empty(), rim, height, min_wall, errs);
    }

    /// With `mold.open_block`, the block's walls beside and beyond each cavity.
    fn walls(&self, si: &StackInput<'_>, cast: &[&ResolvedLayer]) -> Option<Vec<(f64, String)>> {
        let ob = si.mold.open_block.as_ref()?;
        let mut walls = Vec::new();
        for l in cast {
            let (rim, height) = open_cavity_mm(si, l);
            walls.push((
                ob.width_mm / 2.0 - rim,
                "mold.open_block.width_mm: open mold's wall beside the cavity".into(),
            ));
            walls.push((
                ob.height_mm - height,
                "mold.open_block.height_mm: open mold's wall beyond the cavity".into(),
            ));
        }
        Some(walls)
    }

    fn build_layer(&self, b: LayerBuild<'_>) -> Option<Result<LayerOutput, DesignError>> {
        Some(build_open_mold_layer(b))
    }

    /// The space the open mold and the inserts of the layer's features leave.
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError> {
        let mut p = vec![c.need("open_mold")?];
        for role in crate::parts::layer_registry::insert_roles() {
            p.extend(c.part(role));
        }
        Ok((c.negative(&p)?, p))
    }
}
