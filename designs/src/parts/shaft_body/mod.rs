//! The shaft body of a TacTip-style sensor (Pestell et al. Sec. III-A, Fig. 1): a printed
//! tip (the skin) on a rigid fitting that locks onto a round shaft by a bayonet, the shaft
//! housing the LED ring and the camera (`shaft_body` in a design).
//!
//! From the top down, in the sensor frame (mm):
//!
//! - The skin, down to the base plane `z_b`, and under it the tip's fitting, printed with the
//!   skin in the fitting's rigid material (Vero White) as a further volume of the same
//!   multi-material object. The fitting is a ring of the skin's outer diameter: at its top an
//!   inward lip over the lens window's rim, under the lip the window's seat, then the skirt
//!   that goes over the shaft's top, with the bayonet's lugs reaching in from its bottom.
//! - The lens window: an acrylic disc (laser-cut) between the lip and the shaft's top face.
//!   The clear gel fills the skin above it, round the pins (Sec. III-A: "the space between the
//!   inside of the skin and an inserted acrylic lens is manually filled with a clear silicone
//!   gel"); the lip keeps it in the tip when the tip is off the body.
//! - The body (ABS, Sec. III-A): the shaft, `shaft_length_mm` from its top face down to the
//!   base, with the bayonet's grooves round its top, the LED ring PCB's seat in its top (LEDs
//!   up, under the window) and a bore for the light and the view; under the shaft the base,
//!   with a pocket open at the bottom into which the camera board is screwed up against the
//!   ceiling, its lens up through the ceiling into the shaft's bore, and a slot for the cable.
//!
//! The camera's view cone must cover the lip's opening; the fraction of the skin's inner
//! surface it sees (through the lip, the LED ring and the shaft's bore, the pins' shadows
//! ignored) is stated in the manifest ([`view_fraction`]).

mod checks;
mod dimensions;
mod family;
mod members;
mod params;
mod solids;
mod view;

pub use crate::parts::bayonet::BayonetLugs;
pub use checks::check_params;
pub(crate) use checks::half_nozzle;
pub use dimensions::{levels, radii, tip_bayonet, twin_params, ShaftLevels, ShaftRadii};
pub use family::{tip_filling_step, ShaftBodyFamily};
pub use members::{bought_items, members};
pub use params::{
    LedRing, LensWindow, ShaftBase, ShaftBodyParams, ShaftCamera, TipFitting, CABLE_SLOT_MM,
    LED_WIRE_ROOM_MM, OVERLAP_MM,
};
pub use solids::{build_body, filling_gel_solid, tip_fitting_solid};
pub use view::view_fraction;
