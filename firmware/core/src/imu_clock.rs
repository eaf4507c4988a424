//! IMU samples on the sensor's own clock.
//!
//! The ICM-42688-P makes its samples on its own oscillator (nominally
//! 100 Hz here, within a few per cent of it), not on the MCU's 10 ms frame
//! tick. Reading its newest sample once per tick, the frames would get a
//! sample 0-10 ms old in a slow sawtooth as the two clocks drift, the same
//! sample twice when the sensor runs slow and never see one when it runs
//! fast.
//!
//! Instead every sample is kept and placed in time:
//! - the sensor queues each sample in its FIFO and pulses its data-ready
//!   line (INT1); the board's timer latches the MCU time of each pulse in
//!   hardware ([`SampleClock::data_ready`]);
//! - each tick the port hands over every data-ready time, then every sample
//!   read from the FIFO ([`SampleClock::sample`]); both are the same events
//!   in the same order, so the k-th sample is paired with the k-th pulse;
//! - the frame due at `T` gets the sensor's output interpolated to
//!   `T − AGE_US` from the two samples around that time
//!   ([`SampleClock::frame`]). Its IMU value is therefore always exactly
//!   [`AGE_US`] old, whatever the two clocks do; a frame built late (a
//!   catch-up burst after a stall) gets the value of its own tick, as long
//!   as [`HISTORY`] samples reach back to it.
//!
//! What can go wrong is counted, never hidden:
//! - **skipped**: a sample the sensor made that reaches no frame: a gap of
//!   two periods or more between consecutive data-ready times (the FIFO
//!   overflowed or was flushed), a pulse whose sample the FIFO did not
//!   have, or a sample the sensor marked invalid;
//! - **late**: a frame whose time lies after the newest sample (the sensor
//!   stopped or runs more than 20 % slow): no value is made up, the frame
//!   marks the IMU stale;
//! - **untimed**: a sample whose pulse never came (a capture lost): it is
//!   placed one estimated period after the sample before it.
//!
//! Pairing relies on the order of the port's calls: data-ready times are
//! drained *before* the FIFO is read. The sensor writes a sample to its
//! FIFO before it pulses INT1, so every drained pulse has its sample in the
//! FIFO; a sample that arrived between the two steps waits, unpaired, for
//! its pulse at the next read.

use heapless::Deque;

use crate::imu::RawImu;

/// The sensor's nominal sample period (100 Hz output data rate), µs.
pub const NOMINAL_PERIOD_US: u32 = 10_000;

/// Age of every frame's IMU value, µs: the longest sample period accepted
/// (the sensor 20 % slow) after the frame's tick, so that the sample after
/// `T − AGE_US` has always arrived when the frame at `T` is read.
pub const AGE_US: u64 = 12_000;

/// Paired samples kept for interpolation: 16 periods, 160 ms, more than
/// the longest stall of the sampler ([`crate::stall::LONGEST_STALL_US`])
/// plus [`AGE_US`], so the frames of a catch-up burst still find theirs.
pub const HISTORY: usize = 16;

/// Samples the sensor's FIFO holds (2 KiB of 16-byte packets): the longest
/// stall, 1.28 s, after which nothing is lost.
pub const FIFO_CAPACITY: usize = 128;

/// Data-ready times or samples waiting for their partner. A tick brings one
/// of each; after a stall the rest wait in the sensor's FIFO and the
/// adapter's pulse queue, taken as the catch-up frames need them.
pub const PENDING: usize = 16;

/// Two samples further apart than this are not interpolated between, µs:
/// the sensor was gone (four periods).
const MAX_GAP_US: u64 = 4 * NOMINAL_PERIOD_US as u64;

/// Counters of a [`SampleClock`] since boot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClockStats {
    /// Samples paired with their data-ready time.
    pub samples: u32,
    /// Samples the sensor made that reach no frame (module docs).
    pub skipped: u32,
    /// Frames with no sample after their time.
    pub late: u32,
    /// Samples placed by the period estimate: their pulse was lost.
    pub untimed: u32,
}

