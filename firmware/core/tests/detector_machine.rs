//! The detector's alert state machine on its own: hysteresis (amplitudes
//! between the off and on thresholds) and confirmation (bursts shorter and
//! longer than the confirmation), and a reference model of the switching
//! rules, driven by the detector's own per-hop estimate, that every alert
//! change must agree with.

use proptest::prelude::*;
use wobble_core::config::Config;
use wobble_core::detector::{AlertEvent, Detector, DetectorConfig, Estimate};
use wobble_core::wheel::WheelConfig;

const FS: f32 = 100.0;
const TAU: f32 = core::f32::consts::TAU;
/// The detector's ripple ceiling (`RIPPLE_CEILING` in `detector::machine`):
/// below this many times `amp_on_deg`, an oscillation on a wheel harmonic
/// must grow by `harmonic_growth_ratio` to count.
const RIPPLE_CEILING: f32 = 2.0;
/// The envelope trend's floor (`TREND_FLOOR` in `detector::machine`): smaller
/// amplitudes count as this many times `amp_on_deg`.
const TREND_FLOOR: f32 = 0.25;

fn detector(cfg: DetectorConfig) -> Detector {
    Detector::new(cfg, WheelConfig::DEFAULT.circumference_m).expect("valid config")
}

/// The switching rules as the detector's documentation states them, on the
/// estimate of each analysis: on after `confirm_hops` analyses in a row meet
/// every on-condition, off after `off_hold_s` of analyses below
/// `amp_off_deg`.
struct Model {
    cfg: DetectorConfig,
    lookback: usize,
    off_hold: usize,
    decay_span: usize,
    /// The dominant amplitude of every analysis so far.
    amps: Vec<f32>,
    /// Where the envelope trend starts in `amps`.
    trend_from: usize,
    confirm: u8,
    /// `Some(hops below the off threshold)` while the alert is on.
    alerting: Option<usize>,
    /// Longest run of on-conditions that ended without an alert.
    longest_unconfirmed: u8,
}

impl Model {
    fn new(cfg: DetectorConfig) -> Self {
        let hops = |s: f32| (s / cfg.hop_s).round() as usize;
        Self {
            cfg,
            lookback: hops(cfg.lookback_s),
            off_hold: hops(cfg.off_hold_s).max(1),
            decay_span: hops(cfg.decay_span_s),
            amps: Vec::new(),
            trend_from: 0,
            confirm: 0,
            alerting: None,
            longest_unconfirmed: 0,
        }
    }

    /// Whether the estimated frequency may raise the alert. The edge bins
    /// lie outside the band (`bin_lo_hz < band_lo_hz`, `band_hi_hz <
    /// bin_hi_hz`), so a peak on one is out of band by its frequency alone.
    fn in_band(&self, freq_hz: f32) -> bool {
        freq_hz >= self.cfg.band_lo_hz && freq_hz <= self.cfg.band_hi_hz
    }

    /// The slope (1/s) of the weighted least-squares line through the
    /// logarithms of the amplitudes since the latest analysis held off by an
    /// impulse (that one included), the one `k` hops old weighted by
    /// `(1 - hop_s / decay_trend_s)^k`; 0 without a line.
    fn trend_per_s(&self) -> f32 {
        let c = &self.cfg;
        let span = c.decay_trend_s / c.hop_s;
        let forget = if span > 1.0 { 1.0 - 1.0 / span } else { 0.0 };
        let (mut w, mut k, mut kk, mut y, mut ky) = (0.0_f64, 0.0, 0.0, 0.0, 0.0);
        for (age, a) in self.amps[self.trend_from..].iter().rev().enumerate() {
            let wt = f64::from(forget).powi(age as i32);
            let ln = f64::from(a.max(TREND_FLOOR * c.amp_on_deg)).ln();
            let age = age as f64;
            w += wt;
            k += wt * age;
            kk += wt * age * age;
            y += wt * ln;
            ky += wt * age * ln;
        }
        let sxx = w * kk - k * k;
        if sxx <= 1e-9 * w * kk {
            return 0.0;
        }
        (-(w * ky - k * y) / sxx / f64::from(c.hop_s)) as f32
    }

