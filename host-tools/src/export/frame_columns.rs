//! Decoded frames turned into columns as their rows complete: once no fix
//! or UTC pair read later can change a row, it is converted to physical
//! units straight into the columns of the batch being filled, a few hundred
//! rows at a time, and a batch is handed out as soon as it is full. Which
//! fix and UTC fill a row is decided by the same [`Assembly`] that builds
//! [`Row`]s, and the units by the same functions, so the columns hold the
//! values `wobblog decode` writes (a test holds them to its rows); only no
//! 200-byte row is built per frame, and no row is kept once converted (the
//! Python package opens hour-long logs this way).

use wobble_core::format::Record;

use super::columnar::{ColumnBuffers, Field, FrameFields, RowColumns, Values};
use super::columns::Column;
use crate::rows::{self, Assembly, GpsColumns, Row, RowParts};
use crate::summary::RowStats;
use crate::time::TimeWindow;

/// A log's frames as batches of columns, filled record by record.
pub struct FrameColumns {
    assembly: Assembly,
    complete: Complete,
}

/// What becomes of the complete rows.
struct Complete {
    /// Which rows are kept.
    window: TimeWindow,
    /// The batch being filled, and how many rows make one.
    batch: RowColumns,
    batch_rows: usize,
    /// Full batches not yet taken.
    full: Vec<Vec<Values>>,
    /// Rows kept so far, and batches filled.
    kept: usize,
    batches: usize,
    /// Of every complete row, kept or not: the earliest and latest frame
    /// time, µs, and what a summary takes from them.
    span_us: Option<(u64, u64)>,
    stats: RowStats,
}

/// What is left once every record is in.
pub struct Finished {
    /// The last batches: at least one over the whole log (empty for no
    /// rows), so every consumer sees the columns.
    pub batches: Vec<Vec<Values>>,
    /// Rows kept.
    pub rows: usize,
    /// Earliest and latest boot time of every row (inside the window or
    /// not), s.
    pub span_s: Option<(f64, f64)>,
    /// What a summary takes from every row (inside the window or not).
    pub row_stats: RowStats,
}

impl FrameColumns {
    /// No rows yet. The rows inside `window` (as `wobblog decode`: a row
    /// is in when its boot time or UTC, ms, is) will be kept, in `columns`
    /// (of [`super::columns::COLUMNS`]), `batch_rows` to a batch.
    ///
    /// # Errors
    /// A column is not one of the frame columns.
    pub fn new(
        columns: &[Column<Row>],
        window: TimeWindow,
        batch_rows: usize,
    ) -> Result<Self, String> {
        // Frames belong to no run in particular.
        let not_frames = |c: &&Column<Row>| matches!(Field::of_column(c), None | Some(Field::Run));
        let batch = RowColumns::new(columns, batch_rows)
            .filter(|_| !columns.iter().any(|c| not_frames(&c)))
            .ok_or_else(|| {
                let name = columns.iter().find(not_frames).map_or("", |c| c.name);
                format!("{name} is not a column of the frames")
            })?;
        Ok(Self {
            assembly: Assembly::default(),
            complete: Complete {
                window,
                batch,
                batch_rows: batch_rows.max(1),
                full: Vec::new(),
                kept: 0,
                batches: 0,
                span_us: None,
                stats: RowStats::default(),
            },
        })
    }

    /// Forgets every record taken: no rows again (the log is to be read
    /// again from its start).
    pub fn restart(&mut self) {
        self.assembly = Assembly::default();
        let c = &mut self.complete;
        c.batch.take();
        c.full.clear();
        (c.kept, c.batches, c.span_us) = (0, 0, None);
        c.stats = RowStats::default();
    }

    /// Takes the log's next record.
    pub fn push(&mut self, record: &Record<'_>) {
        let complete = &mut self.complete;
        self.assembly.push(record, &mut |rows| complete.take(rows));
    }

    /// The batches filled since the last call, each a value per column, in
    /// physical units.
    pub fn take_full(&mut self) -> Vec<Vec<Values>> {
        std::mem::take(&mut self.complete.full)
    }

    /// Completes the rows still waiting; call once every record is in.
    #[must_use]
    pub fn finish(mut self) -> Finished {
        let complete = &mut self.complete;
        self.assembly.finish(&mut |rows| complete.take(rows));
        let mut c = self.complete;
        if c.batch.len() > 0 || c.batches == 0 {
            c.full.push(c.batch.into_values());
        }
        Finished {
            batches: c.full,
            rows: c.kept,
            span_s: c
                .span_us
                .map(|(first, last)| (rows::seconds(first), rows::seconds(last))),
            row_stats: c.stats,
        }
    }
}

