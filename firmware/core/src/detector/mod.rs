//! The on-board wobble detector: Goertzel bins over 6-9 Hz on the 100 Hz
//! steering angle, an alert state machine with hysteresis, and the buzzer/LED
//! pattern that tells the rider.
//!
//! The design and the reasons for every default are written up in
//! `firmware/docs/detector.md`, with the metrics measured on the recorded-
//! signal corpus in `hil-tests/`. In short, per 100 Hz sample:
//!
//! 1. **Detrend**: a 4th-order Butterworth high-pass at 4 Hz ([`HighPass4`])
//!    removes the steering offset, cornering, weave and most of pedalling.
//!    When the wheel speed is known, a wheel-synchronous canceller
//!    ([`HarmonicCanceller`]) learns and subtracts the steady wheel-rotation
//!    harmonics between 4.5 and 10.5 Hz.
//! 2. The filtered sample goes into a 40-sample (0.4 s) ring buffer, and the
//!    largest |sample| of each hop is kept for the impulse detector.
//! 3. **Every hop** (5 samples, 50 ms: 87.5 % overlap) the ring is multiplied
//!    by a Hann window and a [`GoertzelBank`] evaluates 17 bins from 5.5 to
//!    9.5 Hz every 0.25 Hz. The largest bin and a parabolic interpolation over
//!    its neighbours give the dominant frequency and amplitude (degrees).
//! 4. The [`Detector`]'s state machine switches the alert on when the
//!    amplitude is above [`DetectorConfig::amp_on_deg`], the peak lies inside
//!    the wobble band, the envelope is not decaying (amplitude now versus
//!    [`DetectorConfig::lookback_s`] ago) and no recent impulse (kick,
//!    pothole, kerb) explains it; and off when the amplitude has stayed below
//!    [`DetectorConfig::amp_off_deg`] for [`DetectorConfig::off_hold_s`].
//!
//! Everything is `f32`, nothing allocates, and the cost per sample is bounded
//! (see [`DetectorConfig::cost`]).

mod filter;
mod goertzel;
mod harmonics;
mod machine;
pub mod margin;
pub mod math;
mod pattern;
mod ringdown;
mod trend;

pub use filter::{Biquad, HighPass4};
pub use goertzel::{goertzel_power, GoertzelBank, MAX_BINS};
pub use harmonics::{sincos_turns, HarmonicCanceller};
pub use machine::{AlertEvent, Detector, Estimate};
pub use margin::{MarginEvent, MarginWarning, WobbleSpeed};
pub use pattern::{AlertOutput, AlertPattern, ApproachConfig, PatternConfig};
pub use ringdown::{Kick, SIGMA_SD_FLOOR_PER_S, SIGMA_SE_FACTOR};

/// Longest analysis window, samples (0.64 s at 100 Hz).
pub const MAX_WINDOW: usize = 64;
/// Longest history of per-hop values (amplitudes and impulse envelope), hops.
pub const MAX_HISTORY: usize = 32;

