//! Marker patterns on surfaces of revolution, and marker features (a radial cylinder with a
//! hemispherical end, raised or recessed).
//!
//! Sources: ShadowTac Sec. III-IV (dimples: cylinder with a hemispheric tip, 0.45 mm base,
//! 0.5 mm height, concentric, 1.4 mm spacing); UVDtact Sec. III (slots and protrusions: 0.5 mm
//! radius cylinder of 0.5 mm height ending in a 0.5 mm radius hemisphere); Pestell et al.
//! Sec. III-A, III-D (TacTip pins ending in white dots, four layouts).
//!
//! Positions are on an offset surface of the body profile (sensor frame); a marker's
//! arc length `s` is measured along the profile curve from the pole, its azimuth from +x
//! towards +y. Its polar angle is the angle between +z and the direction from the origin to
//! the marker (for spherical profiles: the usual polar angle).

mod placement;
mod solids;
mod spec;
mod stats;
mod surface;

pub use placement::{place, point_errors, MAX_MARKERS_PER_PATTERN};
pub use solids::{
    embed_depth_mm, feature_solid, frame_to, local_feature, local_feature_dilated,
    tangent_gap_volume_mm3,
};
pub use spec::{
    layout_name, AlternateOffset, FeatureShape, Layout, Marker, MarkerSpec, MarkerSurface, OnSkin,
    Pattern, PatternError, Polarity, RingAzimuthOffset, NO_EFFECT,
};
pub use stats::{nearest_neighbours, stats, PatternStats};
pub use surface::Surface;
