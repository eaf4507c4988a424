//! Counted, rate-limited fault records.
//!
//! A sensor that goes bad can fail hundreds of times a second; one record per
//! failure would flood the card. Instead the first fault of each kind is
//! recorded at once and later ones are counted and recorded at most once per
//! interval, with the count since the previous record of that kind (the
//! `count` field of [`Fault`]). Nothing is lost: the counts add up to the
//! number of faults that happened.
//!
//! Each source defines its codes as `FAULT_*` constants next to the code
//! that detects them. GPS ([`crate::gps`]): 1 checksum mismatch, 2 line
//! without checksum, 3 overlong line, 4 broken line (lost or corrupt bytes),
//! 5 unparseable sentence.

use crate::format::{Fault, FaultSource};

/// Fault counter for one source whose codes are `1..=N`.
#[derive(Clone, Debug)]
pub struct FaultCounter<const N: usize> {
    source: FaultSource,
    interval_us: u64,
    pending: [u16; N],
    last_record_us: [Option<u64>; N],
    total: [u32; N],
}

impl<const N: usize> FaultCounter<N> {
    /// A counter for `source` that records each code at most once per
    /// `interval_us`.
    #[must_use]
    pub const fn new(source: FaultSource, interval_us: u64) -> Self {
        Self {
            source,
            interval_us,
            pending: [0; N],
            last_record_us: [None; N],
            total: [0; N],
        }
    }

    /// Counts one fault with `code` (`1..=N`; others are ignored) at `t_us`,
    /// and hands a record to `out` if one is due.
    pub fn count(&mut self, code: u8, t_us: u64, out: &mut impl FnMut(Fault)) {
        let Some(i) = usize::from(code).checked_sub(1).filter(|&i| i < N) else {
            return;
        };
        self.pending[i] = self.pending[i].saturating_add(1);
        self.total[i] = self.total[i].saturating_add(1);
        let due =
            self.last_record_us[i].is_none_or(|last| t_us.saturating_sub(last) >= self.interval_us);
        // A saturated count would under-report: record before it can.
        if due || self.pending[i] == u16::MAX {
            self.record(i, t_us, out);
        }
    }

    /// Records the counts that have waited at least one interval.
    pub fn poll(&mut self, now_us: u64, out: &mut impl FnMut(Fault)) {
        for i in 0..N {
            let due = self.last_record_us[i]
                .is_none_or(|last| now_us.saturating_sub(last) >= self.interval_us);
            if self.pending[i] > 0 && due {
                self.record(i, now_us, out);
            }
        }
    }

    /// Records every pending count now (end of input, log closing).
    pub fn flush(&mut self, now_us: u64, out: &mut impl FnMut(Fault)) {
        for i in 0..N {
            if self.pending[i] > 0 {
                self.record(i, now_us, out);
            }
        }
    }

    /// Faults with `code` since boot, recorded or not.
    #[must_use]
    pub fn total(&self, code: u8) -> u32 {
        usize::from(code)
            .checked_sub(1)
            .and_then(|i| self.total.get(i))
            .copied()
            .unwrap_or(0)
    }

    fn record(&mut self, i: usize, t_us: u64, out: &mut impl FnMut(Fault)) {
        out(Fault {
            t_us,
            source: self.source,
            // `i < N` and codes are documented as `1..=N` with N small.
            code: (i + 1) as u8,
            count: self.pending[i],
        });
        self.pending[i] = 0;
        self.last_record_us[i] = Some(t_us);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_fault_at_once_then_counted_per_interval() {
        let mut c = FaultCounter::<2>::new(FaultSource::Gps, 1_000_000);
        let mut out = Vec::new();
        for t in (0..2_500_000).step_by(100_000) {
            c.count(1, t, &mut |f| out.push(f));
        }
        c.flush(2_600_000, &mut |f| out.push(f));
        let counts: Vec<_> = out.iter().map(|f| (f.t_us, f.count)).collect();
        assert_eq!(
            counts,
            [(0, 1), (1_000_000, 10), (2_000_000, 10), (2_600_000, 4)]
        );
        assert_eq!(c.total(1), 25);
        assert_eq!(out.iter().map(|f| u32::from(f.count)).sum::<u32>(), 25);
        assert!(out
            .iter()
            .all(|f| f.code == 1 && f.source == FaultSource::Gps));
    }

    #[test]
    fn poll_records_what_waited_an_interval() {
        let mut c = FaultCounter::<1>::new(FaultSource::Gps, 1000);
        let mut out = Vec::new();
        c.count(1, 0, &mut |f| out.push(f));
        c.count(1, 10, &mut |f| out.push(f));
        c.poll(500, &mut |f| out.push(f));
        assert_eq!(out.len(), 1);
        c.poll(1000, &mut |f| out.push(f));
        assert_eq!(out.len(), 2);
        assert_eq!(out[1].count, 1);
    }

    #[test]
    fn codes_out_of_range_are_ignored() {
        let mut c = FaultCounter::<1>::new(FaultSource::Gps, 1000);
        let mut out = Vec::new();
        c.count(0, 0, &mut |f| out.push(f));
        c.count(2, 0, &mut |f| out.push(f));
        assert!(out.is_empty());
        assert_eq!(c.total(0) + c.total(2), 0);
    }
}
