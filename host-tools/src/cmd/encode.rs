//! `wobblog encode`: build a card log from a CSV, through the firmware's encoder.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use wobble_core::config::Config;
use wobble_core::detector::Detector;
use wobble_core::format::header::header_records;
use wobble_core::format::limits::SPEED_CM_S_MAX;
use wobble_core::format::{
    quantise_i16, quantise_i32, quantise_u16, BlockEncoder, FixMode, Frame, FrameStatus, GpsFix,
    LogInfo, Record, UtcSync, ACCEL_COUNTS_PER_G, EDGE_AGE_NONE, GYRO_COUNTS_PER_DPS,
    STEER_COUNTS_PER_DEG,
};

use crate::csv_input::{number_in, Cell, TimeSteps};
use crate::export::{CSV_COLUMNS, MISSING_NUMBER};
use crate::output::Output;
use crate::resample::{CsvRow, Resampler};
use crate::time::parse_iso8601_us;
use crate::CliError;

/// Arguments of `wobblog encode`.
#[derive(clap::Args)]
pub struct Args {
    /// Input CSV with a header line; columns as `wobblog decode` writes them
    /// (`t_s` required, missing channels are zero, other columns ignored).
    /// A `utc` column becomes the log's GPS sync pairs, so the decoded log
    /// has the same UTC.
    #[arg(long)]
    pub csv: PathBuf,
    /// The card log to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Accept a CSV at another rate than the log's 100 Hz (or an uneven
    /// one) and interpolate it linearly onto 100 Hz frames. Rows more than
    /// 0.1 s apart are a gap (no frame is made in it); GPS and UTC come from
    /// the row before each frame. Without this, such a CSV is an error.
    #[arg(long)]
    pub resample: bool,
    /// Run the on-board detector over the frames as the board does, with
    /// the default configuration, and store what it writes: its alert
    /// records (and the frames' alert flag) and its kick ring-down records
    /// (`wobblog events`, `wobblog margin`). The configuration goes into
    /// the header, as the board's does. A gap restarts the detector.
    #[arg(long)]
    pub detect: bool,
    /// The run number the log's header states (as the board numbers its
    /// `RUNnnnnn.WBL` files; `info`, `export` and the data set show it).
    #[arg(long, default_value_t = 0)]
    pub run: u32,
    /// Clamp a number outside what the log can store (a GPS speed of
    /// -0.01 m/s from another logger, a gyro rate beyond the range) to the
    /// nearest it can, and say how many cells of which column were clamped
    /// and by how much at most. NaN, infinities and text are still refused.
    #[arg(long)]
    pub clip: bool,
}

/// How `encode` builds the log.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Interpolate a CSV at another rate (or an uneven one) onto the log's
    /// frames.
    pub resample: bool,
    /// Run the on-board detector and store its alert and kick records.
    pub detect: bool,
    /// The run number in the header.
    pub run: u32,
    /// Clamp numbers outside what the log stores instead of refusing them.
    pub clip: bool,
}

/// The frame rate of the logs `encode` writes, as the firmware's.
const SAMPLE_RATE_HZ: u16 = 100;

/// A GPS fix is repeated at least this often while the CSV's GPS columns
/// stay the same, so decoded rows keep their fix.
const GPS_REPEAT_US: u64 = 500_000;

/// Runs `wobblog encode`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let mut output = Output::create(&args.output, &[&args.csv])?;
    let input = File::open(&args.csv).map_err(|e| CliError::file(&args.csv, e))?;
    let input = crate::csv_input::LineCap::new(input);
    let options = Options {
        resample: args.resample,
        detect: args.detect,
        run: args.run,
        clip: args.clip,
    };
    let clipped = encode_with(input, &args.csv, &mut output, &args.output, options)?;
    for line in clipped.lines(&args.csv) {
        eprintln!("wobblog: {line}");
    }
    output.commit()
}

/// Index of each known column in the CSV, if present, and of `utc`.
struct Columns([Option<usize>; CSV_COLUMNS.len()], Option<usize>);

/// The indices in [`CSV_COLUMNS`] of the GPS numbers: latitude,
/// longitude, ground speed.
const GPS_NUMBERS: [usize; 3] = [9, 10, 11];

/// The column `decode` writes UTC into.
const UTC_COLUMN: &str = "utc";

impl Columns {
    fn new(header: &csv::StringRecord) -> Self {
        let at = |name: &str| header.iter().position(|h| h.trim() == name);
        Self(CSV_COLUMNS.map(at), at(UTC_COLUMN))
    }

