//! `wobblog events`: alerts, markers, faults, dropouts and damage of a log,
//! in time order, listed as the log is read.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::cmd::logs::one_log;
use crate::events::{EventWalk, LogEvent};
use crate::output::Output;
use crate::reader::read_log_try;
use crate::time::{iso8601_unix_us, utc_text_at, SyncPair};
use crate::CliError;

/// Arguments of `wobblog events`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// `--json` (or `--format jsonl`) for JSON instead of text.
    #[command(flatten)]
    pub output: crate::cmd::logs::JsonArgs,
    /// Also list what the host measures in the frames: each wobble episode
    /// and weave ring-down as `wobblog wobble` finds it (`episode` events at
    /// their onset, with the mode). A second reading of the log.
    #[arg(long)]
    pub episodes: bool,
}

/// Runs `wobblog events`.
pub fn run(args: &Args) -> Result<(), CliError> {
    // One run's timeline: its times are seconds since that run's boot and
    // its JSON lines name no log, so the runs of a folder would read as one
    // jumbled listing. A folder is refused with its logs listed; `summary`
    // gives every run's episodes and losses side by side.
    one_log(
        &args.log,
        "events",
        "list them one by one, or `wobblog summary` for every run's episodes and losses",
    )?;
    let json = args.output.is_json()?;
    let mut out = Output::stdout(&[&args.log])?;
    let host = if args.episodes {
        let mut all: Vec<LogEvent> = crate::analysis::Ride::load(&args.log)?
            .all_episodes()
            .iter()
            .map(LogEvent::of_episode)
            .collect();
        all.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        all
    } else {
        Vec::new()
    };
    match list(&args.log, json, host, &mut out)? {
        Ok(()) => out.commit(),
        Err(e) => Err(out.error(e)),
    }
}

/// Writes the events of the log at `path` to `out`, with `host` (events of
/// the host's own measurement, in time order) among them, as a table (time,
/// kind, details; then their number) or as JSON lines.
///
/// # Errors
/// The log cannot be read (the outer error) or `out` failed (the inner).
pub fn list(
    path: &Path,
    json: bool,
    host: Vec<LogEvent>,
    out: impl Write,
) -> Result<std::io::Result<()>, CliError> {
    let mut listing = Listing {
        out,
        json,
        count: 0,
    };
    let mut host = host.into_iter().peekable();
    // The host's events have no UTC of their own: the latest pair the log
    // had read by then places them, as the frames are placed.
    let mut visit = |e: LogEvent, utc_us: Option<i64>, pairs: &[SyncPair]| {
        while let Some(h) = host.next_if(|h| h.t_s < e.t_s) {
            listing.event(&h, utc_text_at(pairs, h.t_s))?;
        }
        listing.event(&e, utc_us.and_then(iso8601_unix_us))
    };
    let mut walk = EventWalk::default();
    let walked = read_log_try(path, |event| walk.observe(&event, &mut visit))?;
    Ok(walked
        .and_then(|()| walk.finish(&mut visit))
        .and_then(|()| {
            for h in host {
                listing.event(&h, utc_text_at(walk.pairs(), h.t_s))?;
            }
            listing.finish()
        }))
}

/// Hands the events of the log at `path` to `visit` in time order, holding
/// only the few that may still move ([`TimeOrder`]), each with its UTC (µs
/// since 1970) through the sync pairs read so far, as `decode`'s `utc`
/// column places a frame. An error from `visit` ends the walk and is the
/// inner result.
///
/// # Errors
/// The log cannot be read.
pub fn walk<E>(
    path: &Path,
    mut visit: impl FnMut(LogEvent, Option<i64>) -> Result<(), E>,
) -> Result<Result<(), E>, CliError> {
    let mut visit = |e, utc_us, _: &[SyncPair]| visit(e, utc_us);
    let mut walk = EventWalk::default();
    let walked = read_log_try(path, |event| walk.observe(&event, &mut visit))?;
    Ok(walked.and_then(|()| walk.finish(&mut visit)))
}

/// One event of the JSON lines: its time since boot, UTC, kind and fields.
#[derive(serde::Serialize)]
pub struct JsonEvent<'a> {
    /// Time since boot, s.
    pub t_s: f64,
    /// ISO 8601, when the log has UTC there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub utc: Option<String>,
    /// What happened, with its fields.
    #[serde(flatten)]
    pub kind: &'a crate::events::EventKind,
}

/// The events as a table or as JSON lines.
struct Listing<W: Write> {
    out: W,
    json: bool,
    count: usize,
}

impl<W: Write> Listing<W> {
    fn event(&mut self, e: &LogEvent, utc: Option<String>) -> std::io::Result<()> {
        self.count += 1;
        if self.json {
            let line = JsonEvent {
                t_s: e.t_s,
                utc,
                kind: &e.kind,
            };
            serde_json::to_writer(&mut self.out, &line)?;
            return self.out.write_all(b"\n");
        }
        if self.count == 1 {
            writeln!(
                self.out,
                "{:>10}  {:<24}  {:<11}  details",
                "t_s", "utc", "event"
            )?;
        }
        let line = format!(
            "{:>10.3}  {:<24}  {:<11}  {}",
            e.t_s,
            utc.as_deref().unwrap_or("-"),
            e.kind.name(),
            e.kind.describe()
        );
        writeln!(self.out, "{}", line.trim_end())
    }

    fn finish(&mut self) -> std::io::Result<()> {
        if !self.json {
            writeln!(self.out, "{}", crate::words::plural(self.count, "event"))?;
        }
        Ok(())
    }
}
