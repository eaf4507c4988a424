//! `wobblog decode`: one row per 100 Hz frame, as CSV, JSON lines or Parquet.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use crate::events::{EventConverter, EventWalk, LogEvent};
use crate::export::columns::{self, Column};
use crate::export::derived::Deriver;
use crate::export::{Format, LogMetadata, RowWriter};
use crate::losses::Losses;
use crate::output::Output;
use crate::reader::read_log;
use crate::rows::{Row, RowAssembler};
use crate::time::{utc_ms_at, SyncPair, TimeWindow, WindowArgs};
use crate::CliError;
use wobble_core::format::{Event, GpsFix, Record};

/// The columns of a decoded row with their units, for `--help` and the
/// man page (`columns::COLUMNS` in this order; a test holds them together).
pub const COLUMNS_HELP: &str = "\
Columns (units in the names):
  t_s            time since boot, s
  ax_g ay_g az_g acceleration, g (1 g = 9.80665 m/s2)
  gx_dps gy_dps gz_dps
                 angular rate, deg/s
  steer_deg      steering angle, deg
  speed_mps      wheel speed, m/s
  gps_lat_deg    GPS latitude, deg (without a fix: NaN in CSV, null in
                 JSON lines and Parquet)
  gps_lon_deg    GPS longitude, deg
  gps_speed_mps  GPS ground speed, m/s
  gps_fix        none, 2d or 3d (empty or null without a fix)
  utc            UTC, ISO 8601 to the microsecond (through the GPS sync pairs;
                 empty or null before the first)";

/// Arguments of `wobblog decode`.
#[derive(clap::Args)]
#[command(after_help = COLUMNS_HELP)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// Output format; by default the `-o` file's name gives it (`.csv`,
    /// `.tsv`, `.jsonl`/`.ndjson`, `.parquet`/`.pq`, `.mcap`; `.gz` after a
    /// text one compresses it), else CSV; an unknown extension is refused.
    /// Parquet and MCAP are binary: they go to the `-o` file, or to
    /// standard output only when that is redirected.
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// CSV field delimiter: one character, or `tab` (a `.tsv` name's
    /// default). Default: a comma.
    #[arg(long, value_name = "CHAR", value_parser = crate::export::parse_delimiter)]
    pub delimiter: Option<u8>,
    /// Output file; standard output if absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Only these columns, in this order (comma-separated names, e.g.
    /// `t_s,steer_deg,speed_mps,utc`). In MCAP, `/sensors` carries only
    /// these fields and is left out when none is named, and `/gps` is
    /// written when a GPS column is named.
    #[arg(long, value_name = "NAMES")]
    pub columns: Option<String>,
    /// The time window (`--from`, `--to`).
    #[command(flatten)]
    pub window: WindowArgs,
}

/// What an export writes: format, columns and time window.
#[derive(Clone)]
pub struct Export {
    /// Output format.
    pub format: Format,
    /// CSV field delimiter.
    pub delimiter: u8,
    /// Columns, in order.
    pub columns: Vec<Column>,
    /// Rows inside this window only.
    pub window: TimeWindow,
    /// The run number every row carries ([`Row::run`]), if any.
    pub run: Option<u32>,
}

impl Export {
    /// Every column of every row.
    #[must_use]
    pub fn all(format: Format) -> Self {
        Self {
            format,
            delimiter: b',',
            columns: columns::COLUMNS.to_vec(),
            window: TimeWindow::default(),
            run: None,
        }
    }

    /// Every column of every row as Parquet, after a `run` column saying
    /// `run` in each row: a dataset's frame file.
    #[must_use]
    pub fn dataset_frames(run: u32) -> Self {
        let mut columns = vec![columns::RUN_COLUMN];
        columns.extend(columns::COLUMNS);
        Self {
            columns,
            run: Some(run),
            ..Self::all(Format::Parquet)
        }
    }
}

/// Runs `wobblog decode`.
pub fn run(args: &Args) -> Result<(), CliError> {
    // One run's frames into one output: a folder is refused with its logs
    // (`export` writes every run of a card as one dataset).
    crate::cmd::logs::one_log(
        &args.log,
        "decode",
        "decode them one by one, or `wobblog export` for every run of a card as one dataset",
    )?;
    let resolved = Format::resolve(args.format, args.output.as_deref(), args.delimiter)?;
    let export = Export {
        format: resolved.format,
        delimiter: resolved.delimiter,
        columns: columns::select(args.columns.as_deref()).map_err(CliError::Usage)?,
        window: args.window.window(),
        run: None,
    };
    export.window.check_order(&args.log)?;
    if export.format == Format::Mcap && args.columns.is_some() {
        say_mcap_homes(&export.columns)?;
    }
    let binary = matches!(export.format, Format::Parquet | Format::Mcap);
    if binary && args.output.is_none() && std::io::stdout().is_terminal() {
        return Err(CliError::Usage(format!(
            "{} output is binary: give -o FILE or redirect standard output",
            export.format.name()
        )));
    }
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.log])?;
    let name = out.name().to_path_buf();
    let decoded = if resolved.gzip {
        let mut gz = flate2::write::GzEncoder::new(&mut out, flate2::Compression::default());
        decode_to(&args.log, &export, &mut gz, &name).and_then(|losses| {
            gz.try_finish()
                .map(|()| losses)
                .map_err(|e| CliError::file(&name, e))
        })
    } else {
        decode_to(&args.log, &export, &mut out, &name)
    };
    let losses = match decoded {
        Err(_) if out.pipe_closed() => return Err(CliError::PipeClosed),
        result => result?,
    };
    out.commit()?;
    for line in crate::cmd::logs::warnings(&losses) {
        eprintln!(
            "wobblog: {}: warning: {line}",
            crate::text::shown(&args.log)
        );
    }
    Ok(())
}

