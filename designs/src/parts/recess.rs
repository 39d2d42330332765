//! The seat of an optic under a solid skin (`layers[0].recess`): a recess open on the base
//! plane whose roof is a spherical cap seen from the base, on a cone that narrows upward by
//! its draft, the edge between them rounded by a fillet. The DIGIT Pinki gel carries one
//! (facebookresearch/digit-design, `DIGIT_Pinki/gel/Pinki Gel.step`: cap R7.4389, cone of
//! 2 deg, fillet R0.25); its mold's insert is the same solid (`open` strategy). It is a
//! layer feature ([`RecessFeature`], [`crate::parts::layer_feature`]): its outline is a
//! [`Seat`].
//!
//! Frame: the sensor frame (docs/conventions.md). The recess is a solid of revolution about
//! the z axis; its heights `h` are measured up from the base plane (`z = base_z + h`).

use crate::error::ParamError;
use crate::geometry::{ChordTolerance, GeometryError};
use crate::parts::layer_feature::{InsertInput, LayerFeature, LayerInput, MoldInsert};
use crate::parts::part::Part;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::seat::Seat;
use crate::schema::shared::LayerProcess;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The largest draft of the recess's cone, degrees (exclusive).
pub const MAX_DRAFT_DEG: f64 = 45.0;

/// The recess under a solid skin, open on the base plane (the seat of the optic the camera
/// looks through). All lengths mm, angles degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Recess {
    /// Diameter of the recess's mouth on the base plane, mm, > 0: below the skin's diameter
    /// there.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub base_diameter_mm: f64,
    /// Height of the roof's apex over the base plane, on the axis, mm, > 0: below the skin's
    /// height.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub depth_mm: f64,
    /// Radius of the roof's sphere (its centre on the axis, `cap_radius_mm` under the apex),
    /// mm, > 0: large enough that the sphere holds the mouth's edge, and the roof meets the
    /// cone on the sphere's upper half (no undercut that would lock the insert in the skin).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cap_radius_mm: f64,
    /// Draft of the wall from the axis direction, degrees, in [0, 45): the wall narrows from
    /// the mouth upward, so that the insert that forms it pulls out downward.
    #[serde(default)]
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 45))]
    pub draft_angle_deg: f64,
    /// Radius of the fillet between the wall and the roof, mm, >= 0 (0: a sharp edge); it
    /// must touch the wall above the base plane.
    #[serde(default)]
    #[schemars(extend("minimum" = 0))]
    pub fillet_radius_mm: f64,
}

