//! Decoded frames kept for columns from the start: each frame is stored
//! once as it comes (its counts, its fix, its UTC), and any range of rows
//! is converted to physical units a column at a time, as soon as those
//! rows are complete (no fix or UTC pair read later changes them). Which
//! fix and UTC fill a row is decided by the same [`Assembly`] that builds
//! [`Row`]s, and the units by the same functions, so the columns hold the
//! values `wobblog decode` writes (a test holds them to its rows); only no
//! 200-byte row is built per frame (the Python package opens hour-long
//! logs this way).

use std::ops::Range;

use wobble_core::format::{Frame, Record};

use super::columnar::{Field, FrameFields, RowColumns, Values};
use super::columns::Column;
use crate::rows::{self, Assembly, GpsColumns, PendingRows, Row};
use crate::summary::RowStats;
use crate::time::TimeWindow;

/// A row without GPS columns, in [`Slot::gps`].
const NO_FIX: u32 = u32::MAX;
/// Rows converted a column at a time (14 KiB of them).
const ROWS_PER_PASS: usize = 256;

/// Frames as columns of counts, filled record by record.
#[derive(Default)]
pub struct FrameColumns {
    assembly: Assembly,
    columns: Counts,
}

impl FrameColumns {
    /// No rows yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// No rows yet, with room for `rows` if it can be had (an estimate,
    /// so a long log's rows are not copied each time their vector grows).
    #[must_use]
    pub fn with_room(rows: usize) -> Self {
        let mut new = Self::default();
        // Without the room, the vector grows as rows come.
        let _ = new.columns.rows.try_reserve_exact(rows);
        new
    }

    /// Takes the log's next record.
    pub fn push(&mut self, record: &Record<'_>) {
        self.assembly.push(record, &mut self.columns);
    }

    /// Completes the rows still waiting; call once every record is in.
    pub fn finish(&mut self) {
        self.assembly.finish(&mut self.columns);
    }

    /// Rows so far.
    #[must_use]
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// Rows complete: no fix or sync pair read later changes them.
    #[must_use]
    pub fn complete(&self) -> usize {
        self.columns.first_pending
    }

    /// Whether there is no row.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Earliest and latest boot time of the complete rows (every row once
    /// [`Self::finish`]ed), s.
    #[must_use]
    pub fn span_s(&self) -> Option<(f64, f64)> {
        self.columns.span_s()
    }

    /// What a summary takes from the complete rows.
    #[must_use]
    pub fn row_stats(&self) -> RowStats {
        self.columns.row_stats()
    }

    /// Keeps the rows inside `window` (as `wobblog decode`: a row is in
    /// when its boot time or UTC, ms, is); call after [`Self::finish`].
    pub fn retain(&mut self, window: &TimeWindow) {
        self.columns.retain(window);
    }

    /// The values of `columns` (of [`super::columns::COLUMNS`]) in `rows`,
    /// in physical units, one entry per column.
    ///
    /// # Errors
    /// A column is not one of the frame columns.
    ///
    /// # Panics
    /// `rows` reaches past the last row.
    pub fn values(
        &self,
        columns: &[Column<Row>],
        rows: Range<usize>,
    ) -> Result<Vec<Values>, String> {
        self.columns.values(columns, rows)
    }
}

/// The rows' frames and what fills them.
#[derive(Default)]
struct Counts {
    /// Every row as read: one store per frame.
    rows: Vec<Slot>,
    /// Every fix that was in force, in order.
    fixes: Vec<GpsColumns>,
    /// The first row still waiting for a late fix or pair.
    first_pending: usize,
    /// Of the complete rows: the earliest and latest frame time, µs, and
    /// what a summary takes from them (kept as they complete: a pass over
    /// a long log's rows afterwards costs more than the rows).
    span_us: Option<(u64, u64)>,
    stats: RowStats,
}

/// A row: its frame, its GPS columns in [`Counts::fixes`] (or
/// [`NO_FIX`]), its UTC.
#[derive(Clone, Copy)]
struct Slot {
    frame: Frame,
    gps: u32,
    utc_us: Option<i64>,
}

