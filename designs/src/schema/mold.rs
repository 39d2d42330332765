//! The mold parameters of a design (`mold`): the strategy, the cavity, the core holder, the
//! open block and the two-piece open mold's plates. The molds they make are
//! [`crate::parts::molds`].

use crate::error::ParamError;
use crate::parts::lasercut::LaserCutParams;
use crate::schema::{MoldStrategy, Technology};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
/// Mold parameters shared by every cast layer. Geometry: R-Tac0 Sec. III-B1 and Fig. 4.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MoldParams {
    pub strategy: MoldStrategy,
    /// Added to the layer's outer surface to form the cavity, mm, >= 0.
    pub cavity_clearance_mm: f64,
    /// Material between the cavity and the outside of a mold half, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// Width of the mold-half flange that carries bolts and keys, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub flange_width_mm: f64,
    /// Draft of the master-strategy mold box wall from the pull direction, degrees, [0, 10).
    #[schemars(extend("minimum" = 0, "exclusiveMaximum" = 10))]
    pub draft_angle_deg: f64,
    pub plinth: Plinth,
    pub registration_key: RegistrationKey,
    pub clamp_bolt: ClampBolt,
    pub sprue: Sprue,
    pub vent: Vent,
    pub core_holder: CoreHolderParams,
    /// Mold Star thickness around the master pattern (master strategy), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub silicone_wall_mm: f64,
    /// The top piece and the flange of the `two_piece_open` strategy.
    pub two_piece: TwoPieceOpenParams,
    /// Technology of parts whose surface forms the skin (mold halves, master patterns).
    pub cavity_print_technology: Technology,
    /// Technology of holders, jigs and boxes.
    pub fixture_print_technology: Technology,
    /// Flat skins: make each casting tray as a stack of laser-cut sheets (DXF and SVG per
    /// sheet) whose union is also written as the printable tray.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub laser_cut: Option<LaserCutParams>,
    /// The block of an `open` mold, square about the axis from the base plane up (the DIGIT
    /// Pinki gel mold's 25.4 x 25.4 x 17 mm); when not given, `wall_thickness_mm` beyond the
    /// cavity's rim and beyond its tallest outward feature.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub open_block: Option<OpenBlock>,
}

/// The outer size of an `open` mold's block (`mold.open_block`), mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OpenBlock {
    /// Width of the square block, mm, > 0: at least the cavity's diameter on the base plane
    /// plus the cavity printer's `min_wall_mm` each side.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Height of the block from the base plane (the open face), mm, > 0: at least the
    /// cavity's height with its outward features plus the cavity printer's `min_wall_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
}

impl OpenBlock {
    /// The rules of `mold.open_block`: given for an `open` mold only, sizes above 0, and a
    /// wall of at least `min_wall_mm` around a cavity of `rim_radius_mm` on the base plane
    /// that reaches `cavity_height_mm` over it.
    pub fn check(
        &self,
        open: bool,
        rim_radius_mm: f64,
        cavity_height_mm: f64,
        min_wall_mm: f64,
        errs: &mut Vec<ParamError>,
    ) {
        if !open {
            errs.push(ParamError::new(
                "mold.open_block",
                "given",
                "applies to the open mold strategy only (no layer is cast in an open mold)",
            ));
            return;
        }
        if crate::parts::check_above_zero("mold.open_block.", self, &[], errs) {
            return;
        }
        let least_width = 2.0 * (rim_radius_mm + min_wall_mm);
        if self.width_mm < least_width {
            errs.push(ParamError::new(
                "mold.open_block.width_mm",
                self.width_mm,
                format!("must be at least the cavity's diameter plus the cavity printer's min_wall_mm each side ({least_width:.3} mm)"),
            ));
        }
        let least_height = cavity_height_mm + min_wall_mm;
        if self.height_mm < least_height {
            errs.push(ParamError::new(
                "mold.open_block.height_mm",
                self.height_mm,
                format!("must be at least the cavity's height with its outward features plus the cavity printer's min_wall_mm ({least_height:.3} mm)"),
            ));
        }
    }
}

defaults!(MoldParams {
    strategy: MoldStrategy::Direct,
    cavity_clearance_mm: 0.0,
    wall_thickness_mm: 4.0,
    flange_width_mm: 8.0,
    draft_angle_deg: 2.0,
    plinth: Plinth::default(),
    registration_key: RegistrationKey::default(),
    clamp_bolt: ClampBolt::default(),
    sprue: Sprue::default(),
    vent: Vent::default(),
    core_holder: CoreHolderParams::default(),
    silicone_wall_mm: 5.0,
    two_piece: TwoPieceOpenParams::default(),
    cavity_print_technology: Technology::Sla,
    fixture_print_technology: Technology::Fdm,
    laser_cut: None,
    open_block: None,
});

/// The disc-shaped recess at the open end of the cavity: it centres the core holder (its
/// spigot plugs into it) and leaves a reservoir ring that feeds the cavity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Plinth {
    /// Radial margin beyond the cavity rim, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub margin_mm: f64,
    /// Depth of the recess, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Depth left free under the holder's spigot as a reservoir, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub reservoir_depth_mm: f64,
}
defaults!(Plinth {
    margin_mm: 5.0,
    height_mm: 3.0,
    reservoir_depth_mm: 1.5
});

