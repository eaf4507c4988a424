//! Decoded frames as Arrow record batches, one array per column of the
//! CLI's column table (`wobblog::export::columns`), so names, order, units
//! and types are those of `wobblog decode`'s Parquet. The columns are
//! built by the library (`wobblog::export::columnar`), as for that Parquet,
//! and their vectors become the arrays' buffers.

use std::sync::Arc;

use arrow_array::{
    ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringArray,
    TimestampMicrosecondArray,
};
use arrow_buffer::{NullBuffer, OffsetBuffer};
use arrow_schema::{ArrowError, DataType, Field, Schema, SchemaRef, TimeUnit};
use wobblog::export::columnar::{buffers, ColumnBuffers, Values};
use wobblog::export::columns::{Column, Kind};
use wobblog::export::frame_columns::FrameColumns;
use wobblog::rows::Row;

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
        Values::Text(v) => Arc::new(StringArray::from(v)),
        Values::Utc(v, present) => {
            Arc::new(TimestampMicrosecondArray::new(v.into(), nulls(present)).with_timezone("UTC"))
        }
        Values::Integer(v, present) => Arc::new(Int64Array::new(v.into(), nulls(present))),
        Values::Bool(v, present) => Arc::new(BooleanArray::new(v.into(), nulls(present))),
    }
}

/// Names from a small set (a few bytes each) as a string array, laid out
/// in one pass.
fn labels(values: &[Option<&str>]) -> StringArray {
    let mut bytes = Vec::with_capacity(4 * values.len());
    let offsets = OffsetBuffer::from_lengths(values.iter().map(|v| {
        let s = v.unwrap_or_default();
        bytes.extend_from_slice(s.as_bytes());
        s.len()
    }));
    let nulls = NullBuffer::from_iter(values.iter().map(Option::is_some));
    let nulls = (nulls.null_count() > 0).then_some(nulls);
    StringArray::new(offsets, bytes.into(), nulls)
}

/// Rows of `R` turned into record batches of [`BATCH_ROWS`] rows.
pub struct TableBuilder<R: 'static> {
    schema: SchemaRef,
    buffers: Box<dyn ColumnBuffers<R>>,
    batches: Vec<RecordBatch>,
}

/// Decoded frames in `columns` as record batches of [`BATCH_ROWS`] rows,
/// each converted once its rows are complete (while the log is still
/// being decoded), the last ones on two threads.
pub struct FrameBatches<'c> {
    schema: SchemaRef,
    columns: &'c [Column<Row>],
    batches: Vec<RecordBatch>,
    /// Rows converted.
    done: usize,
}

impl<'c> FrameBatches<'c> {
    /// No batch yet.
    #[must_use]
    pub fn new(columns: &'c [Column<Row>]) -> Self {
        Self {
            schema: schema(columns),
            columns,
            batches: Vec::new(),
            done: 0,
        }
    }

    fn batch(&self, frames: &FrameColumns, start: usize) -> Result<RecordBatch, ArrowError> {
        let range = start..frames.len().min(start + BATCH_ROWS);
        let arrays = frames
            .values(self.columns, range)
            .map_err(ArrowError::InvalidArgumentError)?
            .into_iter()
            .map(array)
            .collect();
        RecordBatch::try_new(self.schema.clone(), arrays)
    }

    /// Converts the whole batches of `frames`' complete rows not converted
    /// yet.
    ///
    /// # Errors
    /// A column is not one of the frame columns.
    pub fn convert_complete(&mut self, frames: &FrameColumns) -> Result<(), ArrowError> {
        while frames.complete() >= self.done + BATCH_ROWS {
            let batch = self.batch(frames, self.done)?;
            self.batches.push(batch);
            self.done += BATCH_ROWS;
        }
        Ok(())
    }

    /// The schema and every batch, the rows not converted yet converted
    /// now (every other batch on a second thread): at least one batch,
    /// empty for no rows, so every consumer sees the columns.
    ///
    /// # Errors
    /// A column is not one of the frame columns.
    pub fn finish(
        mut self,
        frames: &FrameColumns,
    ) -> Result<(SchemaRef, Vec<RecordBatch>), ArrowError> {
        let rows = frames.len();
        let mut starts = (self.done..rows).step_by(BATCH_ROWS).collect::<Vec<_>>();
        if rows == 0 {
            starts.push(0);
        }
        let this = &self;
        let (even, odd) = std::thread::scope(|scope| {
            let odd = scope.spawn(|| {
                starts
                    .iter()
                    .skip(1)
                    .step_by(2)
                    .map(|&s| this.batch(frames, s))
                    .collect::<Vec<_>>()
            });
            let even: Vec<_> = starts
                .iter()
                .step_by(2)
                .map(|&s| this.batch(frames, s))
                .collect();
            (
                even,
                odd.join().unwrap_or_else(|p| std::panic::resume_unwind(p)),
            )
        });
        let (mut even, mut odd) = (even.into_iter(), odd.into_iter());
        for i in 0..starts.len() {
            let batch = if i % 2 == 0 { even.next() } else { odd.next() };
            if let Some(batch) = batch {
                self.batches.push(batch?);
            }
        }
        Ok((self.schema, self.batches))
    }
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
        let arrays = self.buffers.take().into_iter().map(array).collect();
        self.batches
            .push(RecordBatch::try_new(self.schema.clone(), arrays)?);
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
