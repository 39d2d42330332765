//! The shaft body's parameters (`shaft_body` in a design): the body, the tip's fitting, the
//! bayonet's lugs, the lens window, the LED ring, the camera and the base; and the fixed sizes
//! the parts share (the cable slot, the boolean overlap, the LED wires' room).

use crate::parts::bayonet::BayonetLugs;
use crate::schema::shared::FillingGel;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The shaft body and the tip's fitting (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftBodyParams {
    /// Material key of the body (printed FDM), e.g. `abs`.
    pub material: String,
    /// Outer diameter of the shaft, mm (Sec. III-A: about 23 mm).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub shaft_diameter_mm: f64,
    /// From the shaft's top face (under the lens window) down to the base, mm (Sec. III-A:
    /// about 38 mm, chosen for the lens's focal length and view angle).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub shaft_length_mm: f64,
    /// Wall of the shaft round its bore, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// Radial clearance round seated parts (window, LED ring, lens, camera board), mm, at
    /// least half the FDM nozzle.
    pub fit_clearance_mm: f64,
    pub tip_fitting: TipFitting,
    pub bayonet: BayonetLugs,
    pub lens_window: LensWindow,
    pub led_ring: LedRing,
    pub camera: ShaftCamera,
    pub base: ShaftBase,
    /// The clear gel between the skin and the lens window; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filling_gel: Option<FillingGel>,
    /// The mount that holds the body on a robot by a bayonet; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_mount: Option<crate::parts::robot_mount::RobotMount>,
}

/// The tip's rigid fitting, printed with the skin (Sec. III-A: "a rigid bayonet fitting (Vero
/// White). Both elements are printed as a single part").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TipFitting {
    /// Material key, a PolyJet material printed with the skin (`vero_white`).
    pub material: String,
    /// How far the skirt reaches down over the shaft, below the window, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub skirt_length_mm: f64,
    /// How far the lip reaches in over the window's rim, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lip_width_mm: f64,
    /// Thickness of the lip, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lip_thickness_mm: f64,
}

/// The acrylic lens window (Sec. III-A: "an inserted acrylic lens"), laser-cut.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LensWindow {
    /// Diameter of the acrylic disc, mm: it rests on the shaft's top face, so above the LED
    /// ring's seat (and the shaft's bore) and at most `shaft_diameter_mm`; its seat in the
    /// tip's fitting (this plus `fit_clearance_mm` on each side) must keep the PolyJet minimum
    /// wall inside the fitting.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Thickness of the disc along the axis (the acrylic sheet it is cut from), mm, > 0: from
    /// the shaft's top face up to the underside of the fitting's lip.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
}

/// The LED ring PCB (Sec. III-A: "a PCB ring of six LEDs"), seated in the shaft's top.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LedRing {
    /// Outer diameter of the ring PCB, mm, > 0; its seat in the shaft's top is this plus
    /// `fit_clearance_mm` on each side unless `seat_diameter_mm` is given.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the PCB's bore, mm: below the outer diameter and at most the seat's. The
    /// camera looks through it (the manifest's view fraction counts the rays it passes).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the PCB along the axis, mm, > 0: it sits on the seat's floor, the tops of
    /// its LEDs (`led_height_mm` over it) flush with the shaft's top face.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// LEDs on the ring, for the bought-items list and the assembly (Pestell et al. Sec.
    /// III-A: six); no part's shape depends on it.
    pub led_count: u32,
    /// Height of the LEDs over the PCB, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub led_height_mm: f64,
    /// Diameter of the seat in the shaft's top, mm; the PCB's plus the fit clearance on each
    /// side when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub seat_diameter_mm: Option<f64>,
}

/// The camera board in the base, its lens up the shaft (Sec. III-A2: an ADNS-3080 on a
/// breakout board with an adjustable lens, focal length 4.2 mm, view angle 86 deg).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftCamera {
    /// Module name, for the fabrication sheet.
    pub module: String,
    /// Side of the square board, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub board_width_mm: f64,
    /// Height of the pocket under the base's ceiling: the board and what hangs under it, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bay_height_mm: f64,
    /// Diameter of the lens holder, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_diameter_mm: f64,
    /// Height of the lens's front over the board's top face, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_height_mm: f64,
    /// Focal length of the lens, mm, > 0 (Pestell et al. Sec. III-A2: 4.2 mm); stated in the
    /// bought-items list and the manifest's camera view. No shape or rule uses it: the view
    /// is checked with `view_angle_deg`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub focal_length_mm: f64,
    /// Full view angle of the lens, degrees, in (0, 180).
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
    pub view_angle_deg: f64,
    /// Square pattern of the board's mounting holes, centre to centre, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_hole_spacing_mm: f64,
    /// Pilot for the self-tapping mounting screws, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_pilot_diameter_mm: f64,
    /// Depth of the pilots up into the ceiling, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_pilot_depth_mm: f64,
}

/// The base under the shaft that holds the camera board.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftBase {
    /// Outer diameter of the base, mm: at least `shaft_diameter_mm`, and the board's square
    /// pocket must keep the FDM minimum wall inside it at its corners. With a `robot_mount`,
    /// the mount's cup takes it and its lugs stand out of it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Thickness of the ceiling over the board's pocket, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub ceiling_thickness_mm: f64,
}

/// The camera's cable slot through the base's wall at its bottom, on +y: width x height, mm.
/// ASSUMPTION: the breakout's cable or pin header wires fit 10 x 4 mm (measure yours).
pub const CABLE_SLOT_MM: [f64; 2] = [10.0, 4.0];

/// How far a solid reaches into the one it is united with or cut from, so that no two faces
/// of a boolean coincide, mm.
pub const OVERLAP_MM: f64 = 0.01;

/// Room beside the lens in the ceiling's hole for the LED ring's wires, which run down the
/// shaft's bore into the camera's pocket and out through the cable slot, mm (ASSUMPTION: two
/// 26 AWG wires).
pub const LED_WIRE_ROOM_MM: f64 = 1.0;