impl Counts {
    fn len(&self) -> usize {
        self.rows.len()
    }

    fn span_s(&self) -> Option<(f64, f64)> {
        let (first, last) = self.span_us?;
        Some((rows::seconds(first), rows::seconds(last)))
    }

    fn row_stats(&self) -> RowStats {
        self.stats.clone()
    }

    fn retain(&mut self, window: &TimeWindow) {
        self.rows
            .retain(|r| window.contains(rows::seconds(r.frame.t_us), r.utc_us.map(|u| u / 1000)));
        self.first_pending = self.len();
    }

    fn values(&self, columns: &[Column<Row>], range: Range<usize>) -> Result<Vec<Values>, String> {
        // Frames belong to no run in particular.
        let not_frames = |c: &&Column<Row>| matches!(Field::of_column(c), None | Some(Field::Run));
        let mut out = RowColumns::new(columns, range.len())
            .filter(|_| !columns.iter().any(|c| not_frames(&c)))
            .ok_or_else(|| {
                let name = columns.iter().find(not_frames).map_or("", |c| c.name);
                format!("{name} is not a column of the frames")
            })?;
        // A few hundred rows at a time: they stay in the nearest cache while
        // each column reads them.
        for slots in self.rows[range].chunks(ROWS_PER_PASS) {
            out.store(slots.iter().map(|slot| Fields {
                slot,
                fixes: &self.fixes,
            }));
        }
        Ok(out.into_values())
    }

    /// The index in `fixes` of the fix in force, or [`NO_FIX`].
    fn fix_index(&self, gps: bool) -> u32 {
        match self.fixes.len().checked_sub(1) {
            // A log holds fewer fixes than 2^32 (at 20 Hz, 6 years).
            Some(last) if gps => u32::try_from(last).unwrap_or(NO_FIX),
            _ => NO_FIX,
        }
    }
}

/// A row's fields, read from its slot and the fixes.
#[derive(Clone, Copy)]
struct Fields<'a> {
    slot: &'a Slot,
    fixes: &'a [GpsColumns],
}

impl FrameFields for Fields<'_> {
    fn t_s(&self) -> f64 {
        rows::seconds(self.slot.frame.t_us)
    }
    fn accel_g(&self, axis: usize) -> f64 {
        rows::accel_g(self.slot.frame.accel[axis])
    }
    fn gyro_dps(&self, axis: usize) -> f64 {
        rows::gyro_dps(self.slot.frame.gyro[axis])
    }
    fn steer_deg(&self) -> f64 {
        rows::steer_deg(self.slot.frame.steer_cdeg)
    }
    fn speed_mps(&self) -> f64 {
        rows::speed_mps(self.slot.frame.speed_mm_s)
    }
    fn gps(&self) -> Option<&GpsColumns> {
        self.fixes.get(self.slot.gps as usize)
    }
    fn utc_us(&self) -> Option<i64> {
        self.slot.utc_us
    }
    fn run(&self) -> Option<u32> {
        None
    }
}

impl PendingRows for Counts {
    fn fix(&mut self, gps: GpsColumns) {
        self.fixes.push(gps);
    }

    fn push(&mut self, frame: &Frame, gps: bool, utc_us: Option<i64>) {
        let gps = self.fix_index(gps);
        self.rows.push(Slot {
            frame: *frame,
            gps,
            utc_us,
        });
    }

    fn set_gps(&mut self, i: usize, gps: bool) {
        self.rows[self.first_pending + i].gps = self.fix_index(gps);
    }

    fn set_utc(&mut self, i: usize, utc_us: Option<i64>) {
        self.rows[self.first_pending + i].utc_us = utc_us;
    }

    fn time_us(&self, i: usize) -> u64 {
        self.rows[self.first_pending + i].frame.t_us
    }

