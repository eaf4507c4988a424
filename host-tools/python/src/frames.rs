//! A log's frames as a [`Table`]: the rows `wobblog decode` writes, in its
//! columns and time window, decoded without the GIL.

use std::path::Path;

use pyo3::prelude::*;
use wobble_core::format::{Event, Record};
use wobblog::export::columns::Column;
use wobblog::losses::Losses;
use wobblog::reader::read_log_try;
use wobblog::rows::{Row, RowAssembler};
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::stream::Table;
use crate::table::TableBuilder;

/// Decoder events between two looks for a pending `KeyboardInterrupt`.
const EVENTS_PER_SIGNAL_CHECK: u32 = 1 << 16;

/// The rows of the log at `path` inside `window`, in `columns`, and what
/// the log lost. Called without the GIL; it is taken briefly now and then
/// to see whether Ctrl-C was pressed, which ends the decoding with
/// `KeyboardInterrupt`.
pub fn decode(path: &Path, columns: Vec<Column>, window: TimeWindow) -> PyResult<(Table, Losses)> {
    let fail = |e: CliError| crate::errors::to_py(e);
    window.check_order(path).map_err(fail)?;
    let mut table = TableBuilder::new(columns);
    let mut kept = 0u64;
    let mut span_s: Option<(f64, f64)> = None;
    let mut has_utc = false;
    let mut failure: Option<arrow_schema::ArrowError> = None;
    let mut keep = |row: &Row| {
        span_s = Some(span_s.map_or((row.t_s, row.t_s), |(a, b)| {
            (a.min(row.t_s), b.max(row.t_s))
        }));
        // As `wobblog decode`: a row is in when its boot time or UTC (ms) is.
        if window.is_all() || window.contains(row.t_s, row.utc_us.map(|u| u / 1000)) {
            kept += 1;
            if failure.is_none() {
                failure = table.push(row).err();
            }
        }
    };
    let mut rows = RowAssembler::new();
    let mut losses = Losses::default();
    let mut events = 0u32;
    let walked = read_log_try(path, |event| {
        losses.observe(&event);
        if let Event::Record(record) = event {
            has_utc |= matches!(record, Record::UtcSync(_));
            rows.push(&record, &mut keep);
        }
        events = events.wrapping_add(1);
        if events.is_multiple_of(EVENTS_PER_SIGNAL_CHECK) {
            Python::attach(|py| py.check_signals())?;
        }
        Ok::<(), PyErr>(())
    })
    .map_err(fail)?;
    walked?;
    rows.finish(&mut keep);
    if let Some(e) = failure {
        return Err(arrow_error(path, &e));
    }
    if kept == 0 && !window.is_all() {
        return Err(fail(
            window.selects_nothing(path, "frames", span_s, has_utc),
        ));
    }
    let (schema, batches) = table.finish().map_err(|e| arrow_error(path, &e))?;
    Ok((Table::new(schema, batches), losses))
}

fn arrow_error(path: &Path, e: &arrow_schema::ArrowError) -> PyErr {
    crate::errors::to_py(CliError::file(
        path,
        format!("cannot build the Arrow table: {e}"),
    ))
}
