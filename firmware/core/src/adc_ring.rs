//! The steering ADC's DMA ring as the sampler reads it: which samples each
//! frame gets ([`SampleBacklog`]), and what to do when the conversions stop
//! ([`OverrunRecovery`]). The board's adapter only moves samples and pokes
//! registers; the decisions are here, tested on the host.
//!
//! **Every sample a frame is owed.** The ADC converts continuously while
//! the sampler may stall (an IMU re-initialisation, up to
//! [`crate::stall::LONGEST_STALL_US`]); the ticker then fires the missed
//! ticks back to back. A frame read late takes every sample converted up
//! to its scheduled time, oldest first, and leaves those converted since
//! (the lateness times the conversion rate) to the frames after it, so the
//! catch-up frames each get their own 10 ms of samples instead of the
//! first one taking the newest and the others nothing.
//!
//! **Conversions that stop.** After an overrun (a conversion the DMA did
//! not take in time) the STM32F4's ADC issues no more DMA requests until
//! it is restarted (RM0090 13.8.1: re-initialise the DMA stream, clear
//! OVR, trigger). If no sample comes for [`DRY_US`] anyway, restarted or
//! not, the adapter re-initialises the converter and its DMA stream
//! completely, at most once per [`REINIT_INTERVAL_US`], until samples flow.

/// Samples read from a converter's DMA ring and not yet handed to a frame,
/// oldest first, in `storage` (a `static` on the board: the adapter stays
/// small inside its task's future). The storage must hold the whole ring.
#[derive(Debug)]
pub struct SampleBacklog<'a> {
    samples: &'a mut [u16],
    held: usize,
}

impl<'a> SampleBacklog<'a> {
    /// Empty, holding at most `storage.len()` samples.
    #[must_use]
    pub fn new(storage: &'a mut [u16]) -> Self {
        Self {
            samples: storage,
            held: 0,
        }
    }

    /// Samples held.
    #[must_use]
    pub const fn held(&self) -> usize {
        self.held
    }

    /// Room behind the held samples, for the ring's newest: read them into
    /// its start, then call [`SampleBacklog::filled`].
    pub fn spare(&mut self) -> &mut [u16] {
        self.samples.get_mut(self.held..).unwrap_or_default()
    }

    /// `n` samples were written to the start of [`SampleBacklog::spare`].
    pub fn filled(&mut self, n: usize) {
        self.held = (self.held + n).min(self.samples.len());
    }

    /// Drops every held sample (the converter was restarted).
    pub fn clear(&mut self) {
        self.held = 0;
    }

    /// Hands a frame read `late_us` after its scheduled time the samples
    /// it is owed: all held but the newest `late_us × rate_hz`, which were
    /// converted after that time and belong to the next frame. Returns
    /// them, oldest first; the rest stay held.
    pub fn take_owed(&mut self, late_us: u64, rate_hz: u32) -> Owed<'_, 'a> {
        let newer = u64::from(rate_hz).saturating_mul(late_us) / 1_000_000;
        let keep = usize::try_from(newer).unwrap_or(usize::MAX).min(self.held);
        Owed {
            backlog: self,
            keep,
        }
    }
}

/// A frame's share of a [`SampleBacklog`]; dropping it removes the share
/// and keeps the samples that belong to later frames.
pub struct Owed<'b, 'a> {
    backlog: &'b mut SampleBacklog<'a>,
    keep: usize,
}

impl Owed<'_, '_> {
    /// The frame's samples, oldest first.
    #[must_use]
    pub fn samples(&self) -> &[u16] {
        let owed = self.backlog.held - self.keep;
        self.backlog.samples.get(..owed).unwrap_or_default()
    }
}

impl Drop for Owed<'_, '_> {
    fn drop(&mut self) {
        let b = &mut *self.backlog;
        let owed = b.held - self.keep;
        b.samples.copy_within(owed..b.held, 0);
        b.held = self.keep;
    }
}

