//! The shared frame of the core-holding molds (`direct`, `master`): the pours of a design
//! ([`cast_plans`]), the cavity and the core holder, and the box sizes.

use crate::error::{DesignError, GeometryContext};
use crate::geometry::{revolve, ChordTolerance, Polyline2, Solid};
use crate::parts::context::{ResolvedCore, Stack};
use crate::parts::stack_input::StackInput;
use crate::parts::{Part, PrintTechnology};
use crate::schema::{LayerProcess, MoldStrategy};
use serde_json::json;

/// The cavity of layer `l` in an open mold, from the layer's parameters alone: its radius on
/// the base plane and its height over it with the tallest raised feature of its outer surface,
/// mm (what `mold.open_block` must hold, and its walls are measured from).
pub fn open_cavity_mm(si: &StackInput<'_>, l: &crate::parts::context::ResolvedLayer) -> (f64, f64) {
    let b = &si.ctx.body;
    let raised = si.layers[l.index]
        .markers
        .iter()
        .filter(|m| {
            m.surface == crate::markers::MarkerSurface::Outer
                && m.feature.side() == crate::markers::Polarity::Raised
        })
        .map(|m| m.feature.height_mm)
        .fold(0.0, f64::max);
    (
        b.rim_radius_mm(l.outer_offset_mm),
        b.pole_z_mm(l.outer_offset_mm) + raised - b.base_z_mm(),
    )
}

/// Shoulder under the core's open end in the holder, mm.
pub(crate) const SHOULDER_MM: f64 = 2.0;

/// Radial margin of the holder flange beyond the plinth, mm.
pub(crate) const FLANGE_MARGIN_MM: f64 = 3.0;

/// Height of the master pattern's locating pin and its radius cap, mm.
pub(crate) const LOCATING_PIN_HEIGHT_MM: f64 = 2.0;

pub(crate) const LOCATING_PIN_RADIUS_MM: f64 = 3.0;

/// Floor and wall of the mold box, mm.
pub(crate) const BOX_FLOOR_MM: f64 = 2.0;

pub(crate) const BOX_WALL_MM: f64 = 2.0;

/// How far the box rim stands above the Mold Star fill level, mm.
pub(crate) const BOX_FREEBOARD_MM: f64 = 2.0;

/// One pour into a mold: which layer, the cavity surface, and the core under it.
#[derive(Debug, Clone)]
pub struct CastPlan {
    /// Index of the cast layer.
    pub layer: usize,
    /// Sprayed layers coated into this mold before the pour (outermost first).
    pub sprayed: Vec<usize>,
    /// Offset of the cavity surface from the body surface, mm.
    pub cavity_offset_mm: f64,
    /// Offset of the surface the pour lands on (the layer's inner surface), mm.
    pub core_offset_mm: f64,
    pub strategy: MoldStrategy,
}

/// The pours of a design in casting order (inner layers first).
pub fn cast_plans(si: &StackInput<'_>, stack: &Stack) -> Vec<CastPlan> {
    let mut plans = Vec::new();
    for (i, l) in stack.layers.iter().enumerate() {
        if l.process != LayerProcess::Cast {
            continue;
        }
        let mut sprayed = Vec::new();
        let mut outer = l.outer_offset_mm;
        for s in &stack.layers[i + 1..] {
            if s.process != LayerProcess::Sprayed {
                break;
            }
            sprayed.push(s.index);
            outer = s.outer_offset_mm;
        }
        sprayed.reverse();
        plans.push(CastPlan {
            layer: i,
            sprayed,
            cavity_offset_mm: outer + si.mold.cavity_clearance_mm,
            core_offset_mm: l.inner_offset_mm,
            strategy: l.mold_strategy,
        });
    }
    plans
}

/// Dimensions shared by the parts of one cast's mold, in the sensor frame, mm.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MoldFrame {
    pub base_z_mm: f64,
    pub cavity_rim_radius_mm: f64,
    pub cavity_pole_z_mm: f64,
    pub plinth_radius_mm: f64,
    /// Outer face of the plinth recess (the mold's open face), z.
    pub open_face_z_mm: f64,
    pub spigot_top_z_mm: f64,
    pub core_outer_radius_mm: f64,
    pub core_inner_radius_mm: f64,
    pub core_end_z_mm: f64,
}

impl MoldFrame {
    pub fn new(si: &StackInput<'_>, core: &ResolvedCore, cavity_offset_mm: f64) -> Self {
        let b = &si.ctx.body;
        let m = &si.mold;
        let base_z = b.base_z_mm();
        let rim = b.rim_radius_mm(cavity_offset_mm);
        Self {
            base_z_mm: base_z,
            cavity_rim_radius_mm: rim,
            cavity_pole_z_mm: b.pole_z_mm(cavity_offset_mm),
            plinth_radius_mm: rim + m.plinth.margin_mm,
            open_face_z_mm: base_z - m.plinth.height_mm,
            spigot_top_z_mm: base_z - m.plinth.reservoir_depth_mm,
            core_outer_radius_mm: b.rim_radius_mm(core.outer_offset_mm),
            core_inner_radius_mm: b.rim_radius_mm(core.inner_offset_mm),
            core_end_z_mm: base_z - core.below_base_mm,
        }
    }

