//! Molds for cast layers, in two strategies (R-Tac0 Sec. III-B1, Fig. 4):
//!
//! - `direct`: a printed block split on the parting plane y = 0 (through the axis), with
//!   hemispherical registration keys, clamp bolt holes and a core holder that closes the open
//!   end, keeps the core concentric and carries the sprue and vents.
//! - `master`: a printed master pattern of the cavity and a drafted mold box, to cast a
//!   Mold Star 30 silicone mold, plus the same core holder as casting jig.
//!
//! Both share the cavity: the offset surface of the layer's outermost sprayed coat (or of the
//! layer itself) plus `cavity_clearance_mm`, opening on the base plane into a disc-shaped
//! plinth recess. The core holder's spigot plugs into that recess (centring it) and leaves a
//! reservoir ring between the spigot and the base plane. Casting is done pole-down, so the
//! reservoir is the high point of the cavity: the sprue and the vents open into it.

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cuboid, revolve, sphere, Affine, ChordTolerance, Polyline2, Solid};
use crate::markers::MarkerSurface;
use crate::parts::context::{ResolvedCore, Stack};
use crate::parts::{Part, PrintTechnology};
use crate::schema::{Design, LayerProcess, MoldStrategy};
use serde_json::json;

pub use crate::parts::placement::{place_on_bed, place_posed, with_pose};
pub use crate::schema::mold::{
    ClampBolt, CoreHolderParams, MoldParams, OpenBlock, Plinth, RegistrationBoss, RegistrationKey,
    Sprue, TwoPieceOpenParams, Vent,
};

