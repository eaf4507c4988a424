//! `wobblog decode`.

use crate::CliError;

/// Arguments of `wobblog decode`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `wobblog decode`.
pub fn run(_args: &Args) -> Result<(), CliError> {
    Err(CliError::Usage("not yet".into()))
}
