//! `wobblog detect`: replay a card log (with the settings it was recorded
//! with) or a steering-angle CSV (with the defaults) through the on-board
//! wobble detector, the firmware's own code, and print every alert change.

use std::io::{self, Read};
use std::path::{Path, PathBuf};

use wobble_core::config::{Config, FAULT_REJECTED, FAULT_UNKNOWN_KEY};
use wobble_core::detector::{AlertEvent, Detector, Kick, MarginEvent, MarginWarning};
use wobble_core::format::{Event, FaultSource, MarginRecord, MarginState};

use crate::csv_input::{number_in, Cell, Step, TimeSteps};
use crate::events::{LogEvent, Margin};
use crate::reader::read_log;
use crate::rows::{Row, RowAssembler};
use crate::CliError;

const AFTER_HELP: &str = "\
Input: a card log, replayed with the detector settings of its header (what
`wobblog config LOG` prints), re-tuned with --set; or a CSV with a header naming at least `t_s` (seconds) and `steer_deg`
(degrees), optionally `speed_mps` (m/s; empty cells mean unknown), sampled at
100 Hz. Other columns are ignored, so `wobblog decode` output works as is.
With the speed, the detector cancels the wheel-rotation harmonics as the
firmware does; without it, it runs on the steering alone.

A gap in t_s longer than 1.5 sample periods restarts the detector (an alert
that was on is reported off at the last sample before the gap, and a note goes
to stderr). Samples closer than 7.5 ms, or three gaps of the same length in a
row, are an error: the CSV is not at 100 Hz.

