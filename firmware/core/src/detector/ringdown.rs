//! Measuring a kick's ring-down: the frequency and growth rate of the stable
//! wobble mode that a kick on the bar (or a jolt) rings.
//!
//! When the impulse detector sees a kick, the push itself (a short, large
//! steering transient) is skipped for [`SKIP_S`]; then the high-passed,
//! ripple-cancelled steering is demodulated at a fixed frequency `f0` (the
//! dominant frequency at the kick, or the band's centre) in Hann-windowed
//! segments of [`SEGMENT_S`] every [`STRIDE_S`]. For a damped sinusoid
//! `A e^(sigma t) cos(2 pi f t + phi)` each segment's complex amplitude is
//! `A' e^(sigma t_k) e^(j 2 pi (f - f0) t_k)`, `t_k` its centre, so
//!
//! - the high-pass's slow transient (what a push leaves, a ring's onset) is
//!   taken out of the segments exactly, its pole being known: the fit is on
//!   `Y_k = X_(k+1) - q X_k` (see [`RingDown::fit`]);
//! - `sigma` is the slope of `ln |Y_k|` against `t_k`, fitted by weighted
//!   least squares with weights `|Y_k|^2` (the inverse variance of `ln |Y|`
//!   in additive noise), and its standard error comes from the residuals;
//! - `f - f0` is the phase advance per stride, from the pulse pair
//!   `sum Y_(k+1) conj(Y_k)` (unbiased by white noise, unlike `|Y|`);
//! - the initial amplitude is the fit extrapolated back to the kick.
//!
//! A segment is used while its amplitude is at least [`FLOOR_DEG`]: the fit
//! stops at the first one below, after [`MAX_SEGMENTS`], or when an alert
//! fires or another impulse arrives, and reports a kick only from
//! [`MIN_SEGMENTS`] segments or more with the frequency in the Goertzel
//! bins' range, or at most [`OUTSIDE_BINS_HZ`] outside it if it decays.
//!
//! Cost: per sample, while measuring, one oscillator rotation and one
//! complex multiply-add per open segment (at most 3); per segment, one
//! logarithm; one `atan2` per kick. Memory: about 250 bytes, no allocation.
//!
//! The host's measurement (`wobblog`'s `analysis::kicks`, `f64`) is another
//! algorithm on purpose, not this one refined: with the whole record it
//! fits the samples after the envelope's peak in a zero-phase band, which
//! a causal, one-pass, fixed-memory measurement cannot do; this one is
//! what the board can afford, and the host keeps its records beside its
//! own (see there).

use super::filter::HighPass4;
use super::harmonics::sincos_turns;
use super::Cost1;
use crate::format::{quantise_i16, quantise_u16, KickRingDown};

/// The push is skipped for this long after the impulse is first seen, s (a
/// push lasts up to about 0.12 s; the high-pass's answer to it is taken out
/// by the fit, not skipped).
pub const SKIP_S: f32 = 0.13;
/// Length of a demodulation segment, s: shorter segments follow a fast ring
/// closer to the kick, longer ones hold less noise.
pub const SEGMENT_S: f32 = 0.25;
/// Time between the starts of two segments, s.
pub const STRIDE_S: f32 = 0.1;
/// Most segments per kick (the fit spans at most 1.75 s of ring).
pub const MAX_SEGMENTS: usize = 16;
/// Fewest segments a kick is reported from (three `Y`s).
pub const MIN_SEGMENTS: usize = 4;
/// Segments below this amplitude (degrees) end the fit: noise would bias
/// `ln |X|` upwards.
pub const FLOOR_DEG: f32 = 0.1;
/// A ring is reported this far outside the Goertzel bins' range, Hz.
///
/// Its frequency is measured by the phase advance, not by the bins: `f0` is
/// the dominant bin (the edge bin for a ring beyond the range), and 0.5 Hz
/// from `f0` the phase advances 0.05 turn per stride (unambiguous to 0.5),
/// the 0.25 s Hann segment passes the ring at 0.99 of its amplitude
/// (corrected below) and the 4 Hz high-pass at 5.0 Hz at 0.93 (-0.7 dB),
/// the same factor on every segment, so sigma is not biased. Further down
/// the ring nears the high-pass's own transient (3.7 Hz, decaying at
/// 9.6 1/s) and the high-pass's stop band; the bins' range itself is the
/// alert's choice (`firmware/docs/detector.md`) and stays as it is.
pub const OUTSIDE_BINS_HZ: f32 = 0.5;
/// Longest segment, samples (0.25 s at up to 200 Hz).
const MAX_SEGMENT_LEN: usize = 50;
/// Segments open at once: `SEGMENT_S / STRIDE_S`, rounded up.
const OPEN: usize = 3;

