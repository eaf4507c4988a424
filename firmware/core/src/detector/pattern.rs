//! What the rider hears and sees: a buzzer/LED pattern driven by the alert.
//!
//! The pattern is a pure function of the time since the alert switched on, so
//! it is tested on a mock clock and the board only has to call
//! [`AlertPattern::update`] at the times [`AlertPattern::next_change_us`]
//! names (or simply every tick).

/// The outputs the board drives. Implemented by the board support (GPIO, PWM
/// for the buzzer); the core never touches hardware.
pub trait AlertOutput {
    /// Switches the buzzer.
    fn set_buzzer(&mut self, on: bool);
    /// Switches the alert LED.
    fn set_led(&mut self, on: bool);
}

/// Timing of the alert pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatternConfig {
    /// Buzzer on-time of one beep, µs.
    pub beep_on_us: u32,
    /// Silence between two beeps, µs.
    pub beep_off_us: u32,
    /// The pattern runs at least this long after the alert switched on, even
    /// if the alert switches off sooner: a short alert is still noticed.
    pub min_active_us: u32,
}

impl PatternConfig {
    /// 5 beeps per second (80 ms on, 120 ms off), a fast and unmistakable
    /// rhythm, for at least 1 s.
    pub const DEFAULT: Self = Self {
        beep_on_us: 80_000,
        beep_off_us: 120_000,
        min_active_us: 1_000_000,
    };
}

impl Default for PatternConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Buzzer/LED pattern generator.
///
/// While active, the LED is lit steadily and the buzzer beeps, starting with a
/// beep at the instant the alert switches on. Times are µs since boot, the
/// same clock as the card log's records.
#[derive(Clone, Copy, Debug)]
pub struct AlertPattern {
    cfg: PatternConfig,
    alert: bool,
    /// When the current (or last) alert switched on.
    on_since_us: Option<u64>,
    /// What the outputs were last set to (`None` before the first update).
    driven: Option<(bool, bool)>,
}

impl AlertPattern {
    /// A silent pattern generator.
    #[must_use]
    pub const fn new(cfg: PatternConfig) -> Self {
        Self {
            cfg,
            alert: false,
            on_since_us: None,
            driven: None,
        }
    }

    /// Tells the generator that the alert switched on or off at `now_us`.
    /// Repeating the current state changes nothing.
    pub fn set_alert(&mut self, now_us: u64, on: bool) {
        if on && !self.alert && !self.active(now_us) {
            self.on_since_us = Some(now_us);
        }
        self.alert = on;
    }

    fn active(&self, now_us: u64) -> bool {
        match self.on_since_us {
            None => false,
            Some(t0) => self.alert || now_us.saturating_sub(t0) < u64::from(self.cfg.min_active_us),
        }
    }

    /// `(buzzer, led)` at `now_us`.
    #[must_use]
    pub fn outputs(&self, now_us: u64) -> (bool, bool) {
        match self.on_since_us {
            Some(t0) if self.active(now_us) => {
                let period = u64::from(self.cfg.beep_on_us) + u64::from(self.cfg.beep_off_us);
                let phase = now_us.saturating_sub(t0) % period.max(1);
                (phase < u64::from(self.cfg.beep_on_us), true)
            }
            _ => (false, false),
        }
    }

    /// Drives `out` to the pattern's state at `now_us`, touching an output
    /// only when its state changes.
    pub fn update(&mut self, now_us: u64, out: &mut impl AlertOutput) {
        let (buzzer, led) = self.outputs(now_us);
        let (old_buzzer, old_led) = match self.driven {
            Some(d) => (Some(d.0), Some(d.1)),
            None => (None, None),
        };
        if old_buzzer != Some(buzzer) {
            out.set_buzzer(buzzer);
        }
        if old_led != Some(led) {
            out.set_led(led);
        }
        self.driven = Some((buzzer, led));
    }

