//! Decoded frames as Arrow record batches, one array per column of the
//! CLI's column table (`wobblog::export::columns`), so names, order, units
//! and types are those of `wobblog decode`'s Parquet. The columns are
//! built by the library (`wobblog::export::columnar`), as for that Parquet,
//! and their vectors become the arrays' buffers.

use std::sync::Arc;

use arrow_array::{
    ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringViewArray,
    TimestampMicrosecondArray, UInt32Array,
};
use arrow_buffer::NullBuffer;
use arrow_schema::{ArrowError, DataType, Field, Schema, SchemaRef, TimeUnit};
use wobblog::export::columnar::{buffers, ColumnBuffers, Values};
use wobblog::export::columns::{Column, Kind};

/// Rows per record batch: large enough that per-batch costs vanish, small
/// enough that a consumer can start before a long log is converted.
pub const BATCH_ROWS: usize = 1 << 16;

/// The Arrow type of a column kind, as Parquet types it in `decode`.
fn data_type(kind: Kind) -> DataType {
    match kind {
        Kind::Number | Kind::OptNumber => DataType::Float64,
        // As Polars holds text: it takes these columns without a copy.
        Kind::Label | Kind::Text => DataType::Utf8View,
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

/// One batch of a column as an Arrow array, its buffers moved, not copied
/// (text is laid out anew).
fn array(values: Values) -> ArrayRef {
    // A validity bitmap only where a row lacks its value.
    let nulls =
        |present: Vec<bool>| (!present.iter().all(|&p| p)).then(|| NullBuffer::from(present));
    match values {
        Values::Number(v) => Arc::new(Float64Array::new(v.into(), None)),
        Values::OptNumber(v, present) => Arc::new(Float64Array::new(v.into(), nulls(present))),
        Values::Label(v) => labels(&v),
        Values::Text(v) => Arc::new(StringViewArray::from_iter(v)),
        Values::Utc(v, present) => {
            Arc::new(TimestampMicrosecondArray::new(v.into(), nulls(present)).with_timezone("UTC"))
        }
        Values::Integer(v, present) => Arc::new(Int64Array::new(v.into(), nulls(present))),
        Values::Bool(v, present) => Arc::new(BooleanArray::new(v.into(), nulls(present))),
    }
}

/// Names from a small set (`2d`, `3d`, ...) as string views: each name's
/// view is made once, and each row's picked from those by its index (per
/// row, only an index and a copy, not a string built and checked).
fn labels<'a>(values: &[Option<&'a str>]) -> ArrayRef {
    let mut names: Vec<&'a str> = Vec::new();
    // Names are nearly always the same few `&'static str`s: their
    // addresses are compared before their bytes.
    let same = |a: &str, b: &str| std::ptr::eq(a, b) || a == b;
    let mut index_of = |name: &'a str| match names.iter().position(|n| same(n, name)) {
        Some(i) => i,
        None => {
            names.push(name);
            names.len() - 1
        }
    };
    let indices: Vec<u32> = values
        .iter()
        // Fewer names than 2^32 in a column of fewer rows.
        .map(|v| v.map_or(0, |name| index_of(name) as u32))
        .collect();
    if names.is_empty() {
        return Arc::new(StringViewArray::new_null(values.len()));
    }
    let nulls = (!values.iter().all(Option::is_some))
        .then(|| NullBuffer::from_iter(values.iter().map(Option::is_some)));
    let names = StringViewArray::from_iter_values(names);
    arrow_select::take::take(&names, &UInt32Array::new(indices.into(), nulls), None)
        .unwrap_or_else(|_| Arc::new(StringViewArray::from_iter(values.iter().copied())))
}

/// Rows of `R` turned into record batches of [`BATCH_ROWS`] rows.
pub struct TableBuilder<R: 'static> {
    schema: SchemaRef,
    buffers: Box<dyn ColumnBuffers<R>>,
    batches: Vec<RecordBatch>,
}

/// One batch of `schema`'s columns from their values.
///
/// # Errors
/// Arrow refuses the batch (cannot happen for the columns' own types).
pub fn record_batch(schema: &SchemaRef, values: Vec<Values>) -> Result<RecordBatch, ArrowError> {
    RecordBatch::try_new(schema.clone(), values.into_iter().map(array).collect())
}

impl<R: 'static> TableBuilder<R> {
    /// A table of `columns`.
    #[must_use]
    pub fn new(columns: &[Column<R>]) -> Self {
        Self {
            schema: schema(columns),
            buffers: buffers(columns, BATCH_ROWS),
            batches: Vec::new(),
        }
    }

    /// Appends one row.
    ///
    /// # Errors
    /// A value that does not fit its column, or Arrow refuses the batch
    /// (cannot happen for the columns' own types).
    pub fn push(&mut self, row: &R) -> Result<(), ArrowError> {
        self.buffers
            .push(row)
            .map_err(ArrowError::InvalidArgumentError)?;
        if self.buffers.len() == BATCH_ROWS {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), ArrowError> {
        let batch = record_batch(&self.schema, self.buffers.take())?;
        self.batches.push(batch);
        Ok(())
    }

    /// The schema and the batches (at least one, empty for no rows, so
    /// every consumer sees the columns).
    ///
    /// # Errors
    /// As [`Self::push`].
    pub fn finish(mut self) -> Result<(SchemaRef, Vec<RecordBatch>), ArrowError> {
        if !self.buffers.is_empty() || self.batches.is_empty() {
            self.flush()?;
        }
        Ok((self.schema, self.batches))
    }
}