impl Complete {
    /// Takes a run of complete rows (a few hundred: the assembly hands
    /// them out so, and they are read once per column, so they should sit
    /// in the nearest cache).
    fn take(&mut self, rows: &[RowParts]) {
        for row in rows {
            let t = row.frame.t_us;
            self.span_us = Some(self.span_us.map_or((t, t), |(a, b)| (a.min(t), b.max(t))));
            self.stats.take_parts(row.gps.is_some(), row.utc_us);
        }
        let window = self.window;
        let keeps = move |row: &&RowParts| {
            window.contains(rows::seconds(row.frame.t_us), row.utc_us.map(|u| u / 1000))
        };
        let mut rest = rows;
        while !rest.is_empty() {
            // The rows up to the one that fills the batch, or the rest.
            let room = self.batch_rows - self.batch.len();
            let (mut n, mut kept) = (0, 0);
            while n < rest.len() && kept < room {
                kept += usize::from(keeps(&&rest[n]));
                n += 1;
            }
            let run = &rest[..n];
            if window.is_all() {
                self.batch.store(run.iter());
            } else {
                self.batch.store(run.iter().filter(keeps));
            }
            self.kept += kept;
            if self.batch.len() == self.batch_rows {
                self.full.push(self.batch.take());
                self.batches += 1;
            }
            rest = &rest[run.len()..];
        }
    }
}

impl FrameFields for &RowParts {
    fn t_s(&self) -> f64 {
        rows::seconds(self.frame.t_us)
    }
    fn accel_g(&self, axis: usize) -> f64 {
        rows::accel_g(self.frame.accel[axis])
    }
    fn gyro_dps(&self, axis: usize) -> f64 {
        rows::gyro_dps(self.frame.gyro[axis])
    }
    fn steer_deg(&self) -> f64 {
        rows::steer_deg(self.frame.steer_cdeg)
    }
    fn speed_mps(&self) -> f64 {
        rows::speed_mps(self.frame.speed_mm_s)
    }
    fn gps(&self) -> Option<&GpsColumns> {
        self.gps.as_ref()
    }
    fn utc_us(&self) -> Option<i64> {
        self.utc_us
    }
    fn run(&self) -> Option<u32> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::columns::{Value, COLUMNS};
    use crate::rows::RowAssembler;
    use crate::time::TimeBound;
    use proptest::prelude::*;
    use wobble_core::format::{FixMode, Frame, GpsFix, UtcSync};

