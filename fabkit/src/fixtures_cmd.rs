//! `fabkit fixtures`: argument parsing and dispatch over fabkit-fixtures.

use std::error::Error;

#[derive(clap::Args, Debug)]
pub struct FixturesArgs {}

pub fn run(_args: FixturesArgs) -> Result<(), Box<dyn Error>> {
    Err("fixtures: not built yet".into())
}
