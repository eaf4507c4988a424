//! The detector proper: per-sample ingestion, per-hop analysis and the alert
//! state machine.

use super::filter::HighPass4;
use super::goertzel::{GoertzelBank, MAX_BINS};
use super::harmonics::HarmonicCanceller;
use super::ringdown::{Kick, RingDown};
use super::trend::EnvelopeTrend;
use super::{math, ConfigError, DetectorConfig, Params, MAX_HISTORY, MAX_WINDOW};
use crate::format::{quantise_u16, Alert};

/// The alert switching, as the detector reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AlertEvent {
    /// A wobble started.
    On {
        /// Dominant frequency when the alert fired, Hz.
        freq_hz: f32,
        /// Steering oscillation amplitude (zero to peak) when it fired, degrees.
        amp_deg: f32,
    },
    /// The oscillation died down.
    Off,
}

impl AlertEvent {
    /// The card-log record for this event at local time `t_us`.
    #[must_use]
    pub fn to_record(self, t_us: u64) -> Alert {
        match self {
            Self::On { freq_hz, amp_deg } => Alert {
                t_us,
                on: true,
                freq_chz: quantise_u16(freq_hz, 100.0),
                amp_cdeg: quantise_u16(amp_deg, 100.0),
            },
            Self::Off => Alert {
                t_us,
                on: false,
                freq_chz: 0,
                amp_cdeg: 0,
            },
        }
    }
}

/// What the latest analysis saw.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate {
    /// Amplitude of the dominant bin (interpolated), degrees zero to peak.
    pub amp_deg: f32,
    /// Dominant frequency (interpolated), Hz.
    pub freq_hz: f32,
    /// Whether the peak is an interior bin inside the alert band.
    pub in_band: bool,
    /// Amplitude now over amplitude one look-back ago (1 until known).
    pub growth_ratio: f32,
    /// Whether a recent impulse is holding the alert off.
    pub impulse_holdoff: bool,
    /// Whether the dominant frequency sits on a wheel-rotation harmonic.
    pub at_wheel_harmonic: bool,
    /// The amplitude's trend over the last seconds (the slope of its
    /// logarithm, `decay_trend_s`), 1/s: negative while it decays.
    pub trend_per_s: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// No alert; `confirm` hops in a row have met the on-conditions.
    Quiet { confirm: u8 },
    /// Alert on; `below` hops in a row have been under the off-threshold.
    Alerting { below: usize },
}

/// A fixed-capacity ring of per-hop values.
#[derive(Clone, Copy, Debug)]
struct History {
    buf: [f32; MAX_HISTORY],
    /// Index of the most recent value.
    head: usize,
    /// Values pushed, saturating at `MAX_HISTORY`.
    len: usize,
}

impl History {
    const fn new() -> Self {
        Self {
            buf: [0.0; MAX_HISTORY],
            head: MAX_HISTORY - 1,
            len: 0,
        }
    }

    fn push(&mut self, v: f32) {
        self.head = (self.head + 1) % MAX_HISTORY;
        self.buf[self.head] = v;
        self.len = (self.len + 1).min(MAX_HISTORY);
    }

    /// The value `ago` hops back (0 is the latest), if pushed.
    fn get(&self, ago: usize) -> Option<f32> {
        (ago < self.len).then(|| self.buf[(self.head + MAX_HISTORY - ago) % MAX_HISTORY])
    }

    /// Largest of the values `from..from + n` hops back (missing ones are 0).
    fn max(&self, from: usize, n: usize) -> f32 {
        (from..from + n)
            .filter_map(|a| self.get(a))
            .fold(0.0, f32::max)
    }
}

