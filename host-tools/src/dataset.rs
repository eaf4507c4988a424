//! A campaign as Parquet datasets, one folder per table, so Polars,
//! pyarrow and DuckDB open each with their default options:
//! `frames/RUNnnnnnn.parquet` (one file per run, named as its log, whose
//! first column `run` says the run in every row, so that a reader without
//! partitions, `pyarrow.dataset` with its defaults, or the file alone keeps
//! it; under `card=NAME/` for a folder of cards, a Hive partition with
//! `NAME` percent-encoded as Hive readers decode it), `runs/part-0.parquet` (one row per run, as `wobblog
//! summary`), `episodes/part-0.parquet` (one row per episode, the wobble's
//! and the weave's, as `wobblog wobble`) and `kicks/part-0.parquet` (one
//! row per kick, as `wobblog margin` and `margin --mode weave` take them,
//! with `used`: whether the campaign's prediction gave it weight) and
//! `events/part-0.parquet` (one row per event, as `wobblog events`: alerts,
//! markers, kick records, faults, dropouts, losses). Every file carries its
//! columns' units as key-value metadata (`unit.NAME`).

use std::path::{Path, PathBuf};

use crate::analysis::campaign_kicks::{
    ride_campaign_kicks, CampaignKick, Prefer, Source, SpeedsAfter,
};
use crate::analysis::kicks::{Kick, KickMode};
use crate::analysis::margin::weave::predict_weave;
use crate::analysis::margin::{predict, KickPoint, Trend};
use crate::analysis::{Cut, Episode, Ride, Stability};
use crate::cmd::decode::Taps;
use crate::cmd::summary::{logs_in, RunRow};
use crate::events::{EventKind, LogEvent};
use crate::export::columns::{Column, Kind, Value};
use crate::export::parquet::ParquetWriter;
use crate::output::Output;
use crate::rows::Row;
use crate::CliError;

/// The folder of each table in a dataset.
pub const FRAMES: &str = "frames";
/// See [`FRAMES`].
pub const RUNS: &str = "runs";
/// See [`FRAMES`].
pub const EPISODES: &str = "episodes";
/// See [`FRAMES`].
pub const KICKS: &str = "kicks";
/// See [`FRAMES`].
pub const EVENTS: &str = "events";

/// One log of the campaign and where it goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogEntry {
    /// The card's directory name, for a folder of cards.
    pub card: Option<String>,
    /// Run number: from the file name `RUNnnnnn.WBL`.
    pub run: u32,
    /// The log file.
    pub path: PathBuf,
}

impl LogEntry {
    /// The run's frame file, relative to the dataset. No `run=N` folder:
    /// a Hive partition beside the file's own `run` column is a conflict
    /// pyarrow's `read_table` refuses.
    #[must_use]
    pub fn frame_file(&self) -> PathBuf {
        let file = format!("RUN{:05}.parquet", self.run);
        let frames = Path::new(FRAMES);
        match &self.card {
            Some(card) => frames.join(format!("card={}", hive_value(card))).join(file),
            None => frames.join(file),
        }
    }
}

/// `value` as a Hive partition value: every byte but ASCII letters, digits
/// and `-_.~` percent-encoded (`rider=anna` is `rider%3Danna`, a newline
/// `%0A`, `%2F` is `%252F`), as readers decode it (pyarrow's default `uri`
/// segment encoding, Polars, DuckDB). A name left as it is breaks the
/// `key=value` folder (`=`), the path (`/`, newlines) or reads back as
/// another name (`%`).
fn hive_value(value: &str) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(value.len());
    for byte in value.bytes() {
        if byte.is_ascii_alphanumeric() || b"-_.~".contains(&byte) {
            out.push(char::from(byte));
        } else {
            let _ = write!(out, "%{byte:02X}");
        }
    }
    out
}

/// The run number in a log's file name (`RUN00003.WBL` is 3).
fn run_number(path: &Path) -> Option<u32> {
    let stem = path.file_stem()?.to_string_lossy().to_ascii_uppercase();
    stem.strip_prefix("RUN")?.parse().ok()
}

