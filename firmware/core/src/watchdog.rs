//! How long the independent watchdog waits, and when it may be fed.
//!
//! The watchdog counts the LSI, an RC oscillator the STM32F405 datasheet
//! gives as 17-47 kHz (32 kHz typical); drivers compute the timeout for
//! 32 kHz. At the fastest LSI the real timeout is 32/47 of the request, so
//! the request is the longest legitimate gap between two feeds scaled by
//! 47/32. At the slowest it is 32/17 of the request: how long a hang can
//! go unnoticed.
//!
//! The feed rule ([`Liveness`]): at most once per [`ROUND_US`], and only if
//! every watched task's heartbeat moved since the previous round. The
//! thread-mode writer proves itself by asking (between card operations and
//! from a task behind it), so the longest legitimate gap is one round plus
//! one card operation at its budget.

use crate::drivers::sd_spi::CARD_OPERATION_BUDGET_US;

/// Nominal LSI, Hz: what a driver's timeout arithmetic assumes.
pub const LSI_NOMINAL_HZ: u32 = 32_000;
/// Slowest LSI (datasheet).
pub const LSI_MIN_HZ: u32 = 17_000;
/// Fastest LSI (datasheet).
pub const LSI_MAX_HZ: u32 = 47_000;

/// The liveness check's period, µs.
pub const ROUND_US: u64 = 1_000_000;
/// Slack over the sum: the executor's latency, a late timer.
const MARGIN_US: u64 = 500_000;

/// Longest legitimate time between two feeds, µs.
pub const LONGEST_GAP_US: u64 = ROUND_US + CARD_OPERATION_BUDGET_US + MARGIN_US;

/// The timeout to ask a 32 kHz-assuming driver for, µs, so that even at
/// [`LSI_MAX_HZ`] the watchdog waits at least `needed_us`.
#[must_use]
pub const fn timeout_request_us(needed_us: u64) -> u64 {
    (needed_us * LSI_MAX_HZ as u64).div_ceil(LSI_NOMINAL_HZ as u64)
}

/// The real timeout of `request_us` at an LSI of `lsi_hz`, µs.
#[must_use]
pub const fn real_timeout_us(request_us: u64, lsi_hz: u32) -> u64 {
    request_us * LSI_NOMINAL_HZ as u64 / lsi_hz as u64
}

/// What the board asks its watchdog driver for.
pub const TIMEOUT_REQUEST_US: u64 = timeout_request_us(LONGEST_GAP_US);
// Within the driver's range: prescaler 256, 12-bit reload, at 32 kHz.
const _: () = assert!(TIMEOUT_REQUEST_US <= 4096 * 256 * 1_000_000 / LSI_NOMINAL_HZ as u64);

/// The verdict of one [`Liveness::check`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// Less than a round since the last check: do nothing.
    NotDue,
    /// Every heartbeat moved: feed the watchdog.
    Alive,
    /// The task with this index did not beat during the round: do not feed.
    Stalled(usize),
}

/// The feed rule for `N` heartbeat counters (see the module docs). Until
/// [`Liveness::arm`] (the watchdog started) nothing is due: before it the
/// tasks that beat may not run yet (card reads at boot, the self-test), and
/// no feed or stall means anything.
#[derive(Clone, Debug)]
pub struct Liveness<const N: usize> {
    last_beats: [u32; N],
    /// When the current round began; `None` until armed.
    last_check_us: Option<u64>,
}

impl<const N: usize> Liveness<N> {
    /// Not armed: every check is [`Verdict::NotDue`].
    #[must_use]
    pub const fn new() -> Self {
        Self {
            last_beats: [0; N],
            last_check_us: None,
        }
    }

    /// The watchdog was started at `now_us` with the counters at `beats`:
    /// the first round begins.
    pub fn arm(&mut self, now_us: u64, beats: [u32; N]) {
        self.last_check_us = Some(now_us);
        self.last_beats = beats;
    }

    /// Checks the heartbeat counters `beats` at `now_us`.
    pub fn check(&mut self, now_us: u64, beats: [u32; N]) -> Verdict {
        let Some(last_us) = self.last_check_us else {
            return Verdict::NotDue;
        };
        if now_us.saturating_sub(last_us) < ROUND_US {
            return Verdict::NotDue;
        }
        let stalled = beats
            .iter()
            .zip(self.last_beats)
            .position(|(&now, last)| now == last);
        self.last_check_us = Some(now_us);
        self.last_beats = beats;
        stalled.map_or(Verdict::Alive, Verdict::Stalled)
    }
}

impl<const N: usize> Default for Liveness<N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_timeout_holds_at_the_fastest_lsi_and_is_bounded_at_the_slowest() {
        assert_eq!(LONGEST_GAP_US, 3_000_000);
        assert_eq!(TIMEOUT_REQUEST_US, 4_406_250);
        assert!(real_timeout_us(TIMEOUT_REQUEST_US, LSI_MAX_HZ) >= LONGEST_GAP_US);
        assert_eq!(real_timeout_us(TIMEOUT_REQUEST_US, LSI_MIN_HZ), 8_294_117);
    }

    #[test]
    fn fed_only_when_every_heartbeat_moved_once_a_round() {
        let mut l = Liveness::<2>::new();
        l.arm(0, [0, 0]);
        assert_eq!(l.check(500_000, [50, 5]), Verdict::NotDue);
        assert_eq!(l.check(1_000_000, [100, 10]), Verdict::Alive);
        assert_eq!(l.check(2_000_000, [200, 10]), Verdict::Stalled(1));
        assert_eq!(l.check(3_000_000, [200, 20]), Verdict::Stalled(0));
        assert_eq!(l.check(4_000_000, [300, 30]), Verdict::Alive);
    }

    #[test]
    fn nothing_is_due_before_the_watchdog_is_armed() {
        // Boot card reads and the self-test: the sampler does not beat.
        let mut l = Liveness::<2>::new();
        for k in 0..10 {
            assert_eq!(l.check(k * ROUND_US, [0, 0]), Verdict::NotDue);
        }
        // Armed late: the first round starts then, with the counters then.
        l.arm(10 * ROUND_US, [7, 3]);
        assert_eq!(l.check(10 * ROUND_US + 1, [7, 3]), Verdict::NotDue);
        assert_eq!(l.check(11 * ROUND_US, [8, 4]), Verdict::Alive);
    }
}