/// Says where each chosen column that is not a sensor field goes in MCAP,
/// and which have no home there.
///
/// # Errors
/// No chosen column is a field of a message (`t_s,utc` alone): the file
/// would hold no message.
fn say_mcap_homes(columns: &[Column]) -> Result<(), CliError> {
    let carried = |name: &str| {
        SENSOR_OR_GPS.contains(&crate::export::mcap::home_of(name).unwrap_or_default())
    };
    if !columns.iter().any(|c| carried(c.name)) {
        return Err(CliError::Usage(
            "--columns: none is a field of an MCAP message (t_s and utc are every message's \
             times); choose a sensor or GPS column too"
                .into(),
        ));
    }
    for column in columns {
        match crate::export::mcap::home_of(column.name) {
            Some(crate::export::mcap::SENSORS_TOPIC) => {}
            Some(home) => eprintln!("wobblog: --columns {}: in MCAP it is {home}", column.name),
            None => eprintln!(
                "wobblog: warning: --columns {}: MCAP has no field for it; left out",
                column.name
            ),
        }
    }
    Ok(())
}

/// The homes of [`crate::export::mcap::home_of`] that are message fields.
const SENSOR_OR_GPS: [&str; 2] = [
    crate::export::mcap::SENSORS_TOPIC,
    crate::export::mcap::GPS_HOME,
];

/// Decodes `log` into `out`; returns what could not be recovered.
pub fn decode_to(
    log: &Path,
    export: &Export,
    out: impl Write + Send,
    out_name: &Path,
) -> Result<Losses, CliError> {
    decode_with_events(log, export, out, out_name, Taps::default())
}

/// Takes a log's events in time order with their UTC (µs since 1970), as
/// `wobblog events` lists them.
pub type EventTaker<'a> = &'a mut dyn FnMut(LogEvent, Option<i64>) -> Result<(), CliError>;

/// What else a decoding hands on as it reads the log, so that one reading
/// serves several outputs (a dataset's frames, events and kicks).
#[derive(Default)]
pub struct Taps<'a> {
    /// Takes the log's events; its first error ends the decoding and is
    /// returned.
    pub events: Option<EventTaker<'a>>,
    /// Sees every row as assembled, before any window.
    pub rows: Option<&'a mut dyn FnMut(&Row)>,
}

