//! The `two_piece_open` strategy: a cavity block and a reservoir top bolted together on
//! registration bosses (its frame [`TwoPieceFrame`] and its rules).

use super::frame::material_for;
use super::strategy::{CastPieces, Strategy};
use super::strategy::{MoldBolts, PourInput};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{GeometryError, Solid};
use crate::parts::context::ResolvedLayer;
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

/// Where the parts of a `two_piece_open` mold lie, in the sensor frame, mm (see
/// [`crate::schema::TwoPieceOpenParams`]). The cavity opens on the rim plane `base_z_mm`; the
/// top piece lies below it (beyond the rim, in casting orientation above it).
#[derive(Debug, Clone, serde::Serialize)]
pub struct TwoPieceFrame {
    pub base_z_mm: f64,
    /// Half sizes of the pocket in the cavity block (the boss plus its clearance), x and y.
    pub pocket_half_mm: [f64; 2],
    /// Half sizes of both pieces' outline (pocket plus flange), x and y.
    pub outer_half_mm: [f64; 2],
    /// The parting face: the cavity block's face and the top piece's plate face.
    pub parting_z_mm: f64,
    /// The top piece's outer face (the end of the reservoir).
    pub top_z_mm: f64,
    /// Half sizes of the boss, x and y; it spans parting_z_mm..base_z_mm.
    pub boss_half_mm: [f64; 2],
    pub reservoir_radius_mm: f64,
    /// Bolt axes (x, y), parallel to z: corners first, then the sides.
    pub bolts_xy_mm: Vec<[f64; 2]>,
    /// Bolt hole diameters, mm: in the cavity block and in the top piece.
    pub cavity_block_bolt_hole_mm: f64,
    pub top_piece_bolt_hole_mm: f64,
    /// Bolt pitch along the sides of the flange, x and y sides, mm.
    pub bolt_pitch_mm: [f64; 2],
}

impl TwoPieceFrame {
    /// The frame of a design's `two_piece_open` mold whose cavity opens on the base plane.
    /// Needs an even `bolt_count` of at least 4 (validation checks it; fewer bolts give the
    /// four corners only).
    pub fn new(si: &StackInput<'_>) -> Self {
        let m = &si.mold;
        let t = &m.two_piece;
        let zb = si.ctx.body.base_z_mm();
        let layout = BoltLayout::new(si);
        let BoltLayout {
            boss,
            pocket,
            h,
            kx,
            ky,
        } = layout;
        let (ax, ay) = (2.0 * h[0], 2.0 * h[1]);
        let outer = [pocket[0] + m.flange_width_mm, pocket[1] + m.flange_width_mm];
        let mut bolts = vec![[h[0], h[1]], [-h[0], h[1]], [-h[0], -h[1]], [h[0], -h[1]]];
        for sy in [1.0, -1.0] {
            for i in 1..=kx {
                bolts.push([-h[0] + ax * i as f64 / (kx + 1) as f64, sy * h[1]]);
            }
        }
        for sx in [1.0, -1.0] {
            for j in 1..=ky {
                bolts.push([sx * h[0], -h[1] + ay * j as f64 / (ky + 1) as f64]);
            }
        }
        Self {
            base_z_mm: zb,
            pocket_half_mm: pocket,
            outer_half_mm: outer,
            parting_z_mm: zb - t.boss.height_mm,
            top_z_mm: zb - t.reservoir_height_mm,
            boss_half_mm: boss,
            reservoir_radius_mm: t.reservoir_diameter_mm / 2.0,
            bolts_xy_mm: bolts,
            cavity_block_bolt_hole_mm: t.bolt_holes_mm(m.clamp_bolt.clearance_diameter_mm).0,
            top_piece_bolt_hole_mm: t.bolt_holes_mm(m.clamp_bolt.clearance_diameter_mm).1,
            bolt_pitch_mm: layout.pitch_mm(),
        }
    }
}

/// Where the bolts of a two-piece frame go, computed without placing them (validation bounds
/// `bolt_count` by the pitch this gives before [`TwoPieceFrame::new`] allocates a position per
/// bolt).
struct BoltLayout {
    boss: [f64; 2],
    pocket: [f64; 2],
    /// Half sides of the bolt rectangle on the flange's centre line, mm.
    h: [f64; 2],
    /// Bolts between the corners on each x side and each y side.
    kx: u32,
    ky: u32,
}

