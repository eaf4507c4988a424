//! Decoded frames as Arrow record batches, one array per column of the
//! CLI's column table (`wobblog::export::columns`), so names, order, units
//! and types are those of `wobblog decode`'s Parquet. The columns are
//! built by the library (`wobblog::export::columnar`), as for that Parquet,
//! and their vectors become the arrays' buffers.

use std::sync::Arc;

use arrow_array::{
    ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringViewArray,
    TimestampMicrosecondArray,
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
    let nulls = |present: Vec<bool>| {
        let nulls = NullBuffer::from(present);
        (nulls.null_count() > 0).then_some(nulls)
    };
    match values {
        Values::Number(v) => Arc::new(Float64Array::new(v.into(), None)),
        Values::OptNumber(v, present) => Arc::new(Float64Array::new(v.into(), nulls(present))),
        Values::Label(v) => Arc::new(labels(&v)),
        Values::Text(v) => Arc::new(StringViewArray::from_iter(v)),
        Values::Utc(v, present) => {
            Arc::new(TimestampMicrosecondArray::new(v.into(), nulls(present)).with_timezone("UTC"))
        }
        Values::Integer(v, present) => Arc::new(Int64Array::new(v.into(), nulls(present))),
        Values::Bool(v, present) => Arc::new(BooleanArray::new(v.into(), nulls(present))),
    }
}

/// Longest text a string view holds in itself.
const INLINE_VIEW_LEN: usize = 12;

/// Names from a small set (`2d`, `3d`, ...) as string views: a name short
/// enough lives in its view, so each row's view is made without the
/// builder's per-row bookkeeping; longer names go through the builder.
fn labels(values: &[Option<&str>]) -> StringViewArray {
    let inline = |name: &str| {
        let mut view = [0u8; 16];
        view[..4].copy_from_slice(&(name.len() as u32).to_le_bytes());
        view[4..4 + name.len()].copy_from_slice(name.as_bytes());
        u128::from_le_bytes(view)
    };
    let built = || StringViewArray::from_iter(values.iter().copied());
    let short = |v: &Option<&str>| v.is_none_or(|name| name.len() <= INLINE_VIEW_LEN);
    if !values.iter().all(short) {
        return built();
    }
    let views: Vec<u128> = values.iter().map(|v| v.map_or(0, inline)).collect();
    let nulls = NullBuffer::from_iter(values.iter().map(Option::is_some));
    let nulls = (nulls.null_count() > 0).then_some(nulls);
    // Valid by construction; the builder, should Arrow think otherwise.
    StringViewArray::try_new(views.into(), Vec::new(), nulls).unwrap_or_else(|_| built())
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