/// The logs of `dir`: a card (logs at its top) or a folder of cards (one
/// level of subdirectories holding logs), in name order.
///
/// # Errors
/// An unreadable directory, no logs, a log whose name carries no run
/// number, or two logs of one card with the same run number.
pub fn campaign_logs(dir: &Path) -> Result<Vec<LogEntry>, CliError> {
    let cards = cards_in(dir)?;
    let mut entries: Vec<LogEntry> = Vec::new();
    for (card, logs) in cards {
        for path in logs {
            let run = run_number(&path).ok_or_else(|| {
                CliError::file(&path, "no run number in the name (expected RUNnnnnn.WBL)")
            })?;
            let entry = LogEntry {
                card: card.clone(),
                run,
                path,
            };
            if let Some(twin) = entries
                .iter()
                .find(|e| e.frame_file() == entry.frame_file())
            {
                return Err(CliError::file(
                    &entry.path,
                    format!("the same run number as {}", crate::text::shown(&twin.path)),
                ));
            }
            entries.push(entry);
        }
    }
    Ok(entries)
}

/// A card's name (none for a card given itself) and its logs.
pub type Card = (Option<String>, Vec<PathBuf>);

/// The logs of a card (`*.WBL` at the top of `dir`: one card, no name) or
/// of a folder of cards (none at the top: each subdirectory with logs is a
/// card, named after it), cards and logs sorted by name; a second name or
/// a copy of a log is left out with a note ([`crate::inputs::distinct`]).
///
/// # Errors
/// An unreadable directory, or no log at either level.
pub fn cards_in(dir: &Path) -> Result<Vec<Card>, CliError> {
    let mut cards: Vec<Card> = Vec::new();
    let top = logs_in(dir)?;
    if top.is_empty() {
        let mut subdirs: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| CliError::file(dir, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        subdirs.sort();
        for sub in subdirs {
            let logs = logs_in(&sub)?;
            if !logs.is_empty() {
                let name = sub.file_name().map(|n| n.to_string_lossy().into_owned());
                cards.push((name, logs));
            }
        }
    } else {
        cards.push((None, top));
    }
    let all: Vec<PathBuf> = cards.iter().flat_map(|(_, logs)| logs.clone()).collect();
    let kept = crate::inputs::distinct(all);
    for (_, logs) in &mut cards {
        logs.retain(|log| kept.contains(log));
    }
    cards.retain(|(_, logs)| !logs.is_empty());
    if cards.is_empty() {
        return Err(CliError::file(
            dir,
            "no *.WBL logs here or in its subdirectories",
        ));
    }
    Ok(cards)
}

/// `err` with a file of the temporary dataset `temp` named as it would be
/// in `target` (`DATASET/frames/RUN00001.parquet: No space left on
/// device`): the temporary name means nothing to the user and is gone.
fn named_in(err: CliError, temp: &Path, target: &Path) -> CliError {
    match err {
        CliError::File { path, message } => match path.strip_prefix(temp) {
            Ok(inside) => CliError::File {
                path: target.join(inside),
                message,
            },
            Err(_) => CliError::File { path, message },
        },
        other => other,
    }
}

/// Removes the temporary datasets `.NAME.XXXXXX.tmp` in `parent` that
/// runs which are gone left behind (nobody holds their lock), with a note.
fn remove_stale(parent: &Path, name: &str) {
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let random = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|r| r.strip_suffix(".tmp"));
        if random.is_some_and(|r| r.len() == 6 && !r.contains('.')) && entry.path().is_dir() {
            crate::owner::clear_abandoned(&entry.path());
        }
    }
}

/// One run's row of `runs.parquet`.
pub struct RunsRow {
    entry: LogEntry,
    row: RunRow,
    first_utc_us: Option<i64>,
    firmware: Option<String>,
}

/// One episode's row of `episodes.parquet`.
pub struct EpisodesRow {
    entry: LogEntry,
    episode: Episode,
}

/// One kick's row of `kicks.parquet`: the values alone (a campaign of
/// card records holds many).
pub struct KicksRow {
    entry: LogEntry,
    mode: KickMode,
    source: Source,
    t_s: f64,
    amp_deg: f64,
    point: KickPoint,
    used: bool,
}