    /// The `utc` cell of `line`, for messages.
    fn utc_cell(&self, line: u64) -> Cell<'static> {
        Cell {
            line,
            column: self.1.unwrap_or(0) + 1,
            name: UTC_COLUMN,
        }
    }
}

/// Refuses a header naming a column the log has no place for: a misspelt
/// one (`steer` for `steer_deg`) would otherwise be silently zero.
fn refuse_unknown_columns(header: &csv::StringRecord, in_name: &Path) -> Result<(), CliError> {
    let known = |name: &str| CSV_COLUMNS.contains(&name) || name == UTC_COLUMN;
    match header.iter().map(str::trim).find(|name| !known(name)) {
        Some(name) => Err(CliError::file(
            in_name,
            format!(
                "no column {name:?} in a log; the columns are {},{UTC_COLUMN} (missing ones are zero)",
                CSV_COLUMNS.join(",")
            ),
        )),
        None => Ok(()),
    }
}

/// The sync pairs that give every row its CSV UTC back: a pair at a row
/// whenever the last pair does not already give that row's UTC, to the
/// microsecond as `decode` prints it (so a log decoded and encoded again
/// has pairs only where its clock and UTC drifted apart).
#[derive(Default)]
struct SyncWriter {
    last: Option<UtcSync>,
}

impl SyncWriter {
    /// The pair to write before the frame at `t_us` whose UTC is `utc_us`
    /// (`None`: the row has no UTC), or why the row cannot be stored.
    fn update(&mut self, t_us: u64, utc_us: Option<i64>) -> Result<Option<UtcSync>, String> {
        let Some(us) = utc_us else {
            return match self.last {
                Some(_) => Err("is empty after a row with a UTC: a log's UTC cannot stop".into()),
                None => Ok(None),
            };
        };
        let given = self.last.and_then(|s| {
            let since_us = i64::try_from(t_us.checked_sub(s.t_us)?).ok()?;
            i64::try_from(s.unix_ms)
                .ok()?
                .checked_mul(1000)?
                .checked_add(since_us)
        });
        if given == Some(us) {
            return Ok(None);
        }
        // A pair holds whole milliseconds: it sits the sub-millisecond part
        // of the row's UTC before the row. In the first millisecond since
        // boot there is no room before it, and the row's UTC is rounded to
        // the millisecond.
        let sub_ms = us.rem_euclid(1000).unsigned_abs();
        let sync = match t_us.checked_sub(sub_ms) {
            Some(at) => UtcSync {
                t_us: at,
                unix_ms: u64::try_from(us.div_euclid(1000)).unwrap_or(u64::MAX),
            },
            None => UtcSync {
                t_us,
                unix_ms: u64::try_from((us + 500).div_euclid(1000)).unwrap_or(u64::MAX),
            },
        };
        if !sync.is_valid() {
            return Err("is outside the years a GPS states (2000 to 2099)".into());
        }
        self.last = Some(sync);
        Ok(Some(sync))
    }
}

/// Encodes CSV rows from `input` into a log written to `output`; with
/// `resample`, rows at any rate are interpolated onto the log's frames.
pub fn encode(
    input: impl std::io::Read,
    in_name: &Path,
    output: impl Write,
    out_name: &Path,
    resample: bool,
) -> Result<(), CliError> {
    let options = Options {
        resample,
        ..Options::default()
    };
    encode_with(input, in_name, output, out_name, options).map(|_| ())
}

