//! `wobblog report`: one self-contained HTML page for a card or a set of
//! logs (the campaign view and one ride view per run).

use std::path::{Path, PathBuf};

use crate::output::Output;
use crate::report::page::{self, PageError};
use crate::report::Campaign;
use crate::CliError;

/// Arguments of `wobblog report`.
#[derive(clap::Args)]
pub struct Args {
    /// Card logs (`RUNnnnnn.WBL`) or directories of them (a card): one
    /// ride view each, all of them one campaign.
    #[arg(required = true, value_name = "CARD_OR_LOGS")]
    pub inputs: Vec<PathBuf>,
    /// The page to write (one HTML file, everything inside it).
    #[arg(short, long)]
    pub output: PathBuf,
    /// A parameter file: Figure 8 over its wobble mode, and the wobble
    /// speed of the model fitted to the kicks, as `margin --model` gives it.
    #[arg(long, value_name = "PARAMS")]
    pub model: Option<PathBuf>,
}

/// Runs `wobblog report`: the page is written only when every log was read.
pub fn run(args: &Args) -> Result<(), CliError> {
    let logs = crate::inputs::distinct(crate::cmd::logs::expand(&args.inputs)?);
    let mut inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    if let Some(params) = &args.model {
        inputs.push(params);
    }
    let mut out = Output::create(&args.output, &inputs)?;
    let campaign = Campaign::load(&logs, args.model.as_deref())?;
    // Written as it is made; only a whole page is committed.
    page::write(&campaign, &mut out).map_err(|e| match e {
        PageError::Data(e) => CliError::file(&args.output, format!("cannot write the report: {e}")),
        PageError::Write(e) => out.error(e),
    })?;
    out.commit()
}
