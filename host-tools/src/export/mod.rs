//! Writing rows as CSV, JSON lines or Parquet, with the columns of
//! [`columns::COLUMNS`] (or a selection of them).

pub mod columns;
pub mod mcap;
pub mod metadata;
pub mod parquet;

use std::io::Write;
use std::path::Path;

use columns::{Column, Value};
pub use metadata::LogMetadata;

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
    /// CSV; the flag says whether the header line is out.
    Csv(csv::Writer<W>, bool),
    Jsonl(W),
    Parquet(parquet::ParquetWriter<W>),
    /// Built on the first row: creating it writes the file's header.
    Mcap(Option<Box<mcap::McapWriter<W>>>, Option<W>),
}

impl<W: Write + Send> RowWriter<W> {
    /// A writer of `columns`. Nothing is written until the first row or
    /// [`Self::finish`], so a log that cannot be read leaves no half output.
    pub fn new(format: Format, columns: Vec<Column>, out: W) -> Self {
        let sink = match format {
            Format::Csv => Sink::Csv(csv::Writer::from_writer(out), false),
            Format::Jsonl => Sink::Jsonl(out),
            Format::Parquet => Sink::Parquet(parquet::ParquetWriter::new(out, &columns)),
            Format::Mcap => Sink::Mcap(None, Some(out)),
        };
        Self { columns, sink }
    }

    fn header(&mut self) -> csv::Result<()> {
        if let Sink::Csv(w, done @ false) = &mut self.sink {
            w.write_record(self.columns.iter().map(|c| c.name))?;
            *done = true;
        }
        Ok(())
    }