    /// Amplitude now over amplitude `lookback_s` ago, 1 until known.
    fn growth_ratio(&self, amp_deg: f32) -> f32 {
        match self.amps.len().checked_sub(self.lookback) {
            Some(i) => amp_deg / self.amps[i].max(1e-6),
            None => 1.0,
        }
    }

    /// Whether `freq_hz` lies within `harmonic_tol_hz` of a multiple of the
    /// wheel's rotation frequency at `speed_mps` (never without a speed).
    fn at_wheel_harmonic(&self, freq_hz: f32, speed_mps: Option<f32>) -> bool {
        let Some(f_wheel) = speed_mps.map(|v| v / WheelConfig::DEFAULT.circumference_m) else {
            return false;
        };
        let highest = (freq_hz / f_wheel) as u32 + 1;
        (1..=highest).any(|n| (freq_hz - n as f32 * f_wheel).abs() <= self.cfg.harmonic_tol_hz)
    }

    /// What the analysis with estimate `e` must switch.
    fn analyse(&mut self, e: &Estimate, speed_mps: Option<f32>) -> Option<bool> {
        let c = &self.cfg;
        assert!(c.bin_lo_hz < c.band_lo_hz && c.band_hi_hz < c.bin_hi_hz);
        let has_lookback = self.amps.len() >= self.lookback;
        if e.impulse_holdoff {
            self.trend_from = self.amps.len();
        }
        self.amps.push(e.amp_deg);
        let trend = self.trend_per_s();
        assert!(
            (e.trend_per_s - trend).abs() <= 1e-3 * (1.0 + trend.abs()),
            "trend {} against {trend}",
            e.trend_per_s
        );
        if let Some(below) = self.alerting {
            let below = if e.amp_deg < c.amp_off_deg {
                below + 1
            } else {
                0
            };
            if below >= self.off_hold {
                self.alerting = None;
                return Some(false);
            }
            self.alerting = Some(below);
            return None;
        }
        let min_ratio = if e.at_wheel_harmonic && e.amp_deg < RIPPLE_CEILING * c.amp_on_deg {
            c.harmonic_growth_ratio
        } else {
            c.min_growth_ratio
        };
        // The largest amplitude of the decay span, this analysis included.
        let span_peak = self.amps[self.amps.len().saturating_sub(self.decay_span)..]
            .iter()
            .fold(0.0_f32, |m, &a| m.max(a));
        let on = has_lookback
            && e.amp_deg >= c.decay_span_ratio * span_peak
            && e.trend_per_s >= c.decay_trend_per_s
            && e.amp_deg >= c.amp_on_deg
            && self.in_band(e.freq_hz)
            && !e.impulse_holdoff
            && e.growth_ratio >= min_ratio
            && speed_mps.is_none_or(|v| v >= c.min_speed_mps);
        if !on {
            self.longest_unconfirmed = self.longest_unconfirmed.max(self.confirm);
            self.confirm = 0;
            return None;
        }
        self.confirm += 1;
        if self.confirm < c.confirm_hops {
            return None;
        }
        self.confirm = 0;
        self.alerting = Some(0);
        Some(true)
    }
}

/// Replays `signal` (degrees at 100 Hz) through the detector and the model
/// together; returns the model and the alert changes (sample index, on).
fn replay(
    cfg: DetectorConfig,
    speed_mps: Option<f32>,
    signal: &[f32],
) -> Result<(Model, Vec<(usize, bool)>), TestCaseError> {
    let mut d = detector(cfg);
    let mut model = Model::new(cfg);
    let mut changes = Vec::new();
    for (i, &x) in signal.iter().enumerate() {
        let event = d
            .push(x, speed_mps)
            .map(|e| matches!(e, AlertEvent::On { .. }));
        let expected = if d.analysed() {
            let e = d.estimate();
            prop_assert_eq!(e.in_band, model.in_band(e.freq_hz), "sample {}: {:?}", i, e);
            prop_assert_eq!(
                e.at_wheel_harmonic,
                model.at_wheel_harmonic(e.freq_hz, speed_mps),
                "sample {}: {:?}",
                i,
                e
            );
            let growth = model.growth_ratio(e.amp_deg);
            prop_assert!(
                (e.growth_ratio - growth).abs() <= 1e-5 * growth.abs(),
                "sample {}: growth ratio {} over the look-back, {:?}",
                i,
                growth,
                e
            );
            model.analyse(&e, speed_mps)
        } else {
            None
        };
        prop_assert_eq!(event, expected, "sample {}: {:?}", i, d.estimate());
        prop_assert_eq!(d.alert_active(), model.alerting.is_some());
        if let Some(on) = event {
            changes.push((i, on));
        }
    }
    Ok((model, changes))
}

