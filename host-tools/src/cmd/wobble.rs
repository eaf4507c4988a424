//! `wobblog wobble`: every wobble episode of one or more runs and the
//! weave's kick ring-downs (`mode`), the wobble speed of each, and
//! optionally the seed paper's Figure 8 across them.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::{wobble_speed_mps, Episode, KickMode, Ride, Stability};
use crate::cmd::logs::{expand, for_each_log, print, warn_losses};
use crate::output::Output;
use crate::plot::modes::ModePlot;
use crate::plot::{render, ImageKind};
use crate::time::{utc_text_at, TimeWindow, WindowArgs};
use crate::CliError;

/// Arguments of `wobblog wobble`.
#[derive(clap::Args)]
pub struct Args {
    /// Card logs (`RUNnnnnn.WBL`) or card folders (every `*.WBL` at
    /// their top, in name order).
    #[arg(required = true, value_name = "LOGS|DIRS")]
    pub logs: Vec<PathBuf>,
    /// `--json` (or `--format jsonl`) for JSON instead of text.
    #[command(flatten)]
    pub output: crate::cmd::logs::JsonArgs,
    /// Also draw every episode as a point of sigma against 2 pi f into this
    /// `.png` or `.svg` file.
    #[arg(long, value_name = "OUT")]
    pub plot: Option<PathBuf>,
    /// Only episodes whose onset falls in this window (`--from`, `--to`).
    #[command(flatten)]
    pub window: WindowArgs,
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: crate::plot::FigureArgs,
}

/// The episodes of one run, as printed.
#[derive(Serialize)]
pub struct RunEpisodes {
    /// The log.
    pub log: String,
    /// Lowest speed at onset of an unstable episode, m/s.
    pub wobble_speed_mps: Option<f64>,
    /// Every episode, in time order.
    pub episodes: Vec<EpisodeUtc>,
}

/// An episode and the UTC of its onset.
#[derive(Serialize)]
pub struct EpisodeUtc {
    /// The episode.
    #[serde(flatten)]
    pub episode: Episode,
    /// UTC at onset, ISO 8601, through the log's sync pairs (as `decode`'s
    /// `utc` column); absent before the first pair.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub onset_utc: Option<String>,
}

/// Runs `wobblog wobble`. A log that cannot be read is reported and
/// skipped; the others are still analysed, and the exit code says one failed.
pub fn run(args: &Args) -> Result<(), CliError> {
    let json = args.output.is_json()?;
    if let Some(plot) = &args.plot {
        ImageKind::of(plot)?;
    }
    let logs = crate::inputs::distinct(expand(&args.logs)?);
    let inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    let plot_out = args
        .plot
        .as_deref()
        .map(|p| Output::create(p, &inputs))
        .transpose()?;
    let stdout = Output::stdout(&inputs)?;
    let mut reports = Vec::new();
    let mut names = Vec::new();
    let result = for_each_log(&logs, "analysing", |log| {
        let ride = Ride::load(log)?;
        warn_losses(log, &ride.summary);
        reports.push(episodes_of(&ride, &args.window.window())?);
        names.push(ride.name());
        Ok(())
    });
    let mut text = String::new();
    for report in &reports {
        if json {
            let line = serde_json::to_string(report)
                .map_err(|e| CliError::file(Path::new(&report.log), e))?;
            text.push_str(&line);
            text.push('\n');
        } else {
            text.push_str(&render_text(report));
        }
    }
    // The figure is drawn even when the table's reader went away, and only
    // when every log was read: a failed command leaves an old figure as it was.
    let printed = print(stdout, &text);
    if let (Some(out), Ok(())) = (plot_out, &result) {
        let runs = names
            .into_iter()
            .zip(reports)
            .map(|(name, r)| {
                // Figure 8 is the wobble's: the weave's ring-downs are laid
                // over the model's weave by `wobblog model compare`.
                let wobble = r.episodes.into_iter().map(|e| e.episode);
                (
                    name,
                    wobble.filter(|e| e.mode == KickMode::Wobble).collect(),
                )
            })
            .collect();
        render(&ModePlot::new(runs), out, &args.figure)?;
    }
    result.and(printed)
}

/// The episodes of `ride` whose onset falls in `window`, as `wobblog
/// wobble --json` prints them (the Python package's `Log.episodes` too).
///
/// # Errors
/// A UTC bound of `window` in a log without UTC.
pub fn episodes_of(ride: &Ride, window: &TimeWindow) -> Result<RunEpisodes, CliError> {
    let (from, to) = window.boot_s(&ride.summary.utc_syncs, &ride.path)?;
    let mut episodes = ride.all_episodes();
    episodes.retain(|e| from.is_none_or(|a| e.onset_s >= a) && to.is_none_or(|b| e.onset_s <= b));
    let pairs = &ride.summary.utc_syncs;
    Ok(RunEpisodes {
        log: ride.path.display().to_string(),
        wobble_speed_mps: wobble_speed_mps(&episodes),
        episodes: episodes
            .into_iter()
            .map(|episode| EpisodeUtc {
                onset_utc: utc_text_at(pairs, episode.onset_s),
                episode,
            })
            .collect(),
    })
}

fn render_text(r: &RunEpisodes) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let speed = r
        .wobble_speed_mps
        .map_or("none (no unstable episode)".into(), |v| {
            format!("{v:.2} m/s")
        });
    let _ = writeln!(
        o,
        "{}: {}, wobble speed {speed}",
        crate::text::escape_controls(&r.log),
        crate::words::plural(r.episodes.len(), "episode")
    );
    // The same names as the JSON fields.
    if !r.episodes.is_empty() {
        let _ = writeln!(
            o,
            "  mode    onset_s  onset_utc                   end_s  freq_hz  sigma_per_s  peak_amp_deg  speed_at_onset_mps  stability  source     censored"
        );
    }
    for EpisodeUtc {
        episode: e,
        onset_utc,
    } in &r.episodes
    {
        let stability = match e.stability {
            Stability::Stable => "stable",
            Stability::Unstable => "unstable",
        };
        let line = format!(
            "  {:<6}  {:7.2}  {:<24}  {:7.2}  {:7.2}  {:11.2}  {:12.2}  {:18.2}  {stability:<9}  {:<9}  {}",
            e.mode.as_str(),
            e.onset_s,
            onset_utc.as_deref().unwrap_or("-"),
            e.end_s,
            e.freq_hz,
            e.sigma_per_s,
            e.peak_amp_deg,
            e.speed_at_onset_mps,
            e.source.as_str(),
            e.cuts_text(),
        );
        let _ = writeln!(o, "{}", line.trim_end());
    }
    o
}
