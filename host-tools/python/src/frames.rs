//! A log's frames as a [`Table`]: the rows `wobblog decode` writes, in its
//! columns and time window, decoded without the GIL.

use std::ops::ControlFlow;
use std::path::Path;

use pyo3::prelude::*;
use wobble_core::format::{DecodeStats, Event, Record};
use wobblog::export::columns::Column;
use wobblog::losses::Losses;
use wobblog::reader::read_log_until;
use wobblog::rows::{Row, RowAssembler};
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::stream::Table;
use crate::table::TableBuilder;

/// Decoder events between two looks for a pending `KeyboardInterrupt`.
const EVENTS_PER_SIGNAL_CHECK: u32 = 1 << 14;

/// What one pass over a log gave.
pub struct Decoded {
    /// The rows inside the window.
    pub table: Table,
    /// The decoder's totals.
    pub stats: DecodeStats,
    /// First and last boot time of every row (inside the window or not), s.
    pub span_s: Option<(f64, f64)>,
    /// The log has a UTC sync pair.
    pub has_utc: bool,
}

/// Decodes the log at `path` once: its rows inside `window`, in `columns`,
/// and every decoder event passed to `observe` as well (a summary, the
/// losses). Called without the GIL; it is taken briefly now and then to see
/// whether Ctrl-C was pressed, which ends the decoding with
/// `KeyboardInterrupt`.
pub fn walk(
    path: &Path,
    columns: &[Column],
    window: TimeWindow,
    mut observe: impl FnMut(&Event<'_>),
) -> PyResult<Decoded> {
    let fail = |e: CliError| crate::errors::to_py(e);
    window.check_order(path).map_err(fail)?;
    let mut table = TableBuilder::frames(columns);
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
    let mut events = 0u32;
    let mut interrupted = None;
    // The reader's usual chunks from the start (the first is clamped to them).
    let stats = read_log_until(path, usize::MAX, |event| {
        observe(&event);
        if let Event::Record(record) = event {
            has_utc |= matches!(record, Record::UtcSync(_));
            rows.push(&record, &mut keep);
        }
        events = events.wrapping_add(1);
        if events.is_multiple_of(EVENTS_PER_SIGNAL_CHECK) {
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                interrupted = Some(e);
                return ControlFlow::Break(());
            }
        }
        ControlFlow::Continue(())
    })
    .map_err(fail)?;
    if let Some(e) = interrupted {
        return Err(e);
    }
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
    Ok(Decoded {
        table: Table::new(schema, batches),
        stats,
        span_s,
        has_utc,
    })
}

/// The rows of the log at `path` inside `window`, in `columns`, and what
/// the log lost (see [`walk`]).
pub fn decode(path: &Path, columns: &[Column], window: TimeWindow) -> PyResult<(Table, Losses)> {
    let mut losses = Losses::default();
    let decoded = walk(path, columns, window, |event| losses.observe(event))?;
    Ok((decoded.table, losses))
}

pub fn arrow_error(path: &Path, e: &arrow_schema::ArrowError) -> PyErr {
    crate::errors::to_py(CliError::file(
        path,
        format!("cannot build the Arrow table: {e}"),
    ))
}
