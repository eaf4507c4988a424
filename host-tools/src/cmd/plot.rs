//! `wobblog plot`: the seed paper's Figure 6 for one run.

use std::path::PathBuf;

use crate::analysis::run::{log_name, read_rows};
use crate::cmd::info::summarise;
use crate::cmd::logs::warn_losses;
use crate::output::Output;
use crate::plot::timeplot::TimePlotBuilder;
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

/// Runs `wobblog plot`: one pass for what the log records (its time span,
/// rate, UTC pairs, losses), one to draw the frames, so memory stays flat
/// whatever the run's length.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    let window = args.window.window();
    let out = Output::create(&args.output, &[&args.log])?;
    let summary = summarise(&args.log)?;
    warn_losses(&args.log, &summary);
    let pairs = &summary.utc_syncs;
    let window_s = window.boot_s(pairs, &args.log)?;
    if args.utc && pairs.is_empty() {
        return Err(CliError::file(
            &args.log,
            "--utc: the log has no UTC time (no GPS sync pair)",
        ));
    }
    let no_frames = || CliError::file(&args.log, "no frames in the requested time window");
    let (Some(first), Some(last)) = (summary.start_s, summary.end_s) else {
        return Err(CliError::file(&args.log, "no frames in the log"));
    };
    let name = log_name(&args.log);
    let fs_hz = summary.frame_rate_hz();
    let mut builder = TimePlotBuilder::new(&name, &summary, (first, last), fs_hz, window_s)
        .ok_or_else(no_frames)?;
    read_rows(&args.log, |_| {}, |row| builder.push_row(row))?;
    let mut figure = builder.finish();
    if figure.is_empty() {
        return Err(no_frames());
    }
    if args.utc {
        figure.label_utc(pairs.clone());
    }
    render(&figure, out)
}