impl BoltLayout {
    fn new(si: &StackInput<'_>) -> Self {
        let m = &si.mold;
        let t = &m.two_piece;
        let c = m.registration_key.clearance_mm;
        let boss = [t.boss.width_mm / 2.0, t.boss.length_mm / 2.0];
        let pocket = [boss[0] + c, boss[1] + c];
        let h = [
            pocket[0] + m.flange_width_mm / 2.0,
            pocket[1] + m.flange_width_mm / 2.0,
        ];
        let (ax, ay) = (2.0 * h[0], 2.0 * h[1]);
        let rest = (t.bolt_count.max(4) - 4) / 2;
        let kx = (((rest as f64) * ax / (ax + ay)).round() as u32).min(rest);
        Self {
            boss,
            pocket,
            h,
            kx,
            ky: rest - kx,
        }
    }

    /// Bolt pitch along the x and y sides, mm.
    fn pitch_mm(&self) -> [f64; 2] {
        [
            2.0 * self.h[0] / f64::from(self.kx + 1),
            2.0 * self.h[1] / f64::from(self.ky + 1),
        ]
    }
}

/// Rules of the `two_piece_open` strategy, for a cavity of rim radius `rim_radius_mm` (the
/// widest cast layer's): sizes, the reservoir bore between the cavity rim and the boss, the
/// bolts on the flange, the plate above the boss, the pocket fit.
pub fn check_two_piece(si: &StackInput<'_>, rim_radius_mm: f64, errs: &mut Vec<ParamError>) {
    let m = &si.mold;
    let t = &m.two_piece;
    let cav = si.ctx.printers.get(m.cavity_print_technology);
    let cavity = format!("{:?}", m.cavity_print_technology).to_lowercase();
    let mut ok = true;
    for (p, v) in [
        (
            "mold.two_piece.reservoir_diameter_mm",
            t.reservoir_diameter_mm,
        ),
        ("mold.two_piece.reservoir_height_mm", t.reservoir_height_mm),
        ("mold.two_piece.boss.width_mm", t.boss.width_mm),
        ("mold.two_piece.boss.length_mm", t.boss.length_mm),
        ("mold.two_piece.boss.height_mm", t.boss.height_mm),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(p, v, "must be above 0"));
            ok = false;
        }
    }
    if t.bolt_count < 4 || t.bolt_count % 2 == 1 {
        errs.push(ParamError::new(
            "mold.two_piece.bolt_count",
            t.bolt_count,
            "must be even and at least 4: a bolt at each corner of the flange, the rest in pairs on opposite sides",
        ));
        ok = false;
    }
    for (p, v) in [
        (
            "mold.two_piece.cavity_block_bolt_hole_mm",
            t.cavity_block_bolt_hole_mm,
        ),
        (
            "mold.two_piece.top_piece_bolt_hole_mm",
            t.top_piece_bolt_hole_mm,
        ),
    ] {
        let Some(v) = v else { continue };
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(p, v, "must be above 0"));
            ok = false;
        } else if v < cav.min_hole_diameter_mm {
            errs.push(ParamError::new(
                p,
                v,
                format!(
                    "below the minimum hole {} mm of printer profile '{cavity}'",
                    cav.min_hole_diameter_mm
                ),
            ));
            ok = false;
        }
    }
    let sizes_ok = [
        m.flange_width_mm,
        m.clamp_bolt.clearance_diameter_mm,
        m.registration_key.clearance_mm,
    ]
    .iter()
    .all(|v| v.is_finite() && *v >= 0.0);
    if !ok || !sizes_ok {
        return;
    }
    // The widest bolt hole of the two pieces, and the parameter that sets it.
    let (hole_block, hole_top) = t.bolt_holes_mm(m.clamp_bolt.clearance_diameter_mm);
    let (hole_path, hole) = if hole_block >= hole_top {
        match t.cavity_block_bolt_hole_mm {
            Some(_) => ("mold.two_piece.cavity_block_bolt_hole_mm", hole_block),
            None => ("mold.clamp_bolt.clearance_diameter_mm", hole_block),
        }
    } else {
        match t.top_piece_bolt_hole_mm {
            Some(_) => ("mold.two_piece.top_piece_bolt_hole_mm", hole_top),
            None => ("mold.clamp_bolt.clearance_diameter_mm", hole_top),
        }
    };
    if hole + 2.0 * cav.min_wall_mm > m.flange_width_mm {
        errs.push(ParamError::new(
            hole_path,
            hole,
            format!(
                "does not fit the flange (mold.flange_width_mm = {}) with the minimum wall {} mm of printer profile '{cavity}' on each side",
                m.flange_width_mm, cav.min_wall_mm
            ),
        ));
    }
    let rim_d = 2.0 * rim_radius_mm;
    if t.reservoir_diameter_mm <= rim_d {
        errs.push(ParamError::new(
            "mold.two_piece.reservoir_diameter_mm",
            t.reservoir_diameter_mm,
            format!(
                "must exceed the cavity's rim diameter {rim_d:.3} mm so the reservoir opens the whole cavity"
            ),
        ));
    } else {
        let (path, side) = if t.boss.width_mm <= t.boss.length_mm {
            ("mold.two_piece.boss.width_mm", t.boss.width_mm)
        } else {
            ("mold.two_piece.boss.length_mm", t.boss.length_mm)
        };
        if side < t.reservoir_diameter_mm + 2.0 * cav.min_wall_mm {
            errs.push(ParamError::new(
                path,
                side,
                format!(
                    "must hold the reservoir bore (mold.two_piece.reservoir_diameter_mm = {}) with the minimum wall {} mm of printer profile '{cavity}' on each side",
                    t.reservoir_diameter_mm, cav.min_wall_mm
                ),
            ));
        }
    }
    if t.reservoir_height_mm - t.boss.height_mm < cav.min_wall_mm {
        errs.push(ParamError::new(
            "mold.two_piece.reservoir_height_mm",
            t.reservoir_height_mm,
            format!(
                "leaves a plate of {:.3} mm above the {} mm boss, below the minimum wall {} mm of printer profile '{cavity}'",
                t.reservoir_height_mm - t.boss.height_mm,
                t.boss.height_mm,
                cav.min_wall_mm
            ),
        ));
    }
    if m.registration_key.clearance_mm < cav.xy_resolution_mm {
        errs.push(ParamError::new(
            "mold.registration_key.clearance_mm",
            m.registration_key.clearance_mm,
            format!(
                "the boss of the two-piece mold fits its pocket with this clearance; it must be at least the xy resolution {} mm of printer profile '{cavity}'",
                cav.xy_resolution_mm
            ),
        ));
    }
    let [px, py] = BoltLayout::new(si).pitch_mm();
    let pitch = px.min(py);
    let need = hole + cav.min_wall_mm;
    if pitch < need {
        errs.push(ParamError::new(
            "mold.two_piece.bolt_count",
            t.bolt_count,
            format!(
                "bolts {pitch:.3} mm apart on the flange: closer than the hole {hole} mm ({hole_path}) plus the minimum wall {} mm of printer profile '{cavity}'",
                cav.min_wall_mm
            ),
        ));
    }
}