impl KicksRow {
    fn of(entry: &LogEntry, mode: KickMode, k: &CampaignKick) -> Self {
        Self {
            entry: entry.clone(),
            mode,
            source: k.source,
            t_s: k.t_s,
            amp_deg: k.amp_deg,
            point: KickPoint::from(k),
            used: false,
        }
    }

    /// A weave kick (the host's alone: the board records wobble kicks).
    fn weave(entry: &LogEntry, k: &Kick) -> Self {
        Self {
            entry: entry.clone(),
            mode: KickMode::Weave,
            source: Source::Host,
            t_s: k.t_s,
            amp_deg: k.amp_deg,
            point: KickPoint::from(k),
            used: false,
        }
    }
}

/// Marks each kick of `rows` the campaign's prediction of its mode gave
/// weight (`wobblog margin`'s defaults; `--mode weave`'s for the weave).
fn mark_used(rows: &mut [KicksRow]) {
    for mode in [KickMode::Wobble, KickMode::Weave] {
        let of_mode: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].mode == mode).collect();
        let points: Vec<KickPoint> = of_mode.iter().map(|&i| rows[i].point.clone()).collect();
        let weights = match mode {
            KickMode::Wobble => predict(&points).weights,
            KickMode::Weave => predict_weave(&points, Trend::Line).fit.weights,
        };
        for (&i, w) in of_mode.iter().zip(weights) {
            rows[i].used = w > 0.0;
        }
    }
}

/// The identifying columns every table starts with.
macro_rules! identity {
    ($t:ty) => {
        [
            Column::<$t> {
                name: "card",
                kind: Kind::Text,
                value: |r| Value::Text(r.entry.card.clone()),
            },
            Column::<$t> {
                name: "run",
                kind: Kind::Integer,
                value: |r| Value::Integer(Some(i64::from(r.entry.run))),
            },
            Column::<$t> {
                name: "log",
                kind: Kind::Text,
                value: |r| {
                    Value::Text(
                        r.entry
                            .path
                            .file_name()
                            .map(|n| n.to_string_lossy().into_owned()),
                    )
                },
            },
        ]
    };
}

/// A column of numbers of a table row type.
macro_rules! number {
    ($t:ty, $name:literal, $r:ident => $value:expr) => {
        Column::<$t> {
            name: $name,
            kind: Kind::OptNumber,
            value: |$r| Value::Number($value),
        }
    };
}

/// A column of counts of a table row type.
macro_rules! count {
    ($t:ty, $name:literal, $r:ident => $value:expr) => {
        Column::<$t> {
            name: $name,
            kind: Kind::Integer,
            value: |$r| Value::Integer(i64::try_from($value).ok()),
        }
    };
}

/// The columns of `runs.parquet`: `wobblog summary`'s, with the run's
/// identity and first UTC.
fn runs_columns() -> Vec<Column<RunsRow>> {
    let mut columns = identity!(RunsRow).to_vec();
    columns.extend([
        number!(RunsRow, "duration_s", r => Some(r.row.duration_s)),
        number!(RunsRow, "distance_m", r => Some(r.row.distance_m)),
        number!(RunsRow, "max_speed_mps", r => Some(r.row.max_speed_mps)),
        count!(RunsRow, "episodes", r => r.row.episodes),
        count!(RunsRow, "unstable_episodes", r => r.row.unstable_episodes),
        count!(RunsRow, "censored_episodes", r => r.row.censored_episodes),
        number!(RunsRow, "wobble_speed_mps", r => r.row.wobble_speed_mps),
        count!(RunsRow, "frames_lost", r => r.row.frames_lost),
        count!(RunsRow, "lost_blocks", r => r.row.lost_blocks),
        Column {
            name: "first_utc",
            kind: Kind::Utc,
            value: |r| Value::Utc(r.first_utc_us),
        },
        Column {
            name: "firmware",
            kind: Kind::Text,
            value: |r| Value::Text(r.firmware.clone()),
        },
    ]);
    columns
}