/// The wobble detector. Feed it every steering sample with [`Detector::push`].
///
/// Memory: about 1.9 KiB, all inline (no allocation). Cost per sample: see
/// [`DetectorConfig::cost`]; the state machine never loops over anything
/// longer than [`MAX_WINDOW`] x [`MAX_BINS`].
#[derive(Clone, Debug)]
pub struct Detector {
    cfg: DetectorConfig,
    wheel_circumference_m: f32,
    p: Params,
    hpf: HighPass4,
    canceller: Option<HarmonicCanceller>,
    bank: GoertzelBank,
    /// Hann window of the analysis and its amplitude scale (2 / sum).
    window: [f32; MAX_WINDOW],
    amp_scale: f32,
    /// Hann window of the frequency estimate at alert time, and its scale.
    freq_window: [f32; MAX_WINDOW],
    freq_amp_scale: f32,
    /// The last `MAX_WINDOW` high-passed samples; `ring[head]` is the oldest
    /// once full.
    ring: [f32; MAX_WINDOW],
    head: usize,
    filled: usize,
    hop_phase: usize,
    /// Largest |high-passed sample| in the hop under way.
    block_max: f32,
    /// Per-hop largest |sample| (the impulse detector's envelope).
    envelope: History,
    /// Largest |high-passed sample| before the harmonic canceller, this hop
    /// and per hop (the canceller's learning gate).
    input_block_max: f32,
    input_envelope: History,
    /// Per-hop dominant amplitude, and its trend.
    amps: History,
    trend: EnvelopeTrend,
    capture_left: usize,
    holdoff_left: usize,
    impulse_peak_deg: f32,
    last_input: Option<f32>,
    estimate: Estimate,
    state: State,
    /// The ring-down of the latest kick being measured, and the measured
    /// kick not yet taken.
    ringdown: RingDown,
    kick: Option<Kick>,
}

/// A Hann window of `n` taps sampled at bin midpoints (no zero end taps, sum
/// n / 2), and the scale turning a windowed DFT magnitude into a zero-to-peak
/// amplitude (2 / sum).
fn hann(n: usize) -> ([f32; MAX_WINDOW], f32) {
    let mut window = [0.0; MAX_WINDOW];
    let mut sum = 0.0_f64;
    for (i, w) in window.iter_mut().enumerate().take(n) {
        let x = 0.5 - 0.5 * math::cos(core::f64::consts::TAU * (i as f64 + 0.5) / n as f64);
        *w = x as f32;
        sum += x;
    }
    (window, if sum > 0.0 { (2.0 / sum) as f32 } else { 0.0 })
}

/// Wheel ripple is assumed below this many times `amp_on_deg`: above it (in
/// the high-passed steering) the canceller stops learning, and above it (in
/// band) the wheel-harmonic guard stops applying, so a large oscillation that
/// happens to sit on a harmonic still alerts.
const RIPPLE_CEILING: f32 = 2.0;

/// Largest steering magnitude accepted, degrees; beyond it the sample is
/// clamped (a pot reading this far out is a fault, and clamping keeps every
/// intermediate value far from overflow).
const INPUT_LIMIT_DEG: f32 = 1000.0;

/// The envelope trend takes amplitudes below this many times `amp_on_deg` as
/// this (the noise floor: silence is flat, not a logarithm running to minus
/// infinity).
const TREND_FLOOR: f32 = 0.25;

impl Detector {
    /// A detector with configuration `cfg` on a wheel of rolling
    /// circumference `wheel_circumference_m`, which places the wheel-rotation
    /// harmonics. Pass the wheel-speed estimator's own
    /// ([`crate::wheel::WheelConfig::circumference_m`]; [`crate::config::Config::detector`]
    /// does): a second value would put every harmonic where the wheel is not.
    ///
    /// # Errors
    /// When `cfg` or the circumference is out of range (see [`ConfigError`]).
    pub fn new(cfg: DetectorConfig, wheel_circumference_m: f32) -> Result<Self, ConfigError> {
        let p = Params::new(&cfg)?;
        if !(wheel_circumference_m.is_finite() && wheel_circumference_m > 0.0) {
            return Err(ConfigError::Circumference);
        }
        let (window, amp_scale) = hann(p.window_len);
        let (freq_window, freq_amp_scale) = hann(p.freq_window_len);
        let hop_s = p.hop as f32 / cfg.sample_rate_hz;
        Ok(Self {
            cfg,
            wheel_circumference_m,
            p,
            hpf: HighPass4::new(cfg.highpass_hz, cfg.sample_rate_hz),
            canceller: (cfg.harmonic_tau_s > 0.0).then(|| {
                HarmonicCanceller::new(
                    cfg.bin_lo_hz - 1.0,
                    cfg.bin_hi_hz + 1.0,
                    cfg.harmonic_tau_s,
                    wheel_circumference_m,
                    cfg.min_speed_mps,
                    cfg.sample_rate_hz,
                )
            }),
            bank: GoertzelBank::new(
                cfg.bin_lo_hz,
                cfg.bin_spacing_hz,
                p.n_bins,
                cfg.sample_rate_hz,
            ),
            window,
            amp_scale,
            freq_window,
            freq_amp_scale,
            ring: [0.0; MAX_WINDOW],
            head: 0,
            filled: 0,
            hop_phase: 0,
            block_max: 0.0,
            envelope: History::new(),
            input_block_max: 0.0,
            input_envelope: History::new(),
            amps: History::new(),
            trend: EnvelopeTrend::new(
                cfg.decay_trend_s / hop_s,
                hop_s,
                TREND_FLOOR * cfg.amp_on_deg,
            ),
            capture_left: 0,
            holdoff_left: 0,
            impulse_peak_deg: 0.0,
            last_input: None,
            estimate: Estimate::default(),
            state: State::Quiet { confirm: 0 },
            ringdown: RingDown::new(
                cfg.sample_rate_hz,
                (cfg.bin_lo_hz, cfg.bin_hi_hz),
                cfg.highpass_hz,
            ),
            kick: None,
        })
    }

