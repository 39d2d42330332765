//! fabkit-designs: the geometry core, sensor body profiles, layer stacks, molds, housings and
//! the YAML design schema of fabkit.
pub mod geometry;
pub mod kit;