    /// Records as a log holds them: frames 10 ms apart with now and then a
    /// step back or a long step forward, fixes and sync pairs stamped up to
    /// 0.8 s before the frame they follow (late) or after it, some fixes
    /// without a position.
    fn records() -> impl Strategy<Value = Vec<Record<'static>>> {
        let step = prop_oneof![8 => Just(10_000i64), 1 => -3_000_000i64..3_000_000];
        let item = (step, 0u8..10, -800_000i64..200_000, any::<i16>(), 0u8..4);
        prop::collection::vec(item, 1..600).prop_map(|items| {
            let mut t: i64 = 5_000_000;
            let mut out = Vec::new();
            for (step, kind, stamp, value, mode) in items {
                t = (t + step).max(0);
                let t_us = t as u64;
                out.push(Record::Frame(Frame {
                    t_us,
                    accel: [value, value / 2, value.wrapping_neg()],
                    gyro: [value / 3, value, 7],
                    steer_cdeg: value,
                    speed_mm_s: value.unsigned_abs(),
                    ..Frame::default()
                }));
                let at = (t + stamp).max(0) as u64;
                match kind {
                    0 | 1 => out.push(Record::Gps(GpsFix {
                        t_us: at,
                        lat_e7: (value % 5 != 0).then_some(i32::from(value) * 1000),
                        lon_e7: Some(-i32::from(value)),
                        speed_cm_s: (mode > 1).then_some(value.unsigned_abs()),
                        fix: [
                            FixMode::None,
                            FixMode::Fix3d,
                            FixMode::Fix3d,
                            FixMode::Fix2d,
                        ][usize::from(mode)],
                        ..GpsFix::default()
                    })),
                    2 => out.push(Record::UtcSync(UtcSync {
                        t_us: at,
                        unix_ms: 1_700_000_000_000 + u64::from(value.unsigned_abs()),
                    })),
                    _ => {}
                }
            }
            out
        })
    }

    /// Every column's cells as the column table's value functions give them.
    fn cells(values: Values) -> Vec<Value> {
        match values {
            Values::Number(v) => v.into_iter().map(|x| Value::Number(Some(x))).collect(),
            Values::OptNumber(v, p) => v
                .into_iter()
                .zip(p)
                .map(|(x, has)| Value::Number(has.then_some(x)))
                .collect(),
            Values::Label(v) => v.into_iter().map(Value::Label).collect(),
            Values::Utc(v, p) => v
                .into_iter()
                .zip(p)
                .map(|(x, has)| Value::Utc(has.then_some(x)))
                .collect(),
            other => panic!("not a frame column: {other:?}"),
        }
    }

    /// Every cell of `batches`, column by column.
    fn columns_of(batches: Vec<Vec<Values>>, columns: usize) -> Vec<Vec<Value>> {
        let mut out = vec![Vec::new(); columns];
        for batch in batches {
            assert_eq!(batch.len(), columns);
            for (column, values) in out.iter_mut().zip(batch) {
                column.extend(cells(values));
            }
        }
        out
    }

    /// The rows `wobblog decode` makes of `records`, and the summary's
    /// figures of them.
    fn decoded(records: &[Record<'static>]) -> (Vec<Row>, RowStats) {
        let mut rows = Vec::new();
        let mut stats = RowStats::default();
        let mut keep = |row: &Row| {
            stats.take(row);
            rows.push(*row);
        };
        let mut assembler = RowAssembler::new();
        for record in records {
            assembler.push(record, &mut keep);
        }
        assembler.finish(&mut keep);
        (rows, stats)
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 256,
            rng_seed: proptest::test_runner::RngSeed::Fixed(35),
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// The columns hold, row for row, what the rows of `wobblog decode`
        /// hold, batch after batch, and the summary's figures agree with
        /// those rows'; a window keeps the rows `decode` keeps.
        #[test]
        fn the_columns_are_the_rows_of_decode(records in records(), batch_rows in 1usize..300) {
            let (rows, stats) = decoded(&records);
            let from = rows[rows.len() / 2].t_s;
            let utc_to = rows.iter().find_map(|r| r.utc_us).map(|u| u / 1000 + 2_000);
            let window = TimeWindow {
                from: Some(TimeBound::Boot(from)),
                to: utc_to.map(TimeBound::Utc),
            };
            for window in [TimeWindow::default(), window] {
                let kept: Vec<&Row> = rows
                    .iter()
                    .filter(|r| window.contains(r.t_s, r.utc_us.map(|u| u / 1000)))
                    .collect();
                let mut columns = FrameColumns::new(&COLUMNS, window, batch_rows).unwrap();
                if window.is_all() {
                    // Read in part, then again from the start.
                    for record in &records[..records.len() / 2] {
                        columns.push(record);
                    }
                    columns.restart();
                }
                let mut batches = Vec::new();
                for record in &records {
                    columns.push(record);
                    for batch in columns.take_full() {
                        // Handed out full, while records still come.
                        prop_assert_eq!(batch[0].len(), batch_rows);
                        batches.push(batch);
                    }
                }
                let finished = columns.finish();
                prop_assert_eq!(finished.rows, kept.len());
                prop_assert!(finished.batches.iter().all(|b| b[0].len() <= batch_rows));
                batches.extend(finished.batches);
                prop_assert!(!batches.is_empty());
                let got = columns_of(batches, COLUMNS.len());
                for (column, got) in COLUMNS.iter().zip(got) {
                    let expected: Vec<Value> = kept.iter().map(|r| (column.value)(r)).collect();
                    prop_assert_eq!(got, expected, "column {}", column.name);
                }
                // Of every row, whatever the window.
                prop_assert_eq!(&finished.row_stats, &stats);
                let times = rows.iter().map(|r| r.t_s);
                let span = times.clone().reduce(f64::min).zip(times.reduce(f64::max));
                prop_assert_eq!(finished.span_s, span);
            }
        }
    }

    /// `n` frames 10 ms apart into columns of 100-row batches, `after`
    /// called after each (with its number), finished.
    fn frames_every_10_ms(n: u64, mut after: impl FnMut(u64, &mut FrameColumns)) -> Finished {
        let mut columns = FrameColumns::new(&COLUMNS, TimeWindow::default(), 100).unwrap();
        for i in 0..n {
            columns.push(&Record::Frame(Frame {
                t_us: i * 10_000,
                ..Frame::default()
            }));
            after(i, &mut columns);
        }
        columns.finish()
    }

    #[test]
    fn rows_are_converted_in_runs_once_half_a_second_older_than_the_last_frame() {
        let finished = frames_every_10_ms(400, |i, columns| {
            // The frame at 3.06 s completes the rows up to 2.55 s: a run of
            // 256, two batches and some.
            let expected = if i == 306 { 2 } else { 0 };
            assert_eq!(columns.take_full().len(), expected, "frame {i}");
        });
        assert_eq!(finished.rows, 400);
        let sizes: Vec<usize> = finished.batches.iter().map(|b| b[0].len()).collect();
        assert_eq!(sizes, [100, 100]);
    }

    #[test]
    fn rows_that_fill_whole_batches_leave_no_empty_batch_after_them() {
        let sizes: Vec<usize> = frames_every_10_ms(200, |_, _| {})
            .batches
            .iter()
            .map(|b| b[0].len())
            .collect();
        assert_eq!(sizes, [100, 100]);
    }

    #[test]
    fn no_rows_make_one_empty_batch_and_the_run_is_no_frame_column() {
        let finished = FrameColumns::new(&COLUMNS, TimeWindow::default(), 10)
            .unwrap()
            .finish();
        assert_eq!(finished.rows, 0);
        assert_eq!(finished.span_s, None);
        assert_eq!(finished.batches.len(), 1);
        assert!(finished.batches[0].iter().all(Values::is_empty));
        let run = crate::export::columns::RUN_COLUMN;
        let err = FrameColumns::new(&[COLUMNS[0], run], TimeWindow::default(), 10).err();
        assert_eq!(err.as_deref(), Some("run is not a column of the frames"));
    }
}
