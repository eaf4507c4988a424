//! Rows as an Apache Parquet file, so pandas, Polars and DuckDB read a run
//! directly, with its column types: numbers as doubles (GPS ones nullable),
//! `gps_fix` as a dictionary-encoded string, `utc` as a UTC timestamp, and
//! the log's identity, configuration and units as key-value metadata.

use std::io::Write;
use std::sync::Arc;

use parquet::basic::Compression;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::{
    SerializedColumnWriter, SerializedFileWriter, SerializedRowGroupWriter,
};
use parquet::schema::parser::parse_message_type;
use parquet::schema::types::ColumnPath;

use super::columns::{Column, Kind, Value};
use super::LogMetadata;
use crate::rows::Row;

/// Rows per row group: a few MB per group, so memory stays bounded on long
/// runs while readers still get large, efficient column chunks.
const ROW_GROUP_ROWS: usize = 65_536;

/// Writes rows into a Parquet file on any writer (the format is written
/// front to back; only readers need to seek).
pub struct ParquetWriter<W: Write + Send, R = Row> {
    state: State<W>,
    columns: Vec<Column<R>>,
    buffers: Vec<Buffer>,
    rows: usize,
}

/// One column's values of the row group being built, with the definition
/// levels of a nullable column (1 present, 0 absent).
enum Buffer {
    Number(Vec<f64>, Option<Vec<i16>>),
    Label(Vec<ByteArray>, Vec<i16>),
    Utc(Vec<i64>, Vec<i16>),
    Integer(Vec<i64>, Vec<i16>),
    Text(Vec<ByteArray>, Vec<i16>),
    Bool(Vec<bool>, Vec<i16>),
}

enum State<W: Write + Send> {
    /// Nothing written yet: an unreadable log leaves no half file behind.
    Idle(W),
    Open(SerializedFileWriter<W>),
    Closed,
}

impl<W: Write + Send, R> ParquetWriter<W, R> {
    /// A writer of `columns` on `out`.
    pub fn new(out: W, columns: &[Column<R>]) -> Self {
        let buffers = columns
            .iter()
            .map(|c| match c.kind {
                Kind::Number => Buffer::Number(Vec::new(), None),
                Kind::OptNumber => Buffer::Number(Vec::new(), Some(Vec::new())),
                Kind::Label => Buffer::Label(Vec::new(), Vec::new()),
                Kind::Utc => Buffer::Utc(Vec::new(), Vec::new()),
                Kind::Integer => Buffer::Integer(Vec::new(), Vec::new()),
                Kind::Text => Buffer::Text(Vec::new(), Vec::new()),
                Kind::Bool => Buffer::Bool(Vec::new(), Vec::new()),
            })
            .collect();
        Self {
            state: State::Idle(out),
            columns: columns.to_vec(),
            buffers,
            rows: 0,
        }
    }

    /// The schema of the columns.
    fn schema(&self) -> String {
        let mut s = String::from("message wobblog_row {\n");
        for c in &self.columns {
            let field = match c.kind {
                Kind::Number => "REQUIRED DOUBLE",
                Kind::OptNumber => "OPTIONAL DOUBLE",
                Kind::Label | Kind::Text => "OPTIONAL BYTE_ARRAY",
                Kind::Utc | Kind::Integer => "OPTIONAL INT64",
                Kind::Bool => "OPTIONAL BOOLEAN",
            };
            let annotation = match c.kind {
                Kind::Label | Kind::Text => " (UTF8)",
                Kind::Utc => " (TIMESTAMP(MICROS,true))",
                _ => "",
            };
            s.push_str(&format!("  {field} {}{annotation};\n", c.name));
        }
        s.push('}');
        s
    }