impl Recess {
    /// The recess's outline, or the field and the rule its sizes break together (for
    /// [`check_recess`], which checks each size on its own first: above 0, the draft in
    /// [0, 45) degrees).
    pub fn outline(&self) -> Result<Seat, (&'static str, String)> {
        let r0 = self.base_diameter_mm / 2.0;
        let (d, cap, rf) = (self.depth_mm, self.cap_radius_mm, self.fillet_radius_mm);
        let a = self.draft_angle_deg.to_radians();
        let (t, c, s) = (a.tan(), a.cos(), a.sin());
        let hs = d - cap;
        // the sphere through the apex must hold the mouth's edge
        if r0 * r0 + hs * hs >= cap * cap {
            let least = (r0 * r0 + d * d) / (2.0 * d);
            return Err((
                "cap_radius_mm",
                format!(
                    "must exceed (r^2 + depth^2) / (2 depth) = {least:.4} mm (r: the mouth's radius) so that the roof meets the wall above the base plane"
                ),
            ));
        }
        // Where a circle of radius `cap - k` about the sphere's centre meets the wall moved
        // in by `k` (its larger height): the wall's top (k = 0) or the fillet's centre (k = rf).
        let meet = |k: f64| -> Option<f64> {
            let a0 = r0 - k / c;
            let rr = cap - k;
            let qa = 1.0 + t * t;
            let qb = -2.0 * (a0 * t + hs);
            let qc = a0 * a0 + hs * hs - rr * rr;
            let disc = qb * qb - 4.0 * qa * qc;
            (disc >= 0.0).then(|| (-qb + disc.sqrt()) / (2.0 * qa))
        };
        let Some(h_meet) = meet(0.0) else {
            return Err((
                "cap_radius_mm",
                "the roof's sphere does not meet the wall".into(),
            ));
        };
        if h_meet < hs {
            return Err((
                "cap_radius_mm",
                format!(
                    "the roof must meet the wall on its sphere's upper half (here {h_meet:.4} mm over the base plane, the sphere's centre at {hs:.4} mm): an undercut would lock the insert in the skin"
                ),
            ));
        }
        if rf == 0.0 {
            let p = [r0 - h_meet * t, h_meet];
            return Ok(self.resolved(p, p, p, hs));
        }
        if rf >= cap {
            return Err((
                "fillet_radius_mm",
                format!("must be below cap_radius_mm ({cap})"),
            ));
        }
        let Some(hc) = meet(rf) else {
            return Err((
                "fillet_radius_mm",
                "too large: no fillet touches both the wall and the roof".into(),
            ));
        };
        let centre = [r0 - hc * t - rf / c, hc];
        let wall_top = [centre[0] + rf * c, centre[1] + rf * s];
        let (dr, dh) = (centre[0], centre[1] - hs);
        let len = dr.hypot(dh);
        let roof_edge = [dr / len * cap, hs + dh / len * cap];
        if !(centre[0] > 0.0 && wall_top[1] >= 0.0 && roof_edge[1] >= wall_top[1] && dh >= 0.0) {
            return Err((
                "fillet_radius_mm",
                "too large: the fillet must touch the wall above the base plane and the roof on its sphere's upper half".into(),
            ));
        }
        Ok(self.resolved(centre, wall_top, roof_edge, hs))
    }

    fn resolved(
        &self,
        fillet_centre: [f64; 2],
        wall_top: [f64; 2],
        roof_edge: [f64; 2],
        cap_centre_h_mm: f64,
    ) -> Seat {
        Seat {
            mouth_radius_mm: self.base_diameter_mm / 2.0,
            depth_mm: self.depth_mm,
            cap_radius_mm: self.cap_radius_mm,
            cap_centre_h_mm,
            draft_angle_deg: self.draft_angle_deg,
            fillet_radius_mm: self.fillet_radius_mm,
            fillet_centre,
            wall_top,
            roof_edge,
        }
    }
}

/// The rules of a recess at `path` (`layers[0].recess`) in a skin whose rim radius on the base
/// plane is `rim_radius_mm` and whose height over it is `height_mm`: sizes above 0, the draft
/// in [0, 45) degrees, the fillet 0 or more, the outline that they make
/// ([`Recess::outline`]), and the recess inside the skin.
pub fn check_recess(
    path: &str,
    r: &Recess,
    rim_radius_mm: f64,
    height_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let prefix = format!("{path}.");
    let mut bad = crate::parts::check_above_zero(&prefix, r, &[], errs);
    if !(r.fillet_radius_mm >= 0.0 && r.fillet_radius_mm.is_finite()) {
        errs.push(ParamError::new(
            format!("{prefix}fillet_radius_mm"),
            r.fillet_radius_mm,
            "must be 0 or more",
        ));
        bad = true;
    }
    if !(0.0..MAX_DRAFT_DEG).contains(&r.draft_angle_deg) {
        errs.push(ParamError::new(
            format!("{prefix}draft_angle_deg"),
            r.draft_angle_deg,
            format!("must be in [0, {MAX_DRAFT_DEG})"),
        ));
        bad = true;
    }
    if bad {
        return;
    }
    if r.base_diameter_mm / 2.0 >= rim_radius_mm {
        errs.push(ParamError::new(
            format!("{prefix}base_diameter_mm"),
            r.base_diameter_mm,
            format!(
                "must be below the skin's diameter on the base plane ({:.3} mm)",
                2.0 * rim_radius_mm
            ),
        ));
    }
    if r.depth_mm >= height_mm {
        errs.push(ParamError::new(
            format!("{prefix}depth_mm"),
            r.depth_mm,
            format!("must be below the skin's height over the base plane ({height_mm:.3} mm)"),
        ));
    }
    if let Err((field, rule)) = r.outline() {
        let value = match field {
            "fillet_radius_mm" => r.fillet_radius_mm,
            _ => r.cap_radius_mm,
        };
        errs.push(ParamError::new(format!("{prefix}{field}"), value, rule));
    }
}