/// [`encode`] with every option.
pub fn encode_with(
    input: impl std::io::Read,
    in_name: &Path,
    output: impl Write,
    out_name: &Path,
    options: Options,
) -> Result<Clipped, CliError> {
    let resample = options.resample;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(input);
    let header = reader
        .headers()
        .map_err(|e| CliError::file(in_name, e))?
        .clone();
    refuse_unknown_columns(&header, in_name)?;
    let columns = Columns::new(&header);
    if columns.0[0].is_none() {
        return Err(CliError::file(
            in_name,
            "no `t_s` column in the header line",
        ));
    }
    let mut log = LogWriter {
        encoder: BlockEncoder::new(),
        output,
        out_name,
        in_name,
        columns: &columns,
        syncs: SyncWriter::default(),
        last_gps: None,
        frames: 0,
        line: 0,
        detector: options.detect.then(OnBoard::new).transpose()?,
        run: options.run,
    };
    let mut record = csv::StringRecord::new();
    let mut steps = if resample {
        TimeSteps::any_rate()
    } else {
        TimeSteps::new(f64::from(SAMPLE_RATE_HZ))
    };
    let mut resampler = Resampler::new(1_000_000 / u64::from(SAMPLE_RATE_HZ));
    let mut clip = options.clip.then(Clipped::default);
    while reader
        .read_record(&mut record)
        .map_err(|e| CliError::file(in_name, e))?
    {
        let line = record.position().map_or(0, |p| p.line());
        let row = parse_row(&columns, &record, (in_name, line), &mut clip)?;
        let t_col = columns.0[0].unwrap_or(0);
        steps.step(row.frame.t_us as f64 / 1e6, line).map_err(|e| {
            let cell = Cell {
                line,
                column: t_col + 1,
                name: "t_s",
            };
            cell.error(in_name, e)
        })?;
        log.line = line;
        if resample {
            resampler.push(row, &mut |r: &CsvRow| log.store(r))?;
        } else {
            log.store(&row)?;
        }
    }
    resampler.finish(&mut |r: &CsvRow| log.store(r))?;
    log.finish()?;
    Ok(clip.unwrap_or_default())
}

/// The cells `--clip` clamped, per column: how many and the largest
/// change.
#[derive(Debug, Default, PartialEq)]
pub struct Clipped(Vec<(&'static str, usize, f64)>);

impl Clipped {
    fn add(&mut self, column: &'static str, by: f64) {
        match self.0.iter_mut().find(|c| c.0 == column) {
            Some(c) => {
                c.1 += 1;
                c.2 = c.2.max(by);
            }
            None => self.0.push((column, 1, by)),
        }
    }

    /// What was clamped, a line per column, about the CSV `path`.
    #[must_use]
    pub fn lines(&self, path: &Path) -> Vec<String> {
        self.0
            .iter()
            .map(|(column, n, by)| {
                format!(
                    "{}: --clip: {} of `{column}` outside what the log stores, clamped \
                     (by {} at most)",
                    crate::text::shown(path),
                    crate::words::plural(*n, "cell"),
                    // Six decimals: the CSV's own, not the subtraction's.
                    (by * 1e6).round() / 1e6
                )
            })
            .collect()
    }
}

/// Writes frames, GPS fixes and sync pairs into a log.
struct LogWriter<'a, W> {
    encoder: BlockEncoder,
    output: W,
    out_name: &'a Path,
    in_name: &'a Path,
    columns: &'a Columns,
    syncs: SyncWriter,
    last_gps: Option<(u64, GpsFix)>,
    frames: u64,
    /// The CSV line being read, for messages.
    line: u64,
    /// The on-board detector, with `--detect`.
    detector: Option<OnBoard>,
    /// The run number the header states.
    run: u32,
}

/// The on-board detector as the board's sampler runs it on the frames.
struct OnBoard {
    config: Config,
    detector: Detector,
    /// Time of the last frame it saw, µs.
    last_us: Option<u64>,
}

impl OnBoard {
    fn new() -> Result<Self, CliError> {
        let config = Config::default();
        let detector = config
            .detector()
            .map_err(|e| CliError::Failed(format!("the default detector: {e}")))?;
        Ok(Self {
            config,
            detector,
            last_us: None,
        })
    }

    /// The configuration lines the board writes into the header.
    fn header_lines(&self) -> Vec<String> {
        let mut text = String::new();
        // Writing into a String cannot fail.
        let _ = self.config.write_lines(&mut text);
        text.lines().map(String::from).collect()
    }

    /// Feeds `frame` (as the card stores it) and sets its alert flag; the
    /// records the board would write before it (an alert switching, a
    /// measured kick) go to `out`. A gap of more than 1.5 frame periods
    /// restarts the detector, as `wobblog detect` does.
    fn step(&mut self, frame: &mut Frame, out: &mut Vec<Record<'static>>) {
        let period_us = 1_000_000 / u64::from(SAMPLE_RATE_HZ);
        if self
            .last_us
            .is_some_and(|last| frame.t_us.saturating_sub(last) > period_us * 3 / 2)
        {
            self.detector.reset();
        }
        self.last_us = Some(frame.t_us);
        if let Some(ev) = self
            .detector
            .push(frame.steer_deg(), Some(frame.speed_mps()))
        {
            out.push(Record::Alert(ev.to_record(frame.t_us)));
        }
        if let Some(kick) = self.detector.take_kick() {
            let rate_hz = self.detector.config().sample_rate_hz;
            out.push(Record::Kick(kick.to_record(frame.t_us, rate_hz)));
        }
        if self.detector.alert_active() {
            frame.status.0 |= FrameStatus::ALERT;
        }
    }
}

impl<W: Write> LogWriter<'_, W> {
    /// Writes `record`, and the block it completes if any.
    fn push(&mut self, record: &Record<'_>) -> Result<(), CliError> {
        let block = self
            .encoder
            .push(record)
            .map_err(|e| CliError::file(self.in_name, format!("line {}: {e}", self.line)))?;
        write_block(&mut self.output, self.out_name, block)
    }

    /// Stores one frame of the log, with the header before the first.
    fn store(&mut self, row: &CsvRow) -> Result<(), CliError> {
        if self.frames == 0 {
            let info = LogInfo {
                t_us: row.frame.t_us,
                firmware: concat!("wobblog-encode ", env!("CARGO_PKG_VERSION")),
                device_id: [0; 12],
                sample_rate_hz: SAMPLE_RATE_HZ,
                run: self.run,
            };
            let lines = self.detector.as_ref().map(OnBoard::header_lines);
            let lines = lines.iter().flatten().map(String::as_str);
            for rec in header_records(info, lines) {
                self.push(&rec)?;
            }
        }
        self.frames += 1;
        // Before the frame, so the pair is in force for it.
        let sync = self
            .syncs
            .update(row.frame.t_us, row.utc_us)
            .map_err(|e| self.columns.utc_cell(self.line).error(self.in_name, e))?;
        if let Some(sync) = sync {
            self.push(&Record::UtcSync(sync))?;
        }
        let mut frame = row.frame;
        if let Some(detector) = &mut self.detector {
            let mut records = Vec::new();
            detector.step(&mut frame, &mut records);
            for record in &records {
                self.push(record)?;
            }
        }
        self.push(&Record::Frame(frame))?;
        if let Some(fix) = gps_update(&self.last_gps, row.gps, row.frame.t_us) {
            self.push(&Record::Gps(fix))?;
            self.last_gps = Some((row.frame.t_us, fix));
        }
        Ok(())
    }

    /// Writes the last block and flushes; a CSV without rows is an error.
    fn finish(mut self) -> Result<(), CliError> {
        if self.frames == 0 {
            return Err(CliError::file(self.in_name, "no data rows"));
        }
        let block = self.encoder.finish();
        write_block(&mut self.output, self.out_name, block)?;
        self.output
            .flush()
            .map_err(|e| CliError::file(self.out_name, e))
    }
}

