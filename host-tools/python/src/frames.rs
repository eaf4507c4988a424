//! A log's frames as a [`Table`]: the rows `wobblog decode` writes, in its
//! columns and time window, decoded without the GIL.

use std::ops::ControlFlow;
use std::path::Path;

use pyo3::prelude::*;
use wobble_core::format::{DecodeStats, Event, Record};
use wobblog::export::columns::Column;
use wobblog::export::frame_columns::FrameColumns;
use wobblog::losses::Losses;
use wobblog::reader::read_log_until;
use wobblog::summary::RowStats;
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::stream::Table;

/// Records between two looks for a pending `KeyboardInterrupt`.
const RECORDS_PER_SIGNAL_CHECK: usize = 1 << 14;

/// What one pass over a log gave.
pub struct Decoded {
    /// The rows inside the window.
    pub table: Table,
    /// The decoder's totals.
    pub stats: DecodeStats,
    /// First and last boot time of every row (inside the window or not), s.
    pub span_s: Option<(f64, f64)>,
    /// What a summary takes from every row (inside the window or not).
    pub row_stats: RowStats,
    /// The log has a UTC sync pair.
    pub has_utc: bool,
}

/// Records handed from the decoding thread to the one building the
/// columns at a time.
const RECORDS_PER_HANDOVER: usize = 1024;

/// What the thread building the columns gives back.
struct Built {
    frames: FrameColumns,
    /// Ctrl-C, which stopped the building (and so the decoding).
    interrupted: Option<PyErr>,
}

/// The records the rows are made of (frames, fixes, sync pairs; see
/// [`wobblog::rows::Assembly::push`]), owned, so they can go to another
/// thread.
fn row_record(record: &Record<'_>) -> Option<Record<'static>> {
    match *record {
        Record::Frame(f) => Some(Record::Frame(f)),
        Record::Gps(g) => Some(Record::Gps(g)),
        Record::UtcSync(s) => Some(Record::UtcSync(s)),
        _ => None,
    }
}

/// Turns records into the columns of every row.
fn build(records: std::sync::mpsc::Receiver<Vec<Record<'static>>>) -> Built {
    let mut built = Built {
        frames: FrameColumns::new(),
        interrupted: None,
    };
    let mut since_check = 0;
    for batch in &records {
        for record in &batch {
            built.frames.push(record);
        }
        // Python runs signal handlers on its main thread only: the one that
        // called, this one.
        since_check += batch.len();
        if since_check >= RECORDS_PER_SIGNAL_CHECK {
            since_check = 0;
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                // Dropping the receiver stops the decoding.
                built.interrupted = Some(e);
                return built;
            }
        }
    }
    built.frames.finish();
    built
}

/// Decodes the log at `path` once: its rows inside `window`, in `columns`,
/// and every decoder event passed to `observe` as well (a summary, the
/// losses). The log is decoded on a second thread while this one builds
/// the rows and their columns. Called without the GIL; it is taken briefly now and
/// then to see whether Ctrl-C was pressed, which ends the decoding with
/// `KeyboardInterrupt`.
pub fn walk(
    path: &Path,
    columns: &[Column],
    window: TimeWindow,
    mut observe: impl FnMut(&Event<'_>) + Send,
) -> PyResult<Decoded> {
    let fail = |e: CliError| crate::errors::to_py(e);
    window.check_order(path).map_err(fail)?;
    let (walked, has_utc, built) = std::thread::scope(|scope| {
        let (send, records) = std::sync::mpsc::sync_channel(8);
        let decoder = scope.spawn(move || {
            let mut has_utc = false;
            let mut batch = Vec::with_capacity(RECORDS_PER_HANDOVER);
            // The reader's usual chunks from the start (the first is clamped
            // to them).
            let walked = read_log_until(path, usize::MAX, |event| {
                observe(&event);
                if let Event::Record(record) = &event {
                    has_utc |= matches!(record, Record::UtcSync(_));
                    if let Some(owned) = row_record(record) {
                        batch.push(owned);
                        if batch.len() == RECORDS_PER_HANDOVER {
                            let full = std::mem::replace(
                                &mut batch,
                                Vec::with_capacity(RECORDS_PER_HANDOVER),
                            );
                            if send.send(full).is_err() {
                                // The builder stopped (Ctrl-C).
                                return ControlFlow::Break(());
                            }
                        }
                    }
                }
                ControlFlow::Continue(())
            });
            let _ = send.send(batch);
            (walked, has_utc)
        });
        // The rows are built on this thread, the caller's, where Python
        // looks for Ctrl-C.
        let built = build(records);
        let (walked, has_utc) = match decoder.join() {
            Ok(done) => done,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (walked, has_utc, built)
    });
    let Built {
        mut frames,
        interrupted,
    } = built;
    if let Some(e) = interrupted {
        return Err(e);
    }
    let stats = walked.map_err(fail)?;
    // Of every row, inside the window or not.
    let span_s = frames.span_s();
    let row_stats = frames.row_stats();
    if !window.is_all() {
        frames.retain(&window);
        if frames.is_empty() {
            return Err(fail(
                window.selects_nothing(path, "frames", span_s, has_utc),
            ));
        }
    }
    let (schema, batches) =
        crate::table::frames(&frames, columns).map_err(|e| arrow_error(path, &e))?;
    Ok(Decoded {
        table: Table::new(schema, batches),
        stats,
        span_s,
        row_stats,
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