/// The columns of `kicks.parquet`: `wobblog margin`'s kick fields, the
/// mode, and whether the prediction used the kick.
fn kicks_columns() -> Vec<Column<KicksRow>> {
    let mut columns = identity!(KicksRow).to_vec();
    columns.extend([
        Column::<KicksRow> {
            name: "mode",
            kind: Kind::Label,
            value: |r| Value::Label(Some(r.mode.as_str())),
        },
        Column {
            name: "source",
            kind: Kind::Label,
            value: |r| Value::Label(Some(r.source.as_str())),
        },
        number!(KicksRow, "t_s", r => Some(r.t_s)),
        number!(KicksRow, "speed_mps", r => Some(r.point.speed_mps)),
        number!(KicksRow, "freq_hz", r => Some(r.point.freq_hz)),
        number!(KicksRow, "sigma_per_s", r => Some(r.point.sigma_per_s)),
        number!(KicksRow, "sigma_sd_per_s", r => Some(r.point.sigma_sd_per_s)),
        number!(KicksRow, "amp_deg", r => Some(r.amp_deg)),
        Column {
            name: "used",
            kind: Kind::Bool,
            value: |r| Value::Bool(Some(r.used)),
        },
    ]);
    columns
}

/// The columns of `episodes.parquet`: `wobblog wobble`'s fields.
fn episodes_columns() -> Vec<Column<EpisodesRow>> {
    let mut columns = identity!(EpisodesRow).to_vec();
    columns.extend([
        Column::<EpisodesRow> {
            name: "mode",
            kind: Kind::Label,
            value: |r| Value::Label(Some(r.episode.mode.as_str())),
        },
        number!(EpisodesRow, "onset_s", r => Some(r.episode.onset_s)),
        number!(EpisodesRow, "end_s", r => Some(r.episode.end_s)),
        number!(EpisodesRow, "peak_s", r => Some(r.episode.peak_s)),
        number!(EpisodesRow, "freq_hz", r => Some(r.episode.freq_hz)),
        number!(EpisodesRow, "sigma_per_s", r => Some(r.episode.sigma_per_s)),
        number!(EpisodesRow, "sigma_sd_per_s", r => r.episode.sigma_sd_per_s),
        number!(EpisodesRow, "peak_amp_deg", r => Some(r.episode.peak_amp_deg)),
        number!(EpisodesRow, "speed_at_onset_mps", r => Some(r.episode.speed_at_onset_mps)),
        Column {
            name: "stability",
            kind: Kind::Label,
            value: |r| {
                Value::Label(Some(match r.episode.stability {
                    Stability::Stable => "stable",
                    Stability::Unstable => "unstable",
                }))
            },
        },
        Column {
            name: "source",
            kind: Kind::Label,
            value: |r| Value::Label(Some(r.episode.source.as_str())),
        },
        Column {
            name: "censored",
            kind: Kind::Bool,
            value: |r| Value::Bool(Some(r.episode.censored)),
        },
        Column {
            name: "cut_at_start",
            kind: Kind::Label,
            value: |r| Value::Label(r.episode.cut_at_start.map(Cut::as_str)),
        },
        Column {
            name: "cut_at_end",
            kind: Kind::Label,
            value: |r| Value::Label(r.episode.cut_at_end.map(Cut::as_str)),
        },
    ]);
    columns
}

/// Writes `rows` as the one file of the table folder `dir`.
/// One event's row of `events.parquet`: what `wobblog events --json` lists.
pub struct EventsRow {
    /// Shared by the log's events: a flood of records costs no copy each.
    entry: std::sync::Arc<LogEntry>,
    event: LogEvent,
    /// UTC, µs since 1970, where the log has it.
    utc_us: Option<i64>,
}

impl EventsRow {
    /// The event's numbers: frequency (Hz), growth rate and its standard
    /// error (1/s), amplitude (deg) and speed (m/s), where its kind has them.
    fn numbers(&self) -> [Option<f64>; 5] {
        match &self.event.kind {
            EventKind::AlertOn { freq_hz, amp_deg } => {
                [Some(*freq_hz), None, None, Some(*amp_deg), None]
            }
            EventKind::Kick {
                speed_mps,
                freq_hz,
                sigma_per_s,
                amp_deg,
                sigma_se_per_s,
            } => [
                Some(*freq_hz),
                Some(*sigma_per_s),
                Some(*sigma_se_per_s),
                Some(*amp_deg),
                *speed_mps,
            ],
            EventKind::MarginEstimate(m)
            | EventKind::Approaching(m)
            | EventKind::ApproachingOff(m) => [None, None, None, None, m.speed_mps],
            _ => [None; 5],
        }
    }