Output with --json: one JSON object per line for each alert change and each
kick whose ring-down the detector measured, in time order (a kick's time is
the kick's; speed_mps is null when the speed is unknown),
  {\"t_s\": 12.4, \"event\": \"kick\", \"speed_mps\": 3.1, \"freq_hz\": 6.2, \"sigma_per_s\": -1.8, \"amp_deg\": 1.5, \"sigma_se_per_s\": 0.04}
  {\"t_s\": 17.12, \"event\": \"alert_on\", \"freq_hz\": 6.4, \"amp_deg\": 0.8}
  {\"t_s\": 18.9, \"event\": \"alert_off\"}
and the on-board margin warning's records, the running estimate of the
wobble speed from the kicks so far (after each kick that gives one) and the
warning switching on and off (the speed within alert.margin_mps of the
estimate's lower bound, and clear of it again),
  {\"t_s\":40.2,\"event\":\"margin_estimate\",\"speed_mps\":3.2,\"wobble_speed_mps\":4.1,\"ci95_mps\":[3.8,4.5],\"kicks\":7}
  {\"t_s\":52.6,\"event\":\"approaching\",\"speed_mps\":3.3,\"wobble_speed_mps\":4.1,\"ci95_mps\":[3.8,4.5],\"kicks\":8}
  {\"t_s\":70.1,\"event\":\"approaching_off\", ...}
and nothing else (sigma_per_s: growth rate of the ring, negative when it
decays; sigma_se_per_s: its standard error from the fit; ci95_mps[1] null
when open). Without --json: a table with one line per change, kick or
margin record (time in seconds, event, frequency in Hz and zero-to-peak
steering amplitude in degrees, for a kick its growth rate and speed, for a
margin record the estimate in words), then one summary line.

Exit codes: 0 ok (alerts or not), 1 unreadable or malformed input (the message
names the file, the line and what is wrong), 2 usage error.";

/// Arguments of `wobblog detect`.
#[derive(clap::Args)]
#[command(after_help = AFTER_HELP)]
#[command(group = clap::ArgGroup::new("input").required(true).args(["log", "csv"]))]
pub struct Args {
    /// A card log (`RUNnnnnn.WBL`) to replay with the detector settings in
    /// its header.
    pub log: Option<PathBuf>,
    /// The CSV to replay (`t_s,steer_deg[,speed_mps]` at 100 Hz), with the
    /// firmware's default settings.
    #[arg(long, value_name = "IN")]
    pub csv: Option<PathBuf>,
    /// Re-tune a setting for this replay (`detector.amp_on_deg=0.6`); the
    /// keys of `CONFIG.TXT`, applied after the log's own. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// One JSON object per line for each alert change, nothing else.
    #[arg(long)]
    pub json: bool,
}

/// One alert change of a replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Change {
    /// Time of the sample that caused it, seconds (the CSV's `t_s`).
    pub t_s: f64,
    /// What changed.
    pub event: AlertEvent,
}

/// A kick's ring-down measured during a replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KickAt {
    /// Time of the kick, seconds (the detector reports it later).
    pub t_s: f64,
    /// The measurement.
    pub kick: Kick,
}

/// A margin record of a replay, as the board writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarginAt {
    /// Time of the sample that made it, seconds.
    pub t_s: f64,
    /// The record (speeds quantised as on the card).
    pub record: MarginRecord,
}

/// What a replay saw besides the changes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    /// Alert changes in time order.
    pub changes: Vec<Change>,
    /// Measured kicks, in the order they were reported.
    pub kicks: Vec<KickAt>,
    /// The margin warning's records, in time order.
    pub margins: Vec<MarginAt>,
    /// Rows replayed.
    pub samples: u64,
    /// First and last `t_s`.
    pub span_s: Option<(f64, f64)>,
    /// Whether the CSV has a `speed_mps` column.
    pub has_speed: bool,
    /// Lines (or frames) at which a time gap restarted the detector: the
    /// first [`GAP_NOTES_MAX`] of them.
    pub restarts: Vec<u64>,
    /// Time gaps that restarted the detector, all of them.
    pub restart_count: u64,
}

/// Times a log can hold, s (microseconds since boot in a u64, with room).
const T_S_RANGE: (f64, f64) = (0.0, 1.8e13);
/// Steering angles a log stores, deg (an i16 of 0.01 deg).
const STEER_DEG_RANGE: (f64, f64) = (-327.68, 327.67);
/// Speeds a log stores, m/s (a u16 of mm/s).
const SPEED_MPS_RANGE: (f64, f64) = (0.0, 65.535);
/// Time gaps noted one by one on stderr; the rest are counted.
const GAP_NOTES_MAX: usize = 20;

/// Replays CSV text from `input` through a fresh detector as `config` sets it
/// up (its detector settings on its wheel). `path` only names the input in
/// errors.
///
/// # Errors
/// [`CliError::File`] naming `path`, the line and the problem.
pub fn replay(path: &Path, input: impl Read, config: &Config) -> Result<Replay, CliError> {
    let cfg_rate_hz = config.detector.sample_rate_hz;
    let mut det = config
        .detector()
        .map_err(|e| CliError::Usage(format!("detector: {e}")))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(input);
    let at_line = |line: u64, msg: String| CliError::file(path, format!("line {line}: {msg}"));
    let headers = reader.headers().map_err(|e| csv_error(path, &e))?.clone();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let (Some(t_col), Some(steer_col)) = (column("t_s"), column("steer_deg")) else {
        let missing: Vec<&str> = ["t_s", "steer_deg"]
            .into_iter()
            .filter(|c| column(c).is_none())
            .collect();
        return Err(at_line(
            1,
            format!("no `{}` column in the header", missing.join("` or `")),
        ));
    };
    let speed_col = column("speed_mps");
    let mut margin = MarginWarning::new(config.alert.margin_mps);
    let mut out = Replay {
        has_speed: speed_col.is_some(),
        ..Replay::default()
    };
    let mut record = csv::StringRecord::new();
    let mut last: Option<(f64, u64)> = None;
    let mut steps = TimeSteps::new(f64::from(cfg_rate_hz));
    loop {
        match reader.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_error(path, &e)),
        }
        let line = record.position().map_or(0, csv::Position::line);
        if record.iter().all(str::is_empty) {
            continue;
        }
        let number = |col: usize, name: &str, range, unit| -> Result<Option<f64>, CliError> {
            let cell = Cell {
                line,
                column: col + 1,
                name,
            };
            match record.get(col) {
                None | Some("") => Ok(None),
                Some(text) => number_in(text, range, unit)
                    .map(Some)
                    .map_err(|e| cell.error(path, e)),
            }
        };
        // The ranges a log stores (as `encode` checks them).
        let t_s = number(t_col, "t_s", T_S_RANGE, " s")?
            .ok_or_else(|| at_line(line, "`t_s` is empty".into()))?;
        let steer = number(steer_col, "steer_deg", STEER_DEG_RANGE, " deg")?
            .ok_or_else(|| at_line(line, "`steer_deg` is empty".into()))?;
        let speed = match speed_col {
            Some(c) => number(c, "speed_mps", SPEED_MPS_RANGE, " m/s")?,
            None => None,
        };
        let step = steps.step(t_s, line).map_err(|e| {
            let cell = Cell {
                line,
                column: t_col + 1,
                name: "t_s",
            };
            cell.error(path, e)
        })?;
        let restart = matches!(step, Step::Gap(_)) && last.is_some();
        out.push(&mut det, &mut margin, restart, line, t_s, steer, speed);
        last = Some((t_s, line));
    }
    Ok(out)
}

impl Replay {
    /// Feeds one sample to `det`, restarting it first if `restart` (a gap
    /// before the sample at `place`, a line or frame number): an alert
    /// still on is reported off at the previous sample. Its kicks go to
    /// `margin`, which, as on the board, keeps the ride's kicks across
    /// gaps (the board never restarts it).
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        det: &mut Detector,
        margin: &mut MarginWarning,
        restart: bool,
        place: u64,
        t_s: f64,
        steer_deg: f64,
        speed_mps: Option<f64>,
    ) {
        if let (true, Some((_, t_prev))) = (restart, self.span_s) {
            if det.alert_active() {
                self.changes.push(Change {
                    t_s: t_prev,
                    event: AlertEvent::Off,
                });
            }
            det.reset();
            if self.restarts.len() < GAP_NOTES_MAX {
                self.restarts.push(place);
            }
            self.restart_count += 1;
        }
        self.samples += 1;
        self.span_s = Some((self.span_s.map_or(t_s, |s| s.0), t_s));
        #[allow(clippy::cast_possible_truncation)] // degrees and m/s fit f32
        if let Some(event) = det.push(steer_deg as f32, speed_mps.map(|v| v as f32)) {
            self.changes.push(Change { t_s, event });
        }
        // Times are checked against `T_S_RANGE`: whole µs fit a u64.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let now_us = (t_s * 1e6).round() as u64;
        #[allow(clippy::cast_possible_truncation)]
        let speed = speed_mps.map(|v| v as f32);
        let record = |state, estimate: Option<_>| MarginAt {
            t_s,
            record: MarginRecord::new(now_us, state, speed, estimate.as_ref()),
        };
        if let Some(kick) = det.take_kick() {
            let ago_s = f64::from(kick.samples_ago) / f64::from(det.config().sample_rate_hz);
            self.kicks.push(KickAt {
                t_s: t_s - ago_s,
                kick,
            });
            if let Some(e) = margin.add_kick(&kick) {
                self.margins.push(record(MarginState::Estimate, Some(e)));
            }
        }
        if let Some(ev) = margin.update(now_us, speed) {
            let state = match ev {
                MarginEvent::Approaching => MarginState::Approaching,
                MarginEvent::Clear => MarginState::Clear,
            };
            self.margins.push(record(state, margin.estimate()));
        }
    }
}

/// Replays the frames of the card log at `path` through a fresh detector as
/// `config` sets it up. A gap of more than 1.5 frame periods (lost blocks,
/// dropouts) or a time jump restarts the detector; `restarts` holds the
/// frame numbers (from 0) where it did.
///
/// # Errors
/// The log cannot be read, or `config` does not make a detector.
pub fn replay_log(path: &Path, config: &Config) -> Result<Replay, CliError> {
    let mut det = config
        .detector()
        .map_err(|e| CliError::Usage(format!("detector: {e}")))?;
    let period_s = 1.0 / f64::from(config.detector.sample_rate_hz).max(1.0);
    let mut margin = MarginWarning::new(config.alert.margin_mps);
    let mut out = Replay {
        has_speed: true,
        ..Replay::default()
    };
    let mut rows = RowAssembler::new();
    let mut feed = |row: &Row| {
        let restart = out
            .span_s
            .is_some_and(|(_, last)| !(0.0..=1.5 * period_s).contains(&(row.t_s - last)));
        let place = out.samples;
        out.push(
            &mut det,
            &mut margin,
            restart,
            place,
            row.t_s,
            row.steer_deg,
            Some(row.speed_mps),
        );
    };
    read_log(path, |event| {
        if let Event::Record(record) = event {
            rows.push(&record, &mut feed);
        }
    })?;
    rows.finish(&mut feed);
    Ok(out)
}

/// The configuration a log was recorded with (its header's `CONFIG.TXT`
/// lines, the defaults where it has none), re-tuned by `set` lines
/// (`key=value`, applied after the header's).
///
/// The header's lines the parser would skip (a bad key or value) are left
/// out first: the parser keeps only the first few faults with their line
/// numbers, and a header full of them must not hide a `set` line's.
///
/// # Errors
/// A `set` line the configuration does not accept, as a usage error.
pub fn log_config(header_lines: &[String], set: &[String]) -> Result<Config, CliError> {
    let usable = header_lines.iter().filter(|line| {
        Config::parse(line.as_bytes())
            .faults
            .first()
            .iter()
            .all(|f| f.code == FAULT_REJECTED)
    });
    let usable: Vec<&String> = usable.collect();
    let text: String = usable
        .iter()
        .copied()
        .chain(set)
        .map(|l| format!("{l}\n"))
        .collect();
    let loaded = Config::parse(text.as_bytes());
    let first_set_line = usable.len() + 1;
    let bad: Vec<String> = loaded
        .faults
        .first()
        .iter()
        .filter(|f| usize::from(f.line) >= first_set_line || f.line == 0)
        .map(|f| {
            let what = crate::codes::fault_meaning(FaultSource::Config, f.code);
            match set.get(usize::from(f.line).wrapping_sub(first_set_line)) {
                Some(line) if f.code == FAULT_UNKNOWN_KEY => {
                    format!("--set {line}: {what}; {}", key_hint(line))
                }
                Some(line) => format!("--set {line}: {what}"),
                None => format!("--set: {what}"),
            }
        })
        .collect();
    if !bad.is_empty() {
        return Err(CliError::Usage(bad.join("; ")));
    }
    Ok(loaded.config)
}

/// The configuration key closest to the one of `line` (`key=value`), or
/// the list of keys, as `CONFIG.TXT` and `wobblog config` name them.
fn key_hint(line: &str) -> String {
    let mut text = String::new();
    // Writing to a String cannot fail.
    let _ = Config::default().write_lines(&mut text);
    let known: Vec<&str> = text.lines().filter_map(|l| l.split('=').next()).collect();
    let key = line.split('=').next().unwrap_or(line).trim();
    crate::words::suggest(key, &known, "keys")
}

/// The circumference of the wheel a log was recorded with, m: its config
/// lines' `wheel.circumference_m` (the default where they do not set it).
pub fn wheel_circumference_m(header_lines: &[String]) -> Result<f64, CliError> {
    Ok(f64::from(
        log_config(header_lines, &[])?.wheel.circumference_m,
    ))
}

fn csv_error(path: &Path, e: &csv::Error) -> CliError {
    let line = e.position().map(csv::Position::line);
    let what = match e.kind() {
        csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".to_owned(),
        csv::ErrorKind::Io(io) => io.to_string(),
        _ => e.to_string(),
    };
    match line {
        Some(l) => CliError::file(path, format!("line {l}: {what}")),
        None => CliError::file(path, what),
    }
}

/// Rounds for printing (`decimals` places).
fn round(x: f64, decimals: i32) -> f64 {
    let k = 10f64.powi(decimals);
    (x * k).round() / k
}

/// The JSON line of one change.
#[must_use]
pub fn json_line(c: &Change) -> String {
    // serde_json prints finite f64s as valid JSON numbers; inputs are finite.
    let num = |x: f64| serde_json::to_string(&x).unwrap_or_else(|_| "null".into());
    match c.event {
        AlertEvent::On { freq_hz, amp_deg } => format!(
            "{{\"t_s\": {}, \"event\": \"alert_on\", \"freq_hz\": {}, \"amp_deg\": {}}}",
            num(round(c.t_s, 3)),
            num(round(f64::from(freq_hz), 2)),
            num(round(f64::from(amp_deg), 2)),
        ),
        AlertEvent::Off => format!(
            "{{\"t_s\": {}, \"event\": \"alert_off\"}}",
            num(round(c.t_s, 3))
        ),
    }
}

/// The JSON line of one measured kick.
#[must_use]
pub fn kick_json_line(k: &KickAt) -> String {
    let num = |x: f64| serde_json::to_string(&x).unwrap_or_else(|_| "null".into());
    let m = &k.kick;
    format!(
        "{{\"t_s\": {}, \"event\": \"kick\", \"speed_mps\": {}, \"freq_hz\": {}, \"sigma_per_s\": {}, \"amp_deg\": {}, \"sigma_se_per_s\": {}}}",
        num(round(k.t_s, 3)),
        m.speed_mps
            .map_or("null".into(), |v| num(round(f64::from(v), 2))),
        num(round(f64::from(m.freq_hz), 2)),
        num(round(f64::from(m.sigma_per_s), 3)),
        num(round(f64::from(m.amp_deg), 2)),
        num(round(f64::from(m.sigma_se_per_s), 3)),
    )
}

/// The JSON line of one margin record: the `wobblog events` object.
#[must_use]
pub fn margin_json_line(m: &MarginAt) -> Option<String> {
    let event = LogEvent {
        t_s: round(m.t_s, 3),
        kind: Margin::event(&m.record)?,
    };
    serde_json::to_string(&event).ok()
}

/// One line of the report.
enum Item<'a> {
    Change(&'a Change),
    Kick(&'a KickAt),
    Margin(&'a MarginAt),
}

/// Alert changes, kicks and margin records, each with its time, in time
/// order (a kick is reported after later samples, so the lists
/// interleave).
fn in_time_order(r: &Replay) -> Vec<(f64, Item<'_>)> {
    let mut all: Vec<_> = r
        .changes
        .iter()
        .map(|c| (c.t_s, Item::Change(c)))
        .chain(r.kicks.iter().map(|k| (k.t_s, Item::Kick(k))))
        .chain(r.margins.iter().map(|m| (m.t_s, Item::Margin(m))))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all
}

/// The human-readable report.
#[must_use]
pub fn table(r: &Replay) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    if !r.changes.is_empty() || !r.kicks.is_empty() || !r.margins.is_empty() {
        let _ = writeln!(
            s,
            "{:>10}  {:<9}  {:>7}  {:>7}  {:>11}  {:>9}",
            "t_s", "event", "freq_hz", "amp_deg", "sigma_per_s", "speed_mps"
        );
        for (_, item) in in_time_order(r) {
            let c = match item {
                Item::Change(c) => c,
                Item::Margin(m) => {
                    if let Some(kind) = Margin::event(&m.record) {
                        let _ = writeln!(
                            s,
                            "{:>10.2}  {:<9}  {}",
                            m.t_s,
                            kind.name(),
                            kind.describe()
                        );
                    }
                    continue;
                }
                Item::Kick(k) => {
                    let m = &k.kick;
                    let speed = m.speed_mps.map_or("-".into(), |v| format!("{v:.2}"));
                    let _ = writeln!(
                        s,
                        "{:>10.2}  {:<9}  {:>7.2}  {:>7.2}  {:>11}  {:>9}",
                        k.t_s,
                        "kick",
                        m.freq_hz,
                        m.amp_deg,
                        format!("{:.2}+-{:.2}", m.sigma_per_s, m.sigma_se_per_s),
                        speed
                    );
                    continue;
                }
            };
            match c.event {
                AlertEvent::On { freq_hz, amp_deg } => {
                    let _ = writeln!(
                        s,
                        "{:>10.2}  {:<9}  {:>7.2}  {:>7.2}",
                        c.t_s, "alert_on", freq_hz, amp_deg
                    );
                }
                AlertEvent::Off => {
                    let _ = writeln!(s, "{:>10.2}  {:<9}", c.t_s, "alert_off");
                }
            }
        }
    }
    let duration = r.span_s.map_or(0.0, |(a, b)| b - a);
    let ons = r
        .changes
        .iter()
        .filter(|c| matches!(c.event, AlertEvent::On { .. }))
        .count();
    let _ = write!(
        s,
        "{} over {duration:.2} s ({} samples, {})",
        match ons {
            0 => "no alerts".to_owned(),
            1 => "1 alert".to_owned(),
            n => format!("{n} alerts"),
        },
        r.samples,
        if r.has_speed {
            "with speed"
        } else {
            "steering only"
        }
    );
    if !r.kicks.is_empty() {
        let _ = write!(
            s,
            ", {} measured",
            crate::words::plural(r.kicks.len(), "kick")
        );
    }
    let warnings = r
        .margins
        .iter()
        .filter(|m| m.record.state == MarginState::Approaching)
        .count();
    if warnings > 0 {
        let _ = write!(
            s,
            ", {} approaching the wobble speed",
            crate::words::plural(warnings, "margin warning")
        );
    }
    if r.restart_count > 0 {
        let _ = write!(s, ", {} restarts at time gaps", r.restart_count);
    }
    s.push('\n');
    s
}

/// Runs `wobblog detect`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let named: Vec<&Path> = args
        .log
        .iter()
        .chain(&args.csv)
        .map(PathBuf::as_path)
        .collect();
    let stdout = crate::output::Output::stdout(&named)?;
    let (r, input, place) = match (&args.log, &args.csv) {
        (Some(log), _) => {
            let header = crate::cmd::config::read_header(log)?;
            if header.config.is_empty() {
                eprintln!(
                    "wobblog: {}: note: no configuration in the header; the defaults are used",
                    crate::text::shown(log)
                );
            }
            let config = log_config(&header.config, &args.set)?;
            (replay_log(log, &config)?, log, "frame")
        }
        (None, Some(csv)) => {
            let config = log_config(&[], &args.set)?;
            let file = std::fs::File::open(csv).map_err(|e| CliError::file(csv, e))?;
            let input = crate::csv_input::LineCap::new(io::BufReader::new(file));
            (replay(csv, input, &config)?, csv, "line")
        }
        (None, None) => return Err(CliError::Usage("give a LOG or --csv IN".into())),
    };
    let shown = crate::text::shown(input);
    for at in r.restarts.iter().take(GAP_NOTES_MAX) {
        eprintln!("wobblog: {shown}: {place} {at}: time gap; detector restarted");
    }
    if r.restart_count > GAP_NOTES_MAX as u64 {
        eprintln!(
            "wobblog: {shown}: {} more time gaps; the detector restarted at each",
            r.restart_count - GAP_NOTES_MAX as u64
        );
    }
    let text = if args.json {
        let mut s = String::new();
        for (_, item) in in_time_order(&r) {
            let line = match item {
                Item::Change(c) => json_line(c),
                Item::Kick(k) => kick_json_line(k),
                Item::Margin(m) => match margin_json_line(m) {
                    Some(line) => line,
                    None => continue,
                },
            };
            s.push_str(&line);
            s.push('\n');
        }
        s
    } else {
        table(&r)
    };
    crate::cmd::logs::print(stdout, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_text(text: &str) -> Result<Replay, CliError> {
        replay(Path::new("x.csv"), text.as_bytes(), &Config::default())
    }

    fn message(e: CliError) -> String {
        e.to_string()
    }

    #[test]
    fn json_lines_match_the_documented_shape() {
        let on = Change {
            t_s: 17.12,
            event: AlertEvent::On {
                freq_hz: 6.4012,
                amp_deg: 0.8049,
            },
        };
        assert_eq!(
            json_line(&on),
            r#"{"t_s": 17.12, "event": "alert_on", "freq_hz": 6.4, "amp_deg": 0.8}"#
        );
        let off = Change {
            t_s: 18.9,
            event: AlertEvent::Off,
        };
        assert_eq!(json_line(&off), r#"{"t_s": 18.9, "event": "alert_off"}"#);
    }

    #[test]
    fn header_problems_name_line_one() {
        let m = message(run_text("time,steer\n0,1\n").unwrap_err());
        assert!(
            m.contains("x.csv") && m.contains("line 1") && m.contains("t_s"),
            "{m}"
        );
    }

    #[test]
    fn bad_values_name_their_line() {
        let m = message(run_text("t_s,steer_deg\n0.00,1\n0.01,abc\n").unwrap_err());
        assert!(
            m.contains("line 3") && m.contains("steer_deg") && m.contains("abc"),
            "{m}"
        );
        let m = message(run_text("t_s,steer_deg\n0.00,1\n0.01,NaN\n").unwrap_err());
        assert!(m.contains("line 3"), "{m}");
        let m = message(run_text("t_s,steer_deg\n0.01,1\n0.01,1\n").unwrap_err());
        assert!(m.contains("line 3") && m.contains("after"), "{m}");
        let m = message(run_text("t_s,steer_deg\n0.000,1\n0.001,1\n").unwrap_err());
        assert!(m.contains("100 Hz"), "{m}");
        let m = message(run_text("t_s,steer_deg,speed_mps\n0.00,1,x\n").unwrap_err());
        assert!(m.contains("line 2") && m.contains("speed_mps"), "{m}");
    }

    #[test]
    fn empty_speed_cells_are_unknown_and_extra_columns_ignored() {
        let r = run_text("ax_g,t_s,steer_deg,speed_mps,gps_fix\n0,0.00,1,,none\n0,0.01,1,4.0,3d\n")
            .unwrap();
        assert_eq!(r.samples, 2);
        assert!(r.has_speed);
    }

    #[test]
    fn header_only_is_no_alerts() {
        let r = run_text("t_s,steer_deg\n").unwrap();
        assert_eq!(r.samples, 0);
        assert!(table(&r).starts_with("no alerts over 0.00 s (0 samples"));
    }

    #[test]
    fn a_gap_restarts_and_closes_an_open_alert() {
        let mut text = String::from("t_s,steer_deg\n");
        for i in 0..600 {
            let t = f64::from(i) / 100.0;
            let env = (0.02 * (2.0 * t).exp()).min(3.0);
            text.push_str(&format!(
                "{t:.2},{:.3}\n",
                env * (std::f64::consts::TAU * 6.5 * t).sin()
            ));
        }
        text.push_str("20.00,0\n");
        let r = run_text(&text).unwrap();
        assert_eq!((r.restarts.clone(), r.restart_count), (vec![602], 1));
        assert!(matches!(r.changes[0].event, AlertEvent::On { .. }));
        assert_eq!(
            r.changes.last().map(|c| (c.t_s, c.event)),
            Some((5.99, AlertEvent::Off))
        );
    }

    #[test]
    fn values_a_log_cannot_hold_are_refused_with_line_and_column() {
        for (row, column) in [
            ("0.01,1e300,4", "column 2: `steer_deg` is 1000"),
            ("0.01,1,-1", "column 3: `speed_mps` is -1,"),
            ("-0.01,1,4", "column 1: `t_s` is -0.01,"),
        ] {
            let text = format!("t_s,steer_deg,speed_mps\n0,0,4\n{row}\n");
            let e = message(run_text(&text).unwrap_err());
            assert!(e.contains("line 3") && e.contains(column), "{e}");
        }
    }

    #[test]
    fn time_gaps_are_all_counted_but_only_the_first_kept() {
        let mut text = String::from("t_s,steer_deg\n");
        for i in 0..200 {
            text.push_str(&format!("{},0\n{},0\n", f64::from(i), f64::from(i) + 0.01));
        }
        let r = run_text(&text).unwrap();
        assert_eq!(r.restart_count, 199);
        assert_eq!(r.restarts.len(), GAP_NOTES_MAX);
        assert!(table(&r).contains("199 restarts"));
    }
}
