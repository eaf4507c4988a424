//! `wobblog summary`: one row per run in a directory of logs.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::{wobble_speed_mps, Ride, Stability};
use crate::cmd::logs::{for_each_log, print, warn_losses};
use crate::output::Output;
use crate::CliError;

/// Output formats of `wobblog summary`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SummaryFormat {
    /// Aligned columns for reading.
    Table,
    /// Comma-separated values with a header line.
    Csv,
    /// One JSON object per line.
    Jsonl,
}

/// Arguments of `wobblog summary`.
#[derive(clap::Args)]
pub struct Args {
    /// A card (logs, `*.WBL` in any case, at its top) or a folder of cards
    /// (one directory each, as `export` takes), not searched deeper; a
    /// log of a folder of cards is named `CARD/RUNnnnnn.WBL` in the `log`
    /// column.
    pub dir: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    pub format: SummaryFormat,
    /// The same as `--format jsonl`, as on `info`, `events` and `wobble`.
    #[arg(long, conflicts_with = "format")]
    pub json: bool,
}

/// One run's row.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunRow {
    /// Log file name.
    pub log: String,
    /// Frames times the frame period, s.
    pub duration_s: f64,
    /// Wheel distance over the frames present, m.
    pub distance_m: f64,
    /// Highest wheel speed, m/s.
    pub max_speed_mps: f64,
    /// Wobble episodes, stable and unstable.
    pub episodes: usize,
    /// Of which unstable.
    pub unstable_episodes: usize,
    /// Episodes the data do not show whole (cut by a gap or an end of the
    /// data; counted in `episodes` too).
    pub censored_episodes: usize,
    /// Lowest speed at onset of an unstable episode, m/s.
    pub wobble_speed_mps: Option<f64>,
    /// Frames lost: dropped by the logger plus held by blocks missing from
    /// the file.
    pub frames_lost: u64,
    /// Blocks missing from the file.
    pub lost_blocks: u64,
    /// UTC of the first frame that has one, as `info` gives it.
    pub first_utc: Option<String>,
}

impl RunRow {
    /// The row of `ride`.
    #[must_use]
    pub fn of(ride: &Ride) -> Self {
        let episodes = &ride.episodes;
        let s = &ride.summary;
        Self {
            log: ride.name(),
            duration_s: s.duration_s,
            distance_m: ride.distance_m,
            max_speed_mps: ride.max_speed_mps,
            episodes: episodes.len(),
            unstable_episodes: episodes
                .iter()
                .filter(|e| e.stability == Stability::Unstable)
                .count(),
            censored_episodes: episodes.iter().filter(|e| e.censored).count(),
            wobble_speed_mps: wobble_speed_mps(episodes),
            frames_lost: s.frames_dropped + s.frames_lost,
            lost_blocks: s.lost_blocks,
            first_utc: s.first_utc.clone(),
        }
    }
}

/// The row of `ride`, one of the logs of `cards`: its log named
/// `CARD/RUNnnnnn.WBL` in a folder of cards (the Python package's
/// `wobblog.summary` too).
#[must_use]
pub fn card_row(cards: &[crate::dataset::Card], ride: &Ride) -> RunRow {
    let mut row = RunRow::of(ride);
    let card = cards.iter().find(|(_, logs)| logs.contains(&ride.path));
    if let Some((Some(card), _)) = card {
        row.log = format!("{card}/{}", row.log);
    }
    row
}

/// The card logs in `dir`, sorted by name.
pub fn logs_in(dir: &Path) -> Result<Vec<PathBuf>, CliError> {
    let entries = std::fs::read_dir(dir).map_err(|e| CliError::file(dir, e))?;
    let mut logs = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| CliError::file(dir, e))?.path();
        let is_log = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("wbl"));
        if is_log && path.is_file() {
            logs.push(path);
        }
    }
    logs.sort();
    Ok(logs)
}

