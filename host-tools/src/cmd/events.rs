//! `wobblog events`: alerts, markers, faults, dropouts and damage of a log,
//! in time order, listed as the log is read.

use std::io::Write;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use crate::events::{EventConverter, LogEvent, TimeOrder};
use crate::output::Output;
use crate::reader::{read_log_until, CHUNK_LEN};
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
    let mut failed = None;
    read_log_until(path, CHUNK_LEN, |event| {
        if let Some(e) = converter.convert(&event) {
            order.push(e, &mut |e| hand(&mut visit, &mut failed, e));
        }
        // After a failed write (a closed pipe) the rest is not read.
        if failed.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })?;
    order.finish(&mut |e| hand(&mut visit, &mut failed, e));
    Ok(failed.map_or(Ok(()), Err))
}

/// Hands `e` to `visit` unless an earlier visit failed; keeps the failure.
fn hand<E>(visit: &mut impl FnMut(LogEvent) -> Result<(), E>, failed: &mut Option<E>, e: LogEvent) {
    if failed.is_none() {
        *failed = visit(e).err();
    }
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
