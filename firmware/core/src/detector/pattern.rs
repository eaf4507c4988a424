//! What the rider hears and sees: a buzzer/LED pattern driven by the alert,
//! and a distinct one driven by the margin warning ([`super::MarginWarning`]).
//!
//! - **Wobble alert**: the LED lit steadily and fast beeps
//!   ([`PatternConfig`], 5 a second), for at least a second.
//! - **Approaching the wobble speed**: short groups of beeps (a double chirp
//!   every 1.5 s by default, [`ApproachConfig`]) with the LED flashing along,
//!   the LED dark between groups; at least one whole group. The wobble alert
//!   takes precedence while it runs.
//!
//! The pattern is a pure function of the time since each switched on, so
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

/// Timing of the "approaching the wobble speed" pattern: `beeps` beeps of
/// `beep_on_us` with `beep_off_us` between them, starting every `period_us`;
/// the LED is lit with each beep. `beeps = 0` keeps buzzer and LED quiet
/// (the warning is still logged).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ApproachConfig {
    /// Beeps in a group.
    pub beeps: u8,
    /// Buzzer on-time of one beep, µs.
    pub beep_on_us: u32,
    /// Silence between two beeps of a group, µs.
    pub beep_off_us: u32,
    /// Time from the start of one group to the next, µs.
    pub period_us: u32,
}

impl ApproachConfig {
    /// A double chirp (two 40 ms beeps 80 ms apart) every 1.5 s: slower and
    /// sparser than the wobble alert's 5 beeps a second, never mistaken
    /// for it.
    pub const DEFAULT: Self = Self {
        beeps: 2,
        beep_on_us: 40_000,
        beep_off_us: 80_000,
        period_us: 1_500_000,
    };

    /// Whether a group fits its period (and the period is not zero).
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let group =
            u64::from(self.beeps) * (u64::from(self.beep_on_us) + u64::from(self.beep_off_us));
        self.period_us > 0 && group <= u64::from(self.period_us)
    }

    /// `(buzzer and LED on, next edge)` at `since` µs after the warning
    /// switched on.
    fn at(&self, since: u64) -> (bool, u64) {
        let period = u64::from(self.period_us).max(1);
        let beat = u64::from(self.beep_on_us) + u64::from(self.beep_off_us);
        let start = since - since % period;
        let phase = since % period;
        let k = phase / beat.max(1);
        if beat == 0 || k >= u64::from(self.beeps) {
            return (false, start + period);
        }
        let in_beat = phase % beat;
        let beat_start = start + k * beat;
        if in_beat < u64::from(self.beep_on_us) {
            (true, beat_start + u64::from(self.beep_on_us))
        } else if k + 1 < u64::from(self.beeps) {
            (false, beat_start + beat)
        } else {
            (false, start + period)
        }
    }
}

impl Default for ApproachConfig {
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
    approach: ApproachConfig,
    alert: bool,
    /// When the current (or last) alert switched on.
    on_since_us: Option<u64>,
    /// Whether the margin warning is on, and when it (last) switched on.
    approaching: bool,
    approach_since_us: Option<u64>,
    /// What the outputs were last set to (`None` before the first update).
    driven: Option<(bool, bool)>,
}

impl AlertPattern {
    /// A silent pattern generator.
    #[must_use]
    pub const fn new(cfg: PatternConfig, approach: ApproachConfig) -> Self {
        Self {
            cfg,
            approach,
            alert: false,
            on_since_us: None,
            approaching: false,
            approach_since_us: None,
            driven: None,
        }
    }

    /// Tells the generator that the margin warning switched on or off at
    /// `now_us`. Repeating the current state changes nothing.
    pub fn set_approaching(&mut self, now_us: u64, on: bool) {
        if on && !self.approaching && !self.approach_active(now_us) {
            self.approach_since_us = Some(now_us);
        }
        self.approaching = on;
    }

