//! `fabkit calibrate ...`: argument parsing and dispatch over fabkit-calibration.

use std::error::Error;

#[derive(clap::Subcommand, Debug)]
pub enum CalibrateCommand {
    /// Solve the camera pose (T_cam_sensor) from pin-dome observations.
    Extrinsics(ExtrinsicsArgs),
}

#[derive(clap::Args, Debug)]
pub struct ExtrinsicsArgs {}

pub fn run(cmd: CalibrateCommand) -> Result<(), Box<dyn Error>> {
    match cmd {
        CalibrateCommand::Extrinsics(_) => Err("calibrate extrinsics: not built yet".into()),
    }
}
