//! `wobblog encode`.

use crate::CliError;

/// Arguments of `wobblog encode`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `wobblog encode`.
pub fn run(_args: &Args) -> Result<(), CliError> {
    Err(CliError::Usage("not yet".into()))
}