    /// The configuration in force.
    #[must_use]
    pub fn config(&self) -> &DetectorConfig {
        &self.cfg
    }

    /// The wheel circumference the harmonics are placed with, metres.
    #[must_use]
    pub fn wheel_circumference_m(&self) -> f32 {
        self.wheel_circumference_m
    }

    /// Forgets everything (as after power-up), keeping the configuration.
    pub fn reset(&mut self) {
        // `new` cannot fail: both values were validated when `self` was built.
        if let Ok(fresh) = Self::new(self.cfg, self.wheel_circumference_m) {
            *self = fresh;
        }
    }

    /// Whether the alert is on.
    #[must_use]
    pub fn alert_active(&self) -> bool {
        matches!(self.state, State::Alerting { .. })
    }

    /// The latest analysis (updated once per hop).
    #[must_use]
    pub fn estimate(&self) -> Estimate {
        self.estimate
    }

    /// The latest kick whose ring-down has been measured, once: poll it after
    /// every [`Detector::push`] (a kick is reported about 0.5-2 s after it
    /// happened, [`Kick::samples_ago`] says how long).
    pub fn take_kick(&mut self) -> Option<Kick> {
        self.kick.take()
    }

    /// Samples between two analyses.
    #[must_use]
    pub fn hop_len(&self) -> usize {
        self.p.hop
    }

    /// Whether the last [`Detector::push`] ended a hop (ran an analysis).
    #[must_use]
    pub fn analysed(&self) -> bool {
        self.hop_phase == 0 && self.filled >= self.p.window_len
    }