fn write_block(
    output: &mut impl Write,
    name: &Path,
    block: Option<&[u8; 512]>,
) -> Result<(), CliError> {
    block.map_or(Ok(()), |b| {
        output.write_all(b).map_err(|e| CliError::file(name, e))
    })
}

/// One CSV row as a frame; with `clip`, numbers outside what the log
/// stores are clamped and counted there.
fn parse_row(
    columns: &Columns,
    record: &csv::StringRecord,
    (path, line): (&Path, u64),
    clip: &mut Option<Clipped>,
) -> Result<CsvRow, CliError> {
    let clip = std::cell::RefCell::new(clip);
    let cell = |i: usize, c: usize| Cell {
        line,
        column: c + 1,
        name: CSV_COLUMNS[i],
    };
    // `decode` writes a missing GPS number as NaN: for those columns it is
    // no value (elsewhere NaN is refused as a value no log stores).
    let field = |i: usize| {
        columns.0[i]
            .and_then(|c| Some((c, record.get(c)?)))
            .filter(|(_, f)| !(f.is_empty() || GPS_NUMBERS.contains(&i) && *f == MISSING_NUMBER))
    };
    // A missing column is zero (or no GPS); an empty cell of a column that
    // is there is refused (it would be stored as a zero nobody measured); a
    // value that is given must be one the log can store.
    let number = |i: usize, range: (f64, f64), unit: &str| -> Result<f64, CliError> {
        match (columns.0[i], field(i)) {
            (None, _) => Ok(0.0),
            (Some(c), None) => Err(cell(i, c).error(
                path,
                "is empty: give a value, or leave the column out (then it is zero)",
            )),
            (Some(c), Some((_, text))) => {
                match (number_in(text, range, unit), &mut **clip.borrow_mut()) {
                    (Err(e), Some(clipped)) => {
                        // Out of range but a finite number: clamped, counted.
                        match text.parse::<f64>().ok().filter(|v| v.is_finite()) {
                            Some(v) => {
                                let kept = v.clamp(range.0, range.1);
                                clipped.add(CSV_COLUMNS[i], (v - kept).abs());
                                Ok(kept)
                            }
                            None => Err(cell(i, c).error(path, e)),
                        }
                    }
                    (result, _) => result.map_err(|e| cell(i, c).error(path, e)),
                }
            }
        }
    };
    let counts = |scale: f32| {
        let k = f64::from(scale);
        (f64::from(i16::MIN) / k, f64::from(i16::MAX) / k)
    };
    if field(0).is_none() {
        let c = columns.0[0].unwrap_or(0);
        return Err(cell(0, c).error(path, "is empty"));
    }
    // Microseconds since boot in a u64, with room to spare.
    let t_s = number(0, (0.0, 1.8e13), " s")?;
    let t_us = (t_s * 1e6).round() as u64;
    let q = |i: usize, scale: f32, unit: &str| {
        number(i, counts(scale), unit).map(|v| quantise_i16(v, scale))
    };
    let frame = Frame {
        t_us,
        accel: [
            q(1, ACCEL_COUNTS_PER_G, " g")?,
            q(2, ACCEL_COUNTS_PER_G, " g")?,
            q(3, ACCEL_COUNTS_PER_G, " g")?,
        ],
        gyro: [
            q(4, GYRO_COUNTS_PER_DPS, " deg/s")?,
            q(5, GYRO_COUNTS_PER_DPS, " deg/s")?,
            q(6, GYRO_COUNTS_PER_DPS, " deg/s")?,
        ],
        steer_cdeg: q(7, STEER_COUNTS_PER_DEG, " deg")?,
        wheel_count: 0,
        wheel_edge_age_us: EDGE_AGE_NONE,
        speed_mm_s: quantise_u16(number(8, (0.0, 65.535), " m/s")?, 1000.0),
        status: Default::default(),
    };
    let gps = match (field(9), field(10)) {
        (Some(_), Some(_)) => {
            let fix =
                match field(12) {
                    Some((_, "3d")) => FixMode::Fix3d,
                    Some((_, "2d")) => FixMode::Fix2d,
                    // A position without a fix is not one: `decode` writes
                    // none, and the log would keep it but no reader show it.
                    Some((c, "none")) => {
                        return Err(cell(12, c).error(
                            path,
                            "is none but a position is given: a position needs 2d or 3d \
                             (leave gps_lat_deg and gps_lon_deg empty without a fix)",
                        ))
                    }
                    Some((c, other)) => {
                        return Err(cell(12, c)
                            .error(path, format!("must be 2d, 3d or none, not {other:?}")))
                    }
                    None => {
                        let c = columns.0[12].unwrap_or(record.len());
                        return Err(cell(12, c)
                            .error(path, "must be 2d, 3d or none when a position is given"));
                    }
                };
            Some(GpsFix {
                t_us,
                lat_e7: Some(quantise_i32(number(9, (-90.0, 90.0), " deg")?, 1e7)),
                lon_e7: Some(quantise_i32(number(10, (-180.0, 180.0), " deg")?, 1e7)),
                speed_cm_s: field(11)
                    .map(|_| number(11, (0.0, f64::from(SPEED_CM_S_MAX) / 100.0), " m/s"))
                    .transpose()?
                    .map(|v| quantise_u16(v, 100.0)),
                fix,
                ..GpsFix::default()
            })
        }
        (None, None) => None,
        (Some((c, _)), None) | (None, Some((c, _))) => {
            let i = if field(9).is_some() { 9 } else { 10 };
            return Err(cell(i, c).error(
                path,
                "is given without its partner: gps_lat_deg and gps_lon_deg go together",
            ));
        }
    };
    let utc_us = match columns.1.and_then(|c| record.get(c)) {
        Some("") | None => None,
        Some(text) => Some(parse_iso8601_us(text).ok_or_else(|| {
            columns.utc_cell(line).error(
                path,
                format!("is not a UTC time like 2020-03-18T13:28:20.600Z: {text:?}"),
            )
        })?),
    };
    Ok(CsvRow { frame, gps, utc_us })
}