    /// The next instant after `now_us` at which the outputs may change, if
    /// the alert input stays as it is; `None` when idle.
    #[must_use]
    pub fn next_change_us(&self, now_us: u64) -> Option<u64> {
        let t0 = self.on_since_us?;
        if !self.active(now_us) {
            return None;
        }
        let on = u64::from(self.cfg.beep_on_us);
        let period = on + u64::from(self.cfg.beep_off_us);
        let since = now_us.saturating_sub(t0);
        let phase = since % period.max(1);
        let edge = if phase < on {
            now_us - phase + on
        } else {
            now_us - phase + period
        };
        if self.alert {
            Some(edge)
        } else {
            Some(edge.min(t0 + u64::from(self.cfg.min_active_us)))
        }
    }
}

impl Default for AlertPattern {
    fn default() -> Self {
        Self::new(PatternConfig::DEFAULT)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Records every output change with the mock clock's time.
    #[derive(Default)]
    struct Mock {
        now_us: u64,
        log: Vec<(u64, &'static str, bool)>,
    }

    impl AlertOutput for Mock {
        fn set_buzzer(&mut self, on: bool) {
            self.log.push((self.now_us, "buzzer", on));
        }
        fn set_led(&mut self, on: bool) {
            self.log.push((self.now_us, "led", on));
        }
    }

    /// Runs the pattern on a 1 ms mock clock from 0 to `end_us`, switching
    /// the alert at the given times.
    fn run(switches: &[(u64, bool)], end_us: u64) -> Mock {
        let mut p = AlertPattern::default();
        let mut mock = Mock::default();
        let mut t = 0;
        while t <= end_us {
            mock.now_us = t;
            for &(at, on) in switches {
                if at == t {
                    p.set_alert(t, on);
                }
            }
            p.update(t, &mut mock);
            t += 1000;
        }
        mock
    }

    #[test]
    fn beeps_five_times_a_second_while_alerting() {
        let m = run(&[(100_000, true), (1_500_000, false)], 3_000_000);
        let buzz: Vec<_> = m.log.iter().filter(|e| e.1 == "buzzer").collect();
        // Initial "off", then on/off pairs at 200 ms period from 100 ms.
        assert_eq!(buzz[0], &(0, "buzzer", false));
        assert_eq!(buzz[1], &(100_000, "buzzer", true));
        assert_eq!(buzz[2], &(180_000, "buzzer", false));
        assert_eq!(buzz[3], &(300_000, "buzzer", true));
        let ons = buzz.iter().filter(|e| e.2).count();
        assert_eq!(ons, 7, "{buzz:?}"); // 100, 300, ..., 1300 ms
        let led: Vec<_> = m.log.iter().filter(|e| e.1 == "led").collect();
        assert_eq!(
            led,
            [
                &(0, "led", false),
                &(100_000, "led", true),
                &(1_500_000, "led", false)
            ]
        );
    }

    #[test]
    fn short_alert_still_runs_min_duration() {
        let m = run(&[(0, true), (50_000, false)], 2_000_000);
        let led: Vec<_> = m.log.iter().filter(|e| e.1 == "led").collect();
        assert_eq!(led, [&(0, "led", true), &(1_000_000, "led", false)]);
        let ons = m.log.iter().filter(|e| e.1 == "buzzer" && e.2).count();
        assert_eq!(ons, 5);
    }

    #[test]
    fn next_change_names_every_edge() {
        let mut p = AlertPattern::default();
        p.set_alert(1_000, true);
        let mut t = 1_000;
        let mut edges = Vec::new();
        let mut prev = p.outputs(t);
        while let Some(next) = p.next_change_us(t) {
            if next > 3_000_000 {
                break;
            }
            // Nothing changes strictly between t and next.
            assert_eq!(p.outputs(next - 1), prev);
            prev = p.outputs(next);
            edges.push(next);
            t = next;
            if t >= 2_000_000 {
                p.set_alert(t, false);
            }
        }
        assert_eq!(edges[0], 81_000);
        assert_eq!(edges[1], 201_000);
        assert_eq!(p.outputs(t), (false, false));
    }

    #[test]
    fn idle_drives_nothing_after_first_update() {
        let m = run(&[], 500_000);
        assert_eq!(m.log, [(0, "buzzer", false), (0, "led", false)]);
    }
}
