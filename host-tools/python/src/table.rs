//! Decoded frames as Arrow record batches, one array per column of the
//! CLI's column table (`wobblog::export::columns`), so names, order, units
//! and types are those of `wobblog decode`'s Parquet.

use std::sync::Arc;

use arrow_array::builder::{
    BooleanBuilder, Float64Builder, Int64Builder, StringBuilder, TimestampMicrosecondBuilder,
};
use arrow_array::{ArrayRef, RecordBatch};
use arrow_schema::{ArrowError, DataType, Field, Schema, SchemaRef, TimeUnit};
use wobblog::export::columns::{Column, Kind, Value};

/// Rows per record batch: large enough that per-batch costs vanish, small
/// enough that a consumer can start before a long log is converted.
pub const BATCH_ROWS: usize = 1 << 16;

/// The Arrow type of a column kind, as Parquet types it in `decode`.
fn data_type(kind: Kind) -> DataType {
    match kind {
        Kind::Number | Kind::OptNumber => DataType::Float64,
        Kind::Label | Kind::Text => DataType::Utf8,
        Kind::Utc => DataType::Timestamp(TimeUnit::Microsecond, Some("UTC".into())),
        Kind::Integer => DataType::Int64,
        Kind::Bool => DataType::Boolean,
    }
}

/// The schema of `columns`.
#[must_use]
pub fn schema<R>(columns: &[Column<R>]) -> SchemaRef {
    let fields: Vec<Field> = columns
        .iter()
        .map(|c| Field::new(c.name, data_type(c.kind), c.kind != Kind::Number))
        .collect();
    Arc::new(Schema::new(fields))
}

/// One column being filled.
enum Builder {
    Number(Float64Builder),
    Text(StringBuilder),
    Utc(TimestampMicrosecondBuilder),
    Integer(Int64Builder),
    Bool(BooleanBuilder),
}

impl Builder {
    fn new(kind: Kind) -> Self {
        match kind {
            Kind::Number | Kind::OptNumber => {
                Self::Number(Float64Builder::with_capacity(BATCH_ROWS))
            }
            Kind::Label | Kind::Text => Self::Text(StringBuilder::new()),
            Kind::Utc => Self::Utc(
                TimestampMicrosecondBuilder::with_capacity(BATCH_ROWS).with_timezone("UTC"),
            ),
            Kind::Integer => Self::Integer(Int64Builder::with_capacity(BATCH_ROWS)),
            Kind::Bool => Self::Bool(BooleanBuilder::with_capacity(BATCH_ROWS)),
        }
    }

    fn push(&mut self, value: Value) {
        match (self, value) {
            (Self::Number(b), Value::Number(v)) => b.append_option(v),
            (Self::Text(b), Value::Label(v)) => b.append_option(v),
            (Self::Text(b), Value::Text(v)) => b.append_option(v),
            (Self::Utc(b), Value::Utc(v)) => b.append_option(v),
            (Self::Integer(b), Value::Integer(v)) => b.append_option(v),
            (Self::Bool(b), Value::Bool(v)) => b.append_option(v),
            // A column's kind fixes its values' variant (columns.rs).
            (_, value) => unreachable!("a column value of another kind: {value:?}"),
        }
    }

    fn finish(&mut self) -> ArrayRef {
        match self {
            Self::Number(b) => Arc::new(b.finish()),
            Self::Text(b) => Arc::new(b.finish()),
            Self::Utc(b) => Arc::new(b.finish()),
            Self::Integer(b) => Arc::new(b.finish()),
            Self::Bool(b) => Arc::new(b.finish()),
        }
    }
}

/// Rows of `R` turned into record batches of [`BATCH_ROWS`] rows.
pub struct TableBuilder<R: 'static> {
    columns: Vec<Column<R>>,
    schema: SchemaRef,
    builders: Vec<Builder>,
    rows: usize,
    batches: Vec<RecordBatch>,
}

impl<R> TableBuilder<R> {
    /// A table of `columns`.
    #[must_use]
    pub fn new(columns: Vec<Column<R>>) -> Self {
        Self {
            schema: schema(&columns),
            builders: columns.iter().map(|c| Builder::new(c.kind)).collect(),
            columns,
            rows: 0,
            batches: Vec::new(),
        }
    }

    /// Appends one row.
    ///
    /// # Errors
    /// Arrow refuses the batch (cannot happen for builders of the schema's types).
    pub fn push(&mut self, row: &R) -> Result<(), ArrowError> {
        for (builder, column) in self.builders.iter_mut().zip(&self.columns) {
            builder.push((column.value)(row));
        }
        self.rows += 1;
        if self.rows == BATCH_ROWS {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), ArrowError> {
        let arrays = self.builders.iter_mut().map(Builder::finish).collect();
        self.batches
            .push(RecordBatch::try_new(self.schema.clone(), arrays)?);
        self.rows = 0;
        Ok(())
    }

    /// The schema and the batches (at least one, empty for no rows, so
    /// every consumer sees the columns).
    ///
    /// # Errors
    /// As [`Self::push`].
    pub fn finish(mut self) -> Result<(SchemaRef, Vec<RecordBatch>), ArrowError> {
        if self.rows > 0 || self.batches.is_empty() {
            self.flush()?;
        }
        Ok((self.schema, self.batches))
    }
}
