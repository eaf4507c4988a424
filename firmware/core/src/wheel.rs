//! Wheel speed and distance from hall-sensor edge timestamps.
//!
//! The disc has 50 holes: at 4-10 m/s that is 90-230 edges per second, too
//! many to count per 100 Hz frame (an edge count per 10 ms quantises speed to
//! one hole pitch per 10 ms, 4.4 m/s). So a timer captures the time of every
//! edge and the speed comes from the *period* of recent edges:
//!
//! ```text
//! speed = k · pitch / (t[newest] − t[newest − k]),   pitch = circumference / holes
//! ```
//!
//! with `k` the configured window (default one revolution, 50 intervals),
//! shortened so that the span stays within `max_window_us`. A whole revolution
//! starts and ends on the same hole, so it cancels the spacing errors of the
//! holes and any once-per-revolution error (disc eccentricity), which would
//! otherwise put ripple at the wheel rate and its harmonics, inside the
//! 6-9 Hz wobble band at 4 m/s.
//!
//! The mean over a revolution lags: it is the speed half a revolution ago
//! (0.27 s at 4 m/s). The revolution before it is just as exact, so the
//! difference of the two means is the acceleration, and the estimate is
//! extrapolated from the middle of the last revolution to its newest edge.
//! Under constant acceleration that is exact; at constant speed it changes
//! nothing.
//!
//! While no new edge has come for clearly longer than the current period, the
//! wheel is slowing down: the speed is then also bounded by `1.25 pitch / age`,
//! so it decays smoothly when braking to a stop instead of holding its last
//! value.
//! After `timeout_us` without an edge the wheel is stopped, speed 0.
//!
//! Edge rejection: an edge sooner than `min_edge_interval_us` after the
//! previous one is contact bounce. An edge sooner than `glitch_fraction` of
//! the median of the last three intervals is a glitch: a wheel cannot halve
//! its period between two holes (that is hundreds of m/s²), while accelerating
//! from rest the intervals shrink by less than that once three are known. A
//! single spurious edge therefore never changes the pulse count: if it falls
//! early in the period it is rejected, if late the real edge after it is.
//!
//! The pulse count is exact: distance = pulses × pitch.

use core::fmt;

/// Most intervals a speed window can span.
pub const MAX_WINDOW_EDGES: u16 = 63;

/// Edge timestamps kept: two windows and the first edge of the older one.
const RING: usize = 2 * MAX_WINDOW_EDGES as usize + 1;

/// How much later than one pitch at the estimated speed an edge must be
/// before the estimate is bounded by `pitch / age`.
const OVERDUE_MARGIN: f32 = 0.25;

/// Wheel sensor configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WheelConfig {
    /// Rolling circumference of the tyre, metres. Default 2.180 m: a 28"
    /// trekking tyre, ETRTO 37-622.
    pub circumference_m: f32,
    /// Edges per revolution (holes in the disc). Default 50.
    pub holes: u16,
    /// No edge for this long: the wheel is stopped and its speed zero.
    /// Default 500 ms (below 0.09 m/s with the default wheel).
    pub timeout_us: u32,
    /// An edge sooner than this after the previous one is contact bounce.
    /// Default 500 µs (above 87 m/s with the default wheel).
    pub min_edge_interval_us: u32,
    /// An edge sooner than this fraction of the median of the last three
    /// intervals is a glitch. Default 0.5; 0 disables the check.
    pub glitch_fraction: f32,
    /// Intervals averaged for the speed, at most [`MAX_WINDOW_EDGES`].
    /// Default 50: one revolution of the default disc.
    pub window_edges: u16,
    /// Longest time span averaged: at low speed the window shrinks to keep
    /// the lag bounded. Default 1 s.
    pub max_window_us: u32,
}

impl WheelConfig {
    /// The defaults (see each field).
    pub const DEFAULT: Self = Self {
        circumference_m: 2.180,
        holes: 50,
        timeout_us: 500_000,
        min_edge_interval_us: 500,
        glitch_fraction: 0.5,
        window_edges: 50,
        max_window_us: 1_000_000,
    };

