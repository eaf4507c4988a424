//! Edge times from a free-running 32-bit capture timer.
//!
//! The board's wheel timer counts at 1 MHz and latches its count in
//! hardware at each hall-sensor edge. The interrupt that follows reads three
//! things as close together as it can: the latched count (the *capture*),
//! the running count, and the system clock (µs since boot). The counter kept
//! running since the capture, so the edge happened
//!
//! ```text
//! age = counter − capture   (mod 2³²: exact across the timer's wrap every 71.6 min)
//! t_edge = now − age
//! ```
//!
//! Both clocks come from the same crystal, so no drift separates them; the
//! only error is the few cycles between reading the counter and the clock.
//! Everything here is arithmetic on those three numbers, so the interrupt
//! handler on the board only reads registers.
//!
//! A capture is refused, and counted, when it cannot be an edge that just
//! happened: the same capture value handed in twice (a register read again
//! without a new edge), an age beyond [`MAX_EDGE_AGE_US`] (a stale register,
//! or a capture read through a 16-bit view of the timer, which puts every
//! edge within 65 ms of a multiple of 2¹⁶ µs), an edge before boot, or one
//! not later than the previous edge.

/// What the wheel timer's interrupt read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawCapture {
    /// The running 32-bit count when the interrupt read it, µs.
    pub counter: u32,
    /// The count latched at the edge, µs.
    pub capture: u32,
    /// The system clock when the interrupt read the counter, µs since boot.
    pub now_us: u64,
    /// The hardware latched a newer edge over an unread one (overcapture):
    /// one edge or more was lost before this capture.
    pub overcapture: bool,
}

/// Oldest edge accepted, µs: the handler runs within microseconds of the
/// edge; a whole second can only mean a register that was never refreshed.
pub const MAX_EDGE_AGE_US: u32 = 1_000_000;

/// Why a capture gave no edge time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refused {
    /// The same capture value as the previous one: read twice.
    Repeated,
    /// Older than [`MAX_EDGE_AGE_US`].
    Stale,
    /// Would lie before boot.
    BeforeBoot,
    /// Not later than the previous edge.
    OutOfOrder,
}

/// Counts of what [`EdgeClock`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CaptureStats {
    /// Edge times handed out.
    pub edges: u32,
    /// Captures refused, whatever the reason.
    pub refused: u32,
    /// Overcaptures seen: at least this many edges were lost in hardware.
    pub overcaptures: u32,
}

/// Turns raw captures into edge times, µs since boot (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct EdgeClock {
    last_capture: Option<u32>,
    last_edge_us: Option<u64>,
    stats: CaptureStats,
}

impl EdgeClock {
    /// No edge seen yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            last_capture: None,
            last_edge_us: None,
            stats: CaptureStats {
                edges: 0,
                refused: 0,
                overcaptures: 0,
            },
        }
    }

    /// The edge time of `raw`, µs since boot.
    ///
    /// # Errors
    /// [`Refused`] when the capture cannot be a new edge; it is counted in
    /// [`CaptureStats::refused`].
    pub fn edge_time_us(&mut self, raw: RawCapture) -> Result<u64, Refused> {
        if raw.overcapture {
            self.stats.overcaptures = self.stats.overcaptures.saturating_add(1);
        }
        let result = self.check(raw);
        match result {
            Ok(t_us) => {
                self.last_capture = Some(raw.capture);
                self.last_edge_us = Some(t_us);
                self.stats.edges = self.stats.edges.saturating_add(1);
            }
            Err(_) => self.stats.refused = self.stats.refused.saturating_add(1),
        }
        result
    }

    fn check(&self, raw: RawCapture) -> Result<u64, Refused> {
        if self.last_capture == Some(raw.capture) {
            return Err(Refused::Repeated);
        }
        let age_us = raw.counter.wrapping_sub(raw.capture);
        if age_us > MAX_EDGE_AGE_US {
            return Err(Refused::Stale);
        }
        let t_us = raw
            .now_us
            .checked_sub(u64::from(age_us))
            .ok_or(Refused::BeforeBoot)?;
        if self.last_edge_us.is_some_and(|last| t_us <= last) {
            return Err(Refused::OutOfOrder);
        }
        Ok(t_us)
    }

    /// Counters so far.
    #[must_use]
    pub const fn stats(&self) -> CaptureStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(counter: u32, capture: u32, now_us: u64) -> RawCapture {
        RawCapture {
            counter,
            capture,
            now_us,
            overcapture: false,
        }
    }

    #[test]
    fn age_is_exact_across_the_wrap() {
        let mut clock = EdgeClock::new();
        // Captured 16 counts before the wrap, read 16 counts after it.
        let t = clock.edge_time_us(raw(0x10, 0xFFFF_FFF0, 5_000_000));
        assert_eq!(t, Ok(5_000_000 - 0x20));
    }

    #[test]
    fn a_capture_read_twice_is_one_edge() {
        let mut clock = EdgeClock::new();
        assert_eq!(clock.edge_time_us(raw(120, 100, 1_000)), Ok(980));
        assert_eq!(
            clock.edge_time_us(raw(130, 100, 1_010)),
            Err(Refused::Repeated)
        );
        assert_eq!(clock.stats().edges, 1);
        assert_eq!(clock.stats().refused, 1);
    }

    #[test]
    fn a_16_bit_capture_against_a_32_bit_counter_is_refused() {
        let mut clock = EdgeClock::new();
        // Counter at 300 s; a capture read through a 16-bit view of it.
        let counter = 300_000_000u32;
        let capture_16 = (counter - 50) & 0xFFFF;
        assert_eq!(
            clock.edge_time_us(raw(counter, capture_16, 300_000_000)),
            Err(Refused::Stale)
        );
    }

    #[test]
    fn an_edge_exactly_the_oldest_age_is_accepted_one_more_is_stale() {
        let mut clock = EdgeClock::new();
        let now = 10_000_000;
        let at = |age: u32| raw(5_000_000 + age, 5_000_000, now);
        assert_eq!(
            clock.edge_time_us(at(MAX_EDGE_AGE_US + 1)),
            Err(Refused::Stale)
        );
        assert_eq!(
            clock.edge_time_us(at(MAX_EDGE_AGE_US)),
            Ok(now - u64::from(MAX_EDGE_AGE_US))
        );
    }

    #[test]
    fn an_edge_before_boot_or_out_of_order_is_refused() {
        let mut clock = EdgeClock::new();
        assert_eq!(
            clock.edge_time_us(raw(500, 0, 100)),
            Err(Refused::BeforeBoot)
        );
        assert_eq!(clock.edge_time_us(raw(1_000, 900, 10_000)), Ok(9_900));
        // A different capture that would put the edge earlier.
        assert_eq!(
            clock.edge_time_us(raw(1_000, 800, 9_950)),
            Err(Refused::OutOfOrder)
        );
        assert_eq!(clock.stats().refused, 2);
    }

    #[test]
    fn overcaptures_are_counted_and_the_edge_still_used() {
        let mut clock = EdgeClock::new();
        let mut r = raw(1_000, 990, 2_000);
        r.overcapture = true;
        assert_eq!(clock.edge_time_us(r), Ok(1_990));
        assert_eq!(clock.stats().overcaptures, 1);
    }
}
