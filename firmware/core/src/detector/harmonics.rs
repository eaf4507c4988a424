//! Wheel-synchronous cancellation of the wheel-rotation harmonics.
//!
//! A wheel out of true and a tyre's non-uniformity put a steady ripple on the
//! steering angle at multiples of the wheel's rotation rate: at 4 m/s a 28"
//! wheel turns at 1.88 Hz, so the 3rd and 4th harmonics sit at 5.6 and
//! 7.5 Hz, inside the wobble band. A 0.4 s window cannot resolve them from a
//! wobble 1 Hz away: they pull its frequency estimate and, beating with each
//! other, make an in-band peak that rises and falls like a growing oscillation.
//!
//! When the wheel speed is known, their frequencies are known exactly, so
//! this canceller subtracts them: it integrates the wheel angle from the
//! speed, and a least-mean-squares filter per harmonic order learns that
//! order's amplitude and phase (two weights on `cos(k theta)`, `sin(k theta)`)
//! with a time constant of seconds. Steady ripple is learned and removed; a
//! wobble, which grows within a second or two and is almost never locked to
//! the wheel, is barely learned. Three safeguards keep it so:
//!
//! - the adaptation error is clipped (to [`CLIP_DEG`]), so a kick or a wobble
//!   of several degrees moves the weights no faster than a small ripple would;
//! - adaptation is frozen while the alert is on;
//! - a small leak pulls the weights to zero when there is nothing to learn.
//!
//! Numerics: the wheel angle is a phase accumulator in turns wrapped to
//! [0, 1) every sample, and `cos/sin(k theta)` are rebuilt every sample from
//! `cos/sin(theta)` by angle addition (at most [`MAX_ORDERS`] steps), so there
//! is no free-running oscillator to drift. The LMS weights are bounded by the
//! clipped error and the leak.

/// Most harmonic orders cancelled at once (the lowest orders whose frequency
/// falls in the cancelled range).
pub const MAX_ORDERS: usize = 6;
/// Highest harmonic order considered.
pub const MAX_ORDER: u32 = 12;
/// Adaptation error clip, degrees: above any plausible ripple amplitude.
pub const CLIP_DEG: f32 = 0.2;

/// Learns and subtracts the wheel harmonics in a frequency range.
#[derive(Clone, Copy, Debug)]
pub struct HarmonicCanceller {
    /// Wheel angle, turns, in [0, 1).
    turns: f32,
    /// (cos, sin) weights per order 1..=MAX_ORDER (index order - 1).
    weights: [[f32; 2]; MAX_ORDER as usize],
    mu: f32,
    leak: f32,
    f_lo_hz: f32,
    f_hi_hz: f32,
    inv_circumference: f32,
    dt_s: f32,
    min_speed_mps: f32,
}

impl HarmonicCanceller {
    /// A canceller for harmonics between `f_lo_hz` and `f_hi_hz`, learning
    /// with time constant `tau_s`, at sample rate `fs_hz`. Below
    /// `min_speed_mps` (and when speed is unknown) it passes samples through.
    #[must_use]
    pub fn new(
        f_lo_hz: f32,
        f_hi_hz: f32,
        tau_s: f32,
        circumference_m: f32,
        min_speed_mps: f32,
        fs_hz: f32,
    ) -> Self {
        // Each reference (cos or sin) has mean power 1/2, so an LMS weight
        // converges as (1 - mu/2)^n: time constant 2 / mu samples.
        let tau_samples = (tau_s * fs_hz).max(2.0);
        Self {
            turns: 0.0,
            weights: [[0.0; 2]; MAX_ORDER as usize],
            mu: 2.0 / tau_samples,
            // Leak 200x slower than learning: a 1 % bias on learned ripple.
            leak: 0.01 / tau_samples,
            f_lo_hz,
            f_hi_hz,
            inv_circumference: 1.0 / circumference_m,
            dt_s: 1.0 / fs_hz,
            min_speed_mps,
        }
    }

    /// The learned amplitude of harmonic `order` (1-based), degrees.
    #[must_use]
    pub fn amplitude_deg(&self, order: u32) -> f32 {
        match self.weights.get((order as usize).wrapping_sub(1)) {
            Some(&[a, b]) => super::math::sqrtf(a * a + b * b),
            None => 0.0,
        }
    }