/// The standard uncertainty of a kick's sigma ([`Kick::sigma_sd_per_s`]) is
/// its fit's standard error scaled by this...
///
/// The fit takes its overlapping segments as independent, which they are
/// not (for the former 0.3 s Hann segments every 0.1 s, white noise
/// correlated neighbours by 0.471 and 0.029: about a factor of 1.4 on the
/// error; the 0.25 s segments and the `Y`s, which mix neighbours, differ
/// somewhat). The actual
/// errors are larger still: the road keeps ringing the mode at its own
/// frequency and decay through the ring-down, which no fit can tell from
/// the kick's ring. The host (`wobblog margin`) states the same uncertainty
/// of a card's kick records from these constants.
pub const SIGMA_SE_FACTOR: f64 = 3.3;
/// ... with this (1/s) added in quadrature: an error that no single fit
/// sees. Both calibrated on the simulated kick campaigns of seeds 100-111
/// (844 kicks measured by the former fit, so that the median |error| / SD is the
/// normal distribution's 0.674 in each fifth of the kicks sorted by their
/// standard error), and checked on seeds 200-249: 66.0 % of the errors
/// within one SD and 92.4 % within two; with the fit's own standard error,
/// 43 % within two (`host-tools/docs/kick-testing.md`). Checked again on
/// seeds 100-111 with the present fit (841 kicks): 70.2 % within one SD and
/// 95.4 % within two, the median |error| / SD 0.60-0.79 over the fifths.
/// That is slightly wide, on the side that makes the margin warning early;
/// fitted again (a grid search bringing each fifth's median to 0.674) the
/// constants would be 2.7 and 0.027 1/s (68.3 %, 94.8 %).
/// They are kept, with the figures measured on them.
pub const SIGMA_SD_FLOOR_PER_S: f64 = 0.0175;

/// A kick's ring-down as the detector measured it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Kick {
    /// Samples from the kick (the analysis that first saw it, less the hop)
    /// to the sample that reported it: the kick happened this long ago.
    pub samples_ago: u32,
    /// Mean wheel speed over the fitted ring (`None`: speed unknown), m/s.
    pub speed_mps: Option<f32>,
    /// Ring frequency, Hz.
    pub freq_hz: f32,
    /// Growth rate of the ring, 1/s (negative: it decays).
    pub sigma_per_s: f32,
    /// Standard error of `sigma_per_s` from the fit's residuals, 1/s (an
    /// optimistic one: [`Kick::sigma_sd_per_s`] is the calibrated
    /// uncertainty).
    pub sigma_se_per_s: f32,
    /// Ring amplitude extrapolated back to the kick, degrees (zero to peak).
    pub amp_deg: f32,
    /// Segments the fit used.
    pub segments: u8,
}

impl Kick {
    /// The calibrated standard uncertainty of `sigma_per_s`, 1/s:
    /// `sqrt((SIGMA_SE_FACTOR se)^2 + SIGMA_SD_FLOOR_PER_S^2)` of the fit's
    /// standard error `se`.
    #[must_use]
    pub fn sigma_sd_per_s(&self) -> f32 {
        let (k, e0) = (SIGMA_SE_FACTOR as f32, SIGMA_SD_FLOOR_PER_S as f32);
        let s = k * self.sigma_se_per_s;
        super::math::sqrtf(s * s + e0 * e0)
    }

    /// The card-log record of this kick, reported on the sample at local
    /// time `now_us` of a detector running at `sample_rate_hz`.
    #[must_use]
    pub fn to_record(&self, now_us: u64, sample_rate_hz: f32) -> KickRingDown {
        let ago_us = (self.samples_ago as f32 * 1e6 / sample_rate_hz) as u64;
        KickRingDown {
            t_us: now_us.saturating_sub(ago_us),
            speed_mm_s: self.speed_mps.map(|v| quantise_u16(v, 1000.0)),
            freq_chz: quantise_u16(self.freq_hz, 100.0),
            sigma_milli_per_s: quantise_i16(self.sigma_per_s, 1000.0),
            sigma_se_milli_per_s: quantise_u16(self.sigma_se_per_s, 1000.0),
            amp_cdeg: quantise_u16(self.amp_deg, 100.0),
            segments: self.segments,
        }
    }
}

