//! The calibration crate's integration tests, one binary (one link) with a module per area.

mod board;
mod board_synthetic;
mod camera_files;
mod camera_models;
mod common;
mod elastic;
mod extrinsics_synthetic;
mod flat_response;
mod groundtruth_closed_form;
mod groundtruth_undistort;
mod images_library;
mod imprints;
mod nominal;
mod photometric;
mod press;
mod refine;
mod refraction;
mod shading;
mod shells;
mod tables;