    /// Distance per edge, metres.
    #[must_use]
    pub fn pitch_m(&self) -> f32 {
        self.circumference_m / f32::from(self.holes)
    }
}

impl Default for WheelConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A [`WheelConfig`] that cannot work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum WheelConfigError {
    /// `circumference_m` is not a positive finite number.
    Circumference,
    /// `holes` is zero.
    NoHoles,
    /// `window_edges` is zero or more than [`MAX_WINDOW_EDGES`].
    Window,
    /// `glitch_fraction` is outside 0..1.
    GlitchFraction,
    /// `timeout_us` is not longer than `min_edge_interval_us`.
    Timeout,
}

impl fmt::Display for WheelConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Circumference => "wheel circumference must be a positive number of metres",
            Self::NoHoles => "the wheel disc needs at least one hole",
            Self::Window => "wheel speed window must be 1 to 63 edges",
            Self::GlitchFraction => "wheel glitch fraction must be between 0 and 1",
            Self::Timeout => "wheel timeout must be longer than the minimum edge interval",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for WheelConfigError {}

/// What became of one edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Edge {
    /// Counted.
    Accepted,
    /// Too soon after the previous edge: contact bounce.
    Bounce,
    /// Far too short an interval for a rolling wheel: a glitch.
    Glitch,
    /// Not later than the previous edge (timer misuse): ignored.
    OutOfOrder,
}

/// The wheel's state at one instant, for a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WheelSample {
    /// Accepted edges since boot.
    pub pulses: u32,
    /// Time of the last accepted edge, µs since boot.
    pub last_edge_us: Option<u64>,
    /// Speed, m/s.
    pub speed_mps: f32,
    /// No edge within the timeout: the speed is zero.
    pub stopped: bool,
}

/// Wheel-speed estimator (see the module docs).
#[derive(Clone, Debug)]
pub struct WheelSpeed {
    config: WheelConfig,
    pitch_m: f32,
    /// Accepted edge times; `ring[(head + RING - i) % RING]` is the i-th newest.
    ring: [u64; RING],
    head: usize,
    /// Valid entries in `ring` since the last stop.
    len: usize,
    pulses: u32,
    rejected: u32,
}

impl WheelSpeed {
    /// An estimator for `config`, or why the configuration cannot work.
    pub fn try_new(config: WheelConfig) -> Result<Self, WheelConfigError> {
        if !(config.circumference_m.is_finite() && config.circumference_m > 0.0) {
            return Err(WheelConfigError::Circumference);
        }
        if config.holes == 0 {
            return Err(WheelConfigError::NoHoles);
        }
        if config.window_edges == 0 || config.window_edges > MAX_WINDOW_EDGES {
            return Err(WheelConfigError::Window);
        }
        if !(0.0..1.0).contains(&config.glitch_fraction) {
            return Err(WheelConfigError::GlitchFraction);
        }
        if config.timeout_us <= config.min_edge_interval_us {
            return Err(WheelConfigError::Timeout);
        }
        Ok(Self {
            config,
            pitch_m: config.pitch_m(),
            ring: [0; RING],
            head: 0,
            len: 0,
            pulses: 0,
            rejected: 0,
        })
    }

    /// The configuration in force.
    #[must_use]
    pub const fn config(&self) -> &WheelConfig {
        &self.config
    }

    /// Accepted edges since boot.
    #[must_use]
    pub const fn pulses(&self) -> u32 {
        self.pulses
    }

    /// Edges rejected since boot (bounce, glitch, out of order).
    #[must_use]
    pub const fn rejected(&self) -> u32 {
        self.rejected
    }

    /// Distance since boot, metres.
    #[must_use]
    pub fn distance_m(&self) -> f64 {
        f64::from(self.pulses) * f64::from(self.config.circumference_m)
            / f64::from(self.config.holes)
    }

    /// The `i`-th newest accepted edge time (`i < len`).
    fn edge(&self, i: usize) -> u64 {
        self.ring[(self.head + RING - i) % RING]
    }