/// The cavity of layer `l` in an open mold, from the layer's parameters alone: its radius on
/// the base plane and its height over it with the tallest raised feature of its outer surface,
/// mm (what `mold.open_block` must hold, and its walls are measured from).
pub fn open_cavity_mm(design: &Design, l: &crate::parts::context::ResolvedLayer) -> (f64, f64) {
    let b = &design.body;
    let raised = design.layers[l.index]
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
const SHOULDER_MM: f64 = 2.0;
/// Radial margin of the holder flange beyond the plinth, mm.
const FLANGE_MARGIN_MM: f64 = 3.0;
/// Height of the master pattern's locating pin and its radius cap, mm.
const LOCATING_PIN_HEIGHT_MM: f64 = 2.0;
const LOCATING_PIN_RADIUS_MM: f64 = 3.0;
/// Floor and wall of the mold box, mm.
pub(crate) const BOX_FLOOR_MM: f64 = 2.0;
const BOX_WALL_MM: f64 = 2.0;
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
pub fn cast_plans(design: &Design, stack: &Stack) -> Vec<CastPlan> {
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
            cavity_offset_mm: outer + design.mold.cavity_clearance_mm,
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
    pub fn new(design: &Design, core: &ResolvedCore, cavity_offset_mm: f64) -> Self {
        let b = &design.body;
        let m = &design.mold;
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
    fn pin_top_z_mm(&self, design: &Design) -> f64 {
        let straight_top = match design.body {
            crate::profile::BodyProfile::HemisphereOnCylinder {
                cylinder_length_mm, ..
            } => self.base_z_mm + cylinder_length_mm,
            _ => self.base_z_mm,
        };
        (self.core_end_z_mm + design.mold.core_holder.pin_length_mm).min(straight_top - 0.5)
    }

    /// Radial position of the sprue axis: centred in the room between the core groove and
    /// the spigot edge.
    fn sprue_radius_mm(&self, design: &Design) -> f64 {
        let ch = &design.mold.core_holder;
        let lo = self.core_outer_radius_mm + ch.fit_clearance_mm + ch.min_wall_mm;
        let hi = self.plinth_radius_mm - ch.fit_clearance_mm - ch.min_wall_mm;
        0.5 * (lo + hi)
    }
}

/// Rules on mold parameters alone (sizes, printability).
pub fn check_mold_params(design: &Design, errs: &mut Vec<ParamError>) {
    let m = &design.mold;
    if !check_mold_sizes(design, errs) {
        return;
    }
    if m.plinth.reservoir_depth_mm >= m.plinth.height_mm {
        errs.push(ParamError::new(
            "mold.plinth.reservoir_depth_mm",
            m.plinth.reservoir_depth_mm,
            format!(
                "must be below mold.plinth.height_mm ({}) so the spigot can centre the holder",
                m.plinth.height_mm
            ),
        ));
    }
    check_mold_printability(design, errs);
}

/// Rules on the mold's sizes alone: lengths and diameters above 0 (all are checked),
/// clearances 0 or more, at least one vent, and `mold.draft_angle_deg` in [0, 10). Pushes its
/// errors to `errs`; false when a length or diameter is not above 0, which ends the checks.
fn check_mold_sizes(design: &Design, errs: &mut Vec<ParamError>) -> bool {
    let m = &design.mold;
    let mut pos = |path: &str, v: f64| {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(path, v, "must be above 0"));
            false
        } else {
            true
        }
    };
    let checks = [
        ("mold.wall_thickness_mm", m.wall_thickness_mm),
        ("mold.flange_width_mm", m.flange_width_mm),
        ("mold.plinth.margin_mm", m.plinth.margin_mm),
        ("mold.plinth.height_mm", m.plinth.height_mm),
        (
            "mold.plinth.reservoir_depth_mm",
            m.plinth.reservoir_depth_mm,
        ),
        (
            "mold.registration_key.diameter_mm",
            m.registration_key.diameter_mm,
        ),
        (
            "mold.clamp_bolt.clearance_diameter_mm",
            m.clamp_bolt.clearance_diameter_mm,
        ),
        ("mold.sprue.diameter_mm", m.sprue.diameter_mm),
        ("mold.vent.diameter_mm", m.vent.diameter_mm),
        (
            "mold.core_holder.flange_thickness_mm",
            m.core_holder.flange_thickness_mm,
        ),
        (
            "mold.core_holder.pin_length_mm",
            m.core_holder.pin_length_mm,
        ),
        ("mold.core_holder.min_wall_mm", m.core_holder.min_wall_mm),
        ("mold.silicone_wall_mm", m.silicone_wall_mm),
    ];
    let all_positive = checks.iter().fold(true, |ok, (p, v)| pos(p, *v) && ok);
    for (p, v) in [
        ("mold.cavity_clearance_mm", m.cavity_clearance_mm),
        (
            "mold.registration_key.clearance_mm",
            m.registration_key.clearance_mm,
        ),
        (
            "mold.core_holder.fit_clearance_mm",
            m.core_holder.fit_clearance_mm,
        ),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            errs.push(ParamError::new(p, v, "must be 0 or more"));
        }
    }
    if m.vent.count == 0 {
        errs.push(ParamError::new(
            "mold.vent.count",
            0,
            "at least one vent is needed to let air out of the cavity",
        ));
    }
    if !(0.0..10.0).contains(&m.draft_angle_deg) {
        errs.push(ParamError::new(
            "mold.draft_angle_deg",
            m.draft_angle_deg,
            "must be in [0, 10)",
        ));
    }
    all_positive
}

