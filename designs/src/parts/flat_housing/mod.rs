//! The housing of a flat sensor (`flat_housing` in a design): a printed shell whose top face
//! carries the skin, an acrylic window in the shell's light chamber under the skin, an isolation
//! ring in the camera aperture, and a printed base that carries the camera and closes the shell
//! with screws into heat-set inserts. 9DTact's published parts are its reference (Lin et al.,
//! RA-L 2024; `9DTact_Design/fabrication/sensor_shell.STEP`, `sensor_base.STEP`,
//! `isolation_ring.STEP`): every dimension below is a parameter, and `designs/library` gives
//! 9DTact's with the file each was measured in.
//!
//! Frame: the sensor frame of a flat skin (docs/conventions.md): the skin's base plane is z = 0
//! and the skin stands on it; the shell's top face lies in that plane and the shell goes down
//! to `z = -shell.height_mm`, the base under it. Across x is the outline's width, along y its
//! length; the cable leaves through the +y wall.
//!
//! From the top face down the shell holds: the light chamber (the outline less the wall,
//! `chamber_depth_mm` deep, open at the top), which the window fills; the plate
//! (`plate_mm`) with the square camera aperture and, on its top face, the square collar the
//! window rests on; below the plate the camera pocket, open at the bottom, with a boss round
//! each screw (a heat-set insert's hole in it) and the cable slot through the +y wall. The
//! isolation ring fills the aperture from the plate's underside up to the collar's top, so that
//! light reaches the camera only through the window (9DTact's "isolation ring for more uniform
//! tactile images"). The base is a plate with the screws' counterbored holes, the camera's
//! bosses and posts standing up into the pocket, and the camera's pocket and cable channel in
//! its top face, the channel's floor ramping up to the +y edge.
//!
//! The pocket's ceiling fillet is a sweep along each wall and about each boss and corner, their
//! union: where a boss meets a wall the two sweeps meet in a crease where a CAD kernel's
//! rolling-ball fillet blends them.

mod checks;
mod solids;

pub use solids::{base_solid, ring_solid, rounded_convex, shell_solid};

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{extrude, ChordTolerance};
use crate::materials::MaterialKind;
use crate::parts::channels::FlatLayer;
use crate::parts::cut_part::{CutPart, Operation, Outline};
use crate::parts::flat_family::{FlatBuilt, FlatFamily, FlatFamilyInput};
use crate::parts::member::{Member, MemberKind};
use crate::parts::part::{Part, PrintTechnology};
use crate::parts::placement::{place_posed, with_pose};
use crate::profile::FlatOutline;
use crate::schema::printers::Technology;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The housing of a flat sensor (`flat_housing` in a design).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlatHousingParams {
    /// The screws that close the base onto the shell: their places (sensor frame, mm; 9DTact's
    /// M2 pattern at (+-13.5, +-10)) and holes.
    pub screws: Screws,
    pub shell: FlatShell,
    pub base: FlatBase,
    /// The ring in the camera aperture; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub isolation_ring: Option<IsolationRing>,
    pub window: FlatWindow,
}

/// The screws' places and holes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Screws {
    /// Each screw's (x, y), mm; 1 to 16 of them, each with its boss inside the shell's outline.
    pub xy_mm: Vec<[f64; 2]>,
    /// The clearance hole through the base, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
    /// The counterbore for the head in the base's bottom face, mm, > 0, above the clearance.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub counterbore_diameter_mm: f64,
    /// Its depth, mm, > 0, below the base's thickness.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub counterbore_depth_mm: f64,
    /// The heat-set insert's hole in the shell's boss, from the shell's bottom face up, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub insert_diameter_mm: f64,
    /// Its depth, mm, > 0, at most the camera pocket's depth.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub insert_depth_mm: f64,
}