    /// Registers an edge captured at `t_us`.
    pub fn on_edge(&mut self, t_us: u64) -> Edge {
        let verdict = self.classify(t_us);
        if verdict == Edge::Accepted {
            self.head = (self.head + 1) % RING;
            self.ring[self.head] = t_us;
            self.len = (self.len + 1).min(RING);
            self.pulses = self.pulses.wrapping_add(1);
        } else {
            self.rejected = self.rejected.saturating_add(1);
        }
        verdict
    }

    fn classify(&mut self, t_us: u64) -> Edge {
        if self.len == 0 {
            return Edge::Accepted;
        }
        let newest = self.edge(0);
        if t_us <= newest {
            return Edge::OutOfOrder;
        }
        let dt = t_us - newest;
        if dt > u64::from(self.config.timeout_us) {
            // The wheel stopped in between: start a new history.
            self.len = 0;
            return Edge::Accepted;
        }
        if dt < u64::from(self.config.min_edge_interval_us) {
            return Edge::Bounce;
        }
        if self.len >= 4 {
            let [a, b, c] = [0, 1, 2].map(|i| self.edge(i) - self.edge(i + 1));
            let median = a.max(b).min(a.min(b).max(c));
            if (dt as f32) < self.config.glitch_fraction * median as f32 {
                return Edge::Glitch;
            }
        }
        Edge::Accepted
    }

    /// Speed at `now_us`, m/s.
    #[must_use]
    pub fn speed_mps(&self, now_us: u64) -> f32 {
        if self.len < 2 || self.is_stopped(now_us) {
            return 0.0;
        }
        let newest = self.edge(0);
        let max_span = u64::from(self.config.max_window_us);
        let mut k = (self.len - 1).min(usize::from(self.config.window_edges));
        while k > 1 && newest - self.edge(k) > max_span {
            k -= 1;
        }
        let distance = k as f32 * self.pitch_m * 1e6;
        let span1 = (newest - self.edge(k)) as f32;
        let mean1 = distance / span1;
        let mut speed = mean1;
        if self.len > 2 * k {
            // The window before has the same holes, so its mean is as exact:
            // the change between the two is the acceleration, free of the
            // disc's errors. A window's mean speed is the speed at its middle
            // under constant acceleration; extrapolate to the newest edge.
            let span0 = (self.edge(k) - self.edge(2 * k)) as f32;
            let mean0 = distance / span0;
            let accel_per_us = (mean1 - mean0) / (0.5 * (span0 + span1));
            speed = mean1 + accel_per_us * 0.5 * span1;
        }
        // Overdue edge: the wheel has slowed to less than one pitch per age.
        // Hole spacing varies by a few percent (cutting tolerance, disc
        // eccentricity), so an edge counts as overdue only OVERDUE_MARGIN
        // after its expected time; the bound joins the estimate continuously.
        let age_us = now_us.saturating_sub(newest).max(1);
        speed
            .min(self.pitch_m * (1.0 + OVERDUE_MARGIN) * 1e6 / age_us as f32)
            .max(0.0)
    }

    /// No accepted edge within the timeout before `now_us`.
    #[must_use]
    pub fn is_stopped(&self, now_us: u64) -> bool {
        self.len == 0 || now_us.saturating_sub(self.edge(0)) > u64::from(self.config.timeout_us)
    }

