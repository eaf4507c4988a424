//! A log's frames as a [`Table`]: the rows `wobblog decode` writes, in its
//! columns and time window, decoded without the GIL.

use std::cell::RefCell;
use std::ops::ControlFlow;
use std::path::Path;

use arrow_array::RecordBatch;
use arrow_schema::SchemaRef;
use pyo3::prelude::*;
use wobble_core::format::{DecodeStats, Event, Record};
use wobblog::export::columns::Column;
use wobblog::export::frame_columns::FrameColumns;
use wobblog::losses::Losses;
use wobblog::reader::read_log_restarting;
use wobblog::summary::{RowStats, SummaryBuilder};
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::stream::Table;
use crate::table::{record_batch, schema, BATCH_ROWS};

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
const RECORDS_PER_HANDOVER: usize = 4096;

/// What the thread building the columns gives back.
struct Built {
    /// The rows not converted yet.
    frames: FrameColumns,
    /// The record batches converted so far.
    batches: Vec<RecordBatch>,
    failure: Option<arrow_schema::ArrowError>,
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

/// What goes from the decoding thread to the one building the columns.
enum Handed {
    /// The next records.
    Records(Vec<Record<'static>>),
    /// The decode starts again from the log's start.
    Restart,
}

/// What a log's events are handed to while it is decoded.
pub trait Observer: Send {
    /// Takes the log's next event.
    fn observe(&mut self, event: &Event<'_>);
    /// The decode starts again from the start of the log (its blocks were
    /// not in order): what was observed is to be forgotten.
    fn restart(&mut self);
}

impl Observer for SummaryBuilder {
    fn observe(&mut self, event: &Event<'_>) {
        SummaryBuilder::observe(self, event);
    }
    fn restart(&mut self) {
        *self = SummaryBuilder::rows_elsewhere();
    }
}

impl Observer for Losses {
    fn observe(&mut self, event: &Event<'_>) {
        Losses::observe(self, event);
    }
    fn restart(&mut self) {
        *self = Losses::default();
    }
}

/// The decoding thread's side: the observer, and the records on their way
/// to the thread building the columns.
struct Handover<'o, O> {
    observer: &'o mut O,
    send: std::sync::mpsc::SyncSender<Handed>,
    batch: Vec<Record<'static>>,
    /// Batches the builder is done with, to fill again: a few vectors go
    /// back and forth instead of fresh memory for every batch.
    emptied: std::sync::mpsc::Receiver<Vec<Record<'static>>>,
    has_utc: bool,
}

impl<O: Observer> Handover<'_, O> {
    fn take(&mut self, event: &Event<'_>) -> ControlFlow<()> {
        self.observer.observe(event);
        let Event::Record(record) = event else {
            return ControlFlow::Continue(());
        };
        self.has_utc |= matches!(record, Record::UtcSync(_));
        if let Some(owned) = row_record(record) {
            self.batch.push(owned);
            if self.batch.len() == RECORDS_PER_HANDOVER {
                let empty = self
                    .emptied
                    .try_recv()
                    .unwrap_or_else(|_| Vec::with_capacity(RECORDS_PER_HANDOVER));
                let full = std::mem::replace(&mut self.batch, empty);
                if self.send.send(Handed::Records(full)).is_err() {
                    // The builder stopped (Ctrl-C).
                    return ControlFlow::Break(());
                }
            }
        }
        ControlFlow::Continue(())
    }