/// The two-piece open mold of a solid cast layer (`two_piece_open` strategy, frame
/// [`crate::parts::molds::TwoPieceFrame`]). Builds its solids: the cavity block (the outline from the
/// parting face to `mold.wall_thickness_mm` beyond the tallest outward feature, less the
/// cavity, the pocket and the bolt holes, with the features) and the top piece (plate and
/// boss, less the reservoir bore and the bolt holes); [`two_piece_open_parts`] makes their
/// parts.
pub(crate) fn build_two_piece_open_layer(b: LayerBuild) -> Result<LayerOutput, DesignError> {
    let (si, tol, l) = (b.si, b.tol, b.l);
    let m = &si.mold;
    let g = |r: Result<Solid, GeometryError>| r.part(&b.name);
    // Cavity block: the outline from the parting face to the wall beyond the pole,
    // less the cavity (continued 1 mm into the pocket), the pocket and the bolt holes,
    // with the features: a dimple is a pin standing into the cavity.
    let f = crate::parts::molds::TwoPieceFrame::new(si);
    let zb = f.base_z_mm;
    let plain = g(body_solid(si, l.outer_offset_mm, 1.0, tol))?;
    let cap = g(body_solid(si, l.outer_offset_mm, 0.0, tol))?;
    let top = features_top_z_mm(si, l.outer_offset_mm, &b.outer);
    let z_far = top + m.wall_thickness_mm;
    let [ox, oy] = f.outer_half_mm;
    let [px, py] = f.pocket_half_mm;
    let [bx, by] = f.boss_half_mm;
    let pocket = g(crate::geometry::cuboid(
        [-px, -py, f.parting_z_mm - 1.0],
        [px, py, zb],
    ))?;
    // The bolt holes of one piece: through both, each piece with its own diameter.
    let bolt_holes = |diameter_mm: f64| -> Result<Solid, DesignError> {
        let hole = g(crate::geometry::cylinder(
            z_far - f.top_z_mm + 2.0,
            diameter_mm / 2.0,
            tol,
        ))?;
        Ok(Solid::compose(
            &f.bolts_xy_mm
                .iter()
                .map(|b| hole.translate([b[0], b[1], f.top_z_mm - 1.0]))
                .collect::<Vec<_>>(),
        ))
    };
    let bolts = bolt_holes(f.cavity_block_bolt_hole_mm)?;
    let top_bolts = bolt_holes(f.top_piece_bolt_hole_mm)?;
    let block = g(crate::geometry::cuboid(
        [-ox, -oy, f.parting_z_mm],
        [ox, oy, z_far],
    ))?;
    let bare = g(block
        .difference(&plain)
        .and_then(|b| b.difference(&pocket))
        .and_then(|b| b.difference(&bolts)))?;
    let bottom = g(apply_features_signed(
        si.shared,
        bare.clone(),
        &b.outer,
        tol,
        false,
        -1.0,
    ))?;
    // The skin: the cap less what the features added to the block, plus what they cut.
    let skin_volume = cap.volume() - (bottom.volume() - bare.volume());
    // Top piece: plate and boss, less the reservoir bore and the bolt holes.
    let plate = g(crate::geometry::cuboid(
        [-ox, -oy, f.top_z_mm],
        [ox, oy, f.parting_z_mm],
    ))?;
    let boss = g(crate::geometry::cuboid(
        [-bx, -by, f.parting_z_mm],
        [bx, by, zb],
    ))?;
    let bore = g(
        crate::geometry::cylinder(zb - f.top_z_mm + 2.0, f.reservoir_radius_mm, tol)
            .map(|c| c.translate([0.0, 0.0, f.top_z_mm - 1.0])),
    )?;
    let top_piece = g(plate
        .union(&boss)
        .and_then(|t| t.difference(&Solid::compose(&[bore, top_bolts]))))?;
    Ok(two_piece_open_parts(
        b,
        &f,
        z_far,
        bottom,
        top_piece,
        skin_volume,
    ))
}

