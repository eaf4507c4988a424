//! Rows written as lines of text, formatted on worker threads.
//!
//! Formatting numbers is most of a text export's time (a 64 MiB log is
//! 2.3 million rows of 14 cells), while reading and decoding the log is a
//! fifth of it. The reading thread hands batches of rows round to the
//! workers and writes their text back in the order it sent them, so the
//! output is the one a single thread would write.

use std::collections::VecDeque;
use std::io::Write;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

use super::columns::Column;
use crate::rows::Row;

/// How one row becomes text: appends its line to the string.
pub type FormatLine = super::text::LineFormat;

/// Rows per batch: about 300 KB of text on the widest rows, few enough
/// hand-overs that the channels cost nothing, small enough to stay in cache.
const BATCH_ROWS: usize = 2048;
/// Most workers: beyond this the writing thread is the bottleneck.
const MAX_WORKERS: usize = 4;

/// A batch of rows going out, or the same batch back with its text.
type Batch = (Vec<Row>, String);

struct Worker {
    to: SyncSender<Batch>,
    from: Receiver<Batch>,
}

/// Writes rows as text lines to `out`, in order.
pub struct LineWriter<W: Write> {
    out: W,
    columns: Vec<Column>,
    format: FormatLine,
    batch: Vec<Row>,
    workers: Vec<Worker>,
    /// Workers holding a batch, in the order the batches were sent.
    in_flight: VecDeque<usize>,
    /// Batches sent so far: the next goes to worker `sent % workers`.
    sent: usize,
    /// Buffers back from the workers, for the next batches.
    spare: Vec<Batch>,
}

impl<W: Write> LineWriter<W> {
    /// A writer of `columns`, each row formatted by `format`, with a worker
    /// per core.
    pub fn new(out: W, columns: &[Column], format: FormatLine) -> Self {
        let count = std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_WORKERS));
        Self::with_workers(out, columns, format, count)
    }

    /// With `count` workers, or as many of them as the system starts (with
    /// none, rows are formatted on the calling thread).
    fn with_workers(out: W, columns: &[Column], format: FormatLine, count: usize) -> Self {
        let workers = (0..count)
            .filter_map(|_| {
                let (to, rows) = sync_channel::<Batch>(1);
                let (done, from) = sync_channel::<Batch>(1);
                let columns = columns.to_vec();
                let worker = move || {
                    for (rows, mut text) in rows {
                        format_batch(format, &columns, &rows, &mut text);
                        if done.send((rows, text)).is_err() {
                            break;
                        }
                    }
                };
                let started = std::thread::Builder::new()
                    .name("wobblog-format".into())
                    .spawn(worker);
                started.ok().map(|_| Worker { to, from })
            })
            .collect();
        Self {
            out,
            columns: columns.to_vec(),
            format,
            batch: Vec::with_capacity(BATCH_ROWS),
            workers,
            in_flight: VecDeque::new(),
            sent: 0,
            spare: Vec::new(),
        }
    }

    /// Writes text that goes before every row (a header line).
    pub fn write_text(&mut self, text: &str) -> std::io::Result<()> {
        self.send_batch()?;
        self.drain()?;
        self.out.write_all(text.as_bytes())
    }

    /// Queues one row; full batches go to a worker, and the oldest batch
    /// formatted is written once every worker holds one.
    pub fn write(&mut self, row: &Row) -> std::io::Result<()> {
        self.batch.push(*row);
        if self.batch.len() == BATCH_ROWS {
            self.send_batch()?;
        }
        Ok(())
    }

    /// Writes every queued row and flushes `out`.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.send_batch()?;
        self.drain()?;
        self.out.flush()
    }

    fn send_batch(&mut self) -> std::io::Result<()> {
        if self.batch.is_empty() {
            return Ok(());
        }
        if self.workers.is_empty() {
            let mut text = String::new();
            format_batch(self.format, &self.columns, &self.batch, &mut text);
            self.batch.clear();
            return self.out.write_all(text.as_bytes());
        }
        if self.in_flight.len() == self.workers.len() {
            self.write_oldest()?;
        }
        let (mut next, text) = self.spare.pop().unwrap_or_default();
        next.clear();
        let rows = std::mem::replace(&mut self.batch, next);
        let worker = self.sent % self.workers.len();
        self.workers[worker]
            .to
            .send((rows, text))
            .map_err(|_| stopped())?;
        self.in_flight.push_back(worker);
        self.sent += 1;
        Ok(())
    }

    fn write_oldest(&mut self) -> std::io::Result<()> {
        let Some(worker) = self.in_flight.pop_front() else {
            return Ok(());
        };
        let (rows, text) = self.workers[worker].from.recv().map_err(|_| stopped())?;
        self.out.write_all(text.as_bytes())?;
        self.spare.push((rows, text));
        Ok(())
    }

    fn drain(&mut self) -> std::io::Result<()> {
        while !self.in_flight.is_empty() {
            self.write_oldest()?;
        }
        Ok(())
    }
}