    fn restart(&mut self) {
        self.observer.restart();
        self.batch.clear();
        self.has_utc = false;
        // A builder that stopped (Ctrl-C) stops the decoding by itself.
        let _ = self.send.send(Handed::Restart);
    }
}

/// Turns records into the columns of the rows inside `window`, a record
/// batch as soon as [`BATCH_ROWS`] rows are complete.
fn build(
    records: std::sync::mpsc::Receiver<Handed>,
    emptied: std::sync::mpsc::Sender<Vec<Record<'static>>>,
    frames: FrameColumns,
    schema: &SchemaRef,
) -> Built {
    let mut built = Built {
        frames,
        batches: Vec::new(),
        failure: None,
        interrupted: None,
    };
    let mut since_check = 0;
    for handed in &records {
        let mut batch = match handed {
            Handed::Records(batch) => batch,
            Handed::Restart => {
                built.frames.restart();
                built.batches.clear();
                continue;
            }
        };
        for record in &batch {
            built.frames.push(record);
        }
        for values in built.frames.take_full() {
            match record_batch(schema, values) {
                Ok(b) => built.batches.push(b),
                Err(e) => built.failure = Some(e),
            }
        }
        // Python runs signal handlers on its main thread only: the one that
        // called, this one.
        since_check += batch.len();
        batch.clear();
        // A decoder that has finished takes none back.
        let _ = emptied.send(batch);
        if since_check >= RECORDS_PER_SIGNAL_CHECK {
            since_check = 0;
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                // Dropping the receiver stops the decoding.
                built.interrupted = Some(e);
                return built;
            }
        }
    }
    built
}

/// Decodes the log at `path` once: its rows inside `window`, in `columns`,
/// and every decoder event passed to `observer` as well (a summary, the
/// losses). The log is decoded on a second thread while this one builds
/// the rows and their columns, in one pass when its blocks are in order
/// ([`read_log_restarting`]); rows are converted as soon as they are
/// complete. Called without the GIL; it is taken briefly now and
/// then to see whether Ctrl-C was pressed, which ends the decoding with
/// `KeyboardInterrupt`.
pub fn walk(
    path: &Path,
    columns: &[Column],
    window: TimeWindow,
    observer: &mut impl Observer,
) -> PyResult<Decoded> {
    let fail = |e: CliError| crate::errors::to_py(e);
    window.check_order(path).map_err(fail)?;
    let frames = FrameColumns::new(columns, window, BATCH_ROWS)
        .map_err(|e| fail(CliError::file(path, e)))?;
    let schema = schema(columns);
    let (walked, has_utc, built) = std::thread::scope(|scope| {
        let (send, records) = std::sync::mpsc::sync_channel(8);
        let (give_back, emptied) = std::sync::mpsc::channel();
        let decoder = scope.spawn(move || {
            let handover = RefCell::new(Handover {
                observer,
                send,
                batch: Vec::with_capacity(RECORDS_PER_HANDOVER),
                emptied,
                has_utc: false,
            });
            let walked = read_log_restarting(
                path,
                |event| handover.borrow_mut().take(&event),
                || handover.borrow_mut().restart(),
            );
            let mut handover = handover.into_inner();
            let batch = std::mem::take(&mut handover.batch);
            let _ = handover.send.send(Handed::Records(batch));
            (walked, handover.has_utc)
        });
        // The rows are built on this thread, the caller's, where Python
        // looks for Ctrl-C.
        let built = build(records, give_back, frames, &schema);
        let (walked, has_utc) = match decoder.join() {
            Ok(done) => done,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (walked, has_utc, built)
    });
    let Built {
        frames,
        mut batches,
        failure,
        interrupted,
    } = built;
    if let Some(e) = interrupted {
        return Err(e);
    }
    let stats = walked.map_err(fail)?;
    if let Some(e) = failure {
        return Err(arrow_error(path, &e));
    }
    let finished = frames.finish();
    if finished.rows == 0 && !window.is_all() {
        return Err(fail(window.selects_nothing(
            path,
            "frames",
            finished.span_s,
            has_utc,
        )));
    }
    for values in finished.batches {
        batches.push(record_batch(&schema, values).map_err(|e| arrow_error(path, &e))?);
    }
    Ok(Decoded {
        table: Table::new(schema, batches),
        stats,
        span_s: finished.span_s,
        row_stats: finished.row_stats,
        has_utc,
    })
}

/// The rows of the log at `path` inside `window`, in `columns`, and what
/// the log lost (see [`walk`]).
pub fn decode(path: &Path, columns: &[Column], window: TimeWindow) -> PyResult<(Table, Losses)> {
    let mut losses = Losses::default();
    let decoded = walk(path, columns, window, &mut losses)?;
    Ok((decoded.table, losses))
}

pub fn arrow_error(path: &Path, e: &arrow_schema::ArrowError) -> PyErr {
    crate::errors::to_py(CliError::file(
        path,
        format!("cannot build the Arrow table: {e}"),
    ))
}