/// Rules on printability: each hole, wall and feature of the mold at least the minimum of the
/// printer profile of the part that carries it (the fixtures' for the sprue, vents and core
/// holder, the cavities' for the keys, bolt holes and walls), and `mold.flange_width_mm` wide
/// enough for the registration keys and clamp bolts with the minimum wall around them.
fn check_mold_printability(design: &Design, errs: &mut Vec<ParamError>) {
    let m = &design.mold;
    let fix = design.printers.get(m.fixture_print_technology);
    let cav = design.printers.get(m.cavity_print_technology);
    let fixture = format!("{:?}", m.fixture_print_technology).to_lowercase();
    let cavity = format!("{:?}", m.cavity_print_technology).to_lowercase();
    // Printability: every feature against the profile of the part that carries it.
    let below =
        |errs: &mut Vec<ParamError>, path: &str, v: f64, min: f64, what: &str, profile: &str| {
            if v < min {
                errs.push(ParamError::new(
                    path,
                    v,
                    format!("below the {what} {min} mm of printer profile '{profile}'"),
                ));
            }
        };
    below(
        errs,
        "mold.sprue.diameter_mm",
        m.sprue.diameter_mm,
        fix.min_hole_diameter_mm,
        "minimum hole",
        &fixture,
    );
    below(
        errs,
        "mold.vent.diameter_mm",
        m.vent.diameter_mm,
        fix.min_hole_diameter_mm,
        "minimum hole",
        &fixture,
    );
    below(
        errs,
        "mold.core_holder.min_wall_mm",
        m.core_holder.min_wall_mm,
        fix.min_wall_mm,
        "minimum wall",
        &fixture,
    );
    below(
        errs,
        "mold.registration_key.diameter_mm",
        m.registration_key.diameter_mm,
        cav.min_feature_mm,
        "minimum feature",
        &cavity,
    );
    below(
        errs,
        "mold.clamp_bolt.clearance_diameter_mm",
        m.clamp_bolt.clearance_diameter_mm,
        cav.min_hole_diameter_mm,
        "minimum hole",
        &cavity,
    );
    below(
        errs,
        "mold.wall_thickness_mm",
        m.wall_thickness_mm,
        cav.min_wall_mm,
        "minimum wall",
        &cavity,
    );
    if m.registration_key.diameter_mm
        + 2.0 * m.registration_key.clearance_mm
        + 2.0 * cav.min_wall_mm
        > m.flange_width_mm
        || m.clamp_bolt.clearance_diameter_mm + 2.0 * cav.min_wall_mm > m.flange_width_mm
    {
        errs.push(ParamError::new(
            "mold.flange_width_mm",
            m.flange_width_mm,
            "too narrow for the registration keys and clamp bolts with the printer's minimum wall around them",
        ));
    }
}
/// Rules that need the resolved core: does the holder fit between the core and the plinth.
/// `first_cavity_offset_mm` is the cavity of the innermost cast, the tightest one.
pub fn check_mold_fit(
    design: &Design,
    core: &ResolvedCore,
    first_cavity_offset_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let m = &design.mold;
    let ch = &m.core_holder;
    let f = MoldFrame::new(design, core, first_cavity_offset_mm + m.cavity_clearance_mm);
    let room = f.plinth_radius_mm
        - f.core_outer_radius_mm
        - 2.0 * ch.fit_clearance_mm
        - 2.0 * ch.min_wall_mm;
    if m.sprue.diameter_mm > room {
        errs.push(ParamError::new(
            "mold.sprue.diameter_mm",
            m.sprue.diameter_mm,
            format!(
                "does not fit between the core groove and the spigot edge of the core holder ({room:.2} mm of room); enlarge mold.plinth.margin_mm"
            ),
        ));
    }
    if m.vent.diameter_mm > room {
        errs.push(ParamError::new(
            "mold.vent.diameter_mm",
            m.vent.diameter_mm,
            format!("does not fit in the holder ({room:.2} mm of room)"),
        ));
    }
    // The sprue (azimuth 0) and the vents share the circle at equal steps of 360 / (count + 1)
    // deg; neighbouring holes must keep the holder's minimum wall between them. This also
    // bounds the count before any vent is built (10,000 vents once ran a minute into a mesh
    // error naming no parameter).
    let r_v = f.plinth_radius_mm - ch.fit_clearance_mm - ch.min_wall_mm - m.vent.diameter_mm / 2.0;
    let need = m.vent.diameter_mm.max(m.sprue.diameter_mm) + ch.min_wall_mm;
    if r_v > 0.0 && need > 0.0 && m.vent.count > 0 {
        // Most holes on the circle: a chord of `need` between neighbours.
        let max_holes = if need >= 2.0 * r_v {
            1.0
        } else {
            (std::f64::consts::PI / (need / (2.0 * r_v)).asin()).floor()
        };
        let max_vents = (max_holes - 1.0).max(0.0);
        if f64::from(m.vent.count) > max_vents {
            errs.push(ParamError::new(
                "mold.vent.count",
                m.vent.count,
                format!(
                    "at most {max_vents:.0} vents fit beside the sprue on the holder's vent circle ({:.2} mm across) with mold.core_holder.min_wall_mm ({}) between neighbouring holes",
                    2.0 * r_v,
                    ch.min_wall_mm
                ),
            ));
        }
    }
    if f.core_end_z_mm > f.spigot_top_z_mm - 1.0 {
        errs.push(ParamError::new(
            "core.length_mm",
            design.core.as_ref().map_or(0.0, |c| c.length_mm),
            format!(
                "the core must reach at least {:.3} mm below the base plane so the holder can seat it (1 mm below the spigot top)",
                f.base_z_mm - (f.spigot_top_z_mm - 1.0)
            ),
        ));
    }
    if f.core_inner_radius_mm - ch.fit_clearance_mm
        < design
            .printers
            .get(m.fixture_print_technology)
            .min_feature_mm
            / 2.0
    {
        errs.push(ParamError::new(
            "core.wall_thickness_mm",
            design.core.as_ref().map_or(0.0, |c| c.wall_thickness_mm),
            "leaves no room for the holder's centring pin inside the core",
        ));
    }
    if f.pin_top_z_mm(design) - f.core_end_z_mm < 1.0 {
        errs.push(ParamError::new(
            "mold.core_holder.pin_length_mm",
            ch.pin_length_mm,
            "the centring pin would be shorter than 1 mm inside the core's straight bore",
        ));
    }
}

