//! `wobblog events`: alerts, markers, faults, dropouts and damage of a log,
//! in time order.

use std::path::{Path, PathBuf};

use crate::cmd::logs::print_stdout;
use crate::events::{EventCollector, LogEvent};
use crate::reader::read_log;
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
    let events = collect(&args.log)?;
    let text = if args.json {
        json_lines(&events).map_err(|e| CliError::file(&args.log, e))?
    } else {
        table(&events)
    };
    print_stdout(&text)
}

/// The events of the log at `path`, in time order.
pub fn collect(path: &Path) -> Result<Vec<LogEvent>, CliError> {
    let mut collector = EventCollector::new();
    read_log(path, |event| collector.observe(&event))?;
    Ok(collector.finish())
}

/// One JSON object per event and line.
pub fn json_lines(events: &[LogEvent]) -> serde_json::Result<String> {
    let mut text = String::new();
    for e in events {
        text.push_str(&serde_json::to_string(e)?);
        text.push('\n');
    }
    Ok(text)
}

/// A table: time, kind, details; then the number of events.
#[must_use]
pub fn table(events: &[LogEvent]) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    if !events.is_empty() {
        let _ = writeln!(o, "{:>10}  {:<11}  details", "t_s", "event");
    }
    for e in events {
        let line = format!(
            "{:>10.3}  {:<11}  {}",
            e.t_s,
            e.kind.name(),
            e.kind.describe()
        );
        o.push_str(line.trim_end());
        o.push('\n');
    }
    let _ = writeln!(o, "{}", crate::words::plural(events.len(), "event"));
    o
}