/// The printed shell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlatShell {
    /// Material key, a print material (9DTact's shell is white: it spreads the LEDs' light).
    pub material: String,
    /// How it is printed.
    pub print_technology: Technology,
    /// The outer outline (width across x, length along y, corner radius), mm: at least the
    /// skin's outermost layer.
    pub outline: FlatOutline,
    /// From the top face (the skin's base plane) to the bottom face, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// The side walls round the chamber and the camera pocket, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_mm: f64,
    /// The light chamber's depth from the top face down to the plate, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub chamber_depth_mm: f64,
    /// The chamber's (and the camera pocket's) corner radius, mm, >= 0.
    pub chamber_corner_radius_mm: f64,
    /// The plate between the chamber and the camera pocket, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub plate_mm: f64,
    /// The side of the square camera aperture through the plate, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub aperture_mm: f64,
    pub collar: Collar,
    /// The radius of the boss round each screw in the camera pocket, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub boss_radius_mm: f64,
    /// The fillet along the camera pocket's ceiling (the plate's underside) where it meets the
    /// walls and the bosses, mm, >= 0 (0: none), below the pocket's depth and at most the
    /// chamber's corner radius when that is above 0.
    #[serde(default)]
    pub ceiling_fillet_mm: f64,
    /// The cable's slot through the +y wall; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cable_slot: Option<CableSlot>,
}

/// The square collar on the plate's top face round the aperture, on which the window rests.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Collar {
    /// Its inner side, mm, > 0: above the aperture's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_mm: f64,
    /// Its width, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Its height above the plate, mm, > 0, below the chamber's depth.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
}

/// The cable's slot through the shell's +y wall: a rectangle whose top corners are chamfered
/// at 45 degrees, every corner rounded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CableSlot {
    /// Across x, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Along z, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Its lower edge above the shell's bottom face, mm, >= 0.
    pub above_bottom_mm: f64,
    /// The 45-degree chamfers of its top corners, mm, >= 0.
    pub chamfer_mm: f64,
    /// The radius of every corner, mm, >= 0.
    pub corner_radius_mm: f64,
}

/// The printed base.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlatBase {
    /// Material key, a print material.
    pub material: String,
    /// How it is printed.
    pub print_technology: Technology,
    /// The plate's thickness, mm, > 0 (its outline is the shell's).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// The bosses that carry the camera board; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera_bosses: Option<CameraBosses>,
    /// Posts with a pin on top (they locate the LED board); none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub posts: Option<Posts>,
    /// The pocket in the top face under the camera, and its cable channel; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera_pocket: Option<CameraPocket>,
}

/// Bosses on the base's top face, each with a screw hole.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraBosses {
    /// Each boss's (x, y), mm.
    pub xy_mm: Vec<[f64; 2]>,
    /// Diameter, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Height above the base's top face, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// The hole down from the boss's top, mm, > 0, below the boss's diameter.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub hole_diameter_mm: f64,
    /// Where that hole stops, above the base's bottom face, mm, > 0, below its thickness.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub hole_floor_mm: f64,
    /// The smaller hole on through the bottom face, mm, > 0, at most the hole's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub through_diameter_mm: f64,
}

/// Posts on the base's top face, each with a pin whose top edge is rounded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Posts {
    /// Each post's (x, y), mm.
    pub xy_mm: Vec<[f64; 2]>,
    /// Diameter, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Height above the base's top face, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// The pin's diameter, mm, > 0, below the post's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_diameter_mm: f64,
    /// The pin's height above the post, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_height_mm: f64,
    /// The radius of the pin's top edge, mm, >= 0, below its radius and its height.
    pub pin_fillet_mm: f64,
}

/// The pocket in the base's top face under the camera board, with its cable channel to the +y
/// edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraPocket {
    /// Across x, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// From y to y, mm (increasing, the far end inside the outline).
    pub y_mm: [f64; 2],
    /// Depth from the top face, mm, > 0, below the base's thickness.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub depth_mm: f64,
    /// The channel from the pocket's +y end to the +y edge; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<CableChannel>,
}