/// One segment's demodulated amplitude.
#[derive(Clone, Copy, Debug, Default)]
struct Segment {
    /// Centre, s after the kick.
    t_s: f32,
    re: f32,
    im: f32,
}

/// The ring-down measurement in progress (one at a time).
#[derive(Clone, Debug)]
pub(crate) struct RingDown {
    fs_hz: f32,
    /// The Goertzel bins' range, Hz: `f0` is inside it.
    band: (f32, f32),
    /// The high-pass's slow pole per stride: its magnitude, and its angle
    /// per sample in turns.
    hp_decay: f32,
    hp_turns: f32,
    skip: u32,
    seg_len: usize,
    stride: u32,
    window: [f32; MAX_SEGMENT_LEN],
    amp_scale: f32,
    /// Samples since the kick, while measuring.
    age: Option<u32>,
    f0_hz: f32,
    /// Open segments: start age and running sums.
    open: [Option<(u32, f32, f32)>; OPEN],
    segments: [Segment; MAX_SEGMENTS],
    n: usize,
    speed_sum: f32,
    speed_n: u32,
    speed_known: bool,
}

impl RingDown {
    /// A measurement at sample rate `fs_hz` for rings in or near `band`,
    /// the Goertzel bins' range (Hz).
    /// `highpass_hz` is the corner of the detector's high-pass before it.
    pub(crate) fn new(fs_hz: f32, band: (f32, f32), highpass_hz: f32) -> Self {
        let n = |s: f32| (s * fs_hz + 0.5) as usize;
        let stride = n(STRIDE_S).max(1) as u32;
        let (re, im) = HighPass4::new(highpass_hz, fs_hz).slow_pole();
        let r = super::math::sqrtf(re * re + im * im);
        let seg_len = n(SEGMENT_S).clamp(4, MAX_SEGMENT_LEN);
        let mut window = [0.0; MAX_SEGMENT_LEN];
        let mut sum = 0.0;
        for (i, w) in window.iter_mut().enumerate().take(seg_len) {
            let (_, c) = sincos_turns((i as f32 + 0.5) / seg_len as f32);
            *w = 0.5 - 0.5 * c;
            sum += *w;
        }
        Self {
            fs_hz,
            band,
            hp_decay: libm::expf(stride as f32 * libm::logf(r)),
            hp_turns: libm::atan2f(im, re) / core::f32::consts::TAU,
            skip: n(SKIP_S) as u32,
            seg_len,
            stride,
            window,
            amp_scale: if sum > 0.0 { 2.0 / sum } else { 0.0 },
            age: None,
            f0_hz: 0.0,
            open: [None; OPEN],
            segments: [Segment::default(); MAX_SEGMENTS],
            n: 0,
            speed_sum: 0.0,
            speed_n: 0,
            speed_known: true,
        }
    }

    /// Starts measuring a kick first seen `lead` samples ago, ringing at
    /// about `f0_hz` (the band's centre when that is outside the band).
    pub(crate) fn start(&mut self, lead: u32, f0_hz: f32) {
        let (lo, hi) = self.band;
        self.f0_hz = if f0_hz >= lo && f0_hz <= hi {
            f0_hz
        } else {
            0.5 * (lo + hi)
        };
        self.age = Some(lead);
        self.open = [None; OPEN];
        self.n = 0;
        self.speed_sum = 0.0;
        self.speed_n = 0;
        self.speed_known = true;
    }

    /// Stops without reporting.
    pub(crate) fn cancel(&mut self) {
        self.age = None;
    }

    /// Ends the measurement now (another impulse, an alert) and reports the
    /// kick if enough of the ring was measured.
    pub(crate) fn finish(&mut self) -> Option<Kick> {
        let age = self.age.take()?;
        self.fit(age)
    }

