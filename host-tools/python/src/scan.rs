//! `wobblog.scan` and `wobblog.summary`: every log of a card or a folder of
//! cards, as `wobblog export` and `wobblog summary` take them.

use std::path::PathBuf;
use std::sync::Arc;

use arrow_array::ffi_stream::FFI_ArrowArrayStream;
use arrow_array::{ArrayRef, Int64Array, RecordBatch, StringViewArray};
use arrow_schema::{ArrowError, DataType, Field, Schema, SchemaRef};
use pyo3::prelude::*;
use pyo3::types::PyCapsule;
use wobblog::analysis::Ride;
use wobblog::cmd::summary::card_row;
use wobblog::dataset::{campaign_logs, cards_in, LogEntry};
use wobblog::export::columns::{self, Column};
use wobblog::time::TimeWindow;

use crate::errors::{detached, warn_damage, WobblogError};
use crate::window::window;

/// The frames of every log of a card (`RUNnnnnn.WBL` at its top) or of a
/// folder of cards, as one table with the columns of `Log.frames()` then
/// `run` (the number in the log's name) and, for a folder of cards, `card`
/// (its directory's name): the columns of `wobblog export`'s frames
/// dataset (whose files put `run` first). Logs are decoded one at a time as the table is read, so memory
/// does not grow with their number.
#[pyclass(module = "wobblog", name = "Scan", frozen)]
pub struct Scan {
    entries: Vec<LogEntry>,
    columns: Vec<Column>,
    window: TimeWindow,
    schema: SchemaRef,
}

/// Opens the campaign in `dir` for [`Scan`].
#[pyfunction]
#[pyo3(signature = (dir, columns = None, start = None, end = None))]
pub fn scan(
    py: Python<'_>,
    dir: PathBuf,
    columns: Option<Vec<String>>,
    start: Option<Bound<'_, PyAny>>,
    end: Option<Bound<'_, PyAny>>,
) -> PyResult<Scan> {
    let shown = dir.display().to_string();
    let chosen = columns::select_from(columns.map(|c| c.join(",")).as_deref(), &[])
        .map_err(|e| WobblogError::new_err(format!("{shown}: {e}")))?;
    let window = window(start.as_ref(), end.as_ref())?;
    let entries = detached(py, &shown, || campaign_logs(&dir))?;
    let mut fields: Vec<Field> = crate::table::schema(&chosen)
        .fields()
        .iter()
        .map(|f| f.as_ref().clone())
        .collect();
    fields.push(Field::new("run", DataType::Int64, false));
    if entries.iter().any(|e| e.card.is_some()) {
        fields.push(Field::new("card", DataType::Utf8View, false));
    }
    Ok(Scan {
        entries,
        columns: chosen,
        window,
        schema: Arc::new(Schema::new(fields)),
    })
}

#[pymethods]
impl Scan {
    /// The logs, in the order their frames come.
    #[getter]
    fn logs(&self) -> Vec<PathBuf> {
        self.entries.iter().map(|e| e.path.clone()).collect()
    }

    /// Column names, in order.
    #[getter]
    fn column_names(&self) -> Vec<String> {
        self.schema
            .fields()
            .iter()
            .map(|f| f.name().clone())
            .collect()
    }

    /// The frames of every log as an Arrow C stream (PyCapsule
    /// `arrow_array_stream`), each log decoded when the reader gets to it.
    #[pyo3(signature = (requested_schema = None))]
    fn __arrow_c_stream__<'py>(
        &self,
        py: Python<'py>,
        requested_schema: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyCapsule>> {
        let _ = requested_schema;
        let reader = LogByLog {
            entries: self.entries.clone().into_iter(),
            columns: self.columns.clone(),
            window: self.window,
            schema: self.schema.clone(),
            pending: Vec::new().into_iter(),
        };
        let stream = FFI_ArrowArrayStream::new(Box::new(reader));
        PyCapsule::new_with_value(py, stream, c"arrow_array_stream")
    }

