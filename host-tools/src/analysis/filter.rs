//! Zero-phase filtering for offline analysis: second-order Butterworth
//! sections run forwards and backwards, so nothing the analysis measures is
//! shifted in time.

use std::f64::consts::{FRAC_1_SQRT_2, TAU};

/// One second-order section (direct form II transposed), normalised `a0 = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

/// A [`Biquad`] filtering a stream one sample at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Streaming {
    section: Biquad,
    z1: f64,
    z2: f64,
}

impl Streaming {
    /// The output for the next input `x`.
    pub fn next(&mut self, x: f64) -> f64 {
        let [b0, b1, b2] = self.section.b;
        let [a1, a2] = self.section.a;
        let y = b0 * x + self.z1;
        self.z1 = b1 * x - a1 * y + self.z2;
        self.z2 = b2 * x - a2 * y;
        y
    }
}

/// Which side of the corner frequency a section passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Passes below the corner.
    Low,
    /// Passes above the corner.
    High,
}

impl Biquad {
    /// A Butterworth section (Q = 1/sqrt 2) with its corner at `corner_hz`,
    /// for samples at `fs_hz` (bilinear transform, as in the RBJ cookbook).
    #[must_use]
    pub fn butterworth(pass: Pass, corner_hz: f64, fs_hz: f64) -> Self {
        let w0 = TAU * corner_hz / fs_hz;
        let (sin, cos) = w0.sin_cos();
        let alpha = sin / (2.0 * FRAC_1_SQRT_2);
        let a0 = 1.0 + alpha;
        let b = match pass {
            Pass::Low => [(1.0 - cos) / 2.0, 1.0 - cos, (1.0 - cos) / 2.0],
            Pass::High => [(1.0 + cos) / 2.0, -(1.0 + cos), (1.0 + cos) / 2.0],
        };
        Self {
            b: b.map(|v| v / a0),
            a: [-2.0 * cos / a0, (1.0 - alpha) / a0],
        }
    }

    /// Filters `x` in place in one direction, starting from the state a
    /// constant input equal to the first sample would have settled to, so a
    /// signal offset does not ring at the edges.
    fn run(&self, x: &mut [f64], forward: bool) {
        let first = if forward { x.first() } else { x.last() };
        let Some(&x0) = first else { return };
        let mut section = self.stream(x0);
        let mut step = |v: &mut f64| *v = section.next(*v);
        if forward {
            x.iter_mut().for_each(&mut step);
        } else {
            x.iter_mut().rev().for_each(&mut step);
        }
    }

    /// The section filtering one sample at a time, started from the state
    /// a constant input `x0` would have settled to (as [`Self::forward`]).
    #[must_use]
    pub fn stream(self, x0: f64) -> Streaming {
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        let y0 = (b0 + b1 + b2) / (1.0 + a1 + a2) * x0;
        let z2 = b2 * x0 - a2 * y0;
        Streaming {
            section: self,
            z1: b1 * x0 - a1 * y0 + z2,
            z2,
        }
    }

    /// Filters `x` forwards only: causal, as a filter on the bicycle would.
    pub fn forward(&self, x: &mut [f64]) {
        self.run(x, true);
    }

    /// Filters `x` forwards then backwards: zero phase, squared magnitude.
    pub fn filtfilt(&self, x: &mut [f64]) {
        self.run(x, true);
        self.run(x, false);
    }
}

/// The band-pass every steering analysis starts from: 4-12 Hz around the
/// 6-9 Hz wobble band, wide enough that weave, corners and pedalling (below
/// 2 Hz, their 4th harmonic below 6 Hz at the most) are gone, while the
/// band's edges barely touch a wobble.
#[must_use]
pub fn wobble_band(x: &[f64], fs_hz: f64) -> Vec<f64> {
    band_pass(x, WOBBLE_BAND_HZ, fs_hz)
}

/// The wobble band's corners, Hz: what every wobble analysis passes, and
/// where the frequencies it reports lie.
pub const WOBBLE_BAND_HZ: (f64, f64) = (4.0, 12.0);