    /// Feeds one high-passed, ripple-cancelled sample `y` (degrees) and the
    /// speed; returns the kick once its ring-down is measured.
    pub(crate) fn sample(&mut self, y: f32, speed_mps: Option<f32>) -> Option<Kick> {
        let age = self.age?;
        let next = age + 1;
        self.age = Some(next);
        if age < self.skip {
            return None;
        }
        let since = age - self.skip;
        if since.is_multiple_of(self.stride) && self.n + self.open_count() < MAX_SEGMENTS {
            if let Some(slot) = self.open.iter_mut().find(|s| s.is_none()) {
                *slot = Some((age, 0.0, 0.0));
            }
        }
        match speed_mps {
            Some(v) => {
                self.speed_sum += v;
                self.speed_n += 1;
            }
            None => self.speed_known = false,
        }
        // The reference oscillator's phase is tied to the kick's time, so
        // every segment's phase is on one clock.
        let turns = self.f0_hz * age as f32 / self.fs_hz;
        let (s, c) = sincos_turns(turns - (turns as u32) as f32);
        let mut closed = None;
        for slot in &mut self.open {
            if let Some((start, re, im)) = slot {
                let i = (age - *start) as usize;
                let wy = self.window[i] * y;
                *re += wy * c;
                *im -= wy * s;
                if i + 1 == self.seg_len {
                    let centre = *start as f32 + 0.5 * (self.seg_len - 1) as f32;
                    closed = Some(Segment {
                        t_s: centre / self.fs_hz,
                        re: *re * self.amp_scale,
                        im: *im * self.amp_scale,
                    });
                    *slot = None;
                }
            }
        }
        let seg = closed?;
        let amp = super::math::sqrtf(seg.re * seg.re + seg.im * seg.im);
        if amp < FLOOR_DEG {
            self.age = None;
            return self.fit(next);
        }
        self.segments[self.n] = seg;
        self.n += 1;
        if self.n == MAX_SEGMENTS {
            self.age = None;
            return self.fit(next);
        }
        None
    }

    fn open_count(&self) -> usize {
        self.open.iter().filter(|s| s.is_some()).count()
    }

    /// The high-pass's slow transient as the segments see it: the factor
    /// `q` from one segment to the next (its pole over a stride, less the
    /// reference oscillator's turn).
    fn hp_ratio(&self) -> (f32, f32) {
        let turns = self.stride as f32 * (self.hp_turns - self.f0_hz / self.fs_hz);
        let (s, c) = sincos_turns(turns);
        (self.hp_decay * c, self.hp_decay * s)
    }

    /// The fit over the segments so far, reported `age` samples after the
    /// kick.
    ///
    /// Once the push is over, the high-pass's output is the ring, the road,
    /// and the high-pass's own transients, whose poles are known: the slow
    /// one makes the segments `X_k = A z^k + B q^k` ([`Self::hp_ratio`]),
    /// and `Y_k = X_(k+1) - q X_k = A (z - q) z^k` is the ring alone, at
    /// the cost of one segment (the other section's transient decays 2.4
    /// times faster and is gone after the skip). The fit is on `Y`, in
    /// place: it ends the measurement.
    fn fit(&mut self, age: u32) -> Option<Kick> {
        if self.n < MIN_SEGMENTS {
            return None;
        }
        let (qr, qi) = self.hp_ratio();
        let n = self.n - 1;
        for k in 0..n {
            let (x, next) = (self.segments[k], self.segments[k + 1]);
            self.segments[k].re = next.re - (qr * x.re - qi * x.im);
            self.segments[k].im = next.im - (qr * x.im + qi * x.re);
        }
        let seg = &self.segments[..n];
        let Line {
            sigma,
            sigma_se,
            t_mean,
            l_mean,
        } = line_fit(seg)?;
        // Pulse pair: the mean phase advance per stride.
        let (mut pr, mut pi) = (0.0_f32, 0.0_f32);
        for w in seg.windows(2) {
            pr += w[1].re * w[0].re + w[1].im * w[0].im;
            pi += w[1].im * w[0].re - w[1].re * w[0].im;
        }
        let stride_s = self.stride as f32 / self.fs_hz;
        let freq_hz = self.f0_hz + libm::atan2f(pi, pr) / (core::f32::consts::TAU * stride_s);
        let (lo, hi) = (self.band.0 - OUTSIDE_BINS_HZ, self.band.1 + OUTSIDE_BINS_HZ);
        if !(freq_hz >= lo && freq_hz <= hi && sigma.is_finite()) {
            return None;
        }
        // Outside the bins only a ring that decays is a ring-down: a steady
        // or growing oscillation there is not what the alert watches, and
        // taking it for the wobble mode would warn of a wobble that is not.
        let in_bins = freq_hz >= self.band.0 && freq_hz <= self.band.1;
        if !in_bins && sigma >= 0.0 {
            return None;
        }
        // The segments' Hann window passes a tone (f - f0) away at
        // sinc(d) / (1 - d^2) of its amplitude, d = (f - f0) x its length.
        let d = (freq_hz - self.f0_hz) * self.seg_len as f32 / self.fs_hz;
        let pd = core::f32::consts::PI * d;
        let gain = if d.abs() < 1e-3 {
            1.0
        } else if (1.0 - d.abs()).abs() < 1e-3 {
            0.5
        } else {
            // sin(pi d) by the detector's own sine of d / 2 turns: libm's
            // `sinf` would link its large-argument reduction and its 2/pi
            // table into the firmware for this one value per kick.
            sincos_turns(0.5 * d).0 / (pd * (1.0 - d * d))
        };
        // |z - q| of the ring's step z over a stride.
        let (zs, zc) = sincos_turns((freq_hz - self.f0_hz) * stride_s);
        let zm = libm::expf(sigma * stride_s);
        let (dr, di) = (zm * zc - qr, zm * zs - qi);
        let through = super::math::sqrtf(dr * dr + di * di);
        let amp_deg = libm::expf(l_mean - sigma * t_mean) / (gain * through).max(0.1);
        Some(Kick {
            samples_ago: age,
            speed_mps: (self.speed_known && self.speed_n > 0)
                .then(|| self.speed_sum / self.speed_n as f32),
            freq_hz,
            sigma_per_s: sigma,
            sigma_se_per_s: sigma_se,
            amp_deg,
            // The segments behind the `Y`s fitted.
            segments: self.n as u8,
        })
    }
}

