//! `wobblog plot`: the seed paper's Figure 6 for one run.

use std::path::PathBuf;

use crate::analysis::ride::RideAnalysis;
use crate::analysis::run::{log_name, read_rows};
use crate::cmd::info::summarise;
use crate::cmd::logs::{one_log, warn_losses};
use crate::output::Output;
use crate::plot::timeplot::{TimePlotBuilder, SIZE_PX};
use crate::plot::{render, FigureArgs, ImageKind};
use crate::summary::Summary;
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
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// Runs `wobblog plot`: one pass for what the log records (its time span,
/// rate, UTC pairs, losses), one to draw the frames, so memory stays flat
/// whatever the run's length.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    // One figure per run into one named image: a folder would need as many
    // outputs as logs, so it is refused with its logs listed (`report`
    // draws every run of a card on one page).
    one_log(
        &args.log,
        "plot",
        "plot them one by one, or `wobblog report` for every run on one page",
    )?;
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
    let no_frames = || {
        if window.is_all() {
            CliError::file(&args.log, "no frames in the log")
        } else {
            window.selects_nothing(
                &args.log,
                "frames",
                summary.frame_range_s,
                !pairs.is_empty(),
            )
        }
    };
    let Some((span_s, narrowed)) = summary.plot_span_s() else {
        return Err(CliError::file(&args.log, "no frames in the log"));
    };
    let data_s = if window_s.0.is_some() || window_s.1.is_some() {
        // A window asked for is plotted wherever it lies.
        summary.frame_range_s.unwrap_or(span_s)
    } else {
        if narrowed {
            warn_narrowed(&args.log, &summary, span_s);
        }
        span_s
    };
    let name = log_name(&args.log);
    let fs_hz = summary.frame_rate_hz();
    // A single frame spans its own period: a run of one frame is plotted.
    let data_s = match data_s {
        (a, b) if b <= a && fs_hz > 0.0 => (a, a + 1.0 / fs_hz),
        span => span,
    };
    let width_px = args.figure.size.map_or(SIZE_PX.0, |s| s.0);
    let mut builder = TimePlotBuilder::new(&name, &summary, data_s, fs_hz, window_s, width_px)
        .ok_or_else(no_frames)?;
    // The episodes drawn come from the same reading of the frames.
    let mut analysis = RideAnalysis::new(fs_hz, &summary.config);
    read_rows(
        &args.log,
        |_| {},
        |row| {
            builder.push_row(row);
            analysis.push(row.t_s, row.steer_deg, row.speed_mps, row.gyro_dps[0]);
        },
    )?;
    let mut figure = builder.finish();
    figure.set_episodes(&analysis.finish(&args.log, summary.clone()).all_episodes());
    if figure.is_empty() {
        return Err(no_frames());
    }
    if args.utc {
        figure.label_utc(pairs.clone());
    }
    render(&figure, out, &args.figure)
}

/// Says which stretch a run cut by time jumps is plotted over.
fn warn_narrowed(log: &std::path::Path, summary: &Summary, (from, to): (f64, f64)) {
    let frames = summary.longest_segment.map_or(0, |(_, n)| n);
    eprintln!(
        "wobblog: {}: warning: time jumps leave most of the run's time span empty; plotting its longest stretch, \
         {from:.2} to {to:.2} s ({frames} of {} frames); --from/--to plot another",
        crate::text::shown(log),
        summary.samples
    );
}