/// The cavity solid with its plinth recess, and optionally the master pattern's locating pin,
/// as one revolve.
fn cavity_profile(
    design: &Design,
    f: &MoldFrame,
    offset: f64,
    with_pin: bool,
    tol: ChordTolerance,
) -> Polyline2 {
    let mut pl = design.body.offset_polyline(offset, 0.0, tol.half());
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
fn core_holder(design: &Design, f: &MoldFrame, tol: ChordTolerance) -> Result<Solid, DesignError> {
    let m = &design.mold;
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
        [f.core_inner_radius_mm - fit, f.pin_top_z_mm(design)],
        [0.0, f.pin_top_z_mm(design)],
    ] {
        pl.push(p);
    }
    let body = Solid::from_mesh(&revolve(&pl, tol).part("core holder")?).part("core holder")?;
    // Sprue at azimuth 0, vents spread over the rest of the circle.
    let z0 = z_bottom - 1.0;
    let h = f.spigot_top_z_mm + 1.0 - z0;
    let mut holes = vec![crate::geometry::cylinder(h, m.sprue.diameter_mm / 2.0, tol)
        .part("sprue")?
        .translate([f.sprue_radius_mm(design), 0.0, z0])];
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

fn holder_params(design: &Design, f: &MoldFrame) -> serde_json::Value {
    let m = &design.mold;
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
        "pin_top_z_mm": f.pin_top_z_mm(design),
        "sprue": {"diameter_mm": m.sprue.diameter_mm, "radius_mm": f.sprue_radius_mm(design), "azimuth_deg": 0.0},
        "vent": {"diameter_mm": m.vent.diameter_mm, "count": m.vent.count},
        "print_orientation": "sensor frame, translated so the flange (or boss) rests on z = 0",
    })
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

/// Builds the mold parts of one cast.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn build_mold(
    design: &Design,
    stack: &Stack,
    plan: &CastPlan,
    tol: ChordTolerance,
) -> Result<MoldOutput, DesignError> {
    build_mold_parts(design, stack, plan, tol).map_err(|e| {
        e.from_params(&[
            format!("layers[{}]", plan.layer),
            "mold".into(),
            "core".into(),
        ])
    })
}

