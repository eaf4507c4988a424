//! `wobblog info`.

use crate::CliError;

/// Arguments of `wobblog info`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `wobblog info`.
pub fn run(_args: &Args) -> Result<(), CliError> {
    Err(CliError::Usage("not yet".into()))
}