    fn complete_first(&mut self) {
        let Some(row) = self.rows.get(self.first_pending) else {
            return;
        };
        let t = row.frame.t_us;
        self.span_us = Some(self.span_us.map_or((t, t), |(a, b)| (a.min(t), b.max(t))));
        self.stats.take_parts(row.gps != NO_FIX, row.utc_us);
        self.first_pending += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::columns::{Value, COLUMNS};
    use crate::rows::RowAssembler;
    use crate::time::TimeBound;
    use proptest::prelude::*;
    use wobble_core::format::{FixMode, GpsFix, UtcSync};

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

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 256,
            rng_seed: proptest::test_runner::RngSeed::Fixed(35),
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// The columns hold, row for row, what the rows of `wobblog decode`
        /// hold, and the summary's figures agree with those rows'.
        #[test]
        fn the_columns_are_the_rows_of_decode(records in records()) {
            let mut rows = Vec::new();
            let mut assembler = RowAssembler::new();
            let mut stats = RowStats::default();
            let mut keep = |row: &Row| {
                stats.take(row);
                rows.push(*row);
            };
            let mut columns = FrameColumns::with_room(records.len() / 2);
            // What the complete rows hold half way through the records.
            let mut half_way = None;
            for (k, record) in records.iter().enumerate() {
                assembler.push(record, &mut keep);
                columns.push(record);
                if k == records.len() / 2 {
                    let complete = columns.complete();
                    let values = columns.values(&COLUMNS, 0..complete).unwrap();
                    half_way = Some((complete, values));
                }
            }
            assembler.finish(&mut keep);
            columns.finish();
            prop_assert_eq!(columns.len(), rows.len());
            prop_assert!(!columns.is_empty());
            prop_assert_eq!(columns.complete(), rows.len());
            // Complete rows do not change.
            if let Some((complete, values)) = half_way {
                prop_assert_eq!(values, columns.values(&COLUMNS, 0..complete).unwrap());
            }
            let split = rows.len() / 3;
            let head = columns.values(&COLUMNS, 0..split).unwrap();
            let tail = columns.values(&COLUMNS, split..rows.len()).unwrap();
            for ((column, head), tail) in COLUMNS.iter().zip(head).zip(tail) {
                let expected: Vec<Value> = rows.iter().map(|r| (column.value)(r)).collect();
                let mut got = cells(head);
                got.extend(cells(tail));
                prop_assert_eq!(got, expected, "column {}", column.name);
            }
            prop_assert_eq!(columns.row_stats(), stats);
            let times = rows.iter().map(|r| r.t_s);
            let span = times.clone().reduce(f64::min).zip(times.reduce(f64::max));
            prop_assert_eq!(columns.span_s(), span);

            // A window keeps the rows `decode` keeps.
            let from = rows[rows.len() / 2].t_s;
            let utc_to = rows.iter().find_map(|r| r.utc_us).map(|u| u / 1000 + 2_000);
            let window = TimeWindow {
                from: Some(TimeBound::Boot(from)),
                to: utc_to.map(TimeBound::Utc),
            };
            let inside: Vec<&Row> = rows
                .iter()
                .filter(|r| window.contains(r.t_s, r.utc_us.map(|u| u / 1000)))
                .collect();
            columns.retain(&window);
            prop_assert_eq!(columns.len(), inside.len());
            prop_assert_eq!(columns.is_empty(), inside.is_empty());
            let [t, utc] = [0, 13].map(|c| {
                cells(columns.values(&COLUMNS[c..=c], 0..inside.len()).unwrap().remove(0))
            });
            prop_assert_eq!(t, inside.iter().map(|r| Value::Number(Some(r.t_s))).collect::<Vec<_>>());
            prop_assert_eq!(utc, inside.iter().map(|r| Value::Utc(r.utc_us)).collect::<Vec<_>>());
        }
    }

    #[test]
    fn rows_are_complete_once_half_a_second_older_than_the_last_frame() {
        let mut columns = FrameColumns::new();
        for i in 0..200u64 {
            columns.push(&Record::Frame(Frame {
                t_us: i * 10_000,
                ..Frame::default()
            }));
        }
        // The last frame at 1.99 s: rows up to 1.48 s wait no longer.
        assert_eq!(columns.complete(), 149);
        let mut nothing = FrameColumns::new();
        nothing.finish();
        assert!(nothing.is_empty());
        assert_eq!(nothing.span_s(), None);
    }
}
