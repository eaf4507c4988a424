//! A bank of Goertzel filters evaluated on a block of samples.
//!
//! Each bin runs the second-order recursion `s[n] = x[n] + c s[n-1] - s[n-2]`
//! with `c = 2 cos(2 pi f / fs)` over one block, starting from zero, and ends
//! with the squared magnitude `s1^2 + s2^2 - c s1 s2`. The pole pair lies on
//! the unit circle, so the recursion is only marginally stable; that is
//! harmless here because every block starts from zero state and runs at most
//! [`MAX_WINDOW`](super::MAX_WINDOW) steps, so rounding error is bounded by the
//! block length and can never accumulate over a ride. (A sliding Goertzel /
//! sliding DFT, which updates one running state per sample forever, lets that
//! error random-walk without bound.)
//!
//! Bins need not sit on the block's DFT grid: the magnitude formula holds for
//! any frequency, so the bank samples the windowed spectrum on whatever grid
//! the configuration asks for.

use super::math;

/// Most bins a bank holds.
pub const MAX_BINS: usize = 32;

/// Goertzel coefficients for a set of frequencies.
#[derive(Clone, Copy, Debug)]
pub struct GoertzelBank {
    coeff: [f32; MAX_BINS],
    freq_hz: [f32; MAX_BINS],
    len: usize,
}

impl GoertzelBank {
    /// Bins at `f_lo_hz + k * spacing_hz` for `k` in `0..n_bins` (at most
    /// [`MAX_BINS`], extra bins are dropped) at sample rate `fs_hz`.
    #[must_use]
    pub fn new(f_lo_hz: f32, spacing_hz: f32, n_bins: usize, fs_hz: f32) -> Self {
        let len = n_bins.min(MAX_BINS);
        let mut coeff = [0.0; MAX_BINS];
        let mut freq_hz = [0.0; MAX_BINS];
        for k in 0..len {
            let f = f64::from(f_lo_hz) + k as f64 * f64::from(spacing_hz);
            freq_hz[k] = f as f32;
            coeff[k] = (2.0 * math::cos(core::f64::consts::TAU * f / f64::from(fs_hz))) as f32;
        }
        Self {
            coeff,
            freq_hz,
            len,
        }
    }

    /// Number of bins.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the bank has no bins.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Centre frequency of bin `k`, Hz.
    #[must_use]
    pub fn freq_hz(&self, k: usize) -> f32 {
        self.freq_hz[k]
    }

    /// Squared DFT magnitude of `block` at every bin, into `power[..len()]`.
    ///
    /// Cost: `len() * block.len()` steps of one multiplication and two
    /// additions, plus 3 multiplications and 2 additions per bin.
    pub fn powers(&self, block: &[f32], power: &mut [f32]) {
        for (k, p) in power.iter_mut().enumerate().take(self.len) {
            *p = goertzel_power(block, self.coeff[k]);
        }
    }
}

/// Squared DFT magnitude of `block` at the frequency whose coefficient is
/// `coeff = 2 cos(2 pi f / fs)`. Never negative.
#[must_use]
pub fn goertzel_power(block: &[f32], coeff: f32) -> f32 {
    let (mut s1, mut s2) = (0.0_f32, 0.0_f32);
    for &x in block {
        let s = x + coeff * s1 - s2;
        s2 = s1;
        s1 = s;
    }
    // Rounding can make the difference slightly negative for a near-zero bin.
    (s1 * s1 + s2 * s2 - coeff * s1 * s2).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_direct_dft() {
        let fs = 100.0_f32;
        let block: [f32; 40] = core::array::from_fn(|n| {
            let t = n as f32 / fs;
            1.3 * (core::f32::consts::TAU * 6.7 * t + 0.4).sin() + 0.2 * (n as f32 * 0.37).cos()
        });
        let bank = GoertzelBank::new(5.5, 0.25, 17, fs);
        let mut p = [0.0; MAX_BINS];
        bank.powers(&block, &mut p);
        for (k, &got) in p.iter().enumerate().take(bank.len()) {
            let w = core::f64::consts::TAU * f64::from(bank.freq_hz(k)) / f64::from(fs);
            let (mut re, mut im) = (0.0_f64, 0.0_f64);
            for (n, &x) in block.iter().enumerate() {
                re += f64::from(x) * (w * n as f64).cos();
                im -= f64::from(x) * (w * n as f64).sin();
            }
            let want = re * re + im * im;
            assert!(
                (f64::from(got) - want).abs() < 1e-3 * want.max(1.0),
                "bin {k}"
            );
        }
    }

    #[test]
    fn zero_block_is_zero() {
        assert_eq!(goertzel_power(&[0.0; 40], 1.8), 0.0);
        assert_eq!(goertzel_power(&[], 1.8), 0.0);
    }
}
