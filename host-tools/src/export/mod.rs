//! Writing rows as CSV, JSON lines or Parquet, with the columns of
//! [`columns::COLUMNS`] (or a selection of them).

pub mod columns;
mod lines;
pub mod mcap;
pub mod metadata;
pub mod parquet;
mod text;

use std::io::Write;
use std::path::Path;

use columns::Column;
use lines::LineWriter;
pub use metadata::LogMetadata;
pub(crate) use text::json_object;

use crate::events::LogEvent;
use crate::rows::Row;
use crate::CliError;
use wobble_core::format::GpsFix;

/// The CSV columns `wobblog encode` reads: the documented ones, units in
/// the names (the first columns of [`columns::COLUMNS`]).
pub const CSV_COLUMNS: [&str; 13] = [
    "t_s",
    "ax_g",
    "ay_g",
    "az_g",
    "gx_dps",
    "gy_dps",
    "gz_dps",
    "steer_deg",
    "speed_mps",
    "gps_lat_deg",
    "gps_lon_deg",
    "gps_speed_mps",
    "gps_fix",
];

/// Output formats of `wobblog decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Comma-separated values with a header line.
    Csv,
    /// One JSON object per line.
    Jsonl,
    /// Apache Parquet (binary; typed columns, GPS columns nullable).
    Parquet,
    /// MCAP for Foxglove (binary; a JSON channel per sensor group, GPS as
    /// foxglove.LocationFix, events on their own channel).
    Mcap,
}

impl Format {
    /// The format an output file's extension names, if any.
    #[must_use]
    pub fn of_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "csv" => Some(Self::Csv),
            "jsonl" | "ndjson" => Some(Self::Jsonl),
            "parquet" => Some(Self::Parquet),
            "mcap" => Some(Self::Mcap),
            _ => None,
        }
    }

    /// The format to write: `--format` if given, else the output's
    /// extension, else CSV.
    ///
    /// # Errors
    /// A usage error when `--format` contradicts the extension.
    pub fn resolve(given: Option<Self>, output: Option<&Path>) -> Result<Self, CliError> {
        let implied = output.and_then(Self::of_extension);
        match (given, implied) {
            (Some(g), Some(i)) if g != i => Err(CliError::Usage(format!(
                "--format {} contradicts the output file {} (a {} name)",
                g.name(),
                output.map_or(String::new(), |p| p.display().to_string()),
                i.name()
            ))),
            (Some(f), _) | (None, Some(f)) => Ok(f),
            (None, None) => Ok(Self::Csv),
        }
    }

    /// The name as `--format` takes it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Csv => "csv",
            Self::Jsonl => "jsonl",
            Self::Parquet => "parquet",
            Self::Mcap => "mcap",
        }
    }
}

/// Writes rows in one format.
pub struct RowWriter<W: Write + Send> {
    columns: Vec<Column>,
    sink: Sink<W>,
}

// One writer per export: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
enum Sink<W: Write + Send> {
    /// CSV or JSON lines; the text that goes before the first row (the CSV
    /// header) until it is out.
    Lines(LineWriter<W>, Option<String>),
    Parquet(parquet::ParquetWriter<W>),
    /// Built on the first row: creating it writes the file's header.
    Mcap(Option<Box<mcap::McapWriter<W>>>, Option<W>),
}

impl<W: Write + Send> RowWriter<W> {
    /// A writer of `columns`. Nothing is written until the first row or
    /// [`Self::finish`], so a log that cannot be read leaves no half output.
    pub fn new(format: Format, columns: Vec<Column>, out: W) -> Self {
        let sink = match format {
            Format::Csv => {
                let names: Vec<&str> = columns.iter().map(|c| c.name).collect();
                let header = format!("{}\n", names.join(","));
                Sink::Lines(LineWriter::new(out, &columns, text::csv_line), Some(header))
            }
            Format::Jsonl => Sink::Lines(LineWriter::new(out, &columns, text::json_line), None),
            Format::Parquet => Sink::Parquet(parquet::ParquetWriter::new(out, &columns)),
            Format::Mcap => Sink::Mcap(None, Some(out)),
        };
        Self { columns, sink }
    }