/// The recess as a layer feature (`layers[i].recess`): on a solid layer of a curved body, cast
/// in an `open` mold when cast (its insert sets in the open face), without recessed markers on
/// the same layer (their clearance to the recess is not checked), and within its own rules
/// ([`check_recess`]); it cuts its outline from the layer ([`LayerFeature::seat`]) and its
/// insert forms it in the open mold.
pub struct RecessFeature;

impl LayerFeature for RecessFeature {
    type Params = Recess;
    const KEY: &'static str = "recess";
    const FLAT_RULE: Option<&'static str> =
        Some("applies to curved skins only: a flat skin has no optic's seat");
    const INSERT_ROLE: Option<&'static str> = Some("recess_insert");

    fn check(r: &Recess, input: LayerInput<'_>, errs: &mut Vec<ParamError>) {
        let l = input;
        let path = input.path(Self::KEY);
        if !l.solid {
            errs.push(ParamError::new(
                &path,
                "given",
                format!(
                    "a recess is cut into the base of a solid layer; layer '{}' is not solid",
                    l.name
                ),
            ));
            return;
        }
        let strategy = input.strategy;
        if l.process == LayerProcess::Cast && !strategy.sets_inserts() {
            errs.push(ParamError::new(
                &path,
                "given",
                format!(
                    "a cast layer with a recess needs the open mold strategy (the recess's insert sets in the mold's open face); this layer's is {}",
                    serde_json::to_value(strategy).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default()
                ),
            ));
        }
        if l.markers
            .iter()
            .any(|m| m.feature.side() == crate::markers::Polarity::Recessed)
        {
            errs.push(ParamError::new(
                &path,
                "given",
                format!("layer '{}' carries recessed markers too: their clearance to the recess is not checked, so the two are not taken together", l.name),
            ));
        }
        if input.body_ok {
            let b = input.ctx.body;
            let before = errs.len();
            let height = b.pole_z_mm(0.0) - b.base_z_mm();
            check_recess(&path, r, b.rim_radius_mm(0.0), height, errs);
            let outline = r.outline().ok().filter(|_| errs.len() == before);
            if outline.is_some_and(|o| o.skin_mm(b, 0.0, ChordTolerance::default()) <= 0.0) {
                errs.push(ParamError::new(
                    &path,
                    "given",
                    "breaks through the skin's outer surface: the roof or the wall reaches it",
                ));
            }
        }
    }

    fn seat(r: &Recess) -> Option<Seat> {
        r.outline().ok()
    }

    fn twin_params(r: &Recess) -> Option<serde_json::Value> {
        Self::seat(r).map(|o| json!(o))
    }

    /// The insert that forms the seat: the recess's solid on the base plane, pressed into the
    /// poured open mold dome first.
    fn open_mold_inserts(
        r: &Recess,
        input: InsertInput<'_>,
    ) -> Result<Vec<MoldInsert>, GeometryError> {
        let Some(o) = Self::seat(r) else {
            return Ok(Vec::new());
        };
        let (name, zb) = (input.layer_name, input.base_z_mm);
        let insert = o.solid(zb, 0.0, input.tol)?;
        let volume_mm3 = insert.volume();
        let (placed, pose) = place_posed(&insert, &crate::geometry::Affine::identity());
        let part = Part {
            name: format!("{name}_recess_insert"),
            role: "recess_insert".into(),
            description: format!(
                "Forms the optic's seat under the {name} skin: once the open mold is poured to the brim, press it in dome first until its flat face lies in the mold's open face, centred on the cavity"
            ),
            material: input.material.into(),
            print_technology: input.technology,
            solid: placed,
            params: with_pose(
                json!({"base": input.base_params, "base_z_mm": zb, "recess": o,
                       "print_orientation": "flat face on the bed"}),
                &pose,
            ),
            group: None,
        };
        Ok(vec![MoldInsert { part, volume_mm3 }])
    }
}
