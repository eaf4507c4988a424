//! The envelope's trend over the last seconds: an exponentially weighted
//! least-squares line through the logarithm of the per-hop amplitude, whose
//! slope is the envelope's growth rate (1/s, negative while it decays).
//!
//! The decay check compares the amplitude with its largest value of the last
//! 1.5 s; a slow ring-down (sigma about -0.3 1/s) that has decayed into the
//! road noise and beats with it can rise back to 0.85 of that. The trend
//! looks back further and weighs every analysis, not the largest one, so a
//! beat does not hide the decay. Five running sums (fixed memory, no history):
//! with weights `forget^k` over the age `k` in hops, one step ages every sum
//! by a hop. The forgetting factor makes every recursion contract, so
//! rounding errors die out instead of accumulating over hours.

use super::Cost1;

/// One analysis: a logarithm, the five sums aged and added to (6 mul, 6
/// add), and the slope (4 mul, 2 add, 2 divisions).
pub(crate) const COST: Cost1 = Cost1::new(
    Cost1::LOG.mul + 12,
    Cost1::LOG.add + 8,
    Cost1::LOG.other + 2,
);

/// The running line. `amp_floor_deg` keeps `ln` finite on silence (and
/// noise below it counts as flat).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EnvelopeTrend {
    forget: f32,
    amp_floor_deg: f32,
    hop_s: f32,
    /// Sums over the ages `k` (hops) of `w = forget^k` times 1, `k`, `k^2`,
    /// `ln a` and `k ln a`.
    w: f32,
    k: f32,
    kk: f32,
    y: f32,
    ky: f32,
}

impl EnvelopeTrend {
    /// A trend with time constant `span_hops` (weights fall by `e` every
    /// `span_hops`), analyses `hop_s` apart; `span_hops` <= 1 keeps only the
    /// latest analysis (no trend: its slope stays 0).
    pub(crate) fn new(span_hops: f32, hop_s: f32, amp_floor_deg: f32) -> Self {
        let forget = if span_hops > 1.0 {
            1.0 - 1.0 / span_hops
        } else {
            0.0
        };
        Self {
            forget,
            amp_floor_deg: amp_floor_deg.max(1e-6),
            hop_s,
            w: 0.0,
            k: 0.0,
            kk: 0.0,
            y: 0.0,
            ky: 0.0,
        }
    }

    /// Forgets every analysis: the next one starts a new line.
    pub(crate) fn restart(&mut self) {
        (self.w, self.k, self.kk, self.y, self.ky) = (0.0, 0.0, 0.0, 0.0, 0.0);
    }

    /// Takes the amplitude of a new analysis, degrees. Out of line: inlined
    /// into the analysis it moved the board's machine outliner to share
    /// fragments across the SD driver that the stack bound reads as a cycle.
    #[inline(never)]
    pub(crate) fn push(&mut self, amp_deg: f32) {
        let l = self.forget;
        let y = libm::logf(amp_deg.max(self.amp_floor_deg));
        // Every age grows by one: sum w (k+1)^2, w (k+1), w (k+1) y.
        self.kk = l * (self.kk + 2.0 * self.k + self.w);
        self.k = l * (self.k + self.w);
        self.ky = l * (self.ky + self.y);
        self.w = 1.0 + l * self.w;
        self.y = y + l * self.y;
    }

    /// Slope of `ln` amplitude against time, 1/s (0 until two analyses).
    pub(crate) fn per_s(&self) -> f32 {
        let sxx = self.w * self.kk - self.k * self.k;
        if sxx <= 0.0 {
            return 0.0;
        }
        // Against the age, which runs backwards in time.
        -(self.w * self.ky - self.k * self.y) / sxx / self.hop_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trend_of(amps: impl Iterator<Item = f32>) -> f32 {
        let mut t = EnvelopeTrend::new(40.0, 0.05, 0.01);
        amps.for_each(|a| t.push(a));
        t.per_s()
    }

    #[test]
    fn an_exponential_envelope_gives_its_rate() {
        for rate in [-1.0_f32, -0.3, 0.0, 0.5, 2.0] {
            // 3 s, above the floor.
            let got = trend_of((0..60).map(|i| 2.0 * libm::expf(rate * i as f32 * 0.05)));
            assert!(
                (got - rate).abs() < 1e-3 * (1.0 + rate.abs()),
                "{rate}: {got}"
            );
        }
    }

    #[test]
    fn the_rate_is_seen_before_the_weights_settle() {
        // 10 analyses (0.5 s) of a ring at -0.4 1/s.
        let got = trend_of((0..10).map(|i| 2.0 * libm::expf(-0.4 * i as f32 * 0.05)));
        assert!((got + 0.4).abs() < 1e-3, "{got}");
        assert_eq!(trend_of(core::iter::once(1.0)), 0.0);
    }

    #[test]
    fn old_analyses_are_forgotten() {
        // A decay 20 s (10 time constants) ago, steady since.
        let old = (0..100).map(|i| 2.0 * libm::expf(-(i as f32) * 0.05));
        let got = trend_of(old.chain((0..400).map(|_| 0.3)));
        assert!(got.abs() < 1e-3, "{got}");
    }

    #[test]
    fn silence_is_flat_not_infinite() {
        let got = trend_of((0..100).map(|i| if i < 50 { 0.0 } else { 1e-9 }));
        assert!(got.is_finite() && got.abs() < 1e-4, "{got}");
        let no_span = EnvelopeTrend::new(0.0, 0.05, 0.01);
        assert_eq!(no_span.per_s(), 0.0);
    }
}