/// The text of `rows`, in `text` (cleared first).
fn format_batch(format: FormatLine, columns: &[Column], rows: &[Row], text: &mut String) {
    text.clear();
    for row in rows {
        format.line(text, columns, row);
    }
}

/// A worker gone: only a panic while formatting ends one early.
fn stopped() -> std::io::Error {
    std::io::Error::other("a formatting thread stopped")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::columns::COLUMNS;
    use crate::export::text::{csv_line, LineFormat};

    const CSV: LineFormat = LineFormat::Csv { delimiter: b',' };

    fn rows(n: usize) -> Vec<Row> {
        let any = Row {
            t_s: 0.0,
            accel_g: [0.0; 3],
            gyro_dps: [0.0; 3],
            steer_deg: 0.0,
            speed_mps: 0.0,
            wheel_count: 0,
            status: wobble_core::format::FrameStatus(0),
            gps: None,
            utc_us: None,
            derived: Default::default(),
            run: None,
        };
        (0..n)
            .map(|i| Row {
                t_s: i as f64 / 100.0,
                steer_deg: (i as f64).sin(),
                ..any
            })
            .collect()
    }

    #[test]
    fn lines_come_out_in_row_order_whatever_the_batching() {
        for n in [0, 1, BATCH_ROWS - 1, BATCH_ROWS, 7 * BATCH_ROWS + 3] {
            let rows = rows(n);
            let mut expected = String::from("header\n");
            for row in &rows {
                csv_line(&mut expected, &COLUMNS, row);
            }
            // No worker: the system started none, and the rows are
            // formatted where they are written.
            for workers in 0..=MAX_WORKERS {
                let mut w = LineWriter::with_workers(Vec::new(), &COLUMNS, CSV, workers);
                w.write_text("header\n").unwrap();
                for row in &rows {
                    w.write(row).unwrap();
                }
                w.flush().unwrap();
                let text = String::from_utf8(w.out).unwrap();
                assert!(text == expected, "{n} rows, {workers} workers");
            }
        }
    }

    /// Rows go out in whole batches, and once there are more batches than
    /// workers every worker holds one: the text is formatted in parallel.
    #[test]
    fn rows_go_out_in_full_batches_to_every_worker() {
        for workers in 1..=MAX_WORKERS {
            let mut w = LineWriter::with_workers(std::io::sink(), &COLUMNS, CSV, workers);
            let rows = rows(BATCH_ROWS);
            for batch in 1..=2 * workers {
                rows.iter().try_for_each(|row| w.write(row)).unwrap();
                assert_eq!(w.sent, batch, "{workers} workers");
                assert_eq!(w.in_flight.len(), batch.min(workers), "{workers} workers");
            }
            w.write(&rows[0]).unwrap();
            w.flush().unwrap();
            assert_eq!((w.sent, w.in_flight.len()), (2 * workers + 1, 0));
        }
    }

    /// Takes `room` bytes, then fails as a closed pipe does.
    struct Closing {
        room: usize,
    }

    impl Write for Closing {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if self.room == 0 {
                return Err(std::io::ErrorKind::BrokenPipe.into());
            }
            let n = buf.len().min(self.room);
            self.room -= n;
            Ok(n)
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_failed_write_is_the_error_and_nothing_waits() {
        for workers in 0..=MAX_WORKERS {
            let mut w = LineWriter::with_workers(Closing { room: 1000 }, &COLUMNS, CSV, workers);
            let rows = rows(20 * BATCH_ROWS);
            let written: std::io::Result<()> = rows.iter().try_for_each(|row| w.write(row));
            let err = written
                .and_then(|()| w.flush())
                .expect_err("the write fails");
            assert_eq!(
                err.kind(),
                std::io::ErrorKind::BrokenPipe,
                "{workers} workers"
            );
        }
    }
}
