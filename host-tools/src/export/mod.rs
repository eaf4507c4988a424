//! Writing rows as CSV, JSON lines or Parquet, with the columns of
//! [`columns::COLUMNS`] (or a selection of them).

pub mod columnar;
pub mod columns;
pub mod derived;
pub mod frame_columns;
mod lines;
pub mod mcap;
mod mcap_file;
pub mod metadata;
pub mod parquet;
mod text;
pub use text::MISSING_NUMBER;

use std::io::Write;
use std::path::Path;

use columns::Column;
use lines::LineWriter;
pub use metadata::LogMetadata;
use text::LineFormat;

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
    /// MCAP for Foxglove (binary, zstd; one CDR message per frame on
    /// /sensors, GPS as foxglove.LocationFix, events as foxglove.Log; log
    /// times in UTC).
    Mcap,
}

/// What an output file's name asks for: `run.tsv.gz` is CSV, tab
/// separated, gzip compressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Named {
    /// The format.
    pub format: Format,
    /// Tab-separated (`.tsv`).
    pub tab: bool,
    /// Gzip-compressed (`.gz` after a text format).
    pub gzip: bool,
}

/// The output names `decode` knows, and what each asks for.
const NAMES: [(&str, Format, bool, bool); 12] = [
    (".csv", Format::Csv, false, false),
    (".csv.gz", Format::Csv, false, true),
    (".tsv", Format::Csv, true, false),
    (".tsv.gz", Format::Csv, true, true),
    (".jsonl", Format::Jsonl, false, false),
    (".jsonl.gz", Format::Jsonl, false, true),
    (".ndjson", Format::Jsonl, false, false),
    (".ndjson.gz", Format::Jsonl, false, true),
    (".parquet", Format::Parquet, false, false),
    (".pq", Format::Parquet, false, false),
    (".mcap", Format::Mcap, false, false),
    // Last: a longer name above wins.
    ("", Format::Csv, false, false),
];

/// The output as `decode` writes it: format, field delimiter (CSV) and
/// compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolved {
    /// The format.
    pub format: Format,
    /// The CSV field delimiter.
    pub delimiter: u8,
    /// Gzip the output.
    pub gzip: bool,
}