/// Tuning of the wobble detector. All times in seconds, frequencies in hertz,
/// amplitudes in degrees of steering angle (zero to peak).
///
/// The defaults are the ones the firmware runs and `wobblog detect` replays;
/// the corpus benchmark in `hil-tests` measures them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DetectorConfig {
    /// Steering sample rate.
    pub sample_rate_hz: f32,
    /// Analysis window length (Hann).
    pub window_s: f32,
    /// Time between two analyses (the window slides by this much).
    pub hop_s: f32,
    /// Centre of the lowest Goertzel bin.
    pub bin_lo_hz: f32,
    /// Centre of the highest Goertzel bin (inclusive, rounded to the grid).
    pub bin_hi_hz: f32,
    /// Spacing of the Goertzel bins.
    pub bin_spacing_hz: f32,
    /// Lowest dominant frequency that may raise the alert.
    pub band_lo_hz: f32,
    /// Highest dominant frequency that may raise the alert.
    pub band_hi_hz: f32,
    /// Corner of the detrending high-pass (4th-order Butterworth).
    pub highpass_hz: f32,
    /// Amplitude the oscillation must reach to switch the alert on.
    pub amp_on_deg: f32,
    /// Amplitude below which the alert may switch off (hysteresis).
    pub amp_off_deg: f32,
    /// How long the amplitude must stay below `amp_off_deg` to switch off.
    pub off_hold_s: f32,
    /// Growth look-back: the amplitude now is compared with this long ago.
    pub lookback_s: f32,
    /// Smallest ratio amplitude(now) / amplitude(`lookback_s` ago) that counts
    /// as "growing or sustained". Below it the oscillation is decaying.
    pub min_growth_ratio: f32,
    /// Consecutive hops all alert conditions must hold before the alert fires.
    pub confirm_hops: u8,
    /// Recent span of the impulse detector's envelope.
    pub impulse_fast_s: f32,
    /// Reference span of the impulse detector's envelope, just before the
    /// recent span.
    pub impulse_ref_s: f32,
    /// The envelope jumping by this factor over the reference marks an impulse.
    pub impulse_ratio: f32,
    /// An impulse must reach at least this peak (degrees, high-passed).
    pub impulse_min_deg: f32,
    /// After an impulse, the alert waits this long...
    pub impulse_holdoff_s: f32,
    /// ...unless the Goertzel amplitude catches up with this fraction of the
    /// impulse's peak (a decaying ring never does; a growing wobble soon does).
    pub impulse_catchup: f32,
    /// The impulse's peak is the envelope's largest value within this long
    /// after the impulse is first seen.
    pub impulse_capture_s: f32,
    /// The Goertzel amplitude growing by more than this ratio over
    /// `lookback_s` is faster than any wobble: it is treated as an impulse too
    /// (a kick's ring entering the window, beating wheel harmonics).
    pub max_growth_ratio: f32,
    /// Window of the frequency estimate reported when the alert fires: longer
    /// than `window_s`, so noise and nearby wheel harmonics bias it less.
    pub freq_window_s: f32,
    /// Below this wheel speed (when speed is known) the alert stays off.
    pub min_speed_mps: f32,
    /// A dominant frequency this close to a wheel harmonic counts as one.
    pub harmonic_tol_hz: f32,
    /// At a wheel harmonic (speed known) and below twice `amp_on_deg`, the
    /// amplitude must grow by at least this ratio over `lookback_s`: steady
    /// ripple never alerts. A safety net behind the canceller (before it has
    /// converged, or when it is off).
    pub harmonic_growth_ratio: f32,
    /// Learning time constant of the wheel-harmonic canceller (speed known);
    /// 0 switches the canceller off.
    pub harmonic_tau_s: f32,
    /// Span of the decay check: the largest amplitude of the analyses over
    /// this long (the current one included)...
    pub decay_span_s: f32,
    /// ...times this ratio must not exceed the amplitude now. Below it the
    /// oscillation has died down since (a kick's ring-down once it is past
    /// the impulse hold-off) and never alerts; 0 switches the check off.
    pub decay_span_ratio: f32,
    /// Time constant of the envelope trend: a line through the logarithm of
    /// the analyses' amplitudes, weighted by `exp(-age / decay_trend_s)`
    /// (0 switches the check off)...
    pub decay_trend_s: f32,
    /// ...whose slope (1/s) must not be below this: an envelope decaying
    /// faster over the trend's span (a slow ring-down that has decayed into
    /// the road noise and beats with it) never alerts.
    pub decay_trend_per_s: f32,
}

impl DetectorConfig {
    /// The firmware's defaults (see `firmware/docs/detector.md` for why).
    pub const DEFAULT: Self = Self {
        sample_rate_hz: 100.0,
        window_s: 0.40,
        hop_s: 0.05,
        bin_lo_hz: 5.5,
        bin_hi_hz: 9.5,
        bin_spacing_hz: 0.25,
        band_lo_hz: 5.8,
        band_hi_hz: 9.2,
        highpass_hz: 4.0,
        amp_on_deg: 0.40,
        amp_off_deg: 0.25,
        off_hold_s: 0.30,
        lookback_s: 0.20,
        min_growth_ratio: 0.90,
        confirm_hops: 2,
        impulse_fast_s: 0.10,
        impulse_ref_s: 0.40,
        impulse_ratio: 3.0,
        impulse_min_deg: 0.50,
        impulse_holdoff_s: 1.0,
        impulse_catchup: 1.4,
        impulse_capture_s: 0.40,
        max_growth_ratio: 2.7,
        freq_window_s: 0.64,
        min_speed_mps: 1.5,
        harmonic_tol_hz: 0.20,
        harmonic_growth_ratio: 1.05,
        harmonic_tau_s: 3.0,
        decay_span_s: 1.5,
        decay_span_ratio: 0.85,
        decay_trend_s: 2.0,
        decay_trend_per_s: -0.15,
    };