/// One frame's IMU value from [`SampleClock::frame`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameValue {
    /// The six axes (accel x/y/z, gyro x/y/z) in sensor counts,
    /// interpolated to the frame's time less [`AGE_US`]; `None` when no
    /// sample follows that time (late) or none precedes it.
    pub counts: Option<[f32; 6]>,
    /// Samples skipped since the previous frame (`ClockStats::skipped`).
    pub skipped: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Timed {
    t_us: u64,
    raw: RawImu,
}

/// A sample read from the FIFO, waiting for its data-ready time.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Waiting {
    /// `None`: the sensor marked it invalid; it still had a pulse.
    raw: Option<RawImu>,
    /// When the FIFO read that found it ended (set by the frame after it):
    /// its own pulse cannot be later.
    seen_us: Option<u64>,
}

/// Pairs samples with their data-ready times and resamples them onto the
/// frames (module docs).
#[derive(Clone, Debug)]
pub struct SampleClock {
    pulses: Deque<u64, PENDING>,
    waiting: Deque<Waiting, PENDING>,
    history: Deque<Timed, HISTORY>,
    /// Time of the newest paired pulse, also of an invalid sample's.
    last_pulse_us: Option<u64>,
    /// The sensor's period in MCU µs, estimated from the pulses.
    period_us: f32,
    stats: ClockStats,
    /// `stats.skipped` at the last frame.
    skipped_reported: u32,
}

impl Default for SampleClock {
    fn default() -> Self {
        Self::new()
    }
}