impl Format {
    /// What an output file's name asks for. `Ok(None)` for a name without
    /// an extension (`-o /dev/stdout`).
    ///
    /// # Errors
    /// An extension no format has (`.json`, `.txt`, `.gpx`): the known ones.
    pub fn of_name(path: &Path) -> Result<Option<Named>, String> {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().to_ascii_lowercase());
        if path.extension().is_none() {
            return Ok(None);
        }
        NAMES
            .iter()
            .filter(|(ext, ..)| !ext.is_empty())
            .find(|(ext, ..)| name.ends_with(ext))
            .map(|&(_, format, tab, gzip)| Some(Named { format, tab, gzip }))
            .ok_or_else(|| {
                let known: Vec<&str> = NAMES
                    .iter()
                    .map(|n| n.0)
                    .filter(|e| !e.is_empty())
                    .collect();
                format!(
                    "{}: no output format has this extension; the known ones are {} (or give --format)",
                    crate::text::shown(path),
                    known.join(" ")
                )
            })
    }

    /// The output to write: `--format` if given, else what the output's
    /// name asks for, else CSV; `--delimiter` over a `.tsv` name's tab.
    ///
    /// # Errors
    /// A usage error when `--format` contradicts the name, when the name's
    /// extension is unknown and no `--format` is given, or when a
    /// delimiter is given for a format other than CSV.
    pub fn resolve(
        given: Option<Self>,
        output: Option<&Path>,
        delimiter: Option<u8>,
    ) -> Result<Resolved, CliError> {
        let named = match output.map(Self::of_name).transpose() {
            Ok(named) => named.flatten(),
            // An explicit --format is honoured whatever the name.
            Err(_) if given.is_some() => None,
            Err(e) => return Err(CliError::Usage(e)),
        };
        let format = match (given, named) {
            (Some(g), Some(n)) if g != n.format => {
                return Err(CliError::Usage(format!(
                    "--format {} contradicts the output file {} (a {} name)",
                    g.name(),
                    output.map_or(String::new(), crate::text::shown),
                    n.format.name()
                )))
            }
            (Some(f), _) => f,
            (None, Some(n)) => n.format,
            (None, None) => Self::Csv,
        };
        if delimiter.is_some() && format != Self::Csv {
            return Err(CliError::Usage(format!(
                "--delimiter is for CSV, not {}",
                format.name()
            )));
        }
        let tab = named.is_some_and(|n| n.tab);
        Ok(Resolved {
            format,
            delimiter: delimiter.unwrap_or(if tab { b'\t' } else { b',' }),
            gzip: named.is_some_and(|n| n.gzip),
        })
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

/// Parses `--delimiter`: one ASCII character, or `tab` / `\t`.
///
/// # Errors
/// Anything else, or a character CSV cannot delimit with (a quote, a line
/// break).
pub fn parse_delimiter(text: &str) -> Result<u8, String> {
    let byte = match text {
        "tab" | "\\t" | "\t" => b'\t',
        _ if text.len() == 1 && text.is_ascii() => text.as_bytes()[0],
        _ => return Err(format!("{text:?} is not one ASCII character (or `tab`)")),
    };
    // Nor a character of a number or a UTC time: cells are not quoted.
    if matches!(byte, b'"' | b'\n' | b'\r' | b'.' | b'-' | b'+' | b':')
        || byte.is_ascii_alphanumeric()
    {
        return Err(format!("{text:?} cannot delimit CSV fields"));
    }
    Ok(byte)
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
    /// A writer of `columns`, CSV fields separated by `delimiter`. Nothing
    /// is written until the first row or [`Self::finish`], so a log that
    /// cannot be read leaves no half output.
    pub fn new(format: Format, columns: Vec<Column>, delimiter: u8, out: W) -> Self {
        let sink = match format {
            Format::Csv => {
                let names: Vec<&str> = columns.iter().map(|c| c.name).collect();
                let header = format!("{}\n", names.join(&char::from(delimiter).to_string()));
                let line = LineFormat::Csv { delimiter };
                Sink::Lines(LineWriter::new(out, &columns, line), Some(header))
            }
            Format::Jsonl => Sink::Lines(LineWriter::new(out, &columns, LineFormat::Json), None),
            Format::Parquet => Sink::Parquet(parquet::ParquetWriter::frames(out, &columns)),
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
            Sink::Mcap(..) => self.mcap()?.row(row),
        }
    }

    /// Writes a GPS fix (MCAP only: the table formats carry the fix in
    /// force on every row).
    pub fn gps(&mut self, fix: &GpsFix) -> std::io::Result<()> {
        match self.sink {
            Sink::Mcap(..) => self.mcap()?.gps(fix),
            _ => Ok(()),
        }
    }

    /// Writes an event of the log named `log_name` (MCAP only).
    pub fn event(&mut self, event: &LogEvent, log_name: &str) -> std::io::Result<()> {
        match self.sink {
            Sink::Mcap(..) => self.mcap()?.event(event, log_name),
            _ => Ok(()),
        }
    }

    /// Takes a GPS sync pair: MCAP log times are UTC from it on (the
    /// table formats carry UTC in their `utc` column).
    pub fn sync(&mut self, t_us: u64, unix_ms: u64) -> std::io::Result<()> {
        if let Sink::Mcap(..) = self.sink {
            self.mcap()?.sync(t_us, unix_ms);
        }
        Ok(())
    }

    fn mcap(&mut self) -> std::io::Result<&mut mcap::McapWriter<W>> {
        let Sink::Mcap(writer, out) = &mut self.sink else {
            return Err(std::io::Error::other("not an MCAP output"));
        };
        if let Some(out) = out.take() {
            let mcap = mcap::McapWriter::new(out, &self.columns)?;
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
            Sink::Mcap(..) => {
                // Started here if no row came; finished once.
                self.mcap()?;
                let Sink::Mcap(writer, _) = &mut self.sink else {
                    return Ok(());
                };
                writer.take().map_or(Ok(()), |w| w.finish(meta))
            }
        }
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
    fn format_follows_the_name_and_refuses_contradictions_and_unknown_names() {
        fn r(given: Option<Format>, name: &str) -> Result<Resolved, CliError> {
            Format::resolve(given, Some(Path::new(name)), None)
        }
        let plain = |format, delimiter, gzip| Resolved {
            format,
            delimiter,
            gzip,
        };
        assert_eq!(
            r(None, "a.parquet").unwrap(),
            plain(Format::Parquet, b',', false)
        );
        assert_eq!(r(None, "a.pq").unwrap().format, Format::Parquet);
        assert_eq!(r(None, "a.JSONL").unwrap().format, Format::Jsonl);
        assert_eq!(r(None, "a.tsv").unwrap(), plain(Format::Csv, b'\t', false));
        assert_eq!(
            r(None, "run.1.csv.gz").unwrap(),
            plain(Format::Csv, b',', true)
        );
        assert_eq!(
            r(None, "a.ndjson.gz").unwrap(),
            plain(Format::Jsonl, b',', true)
        );
        assert_eq!(r(None, "a").unwrap().format, Format::Csv);
        assert_eq!(
            Format::resolve(None, None, None).unwrap().format,
            Format::Csv
        );
        for unknown in ["a.txt", "a.json", "a.gpx", "a.gz", "a.parquet.gz"] {
            assert_eq!(r(None, unknown).unwrap_err().exit_code(), 2, "{unknown}");
        }
        assert_eq!(
            r(Some(Format::Jsonl), "a.txt").unwrap().format,
            Format::Jsonl
        );
        assert_eq!(
            r(Some(Format::Csv), "a.parquet").unwrap_err().exit_code(),
            2
        );
        let semicolon = Format::resolve(None, Some(Path::new("a.tsv")), Some(b';')).unwrap();
        assert_eq!(semicolon.delimiter, b';');
        let parquet = Format::resolve(None, Some(Path::new("a.pq")), Some(b';'));
        assert_eq!(parquet.unwrap_err().exit_code(), 2);
    }

    #[test]
    fn delimiters_are_one_safe_character() {
        assert_eq!(parse_delimiter(";"), Ok(b';'));
        assert_eq!(parse_delimiter("tab"), Ok(b'\t'));
        assert_eq!(parse_delimiter("\t"), Ok(b'\t'));
        for bad in ["", ";;", "\"", "a", "1", ".", "-", ":", "é"] {
            assert!(parse_delimiter(bad).is_err(), "{bad:?}");
        }
    }
}