    /// Dominant (frequency Hz, amplitude deg, interior bin) of the latest
    /// `window.len()` samples under `window`.
    fn peak(&self, window: &[f32], amp_scale: f32) -> (f32, f32, bool) {
        let n = window.len();
        let mut block = [0.0_f32; MAX_WINDOW];
        // Oldest sample first: `head` is where the next write goes.
        let start = self.head + MAX_WINDOW - n;
        for (i, b) in block.iter_mut().enumerate().take(n) {
            *b = window[i] * self.ring[(start + i) % MAX_WINDOW];
        }
        let mut power = [0.0_f32; MAX_BINS];
        self.bank.powers(&block[..n], &mut power);
        let k_bins = self.bank.len();
        let mut k = 0;
        for i in 1..k_bins {
            if power[i] > power[k] {
                k = i;
            }
        }
        if k == 0 || k + 1 == k_bins {
            return (
                self.bank.freq_hz(k),
                math::sqrtf(power[k]) * amp_scale,
                false,
            );
        }
        let (a, b, c) = (
            math::sqrtf(power[k - 1]),
            math::sqrtf(power[k]),
            math::sqrtf(power[k + 1]),
        );
        let den = a - 2.0 * b + c;
        // b is the largest, so den <= 0; den == 0 only for a flat top.
        let d = if den < 0.0 {
            (0.5 * (a - c) / den).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let f = self.bank.freq_hz(k) + d * self.cfg.bin_spacing_hz;
        (f, (b - 0.25 * (a - c) * d) * amp_scale, true)
    }

    /// Feeds one steering sample (degrees) and, when known, the wheel speed
    /// (m/s). Returns the alert change this sample caused, if any.
    ///
    /// Non-finite steering values repeat the previous sample; magnitudes above
    /// 1000 degrees are clamped. A non-finite or negative speed counts as
    /// unknown.
    pub fn push(&mut self, steer_deg: f32, speed_mps: Option<f32>) -> Option<AlertEvent> {
        let x = if steer_deg.is_finite() {
            steer_deg.clamp(-INPUT_LIMIT_DEG, INPUT_LIMIT_DEG)
        } else {
            self.last_input.unwrap_or(0.0)
        };
        if self.last_input.is_none() {
            self.hpf.settle(x);
        }
        self.last_input = Some(x);
        let speed = speed_mps.filter(|v| v.is_finite() && *v >= 0.0);
        let mut y = self.hpf.process(x);
        // Learn only steady ripple: not during an alert, and not while the
        // steering carries more than ripple can be (kicks, jolts, a large
        // oscillation). The gate looks at the canceller's input, never at its
        // output: gating on the output lets the gate's own rhythm pump the
        // weights.
        self.input_block_max = self.input_block_max.max(y.abs());
        let quiet_input = self
            .input_envelope
            .max(0, self.p.window_len.div_ceil(self.p.hop))
            < RIPPLE_CEILING * self.cfg.amp_on_deg;
        let adapt = !self.alert_active() && quiet_input;
        if let Some(c) = self.canceller.as_mut() {
            y = c.process(y, speed, adapt);
        }

        if let Some(kick) = self.ringdown.sample(y, speed) {
            self.kick = Some(kick);
        }
        self.ring[self.head] = y;
        self.head = (self.head + 1) % MAX_WINDOW;
        if self.filled < MAX_WINDOW {
            self.filled += 1;
        }
        self.block_max = self.block_max.max(y.abs());
        self.hop_phase += 1;
        if self.hop_phase < self.p.hop {
            return None;
        }
        self.hop_phase = 0;
        self.envelope.push(self.block_max);
        self.block_max = 0.0;
        self.input_envelope.push(self.input_block_max);
        self.input_block_max = 0.0;
        if self.filled < self.p.window_len {
            return None;
        }
        self.analyse(speed)
    }

    /// A new impulse: the kick before it, if one was still being measured, is
    /// reported with what was measured; this one's ring-down is measured
    /// (not during an alert, nor below walking speed). An envelope jump is
    /// seen within a hop of the kick; a spectral jump once its ring fills
    /// part of the window, about a look-back later.
    fn start_ringdown(&mut self, envelope_jump: bool, freq_hz: f32, speed_mps: Option<f32>) {
        if let Some(kick) = self.ringdown.finish() {
            self.kick = Some(kick);
        }
        let walking = speed_mps.is_some_and(|v| v < self.cfg.min_speed_mps);
        if self.alert_active() || walking {
            return;
        }
        let lead = if envelope_jump {
            self.p.hop
        } else {
            self.p.lookback * self.p.hop
        };
        self.ringdown.start(lead as u32, freq_hz);
    }

    /// One analysis: spectrum, impulse detector, state machine.
    fn analyse(&mut self, speed_mps: Option<f32>) -> Option<AlertEvent> {
        let (freq_hz, amp_deg, interior) =
            self.peak(&self.window[..self.p.window_len], self.amp_scale);
        let in_band = interior && freq_hz >= self.cfg.band_lo_hz && freq_hz <= self.cfg.band_hi_hz;

        let previous = self.amps.get(self.p.lookback - 1);
        self.amps.push(amp_deg);
        let growth_ratio = previous.map_or(1.0, |prev| amp_deg / prev.max(1e-6));

        // Impulse detector on the high-passed envelope: a sudden jump over
        // what the preceding `impulse_ref` hops held.
        let fast = self.envelope.max(0, self.p.impulse_fast);
        let reference = self.envelope.max(self.p.impulse_fast, self.p.impulse_ref);
        let envelope_jump =
            fast >= self.cfg.impulse_min_deg && fast >= self.cfg.impulse_ratio * reference;
        // ...or the spectral amplitude rising faster than any wobble grows.
        let spectral_jump = previous.is_some()
            && amp_deg >= self.cfg.amp_off_deg
            && growth_ratio >= self.cfg.max_growth_ratio;
        if envelope_jump || spectral_jump {
            if self.holdoff_left == 0 {
                self.start_ringdown(envelope_jump, freq_hz, speed_mps);
                // The jolt that caused a spectral jump may be anywhere in the
                // analysis window: start from the envelope's peak over it.
                let hops = self.p.window_len.div_ceil(self.p.hop);
                self.impulse_peak_deg = self.envelope.max(0, hops);
            }
            self.holdoff_left = self.p.impulse_holdoff;
            // A jump of the envelope is seen at the jolt's start, before the
            // high-passed ring peaks: follow it for a while. A spectral jump
            // is seen once the ring is in the window, peak included.
            if envelope_jump {
                self.capture_left = self.p.impulse_capture.max(1);
            }
        } else if self.holdoff_left > 0 {
            self.holdoff_left -= 1;
        }
        if self.capture_left > 0 {
            self.capture_left -= 1;
            self.impulse_peak_deg = self.impulse_peak_deg.max(fast);
        }
        let holdoff =
            self.holdoff_left > 0 && amp_deg < self.cfg.impulse_catchup * self.impulse_peak_deg;
        // The trend of a ring starts where its impulse stops holding the
        // alert off: the jump from the noise to the ring (and the ring
        // filling the window) would read as growth for seconds.
        if holdoff {
            self.trend.restart();
        }
        self.trend.push(amp_deg);
        let trend_per_s = self.trend.per_s();

        let at_wheel_harmonic = speed_mps.is_some_and(|v| {
            let f_wheel = v / self.wheel_circumference_m;
            if f_wheel <= 0.0 {
                return false;
            }
            let order = (freq_hz / f_wheel + 0.5) as u32;
            order >= 1 && (freq_hz - order as f32 * f_wheel).abs() <= self.cfg.harmonic_tol_hz
        });

        self.estimate = Estimate {
            amp_deg,
            freq_hz,
            in_band,
            growth_ratio,
            impulse_holdoff: holdoff,
            at_wheel_harmonic,
            trend_per_s,
        };

        match self.state {
            State::Quiet { confirm } => {
                let min_ratio =
                    if at_wheel_harmonic && amp_deg < RIPPLE_CEILING * self.cfg.amp_on_deg {
                        self.cfg.harmonic_growth_ratio
                    } else {
                        self.cfg.min_growth_ratio
                    };
                // Decayed from the largest amplitude of the decay span (a kick's
                // ring-down outlasting the impulse hold-off): no alert.
                let decayed =
                    amp_deg < self.cfg.decay_span_ratio * self.amps.max(0, self.p.decay_span);
                // Decaying over the trend's longer span (a slow ring-down
                // beating with the road noise after the span's peak): no
                // alert either.
                let decaying = trend_per_s < self.cfg.decay_trend_per_s;
                let on = previous.is_some()
                    && !decayed
                    && !decaying
                    && amp_deg >= self.cfg.amp_on_deg
                    && in_band
                    && !holdoff
                    && growth_ratio >= min_ratio
                    && speed_mps.is_none_or(|v| v >= self.cfg.min_speed_mps);
                if !on {
                    self.state = State::Quiet { confirm: 0 };
                    return None;
                }
                let confirm = confirm.saturating_add(1);
                if confirm < self.cfg.confirm_hops {
                    self.state = State::Quiet { confirm };
                    return None;
                }
                self.state = State::Alerting { below: 0 };
                // A ring that alerts is not a ring-down.
                self.ringdown.cancel();
                // Report the frequency from the longer window when it agrees
                // that the peak is in band (in noise and beside leftover wheel
                // ripple it measures better); otherwise the analysis window's.
                let n = self.p.freq_window_len.min(self.filled);
                let freq_hz = if n > self.p.window_len {
                    let (window, scale) = if n == self.p.freq_window_len {
                        (&self.freq_window[..n], self.freq_amp_scale)
                    } else {
                        (&self.window[..self.p.window_len], self.amp_scale)
                    };
                    let (f, _, ok) = self.peak(window, scale);
                    if ok && f >= self.cfg.band_lo_hz && f <= self.cfg.band_hi_hz {
                        f
                    } else {
                        freq_hz
                    }
                } else {
                    freq_hz
                };
                Some(AlertEvent::On { freq_hz, amp_deg })
            }
            State::Alerting { below } => {
                let below = if amp_deg < self.cfg.amp_off_deg {
                    below + 1
                } else {
                    0
                };
                if below >= self.p.off_hold {
                    self.state = State::Quiet { confirm: 0 };
                    Some(AlertEvent::Off)
                } else {
                    self.state = State::Alerting { below };
                    None
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAU: f32 = core::f32::consts::TAU;

    fn detector() -> Detector {
        Detector::new(
            DetectorConfig::default(),
            crate::wheel::WheelConfig::DEFAULT.circumference_m,
        )
        .unwrap()
    }

    #[test]
    fn alert_records_carry_hundredths() {
        let on = AlertEvent::On {
            freq_hz: 6.404,
            amp_deg: 0.806,
        };
        assert_eq!(
            on.to_record(17_120_000),
            Alert {
                t_us: 17_120_000,
                on: true,
                freq_chz: 640,
                amp_cdeg: 81
            }
        );
        let off = AlertEvent::Off.to_record(5);
        assert!(!off.on && off.freq_chz == 0 && off.amp_cdeg == 0);
    }

    #[test]
    fn analyses_once_per_hop_after_the_window_fills() {
        let mut d = detector();
        let mut analyses = 0;
        for i in 0..100 {
            d.push(0.0, None);
            if d.analysed() {
                analyses += 1;
                assert!(i + 1 >= 40 && (i + 1) % d.hop_len() == 0);
            }
        }
        assert_eq!(analyses, (100 - 40) / 5 + 1);
    }

    #[test]
    fn growing_wobble_alerts_then_clears_and_reset_forgets() {
        let mut d = detector();
        let (mut on_at, mut off_at) = (None, None);
        for i in 0..1200 {
            let t = i as f32 / 100.0;
            // Grows from 0.02 deg at 3 s at 2/s to 3 deg, then decays at 5/s.
            let env = if t < 5.5 {
                (0.02 * (2.0 * (t - 3.0)).exp()).min(3.0)
            } else {
                3.0 * (-5.0 * (t - 5.5)).exp()
            };
            match d.push(env * (TAU * 7.0 * t).sin(), Some(5.0)) {
                Some(e @ AlertEvent::On { .. }) => on_at = Some((t, e)),
                Some(AlertEvent::Off) => off_at = Some(t),
                None => {}
            }
        }
        let (t_on, on) = on_at.unwrap();
        // 0.5 deg at 3 + ln(25)/2 = 4.61 s.
        assert!(t_on > 4.3 && t_on < 5.0, "{t_on}");
        let AlertEvent::On { freq_hz, .. } = on else {
            unreachable!()
        };
        assert!((freq_hz - 7.0).abs() < 0.1, "{freq_hz}");
        assert!(off_at.unwrap() > 5.5);
        assert!(!d.alert_active());
        d.reset();
        assert_eq!(d.estimate(), Estimate::default());
    }

    #[test]
    fn the_canceller_does_not_learn_a_wobble_while_the_alert_is_on() {
        // A wobble phase-locked to the wheel's 3rd harmonic (5 m/s): grows
        // at 2/s from 0.02 deg to 0.7 deg (under the 0.8 deg input gate, so
        // only the alert stops the learning), then holds for 12 s. Learning
        // it during the alert would remove it within a few 3 s time
        // constants and switch the alert off while the wobble goes on.
        let mut d = detector();
        let v = 5.0;
        let f = 3.0 * v / crate::wheel::WheelConfig::DEFAULT.circumference_m;
        let mut on_at = None;
        for i in 0..2000 {
            let t = i as f32 / 100.0;
            let env = (0.02 * (2.0 * t).exp()).min(0.7);
            match d.push(env * (TAU * f * t).sin(), Some(v)) {
                Some(AlertEvent::On { .. }) => on_at = Some(t),
                Some(AlertEvent::Off) => panic!("alert off at {t} s during the wobble"),
                None => {}
            }
        }
        let on = on_at.expect("the wobble alerts");
        assert!(on < 3.0, "{on}");
        assert!(d.alert_active());
    }

    #[test]
    fn a_decaying_ring_past_the_impulse_hold_off_does_not_alert() {
        // A kick ringing from 2.5 deg at 6.5 Hz, decaying at 0.4/s: the
        // 0.2 s look-back sees 0.92 of the amplitude (above
        // min_growth_ratio), but against the largest amplitude of the last
        // 1.5 s the ring has decayed below decay_span_ratio.
        let mut d = detector();
        let mut kick = None;
        for i in 0..1200 {
            let t = i as f32 / 100.0;
            let x = if t < 2.0 {
                0.0
            } else {
                2.5 * (-0.4 * (t - 2.0)).exp() * (TAU * 6.5 * (t - 2.0)).sin()
            };
            assert_eq!(d.push(x, Some(3.0)), None, "alert at {t} s");
            kick = kick.or(d.take_kick());
        }
        let k = kick.expect("the ring-down is measured");
        assert!((k.sigma_per_s + 0.4).abs() < 0.1, "{k:?}");
        assert!((k.freq_hz - 6.5).abs() < 0.05, "{k:?}");
    }

    /// A kick at 2 s ringing from 2.45 deg at 6 Hz, decaying at 0.31/s, on a
    /// steady 0.13 deg tone at 6.5 Hz: once the ring has decayed to about
    /// 0.3 deg the two beat every 2 s, and each beat's peak rises above
    /// `amp_on_deg` and above 0.85 of the 1.5 s before it.
    fn slow_ring_beating(t: f32, hold_from_s: f32) -> f32 {
        let tau = t - 2.0;
        let ring = if tau < 0.0 {
            0.0
        } else {
            2.45 * (-0.31 * tau.min(hold_from_s)).exp() * (TAU * 6.0 * tau).sin()
        };
        ring + 0.13 * (TAU * 6.5 * t).sin()
    }

    fn alerts(cfg: DetectorConfig, secs: f32, signal: impl Fn(f32) -> f32) -> Vec<f32> {
        let mut d =
            Detector::new(cfg, crate::wheel::WheelConfig::DEFAULT.circumference_m).expect("valid");
        (0..(secs * 100.0) as usize)
            .filter_map(|i| {
                let t = i as f32 / 100.0;
                matches!(d.push(signal(t), None), Some(AlertEvent::On { .. })).then_some(t)
            })
            .collect()
    }

    #[test]
    fn a_slow_ring_beating_with_the_noise_does_not_alert() {
        let ring = |t| slow_ring_beating(t, f32::INFINITY);
        let cfg = DetectorConfig::default();
        assert_eq!(alerts(cfg, 12.0, ring), [] as [f32; 0]);
        // Without the trend the decay check alone lets a beat's peak alert.
        let no_trend = DetectorConfig {
            decay_trend_s: 0.0,
            ..cfg
        };
        assert!(!alerts(no_trend, 12.0, ring).is_empty());
    }

    #[test]
    fn a_ring_that_stops_decaying_and_holds_alerts() {
        // The same ring holding at 0.9 deg from 3.3 s after the kick.
        let hold_s = 3.3;
        let on = alerts(DetectorConfig::default(), 12.0, |t| {
            slow_ring_beating(t, hold_s)
        });
        let hold_at = 2.0 + hold_s;
        assert!(
            on.first()
                .is_some_and(|&t| t > hold_at && t < hold_at + 3.0),
            "{on:?}"
        );
    }

    #[test]
    fn below_walking_speed_never_alerts() {
        let mut d = detector();
        for i in 0..1000 {
            let t = i as f32 / 100.0;
            assert!(d
                .push(2.0 * (TAU * 7.0 * t).sin() * (t / 5.0).min(1.0), Some(1.0))
                .is_none());
        }
    }
}
