//! The names of a dataset's files, defined once for their writer (`dataset.rs`) and its readers
//! (Python's `fabkit.GroundTruth` takes them from `fabkit.GROUNDTRUTH_FILES`).

/// The manifest, at the top of the dataset.
pub const MANIFEST: &str = "manifest.json";
/// The stitched pairs of protrusion patterns (not written for pin captures).
pub const PAIRS: &str = "pairs.csv";
/// pairs.csv's header row.
pub const PAIRS_HEADER: [&str; 5] = [
    "pair",
    "right_pattern",
    "right_dir",
    "left_pattern",
    "left_dir",
];
/// The half masks: pixels seeing the reference surface at sensor-frame x < 0 and x >= 0.
pub const LEFT_MASK: &str = "left_mask.png";
pub const RIGHT_MASK: &str = "right_mask.png";
/// The reference (undeformed) frame's folder.
pub const REFERENCE_DIR: &str = "reference";
/// The float32 maps of every frame, in mm.
pub const MAPS: [&str; 2] = ["range_mm", "zdepth_mm"];
/// The differences to the reference of an indented frame's maps, mm.
pub const DELTA_MAPS: [&str; 2] = ["delta_range_mm", "delta_zdepth_mm"];
/// The (H, W, 3) float32 unit normals of every frame.
pub const NORMALS: &str = "normals";
/// A map's float32 file (`npy`): `<map>.npy`.
pub const NPY_SUFFIX: &str = ".npy";
/// A map `<stem>_mm`'s 16-bit PNG: `<stem>_um.png`.
pub const PNG16_SUFFIX: &str = "_um.png";
/// A map `<stem>_mm`'s colour-mapped preview: `<stem>_preview.png`.
pub const PREVIEW_SUFFIX: &str = "_preview.png";
/// A frame's float32 maps in one file (`npz`).
pub const ARRAYS_NPZ: &str = "arrays.npz";
/// A frame's surface points (`npy`).
pub const POINTS: &str = "points.ply";
/// An indented frame's contact mask.
pub const CONTACT_MASK: &str = "contact_mask.png";
/// A frame's rendered image (`--images`).
pub const IMAGE: &str = "image.png";

/// The stem of a map's PNG files: `range_mm` -> `range`.
pub fn stem(map: &str) -> &str {
    map.trim_end_matches("_mm")
}