/// Zero-phase band-pass of `x` between `(low, high)` Hz: a Butterworth
/// high-pass and low-pass section, each run forwards and backwards.
#[must_use]
pub fn band_pass(x: &[f64], (low_hz, high_hz): (f64, f64), fs_hz: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    Biquad::butterworth(Pass::High, low_hz, fs_hz).filtfilt(&mut y);
    Biquad::butterworth(Pass::Low, high_hz, fs_hz).filtfilt(&mut y);
    y
}

/// The same band as [`wobble_band`], filtered forwards only (each section
/// twice, for the same squared magnitude): causal, so nothing shows in it
/// before it happened. A zero-phase filter answers a sharp transient
/// (a push on the bar) on both sides of it, with an oscillation near the
/// band's centre that grows towards the transient; here that oscillation
/// only follows it.
#[must_use]
pub fn wobble_band_causal(x: &[f64], fs_hz: f64) -> Vec<f64> {
    band_pass_causal(x, WOBBLE_BAND_HZ, fs_hz)
}

/// [`band_pass`] filtered forwards only, each section twice: causal.
#[must_use]
pub fn band_pass_causal(x: &[f64], (low_hz, high_hz): (f64, f64), fs_hz: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    let high = Biquad::butterworth(Pass::High, low_hz, fs_hz);
    let low = Biquad::butterworth(Pass::Low, high_hz, fs_hz);
    for section in [high, high, low, low] {
        section.forward(&mut y);
    }
    y
}

/// Whether a frame at `t_s` is the one after a frame at `prev_s`, for
/// frames `period_s` apart: later by more than half a period and less than
/// one and a half.
#[must_use]
pub fn follows(prev_s: f64, t_s: f64, period_s: f64) -> bool {
    let dt = t_s - prev_s;
    dt > 0.5 * period_s && dt < 1.5 * period_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone_amplitude_after(pass: Pass, corner_hz: f64, f_hz: f64) -> f64 {
        let fs = 100.0;
        let mut x: Vec<f64> = (0..4000)
            .map(|i| (TAU * f_hz * f64::from(i) / fs).sin())
            .collect();
        Biquad::butterworth(pass, corner_hz, fs).filtfilt(&mut x);
        x[1000..3000].iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    #[test]
    fn corner_is_half_power_after_both_passes() {
        // One pass is -3 dB at the corner; forwards and backwards, -6 dB.
        for pass in [Pass::Low, Pass::High] {
            let a = tone_amplitude_after(pass, 8.0, 8.0);
            assert!((a - 0.5).abs() < 0.01, "{pass:?}: {a}");
        }
        assert!(tone_amplitude_after(Pass::Low, 2.0, 20.0) < 1e-3);
        assert!(tone_amplitude_after(Pass::High, 4.0, 0.5) < 1e-3);
    }

    /// The causal band shows nothing before a step and rings after it;
    /// the zero-phase band rings on both sides.
    #[test]
    fn causal_band_does_not_ring_before_a_step() {
        let x: Vec<f64> = (0..600).map(|i| if i < 300 { 0.0 } else { 5.0 }).collect();
        let before = |y: &[f64]| y[200..298].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let after = |y: &[f64]| y[300..400].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let causal = wobble_band_causal(&x, 100.0);
        let zero_phase = wobble_band(&x, 100.0);
        assert!(before(&causal) < 1e-9, "{}", before(&causal));
        assert!(after(&causal) > 0.5);
        assert!(before(&zero_phase) > 0.1, "{}", before(&zero_phase));
    }

    #[test]
    fn a_gap_or_a_reversal_breaks_the_sequence() {
        let t = [0.0, 0.01, 0.02, 0.05, 0.06, 0.055, 0.065];
        let breaks: Vec<usize> = (1..t.len())
            .filter(|&i| !follows(t[i - 1], t[i], 0.01))
            .collect();
        assert_eq!(breaks, [3, 5]);
        // Within half a period either side of the next frame.
        assert!(follows(1.0, 1.014, 0.01) && follows(1.0, 1.006, 0.01));
        assert!(!follows(1.0, 1.016, 0.01) && !follows(1.0, 1.004, 0.01));
    }
}
