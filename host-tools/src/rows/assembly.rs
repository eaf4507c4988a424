//! Which GPS fix and which UTC sync pair fill each frame's row, and when a
//! row is complete: the logic every reader of rows shares, whatever holds
//! the rows meanwhile (a queue of [`super::Row`]s, or columns).
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

/// Rows waiting for a late fix or pair, held by the caller, oldest first.
/// A row's GPS columns are those of the fix in force (the last one passed
/// to [`PendingRows::fix`]) or none.
pub trait PendingRows {
    /// The fix in force from now on.
    fn fix(&mut self, gps: GpsColumns);
    /// A new row for `frame` at the back, with the fix in force or none,
    /// and the UTC known so far.
    fn push(&mut self, frame: &Frame, gps: bool, utc_us: Option<i64>);
    /// Pending row `i` (0: the oldest) takes the fix in force, or none.
    fn set_gps(&mut self, i: usize, gps: bool);
    /// Pending row `i` takes this UTC.
    fn set_utc(&mut self, i: usize, utc_us: Option<i64>);
    /// The frame time of pending row `i`, µs.
    fn time_us(&self, i: usize) -> u64;
    /// The oldest pending row is complete and leaves the queue.
    fn complete_first(&mut self);
}

/// Decides, record by record, what fills the pending rows and when they
/// are complete. Memory is bounded: at most [`MAX_PENDING_ROWS`] wait.
#[derive(Default)]
pub struct Assembly {
    /// Rows pending (their times never decrease: time going back
    /// completes them all).
    pending: usize,
    /// The fix in force and its time.
    gps: Option<(u64, GpsColumns)>,
    sync: Option<UtcSync>,
}

impl Assembly {
    /// Takes one record (frames, fixes and sync pairs matter; the others
    /// are passed over).
    pub fn push(&mut self, record: &Record<'_>, rows: &mut impl PendingRows) {
        match record {
            Record::Frame(frame) => self.frame(frame, rows),
            Record::Gps(fix) => {
                let columns = GpsColumns::from_fix(fix);
                let newer = self.gps.is_none_or(|(t, _)| fix.t_us >= t);
                if newer {
                    self.gps = columns.map(|c| (fix.t_us, c));
                    if let Some(c) = columns {
                        rows.fix(c);
                    }
                    for i in 0..self.pending {
                        let t = rows.time_us(i);
                        if t >= fix.t_us {
                            rows.set_gps(i, columns.is_some() && t - fix.t_us <= GPS_STALE_US);
                        }
                    }
                }
            }
            // Like a fix, a pair is stamped before frames written ahead of it.
            Record::UtcSync(sync) if self.sync.is_none_or(|s| sync.t_us >= s.t_us) => {
                self.sync = Some(*sync);
                for i in 0..self.pending {
                    let t = rows.time_us(i);
                    if t >= sync.t_us {
                        rows.set_utc(i, utc_us_at(*sync, t));
                    }
                }
            }
            _ => {}
        }
    }

    fn frame(&mut self, frame: &Frame, rows: &mut impl PendingRows) {
        // Time going back starts a new segment: nothing waits across it,
        // and a fix from before it fills no row after it.
        if self.pending > 0 && frame.t_us < rows.time_us(self.pending - 1) {
            self.finish(rows);
            self.gps = None;
        }
        if self.pending >= MAX_PENDING_ROWS {
            self.complete_first(rows);
        }
        let gps = self
            .gps
            .is_some_and(|(t, _)| t <= frame.t_us && frame.t_us - t <= GPS_STALE_US);
        let utc_us = self
            .sync
            .filter(|s| s.t_us <= frame.t_us)
            .and_then(|s| utc_us_at(s, frame.t_us));
        rows.push(frame, gps, utc_us);
        self.pending += 1;
        while self.pending > 0 && rows.time_us(0) + GPS_WAIT_US < frame.t_us {
            self.complete_first(rows);
        }
    }

    /// Completes every row still held back.
    pub fn finish(&mut self, rows: &mut impl PendingRows) {
        while self.pending > 0 {
            self.complete_first(rows);
        }
    }

    fn complete_first(&mut self, rows: &mut impl PendingRows) {
        self.pending -= 1;
        rows.complete_first();
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
