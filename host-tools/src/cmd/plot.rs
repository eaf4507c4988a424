//! `wobblog plot`: the seed paper's Figure 6 for one run.

use std::path::PathBuf;

use crate::analysis::Run;
use crate::cmd::logs::warn_losses;
use crate::output::Output;
use crate::plot::timeplot::TimePlot;
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Arguments of `wobblog plot`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// The image to write: `.png` or `.svg`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Start of the time window, s since boot (default: the first frame).
    #[arg(long)]
    pub from: Option<f64>,
    /// End of the time window, s since boot (default: the last frame).
    #[arg(long)]
    pub to: Option<f64>,
}

/// Runs `wobblog plot`.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    if let (Some(a), Some(b)) = (args.from, args.to) {
        if a >= b {
            return Err(CliError::Usage(format!(
                "--from {a} is not before --to {b}"
            )));
        }
    }
    let out = Output::create(&args.output, &[&args.log])?;
    let run = Run::load(&args.log)?;
    warn_losses(&run);
    let figure = TimePlot::new(&run, args.from, args.to)
        .ok_or_else(|| CliError::file(&args.log, "no frames in the requested time window"))?;
    render(&figure, out)
}
