//! The base of a fingertip sensor whose skin is cast onto a rigid shell (UVDtact Sec. III-C,
//! Fig. 2: "the camera holder, shell holder, and sensor base are fabricated using an SLA 3D
//! printer ... the sensor base, camera, camera holder, lighting PCB, and diffusion ring are
//! arranged, and the components are secured to the sensor base using instant adhesive.
//! Likewise, the acrylic shell of the elastomer part is attached to the shell holder with
//! instant adhesive ... the sensor base and shell holder are fastened together with three M1.2
//! bolts"), `fingertip_base` in a design.
//!
//! From the top down, in the sensor frame (mm):
//!
//! - The skin's layers, down to the base plane `z = 0`, on the shell (the design's core), whose
//!   straight foot continues down to its end `z_e = -core.below_base`.
//! - The shell holder: a ring round the shell's foot from `z_e` up to the base plane, under the
//!   skin's base; the bolts' pilots go up into it from below.
//! - The sensor base under it, its top face at `z_e`: a pocket in its top holds the lighting
//!   PCB on the pocket's floor (white and UV LEDs alternating every 45 deg, facing up) and the
//!   diffusion ring at the pocket's top, flush with the base's top, under the shell's end; the
//!   ring has a hole over each UV LED (UV light does not pass the white ring). The camera
//!   holder, a tube standing on the pocket's floor through the PCB's and the ring's bores,
//!   holds the endoscopic camera with its front flush with the ring's top. Holes in the
//!   base's floor pass the camera's wire and the PCB's wires; the bolts come up through
//!   counterbored holes in the base.

use super::{axial_cylinder, axial_ring, Member, MemberKind};
use super::{Part, PrintTechnology};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{ChordTolerance, GeometryError, Solid};
use crate::materials::MaterialKind;
use crate::optics::elements::{Lens, Light, DEFAULT_LED_INTENSITY};
use crate::parts::context::Context;
use crate::parts::context::Stack;
use crate::parts::cut_part::{CutPart, Operation, Outline};
use crate::parts::family::{envelope, AssemblyInput, AssemblyStep, Built, Family, FamilyInput};
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::shaft_body::OVERLAP_MM;
use crate::parts::z_cylinder;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The fingertip's base (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FingertipBase {
    /// Material key of the shell holder, the sensor base and the camera holder (printed SLA).
    pub material: String,
    /// Outer diameter of the shell holder and the sensor base, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Radial clearance round seated parts (the shell in its holder, the PCB and the ring in
    /// the pocket, the camera in its holder), mm, at least the SLA printer's xy resolution.
    pub fit_clearance_mm: f64,
    /// Depth of the sensor base's pocket: the PCB with its LEDs and the diffusion ring, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pocket_depth_mm: f64,
    /// The sensor base's floor under the pocket, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub floor_thickness_mm: f64,
    pub led_pcb: LightingPcb,
    pub diffusion_ring: DiffusionRing,
    pub camera: MiniCamera,
    pub camera_holder: CameraHolder,
    pub bolts: HolderBolts,
}

/// The lighting PCB (bought): a ring with 4 white and 4 UV LEDs alternating every 45 deg, the
/// first white LED on +x (UVDtact Sec. III-C).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LightingPcb {
    /// Outer diameter of the PCB, mm, > 0: the sensor base's pocket is this plus
    /// `fit_clearance_mm` on each side and must keep the SLA minimum wall to the bolts'
    /// counterbores; the diffusion ring has the same outer diameter.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the PCB's bore, through which the camera holder stands, mm, > 0; below the
    /// outer diameter, the LEDs between the two.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the board along the axis, mm, > 0; it lies on the pocket's floor.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// The circle the LEDs' centres are on, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub led_circle_diameter_mm: f64,
    /// One LED: its length (radial) and height over the board, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub led_length_mm: f64,
    /// Height of the LEDs over the board's top face, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub led_height_mm: f64,
    /// Hole in the base's floor under the board for its wires, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wire_hole_diameter_mm: f64,
}

/// The white SLA diffusion ring over the LEDs, with a hole over each UV LED.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiffusionRing {
    /// Material key (printed SLA, white).
    pub material: String,
    /// Diameter of the ring's bore, through which the camera holder stands, mm, > 0; its
    /// outer diameter is the lighting PCB's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the ring along the axis, from the shell's end (flush with the sensor
    /// base's top) down, mm: at least the SLA minimum wall and below `pocket_depth_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// Diameter of the holes through the ring over the 4 UV LEDs (UV light does not pass the
    /// white ring), mm, > 0; centred on `led_pcb.led_circle_diameter_mm`, each keeps the SLA
    /// minimum wall to the ring's bore and to its edge.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub uv_hole_diameter_mm: f64,
}

