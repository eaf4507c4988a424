//! Rows as an Apache Parquet file, so pandas, Polars and DuckDB read a run
//! directly, with its column types. Same columns as the CSV; GPS columns are
//! nullable.

use std::io::Write;
use std::sync::Arc;

use parquet::basic::Compression;
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType};
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::{
    SerializedColumnWriter, SerializedFileWriter, SerializedRowGroupWriter,
};
use parquet::schema::parser::parse_message_type;

use super::CSV_COLUMNS;
use crate::rows::Row;

/// Rows per row group: a few MB per group, so memory stays bounded on long
/// runs while readers still get large, efficient column chunks.
const ROW_GROUP_ROWS: usize = 65_536;
/// Columns always present: `t_s` to `speed_mps`.
const REQUIRED: usize = 9;
/// Nullable numeric GPS columns that follow them.
const GPS_NUMERIC: usize = 3;

/// Writes rows into a Parquet file on any writer (the format is written
/// front to back; only readers need to seek).
pub struct ParquetWriter<W: Write + Send> {
    state: State<W>,
    required: [Vec<f64>; REQUIRED],
    gps: [Vec<f64>; GPS_NUMERIC],
    gps_defined: [Vec<i16>; GPS_NUMERIC],
    fix: Vec<ByteArray>,
    fix_defined: Vec<i16>,
    rows: usize,
}

enum State<W: Write + Send> {
    /// Nothing written yet: an unreadable log leaves no half file behind.
    Idle(W),
    Open(SerializedFileWriter<W>),
    Closed,
}

impl<W: Write + Send> ParquetWriter<W> {
    /// A writer on `out`.
    pub fn new(out: W) -> Self {
        Self {
            state: State::Idle(out),
            required: Default::default(),
            gps: Default::default(),
            gps_defined: Default::default(),
            fix: Vec::new(),
            fix_defined: Vec::new(),
            rows: 0,
        }
    }

    /// The schema, built from the CSV column names.
    fn schema() -> String {
        let mut s = String::from("message wobblog_row {\n");
        for (i, name) in CSV_COLUMNS.iter().enumerate() {
            let field = match i {
                i if i < REQUIRED => "REQUIRED DOUBLE",
                i if i < REQUIRED + GPS_NUMERIC => "OPTIONAL DOUBLE",
                _ => "OPTIONAL BYTE_ARRAY",
            };
            let annotation = if field.ends_with("BYTE_ARRAY") {
                " (UTF8)"
            } else {
                ""
            };
            s.push_str(&format!("  {field} {name}{annotation};\n"));
        }
        s.push('}');
        s
    }

    fn file(&mut self) -> Result<&mut SerializedFileWriter<W>, ParquetError> {
        if let State::Idle(_) = self.state {
            let schema = Arc::new(parse_message_type(&Self::schema())?);
            let props = WriterProperties::builder()
                .set_compression(Compression::SNAPPY)
                .set_created_by(concat!("wobblog ", env!("CARGO_PKG_VERSION")).into())
                .build();
            self.state = match std::mem::replace(&mut self.state, State::Closed) {
                State::Idle(out) => {
                    State::Open(SerializedFileWriter::new(out, schema, Arc::new(props))?)
                }
                other => other,
            };
        }
        match &mut self.state {
            State::Open(w) => Ok(w),
            _ => Err(ParquetError::General(
                "the Parquet file is already closed".into(),
            )),
        }
    }

    /// Adds one row.
    pub fn write(&mut self, row: &Row) -> Result<(), ParquetError> {
        let values = [row.t_s]
            .into_iter()
            .chain(row.accel_g)
            .chain(row.gyro_dps)
            .chain([row.steer_deg, row.speed_mps]);
        for (column, v) in self.required.iter_mut().zip(values) {
            column.push(v);
        }
        let gps = [
            row.gps.map(|g| g.lat_deg),
            row.gps.map(|g| g.lon_deg),
            row.gps.and_then(|g| g.speed_mps),
        ];
        for ((column, defined), v) in self.gps.iter_mut().zip(&mut self.gps_defined).zip(gps) {
            defined.push(i16::from(v.is_some()));
            column.extend(v);
        }
        self.fix_defined.push(i16::from(row.gps.is_some()));
        self.fix.extend(
            row.gps
                .map(|g| ByteArray::from(g.fix.as_str().as_bytes().to_vec())),
        );
        self.rows += 1;
        if self.rows >= ROW_GROUP_ROWS {
            self.write_group()?;
        }
        Ok(())
    }

    fn write_group(&mut self) -> Result<(), ParquetError> {
        let rows = std::mem::take(&mut self.rows);
        let required = std::mem::take(&mut self.required);
        let gps = std::mem::take(&mut self.gps);
        let gps_defined = std::mem::take(&mut self.gps_defined);
        let fix = std::mem::take(&mut self.fix);
        let fix_defined = std::mem::take(&mut self.fix_defined);
        let file = self.file()?;
        if rows == 0 {
            return Ok(());
        }
        let mut group = file.next_row_group()?;
        for values in &required {
            let mut column = next_column(&mut group)?;
            column
                .typed::<DoubleType>()
                .write_batch(values, None, None)?;
            column.close()?;
        }
        for (values, defined) in gps.iter().zip(&gps_defined) {
            let mut column = next_column(&mut group)?;
            column
                .typed::<DoubleType>()
                .write_batch(values, Some(defined), None)?;
            column.close()?;
        }
        let mut column = next_column(&mut group)?;
        column
            .typed::<ByteArrayType>()
            .write_batch(&fix, Some(&fix_defined), None)?;
        column.close()?;
        group.close()?;
        Ok(())
    }

    /// Writes the rows still buffered and the file footer; the file is
    /// complete after this (also with no rows at all).
    pub fn finish(&mut self) -> Result<(), ParquetError> {
        self.write_group()?;
        if let State::Open(mut file) = std::mem::replace(&mut self.state, State::Closed) {
            file.finish()?;
            file.inner_mut().flush()?;
        }
        Ok(())
    }
}

fn next_column<'a, W: Write + Send>(
    group: &'a mut SerializedRowGroupWriter<'_, W>,
) -> Result<SerializedColumnWriter<'a>, ParquetError> {
    group
        .next_column()?
        .ok_or_else(|| ParquetError::General("the schema has fewer columns than a row".into()))
}
