//! Which GPS fix and which UTC sync pair fill each frame's row, and when a
//! row is complete: the logic every reader of rows shares, whatever it
//! makes of a complete row (a [`super::Row`], or cells of columns).
//!
//! A GPS fix is stamped when its first sentence began, so it reaches the
//! card after frames that come later than it; rows are held back for
//! [`GPS_WAIT_US`] so such a fix still fills them. A UTC sync pair is
//! stamped the same way.

use wobble_core::format::{Frame, Record, UtcSync};

use super::GpsColumns;

/// A GPS fix older than this no longer fills a row's GPS columns.
pub const GPS_STALE_US: u64 = 1_000_000;
/// How long rows wait for a GPS fix stamped before them but written after.
const GPS_WAIT_US: u64 = 500_000;
/// Most rows held back, whatever the frame times say (0.5 s at 100 Hz is
/// 50): times that stand still cannot make the assembler hoard memory.
const MAX_PENDING_ROWS: usize = 4096;
/// Complete rows are handed out this many at a time (or fewer, when every
/// row is), so that those who take them can work on a few hundred at once.
const COMPLETE_RUN: usize = 256;

/// A row as assembled: its frame, and what fills it.
#[derive(Clone, Copy, Debug)]
pub struct RowParts {
    /// The frame, as decoded.
    pub frame: Frame,
    /// The GPS fix in force, if any.
    pub gps: Option<GpsColumns>,
    /// UTC, µs since 1970, from the latest sync pair at or before the frame.
    pub utc_us: Option<i64>,
}

/// Decides, record by record, what fills each row and when it is complete;
/// the rows wait here meanwhile, and complete rows until a run of them is
/// handed out. Memory is bounded: at most [`MAX_PENDING_ROWS`] wait.
#[derive(Default)]
pub struct Assembly {
    /// The rows, oldest first: `complete` complete ones, then the pending
    /// ones (whose times never decrease: time going back completes them
    /// all).
    rows: Vec<RowParts>,
    complete: usize,
    /// The fix in force: its time and columns.
    fix: Option<(u64, GpsColumns)>,
    sync: Option<UtcSync>,
}

impl Assembly {
    /// Takes one record (frames, fixes and sync pairs matter; the others
    /// are passed over); hands complete rows to `out`, in order, a run at a
    /// time.
    pub fn push(&mut self, record: &Record<'_>, out: &mut impl FnMut(&[RowParts])) {
        match record {
            Record::Frame(frame) => self.frame(frame, out),
            Record::Gps(fix) => {
                let newer = self.fix.is_none_or(|(t, _)| fix.t_us >= t);
                if newer {
                    let columns = GpsColumns::from_fix(fix);
                    self.fix = columns.map(|c| (fix.t_us, c));
                    for row in self.pending_from(fix.t_us) {
                        let t = row.frame.t_us;
                        row.gps = columns.filter(|_| t - fix.t_us <= GPS_STALE_US);
                    }
                }
            }
            // Like a fix, a pair is stamped before frames written ahead of it.
            Record::UtcSync(sync) if self.sync.is_none_or(|s| sync.t_us >= s.t_us) => {
                self.sync = Some(*sync);
                for row in self.pending_from(sync.t_us) {
                    row.utc_us = utc_us_at(*sync, row.frame.t_us);
                }
            }
            _ => {}
        }
    }

    /// The rows still pending from time `t_us` on, latest first (their
    /// times never decrease: only those at the back are looked at).
    fn pending_from(&mut self, t_us: u64) -> impl Iterator<Item = &mut RowParts> {
        self.rows[self.complete..]
            .iter_mut()
            .rev()
            .take_while(move |row| row.frame.t_us >= t_us)
    }