/// The cable channel: as deep as the pocket from its +y end, its floor ramping up (a concave
/// arc, a straight, a convex arc) to `exit_depth_mm` before the +y edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CableChannel {
    /// Across x, mm, > 0, at most the pocket's width.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// The radius of the base's corners between the pocket's far end and the channel's sides,
    /// mm, >= 0, at most half the difference of their widths.
    pub corner_radius_mm: f64,
    /// Depth at the +y edge, mm, > 0, below the pocket's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub exit_depth_mm: f64,
    /// Where the ramp's lower arc starts and its upper arc ends, y, mm: after the pocket's far
    /// end, before the +y edge.
    pub ramp_y_mm: [f64; 2],
    /// The radii of the lower (concave) and upper (convex) arcs, mm, > 0.
    pub ramp_radii_mm: [f64; 2],
}

/// The ring that fills the camera aperture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IsolationRing {
    /// Material key, a print material (black: it stops light).
    pub material: String,
    /// How it is printed.
    pub print_technology: Technology,
    /// Its square outer side, mm, > 0, at most the aperture's (its height is the plate's and
    /// the collar's: it fills the aperture up to the collar's top).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_mm: f64,
    /// Its round bore, mm, > 0, below the outer side.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bore_diameter_mm: f64,
    /// The 45-degree countersink of the bore at its top (towards the skin), mm, >= 0: the bore
    /// plus twice this at most the outer side.
    pub countersink_mm: f64,
}

/// The acrylic window in the light chamber, under the skin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlatWindow {
    /// Material key, a bought material (`pmma`).
    pub material: String,
    /// Its gap to the chamber's walls each side, mm, >= 0. Its outline is the chamber's less
    /// this; its thickness takes it from the collar's top to the top face, where the skin lies
    /// on it.
    pub clearance_mm: f64,
}

/// Most screws, posts or bosses of one kind.
const MAX_HOLES: usize = 16;

impl FlatHousingParams {
    /// The chamber's (and camera pocket's) outline.
    pub fn chamber(&self) -> FlatOutline {
        let s = &self.shell;
        FlatOutline {
            width_mm: s.outline.width_mm - 2.0 * s.wall_mm,
            length_mm: s.outline.length_mm - 2.0 * s.wall_mm,
            corner_radius_mm: s.chamber_corner_radius_mm,
        }
    }

    /// The window's outline.
    pub fn window_outline(&self) -> FlatOutline {
        let c = self.chamber();
        let k = self.window.clearance_mm;
        FlatOutline {
            width_mm: c.width_mm - 2.0 * k,
            length_mm: c.length_mm - 2.0 * k,
            corner_radius_mm: (c.corner_radius_mm - k).max(0.0),
        }
    }

    /// The window's thickness: from the collar's top to the top face, mm.
    pub fn window_thickness_mm(&self) -> f64 {
        self.shell.chamber_depth_mm - self.shell.collar.height_mm
    }

    /// The camera pocket's depth: from the plate's underside to the bottom face, mm.
    pub fn pocket_depth_mm(&self) -> f64 {
        let s = &self.shell;
        s.height_mm - s.chamber_depth_mm - s.plate_mm
    }
}

/// The flat housing family.
pub struct FlatHousingFamily;

impl FlatFamily for FlatHousingFamily {
    type Params = FlatHousingParams;
    const PATH: &'static str = "flat_housing";

    fn materials(p: &FlatHousingParams) -> Vec<(String, &str, &'static [MaterialKind])> {
        let mut m = vec![
            (
                "flat_housing.shell.material".into(),
                p.shell.material.as_str(),
                &[MaterialKind::Print][..],
            ),
            (
                "flat_housing.base.material".into(),
                p.base.material.as_str(),
                &[MaterialKind::Print][..],
            ),
            (
                "flat_housing.window.material".into(),
                p.window.material.as_str(),
                &[MaterialKind::Bought][..],
            ),
        ];
        if let Some(r) = &p.isolation_ring {
            m.push((
                "flat_housing.isolation_ring.material".into(),
                r.material.as_str(),
                &[MaterialKind::Print][..],
            ));
        }
        m
    }