    /// Worst-case and average arithmetic per sample for this configuration
    /// (see [`Cost`]).
    ///
    /// # Errors
    /// When the configuration is invalid.
    pub fn cost(&self) -> Result<Cost, ConfigError> {
        let p = Params::new(self)?;
        let (n, k, m) = (
            p.window_len as u32,
            p.n_bins as u32,
            p.freq_window_len as u32,
        );
        // Per sample: sanitise (2 compares), high-pass (10 mul, 8 add), ring
        // write, two |y| running maxima (4 compares), hop bookkeeping.
        let per_sample = Cost1 {
            mul: 10,
            add: 8,
            other: 8,
        };
        // A bank evaluation over `len` samples: window (len mul), Goertzel
        // (k*len mul, 2*k*len add), powers (3k mul, 2k add), argmax (k
        // compares), 3 square roots (3 div + 3 mul + 3 add each), parabolic
        // interpolation (8 mul/add).
        let bank = |len: u32| Cost1 {
            mul: len + k * len + 3 * k + 9 + 8,
            add: 2 * k * len + 2 * k + 9 + 4,
            other: k + 3,
        };
        // Per hop: one bank over the window, the impulse envelope maxima,
        // the envelope trend and the state machine (~20 compares / mul).
        let b = bank(n);
        let per_hop = Cost1 {
            mul: b.mul + 6,
            add: b.add + 2,
            other: b.other
                + 2 * (p.impulse_fast + p.impulse_ref + p.window_len / p.hop) as u32
                + 20,
        } + trend::COST;
        // When the alert fires: one more bank over the frequency window.
        let on_alert = bank(m);
        let hop = p.hop as u32;
        // Harmonic canceller (speed known): sincos (13 mul, 12 add), angle
        // additions up to the first order (at most MAX_ORDER - 1 of 4 mul +
        // 2 add), and per cancelled order: prediction (2 mul, 2 add),
        // rotation (4 mul, 2 add), update (5 mul, 2 add).
        let rotations = harmonics::MAX_ORDER - 1;
        let orders = harmonics::MAX_ORDERS as u32;
        let canceller = Cost1 {
            mul: 13 + 4 * rotations + 11 * orders + 2,
            add: 12 + 2 * rotations + 6 * orders + 2,
            other: 6,
        };
        let (ringdown, kick_fit) = ringdown::cost();
        let (margin_estimate, margin_update) = margin::cost();
        let average = per_sample
            + Cost1 {
                mul: per_hop.mul.div_ceil(hop),
                add: per_hop.add.div_ceil(hop),
                other: per_hop.other.div_ceil(hop),
            }
            + margin_update;
        Ok(Cost {
            // A ring-down fit (a segment below the floor) and the alert can
            // fall on the sample that ends a hop: everything at once.
            worst: per_sample
                + per_hop
                + on_alert
                + ringdown
                + kick_fit
                + margin_estimate
                + margin_update,
            average,
            canceller,
            goertzel_steps_per_hop: k * n,
            ringdown,
            kick: kick_fit + margin_estimate,
        })
    }
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Floating-point operations of one kind of sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost1 {
    /// Multiplications (and the 3 divisions per square root are counted here
    /// too; the Cortex-M4F divides in 14 cycles, multiplies in 1).
    pub mul: u32,
    /// Additions and subtractions.
    pub add: u32,
    /// Compares, absolute values and bookkeeping.
    pub other: u32,
}

impl core::ops::Add for Cost1 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            mul: self.mul + o.mul,
            add: self.add + o.add,
            other: self.other + o.other,
        }
    }
}

impl core::ops::Mul<u32> for Cost1 {
    type Output = Self;
    fn mul(self, n: u32) -> Self {
        Self {
            mul: self.mul * n,
            add: self.add * n,
            other: self.other * n,
        }
    }
}

impl Cost1 {
    /// `mul` multiplications, `add` additions, `other` compares and
    /// bookkeeping.
    pub(crate) const fn new(mul: u32, add: u32, other: u32) -> Self {
        Self { mul, add, other }
    }

