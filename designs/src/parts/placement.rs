//! Print placement: a part turned into its print orientation and set on the bed, with the
//! map from the sensor frame to the print frame that the part records for its twin
//! (`docs/conventions.md`, `T_print_sensor`).

use crate::geometry::{Affine, Solid};

/// Places a solid for printing: minimum z on the plate (z = 0), bounding box centred on x = y = 0.
pub fn place_on_bed(s: &Solid) -> Solid {
    match s.bounding_box() {
        Some(b) => s.translate([
            -(b.min[0] + b.max[0]) / 2.0,
            -(b.min[1] + b.max[1]) / 2.0,
            -b.min[2],
        ]),
        None => s.clone(),
    }
}

/// `s` turned by the rigid map `pose` into its print orientation, then placed as
/// [`place_on_bed`] does; with the whole map `T_print_sensor` (sensor frame to print frame,
/// mm). Parts record it in `params.T_print_sensor` so that an independent twin
/// (export/python/twins) can rebuild them in the sensor frame and place them the same way.
pub fn place_posed(s: &Solid, pose: &Affine) -> (Solid, Affine) {
    let turned = if *pose == Affine::identity() {
        s.clone()
    } else {
        s.transform(pose)
    };
    let shift = match turned.bounding_box() {
        Some(b) => [
            -(b.min[0] + b.max[0]) / 2.0,
            -(b.min[1] + b.max[1]) / 2.0,
            -b.min[2],
        ],
        None => [0.0; 3],
    };
    (
        turned.translate(shift),
        crate::geometry::transform::translation(shift) * pose,
    )
}

/// `params` with `T_print_sensor` (see [`place_posed`]) added.
pub fn with_pose(mut params: serde_json::Value, t: &Affine) -> serde_json::Value {
    if let Some(o) = params.as_object_mut() {
        o.insert(
            "T_print_sensor".into(),
            crate::geometry::transform::to_json(t),
        );
    }
    params
}