    fn header(&mut self) -> std::io::Result<()> {
        if let Sink::Lines(w, header) = &mut self.sink {
            if let Some(text) = header.take() {
                w.write_text(&text)?;
            }
        }
        Ok(())
    }

    /// Writes one row.
    pub fn write(&mut self, row: &Row) -> std::io::Result<()> {
        self.header()?;
        match &mut self.sink {
            Sink::Lines(w, _) => w.write(row),
            Sink::Parquet(w) => w.write(row).map_err(std::io::Error::other),
            Sink::Mcap(..) => self.mcap()?.row(row).map_err(mcap_io_error),
        }
    }

    /// Writes a GPS fix (MCAP only: the table formats carry the fix in
    /// force on every row).
    pub fn gps(&mut self, fix: &GpsFix) -> std::io::Result<()> {
        match self.sink {
            Sink::Mcap(..) => self.mcap()?.gps(fix).map_err(mcap_io_error),
            _ => Ok(()),
        }
    }

    /// Writes an event (MCAP only).
    pub fn event(&mut self, event: &LogEvent) -> std::io::Result<()> {
        match self.sink {
            Sink::Mcap(..) => self.mcap()?.event(event).map_err(mcap_io_error),
            _ => Ok(()),
        }
    }

    fn mcap(&mut self) -> std::io::Result<&mut mcap::McapWriter<W>> {
        let Sink::Mcap(writer, out) = &mut self.sink else {
            return Err(std::io::Error::other("not an MCAP output"));
        };
        if let Some(out) = out.take() {
            let mcap = mcap::McapWriter::new(out, &self.columns).map_err(mcap_io_error)?;
            *writer = Some(Box::new(mcap));
        }
        writer
            .as_deref_mut()
            .ok_or_else(|| std::io::Error::other("the MCAP file could not be started"))
    }

    /// Writes the CSV header if no row came, or the Parquet footer with
    /// `meta`, and flushes buffered output.
    pub fn finish(&mut self, meta: &LogMetadata) -> std::io::Result<()> {
        self.header()?;
        match &mut self.sink {
            Sink::Lines(w, _) => w.flush(),
            Sink::Parquet(w) => w.finish(meta).map_err(std::io::Error::other),
            Sink::Mcap(..) => self.mcap()?.finish(meta).map_err(mcap_io_error),
        }
    }
}

/// Keeps the kind of an I/O error wrapped by `mcap`.
fn mcap_io_error(err: ::mcap::McapError) -> std::io::Error {
    match err {
        ::mcap::McapError::Io(e) => e,
        other => std::io::Error::other(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_csv_columns_come_first() {
        let names: Vec<&str> = columns::COLUMNS.iter().map(|c| c.name).collect();
        assert_eq!(names[..CSV_COLUMNS.len()], CSV_COLUMNS);
    }

    #[test]
    fn format_follows_the_extension_and_refuses_contradictions() {
        fn p(s: &str) -> Option<&Path> {
            Some(Path::new(s))
        }
        assert_eq!(
            Format::resolve(None, p("a.parquet")).unwrap(),
            Format::Parquet
        );
        assert_eq!(Format::resolve(None, p("a.JSONL")).unwrap(), Format::Jsonl);
        assert_eq!(Format::resolve(None, p("a.txt")).unwrap(), Format::Csv);
        assert_eq!(Format::resolve(None, None).unwrap(), Format::Csv);
        assert_eq!(
            Format::resolve(Some(Format::Jsonl), p("a.txt")).unwrap(),
            Format::Jsonl
        );
        let err = Format::resolve(Some(Format::Csv), p("a.parquet")).unwrap_err();
        assert_eq!(err.exit_code(), 2);
    }
}