/// [`decode_to`], handing `taps` what they take as the log is read.
///
/// # Errors
/// The log cannot be read, `out` fails, or the events' taker does.
pub fn decode_with_events(
    log: &Path,
    export: &Export,
    out: impl Write + Send,
    out_name: &Path,
    taps: Taps<'_>,
) -> Result<Losses, CliError> {
    let Taps {
        events: mut events_to,
        rows: mut rows_seen,
    } = taps;
    let mut walk = EventWalk::default();
    let mut event_error: Option<CliError> = None;
    let mut sink = WindowedSink {
        writer: RowWriter::new(export.format, export.columns.clone(), export.delimiter, out),
        window: export.window,
        failure: None,
        sync: Vec::new(),
        rows_kept: 0,
        span_s: None,
        has_utc: false,
        run: export.run,
    };
    let mut rows = RowAssembler::new();
    let mut losses = Losses::default();
    let mut meta = LogMetadata::default();
    // Fixes and events have messages of their own only in MCAP.
    let mut events = (export.format == Format::Mcap).then(EventConverter::new);
    if events.is_some() {
        // MCAP log times are UTC from the first row on, placed through the
        // first sync pair: find it before writing.
        if let Some((t_us, unix_ms)) = first_sync_pair(log)? {
            sink.sync_pair(t_us, unix_ms);
        }
    }
    let log_name = log
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let names: Vec<&str> = export.columns.iter().map(|c| c.name).collect();
    // Made at the first frame, when the header has given the frame rate.
    let mut deriver: Option<Option<Deriver>> = None;
    let mut rows_out = |row: &Row, meta: &LogMetadata, sink: &mut WindowedSink<_>| {
        if let Some(seen) = rows_seen.as_mut() {
            seen(row);
        }
        let fs_hz = f64::from(meta.sample_rate_hz.unwrap_or(100).max(1));
        match deriver.get_or_insert_with(|| Deriver::for_columns(&names, fs_hz)) {
            Some(d) => d.push(row, &mut |r: &Row| sink.row(r)),
            None => sink.row(row),
        }
    };
    read_log(log, |event| {
        losses.observe(&event);
        meta.observe(&event);
        if let (Some(take), None) = (events_to.as_mut(), &event_error) {
            event_error = walk.observe(&event, &mut |e, utc, _| take(e, utc)).err();
        }
        if let Some(e) = events.as_mut().and_then(|c| c.convert(&event)) {
            sink.event(&e, &log_name);
        }
        if let Event::Record(record) = event {
            match (&events, &record) {
                (Some(_), Record::Gps(fix)) => sink.gps(fix),
                (Some(_), Record::UtcSync(pair)) => {
                    if let Ok(ms) = i64::try_from(pair.unix_ms) {
                        sink.sync = vec![(pair.t_us as f64 / 1e6, ms)];
                    }
                    sink.sync_pair(pair.t_us, pair.unix_ms);
                }
                _ => {}
            }
            sink.has_utc |= matches!(record, Record::UtcSync(_));
            rows.push(&record, &mut |row: &Row| rows_out(row, &meta, &mut sink));
        }
    })?;
    rows.finish(&mut |row: &Row| rows_out(row, &meta, &mut sink));
    if let (Some(take), None) = (events_to.as_mut(), &event_error) {
        event_error = walk.finish(&mut |e, utc, _| take(e, utc)).err();
    }
    if let Some(e) = event_error {
        return Err(e);
    }
    if let Some(Some(d)) = &mut deriver {
        d.finish(&mut |r: &Row| sink.row(r));
    }
    if sink.rows_kept == 0 && !export.window.is_all() {
        // Nothing is written: an empty file would pass for a result.
        return Err(export
            .window
            .selects_nothing(log, "frames", sink.span_s, sink.has_utc));
    }
    let WindowedSink {
        mut writer,
        failure,
        ..
    } = sink;
    match failure.map_or_else(|| writer.finish(&meta), Err) {
        // The reader went away (`wobblog decode LOG | head`): not a failure.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(losses),
        Err(e) => Err(CliError::file(out_name, e)),
        Ok(()) => Ok(losses),
    }
}

/// A writer that keeps what falls in the window and remembers the first
/// write failure (the decoder's callbacks cannot return one).
struct WindowedSink<W: Write + Send> {
    writer: RowWriter<W>,
    window: TimeWindow,
    failure: Option<std::io::Error>,
    /// The latest sync pair, which places events in UTC.
    sync: Vec<SyncPair>,
    /// Rows inside the window.
    rows_kept: u64,
    /// First and last row time, s since boot.
    span_s: Option<(f64, f64)>,
    /// Whether the log has a sync pair.
    has_utc: bool,
    /// The run number every row carries, if any.
    run: Option<u32>,
}

impl<W: Write + Send> WindowedSink<W> {
    fn keep(&mut self, inside: bool, write: impl FnOnce(&mut RowWriter<W>) -> std::io::Result<()>) {
        if inside && self.failure.is_none() {
            self.failure = write(&mut self.writer).err();
        }
    }

    fn row(&mut self, row: &Row) {
        let inside =
            self.window.is_all() || self.window.contains(row.t_s, row.utc_us.map(|u| u / 1000));
        self.span_s = Some(self.span_s.map_or((row.t_s, row.t_s), |(a, b)| {
            (a.min(row.t_s), b.max(row.t_s))
        }));
        self.rows_kept += u64::from(inside);
        match self.run {
            Some(run) => {
                let row = Row {
                    run: Some(run),
                    ..*row
                };
                self.keep(inside, |w| w.write(&row));
            }
            None => self.keep(inside, |w| w.write(row)),
        }
    }

    fn gps(&mut self, fix: &GpsFix) {
        let utc_ms = fix.utc.and_then(|u| i64::try_from(u.unix_ms()).ok());
        let inside = self.window.contains(fix.t_us as f64 / 1e6, utc_ms);
        self.keep(inside, |w| w.gps(fix));
    }

    fn event(&mut self, event: &LogEvent, log_name: &str) {
        let inside = self
            .window
            .contains(event.t_s, utc_ms_at(&self.sync, event.t_s));
        self.keep(inside, |w| w.event(event, log_name));
    }

    fn sync_pair(&mut self, t_us: u64, unix_ms: u64) {
        self.keep(true, |w| w.sync(t_us, unix_ms));
    }
}

/// The log's first GPS sync pair (µs since boot, ms since 1970), reading
/// only up to it.
fn first_sync_pair(log: &Path) -> Result<Option<(u64, u64)>, CliError> {
    let found = crate::reader::read_log_try(log, |event| match event {
        Event::Record(Record::UtcSync(pair)) => Err((pair.t_us, pair.unix_ms)),
        _ => Ok(()),
    })?;
    Ok(found.err())
}