    /// Whether the approach pattern runs at `now_us`: while the warning is
    /// on, and for at least one period from its start (so a short warning
    /// still sounds one whole group).
    fn approach_active(&self, now_us: u64) -> bool {
        match self.approach_since_us {
            None => false,
            Some(t0) => {
                let since = now_us.saturating_sub(t0);
                self.approaching || since < u64::from(self.approach.period_us)
            }
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
        match (self.on_since_us, self.approach_since_us) {
            (Some(t0), _) if self.active(now_us) => {
                let period = u64::from(self.cfg.beep_on_us) + u64::from(self.cfg.beep_off_us);
                let phase = now_us.saturating_sub(t0) % period.max(1);
                (phase < u64::from(self.cfg.beep_on_us), true)
            }
            (_, Some(t0)) if self.approach_active(now_us) => {
                let (on, _) = self.approach.at(now_us.saturating_sub(t0));
                (on, on)
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
        let alert = self.on_since_us.filter(|_| self.active(now_us));
        let Some(t0) = alert else {
            let t0 = self.approach_since_us?;
            if !self.approach_active(now_us) {
                return None;
            }
            let (_, edge) = self.approach.at(now_us.saturating_sub(t0));
            let edge = t0 + edge;
            let end = t0 + u64::from(self.approach.period_us);
            return Some(if self.approaching {
                edge
            } else {
                edge.min(end)
            });
        };
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
        Self::new(PatternConfig::DEFAULT, ApproachConfig::DEFAULT)
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

    /// Runs on a 1 ms mock clock with the alert and the margin warning
    /// switched at the given times: `(t_us, alert?, on)`.
    fn run_both(switches: &[(u64, bool, bool)], end_us: u64) -> Mock {
        let mut p = AlertPattern::default();
        let mut mock = Mock::default();
        let mut t = 0;
        while t <= end_us {
            mock.now_us = t;
            for &(at, alert, on) in switches {
                if at == t && alert {
                    p.set_alert(t, on);
                } else if at == t {
                    p.set_approaching(t, on);
                }
            }
            p.update(t, &mut mock);
            t += 1000;
        }
        mock
    }

    fn edges(m: &Mock, what: &str, on: bool) -> Vec<u64> {
        m.log
            .iter()
            .filter(|e| e.1 == what && e.2 == on && e.0 > 0)
            .map(|e| e.0)
            .collect()
    }

    #[test]
    fn approaching_is_a_double_chirp_every_one_and_a_half_seconds() {
        let m = run_both(
            &[(100_000, false, true), (3_300_000, false, false)],
            5_000_000,
        );
        // Beeps at 0, 120 ms of each 1.5 s group, 40 ms long; the LED with them.
        let groups = [100_000, 1_600_000, 3_100_000];
        let want_on: Vec<u64> = groups.iter().flat_map(|&g| [g, g + 120_000]).collect();
        let want_off: Vec<u64> = want_on.iter().map(|t| t + 40_000).collect();
        assert_eq!(edges(&m, "buzzer", true), want_on);
        assert_eq!(edges(&m, "buzzer", false), want_off);
        assert_eq!(edges(&m, "led", true), want_on);
        assert_eq!(edges(&m, "led", false), want_off);
    }

    #[test]
    fn a_short_warning_sounds_one_whole_group_and_the_alert_wins() {
        let m = run_both(&[(0, false, true), (10_000, false, false)], 3_000_000);
        assert_eq!(edges(&m, "buzzer", true), [120_000]);
        // The alert over a warning: steady LED and fast beeps, then the
        // warning's groups again once the alert's pattern is over.
        let m = run_both(
            &[
                (0, false, true),
                (500_000, true, true),
                (600_000, true, false),
            ],
            3_200_000,
        );
        let led_on = edges(&m, "led", true);
        // At 1.5 s the alert's pattern ends on a warning's beep: the LED
        // stays lit into it.
        assert_eq!(led_on, [120_000, 500_000, 1_620_000, 3_000_000, 3_120_000]);
        assert_eq!(edges(&m, "led", false)[..2], [40_000, 160_000]);
        assert!(edges(&m, "led", false).contains(&1_540_000));
        let fast: Vec<u64> = edges(&m, "buzzer", true)
            .into_iter()
            .filter(|t| (500_000..1_500_000).contains(t))
            .collect();
        assert_eq!(fast, [500_000, 700_000, 900_000, 1_100_000, 1_300_000]);
    }

    #[test]
    fn next_change_names_every_approach_edge() {
        let mut p = AlertPattern::default();
        p.set_approaching(1_000, true);
        let mut t = 1_000;
        let mut seen = Vec::new();
        let mut prev = p.outputs(t);
        while let Some(next) = p.next_change_us(t) {
            assert!(next > t, "{next} after {t}");
            assert_eq!(p.outputs(next - 1), prev, "{next}");
            if p.outputs(next) != prev {
                seen.push(next);
            }
            prev = p.outputs(next);
            t = next;
            if t >= 4_000_000 {
                p.set_approaching(t, false);
            }
            assert!(t < 10_000_000);
        }
        assert_eq!(seen[..4], [41_000, 121_000, 161_000, 1_501_000]);
        assert_eq!(p.outputs(t), (false, false));
    }

    #[test]
    fn approach_configs_must_fit_their_period() {
        assert!(ApproachConfig::DEFAULT.is_valid());
        let c = ApproachConfig {
            beeps: 20,
            ..ApproachConfig::DEFAULT
        };
        assert!(!c.is_valid());
        let c = ApproachConfig {
            period_us: 0,
            beeps: 0,
            ..ApproachConfig::DEFAULT
        };
        assert!(!c.is_valid());
        // No beeps: silent.
        let mut p = AlertPattern::new(
            PatternConfig::DEFAULT,
            ApproachConfig {
                beeps: 0,
                ..ApproachConfig::DEFAULT
            },
        );
        p.set_approaching(0, true);
        assert_eq!(p.outputs(0), (false, false));
    }
}