/// `amp` at `f` with a raised-cosine ramp of `ramp_s` at both ends, held for
/// `hold_s`, starting at `start_s`, inside `total_s` of a light noise floor.
fn burst(f: f32, amp: f32, start_s: f32, ramp_s: f32, hold_s: f32, total_s: f32) -> Vec<f32> {
    (0..(total_s * FS) as usize)
        .map(|i| {
            let t = i as f32 / FS;
            let u = t - start_s;
            let gain = if u < 0.0 || u > 2.0 * ramp_s + hold_s {
                0.0
            } else if u < ramp_s {
                0.5 - 0.5 * (core::f32::consts::PI * u / ramp_s).cos()
            } else if u > ramp_s + hold_s {
                0.5 + 0.5 * (core::f32::consts::PI * (u - ramp_s - hold_s) / ramp_s).cos()
            } else {
                1.0
            };
            gain * amp * (TAU * f * t).sin() + 0.01 * (TAU * 13.7 * t).sin()
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Once on, the alert stays on while the oscillation sits between the
    /// off and on thresholds, and goes off only after it drops below the
    /// off threshold.
    #[test]
    fn between_the_thresholds_an_alert_stays_on(
        f in 6.2f32..8.8, level in 0.0f32..1.0, hold_s in 2.0f32..6.0,
    ) {
        let cfg = Config::default().detector;
        // 20 % inside either threshold: far beyond the estimate's 3 %.
        let (lo, hi) = (1.2 * cfg.amp_off_deg, 0.8 * cfg.amp_on_deg);
        let level_deg = lo + level * (hi - lo);
        let grown = |t: f32| (0.02 * (2.0 * t).exp()).min(1.0);
        let t_drop = 4.0;
        let t_end = t_drop + hold_s;
        let signal: Vec<f32> = (0..((t_end + 3.0) * FS) as usize)
            .map(|i| {
                let t = i as f32 / FS;
                let env = if t < t_drop { grown(t) } else if t < t_end { level_deg } else { 0.0 };
                env * (TAU * f * t).sin()
            })
            .collect();
        let (_, changes) = replay(cfg, None, &signal)?;
        prop_assert_eq!(changes.len(), 2, "{:?}", changes);
        prop_assert!(changes[0].1 && (changes[0].0 as f32) < t_drop * FS);
        let off_s = changes[1].0 as f32 / FS;
        prop_assert!(!changes[1].1 && off_s > t_end, "off at {off_s} s, level held to {t_end} s");
        prop_assert!(off_s < t_end + cfg.off_hold_s + cfg.window_s + 0.1, "off at {off_s} s");
    }

    /// From quiet, a sustained oscillation between the thresholds never
    /// raises the alert, however long it lasts.
    #[test]
    fn between_the_thresholds_a_quiet_detector_stays_quiet(f in 6.2f32..8.8, level in 0.0f32..1.0) {
        let cfg = Config::default().detector;
        let (lo, hi) = (1.2 * cfg.amp_off_deg, 0.8 * cfg.amp_on_deg);
        let level_deg = lo + level * (hi - lo);
        let signal = burst(f, level_deg, 1.0, 0.5, 10.0, 13.0);
        let (_, changes) = replay(cfg, None, &signal)?;
        prop_assert!(changes.is_empty(), "{:?}", changes);
    }

    /// Any mix of bursts, growths and decays, with or without speed, under
    /// any confirmation and hysteresis setting: every alert change is the
    /// one the switching rules give for the detector's own estimates.
    #[test]
    fn every_change_follows_the_switching_rules(
        confirm_hops in 1u8..5,
        amp_on_deg in 0.3f32..0.7,
        off_ratio in 0.3f32..0.9,
        off_hold_s in 0.05f32..0.6,
        speed in prop::option::of(0.5f32..9.0),
        bursts in proptest::collection::vec((5.5f32..9.5, 0.1f32..2.0, 0.02f32..0.4, 0.0f32..1.0), 1..5),
    ) {
        let cfg = DetectorConfig {
            confirm_hops,
            amp_on_deg,
            amp_off_deg: off_ratio * amp_on_deg,
            off_hold_s,
            ..Config::default().detector
        };
        let mut signal = vec![0.0f32; 1200];
        for (k, &(f, amp, ramp_s, hold_s)) in bursts.iter().enumerate() {
            let b = burst(f, amp, 1.0 + 2.5 * k as f32, ramp_s, hold_s, 12.0);
            signal.iter_mut().zip(b).for_each(|(s, x)| *s += x);
        }
        replay(cfg, speed, &signal)?;
    }
}

/// Bursts swept from shorter to longer than the confirmation: the sweep
/// reaches both cases (a run of on-conditions one analysis short of the
/// confirmation that raises nothing, and one that alerts), and the
/// detector agrees with the rules in each.
#[test]
fn bursts_shorter_and_longer_than_the_confirmation() {
    let cfg = DetectorConfig {
        // A lower bar to grow past, so bursts of a few hops meet every
        // on-condition; the confirmation is what decides.
        min_growth_ratio: 0.0,
        max_growth_ratio: 1e9,
        impulse_ratio: 1e9,
        ..Config::default().detector
    };
    let (mut short_quiet, mut long_alerted) = (false, false);
    // A short burst sweeps through the window: the bigger it is, the more
    // analyses see it above the on threshold.
    for step in 0..40 {
        let amp = 0.2 + 0.04 * step as f32;
        let signal = burst(7.0, amp, 1.0, 0.1, 0.0, 4.0);
        let (model, changes) = replay(cfg, None, &signal).expect("agrees with the rules");
        let alerted = changes.iter().any(|c| c.1);
        short_quiet |= !alerted && model.longest_unconfirmed + 1 == cfg.confirm_hops;
        long_alerted |= alerted;
    }
    assert!(
        short_quiet,
        "no burst ended one analysis short of the confirmation"
    );
    assert!(long_alerted, "no burst was long enough to alert");
}

/// An oscillation on a wheel harmonic, growing too slowly to count as a
/// wobble while it could still be ripple, alerts once it is above the
/// ripple ceiling, where the wheel-harmonic guard no longer applies.
#[test]
fn above_the_ripple_ceiling_a_harmonic_oscillation_alerts() {
    let cfg = DetectorConfig {
        // No canceller: the oscillation reaches the analysis as it is.
        harmonic_tau_s: 0.0,
        ..Config::default().detector
    };
    let ceiling_deg = RIPPLE_CEILING * cfg.amp_on_deg;
    let f = 7.0;
    // The wheel's 4th harmonic at 7 Hz.
    let speed = f / 4.0 * WheelConfig::DEFAULT.circumference_m;
    // Growth over the look-back between the two ratios: enough for a
    // wobble, too little for ripple.
    let rate_per_s =
        0.5 * (cfg.min_growth_ratio.max(1.0) * cfg.harmonic_growth_ratio).ln() / cfg.lookback_s;
    let amp = |t: f32| (0.5 * cfg.amp_on_deg * (rate_per_s * t).exp()).min(1.5 * ceiling_deg);
    let signal: Vec<f32> = (0..3000)
        .map(|i| {
            let t = i as f32 / FS;
            amp(t) * (TAU * f * t).sin()
        })
        .collect();
    let (_, changes) = replay(cfg, Some(speed), &signal).expect("agrees with the rules");
    let (on_at, _) = changes.first().copied().expect("an alert");
    let envelope = amp(on_at as f32 / FS);
    assert!(
        envelope > ceiling_deg && envelope < 1.2 * ceiling_deg,
        "alert at {envelope} deg, ceiling {ceiling_deg} deg"
    );
}