/// The endoscopic camera (bought).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MiniCamera {
    /// The camera, for the sheet.
    pub module: String,
    /// Outer diameter of the camera, mm, > 0 (UVDtact Sec. III-C: 1.5 mm); its holder's bore
    /// is this plus `fit_clearance_mm` on each side.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Length of the camera along the axis, from its back up to its front, which is flush
    /// with the diffusion ring's top, mm, > 0; at most `pocket_depth_mm` (UVDtact Sec. III-C:
    /// 3 mm).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub length_mm: f64,
    /// Full field of view, degrees.
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
    pub view_angle_deg: f64,
    /// Hole in the base's floor for its wire, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wire_hole_diameter_mm: f64,
}

/// The camera holder: a tube round the camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraHolder {
    /// Outer diameter of the tube, which stands on the pocket's floor up to the shell's end,
    /// mm, > 0; it must leave the SLA minimum wall round the camera's bore.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
}

/// The bolts that fasten the sensor base to the shell holder: up through counterbored holes
/// in the base into pilots in the holder, on a circle between the shell and the outside.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HolderBolts {
    /// 2..=6, at equal angles, the first on +y.
    #[schemars(extend("minimum" = 2, "maximum" = 6))]
    pub count: u32,
    /// Diameter of the pilots in the shell holder that the bolts thread into, mm, > 0, below
    /// the clearance hole's (UVDtact Sec. III-C: M1.2 bolts). The bolt circle lies midway
    /// between the holder's bore and the outside; pilots and counterbores must keep the SLA
    /// minimum wall on both sides.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_diameter_mm: f64,
    /// Depth of the pilots up into the shell holder from its bottom (the shell's end), mm,
    /// above 0; the SLA minimum wall must remain above them in the core's foot below the base
    /// plane (`core.length_mm`).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_depth_mm: f64,
    /// Diameter of the bolts' holes through the sensor base, mm, > 0; between the pilot's and
    /// the head's diameters.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
    /// Diameter of the counterbores for the bolts' heads in the sensor base's bottom, mm,
    /// above the clearance hole's.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub head_diameter_mm: f64,
    /// Counterbore for the head, from the base's bottom, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub head_depth_mm: f64,
}

/// Levels of the fingertip's base, sensor frame, mm (top to bottom).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FingertipLevels {
    /// The shell's end: the holder's bottom, the base's and the ring's tops, the camera's front.
    pub shell_end_z_mm: f64,
    /// The ring's bottom.
    pub ring_bottom_z_mm: f64,
    /// The LEDs' tops.
    pub led_top_z_mm: f64,
    /// The PCB's top.
    pub pcb_top_z_mm: f64,
    /// The pocket's floor: the PCB's and the camera holder's bottoms.
    pub pocket_floor_z_mm: f64,
    /// The camera's back.
    pub camera_back_z_mm: f64,
    /// The sensor's bottom.
    pub bottom_z_mm: f64,
    /// From the bottom to the skin's pole, mm.
    pub envelope_height_mm: f64,
}

/// The base's levels; the shell's end from the stack's core (the base plane without one).
pub fn levels(ctx: &Context<'_>, f: &FingertipBase, stack: &Stack) -> FingertipLevels {
    let end = -stack.core.as_ref().map_or(0.0, |c| c.below_base_mm);
    let floor = end - f.pocket_depth_mm;
    let pcb_top = floor + f.led_pcb.thickness_mm;
    let bottom = floor - f.floor_thickness_mm;
    FingertipLevels {
        shell_end_z_mm: end,
        ring_bottom_z_mm: end - f.diffusion_ring.thickness_mm,
        led_top_z_mm: pcb_top + f.led_pcb.led_height_mm,
        pcb_top_z_mm: pcb_top,
        pocket_floor_z_mm: floor,
        camera_back_z_mm: end - f.camera.length_mm,
        bottom_z_mm: bottom,
        envelope_height_mm: ctx.body.pole_z_mm(0.0) - bottom,
    }
}

/// Radii, mm: the shell's outside at its foot, the holder's bore, the pocket, the bolt circle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FingertipRadii {
    pub shell_outer_mm: f64,
    pub holder_bore_mm: f64,
    pub pocket_mm: f64,
    pub bolt_circle_mm: f64,
    pub outside_mm: f64,
}

/// The base's radii (see [`FingertipRadii`]).
pub fn radii(ctx: &Context<'_>, f: &FingertipBase, stack: &Stack) -> FingertipRadii {
    let shell = stack
        .core
        .as_ref()
        .map_or(0.0, |c| ctx.body.rim_radius_mm(c.outer_offset_mm));
    let bore = shell + f.fit_clearance_mm;
    let outside = f.outer_diameter_mm / 2.0;
    FingertipRadii {
        shell_outer_mm: shell,
        holder_bore_mm: bore,
        pocket_mm: f.led_pcb.outer_diameter_mm / 2.0 + f.fit_clearance_mm,
        bolt_circle_mm: (bore + outside) / 2.0,
        outside_mm: outside,
    }
}