    /// The details in words, as `wobblog events` prints them, for the
    /// kinds whose number columns do not hold all they say.
    fn details(&self) -> Option<String> {
        match &self.event.kind {
            EventKind::AlertOn { .. } | EventKind::AlertOff | EventKind::Kick { .. } => None,
            kind => Some(kind.describe()),
        }
    }
}

/// The columns of `events.parquet`: the time, the kind, its numbers where
/// it has them, and the details in words as `wobblog events` prints them
/// where the numbers do not say it all.
fn events_columns() -> Vec<Column<EventsRow>> {
    let mut columns = identity!(EventsRow).to_vec();
    columns.extend([
        number!(EventsRow, "t_s", r => Some(r.event.t_s)),
        Column::<EventsRow> {
            name: "utc",
            kind: Kind::Utc,
            value: |r| Value::Utc(r.utc_us),
        },
        Column {
            name: "event",
            kind: Kind::Label,
            value: |r| Value::Label(Some(r.event.kind.name())),
        },
        number!(EventsRow, "freq_hz", r => r.numbers()[0]),
        number!(EventsRow, "sigma_per_s", r => r.numbers()[1]),
        number!(EventsRow, "sigma_se_per_s", r => r.numbers()[2]),
        number!(EventsRow, "amp_deg", r => r.numbers()[3]),
        number!(EventsRow, "speed_mps", r => r.numbers()[4]),
        Column {
            name: "details",
            kind: Kind::Text,
            value: |r| Value::Text(r.details()),
        },
    ]);
    columns
}

/// The events table being written: each log's events go in as its frames
/// are decoded, so a log of millions of records never sits in memory.
struct EventsTable<'a, W: std::io::Write + Send> {
    writer: ParquetWriter<W, EventsRow>,
    path: &'a Path,
}

/// The file of the table in folder `dir`, created (the folder too).
fn table_file(dir: &Path) -> Result<(PathBuf, Output), CliError> {
    std::fs::create_dir_all(dir).map_err(|e| CliError::file(dir, e))?;
    let path = dir.join("part-0.parquet");
    let out = Output::create(&path, &[])?;
    Ok((path, out))
}

/// Finishes a table's file: the version and the columns' units as its
/// metadata.
fn finish_table<W: std::io::Write + Send, R: 'static>(
    writer: &mut ParquetWriter<W, R>,
    columns: &[Column<R>],
) -> Result<(), parquet::errors::ParquetError> {
    let mut pairs = vec![(
        "wobblog.version".to_string(),
        env!("CARGO_PKG_VERSION").to_string(),
    )];
    pairs.extend(crate::export::metadata::units(columns));
    writer.finish_with(pairs)
}

fn write_table<R: 'static>(dir: &Path, columns: &[Column<R>], rows: &[R]) -> Result<(), CliError> {
    let (path, mut out) = table_file(dir)?;
    let mut writer = ParquetWriter::new(&mut out, columns);
    rows.iter()
        .try_for_each(|r| writer.write(r))
        .and_then(|()| finish_table(&mut writer, columns))
        .map_err(|e| CliError::file(&path, e))?;
    drop(writer);
    out.commit()
}