    fn check(p: &FlatHousingParams, layers: Option<&[FlatLayer]>, errs: &mut Vec<ParamError>) {
        let before = errs.len();
        checks::check_sizes(p, errs);
        if errs.len() > before {
            return;
        }
        if let Some(layers) = layers {
            checks::check_skin(p, layers, errs);
        }
    }

    fn estimated_triangles(p: &FlatHousingParams, tol: ChordTolerance) -> f64 {
        let seg = |r: f64| tol.circle_segments(r.max(1e-3)) as f64;
        let s = &p.shell;
        let screws = p.screws.xy_mm.len() as f64;
        let mut circles = 4.0 * seg(s.outline.corner_radius_mm)
            + 2.0 * seg(s.chamber_corner_radius_mm)
            + screws
                * (seg(s.boss_radius_mm)
                    + seg(p.screws.insert_diameter_mm / 2.0)
                    + seg(p.screws.counterbore_diameter_mm / 2.0)
                    + seg(p.screws.clearance_diameter_mm / 2.0));
        if let Some(b) = &p.base.camera_bosses {
            circles += b.xy_mm.len() as f64
                * (seg(b.diameter_mm / 2.0)
                    + seg(b.hole_diameter_mm / 2.0)
                    + seg(b.through_diameter_mm / 2.0));
        }
        if let Some(q) = &p.base.posts {
            circles += q.xy_mm.len() as f64 * seg(q.diameter_mm / 2.0) * 8.0;
        }
        if let Some(r) = &p.isolation_ring {
            circles += 4.0 * seg(r.bore_diameter_mm / 2.0);
        }
        if s.ceiling_fillet_mm > 0.0 {
            // the fillet's section (a quarter circle) revolved about each boss
            let section = seg(s.ceiling_fillet_mm) / 4.0 + 4.0;
            circles += screws * seg(s.boss_radius_mm + s.ceiling_fillet_mm) * section / 4.0;
        }
        // about 8 triangles per segment of each circle (caps, sides, the booleans' splits),
        // twice: the printed parts and their members of the assembly
        2.0 * (8.0 * circles + 2_000.0)
    }

    fn build(p: &FlatHousingParams, input: FlatFamilyInput<'_>) -> Result<FlatBuilt, DesignError> {
        let tol = input.tol;
        let mut out = FlatBuilt::default();
        let shell = shell_solid(p, tol).part("flat_shell")?;
        let base = base_solid(p, tol).part("flat_base")?;
        let mut printed = vec![
            (
                "flat_shell",
                "Shell",
                &p.shell.material,
                p.shell.print_technology,
                shell,
            ),
            (
                "flat_base",
                "Base",
                &p.base.material,
                p.base.print_technology,
                base,
            ),
        ];
        if let Some(r) = &p.isolation_ring {
            let ring = ring_solid(p, r, tol).part("isolation_ring")?;
            printed.push((
                "isolation_ring",
                "Isolation ring",
                &r.material,
                r.print_technology,
                ring,
            ));
        }
        for (name, what, material, tech, solid) in printed {
            let (placed, pose) = place_posed(&solid, &crate::geometry::Affine::identity());
            out.parts.push(Part {
                name: name.into(),
                role: name.into(),
                description: description(p, name, what),
                material: material.clone(),
                print_technology: PrintTechnology::from(tech),
                solid: placed,
                params: with_pose(json!({"flat_housing": p, "part": name}), &pose),
                group: None,
            });
            out.members.push(Member {
                name: name.into(),
                kind: MemberKind::Printed,
                description: format!("{what} (printed)"),
                solid,
                fix: vec![format!("flat_housing.{}", fix_path(name))],
                nested_by_stack: false,
                features: Default::default(),
                exact: None,
                material: Some(material.clone()),
            });
        }
        let w = p.window_outline();
        let t = p.window_thickness_mm();
        let window = extrude(&[w.polygon(tol)], -t, 0.0).part("window")?;
        out.members.push(Member {
            name: "window".into(),
            kind: MemberKind::Bought,
            description: "Acrylic window (cut)".into(),
            solid: window,
            fix: vec![
                "flat_housing.window.clearance_mm".into(),
                "flat_housing.shell.collar".into(),
            ],
            nested_by_stack: false,
            features: Default::default(),
            exact: None,
            // "clear acrylic" (the cut list)
            material: Some("pmma".into()),
        });
        out.cut_parts.push(CutPart {
            name: "window".into(),
            description: format!(
                "Window: clear acrylic, {:.2} x {:.2} mm, R{:.2} corners, {:.2} mm thick (cut from thicker sheet or block and faced to thickness); it sits in the shell's chamber on the collar, its top face level with the shell's top face",
                w.width_mm, w.length_mm, w.corner_radius_mm, t
            ),
            material: p.window.material.clone(),
            thickness_mm: t,
            outlines: vec![(
                Operation::Cut,
                Outline::Polygon {
                    points_mm: w.polygon(tol),
                },
            )],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        });
        Ok(out)
    }

