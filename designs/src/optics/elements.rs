//! The optical elements a section family contributes to its sensor
//! ([`crate::parts::family::Family`]): its lights, its lens, and the flat interfaces between
//! the lens and the skin. A leaf: the families and the design's `optics` parameters
//! ([`crate::schema::optics`]) use it; what resolves a design's optics is [`crate::optics`].
//! Sensor frame, mm (docs/conventions.md).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One light: a point emitter whose intensity falls as the cosine of the angle from its beam's
/// axis (a bare LED), and is 0 outside its cone.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Light {
    /// Where the light is emitted, sensor frame, mm.
    pub position_mm: [f64; 3],
    /// The beam's axis, sensor frame: any vector longer than 0 (it is normalised).
    pub direction: [f64; 3],
    /// Half-angle of the cone outside which the light gives nothing, degrees, in (0, 90]
    /// (90 for a bare LED).
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 90))]
    pub cone_half_angle_deg: f64,
    /// Colour, relative RGB, each in [0, 1] and not all 0.
    pub colour_rgb: [f64; 3],
    /// Radiant intensity on the beam's axis, relative units, > 0: a surface facing the light
    /// `d` mm away on its axis receives `intensity / d^2` (1 at 10 mm for 100).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub intensity: f64,
}

/// `n` white lights of `intensity` evenly round a circle of radius `r_mm` at height `z_mm`
/// (the first on +x), each pointing along `direction` (`None`: towards the axis), cone 90 deg.
pub fn ring_of_lights(
    n: u32,
    r_mm: f64,
    z_mm: f64,
    first_azimuth_deg: f64,
    direction: Option<[f64; 3]>,
    colour_rgb: impl Fn(u32) -> [f64; 3],
) -> Vec<Light> {
    (0..n)
        .map(|k| {
            let a = (first_azimuth_deg + f64::from(k) * 360.0 / f64::from(n.max(1))).to_radians();
            let (c, s) = (a.cos(), a.sin());
            Light {
                position_mm: [r_mm * c, r_mm * s, z_mm],
                direction: direction.unwrap_or([-c, -s, 0.0]),
                cone_half_angle_deg: 90.0,
                colour_rgb: colour_rgb(k),
                intensity: DEFAULT_LED_INTENSITY,
            }
        })
        .collect()
}

/// The intensity of a family's LED, relative units (see [`Light::intensity`]): 100, so that a
/// white patch 10 mm in front of one LED receives 1.
pub const DEFAULT_LED_INTENSITY: f64 = 100.0;

/// One flat interface between the camera and the skin: a plane normal to the sensor's z axis
/// where the medium changes (a filling gel's free surface, a window's or a plate's face).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlatInterface {
    /// Height of the plane, sensor frame z, mm.
    pub z_mm: f64,
    /// The medium above the plane (towards the skin): a material key of the materials table,
    /// or [`AIR`].
    pub above: String,
    /// What the plane is, naming the parameters it comes from
    /// (`housing.filling_gel: the gel's free surface at the core's open end`).
    pub what: String,
}

/// The camera's lens as a section family places it ([`crate::parts::family::Family::lens`]):
/// on the sensor's axis, looking along +z.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Lens {
    /// Height of the lens's front, sensor frame z, mm: taken as the camera's centre of
    /// projection (the entrance pupil of a short wide-angle lens lies close behind its front
    /// element; R-Tac0's, measured from its authors' pose, 8.4 mm under the filling gel's free
    /// surface, issue 97).
    pub front_z_mm: f64,
    /// The lens's full view angle, degrees, in (0, 180), when the design gives it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view_angle_deg: Option<f64>,
    /// Where it comes from, naming its parameters (`housing.camera.lens_height_mm`).
    pub what: String,
}

/// The medium key of air (n = 1.000 at the sodium D line; 1.0003 in fact, a 0.03 % bend
/// ignored), the medium a camera file's lens was calibrated in.
pub const AIR: &str = "air";