    /// [`math::sqrtf`]: 3 divisions, 3 multiplications, 3 additions.
    pub(crate) const SQRT: Self = Self::new(6, 3, 2);
    /// `libm::logf` (its source: a reduction, one division, a degree-4
    /// polynomial in `s^2`).
    pub(crate) const LOG: Self = Self::new(12, 10, 4);
    /// `libm::expf`, `libm::sinf` (a reduction and a short polynomial).
    pub(crate) const EXP: Self = Self::new(9, 7, 4);
    /// `libm::atan2f` (a division and `atanf`'s polynomial).
    pub(crate) const ATAN2: Self = Self::new(13, 12, 8);
    /// [`sincos_turns`] (also the canceller's first step).
    pub(crate) const SINCOS: Self = Self::new(13, 12, 2);
}

/// Analytical cost per sample of the detector and the margin warning
/// ([`MarginWarning`], which the sampler runs beside it).
///
/// `worst` is a sample that ends a hop (the whole Goertzel bank runs then) on
/// which the alert also fires (one more bank over the frequency window), a
/// kick's ring-down is fitted and the margin re-estimated from it (the most
/// that can fall on one sample); `average` spreads the hop's work over its
/// samples, with no kick being measured. Both exclude the harmonic
/// canceller, which runs on every sample when the speed is known and costs
/// at most `canceller` more.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    /// A sample on which the bank is evaluated, the alert fires and a kick
    /// is reported.
    pub worst: Cost1,
    /// Average over a hop, no kick being measured (the margin warning's
    /// per-sample check included).
    pub average: Cost1,
    /// Harmonic canceller, per sample, when the speed is known (worst case).
    pub canceller: Cost1,
    /// Goertzel recursion steps per hop (bins x window).
    pub goertzel_steps_per_hop: u32,
    /// More per sample while a kick's ring-down is measured (at most 1.88 s
    /// after each kick).
    pub ringdown: Cost1,
    /// Once per kick, on the sample that reports it: the ring-down fit and
    /// the margin estimate (worst case: [`margin::MAX_KICKS`] kicks and
    /// every reweighting pass).
    pub kick: Cost1,
}

/// Why a [`DetectorConfig`] was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigError {
    /// The sample rate is not a positive finite number.
    SampleRate,
    /// The window is shorter than 8 samples or longer than [`MAX_WINDOW`], or
    /// the frequency window is shorter than the window or longer than
    /// [`MAX_WINDOW`].
    Window,
    /// The hop is zero samples or longer than the window.
    Hop,
    /// Fewer than 3 bins, more than [`MAX_BINS`], or a bin at or above
    /// Nyquist / at or below 0 Hz.
    Bins,
    /// `amp_off_deg` is not below `amp_on_deg`, or a threshold is negative.
    Thresholds,
    /// A look-back, impulse or decay span does not fit [`MAX_HISTORY`] hops,
    /// or is zero.
    History,
    /// A value is NaN or infinite.
    NotFinite,
    /// The wheel circumference (which places the wheel-rotation harmonics)
    /// is not a positive finite number.
    Circumference,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::SampleRate => "sample rate must be positive",
            Self::Window => "window must be 8 to 64 samples",
            Self::Hop => "hop must be 1 sample to the window length",
            Self::Bins => "bins must be 3 to 32 between 0 Hz and Nyquist",
            Self::Thresholds => "amp_off_deg must be below amp_on_deg, thresholds non-negative",
            Self::History => "look-back, impulse and decay spans must be 1 to 31 hops",
            Self::NotFinite => "a value is NaN or infinite",
            Self::Circumference => "wheel circumference must be a positive number of metres",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigError {}

/// A configuration turned into sample and hop counts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Params {
    pub window_len: usize,
    pub freq_window_len: usize,
    pub hop: usize,
    pub n_bins: usize,
    pub lookback: usize,
    pub off_hold: usize,
    pub impulse_fast: usize,
    pub impulse_ref: usize,
    pub impulse_holdoff: usize,
    pub impulse_capture: usize,
    pub decay_span: usize,
}

/// Nearest count to a non-negative `x` (no `f32::round` without std).
fn count(x: f32) -> usize {
    if x.is_finite() && x > 0.0 {
        (x + 0.5) as usize
    } else {
        0
    }
}