/// What a log gave the dataset, or why it gave nothing.
pub enum Outcome<'a> {
    /// Its frames, run row and episodes are in.
    Written(&'a Ride),
    /// It could not be read; the dataset goes on without it.
    Skipped(&'a CliError),
}

/// The kicks of `ride` (read from `entry`) as `wobblog margin` takes them
/// (`--kicks best`), the weave's after them. A card record without a speed
/// takes the frames' speed after it, from `speeds` (gathered as the frames
/// were written).
fn kicks_of(entry: &LogEntry, ride: &Ride, speeds: &SpeedsAfter) -> Vec<KicksRow> {
    // A config the host refuses gives no wobble kicks, as in `margin`.
    let wobble = ride_campaign_kicks(ride, Prefer::Best, speeds).unwrap_or_default();
    let mut rows: Vec<KicksRow> = wobble
        .iter()
        .map(|k| KicksRow::of(entry, KickMode::Wobble, k))
        .collect();
    rows.extend(ride.weave_kicks.iter().map(|k| KicksRow::weave(entry, k)));
    rows
}

/// Writes one log's frame file, its events into `events`, and returns its
/// analysis and the speeds after its card records that carry none (for its
/// kicks); nothing of its frames stays on failure. A log that cannot be
/// analysed fails before anything is written (and may be skipped); one
/// whose second reading fails after its events went in fails the dataset.
fn write_log<W: std::io::Write + Send>(
    entry: &LogEntry,
    dir: &Path,
    events: &mut EventsTable<'_, W>,
) -> Result<(Ride, SpeedsAfter), CliError> {
    // Analysed first: a log that cannot be read fails before a file is made.
    let ride = Ride::load(&entry.path)?;
    let part = dir.join(entry.frame_file());
    let folder = part.parent().unwrap_or(dir);
    std::fs::create_dir_all(folder).map_err(|e| CliError::file(folder, e))?;
    let mut speeds = SpeedsAfter::for_records(&ride.summary.kick_records);
    let needs_speeds = !speeds.is_empty();
    let mut gather = |row: &Row| speeds.push(row.t_s, row.speed_mps);
    let shared = std::sync::Arc::new(entry.clone());
    let mut take = |event, utc_us| {
        let row = EventsRow {
            entry: shared.clone(),
            event,
            utc_us,
        };
        events
            .writer
            .write(&row)
            .map_err(|e| CliError::file(events.path, e))
    };
    let written = Output::create(&part, &[&entry.path]).and_then(|mut out| {
        let export = crate::cmd::decode::Export::dataset_frames(entry.run);
        let taps = Taps {
            events: Some(&mut take),
            rows: needs_speeds.then_some(&mut gather as &mut dyn FnMut(&Row)),
        };
        crate::cmd::decode::decode_with_events(&entry.path, &export, &mut out, &part, taps)?;
        out.commit()
    });
    if written.is_err() {
        // The folder only if it is empty: never data.
        let _ = std::fs::remove_dir(folder);
    }
    written.map(|()| (ride, speeds)).map_err(|e| match e {
        // Not a log to leave out: some of its events are in.
        CliError::File { path, message } if path == entry.path => CliError::Failed(format!(
            "{}: {message} (read once, not a second time; no dataset written)",
            crate::text::shown(&path)
        )),
        other => other,
    })
}

/// Writes the dataset of `entries` into `dir` (which must exist and be
/// empty); `progress` is told what became of each log. A log that cannot
/// be read is left out (and told) unless `strict`.
///
/// # Errors
/// With `strict`, the first log that cannot be read; an output that cannot
/// be written. Returns how many logs were skipped.
pub fn write_dataset(
    entries: &[LogEntry],
    dir: &Path,
    strict: bool,
    mut progress: impl FnMut(&LogEntry, Outcome<'_>),
) -> Result<usize, CliError> {
    let mut runs = Vec::new();
    let mut episodes = Vec::new();
    let mut kicks = Vec::new();
    let mut skipped = 0;
    // Events are written as each log is read.
    let (events_path, mut events_out) = table_file(&dir.join(EVENTS))?;
    let events_columns = events_columns();
    let mut events = EventsTable {
        writer: ParquetWriter::new(&mut events_out, &events_columns),
        path: &events_path,
    };
    for entry in entries {
        let (ride, speeds) = match write_log(entry, dir, &mut events) {
            Ok(ride) => ride,
            Err(e)
                if !strict
                    && matches!(e, CliError::File { ref path, .. } if path == &entry.path) =>
            {
                progress(entry, Outcome::Skipped(&e));
                skipped += 1;
                continue;
            }
            Err(e) => return Err(e),
        };
        progress(entry, Outcome::Written(&ride));
        kicks.extend(kicks_of(entry, &ride, &speeds));
        episodes.extend(ride.all_episodes().into_iter().map(|episode| EpisodesRow {
            entry: entry.clone(),
            episode,
        }));
        runs.push(RunsRow {
            entry: entry.clone(),
            row: RunRow::of(&ride),
            first_utc_us: ride.summary.first_utc_us,
            firmware: ride.summary.firmware.clone(),
        });
    }
    if runs.is_empty() {
        return Err(CliError::Failed(format!(
            "none of the {} logs could be read; no dataset written",
            entries.len()
        )));
    }
    write_table(&dir.join(RUNS), &runs_columns(), &runs)?;
    write_table(&dir.join(EPISODES), &episodes_columns(), &episodes)?;
    mark_used(&mut kicks);
    write_table(&dir.join(KICKS), &kicks_columns(), &kicks)?;
    finish_table(&mut events.writer, &events_columns)
        .map_err(|e| CliError::file(&events_path, e))?;
    drop(events);
    events_out.commit()?;
    Ok(skipped)
}

/// Builds the dataset of `entries` at `target` whole or not at all: in a
/// temporary directory beside it, renamed to `target` once complete.
///
/// # Errors
/// `target` exists already (a dataset is never merged into or replaced), or
/// any failure of [`write_dataset`]; nothing is left behind then. Returns
/// how many logs were skipped.
pub fn build(
    entries: &[LogEntry],
    target: &Path,
    strict: bool,
    progress: impl FnMut(&LogEntry, Outcome<'_>),
) -> Result<usize, CliError> {
    // A symlink counts, dangling or not: the final rename would fail on
    // it after all the work.
    if std::fs::symlink_metadata(target).is_ok() {
        return Err(CliError::file(
            target,
            "exists already; a dataset is written whole into a new directory",
        ));
    }
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = target
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    remove_stale(parent, &name);
    // Removed if a signal ends the process before it is in place; locked
    // (the lock held until the end) so no other run takes it for a leftover.
    let (temp, _lock) = crate::interrupt::make_tracked(
        || {
            crate::owner::make_held(
                || {
                    tempfile::Builder::new()
                        .prefix(&format!(".{name}."))
                        .suffix(".tmp")
                        .rand_bytes(6)
                        .tempdir_in(parent)
                },
                |dir| std::fs::File::open(dir.path()),
            )
        },
        |(dir, _)| dir.path(),
    )
    .map_err(|e| CliError::file(target, format!("cannot create the dataset: {e}")))?;
    // A non-empty directory that appeared at `target` meanwhile makes the
    // rename fail rather than be replaced.
    let result = write_dataset(entries, temp.path(), strict, progress)
        .map_err(|e| named_in(e, temp.path(), target))
        .and_then(|skipped| {
            std::fs::rename(temp.path(), target)
                .map(|()| skipped)
                .map_err(|e| {
                    CliError::file(target, format!("cannot move the dataset in place: {e}"))
                })
        });
    crate::interrupt::untrack(temp.path());
    let skipped = result?;
    // The directory moved; there is nothing left to clean up.
    let _ = temp.keep();
    Ok(skipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn partition_of(card: &str) -> PathBuf {
        LogEntry {
            card: Some(card.into()),
            run: 3,
            path: PathBuf::from("RUN00003.WBL"),
        }
        .frame_file()
    }

    #[test]
    fn a_write_error_names_the_file_in_the_dataset_not_the_temporary_one() {
        let temp = Path::new("cards/.season.a1b2c3.tmp");
        let err = CliError::file(
            &temp.join("frames/RUN00001.parquet"),
            "No space left on device",
        );
        let named = named_in(err, temp, Path::new("season"));
        assert_eq!(
            named.to_string(),
            "season/frames/RUN00001.parquet: No space left on device"
        );
        // A log's own error stays the log's.
        let log = CliError::file(Path::new("cards/RUN00001.WBL"), "bad");
        assert_eq!(
            named_in(log, temp, Path::new("season")).to_string(),
            "cards/RUN00001.WBL: bad"
        );
    }

    #[test]
    fn card_names_are_percent_encoded_in_their_folders() {
        for (card, folder) in [
            ("anna", "card=anna"),
            ("rider=anna", "card=rider%3Danna"),
            ("a\nb", "card=a%0Ab"),
            ("a%2Fb", "card=a%252Fb"),
            ("a/b c", "card=a%2Fb%20c"),
            ("Zoë", "card=Zo%C3%AB"),
        ] {
            assert_eq!(
                partition_of(card),
                Path::new("frames").join(folder).join("RUN00003.parquet"),
                "{card:?}"
            );
        }
    }
}
