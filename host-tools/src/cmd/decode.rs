//! `wobblog decode`: one row per 100 Hz frame, as CSV, JSON lines or Parquet.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use crate::export::columns::{self, Column};
use crate::export::{Format, LogMetadata, RowWriter};
use crate::losses::Losses;
use crate::output::Output;
use crate::reader::read_log;
use crate::rows::RowAssembler;
use crate::time::{TimeWindow, WindowArgs};
use crate::CliError;

/// Arguments of `wobblog decode`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// Output format; by default the `-o` file's extension (`.csv`,
    /// `.jsonl`, `.parquet`) names it, else CSV. Parquet is binary: it goes
    /// to the `-o` file, or to standard output only when that is redirected.
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Output file; standard output if absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Only these columns, in this order (comma-separated names, e.g.
    /// `t_s,steer_deg,speed_mps,utc`).
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
    /// Columns, in order.
    pub columns: Vec<Column>,
    /// Rows inside this window only.
    pub window: TimeWindow,
}

impl Export {
    /// Every column of every row.
    #[must_use]
    pub fn all(format: Format) -> Self {
        Self {
            format,
            columns: columns::COLUMNS.to_vec(),
            window: TimeWindow::default(),
        }
    }
}

/// Runs `wobblog decode`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let export = Export {
        format: Format::resolve(args.format, args.output.as_deref())?,
        columns: columns::select(args.columns.as_deref()).map_err(CliError::Usage)?,
        window: args.window.window(),
    };
    if export.format == Format::Parquet && args.output.is_none() && std::io::stdout().is_terminal()
    {
        return Err(CliError::Usage(
            "parquet output is binary: give -o FILE or redirect standard output".into(),
        ));
    }
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.log])?;
    let name = out.name().to_path_buf();
    let losses = match decode_to(&args.log, &export, &mut out, &name) {
        Err(_) if out.pipe_closed() => return Err(CliError::PipeClosed),
        result => result?,
    };
    out.commit()?;
    for line in losses.describe() {
        eprintln!("wobblog: {}: warning: {line}", args.log.display());
    }
    Ok(())
}

/// Decodes `log` into `out`; returns what could not be recovered.
pub fn decode_to(
    log: &Path,
    export: &Export,
    out: impl Write + Send,
    out_name: &Path,
) -> Result<Losses, CliError> {
    let write_err = |e: &dyn std::fmt::Display| CliError::file(out_name, e);
    let mut writer = RowWriter::new(export.format, export.columns.clone(), out);
    let mut rows = RowAssembler::new();
    let mut losses = Losses::default();
    let mut meta = LogMetadata::default();
    let mut failure: Option<std::io::Error> = None;
    let window = export.window;
    let mut emit = |row: &crate::rows::Row| {
        let inside = window.is_all() || window.contains(row.t_s, row.utc_us.map(|u| u / 1000));
        if failure.is_none() && inside {
            failure = writer.write(row).err();
        }
    };
    read_log(log, |event| {
        losses.observe(&event);
        meta.observe(&event);
        if let wobble_core::format::Event::Record(record) = event {
            rows.push(&record, &mut emit);
        }
    })?;
    rows.finish(&mut emit);
    match failure.map_or_else(|| writer.finish(&meta), Err) {
        // The reader went away (`wobblog decode LOG | head`): not a failure.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(losses),
        Err(e) => Err(write_err(&e)),
        Ok(()) => Ok(losses),
    }
}
