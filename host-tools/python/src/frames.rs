//! A log's frames as a [`Table`]: the rows `wobblog decode` writes, in its
//! columns and time window, decoded without the GIL.

use std::cell::RefCell;
use std::ops::ControlFlow;
use std::path::Path;

use pyo3::prelude::*;
use wobble_core::format::codec::FRAME_MIN_LEN;
use wobble_core::format::{DecodeStats, Event, Record};
use wobblog::export::columns::Column;
use wobblog::export::frame_columns::FrameColumns;
use wobblog::losses::Losses;
use wobblog::reader::read_log_restarting;
use wobblog::summary::{RowStats, SummaryBuilder};
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::stream::Table;
use crate::table::FrameBatches;

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
struct Built<'c> {
    frames: FrameColumns,
    /// The record batches converted so far (whole-log decodes only: a
    /// window is applied once every row is in).
    batches: FrameBatches<'c>,
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
                let full =
                    std::mem::replace(&mut self.batch, Vec::with_capacity(RECORDS_PER_HANDOVER));
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

/// Turns records into the columns of every row.
fn build<'c>(
    records: std::sync::mpsc::Receiver<Handed>,
    columns: &'c [Column],
    window: TimeWindow,
    room: usize,
) -> Built<'c> {
    let mut built = Built {
        frames: FrameColumns::with_room(room),
        batches: FrameBatches::new(columns),
        failure: None,
        interrupted: None,
    };
    let mut since_check = 0;
    for handed in &records {
        let batch = match handed {
            Handed::Records(batch) => batch,
            Handed::Restart => {
                built.frames = FrameColumns::with_room(room);
                built.batches = FrameBatches::new(columns);
                continue;
            }
        };
        for record in &batch {
            built.frames.push(record);
        }
        if window.is_all() && built.failure.is_none() {
            built.failure = built.batches.convert_complete(&built.frames).err();
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

/// The most frames the log at `path` can hold, up to a day of them (a card
/// image given as a log reserves no more); 0 if its size is unknown.
fn room_for_frames(path: &Path) -> usize {
    const DAY_OF_FRAMES: u64 = 100 * 86_400;
    let len = std::fs::metadata(path).map_or(0, |m| m.len());
    usize::try_from((len / FRAME_MIN_LEN as u64).min(DAY_OF_FRAMES)).unwrap_or(0)
}

/// Decodes the log at `path` once: its rows inside `window`, in `columns`,
/// and every decoder event passed to `observer` as well (a summary, the
/// losses). The log is decoded on a second thread while this one builds
/// the rows and their columns, in one pass when its blocks are in order
/// ([`read_log_restarting`]); a record batch is converted as soon as its
/// rows are complete. Called without the GIL; it is taken briefly now and
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
    let (walked, has_utc, built) = std::thread::scope(|scope| {
        let (send, records) = std::sync::mpsc::sync_channel(8);
        let decoder = scope.spawn(move || {
            let handover = RefCell::new(Handover {
                observer,
                send,
                batch: Vec::with_capacity(RECORDS_PER_HANDOVER),
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
        let built = build(records, columns, window, room_for_frames(path));
        let (walked, has_utc) = match decoder.join() {
            Ok(done) => done,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (walked, has_utc, built)
    });
    let Built {
        mut frames,
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
    // Of every row, inside the window or not.
    let span_s = frames.span_s();
    let row_stats = frames.row_stats();
    if !window.is_all() {
        frames.retain(&window);
        batches = FrameBatches::new(columns);
        if frames.is_empty() {
            return Err(fail(
                window.selects_nothing(path, "frames", span_s, has_utc),
            ));
        }
    }
    let (schema, batches) = batches.finish(&frames).map_err(|e| arrow_error(path, &e))?;
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
    let decoded = walk(path, columns, window, &mut losses)?;
    Ok((decoded.table, losses))
}

pub fn arrow_error(path: &Path, e: &arrow_schema::ArrowError) -> PyErr {
    crate::errors::to_py(CliError::file(
        path,
        format!("cannot build the Arrow table: {e}"),
    ))
}