impl Params {
    pub(crate) fn new(c: &DetectorConfig) -> Result<Self, ConfigError> {
        let all = [
            c.sample_rate_hz,
            c.window_s,
            c.hop_s,
            c.bin_lo_hz,
            c.bin_hi_hz,
            c.bin_spacing_hz,
            c.band_lo_hz,
            c.band_hi_hz,
            c.highpass_hz,
            c.amp_on_deg,
            c.amp_off_deg,
            c.off_hold_s,
            c.lookback_s,
            c.min_growth_ratio,
            c.impulse_fast_s,
            c.impulse_ref_s,
            c.impulse_ratio,
            c.impulse_min_deg,
            c.impulse_holdoff_s,
            c.impulse_catchup,
            c.impulse_capture_s,
            c.max_growth_ratio,
            c.freq_window_s,
            c.min_speed_mps,
            c.harmonic_tol_hz,
            c.harmonic_growth_ratio,
            c.harmonic_tau_s,
            c.decay_span_s,
            c.decay_span_ratio,
            c.decay_trend_s,
            c.decay_trend_per_s,
        ];
        if all.iter().any(|v| !v.is_finite()) {
            return Err(ConfigError::NotFinite);
        }
        let fs = c.sample_rate_hz;
        if fs <= 0.0 {
            return Err(ConfigError::SampleRate);
        }
        let window_len = count(c.window_s * fs);
        if !(8..=MAX_WINDOW).contains(&window_len) {
            return Err(ConfigError::Window);
        }
        let freq_window_len = count(c.freq_window_s * fs);
        if !(window_len..=MAX_WINDOW).contains(&freq_window_len) {
            return Err(ConfigError::Window);
        }
        let hop = count(c.hop_s * fs);
        if hop == 0 || hop > window_len {
            return Err(ConfigError::Hop);
        }
        if c.bin_spacing_hz <= 0.0 || c.bin_lo_hz <= 0.0 || c.bin_hi_hz >= fs / 2.0 {
            return Err(ConfigError::Bins);
        }
        let n_bins = count((c.bin_hi_hz - c.bin_lo_hz) / c.bin_spacing_hz) + 1;
        if !(3..=MAX_BINS).contains(&n_bins) || c.bin_hi_hz <= c.bin_lo_hz {
            return Err(ConfigError::Bins);
        }
        if c.highpass_hz <= 0.0 || c.highpass_hz >= fs / 2.0 {
            return Err(ConfigError::Bins);
        }
        let non_negative = [
            c.amp_on_deg,
            c.amp_off_deg,
            c.off_hold_s,
            c.min_growth_ratio,
            c.impulse_ratio,
            c.impulse_min_deg,
            c.impulse_holdoff_s,
            c.impulse_catchup,
            c.impulse_capture_s,
            c.max_growth_ratio,
            c.min_speed_mps,
            c.harmonic_tol_hz,
            c.harmonic_growth_ratio,
            c.harmonic_tau_s,
            c.decay_span_s,
            c.decay_span_ratio,
            c.decay_trend_s,
        ];
        if c.amp_off_deg >= c.amp_on_deg || non_negative.iter().any(|&v| v < 0.0) {
            return Err(ConfigError::Thresholds);
        }
        let hop_s = hop as f32 / fs;
        let hops = |s: f32| count(s / hop_s);
        let lookback = hops(c.lookback_s);
        let impulse_fast = hops(c.impulse_fast_s);
        let impulse_ref = hops(c.impulse_ref_s);
        let decay_span = hops(c.decay_span_s);
        if lookback == 0
            || decay_span == 0
            || decay_span >= MAX_HISTORY
            || lookback >= MAX_HISTORY
            || impulse_fast == 0
            || impulse_ref == 0
            || impulse_fast + impulse_ref > MAX_HISTORY
        {
            return Err(ConfigError::History);
        }
        Ok(Self {
            window_len,
            freq_window_len,
            hop,
            n_bins,
            lookback,
            off_hold: hops(c.off_hold_s).max(1),
            impulse_fast,
            impulse_ref,
            impulse_holdoff: hops(c.impulse_holdoff_s),
            impulse_capture: hops(c.impulse_capture_s),
            decay_span,
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn default_config_is_valid() {
        let p = Params::new(&DetectorConfig::default()).unwrap();
        assert_eq!(p.window_len, 40);
        assert_eq!(p.hop, 5);
        assert_eq!(p.n_bins, 17);
        assert_eq!(p.lookback, 4);
    }

    #[test]
    fn bad_configs_are_rejected() {
        let d = DetectorConfig::default();
        let bad = [
            (
                DetectorConfig {
                    sample_rate_hz: 0.0,
                    ..d
                },
                ConfigError::SampleRate,
            ),
            (DetectorConfig { window_s: 1.0, ..d }, ConfigError::Window),
            (DetectorConfig { hop_s: 0.0, ..d }, ConfigError::Hop),
            (
                DetectorConfig {
                    bin_hi_hz: 60.0,
                    ..d
                },
                ConfigError::Bins,
            ),
            (
                DetectorConfig {
                    bin_spacing_hz: 0.01,
                    ..d
                },
                ConfigError::Bins,
            ),
            (
                DetectorConfig {
                    amp_off_deg: 0.5,
                    ..d
                },
                ConfigError::Thresholds,
            ),
            (
                DetectorConfig {
                    lookback_s: 5.0,
                    ..d
                },
                ConfigError::History,
            ),
            (
                DetectorConfig {
                    amp_on_deg: f32::NAN,
                    ..d
                },
                ConfigError::NotFinite,
            ),
        ];
        for (cfg, want) in bad {
            assert_eq!(Params::new(&cfg).unwrap_err(), want);
        }
    }

    #[test]
    fn cost_of_defaults() {
        let c = DetectorConfig::default().cost().unwrap();
        std::println!("FIGURES cost: {c:?}");
        assert_eq!(c.goertzel_steps_per_hop, 17 * 40);
        assert!(c.average.mul < 200, "{c:?}");
        assert!(c.canceller.mul < 150, "{c:?}");
        // While a ring is measured: an oscillator and 3 open segments.
        assert!(c.ringdown.mul > 20 && c.ringdown.mul < 60, "{c:?}");
        // The worst sample holds the kick-free worst (2 banks, < 2200 mul)
        // and a kick's work, which is larger.
        let (ringdown, fit) = ringdown::cost();
        let (estimate, update) = margin::cost();
        assert_eq!(c.kick, fit + estimate);
        let kick_free = c.worst.mul - c.kick.mul - ringdown.mul - update.mul;
        assert!(kick_free > 2000 && kick_free < 2200, "{c:?}");
        assert!(c.kick.mul > kick_free, "{c:?}");
    }

    /// What the detector and the margin warning hold (no allocation):
    /// `cargo test -p wobble-core --lib memory_of -- --nocapture`.
    #[test]
    fn memory_of_the_detector_and_the_margin_warning() {
        let (d, m) = (
            core::mem::size_of::<Detector>(),
            core::mem::size_of::<MarginWarning>(),
        );
        std::println!("FIGURES memory: Detector {d} B, MarginWarning {m} B");
        assert!(d < 4096 && m < 512, "{d} {m}");
    }

    /// The ring-down fit is a line fit over the segments and a few
    /// transcendental functions; the margin estimate, [`margin::ITERATIONS`]
    /// reweighting passes over [`margin::MAX_KICKS`] kicks, dominates.
    #[test]
    fn the_kick_costs_scale_with_their_sizes() {
        let (_, fit) = ringdown::cost();
        let (estimate, update) = margin::cost();
        // Per segment but the last at least a logarithm and its weights.
        let passes = 15;
        assert!(fit.mul >= passes * (Cost1::LOG.mul + 2), "{fit:?}");
        assert!(fit.mul < 2 * passes * (Cost1::LOG.mul + 12), "{fit:?}");
        // Per pass and kick at least a residual, a weight and a line term,
        // and the median's insertion sort.
        let (n, k) = (margin::MAX_KICKS as u32, margin::ITERATIONS as u32);
        assert!(estimate.mul >= k * n * 10, "{estimate:?}");
        assert!(estimate.other >= k * n * (n - 1) / 2, "{estimate:?}");
        assert!(estimate.mul > 4 * fit.mul, "{estimate:?} {fit:?}");
        assert!(update.mul == 0 && update.other <= 4, "{update:?}");
    }
}