/// The two parts of a two-piece open mold of frame `f` from its solids (`bottom`, the cavity
/// block, and `top_piece`, sensor frame), the cavity block reaching up to `z_far` mm: the
/// cavity block printed parting face up and the reservoir top, with the frame, bolt grip and
/// reservoir volume in their parameters; one pour of the layer's material, `skin_volume`
/// mm^3, into both.
pub(crate) fn two_piece_open_parts(
    b: LayerBuild,
    f: &crate::parts::molds::TwoPieceFrame,
    z_far: f64,
    bottom: Solid,
    top_piece: Solid,
    skin_volume: f64,
) -> LayerOutput {
    let (si, l, name, cavity_tech) = (b.si, b.l, &b.name, b.cavity_tech);
    let m = &si.mold;
    let zb = f.base_z_mm;
    let reservoir_mm3 = std::f64::consts::PI * f.reservoir_radius_mm.powi(2) * (zb - f.top_z_mm);
    let params = json!({
        "base": b.base_params,
        "two_piece": m.two_piece,
        "frame": f,
        "cavity_block_z_mm": [f.parting_z_mm, z_far],
        "bolt_holes_z_mm": [f.top_z_mm - 1.0, z_far + 1.0],
        "bolt_grip_mm": z_far - f.top_z_mm,
        "registration_clearance_mm": m.registration_key.clearance_mm,
        "reservoir_volume_mm3": reservoir_mm3,
        "pull_direction": "along the sensor axis: the top piece off the cavity block, then the skin out of the cavity",
    });
    let (bottom_placed, bottom_pose) =
        place_posed(&bottom, &crate::geometry::rotation_deg(180.0, 0.0, 0.0));
    let (top_placed, top_pose) = place_posed(&top_piece, &crate::geometry::Affine::identity());
    let piece = |suffix: &str, which: &str, desc: String, solid, pose| {
        let mut p = params.clone();
        p["piece"] = json!(which);
        Part {
            name: format!("{name}_{suffix}"),
            role: "open_mold_piece".into(),
            description: desc,
            material: material_for(cavity_tech).into(),
            print_technology: cavity_tech,
            solid,
            params: with_pose(p, &pose),
            group: None,
        }
    };
    let n_bolts = f.bolts_xy_mm.len();
    let parts = vec![
        piece(
            "cavity_block",
            "cavity_block",
            format!(
                "Bottom piece of the two-piece mold for the solid {name} skin: the cavity, printed parting face up, with the pocket for the top piece's boss and {n_bolts} bolt holes"
            ),
            bottom_placed,
            bottom_pose,
        ),
        piece(
            "reservoir_top",
            "reservoir_top",
            format!(
                "Top piece of the two-piece mold for the {name} skin: its {} mm bore is the pour reservoir that forms the skin's back; boss down into the cavity block's pocket, {n_bolts} bolts",
                2.0 * f.reservoir_radius_mm
            ),
            top_placed,
            top_pose,
        ),
    ];
    let pour_parts = parts.iter().map(|p| p.name.clone()).collect();
    let mut markers = b.markers_json;
    set_forming(&mut markers, &[format!("{name}_cavity_block")], &[], 0.0);
    LayerOutput {
        parts,
        pours: vec![(name.clone(), l.material.clone(), skin_volume, pour_parts)],
        markers,
    }
}