    fn bought_items(p: &FlatHousingParams) -> Vec<String> {
        let n = p.screws.xy_mm.len();
        vec![
            format!(
                "{n} machine screws for {:.2} mm clearance holes (M{:.0}), long enough to pass the base ({:.2} mm) into the shell's inserts, and {n} heat-set inserts for {:.2} mm holes, {:.2} mm deep",
                p.screws.clearance_diameter_mm,
                p.screws.clearance_diameter_mm.floor(),
                p.base.thickness_mm,
                p.screws.insert_diameter_mm,
                p.screws.insert_depth_mm
            ),
            "A camera board and its lens, and the LEDs, for the base's bosses and posts".into(),
        ]
    }

    fn assembly_steps(p: &FlatHousingParams, _parts: &[Part]) -> Vec<String> {
        let mut s = vec![format!(
            "Press the {} heat-set inserts into the bosses of flat_shell from its bottom face with a soldering iron.",
            p.screws.xy_mm.len()
        )];
        if p.isolation_ring.is_some() {
            s.push("Push isolation_ring into the shell's camera aperture from below, its countersunk end up, until its top is level with the collar's.".into());
        }
        s.push(format!(
            "Lay the window ({:.2} mm acrylic) into the shell's chamber onto the collar: its top face is level with the shell's top face.",
            p.window_thickness_mm()
        ));
        s.push("Lay the skin on the shell's top face over the window, centred, and bond its rim to the shell with a thin bead of silicone adhesive.".into());
        s.push(format!(
            "Mount the camera board and the LEDs on flat_base, lead the cable out through the channel and the shell's slot, and screw the base to the shell's bottom face with the {} screws.",
            p.screws.xy_mm.len()
        ));
        s
    }
}

/// The parameter path under `flat_housing.` that sizes the printed part `name`.
fn fix_path(name: &str) -> &'static str {
    match name {
        "flat_shell" => "shell",
        "flat_base" => "base",
        _ => "isolation_ring",
    }
}

/// A printed part's one-line description.
fn description(p: &FlatHousingParams, name: &str, what: &str) -> String {
    let o = &p.shell.outline;
    match name {
        "flat_shell" => format!(
            "{what}: {:.2} x {:.2} x {:.2} mm, R{:.2}; the skin lies on its top face, the window in its {:.2} mm chamber, the camera below its {:.2} mm aperture",
            o.width_mm, o.length_mm, p.shell.height_mm, o.corner_radius_mm, p.shell.chamber_depth_mm, p.shell.aperture_mm
        ),
        "flat_base" => format!(
            "{what}: {:.2} x {:.2} x {:.2} mm plate under the shell; carries the camera, screwed to the shell",
            o.width_mm, o.length_mm, p.base.thickness_mm
        ),
        _ => format!(
            "{what}: fills the shell's camera aperture; light reaches the camera only through the window"
        ),
    }
}