/// The measurement's arithmetic (see [`super::Cost`]): per sample while a
/// ring is measured (on the sample a segment closes), and the fit on the
/// sample that reports the kick (worst case: [`MAX_SEGMENTS`] segments).
pub(crate) fn cost() -> (Cost1, Cost1) {
    let open = OPEN as u32;
    // The oscillator's phase and sincos; per open segment a window and two
    // products into the sums; the speed's sum; a closing segment's centre,
    // scale and amplitude.
    let per_sample =
        Cost1::SINCOS + Cost1::SQRT + Cost1::new(2 + 3 * open + 6, 1 + 2 * open + 4, 2 * open + 4);
    // Per `Y`: the transient taken out (a complex multiply-add), its power,
    // half its logarithm, the three weighted sums, then the two centred
    // sums and the residual.
    let segment = Cost1::LOG + Cost1::new(16, 16, 2);
    // The line: the means, the slope and its standard error.
    let line = Cost1::SQRT + Cost1::new(6, 0, 2);
    let n = MAX_SEGMENTS as u32;
    // The pulse pair over the neighbours, the frequency, the window's gain
    // (a sine), the transient's step q (a sincos), the ring's step z over a
    // stride (an exponential, a sincos) and |z - q|, the amplitude (an
    // exponential).
    let pulse_pair = Cost1::new(4, 4, 0);
    let fit = segment * (n - 1)
        + line
        + pulse_pair * (n - 2)
        + Cost1::ATAN2
        + Cost1::EXP * 3
        + Cost1::SINCOS * 2
        + Cost1::SQRT
        + Cost1::new(23, 10, 10);
    (per_sample, fit)
}

/// A weighted straight line through `ln |X_k|` against `t_k`.
struct Line {
    sigma: f32,
    sigma_se: f32,
    t_mean: f32,
    l_mean: f32,
}