    fn file(&mut self) -> Result<&mut SerializedFileWriter<W>, ParquetError> {
        if let State::Idle(_) = self.state {
            let schema = Arc::new(parse_message_type(&self.schema())?);
            let mut props = WriterProperties::builder()
                .set_compression(Compression::SNAPPY)
                .set_created_by(concat!("wobblog ", env!("CARGO_PKG_VERSION")).into())
                // Numbers are nearly all distinct: a dictionary would be
                // built and thrown away for every page.
                .set_dictionary_enabled(false);
            for c in self
                .columns
                .iter()
                .filter(|c| matches!(c.kind, Kind::Label | Kind::Text))
            {
                props = props.set_column_dictionary_enabled(ColumnPath::from(c.name), true);
            }
            self.state = match std::mem::replace(&mut self.state, State::Closed) {
                State::Idle(out) => State::Open(SerializedFileWriter::new(
                    out,
                    schema,
                    Arc::new(props.build()),
                )?),
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
    pub fn write(&mut self, row: &R) -> Result<(), ParquetError> {
        for (column, buffer) in self.columns.iter().zip(&mut self.buffers) {
            match (buffer, (column.value)(row)) {
                (Buffer::Number(values, levels), Value::Number(v)) => {
                    match levels {
                        Some(levels) => levels.push(i16::from(v.is_some())),
                        None if v.is_none() => {
                            return Err(ParquetError::General(format!(
                                "{} has no value in a row",
                                column.name
                            )))
                        }
                        None => {}
                    }
                    values.extend(v);
                }
                (Buffer::Label(values, levels), Value::Label(v)) => {
                    levels.push(i16::from(v.is_some()));
                    values.extend(v.map(|s| ByteArray::from(s.as_bytes().to_vec())));
                }
                (Buffer::Utc(values, levels), Value::Utc(v))
                | (Buffer::Integer(values, levels), Value::Integer(v)) => {
                    levels.push(i16::from(v.is_some()));
                    values.extend(v);
                }
                (Buffer::Text(values, levels), Value::Text(v)) => {
                    levels.push(i16::from(v.is_some()));
                    values.extend(v.map(|s| ByteArray::from(s.into_bytes())));
                }
                (Buffer::Bool(values, levels), Value::Bool(v)) => {
                    levels.push(i16::from(v.is_some()));
                    values.extend(v);
                }
                _ => {
                    return Err(ParquetError::General(format!(
                        "{}: value of the wrong type",
                        column.name
                    )))
                }
            }
        }
        self.rows += 1;
        if self.rows >= ROW_GROUP_ROWS {
            self.write_group()?;
        }
        Ok(())
    }

    fn write_group(&mut self) -> Result<(), ParquetError> {
        let rows = std::mem::take(&mut self.rows);
        let buffers: Vec<Buffer> = self
            .buffers
            .iter_mut()
            .map(|b| match b {
                Buffer::Number(v, l) => {
                    Buffer::Number(std::mem::take(v), l.as_mut().map(std::mem::take))
                }
                Buffer::Label(v, l) => Buffer::Label(std::mem::take(v), std::mem::take(l)),
                Buffer::Utc(v, l) => Buffer::Utc(std::mem::take(v), std::mem::take(l)),
                Buffer::Integer(v, l) => Buffer::Integer(std::mem::take(v), std::mem::take(l)),
                Buffer::Text(v, l) => Buffer::Text(std::mem::take(v), std::mem::take(l)),
                Buffer::Bool(v, l) => Buffer::Bool(std::mem::take(v), std::mem::take(l)),
            })
            .collect();
        let file = self.file()?;
        if rows == 0 {
            return Ok(());
        }
        let mut group = file.next_row_group()?;
        for buffer in &buffers {
            let mut column = next_column(&mut group)?;
            match buffer {
                Buffer::Number(values, levels) => {
                    column
                        .typed::<DoubleType>()
                        .write_batch(values, levels.as_deref(), None)?;
                }
                Buffer::Label(values, levels) | Buffer::Text(values, levels) => {
                    column
                        .typed::<ByteArrayType>()
                        .write_batch(values, Some(levels), None)?;
                }
                Buffer::Utc(values, levels) | Buffer::Integer(values, levels) => {
                    column
                        .typed::<Int64Type>()
                        .write_batch(values, Some(levels), None)?;
                }
                Buffer::Bool(values, levels) => {
                    column
                        .typed::<BoolType>()
                        .write_batch(values, Some(levels), None)?;
                }
            }
            column.close()?;
        }
        group.close()?;
        Ok(())
    }

    /// Writes the rows still buffered and the file footer with `pairs` as
    /// key-value metadata; the file is complete after this (also with no
    /// rows at all).
    pub fn finish_with(&mut self, pairs: Vec<(String, String)>) -> Result<(), ParquetError> {
        self.write_group()?;
        if let State::Open(mut file) = std::mem::replace(&mut self.state, State::Closed) {
            for (key, value) in pairs {
                file.append_key_value_metadata(KeyValue::new(key, value));
            }
            file.finish()?;
            file.inner_mut().flush()?;
        }
        Ok(())
    }
}

impl<W: Write + Send> ParquetWriter<W, Row> {
    /// [`Self::finish_with`] the log's metadata and the columns' units.
    ///
    /// # Errors
    /// When the output fails.
    pub fn finish(&mut self, meta: &LogMetadata) -> Result<(), ParquetError> {
        let pairs = meta.pairs(&self.columns);
        self.finish_with(pairs)
    }
}

fn next_column<'a, W: Write + Send>(
    group: &'a mut SerializedRowGroupWriter<'_, W>,
) -> Result<SerializedColumnWriter<'a>, ParquetError> {
    group
        .next_column()?
        .ok_or_else(|| ParquetError::General("the schema has fewer columns than a row".into()))
}
