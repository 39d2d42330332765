//! Part families that any sensor design can use, one module per family (../shared/STYLE.md):
//! each with its parameters, its rules and its solids.

pub mod bayonet;
pub mod casing;
pub mod fingertip_base;
pub mod robot_mount;
pub mod shaft_body;