/// No conversion for this long: the converter has stopped (at 42.7 kHz a
/// frame brings about 427). Three frames, so one late frame is no alarm.
pub const DRY_US: u64 = 30_000;
/// Full re-initialisations are at least this far apart, so a converter
/// that does not come back costs one attempt a second, not every frame.
pub const REINIT_INTERVAL_US: u64 = 1_000_000;

/// What the adapter does to its converter this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Recovery {
    /// Nothing: samples are flowing, or the last attempt is recent.
    None,
    /// The overrun restart of RM0090 13.8.1.
    Restart,
    /// Converter and DMA stream set up from scratch.
    Reinit,
}

/// Counters of [`OverrunRecovery`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RecoveryStats {
    /// Overrun restarts.
    pub restarts: u32,
    /// Full re-initialisations.
    pub reinits: u32,
}

/// Decides, frame by frame, whether the converter needs a restart or a
/// re-initialisation (module docs).
#[derive(Clone, Debug, Default)]
pub struct OverrunRecovery {
    /// When the last sample came (or the converter was last started).
    last_sample_us: Option<u64>,
    last_reinit_us: Option<u64>,
    stats: RecoveryStats,
}

impl OverrunRecovery {
    /// Nothing seen yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            last_sample_us: None,
            last_reinit_us: None,
            stats: RecoveryStats {
                restarts: 0,
                reinits: 0,
            },
        }
    }

    /// Counters so far.
    #[must_use]
    pub const fn stats(&self) -> RecoveryStats {
        self.stats
    }

    /// One frame at `now_us`: whether the overrun flag was set, and how many
    /// new samples the ring gave. Returns what to do.
    pub fn frame(&mut self, now_us: u64, overrun: bool, new_samples: usize) -> Recovery {
        if overrun {
            self.stats.restarts = self.stats.restarts.saturating_add(1);
            // The restart's samples are due from now.
            self.last_sample_us = Some(now_us);
            return Recovery::Restart;
        }
        let since = *self.last_sample_us.get_or_insert(now_us);
        if new_samples > 0 {
            self.last_sample_us = Some(now_us);
            return Recovery::None;
        }
        let dry = now_us.saturating_sub(since) >= DRY_US;
        let due = self
            .last_reinit_us
            .is_none_or(|t| now_us.saturating_sub(t) >= REINIT_INTERVAL_US);
        if dry && due {
            self.last_reinit_us = Some(now_us);
            self.stats.reinits = self.stats.reinits.saturating_add(1);
            return Recovery::Reinit;
        }
        Recovery::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 42.7 kHz: the board's ADC1 rate.
    const RATE_HZ: u32 = 21_000_000 / 492;
    const RING: usize = 2818;

    /// A converter producing sample `k` (its own index) at `k / RATE_HZ`,
    /// read into a backlog at the given times, each frame `late_us` after
    /// its schedule; returns each frame's samples.
    fn frames(reads: &[(u64, u64)]) -> Vec<Vec<u16>> {
        let mut storage = [0u16; RING];
        let mut backlog = SampleBacklog::new(&mut storage);
        let mut produced = 0u64;
        let mut out = Vec::new();
        for &(now_us, late_us) in reads {
            let due = now_us * u64::from(RATE_HZ) / 1_000_000;
            let spare = backlog.spare();
            let n = ((due - produced) as usize).min(spare.len());
            for (i, s) in spare.iter_mut().take(n).enumerate() {
                *s = ((produced + i as u64) % 65_536) as u16;
            }
            produced += n as u64;
            backlog.filled(n);
            out.push(backlog.take_owed(late_us, RATE_HZ).samples().to_vec());
        }
        out
    }

    #[test]
    fn frames_on_time_take_everything() {
        let reads: Vec<_> = (1..=5).map(|k| (k * 10_000, 0)).collect();
        let got = frames(&reads);
        assert!(got.iter().all(|f| f.len() == 426 || f.len() == 427));
        // Contiguous: nothing skipped, nothing twice.
        let all: Vec<u16> = got.concat();
        assert!(all.iter().zip(0u16..).all(|(&s, i)| s == i));
    }

    #[test]
    fn catch_up_frames_after_a_66_ms_stall_each_get_their_own_10_ms() {
        // Frames due at 10 and 20 ms on time; then the sampler stalls until
        // 86 ms; frames due at 30..80 ms fire back to back at 86 ms (1 µs
        // apart), the one due at 90 ms on time.
        let mut reads = vec![(10_000, 0), (20_000, 0)];
        for k in 3..=8u64 {
            let now = 86_000 + k;
            reads.push((now, now - k * 10_000));
        }
        reads.push((90_000, 0));
        let got = frames(&reads);
        for (k, f) in got.iter().enumerate() {
            // 426 or 427 each (the catch-up frames to within one sample).
            assert!(
                (425..=428).contains(&f.len()),
                "frame {} got {} samples",
                k + 1,
                f.len()
            );
        }
        // Every sample converted up to 90 ms, once, in order.
        let all: Vec<u16> = got.concat();
        assert_eq!(all.len() as u64, 90_000 * u64::from(RATE_HZ) / 1_000_000);
        assert!(all.iter().zip(0u16..).all(|(&s, i)| s == i));
    }

    #[test]
    fn a_frame_late_beyond_what_is_held_gets_nothing_and_loses_nothing() {
        let mut storage = [0u16; 8];
        let mut backlog = SampleBacklog::new(&mut storage);
        backlog.spare()[..3].copy_from_slice(&[1, 2, 3]);
        backlog.filled(3);
        assert!(backlog.take_owed(1_000_000, RATE_HZ).samples().is_empty());
        assert_eq!(backlog.held(), 3);
        assert_eq!(backlog.take_owed(0, RATE_HZ).samples(), [1, 2, 3]);
        assert_eq!(backlog.held(), 0);
        // Overfilled: never more than N.
        backlog.filled(100);
        assert_eq!(backlog.held(), 8);
        assert!(backlog.spare().is_empty());
        backlog.clear();
        assert_eq!(backlog.spare().len(), 8);
    }

    #[test]
    fn an_overrun_is_restarted_and_a_dead_converter_reinitialised_once_a_second() {
        let mut r = OverrunRecovery::new();
        assert_eq!(r.frame(10_000, false, 427), Recovery::None);
        assert_eq!(r.frame(20_000, true, 0), Recovery::Restart);
        // The restart took: samples again.
        assert_eq!(r.frame(30_000, false, 427), Recovery::None);
        // Another overrun, and this time nothing comes back.
        assert_eq!(r.frame(40_000, true, 0), Recovery::Restart);
        let mut actions = Vec::new();
        for k in 5..=300u64 {
            actions.push((k * 10_000, r.frame(k * 10_000, false, 0)));
        }
        let reinits: Vec<u64> = actions
            .iter()
            .filter(|a| a.1 == Recovery::Reinit)
            .map(|a| a.0)
            .collect();
        // First 30 ms after the restart, then once a second.
        assert_eq!(reinits, [70_000, 1_070_000, 2_070_000]);
        assert_eq!(
            r.stats(),
            RecoveryStats {
                restarts: 2,
                reinits: 3
            }
        );
        // Back: no more action.
        assert_eq!(r.frame(3_010_000, false, 427), Recovery::None);
        assert_eq!(r.frame(3_020_000, false, 0), Recovery::None);
    }

    #[test]
    fn catch_up_frames_with_no_new_samples_are_no_alarm() {
        let mut r = OverrunRecovery::new();
        assert_eq!(r.frame(86_000, false, 2818), Recovery::None);
        for k in 1..6 {
            assert_eq!(r.frame(86_000 + k, false, 0), Recovery::None);
        }
    }
}