    /// The state at `now_us`, for a frame.
    #[must_use]
    pub fn sample(&self, now_us: u64) -> WheelSample {
        WheelSample {
            pulses: self.pulses,
            last_edge_us: (self.pulses > 0).then(|| self.ring[self.head]),
            speed_mps: self.speed_mps(now_us),
            stopped: self.is_stopped(now_us),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimate at `now_us` is `expected` to 0.1 %.
    fn assert_speed(w: &WheelSpeed, now_us: u64, expected: f32) {
        let speed = w.speed_mps(now_us);
        assert!(
            (speed - expected).abs() < 1e-3 * expected,
            "{speed} against {expected}"
        );
    }

    #[test]
    fn defaults_are_valid_and_match_the_bike() {
        let w = WheelSpeed::try_new(WheelConfig::default()).unwrap();
        assert!((w.config().pitch_m() - 0.0436).abs() < 1e-6);
    }

    #[test]
    fn bad_configurations_are_refused() {
        let bad = |c| WheelSpeed::try_new(c).unwrap_err();
        let d = WheelConfig::DEFAULT;
        assert_eq!(
            bad(WheelConfig {
                circumference_m: 0.0,
                ..d
            }),
            WheelConfigError::Circumference
        );
        assert_eq!(
            bad(WheelConfig { holes: 0, ..d }),
            WheelConfigError::NoHoles
        );
        assert_eq!(
            bad(WheelConfig {
                window_edges: 64,
                ..d
            }),
            WheelConfigError::Window
        );
        assert_eq!(
            bad(WheelConfig {
                glitch_fraction: 1.0,
                ..d
            }),
            WheelConfigError::GlitchFraction
        );
        assert_eq!(
            bad(WheelConfig {
                timeout_us: 400,
                ..d
            }),
            WheelConfigError::Timeout
        );
    }

    #[test]
    fn the_widest_window_keeps_both_of_its_windows() {
        // Constant acceleration from 3 m/s at 2 m/s^2: the mean over one
        // 63-edge window lags the speed at its newest edge by about 10 %;
        // with the window before it the estimate extrapolates to the edge.
        let config = WheelConfig {
            window_edges: MAX_WINDOW_EDGES,
            max_window_us: 5_000_000,
            ..WheelConfig::DEFAULT
        };
        let mut w = WheelSpeed::try_new(config).unwrap();
        let (v0, a, pitch) = (3.0f64, 2.0f64, f64::from(config.pitch_m()));
        let t_s = |n: u32| (-v0 + (v0 * v0 + 2.0 * a * f64::from(n) * pitch).sqrt()) / a;
        for n in 0..400 {
            assert_eq!(w.on_edge((t_s(n) * 1e6) as u64), Edge::Accepted);
        }
        let newest = t_s(399);
        let truth = v0 + a * newest;
        let speed = f64::from(w.speed_mps((newest * 1e6) as u64));
        assert!(
            (speed - truth).abs() < 0.005 * truth,
            "{speed} against {truth}"
        );
    }

    #[test]
    fn a_wheel_turning_one_hole_per_timeout_still_has_a_speed() {
        let d = WheelConfig::DEFAULT;
        let mut w = WheelSpeed::try_new(d).unwrap();
        let step = u64::from(d.timeout_us);
        for i in 0..10 {
            assert_eq!(w.on_edge(1_000 + i * step), Edge::Accepted);
        }
        let newest = 1_000 + 9 * step;
        assert_speed(&w, newest, d.pitch_m() * 1e6 / step as f32);
        // Stopped only once the timeout has passed.
        assert!(!w.is_stopped(newest + step));
        assert!(w.is_stopped(newest + step + 1));
    }

    #[test]
    fn the_thresholds_themselves_are_not_bounce_nor_glitch() {
        let d = WheelConfig::DEFAULT;
        // Exactly the minimum interval: an edge, not bounce.
        let mut w = WheelSpeed::try_new(d).unwrap();
        w.on_edge(1_000);
        let at_min = 1_000 + u64::from(d.min_edge_interval_us);
        assert_eq!(w.on_edge(at_min), Edge::Accepted);
        // Exactly the glitch fraction of the median interval: an edge.
        let mut w = WheelSpeed::try_new(d).unwrap();
        for i in 0..5 {
            w.on_edge(10_000 * i);
        }
        assert_eq!(w.on_edge(40_000 + 5_000), Edge::Accepted);
        let mut w = WheelSpeed::try_new(d).unwrap();
        for i in 0..5 {
            w.on_edge(10_000 * i);
        }
        assert_eq!(w.on_edge(40_000 + 4_999), Edge::Glitch);
    }

    #[test]
    fn two_edges_give_a_speed() {
        let d = WheelConfig::DEFAULT;
        let mut w = WheelSpeed::try_new(d).unwrap();
        w.on_edge(100_000);
        w.on_edge(110_000);
        assert_speed(&w, 110_000, d.pitch_m() * 1e6 / 10_000.0);
    }

    #[test]
    fn at_low_speed_the_window_shrinks_to_its_time_span() {
        // 20 edges 100 ms apart, then 40 edges 50 ms apart: a 50-edge
        // window would reach back into the slow part (17 % low); one of
        // at most 1 s holds only the last 20 intervals.
        let d = WheelConfig::DEFAULT;
        let mut w = WheelSpeed::try_new(d).unwrap();
        let mut t = 0;
        for i in 0..60 {
            t += if i < 20 { 100_000 } else { 50_000 };
            assert_eq!(w.on_edge(t), Edge::Accepted);
        }
        assert_speed(&w, t, d.pitch_m() * 1e6 / 50_000.0);
    }

    #[test]
    fn one_interval_longer_than_the_window_span_still_gives_its_speed() {
        // A timeout beyond the window's span: a single 1.5 s interval is
        // longer than the window may reach, yet it is the one measurement.
        let config = WheelConfig {
            timeout_us: 3_000_000,
            ..WheelConfig::DEFAULT
        };
        let mut w = WheelSpeed::try_new(config).unwrap();
        for i in 0..4 {
            w.on_edge(1_000 + i * 1_500_000);
        }
        let newest = 1_000 + 3 * 1_500_000;
        assert_speed(&w, newest, config.pitch_m() * 1e6 / 1_500_000.0);
    }

    #[test]
    fn an_overdue_edge_bounds_the_speed_by_one_pitch_per_age() {
        // 20 ms per hole, then the edges stop: once an edge is a quarter
        // of an interval late, the speed is at most 1.25 pitches per age.
        let d = WheelConfig::DEFAULT;
        let mut w = WheelSpeed::try_new(d).unwrap();
        for i in 0..60 {
            w.on_edge(i * 20_000);
        }
        let newest = 59 * 20_000;
        assert_speed(&w, newest + 20_000, d.pitch_m() * 1e6 / 20_000.0);
        for age in [40_000u64, 100_000, 300_000] {
            assert_speed(&w, newest + age, d.pitch_m() * 1.25e6 / age as f32);
        }
    }

    #[test]
    fn every_configuration_error_says_what_is_wrong() {
        use std::string::ToString;
        let all = [
            WheelConfigError::Circumference,
            WheelConfigError::NoHoles,
            WheelConfigError::Window,
            WheelConfigError::GlitchFraction,
            WheelConfigError::Timeout,
        ];
        let texts: std::vec::Vec<_> = all.iter().map(ToString::to_string).collect();
        for (error, text) in all.iter().zip(&texts) {
            assert!(
                text.starts_with("wheel") || text.contains("wheel"),
                "{error:?}: {text}"
            );
        }
        let mut unique = texts.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), all.len(), "{texts:?}");
        assert!(
            texts[2].contains(&MAX_WINDOW_EDGES.to_string()),
            "{}",
            texts[2]
        );
    }

    #[test]
    fn single_edge_gives_no_speed_yet() {
        let mut w = WheelSpeed::try_new(WheelConfig::default()).unwrap();
        assert!(w.sample(0).stopped);
        assert_eq!(w.sample(0).last_edge_us, None);
        w.on_edge(1000);
        let s = w.sample(2000);
        assert_eq!(
            (s.pulses, s.last_edge_us, s.stopped),
            (1, Some(1000), false)
        );
        assert_eq!(s.speed_mps, 0.0);
    }

    #[test]
    fn out_of_order_edges_are_ignored() {
        let mut w = WheelSpeed::try_new(WheelConfig::default()).unwrap();
        w.on_edge(10_000);
        assert_eq!(w.on_edge(10_000), Edge::OutOfOrder);
        assert_eq!(w.on_edge(5_000), Edge::OutOfOrder);
        assert_eq!(w.pulses(), 1);
        assert_eq!(w.rejected(), 2);
    }
}