    fn frame(&mut self, frame: &Frame, out: &mut impl FnMut(&[RowParts])) {
        // Time going back starts a new segment: nothing waits across it,
        // and a fix from before it fills no row after it.
        if self.rows.last().is_some_and(|r| frame.t_us < r.frame.t_us) {
            self.finish(out);
            self.fix = None;
        }
        if self.rows.len() - self.complete >= MAX_PENDING_ROWS {
            self.complete += 1;
        }
        let gps = self
            .fix
            .filter(|&(t, _)| t <= frame.t_us && frame.t_us - t <= GPS_STALE_US)
            .map(|(_, columns)| columns);
        let utc_us = self
            .sync
            .filter(|s| s.t_us <= frame.t_us)
            .and_then(|s| utc_us_at(s, frame.t_us));
        self.rows.push(RowParts {
            frame: *frame,
            gps,
            utc_us,
        });
        while self
            .rows
            .get(self.complete)
            .is_some_and(|r| r.frame.t_us + GPS_WAIT_US < frame.t_us)
        {
            self.complete += 1;
        }
        if self.complete >= COMPLETE_RUN {
            self.hand_out(out);
        }
    }

    /// Completes every row still held back, and hands out every row.
    pub fn finish(&mut self, out: &mut impl FnMut(&[RowParts])) {
        self.complete = self.rows.len();
        self.hand_out(out);
    }

    /// Hands out the complete rows; the pending ones (a few dozen) move
    /// to the front.
    fn hand_out(&mut self, out: &mut impl FnMut(&[RowParts])) {
        out(&self.rows[..self.complete]);
        self.rows.drain(..self.complete);
        self.complete = 0;
    }
}

/// UTC at local time `t_us` through the pair `sync`, µs since 1970.
fn utc_us_at(sync: UtcSync, t_us: u64) -> Option<i64> {
    let offset_us = i64::try_from(t_us).ok()? - i64::try_from(sync.t_us).ok()?;
    i64::try_from(sync.unix_ms)
        .ok()?
        .checked_mul(1000)?
        .checked_add(offset_us)
}

#[cfg(test)]
mod tests {
    //! The rules by hand: frames every 10 ms, fixes and sync pairs placed
    //! where a logger writes them (stamped before frames already written).
    use super::*;
    use crate::rows::{Row, RowAssembler};
    use wobble_core::format::{FixMode, GpsFix};