/// The `two_piece_open` strategy ([`super::STRATEGIES`]).
pub struct TwoPieceOpen;

impl Strategy for TwoPieceOpen {
    fn kind(&self) -> Kind {
        Kind::TwoPieceOpen
    }

    /// The reservoir top bolted onto the cavity block, then the pour into its bore.
    fn pour_steps(&self, p: PourInput<'_>) -> Vec<ProcedureStep> {
        let (n, mix) = (p.step, p.mix);
        let mut out = Vec::new();
        let top = p
            .pieces
            .iter()
            .find(|q| q.params["piece"] == "reservoir_top");
        let block = p
            .pieces
            .iter()
            .find(|q| q.params["piece"] == "cavity_block");
        if let (Some(t), Some(b)) = (top, block) {
            out.push(ProcedureStep::new(
                ProcedureAction::CloseMold,
                format!(
                    "Step {n}: set `{}` on `{}`, boss down into the pocket{}.",
                    t.name, b.name, p.bolt_text
                ),
            ));
        }
        out.push(ProcedureStep::new(
            ProcedureAction::Pour,
            format!(
                "Step {n}: with the cavity down and the reservoir bore up, mix and degas {mix} \
                 and pour it into the bore to its top face; degas the filled mold again."
            ),
        ));
        out
    }

    /// `mold.two_piece.bolt_count` bolts through both pieces, named on the cavity block.
    fn clamp_bolts(&self, si: &StackInput<'_>, p: &Part) -> Option<MoldBolts> {
        if p.role != "open_mold_piece" || p.params["piece"] != "cavity_block" {
            return None;
        }
        let grip = p.params["bolt_grip_mm"].as_f64()?;
        let n = p.params["frame"]["bolts_xy_mm"].as_array().map(Vec::len)?;
        let (a, b) = si
            .mold
            .two_piece
            .bolt_holes_mm(si.mold.clamp_bolt.clearance_diameter_mm);
        Some(MoldBolts {
            count: n,
            grip_mm: grip,
            clearance_mm: a.min(b),
        })
    }

    /// [`check_two_piece`] for the widest layer cast in it.
    fn check_layers(
        &self,
        si: &StackInput<'_>,
        cast: Option<&[&ResolvedLayer]>,
        errs: &mut Vec<ParamError>,
    ) {
        let rim = cast
            .unwrap_or_default()
            .iter()
            .map(|l| si.ctx.body.rim_radius_mm(l.outer_offset_mm))
            .fold(None, |a: Option<f64>, r| Some(a.map_or(r, |a| a.max(r))));
        if let Some(rim) = rim {
            check_two_piece(si, rim, errs);
        }
    }

    fn solid_only(&self) -> bool {
        true
    }

    fn build_layer(&self, b: LayerBuild<'_>) -> Option<Result<LayerOutput, DesignError>> {
        Some(build_two_piece_open_layer(b))
    }

    /// The space the closed cavity block and reservoir top leave.
    fn cast<'k>(&self, c: &dyn CastPieces<'k>) -> Result<(Solid, Vec<&'k Part>), DesignError> {
        let p = vec![c.need("cavity_block")?, c.need("reservoir_top")?];
        Ok((c.negative(&p)?, p))
    }
}