fn build_mold_parts(
    design: &Design,
    stack: &Stack,
    plan: &CastPlan,
    tol: ChordTolerance,
) -> Result<MoldOutput, DesignError> {
    let layer = &stack.layers[plan.layer];
    let core = stack.core.as_ref().ok_or_else(|| {
        DesignError::Params(crate::error::ParamErrors(vec![ParamError::new(
            "core",
            "missing",
            "direct and master molds hold a core",
        )]))
    })?;
    let f = MoldFrame::new(design, core, plan.cavity_offset_mm);
    let m = &design.mold;
    let name = &layer.name;
    let fixture_tech: PrintTechnology = m.fixture_print_technology.into();
    let fixture_material = material_for(fixture_tech);

    // The cavity carries the layer's outer features, grown by the coats sprayed into it.
    let features = crate::parts::layers::cavity_features(
        design,
        stack,
        plan.layer,
        plan.cavity_offset_mm,
        tol,
    );
    let features: Vec<_> = features.iter().collect();
    let with_features =
        |s: Solid| crate::parts::layers::apply_features(s, &features, tol, false).part(name);
    let cavity = with_features(
        Solid::from_mesh(
            &revolve(
                &cavity_profile(design, &f, plan.cavity_offset_mm, false, tol),
                tol,
            )
            .part(name)?,
        )
        .part(name)?,
    )?;
    let holder = core_holder(design, &f, tol)?;
    // The pour fills the cavity, minus what is inside it (core and inner layers), minus the holder.
    // What the pour lands on: the layers under it down to the base plane, and below it the
    // core alone (its bore is closed by the holder's pin, so it counts as solid).
    let mut inner_pl = design
        .body
        .offset_polyline(plan.core_offset_mm, 0.0, tol.half());
    inner_pl.push([f.core_outer_radius_mm, f.base_z_mm]);
    inner_pl.push([f.core_outer_radius_mm, f.core_end_z_mm]);
    inner_pl.push([0.0, f.core_end_z_mm]);
    let inner = Solid::from_mesh(&revolve(&inner_pl, tol).part(name)?).part(name)?;
    let void = cavity
        .difference(&holder.union(&inner).part(name)?)
        .part(name)?;
    // a coat over features follows them (crate::parts::layers::taken_features)
    let sprayed_volume: f64 = plan
        .sprayed
        .iter()
        .map(|&i| {
            if features.is_empty() {
                stack.layer_solid(design, i, tol)
            } else {
                crate::parts::layers::layer_solid(design, stack, i, tol)
            }
            .map(|s| s.volume())
        })
        .sum::<Result<f64, _>>()
        .part(name)?;
    let pour_volume = void.volume() - sprayed_volume;

    let mut common = json!({
        "layer": name,
        "strategy": plan.strategy,
        "cavity_offset_mm": plan.cavity_offset_mm,
        "core_offset_mm": plan.core_offset_mm,
        "body": design.body,
        "frame": f,
        "plinth": m.plinth,
    });
    if !features.is_empty() {
        // the features the cavity carries, for the twins (export/python/twins/cq_molds.py)
        common["markers"] = json!(features
            .iter()
            .map(|p| crate::parts::layers::twin_marker_set(p, MarkerSurface::Outer))
            .collect::<Vec<_>>());
    }
    let direct = plan.strategy == MoldStrategy::Direct;
    let holder_name = if direct {
        format!("{name}_core_holder")
    } else {
        format!("{name}_casting_jig")
    };
    let (holder_placed, holder_pose) = place_posed(&holder, &crate::geometry::Affine::identity());
    let holder_part = Part {
        name: holder_name.clone(),
        role: if direct { "core_holder".into() } else { "casting_jig".into() },
        description: format!(
            "Closes the {name} mold, centres the core on its bore and carries the sprue and {} vents",
            m.vent.count
        ),
        material: fixture_material.into(),
        print_technology: fixture_tech,
        solid: holder_placed,
        params: with_pose(holder_params(design, &f), &holder_pose),
        group: None,
    };

    let c = CastMold {
        name,
        f,
        common,
        holder_name,
        holder_part,
        pour_volume,
    };
    let mut out = match plan.strategy {
        MoldStrategy::Open | MoldStrategy::TwoPieceOpen | MoldStrategy::Boundary => {
            unreachable!("built by crate::parts::layers")
        }
        MoldStrategy::Direct => direct_mold_parts(design, &cavity, tol, c),
        MoldStrategy::Master => master_mold_parts(design, plan, tol, c, &with_features),
    }?;
    let placed = crate::parts::layers::place_layer_markers(design, layer, tol);
    out.markers = crate::parts::layers::marker_summary(
        layer,
        &placed,
        crate::parts::layers::feature_technology(design, &design.layers[plan.layer]),
        design,
    );
    let carriers: Vec<String> = out
        .parts
        .iter()
        .filter(|p| matches!(p.role.as_str(), "mold_half" | "master_pattern"))
        .map(|p| p.name.clone())
        .collect();
    crate::parts::layers::set_forming(
        &mut out.markers,
        &carriers,
        &[],
        plan.cavity_offset_mm - layer.outer_offset_mm,
    );
    Ok(out)
}

/// What both strategies of [`build_mold_parts`] build from: the cast layer's `name`, the
/// mold frame `f`, the parameters `common` to the mold's parts, the core holder (or casting
/// jig) part and its name, and the volume the gel pour fills, mm^3.
struct CastMold<'a> {
    name: &'a str,
    f: MoldFrame,
    common: serde_json::Value,
    holder_name: String,
    holder_part: Part,
    pour_volume: f64,
}