    fn frame(ms: u64) -> Record<'static> {
        Record::Frame(Frame {
            t_us: ms * 1000,
            ..Frame::default()
        })
    }

    /// A fix stamped at `ms` at latitude `lat` degrees (none: no position).
    fn fix(ms: u64, lat: Option<i32>) -> Record<'static> {
        Record::Gps(GpsFix {
            t_us: ms * 1000,
            lat_e7: lat.map(|d| d * 10_000_000),
            lon_e7: Some(0),
            fix: FixMode::Fix3d,
            ..GpsFix::default()
        })
    }

    fn sync(ms: u64, unix_ms: u64) -> Record<'static> {
        Record::UtcSync(UtcSync {
            t_us: ms * 1000,
            unix_ms,
        })
    }

    /// The rows of `records`: (ms since boot, latitude, UTC in ms).
    fn rows_of(records: &[Record<'static>]) -> Vec<(u64, Option<f64>, Option<i64>)> {
        let mut out = Vec::new();
        let mut keep = |r: &Row| {
            out.push((
                (r.t_s * 1000.0).round() as u64,
                r.gps.map(|g| g.lat_deg),
                r.utc_us.map(|u| u / 1000),
            ));
        };
        let mut assembler = RowAssembler::new();
        for r in records {
            assembler.push(r, &mut keep);
        }
        assembler.finish(&mut keep);
        out
    }

    fn frames(from_ms: u64, to_ms: u64) -> impl Iterator<Item = Record<'static>> {
        (from_ms..=to_ms).step_by(10).map(frame)
    }

    #[test]
    fn a_late_fix_fills_the_rows_from_its_stamp_for_a_second() {
        // Stamped at 50 ms, written after the frame of 200 ms.
        let mut records: Vec<_> = frames(0, 200).collect();
        records.push(fix(50, Some(45)));
        records.extend(frames(210, 1200));
        for (t, lat, _) in rows_of(&records) {
            // From 50 ms to 1.05 s (a second old at most), not before, not after.
            let expected = (50..=1050).contains(&t).then_some(45.0);
            assert_eq!(lat, expected, "row at {t} ms");
        }
    }

    #[test]
    fn rows_half_a_second_old_are_complete_before_a_later_fix() {
        // Stamped at 100 ms but written after the frame of 700 ms: the
        // rows before 200 ms waited 0.5 s and were complete.
        let mut records: Vec<_> = frames(0, 700).collect();
        records.push(fix(100, Some(45)));
        let filled: Vec<u64> = rows_of(&records)
            .into_iter()
            .filter_map(|(t, lat, _)| lat.map(|_| t))
            .collect();
        assert_eq!(filled.first(), Some(&200));
        assert_eq!(filled.last(), Some(&700));
    }

    #[test]
    fn an_older_fix_read_later_and_a_fix_without_position_change_nothing_or_stop_it() {
        let mut records: Vec<_> = frames(0, 100).collect();
        records.push(fix(100, Some(45)));
        records.extend(frames(110, 300));
        // Older than the fix in force: ignored.
        records.push(fix(90, Some(10)));
        records.extend(frames(310, 400));
        // No position from 400 ms on.
        records.push(fix(400, None));
        records.extend(frames(410, 500));
        for (t, lat, _) in rows_of(&records) {
            let expected = (100..400).contains(&t).then_some(45.0);
            assert_eq!(lat, expected, "row at {t} ms");
        }
    }

    /// The rows of frames `first` (ms), a fix stamped at their start read
    /// after them, then frames `then`, whose start is earlier than the end
    /// of `first`.
    fn fix_then_back(first: (u64, u64), then: (u64, u64)) -> Vec<(u64, Option<f64>, Option<i64>)> {
        let mut records: Vec<_> = frames(first.0, first.1).collect();
        records.push(fix(first.0, Some(45)));
        records.extend(frames(then.0, then.1));
        rows_of(&records)
    }

    #[test]
    fn time_going_back_leaves_the_fix_behind() {
        // A new segment from 0 (a restarted clock): the fix of 1 s is
        // not in force there, though within a second of its rows.
        let rows = fix_then_back((1000, 1100), (0, 100));
        assert!(rows[..11].iter().all(|r| r.1 == Some(45.0)));
        assert!(rows[11..].iter().all(|r| r.1.is_none()));
        assert_eq!(rows[11].0, 0);
    }

    #[test]
    fn time_going_back_even_a_little_starts_afresh_and_a_repeated_time_does_not() {
        // Back from 600 to 550 ms: the fix of 500 ms, though older than
        // the new rows, fills none of them.
        let rows = fix_then_back((500, 600), (550, 650));
        assert_eq!(rows.len(), 22);
        assert!(rows[..11].iter().all(|r| r.1 == Some(45.0)));
        assert!(rows[11..].iter().all(|r| r.1.is_none()));
        // A frame at the time of the one before is no step back.
        let mut records: Vec<_> = frames(0, 100).collect();
        records.push(fix(0, Some(45)));
        records.extend([frame(100), frame(110)]);
        assert!(rows_of(&records).iter().all(|r| r.1 == Some(45.0)));
    }

    #[test]
    fn frames_whose_time_stands_still_wait_in_bounded_numbers() {
        let mut assembler = RowAssembler::new();
        let mut emitted = 0;
        for pushed in 1..=10_000 {
            assembler.push(&frame(5), &mut |_| emitted += 1);
            // Handed out a run at a time: never more than the bound and a
            // run held.
            assert!(
                pushed - emitted < MAX_PENDING_ROWS + COMPLETE_RUN,
                "{pushed}"
            );
        }
        assert!(emitted > 0);
        assembler.finish(&mut |_| emitted += 1);
        assert_eq!(emitted, 10_000);
    }

    #[test]
    fn utc_runs_from_the_latest_pair_at_or_before_each_row() {
        let mut records: Vec<_> = frames(0, 300).collect();
        // Stamped at 150 ms, written after the frame of 300 ms.
        records.push(sync(150, 1_700_000_000_000));
        records.extend(frames(310, 600));
        // An older pair read later changes nothing; a newer one rules
        // from its stamp on.
        records.push(sync(100, 1_600_000_000_000));
        records.push(sync(500, 1_700_000_001_000));
        for (t, _, utc) in rows_of(&records) {
            let expected = match t {
                0..150 => None,
                150..500 => Some(1_700_000_000_000 + (t as i64 - 150)),
                _ => Some(1_700_000_001_000 + (t as i64 - 500)),
            };
            assert_eq!(utc, expected, "row at {t} ms");
        }
    }
}