/// Hemispherical registration keys on the parting plane: male on one half, female with
/// clearance on the other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RegistrationKey {
    /// Diameter of the keys' spheres, mm, > 0: one key each side of the cavity, in the middle
    /// of the flange and half-way up the mold, on the parting plane of a `direct` mold's two
    /// halves. At least the cavity printer's `min_feature_mm`; with twice `clearance_mm` and
    /// twice the cavity printer's `min_wall_mm` at most `mold.flange_width_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Radial clearance of the female socket, mm.
    pub clearance_mm: f64,
}
defaults!(RegistrationKey {
    diameter_mm: 3.0,
    clearance_mm: 0.15
});

/// Clamp bolts through both mold halves, perpendicular to the parting plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ClampBolt {
    /// Through-hole diameter, mm (3.4 for M3).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
}
defaults!(ClampBolt {
    clearance_diameter_mm: 3.4
});

/// The top piece of a `two_piece_open` mold and how it joins the cavity block. The cavity
/// block's face lies `boss.height_mm` beyond the cavity's rim plane; a pocket in it (the boss
/// plus `registration_key.clearance_mm` on every side) reaches down to the rim plane. The top
/// piece stands `reservoir_height_mm` beyond the rim plane, its boss sits in the pocket, and a
/// bore through it opens the whole cavity: the pour reservoir whose level forms the skin's
/// back. `bolt_count` clamp bolts (`clamp_bolt.clearance_diameter_mm` holes through both
/// pieces) stand on the centre line of the flange (`flange_width_mm` wide) around the pocket,
/// one at each corner and the rest spread evenly over the sides.
/// Defaults: the authors' ShadowTac mold (authors' CAD, measured).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct TwoPieceOpenParams {
    /// Diameter of the reservoir bore, mm (authors: 45).
    pub reservoir_diameter_mm: f64,
    /// Height of the top piece above the cavity's rim plane, mm (authors: 14).
    pub reservoir_height_mm: f64,
    /// Clamp bolts through the flange, even, >= 4 (authors: 20).
    pub bolt_count: u32,
    /// Bolt hole diameter in the cavity block, mm (authors: 3.5); default
    /// `mold.clamp_bolt.clearance_diameter_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cavity_block_bolt_hole_mm: Option<f64>,
    /// Bolt hole diameter in the top piece, mm (authors: 3.4); default
    /// `mold.clamp_bolt.clearance_diameter_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub top_piece_bolt_hole_mm: Option<f64>,
    pub boss: RegistrationBoss,
}
defaults!(TwoPieceOpenParams {
    reservoir_diameter_mm: 45.0,
    reservoir_height_mm: 14.0,
    bolt_count: 20,
    cavity_block_bolt_hole_mm: None,
    top_piece_bolt_hole_mm: None,
    boss: RegistrationBoss::default(),
});

impl TwoPieceOpenParams {
    /// (cavity block, top piece) bolt hole diameters, mm: the per-piece values, else
    /// `clearance_mm` (`mold.clamp_bolt.clearance_diameter_mm`).
    pub fn bolt_holes_mm(&self, clearance_mm: f64) -> (f64, f64) {
        (
            self.cavity_block_bolt_hole_mm.unwrap_or(clearance_mm),
            self.top_piece_bolt_hole_mm.unwrap_or(clearance_mm),
        )
    }
}

/// A rectangular boss on the top piece of a two-piece mold that registers it in a pocket of
/// the cavity block (authors' ShadowTac mold: 60 x 65 x 2 mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RegistrationBoss {
    /// Along x, mm.
    pub width_mm: f64,
    /// Along y, mm.
    pub length_mm: f64,
    /// Along the pull direction (the sensor axis), mm.
    pub height_mm: f64,
}
defaults!(RegistrationBoss {
    width_mm: 60.0,
    length_mm: 65.0,
    height_mm: 2.0
});

/// The pour opening through the core holder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Sprue {
    /// Diameter of the pour hole, mm, > 0: through the core holder parallel to the axis, at
    /// azimuth 0, centred between the core's groove and the spigot's edge. At least the
    /// fixture printer's `min_hole_diameter_mm`, and it must fit that room, which
    /// `mold.plinth.margin_mm` widens.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
}
defaults!(Sprue { diameter_mm: 3.0 });

/// Air vents through the core holder at the cavity's high points (cast pole-down).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Vent {
    /// Diameter of each vent hole, mm, > 0: through the core holder parallel to the axis, on a
    /// circle that leaves `core_holder.min_wall_mm` between the holes and the spigot's edge.
    /// At least the fixture printer's `min_hole_diameter_mm`, and it must fit in the holder
    /// beside the core, as the sprue.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Number of vents, at least 1, spread round the axis with the sprue at equal steps of
    /// 360 / (count + 1) degrees, the sprue at azimuth 0; at most as many as keep
    /// `core_holder.min_wall_mm` between neighbouring holes.
    #[schemars(extend("minimum" = 1))]
    pub count: u32,
}
defaults!(Vent {
    diameter_mm: 1.2,
    count: 2
});

/// The core holder (casting jig): keeps the core concentric with the cavity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CoreHolderParams {
    /// Radial clearance between the centring pin and the core's bore, and around the core
    /// wall, mm.
    pub fit_clearance_mm: f64,
    /// Thickness along the axis of the holder's flange, the disc that lies on the mold's open
    /// face (the outer face of the plinth recess) and reaches 3 mm beyond the plinth, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub flange_thickness_mm: f64,
    /// Length of the centring pin that enters the core's open end, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pin_length_mm: f64,
    /// Smallest wall left around holes in the holder, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_wall_mm: f64,
}
defaults!(CoreHolderParams {
    fit_clearance_mm: 0.1,
    flange_thickness_mm: 3.0,
    pin_length_mm: 6.0,
    min_wall_mm: 1.5,
});