    /// Writes one row.
    pub fn write(&mut self, row: &Row) -> std::io::Result<()> {
        self.header().map_err(csv_io_error)?;
        match &mut self.sink {
            Sink::Csv(w, _) => write_csv(w, &self.columns, row).map_err(csv_io_error),
            Sink::Jsonl(w) => write_json(w, &self.columns, row),
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
        self.header().map_err(csv_io_error)?;
        match &mut self.sink {
            Sink::Csv(w, _) => w.flush(),
            Sink::Jsonl(w) => w.flush(),
            Sink::Parquet(w) => w.finish(meta).map_err(std::io::Error::other),
            Sink::Mcap(..) => self.mcap()?.finish(meta).map_err(mcap_io_error),
        }
    }
}

fn write_csv<W: Write>(w: &mut csv::Writer<W>, columns: &[Column], row: &Row) -> csv::Result<()> {
    let mut num = ryu::Buffer::new();
    let mut time = [0u8; UTC_LEN];
    for column in columns {
        match (column.value)(row) {
            Value::Number(Some(v)) => w.write_field(num.format(v))?,
            Value::Label(Some(s)) => w.write_field(s)?,
            Value::Utc(Some(us)) => w.write_field(utc_text(us, &mut time))?,
            Value::Integer(Some(n)) => w.write_field(n.to_string())?,
            Value::Text(Some(s)) => w.write_field(s)?,
            Value::Number(None)
            | Value::Label(None)
            | Value::Utc(None)
            | Value::Integer(None)
            | Value::Text(None) => w.write_field("")?,
        }
    }
    w.write_record(None::<&[u8]>)
}

/// One JSON object per row, on a line of its own.
fn write_json<W: Write>(w: &mut W, columns: &[Column], row: &Row) -> std::io::Result<()> {
    let mut line = String::with_capacity(320);
    json_object(&mut line, columns, row);
    line.push('\n');
    w.write_all(line.as_bytes())
}

/// Appends the JSON object of `row`'s `columns` to `line`; absent values
/// are left out. Written by hand: every key is a plain column name and
/// every string value a fixed name, an ISO time or a file name (escaped by
/// serde), and nothing is allocated per number (the one-hour export is
/// benchmarked).
fn json_object(line: &mut String, columns: &[Column], row: &Row) {
    let mut num = ryu::Buffer::new();
    let mut time = [0u8; UTC_LEN];
    let start = line.len();
    line.push('{');
    for column in columns {
        let value = (column.value)(row);
        let is_some = match &value {
            Value::Number(v) => v.is_some(),
            Value::Label(v) => v.is_some(),
            Value::Utc(v) | Value::Integer(v) => v.is_some(),
            Value::Text(v) => v.is_some(),
        };
        if !is_some {
            continue;
        }
        if line.len() > start + 1 {
            line.push(',');
        }
        line.push('"');
        line.push_str(column.name);
        line.push_str("\":");
        match value {
            Value::Number(Some(v)) => line.push_str(num.format(v)),
            Value::Label(Some(s)) => {
                line.push('"');
                line.push_str(s);
                line.push('"');
            }
            Value::Utc(Some(us)) => {
                line.push('"');
                line.push_str(utc_text(us, &mut time));
                line.push('"');
            }
            Value::Integer(Some(n)) => line.push_str(&n.to_string()),
            Value::Text(Some(s)) => {
                // Serialising a string cannot fail.
                line.push_str(&serde_json::Value::String(s).to_string());
            }
            _ => {}
        }
    }
    line.push('}');
}

/// Length of `2020-03-18T13:28:20.600Z`.
const UTC_LEN: usize = 24;

/// UTC in ISO 8601 to the millisecond (rounded down), as
/// [`crate::time::iso8601`] writes it, into `buf` without allocating;
/// empty outside the card's dates.
fn utc_text(us: i64, buf: &mut [u8; UTC_LEN]) -> &str {
    const MS_PER_DAY: i64 = 86_400_000;
    const UNIX_MS_AT_2000: i64 = 10_957 * MS_PER_DAY;
    let since_2000 = us.div_euclid(1000) - UNIX_MS_AT_2000;
    let Ok(days_since_2000) = u16::try_from(since_2000.div_euclid(MS_PER_DAY)) else {
        return "";
    };
    let ms = since_2000.rem_euclid(MS_PER_DAY);
    let utc = wobble_core::format::UtcTime {
        days_since_2000,
        ms_of_day: ms as u32,
    };
    let (year, month, day) = utc.date();
    let mut put = |at: usize, value: i64, digits: usize| {
        let mut v = value;
        for i in (0..digits).rev() {
            buf[at + i] = b'0' + (v % 10) as u8;
            v /= 10;
        }
    };
    put(0, i64::from(year), 4);
    put(5, i64::from(month), 2);
    put(8, i64::from(day), 2);
    put(11, ms / 3_600_000, 2);
    put(14, ms / 60_000 % 60, 2);
    put(17, ms / 1000 % 60, 2);
    put(20, ms % 1000, 3);
    for (at, sep) in [
        (4, b'-'),
        (7, b'-'),
        (10, b'T'),
        (13, b':'),
        (16, b':'),
        (19, b'.'),
        (23, b'Z'),
    ] {
        buf[at] = sep;
    }
    std::str::from_utf8(buf).unwrap_or("")
}

/// Keeps the kind of an I/O error wrapped by `mcap`.
fn mcap_io_error(err: ::mcap::McapError) -> std::io::Error {
    match err {
        ::mcap::McapError::Io(e) => e,
        other => std::io::Error::other(other.to_string()),
    }
}

/// Keeps the kind of an I/O error wrapped by `csv` (its own conversion
/// turns every error into `Other`, hiding a closed pipe).
fn csv_io_error(err: csv::Error) -> std::io::Error {
    let message = err.to_string();
    match err.into_kind() {
        csv::ErrorKind::Io(e) => e,
        _ => std::io::Error::other(message),
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
    fn fast_utc_text_is_iso8601() {
        let mut buf = [0u8; UTC_LEN];
        for ms in [
            946_684_800_000i64,
            1_584_538_100_600,
            1_584_575_999_999,
            4_102_444_800_123,
        ] {
            assert_eq!(
                utc_text(ms * 1000 + 999, &mut buf),
                crate::time::iso8601_unix_ms(ms).unwrap()
            );
        }
        assert_eq!(utc_text(0, &mut buf), "");
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