    /// The frames as a `polars.DataFrame` (needs polars).
    fn to_polars<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        crate::stream::to_polars(slf.as_any())
    }

    /// The frames as a `polars.LazyFrame` (needs polars): each log decoded
    /// when the query reaches it, with the query's column choice, filter
    /// and row limit applied to it before the next is read.
    fn lazy<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        slf.py()
            .import("wobblog._lazy")?
            .call_method1("lazy_frame", (slf,))
    }

    /// One scan per log, in order, with this scan's columns and window
    /// (what [`Self::lazy`] reads one after another).
    fn _parts(&self) -> Vec<Self> {
        self.entries
            .iter()
            .map(|e| Self {
                entries: vec![e.clone()],
                ..self.without_logs()
            })
            .collect()
    }

    /// This scan without its logs: its columns, no rows.
    fn _empty(&self) -> Self {
        self.without_logs()
    }

    /// The frames as a `pyarrow.Table` (needs pyarrow).
    fn to_arrow<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        crate::stream::to_arrow(slf.as_any())
    }

    fn __repr__(&self) -> String {
        format!("wobblog.Scan({} logs)", self.entries.len())
    }
}

impl Scan {
    /// This scan's columns, window and schema, with no logs.
    fn without_logs(&self) -> Self {
        Self {
            entries: Vec::new(),
            columns: self.columns.clone(),
            window: self.window,
            schema: self.schema.clone(),
        }
    }
}

/// The batches of one log after another.
struct LogByLog {
    entries: std::vec::IntoIter<LogEntry>,
    columns: Vec<Column>,
    window: TimeWindow,
    schema: SchemaRef,
    pending: std::vec::IntoIter<RecordBatch>,
}

impl LogByLog {
    /// The batches of `entry` with its `run` (and `card`) columns; a log
    /// that cannot be read, or has no frame in the window, gives none and a
    /// warning, as `wobblog export` goes on past it.
    fn batches_of(&self, entry: &LogEntry) -> Result<Vec<RecordBatch>, ArrowError> {
        let decoded = crate::frames::decode(&entry.path, &self.columns, self.window);
        let (table, losses) = match decoded {
            Ok(decoded) => decoded,
            Err(e) => {
                let interrupted = Python::attach(|py| {
                    e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py)
                });
                if interrupted {
                    return Err(ArrowError::ExternalError(Box::new(e)));
                }
                warn(&format!("{e} (left out of the scan)"))?;
                return Ok(Vec::new());
            }
        };
        for line in wobblog::cmd::logs::warnings(&losses) {
            warn(&format!("{}: {line}", entry.path.display()))?;
        }
        let (_, batches) = table.into_parts();
        batches
            .into_iter()
            .map(|batch| {
                let n = batch.num_rows();
                let mut arrays: Vec<ArrayRef> = batch.columns().to_vec();
                arrays.push(Arc::new(Int64Array::from(vec![i64::from(entry.run); n])));
                if self.schema.fields().len() > arrays.len() {
                    let card = entry.card.clone().unwrap_or_default();
                    arrays.push(Arc::new(StringViewArray::from(vec![card; n])));
                }
                RecordBatch::try_new(self.schema.clone(), arrays)
            })
            .collect()
    }
}

/// A `DamageWarning` from inside a stream; a warnings filter that turns it
/// into an error ends the stream with that error.
fn warn(message: &str) -> Result<(), ArrowError> {
    Python::attach(|py| warn_damage(py, message))
        .map_err(|e| ArrowError::ExternalError(Box::new(e)))
}

impl Iterator for LogByLog {
    type Item = Result<RecordBatch, ArrowError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(batch) = self.pending.next() {
                return Some(Ok(batch));
            }
            let entry = self.entries.next()?;
            match self.batches_of(&entry) {
                Ok(batches) => self.pending = batches.into_iter(),
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

impl arrow_array::RecordBatchReader for LogByLog {
    fn schema(&self) -> SchemaRef {
        self.schema.clone()
    }
}

/// One row per run of a card or folder of cards, as the lines of `wobblog
/// summary --json`. A log that cannot be read is a `DamageWarning` and left
/// out, as the CLI reports it and goes on.
#[pyfunction]
pub fn summary<'py>(py: Python<'py>, dir: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let shown = dir.display().to_string();
    let cards = detached(py, &shown, || cards_in(&dir))?;
    let logs: Vec<PathBuf> = cards.iter().flat_map(|(_, logs)| logs.clone()).collect();
    let rides = detached(py, &shown, || {
        Ok(logs.iter().map(|log| Ride::load(log)).collect::<Vec<_>>())
    })?;
    let mut rows = Vec::new();
    for ride in rides {
        match ride {
            Ok(ride) => {
                for line in wobblog::cmd::logs::warnings(&ride.summary.losses) {
                    warn_damage(py, &format!("{}: {line}", ride.path.display()))?;
                }
                rows.push(card_row(&cards, &ride));
            }
            Err(e) => warn_damage(py, &format!("{e} (left out of the summary)"))?,
        }
    }
    crate::json::to_py(py, &rows)
}
