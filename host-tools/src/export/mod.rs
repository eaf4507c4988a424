//! Writing rows as CSV, JSON lines or Parquet.

pub mod parquet;

use std::io::Write;

use serde::Serialize;

use crate::rows::Row;

/// CSV column names, units in the names. `wobblog encode` reads the same.
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
}

/// Writes rows in one format.
// One writer per export: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum RowWriter<W: Write + Send> {
    /// CSV; the flag says whether the header line is out.
    Csv(csv::Writer<W>, bool),
    /// JSON lines.
    Jsonl(W),
    /// Parquet.
    Parquet(parquet::ParquetWriter<W>),
}

impl<W: Write + Send> RowWriter<W> {
    /// A writer. Nothing is written until the first row or [`Self::flush`],
    /// so a log that cannot be read leaves no half output.
    pub fn new(format: Format, out: W) -> Self {
        match format {
            Format::Csv => Self::Csv(csv::Writer::from_writer(out), false),
            Format::Jsonl => Self::Jsonl(out),
            Format::Parquet => Self::Parquet(parquet::ParquetWriter::new(out)),
        }
    }

    fn header(&mut self) -> csv::Result<()> {
        if let Self::Csv(w, done @ false) = self {
            w.write_record(CSV_COLUMNS)?;
            *done = true;
        }
        Ok(())
    }

    /// Writes one row.
    pub fn write(&mut self, row: &Row) -> std::io::Result<()> {
        self.header().map_err(csv_io_error)?;
        match self {
            Self::Csv(w, _) => write_csv(w, row).map_err(csv_io_error),
            Self::Jsonl(w) => {
                serde_json::to_writer(&mut *w, &JsonRow::from(row))?;
                w.write_all(b"\n")
            }
            Self::Parquet(w) => w.write(row).map_err(std::io::Error::other),
        }
    }

    /// Writes the CSV header if no row came (the Parquet footer), and
    /// flushes buffered output.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.header().map_err(csv_io_error)?;
        match self {
            Self::Csv(w, _) => w.flush(),
            Self::Jsonl(w) => w.flush(),
            Self::Parquet(w) => w.finish().map_err(std::io::Error::other),
        }
    }
}

fn write_csv<W: Write>(w: &mut csv::Writer<W>, row: &Row) -> csv::Result<()> {
    let mut num = ryu::Buffer::new();
    w.write_field(num.format(row.t_s))?;
    for v in row
        .accel_g
        .iter()
        .chain(&row.gyro_dps)
        .chain([&row.steer_deg, &row.speed_mps])
    {
        w.write_field(num.format(*v))?;
    }
    match &row.gps {
        Some(gps) => {
            w.write_field(num.format(gps.lat_deg))?;
            w.write_field(num.format(gps.lon_deg))?;
            w.write_field(gps.speed_mps.map_or("", |v| num.format(v)))?;
            w.write_field(gps.fix.as_str())?;
        }
        None => (0..4).try_for_each(|_| w.write_field(""))?,
    }
    w.write_record(None::<&[u8]>)
}

#[derive(Serialize)]
struct JsonRow {
    t_s: f64,
    ax_g: f64,
    ay_g: f64,
    az_g: f64,
    gx_dps: f64,
    gy_dps: f64,
    gz_dps: f64,
    steer_deg: f64,
    speed_mps: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    gps_lat_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gps_lon_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gps_speed_mps: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gps_fix: Option<&'static str>,
}

impl From<&Row> for JsonRow {
    fn from(r: &Row) -> Self {
        let [ax_g, ay_g, az_g] = r.accel_g;
        let [gx_dps, gy_dps, gz_dps] = r.gyro_dps;
        Self {
            t_s: r.t_s,
            ax_g,
            ay_g,
            az_g,
            gx_dps,
            gy_dps,
            gz_dps,
            steer_deg: r.steer_deg,
            speed_mps: r.speed_mps,
            gps_lat_deg: r.gps.map(|g| g.lat_deg),
            gps_lon_deg: r.gps.map(|g| g.lon_deg),
            gps_speed_mps: r.gps.and_then(|g| g.speed_mps),
            gps_fix: r.gps.map(|g| g.fix.as_str()),
        }
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