impl SampleClock {
    /// Nothing seen; the period at its nominal value.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            pulses: Deque::new(),
            waiting: Deque::new(),
            history: Deque::new(),
            last_pulse_us: None,
            period_us: NOMINAL_PERIOD_US as f32,
            stats: ClockStats {
                samples: 0,
                skipped: 0,
                late: 0,
                untimed: 0,
            },
            skipped_reported: 0,
        }
    }

    /// Counters so far.
    #[must_use]
    pub const fn stats(&self) -> ClockStats {
        self.stats
    }

    /// The sensor's sample period as measured in MCU time, µs (10 000 at
    /// exactly 100 Hz; 10 200 for a sensor 2 % slow).
    #[must_use]
    pub const fn period_us(&self) -> f32 {
        self.period_us
    }

    /// Forgets every sample and pulse (the sensor was reset, its FIFO
    /// flushed); counters and the period estimate stay.
    pub fn restart(&mut self) {
        self.pulses.clear();
        self.waiting.clear();
        self.history.clear();
        self.last_pulse_us = None;
    }

    /// A data-ready pulse at `t_us` (MCU time, µs since boot), in order.
    /// Returns whether the clock has room for more pulses now.
    pub fn data_ready(&mut self, t_us: u64) -> bool {
        // A waiting sample seen before this pulse is not its sample: its
        // own pulse was lost.
        while let Some(w) = self.waiting.front().copied() {
            if w.seen_us.is_none_or(|seen| t_us <= seen) {
                break;
            }
            self.waiting.pop_front();
            self.untimed(w);
        }
        if self.pulses.is_full() {
            // Samples that never came for the oldest pulses: skipped.
            self.pulses.pop_front();
            self.count_skipped(1);
        }
        let _ = self.pulses.push_back(t_us);
        self.pair();
        !self.pulses.is_full()
    }

    /// Pulses waiting for their samples.
    #[must_use]
    pub fn pulses_waiting(&self) -> usize {
        self.pulses.len()
    }

    /// The next sample from the FIFO, in order; `None` for one the sensor
    /// marked invalid.
    pub fn sample(&mut self, raw: Option<RawImu>) {
        if self.waiting.is_full() {
            self.waiting.pop_front();
            self.count_skipped(1);
        }
        let _ = self.waiting.push_back(Waiting { raw, seen_us: None });
        self.pair();
    }

    /// Whether the frame due at `frame_us` still lacks the sample after its
    /// time: the port reads the FIFO until it has it, and leaves the rest
    /// there (the FIFO is the buffer of a catch-up burst, not this clock).
    #[must_use]
    pub fn wants_sample(&self, frame_us: u64) -> bool {
        let t_us = frame_us.saturating_sub(AGE_US);
        self.history.back().is_none_or(|s| s.t_us < t_us)
    }

    /// The value of the frame due at `frame_us`, after this tick's pulses
    /// and samples, the FIFO read having ended at `read_us` and the whole
    /// FIFO read (module docs).
    pub fn frame(&mut self, frame_us: u64, read_us: u64) -> FrameValue {
        self.frame_leaving(frame_us, read_us, 0)
    }

    /// As [`SampleClock::frame`], with `unread` samples left in the FIFO:
    /// the oldest `unread` pulses still alone are theirs and wait.
    pub fn frame_leaving(&mut self, frame_us: u64, read_us: u64, unread: usize) -> FrameValue {
        // Every other pulse handed in before the FIFO was read has had its
        // sample: one still alone has lost it (the FIFO overflowed, and the
        // sensor dropped its oldest samples).
        while self.pulses.len() > unread {
            if let Some(t_us) = self.pulses.pop_front() {
                self.place(t_us, None);
            }
        }
        // A sample found by an earlier read would have been paired with its
        // pulse by now: the pulse was lost (or the data-ready line is dead).
        // It is placed by the period estimate.
        while let Some(w) = self.waiting.front().copied() {
            if w.seen_us.is_none() {
                break;
            }
            self.waiting.pop_front();
            self.untimed(w);
        }
        for w in &mut self.waiting {
            w.seen_us.get_or_insert(read_us);
        }
        let counts = self.interpolate(frame_us.saturating_sub(AGE_US));
        if counts.is_none() {
            self.stats.late = self.stats.late.saturating_add(1);
        }
        let skipped = self.stats.skipped - self.skipped_reported;
        self.skipped_reported = self.stats.skipped;
        FrameValue { counts, skipped }
    }

    /// Places a sample whose pulse was lost a period after the one before
    /// (or when it was seen, with none before).
    fn untimed(&mut self, w: Waiting) {
        self.stats.untimed = self.stats.untimed.saturating_add(1);
        let t_us = match (self.last_pulse_us, w.seen_us) {
            (Some(t), _) => t + self.period_us as u64,
            (None, seen) => seen.unwrap_or(0),
        };
        self.place(t_us, w.raw);
    }

    fn count_skipped(&mut self, n: usize) {
        let n = u32::try_from(n).unwrap_or(u32::MAX);
        self.stats.skipped = self.stats.skipped.saturating_add(n);
    }

    fn pair(&mut self) {
        while !self.pulses.is_empty() && !self.waiting.is_empty() {
            if let (Some(t_us), Some(w)) = (self.pulses.pop_front(), self.waiting.pop_front()) {
                self.stats.samples = self.stats.samples.saturating_add(1);
                self.place(t_us, w.raw);
            }
        }
    }

    /// Puts a sample at `t_us`: counts the periods missing before it,
    /// refines the period estimate, keeps it for interpolation.
    fn place(&mut self, t_us: u64, raw: Option<RawImu>) {
        if let Some(prev) = self.last_pulse_us {
            let gap = t_us.saturating_sub(prev) as f32;
            let periods = (gap / self.period_us + 0.5) as u32;
            self.count_skipped(periods.saturating_sub(1) as usize);
            // Only single, plausible periods teach the estimate (±20 %).
            if periods == 1 && (gap - self.period_us).abs() < 0.2 * self.period_us {
                self.period_us += (gap - self.period_us) / 64.0;
            }
        }
        self.last_pulse_us = Some(t_us);
        let Some(raw) = raw else {
            self.count_skipped(1);
            return;
        };
        if self.history.is_full() {
            self.history.pop_front();
        }
        let _ = self.history.push_back(Timed { t_us, raw });
    }

    /// The six axes at `t_us`, linear between the samples either side.
    fn interpolate(&self, t_us: u64) -> Option<[f32; 6]> {
        let mut before: Option<&Timed> = None;
        for s in &self.history {
            if s.t_us >= t_us {
                let a = before?;
                if s.t_us - a.t_us > MAX_GAP_US {
                    return None;
                }
                let span = (s.t_us - a.t_us).max(1) as f32;
                let w = (t_us - a.t_us) as f32 / span;
                let (xa, xb) = (axes(&a.raw), axes(&s.raw));
                return Some(core::array::from_fn(|i| xa[i] + (xb[i] - xa[i]) * w));
            }
            before = Some(s);
        }
        None
    }
}

