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

use super::columnar::{buffers, present_only, row_buffers, ColumnBuffers, Values};
use super::columns::{Column, Kind};
use super::LogMetadata;
use crate::rows::Row;

/// Rows per row group: a few MB per group, so memory stays bounded on long
/// runs while readers still get large, efficient column chunks.
const ROW_GROUP_ROWS: usize = 65_536;
/// Rows per row group of the other tables (runs, episodes, kicks, events):
/// their rows go through one value per cell ([`super::columnar::Values`]),
/// ten times a frame's memory, and only an events table of a flood of card
/// records grows long.
const TABLE_ROW_GROUP_ROWS: usize = 8_192;

/// Writes rows into a Parquet file on any writer (the format is written
/// front to back; only readers need to seek).
pub struct ParquetWriter<W: Write + Send, R = Row> {
    state: State<W>,
    columns: Vec<Column<R>>,
    /// Rows per row group.
    group_rows: usize,
    /// The row group being built ([`super::columnar`]).
    buffers: Box<dyn ColumnBuffers<R>>,
}

enum State<W: Write + Send> {
    /// Nothing written yet: an unreadable log leaves no half file behind.
    Idle(W),
    Open(SerializedFileWriter<W>),
    Closed,
}

impl<W: Write + Send> ParquetWriter<W, Row> {
    /// A writer of decoded frames in `columns` on `out`, each field stored
    /// straight into its column ([`super::columnar::RowColumns`]).
    pub fn frames(out: W, columns: &[Column<Row>]) -> Self {
        Self::with_buffers(
            out,
            columns,
            row_buffers(columns, ROW_GROUP_ROWS),
            ROW_GROUP_ROWS,
        )
    }
}

impl<W: Write + Send, R: 'static> ParquetWriter<W, R> {
    /// A writer of `columns` on `out`.
    pub fn new(out: W, columns: &[Column<R>]) -> Self {
        Self::with_buffers(
            out,
            columns,
            buffers(columns, TABLE_ROW_GROUP_ROWS),
            TABLE_ROW_GROUP_ROWS,
        )
    }

    fn with_buffers(
        out: W,
        columns: &[Column<R>],
        buffers: Box<dyn ColumnBuffers<R>>,
        group_rows: usize,
    ) -> Self {
        Self {
            state: State::Idle(out),
            columns: columns.to_vec(),
            group_rows,
            buffers,
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
        self.buffers.push(row).map_err(ParquetError::General)?;
        if self.buffers.len() >= self.group_rows {
            self.write_group()?;
        }
        Ok(())
    }

    fn write_group(&mut self) -> Result<(), ParquetError> {
        let rows = self.buffers.len();
        let columns = self.buffers.take();
        let file = self.file()?;
        if rows == 0 {
            return Ok(());
        }
        let levels =
            |present: &[bool]| -> Vec<i16> { present.iter().map(|&p| i16::from(p)).collect() };
        let bytes = |labels: &[Option<&str>]| -> Vec<ByteArray> {
            labels
                .iter()
                .flatten()
                .map(|s| ByteArray::from(s.as_bytes().to_vec()))
                .collect()
        };
        let mut group = file.next_row_group()?;
        for values in columns {
            let mut column = next_column(&mut group)?;
            match values {
                Values::Number(values) => {
                    column
                        .typed::<DoubleType>()
                        .write_batch(&values, None, None)?;
                }
                Values::OptNumber(values, present) => {
                    column.typed::<DoubleType>().write_batch(
                        &present_only(&values, &present),
                        Some(&levels(&present)),
                        None,
                    )?;
                }
                Values::Label(labels) => {
                    let present: Vec<bool> = labels.iter().map(Option::is_some).collect();
                    column.typed::<ByteArrayType>().write_batch(
                        &bytes(&labels),
                        Some(&levels(&present)),
                        None,
                    )?;
                }
                Values::Text(texts) => {
                    let present: Vec<bool> = texts.iter().map(Option::is_some).collect();
                    let values: Vec<ByteArray> = texts
                        .into_iter()
                        .flatten()
                        .map(|s| ByteArray::from(s.into_bytes()))
                        .collect();
                    column.typed::<ByteArrayType>().write_batch(
                        &values,
                        Some(&levels(&present)),
                        None,
                    )?;
                }
                Values::Utc(values, present) | Values::Integer(values, present) => {
                    column.typed::<Int64Type>().write_batch(
                        &present_only(&values, &present),
                        Some(&levels(&present)),
                        None,
                    )?;
                }
                Values::Bool(values, present) => {
                    column.typed::<BoolType>().write_batch(
                        &present_only(&values, &present),
                        Some(&levels(&present)),
                        None,
                    )?;
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
