//! `wobblog plot`: the seed paper's Figure 6 for one run.

use std::path::PathBuf;

use crate::analysis::Run;
use crate::cmd::logs::warn_losses;
use crate::output::Output;
use crate::plot::timeplot::TimePlot;
use crate::plot::{render, ImageKind};
use crate::time::WindowArgs;
use crate::CliError;

/// Arguments of `wobblog plot`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// The image to write: `.png` or `.svg`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// The time window (`--from`, `--to`).
    #[command(flatten)]
    pub window: WindowArgs,
    /// Label the time axis in UTC (from the log's GPS sync pairs) instead
    /// of seconds since boot.
    #[arg(long)]
    pub utc: bool,
}

/// Runs `wobblog plot`.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    let window = args.window.window();
    let out = Output::create(&args.output, &[&args.log])?;
    let run = Run::load(&args.log)?;
    warn_losses(&run);
    let pairs = &run.summary.utc_syncs;
    let (from, to) = window.boot_s(pairs, &args.log)?;
    if args.utc && pairs.is_empty() {
        return Err(CliError::file(
            &args.log,
            "--utc: the log has no UTC time (no GPS sync pair)",
        ));
    }
    let mut figure = TimePlot::new(&run, from, to)
        .ok_or_else(|| CliError::file(&args.log, "no frames in the requested time window"))?;
    if args.utc {
        figure.label_utc(pairs.clone());
    }
    render(&figure, out)
}