/// The parts of a `direct` mold: the two mold halves split at the parting plane y = 0 around
/// `cavity` (male and female registration keys) and the core holder; the gel pours into all
/// three.
fn direct_mold_parts(
    design: &Design,
    cavity: &Solid,
    tol: ChordTolerance,
    c: CastMold,
) -> Result<MoldOutput, DesignError> {
    let (name, f) = (c.name, &c.f);
    let m = &design.mold;
    let cavity_tech: PrintTechnology = m.cavity_print_technology.into();
    let cavity_material = material_for(cavity_tech);
    let ((a, pose_a), (b, pose_b)) = direct_halves(design, f, cavity, tol).part(name)?;
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
    Ok(MoldOutput {
        parts,
        pour_volume_mm3: c.pour_volume,
        silicone_pour: None,
        pour_parts,
        markers: Vec::new(),
    })
}

/// The parts of a `master` mold: the master pattern (the cavity of the cast with its plinth
/// and locating pin) and the drafted box that holds it while the Mold Star 30 mold cures, then
/// the casting jig; the silicone pours into the master and box, the gel into the silicone
/// mold and the jig.
fn master_mold_parts(
    design: &Design,
    plan: &CastPlan,
    tol: ChordTolerance,
    c: CastMold,
    with_features: &dyn Fn(Solid) -> Result<Solid, DesignError>,
) -> Result<MoldOutput, DesignError> {
    let (name, f) = (c.name, &c.f);
    let m = &design.mold;
    let cavity_tech: PrintTechnology = m.cavity_print_technology.into();
    let fixture_tech: PrintTechnology = m.fixture_print_technology.into();
    let cavity_material = material_for(cavity_tech);
    let fixture_material = material_for(fixture_tech);
    let master = with_features(
        Solid::from_mesh(
            &revolve(
                &cavity_profile(design, f, plan.cavity_offset_mm, true, tol),
                tol,
            )
            .part(name)?,
        )
        .part(name)?,
    )?;
    let (mold_box, fill) = master_box(design, f, tol).part(name)?;
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
    Ok(MoldOutput {
        parts,
        pour_volume_mm3: c.pour_volume,
        silicone_pour: Some((silicone, vec![master_name, box_name])),
        pour_parts: vec![format!("silicone_mold:{name}"), c.holder_name],
        markers: Vec::new(),
    })
}

pub(crate) fn material_for(t: PrintTechnology) -> &'static str {
    match t {
        PrintTechnology::Fdm => "pla",
        PrintTechnology::Sla => "sla_standard_resin",
        PrintTechnology::Polyjet => "tango_black_plus",
    }
}

/// A solid in print orientation with its `T_print_sensor`.
type Posed = (Solid, Affine);

/// The two halves of a direct mold, each in print orientation (parting face up).
fn direct_halves(
    design: &Design,
    f: &MoldFrame,
    cavity: &Solid,
    tol: ChordTolerance,
) -> Result<(Posed, Posed), crate::geometry::GeometryError> {
    let m = &design.mold;
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
    let a = pos
        .union(&Solid::compose(&key_at(r_key)?))?
        .difference(&bolts)?;
    let bh = neg
        .difference(&Solid::compose(&key_at(
            r_key + m.registration_key.clearance_mm,
        )?))?
        .difference(&bolts)?;
    Ok((
        place_posed(&a, &crate::geometry::rotation_deg(-90.0, 0.0, 0.0)),
        place_posed(&bh, &crate::geometry::rotation_deg(90.0, 0.0, 0.0)),
    ))
}

/// The mold box (sensor frame) and the solid the Mold Star fills up to its fill level.
fn master_box(
    design: &Design,
    f: &MoldFrame,
    tol: ChordTolerance,
) -> Result<(Solid, Solid), crate::geometry::GeometryError> {
    drafted_box(
        design,
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
    design: &Design,
    plinth_radius_mm: f64,
    z0: f64,
    pole_z: f64,
    tol: ChordTolerance,
) -> Result<(Solid, Solid), crate::geometry::GeometryError> {
    let m = &design.mold;
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
    pub fn new(design: &Design) -> Self {
        let m = &design.mold;
        let t = &m.two_piece;
        let zb = design.body.base_z_mm();
        let layout = BoltLayout::new(design);
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
    fn new(design: &Design) -> Self {
        let m = &design.mold;
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
pub fn check_two_piece(design: &Design, rim_radius_mm: f64, errs: &mut Vec<ParamError>) {
    let m = &design.mold;
    let t = &m.two_piece;
    let cav = design.printers.get(m.cavity_print_technology);
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
    let [px, py] = BoltLayout::new(design).pitch_mm();
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