    /// Removes the learned ripple from `y` (degrees) and, if `adapt`, learns
    /// from the residue. `speed_mps` advances the wheel angle.
    ///
    /// Cost per sample: one `sincos` (about 20 operations) and per cancelled
    /// order about 8 multiplications and 6 additions.
    pub fn process(&mut self, y: f32, speed_mps: Option<f32>, adapt: bool) -> f32 {
        let Some(v) = speed_mps else { return y };
        let f_wheel = v * self.inv_circumference;
        self.turns += f_wheel * self.dt_s;
        self.turns -= self.turns as i32 as f32; // wrap to [0, 1) (v >= 0)
        if v < self.min_speed_mps || f_wheel <= 0.0 {
            return y;
        }
        let (s1, c1) = sincos_turns(self.turns);
        // Orders whose frequency is in range: k from ceil(f_lo / f_wheel).
        let mut k = ((self.f_lo_hz / f_wheel) as u32).max(1);
        if (k as f32) * f_wheel < self.f_lo_hz {
            k += 1;
        }
        let k_first = k;
        let mut n = 0;
        // cos/sin(k theta) by angle addition from k = 1.
        let (mut ck, mut sk) = (c1, s1);
        for _ in 1..k_first.min(MAX_ORDER + 1) {
            let c = ck * c1 - sk * s1;
            sk = sk * c1 + ck * s1;
            ck = c;
        }
        let mut refs = [(0usize, 0.0_f32, 0.0_f32); MAX_ORDERS];
        let mut prediction = 0.0;
        while k <= MAX_ORDER && n < MAX_ORDERS && (k as f32) * f_wheel <= self.f_hi_hz {
            let w = self.weights[k as usize - 1];
            prediction += w[0] * ck + w[1] * sk;
            refs[n] = (k as usize - 1, ck, sk);
            n += 1;
            let c = ck * c1 - sk * s1;
            sk = sk * c1 + ck * s1;
            ck = c;
            k += 1;
        }
        let e = y - prediction;
        if adapt {
            let g = self.mu * e.clamp(-CLIP_DEG, CLIP_DEG);
            let keep = 1.0 - self.leak;
            for &(i, c, s) in &refs[..n] {
                let w = &mut self.weights[i];
                w[0] = keep * w[0] + g * c;
                w[1] = keep * w[1] + g * s;
            }
        }
        e
    }
}