fn axes(raw: &RawImu) -> [f32; 6] {
    let [ax, ay, az] = raw.accel.map(f32::from);
    let [gx, gy, gz] = raw.gyro.map(f32::from);
    [ax, ay, az, gx, gy, gz]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(k: i16) -> RawImu {
        RawImu {
            accel: [k, 0, 0],
            gyro: [0, 0, -k],
        }
    }

    #[test]
    fn a_frame_between_two_samples_gets_their_interpolation() {
        let mut c = SampleClock::new();
        c.data_ready(100_000);
        c.sample(Some(raw(10)));
        c.data_ready(110_000);
        c.sample(Some(raw(20)));
        // Due at 119 ms: the value at 107 ms, 70 % of the way.
        let v = c.frame(119_000, 119_100);
        let counts = v.counts.expect("bracketed");
        assert!((counts[0] - 17.0).abs() < 1e-4 && (counts[5] + 17.0).abs() < 1e-4);
        assert_eq!(v.skipped, 0);
        // Due at 123 ms: 111 ms is after the newest sample: late.
        assert_eq!(c.frame(123_000, 123_100).counts, None);
        assert_eq!(c.stats().late, 1);
    }

    #[test]
    fn a_sample_before_its_pulse_waits_one_frame_for_it() {
        let mut c = SampleClock::new();
        // Pulses drained at 109.99 ms; the pulse at 110 ms comes before
        // the FIFO read ends at 110.02 ms, which finds both samples.
        c.data_ready(100_000);
        c.sample(Some(raw(1)));
        c.sample(Some(raw(2)));
        let _ = c.frame(110_000, 110_020);
        c.data_ready(110_000);
        c.data_ready(120_000);
        c.sample(Some(raw(3)));
        let v = c.frame(120_000, 120_030);
        assert_eq!(v.counts.map(|x| x[0]), Some(1.8));
        assert_eq!(c.stats().untimed, 0);
        assert_eq!(c.stats().samples, 3);
    }

    /// A pulse latched at the very microsecond the FIFO read ended is the
    /// pulse of the sample that read found waiting (the sensor writes its
    /// sample before it pulses): paired, not placed by the period.
    #[test]
    fn a_pulse_exactly_at_the_reads_end_is_its_samples() {
        let mut c = SampleClock::new();
        c.data_ready(100_000);
        c.sample(Some(raw(1)));
        c.sample(Some(raw(2)));
        let _ = c.frame(110_000, 110_020);
        c.data_ready(110_020);
        c.data_ready(120_020);
        c.sample(Some(raw(3)));
        let v = c.frame(120_000, 120_030);
        assert_eq!(c.stats().untimed, 0);
        assert_eq!(c.stats().samples, 3);
        // 108 ms lies 8 of the 10.02 ms from the first sample to the second.
        let want = 1.0 + 8_000.0 / 10_020.0;
        assert!(
            v.counts.is_some_and(|x| (x[0] - want).abs() < 1e-4),
            "{v:?}"
        );
    }

    #[test]
    fn lost_pulses_samples_and_gaps_are_counted() {
        let mut c = SampleClock::new();
        c.data_ready(100_000);
        c.sample(Some(raw(1)));
        let _ = c.frame(105_000, 105_100);
        // Two periods missing (the FIFO overflowed): skipped 2.
        c.data_ready(130_000);
        c.sample(Some(raw(4)));
        assert_eq!(c.frame(135_000, 135_100).skipped, 2);
        // A pulse whose sample the FIFO did not have.
        c.data_ready(140_000);
        assert_eq!(c.frame(145_000, 145_100).skipped, 1);
        // A sample (made at 150 ms) whose pulse never comes: the next
        // pulse is after the read that found it, so not its own.
        c.sample(Some(raw(6)));
        let _ = c.frame(155_000, 155_100);
        c.data_ready(160_000);
        c.sample(Some(raw(7)));
        let v = c.frame(165_000, 165_100);
        assert_eq!(c.stats().untimed, 1);
        // 6 placed a period after the lone pulse at 140 ms.
        assert!((v.counts.expect("bracketed")[0] - 6.3).abs() < 1e-4);
        // An invalid sample consumes its pulse and is skipped.
        c.data_ready(170_000);
        c.sample(None);
        assert_eq!(c.frame(175_000, 175_100).skipped, 1);
        assert_eq!(c.stats().skipped, 4);
    }

    #[test]
    fn without_pulses_the_samples_are_placed_by_the_period() {
        // A dead data-ready line: every sample is untimed, none lost.
        let mut c = SampleClock::new();
        let mut last = None;
        for k in 0..20u64 {
            c.sample(Some(raw(k as i16)));
            last = c.frame(100_000 + k * 10_000, 100_050 + k * 10_000).counts;
        }
        assert_eq!(c.stats().untimed, 19);
        assert_eq!(c.stats().skipped, 0);
        assert!(last.is_some());
    }

    #[test]
    fn the_period_is_learnt_from_the_pulses() {
        let mut c = SampleClock::new();
        for k in 0..2000u64 {
            c.data_ready(k * 10_200);
            c.sample(Some(raw(0)));
        }
        assert!((c.period_us() - 10_200.0).abs() < 1.0, "{}", c.period_us());
    }

    #[test]
    fn no_interpolation_across_a_dead_sensor() {
        let mut c = SampleClock::new();
        c.data_ready(100_000);
        c.sample(Some(raw(1)));
        c.data_ready(200_000);
        c.sample(Some(raw(2)));
        assert_eq!(c.frame(162_000, 162_100).counts, None);
        c.restart();
        assert_eq!(c.frame(212_000, 212_100).counts, None);
    }

    #[test]
    fn a_pulse_whose_sample_is_still_in_the_fifo_waits_for_it() {
        let mut c = SampleClock::new();
        for k in 0..3 {
            c.data_ready(100_000 + k * 10_000);
        }
        c.sample(Some(raw(0)));
        c.sample(Some(raw(1)));
        assert!(!c.wants_sample(120_000));
        assert!(c.wants_sample(135_000));
        // The third sample is still in the FIFO: its pulse waits for it.
        assert_eq!(c.frame_leaving(120_000, 120_100, 1).skipped, 0);
        assert_eq!(c.pulses_waiting(), 1);
        c.sample(Some(raw(2)));
        let v = c.frame_leaving(130_000, 130_100, 0);
        assert_eq!(v.skipped, 0);
        assert_eq!(v.counts.map(|a| a[0]), Some(1.8));
        assert_eq!(c.stats().samples, 3);
        // With the FIFO said empty, a pulse still alone has lost its sample.
        c.data_ready(130_000);
        assert_eq!(c.frame(140_000, 140_100).skipped, 1);
    }

    #[test]
    fn the_clock_says_when_it_has_no_room_for_pulses() {
        let mut c = SampleClock::new();
        for k in 0..PENDING as u64 - 1 {
            assert!(c.data_ready(100_000 + k * 10_000));
        }
        assert!(!c.data_ready(300_000));
        assert_eq!(c.pulses_waiting(), PENDING);
    }
}
