//! Which GPS fix and which UTC sync pair fill each frame's row, and when a
//! row is complete: the logic every reader of rows shares, whatever holds
//! the rows meanwhile (a queue of [`super::Row`]s, or columns).
//!
//! A GPS fix is stamped when its first sentence began, so it reaches the
//! card after frames that come later than it; rows are held back for
//! [`GPS_WAIT_US`] so such a fix still fills them. A UTC sync pair is
//! stamped the same way.

use std::collections::VecDeque;

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
pub trait PendingRows {
    /// A new row for `frame` at the back, with the fix and UTC known so far.
    fn push(&mut self, frame: &Frame, gps: Option<GpsColumns>, utc_us: Option<i64>);
    /// Pending row `i` (0: the oldest) takes these GPS columns.
    fn set_gps(&mut self, i: usize, gps: Option<GpsColumns>);
    /// Pending row `i` takes this UTC.
    fn set_utc(&mut self, i: usize, utc_us: Option<i64>);
    /// The oldest pending row is complete and leaves the queue.
    fn complete_first(&mut self);
}

/// Decides, record by record, what fills the pending rows and when they
/// are complete. Memory is bounded: at most [`MAX_PENDING_ROWS`] wait.
#[derive(Default)]
pub struct Assembly {
    /// The time of every pending row, oldest first (never decreasing:
    /// time going back completes them all).
    pending_us: VecDeque<u64>,
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
                    for (i, &t) in self.pending_us.iter().enumerate() {
                        if t >= fix.t_us {
                            rows.set_gps(i, columns.filter(|_| t - fix.t_us <= GPS_STALE_US));
                        }
                    }
                }
            }
            // Like a fix, a pair is stamped before frames written ahead of it.
            Record::UtcSync(sync) if self.sync.is_none_or(|s| sync.t_us >= s.t_us) => {
                self.sync = Some(*sync);
                for (i, &t) in self.pending_us.iter().enumerate() {
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
        if self.pending_us.back().is_some_and(|&t| frame.t_us < t) {
            self.finish(rows);
            self.gps = None;
        }
        if self.pending_us.len() >= MAX_PENDING_ROWS {
            self.complete_first(rows);
        }
        let gps = self.gps.and_then(|(t, columns)| {
            (t <= frame.t_us && frame.t_us - t <= GPS_STALE_US).then_some(columns)
        });
        let utc_us = self
            .sync
            .filter(|s| s.t_us <= frame.t_us)
            .and_then(|s| utc_us_at(s, frame.t_us));
        rows.push(frame, gps, utc_us);
        self.pending_us.push_back(frame.t_us);
        while self
            .pending_us
            .front()
            .is_some_and(|&t| t + GPS_WAIT_US < frame.t_us)
        {
            self.complete_first(rows);
        }
    }

    /// Completes every row still held back.
    pub fn finish(&mut self, rows: &mut impl PendingRows) {
        while !self.pending_us.is_empty() {
            self.complete_first(rows);
        }
    }

    fn complete_first(&mut self, rows: &mut impl PendingRows) {
        self.pending_us.pop_front();
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