/// `(sin, cos)` of `turns` full turns, `turns` in [0, 1).
///
/// Reduced to an octant-free form: x in [-1/4, 1/4] turn via symmetry, then
/// odd/even Taylor polynomials to degree 13/12 in `x * 2 pi` (|x| <= pi/2):
/// truncation error below 1e-8, under f32 rounding.
#[must_use]
pub fn sincos_turns(turns: f32) -> (f32, f32) {
    // Map to [-0.5, 0.5).
    let mut t = turns - (turns + 0.5) as i32 as f32;
    if t < -0.5 {
        t += 1.0;
    }
    // sin(pi - a) = sin a, cos(pi - a) = -cos a: fold to [-0.25, 0.25].
    let (u, cos_sign) = if t > 0.25 {
        (0.5 - t, -1.0)
    } else if t < -0.25 {
        (-0.5 - t, -1.0)
    } else {
        (t, 1.0)
    };
    let x = u * core::f32::consts::TAU;
    let x2 = x * x;
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0
                        + x2 * (1.0 / 362_880.0
                            + x2 * (-1.0 / 39_916_800.0 + x2 * (1.0 / 6_227_020_800.0)))))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0
                    + x2 * (1.0 / 40_320.0
                        + x2 * (-1.0 / 3_628_800.0 + x2 * (1.0 / 479_001_600.0))))));
    (s, cos_sign * c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sincos_matches_std() {
        let mut t = 0.0_f32;
        while t < 1.0 {
            let (s, c) = sincos_turns(t);
            let a = core::f64::consts::TAU * f64::from(t);
            assert!((f64::from(s) - a.sin()).abs() < 3e-7, "sin {t}");
            assert!((f64::from(c) - a.cos()).abs() < 3e-7, "cos {t}");
            t += 0.0007;
        }
    }

    /// Runs `secs` of a ripple at orders 3 and 4 plus `extra(t)` through a
    /// canceller at 4 m/s; returns the output's RMS over the last second.
    fn residual(secs: f32, extra: impl Fn(f32) -> f32) -> f32 {
        let (fs, v, c) = (100.0, 4.0, 2.13);
        let mut h = HarmonicCanceller::new(4.5, 10.5, 3.0, c, 1.5, fs);
        let n = (secs * fs) as usize;
        let mut acc = 0.0;
        for i in 0..n {
            let t = i as f32 / fs;
            let th = core::f32::consts::TAU * v / c * t;
            let x = 0.1 * (3.0 * th + 0.3).sin() + 0.1 * (4.0 * th + 1.0).sin() + extra(t);
            let e = h.process(x, Some(v), true);
            if i >= n - 100 {
                acc += (e - extra(t)) * (e - extra(t));
            }
        }
        (acc / 100.0).sqrt()
    }

    #[test]
    fn learns_and_removes_steady_ripple() {
        let r = residual(20.0, |_| 0.0);
        assert!(r < 0.005, "{r}");
    }

    #[test]
    fn passes_a_wobble_between_harmonics() {
        // A 1 deg 6.4 Hz oscillation for 3 s after the ripple was learned:
        // the output still carries the wobble (residue = output - wobble).
        let r = residual(23.0, |t| {
            if t > 20.0 {
                (core::f32::consts::TAU * 6.4 * t).sin()
            } else {
                0.0
            }
        });
        assert!(r < 0.1, "{r}");
    }

    /// Runs `secs` of `amp` degrees of ripple at order 3 alone, phase-locked
    /// to the wheel at 4 m/s, through a fresh canceller that always learns;
    /// returns the amplitude it learned.
    fn learned(secs: f32, amp: f32) -> f32 {
        let (fs, v, c) = (100.0, 4.0, 2.13);
        let mut h = HarmonicCanceller::new(4.5, 10.5, 3.0, c, 1.5, fs);
        for i in 0..(secs * fs) as usize {
            let th = core::f32::consts::TAU * v / c * (i as f32 / fs);
            h.process(amp * (3.0 * th + 0.7).sin(), Some(v), true);
        }
        h.amplitude_deg(3)
    }

    #[test]
    fn the_error_clip_bounds_how_fast_a_large_oscillation_is_learned() {
        // 3 deg on the 3rd harmonic for 1 s. Unclipped, LMS with a 3 s time
        // constant learns 3 (1 - e^(-1/3)) = 0.85 deg of it; with the error
        // clipped to CLIP_DEG each weight moves by at most mu x CLIP_DEG per
        // sample: 100 x (2 / 300) x 0.2 = 0.13 deg in 1 s.
        let a = learned(1.0, 3.0);
        let bound = 100.0 * (2.0 / 300.0) * CLIP_DEG;
        assert!(a <= bound, "learned {a} deg, clip bound {bound}");
        // A ripple under the clip is learned at the full rate.
        let small = learned(1.0, 0.15);
        assert!(
            (small / 0.15 - (1.0 - (-1.0_f32 / 3.0).exp())).abs() < 0.05,
            "{small}"
        );
    }

    #[test]
    fn the_leak_holds_learned_ripple_one_percent_low() {
        // At convergence leak x w = (mu / 2) (A - w): w = A / (1 + 2 leak /
        // mu) = A / 1.01 with the leak 200 times slower than learning. No
        // leak would converge to A itself.
        let a = learned(60.0, 0.1) / 0.1;
        assert!((a - 1.0 / 1.01).abs() < 0.002, "{a}");
    }

    #[test]
    fn unknown_speed_passes_through() {
        let mut h = HarmonicCanceller::new(4.5, 10.5, 3.0, 2.13, 1.5, 100.0);
        for i in 0..1000 {
            let x = (i as f32 * 0.3).sin();
            assert_eq!(h.process(x, None, true), x);
        }
    }
}
