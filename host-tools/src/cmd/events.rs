//! `wobblog events`: alerts, markers, faults, dropouts and damage of a log,
//! in time order, listed as the log is read.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::events::{EventConverter, LogEvent, TimeOrder};
use crate::output::Output;
use crate::reader::read_log_try;
use crate::CliError;

/// Arguments of `wobblog events`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// One JSON object per line (`{"t_s": .., "event": "alert_on", ..}`)
    /// instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `wobblog events`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let mut out = Output::stdout();
    match list(&args.log, args.json, &mut out)? {
        Ok(()) => out.commit(),
        Err(e) => Err(out.error(e)),
    }
}

/// Writes the events of the log at `path` to `out`, as a table (time,
/// kind, details; then their number) or as JSON lines.
///
/// # Errors
/// The log cannot be read (the outer error) or `out` failed (the inner).
pub fn list(path: &Path, json: bool, out: impl Write) -> Result<std::io::Result<()>, CliError> {
    let mut listing = Listing {
        out,
        json,
        count: 0,
    };
    let walked = walk(path, |e| listing.event(&e))?;
    Ok(walked.and_then(|()| listing.finish()))
}

/// Hands the events of the log at `path` to `visit` in time order, holding
/// only the few that may still move ([`TimeOrder`]). An error from `visit`
/// ends the walk and is the inner result.
///
/// # Errors
/// The log cannot be read.
pub fn walk<E>(
    path: &Path,
    mut visit: impl FnMut(LogEvent) -> Result<(), E>,
) -> Result<Result<(), E>, CliError> {
    let mut converter = EventConverter::new();
    let mut order = TimeOrder::new();
    let walked = read_log_try(path, |event| match converter.convert(&event) {
        Some(e) => order.push(e, &mut visit),
        None => Ok(()),
    })?;
    Ok(walked.and_then(|()| order.finish(&mut visit)))
}

/// The events as a table or as JSON lines.
struct Listing<W: Write> {
    out: W,
    json: bool,
    count: usize,
}

impl<W: Write> Listing<W> {
    fn event(&mut self, e: &LogEvent) -> std::io::Result<()> {
        self.count += 1;
        if self.json {
            serde_json::to_writer(&mut self.out, e)?;
            return self.out.write_all(b"\n");
        }
        if self.count == 1 {
            writeln!(self.out, "{:>10}  {:<11}  details", "t_s", "event")?;
        }
        let line = format!(
            "{:>10.3}  {:<11}  {}",
            e.t_s,
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