    /// Top of the centring pin: it must stay where the core's bore is still straight.
    pub(crate) fn pin_top_z_mm(&self, si: &StackInput<'_>) -> f64 {
        let straight_top = match si.ctx.body {
            crate::profile::BodyProfile::HemisphereOnCylinder {
                cylinder_length_mm, ..
            } => self.base_z_mm + cylinder_length_mm,
            _ => self.base_z_mm,
        };
        (self.core_end_z_mm + si.mold.core_holder.pin_length_mm).min(straight_top - 0.5)
    }

    /// Radial position of the sprue axis: centred in the room between the core groove and
    /// the spigot edge.
    fn sprue_radius_mm(&self, si: &StackInput<'_>) -> f64 {
        let ch = &si.mold.core_holder;
        let lo = self.core_outer_radius_mm + ch.fit_clearance_mm + ch.min_wall_mm;
        let hi = self.plinth_radius_mm - ch.fit_clearance_mm - ch.min_wall_mm;
        0.5 * (lo + hi)
    }
}

/// The cavity solid with its plinth recess, and optionally the master pattern's locating pin,
/// as one revolve.
pub(crate) fn cavity_profile(
    si: &StackInput<'_>,
    f: &MoldFrame,
    offset: f64,
    with_pin: bool,
    tol: ChordTolerance,
) -> Polyline2 {
    let mut pl = si.ctx.body.offset_polyline(offset, 0.0, tol.half());
    pl.push([f.plinth_radius_mm, f.base_z_mm]);
    pl.push([f.plinth_radius_mm, f.open_face_z_mm]);
    if with_pin {
        let r = LOCATING_PIN_RADIUS_MM.min(f.plinth_radius_mm / 3.0);
        pl.push([r, f.open_face_z_mm]);
        pl.push([r, f.open_face_z_mm - LOCATING_PIN_HEIGHT_MM]);
        pl.push([0.0, f.open_face_z_mm - LOCATING_PIN_HEIGHT_MM]);
    } else {
        pl.push([0.0, f.open_face_z_mm]);
    }
    pl
}

/// The core holder / casting jig in the sensor frame (assembled position).
pub(crate) fn core_holder(
    si: &StackInput<'_>,
    f: &MoldFrame,
    tol: ChordTolerance,
) -> Result<Solid, DesignError> {
    let m = &si.mold;
    let ch = &m.core_holder;
    let fit = ch.fit_clearance_mm;
    let r_f = f.plinth_radius_mm + FLANGE_MARGIN_MM;
    let z_f0 = f.open_face_z_mm - ch.flange_thickness_mm;
    let r_boss = f.core_outer_radius_mm + fit + ch.min_wall_mm;
    let z_bottom = z_f0.min(f.core_end_z_mm - SHOULDER_MM);
    let mut pl = Polyline2::default();
    pl.push([0.0, z_bottom]);
    if z_bottom < z_f0 {
        pl.push([r_boss, z_bottom]);
        pl.push([r_boss, z_f0]);
    }
    for p in [
        [r_f, z_f0],
        [r_f, f.open_face_z_mm],
        [f.plinth_radius_mm - fit, f.open_face_z_mm],
        [f.plinth_radius_mm - fit, f.spigot_top_z_mm],
        [f.core_outer_radius_mm + fit, f.spigot_top_z_mm],
        [f.core_outer_radius_mm + fit, f.core_end_z_mm],
        [f.core_inner_radius_mm - fit, f.core_end_z_mm],
        [f.core_inner_radius_mm - fit, f.pin_top_z_mm(si)],
        [0.0, f.pin_top_z_mm(si)],
    ] {
        pl.push(p);
    }
    let body = Solid::from_mesh(&revolve(&pl, tol).part("core holder")?).part("core holder")?;
    // Sprue at azimuth 0, vents spread over the rest of the circle.
    let z0 = z_bottom - 1.0;
    let h = f.spigot_top_z_mm + 1.0 - z0;
    let mut holes = vec![crate::geometry::cylinder(h, m.sprue.diameter_mm / 2.0, tol)
        .part("sprue")?
        .translate([f.sprue_radius_mm(si), 0.0, z0])];
    let r_v = f.plinth_radius_mm - fit - ch.min_wall_mm - m.vent.diameter_mm / 2.0;
    for k in 1..=m.vent.count {
        let a = 2.0 * std::f64::consts::PI * k as f64 / (m.vent.count + 1) as f64;
        holes.push(
            crate::geometry::cylinder(h, m.vent.diameter_mm / 2.0, tol)
                .part("vent")?
                .translate([r_v * a.cos(), r_v * a.sin(), z0]),
        );
    }
    body.difference(&Solid::compose(&holes)).part("core holder")
}