/// Weighted least squares of `ln |X|` on `t`, weights `|X|^2` (the inverse
/// variance of `ln |X|` in additive noise); `None` without a spread in time.
fn line_fit(seg: &[Segment]) -> Option<Line> {
    let (mut sw, mut st, mut sl) = (0.0_f32, 0.0_f32, 0.0_f32);
    let mut logs = [0.0_f32; MAX_SEGMENTS];
    let mut weights = [0.0_f32; MAX_SEGMENTS];
    for (k, s) in seg.iter().enumerate() {
        let p = s.re * s.re + s.im * s.im;
        logs[k] = 0.5 * libm::logf(p);
        weights[k] = p;
        sw += p;
        st += p * s.t_s;
        sl += p * logs[k];
    }
    let (t_mean, l_mean) = (st / sw, sl / sw);
    let (mut stt, mut stl) = (0.0_f32, 0.0_f32);
    for (k, s) in seg.iter().enumerate() {
        let dt = s.t_s - t_mean;
        stt += weights[k] * dt * dt;
        stl += weights[k] * dt * (logs[k] - l_mean);
    }
    if stt.is_nan() || stt <= 0.0 {
        return None;
    }
    let sigma = stl / stt;
    let mut ssr = 0.0_f32;
    for (k, s) in seg.iter().enumerate() {
        let r = logs[k] - l_mean - sigma * (s.t_s - t_mean);
        ssr += weights[k] * r * r;
    }
    let dof = (seg.len() - 2) as f32;
    Some(Line {
        sigma,
        sigma_se: super::math::sqrtf(ssr / dof / stt),
        t_mean,
        l_mean,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clean damped sinusoid from the kick on, measured for the bins'
    /// range `band` from `f0_hz`: the kick, if one is reported.
    fn ring(f: f32, sigma: f32, amp: f32, band: (f32, f32), f0_hz: f32) -> Option<Kick> {
        let mut r = RingDown::new(100.0, band, 4.0);
        r.start(0, f0_hz);
        for i in 0..400 {
            let t = i as f32 / 100.0;
            let y = amp * libm::expf(sigma * t) * libm::sinf(core::f32::consts::TAU * f * t);
            if let Some(k) = r.sample(y, Some(3.0)) {
                return Some(k);
            }
        }
        r.finish()
    }

    fn measure(f: f32, sigma: f32, amp: f32) -> Kick {
        ring(f, sigma, amp, (5.8, 9.2), 7.0).expect("a kick")
    }

    fn assert_exact(k: &Kick, f: f32, sigma: f32, amp: f32) {
        assert!((k.freq_hz - f).abs() < 0.02, "{k:?}");
        assert!((k.sigma_per_s - sigma).abs() < 0.05, "{k:?}");
        assert!((k.amp_deg - amp).abs() < 0.05 * amp, "{k:?}");
        assert!(k.sigma_se_per_s < 0.05, "{k:?}");
        assert_eq!(k.speed_mps, Some(3.0));
    }

    #[test]
    fn a_clean_ring_is_measured_exactly() {
        for (f, sigma, amp) in [(6.2, -0.3, 1.5), (7.6, -1.5, 2.0), (8.8, -3.0, 2.6)] {
            assert_exact(&measure(f, sigma, amp), f, sigma, amp);
        }
    }

    /// A push of 4 deg over 0.1 s, then a fast ring, through the detector's
    /// high-pass: its transient (3.7 Hz, decaying at 9.6 1/s) is in the
    /// first segments, and the fit sees through it.
    #[test]
    fn a_pushed_fast_ring_is_measured_through_the_high_pass_transient() {
        for (f, sigma, amp, push) in [(6.0, -2.5, 1.5, 4.0), (6.6, -2.0, 1.2, -5.0)] {
            let mut hp = HighPass4::new(4.0, 100.0);
            let mut r = RingDown::new(100.0, (5.5, 9.5), 4.0);
            r.start(0, f);
            let mut kick = None;
            for i in 0..400 {
                let t = i as f32 / 100.0;
                let x = if t < 0.1 {
                    push * libm::sinf(core::f32::consts::PI * t / 0.1)
                } else {
                    let tau = t - 0.1;
                    amp * libm::expf(sigma * tau) * libm::sinf(core::f32::consts::TAU * f * tau)
                };
                kick = kick.or(r.sample(hp.process(x), None));
            }
            let k = kick.or_else(|| r.finish()).expect("a kick");
            assert!((k.freq_hz - f).abs() < 0.05, "{k:?}");
            assert!((k.sigma_per_s - sigma).abs() < 0.1, "{k:?}");
            assert_eq!(k.speed_mps, None);
        }
    }

    /// A bicycle whose wobble rings just below the bins (5.35-5.42 Hz for
    /// the paper's test bicycle with its light rider, bins from 5.5 Hz):
    /// the dominant bin is the lowest, and the ring is measured from there.
    #[test]
    fn a_ring_just_outside_the_bins_is_measured_from_the_edge_bin() {
        let bins = (5.5, 9.5);
        for (f, f0) in [(5.38, 5.5), (5.05, 5.5), (9.95, 9.5)] {
            let k = ring(f, -0.8, 1.5, bins, f0).expect("a kick");
            assert_exact(&k, f, -0.8, 1.5);
        }
        // Further out (the high-pass's transient, its stop band): none.
        for (f, f0) in [(4.9, 5.5), (10.1, 9.5)] {
            assert_eq!(ring(f, -0.8, 1.5, bins, f0), None, "{f} Hz");
        }
        // Just outside, a ring that does not decay is no ring-down; inside
        // the bins it is measured (a wobble starting).
        assert_eq!(ring(5.3, 0.1, 1.0, bins, 5.5), None);
        let k = ring(5.7, 0.1, 1.0, bins, 5.5).expect("a kick");
        assert!((k.sigma_per_s - 0.1).abs() < 0.05, "{k:?}");
    }

    /// The fit's standard error is the weighted least squares one with
    /// n - 2 degrees of freedom: worked here in f64 from the formula (the
    /// line through (t, ln |y|) weighted by |y|^2), apart from the code.
    #[test]
    fn the_standard_error_has_n_minus_2_degrees_of_freedom() {
        let t = [0.0_f64, 0.1, 0.2, 0.3, 0.4];
        let l = [0.0_f64, -0.2, -0.55, -0.6, -0.95];
        let seg: Vec<Segment> = t
            .iter()
            .zip(l)
            .map(|(&t_s, l)| Segment {
                t_s: t_s as f32,
                re: (0.6 * l.exp()) as f32,
                im: (0.8 * l.exp()) as f32,
            })
            .collect();
        let w: Vec<f64> = l.iter().map(|l| (2.0 * l).exp()).collect();
        let sw: f64 = w.iter().sum();
        let tm = w.iter().zip(t).map(|(w, t)| w * t).sum::<f64>() / sw;
        let lm = w.iter().zip(l).map(|(w, l)| w * l).sum::<f64>() / sw;
        let stt: f64 = w.iter().zip(t).map(|(w, t)| w * (t - tm).powi(2)).sum();
        let stl: f64 = (0..5).map(|k| w[k] * (t[k] - tm) * (l[k] - lm)).sum();
        let sigma = stl / stt;
        let ssr: f64 = (0..5)
            .map(|k| w[k] * (l[k] - lm - sigma * (t[k] - tm)).powi(2))
            .sum();
        let se = (ssr / 3.0 / stt).sqrt();
        let line = line_fit(&seg).expect("a line");
        assert!(
            (f64::from(line.sigma) - sigma).abs() < 1e-4,
            "{}",
            line.sigma
        );
        assert!(
            (f64::from(line.sigma_se) - se).abs() < 1e-4 * se,
            "{} against {se}",
            line.sigma_se
        );
    }

    /// A kick's record is stamped when it happened: `samples_ago` samples
    /// at 100 Hz before the sample that reports it.
    #[test]
    fn a_record_is_stamped_at_the_kick() {
        let kick = Kick {
            samples_ago: 150,
            speed_mps: Some(3.2),
            freq_hz: 6.4,
            sigma_per_s: -1.1,
            sigma_se_per_s: 0.05,
            amp_deg: 1.5,
            segments: 9,
        };
        // 1.5 s before 10 s.
        assert_eq!(kick.to_record(10_000_000, 100.0).t_us, 8_500_000);
        assert_eq!(kick.to_record(10_000_000, 50.0).t_us, 7_000_000);
    }

    /// A ring whose wheel speed drops out part of the way has no speed:
    /// the mean of the part that had one is not the ring's.
    #[test]
    fn a_ring_whose_speed_drops_out_has_no_speed() {
        let mut r = RingDown::new(100.0, (5.8, 9.2), 4.0);
        r.start(0, 7.0);
        let mut kick = None;
        for i in 0..400 {
            let t = i as f32 / 100.0;
            let y = 1.5 * libm::expf(-t) * libm::sinf(core::f32::consts::TAU * 7.0 * t);
            let speed = (t < 0.5).then_some(3.0);
            kick = kick.or(r.sample(y, speed));
        }
        let k = kick.or_else(|| r.finish()).expect("a kick");
        assert_eq!(k.speed_mps, None, "{k:?}");
    }
}