/// The GPS record to write at `t_us`, if any: when the fix changes, when it
/// has been unchanged for [`GPS_REPEAT_US`], and a no-fix record when it ends.
fn gps_update(last: &Option<(u64, GpsFix)>, now: Option<GpsFix>, t_us: u64) -> Option<GpsFix> {
    let same = |a: &GpsFix, b: &GpsFix| {
        (a.lat_e7, a.lon_e7, a.speed_cm_s, a.fix) == (b.lat_e7, b.lon_e7, b.speed_cm_s, b.fix)
    };
    match (last, now) {
        (Some((t, prev)), Some(fix)) if same(prev, &fix) && t_us < t + GPS_REPEAT_US => None,
        (_, Some(fix)) => Some(fix),
        (Some((_, prev)), None) if prev.fix != FixMode::None => Some(GpsFix {
            t_us,
            ..GpsFix::default()
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2020-03-18T10:00:01.000Z, µs since 1970.
    const US: i64 = 1_584_525_601_000_000;

    #[test]
    fn a_pair_is_written_only_where_the_last_one_is_wrong() {
        let mut syncs = SyncWriter::default();
        assert_eq!(syncs.update(0, None), Ok(None));
        let first = syncs.update(1_000_000, Some(US)).unwrap().unwrap();
        assert_eq!((first.t_us, first.unix_ms), (1_000_000, (US / 1000) as u64));
        // 10 ms later the pair gives 10 ms more, to the microsecond.
        assert_eq!(syncs.update(1_010_000, Some(US + 10_000)), Ok(None));
        assert_eq!(syncs.update(1_009_999, Some(US + 9_999)), Ok(None));
        // A clock 250 µs off: a new pair, 250 µs before this frame, holding
        // the whole millisecond.
        let next = syncs.update(1_020_000, Some(US + 20_250)).unwrap().unwrap();
        assert_eq!(
            (next.t_us, next.unix_ms),
            (1_019_750, (US / 1000) as u64 + 20)
        );
        assert_eq!(syncs.update(1_030_000, Some(US + 30_250)), Ok(None));
        // In the first millisecond since boot there is no room before the
        // frame: the nearest millisecond.
        let mut early = SyncWriter::default();
        let pair = early.update(400, Some(US + 600)).unwrap().unwrap();
        assert_eq!((pair.t_us, pair.unix_ms), (400, (US / 1000) as u64 + 1));
    }

    #[test]
    fn utc_cannot_stop_or_leave_the_gps_years() {
        let mut syncs = SyncWriter::default();
        assert!(syncs
            .update(0, Some(0))
            .unwrap_err()
            .contains("2000 to 2099"));
        assert!(syncs.update(0, Some(4_102_444_800_000_000)).is_err());
        assert!(syncs
            .update(0, Some(4_102_444_799_999_000))
            .unwrap()
            .is_some());
        assert!(syncs
            .update(10_000, None)
            .unwrap_err()
            .contains("cannot stop"));
    }

    #[test]
    fn the_utc_cell_is_named_by_its_column() {
        let header = csv::StringRecord::from(vec!["t_s", "steer_deg", "utc"]);
        let cell = Columns::new(&header).utc_cell(7);
        assert_eq!((cell.line, cell.column, cell.name), (7, 3, "utc"));
    }

    fn encoded(text: &str) -> Result<(), String> {
        encode(
            text.as_bytes(),
            Path::new("in.csv"),
            std::io::sink(),
            Path::new("out"),
            false,
        )
        .map_err(|e| e.to_string())
    }

    #[test]
    fn an_empty_cell_is_refused_but_a_missing_column_is_zero() {
        let e = encoded("t_s,steer_deg,speed_mps\n0,1,4\n0.01,,4\n").unwrap_err();
        assert!(e.contains("line 3, column 2: `steer_deg` is empty"), "{e}");
        encoded("t_s,steer_deg\n0,1\n0.01,2\n").unwrap();
    }

    #[test]
    fn a_position_without_a_fix_is_refused() {
        let head = "t_s,steer_deg,gps_lat_deg,gps_lon_deg,gps_fix\n";
        let e = encoded(&format!("{head}0,1,52.1,6.9,none\n")).unwrap_err();
        assert!(
            e.contains("column 5: `gps_fix` is none but a position"),
            "{e}"
        );
        encoded(&format!("{head}0,1,52.1,6.9,3d\n0.01,1,,,\n")).unwrap();
    }

    #[test]
    fn a_day_the_month_lacks_and_a_leap_second_off_its_day_are_refused() {
        let head = "t_s,steer_deg,utc\n";
        for utc in ["2026-02-30T10:00:00.000Z", "2026-02-14T23:59:60.000Z"] {
            let e = encoded(&format!("{head}0,1,{utc}\n")).unwrap_err();
            assert!(e.contains("is not a UTC time"), "{e}");
        }
        encoded(&format!("{head}0,1,2016-12-31T23:59:60.000Z\n")).unwrap();
    }
}