pub(crate) fn holder_params(si: &StackInput<'_>, f: &MoldFrame) -> serde_json::Value {
    let m = &si.mold;
    let ch = &m.core_holder;
    let fit = ch.fit_clearance_mm;
    let z_f0 = f.open_face_z_mm - ch.flange_thickness_mm;
    let z_bottom = z_f0.min(f.core_end_z_mm - SHOULDER_MM);
    let r_v = f.plinth_radius_mm - fit - ch.min_wall_mm - m.vent.diameter_mm / 2.0;
    json!({
        "boss_radius_mm": f.core_outer_radius_mm + fit + ch.min_wall_mm,
        "bottom_z_mm": z_bottom,
        "holes_z_mm": [z_bottom - 1.0, f.spigot_top_z_mm + 1.0],
        "vent_radius_mm": r_v,
        "vent_azimuths_deg": (1..=m.vent.count).map(|k| 360.0 * k as f64 / (m.vent.count + 1) as f64).collect::<Vec<_>>(),
        "frame": f,
        "fit_clearance_mm": m.core_holder.fit_clearance_mm,
        "flange_thickness_mm": m.core_holder.flange_thickness_mm,
        "flange_radius_mm": f.plinth_radius_mm + FLANGE_MARGIN_MM,
        "pin_top_z_mm": f.pin_top_z_mm(si),
        "sprue": {"diameter_mm": m.sprue.diameter_mm, "radius_mm": f.sprue_radius_mm(si), "azimuth_deg": 0.0},
        "vent": {"diameter_mm": m.vent.diameter_mm, "count": m.vent.count},
        "print_orientation": "sensor frame, translated so the flange (or boss) rests on z = 0",
    })
}

/// What a core-holding strategy builds for one cast ([`super::strategy::Strategy::core_mold`]):
/// the mold builder adds the pour's volume, computed beside it, and the marker summary
/// ([`MoldOutput`]).
pub struct CoreMold {
    pub parts: Vec<Part>,
    /// For the master strategy: (silicone mold volume mm^3, parts that hold the pour).
    pub silicone_pour: Option<(f64, Vec<String>)>,
    /// Names of the parts that hold the gel pour.
    pub pour_parts: Vec<String>,
}

/// What the mold builder returns for one cast.
pub struct MoldOutput {
    pub parts: Vec<Part>,
    /// Volume the gel pour fills (cavity and reservoir minus core and holder), mm^3.
    pub pour_volume_mm3: f64,
    /// For the master strategy: (silicone mold volume mm^3, parts that hold the pour).
    pub silicone_pour: Option<(f64, Vec<String>)>,
    /// Names of the parts that hold the gel pour.
    pub pour_parts: Vec<String>,
    /// The layer's marker summary with the parts that form the features
    /// ([`crate::parts::layers::set_forming`]).
    pub markers: Vec<serde_json::Value>,
}

/// What both strategies of [`build_mold_parts`] build from: the cast layer's `name`, the
/// mold frame `f`, the parameters `common` to the mold's parts, the core holder (or casting
/// jig) part and its name.
pub struct CastMold<'a> {
    pub(crate) name: &'a str,
    pub(crate) f: MoldFrame,
    pub(crate) common: serde_json::Value,
    pub(crate) holder_name: String,
    pub(crate) holder_part: Part,
}

pub(crate) fn material_for(t: PrintTechnology) -> &'static str {
    match t {
        PrintTechnology::Fdm => "pla",
        PrintTechnology::Sla => "sla_standard_resin",
        PrintTechnology::Polyjet => "tango_black_plus",
    }
}

/// `the 3.0 mm hole 12.5 mm from the axis, nearest it; the 3 vents are the 2.0 mm holes at
/// 17.0 mm`, from the holder's parameters.
pub(crate) fn sprue_text(holder: &Part) -> String {
    let p = &holder.params;
    let (Some(d), Some(r)) = (
        p["sprue"]["diameter_mm"].as_f64(),
        p["sprue"]["radius_mm"].as_f64(),
    ) else {
        return "the sprue".into();
    };
    let rv = p["vent_radius_mm"].as_f64().unwrap_or(f64::NAN);
    let dv = p["vent"]["diameter_mm"].as_f64().unwrap_or(f64::NAN);
    let nv = p["vent"]["count"].as_u64().unwrap_or(0);
    let nearest = if r < rv {
        ", the one nearest the axis"
    } else {
        ""
    };
    format!(
        "the {d:.1} mm hole {r:.1} mm from the axis{nearest}; the {nv} vents are the {dv:.1} mm \
         holes {rv:.1} mm from it"
    )
}

/// The pour through the core holder's sprue, step `n`, of `mix`.
pub(crate) fn sprue_pour_text(n: u32, mix: &str, holder: Option<&Part>) -> String {
    let sprue = holder.map_or_else(|| "the sprue".to_string(), sprue_text);
    format!(
        "Step {n}: stand the mold pole-down, the holder's flange on top. Mix and degas {mix} and \
         pour it slowly through the sprue ({sprue}) until it shows in every vent."
    )
}
