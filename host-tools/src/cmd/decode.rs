//! `wobblog decode`: one row per 100 Hz frame, as CSV, JSON lines or Parquet.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use crate::export::{Format, RowWriter};
use crate::losses::Losses;
use crate::output::Output;
use crate::reader::read_log;
use crate::rows::RowAssembler;
use crate::CliError;

/// Arguments of `wobblog decode`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// Output format. Parquet is binary: it goes to the `-o` file, or to
    /// standard output only when that is redirected (not a terminal).
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Output file; standard output if absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs `wobblog decode`.
pub fn run(args: &Args) -> Result<(), CliError> {
    if args.format == Format::Parquet && args.output.is_none() && std::io::stdout().is_terminal() {
        return Err(CliError::Usage(
            "parquet output is binary: give -o FILE or redirect standard output".into(),
        ));
    }
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.log])?;
    let name = out.name().to_path_buf();
    let losses = match decode_to(&args.log, args.format, &mut out, &name) {
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
    format: Format,
    out: impl Write + Send,
    out_name: &Path,
) -> Result<Losses, CliError> {
    let write_err = |e: &dyn std::fmt::Display| CliError::file(out_name, e);
    let mut writer = RowWriter::new(format, out);
    let mut rows = RowAssembler::new();
    let mut losses = Losses::default();
    let mut failure: Option<std::io::Error> = None;
    let mut emit = |row: &crate::rows::Row| {
        if failure.is_none() {
            failure = writer.write(row).err();
        }
    };
    read_log(log, |event| {
        losses.observe(&event);
        if let wobble_core::format::Event::Record(record) = event {
            rows.push(&record, &mut emit);
        }
    })?;
    rows.finish(&mut emit);
    match failure.map_or_else(|| writer.flush(), Err) {
        // The reader went away (`wobblog decode LOG | head`): not a failure.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(losses),
        Err(e) => Err(write_err(&e)),
        Ok(()) => Ok(losses),
    }
}
