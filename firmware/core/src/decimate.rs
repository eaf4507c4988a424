//! Boxcar decimation of fast samples to the 100 Hz frame rate.
//!
//! Sensors are sampled faster than 100 Hz (the steering ADC at 1-10 kHz, the
//! IMU at its output data rate); each frame takes the mean of the samples that
//! arrived since the previous frame. A 10 ms mean is a sinc filter with nulls
//! at every multiple of 100 Hz, exactly the frequencies that would alias to
//! 0 Hz. Its response, for the wobble band and for what would alias into it:
//!
//! | frequency | gain | note |
//! |---|---|---|
//! | 6 Hz | 0.994 (-0.05 dB) | wobble band |
//! | 9 Hz | 0.987 (-0.12 dB) | wobble band |
//! | 91 / 109 Hz | 0.098 / 0.082 (-20 / -22 dB) | alias to 9 Hz |
//! | 94 / 106 Hz | 0.064 / 0.056 (-24 / -25 dB) | alias to 6 Hz |
//!
//! Sums are integers, so the mean of any number of samples is exact until it
//! is divided once at the tick.

/// Running sums of `N`-channel integer samples since the last tick.
#[derive(Clone, Copy, Debug)]
pub struct Boxcar<const N: usize> {
    sum: [i64; N],
    count: u32,
}

impl<const N: usize> Default for Boxcar<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Boxcar<N> {
    /// No samples yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            sum: [0; N],
            count: 0,
        }
    }

    /// Adds one sample.
    pub fn push(&mut self, sample: [i32; N]) {
        for (s, x) in self.sum.iter_mut().zip(sample) {
            *s = s.saturating_add(i64::from(x));
        }
        self.count = self.count.saturating_add(1);
    }

    /// Samples since the last [`Self::take`].
    #[must_use]
    pub const fn count(&self) -> u32 {
        self.count
    }

    /// The mean of the samples since the last call, and starts over; `None`
    /// if there were none.
    pub fn take(&mut self) -> Option<[f32; N]> {
        if self.count == 0 {
            return None;
        }
        let n = self.count as f32;
        let mean = self.sum.map(|s| s as f32 / n);
        *self = Self::new();
        Some(mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_the_samples_since_the_last_take() {
        let mut b = Boxcar::<2>::new();
        assert_eq!(b.take(), None);
        for x in [1, 2, 3, 4] {
            b.push([x, -10 * x]);
        }
        assert_eq!(b.count(), 4);
        assert_eq!(b.take(), Some([2.5, -25.0]));
        assert_eq!(b.take(), None);
    }

    #[test]
    fn a_100_hz_tone_averages_out() {
        // 10 kHz samples of a 100 Hz sine: one whole period per frame.
        let mut b = Boxcar::<1>::new();
        for i in 0..100 {
            let phase = core::f64::consts::TAU * f64::from(i) / 100.0;
            b.push([(1000.0 * phase.sin()).round() as i32]);
        }
        assert!(b.take().unwrap()[0].abs() < 0.01);
    }
}