/// What an RGB camera sees of a 365 nm UV LED: a faint violet (the LED's visible tail), relative
/// RGB.
pub const UV_LED_RGB: [f64; 3] = [0.1, 0.0, 0.3];

/// The LEDs' azimuths, degrees, and whether each is a UV LED: white on +x, then alternating
/// every 45 deg (UVDtact Sec. III-C).
pub fn leds() -> Vec<(f64, bool)> {
    (0..8).map(|k| (45.0 * f64::from(k), k % 2 == 1)).collect()
}

fn bolt_xy(f: &FingertipBase, r: f64) -> Vec<[f64; 2]> {
    let n = f.bolts.count.max(1);
    (0..n)
        .map(|k| {
            let a = (90.0 + f64::from(k) * 360.0 / f64::from(n)).to_radians();
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

/// Where the PCB's wire hole is: under the board, between the first two LEDs, mm.
fn pcb_wire_xy(f: &FingertipBase) -> [f64; 2] {
    let r = (f.led_pcb.inner_diameter_mm + f.led_pcb.outer_diameter_mm) / 4.0;
    let a = 22.5f64.to_radians();
    [r * a.cos(), r * a.sin()]
}

/// Rules on the fingertip's base, paths under `fingertip_base`: walls print, parts are held.
/// Overlaps between the printed parts and the bought ones are the fit check's.
pub fn check_params(
    ctx: &Context<'_>,
    f: &FingertipBase,
    stack: &Stack,
    errs: &mut Vec<ParamError>,
) {
    let before = errs.len();
    check_numbers(ctx, f, errs);
    let Some(core) = &stack.core else {
        errs.push(ParamError::new(
            "fingertip_base",
            "given",
            "the shell holder holds the core's foot: give core: with length_mm reaching below the base plane, or remove fingertip_base:",
        ));
        return;
    };
    if errs.len() > before {
        return;
    }
    check_bolts(ctx, f, stack, core, errs);
    check_lighting_and_camera(ctx, f, stack, errs);
}

/// The base's numbers that must be above 0, `camera.view_angle_deg` in (0, 180), `bolts.count`
/// 2 to 6, and `fit_clearance_mm` at least the SLA printer's xy resolution; paths under
/// `fingertip_base`.
fn check_numbers(ctx: &Context<'_>, f: &FingertipBase, errs: &mut Vec<ParamError>) {
    let path = |p: &str| format!("fingertip_base.{p}");
    let (cam, b) = (&f.camera, &f.bolts);
    crate::parts::check_above_zero("fingertip_base.", f, &[], errs);
    if !(cam.view_angle_deg > 0.0 && cam.view_angle_deg < 180.0) {
        errs.push(ParamError::new(
            path("camera.view_angle_deg"),
            cam.view_angle_deg,
            "must be above 0 and below 180",
        ));
    }
    if !(2..=6).contains(&b.count) {
        errs.push(ParamError::new(
            path("bolts.count"),
            b.count,
            "must be 2 to 6",
        ));
    }
    let sla = &ctx.printers.sla;
    if !(f.fit_clearance_mm >= sla.xy_resolution_mm && f.fit_clearance_mm.is_finite()) {
        errs.push(ParamError::new(
            path("fit_clearance_mm"),
            f.fit_clearance_mm,
            format!(
                "must be at least the SLA printer's xy resolution (printers.sla.xy_resolution_mm = {:.2} mm): a tighter printed fit fuses or jams",
                sla.xy_resolution_mm
            ),
        ));
    }
}

/// The bolts and the base's floor, mm: the pilots under the shell holder's top (the core's
/// foot, `core.length_mm`), the bolts' circle between the holder's bore and the outside and
/// clear of the PCB's pocket, the bolts' clearance holes and counterbores, and the floor at
/// least the SLA minimum wall.
fn check_bolts(
    ctx: &Context<'_>,
    f: &FingertipBase,
    stack: &Stack,
    core: &crate::parts::context::ResolvedCore,
    errs: &mut Vec<ParamError>,
) {
    let path = |p: &str| format!("fingertip_base.{p}");
    let (pcb, b) = (&f.led_pcb, &f.bolts);
    let wall = ctx.printers.sla.min_wall_mm;
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let r = radii(ctx, f, stack);
    let below = core.below_base_mm;
    rule(
        below >= b.pilot_depth_mm + wall,
        "bolts.pilot_depth_mm",
        b.pilot_depth_mm,
        format!(
            "the shell holder is the core's foot below the base plane ({below:.2} mm, core.length_mm): the pilots must stay {wall:.2} mm under its top"
        ),
    );
    rule(
        r.bolt_circle_mm - b.pilot_diameter_mm.max(b.head_diameter_mm) / 2.0 >= r.holder_bore_mm + wall
            && r.bolt_circle_mm + b.pilot_diameter_mm.max(b.head_diameter_mm) / 2.0 + wall <= r.outside_mm,
        "outer_diameter_mm",
        f.outer_diameter_mm,
        format!(
            "the bolts (pilots {:.2} mm, heads {:.2} mm) on the {:.2} mm circle between the shell's holder ({:.2} mm) and the outside must keep a {wall:.2} mm wall each side",
            b.pilot_diameter_mm,
            b.head_diameter_mm,
            2.0 * r.bolt_circle_mm,
            2.0 * r.holder_bore_mm
        ),
    );
    rule(
        r.bolt_circle_mm - b.head_diameter_mm / 2.0 >= r.pocket_mm + wall,
        "led_pcb.outer_diameter_mm",
        pcb.outer_diameter_mm,
        format!(
            "the PCB's pocket ({:.2} mm) must keep a {wall:.2} mm wall to the bolts' counterbores ({:.2} mm on a {:.2} mm circle)",
            2.0 * r.pocket_mm,
            b.head_diameter_mm,
            2.0 * r.bolt_circle_mm
        ),
    );
    rule(
        b.head_diameter_mm > b.clearance_diameter_mm
            && b.clearance_diameter_mm > b.pilot_diameter_mm,
        "bolts.clearance_diameter_mm",
        b.clearance_diameter_mm,
        format!(
            "must lie between the pilot ({:.2} mm) and the head's counterbore ({:.2} mm)",
            b.pilot_diameter_mm, b.head_diameter_mm
        ),
    );
    rule(
        b.head_depth_mm + wall <= f.floor_thickness_mm + f.pocket_depth_mm,
        "bolts.head_depth_mm",
        b.head_depth_mm,
        format!(
            "must stay {wall:.2} mm under the base's top ({:.2} mm tall)",
            f.floor_thickness_mm + f.pocket_depth_mm
        ),
    );
    rule(
        f.floor_thickness_mm >= wall,
        "floor_thickness_mm",
        f.floor_thickness_mm,
        format!("must be at least the SLA minimum wall ({wall:.2} mm)"),
    );
}

/// The lighting PCB, the diffusion ring and the camera, mm: the LEDs on the board, the PCB's
/// wire hole between the camera holder and the pocket's side, the ring's holes over the UV
/// LEDs and its thickness, the camera holder's wall round the camera's bore, the camera's
/// length in the pocket and its wire hole under the holder's bore.
fn check_lighting_and_camera(
    ctx: &Context<'_>,
    f: &FingertipBase,
    stack: &Stack,
    errs: &mut Vec<ParamError>,
) {
    let path = |p: &str| format!("fingertip_base.{p}");
    let (pcb, ring, cam) = (&f.led_pcb, &f.diffusion_ring, &f.camera);
    let wall = ctx.printers.sla.min_wall_mm;
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let r = radii(ctx, f, stack);
    let (ri, ro) = (pcb.inner_diameter_mm / 2.0, pcb.outer_diameter_mm / 2.0);
    let rl = pcb.led_circle_diameter_mm / 2.0;
    rule(
        ri < ro && rl - pcb.led_length_mm / 2.0 >= ri && rl + pcb.led_length_mm / 2.0 <= ro,
        "led_pcb.led_circle_diameter_mm",
        pcb.led_circle_diameter_mm,
        format!(
            "the LEDs ({:.2} mm long) must sit on the board, between its bore ({:.2} mm) and its edge ({:.2} mm)",
            pcb.led_length_mm, pcb.inner_diameter_mm, pcb.outer_diameter_mm
        ),
    );
    let rh = f.camera_holder.outer_diameter_mm / 2.0;
    let [wx, wy] = pcb_wire_xy(f);
    let rw = wx.hypot(wy);
    rule(
        rw - pcb.wire_hole_diameter_mm / 2.0 >= rh + wall
            && rw + pcb.wire_hole_diameter_mm / 2.0 + wall <= r.pocket_mm,
        "led_pcb.wire_hole_diameter_mm",
        pcb.wire_hole_diameter_mm,
        format!(
            "the wire hole under the board ({rw:.2} mm from the axis) must keep a {wall:.2} mm wall to the camera holder ({:.2} mm) and to the pocket's side ({:.2} mm)",
            2.0 * rh,
            2.0 * r.pocket_mm
        ),
    );
    let ring_in = ring.inner_diameter_mm / 2.0;
    rule(
        ring_in + wall <= rl - ring.uv_hole_diameter_mm / 2.0
            && rl + ring.uv_hole_diameter_mm / 2.0 + wall <= ro,
        "diffusion_ring.uv_hole_diameter_mm",
        ring.uv_hole_diameter_mm,
        format!(
            "the holes over the UV LEDs ({:.2} mm circle) must keep a {wall:.2} mm wall to the ring's bore ({:.2} mm) and edge ({:.2} mm)",
            pcb.led_circle_diameter_mm, ring.inner_diameter_mm, pcb.outer_diameter_mm
        ),
    );
    rule(
        ring.thickness_mm >= wall && ring.thickness_mm < f.pocket_depth_mm,
        "diffusion_ring.thickness_mm",
        ring.thickness_mm,
        format!(
            "must be at least the SLA minimum wall ({wall:.2} mm) and fit the pocket ({:.2} mm deep)",
            f.pocket_depth_mm
        ),
    );
    rule(
        rh >= cam.diameter_mm / 2.0 + f.fit_clearance_mm + wall,
        "camera_holder.outer_diameter_mm",
        f.camera_holder.outer_diameter_mm,
        format!(
            "must leave a {wall:.2} mm wall round the camera's bore ({:.2} mm)",
            cam.diameter_mm + 2.0 * f.fit_clearance_mm
        ),
    );
    rule(
        cam.length_mm <= f.pocket_depth_mm,
        "camera.length_mm",
        cam.length_mm,
        format!(
            "the camera stands in its holder, from the pocket's floor up to the ring's top ({:.2} mm)",
            f.pocket_depth_mm
        ),
    );
    rule(
        cam.wire_hole_diameter_mm <= cam.diameter_mm + 2.0 * f.fit_clearance_mm,
        "camera.wire_hole_diameter_mm",
        cam.wire_hole_diameter_mm,
        format!(
            "must lie under the camera holder's bore ({:.2} mm)",
            cam.diameter_mm + 2.0 * f.fit_clearance_mm
        ),
    );
}

/// The parts' parameters for their twins.
pub fn twin_params(ctx: &Context<'_>, f: &FingertipBase, stack: &Stack) -> serde_json::Value {
    let r = radii(ctx, f, stack);
    json!({
        "fingertip_base": f,
        "levels": levels(ctx, f, stack),
        "radii": r,
        "leds": leds(),
        "bolt_xy_mm": bolt_xy(f, r.bolt_circle_mm),
        "pcb_wire_xy_mm": pcb_wire_xy(f),
        "overlap_mm": OVERLAP_MM,
    })
}

/// A ring about the z axis, radii `ri` < `ro`, from `z0` to `z1`.
fn z_ring(ri: f64, ro: f64, z0: f64, z1: f64, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    z_cylinder(ro, z0, z1, [0.0; 2], tol)?.difference(&z_cylinder(
        ri,
        z0 - 1.0,
        z1 + 1.0,
        [0.0; 2],
        tol,
    )?)
}

/// The four printed parts: shell holder, sensor base, camera holder, diffusion ring, each
/// printed standing as it sits in the sensor.
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_parts(f: &FingertipBase, input: FamilyInput<'_>) -> Result<Vec<Part>, DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let lv = levels(ctx, f, stack);
    let r = radii(ctx, f, stack);
    let b = &f.bolts;
    let bolts = bolt_xy(f, r.bolt_circle_mm);
    let part = |name: &str, material: &str, solid: Solid, description: String| {
        let (placed, pose) = place_posed(&solid, &crate::geometry::Affine::identity());
        Part {
            name: name.into(),
            role: name.into(),
            description,
            material: material.into(),
            print_technology: PrintTechnology::Sla,
            solid: placed,
            params: with_pose(twin_params(ctx, f, stack), &pose),
            group: None,
        }
    };
    // the shell holder
    let holder = build_shell_holder(f, &lv, &r, &bolts, tol)?;
    // the sensor base
    let base = build_sensor_base(f, &lv, &r, &bolts, tol)?;
    // the camera holder
    let camera_holder = z_ring(
        f.camera.diameter_mm / 2.0 + f.fit_clearance_mm,
        f.camera_holder.outer_diameter_mm / 2.0,
        lv.pocket_floor_z_mm,
        lv.shell_end_z_mm,
        tol,
    )
    .part("camera_holder")?;
    // the diffusion ring
    let ring = build_diffusion_ring(f, &lv, tol)?;
    Ok(vec![
        part(
            "shell_holder",
            &f.material,
            holder,
            format!(
                "Shell holder: ring round the acrylic shell's foot, {:.1} mm outside, glued to the shell with instant adhesive, {} bolt pilots (UVDtact Sec. III-C, Fig. 2)",
                f.outer_diameter_mm, b.count
            ),
        ),
        part(
            "sensor_base",
            &f.material,
            base,
            format!(
                "Sensor base: {:.1} mm, the pocket for the lighting PCB and the diffusion ring, the wires' holes and {} counterbored bolt holes (UVDtact Sec. III-C, Fig. 2)",
                f.outer_diameter_mm, b.count
            ),
        ),
        part(
            "camera_holder",
            &f.material,
            camera_holder,
            format!(
                "Camera holder: tube round the {:.1} mm endoscopic camera, glued to the base's floor (UVDtact Sec. III-C)",
                f.camera.diameter_mm
            ),
        ),
        part(
            "diffusion_ring",
            &f.diffusion_ring.material,
            ring,
            "Diffusion ring: white SLA ring over the LEDs, a hole over each UV LED (UVDtact Sec. III-C)".into(),
        ),
    ])
}

/// The shell holder: a ring from the holder's bore round the shell's foot to the outside, from
/// the shell's end up to the base plane, with the bolts' pilots up into it.
fn build_shell_holder(
    f: &FingertipBase,
    lv: &FingertipLevels,
    r: &FingertipRadii,
    bolts: &[[f64; 2]],
    tol: ChordTolerance,
) -> Result<Solid, DesignError> {
    let b = &f.bolts;
    let g = |x: Result<Solid, GeometryError>| x.part("shell_holder");
    let mut cuts = Vec::new();
    for &xy in bolts {
        cuts.push(g(z_cylinder(
            b.pilot_diameter_mm / 2.0,
            lv.shell_end_z_mm - 1.0,
            lv.shell_end_z_mm + b.pilot_depth_mm,
            xy,
            tol,
        ))?);
    }
    g(g(z_ring(
        r.holder_bore_mm,
        r.outside_mm,
        lv.shell_end_z_mm,
        0.0,
        tol,
    ))?
    .difference(&g(Solid::union_all(&cuts))?))
}

/// The sensor base: a disc from the bottom up to the shell's end, with the pocket for the
/// lighting PCB and the diffusion ring, the camera's and the PCB's wire holes through the
/// floor, and the bolts' clearance holes, counterbored from below.
fn build_sensor_base(
    f: &FingertipBase,
    lv: &FingertipLevels,
    r: &FingertipRadii,
    bolts: &[[f64; 2]],
    tol: ChordTolerance,
) -> Result<Solid, DesignError> {
    let e = OVERLAP_MM;
    let b = &f.bolts;
    let g = |x: Result<Solid, GeometryError>| x.part("sensor_base");
    let mut cuts = vec![
        g(z_cylinder(
            r.pocket_mm,
            lv.pocket_floor_z_mm,
            lv.shell_end_z_mm + 1.0,
            [0.0; 2],
            tol,
        ))?,
        g(z_cylinder(
            f.camera.wire_hole_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            lv.pocket_floor_z_mm + e,
            [0.0; 2],
            tol,
        ))?,
        g(z_cylinder(
            f.led_pcb.wire_hole_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            lv.pocket_floor_z_mm + e,
            pcb_wire_xy(f),
            tol,
        ))?,
    ];
    for &xy in bolts {
        cuts.push(g(z_cylinder(
            b.clearance_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            lv.shell_end_z_mm + 1.0,
            xy,
            tol,
        ))?);
        cuts.push(g(z_cylinder(
            b.head_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            lv.bottom_z_mm + b.head_depth_mm,
            xy,
            tol,
        ))?);
    }
    g(g(z_cylinder(
        r.outside_mm,
        lv.bottom_z_mm,
        lv.shell_end_z_mm,
        [0.0; 2],
        tol,
    ))?
    .difference(&g(Solid::union_all(&cuts))?))
}

/// The diffusion ring: from the ring's bore to the PCB's edge, from the ring's bottom up to
/// the shell's end, with a hole over each UV LED.
fn build_diffusion_ring(
    f: &FingertipBase,
    lv: &FingertipLevels,
    tol: ChordTolerance,
) -> Result<Solid, DesignError> {
    let g = |x: Result<Solid, GeometryError>| x.part("diffusion_ring");
    let rl = f.led_pcb.led_circle_diameter_mm / 2.0;
    let mut holes = Vec::new();
    for (a, uv) in leds() {
        if uv {
            let (s, c) = a.to_radians().sin_cos();
            holes.push(g(z_cylinder(
                f.diffusion_ring.uv_hole_diameter_mm / 2.0,
                lv.ring_bottom_z_mm - 1.0,
                lv.shell_end_z_mm + 1.0,
                [rl * c, rl * s],
                tol,
            ))?);
        }
    }
    g(g(z_ring(
        f.diffusion_ring.inner_diameter_mm / 2.0,
        f.led_pcb.outer_diameter_mm / 2.0,
        lv.ring_bottom_z_mm,
        lv.shell_end_z_mm,
        tol,
    ))?
    .difference(&g(Solid::union_all(&holes))?))
}

/// The bought parts the base holds, as assembly envelopes: the lighting PCB, its LEDs (one
/// ring over their circle) and the camera.
///
/// # Errors
/// [`DesignError::Geometry`] naming the member if the kernel fails.
pub fn members(f: &FingertipBase, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let lv = levels(ctx, f, stack);
    let member =
        |name: &str, description: String, (ri, ro, z0, z1): (f64, f64, f64, f64), fix: &[&str]| {
            let (solid, exact) = if ri > 0.0 {
                axial_ring(ro, ri, z0, z1, tol)
            } else {
                axial_cylinder(ro, z0, z1, tol)
            }
            .part(name)?;
            Ok::<_, DesignError>(Member {
                name: name.into(),
                kind: MemberKind::Bought,
                description,
                solid,
                fix: fix.iter().map(|p| format!("fingertip_base.{p}")).collect(),
                nested_by_stack: false,
                features: Default::default(),
                exact: Some(exact),
                material: None,
            })
        };
    let p = &f.led_pcb;
    let rl = p.led_circle_diameter_mm / 2.0;
    Ok(vec![
        member(
            "led_pcb_envelope",
            "Lighting PCB (bought): 4 white and 4 UV LEDs, two resistors and a dual SPST switch"
                .into(),
            (
                p.inner_diameter_mm / 2.0,
                p.outer_diameter_mm / 2.0,
                lv.pocket_floor_z_mm,
                lv.pcb_top_z_mm,
            ),
            &["led_pcb.inner_diameter_mm", "led_pcb.outer_diameter_mm"],
        )?,
        member(
            "leds_envelope",
            "The 8 LEDs on the PCB (bought), as one ring over their circle".into(),
            (
                rl - p.led_length_mm / 2.0,
                rl + p.led_length_mm / 2.0,
                lv.pcb_top_z_mm,
                lv.led_top_z_mm,
            ),
            &["pocket_depth_mm", "led_pcb.led_height_mm"],
        )?,
        member(
            "camera_envelope",
            format!("Camera (bought): {}", f.camera.module),
            (
                0.0,
                f.camera.diameter_mm / 2.0,
                lv.camera_back_z_mm,
                lv.shell_end_z_mm,
            ),
            &["camera.diameter_mm", "camera.length_mm"],
        )?,
    ])
}

/// The base's bought items: the camera, the PCB, the bolts and the adhesive.
pub fn bought_items(f: &FingertipBase) -> Vec<String> {
    let p = &f.led_pcb;
    vec![
        format!(
            "Camera: {} ({:.1} mm across, {:.1} mm long, {:.0} deg view), its wire down through the base (UVDtact Sec. III-C)",
            f.camera.module, f.camera.diameter_mm, f.camera.length_mm, f.camera.view_angle_deg
        ),
        format!(
            "Lighting PCB: {:.1} mm ring with a {:.1} mm bore, {:.1} mm thick; 4 white and 4 UV (365 nm) LEDs alternating every 45 deg on a {:.1} mm circle, two resistors, a dual SPST switch (UVDtact Sec. III-C)",
            p.outer_diameter_mm, p.inner_diameter_mm, p.thickness_mm, p.led_circle_diameter_mm
        ),
        format!(
            "Sensor base to shell holder: {} bolts through {:.1} mm holes, heads in {:.1} mm counterbores, into {:.1} mm pilots (UVDtact Sec. III-C: three M1.2 bolts)",
            f.bolts.count, f.bolts.clearance_diameter_mm, f.bolts.head_diameter_mm, f.bolts.pilot_diameter_mm
        ),
        "Instant adhesive (cyanoacrylate): the camera, its holder, the PCB and the ring to the base; the shell to its holder (UVDtact Sec. III-C)".into(),
    ]
}

/// The fingertip-base family (`fingertip_base`): the sensor base, the shell holder, the
/// camera holder and the diffusion ring round the lighting PCB (UVDtact Sec. III-C).
pub struct FingertipBaseFamily;

impl Family for FingertipBaseFamily {
    type Params = FingertipBase;
    const PATH: &'static str = "fingertip_base";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[
        ("shell_holder", &["fingertip_base.fit_clearance_mm"]),
        ("sensor_base", &["fingertip_base.fit_clearance_mm"]),
        (
            "camera_holder",
            &["fingertip_base.camera_holder.outer_diameter_mm"],
        ),
        (
            "diffusion_ring",
            &["fingertip_base.diffusion_ring.inner_diameter_mm"],
        ),
    ];

    fn materials(f: &FingertipBase) -> Vec<(String, &str, &'static [MaterialKind])> {
        vec![
            (
                "fingertip_base.material".into(),
                &f.material,
                &[MaterialKind::Print],
            ),
            (
                "fingertip_base.diffusion_ring.material".into(),
                &f.diffusion_ring.material,
                &[MaterialKind::Print],
            ),
        ]
    }

    fn lens(f: &FingertipBase, ctx: &Context<'_>, stack: &Stack) -> Option<Lens> {
        Some(Lens {
            front_z_mm: levels(ctx, f, stack).shell_end_z_mm,
            view_angle_deg: Some(f.camera.view_angle_deg),
            what: "fingertip_base.camera.length_mm: the camera's front flush with the diffusion ring's top".into(),
        })
    }

    fn lights(f: &FingertipBase, ctx: &Context<'_>, stack: &Stack) -> Vec<Light> {
        // the LEDs' tops on their circle, facing the skin: white, and UV (365 nm) that the
        // camera sees only by its faint violet tail (UVDtact Sec. III-C; the UV ink's
        // fluorescence is not modelled)
        let z = levels(ctx, f, stack).led_top_z_mm;
        let r = f.led_pcb.led_circle_diameter_mm / 2.0;
        leds()
            .into_iter()
            .map(|(az, uv)| {
                let a = az.to_radians();
                Light {
                    position_mm: [r * a.cos(), r * a.sin(), z],
                    direction: [0.0, 0.0, 1.0],
                    cone_half_angle_deg: 90.0,
                    colour_rgb: if uv { UV_LED_RGB } else { [1.0, 1.0, 1.0] },
                    intensity: DEFAULT_LED_INTENSITY,
                }
            })
            .collect()
    }

    fn estimated_triangles(f: &FingertipBase, input: FamilyInput<'_>) -> f64 {
        // the shell holder, sensor base, camera holder and diffusion ring: about 40 circles
        // of the base's outer radius
        40.0 * input.tol.circle_segments(f.outer_diameter_mm / 2.0) as f64
    }

    fn pcb_outlines(f: &FingertipBase) -> Vec<CutPart> {
        let circle = |[x, y]: [f64; 2], r: f64| Outline::Circle {
            centre_mm: [x, y],
            radius_mm: r,
        };
        let p = &f.led_pcb;
        let mut outlines = vec![
            (Operation::Cut, circle([0.0; 2], p.outer_diameter_mm / 2.0)),
            (Operation::Cut, circle([0.0; 2], p.inner_diameter_mm / 2.0)),
        ];
        let r = p.led_circle_diameter_mm / 2.0;
        for (a, _) in leds() {
            let (s, c) = a.to_radians().sin_cos();
            outlines.push((
                Operation::Engrave,
                circle([r * c, r * s], p.led_length_mm / 2.0),
            ));
        }
        vec![CutPart {
            name: "lighting_pcb".into(),
            description: format!(
                "Lighting PCB outline: {:.1} mm board with a {:.1} mm bore, {:.1} mm thick; 8 LED places on a {:.1} mm circle, white on +x then UV and white alternating every 45 deg (UVDtact Sec. III-C)",
                p.outer_diameter_mm, p.inner_diameter_mm, p.thickness_mm, p.led_circle_diameter_mm
            ),
            material: "fr4".into(),
            thickness_mm: p.thickness_mm,
            outlines,
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        }]
    }

    fn check(f: &FingertipBase, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>) {
        check_params(ctx, f, stack, errs);
    }

    fn build(f: &FingertipBase, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let FamilyInput { ctx, stack, .. } = input;
        let parts = build_parts(f, input)?;
        let lv = levels(ctx, f, stack);
        Ok(Built {
            parts,
            summary: vec![
                ("fingertip_levels", json!(&lv)),
                envelope(ctx, f.outer_diameter_mm, lv.envelope_height_mm),
            ],
        })
    }

    fn members(f: &FingertipBase, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        members(f, input)
    }

    fn bought_items(f: &FingertipBase) -> Vec<String> {
        bought_items(f)
    }

    fn assembly_steps(f: &FingertipBase, _input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let mut out = Vec::new();
        out.push(AssemblyStep::Text(format!(
            "Glue the camera ({}) into `camera_holder` with instant adhesive, its front flush \
             with the holder's top and its wire down the bore; glue the holder onto the floor of \
             the pocket of `sensor_base`, over the centre hole, the wire down through the floor \
             (UVDtact Sec. III-C).",
            f.camera.module
        )));
        out.push(AssemblyStep::Text(
            "Lead the lighting PCB's wires down through the floor's wire hole and glue the PCB, \
             LEDs up and the first white LED on +x, onto the pocket's floor round the camera \
             holder; glue `diffusion_ring` on top, flush with the base's top, its holes over the \
             UV LEDs (UVDtact Sec. III-C)."
                .into(),
        ));
        out.push(AssemblyStep::Text(
            "Glue the acrylic shell's foot, with the elastomer on it, into `shell_holder` with \
             instant adhesive, the shell's end flush with the holder's bottom (UVDtact \
             Sec. III-C)."
                .into(),
        ));
        out.push(AssemblyStep::Text(format!(
            "Set `shell_holder` on `sensor_base` and fasten them with {} bolts up through the \
             base's counterbored holes; to replace the elastomer, undo them (UVDtact Sec. III-C: \
             three M1.2 bolts).",
            f.bolts.count
        )));
        out
    }
}