/// Refuses a file where `summary` takes a card folder, pointing a single
/// log to `info` (the folder listing would only say "Not a directory").
fn card_folder(dir: &Path) -> Result<(), CliError> {
    if dir.exists() && !dir.is_dir() {
        return Err(CliError::file(
            dir,
            "not a directory: `wobblog summary` takes a card folder (or a folder of cards); \
             `wobblog info` reports one log",
        ));
    }
    Ok(())
}

/// Runs `wobblog summary`: rows for every readable log, even when some are not.
pub fn run(args: &Args) -> Result<(), CliError> {
    card_folder(&args.dir)?;
    let cards = crate::dataset::cards_in(&args.dir)?;
    let logs: Vec<PathBuf> = cards.iter().flat_map(|(_, logs)| logs.clone()).collect();
    let stdout = Output::stdout(&logs.iter().map(PathBuf::as_path).collect::<Vec<_>>())?;
    let mut rows = Vec::new();
    let result = for_each_log(&logs, "summarising", |log| {
        let ride = Ride::load(log)?;
        warn_losses(log, &ride.summary);
        rows.push(card_row(&cards, &ride));
        Ok(())
    });
    let format = if args.json {
        SummaryFormat::Jsonl
    } else {
        args.format
    };
    let printed = print(stdout, &render(&rows, format));
    result.and(printed)
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| format!("{v:.2}"))
}

/// A row's cells for the table and CSV forms, which are read on a
/// terminal: the log's name with control and bidirectional characters
/// escaped (the JSON lines keep the exact name, in JSON escapes).
fn cells(r: &RunRow) -> [String; 11] {
    [
        crate::text::escape_controls(&r.log).into_owned(),
        format!("{:.2}", r.duration_s),
        format!("{:.1}", r.distance_m),
        format!("{:.2}", r.max_speed_mps),
        r.episodes.to_string(),
        r.unstable_episodes.to_string(),
        r.censored_episodes.to_string(),
        opt(r.wobble_speed_mps),
        r.frames_lost.to_string(),
        r.lost_blocks.to_string(),
        r.first_utc.clone().unwrap_or_default(),
    ]
}

const HEADER: [&str; 11] = [
    "log",
    "duration_s",
    "distance_m",
    "max_speed_mps",
    "episodes",
    "unstable_episodes",
    "censored_episodes",
    "wobble_speed_mps",
    "frames_lost",
    "lost_blocks",
    "first_utc",
];

/// The rows in `format`.
#[must_use]
pub fn render(rows: &[RunRow], format: SummaryFormat) -> String {
    match format {
        SummaryFormat::Jsonl => rows
            .iter()
            .filter_map(|r| serde_json::to_string(r).ok())
            .map(|line| crate::text::json_terminal_safe(line) + "\n")
            .collect(),
        SummaryFormat::Csv => {
            let mut w = csv::Writer::from_writer(Vec::new());
            let written = std::iter::once(HEADER.map(String::from))
                .chain(rows.iter().map(cells))
                .try_for_each(|record| w.write_record(&record));
            match (written, w.into_inner()) {
                (Ok(()), Ok(bytes)) => String::from_utf8_lossy(&bytes).into_owned(),
                _ => String::new(),
            }
        }
        SummaryFormat::Table => {
            let table: Vec<[String; 11]> = std::iter::once(HEADER.map(String::from))
                .chain(rows.iter().map(cells))
                .collect();
            let widths: Vec<usize> = (0..HEADER.len())
                .map(|c| table.iter().map(|r| r[c].len()).max().unwrap_or(0))
                .collect();
            let mut out = String::new();
            for row in &table {
                let line: Vec<String> = row
                    .iter()
                    .zip(&widths)
                    .enumerate()
                    .map(|(c, (v, &w))| {
                        if c == 0 {
                            format!("{v:<w$}")
                        } else {
                            format!("{v:>w$}")
                        }
                    })
                    .collect();
                out.push_str(line.join("  ").trim_end());
                out.push('\n');
            }
            out
        }
    }
}
